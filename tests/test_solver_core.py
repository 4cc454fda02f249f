"""Harmonic balance solver core: condensed vs banded formulations, linear closed forms,
continuation through folds, results files and resume, model validation."""

import numpy as np
import pytest
import scipy.sparse as sp

import frirom
from _models import duffing
from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.results import FRF, FRFWriter
from frirom.solver import HILL_MAX, SolverOptions, frf, solve_point


def chain(n=6, k=1e5, masses=None):
    K = (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)) * k
    K[-1, -1] = k
    M = np.diag(masses if masses is not None else np.linspace(1.0, 1.5, n))
    return M, K


def friction_model():
    """6-DoF chain plus a separate normal oscillator (DoF 6): a Jenkins element DoF 1 to
    ground, a Jenkins element between DoFs 2 and 5, and a 1-D normal-load element
    (tangential DoF 3, normal DoF 6) kept closed by a 50 N preload whose normal load varies
    with DoF 6. The preload moves only DoF 6 statically, so no element sits statically on
    its slip limit (a non-differentiable point where Newton stalls near 1e-8)."""
    n = 7
    M, K = chain(6)
    M = np.diag(np.r_[np.diag(M), 0.5])
    K = np.block([[K, np.zeros((6, 1))], [np.zeros((1, 6)), 2e5 * np.ones((1, 1))]])
    g1 = ContactGroup("jenkins", sp.csr_matrix(([1.0, 1.0, -1.0], ([0, 1, 1], [1, 2, 5])),
                                               shape=(2, n)),
                      [[2e5, 0.3, 10.0], [1e5, 0.2, 5.0]], name="jen")
    g2 = ContactGroup("normal1d", sp.csr_matrix(([1.0, 1.0], ([0, 1], [3, 6])), shape=(2, n)),
                      [[1e5, 2e5, 0.5, 50.0]], name="n1d")
    model = Model(M, K, Damping.rayleigh(2.0, 1e-6), [g1, g2])
    F = np.zeros((n, 2), complex)
    F[5, 1] = 8.0
    F[2, 1] = 3.0j
    F[6, 1] = 5.0
    return model, Excitation(F)


@pytest.mark.parametrize("omega", [60.0, 120.0, 180.0, 260.0])
def test_condensed_and_banded_agree(omega):
    """Both formulations solve the same equations; with tight tolerances their output
    harmonics agree to 1e-8 relative (the Newton tolerance is 1e-11, the rest is the
    conditioning of the two linear algebras)."""
    model, ex = friction_model()
    xs = {}
    for form in ("condensed", "banded"):
        o = SolverOptions(harmonics=5, samples=128, formulation=form, tol_residual=1e-11,
                          tol_update=1e-11, max_iter=60)
        p = solve_point(model, ex, omega, o)
        xs[form] = p.X
        assert p.state_fractions.shape == (2, 3)
    scale = np.abs(xs["banded"]).max()
    assert np.abs(xs["condensed"] - xs["banded"]).max() <= 1e-8 * scale


def test_frf_condensed_and_banded_agree_at_end():
    """Same FRF run in both formulations: the last point is solved exactly at omega_end.
    The range stops below 160 rad/s, where the normal-load element enters stick-all-cycle:
    there the AFT restarts its slider from w0 = 0, so R jumps (see the solver notes)."""
    model, ex = friction_model()
    ends = {}
    for form in ("condensed", "banded"):
        o = SolverOptions(harmonics=3, samples=100, formulation=form, tol_residual=1e-11,
                          tol_update=1e-11)
        r = frf(model, ex, 100.0, 155.0, o, outputs=[0, 5])
        assert r.complete, r.message
        assert r.omega[-1] == 155.0
        ends[form] = r.X[-1]
    assert np.abs(ends["condensed"] - ends["banded"]).max() <= 1e-8 * np.abs(ends["banded"]).max()


