"""Bifurcations located on the curve (issue 30 item 3, frirom._fold).

Reference: the Duffing oscillator x'' + c x' + x + k3 x^3 = F cos(w t) at H = 1, where
the harmonic balance is exactly the single-harmonic closed form
    G(u, W) = u [(1 + 3/4 k3 u - W)^2 + c^2 W] - F^2 = 0,  u = A^2, W = w^2,
and a fold in w is where dG/du = 0 as well. The two equations are solved by scipy from
the located fold; the solver's fold must match them to its tolerance (the frequency is an
extremum of w(s) along the curve, so its error is second order: 1e-9 relative; the
amplitude 1e-6 relative), much closer than the flagged points themselves (a step away).
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import csv

import numpy as np
import pytest
from scipy.optimize import fsolve

from frirom.results import FRF
from frirom.solver import SolverOptions, frf

from _models import duffing

C, K3, F = 0.02, 0.5, 0.1


def closed_form_fold(w0, a0, f_amp=F):
    """(w, A) of the H = 1 fold nearest (w0, a0) at forcing f_amp."""
    def eqs(v):
        u, W = v
        r = 1.0 + 0.75 * K3 * u - W
        return [u * (r * r + C * C * W) - f_amp * f_amp,
                r * r + C * C * W + 1.5 * K3 * u * r]
    u, W = fsolve(eqs, [a0 * a0, w0 * w0], xtol=1e-12)
    assert np.allclose(eqs([u, W]), 0.0, atol=1e-13)
    return np.sqrt(W), np.sqrt(u)


@pytest.fixture(scope="module")
def curve():
    model, ex = duffing()
    opts = SolverOptions(harmonics=1, samples=16, formulation="condensed", ds_max=0.3,
                         stability=True)
    return frf(model, ex, 1.0, 2.0, opts, outputs=[0])


def test_duffing_folds_located_on_the_closed_form(curve):
    folds = [b for b in curve.bifurcations if b.kind == "fold"]
    assert len(folds) == 2 and all(b.located for b in folds)
    for b in folds:
        w, a = closed_form_fold(b.omega, b.amp_max[0])
        assert abs(b.omega - w) < 1e-9 * w, (b.omega, w)
        assert abs(b.amp_max[0] - a) < 1e-6 * a, (b.amp_max[0], a)
        assert abs(b.t_lam) < 1e-8
        # the flagged points beside it are a step away
        near = curve.omega[b.index - 1:b.index + 1]
        assert np.abs(near - w).max() > 1e3 * abs(b.omega - w)
    # the upper fold (jump down) at the larger frequency and amplitude
    hi, lo = sorted(folds, key=lambda b: -b.omega)
    assert hi.amp_max[0] > lo.amp_max[0]
    # Duffing's stability changes only at its folds
    assert not [b for b in curve.bifurcations if b.kind == "ns_or_pd"]


def test_bifurcations_kept_in_files(curve, tmp_path):
    curve.save_h5(tmp_path / "frf.h5")
    back = FRF.load(tmp_path / "frf.h5")
    assert [b.kind for b in back.bifurcations] == [b.kind for b in curve.bifurcations]
    assert np.allclose([b.omega for b in back.bifurcations],
                       [b.omega for b in curve.bifurcations], rtol=0, atol=0)
    curve.save_bifurcations_csv(tmp_path / "bif.csv")
    rows = list(csv.reader(open(tmp_path / "bif.csv")))
    assert rows[0][:3] == ["kind", "f_hz", "omega_rad_s"]
    assert len(rows) == 1 + len(curve.bifurcations)
    assert float(rows[1][2]) == curve.bifurcations[0].omega


def closed_form_fold_count(f_amp, w_lo, w_hi):
    """Folds in w of the H = 1 closed form at forcing f_amp with w in (w_lo, w_hi):
    dG/du = 0 is a quadratic in r = 1 + 3/4 k3 u - W at each u,
    r^2 + (3/2 k3 u - c^2) r + c^2 (1 + 3/4 k3 u) = 0; on each root, the sign changes of
    G(u, W(u)) over a fine grid of u are the folds."""
    u = np.geomspace(1e-8, 1e3, 200001)
    b = 1.0 + 0.75 * K3 * u
    p = 1.5 * K3 * u - C * C
    disc = p * p / 4.0 - C * C * b
    n = 0
    for sgn in (1.0, -1.0):
        r = -p / 2.0 + sgn * np.sqrt(np.where(disc >= 0, disc, np.nan))
        W = b - r
        g = u * (r * r + C * C * W) - f_amp ** 2
        ok = np.isfinite(g) & (W > w_lo ** 2) & (W < w_hi ** 2)
        change = (np.sign(g[1:]) != np.sign(g[:-1])) & ok[1:] & ok[:-1]
        n += int(change.sum())
    return n


def test_duffing_fold_locus_against_the_closed_form():
    from frirom.bifurcations import fold_locus
    model, ex = duffing()
    opts = SolverOptions(harmonics=1, samples=16, formulation="condensed", ds_max=0.3,
                         stability=False)
    levels = [0.05, 0.5, 1.5]
    loc = fold_locus(model, ex, 0.5, 3.0, levels, opts, outputs=[0])
    assert loc.complete.all()
    for i, lv in enumerate(levels):
        assert loc.n_folds[i] == closed_form_fold_count(F * lv, 0.5, 3.0), lv
        for j in range(loc.n_folds[i]):
            assert loc.located[i, j]
            w_ref, a_ref = closed_form_fold(loc.omega[i, j], loc.amp_max[i, j, 0],
                                            F * lv)
            assert abs(loc.omega[i, j] - w_ref) < 1e-9 * w_ref
            assert abs(loc.amp_max[i, j, 0] - a_ref) < 1e-6 * a_ref
    # below the cusp no fold; above it the jump-down fold moves up in frequency with the
    # level along the backbone, faster than the jump-up fold: the hysteresis widens
    assert loc.n_folds.tolist() == [0, 2, 2]
    assert loc.omega[2, 0] - loc.omega[2, 1] > loc.omega[1, 0] - loc.omega[1, 1] > 0


DUFFING_DECK = """
title = "Duffing"
[model]
format = "mtx"
mass = "M.mtx"
stiffness = "K.mtx"
[damping]
type = "rayleigh"
alpha = 0.02
beta = 0.0
[[excitation.load]]
dof = 0
harmonic = 1
amplitude = 0.1
[[contacts]]
name = "duffing"
law = "cubic"
elements = [ { a = [0], b = "ground" } ]
directions = [ [1.0] ]
k1 = 0.0
k3 = 0.5
[solver]
harmonics = 1
samples = 16
formulation = "condensed"
stability = true
[frequency]
start = 1.0
end = 2.0
unit = "rad/s"
[continuation]
max_step = 0.3
[outputs]
dofs = [0]
plot = false
[fold_locus]
levels = [0.5, 1.0]
"""


@pytest.mark.slow
def test_deck_lists_bifurcations_and_fold_locus(tmp_path, capsys):
    """The CLI: folds printed and kept in frf.h5, [fold_locus] written (9 s loaded)."""
    from frirom.cli import main
    one = "%%MatrixMarket matrix coordinate real symmetric\n1 1 1\n1 1 1.0\n"
    for name in ("M.mtx", "K.mtx"):
        (tmp_path / name).write_text(one)
    (tmp_path / "duffing.toml").write_text(DUFFING_DECK)
    assert main(["run", str(tmp_path / "duffing.toml"), "--out", str(tmp_path / "out"),
                 "--quiet"]) == 0
    text = capsys.readouterr().out
    assert text.count("fold at") == 2 and "located on the curve" in text
    back = FRF.load(tmp_path / "out" / "frf.h5")
    folds = [b for b in back.bifurcations if b.kind == "fold"]
    assert len(folds) == 2
    for b in folds:
        w, _ = closed_form_fold(b.omega, b.amp_max[0])
        assert abs(b.omega - w) < 1e-9 * w
    rows = list(csv.DictReader(open(tmp_path / "out" / "fold_locus.csv")))
    assert [r["level"] for r in rows].count("1.0") == 2
    for r in rows:
        w, _ = closed_form_fold(float(r["omega_rad_s"]), float(list(r.values())[-1]),
                                F * float(r["level"]))
        assert abs(float(r["omega_rad_s"]) - w) < 1e-9 * w


def test_stability_auto_on_where_affordable_and_its_cost_reported():
    """stability = 'auto': on for a small model (its Hill time reported beside the
    run's), off with the reason above HILL_AUTO_MAX Hill unknowns or with contact
    coordinates."""
    import scipy.sparse as sp

    from frirom._pack import HILL_AUTO_MAX
    from frirom.model import ContactGroup, Damping, Excitation, Model
    model, ex = duffing()
    o = SolverOptions(harmonics=1, samples=16, ds_max=0.3, stability="auto")
    r = frf(model, ex, 1.0, 2.0, o, outputs=[0])
    assert r.stability_computed and not r.stable.all()
    assert 0.0 < r.timings["hill"] <= r.timings["fortran_total"]
    assert "stability (Hill)" in r.solver_info
    # a chain of n unit oscillators, the Duffing spring on the first: above the bound
    n = HILL_AUTO_MAX // (2 * 3) + 1
    G = sp.csr_matrix(([1.0], ([0], [0])), shape=(1, n))
    big = Model(sp.identity(n, format="csr"), sp.diags(np.linspace(1.0, 50.0, n)).tocsr(),
                Damping.rayleigh(0.0, 0.02), [ContactGroup("cubic", G, [[0.0, 0.5]])])
    F = np.zeros((n, 2), complex)
    F[0, 1] = 0.1
    rb = frf(big, Excitation(F), 1.0, 1.05, o, outputs=[0])
    assert not rb.stability_computed
    assert "stability: off ('auto':" in rb.solver_info and "Hill unknowns" in rb.solver_info
    with pytest.raises(Exception, match="stability"):
        SolverOptions(stability="maybe").check()
