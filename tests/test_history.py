"""Contact history along a continuation: a friction contact stuck all cycle has no unique
periodic solution (its slider stays where it last slipped), so each point must start its
sliders where the previous converged point left them (solver: the accept hook of the
Newton/continuation layer, FRFPoint.slider).

Model: SDOF oscillator, m = k = 1, c = 0.1, Jenkins element kt = 2, mu fn0 = 0.2, static
load 0.15 (so the stuck state has a slider offset that history decides) and dynamic
0.05: the sweep 0.5 -> 2.5 rad/s goes stick -> slip (around the resonance) -> stick.

Tolerances and why:
* Residual: each converged point is a root of the HBM equations written here from the
  closed form (D(h w) X + F_c(X) - F_e, forces from frirom.contact.aft) both with the
  history it inherited and with the one it leaves, to 1e-7 relative (the solver's Newton
  tolerance is 1e-8; the carried slider closes the same cycle, so nothing may jump).
* Stuck points against time integration (frirom.timeint, its own slider return map)
  started from the previous point's state (displacement, velocity and slider at tau = 0):
  with every sample stuck the HBM is exact (a linear system with a fixed slider), so where
  the previous point was stuck too the difference is the time integration's own error,
  2e-4 of the peak-to-peak motion (test_verification's figure for it; reached 3e-5).
  The first stuck point after the slip range inherits the slider from a slipping point:
  there the real transient (the frequency changed abruptly by one step) slips a little
  before it sticks, while the HBM settles the slider under the new periodic motion; the
  two stuck states differ by O(step): within test_verification's 1 % (reached 0.3 %).
  The history-less run misses the time integration by 100x more than that.
"""

import numpy as np
import pytest

from frirom.contact import aft
from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import SolverOptions, frf, load_curve, solve_point
from frirom.timeint import TimeContact, integrate, state_from_harmonics

M, K, C = 1.0, 1.0, 0.1
PAR = [2.0, 0.2, 1.0]            # kt, mu, fn0
F = np.array([[0.15, 0.05]], complex)
H, NS = 5, 64


def model():
    return Model(np.eye(1) * M, np.eye(1) * K, Damping.matrix(np.eye(1) * C),
                 [ContactGroup("jenkins", np.eye(1), np.atleast_2d(PAR))])


def options(**kw):
    return SolverOptions(**{**dict(harmonics=H, samples=NS, ds=0.02, ds_max=0.05,
                                   max_points=2000), **kw})


def residual(X, omega, w0, fe):
    """Relative HBM residual of the SDOF at harmonics X (2H+1,), slider w0."""
    f = aft("jenkins", X[None, None, :], np.array([PAR]), NS, w0=np.array([[w0]]),
            jacobian=False).forces[0, 0]
    r = K * X + f - fe
    for h in range(1, H + 1):
        a, b = X[2 * h - 1], X[2 * h]
        hw = h * omega
        r[2 * h - 1] += -hw * hw * M * a + hw * C * b
        r[2 * h] += -hw * hw * M * b - hw * C * a
    return np.linalg.norm(r) / max(np.linalg.norm(fe), np.linalg.norm(f), 1e-300)


@pytest.fixture(scope="module")
def sweeps():
    with_h = frf(model(), Excitation(F), 0.5, 2.5, options())
    without = frf(model(), Excitation(F), 0.5, 2.5, options(history=False))
    return with_h, without


