"""Checks of the implicit (HHT-alpha) time integration of frirom.timeint against closed
forms and against the explicit integrator (central differences, a different scheme with the
same return maps), so that it can serve as the reference on reduced FE models, whose
highest modes make the explicit scheme impractical."""

import numpy as np
import pytest

from frirom import InputError
from frirom.timeint import TimeContact, integrate
from frirom.timeint_implicit import algorithmic_properties


def _two_dof():
    M = np.diag([1.0, 0.5])
    K = np.array([[3.0, -1.0], [-1.0, 1.0]])
    C = 0.02 * K + 0.01 * M
    return M, C, K


def test_hht_spectral_properties_match_closed_forms():
    # HHT-alpha: spectral radius (1 + alpha) / (1 - alpha) as omega dt -> inf, frequency
    # error -(omega dt)^2 / 12 at alpha = 0 (Newmark's average acceleration), a little
    # more with alpha < 0 (measured factor 1.14 at -0.05, 1.25 at -0.1: bounded by 1 - 3
    # alpha), and algorithmic damping O((omega dt)^3) for resolved modes. Tolerances: 1e-3
    # on the radius at omega dt = 1e4 (the limit is reached as 1/(omega dt)^2), 2 % on the
    # alpha = 0 frequency error (higher-order terms: (omega dt)^2 = 6e-4 relative),
    # zeta < 1e-6 at 256 steps per period (measured 8e-8 at alpha = -0.05).
    for alpha in (0.0, -0.05, -0.1):
        rho, dfreq, zeta = algorithmic_properties(alpha, [2 * np.pi / 256, 1e4])
        assert abs(rho[1] - (1 + alpha) / (1 - alpha)) < 1e-3, (alpha, rho)
        ratio = dfreq[0] / (-(2 * np.pi / 256) ** 2 / 12)
        assert 0.98 < ratio < 1.02 * (1 - 3 * alpha), (alpha, ratio)
        assert 0.0 <= zeta[0] < 1e-6 or (alpha == 0.0 and abs(zeta[0]) < 1e-12), zeta
    with pytest.raises(InputError, match="alpha"):
        algorithmic_properties(0.1, 1.0)


@pytest.mark.slow
def test_linear_two_dof_second_order_against_closed_form():
    # The closed-form FRF of a 2-DoF system (1 % and 1.5 % damping) at 6 frequencies
    # including both resonances. Step error O(dt^2): the frequency shift (2 pi/N)^2/12 =
    # 2.5e-4 at N = 128 moves the complex amplitude near the peaks by ~1.5e-2 of the peak
    # (measured 1.5e-2 at N = 128, 3.8e-3 at 256, 9.5e-4 at 512): bound 2e-2 at N = 128,
    # and halving the step must divide the error by 4 (3.5 to 4.5: second order).
    M, C, K = _two_dof()
    F = np.zeros((2, 3), complex)
    F[1, 1] = 1.0
    F[0, 0] = 0.3                     # static load
    om = np.array([0.5, 0.63, 0.9, 1.5, 1.8, 2.2])
    X = np.array([np.linalg.solve(K - w * w * M + 1j * w * C, F[:, 1]) for w in om])
    err = []
    for N in (128, 256):
        r = integrate(M, C, K, [], F, om, H=2, periods=600, tol=1e-10, steps_per_period=N,
                      method="implicit")
        assert r.drift.max() < 1e-9 and r.steps_per_period == N
        Xt = r.harmonics[:, :, 1] - 1j * r.harmonics[:, :, 2]
        err.append(np.abs(Xt - X).max() / np.abs(X).max())
        x0 = np.linalg.solve(K, F[:, 0].real)
        assert np.allclose(r.harmonics[:, :, 0], x0, rtol=1e-9, atol=1e-12)
        assert np.abs(r.harmonics[:, :, 3:]).max() < 1e-9 * np.abs(X).max()
    assert err[0] < 2e-2, err
    assert 3.5 < err[0] / err[1] < 4.5, err


# ---- friction: against the explicit integrator ---------------------------------------------
J_M, J_K, J_C = np.eye(1), np.eye(1), 0.02 * np.eye(1)
J_PAR = [[2.0, 0.2, 1.0]]            # kt, mu, fn0: slip force 0.2, stuck frequency sqrt(3)
N_M = np.diag([1.0, 1.0, 0.5])
N_K = np.array([[3.0, 0.0, -1.0], [0.0, 4.0, 0.0], [-1.0, 0.0, 1.0]])
N_C = 0.01 * N_K + 0.01 * N_M
_c, _s = np.cos(np.pi / 6), np.sin(np.pi / 6)
N_G = np.array([[_c, _s, 0.0], [-_s, _c, 0.0]])    # inclined face: bending rubs and unloads


