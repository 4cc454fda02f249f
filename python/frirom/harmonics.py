"""Real harmonic coefficients <-> time samples, in numpy (for setup, plots and checks).

frirom's harmonic ordering, used by every array with a last axis of length 2H+1::

    [a0, a1, b1, a2, b2, ..., aH, bH]
    x(tau) = a0 + sum_h a_h cos(h tau) + b_h sin(h tau),   tau = omega t

sampled at tau_k = 2 pi k / N, k = 0..N-1. The Fortran AFT uses the same maps through
FFTW; these numpy versions are for the thin layer, not the hot path.
"""

from __future__ import annotations

import numpy as np

from ._errors import SamplesError, SizeError


def n_harmonics(n_coef: int) -> int:
    """H from the length 2H+1 of a harmonic axis."""
    if n_coef < 1 or n_coef % 2 == 0:
        raise SizeError(f"harmonic axis has length {n_coef}; expected 2H+1 (odd, >= 1)")
    return (n_coef - 1) // 2


def sample_phases(n_samples: int) -> np.ndarray:
    """tau_k = 2 pi k / N, shape (N,)."""
    return 2.0 * np.pi * np.arange(n_samples) / n_samples


def basis(n_harm: int, n_samples: int) -> np.ndarray:
    """E (N, 2H+1): row k = [1, cos tau_k, sin tau_k, ..., cos H tau_k, sin H tau_k]."""
    tau = sample_phases(n_samples)
    e = np.empty((n_samples, 2 * n_harm + 1))
    e[:, 0] = 1.0
    h = np.arange(1, n_harm + 1)
    e[:, 1::2] = np.cos(np.outer(tau, h))
    e[:, 2::2] = np.sin(np.outer(tau, h))
    return e


def to_time(xh: np.ndarray, n_samples: int) -> np.ndarray:
    """Time samples of harmonic coefficients: (..., 2H+1) -> (..., N)."""
    xh = np.asarray(xh, dtype=float)
    h = n_harmonics(xh.shape[-1])
    if n_samples < 2 * h + 1:
        raise SamplesError(f"N = {n_samples} samples for H = {h}: need N >= 2H+1 = {2 * h + 1}")
    return xh @ basis(h, n_samples).T


def to_harmonics(xt: np.ndarray, n_harm: int) -> np.ndarray:
    """Harmonic coefficients of time samples: (..., N) -> (..., 2H+1), by FFT."""
    xt = np.asarray(xt, dtype=float)
    n = xt.shape[-1]
    if n < 2 * n_harm + 1:
        raise SamplesError(f"N = {n} samples for H = {n_harm}: need N >= 2H+1 = {2 * n_harm + 1}")
    z = np.fft.rfft(xt, axis=-1)
    out = np.empty(xt.shape[:-1] + (2 * n_harm + 1,))
    out[..., 0] = z[..., 0].real / n
    out[..., 1::2] = 2.0 / n * z[..., 1:n_harm + 1].real
    out[..., 2::2] = -2.0 / n * z[..., 1:n_harm + 1].imag
    return out


def amplitudes(xh: np.ndarray) -> np.ndarray:
    """Amplitude of each harmonic: (..., 2H+1) -> (..., H+1), |a0| then sqrt(a_h^2 + b_h^2)."""
    xh = np.asarray(xh, dtype=float)
    out = np.empty(xh.shape[:-1] + ((xh.shape[-1] + 1) // 2,))
    out[..., 0] = np.abs(xh[..., 0])
    out[..., 1:] = np.hypot(xh[..., 1::2], xh[..., 2::2])
    return out
