"""frirom.reduction.eigen (f2py -> frirom_eigen) against a closed form, and its errors.

Free-free chain of n unit masses and n-1 unit springs: lambda_j = 2 - 2 cos(j pi / n),
j = 0..n-1 (one rigid-body mode). Tolerance 1e-12 absolute: eigenvalues are O(1e-3..1)
and ARPACK converges to machine precision.
"""

import numpy as np
import pytest
import scipy.sparse as sp

from frirom import NonFiniteError, SingularMatrixError
from frirom.reduction.eigen import eigsh_shift_invert

N = 300


def _chain():
    K = sp.diags([-np.ones(N - 1), 2 * np.ones(N), -np.ones(N - 1)], [-1, 0, 1]).tolil()
    K[0, 0] = K[N - 1, N - 1] = 1.0
    return K.tocsr(), sp.identity(N, format="csr")


def test_free_free_chain_with_negative_shift():
    K, M = _chain()
    lam, phi, x = eigsh_shift_invert(K, M, 8, sigma=-0.01)
    exact = 2 - 2 * np.cos(np.arange(8) * np.pi / N)
    assert np.max(np.abs(lam - exact)) < 1e-12
    assert np.max(np.abs(phi.T @ phi - np.eye(8))) < 1e-10
    assert x is None


def test_static_solves_reuse_the_factor_of_k():
    K, M = _chain()
    K = K + sp.identity(N) * 1e-2            # grounded: K nonsingular
    b = np.random.default_rng(0).standard_normal((N, 4))
    lam, phi, x = eigsh_shift_invert(K, M, 3, sigma=0.5, rhs=b)
    assert np.max(np.abs(K @ x - b)) < 1e-10 * np.max(np.abs(b))
    assert np.allclose(b, np.random.default_rng(0).standard_normal((N, 4)))  # not clobbered


def test_singular_and_nonfinite_inputs_raise():
    K, M = _chain()
    with pytest.raises(SingularMatrixError, match="dmumps.*singular"):
        eigsh_shift_invert(K, M, 4)           # rigid-body mode, shift 0
    K2 = K.copy()
    K2.data[5] = np.nan
    with pytest.raises(NonFiniteError, match="NaN"):
        eigsh_shift_invert(K2, M, 4)
