"""Iwan elements (laws iwan4 and iwan): closed-form dissipation of Segalman's
four-parameter Iwan, the discrete Iwan against its sliders as Jenkins elements and against
an independent numpy march, and finite-difference Jacobians."""

import numpy as np
import pytest

from frirom import contact
from frirom._timeint_maps import _forces
from frirom.harmonics import to_harmonics

H = 3
N = 1024


def _density(fs, kt, chi, beta):
    den = beta + (chi + 1) / (chi + 2)
    phimax = fs * (1 + beta) / (kt * den)
    return phimax, fs * (chi + 1) / (phimax ** (chi + 2) * den), fs * beta / (phimax * den)


def _closed_form(a, fs, kt, chi, beta):
    """Dissipated energy per cycle at displacement amplitude a (Segalman 2005)."""
    phimax, r, s = _density(fs, kt, chi, beta)
    if a <= phimax:
        return 4 * r * a ** (chi + 3) / ((chi + 2) * (chi + 3))
    return (4 * r * (a * phimax ** (chi + 2) / (chi + 2) - phimax ** (chi + 3) / (chi + 3))
            + 4 * s * phimax * (a - phimax))


def _harmonic(amps):
    x = np.zeros((len(amps), 1, 2 * H + 1))
    x[:, 0, 1] = amps
    return x


def _dissipation(law, amps, params, n=N):
    res = contact.aft(law, _harmonic(amps), params, n_samples=n, jacobian=False)
    # u = a cos(tau), f = ... + b1 sin(tau): the work of f along u per cycle is pi a b1
    return np.pi * np.asarray(amps) * np.abs(res.forces[:, 0, 2])


@pytest.mark.parametrize("chi, beta", [(-0.5, 0.2), (-0.8, 0.0), (0.0, 1.0)])
def test_iwan4_dissipation_closed_form(chi, beta):
    fs, kt = 100.0, 1.0e6
    phimax = _density(fs, kt, chi, beta)[0]
    ratios = np.array([1e-2, 3e-2, 0.1, 0.3, 0.7, 1.0, 2.0, 10.0])
    d = _dissipation("iwan4", ratios * phimax, [fs, kt, chi, beta], n=2048)
    ref = np.array([_closed_form(a, fs, kt, chi, beta) for a in ratios * phimax])
    err = np.abs(d / ref - 1)
    assert np.all(err[ratios <= 1] < 0.03), err
    assert np.all(err[ratios >= 2] < 2e-3), err


def test_iwan4_power_law_and_macroslip():
    fs, kt, chi, beta = 100.0, 1.0e6, -0.5, 0.2
    phimax = _density(fs, kt, chi, beta)[0]
    amps = phimax * np.array([0.02, 0.2])
    d = _dissipation("iwan4", amps, [fs, kt, chi, beta], n=2048)
    slope = np.log(d[1] / d[0]) / np.log(10.0)
    assert abs(slope - (chi + 3)) < 0.02          # power law D ~ A^(chi + 3)
    big = 1e3 * phimax
    dm = _dissipation("iwan4", [big], [fs, kt, chi, beta])[0]
    assert abs(dm / (4 * fs * big) - 1) < 2e-3    # macroslip: D -> 4 F_S A
    # stiffness at vanishing amplitude: K_T
    res = contact.aft("iwan4", _harmonic([1e-5 * phimax]), [fs, kt, chi, beta], n_samples=64)
    assert abs(res.forces[0, 0, 1] / (1e-5 * phimax) / kt - 1) < 1e-12


def _random_iwan(rng, ne, used=10):
    p = np.zeros((ne, 20))
    p[:, 0:2 * used:2] = rng.uniform(1e4, 1e5, (ne, used))
    p[:, 1:2 * used:2] = rng.uniform(0.5, 5.0, (ne, used))
    return p


