"""The Fortran run object (frirom._run, fortran/frirom_run.f90): the one continuation
driver behind frirom.solver, frirom.h and legacy Fortran programs.

References: the closed-form linear response of a model without contacts (numpy's dense
solve of the dynamic stiffness), the uninterrupted run itself (checkpoints, interleaved
runs: tolerance 0, the same arithmetic), Fortran's own settings."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from frirom import _kernels, _run
from frirom._errors import ParameterError, SizeError
from frirom._pack import pack
from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import SolverOptions, frf, solve_point


def _chain(contact: bool = True):
    """Three masses in a chain, a Jenkins element on the first (when contact)."""
    K = sp.csr_matrix(np.array([[2e4, -1e4, 0], [-1e4, 2e4, -1e4], [0, -1e4, 1e4]]))
    M = sp.identity(3, format="csr")
    groups = [ContactGroup("jenkins", sp.csr_matrix(([1.0], ([0], [0])), shape=(1, 3)),
                           (5e3, 0.3, 2.0), name="c")] if contact else []
    F = np.zeros((3, 2), complex)
    F[2, 1] = 1.0
    return Model(M, K, Damping.rayleigh(0.0, 1e-4), groups), Excitation(F)


@pytest.mark.parametrize("form", ["condensed", "banded"])
def test_model_without_contacts_gives_its_linear_response(form):
    """No contact group: the condensed formulation has nothing to condense to and solves
    the linear response in the banded formulation (saying so); both equal the dense
    solve of (K - w^2 M + i w C) x = F at every point to 1e-8, the continuation's
    Newton tolerance (a corrector may stop before its last, round-off-level update;
    measured 2.4e-10). A wrong damping sign or harmonic slot fails by far."""
    model, ex = _chain(contact=False)
    r = frf(model, ex, 20.0, 200.0, SolverOptions(harmonics=1, formulation=form))
    assert r.complete and len(r) > 20
    if form == "condensed":
        assert "no contact DoFs" in r.solver_info
    K, M, C = (a.toarray() for a in (model.K, model.M, model.C))
    for k in range(len(r)):
        w = r.omega[k]
        x = np.linalg.solve(K - w**2 * M + 1j * w * C, ex.F[:, 1])
        ref = np.c_[x.real, -x.imag]          # a1 cos + b1 sin: x = Re(X e^{iwt})
        assert np.abs(r.X[k][:, 1:3] - ref).max() <= 1e-8 * np.abs(x).max()


def test_defaults_come_from_fortran():
    """SolverOptions' numerical defaults are Fortran's run_settings (the C struct's
    frirom_settings_default): one place; a changed Fortran default would show here."""
    iv, rv, names = _kernels.settings_defaults(_run._N_ISET, _run._N_RSET)
    names = names.decode().split()
    o = SolverOptions()
    for name, value in zip(names, list(iv) + list(rv)):
        if name in ("samples", "formulation"):
            continue
        assert getattr(o, name) == value, name
    assert o.samples is None and iv[names.index("samples")] == 0


def test_two_runs_in_one_process_share_nothing():
    """Two runs advanced in turn give the points each gives alone (no module state)."""
    model, ex = _chain()
    opts = SolverOptions(harmonics=3, samples=64, refine_peak=False)
    alone = [frf(model, ex, w0, w1, opts) for w0, w1 in ((60.0, 140.0), (140.0, 60.0))]
    pa, pb = pack(model, ex, opts, None), pack(model, ex, opts, None)
    ra, rb = pa.run, pb.run
    ra.start(_run.START_COLD, 60.0, 140.0)
    rb.start(_run.START_COLD, 140.0, 60.0)
    got = [[], []]
    while True:
        done = True
        for k, (p, r) in enumerate(((pa, ra), (pb, rb))):
            res = r.advance(7)
            got[k] += [q.X for q in p.points(res, 0.0)]
            done &= res.status != _run.GOING
        if done:
            break
    for k in range(2):
        assert len(got[k]) == len(alone[k])
        assert all(np.array_equal(a, b) for a, b in zip(got[k], alone[k].X))


def test_checkpoint_restores_the_uninterrupted_run_exactly():
    """A run stopped after a segment, checkpointed (the start of the next segment: the
    point, its tangent and scale, the step, the history) and restored on a new run
    makes the points the uninterrupted run made after it, bit for bit."""
    model, ex = _chain()
    opts = SolverOptions(harmonics=3, samples=64, refine_peak=False, batch=5)
    full = frf(model, ex, 60.0, 140.0, opts)
    pts = []
    frf(model, ex, 60.0, 140.0, opts, sink=pts.append)
    cut = [p for p in pts[:16]]
    ck = cut[-1]
    assert np.isfinite(ck.ds_next)
    rest = frf(model, ex, 60.0, 140.0, opts,
               start={"parameter": ck.parameter, "unknowns": ck.unknowns,
                      "tangent": ck.tangent, "yscale": ck.yscale, "slider": ck.slider,
                      "ds": ck.ds_next, "n_points": 16})
    assert len(rest) == len(full) - 16
    assert np.array_equal(rest.X, full.X[16:]) and np.array_equal(rest.omega, full.omega[16:])


def test_closed_run_and_bad_calls_are_refused_by_name():
    """A closed handle, a solve with unknowns of the wrong size and a resume without a
    tangent are errors naming the call, never a crash."""
    model, ex = _chain()
    p = pack(model, ex, SolverOptions(harmonics=1), None)
    run = p.run
    with pytest.raises(Exception, match="run_solve"):
        run.solve(_run.SOLVE_FIXED, 100.0, np.zeros(p.ny + 1))
    with pytest.raises((ParameterError, SizeError), match="resume needs|tan0"):
        run.start(_run.START_RESUME, 60.0, 140.0, lam0=60.0, y0=np.zeros(p.ny))
    h = run.handle
    run.close()
    _, _, _, _, _, _, _, _, _, _, _, info, msg = _kernels.frun_solve(
        h, _run.SOLVE_FIXED, 100.0, np.zeros(p.ny), np.zeros(p.ny + 1), 0.0, 0.0,
        np.zeros(1), 0, 0, 0, 3, 3, 1, int(_run._N_TIMERS))
    assert info != 0 and b"not an open run" in msg


def test_one_solve_on_an_open_run_equals_solve_point():
    """Run.solve at fixed frequency from the linear solution (with the homotopy start
    where Newton fails) gives solve_point's answer, on a run set up once."""
    model, ex = _chain()
    opts = SolverOptions(harmonics=3, samples=64)
    p = pack(model, ex, opts, None)
    for w in (80.0, 100.0, 120.0):
        ref = solve_point(model, ex, w, opts)
        res = p.run.solve(_run.SOLVE_FIXED, w, np.zeros(p.ny), cold=True)
        assert res.info == 0
        assert np.array_equal(p.points(res, 0.0)[0].X, ref.X)


