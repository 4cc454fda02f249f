"""Nonlinear forced response of a cyclic sector against the whole tuned rotor.

The reference is independent of the cyclic machinery: the full N-sector lattice rotor
(tests/_lattices.py; its supports and contacts in tests/_rotor.py), every sector carrying
its own friction contacts (to ground and between neighbouring blade tips), excited by an
engine-order travelling wave and solved by the ordinary condensed harmonic balance on all
its DoFs. The sector model only sees sector
0 and the modes of the nodal diameters k_h = -h EO mod N of each time harmonic h.

With N = 7 and EO = 2 the harmonics 0..3 live on nodal diameters 0, 5, 3 and 1: four
different diameters, so a solver that used one index for all harmonics (the one-index
shortcut) cannot agree, and the test shows by how much it does not.
The AFT uses 7 x 16 samples: the time lag between sectors is then a whole number of
samples and the full rotor's AFT sees exactly the samples of sector 0, shifted, so the two
solutions agree to the Newton tolerance.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from _rotor import (ALPHA, BETA, EO, FORCE, H, N, OPTS, full_model, rotor, rotor_sector,
                    sector_contacts)
from frirom import ParameterError, SizeError
from frirom.model import ContactGroup, CyclicModel, Damping, Excitation
from frirom.reduction.cyclic import CyclicSector, axis_rotation, cyclic_model
from frirom.solver import SolverOptions, frf, load_curve, solve_point


def _models(single_index=None):
    r, K, Ks, glob = rotor()
    s = r["sector"]
    n_s = Ks.shape[0]
    sector = rotor_sector(r, N)
    cm = cyclic_model(sector, Ks, s["M"], sector_contacts(r, glob, n_s), EO, H,
                      damping=Damping.rayleigh(ALPHA, BETA), single_index=single_index)
    full = full_model(r, K)
    # travelling wave on the blade tips: FORCE tangential (+ 0.3 FORCE axial) on sector 0
    Q = axis_rotation(2 * np.pi / N)
    tip = r["tips"]
    th = np.arctan2(r["coords"][tip[0], 1], r["coords"][tip[0], 0])
    f0 = FORCE * np.array([-np.sin(th), np.cos(th), 0.3])
    F = np.zeros((K.shape[0], 2), complex)
    for k in range(N):
        F[3 * tip[k]:3 * tip[k] + 3, 1] = (np.linalg.matrix_power(Q, k) @ f0) * \
            np.exp(-2j * np.pi * EO * k / N)
    loc = -np.ones(glob.max() + 1, dtype=np.int64)
    loc[glob] = np.arange(glob.size)
    Fs = np.zeros((n_s, 2), complex)
    Fs[loc[3 * tip[0] + np.arange(3)], 1] = f0
    out_full = 3 * tip[0] + np.arange(3)
    out_sec = loc[out_full]
    return cm, full, Excitation(Fs), Excitation(F), out_sec, out_full


@pytest.fixture(scope="module")
def models():
    return _models()


def test_harmonics_live_on_their_nodal_diameters(models):
    cm = models[0]
    assert cm.indices(H) == [0, 5, 3, 1]
    assert sorted(cm.modes) == [0, 1, 3, 5]      # one eigen-solve per diameter used
    m5, m2 = cm.modes_of(5), cm.modes_of(2)
    assert np.allclose(m5.psi, m2.psi.conj()) and np.allclose(m5.omega, m2.omega)


def test_sector_matches_full_rotor(models):
    """Sector 0's tip harmonics equal the full rotor's to 1e-9 (Newton tolerance 1e-11
    on both; the contacts slip and lift off, so the test exercises the nonlinear path), at
    three frequencies around the first resonance of nodal diameter 5 (EO 2 backward)."""
    cm, full, ex_s, ex_f, out_s, out_f = models
    w1 = cm.modes_of(5).omega[0]
    for w in (0.9 * w1, 1.0 * w1, 1.08 * w1):
        ps = solve_point(cm, ex_s, w, SolverOptions(**OPTS), outputs=out_s)
        pf = solve_point(full, ex_f, w, SolverOptions(**OPTS), outputs=out_f)
        scale = np.abs(pf.X).max()
        err = np.abs(ps.X - pf.X).max() / scale
        assert err < 1e-9, (w / w1, err)
        # the nonlinearity is real: higher harmonics present, contacts slip
        assert np.abs(pf.X[:, 3:]).max() > 1e-3 * scale
        assert ps.state_fractions[0, 1] > 0.05


def test_sector_frf_matches_full_rotor_through_resonance(models):
    """Continuation on the sector against solve_point on the full rotor at the FRF's own
    frequencies (five of them, the peak included)."""
    cm, full, ex_s, ex_f, out_s, out_f = models
    w1 = cm.modes_of(5).omega[0]
    r = frf(cm, ex_s, 0.85 * w1, 1.15 * w1, SolverOptions(**{**OPTS, "tol_residual": 1e-10,
                                                                  "tol_update": 1e-10}),
            outputs=out_s)
    assert r.complete and r.omega.size > 10
    amp = r.amp_max.max(axis=1)
    picks = np.unique(np.r_[np.argmax(amp), np.linspace(0, amp.size - 1, 4).astype(int)])
    for i in picks:
        pf = solve_point(full, ex_f, r.omega[i], SolverOptions(**OPTS), outputs=out_f)
        Xs = r.X[i]
        assert np.abs(Xs - pf.X).max() < 1e-6 * np.abs(pf.X).max()


def test_sector_load_curve_matches_full_rotor(models):
    """Continuation in the excitation level (the load part of the condensed system) at the
    ND-5 resonance ends where the full rotor's solve at full load does (measured 7e-13)."""
    cm, full, ex_s, ex_f, out_s, out_f = models
    w1 = cm.modes_of(5).omega[0]
    r = load_curve(cm, ex_s, w1, 0.1, 1.0, SolverOptions(**OPTS), outputs=out_s)
    pf = solve_point(full, ex_f, w1, SolverOptions(**OPTS), outputs=out_f)
    assert r.complete and r.parameter[-1] == 1.0
    assert np.abs(r.X[-1] - pf.X).max() < 1e-9 * np.abs(pf.X).max()


