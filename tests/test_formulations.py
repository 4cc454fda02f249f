"""The condensed and the banded formulation trace the same curve (issue 9, item 5).

Reference model: the 8-node Euler-Bernoulli cantilever of NLvib's friction-beam example
(FE_EulerBernoulliBeam, clamped-free, L 0.7 m, 0.03 x 0.03 m, E 185 GPa, rho 7830 kg/m^3;
a Jenkins element kt 1.3e6 N/m, mu N = 1 N at node 4 (the clamped node is node 1), 0.1 N
at the tip; Rayleigh damping giving 0.8 % and 0.2 % to the first two modes with the
contact stuck). Its first stuck mode is at 390.3 rad/s; from 430 down to 330 rad/s the
contact is stuck all cycle away from the resonance and slips over a third of it near it.
At 398.78 rad/s two samples of the AFT switch from slip to stick and the solution curve
turns there by 93 degrees in the banded formulation's arc-length metric (80 in the
condensed one's): the banded run used to stop there at N = 256, 512 and 1024.

"The same curve" is checked point by point: a point of one formulation's run, solved
again at its frequency and with its contact history by the other formulation, must give
the same harmonics at every DoF. Both solve the same equations (the condensed one with the
linear DoFs eliminated exactly) to |R|/rref <= 1e-8, and the harmonics agree to 3.5e-9 at
worst over every point of both runs (N = 256 and 1024); the tolerance, 1e-7 relative,
leaves room for the response's sensitivity near a resonance, and is far below the
differences a stopped or strayed run makes (the whole curve, or 1e-3 and more).
"""

from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from frirom._pack import pack
from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import SolverOptions, frf, solve_point

#: relative agreement of the harmonics of one point solved by both formulations
SAME_POINT = 1e-7


def _beam_matrices(n_nodes=8, length=0.7, height=0.03, width=0.03, E=185e9, rho=7830.0):
    """K, M of a clamped-free Euler-Bernoulli beam with cubic Hermite elements (the exact
    integrals of NLvib's element matrices); DoFs per free node: deflection, slope."""
    EI = E * width * height**3 / 12
    rA = rho * width * height
    le = length / (n_nodes - 1)
    k = EI / le**3 * np.array([[12, 6 * le, -12, 6 * le],
                               [6 * le, 4 * le**2, -6 * le, 2 * le**2],
                               [-12, -6 * le, 12, -6 * le],
                               [6 * le, 2 * le**2, -6 * le, 4 * le**2]])
    m = rA * le / 420 * np.array([[156, 22 * le, 54, -13 * le],
                                  [22 * le, 4 * le**2, 13 * le, -3 * le**2],
                                  [54, 13 * le, 156, -22 * le],
                                  [-13 * le, -3 * le**2, -22 * le, 4 * le**2]])
    n = 2 * n_nodes
    K, M = np.zeros((n, n)), np.zeros((n, n))
    for e in range(n_nodes - 1):
        s = slice(2 * e, 2 * e + 4)
        K[s, s] += k
        M[s, s] += m
    return K[2:, 2:], M[2:, 2:]


def nlvib_friction_beam(kt=1.3e6, mu_n=1.0, tip_force=0.1):
    """(model, excitation, index of the contact DoF, index of the tip deflection)."""
    K, M = _beam_matrices()
    n = K.shape[0]
    dof = 2 * (4 - 2)                       # node 4 deflection (node 1 is clamped)
    tip = n - 2
    Kstuck = K.copy()
    Kstuck[dof, dof] += kt
    w = np.sqrt(scipy.linalg.eigh(Kstuck, M, eigvals_only=True)[:2])
    z1, z2 = 8e-3, 2e-3
    beta = 2 * (z2 * w[1] - z1 * w[0]) / (w[1]**2 - w[0]**2)
    alpha = 2 * w[0] * z1 - beta * w[0]**2
    G = np.zeros((1, n))
    G[0, dof] = 1.0
    model = Model(M, K, Damping.matrix(alpha * M + beta * Kstuck),
                  [ContactGroup("jenkins", G, np.array([[kt, mu_n, 1.0]]))])
    F = np.zeros(n, complex)
    F[tip] = tip_force
    return model, Excitation(F), dof, tip


def _unknowns(X, model, exc, opts):
    """The unknowns of `opts.formulation` for the harmonics X (n_dof, 2H+1) of every DoF:
    condensed, the contact DoFs' harmonic by harmonic; banded, DoF by DoF in RCM order."""
    if opts.formulation == "condensed":
        return X[model.nonlinear_dofs()].ravel(order="F")
    return X[np.asarray(pack(model, exc, opts, None).perm) - 1].ravel()


def _resolved(model, exc, points, options, formulation):
    """Each point solved again by `formulation` at its frequency, from its harmonics and
    its contact history (near a fold another solution exists at the same frequency)."""
    opts = SolverOptions(**{**options.__dict__, "formulation": formulation})
    return [solve_point(model, exc, p.omega, opts, start={
        "unknowns": _unknowns(p.X, model, exc, opts), "slider": p.slider}) for p in points]