@pytest.mark.parametrize("form", ["condensed", "banded"])
def test_linear_limit_matches_direct_solve(form):
    """A cubic element with k3 = 0 is a linear spring: the response is (K + k1 e e^T
    + i w C - w^2 M)^-1 F exactly (to solver tolerance)."""
    n = 5
    M, K = chain(n, 1.0, np.ones(n))
    G = sp.csr_matrix(([1.0], ([0], [2])), shape=(1, n))
    model = Model(M, K, Damping.rayleigh(0.01, 0.001),
                  [ContactGroup("cubic", G, [[0.7, 0.0]], name="lin")])
    F = np.zeros((n, 3), complex)
    F[0, 1] = 0.3 - 0.1j
    F[4, 2] = 0.05j
    F[1, 0] = 0.02
    w = 0.8
    o = SolverOptions(harmonics=2, samples=16, formulation=form)
    p = solve_point(model, Excitation(F), w, o)
    Kt = K.copy()
    Kt[2, 2] += 0.7
    C = model.C.toarray()
    for h in range(3):
        Xh = np.linalg.solve(Kt + 1j * h * w * C - (h * w) ** 2 * M, F[:, h])
        if h == 0:
            np.testing.assert_allclose(p.X[:, 0], Xh.real, rtol=1e-9, atol=1e-14)
        else:
            np.testing.assert_allclose(p.X[:, 2 * h - 1], Xh.real, rtol=1e-9, atol=1e-14)
            np.testing.assert_allclose(p.X[:, 2 * h], -Xh.imag, rtol=1e-9, atol=1e-14)


@pytest.mark.parametrize("form", ["condensed", "banded"])
def test_duffing_folds_and_single_harmonic_closed_form(form):
    """H = 1: every point satisfies the single-harmonic amplitude equation
    ((1 - w^2) A + 3/4 k3 A^3)^2 + (c w A)^2 = F^2; the continuation passes the two
    turning points of the hardening branch and flags them."""
    model, ex = duffing()
    o = SolverOptions(harmonics=1, samples=16, formulation=form, tol_residual=1e-12,
                      tol_update=1e-12)
    r = frf(model, ex, 0.5, 2.0, o, outputs=[0])
    assert r.complete, r.message
    A = np.hypot(r.X[:, 0, 1], r.X[:, 0, 2])
    w = r.omega
    res = ((1 - w**2) * A + 0.375 * A**3) ** 2 + (0.02 * w * A) ** 2 - 0.01
    assert np.abs(res).max() < 1e-9
    turns = np.sum(np.diff(np.sign(np.diff(w))) != 0)
    assert turns == 2
    assert r.fold.sum() == 2
    assert A.max() > 1.5     # the resonant branch was followed up the backbone


def test_results_files_and_resume(tmp_path):
    """HDF5/CSV round trip; a run cut short by max_points and resumed from its file ends
    at the same solution as an uninterrupted run."""
    model, ex = duffing()
    o = SolverOptions(harmonics=3, samples=32, formulation="condensed",
                      tol_residual=1e-12, tol_update=1e-12)
    got = []
    full = frf(model, ex, 0.5, 2.0, o, outputs=[0], sink=got.append)
    assert [p.omega for p in got] == list(full.omega)   # every point, in order, once
    assert all(p.yscale > 0 for p in got)
    full.save_h5(tmp_path / "a.h5")
    full.save_csv(tmp_path / "a.csv")
    back = FRF.load(tmp_path / "a.h5")
    np.testing.assert_array_equal(back.X, full.X)
    np.testing.assert_array_equal(back.fold, full.fold)
    assert (tmp_path / "a.csv").read_text().count("\n") == len(full) + 1

    path = tmp_path / "run.h5"
    w = FRFWriter(path, [0], ["duffing"], 3)
    short = frf(model, ex, 0.5, 2.0, SolverOptions(**{**o.__dict__, "max_points": 40}),
                outputs=[0], sink=w.append)
    w.close(complete=short.complete, message=short.message)
    assert not short.complete and len(short) == 40
    start = FRFWriter.resume_point(path)
    w = FRFWriter(path, [0], ["duffing"], 3, append=True)
    rest = frf(model, ex, 0.5, 2.0, o, outputs=[0], sink=w.append, start=start)
    w.close()
    assert rest.complete
    saved = FRF.load(path)
    assert len(saved) == 40 + len(rest)
    np.testing.assert_allclose(saved.X[-1], full.X[-1], rtol=0, atol=1e-9)


def test_start_from_lower_harmonics():
    model, ex = duffing()
    p1 = solve_point(model, ex, 1.2, SolverOptions(harmonics=1, samples=16))
    o5 = SolverOptions(harmonics=5, samples=64)
    p5 = solve_point(model, ex, 1.2, o5, start={"unknowns": p1.unknowns}, start_harmonics=1)
    assert p5.iterations <= 6
    assert p5.X.shape == (1, 11)
    assert abs(np.hypot(*p5.X[0, 1:3]) - np.hypot(*p1.X[0, 1:3])) < 0.05 * np.hypot(*p1.X[0, 1:3])


