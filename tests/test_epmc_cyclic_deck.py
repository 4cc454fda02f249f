"""A nonlinear-mode deck on a cyclic sector (``[analysis] kind = "nonlinear_mode"`` with
``[reduction.cyclic]`` and ``nodal_diameter``): the bundled case cases/bladed_sector (a
12-sector bladed disk whose flange rubs on its mating flange, CalculiX matrices) run as
the backbone of nodal diameter 3 by ``frirom run``; its linear limit against a direct
eigen-solve of the sector projected on nodal diameter 3 with the contacts stuck; the
case's deck made a synthesis from the backbone (``kind = "from_backbone"``) against its
forced-response deck."""

import os
import shutil
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

import make_bladed_sector  # cases/bladed_sector/make_bladed_sector.py
from frirom._errors import InputError
from frirom.backbone import load_h5
from frirom.contact import stuck_stiffness
from frirom.deck import load_deck

CASES = Path(__file__).resolve().parents[1] / "cases"


def _mode_deck(text, nd="3"):
    """The case's deck made a nonlinear-mode deck: no tip load, no [frequency]."""
    tip = text.index("[[excitation.load]]           # blade-tip force")
    text = text[:tip] + text[text.index("[solver]"):]
    freq = text.index("[frequency]")
    return (text[:freq] + '[analysis]\nkind = "nonlinear_mode"\n'
            + (f"nodal_diameter = {nd}\n" if nd is not None else "")
            + "amplitudes = [1.0e-4, 1.0]\n\n" + text[text.index("[continuation]"):])


def _is_number(t: str) -> bool:
    try:
        float(t)
    except ValueError:
        return False
    return True


@pytest.mark.slow
def test_bladed_sector_mode_deck(tmp_path, capsys):
    """`frirom run` of the mode deck: the backbone of nodal diameter 3 (harmonic 1 on
    k = 9), written and read back; its first point (a = 1e-4 sqrt(kg) m, flange stuck)
    at the stuck sector's eigenfrequency of k = 9 from a direct Hermitian eigen-solve of
    T^H (K + G^T Ks G) T, T^H M T, to 1e-8 (measured 3.6e-10: the modal damping of
    0.2 %, not proportional to the stuck stiffness, moves it by O(zeta^2) of the free
    modes' mixing); the flange slips at the end (damping ratio above its stuck value);
    `frirom show` balances the energy per cycle at the damping peak to 1e-8 (measured
    1.4e-10)."""
    if shutil.which("ccx") is None:
        pytest.skip("ccx (calculix-ccx) not installed")
    from frirom.cli import main
    make_bladed_sector.make(tmp_path, 12)
    p = tmp_path / "mode.toml"
    p.write_text(_mode_deck((CASES / "bladed_sector" / "bladed_sector.toml").read_text()))
    assert main(["run", str(p), "--out", str(tmp_path / "run")]) == 0
    printed = capsys.readouterr().out
    assert "nodal diameter 3" in printed
    bb, _ = load_h5(tmp_path / "run" / "backbone.h5")
    assert bb.nodal_diameter == 9 and bb.status == "done"
    d = load_deck(p)
    cs = d.cyclic["sector"]
    T = cs.projection(9)
    Kc = sp.csr_matrix(d.K)
    for c in d.contacts:
        G = sp.csr_matrix(c.G)
        Kc = Kc + G.T @ sp.diags(stuck_stiffness(c.law, c.params).ravel()) @ G
    Kk = (T.conj().T @ Kc @ T).toarray()
    Mk = (T.conj().T @ sp.csr_matrix(d.M) @ T).toarray()
    w = np.sqrt(sla.eigvalsh(0.5 * (Kk + Kk.conj().T), 0.5 * (Mk + Mk.conj().T)))
    err = np.abs(w / bb.omega[0] - 1).min()
    print(f"\nbladed sector ND 3: linear limit {bb.frequency[0]:.4f} Hz, direct stuck "
          f"eigen-solve off by {err:.1e}; last point {bb.frequency[-1]:.4f} Hz, damping "
          f"ratio {bb.damping_ratio[-1]:.4g} (first {bb.damping_ratio[0]:.4g})")
    assert err < 1e-8
    assert bb.damping_ratio.max() > 1.1 * bb.damping_ratio[0]
    assert bb.states[-1, 1].max() > 0
    # frirom show at the damping peak: the mode's energy per cycle = the flange's
    # dissipation + the viscous work (from each harmonic's modal coordinates)
    assert main(["show", str(tmp_path / "run")]) == 0
    printed = capsys.readouterr().out
    line = next(s for s in printed.splitlines() if "energy per cycle: mode" in s)
    nums = [float(t) for t in line.replace("(", " ").split() if _is_number(t)]
    assert abs(nums[-1]) < 1e-8 * nums[0], line
    # nodal_diameter below the sectors, and only in a nonlinear-mode deck
    text = _mode_deck((CASES / "bladed_sector" / "bladed_sector.toml").read_text(), "12")
    p = tmp_path / "bad.toml"
    p.write_text(text)
    with pytest.raises(InputError, match="analysis.nodal_diameter.*0..11"):
        load_deck(p)
    p.write_text(text.replace('kind = "nonlinear_mode"', 'kind = "from_backbone"'))
    with pytest.raises(InputError, match="analysis.nodal_diameter"):
        load_deck(p)