def test_discrete_iwan_is_its_jenkins_sum():
    rng = np.random.default_rng(3)
    ne = 5
    p = _random_iwan(rng, ne, used=7)
    x = rng.normal(size=(ne, 1, 2 * H + 1)) * 5e-5
    w0 = rng.normal(size=(ne, 10)) * 1e-5
    res = contact.aft("iwan", x, p, n_samples=N, w0=w0)
    f = np.zeros_like(res.forces)
    jac = np.zeros_like(res.jacobian)
    for s in range(7):
        r = contact.aft("jenkins", x, np.stack([p[:, 2 * s], np.ones(ne), p[:, 2 * s + 1]], 1),
                        n_samples=N, w0=w0[:, [s]])
        f += r.forces
        jac += r.jacobian
        assert np.allclose(res.slider[:, s], r.slider[:, 0], rtol=0, atol=1e-15)
    assert np.allclose(res.slider[:, 7:], w0[:, 7:], rtol=0, atol=0)   # unused sliders
    assert np.max(np.abs(res.forces - f)) <= 1e-12 * np.max(np.abs(f))
    assert np.max(np.abs(res.jacobian - jac)) <= 1e-12 * np.max(np.abs(jac))


def test_discrete_iwan_against_numpy_march():
    """Independent: the time integrations' return map (frirom._timeint_maps) marched
    over three periods, harmonics of the last one."""
    rng = np.random.default_rng(5)
    ne = 4
    p = _random_iwan(rng, ne)
    x = rng.normal(size=(ne, 1, 2 * H + 1)) * 5e-5
    res = contact.aft("iwan", x, p, n_samples=N, jacobian=False)
    tau = 2 * np.pi * np.arange(N) / N
    cols = [np.ones(N)] + [f(h * tau) for h in range(1, H + 1) for f in (np.cos, np.sin)]
    ut = x[:, 0, :] @ np.array(cols)                            # (ne, N)
    w = np.zeros((1, ne, 10))
    pl = [p[:, j] for j in range(20)]
    for _ in range(3):
        ft = np.empty((ne, N))
        for k in range(N):
            f, w, _ = _forces("iwan", pl, ut[None, :, k, None], w)
            ft[:, k] = f[0, :, 0]
    ref = to_harmonics(ft, H)
    assert np.max(np.abs(res.forces[:, 0] - ref)) <= 1e-11 * np.max(np.abs(ref))


@pytest.mark.parametrize("law", ["iwan4", "iwan"])
def test_iwan_jacobian_finite_differences(law):
    rng = np.random.default_rng(7)
    ne = 3
    p = ([100.0, 1e6, -0.5, 0.3] if law == "iwan4" else _random_iwan(rng, ne))
    # odd harmonics only: u(tau + pi) = -u(tau), so from w0 = 0 no slider ends its
    # transient stuck exactly on its slip limit (the one place Jenkins is not differentiable:
    # there the analytical Jacobian takes the slipping side)
    x = rng.normal(size=(ne, 1, 2 * H + 1)) * 1e-4
    x[:, :, [0, 3, 4]] = 0.0
    base = contact.aft(law, x, p, n_samples=N)
    h = 1e-10
    fd = np.empty_like(base.jacobian)
    for j in range(2 * H + 1):
        dx = np.zeros_like(x)
        dx[:, 0, j] = h
        fp = contact.aft(law, x + dx, p, n_samples=N, w0=base.slider, jacobian=False).forces
        fm = contact.aft(law, x - dx, p, n_samples=N, w0=base.slider, jacobian=False).forces
        fd[:, :, j] = (fp - fm)[:, 0, :] / (2 * h)
    scale = np.max(np.abs(base.jacobian))
    assert np.max(np.abs(fd - base.jacobian)) < 1e-5 * scale


def test_iwan_bad_parameters():
    x = _harmonic([1e-5])
    with pytest.raises(Exception, match="chi must be > -1"):
        contact.aft("iwan4", x, [100.0, 1e6, -1.0, 0.0])
    with pytest.raises(Exception, match="beta must be >= 0"):
        contact.aft("iwan4", x, [100.0, 1e6, -0.5, -0.1])
    with pytest.raises(Exception, match="at least one slider stiffness"):
        contact.aft("iwan", x, np.zeros(20))
