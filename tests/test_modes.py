"""Linear pre-check (frirom.modes, `frirom modes`): free and stuck natural frequencies and
linear FRFs, checked against matrices assembled here, against the nonlinear solver in its
two linear limits, and (cyclic) against CalculiX's own cyclic eigenvalues."""

import os
import shutil
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.linalg as sla

from frirom.cli import main
from frirom.deck import load_deck
from frirom.modes import linear_check, linear_response
from frirom.solver import frf

ROOT = Path(__file__).resolve().parents[1]
JOINT = ROOT / "cases" / "joint"


def joint_deck(tmp_path, changes=()):
    text = (JOINT / "joint.toml").read_text()
    for old, new in [("harmonics = 5", "harmonics = 1"), ("samples = 64", "samples = 32"),
                     *changes]:
        assert old in text
        text = text.replace(old, new)
    for f in ("M.mtx", "K.mtx", "dofs.txt"):
        shutil.copy(JOINT / f, tmp_path / f)
    p = tmp_path / "joint.toml"
    p.write_text(text)
    return load_deck(p)


def test_frequencies_against_matrices_built_here(tmp_path):
    """Free: eig(K, M); stuck: K + kt d d^T with d the 30 deg face direction on the
    platform's (x, y) DoFs, assembled here from the labels (not through G). 1e-10: the
    same dense eigen-solve of the same matrices up to round-off."""
    deck = joint_deck(tmp_path)
    check = linear_check(deck)
    K, M = deck.K.toarray(), deck.M.toarray()
    d = np.zeros(deck.n_dof)
    d[deck.dof_labels.index("platform:x")] = np.cos(np.pi / 6)
    d[deck.dof_labels.index("platform:y")] = np.sin(np.pi / 6)
    free = np.sqrt(sla.eigh(K, M, eigvals_only=True))
    stuck = np.sqrt(sla.eigh(K + 1.0e7 * np.outer(d, d), M, eigvals_only=True))
    # the first mode is the bending one near the range 400-520 Hz
    assert np.allclose(check.free, free[:check.free.size], rtol=1e-10)
    assert np.allclose(check.stuck, stuck[:check.stuck.size], rtol=1e-10)
    assert free[0] < 2 * np.pi * 460 < stuck[0]       # the friction resonance between
    s0, s1 = check.suggested
    assert s0 < free[0] and stuck[0] < s1
    # linear FRF at one frequency by a dense complex solve
    w = 2 * np.pi * 455.0
    C = deck.damping_object().assemble(deck.M, deck.K).toarray()
    x = np.linalg.solve(K + 1.0e7 * np.outer(d, d) - w * w * M + 1j * w * C, deck.F[:, 1])
    got = linear_response(deck, [w], stuck=True)[0]
    assert np.allclose(got, np.abs(x[deck.outputs]), rtol=1e-10)


@pytest.mark.parametrize("limit", ["stuck", "free"])
def test_nonlinear_solver_in_its_linear_limits(tmp_path, limit):
    """Jenkins stuck all cycle is the linear system with kt added (a 1e-3 N shaker:
    the spring force stays 1e-4 of mu fn0); with fn0 = 1e-7 N the friction force is 1e-7
    of the load, so the response is the free one. Nonlinear FRF (H = 1) against
    linear_response at its own points: 1e-6 (Newton's tolerance; measured 1e-9 stuck,
    1e-7 free)."""
    changes = ([("amplitude = 2.0", "amplitude = 1.0e-3")] if limit == "stuck" else
               [("fn0 = 100.0", "fn0 = 1.0e-7")])
    changes += [("start = 400.0", "start = 430.0"), ("end = 520.0", "end = 490.0")]
    deck = joint_deck(tmp_path, changes)
    res = frf(deck.model(), deck.excitation(), deck.omega_start, deck.omega_end,
              deck.options(), outputs=deck.outputs)
    assert res.complete and len(res) > 10
    lin = linear_response(deck, res.omega, stuck=limit == "stuck")
    err = np.abs(res.amp_max - lin).max() / np.abs(lin).max()
    assert err < 1e-6, err


def test_cli_modes_and_run_print_the_precheck(tmp_path, capsys):
    deck = joint_deck(tmp_path)
    assert main(["modes", str(deck.path), "--out", str(tmp_path / "m")]) == 0
    text = capsys.readouterr().out
    assert "contacts free: 444.87" in text and "contacts stuck: 469.26" in text
    assert "suggested range" in text and (tmp_path / "m" / "linear.png").is_file()


def test_cyclic_stuck_frequency_is_ccx_clamped(tmp_path_factory):
    """Cyclic sector (tests/test_cyclic_deck.py's: inner edge of the flange clamped, its
    outer edge on ground contacts of stiffness 1e13): the stuck frequency of nodal
    diameter 2 (harmonic index 10 = -2 mod 12) is ccx's clamped ND-2 frequency from its
    own cyclic eigen-solve (5e-6: the penalty and CB 30, as test_cyclic_deck measures)."""
    if shutil.which("ccx") is None:
        pytest.skip("ccx (calculix-ccx) not installed")
    import bladed_sector
    from _models import N_SEC, write_cyclic_deck
    out = tmp_path_factory.mktemp("modes_cyclic")
    for sub, clamp in (("inner", "inner"), ("clamped", "flange")):
        cyc, sec = bladed_sector.write_sector_decks(out / sub, N_SEC, n_modes=4,
                                                    sector_clamp=clamp)
        if sub == "inner":
            bladed_sector.run_ccx(sec, expect=(".sti", ".mas", ".dof"))
        else:
            bladed_sector.run_ccx(cyc, expect=(".dat",))
    ref = bladed_sector.read_cyclic_eigenvalues(out / "clamped" / "cyclic.dat")
    f_ccx = np.sqrt(ref[2][0])
    deck = load_deck(write_cyclic_deck(out))
    check = linear_check(deck)
    free, stuck = check.per_index[10]
    assert stuck is not None and np.min(np.abs(stuck / f_ccx - 1)) < 5e-6
    assert free.min() < f_ccx * (1 - 1e-3)            # the free sector is softer
    assert check.amp_free.shape == check.amp_stuck.shape == (check.omega.size, 1)
