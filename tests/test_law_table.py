"""The contact-law table has one source: frirom_aft (Fortran) holds the codes and sizes,
frirom.contact.LAWS adds the names of directions and parameters and is checked against it
at import. Here: LAWS agrees with the Fortran table code by code, a disagreement stops
the import, and Fortran's message for an unknown code lists the laws of its table."""

import pytest

from frirom import ParameterError, _kernels, contact


def _built_in():
    """The laws of the Fortran table (user laws registered by other tests in this process
    carry negative codes and are not in it)."""
    return [law for law in contact.LAWS.values() if law.code > 0]


def test_laws_match_the_fortran_table():
    *_, n_law = _kernels.law_info(0)
    assert sorted(law.code for law in _built_in()) == list(range(1, n_law + 1))
    for law in _built_in():
        n_dir, n_par, n_slider, name, _ = _kernels.law_info(law.code)
        assert (name.decode().strip(), n_dir, n_par, n_slider) == \
            (law.name, law.n_dir, len(law.parameters), law.n_slider)
    for code in (0, n_law + 1, -3):
        assert _kernels.law_info(code)[:4] == (0, 0, 0, b"")


@pytest.mark.parametrize("names", [
    {**contact._NAMES, "jenkins": (("u", "v"), ("kt", "mu", "fn0"), "two directions?")},
    {k: v for k, v in contact._NAMES.items() if k != "cubic"},
    {**contact._NAMES, "coulomb3d": (("u",), ("kt",), "not in Fortran")},
])
def test_disagreement_stops_the_import(monkeypatch, names):
    monkeypatch.setattr(contact, "_NAMES", names)
    with pytest.raises(RuntimeError, match="law"):
        contact._build_laws()


def test_unknown_code_message_lists_the_laws():
    bogus = contact.Law("bogus", 9, ("u",), ("kt", "mu", "fn0"), 1)
    expected = ", ".join(f"{law.code} {law.name}" for law in _built_in())
    with pytest.raises(ParameterError, match=f"law 9 \\(expected {expected}\\)"):
        contact.aft(bogus, [[0.0, 1e-3, 0.0]], [1e5, 0.3, 10.0], n_samples=16)