def test_frf_from_a_solve_point_start():
    """A point solved at fixed frequency carries a tangent in no arc-length scale (its
    solve ran with the purely relative one): frf(start=it) takes a new tangent from the
    point and follows the same curve as a run from nothing (found by review: for a while
    such points carried the relative scale 1e-300, the resumed predictor did not move y,
    and the run stopped at its first step). Peaks within 1e-8 (both converge to 1e-12)."""
    model, ex = duffing()
    o = SolverOptions(harmonics=3, samples=32, tol_residual=1e-12, tol_update=1e-12)
    p = solve_point(model, ex, 0.5, o, outputs=[0])
    assert p.yscale == 0.0
    ref = frf(model, ex, 0.5, 2.0, o, outputs=[0])
    run = frf(model, ex, 0.5, 2.0, o, outputs=[0], start=p)
    assert ref.complete and run.complete
    assert abs(run.peak(0).amplitude / ref.peak(0).amplitude - 1) < 1e-8
    assert abs(run.peak(0).omega / ref.peak(0).omega - 1) < 1e-8


def test_model_validation_names_the_field():
    M, K = chain(3)
    with pytest.raises(frirom.SizeError, match="K"):
        Model(M, K[:2, :2])
    Kb = K.copy()
    Kb[0, 1] += 1.0
    with pytest.raises(frirom.ParameterError, match="K: must be symmetric"):
        Model(M, Kb)
    with pytest.raises(frirom.ParameterError, match="M"):
        Model(-M, K)
    with pytest.raises(frirom.NonFiniteError, match="M"):
        Model(M * np.nan, K)
    G = sp.csr_matrix(([1.0], ([0], [0])), shape=(1, 3))
    with pytest.raises(frirom.ParameterError, match="law 'coulomb' unknown"):
        ContactGroup("coulomb", G, [[1.0]])
    with pytest.raises(frirom.SizeError, match="params"):
        ContactGroup("jenkins", G, [[1.0, 0.3]])
    with pytest.raises(frirom.ParameterError, match="mu"):
        ContactGroup("jenkins", G, [[1.0, -0.3, 1.0]])
    with pytest.raises(frirom.SizeError, match="rows"):
        ContactGroup("normal1d", G, [[1.0, 1.0, 0.3, 1.0]])
    with pytest.raises(frirom.SizeError, match="columns"):
        Model(M, K, contacts=[ContactGroup("jenkins", sp.csr_matrix((1, 4)), [[1, .3, 1]])])
    with pytest.raises(frirom.ParameterError, match="zeta"):
        Damping.modal([0.01, 1.5])
    with pytest.raises(frirom.SizeError, match="excitation.F"):
        Excitation(np.zeros((2, 2))).real_harmonic(3, 1)
    with pytest.raises(frirom.ParameterError, match="options.formulation"):
        SolverOptions(formulation="dense").check()
    with pytest.raises(frirom.ParameterError, match="options.samples"):
        SolverOptions(harmonics=5, samples=8).check()


def test_modal_damping_gives_the_requested_ratios():
    """C from modal ratios: Phi^T C Phi = diag(2 zeta w) for the mass-normalised modes."""
    import scipy.linalg as sla
    M, K = chain(4)
    z = [0.01, 0.02, 0.03, 0.04]
    model = Model(M, K, Damping.modal(z))
    w2, phi = sla.eigh(K, M)
    d = phi.T @ model.C.toarray() @ phi
    np.testing.assert_allclose(np.diag(d), 2 * np.array(z) * np.sqrt(w2), rtol=1e-10)


@pytest.mark.parametrize("form", ["condensed", "banded"])
def test_hill_stability_duffing_middle_branch(form):
    """Hill's method: on the hardening Duffing curve exactly the points between the two
    folds (the saddle branch) are unstable; the friction model's curve (no fold) is stable
    everywhere."""
    model, ex = duffing()
    r = frf(model, ex, 0.5, 2.0, SolverOptions(harmonics=3, samples=32, formulation=form,
                                               stability=True), outputs=[0])
    assert r.complete and r.stability_computed
    f1, f2 = np.where(r.fold)[0]
    expected = np.zeros(len(r), bool)
    expected[f1:f2] = True          # fold flags sit on the first point past each turn
    np.testing.assert_array_equal(~r.stable, expected)
    model, ex = friction_model()
    r = frf(model, ex, 100.0, 155.0, SolverOptions(harmonics=3, samples=100, formulation=form,
                                                   stability=True), outputs=[0])
    assert r.complete and r.stable.all()