def test_sweep_through_stick_is_traced_and_carries_the_slider(sweeps):
    r, _ = sweeps
    assert r.complete, r.message
    stuck = r.state_fractions[:, 0, 0] == 1.0
    # stick -> slip -> stick, several points on each side
    change = np.flatnonzero(np.diff(stuck.astype(int)))
    assert change.size >= 2 and stuck[:5].all() and stuck[-5:].all()
    assert (~stuck).sum() > 10
    # every step short: the curve is traced, nothing stepped over (arc length in the
    # solver's scaling is bounded by ds_max; frequency steps by ds_max times the range)
    assert np.all(np.diff(r.omega) > 0)
    assert np.diff(r.omega).max() <= 0.05 * 2.0 * (1 + 1e-9)
    # through the stuck range after the resonance the slider does not move
    tail = slice(change[-1] + 1, None)
    assert np.ptp(r.slider[tail, 0]) == 0.0
    assert abs(r.slider[-1, 0]) > 0.1          # far from w0 = 0: history decides
    # stuck with slider w: the mean force balance gives a0 exactly
    a0 = (F[0, 0].real + PAR[0] * r.slider[tail, 0]) / (K + PAR[0])
    assert np.allclose(r.X[tail, 0, 0], a0, rtol=1e-9, atol=0)


def test_residual_holds_with_inherited_and_left_history(sweeps):
    r, _ = sweeps
    fe = np.zeros(2 * H + 1)
    fe[0], fe[1], fe[2] = F[0, 0].real, F[0, 1].real, -F[0, 1].imag
    worst = 0.0
    for k in range(1, len(r)):
        for w in (r.slider[k - 1, 0], r.slider[k, 0]):
            worst = max(worst, residual(r.X[k, 0], r.omega[k], w, fe))
    assert worst < 1e-7, worst


@pytest.mark.slow
def test_stuck_points_match_time_integration_from_previous_state(sweeps):
    r, r0 = sweeps
    stuck = r.state_fractions[:, 0, 0] == 1.0
    change = np.flatnonzero(np.diff(stuck.astype(int)))
    ks = np.arange(change[-1] + 1, len(r))
    ks = ks[np.linspace(0, ks.size - 1, min(6, ks.size)).astype(int)]
    x0, v0 = state_from_harmonics(r.X[ks - 1], r.omega[ks - 1])
    ti = integrate(np.eye(1) * M, np.eye(1) * C, np.eye(1) * K,
                   [TimeContact("jenkins", np.eye(1), [PAR])], F, r.omega[ks], H=H,
                   periods=200, tol=1e-9, steps_per_period=512, x0=x0, v0=v0,
                   w0=[r.slider[ks - 1][:, None, :]])
    assert np.all(ti.state_fractions[:, 0, 0] == 1.0)        # it stays stuck
    scale = np.ptp(ti.samples[:, :, 0], axis=1)
    err = np.abs(ti.harmonics[:, 0] - r.X[ks, 0]).max(axis=1) / scale
    assert err[0] < 1e-2 and err[1:].max() < 2e-4, err
    # without history every point restarts from w0 = 0: its stuck solution slides back
    # (no physical slip) and misses the time integration by far
    near = [int(np.argmin(np.abs(r0.omega - w))) for w in r.omega[ks[-2:]]]
    assert np.all(r0.state_fractions[near, 0, 0] == 1.0)
    assert np.all(np.abs(r0.X[near, 0, 0] - ti.harmonics[-2:, 0, 0]) > 1e-2 * 100 * scale[-2:])


def test_formulations_and_load_continuation_carry_the_same_history(sweeps):
    r, _ = sweeps
    rb = frf(model(), Excitation(F), 0.5, 2.5, options(formulation="banded"))
    assert rb.complete and len(rb) == len(r)
    assert np.abs(rb.X - r.X).max() < 1e-8 * np.abs(r.X).max()
    assert np.abs(rb.slider - r.slider).max() < 1e-8 * np.abs(r.slider).max()
    # excitation level 1 -> 0.05 at the resonance: slips, then sticks with the slider
    # where it last slipped; a0 then follows the stuck balance with that slider
    w = r.omega[np.argmax(r.amp_max[:, 0])]
    lc = load_curve(model(), Excitation(F), w, 1.0, 0.05, options())
    assert lc.complete, lc.message
    st = lc.state_fractions[:, 0, 0] == 1.0
    assert not st[0] and st[-1]
    a0 = (F[0, 0].real + PAR[0] * lc.slider[-1, 0]) / (K + PAR[0])
    assert lc.X[-1, 0, 0] == pytest.approx(a0, rel=1e-9)
    # solve_point from the last point's history reproduces it (a fresh, history-less
    # solve does not)
    p = solve_point(model(), Excitation(F), r.omega[-1], options(),
                    start={"slider": r.slider[-1]})
    assert np.abs(p.X[0] - r.X[-1, 0]).max() < 1e-8 * np.abs(r.X[-1]).max()
    q = solve_point(model(), Excitation(F), r.omega[-1], options())
    assert abs(q.X[0, 0] - r.X[-1, 0, 0]) > 1e-2