def _assert_same_points(points, again, what):
    for p, q in zip(points, again):
        err = np.linalg.norm(q.X - p.X) / np.linalg.norm(p.X)
        assert err < SAME_POINT, f"{what} at {p.omega:.4f} rad/s: rel. difference {err:.2e}"


def _both_runs(model, exc, lam0, lam1, options):
    """{formulation: (options, points)} of a complete run in each formulation."""
    runs = {}
    for form in ("condensed", "banded"):
        opts = SolverOptions(**{**options.__dict__, "formulation": form})
        pts = []
        r = frf(model, exc, lam0, lam1, opts, sink=pts.append)
        assert r.complete, f"{form}: {r.message}"
        assert r.omega[-1] == lam1
        runs[form] = (opts, pts)
    return runs


def _cross_check(model, exc, runs, every, what):
    """Every `every`-th point of each run (and its peak) re-solved by the other."""
    for form, other in (("banded", "condensed"), ("condensed", "banded")):
        opts, pts = runs[form]
        sel = _every(pts, every)
        _assert_same_points(sel, _resolved(model, exc, sel, opts, other),
                            f"{what}: {form} point re-solved by {other}")


def _every(points, k):
    """Every k-th point, the last one and the one of largest first output."""
    ip = int(np.argmax([p.amp_max.max() for p in points]))
    return [points[i] for i in sorted(set(range(0, len(points), k)) | {ip, len(points) - 1})]


@pytest.mark.parametrize("samples", [256, pytest.param(1024, marks=pytest.mark.slow)])
def test_nlvib_beam_both_formulations_trace_the_same_curve(samples):
    """Both runs reach 330 rad/s through the corner at 398.78 rad/s; every 6th point of
    each (and its peak) is a solution of the other formulation to SAME_POINT."""
    model, exc, dof, tip = nlvib_friction_beam()
    runs = _both_runs(model, exc, 430.0, 330.0, SolverOptions(harmonics=7, samples=samples))
    for _, pts in runs.values():
        # stuck all cycle at the start, slipping over a third of it near the resonance
        slip = np.array([p.state_fractions[0, 1] for p in pts])
        assert slip[0] == 0 and slip.max() > 0.3
    _cross_check(model, exc, runs, 6, "beam")
    # and their peaks (the largest sampled tip amplitude): same height to 1e-3 (two
    # different sets of points on a flat top), within 1.5 rad/s of each other
    peaks = {f: max(pts, key=lambda p: p.amp_max[tip]) for f, (_, pts) in runs.items()}
    a, b = peaks["condensed"], peaks["banded"]
    assert abs(a.amp_max[tip] / b.amp_max[tip] - 1) < 1e-3
    assert abs(a.omega - b.omega) < 1.5


def test_banded_turns_the_corner_at_398_78():
    """The corner itself, in small steps: the banded run used to stall there (the
    corrector's hyperplane across the old tangent never meets the branch beyond)."""
    model, exc, dof, tip = nlvib_friction_beam()
    runs = _both_runs(model, exc, 398.9, 398.6,
                      SolverOptions(harmonics=7, samples=512, ds_max=0.02))
    for _, pts in runs.values():
        # the stick fraction steps up by 2 samples (one per half cycle) on the way
        stick = np.array([p.state_fractions[0, 0] for p in pts])
        assert stick.min() < 0.809 and stick.max() > 0.812
    # every point on either side of the corner solves the other formulation's equations
    _cross_check(model, exc, runs, 1, "corner")


def _curve_gap(a, b):
    """Largest distance from a point of curve a to the polyline b, in the box of both
    scaled to 1 x 1: (omega, amplitude) pairs (m, 2) and (k, 2)."""
    lo, hi = np.minimum(a.min(0), b.min(0)), np.maximum(a.max(0), b.max(0))
    a, b = (a - lo) / (hi - lo), (b - lo) / (hi - lo)
    p, d = b[:-1], np.diff(b, axis=0)
    s = np.clip(((a[:, None] - p[None]) * d[None]).sum(2) / np.maximum((d**2).sum(1), 1e-300),
                0.0, 1.0)
    return np.sqrt(((a[:, None] - p[None] - s[..., None] * d[None])**2).sum(2)).min(1).max()


@pytest.mark.parametrize("deck", [pytest.param("joint/joint.toml", marks=pytest.mark.slow),
                                  "bladed_disk/bladed_disk.toml",
                                  pytest.param("joint/joint_liftoff.toml",
                                               marks=pytest.mark.slow)])