def test_one_index_shortcut_is_an_approximation(models):
    """The one-index shortcut (every harmonic on nodal diameter 5) differs from the exact
    answer in the higher harmonics and the static part, which live on other diameters.
    Measured at 0.9 / 1.0 / 1.08 of the first ND-5 frequency: max amplitude off by +3.8 /
    -11 / +11 %, harmonics >= 2 off by 210 / 73 / 250 % of their size."""
    cm, full, ex_s, ex_f, out_s, out_f = models
    approx = _models(single_index=5)[0]
    w = cm.modes_of(5).omega[0]
    pe = solve_point(cm, ex_s, w, SolverOptions(**OPTS), outputs=out_s)
    pa = solve_point(approx, ex_s, w, SolverOptions(**OPTS), outputs=out_s)
    higher = np.abs(pa.X[:, 3:] - pe.X[:, 3:]).max() / np.abs(pe.X[:, 3:]).max()
    assert higher > 0.1
    assert abs(pa.amp_max.max() / pe.amp_max.max() - 1) > 0.01


def test_cyclic_model_errors(models):
    cm = models[0]
    g = cm.contacts[0]
    with pytest.raises(SizeError, match="columns"):
        CyclicModel(n_dof=cm.n_dof + 1, n_sectors=N, engine_order=EO, modes={}, contacts=[g])
    with pytest.raises(ParameterError, match="sign"):
        CyclicModel(n_dof=cm.n_dof, n_sectors=N, engine_order=EO, modes={}, contacts=[g],
                    sign=2)
    bare = CyclicModel(n_dof=cm.n_dof, n_sectors=N, engine_order=EO,
                       modes={0: cm.modes[0]}, contacts=[g])
    with pytest.raises(ParameterError, match="no modes of harmonic index 5"):
        solve_point(bare, models[2], 100.0, SolverOptions(harmonics=1))
    with pytest.raises(ParameterError, match="stability"):
        solve_point(cm, models[2], 100.0, SolverOptions(harmonics=1, stability=True))
    with pytest.raises(ParameterError, match="condensed"):
        solve_point(cm, models[2], 100.0, SolverOptions(harmonics=1, formulation="banded"))


