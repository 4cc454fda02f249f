"""Python exceptions built from the Fortran status codes (see fortran/frirom_status.f90).

The codes are read from the Fortran library by name at import, never typed here.
"""

from __future__ import annotations

import math
import re

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


#: a frequency in rad/s not yet followed by its value in Hz
_RAD_S = re.compile(r"([-+]?\d[\d.]*(?:[eE][-+]?\d+)?) ?rad/s(?! \([-+\d.eE]+ Hz\))")


def with_hz(text: str) -> str:
    """A message's frequencies in rad/s followed by the same in Hz:
    ``through omega = 2950.3 rad/s`` -> ``... 2950.3 rad/s (469.56 Hz)``; idempotent."""
    return _RAD_S.sub(lambda m: f"{m.group(0)} ({float(m.group(1)) / 2 / math.pi:.6g}"
                      " Hz)", text)


def raise_for_status(info: int, message: str) -> None:
    """Raise the exception class of a nonzero Fortran status, with Fortran's message
    (frequencies in rad/s also in Hz)."""
    if info == 0:
        return
    cls = _BY_CODE.get(int(info), NumericalError)
    raise cls(with_hz(message.strip()) or f"frirom status {info}", code=int(info))


# ---- checks of Python API arguments: each names the argument and what was expected ----

#: Highest harmonic H a run may ask for (dense Jacobians of (2H+1)^2 blocks per DoF pair).
MAX_HARMONICS = 200
#: Most AFT time samples per period N: 2^20, 2 000 times the default for H <= 15 and far
#: past where the AFT error stops improving (cases/bench/samples.py); it also keeps N and
#: the FFTW buffer sizes inside the 32-bit integers of the Fortran interface.
MAX_SAMPLES = 1 << 20
#: Highest frequency [rad/s] a run may ask for (~160 MHz): omega^2 M must stay far from
#: overflow, and no structural model is meaningful beyond it.
MAX_OMEGA = 1.0e9


def _shown(v) -> str:
    s = repr(v)
    return s if len(s) <= 80 else s[:77] + "..."


def check_number(name: str, v, *, positive: bool = False, nonneg: bool = False,
                 maximum: float | None = None, cls=None) -> float:
    """``v`` as a float: a real finite number (>0, >=0, <= maximum as asked); else
    ``cls`` (default ParameterError) naming ``name``."""
    cls = cls or ParameterError
    what = ("a positive" if positive else "a non-negative" if nonneg else "a finite") \
        + " number" + (f" at most {maximum:g}" if maximum is not None else "")
    try:
        ok = not isinstance(v, (bool, str, bytes, complex)) and float(v) == float(v)
        x = float(v) if ok else float("nan")
    except (TypeError, ValueError, OverflowError):
        x = float("nan")
    if (x != x or abs(x) == float("inf") or (positive and x <= 0) or (nonneg and x < 0)
            or (maximum is not None and x > maximum)):
        raise cls(f"{name}: expected {what}, got {_shown(v)}")
    return x


def as_floats(name: str, v, cls=None):
    """``v`` as a float ndarray; ``cls`` (default ParameterError) naming ``name`` if it
    holds anything but real numbers (text, None, an integer too big for a float)."""
    import numpy as np
    try:
        return np.asarray(v, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise (cls or ParameterError)(f"{name}: expected numbers, got {_shown(v)}") from None


def check_integer(name: str, v, *, minimum: int | None = None, maximum: int | None = None,
                  cls=None) -> int:
    """``v`` as an int (an integral Python or numpy integer, not a float or bool) within
    [minimum, maximum]; else ``cls`` (default ParameterError) naming ``name``."""
    import numpy as np
    cls = cls or ParameterError
    rng = ("" if minimum is None and maximum is None else
           f" >= {minimum}" if maximum is None else f" in {minimum}..{maximum}"
           if minimum is not None else f" at most {maximum}")
    if (isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer))
            or (minimum is not None and v < minimum) or (maximum is not None and v > maximum)):
        raise cls(f"{name}: expected an integer{rng}, got {_shown(v)}")
    return int(v)


def aft_bytes(n_harm: int, n_samples: int, n_signals: int = 1) -> int:
    """Memory [bytes] an AFT plan of H harmonics and N samples needs: its tables (the
    (N, 2H+1) basis and the (4H+1, N+1) prefix sums of frirom_fourier) and four FFTW
    buffers of N values per signal (``n_signals``: contact directions AFT'd together)."""
    return 8 * int(n_samples) * (6 * int(n_harm) + 2 + 4 * max(int(n_signals), 1))


def samples_problem(n_harm: int, n_samples, n_signals: int = 1) -> str | None:
    """What is wrong with N = ``n_samples`` AFT samples for H = ``n_harm`` (None: nothing):
    the text says what was expected, with the memory N would need when it is too large
    or more than half of this machine's memory."""
    import numpy as np
    lo = 2 * int(n_harm) + 1
    if isinstance(n_samples, (bool, np.bool_)) or not isinstance(n_samples, (int, np.integer)):
        return f"an integer in {lo}..{MAX_SAMPLES}"
    if n_samples < lo:
        return f"an integer >= 2*harmonics+1 (2H+1 = {lo})"
    need = aft_bytes(n_harm, n_samples, n_signals)
    if n_samples > MAX_SAMPLES:
        return (f"at most {MAX_SAMPLES} samples (N = {n_samples} would need "
                f"{need / 2**30:.3g} GiB of memory for the AFT)")
    avail = _physical_memory()
    if avail and need > avail // 2:
        return (f"fewer samples: N = {n_samples} needs {need / 2**30:.3g} GiB of memory for "
                f"the AFT, more than half of this machine's {avail / 2**30:.3g} GiB")
    return None


def _physical_memory() -> int:
    """Bytes of physical memory (0 if unknown)."""
    import os
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return 0
