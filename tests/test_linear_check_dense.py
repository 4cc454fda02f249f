"""The linear check of a dense (reduced) model by its modes (frirom.modes._response): equal
to a sparse solve per frequency where the modes diagonalise the damping (Rayleigh, free
structure), the normal-mode approximation said in the notes where they do not (the stuck
structure under the free structure's damping), an exact solve when no notes are kept."""

import numpy as np
import scipy.sparse as sp

from frirom import modes


def _dense_model(n=320, seed=3):
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((n, n)) / np.sqrt(n)
    K = a @ a.T + np.eye(n)
    M = np.eye(n) + 0.1 * np.diag(rng.random(n))
    C = 1e-3 * K + 0.2 * M
    F = np.zeros((n, 3), complex)
    F[:5, 1] = 1.0
    F[7, 2] = 0.3j
    return sp.csr_matrix(K), sp.csr_matrix(M), sp.csr_matrix(C), F


def _by_solves(K, M, C, F, out, omega):
    saved = modes.DENSE_MIN
    try:
        modes.DENSE_MIN = 10 ** 9
        return modes._response(K, M, C, F, out, omega)
    finally:
        modes.DENSE_MIN = saved


def test_modal_sum_equals_the_solve_per_frequency():
    K, M, C, F = _dense_model()
    out = [0, 11, 200]
    omega = np.linspace(0.2, 2.5, 25)
    notes = []
    got = modes._response(K, M, C, F, out, omega, notes, "free")
    ref = _by_solves(K, M, C, F, out, omega)
    assert not notes
    np.testing.assert_allclose(got, ref, rtol=1e-9)


def test_stuck_modes_under_free_damping_noted_or_solved():
    K, M, C, F = _dense_model()
    Ks = K + sp.csr_matrix(np.diag(np.r_[np.full(20, 5.0), np.zeros(K.shape[0] - 20)]))
    out = [0, 11]
    omega = np.linspace(0.2, 2.5, 25)
    notes = []
    approx = modes._response(Ks, M, C, F, out, omega, notes, "stuck")
    assert len(notes) == 1 and "left out" in notes[0] and "stuck" in notes[0]
    exact = modes._response(Ks, M, C, F, out, omega)          # no notes: solved exactly
    np.testing.assert_allclose(exact, _by_solves(Ks, M, C, F, out, omega), rtol=1e-12)
    # the approximation is close but not equal (light damping)
    rel = np.abs(approx - exact).max() / exact.max()
    assert 0 < rel < 0.05
