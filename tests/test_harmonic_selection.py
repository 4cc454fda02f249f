"""Harmonic selection (SolverOptions.harmonics_kept): the nonlinear DoFs solved on the kept
harmonics only. References: the full solution of the same model (a symmetric nonlinearity
under a harmonic load has no even harmonics, so keeping the odd ones is exact), and the
selection's leak where it is not exact."""

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from _models import duffing
from frirom._errors import InputError, ParameterError
from frirom.deck import load_deck
from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.options import kept_harmonics
from frirom.results import FRF
from frirom.solver import SolverOptions, frf, solve_point

TIGHT = dict(tol_residual=1e-13, tol_update=1e-13)


def test_kept_harmonics_specs():
    assert kept_harmonics("odd", 5).tolist() == [False, True, False, True, False, True]
    assert kept_harmonics("even", 3).tolist() == [True, False, True, False]
    assert kept_harmonics([0, 1, 3], 3).tolist() == [True, True, False, True]
    for bad in ("all", [1, 1], [4], [-1], [], [1.5], None):
        with pytest.raises(ParameterError, match="harmonics_kept"):
            kept_harmonics(bad, 3, "harmonics_kept")


@pytest.mark.parametrize("omega", [0.8, 1.05, 1.6])
def test_duffing_odd_harmonics_equal_the_full_solution(omega):
    # x'' + 0.02 x' + x + 0.5 x^3 = 0.1 cos(w t), H = 7: the full solution's even
    # harmonics vanish, and the odd-only solution (8 unknowns instead of 15) equals it
    model, ex = duffing()
    full = solve_point(model, ex, omega, SolverOptions(harmonics=7, samples=64, **TIGHT))
    odd = solve_point(model, ex, omega, SolverOptions(harmonics=7, samples=64,
                                                      harmonics_kept="odd", **TIGHT))
    X = full.X[0]
    assert np.abs(X[[0, 3, 4, 7, 8, 11, 12]]).max() < 1e-12 * np.abs(X).max()
    assert np.abs(odd.X[0] - X).max() <= 1e-10 * np.abs(X).max()
    assert odd.unknowns.size == full.unknowns.size      # reported in the full layout
    assert odd.leak is not None and odd.leak < 1e-12


def test_duffing_frf_odd_peak_equals_full():
    model, ex = duffing()
    base = SolverOptions(harmonics=5, samples=64, **TIGHT)
    a = frf(model, ex, 0.6, 2.0, base)
    b = frf(model, ex, 0.6, 2.0, dataclasses.replace(base, harmonics_kept="odd"))
    assert a.complete and b.complete
    pa, pb = a.peaks[0], b.peaks[0]
    assert abs(pb.amplitude / pa.amplitude - 1) < 1e-9
    assert abs(pb.omega / pa.omega - 1) < 1e-9
    assert "harmonic selection: 6 of 11 unknowns" in b.solver_info


def _two_groups():
    # two Duffing DoFs coupled by a spring; group "a" on DoF 0, "b" on DoF 1
    K = np.array([[2.0, -1.0], [-1.0, 2.0]])
    ga = ContactGroup("cubic", sp.csr_matrix([[1.0, 0.0]]), [[0.0, 0.5]], name="a")
    gb = ContactGroup("cubic", sp.csr_matrix([[0.0, 1.0]]), [[0.0, 0.3]], name="b")
    model = Model(K, np.eye(2), Damping.rayleigh(0.0, 0.02), [ga, gb])
    return model, Excitation(np.array([[0.0, 0.1], [0.0, 0.0]], complex))


def test_per_group_selection_and_its_leak():
    model, ex = _two_groups()
    opts = SolverOptions(harmonics=5, samples=64, **TIGHT)
    full = solve_point(model, ex, 1.2, opts)
    # odd on group "a" only: exact (the system is odd as a whole)
    odd_a = solve_point(model, ex, 1.2, dataclasses.replace(opts,
                                                           harmonics_kept={"a": "odd"}))
    assert np.abs(odd_a.X - full.X).max() <= 1e-10 * np.abs(full.X).max()
    # harmonic 1 alone on group "b" (index 1): an approximation, its leak says how much
    with pytest.warns(RuntimeWarning, match="harmonic selection leaks"):
        h1 = solve_point(model, ex, 1.2, dataclasses.replace(opts, harmonics_kept={1: [1]}))
    err = np.abs(h1.X - full.X).max() / np.abs(full.X).max()
    assert 1e-9 < err < 1e-3            # harmonic 3 at 3 w, far from resonance: small
    assert h1.leak > 1e-3               # but its force is not


