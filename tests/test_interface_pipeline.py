"""FE matrices from ccx -> Craig-Bampton -> GSI interface reduction -> reduced contact map.

The clamped block of cases/models/block.py carries a contact patch (node set IFACE) on its
free end, tied to ground by contact springs (kt, kt, kn) in a tilted local frame. The GSI
basis of the CB model equals that of the FE model (the CB master partition is the Guyan
condensation), and the stuck interface FRF of CB + GSI converges to the CB model's as GSI
modes are added, the CB model itself being within a small error of the full FE model.
"""

import os
import shutil

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from frirom.io import read_calculix
from frirom.reduction.cb import craig_bampton
from frirom.reduction.interface import (ContactPairs, contact_matrix, gsi_basis, local_frames,
                                        reduce_interface, stick_stiffness)

import block  # cases/models/block.py

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx not installed")
ETA = 0.01


@pytest.fixture(scope="module")
def fe(tmp_path_factory):
    out = tmp_path_factory.mktemp("gsi_block")
    deck = block.write_block_deck(out / "block.inp", 12, 4, 4, n_ref_modes=0, patch=1.0)
    model = read_calculix(block.run_ccx(deck))
    key = {(a, b): i for i, (a, b) in enumerate(model.dofs)}
    nodes = model.node_sets["IFACE"]
    dofs = np.array([[key[(nd, c)] for c in (1, 2, 3)] for nd in nodes])
    frames = local_frames(np.tile([1.0, 0.1, -0.2], (len(nodes), 1)))   # normal ~ x
    pairs = ContactPairs(dofs, -np.ones_like(dofs), frames,
                         np.tile([2e8, 2e8, 8e8], (len(nodes), 1)))
    return model, pairs


def _frf(K, M, G, f, om):
    lam, phi = sla.eigh(K, M)
    den = lam[None, :] * (1 + 1j * ETA) - om[:, None] ** 2
    return ((phi.T @ f)[None, :] / den) @ np.asarray(G @ phi).T


def _gsi_frfs(cb, iface, active, pairs, n_free, n_stick, fq, om, groups=None):
    """CB + GSI with n_free free and n_stick full-stick interface modes: its basis B
    (n_q, n_k) and its stuck and free interface FRFs (n_om, n_iface), as _frf."""
    B, _ = gsi_basis(cb.K, cb.M, iface, active, pairs, n_free, n_stick, groups=groups)
    red = reduce_interface(cb.K, cb.M, iface, B)
    G = red.contact_matrix(pairs)
    ks = sp.diags(pairs.stiffness.ravel())
    f = red.project(fq)
    stuck = _frf(red.K + (G.T @ ks @ G).toarray(), red.M, G, f, om)
    return B, stuck, _frf(red.K, red.M, G, f, om)


def _rel(x, ref):
    """||x - ref|| / ||ref|| (Frobenius norms)."""
    return np.linalg.norm(x - ref) / np.linalg.norm(ref)


def _error_table(capsys, title, labels, rows):
    """Print rows (n_k, error 1, error 2) under title, past pytest's capture; return the
    two error columns (n_rows,)."""
    with capsys.disabled():
        print("\n" + title)
        for nk, e1, e2 in rows:
            print(f"  n_k = {nk:3d}: {labels[0]} {e1:.2e}, {labels[1]} {e2:.2e}")
    table = np.array(rows)
    return table[:, 1], table[:, 2]