def test_bundled_deck_same_curve_in_both_formulations(deck):
    """A bundled deck run in both formulations: both complete (joint_liftoff's banded run
    used to stop at 447.6 Hz), every 10th point of each is a solution of the other to
    SAME_POINT, and the two (omega, amplitude) curves of the largest output
    are within 5e-3 of the plot box of each other: no loop left out (measured, chords
    of differently placed steps: 1e-3 on joint and bladed_disk, 2.1e-3 on joint_liftoff's
    saw-tooth of corners near 447.5 Hz, which the condensed run resolves in smaller
    steps; leaving out its loop at 447.3-449.6 Hz makes 1.1e-2)."""
    from frirom.deck import load_deck

    d = load_deck(Path(__file__).resolve().parents[1] / "cases" / deck)
    model, exc = d.model(), d.excitation()
    runs = _both_runs(model, exc, d.omega_start, d.omega_end, d.options())
    _cross_check(model, exc, runs, 10, deck)
    out = int(np.argmax(runs["condensed"][1][0].amp_max))
    curves = [np.array([[p.omega, p.amp_max[out]] for p in runs[f][1]]) for f in runs]
    gap = max(_curve_gap(curves[0], curves[1]), _curve_gap(curves[1], curves[0]))
    print(f"{deck}: curves {gap:.1e} apart")
    assert gap < 5e-3


def _stop_message(**options):
    model, exc, _, _ = nlvib_friction_beam()
    opts = SolverOptions(harmonics=7, formulation="banded", **options)
    with pytest.warns(RuntimeWarning, match="continuation stopped early"):
        r = frf(model, exc, 430.0, 330.0, opts)
    assert not r.complete
    return r.message


def test_stop_message_states_the_samples_in_use_and_advises_only_changes():
    """A run made to stop (ds_min = ds_max = 0.1: no room to shrink the step): the message
    gives the N in use, advises a smaller ds_min, and no sample count at or below it."""
    msg = _stop_message(samples=512, ds_min=0.1, ds_max=0.1)
    assert "N = 512 AFT samples" in msg
    assert "ds_min = 0.001 (now 0.1)" in msg
    assert "recommended" not in msg and "samples = 256" not in msg
    assert "tol_stall" not in msg          # the last corrector was far from converged


def test_stop_message_advises_what_the_failure_calls_for():
    """max_iter = 3 with large steps: the last corrector met tol_residual but not the update
    test, so max_iter (doubled from the value in use) and tol_stall are advised; with
    N = 64 below the default for H = 7, the default is advised too."""
    default_n = SolverOptions(harmonics=7).n_samples
    msg = _stop_message(samples=64, max_iter=3, ds_min=0.05)
    assert "N = 64 AFT samples" in msg
    assert "max_iter = 6 (now 3)" in msg
    assert f"samples = {default_n} (the default for H = 7; now 64)" in msg


@pytest.mark.slow
def test_nlvib_beam_banded_against_time_integration():
    """The banded run's peak and its point nearest 400 rad/s (micro-slip, past the corner)
    against frirom.timeint (explicit central differences, its own Jenkins return map),
    started on the HB state and slider and run 20 periods (8 518 steps each: the stuck
    beam's highest mode is at 2.5e5 rad/s). Measured: harmonics 0.07 % and 0.16 % apart,
    tip amplitude 5e-4 and 6e-4, slip fraction 0.305 against 0.300 and 0.297, the change
    over the last period 6e-5 and 1.4e-4. Tolerances: 3e-3 on the harmonics and 2e-3 on
    the amplitude (H = 7 and N = 256 truncation, ~1e-3), 5e-4 on the drift, 0.02 on the
    slip fraction (a sample is 0.004)."""
    from frirom.timeint import TimeContact, integrate, state_from_harmonics

    model, exc, dof, tip = nlvib_friction_beam()
    pts = []
    r = frf(model, exc, 430.0, 330.0, SolverOptions(harmonics=7, samples=256,
                                                    formulation="banded"), sink=pts.append)
    assert r.complete, r.message
    sel = [max(pts, key=lambda p: p.amp_max[tip]), min(pts, key=lambda p: abs(p.omega - 400))]
    om = np.array([p.omega for p in sel])
    X = np.array([p.X for p in sel])
    x0, v0 = state_from_harmonics(X, om)
    c = model.contacts[0]
    ti = integrate(model.M.toarray(), model.C.toarray(), model.K.toarray(),
                   [TimeContact("jenkins", c.G.toarray(), c.params)], exc.F, om, H=7,
                   periods=20, min_periods=20, x0=x0, v0=v0, tol=0.0,
                   w0=[np.array([p.slider.reshape(1, 1) for p in sel])])
    for i, p in enumerate(sel):
        assert ti.drift[i] < 5e-4
        assert np.linalg.norm(ti.harmonics[i] - p.X) / np.linalg.norm(p.X) < 3e-3
        assert abs(ti.amp_max[i, tip] / p.amp_max[tip] - 1) < 2e-3
        assert abs(ti.state_fractions[i, 0, 1] - p.state_fractions[0, 1]) < 0.02