def test_refusals_name_the_option():
    model, ex = duffing()
    pre = Excitation(np.array([[0.05, 0.1]], complex))     # a static load on harmonic 0
    with pytest.raises(ParameterError, match="harmonic 0, outside the selection"):
        solve_point(model, pre, 1.0, SolverOptions(harmonics=3, harmonics_kept="odd"))
    with pytest.raises(ParameterError, match="no contact group named 'x'"):
        solve_point(model, ex, 1.0, SolverOptions(harmonics=3, harmonics_kept={"x": "odd"}))
    with pytest.raises(ParameterError, match="harmonic selection needs the 'condensed'"):
        solve_point(model, ex, 1.0, SolverOptions(harmonics=3, harmonics_kept="odd",
                                                  formulation="banded"))


# ---- from a deck ------------------------------------------------------------------------

JOINT = Path(__file__).resolve().parents[1] / "cases" / "joint"


def _joint_deck(tmp_path, solver_extra: str):
    text = (JOINT / "joint.toml").read_text()
    text = text.replace('stability = true', 'stability = false\nhistory = false')
    text = text.replace('formulation = "condensed"\n',
                        'formulation = "condensed"\n' + solver_extra + "\n")
    for f in ("K.mtx", "M.mtx", "dofs.txt"):
        (tmp_path / f).write_bytes((JOINT / f).read_bytes())
    path = tmp_path / "joint.toml"
    path.write_text(text)
    return path


def test_deck_odd_harmonics_on_the_friction_joint(tmp_path):
    # Jenkins without preload, no carried history: half-wave symmetric, so the odd
    # harmonics alone give the full curve's peak (fewer unknowns, measured in the info)
    full = load_deck(_joint_deck(tmp_path, ""))
    deck = load_deck(_joint_deck(tmp_path, 'harmonics_kept = "odd"'))
    opts = deck.options()
    assert opts.harmonics_kept == "odd" and not opts.stability
    a = frf(full.model(), full.excitation(), full.omega_start, full.omega_end,
            full.options(), outputs=full.solver_outputs)
    b = frf(deck.model(), deck.excitation(), deck.omega_start, deck.omega_end, opts,
            outputs=deck.solver_outputs)
    assert a.complete and b.complete
    assert "harmonic selection" in b.solver_info
    # the tip's peak, to the peak search's own tolerance (the two curves have other
    # points; the platform's flat-topped curves may peak elsewhere on their plateau)
    assert abs(b.peaks[0].amplitude / a.peaks[0].amplitude - 1) < 2e-5
    assert np.nanmax(b.leak) < 1e-9
    # at the full curve's peak frequency, the same point to round-off
    w = a.peaks[0].omega
    tight = dict(tol_residual=1e-13, tol_update=1e-13)
    pa = solve_point(full.model(), full.excitation(), w,
                     dataclasses.replace(full.options(), **tight), outputs=full.solver_outputs)
    pb = solve_point(deck.model(), deck.excitation(), w,
                     dataclasses.replace(opts, **tight), outputs=deck.solver_outputs)
    assert np.abs(pb.X - pa.X).max() <= 1e-10 * np.abs(pa.X).max()


@pytest.mark.parametrize("extra, key", [
    ('harmonics_kept = "all"', "solver.harmonics_kept"),
    ("harmonics_kept = [1, 9]", "solver.harmonics_kept"),
    ('harmonics_kept = {nope = "odd"}', "solver.harmonics_kept.nope"),
    ('harmonics_kept = {damper = [7]}', "solver.harmonics_kept.damper"),
    ('harmonics_kept = "odd"\nstability = true', "solver.stability")])
def test_deck_refuses_bad_selections_naming_the_key(tmp_path, extra, key):
    path = _joint_deck(tmp_path, extra)
    if "stability = true" in extra:
        path.write_text(path.read_text().replace("stability = false\n", "", 1))
    with pytest.raises(InputError, match=re.escape(f"{path}: {key}: expected")):
        load_deck(path)


