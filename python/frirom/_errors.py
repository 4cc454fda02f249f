"""Python exceptions built from the Fortran status codes (see fortran/frirom_status.f90)."""

from __future__ import annotations


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
    code = 1


class ParameterError(InputError):
    code = 2


class NonFiniteError(InputError):
    code = 3


class SamplesError(InputError):
    code = 4


class NumericalError(FriromError, ArithmeticError):
    """A numerical procedure failed (factorisation, eigen-solve, non-convergence)."""


class ConvergenceError(NumericalError):
    code = 9


class SingularMatrixError(NumericalError):
    code = 10


class FactorizationError(NumericalError):
    """The sparse factorisation (MUMPS) of K - sigma M failed: out of memory, or a
    structurally singular matrix (a free body without masters, a zero-stiffness DoF)."""
    code = 40


_BY_CODE = {cls.code: cls for cls in (SizeError, ParameterError, NonFiniteError,
                                      SamplesError, ConvergenceError, SingularMatrixError,
                                      FactorizationError)}
_BY_CODE[11] = ParameterError      # unknown contact law
_BY_CODE[12] = ConvergenceError    # hysteresis cycle did not close
_BY_CODE[20] = ConvergenceError    # continuation stopped at the minimum step
_BY_CODE[21] = ParameterError      # inconsistent model data (solver)


def raise_for_status(info: int, message: str) -> None:
    """Raise the exception class of a nonzero Fortran status, with Fortran's message."""
    if info == 0:
        return
    cls = _BY_CODE.get(int(info), NumericalError)
    raise cls(message.strip() or f"frirom status {info}", code=int(info))
