"""Convergence of the AFT force harmonics with the number of time samples N, per regime.

The friction forces are continuous with kinks at the state changes, so the trapezoidal
(DFT) harmonics of exact samples converge like N^-2; a state change that the march places
at a sample instead of between samples (the slider re-anchored one sample off) leaves an
O(1/N) error over the following stick and the rate drops to N^-1. Each regime is run at
N = 64..1024 (13 sizes, not only powers of two: where the transitions fall between samples
makes the error jitter with N) and the slope of log(error) against log(N) is fitted to
the upper envelope of the errors (the largest error at this N or above): a lucky N whose
kink errors cancel would otherwise tilt the fit. Sizes are 2^a 5^b (cheap FFTW plans).

References: the closed form of the Jenkins element under u = a cos(tau) (independent of
the AFT), and otherwise the same AFT at N = 2^16 samples, whose own error (~N^-2 ~ 1e-9
relative) is below the errors fitted here. The 2-D law's closed-form and time-integration
checks are in test_normal2d_aft.py.
"""

import numpy as np
import pytest

from frirom import contact

N_FIT = (64, 80, 100, 128, 160, 200, 256, 320, 400, 512, 640, 800, 1024)
N_REF = 2 ** 16
H = 5


def _x(n_dir, terms):
    """(1, n_dir, 2H+1) harmonics from {(direction, coefficient index): value}."""
    x = np.zeros((1, n_dir, 2 * H + 1))
    for (d, c), value in terms.items():
        x[0, d, c] = value
    return x


def jenkins_first_harmonic(a, kt, fs):
    """(a1, b1) of the Jenkins force under u = a cos(tau), a > fs/kt (stick ends at ts)."""
    ts = np.arccos(1.0 - 2.0 * fs / (kt * a))
    a1 = 2 / np.pi * ((2 * fs - kt * a) * np.sin(ts) + kt * a * (ts / 2 + np.sin(2 * ts) / 4))
    b1 = 2 / np.pi * ((fs - kt * a) * (1 - np.cos(ts)) + kt * a * np.sin(ts) ** 2 / 2
                      - fs * (1 + np.cos(ts)))
    return np.array([a1, b1])


# regime: law, x, params, expected states (min stick, slip, lift-off fractions present)
ISSUE = [2.0, 1.5, 0.3, 1.0]        # kt, kn, mu, n0 of the issue 9 case
REGIMES = {
    # constant normal load, two harmonics: stick and slip in each half cycle
    "jenkins": ("jenkins", _x(1, {(0, 1): 1e-3, (0, 4): 0.3e-3}), [1e5, 0.3, 100.0]),
    # varying normal load that never opens: slip on a moving limit, stick at reversals
    "stick-slip": ("normal1d", _x(2, {(0, 1): 1.0, (0, 4): 0.2, (1, 2): -0.4}), ISSUE),
    # the issue's case: opens for sin > 2/3 and sticks when it recloses
    "lift-off": ("normal1d", _x(2, {(0, 1): 0.1, (1, 2): -1.0}), ISSUE),
    # lift-off with slip before it and after re-contact, second harmonics in both directions
    "lift-off-slip": ("normal1d", _x(2, {(0, 1): 1e-3, (0, 4): 0.2e-3, (1, 2): 1.2e-3,
                                         (1, 3): 0.3e-3}), [1e5, 0.8e5, 0.4, 60.0]),
    # 2-D: elliptic in-plane motion (curved slip paths) with lift-off
    "normal2d": ("normal2d", _x(3, {(0, 1): 0.1, (1, 2): 0.05, (2, 2): -1.0}), ISSUE),
    # 2-D stick-slip at constant normal load: a Lissajous orbit, slip on curved paths
    "normal2d-stick-slip": ("normal2d", _x(3, {(0, 1): 0.45e-3, (1, 4): 0.4e-3,
                                               (1, 1): 0.1e-3}), [1e5, 0.0, 0.3, 100.0]),
    # the same under a normal load that varies but never opens (slip radius moves)
    "normal2d-varying": ("normal2d", _x(3, {(0, 1): 0.45e-3, (1, 4): 0.4e-3, (1, 1): 0.1e-3,
                                            (2, 2): 0.5e-3}), [1e5, 1e5, 0.3, 100.0]),
    # 2-D lift-off with curved slip before it and after re-contact
    "normal2d-lift-off-slip": ("normal2d", _x(3, {(0, 1): 1e-3, (0, 4): 0.2e-3, (1, 2): 0.6e-3,
                                                  (1, 3): 0.2e-3, (2, 2): 1.2e-3,
                                                  (2, 3): 0.3e-3}), [1e5, 0.8e5, 0.4, 60.0]),
}


