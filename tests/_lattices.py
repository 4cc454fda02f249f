"""Small test structures built here (independent of the FE readers): 3-D truss lattices of
point masses joined by axial springs, assembled as sparse (K, M)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def truss(coords: np.ndarray, edges: np.ndarray, k_axial, masses):
    """Assemble K, M (3 DoFs per node, x y z) of axial springs between node pairs."""
    n = len(coords)
    d = coords[edges[:, 1]] - coords[edges[:, 0]]
    e = d / np.linalg.norm(d, axis=1)[:, None]
    kk = np.broadcast_to(np.asarray(k_axial, dtype=float), (len(edges),))
    blk = kk[:, None, None] * e[:, :, None] * e[:, None, :]      # (n_e, 3, 3)
    rows, cols, vals = [], [], []
    for (p, q), sgn in (((0, 0), 1.0), ((1, 1), 1.0), ((0, 1), -1.0), ((1, 0), -1.0)):
        r = 3 * edges[:, p][:, None, None] + np.arange(3)[None, :, None]
        c = 3 * edges[:, q][:, None, None] + np.arange(3)[None, None, :]
        rows.append(np.broadcast_to(r, blk.shape).ravel())
        cols.append(np.broadcast_to(c, blk.shape).ravel())
        vals.append(sgn * blk.ravel())
    K = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(3 * n, 3 * n))
    M = sp.diags(np.repeat(np.broadcast_to(np.asarray(masses, float), (n,)), 3)).tocsr()
    return K, M


def lattice_edges(coords: np.ndarray, reach: float) -> np.ndarray:
    """All node pairs closer than ``reach`` (edges and diagonals of a grid)."""
    d = np.linalg.norm(coords[:, None, :] - coords[None, :, :], axis=2)
    i, j = np.nonzero(np.triu(d < reach, 1))
    return np.column_stack([i, j])


def two_blocks(nx=6, ny=4, nz=3, seed=0):
    """Two lattice blocks stacked in z, touching on a plane with coincident node pairs.

    The lower block is clamped on its bottom face, the upper block on its top face. Returns
    dict with K, M (free DoFs only), the contact node DoFs of both sides (n_pair, 3), the
    active DoF (a point inside the upper block, x direction) and the kept-DoF map.
    """
    rng = np.random.default_rng(seed)
    g = np.stack(np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij"),
                 axis=-1).reshape(-1, 3).astype(float)
    jitter = 0.12 * rng.standard_normal(g.shape)
    jitter[:, 2] = np.where(np.isclose(g[:, 2], nz - 1), 0.0, jitter[:, 2])
    lower = g + jitter
    jitter2 = 0.12 * rng.standard_normal(g.shape)
    upper = g + jitter2 + np.array([0.0, 0.0, nz - 1])
    # the contact plane: upper bottom nodes coincide with lower top nodes
    top = np.isclose(g[:, 2], nz - 1)
    bot = np.isclose(g[:, 2], 0)
    upper[bot] = lower[top]
    coords = np.vstack([lower, upper])
    nl = len(lower)
    e1 = lattice_edges(lower, 1.8)
    e2 = lattice_edges(upper, 1.8) + nl
    edges = np.vstack([e1, e2])
    kax = 1e6 * (1.0 + 0.3 * rng.random(len(edges)))
    masses = 0.05 * (1.0 + 0.2 * rng.random(len(coords)))
    K, M = truss(coords, edges, kax, masses)
    fixed_nodes = np.concatenate([np.nonzero(bot)[0], nl + np.nonzero(top)[0]])
    fixed = np.sort((3 * fixed_nodes[:, None] + np.arange(3)).ravel())
    free = np.setdiff1d(np.arange(3 * len(coords)), fixed)
    new = -np.ones(3 * len(coords), dtype=np.int64)
    new[free] = np.arange(free.size)
    K = K[free][:, free].tocsr()
    M = M[free][:, free].tocsr()
    node_a = np.nonzero(top)[0]
    node_b = nl + np.nonzero(bot)[0]
    dofs_a = new[3 * node_a[:, None] + np.arange(3)]
    dofs_b = new[3 * node_b[:, None] + np.arange(3)]
    mid = nl + np.argmin(np.linalg.norm(upper - upper.mean(axis=0), axis=1))
    active = new[3 * mid + np.arange(3)]
    return {"K": K, "M": M, "dofs_a": dofs_a, "dofs_b": dofs_b, "active": active,
            "coords": coords, "map": new}