@pytest.mark.slow
def test_resume_restores_history_and_reads_files_from_before(tmp_path):
    """A run stopped in the stuck range after the resonance resumes with the slider it
    stopped at: the resumed points equal the uninterrupted run's. A file written before
    the history was kept (no 'slider', 'last_slider') still loads (slider None), resumes
    with a warning from w0 (re-solving its last point first: with another history it is no
    solution, and continuing from it stalls), and appending to it marks the old points'
    history unknown (NaN)."""
    import h5py

    from frirom.results import FRF, FRFWriter

    full = frf(model(), Excitation(F), 0.5, 2.5, options())
    stuck = full.state_fractions[:, 0, 0] == 1.0
    n_stop = int(np.flatnonzero(np.diff(stuck.astype(int)))[-1]) + 4   # stuck, slider != 0
    path = tmp_path / "run.h5"
    w = FRFWriter(path, [0], ["jenkins"], H)
    frf(model(), Excitation(F), 0.5, 2.5, options(max_points=n_stop), outputs=[0],
        sink=w.append)
    w.close(complete=False)
    start = FRFWriter.resume_point(path)
    assert start["slider"][0] == full.slider[n_stop - 1, 0] != 0.0
    w = FRFWriter(path, [0], ["jenkins"], H, append=True)
    rest = frf(model(), Excitation(F), 0.5, 2.5, options(), outputs=[0], sink=w.append,
               start=start)
    w.close()
    assert rest.complete and np.all(rest.state_fractions[:, 0, 0] == 1.0)
    saved = FRF.load(path)
    n = len(saved)
    assert n == n_stop + len(rest) and saved.slider.shape == (n, 1)
    assert np.all(saved.slider[n_stop:] == full.slider[n_stop])
    # the stuck balance with that slider: the same mean displacement as the full run
    assert np.allclose(saved.X[n_stop:, 0, 0], full.X[-1, 0, 0], rtol=1e-9, atol=0)
    assert saved.omega[-1] == full.omega[-1]

    # the same file as written before the history was kept (and before checkpoints: the
    # last point's state in last_* datasets and attributes)
    last = FRFWriter.resume_point(path)
    with h5py.File(path, "a") as f:
        for name in ("slider", "ck_unknowns", "ck_tangent", "ck_scalars"):
            del f[name]
        del f.attrs["committed"], f.attrs["content_sha256"]    # both came later
        f["last_unknowns"], f["last_tangent"] = last["unknowns"], last["tangent"]
        f.attrs["last_parameter"] = f.attrs["last_omega"] = last["parameter"]
        f.attrs["last_yscale"] = last["yscale"]
    old = FRF.load(path)
    assert old.slider is None and len(old) == n
    with pytest.warns(RuntimeWarning, match="before frirom kept the contact history"):
        start = FRFWriter.resume_point(path)
    assert start["slider"] is None
    w = FRFWriter(path, [0], ["jenkins"], H, append=True)
    more = frf(model(), Excitation(F), 0.5, 2.6, options(), outputs=[0], sink=w.append,
               start=start)
    w.close()
    back = FRF.load(path)
    assert np.all(np.isnan(back.slider[:n])) and np.all(np.isfinite(back.slider[n:]))
    assert len(back) == n + len(more)
