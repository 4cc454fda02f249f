"""Reproducible reductions (issue 29 item 6): identical components have degenerate modes,
and any rotation of a degenerate eigenbasis is an eigenbasis; which one ARPACK returns
depends on rounding (threads, ordering, start vector), so byte-identical FE files gave
another Craig-Bampton basis, and the same FRF took other points. The modes are now
canonical: the same subspace gives the same basis to round-off whatever basis of it the
eigen-solver found.

Model: two identical, uncoupled spring-mass chains ("blades", 150 DoFs each, grounded at
the root): every mode is doubly degenerate. Perturbations: the stiffness scaled by
(1 + 1e-14 r), r a random symmetric pattern (a build whose factorisation rounds
otherwise), and scipy's ARPACK from two random start vectors against frirom's."""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from frirom.reduction.cb import craig_bampton
from frirom.reduction.eigen import canonical_modes, eigsh_shift_invert


def _blades(n=150):
    k = 1e6 * (1 + 0.5 * np.sin(np.arange(n)))          # not uniform: no extra symmetry
    main = np.r_[k[:-1] + k[1:], k[-1]]
    Kb = sp.diags([main, -k[1:], -k[1:]], [0, -1, 1])
    Mb = sp.diags(0.01 * (1 + 0.3 * np.cos(np.arange(n))))
    return sp.block_diag([Kb, Kb]).tocsr(), sp.block_diag([Mb, Mb]).tocsr()


def _perturbed(K, seed):
    rng = np.random.default_rng(seed)
    U = sp.triu(K).tocoo()
    U.data = U.data * (1 + 1e-14 * rng.standard_normal(U.nnz))
    return (U + sp.triu(U, 1).T).tocsr()


def _same(a, b, tol):
    return np.max(np.abs(a - b)) <= tol * np.max(np.abs(b))


def test_degenerate_modes_same_basis_on_every_build():
    K, M = _blades()
    nm = 8
    lam0, phi0, _ = eigsh_shift_invert(K, M, nm)
    assert np.allclose(lam0[0::2], lam0[1::2], rtol=1e-10)      # degenerate pairs
    # round-off in the matrices: the same basis to round-off (1e-8: the subspaces move by
    # ~1e-14 / the relative gap to the next pair)
    for seed in (1, 2):
        lam, phi, _ = eigsh_shift_invert(_perturbed(K, seed), M, nm)
        assert _same(phi, phi0, 1e-8), seed
    # scipy's ARPACK from random start vectors: the same basis as frirom's
    for seed in (3, 4):
        v0 = np.random.default_rng(seed).standard_normal(K.shape[0])
        lam, phi = spla.eigsh(K.tocsc(), k=nm, M=M.tocsc(), sigma=0.0, v0=v0)
        lam, phi = canonical_modes(lam, phi)
        assert _same(phi, phi0, 1e-8), seed
        np.testing.assert_allclose(lam, lam0, rtol=1e-10)
    # still M-orthonormal eigenvectors
    np.testing.assert_allclose(phi0.T @ (M @ phi0), np.eye(nm), atol=1e-10)
    np.testing.assert_allclose(phi0.T @ (K @ phi0), np.diag(lam0), atol=1e-8 * lam0.max())


def test_craig_bampton_basis_reproducible():
    # the blades' roots and tips are masters; the fixed-interface modes, degenerate in
    # pairs, give the same CB basis (and reduced matrices) on a perturbed build and with
    # the scipy solver
    K, M = _blades()
    masters = [0, 149, 150, 299]
    a = craig_bampton((K, M), 10, masters=masters)
    b = craig_bampton((_perturbed(K, 7), M), 10, masters=masters)
    c = craig_bampton((K, M), 10, masters=masters, solver="scipy")
    for other in (b, c):
        assert _same(other.phi, a.phi, 1e-8)
        assert _same(other.M, a.M, 1e-8) and _same(other.K, a.K, 1e-8)


def test_a_non_degenerate_basis_is_left_alone():
    # distinct eigenvalues: the eigenvectors themselves, only signs fixed
    K, M = _blades()
    K2 = K + sp.diags(np.r_[np.zeros(150), np.full(150, 1e4)])    # blade 2 stiffer
    lam, phi, _ = eigsh_shift_invert(K2, M, 6)
    ref_lam, ref = spla.eigsh(K2.tocsc(), k=6, M=M.tocsc(), sigma=0.0)
    for j in range(6):
        assert abs(abs(ref[:, j] @ (M @ phi[:, j])) - 1) < 1e-8