@pytest.mark.parametrize("form", ["condensed", "banded"])
def test_load_continuation_ends_on_the_frequency_solution(form):
    """Continuation in the excitation level at fixed omega from 0 to 1 ends on the same
    solution as the direct solve at that omega (on the resonant branch below the fold,
    where the solution is unique); the static preload is kept fixed."""
    from frirom.solver import load_curve
    model, ex = friction_model()
    o = SolverOptions(harmonics=3, samples=100, formulation=form, tol_residual=1e-11,
                      tol_update=1e-11)
    r = load_curve(model, ex, 130.0, 0.0, 1.0, o, outputs=[0, 5])
    assert r.complete and r.parameter[-1] == 1.0 and r.parameter_name == "load"
    assert np.all(r.omega == 130.0)
    p = solve_point(model, ex, 130.0, o, outputs=[0, 5])
    np.testing.assert_allclose(r.X[-1], p.X, rtol=0, atol=1e-8 * np.abs(p.X).max())
    # at zero dynamic load the response is static only
    assert np.abs(r.X[0][:, 1:]).max() <= 1e-12 * np.abs(p.X).max()


def test_modal_superposition_with_all_modes_matches_banded():
    """Condensed receptances from all modes with modal damping ratios are the exact
    inverse of K + i h w C - (h w)^2 M when C is built from the same ratios: the answer
    equals the banded formulation's (1e-8), along an FRF end point and a single point."""
    model, ex = friction_model()
    n = model.n_dof
    model = Model(model.M, model.K, Damping.modal(np.linspace(0.01, 0.03, n)),
                  model.contacts)
    kw = dict(harmonics=3, samples=100, tol_residual=1e-11, tol_update=1e-11)
    pb = solve_point(model, ex, 120.0, SolverOptions(formulation="banded", **kw))
    pm = solve_point(model, ex, 120.0, SolverOptions(formulation="condensed", modes=n, **kw))
    np.testing.assert_allclose(pm.X, pb.X, rtol=0, atol=1e-8 * np.abs(pb.X).max())
    r = frf(model, ex, 100.0, 130.0, SolverOptions(formulation="condensed", modes=n, **kw),
            outputs=np.arange(n))
    assert r.complete
    pe = solve_point(model, ex, 130.0, SolverOptions(formulation="banded", **kw))
    np.testing.assert_allclose(r.X[-1], pe.X, rtol=0, atol=1e-8 * np.abs(pe.X).max())
    with pytest.raises(frirom.ParameterError, match="modes"):
        SolverOptions(formulation="banded", modes=3).check()


@pytest.mark.parametrize("alpha", [0.01, 0.03])
def test_stability_computed_above_hill_max(alpha):
    """2 n_dof (2H+1) = 1120 > HILL_MAX: the exponents come from shift-invert Arnoldi (no
    longer skipped). Reference, a closed form: with mass-proportional damping C = alpha M,
    s = mu - alpha/2 turns the Hill problem (J + s D1 + s^2 M) v = 0 into the undamped one
    for mu (the terms in alpha cancel exactly, truncated or not), whose matrices are
    symmetric (K, the cubic's tangent) and skew (M x d/dt): a gyroscopic problem whose
    exponents come as mu, -mu, conj(mu). Here (a weak cubic, 4e-5 of the chain's
    stiffness at this amplitude, far from any parametric resonance) they are all on the
    imaginary axis, so every Floquet exponent has Re s = -alpha/2: the largest must be
    that, to 1e-8 of omega (ARPACK's tolerance; measured ~1e-16), at every point, and
    the points stable. An exponent of the wrong problem (the damping or the nonlinear
    tangent dropped, a shift not undone), a skipped computation (0.0) or a wrong sign
    fails it."""
    n = 80
    M, K = chain(n, 1.0, np.ones(n))
    G = sp.csr_matrix(([1.0], ([0], [n - 1])), shape=(1, n))
    model = Model(M, K, Damping.rayleigh(alpha, 0.0), [ContactGroup("cubic", G, [[0, 0.1]])])
    F = np.zeros((n, 2), complex)
    F[0, 1] = 0.01
    assert 2 * n * 7 > HILL_MAX
    points = []
    r = frf(model, Excitation(F), 0.05, 0.06, SolverOptions(harmonics=3, samples=16,
            formulation="banded", stability=True, max_points=3), outputs=[0],
            sink=points.append)
    assert r.stability_computed and len(points) == len(r) == 3
    re_max = np.array([p.floquet_max_re for p in points])
    np.testing.assert_allclose(re_max, -alpha / 2, rtol=0, atol=1e-8 * 0.06)
    assert r.stable.all()