def test_craig_bampton_sector_converges_to_the_unreduced_sector():
    """The sector reduced by Craig-Bampton (masters: both cyclic boundaries, the contact
    nodes and the blade tip) converges to the unreduced sector's nonlinear response at the
    resonance as fixed-interface modes are added: tip-harmonic errors measured 3.2e-2 /
    1.7e-2 / 5.4e-3 / 4.4e-4 / 3.8e-5 with 4 / 8 / 16 / 32 / 49 of the 51 slave modes."""
    from frirom.reduction.cb import craig_bampton
    r, K, Ks, glob = rotor()
    s = r["sector"]
    n_s = Ks.shape[0]
    contacts = sector_contacts(r, glob, n_s)
    loc = -np.ones(glob.max() + 1, dtype=np.int64)
    loc[glob] = np.arange(glob.size)
    tip = loc[3 * r["tips"][0] + np.arange(3)]
    used = np.unique(np.concatenate([g.G.indices % n_s for g in contacts]))
    left, right = s["node_dofs"][s["left"]], s["node_dofs"][s["right"]]
    masters = np.unique(np.concatenate([left.ravel(), right.ravel(), used, tip]))
    F = np.zeros((n_s, 2), complex)
    F[tip, 1] = _models()[2].F[tip, 1]

    def response(Kr, Mr, Tr, n):
        pos = np.searchsorted(masters, np.arange(n_s))
        sec = CyclicSector(n_dof=n, n_sectors=N, left=pos[left], right=pos[right],
                           axis=np.array([0.0, 0.0, 1.0]), origin=np.zeros(3))
        groups = []
        for g in contacts:
            blocks = [g.G[:, b * n_s:(b + 1) * n_s] @ Tr for b in range(g.G.shape[1] // n_s)]
            groups.append(ContactGroup(g.law, sp.hstack(blocks), g.params, name=g.name))
        cm = cyclic_model(sec, Kr, Mr, groups, EO, H, damping=Damping.rayleigh(ALPHA, BETA))
        return cm, Excitation(Tr.T @ F)

    cm_full, ex_full = _models()[0], Excitation(F)
    w = cm_full.modes_of(5).omega[0]
    ref = solve_point(cm_full, ex_full, w, SolverOptions(**OPTS), outputs=tip)
    n_slave = n_s - masters.size
    errs = []
    for nm in (4, 8, 16, 32, n_slave - 2):
        cb = craig_bampton((Ks, s["M"]), nm, masters=masters)
        assert np.array_equal(cb.master_index, masters)
        Tr = np.zeros((n_s, cb.K.shape[0]))
        Tr[masters, np.arange(masters.size)] = 1.0
        Tr[np.ix_(cb.slave_index, np.arange(masters.size))] = cb.psi
        Tr[np.ix_(cb.slave_index, masters.size + np.arange(nm))] = cb.phi
        cm, ex = response(cb.K, cb.M, sp.csr_matrix(Tr), cb.K.shape[0])
        out = np.searchsorted(masters, tip)
        p = solve_point(cm, ex, w, SolverOptions(**OPTS), outputs=out)
        errs.append(np.abs(p.X - ref.X).max() / np.abs(ref.X).max())
    assert all(b < a for a, b in zip(errs, errs[1:])), errs
    assert errs[-1] < 1e-4, errs
