"""A cyclic sector whose contact DoFs are reduced by GSI interface modes: more contact rows
than columns, so the condensed solver may take the contact coordinates G x (6 per harmonic
coefficient) or the columns of G (5). Both must give the same answer; the contact
coordinates once read past the end of the nonlinear DoF list in hbm_setup (a segfault on
the paper_hooks ROM_II with coordinates = "contact").

Model: the lattice rotor sector of tests/_rotor.py (N = 7, EO = 2, H = 3), its
three ground contacts (normal1d, 6 rows on 9 DoFs) reduced by 3 free GSI modes where they
are off the cyclic boundary (G: 6 rows on 3 dense GSI columns + 2 boundary DoFs), the tip
forced by the travelling wave. Tolerance 1e-8 on the output harmonics relative to their largest: both solves converge to a residual of 1e-11 of the
same equations in other unknowns (J's condition ~1e3).
"""

from __future__ import annotations

import numpy as np
import pytest

from frirom.model import ContactGroup, Damping, Excitation
from frirom.reduction.cyclic import CyclicSector, cyclic_model
from frirom.reduction.interface import gsi_basis, reduce_interface
from frirom.solver import SolverOptions, frf, solve_point
from _rotor import (ALPHA, BETA, EO, FORCE, H, N, OPTS, P_GROUND, rotor,
                    sector_contacts)


@pytest.fixture(scope="module")
def gsi_sector():
    r, _, Ks, glob = rotor()
    s = r["sector"]
    n_s = Ks.shape[0]
    G1 = sector_contacts(r, glob, n_s)[0].G
    nd = s["node_dofs"]
    bnd = np.concatenate([nd[s["left"]].ravel(), nd[s["right"]].ravel()])
    iface = np.setdiff1d(G1.indices, bnd)      # the boundary stays physical
    basis, _ = gsi_basis(Ks, s["M"], iface, n_free=3)
    red = reduce_interface(Ks, s["M"], iface, basis)
    n_k = basis.shape[1]
    pos = -np.ones(n_s, dtype=np.int64)
    pos[red.kept] = n_k + np.arange(red.kept.size)
    left, right = pos[nd[s["left"]]], pos[nd[s["right"]]]
    sector = CyclicSector(n_dof=red.K.shape[0], n_sectors=N, left=left, right=right,
                          axis=np.array([0.0, 0.0, 1.0]), origin=np.zeros(3))
    G = (G1 @ red.R).toarray()
    # 3 GSI columns and the 2 contact DoFs on the cyclic boundary: 5 < 6 rows
    assert G.shape == (6, red.K.shape[0]) and np.count_nonzero(G.any(axis=0)) == 5
    cm = cyclic_model(sector, red.K, red.M, [ContactGroup("normal1d", G, P_GROUND)], EO, H,
                      damping=Damping.rayleigh(ALPHA, BETA))
    loc = -np.ones(glob.max() + 1, dtype=np.int64)
    loc[glob] = np.arange(glob.size)
    tip = pos[loc[3 * r["tips"][0] + np.arange(3)]]
    th = np.arctan2(r["coords"][r["tips"][0], 1], r["coords"][r["tips"][0], 0])
    F = np.zeros((red.K.shape[0], 2), complex)
    F[tip, 1] = FORCE * np.array([-np.sin(th), np.cos(th), 0.3])
    return cm, Excitation(F), tip


def test_contact_and_gsi_coordinates_agree(gsi_sector):
    """FRF in the GSI coordinates ('auto' takes them: 5 < 6), then solve_point in contact
    coordinates at five of its frequencies (the peak included): same outputs to 1e-8."""
    cm, ex, out = gsi_sector
    w1 = cm.modes_of(cm.harmonic_index(1)).omega[0]
    opts = dict(OPTS, tol_residual=1e-11, tol_update=1e-11)
    r = frf(cm, ex, 0.85 * w1, 1.15 * w1, SolverOptions(**opts), outputs=out)
    assert r.complete and "5 contact DoFs" in r.solver_info
    amp = r.amp_max.max(axis=1)
    picks = np.unique(np.r_[np.argmax(amp), np.linspace(0, amp.size - 1, 4).astype(int)])
    slip = 0.0
    for i in picks:
        pc = solve_point(cm, ex, r.omega[i], SolverOptions(**opts, coordinates="contact"),
                         outputs=out)
        pd = solve_point(cm, ex, r.omega[i], SolverOptions(**opts, coordinates="dofs"),
                         outputs=out)
        scale = np.abs(pd.X).max()
        assert np.abs(pc.X - pd.X).max() < 1e-8 * scale
        assert np.abs(r.X[i] - pd.X).max() < 1e-6 * scale     # continuation tolerance
        slip = max(slip, pc.state_fractions[0, 1])
    assert slip > 0.05                          # the contacts slip: the nonlinear path


def test_contact_coordinates_frf(gsi_sector):
    """A whole FRF in contact coordinates runs (it crashed) and ends where 'dofs' does."""
    cm, ex, out = gsi_sector
    w1 = cm.modes_of(cm.harmonic_index(1)).omega[0]
    opts = dict(OPTS, tol_residual=1e-11, tol_update=1e-11)
    rc = frf(cm, ex, 0.9 * w1, 1.1 * w1, SolverOptions(**opts, coordinates="contact"),
             outputs=out)
    assert rc.complete and "6 contact coordinates" in rc.solver_info
    pd = solve_point(cm, ex, rc.omega[-1], SolverOptions(**opts, coordinates="dofs"),
                     outputs=out)
    assert np.abs(rc.X[-1] - pd.X).max() < 1e-8 * np.abs(pd.X).max()