@pytest.mark.parametrize("case", ["jenkins", pytest.param("normal1d",
                                                           marks=pytest.mark.slow)])
def test_friction_against_explicit(case):
    # The test_verification models: a Jenkins SDOF in partial slip (13-32 % stick) and a
    # 3-DoF with a normal1d contact that lifts off over 23 % of the period at 1.05 rad/s.
    # Reference: the explicit scheme at N = 1024 (its error 3e-5, measured against N =
    # 2048). The implicit one at N = 256 errs by (2 pi/N)^2-scaled 1.3e-3 (jenkins) and
    # 1.4e-3 (normal1d) in max |x| and in the harmonics (measured against explicit N =
    # 2048): bound 3e-3 of the largest amplitude; the contact states (stick/slip/lift-off
    # fractions of the period) within 2 % of the period (one kink moves by < 3 samples).
    if case == "jenkins":
        M, C, K, out = J_M, J_C, J_K, 0
        con = [TimeContact("jenkins", np.array([[1.0]]), J_PAR)]
        F = np.array([[0.0, 0.3]], complex)
    else:
        M, C, K, out = N_M, N_C, N_K, 2
        con = [TimeContact("normal1d", N_G, [[2.0, 2.0, 0.3, 0.7]])]
        F = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.1]], complex)
    om = np.array([0.9, 1.05, 1.2])
    kw = dict(H=5, periods=800, tol=1e-7)
    ref = integrate(M, C, K, con, F, om, steps_per_period=512, **kw)
    # started where the reference ends: only the O(dt^2) difference decays
    r = integrate(M, C, K, con, F, om, steps_per_period=256, method="implicit", **kw,
                  **ref.restart())
    assert r.drift.max() < 1e-7
    scale = ref.amp_max[:, out].max()
    assert np.abs(r.amp_max[:, out] - ref.amp_max[:, out]).max() < 3e-3 * scale
    assert np.abs(r.harmonics[:, out] - ref.harmonics[:, out]).max() < 3e-3 * scale
    np.testing.assert_allclose(r.state_fractions, ref.state_fractions, atol=0.02)
    assert r.state_fractions[1:, 0, 1].min() > 0.2               # it slips
    if case == "normal1d":
        assert r.state_fractions[1, 0, 2] > 0.1                  # and lifts off at 1.05


@pytest.mark.slow
def test_normal2d_in_one_plane_equals_normal1d_implicit():
    # normal2d with the motion in one tangential plane equals normal1d to round-off in the
    # Newton solve (1e-10 of the amplitude: Newton stops at 1e-12 relative updates). The
    # two laws take the two Newton paths (normal1d: exact once the states are right;
    # normal2d: a curved slip surface, iterated to the update tolerance).
    M = np.diag([1.0, 1.0])
    K = np.array([[2.0, -0.5], [-0.5, 1.5]])
    C = 0.02 * K
    F = np.zeros((2, 2), complex)
    F[0, 1] = 0.4
    G1 = np.array([[1.0, 0.0], [0.0, 1.0]])
    G2 = np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 1.0]])
    par = [[1.5, 1.0, 0.3, 0.4]]
    om = np.array([0.8, 1.1])
    kw = dict(H=3, periods=60, min_periods=60, tol=0.0, steps_per_period=64,
              method="implicit")
    r1 = integrate(M, C, K, [TimeContact("normal1d", G1, par)], F, om, **kw)
    r2 = integrate(M, C, K, [TimeContact("normal2d", G2, par)], F, om, **kw)
    assert r1.state_fractions[:, 0, 1:].sum(axis=1).max() > 0.2
    assert np.abs(r1.samples - r2.samples).max() < 1e-10 * np.abs(r1.samples).max()
    np.testing.assert_allclose(r1.state_fractions, r2.state_fractions)


@pytest.mark.slow
def test_duffing_against_explicit():
    # cubic law (Newton iterated to the update tolerance), Duffing oscillator with 5 %
    # damping on the resonance's flanks against the explicit scheme at N = 1024 (error
    # ~3e-5): the implicit one at N = 128 within 1e-2 of the amplitude (O((2 pi/N)^2):
    # measured 2.5e-3).
    cub = [TimeContact("cubic", np.array([[1.0]]), [[0.0, 0.5]])]
    Fd = np.array([[0.0, 0.1]], complex)
    om = np.array([0.8, 1.2])
    args = (np.eye(1), 0.05 * np.eye(1), np.eye(1), cub, Fd, om)
    ref = integrate(*args, H=5, periods=800, tol=1e-8, steps_per_period=512)
    r = integrate(*args, H=5, periods=800, tol=1e-8, steps_per_period=128,
                  method="implicit", **ref.restart())
    assert r.drift.max() < 1e-8
    err = np.abs(r.amp_max - ref.amp_max).max() / ref.amp_max.max()
    assert err < 1e-2, err


