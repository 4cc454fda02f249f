"""Real harmonic coefficients <-> time samples, in numpy (for setup, plots and checks).

frirom's harmonic ordering, used by every array with a last axis of length 2H+1::

    [a0, a1, b1, a2, b2, ..., aH, bH]
    x(tau) = a0 + sum_h a_h cos(h tau) + b_h sin(h tau),   tau = omega t

sampled at tau_k = 2 pi k / N, k = 0..N-1. The Fortran AFT uses the same maps through
FFTW; these numpy versions are for the thin layer, not the hot path.
"""

from __future__ import annotations

import numpy as np

from ._errors import SamplesError, SizeError, as_floats


def n_harmonics(n_coef: int) -> int:
    """H from the length 2H+1 of a harmonic axis."""
    if n_coef < 1 or n_coef % 2 == 0:
        raise SizeError(f"harmonic axis has length {n_coef}; expected 2H+1 (odd, >= 1)")
    return (n_coef - 1) // 2


def element_harmonics(x, n_dir: int, what: str) -> np.ndarray:
    """x as floats of shape (n_elem, n_dir, 2H+1) (a 2-D x taken as one direction); a
    SizeError naming ``what`` (the law) otherwise."""
    x = as_floats("x", x)
    if x.ndim == 2 and n_dir == 1:
        x = x[:, None, :]
    if x.ndim != 3 or x.shape[1] != n_dir:
        raise SizeError(f"{what}: x has shape {x.shape}; expected (n_elem, {n_dir}, 2H+1)")
    n_harmonics(x.shape[2])
    return x


def default_samples(n_harm: int) -> int:
    """The default number N of AFT time samples per period for H harmonics: 512, or 16
    samples per period of the highest harmonic rounded up to a power of two when that is
    more (H >= 16). The rule is frirom_solve's frf_default_samples (the C/Fortran whole
    solve uses it too), read from Fortran.

    It targets 1e-4 relative on the response amplitude at a friction resonance: the AFT
    forces converge like N^-2 (tests/test_aft_convergence.py) and
    ``cases/bench/samples.py`` measures, for H = 1..15 on a Jenkins SDOF, a 3-DoF model
    whose normal-load contact lifts off and ``cases/joint/joint.toml``, errors against
    N = 2^14 of at most 4.3e-5 with N = 512, but up to 2.6e-4 with 256 and 1.4e-3 with 128
    (the old default 8(2H+1) was 1.2e-3 to 6.8e-3 off). Per N the cost of an AFT +
    Jacobian is linear: 512 costs 1.4-2.1x what 256 does (H = 15 and 1). The 2-D law
    (normal2d) converges like 1/N on curved slip paths: give it more samples.

    Parameters
    ----------
    n_harm : int
        H, the highest harmonic.

    Returns
    -------
    int
        N (>= 2H+1).
    """
    from . import _kernels
    return int(_kernels.default_samples(int(n_harm)))


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