def test_cb_then_gsi(fe, capsys):
    model, pairs = fe
    n = model.n_dof
    cb = craig_bampton(model, 40, interface="IFACE", active="ACTIVE")
    # physical DoFs -> positions in the CB coordinates q = [x_m, eta]
    pos = -np.ones(n, dtype=np.int64)
    pos[cb.master_index] = np.arange(cb.n_masters)
    pairs_cb = ContactPairs(pos[pairs.dofs_a], pairs.dofs_b, pairs.frames, pairs.stiffness)
    iface = pairs_cb.dofs
    act_fe = model.dof_indices("ACTIVE")
    active = pos[act_fe]
    # the GSI basis of the CB model spans what the FE model's does (same CC modes)
    B_fe, _ = gsi_basis(model.K, model.M, pairs.dofs, act_fe, pairs, 10, 10)
    B_cb, _ = gsi_basis(cb.K, cb.M, iface, active, pairs_cb, 10, 10)
    # same DoF order: pairs.dofs and pairs_cb.dofs follow sorted FE indices = master order
    assert np.array_equal(cb.master_index[iface], pairs.dofs)
    P_fe, P_cb = B_fe @ B_fe.T, B_cb @ B_cb.T
    assert np.linalg.norm(P_fe - P_cb) < 1e-6 * np.linalg.norm(P_fe)

    # stuck interface FRF: full FE (reference), CB, CB + GSI
    f = np.zeros(n)
    f[act_fe] = [1.0, 0.4, 0.7]
    Kst = (model.K + stick_stiffness(pairs, n)).toarray()
    w = np.sqrt(sla.eigh(Kst, model.M.toarray(), eigvals_only=True, subset_by_index=[0, 5]))
    om = np.linspace(0.3 * w[0], 1.1 * w[5], 300)
    ref = _frf(Kst, model.M.toarray(), contact_matrix(pairs, n), f, om)
    fq = np.zeros(cb.K.shape[0])
    fq[active] = f[act_fe]
    g_cb = contact_matrix(pairs_cb, cb.K.shape[0])
    x_cb = _frf(cb.K + stick_stiffness(pairs_cb, cb.K.shape[0]).toarray(), cb.M, g_cb, fq, om)
    e_cb = _rel(x_cb, ref)
    rows = []
    for nf, ns in ((2, 2), (4, 4), (8, 8), (16, 16), (38, iface.size - 38)):
        B, x, _ = _gsi_frfs(cb, iface, active, pairs_cb, nf, ns, fq, om)
        rows.append((B.shape[1], _rel(x, x_cb), _rel(x, ref)))
    e, _ = _error_table(capsys, f"ccx block, {iface.size} interface DoFs, CB 40 modes (CB vs "
                        f"FE stuck interface FRF error {e_cb:.2e}); CB+GSI:",
                        ("vs CB", "vs FE"), rows)
    assert np.all(np.diff(e) < 0)
    assert e[-1] < 1e-10                 # complete interface basis: the CB model itself
    assert e[-2] < 2e-2 and e_cb < 1e-2  # 32 GSI modes for 3x25 DoFs: within 2 %


@pytest.mark.slow
def test_gsi_on_gmsh_lap_joint(tmp_path, capsys):
    """The paper's setting (Sec. 3.2.1): two components joined over an extended contact,
    reduced by CB (ROM_I, the benchmark), then GSI with free + full-stick modes per side
    (ROM_II). The stuck and free interface FRFs of ROM_II converge to ROM_I's."""
    pytest.importorskip("gmsh")
    import lap_joint
    from frirom.reduction.rom import pairs_from_node_sets

    job = block.run_ccx(lap_joint.write_lap_joint_deck(tmp_path / "lap.inp", size=0.008,
                                                       n_ref_modes=0))
    model = read_calculix(job)
    pairs = pairs_from_node_sets(model, "CONTACT_A", "CONTACT_B", [0.0, 0.0, 1.0],
                                 kt=5e7, kn=2e8)
    cb = craig_bampton(model, 40, interface="IFACE", active="ACTIVE")
    pos = -np.ones(model.n_dof, dtype=np.int64)
    pos[cb.master_index] = np.arange(cb.n_masters)
    pq = ContactPairs(pos[pairs.dofs_a], pos[pairs.dofs_b], pairs.frames, pairs.stiffness)
    iface = pq.dofs
    active = pos[model.dof_indices("ACTIVE")]
    side_a = np.isin(iface, pq.dofs_a)
    groups = [np.nonzero(side_a)[0], np.nonzero(~side_a)[0]]
    nq = cb.K.shape[0]
    fq = np.zeros(nq)
    fq[active] = [0.2, 0.3, 1.0]
    ks = sp.diags(pq.stiffness.ravel())
    g1 = contact_matrix(pq, nq)
    k1 = cb.K + (g1.T @ ks @ g1).toarray()
    w = np.sqrt(sla.eigh(k1, cb.M, eigvals_only=True, subset_by_index=[0, 5]))
    om = np.linspace(0.3 * w[0], 1.1 * w[5], 300)
    ref_s = _frf(k1, cb.M, g1, fq, om)
    ref_f = _frf(cb.K, cb.M, g1, fq, om)
    rows = []
    for n in (2, 4, 8, 16):
        B, xs, xf = _gsi_frfs(cb, iface, active, pq, n, n, fq, om, groups=groups)
        assert np.abs(B.T @ B - np.eye(B.shape[1])).max() < 1e-12
        rows.append((B.shape[1], _rel(xs, ref_s), _rel(xf, ref_f)))
    es, ef = _error_table(capsys, f"gmsh lap joint: {pairs.n_elem} contact pairs, {iface.size} "
                          "interface DoFs, CB 40 modes; GSI (free + stick per side) interface "
                          "FRF error vs CB:", ("stuck", "free"), rows)
    assert np.all(np.diff(es) < 0) and np.all(np.diff(ef) < 0)
    assert es[-1] < 2e-2 and ef[-1] < 2e-2
