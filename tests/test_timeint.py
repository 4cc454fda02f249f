"""Checks of the time-integration reference itself (frirom.timeint) against closed forms,
so that the HBM verification against it means something."""

import numpy as np
import pytest

from frirom import InputError
from frirom.timeint import TimeContact, harmonics_from_samples, integrate


def _two_dof():
    M = np.diag([1.0, 0.5])
    K = np.array([[3.0, -1.0], [-1.0, 1.0]])
    C = 0.02 * K + 0.01 * M
    return M, C, K


@pytest.mark.slow
def test_linear_two_dof_matches_closed_form():
    # Central differences shift a frequency by (omega dt)^2/24 = (2 pi/N)^2/24 = 1.6e-5
    # relatively at N = 1024; with a half-power bandwidth of ~1.5 % around the peaks the
    # complex amplitude moves by <~ 0.3 %. Tolerance 0.5 % (relative to the peak).
    M, C, K = _two_dof()
    F = np.zeros((2, 3), complex)
    F[1, 1] = 1.0
    F[0, 0] = 0.3                     # static load
    om = np.linspace(0.5, 2.2, 18)
    r = integrate(M, C, K, [], F, om, H=2, periods=600, tol=1e-9, steps_per_period=1024)
    assert r.drift.max() < 1e-7
    X = np.array([np.linalg.solve(K - w * w * M + 1j * w * C, F[:, 1]) for w in om])
    Xt = r.harmonics[:, :, 1] - 1j * r.harmonics[:, :, 2]
    err = np.abs(Xt - X).max() / np.abs(X).max()
    assert err < 5e-3, err
    x0 = np.linalg.solve(K, F[:, 0].real)
    assert np.allclose(r.harmonics[:, :, 0], x0, rtol=1e-6, atol=1e-9)
    assert np.abs(r.harmonics[:, :, 3:]).max() < 1e-8 * np.abs(X).max()


@pytest.mark.slow
def test_stuck_jenkins_and_open_gap_are_linear():
    # mu*fn0 far above any spring force: the Jenkins element is a spring kt (exactly).
    # 128 steps per period: central differences shift the frequencies by (2 pi/N)^2/24 =
    # 1e-4, which moves these off-resonance amplitudes by < 1e-3 (measured 4e-4 and 9e-4;
    # 2.5e-5 and 5.6e-5 at N = 512): tolerance 5e-3 of the largest amplitude.
    M, C, K = _two_dof()
    F = np.zeros((2, 2), complex)
    F[0, 1] = 1.0
    G = np.array([[1.0, -1.0]])
    jen = TimeContact("jenkins", G, [[2.0, 1.0, 1e6]])
    om = np.array([0.9, 1.7])
    r = integrate(M, C, K, [jen], F, om, H=1, periods=400, tol=1e-7, steps_per_period=128)
    Ks = K + 2.0 * G.T @ G
    X = np.array([np.linalg.solve(Ks - w * w * M + 1j * w * C, F[:, 1]) for w in om])
    Xt = r.harmonics[:, :, 1] - 1j * r.harmonics[:, :, 2]
    assert np.abs(Xt - X).max() / np.abs(X).max() < 5e-3
    assert np.all(r.state_fractions[:, 0, 0] == 1.0)
    # a normal1d contact with a gap far larger than the motion never touches
    gap = TimeContact("normal1d", np.array([[1.0, 0.0], [0.0, 1.0]]),
                      [[5.0, 5.0, 0.3, -1e3]])
    r2 = integrate(M, C, K, [gap], F, om, H=1, periods=400, tol=1e-7,
                   steps_per_period=128)
    X2 = np.array([np.linalg.solve(K - w * w * M + 1j * w * C, F[:, 1]) for w in om])
    Xt2 = r2.harmonics[:, :, 1] - 1j * r2.harmonics[:, :, 2]
    assert np.abs(Xt2 - X2).max() / np.abs(X2).max() < 5e-3
    assert np.all(r2.state_fractions[:, 0, 2] == 1.0)


