"""Fortran status codes become Python exceptions of the right family, carrying the text
Fortran produced. Codes and messages are read through the extension (frirom_status's
frirom_status_code and frirom_status_message), never from the Fortran source text."""

import pytest

import frirom
from frirom import _kernels
from frirom._errors import int_constant, raise_for_status

#: Every nonzero status of frirom_status, by name, with the exception family Python must
#: raise for it (bad input, or a numerical failure).
FAMILY = {
    "FRIROM_ERR_SIZE": frirom.InputError,
    "FRIROM_ERR_PARAM": frirom.InputError,
    "FRIROM_ERR_NONFINITE": frirom.InputError,
    "FRIROM_ERR_SAMPLES": frirom.InputError,
    "FRIROM_ERR_ALLOC": frirom.NumericalError,
    "FRIROM_ERR_FFTW": frirom.NumericalError,
    "FRIROM_ERR_LAPACK": frirom.NumericalError,
    "FRIROM_ERR_ARPACK": frirom.NumericalError,
    "FRIROM_ERR_NOCONV": frirom.NumericalError,
    "FRIROM_ERR_SINGULAR": frirom.NumericalError,
    "FRIROM_ERR_LAW": frirom.InputError,
    "FRIROM_ERR_NOCLOSE": frirom.NumericalError,
    "FRIROM_ERR_CONT": frirom.NumericalError,
    "FRIROM_ERR_MODEL": frirom.InputError,
    "FRIROM_ERR_FACTOR": frirom.NumericalError,
}


def message(code):
    return _kernels.status_message(code).decode().strip()


def test_every_fortran_code_has_a_message_and_an_exception_family():
    codes = {name: int_constant(name) for name in FAMILY}
    # every code Fortran has a message for is one of the names above
    known = {c for c in range(1, 1000) if message(c) != "unknown status code"}
    assert known == set(codes.values())
    assert int_constant("FRIROM_OK") == 0
    for name, code in codes.items():
        msg = message(code)
        with pytest.raises(frirom.FriromError) as info:
            raise_for_status(code, msg)
        assert info.value.code == code and msg in str(info.value)
        assert isinstance(info.value, FAMILY[name]), name
    raise_for_status(0, "")   # success raises nothing


def test_factorisation_failure_has_its_own_class():
    with pytest.raises(frirom.FactorizationError):
        raise_for_status(int_constant("FRIROM_ERR_FACTOR"), "dmumps: out of memory")
