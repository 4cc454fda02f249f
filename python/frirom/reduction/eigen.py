"""Sparse symmetric eigen-solves and static solves by the Fortran core (frirom_eigen).

ARPACK (dsaupd/dseupd) in shift-invert mode on K phi = lambda M phi, with MUMPS's sparse
LDL^T factor of K - sigma M (nested-dissection ordering); the same factor, or one of K
when sigma != 0, solves K x = rhs for many right-hand sides.

The modes returned are canonical (:func:`canonical_modes`): within a degenerate eigenvalue
(identical components: two blades, sectors) any rotation of the eigenvectors is an
eigenbasis, and which one ARPACK returns depends on rounding (threads, factorisation
order, start vector). Each degenerate subspace is turned to one basis fixed by the
subspace alone, and every mode's sign fixed, so the same files give the same basis on
every build.
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


#: Modes whose eigenvalues differ by at most this relative amount form one degenerate
#: subspace (round-off splits an exact degeneracy of identical components by ~1e-13-1e-10
#: relative; modes this close are not told apart by the reduction either).
DEGENERATE_RTOL = 1e-8

_GOLDEN = 0.6180339887498949


def _fixed_weights(n: int, shift: float) -> np.ndarray:
    """(n,) deterministic, distinct, generic weights in [-0.5, 0.5) (golden-ratio sequence):
    a fixed function of the DoF index, so that identical components get different
    weights."""
    return np.modf((np.arange(1, n + 1) + shift) * _GOLDEN)[0] - 0.5


def canonical_modes(lam, phi, rtol: float = DEGENERATE_RTOL):
    """The eigenbasis ``phi`` turned, in each degenerate subspace, to a basis fixed by the
    subspace (not by the basis given), and every column's sign fixed.

    lam : (k,) ascending eigenvalues; phi : (n, k) M-orthonormal eigenvectors.

    Modes i, i+1 belong to one subspace when |lam[i+1] - lam[i]| <= rtol * max(|lam|
    of the two, 1e3 eps max |lam|). A subspace B (n, m) is rotated by the eigenvectors V of
    B^T W B, W a fixed diagonal weighting of the DoFs (:func:`_fixed_weights`): for any
    rotation B Q of B, (B Q)^T W (B Q) has the eigenvectors Q^T V, so B V does not depend
    on Q (unique when the weighted eigenvalues are distinct, which generic weights make
    them). V is orthogonal, so B V stays M-orthonormal; its eigenvalues become the Rayleigh
    quotients diag(V^T diag(lam) V), equal to lam within rtol. Then each column's sign
    makes its dot product with a second fixed vector positive.

    Returns (lam (k,), phi (n, k)) new arrays.
    """
    lam = np.array(lam, dtype=float)
    phi = np.array(phi, dtype=float, order="F")
    n, k = phi.shape
    if k == 0:
        return lam, phi
    floor = 1e3 * np.finfo(float).eps * float(np.max(np.abs(lam)))
    w = None
    i = 0
    while i < k:
        j = i + 1
        while j < k and abs(lam[j] - lam[j - 1]) <= max(
                rtol * max(abs(lam[j]), abs(lam[j - 1])), floor):
            j += 1
        if j - i > 1:
            if w is None:
                w = _fixed_weights(n, 0.0)
            B = phi[:, i:j]
            C = B.T @ (w[:, None] * B)
            _, V = np.linalg.eigh(0.5 * (C + C.T))
            phi[:, i:j] = B @ V
            lam[i:j] = np.einsum("ij,i,ij->j", V, lam[i:j], V)
        i = j
    s = _fixed_weights(n, 0.5)
    flip = (s @ phi) < 0
    phi[:, flip] *= -1.0
    return lam, phi


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

    Returns (lam (n_modes,) ascending, phi (n, n_modes) M-orthonormal and canonical
    (:func:`canonical_modes`), x (n, n_rhs) or None).
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
    lam, phi = canonical_modes(lam, phi)
    return lam, phi, (None if rhs is None else x)
