"""Fortran status codes become Python exceptions of the right family, carrying the text
Fortran produced (fortran/frirom_status.f90 is the source of the codes)."""

import re
from pathlib import Path

import pytest

import frirom
from frirom import _kernels
from frirom._errors import raise_for_status

STATUS = Path(__file__).resolve().parents[1] / "fortran" / "frirom_status.f90"


def fortran_codes():
    text = STATUS.read_text()
    return {name: int(v) for name, v in
            re.findall(r"parameter :: (FRIROM_ERR_\w+) = (\d+)", text)}


def test_every_fortran_code_has_a_message_and_an_exception_family():
    codes = fortran_codes()
    assert len(codes) >= 15
    for name, code in codes.items():
        msg = _kernels.status_message(code).decode().strip()
        assert msg and msg != "unknown status code", name
        with pytest.raises(frirom.FriromError) as info:
            raise_for_status(code, msg)
        assert info.value.code == code and msg in str(info.value)
        expected = frirom.InputError if name in {
            "FRIROM_ERR_SIZE", "FRIROM_ERR_PARAM", "FRIROM_ERR_NONFINITE",
            "FRIROM_ERR_SAMPLES", "FRIROM_ERR_LAW", "FRIROM_ERR_MODEL"} else frirom.NumericalError
        assert isinstance(info.value, expected), name
    raise_for_status(0, "")   # success raises nothing


def test_factorisation_failure_has_its_own_class():
    with pytest.raises(frirom.FactorizationError):
        raise_for_status(40, "dmumps: out of memory")