@pytest.mark.slow
def test_auto_takes_implicit_on_stiff_models_only():
    # A 2-DoF with a stiff, lightly damped second mode 1000 times the forcing (a reduced FE
    # model's residual mode, here excited through a stuck Jenkins contact): "auto" must
    # take the implicit scheme (the explicit one would need 12 600 steps per period, more
    # than 8 x 128) and match the closed-form FRF of the stuck system to the O(dt^2)
    # error at N = 128 off resonance (measured 4e-4; bound 2e-3), with the high mode
    # damped out (the period-to-period change reaches 1e-7, at the pace of the low
    # mode's 1.2 % damping). On the small two-DoF model
    # above it keeps the explicit scheme (results as before the implicit one existed).
    M = np.diag([1.0, 1e-6])
    K = np.array([[1.0, -1.0], [-1.0, 1.0]])
    C = 0.02 * np.eye(2) + 1e-5 * K
    G = np.array([[0.0, 1.0]])
    jen = [TimeContact("jenkins", G, [[2.0, 1.0, 1e6]])]
    F = np.array([[0.0, 0.5], [0.0, 0.0]], complex)
    om = np.array([0.4, 1.6])
    Ks = K + 2.0 * G.T @ G
    X = np.array([np.linalg.solve(Ks - w * w * M + 1j * w * C, F[:, 1]) for w in om])
    x0, v0 = X.real, om[:, None] * -X.imag          # started on the closed-form orbit
    r = integrate(M, C, K, jen, F, om, H=1, periods=600, tol=1e-7, steps_per_period=128,
                  x0=x0, v0=v0)
    assert r.method == "implicit" and r.steps_per_period == 128
    assert r.drift.max() < 1e-7
    Xt = r.harmonics[:, :, 1] - 1j * r.harmonics[:, :, 2]
    assert np.abs(Xt - X).max() / np.abs(X).max() < 2e-3
    M2, C2, K2 = _two_dof()
    r2 = integrate(M2, C2, K2, [], np.ones((2, 2)), 1.0, H=1, periods=3)
    assert r2.method == "explicit"


def test_implicit_bad_input():
    M, C, K = _two_dof()
    with pytest.raises(InputError, match="method"):
        integrate(M, C, K, [], np.ones((2, 2)), 1.0, method="rk4")
    with pytest.raises(InputError, match="alpha"):
        integrate(M, C, K, [], np.ones((2, 2)), 1.0, method="implicit", alpha=0.2)


# ---- a reduced FE model: the lap joint (gmsh + ccx, CB + GSI) ------------------------------
LAP_HZ = 877.65       # on the first bending resonance's flank (peak 859.8 Hz)


@pytest.fixture(scope="module")
def lap_gsi(lap_joint_mesh, tmp_path_factory):
    from _models import copy_job
    return lap_deck(copy_job(lap_joint_mesh, tmp_path_factory.mktemp("lap_ti")))


def lap_deck(out):
    """The coarse lap joint of tests/test_lap_joint_case.py (element size 12 mm, CB 20 +
    GSI 40 modes) in ``out`` (meshed here unless its ccx files are there): its loaded
    deck."""
    import make_lap_joint
    from _models import small_lap_joint_deck
    from frirom.deck import load_deck
    if not (out / "lap.sti").exists():
        make_lap_joint.make(out, size=0.012)
    (out / "gsi.toml").write_text(small_lap_joint_deck(40))
    return load_deck(out / "gsi.toml")


def hbm_point(d, omega, H=7):
    """Harmonic balance point of deck ``d`` at omega rad/s, every DoF, N = 256: Newton from
    H = 1 and 3 (cold Newton at H = 7 takes minutes)."""
    import dataclasses

    from frirom.solver import solve_point
    m = d.model()
    start, h0 = None, None
    for h, ns in ((1, 64), (3, 128), (H, 256)):
        opts = dataclasses.replace(d.options(), harmonics=h, samples=ns)
        start = solve_point(m, d.excitation(), omega, opts, outputs=np.arange(m.n_dof),
                            start=start, start_harmonics=h0)
        h0 = h
    return start


