"""The condensed formulation's unknown coordinates and receptance routes give the answers of
the path they replace (issue 10, items 1-3).

Reference: unknowns on the contact DoFs with receptances from a banded LU of the dynamic
stiffness per harmonic (the route of every earlier release). Against it: unknowns in
contact coordinates G x, receptances from all modes of the model (one dense eigh) and from
a sparse LU (MUMPS) per harmonic, each alone and with either coordinates, on
  * a lattice of two blocks touching on a plane (an unreduced, sparse FE-like model,
    tests/_lattices.py), normal1d friction on every node pair along tilted directions so
    that each contact row reads 6 DoFs (72 contact DoFs, 24 contact coordinates), and
  * its Craig-Bampton reduction (dense: the route 'auto' takes the modes).
The preload and force make the contacts stick, slip and lift off at the frequencies used.
The Jacobians of the new routes are checked against finite differences in
tests/test_hbm.f90; the cyclic sector (modes per harmonic, contact coordinates chosen
automatically) against the full rotor in tests/test_cyclic_solver.py.

Tolerance 1e-8 on the output harmonics, relative to their largest: every solve converges
to a residual of 1e-12 (relative), and J has condition ~1e3 here.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp

from _lattices import two_blocks
from frirom import ParameterError
from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.reduction.cb import craig_bampton
from frirom.solver import SolverOptions, frf, solve_point

TOL = 1e-8
OPTS = dict(harmonics=2, samples=40, tol_residual=1e-12, tol_update=1e-12, max_iter=60)
ROUTES = [("contact", "factorization"), ("dofs", "modes"), ("contact", "modes"),
          ("dofs", "sparse"), ("contact", "sparse")]


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def _contact_G(m, n):
    """Two rows per node pair (tangential, normal), tilted: each reads 6 DoFs."""
    t, nn = _unit([1.0, 0.3, 0.2]), _unit([0.1, -0.2, 1.0])
    pairs = len(m["dofs_a"])
    G = sp.lil_matrix((2 * pairs, n))
    for e, (a, b) in enumerate(zip(m["dofs_a"], m["dofs_b"])):
        for d, v in enumerate((t, nn)):
            G[2 * e + d, a] = v
            G[2 * e + d, b] = -v
    return G.tocsr()


@pytest.fixture(scope="module")
def models():
    m = two_blocks(nx=4, ny=3, nz=3, seed=2)
    K, M = m["K"], m["M"]
    n = K.shape[0]
    G = _contact_G(m, n)
    params = (3e5, 3e5, 0.3, 2.0)                   # kt, kn (N/m), mu, n0 (N)
    damp = Damping.rayleigh(5.0, 2e-6)
    full = Model(M, K, damp, [ContactGroup("normal1d", G, params, name="plane")])
    masters = np.unique(np.concatenate([G.indices, m["active"]]))
    cb = craig_bampton((K, M), 12, masters=masters)
    at = -np.ones(n, dtype=np.int64)
    at[cb.master_index] = np.arange(cb.master_index.size)
    Gr = sp.csr_matrix((G.data, at[G.indices], G.indptr), shape=(G.shape[0], cb.K.shape[0]))
    red = Model(cb.M, cb.K, damp, [ContactGroup("normal1d", Gr, params, name="plane")])
    # stuck-contact first resonance of the full model, force on the active node
    Ks = (K + G.T @ sp.diags(np.full(G.shape[0], 3e5)) @ G).toarray()
    import scipy.linalg as sla
    w1 = float(np.sqrt(sla.eigh(Ks, M.toarray(), eigvals_only=True, subset_by_index=[0, 0])[0]))
    F = np.zeros((n, 2), complex)
    F[m["active"], 1] = [15.0, 5.0, 10.0]
    Fr = np.zeros((cb.K.shape[0], 2), complex)
    Fr[at[m["active"]], 1] = F[m["active"], 1]
    out_f, out_r = m["active"], at[m["active"]]
    return dict(full=(full, Excitation(F), out_f), red=(red, Excitation(Fr), out_r), w1=w1)


def _solve(model, ex, out, w, start=None, **kw):
    p = solve_point(model, ex, w, SolverOptions(**OPTS, **kw), outputs=out, start=start)
    return p


@pytest.mark.parametrize("which", ["full", "red"])
def test_routes_agree_with_the_banded_dof_route(models, which):
    """Output harmonics of each route against the reference at three frequencies around
    the stuck resonance; the contacts are in mixed states there (asserted). Each route
    starts from the reference's contact history: where Newton from the linear solution
    fails, the point is reached by load continuation, whose path (round-off decides its
    steps) leaves contacts stuck all cycle with sliders that differ by ~1e-9 m, and so
    solutions ~4e-5 apart; with the same history the routes agree to round-off."""
    model, ex, out = models[which]
    mixed = 0
    for w in (0.9 * models["w1"], 1.05 * models["w1"], 1.2 * models["w1"]):
        ref = _solve(model, ex, out, w, coordinates="dofs", receptances="factorization")
        st = ref.state_fractions[0]
        mixed += st[1] > 0.01 or st[2] > 0.01          # slip or lift-off somewhere
        scale = np.abs(ref.X).max()
        for coords, rec in ROUTES:
            p = _solve(model, ex, out, w, start={"slider": ref.slider}, coordinates=coords,
                       receptances=rec)
            err = np.abs(p.X - ref.X).max() / scale
            assert err < TOL, (which, w, coords, rec, err)
            assert p.unknowns.size == (24 if coords == "contact" else 72) * 5
    assert mixed >= 2


def test_auto_choice_and_its_log(models):
    """'auto' takes the contact coordinates when they are fewer, the modes for the dense
    reduced model and the banded LU for the sparse one; FRF.solver_info says so. An FRF
    along the new route passes through the reference's solutions at its own points."""
    model, ex, out = models["red"]
    w1 = models["w1"]
    kept = []
    r = frf(model, ex, 1.17 * w1, 1.2 * w1, SolverOptions(**OPTS), outputs=out,
            sink=kept.append)
    assert r.complete
    assert "24 contact coordinates" in r.solver_info and "all" in r.solver_info
    assert "modes (exact" in r.solver_info
    ref_opts = SolverOptions(**OPTS, coordinates="dofs", receptances="factorization")
    for p in (kept[1], kept[len(kept) // 2], kept[-1]):
        # the reference route with the point's own contact history (contacts stuck all
        # cycle sit where the curve left them: a fresh start may find another such state)
        guess = solve_point(model, ex, p.omega, ref_opts, outputs=out)
        ref = solve_point(model, ex, p.omega, ref_opts, outputs=out,
                          start={"parameter": p.omega, "slider": p.slider,
                                 "unknowns": guess.unknowns})
        assert np.abs(p.X - ref.X).max() / np.abs(ref.X).max() < TOL
    # a lumped chain (tridiagonal K: sparse) keeps the banded LU; one contact element
    # reading one DoF: the contact DoFs are as few as the coordinates, and are kept
    n = 60
    K = sp.diags([np.full(n - 1, -1e6), np.full(n, 2e6), np.full(n - 1, -1e6)], [-1, 0, 1])
    chain = Model(sp.identity(n) * 0.1, K, Damping.rayleigh(1.0, 1e-6),
                  [ContactGroup("jenkins", sp.csr_matrix(([1.0], ([0], [n - 1])), (1, n)),
                                (1e6, 0.3, 1.0))])
    F = np.zeros((n, 2), complex)
    F[n // 2, 1] = 1.0
    r2 = frf(chain, Excitation(F), 100.0, 101.0, SolverOptions(**OPTS, max_points=2))
    assert "banded LU" in r2.solver_info and "sparse" in r2.solver_info
    assert "1 contact DoFs" in r2.solver_info


def test_general_damping_keeps_the_factorisation(models):
    """A damper between two DoFs is not diagonal in the modes: 'auto' factorises (and
    says why), 'modes' is refused with a message naming the option; stability forces the
    contact DoFs as unknowns, and asking for contact coordinates with it is refused."""
    model, ex, out = models["red"]
    n = model.n_dof
    C = model.C.toarray()
    C[0, 0] += 5.0
    C[1, 1] += 5.0
    C[0, 1] -= 5.0
    C[1, 0] -= 5.0
    m2 = Model(model.M, model.K, Damping.matrix(C), model.contacts)
    w = 0.95 * models["w1"]
    p_auto = solve_point(m2, ex, w, SolverOptions(**OPTS, max_points=2), outputs=out)
    r = frf(m2, ex, w, 1.001 * w, SolverOptions(**OPTS, max_points=2), outputs=out)
    assert "not diagonal" in r.solver_info
    ref = _solve(m2, ex, out, w, coordinates="dofs", receptances="factorization")
    assert np.abs(p_auto.X - ref.X).max() / np.abs(ref.X).max() < TOL
    with pytest.raises(ParameterError, match="options.receptances"):
        _solve(m2, ex, out, w, receptances="modes")
    with pytest.raises(ParameterError, match="options.coordinates"):
        _solve(model, ex, out, w, coordinates="contact", stability=True)
    with pytest.raises(ParameterError, match="options.coordinates"):
        SolverOptions(coordinates="nodes").check()
    assert n == model.n_dof


@pytest.mark.slow
def test_krylov_solves_agree_with_direct_ones(models):
    """GMRES on the current J preconditioned by an older LU (forced on here; by default
    from 1000 unknowns): the same points to TOL, along an FRF through slip, with fewer
    factorisations than Jacobians."""
    model, ex, out = models["red"]
    w1 = models["w1"]
    res, kept = {}, []
    for kr in (False, True):
        o = SolverOptions(**OPTS, krylov=kr)
        r = frf(model, ex, 1.17 * w1, 1.2 * w1, o, outputs=out,
                sink=kept.append if kr else None)
        assert r.complete
        res[kr] = r
    # each point re-solved by direct LUs from its own unknowns and contact history (a
    # fresh start from the linear solution may find another stuck state: friction is
    # history dependent)
    for k in (1, len(kept) // 2, len(kept) - 1):
        ref = solve_point(model, ex, kept[k].omega, SolverOptions(**OPTS, krylov=False),
                          outputs=out, start=kept[k])
        assert np.abs(kept[k].X - ref.X).max() / np.abs(ref.X).max() < TOL
    assert res[True].timings["factorizations"] < 0.5 * res[False].timings["factorizations"]


def test_start_from_the_other_coordinates_is_explained(models):
    """A saved point whose unknowns are on the contact DoFs (an earlier release, or
    coordinates='dofs') does not fit the contact coordinates 'auto' takes: the error says
    which option makes it fit, and with it the point resumes to the same solution."""
    model, ex, out = models["red"]
    w = 1.05 * models["w1"]
    p = _solve(model, ex, out, w, coordinates="dofs")
    from frirom import SizeError
    with pytest.raises(SizeError, match="options.coordinates = 'dofs'"):
        solve_point(model, ex, w, SolverOptions(**OPTS), outputs=out, start=p)
    q = solve_point(model, ex, w, SolverOptions(**OPTS, coordinates="dofs"), outputs=out,
                    start=p)
    assert np.abs(q.X - p.X).max() / np.abs(p.X).max() < TOL


@pytest.mark.slow
def test_large_system_solves_by_gmres_on_the_held_lu():
    """Above some thousand unknowns an LU is worth many GMRES iterations: a Jacobian after
    the first is applied matrix-free and solved by GMRES preconditioned by the LU held
    (factorised again when the iterations since it reach the LU's worth). Along an FRF
    through slip: GMRES is used and most points need no LU; each point re-solved from its
    own unknowns and contact history by a fresh LU (the direct path) agrees to TOL (the
    GMRES solves reach 1e-8 of the right-hand side; Newton then converges to 1e-10)."""
    from condensed import reduced_model      # ROM_I's kind: random modes, 6 DoFs/contact
    model, ex = reduced_model(n=600, nc=80, seed=3)   # 160 coordinates: 1 120 unknowns
    out = np.arange(6)
    o = SolverOptions(harmonics=3, samples=64, tol_residual=1e-10, tol_update=1e-10)
    kept = []
    r = frf(model, ex, 2 * np.pi * 516.0, 2 * np.pi * 524.0, o, outputs=out,
            sink=kept.append)
    assert r.complete
    assert "1120 unknowns" in r.solver_info
    assert r.timings["krylov_iterations"] > 0
    assert r.timings["factorizations"] < 0.8 * len(r)
    # the single-precision LU preconditions this well-conditioned J: no double fall-back
    assert r.timings["double_factorizations"] == 0
    assert max(p.state_fractions[0][1] for p in kept) > 0.01      # slip on the way
    for k in (1, len(kept) // 2, len(kept) - 1):
        # a new system holds no LU: its Newton solves are by a fresh LU
        ref = solve_point(model, ex, kept[k].omega, o, outputs=out, start=kept[k])
        assert np.abs(kept[k].X - ref.X).max() / np.abs(ref.X).max() < TOL


@pytest.mark.slow
def test_ill_conditioned_j_falls_back_to_a_double_lu():
    """The held LU is single precision: it only preconditions GMRES, and when GMRES on it
    does not converge (J too ill-conditioned for single precision) J is factorised in
    double. Forced here by a lightly damped mode at the excitation frequency: the model of
    the large-system test with modal damping (its Rayleigh ratios), the resonant mode's
    ratio 2e-10 instead of 0.002. That mode's receptance factor 1/(2 zeta w^2) is then 1e7
    times larger, so a single-precision LU of J = I + R dF/dU is off by ~6e-8 x 1e7 ~ 0.6:
    GMRES on it stalls (the fall-back counter, asserted), a double LU is off by ~1e-9.
    The answer against two other paths from the same contact history: double LUs of J
    throughout (krylov mode: GMRES preconditioned by an older double LU) and the dense
    path (unknowns on the contact DoFs, receptances by a banded LU of D_h, C assembled
    from the same modal ratios). Tolerance 1e-7: at zeta 5e-11 to 4e-10 the three agree
    pairwise to 0.5-6e-8, the round-off floor of this conditioning (Newton stops at 1e-10
    of the residual; the well-damped model agrees to ~1e-11); with zeta >= 1e-9 the
    single LU suffices and no fall-back fires."""
    import scipy.linalg as sla
    from condensed import F_RES, reduced_model
    model, ex = reduced_model(n=600, nc=80, seed=3)   # 160 coordinates: 1 120 unknowns
    w = np.sqrt(sla.eigh(model.K.toarray(), model.M.toarray(), eigvals_only=True))
    zeta = model.damping.beta * w / 2.0               # its Rayleigh ratios, as modal ones
    wr = 2 * np.pi * F_RES
    zeta[np.argmin(abs(w - wr))] = 2e-10
    light = Model(model.M, model.K, Damping.modal(zeta), model.contacts)
    out = np.arange(6)
    o = SolverOptions(harmonics=3, samples=64, tol_residual=1e-10, tol_update=1e-10,
                      modes=w.size)
    hist = {"slider": solve_point(light, ex, wr, o, outputs=out).slider}
    p = solve_point(light, ex, wr, o, outputs=out, start=hist)
    assert p.timings["double_factorizations"] >= 1
    assert p.state_fractions[0][0] > 0.1 and p.state_fractions[0][1] > 0.1   # stick, slip
    for kw in (dict(krylov=True),
               dict(modes=None, coordinates="dofs", receptances="factorization")):
        ref = solve_point(light, ex, wr, dataclasses.replace(o, **kw), outputs=out,
                          start=hist)
        assert np.abs(p.X - ref.X).max() / np.abs(ref.X).max() < 1e-7, kw


@pytest.mark.slow
def test_held_lu_carried_from_solve_to_solve():
    """The LU a large system holds stays in the Fortran run from one corrector solve to
    the next (run_solve: the FRF's peak solves, solve_point's): a solve after the first
    solves its Jacobians by GMRES preconditioned by that LU and factorises none while the
    LU stays worth its iterations; a continuation segment (run_advance) forgets it, as a
    restored run starts without one. The LU only preconditions: the answer is that of a
    fresh run (its own LU) to TOL, and of the dense path (unknowns on the contact DoFs,
    receptances by banded LU) to TOL. Tolerance as above: Newton converges to 1e-10 of
    the residual, GMRES solves to 1e-8."""
    from frirom import _kernels, _run
    from frirom._pack import add_timings, pack
    from condensed import reduced_model
    model, ex = reduced_model(n=600, nc=80, seed=3)   # 160 coordinates: 1 120 unknowns
    out = np.arange(6)
    o = SolverOptions(harmonics=3, samples=64, tol_residual=1e-10, tol_update=1e-10)
    assert _kernels.hbm_lu_holds(3, 160, 600) == 1 and _kernels.hbm_lu_holds(3, 10, 30) == 0
    p = pack(model, ex, o, out)
    run = p.run

    def solve(w, y0, sliders):
        r = run.solve(_run.SOLVE_FIXED, w, y0, sliders=sliders)
        assert r.info == 0 and r.npts == 1, r.msg
        t = {}
        add_timings(t, r.timings)
        return r.ys[:, 0], r.xo[:, :, 0], r.sliders[:p.nw, 0], dict(
            fact=t["factorizations"], its=t["krylov_iterations"])

    w1, w2 = 2 * np.pi * np.array([519.0, 519.1])
    y1, _, s1, t1 = solve(w1, np.zeros(p.ny), None)
    assert t1["fact"] >= 1
    y2, x2, _, t2 = solve(w2, y1, s1)             # the LU of w1 kept: no new LU
    assert t2["fact"] == 0 and t2["its"] > 0
    for kw in ({}, dict(coordinates="dofs", receptances="factorization")):
        start = {"slider": s1} if kw else {"slider": s1, "unknowns": y1}
        ref = solve_point(model, ex, w2, dataclasses.replace(o, **kw), outputs=out,
                          start=start)
        assert np.abs(x2 - ref.X).max() / np.abs(ref.X).max() < TOL
    # a continuation segment starts without the held LU (exact resume)
    run.start(_run.START_RESUME, w1, w2 * 1.001, lam0=w1, y0=y1,
              tan0=np.r_[np.zeros(p.ny), 1.0], yscale=float(np.linalg.norm(y1)),
              sliders=s1)
    seg = run.advance(1)
    t3 = {}
    add_timings(t3, seg.timings)
    assert seg.npts == 1 and t3["factorizations"] >= 1
