"""The bundled under-platform damper case (cases/upd/, issue 29 item 7, linear part): two
blades and a strip damper held only by its contacts, structured C3D8 meshes, CalculiX
matrices. `frirom modes` on its deck against CalculiX's own eigenfrequencies of the full
FE models: the blades alone (contacts free; the damper's six rigid motions are flagged,
named, and left out) and the assembly with every contact pair joined by the deck's kt, kn
springs (contacts stuck). Tolerance 1e-4 relative: the Craig-Bampton model keeps 30
fixed-interface modes (its truncation error, measured 7e-5 at the second pair)."""

import shutil
from pathlib import Path

import numpy as np
import pytest

from frirom.deck import load_deck
from frirom.modes import linear_check

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_upd_linear_limits_against_calculix(tmp_path, monkeypatch):
    if shutil.which("ccx") is None:
        pytest.skip("ccx not installed")
    import make_upd
    from upd import read_eigenfrequencies
    monkeypatch.setenv("FRIROM_CACHE", str(tmp_path / "cache"))
    make_upd.make(tmp_path, retainer=0.0)     # the damper held by its contacts alone
    shutil.copy(ROOT / "cases" / "upd" / "upd.toml", tmp_path / "upd.toml")
    deck = load_deck(tmp_path / "upd.toml")
    # the damper load given once: 200 N over 2 x 45 pairs of parallel faces
    for c in deck.contacts:
        assert c.params[:, 3] == pytest.approx(200.0 / 90, rel=1e-12)
    chk = linear_check(deck, n_grid=10, n_show=4)
    free_ref = read_eigenfrequencies(tmp_path / "free.dat")
    stuck_ref = read_eigenfrequencies(tmp_path / "stuck.dat")
    free = chk.free[chk.free > 1.0] / 2 / np.pi
    stuck = chk.stuck / 2 / np.pi
    np.testing.assert_allclose(free[:4], free_ref[:4], rtol=1e-4)
    np.testing.assert_allclose(stuck[:4], stuck_ref[:4], rtol=1e-4)
    text = "\n".join(chk.notes)
    assert "contacts free: 6 natural frequencies are 0 Hz: a body held only by its " \
           "contacts" in text
    assert ("free motions: node sets DAMPER, DAMPER_L, DAMPER_R: translations in every "
            "direction, 3 rotations or deformations; PLAT_0, PLAT_1, TIP_0, TIP_1 still"
            in text), text
    assert "WARNING" not in text            # stuck, the contacts hold the damper
    # the contact patch as meshed (frirom.held's default): cases/models/upd.py's lattice,
    # h = 2 mm: patches x0..x1 = 4 cells along the tangent x, z 1..9 = 8 cells along z
    from upd import DAMPER, PATCHES
    h = 0.002
    for c, side in zip(deck.model().contacts, "LR"):
        x0, x1, _ = PATCHES[side]
        ext = [(x1 - x0) * h, (DAMPER[0][5] - DAMPER[0][4]) * h]
        np.testing.assert_allclose(c.patch, ext, rtol=1e-9)