def _errors(law, x, params, reference):
    """Relative error of the force harmonics at each N of N_FIT: the largest error over
    the harmonics of each direction relative to that direction's largest harmonic."""
    scale = np.abs(reference).max(axis=-1)
    out = []
    for n in N_FIT:
        f = contact.aft(law, x, params, n, jacobian=False).forces[0]
        out.append((np.abs(f - reference).max(axis=-1) / scale).max())
    return np.array(out)


def _slope(errors):
    """Fitted exponent p of error ~ N^p over N_FIT, on the upper envelope of the errors."""
    envelope = np.maximum.accumulate(np.asarray(errors)[::-1])[::-1]
    return np.polyfit(np.log(N_FIT), np.log(envelope), 1)[0]


def _check_second_order(errs, what):
    """Slope of the envelope in (-2.5, -1.65) and error <= 20 N^-2 at every N.

    Seen: slopes -1.78 to -2.15 and error N^2 <= 14.5 over these regimes. A state change
    placed one sample off gives an O(1/N) error: the issue's lift-off case had slope -1.44
    (the jitter hides part of the first order) and error N^2 up to 1150."""
    slope = _slope(errs)
    print(what, dict(zip(N_FIT, np.round(errs, 10))), "slope", round(slope, 3))
    assert -2.5 < slope < -1.65, (what, slope)
    assert np.all(errs * np.array(N_FIT) ** 2 <= 20.0), (what, errs * np.array(N_FIT) ** 2)


def test_jenkins_converges_like_n_minus_2_to_its_closed_form():
    """First harmonic of the Jenkins force under u = a cos against the closed form."""
    amp, kt, fs = 1e-3, 1e5, 30.0
    x = _x(1, {(0, 1): amp})
    ref = jenkins_first_harmonic(amp, kt, fs)
    errs = np.array([np.abs(contact.aft("jenkins", x, [kt, 0.3, 100.0], n, jacobian=False)
                            .forces[0, 0, 1:3] - ref).max() / np.abs(ref).max()
                     for n in N_FIT])
    _check_second_order(errs, "jenkins closed form")


@pytest.mark.parametrize("regime", ["jenkins", "stick-slip", "lift-off", "lift-off-slip"])
def test_1d_laws_converge_like_n_minus_2(regime):
    """Every 1-D regime against N = 2^16 (see _check_second_order). The issue's case
    ('lift-off') was 3.8e-3 off at N = 256 and 2.3e-4 at 1024 with the slider re-anchored
    at the last open sample; located at the re-contact instant: 7.6e-5 and 2.6e-6."""
    law, x, params = REGIMES[regime]
    ref_run = contact.aft(law, x, params, N_REF, jacobian=False)
    states = ref_run.states[0]
    assert states[0] > 0.05 and states[1] > 0.05      # sticks and slips
    if regime.startswith("lift-off"):
        assert states[2] > 0.05                       # and opens
    else:
        assert states[2] == 0.0
    _check_second_order(_errors(law, x, params, ref_run.forces[0]), regime)


@pytest.mark.parametrize("regime", ["normal2d-stick-slip", "normal2d-varying", "normal2d",
                                    "normal2d-lift-off-slip"])
def test_2d_law_converges_like_n_minus_2(regime):
    """The 2-D law, whose march moves the slider exactly along the interpolated path
    between closed samples (frirom_contact slip2d_step), converges like the 1-D laws (see
    _check_second_order; seen slopes -1.95 to -2.09, error N^2 <= 14.7). With the radial
    return it replaced the slope was -0.96 with lift-off ('normal2d': 1.45e-3 at N = 256,
    3.7e-4 at 1024; now 6.9e-5 and 3.1e-6) and -0.98 in stick-slip."""
    law, x, params = REGIMES[regime]
    ref_run = contact.aft(law, x, params, N_REF, jacobian=False)
    states = ref_run.states[0]
    assert states[0] > 0.1 and states[1] > 0.1        # sticks and slips
    if "lift-off" in regime or regime == "normal2d":
        assert states[2] > 0.2
    else:
        assert states[2] == 0.0
    _check_second_order(_errors(law, x, params, ref_run.forces[0]), regime)