@pytest.mark.slow
def test_lap_joint_hbm_against_implicit_time_integration(lap_gsi):
    """The coarse lap joint of tests/test_lap_joint_case.py (CB 20 + GSI 40 modes: 63
    coordinates, 65 normal1d pairs) at 877.65 Hz, on the resonance's flank, where the
    joint sticks 69 %, slips 30 % and lifts off 1 % of the period. With every contact stuck
    its highest mode is 316 times the forcing frequency: the explicit scheme needs 3874
    steps per period (cases/bench/timeint.py: 4.4 times the time per period of the
    implicit one at 128 steps). Harmonic balance at H = 7 (N = 256; H = 11 moves the
    amplitude by 5e-5) against the implicit integration started from it: the amplitude at
    the shaker within 1 % (the issue's criterion; measured 2.8e-3 at N = 128 and 1.7e-3
    at 256, the rest is the AFT's sampling of lift-off at N = 256) and the contact state
    fractions within 0.03 of the period (measured 0.014)."""
    from frirom.timeint import state_from_harmonics
    d = lap_gsi
    m = d.model()
    act = d.outputs[0]
    w = 2 * np.pi * LAP_HZ
    start = hbm_point(d, w)
    x0, v0 = state_from_harmonics(start.X, w)
    c = d.contacts[0]
    ti = integrate(m.M.toarray(), m.C.toarray(), m.K.toarray(),
                   [TimeContact(c.law, c.G.toarray(), c.params)], d.F, w, H=7,
                   periods=200, tol=1e-6, steps_per_period=128, x0=x0, v0=v0,
                   w0=[start.slider.reshape(1, -1, 1)], method="implicit")
    assert ti.drift[0] < 1e-6, ti.drift
    assert abs(start.amp_max[act] / ti.amp_max[0, act] - 1) < 1e-2
    np.testing.assert_allclose(ti.state_fractions[0, 0], start.state_fractions[0], atol=0.03)
    assert start.state_fractions[0, 1] > 0.2 and start.state_fractions[0, 2] > 0.0


@pytest.mark.parametrize("law", ["jenkins", "normal1d"])
def test_tangent_of_pattern_matches_finite_differences(law):
    # The Newton Jacobian of the piecewise-linear laws, built from the stick/slip/lift-off
    # pattern, against central differences of the return map (exact inside a pattern
    # region: step 1e-7 of the 1e-1-sized displacements, tolerance 1e-6 relative).
    from frirom.timeint import _forces
    from frirom.timeint_implicit import _forces_and_tangent, _tangent_of_pattern
    rng = np.random.default_rng(3)
    ne = 40
    if law == "jenkins":
        p = [np.full(ne, 2.0), np.full(ne, 0.3), np.full(ne, 0.5)]
        u = rng.uniform(-0.3, 0.3, (1, ne, 1))
    else:
        p = [np.full(ne, 2.0), np.full(ne, 3.0), np.full(ne, 0.3), np.full(ne, 0.2)]
        u = rng.uniform(-0.3, 0.3, (1, ne, 2))
    w = rng.uniform(-0.1, 0.1, (1, ne, 1))
    f, _, state, D = _forces_and_tangent(law, p, u, w)
    assert {0, 1}.issubset(set(state.ravel()))               # stick and slip both seen
    pat = state + 3 * (f[..., 0] > 0.0)
    assert np.array_equal(_tangent_of_pattern(law, p, pat), D)
    h = 1e-7
    for d in range(u.shape[-1]):
        du = np.zeros_like(u)
        du[..., d] = h
        fd = (_forces(law, p, u + du, w)[0] - _forces(law, p, u - du, w)[0]) / (2 * h)
        assert np.allclose(D[..., :, d], fd, rtol=1e-6, atol=1e-6 * 2.0)


@pytest.mark.parametrize("method", ["explicit", "implicit"])
def test_on_period_records_every_period_as_a_restart_would(method):
    """integrate(on_period=...) hands over each period's samples: the k-th equals the last
    period of a run of k periods (the same steps), for a batch of two frequencies, one of
    them twice (the implicit scheme then shares its operators between the two)."""
    con = [TimeContact("jenkins", np.array([[1.0]]), J_PAR)]
    F = np.array([[0.0, 0.3]], complex)
    om = np.array([1.05, 1.05, 1.2])
    seen = []
    kw = dict(H=3, min_periods=3, tol=0.0, steps_per_period=64, method=method)
    r = integrate(J_M, J_C, J_K, con, F, om, periods=3, **kw,
                  on_period=lambda k, s: seen.append((k, s.copy())))
    assert [k for k, _ in seen] == [1, 2, 3]
    np.testing.assert_array_equal(seen[-1][1], r.samples)
    r2 = integrate(J_M, J_C, J_K, con, F, om, periods=2, **dict(kw, min_periods=2))
    np.testing.assert_array_equal(seen[1][1], r2.samples)
    np.testing.assert_array_equal(r.samples[0], r.samples[1])
