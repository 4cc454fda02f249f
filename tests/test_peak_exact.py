"""results.amplitude_max (the Fortran frirom_peak kernel) against a reference written
independently here: |x| sampled densely, every sampled local maximum refined by
golden-section search. Random series at H = 0..20 and adversarial ones (degenerate
leading harmonics, even series whose x' has a root at t = pi, pure harmonics). Tolerance:
1e-12 sum|X| (the reference resolves a peak's value to about H^2 eps)."""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest

from frirom._errors import SizeError
from frirom.results import amplitude_max


def abs_x(X, t):
    """|x(t)| of each row of X (rows, 2H+1) at times t (rows, m), from cos and sin."""
    h = np.arange(1, (X.shape[1] - 1) // 2 + 1)
    ht = h * t[..., None]
    return np.abs(X[:, :1] + (X[:, None, 1::2] * np.cos(ht)
                              + X[:, None, 2::2] * np.sin(ht)).sum(-1))


def brute_force(X):
    """max |x| per row: 64(2H+1) samples, then golden section around each local maximum."""
    ns = 64 * X.shape[1]
    v = abs_x(X, np.broadcast_to(2 * np.pi * np.arange(ns) / ns, (X.shape[0], ns)))
    best = v.max(axis=1)
    r, k = np.nonzero((v >= np.roll(v, 1, axis=1)) & (v >= np.roll(v, -1, axis=1)))
    lo, hi = 2 * np.pi * (k - 1) / ns, 2 * np.pi * (k + 1) / ns
    g = (np.sqrt(5) - 1) / 2
    for _ in range(80):
        c, d = hi - g * (hi - lo), lo + g * (hi - lo)
        left = abs_x(X[r], c[:, None])[:, 0] > abs_x(X[r], d[:, None])[:, 0]
        hi, lo = np.where(left, d, hi), np.where(left, lo, c)
    np.maximum.at(best, r, abs_x(X[r], (0.5 * (lo + hi))[:, None])[:, 0])
    return best


def cases(H, rng):
    X = rng.standard_normal((160, 2 * H + 1))
    X[40:80, 1:] /= np.repeat(np.arange(1, H + 1) ** 2, 2)          # decaying
    X[80:120, 3::2] = 0.0                                           # even: x'(pi) = 0
    if H:
        X[120:, 2 * H - 1:] *= 10.0 ** rng.uniform(-14, -10, (40, 1))   # near-zero leading
    return X * 10.0 ** rng.integers(-100, 100, (X.shape[0], 1))


@pytest.mark.parametrize("H", [0, 1, 2, 3, 5, 8, 13, 20])
def test_against_brute_force(H):
    rng = np.random.default_rng(100 + H)
    X = cases(H, rng)
    amp, t = amplitude_max(X, return_time=True)
    scale = np.abs(X).sum(axis=1)
    assert np.all(np.abs(amp - brute_force(X)) <= 1e-12 * scale)
    assert np.all(np.abs(abs_x(X, t[:, None])[:, 0] - amp) <= 1e-12 * scale)
    assert np.all((0 <= t) & (t < 2 * np.pi))


def test_closed_forms_and_shapes():
    # pure harmonic h: |a0| + hypot(a_h, b_h); maximum exactly at t = pi
    for H in range(1, 8):
        for h in range(1, H + 1):
            X = np.zeros(2 * H + 1)
            X[0], X[2 * h - 1], X[2 * h] = 0.5, 0.3 * h, -0.7
            assert amplitude_max(X) == pytest.approx(0.5 + np.hypot(0.3 * h, 0.7), rel=1e-14)
    amp, t = amplitude_max(np.array([0.0, 1.0, 0.0, -0.3, 0.0]), return_time=True)
    assert amp == pytest.approx(1.3, rel=1e-15) and t == pytest.approx(np.pi, abs=1e-7)
    # leading shape kept, columns of different degree in one batch
    X = np.random.default_rng(0).standard_normal((3, 4, 7))
    X[1, :, 3:] = 0.0
    amp = amplitude_max(X)
    assert amp.shape == (3, 4)
    assert np.allclose(amp, brute_force(X.reshape(-1, 7)).reshape(3, 4), rtol=1e-12, atol=0)
    assert amplitude_max(np.zeros((0, 2, 5))).shape == (0, 2)
    assert amplitude_max(np.array([[2.5], [-4.0]])).tolist() == [2.5, 4.0]


def test_bad_input():
    amp = amplitude_max(np.array([[1.0, np.nan, 0.0], [1.0, 2.0, 0.0]]))
    assert np.isnan(amp[0]) and amp[1] == pytest.approx(3.0, rel=1e-15)
    with pytest.raises(SizeError, match="2H\\+1"):
        amplitude_max(np.zeros((3, 4)))
