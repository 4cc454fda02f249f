"""The true maximum over a period of |x(t)| of a truncated Fourier series
(results.amplitude_max): closed forms, a brute-force reference, degenerate series, and the
value every FRF point reports."""

import numpy as np
import pytest

from frirom.results import FRF, Peak, amplitude_max
from frirom.solver import SolverOptions, frf

from _models import duffing


def shifted(coeffs, phi):
    """Real harmonics [a0, a1, b1, ...] of x(t) = c0 + sum_h c_h cos(h (t - phi))."""
    X = np.zeros(2 * len(coeffs) - 1)
    X[0] = coeffs[0]
    for h, c in enumerate(coeffs[1:], start=1):
        X[2 * h - 1], X[2 * h] = c * np.cos(h * phi), c * np.sin(h * phi)
    return X


def brute(X, n=10**6):
    """max |x| from n equally spaced samples, each row's best sample refined by the parabola
    through it and its neighbours (error O((H/n)^4): far below 1e-12); (rows,) for
    X (rows, 2H+1)."""
    X = np.atleast_2d(X)
    H = (X.shape[1] - 1) // 2
    t = 2 * np.pi * np.arange(n) / n
    x = np.repeat(X[:, :1], n, axis=1)
    for h in range(1, H + 1):
        x += X[:, 2 * h - 1:2 * h] * np.cos(h * t) + X[:, 2 * h:2 * h + 1] * np.sin(h * t)
    x = np.abs(x)
    out = np.empty(X.shape[0])
    for r, x in enumerate(x):
        k = int(np.argmax(x))
        y0, y1, y2 = x[k - 1], x[k], x[(k + 1) % n]
        den = y0 - 2 * y1 + y2
        out[r] = y1 - (y2 - y0) ** 2 / (8 * den) if den < 0 else y1
    return out


def test_single_harmonic_is_its_magnitude():
    """x = a cos(h t) + b sin(h t) (+ a0): max |x| = |a0| + hypot(a, b) exactly (round-off,
    1e-14 relative), for any h and phase, where no sample of a grid need fall."""
    for h in (1, 2, 5):
        for a, b, a0 in ((0.3, -1.7, 0.0), (-2.0, 0.1, 0.25), (1e-3, 2e-3, -1e-3)):
            X = np.zeros(2 * 5 + 1)
            X[0], X[2 * h - 1], X[2 * h] = a0, a, b
            assert amplitude_max(X) == pytest.approx(abs(a0) + np.hypot(a, b), rel=1e-14)


def test_two_harmonics_closed_form():
    """x = 1 + cos(t - phi) - a cos(2 (t - phi)), a >= 1: x' = 0 at cos = 1/(4a), where
    x = 1 + a + 1/(8a) (the ends t - phi = 0, pi give 2 - a and a); 1e-13 relative."""
    for a in (1.0, 1.7, 3.0):
        for phi in (0.0, 0.1234567, 2.0):
            X = shifted([1.0, 1.0, -a], phi)
            assert amplitude_max(X) == pytest.approx(1 + a + 1 / (8 * a), rel=1e-13)
    # and the time of the maximum: cos(t - phi) = 1/(4a)
    amp, t = amplitude_max(shifted([1.0, 1.0, -2.0], 0.5), return_time=True)
    assert np.cos(t - 0.5) == pytest.approx(1 / 8, abs=1e-10)


def test_random_series_against_brute_force():
    """Random harmonics, H = 1..9, shaped (2, 3, 2H+1): 1e-12 relative to 10^6 samples with
    a parabolic refinement (their own error ~(H pi / 10^6)^4, negligible); never above it
    (every candidate is a real time) beyond round-off."""
    rng = np.random.default_rng(7)
    for H in (1, 3, 7, 9):
        X = rng.standard_normal((2, 3, 2 * H + 1)) * rng.uniform(0.1, 10.0, (2, 3, 1))
        X[..., 2 * H - 1:] *= 10.0 ** -rng.integers(0, 4)      # weak top harmonics too
        amp = amplitude_max(X)
        assert amp.shape == (2, 3)
        ref = brute(X.reshape(-1, 2 * H + 1)).reshape(2, 3)
        np.testing.assert_allclose(amp, ref, rtol=1e-12)


def test_degenerate_series():
    """All zero, constant, H = 0, round-off top harmonics (the linear case of a nonlinear
    run), an empty batch: exact values and shapes."""
    assert amplitude_max(np.zeros(7)) == 0.0
    assert amplitude_max(np.array([-3.0, 0, 0, 0, 0])) == 3.0
    assert amplitude_max(np.array([[2.5], [-4.0]])).tolist() == [2.5, 4.0]
    X = shifted([0.0, 1.0], 0.3)
    X = np.r_[X, 1e-19, -1e-19, 0.0, 0.0]      # H = 3, harmonics 2 and 3 at round-off
    assert amplitude_max(X) == pytest.approx(1.0, rel=1e-14)
    assert amplitude_max(np.zeros((0, 2, 5))).shape == (0, 2)


def test_frf_reports_the_true_maximum():
    """Points of a Duffing FRF (H = 5, up the resonant branch to its fold): amp_max is the
    maximum of the point's own harmonics to 1e-12 (brute force above); the former
    16(2H+1)-sample maximum is 1e-5 to 5e-5 low at these points, so the test separates the
    two."""
    model, ex = duffing()
    o = SolverOptions(harmonics=5)
    r = frf(model, ex, 0.8, 2.5, o, outputs=[0])
    assert r.complete, r.message
    pick = np.r_[np.argsort(r.amp_max[:, 0])[-3:], 0, len(r) - 1]
    ref = brute(r.X[pick, 0])
    np.testing.assert_allclose(r.amp_max[pick, 0], ref, rtol=1e-12)


def test_frf_peak_between_points_and_in_files(tmp_path):
    """FRF.peak without solved peaks: the parabola through the largest point and its
    neighbours, exact for points on a parabola in omega (1e-12); a maximum at an end is
    that point;
    solved peaks (FRF.peaks) survive an HDF5 round trip."""
    w = np.linspace(1.0, 2.0, 11)
    a = 3.0 - 40.0 * (w - 1.437) ** 2
    r = FRF(omega=w, X=np.zeros((11, 2, 3)), amp_max=np.c_[a, w],
            state_fractions=np.zeros((11, 0, 3)), stable=np.ones(11, bool),
            fold=np.zeros(11, bool), iterations=np.zeros(11, int), time_s=np.zeros(11),
            output_dofs=np.array([0, 1]))
    p = r.peak(0)
    assert p.method == "parabola" and p.index == 4
    assert p.amplitude == pytest.approx(3.0, rel=1e-12)
    assert p.omega == pytest.approx(1.437, rel=1e-12)
    q = r.peak(1)
    assert (q.method, q.index, q.amplitude) == ("point", 10, 2.0)
    r.peaks = [Peak(1.5, 3.1, 4, "solve"), q]
    r.save_h5(tmp_path / "f.h5")
    assert FRF.load(tmp_path / "f.h5").peaks == r.peaks