def test_every_output_gets_its_own_solved_peak():
    """Two outputs of one resonance peak at different frequencies (a 2-DoF chain with
    heavy damping on the second mass); each output's FRF.peaks entry is its own solved
    peak: equal to the maximum over 200 001 frequencies of the closed-form linear
    response (numpy's dense solve) to 1e-7 (the search's tolerance on the arc length,
    2e-3 of two steps, gives ~1e-6 of the amplitude change over a step). Before, the
    second output took the nearest of the first output's solves: 1e-4 low here."""
    K = sp.csr_matrix(np.array([[2e4, -1e4], [-1e4, 1e4]]))
    M = sp.csr_matrix(np.diag([1.0, 0.5]))
    C = sp.csr_matrix(np.array([[0.5, 0.0], [0.0, 6.0]]))
    model = Model(M, K, Damping.matrix(C), [])
    F = np.zeros((2, 2), complex)
    F[0, 1] = 1.0
    r = frf(model, Excitation(F), 50.0, 110.0, SolverOptions(harmonics=1), outputs=[0, 1])
    w = np.linspace(50.0, 110.0, 200_001)
    Kd, Md, Cd = K.toarray(), M.toarray(), C.toarray()
    amp = np.abs(np.array([np.linalg.solve(Kd - x**2 * Md + 1j * x * Cd, F[:, 1])
                           for x in w]))
    for j in range(2):
        ref = amp[:, j].max()
        assert r.peaks[j].method == "solve"
        assert abs(r.peaks[j].amplitude - ref) <= 1e-7 * ref, (j, r.peaks[j], ref)
    assert abs(r.peaks[0].omega - r.peaks[1].omega) > 0.05   # two different frequencies
