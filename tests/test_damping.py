"""Damping of reduced models, checked on the eigenvalues of the first-order (state-space)
system, computed independently by a general eigen-solver."""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.linalg as sla

from _lattices import two_blocks
from frirom._errors import InputError, SizeError
from frirom.reduction.damping import modal_damping, rayleigh_coefficients, rayleigh_damping
from frirom.reduction.interface import gsi_basis, reduce_interface


@pytest.fixture(scope="module")
def rom():
    m = two_blocks(nx=4, ny=3, nz=3, seed=4)
    iface = np.unique(np.concatenate([m["dofs_a"].ravel(), m["dofs_b"].ravel()]))
    B, _ = gsi_basis(m["K"], m["M"], iface, m["active"], None, 12, 0)
    return reduce_interface(m["K"], m["M"], iface, B)


def state_space_modes(K, M, C):
    """Natural frequencies and damping ratios from the eigenvalues of the 2n system."""
    n = K.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    lam = sla.eigvals(A)
    lam = lam[lam.imag >= 0]                       # one of each conjugate pair
    wn = np.abs(lam)
    order = np.argsort(wn)
    return wn[order], (-lam.real / np.abs(lam))[order]


def test_modal_damping_gives_the_ratios(rom):
    n = rom.K.shape[0]
    zeta = np.linspace(0.002, 0.05, 10)
    C, omega = modal_damping(rom.K, rom.M, zeta)
    wn, z = state_space_modes(rom.K, rom.M, C)
    w_ref = np.sqrt(sla.eigh(rom.K, rom.M, eigvals_only=True))
    # damped modes: |lambda| = omega_j, zeta_j as asked; the others stay undamped
    assert np.abs(wn / w_ref - 1).max() < 1e-8
    assert np.abs(z[:10] - zeta).max() < 1e-9
    assert np.abs(z[10:]).max() < 1e-9
    assert np.abs(omega / w_ref[:10] - 1).max() < 1e-12
    C1, _ = modal_damping(rom.K, rom.M, 0.01)            # scalar: every mode
    _, z1 = state_space_modes(rom.K, rom.M, C1)
    assert np.abs(z1 - 0.01).max() < 1e-9 and C1.shape == (n, n)


def test_rayleigh_fits_two_ratios(rom):
    w = np.sqrt(sla.eigh(rom.K, rom.M, eigvals_only=True))
    f1, f2 = w[0] / (2 * np.pi), w[8] / (2 * np.pi)
    a, b = rayleigh_coefficients(f1, 0.02, f2, 0.01)
    C = rayleigh_damping(rom.K, rom.M, a, b)
    wn, z = state_space_modes(rom.K, rom.M, C)
    assert abs(z[0] - 0.02) < 1e-9 and abs(z[8] - 0.01) < 1e-9
    assert np.allclose(z, a / (2 * w) + b * w / 2, rtol=1e-8, atol=0)


def test_bad_damping_input(rom):
    with pytest.raises(InputError):
        modal_damping(rom.K, rom.M, -0.01)
    with pytest.raises(SizeError):
        modal_damping(rom.K, rom.M, [0.01, 0.02], n_modes=3)
    with pytest.raises(InputError):
        rayleigh_coefficients(10.0, 0.01, 10.0, 0.02)
