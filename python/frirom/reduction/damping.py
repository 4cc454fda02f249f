"""Viscous damping of an assembled (reduced) model: modal damping ratios or Rayleigh.

Modal: with the mass-normalised modes Phi of (K, M) and their circular frequencies omega,
C = M Phi diag(2 zeta omega) Phi^H M, so that mode j has damping ratio zeta_j exactly and
the modes stay uncoupled (the paper's choice for the assembled ROM, after Eq. 16). Modes
beyond the ratios given get none. The kernel is the Fortran library's
(fortran/frirom_damping.fypp), the one frirom_solve uses for C and legacy callers. Rayleigh: C = alpha M + beta K, with
:func:`rayleigh_coefficients` fitting two (frequency, ratio) pairs.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .. import _kernels
from .._errors import CODES, InputError, NumericalError, SizeError, raise_for_status

__all__ = ["modal_damping", "rayleigh_coefficients", "rayleigh_damping"]


def _dense(A):
    return A.toarray() if sp.issparse(A) else np.asarray(A)


def modal_damping(K, M, zeta, n_modes: int | None = None):
    """Modal damping matrix of a reduced model.

    K, M: (n, n) stiffness and mass (dense or sparse; real symmetric or complex Hermitian);
    zeta: damping ratio, a scalar for every damped mode or (n_modes,) per mode in order of
    increasing frequency; n_modes: modes that get damping (default: len(zeta), or all n for
    a scalar). Returns (C (n, n) dense, omega (n_modes,) rad/s of the damped modes).
    """
    Kd, Md = _dense(K), _dense(M)
    n = Kd.shape[0]
    if Kd.shape != (n, n) or Md.shape != (n, n):
        raise SizeError(f"modal_damping: K {Kd.shape} and M {Md.shape} must be square, equal")
    z = np.atleast_1d(np.asarray(zeta, dtype=float))
    if z.ndim != 1 or not np.all(np.isfinite(z)) or np.any(z < 0):
        raise InputError("modal_damping: zeta must be finite ratios >= 0")
    if n_modes is None:
        n_modes = n if z.size == 1 else z.size
    if not 1 <= n_modes <= n:
        raise InputError(f"modal_damping: n_modes must lie in 1..{n}, got {n_modes}")
    if z.size == 1:
        z = np.full(n_modes, z[0])
    elif z.size != n_modes:
        raise SizeError(f"modal_damping: {z.size} ratios for {n_modes} modes")
    # the kernel reads the lower triangles (as scipy's eigh does by default)
    herm = np.iscomplexobj(Kd) or np.iscomplexobj(Md)
    dtype = complex if herm else float
    kernel = _kernels.modal_damping_hermitian if herm else _kernels.modal_damping
    C, omega, info, msg = kernel(np.asfortranarray(Kd, dtype=dtype),
                                 np.asfortranarray(Md, dtype=dtype), z)
    if info != 0:
        text = msg.decode(errors="replace").strip()
        if info in (CODES["FRIROM_ERR_SIZE"], CODES["FRIROM_ERR_NONFINITE"],
                    CODES["FRIROM_ERR_PARAM"]):
            raise_for_status(info, text)
        # M not positive definite, K with a negative eigenvalue, a failed eigen-solve
        raise NumericalError(text, code=int(info))
    return C, omega


def rayleigh_coefficients(f1: float, zeta1: float, f2: float, zeta2: float):
    """(alpha [1/s], beta [s]) so that zeta(f) = alpha / (2 w) + beta w / 2 hits both pairs.

    f1, f2: distinct frequencies [Hz]; zeta1, zeta2: the damping ratios there.
    """
    if not (f1 > 0 and f2 > 0 and f1 != f2):
        raise InputError(f"rayleigh_coefficients: need two distinct frequencies > 0, got "
                         f"{f1}, {f2}")
    w1, w2 = 2 * np.pi * f1, 2 * np.pi * f2
    A = np.array([[1 / (2 * w1), w1 / 2], [1 / (2 * w2), w2 / 2]])
    alpha, beta = np.linalg.solve(A, [zeta1, zeta2])
    return float(alpha), float(beta)


def rayleigh_damping(K, M, alpha: float, beta: float):
    """C = alpha M + beta K (same storage as K and M)."""
    if not (np.isfinite(alpha) and np.isfinite(beta)):
        raise InputError("rayleigh_damping: alpha and beta must be finite")
    if K.shape != M.shape:
        raise SizeError(f"rayleigh_damping: K {K.shape} and M {M.shape} differ")
    return alpha * M + beta * K