@pytest.mark.slow
@pytest.mark.parametrize("level, tol_a", [(20.0, 3e-3), (100.0, 5e-3)])
def test_bladed_sector_from_backbone_deck(tmp_path, capsys, level, tol_a):
    """The case's deck made ``kind = "from_backbone"`` (the backbone of the engine order's
    nodal diameter, harmonic 1 on k = 10, its forced response synthesised under the same
    tip load) against the case's own forced-response deck at the same level: tip peak
    amplitude within tol_a (measured -0.08 % at 20 N, the flange slipping; -0.10 % at
    100 N, also lifting off; -0.34 % at 50 N), frequency 1e-5 (measured 1e-7, 3e-6)."""
    if shutil.which("ccx") is None:
        pytest.skip("ccx (calculix-ccx) not installed")
    from frirom.cli import main
    from frirom.results import FRF
    make_bladed_sector.make(tmp_path, 12)
    text = (CASES / "bladed_sector" / "bladed_sector.toml").read_text()
    text = text.replace("amplitude = 50.0", f"amplitude = {level}")
    (tmp_path / "frf.toml").write_text(text)
    (tmp_path / "syn.toml").write_text(text.replace(
        "[continuation]", '[analysis]\nkind = "from_backbone"\namplitudes = [1.0e-4, 3.0]\n\n'
        "[continuation]"))
    for name in ("frf", "syn"):
        assert main(["run", str(tmp_path / f"{name}.toml"), "--out",
                     str(tmp_path / name)]) == 0
    capsys.readouterr()
    ref, syn = (FRF.load(tmp_path / name / "frf.h5") for name in ("frf", "syn"))
    assert syn.meta["method"] == "snmt" and syn.complete
    ea = syn.peak(0).amplitude / ref.peak(0).amplitude - 1
    ew = syn.peak(0).omega / ref.peak(0).omega - 1
    print(f"\nbladed sector from_backbone {level} N: peak amplitude {ea:+.2e}, "
          f"frequency {ew:+.2e}")
    assert abs(ea) < tol_a and abs(ew) < 1e-5


def test_mode_deck_errors(tmp_path):
    """nodal_diameter only with [reduction.cyclic] (the cyclic deck's errors: in
    test_bladed_sector_mode_deck, which has the case's matrices)."""
    joint = (CASES / "joint" / "joint_mode.toml").read_text()
    p = tmp_path / "joint_nd.toml"
    p.write_text(joint.replace('kind = "nonlinear_mode"',
                               'kind = "nonlinear_mode"\nnodal_diameter = 1'))
    with pytest.raises(InputError, match="analysis.nodal_diameter"):
        load_deck(p)