# ---- automatic selection (frirom.auto_kept) ---------------------------------------------

def test_auto_selection_finds_the_odd_harmonics_of_duffing():
    from frirom.auto_kept import choose_kept
    model, ex = duffing()
    opts = SolverOptions(harmonics=5, samples=64, **TIGHT)
    ch = choose_kept(model, ex.F, 0.6, 2.0, opts, tolerance=1e-6)
    assert ch.selection is not None, ch.notes
    assert ch.selection[0].tolist() == [False, True, False, True, False, True]
    assert ch.unknowns == (6, 11) and ch.leak <= 1e-6
    assert "6 of 11 unknowns" in ch.summary() and "dropped h0 on 1" in ch.summary()
    a = frf(model, ex, 0.6, 2.0, opts)
    b = frf(model, ex, 0.6, 2.0, dataclasses.replace(opts, harmonics_kept=ch.selection))
    assert abs(b.peaks[0].amplitude / a.peaks[0].amplitude - 1) < 1e-9
    assert "harmonic selection: 6 of 11 unknowns" in b.solver_info


def test_auto_selection_keeps_what_saves_nothing(tmp_path):
    # the joint's one Jenkins element: 1 contact coordinate against 2 contact DoFs, so a
    # selection on the DoFs (12 of 22) would solve more than the run without it (11)
    from frirom.auto import resolve_deck
    deck = resolve_deck(load_deck(_joint_deck(tmp_path, 'harmonics_kept = "auto"')),
                        lambda s: None)
    kc = deck.auto.kept
    assert kc.selection is None and deck.kept_auto is None
    assert "nothing saved" in kc.summary()
    assert deck.options().harmonics_kept is None


@pytest.mark.slow
def test_a_selection_that_leaks_along_the_curve_is_restored(tmp_path, monkeypatch, capsys):
    # a selection that drops harmonic 3 on the joint's contact DoFs: the slipping
    # damper's force has a third harmonic, so the leak grows past the tolerance and
    # `frirom run` runs the curve again with every harmonic (its file: the full curve)
    import frirom.auto_kept as ak
    from frirom.cli import main

    def bad_choice(model, F, w0, w1, options, outputs=None, tolerance=1e-3, probes=None):
        sel = np.ones((model.n_dof, options.harmonics + 1), bool)
        sel[model.nonlinear_dofs(), 3] = False
        return ak.KeptChoice(selection=sel, tolerance=tolerance, unknowns=(18, 11),
                             dropped={3: 2}, leak=0.0, change=0.0, threshold=tolerance)

    monkeypatch.setattr(ak, "choose_kept", bad_choice)
    path = _joint_deck(tmp_path, 'harmonics_kept = "auto"\ntolerance_auto = 1e-6')
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert "run again with every harmonic" in err and "leak" in err
    got = FRF.load(tmp_path / "o" / "frf.h5")
    full = load_deck(_joint_deck(tmp_path, ""))
    ref = frf(full.model(), full.excitation(), full.omega_start, full.omega_end,
              full.options(), outputs=full.solver_outputs)
    assert got.leak is None or np.all(np.isnan(np.asarray(got.leak, float)))
    # the file holds the full curve, point for point
    assert np.array_equal(got.omega, ref.omega) and np.array_equal(got.X, ref.X)
    import h5py
    with h5py.File(tmp_path / "o" / "frf.h5", "r") as f:
        auto = f.attrs["auto"]
    assert "RESTORED every harmonic" in (auto.decode() if isinstance(auto, bytes) else auto)


def test_restore_rule():
    from frirom.auto_kept import KeptChoice, restore
    sel = np.ones((1, 4), bool)

    class R:
        leak = np.array([1e-9, 3e-3, 1e-8])
        omega = np.array([1.0, 2.0, 3.0]) * 2 * np.pi

    ch = KeptChoice(selection=sel, tolerance=1e-3)
    assert restore(ch, R) and "3.0e-03" in ch.restored and "2 Hz" in ch.restored
    assert not restore(KeptChoice(selection=None, tolerance=1e-3), R)
    R.leak = np.array([1e-9, 1e-4])
    assert not restore(KeptChoice(selection=sel, tolerance=1e-3), R)
