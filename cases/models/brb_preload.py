"""The bolts' clamping load on the Brake-Reuss beam's lap: a static contact solve of the
FE model, and the joint's contact parameters from it (docs/cases/brb.md).

The three bolts are not meshed: each presses the washers' footprints together, beam B's
top face down and beam A's bottom face up (node sets WASHER_B, WASHER_A of
cases/models/brb.py), with its measured preload spread evenly over the nodes of its
footprint. The interface pairs (CONTACT_A with CONTACT_B, node to node) carry it through
stiff unilateral springs kp in the normal direction (frictionless, hard contact in the
limit): an active-set iteration on the assembled stiffness K of CalculiX's matrices (its
strings included, which the self-balanced bolt loads do not load) drops the pairs that
would pull and takes back the ones that would close, until none changes. Each pair's
normal force n0 is what the joint's friction law is preloaded with: concentrated around
the bolts, nothing at the ends of the lap, which the bolts' clamping leaves open.

The contact stiffness of a pair follows its load, kn = n0 / DELTA_N (a rough surface's
normal stiffness grows in proportion to its load for an exponential distribution of
asperity heights: Greenwood & Williamson, Proc. R. Soc. A 295 (1966) 300-319), and
kt = KT_OVER_KN kn (Mindlin's ratio 2 (1 - nu) / (2 - nu) of an elastic contact,
nu = 0.3). DELTA_N, the one length, is calibrated so that the stuck first bending mode
of the full FE model is the published 168.5 Hz (brb.md gives the numbers).

The friction law has one parameter set per [[contacts]] table, so the pairs are grouped
by their n0 into N_GROUPS tables of equal size (LAP1 .. LAPn, n0 and the stiffnesses the
group's mean): :func:`contact_groups`.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: per-bolt clamping load [N]: the mean of the three measured ones, 12 002, 12 075 and
#: 12 670 N (tmdsimpy, examples/structures/brb_epmc.py, after Porter & Brake 2023)
BOLT_LOAD = (12002.0 + 12075.0 + 12670.0) / 3
#: the normal penalty of the static solve, per pair [N/m] (hard contact: the pressure
#: field changes by < 1e-3 of the peak from 1e11 to 1e12)
KP_STATIC = 1.0e11
#: kn = n0 / DELTA_N [m]: calibrated to the published stuck first bending mode, 168.5 Hz
DELTA_N = 3.0e-8
#: kt / kn (Mindlin, nu = 0.3)
KT_OVER_KN = 2 * (1 - 0.3) / (2 - 0.3)
#: friction coefficient: Porter & Brake's, whose model gave the published backbone
#: (tmdsimpy brb_epmc.py, mu = 0.03; brb.md shows mu = 0.6 beside it)
MU = 0.03
#: number of [[contacts]] tables the loaded pairs are grouped into
N_GROUPS = 8


def pair_nodes(fe, tol=1e-7):
    """(a, b): node ids of CONTACT_A and their coincident partners in CONTACT_B, and the
    coordinates (n, 3) of the pairs."""
    from scipy.spatial import cKDTree
    row = {int(n): k for k, n in enumerate(fe.node_ids)}
    a = np.asarray(fe.node_sets["CONTACT_A"])
    b = np.asarray(fe.node_sets["CONTACT_B"])
    xa = fe.coords[[row[int(n)] for n in a]]
    xb = fe.coords[[row[int(n)] for n in b]]
    d, k = cKDTree(xb).query(xa)
    if d.max() > tol or np.unique(k).size != k.size:
        raise ValueError(f"brb_preload: CONTACT_A and CONTACT_B do not pair node to node "
                         f"(largest distance {d.max():.3g} m)")
    return a, b[k], xa


def _dof_index(fe):
    return {(int(n), int(d)): i for i, (n, d) in enumerate(fe.dofs)}


def bolt_loads(fe, centres, load=BOLT_LOAD):
    """Harmonic-0 load vector of the bolts: each bolt's load on the washer nodes nearest
    its axis (x of `centres`), +z on WASHER_A, -z on WASHER_B, evenly per node."""
    idx = _dof_index(fe)
    row = {int(n): k for k, n in enumerate(fe.node_ids)}
    F = np.zeros(fe.n_dof)
    for name, sign in (("WASHER_A", 1.0), ("WASHER_B", -1.0)):
        nodes = np.asarray(fe.node_sets[name])
        x = fe.coords[[row[int(n)] for n in nodes], 0]
        which = np.argmin(np.abs(x[:, None] - np.asarray(centres)[None, :]), axis=1)
        for j in range(len(centres)):
            mine = nodes[which == j]
            if mine.size == 0:
                raise ValueError(f"brb_preload: no node of {name} under bolt {j + 1}")
            for n in mine:
                F[idx[(int(n), 3)]] += sign * load / mine.size
    return F


def spring_matrix(fe, groups):
    """Stiffness of springs joining node pairs: groups of (a_nodes, b_nodes, k, dirs)
    with k per spring (scalar or per pair) along the directions dirs (1..3)."""
    idx = _dof_index(fe)
    rows, cols, vals = [], [], []
    for a, b, k, dirs in groups:
        kk = np.broadcast_to(np.asarray(k, float), (len(a),))
        for d in dirs:
            for na, nb, kv in zip(a, b, kk):
                if kv <= 0:
                    continue
                i, j = idx[(int(na), d)], idx[(int(nb), d)]
                rows += [i, j, i, j]
                cols += [i, j, j, i]
                vals += [kv, kv, -kv, -kv]
    return sp.csr_matrix((vals, (rows, cols)), shape=fe.K.shape)


def static_preload(fe, centres, load=BOLT_LOAD, kp=KP_STATIC, bolts=(), max_iter=60):
    """Normal force n0 [N] of every interface pair (order of :func:`pair_nodes`) under the
    bolts' loads, by an active-set iteration of unilateral springs kp; returns
    (n0, info) with info the iterations and the pairs in contact. bolts: the shanks'
    springs (b_nodes, a_nodes, k) in the matrices, taken out of K here: tightening sets
    the preload, their stiffness acts on the vibration about it."""
    a, b, _ = pair_nodes(fe)
    idx = _dof_index(fe)
    ia = np.array([idx[(int(n), 3)] for n in a])
    ib = np.array([idx[(int(n), 3)] for n in b])
    F = bolt_loads(fe, centres, load)
    K = sp.csr_matrix(fe.K) - spring_matrix(fe, [(nb, na, k, (3,)) for nb, na, k in bolts])
    npair = a.size
    # G: gaps v = u_z(a) - u_z(b) (> 0 closes: beam A below, pushed up into beam B)
    G = sp.csr_matrix((np.r_[np.ones(npair), -np.ones(npair)],
                       (np.r_[np.arange(npair), np.arange(npair)], np.r_[ia, ib])),
                      shape=(npair, fe.n_dof))
    active = np.ones(npair, bool)
    for it in range(1, max_iter + 1):
        D = sp.diags(np.where(active, kp, 0.0))
        u = spla.spsolve((K + G.T @ D @ G).tocsc(), F)
        v = G @ u
        new = v > 0.0
        if np.array_equal(new, active):
            break
        active = new
    else:
        raise RuntimeError(f"brb_preload: active set not settled in {max_iter} iterations")
    n0 = np.where(active, kp * v, 0.0)
    return n0, dict(iterations=it, closed=int(active.sum()), pairs=npair,
                    total=float(n0.sum()))


def contact_groups(n0, n_groups=N_GROUPS):
    """Group the loaded pairs (n0 > 0) into n_groups of equal size by n0: a list of index
    arrays (highest load first); the open pairs are in no group."""
    on = np.flatnonzero(n0 > 0)
    order = on[np.argsort(-n0[on], kind="stable")]
    return [g for g in np.array_split(order, n_groups) if g.size]


def group_parameters(n0, groups, delta_n=DELTA_N, ratio=KT_OVER_KN):
    """Per group: (n0 mean, kt, kn) with kn = n0 / delta_n, kt = ratio kn [N, N/m]."""
    out = []
    for g in groups:
        m = float(n0[g].mean())
        out.append((m, ratio * m / delta_n, m / delta_n))
    return out


def stuck_modes(fe, a, b, kt, kn, n_modes=12, f_shift=150.0):
    """Eigenfrequencies [Hz] of the full FE model with pair k joined by springs kt[k]
    (x, y) and kn[k] (z), and each mode's share of z motion at the tips (EXC, OUT): the
    bending modes normal to the lap have it near 1."""
    idx = _dof_index(fe)
    Kj = spring_matrix(fe, [(a, b, kt, (1, 2)), (a, b, kn, (3,))])
    sig = (2 * np.pi * f_shift) ** 2
    w2, V = spla.eigsh((fe.K + Kj).tocsc(), n_modes, fe.M.tocsc(), sigma=sig, which="LM")
    order = np.argsort(w2)
    w2, V = w2[order], V[:, order]
    tips = [int(n) for s in ("EXC", "OUT") for n in fe.node_sets[s]]
    zs = np.array([[abs(V[idx[(n, d)], m]) for d in (1, 2, 3)] for m in range(V.shape[1])
                   for n in tips]).reshape(V.shape[1], len(tips), 3)
    share = (zs[:, :, 2] ** 2).sum(1) / np.maximum((zs ** 2).sum((1, 2)), 1e-300)
    return np.sqrt(np.abs(w2)) / (2 * np.pi), share
