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


#: Status codes Python tests for, by their Fortran names.
CODES = {name: int_constant(name) for name in (
    "FRIROM_ERR_SIZE", "FRIROM_ERR_PARAM", "FRIROM_ERR_NONFINITE", "FRIROM_ERR_SAMPLES",
    "FRIROM_ERR_NOCONV", "FRIROM_ERR_SINGULAR", "FRIROM_ERR_LAW", "FRIROM_ERR_NOCLOSE",
    "FRIROM_ERR_CONT", "FRIROM_ERR_MODEL", "FRIROM_ERR_FACTOR")}


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


class SizeError(InputError):
    code = CODES["FRIROM_ERR_SIZE"]


class ParameterError(InputError):
    code = CODES["FRIROM_ERR_PARAM"]


class NonFiniteError(InputError):
    code = CODES["FRIROM_ERR_NONFINITE"]


class SamplesError(InputError):
    code = CODES["FRIROM_ERR_SAMPLES"]


class NumericalError(FriromError, ArithmeticError):
    """A numerical procedure failed (factorisation, eigen-solve, non-convergence)."""


class ConvergenceError(NumericalError):
    code = CODES["FRIROM_ERR_NOCONV"]


class SingularMatrixError(NumericalError):
    code = CODES["FRIROM_ERR_SINGULAR"]


class FactorizationError(NumericalError):
    """The sparse factorisation (MUMPS) of K - sigma M failed: out of memory, or a
    structurally singular matrix (a free body without masters, a zero-stiffness DoF)."""
    code = CODES["FRIROM_ERR_FACTOR"]


_BY_CODE = {cls.code: cls for cls in (SizeError, ParameterError, NonFiniteError,
                                      SamplesError, ConvergenceError, SingularMatrixError,
                                      FactorizationError)}
_BY_CODE[CODES["FRIROM_ERR_LAW"]] = ParameterError       # unknown contact law
_BY_CODE[CODES["FRIROM_ERR_NOCLOSE"]] = ConvergenceError  # hysteresis cycle did not close
_BY_CODE[CODES["FRIROM_ERR_CONT"]] = ConvergenceError     # continuation at the minimum step
_BY_CODE[CODES["FRIROM_ERR_MODEL"]] = ParameterError      # inconsistent model data (solver)
# every other code (allocation, FFTW, LAPACK, ARPACK) is a NumericalError


def raise_for_status(info: int, message: str) -> None:
    """Raise the exception class of a nonzero Fortran status, with Fortran's message."""
    if info == 0:
        return
    cls = _BY_CODE.get(int(info), NumericalError)
    raise cls(message.strip() or f"frirom status {info}", code=int(info))
