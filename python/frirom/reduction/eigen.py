"""Sparse symmetric eigen-solves and static solves by the Fortran core (frirom_eigen).

ARPACK (dsaupd/dseupd) in shift-invert mode on K phi = lambda M phi, with MUMPS's sparse
LDL^T factor of K - sigma M (nested-dissection ordering); the same factor, or one of K
when sigma != 0, solves K x = rhs for many right-hand sides.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .. import _kernels
from .._errors import InputError, NonFiniteError, raise_for_status


def _upper_coo(A, name):
    U = sp.triu(sp.csr_matrix(A), format="coo")
    if U.nnz >= 2**31:
        raise InputError(f"{name} has more than 2^31 stored entries")
    return ((U.row + 1).astype(np.int32), (U.col + 1).astype(np.int32),
            np.ascontiguousarray(U.data, dtype=np.float64))


def default_ncv(n_modes: int, n: int) -> int:
    """Lanczos basis size used when ncv = 0: n_modes + 30 % + 10 (see frirom_eigen)."""
    return min(n, n_modes + (3 * n_modes) // 10 + 10)


def eigsh_shift_invert(K, M, n_modes: int, sigma: float = 0.0, rhs=None, tol: float = 0.0,
                       ncv: int = 0, maxiter: int = 500, overwrite_rhs: bool = False):
    """Lowest (nearest sigma) eigenpairs and optional static solves.

    K, M : (n, n) symmetric scipy.sparse matrices (full storage; only the upper triangle
        is used for the factorisation).
    n_modes : eigenpairs wanted (0: static solves only).
    sigma : shift [rad^2/s^2]; K - sigma M must be nonsingular.
    rhs : (n, n_rhs) array or None; solved as K x = rhs with the factor of K.
    tol : ARPACK relative tolerance (0 = machine precision); ncv : Lanczos basis size
        (0 = default_ncv); maxiter : ARPACK restarts allowed.
    overwrite_rhs : solve in place when rhs is a float64 Fortran-ordered array (saves a
        copy of an (n, n_rhs) block).

    Returns (lam (n_modes,) ascending, phi (n, n_modes) M-orthonormal, x (n, n_rhs) or None).
    """
    K = sp.csr_matrix(K)
    M = sp.csr_matrix(M)
    n = K.shape[0]
    if K.shape != (n, n) or M.shape != (n, n):
        raise InputError(f"K {K.shape} and M {M.shape} must be square and of one size")
    if n_modes < 0 or (n_modes > 0 and n_modes >= n - 1):
        raise InputError(f"n_modes = {n_modes}: expected 0 <= n_modes <= n - 2 = {n - 2}")
    for A, name in ((K, "K"), (M, "M")):
        if not np.all(np.isfinite(A.data)):
            raise NonFiniteError(f"{name} holds NaN or Inf")

    kr, kc, kv = _upper_coo(K, "K")
    mr, mc, mv = _upper_coo(M, "M")
    M.sort_indices()
    mptr = (M.indptr + 1).astype(np.int32)
    mind = (M.indices + 1).astype(np.int32)
    if rhs is None:
        x = np.zeros((n, 0), order="F")
    else:
        x = np.asfortranarray(rhs, dtype=np.float64)
        if x is rhs and not overwrite_rhs:
            x = x.copy(order="F")
    if x.ndim != 2 or x.shape[0] != n:
        raise InputError(f"rhs must be ({n}, n_rhs), got {x.shape}")
    lam, phi, info, msg = _kernels.eigen_shift_invert(
        kr, kc, kv, mr, mc, mv, mptr, mind, np.ascontiguousarray(M.data, dtype=np.float64),
        float(sigma), int(n_modes), x, int(ncv), float(tol), int(maxiter))
    raise_for_status(info, msg.decode(errors="replace") if isinstance(msg, bytes) else msg)
    return lam, phi, (None if rhs is None else x)
