"""Hill stability (issue 9 item 1): which Floquet exponents are kept, and the Arnoldi path
for models above HILL_MAX, against the dense path, closed forms and time integration.

The cause of the issue: every exponent of the truncated Hill matrix appears 2H+1 times,
shifted by i h omega with its eigenvector shifted by h harmonics. The old selection kept the
2 n_dof with the smallest |Im s|. A reduced FE model has most of its modes far above
H omega, whose copies all have large |Im s|; the 2 n_dof smallest were then mostly
off-centre copies of the few low modes (58 of 66 on the issue's cantilever). For a
friction law these copies are not copies at all (the AFT Jacobian of a hysteretic law is
not block-Toeplitz) and some have Re s = +242 1/s at points that time integration finds
stable. Now the exponents whose eigenvectors are centred on harmonic 0 are kept.

Tolerances and why:
* Arnoldi against dense: the same eigenvalues by two algorithms; ARPACK's tolerance is
  1e-10 relative to the Ritz values of (A - sigma)^-1, so 1e-8 of omega absolute.
* Closed form: a linear oscillator uncoupled from the rest has the exponents
  -zeta w_e +- i w_e sqrt(1 - zeta^2), the same bound.
* Time integration (frirom.timeint, explicit, written from the physics): a perturbation of
  the HB solution must not grow where Hill says stable; the old verdicts (+240 1/s on the
  cantilever) predict growth by e^(Re T) per period, >= 1.3 per period, so a factor 10
  over the integration is far beyond the integration's own error.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.sparse as sp

from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import HILL_MAX, SolverOptions, frf, solve_point
from frirom.timeint import TimeContact, integrate, state_from_harmonics

# Duffing x'' + 0.02 x' + x + 0.5 x^3 = 0.1 cos(w t), as in test_solver_core
DUF_C, DUF_K3, DUF_F = 0.02, 0.5, 0.1


def duffing_plus_oscillators(n_extra=0, w_e=2.2, zeta_e=0.05):
    """The Duffing DoF 0 and n_extra uncoupled unit-mass oscillators: the first at w_e
    (inside the windows the Arnoldi path scans, damping ratio zeta_e), the others at
    8..60 rad/s (zeta 0.02), above every window of H = 3 for w < 2."""
    w = np.r_[1.0, np.r_[w_e, np.linspace(8.0, 60.0, max(n_extra - 1, 0))][:n_extra]]
    z = np.r_[DUF_C / 2, np.r_[zeta_e, np.full(max(n_extra - 1, 0), 0.02)][:n_extra]]
    n = w.size
    G = sp.csr_matrix(([1.0], ([0], [0])), shape=(1, n))
    model = Model(sp.identity(n), sp.diags(w ** 2), Damping.matrix(sp.diags(2 * z * w)),
                  [ContactGroup("cubic", G, [[0.0, DUF_K3]], name="duffing")])
    F = np.zeros((n, 2), complex)
    F[0, 1] = DUF_F
    return model, Excitation(F)


OPTS = dict(harmonics=3, samples=32, formulation="condensed", stability=True)


@pytest.fixture(scope="module")
def duffing_curves():
    small = frf(*duffing_plus_oscillators(0), 0.5, 2.0, SolverOptions(**OPTS), outputs=[0])
    big_model, big_ex = duffing_plus_oscillators(80)
    assert 2 * big_model.n_dof * 7 > HILL_MAX        # the Arnoldi path
    big = frf(big_model, big_ex, 0.5, 2.0, SolverOptions(**OPTS), outputs=[0])
    return small, big


def test_unstable_branch_between_folds_flagged_by_both_paths(duffing_curves):
    """Exactly the saddle branch between the two folds is unstable, dense and Arnoldi."""
    for r in duffing_curves:
        assert r.complete and r.stability_computed
        f1, f2 = np.where(r.fold)[0]
        expected = np.zeros(len(r), bool)
        expected[f1:f2] = True          # fold flags sit on the first point past each turn
        np.testing.assert_array_equal(~r.stable, expected)
    small, big = duffing_curves
    assert len(small) == len(big)
    np.testing.assert_allclose(big.omega, small.omega, rtol=1e-9)


@pytest.mark.parametrize("w", [0.8, 1.2, 1.9])
def test_arnoldi_exponents_match_dense_and_closed_form(w):
    """The largest Re s on the 81-DoF model: the Duffing DoF's (dense path on the 1-DoF
    model) when the in-window oscillator is damped more, and -zeta w_e (closed form) when
    it is damped less."""
    o = SolverOptions(**OPTS)
    ref = solve_point(*duffing_plus_oscillators(0), w, o).floquet_max_re
    assert ref < 0
    big = solve_point(*duffing_plus_oscillators(80, zeta_e=0.2), w, o)
    assert abs(big.floquet_max_re - ref) < 1e-8 * w, (big.floquet_max_re, ref)
    w_e, zeta_e = 2.2, 1e-3
    light = solve_point(*duffing_plus_oscillators(80, w_e, zeta_e), w, o)
    assert abs(light.floquet_max_re + zeta_e * w_e) < 1e-8 * w, light.floquet_max_re
