"""The modal-damping kernel (fortran/frirom_damping.fypp, through
reduction.damping.modal_damping) against a closed-form 2-DoF model, the modal property
Phi^H C Phi = diag(2 zeta omega) with modes from scipy (real symmetric and complex
Hermitian models), and its failures named."""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from frirom._errors import NonFiniteError, NumericalError
from frirom.reduction.damping import modal_damping


def test_two_dof_closed_form():
    # ground - k1 - m1 - k2 - m2: omega^2 from m1 m2 w^4 - (m1 k2 + m2 (k1 + k2)) w^2 + k1 k2
    m1, m2, k1, k2 = 2.0, 0.5, 3.0e4, 1.0e4
    K = np.array([[k1 + k2, -k2], [-k2, k2]])
    M = np.diag([m1, m2])
    b = m1 * k2 + m2 * (k1 + k2)
    disc = np.sqrt(b * b - 4 * m1 * m2 * k1 * k2)
    w2 = np.array([(b - disc) / (2 * m1 * m2), (b + disc) / (2 * m1 * m2)])
    zeta = np.array([0.02, 0.05])
    terms = []
    for j in range(2):
        phi = np.array([1.0, (k1 + k2 - w2[j] * m1) / k2])     # first row of (K - w2 M) phi = 0
        phi /= np.sqrt(phi @ M @ phi)
        terms.append(2 * zeta[j] * np.sqrt(w2[j]) * np.outer(M @ phi, M @ phi))
    C, omega = modal_damping(K, M, zeta)
    assert np.allclose(omega, np.sqrt(w2), rtol=1e-14, atol=0)
    assert np.abs(C - terms[0] - terms[1]).max() <= 1e-12 * np.abs(C).max()
    C1, om1 = modal_damping(sp.csr_matrix(K), sp.csr_matrix(M), zeta[0], n_modes=1)
    assert om1.shape == (1,) and np.abs(C1 - C1.T).max() == 0.0
    assert np.abs(C1 - terms[0]).max() <= 1e-12 * np.abs(C1).max()


def random_model(n, rng, herm=False):
    A = rng.standard_normal((n, n)) + (1j * rng.standard_normal((n, n)) if herm else 0)
    B = rng.standard_normal((n, n)) + (1j * rng.standard_normal((n, n)) if herm else 0)
    return A @ A.conj().T + n * np.eye(n), B @ B.conj().T / n + np.eye(n)


@pytest.mark.parametrize("herm", [False, True])
def test_modal_property(herm):
    rng = np.random.default_rng(7)
    n, nm = 30, 12
    K, M = random_model(n, rng, herm)
    zeta = np.linspace(0.001, 0.08, nm)
    C, omega = modal_damping(K, M, zeta)
    lam, phi = sla.eigh(K, M)                       # independent modes (M-normalised)
    assert C.dtype == (complex if herm else float)
    assert np.allclose(omega, np.sqrt(lam[:nm]), rtol=1e-12, atol=0)
    D = phi.conj().T @ C @ phi
    want = np.zeros(n)
    want[:nm] = 2 * zeta * omega
    assert np.abs(D - np.diag(want)).max() <= 1e-10 * want.max()
    assert np.abs(C - C.conj().T).max() == 0.0


def test_rigid_body_mode_gets_no_damping():
    K = np.array([[1.0, -1.0], [-1.0, 1.0]])        # free-free: omega_1 = 0
    M = np.eye(2)
    C, omega = modal_damping(K, M, [0.05, 0.05])
    assert omega[0] == pytest.approx(0.0, abs=1e-7) and omega[1] == pytest.approx(np.sqrt(2))
    v = np.array([1.0, -1.0]) / np.sqrt(2)
    assert np.allclose(C, 2 * 0.05 * np.sqrt(2) * np.outer(v, v), rtol=1e-12, atol=1e-14)


def test_failures_are_named():
    K = np.diag([1.0, 2.0, 3.0])
    with pytest.raises(NumericalError, match="M is not positive definite"):
        modal_damping(K, np.diag([1.0, -1.0, 1.0]), 0.01)
    with pytest.raises(NumericalError, match="negative eigenvalue"):
        modal_damping(np.diag([-1.0, 2.0, 3.0]), np.eye(3), 0.01)
    with pytest.raises(NonFiniteError, match="NaN or Inf"):
        modal_damping(np.diag([np.nan, 2.0, 3.0]), np.eye(3), 0.01)
