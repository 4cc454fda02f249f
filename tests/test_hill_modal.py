"""Hill's method by the modes (issue 30 item 1): a condensed system whose receptances come
from real modes solves the Hill eigenproblem in modal coordinates, the modal part diagonal
per harmonic and the contact coupling by a Woodbury identity on the contact DoFs, so that a
dense reduced model of thousands of DoFs needs no band of every DoF.

References, independent of that code:
* the numpy Hill matrix of tests/test_stability.hill_reference (all 2 n (2H+1) exponents
  of the physical matrices, numpy's eig, frirom.contact.aft's Jacobian): the largest Re s of
  its strip |Im s| <= w/2, to 1e-8 of w (ARPACK's 1e-10 relative on the Ritz values of
  the shifted inverse);
* the banded Arnoldi path on the same model (formulation 'banded'), the same bound.
A model with every mode kept is exactly the physical one (the modal transformation is a
congruence), so both must agree to round-off.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.sparse as sp
from test_stability import hill_reference

from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import HILL_MAX, SolverOptions, solve_point


def dense_reduced(n=80, seed=3, alpha=0.01, beta=2e-4):
    """A reduced-model-like system: n DoFs, M = I + a dense low-rank coupling, a dense
    stiffness with modes from 1 to ~30 rad/s, Rayleigh damping (diagonal in the modes);
    a Jenkins element (kt 2, mu fn 0.15) on DoF 0 and a cubic spring between DoFs 0 and 1;
    the load on DoF 0."""
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    lam = np.r_[1.0, np.linspace(2.6, 30.0, n - 1)] ** 2
    b = 0.1 * rng.standard_normal((n, 3))
    M = np.eye(n) + b @ b.T
    L = np.linalg.cholesky(M)
    K = L @ q @ np.diag(lam) @ q.T @ L.T
    K = 0.5 * (K + K.T)
    G1 = sp.csr_matrix(([1.0], ([0], [0])), shape=(1, n))
    G2 = sp.csr_matrix(([1.0, -1.0], ([0, 0], [0, 1])), shape=(1, n))
    model = Model(M, K, Damping.rayleigh(alpha, beta),
                  [ContactGroup("jenkins", G1, [[2.0, 0.15, 1.0]], name="slider"),
                   ContactGroup("cubic", G2, [[0.0, 0.3]], name="spring")])
    F = np.zeros((n, 2), complex)
    F[0, 1] = 0.3
    return model, Excitation(F)


@pytest.mark.parametrize("w", [0.9, 1.1, 1.35])
@pytest.mark.parametrize("stability", [True, "strip"])
def test_modal_hill_matches_dense_reference_and_banded_path(w, stability):
    """Stick-slip (and, at 1.1, near resonance) points of the 80-DoF dense model: the modal
    routes' largest Re s (the exponents nearest 0 through the Newton matrix, and the whole
    strip by the modes) equal numpy's strip and the banded Arnoldi path's, 1e-8 of w."""
    model, ex = dense_reduced()
    H = 3
    assert 2 * model.n_dof * (2 * H + 1) > HILL_MAX
    base = dict(harmonics=H, samples=128)
    pm = solve_point(model, ex, w, SolverOptions(formulation="condensed",
                                                 receptances="modes", stability=stability,
                                                 **base),
                     outputs=np.arange(model.n_dof))
    pb = solve_point(model, ex, w, SolverOptions(formulation="banded", stability=True,
                                                 **base),
                     outputs=np.arange(model.n_dof))
    np.testing.assert_allclose(pm.X, pb.X, atol=1e-9 * np.abs(pb.X).max())
    assert abs(pm.floquet_max_re - pb.floquet_max_re) < 1e-8 * w, \
        (pm.floquet_max_re, pb.floquet_max_re)
    lam, _ = hill_reference(model, pb.X, w, pb.slider, 128)
    strip = lam[np.abs(lam.imag) <= w / 2].real.max()
    assert abs(pm.floquet_max_re - strip) < 1e-8 * w, (pm.floquet_max_re, strip)


def test_modal_hill_flags_the_saddle_branch_as_the_dense_path():
    """Duffing DoF and 80 uncoupled oscillators (tests/test_stability), receptances from
    all modes: the curve is the 1-DoF one (omega to 1e-9) and exactly its saddle branch
    between the two folds is unstable, as the dense path finds on the 1-DoF model; the
    route is logged."""
    from test_stability import OPTS, duffing_plus_oscillators

    from frirom.solver import frf
    small = frf(*duffing_plus_oscillators(0), 1.0, 2.0, SolverOptions(**OPTS), outputs=[0])
    big = frf(*duffing_plus_oscillators(80, zeta_e=0.2), 1.0, 2.0,
              SolverOptions(receptances="modes", **OPTS), outputs=[0])
    assert "Arnoldi at s = 0" in big.solver_info
    assert big.complete and big.stability_computed
    assert len(small) == len(big)
    np.testing.assert_allclose(big.omega, small.omega, rtol=1e-9)
    f1, f2 = np.where(big.fold)[0]
    expected = np.zeros(len(big), bool)
    expected[f1:f2] = True
    np.testing.assert_array_equal(~big.stable, expected)
    np.testing.assert_array_equal(big.stable, small.stable)


def test_truncated_modes_give_the_truncated_models_exponents():
    """Receptances from the lowest 75 of 80 modes: the exponents are those of the modal
    model itself (I, diag(w^2), diag(2 zeta w), contacts G Phi), solved here in the
    banded formulation (banded Arnoldi path), to 1e-8 of w."""
    import scipy.linalg as sla
    model, ex = dense_reduced()
    nm, H, w = 75, 3, 1.1
    w2, phi = sla.eigh(model.K.toarray() if sp.issparse(model.K) else model.K,
                       model.M.toarray() if sp.issparse(model.M) else model.M,
                       subset_by_index=[0, nm - 1])
    wn = np.sqrt(w2)
    zeta = (0.01 + 2e-4 * w2) / (2 * wn)
    groups = [ContactGroup(g.law, sp.csr_matrix(g.G @ phi), g.params, name=g.name)
              for g in model.contacts]
    reduced = Model(np.eye(nm), np.diag(w2), Damping.matrix(np.diag(2 * zeta * wn)), groups)
    red_ex = Excitation(phi.T @ ex.F)
    base = dict(harmonics=H, samples=128, stability=True)
    pm = solve_point(model, ex, w, SolverOptions(formulation="condensed", modes=nm, **base))
    pr = solve_point(reduced, red_ex, w, SolverOptions(formulation="banded", **base))
    assert 2 * nm * (2 * H + 1) > HILL_MAX
    assert abs(pm.floquet_max_re - pr.floquet_max_re) < 1e-8 * w, \
        (pm.floquet_max_re, pr.floquet_max_re)


def test_near0_in_contact_coordinates_matches_the_banded_path():
    """Two relative contacts (a Jenkins element between DoFs 0 and 2, a cubic spring
    between 1 and 3) on the 80-DoF dense model: 2 contact coordinates against 4 contact
    DoFs, so the s = 0 route (which works in either) leaves the solve on the shorter
    coordinates; its largest Re s equals the banded Arnoldi path's and the whole strip's
    (on the contact DoFs), 1e-8 of w."""
    model, ex = dense_reduced()
    n = model.n_dof
    G1 = sp.csr_matrix(([1.0, -1.0], ([0, 0], [0, 2])), shape=(1, n))
    G2 = sp.csr_matrix(([1.0, -1.0], ([0, 0], [1, 3])), shape=(1, n))
    model.contacts = [ContactGroup("jenkins", G1, [[2.0, 0.15, 1.0]], name="slider"),
                      ContactGroup("cubic", G2, [[0.0, 0.3]], name="spring")]
    from frirom._pack import pack
    base = dict(harmonics=3, samples=128)
    o0 = SolverOptions(formulation="condensed", receptances="modes", stability=True, **base)
    os_ = SolverOptions(formulation="condensed", receptances="modes", stability="strip",
                        **base)
    info = pack(model, ex, o0, None).info
    assert "2 contact coordinates" in info and "s = 0" in info, info
    assert "4 contact DoFs" in pack(model, ex, os_, None).info
    for w in (0.9, 1.1):
        p0 = solve_point(model, ex, w, o0)
        ps = solve_point(model, ex, w, os_)
        pb = solve_point(model, ex, w, SolverOptions(formulation="banded", stability=True,
                                                     **base))
        assert abs(p0.floquet_max_re - pb.floquet_max_re) < 1e-8 * w, \
            (p0.floquet_max_re, pb.floquet_max_re)
        assert abs(ps.floquet_max_re - pb.floquet_max_re) < 1e-8 * w


def test_stability_strip_is_an_option_and_bad_values_are_named():
    """'strip' is a valid stability value (the route it picks is checked above); another
    string is refused naming the values."""
    from frirom import ParameterError
    SolverOptions(stability="strip").check()
    with pytest.raises(ParameterError, match="'strip'"):
        SolverOptions(stability="full").check()