@pytest.mark.slow
def test_jenkins_energy_per_cycle_in_full_slip():
    # A massless-like check of the return map: in gross slip at low frequency the element
    # dissipates 4 mu fn0 (2 u_amp - 2 mu fn0 / kt) per cycle (hysteresis loop area), and
    # that energy equals the work of the force on the mass-spring system per period.
    # 256 steps per period: the balance holds to 4.5e-5 (1.7e-5 at 512 steps, 2.2e-6 at
    # 1024); tolerance 2e-3.
    M = np.array([[1.0]])
    K = np.array([[1.0]])
    C = np.array([[0.0]])
    kt, mu, fn0 = 4.0, 0.5, 0.2
    jen = TimeContact("jenkins", np.array([[1.0]]), [[kt, mu, fn0]])
    F = np.array([[0.0, 0.6]], complex)
    om = np.array([0.5])
    r = integrate(M, C, K, [jen], F, om, H=9, periods=400, tol=1e-9,
                  steps_per_period=256)
    x = r.samples[0, :, 0]
    N = x.size
    tau = 2 * np.pi * np.arange(N) / N
    # work of the external force over one period: int f dx (periodic: trapezoid exact-ish)
    dx = np.roll(x, -1) - x
    fe = 0.6 * np.cos(tau + np.pi / N)           # force at mid-step
    work = np.sum(fe * dx)
    # the loop: amplitude u_a = (max - min)/2 about the centre
    ua = 0.5 * (x.max() - x.min())
    loop = 4 * mu * fn0 * (2 * ua - 2 * mu * fn0 / kt) / 2
    assert abs(work - loop) / loop < 2e-3, (work, loop)


def test_harmonics_from_samples_roundtrip():
    N = 32
    tau = 2 * np.pi * np.arange(N) / N
    x = 0.5 + 2 * np.cos(tau) - 3 * np.sin(tau) + 0.25 * np.sin(3 * tau)
    c = harmonics_from_samples(x[:, None], 3)[0]
    assert np.allclose(c, [0.5, 2, -3, 0, 0, 0, 0.25], atol=1e-12)


def test_bad_input_raises():
    M, C, K = _two_dof()
    with pytest.raises(InputError, match="params"):
        TimeContact("jenkins", np.array([[1.0, 0.0]]), [[1.0, 0.3]])
    with pytest.raises(InputError, match="law"):
        TimeContact("coulomb", np.array([[1.0, 0.0]]), [[1.0, 0.3, 1.0]])
    with pytest.raises(InputError, match="omega"):
        integrate(M, C, K, [], np.ones((2, 2)), -1.0)


@pytest.mark.slow
def test_normal2d_in_one_plane_equals_normal1d():
    # motion confined to the first tangential direction: the circular friction limit
    # reduces to the 1-D one, so both laws must give the same response
    M = np.diag([1.0, 1.0])
    K = np.array([[2.0, -0.5], [-0.5, 1.5]])
    C = 0.02 * K
    F = np.zeros((2, 2), complex)
    F[0, 1] = 0.4
    G1 = np.array([[1.0, 0.0], [0.0, 1.0]])                  # u, v
    G2 = np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 1.0]])      # u1, u2 (= 0), v
    par = [[1.5, 1.0, 0.3, 0.4]]
    om = np.array([0.8, 1.1, 1.4])
    kw = dict(H=3, periods=300, tol=1e-8, steps_per_period=256)
    r1 = integrate(M, C, K, [TimeContact("normal1d", G1, par)], F, om, **kw)
    r2 = integrate(M, C, K, [TimeContact("normal2d", G2, par)], F, om, **kw)
    assert r1.state_fractions[:, 0, 1:].sum(axis=1).max() > 0.2     # slips / lifts off
    assert np.allclose(r1.samples, r2.samples, rtol=0, atol=1e-12)
    assert np.allclose(r1.state_fractions, r2.state_fractions)


@pytest.mark.parametrize("method", ["explicit", "implicit"])
def test_no_period_gives_the_start_state_and_no_samples(method):
    """periods = 0 (frirom.floquet asks for the start state this way): x and v are the
    start (v to O(dt) in the explicit march), and the samples, harmonics and contact states are NaN, not the unwritten
    buffers (their garbage gave overflow warnings in the FFT, and numbers)."""
    import warnings
    G = np.array([[1.0]])
    jen = TimeContact("jenkins", G, [[2.0, 1.0, 1e6]])
    F = np.zeros((1, 2), complex)
    F[0, 1] = 0.5
    x0, v0 = np.array([[0.1]]), np.array([[-0.2]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = integrate(np.eye(1), 0.01 * np.eye(1), np.eye(1), [jen], F, np.array([1.1]),
                      H=3, periods=0, min_periods=0, x0=x0, v0=v0, method=method)
    assert r.periods == 0
    # the explicit march keeps x and x_prev: its v is their difference, within O(dt)
    assert np.allclose(r.x, x0) and np.allclose(r.v, v0, rtol=1e-2)
    for a in (r.samples, r.harmonics, r.amp_max, r.state_fractions):
        assert np.isnan(a).all()
