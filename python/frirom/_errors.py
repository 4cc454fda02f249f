"""Python exceptions built from the Fortran status codes (see fortran/frirom_status.f90).

The codes are read from the Fortran library by name at import, never typed here.
"""

from __future__ import annotations

from . import _kernels


def int_constant(name: str) -> int:
    """A named integer constant of the Fortran interface (frirom_f2py int_constant: status
    codes such as ``'FRIROM_ERR_CONT'``, option and timer slots, start modes); ImportError
    if the library has no constant of that name."""
    value, info, msg = _kernels.int_constant(name)
    if info != 0:
        raise ImportError(msg.decode(errors="replace").strip())
    return int(value)


class FriromError(Exception):
    """Base class of every error frirom raises on purpose.

    ``code`` is the Fortran status code (0 when the error was found in Python).
    """

    code = 0

    def __init__(self, message: str, code: int | None = None):
        super().__init__(message)
        if code is not None:
            self.code = code


class InputError(FriromError, ValueError):
    """Bad input: wrong shape, out-of-range parameter, malformed file or deck field."""


class NumericalError(FriromError, ArithmeticError):
    """A numerical procedure failed (factorisation, eigen-solve, non-convergence)."""


class SizeError(InputError):
    """Array sizes or shapes do not match."""


class ParameterError(InputError):
    """A parameter is out of range, a contact law is unknown, or the model data are
    inconsistent."""


class NonFiniteError(InputError):
    """NaN or Inf in the input."""


class SamplesError(InputError):
    """Too few time samples for the harmonics (N < 2H+1)."""


class ConvergenceError(NumericalError):
    """An iteration did not converge: Newton, the hysteresis cycle, or continuation at
    the minimum step."""


class SingularMatrixError(NumericalError):
    """A matrix is singular."""


class FactorizationError(NumericalError):
    """The sparse factorisation (MUMPS) of K - sigma M failed: out of memory, or a
    structurally singular matrix (a free body without masters, a zero-stiffness DoF)."""


#: The Fortran statuses each class is raised for; ``cls.code`` is the first. Every other
#: nonzero code (allocation, FFTW, LAPACK, ARPACK) is a NumericalError.
_RAISED_FOR = {
    SizeError: ("FRIROM_ERR_SIZE",),
    ParameterError: ("FRIROM_ERR_PARAM", "FRIROM_ERR_LAW", "FRIROM_ERR_MODEL"),
    NonFiniteError: ("FRIROM_ERR_NONFINITE",),
    SamplesError: ("FRIROM_ERR_SAMPLES",),
    ConvergenceError: ("FRIROM_ERR_NOCONV", "FRIROM_ERR_NOCLOSE", "FRIROM_ERR_CONT"),
    SingularMatrixError: ("FRIROM_ERR_SINGULAR",),
    FactorizationError: ("FRIROM_ERR_FACTOR",),
}
#: Status codes Python raises for, by their Fortran names.
CODES = {name: int_constant(name) for names in _RAISED_FOR.values() for name in names}
_BY_CODE = {CODES[name]: cls for cls, names in _RAISED_FOR.items() for name in names}
for _cls, _names in _RAISED_FOR.items():
    _cls.code = CODES[_names[0]]
del _cls, _names


def raise_for_status(info: int, message: str) -> None:
    """Raise the exception class of a nonzero Fortran status, with Fortran's message."""
    if info == 0:
        return
    cls = _BY_CODE.get(int(info), NumericalError)
    raise cls(message.strip() or f"frirom status {info}", code=int(info))
