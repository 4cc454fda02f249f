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


def _rotation_to(axis):
    """Rotation matrix whose third column is the unit ``axis`` (a right-handed frame)."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    e1 = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = e1 - e1 @ a * a
    e1 /= np.linalg.norm(e1)
    return np.column_stack([e1, np.cross(a, e1), a])


def tuned_rotor(n_sectors=7, per_sector=3, radii=(1.0, 1.15, 1.3), n_axial=3, blade=2,
                uniform=False, seed=0, axis=(0.0, 0.0, 1.0), origin=(0.0, 0.0, 0.0),
                k_ground=(2e5, 2e5, 8e5)):
    """A tuned lattice rotor: NZ = N Z angular stations x radii x axial layers, plus a
    blade (a chain of ``blade`` nodes outward) per sector. Sector-periodic by construction:
    every sector has the same (random) angular offsets, stiffnesses and masses. The face at
    axial layer 0 is the interface: its nodes are tied to ground by springs (kt, kt, kn) in
    cylindrical frames. Returns dict with K, M, iface_nodes, iface coords/dofs, blade-tip
    dofs per sector, coords, frame rotation, ground pairs data.
    """
    rng = np.random.default_rng(seed)
    n, z = n_sectors, per_sector
    nz = n * z
    nr = len(radii)
    # sector-periodic perturbations
    dth = np.zeros(z) if uniform else 0.25 * (2 * np.pi / nz) * (rng.random(z) - 0.5)
    dth[0] = 0.0
    dr = 0.03 * rng.standard_normal((z, nr, n_axial))
    dz = 0.03 * rng.standard_normal((z, nr, n_axial))
    dr[:, :, 0] = 0.0          # interface nodes: common radial/axial positions
    dz[:, :, 0] = 0.0
    dth_node = 0.02 * rng.standard_normal((z, nr, n_axial)) / nz
    dth_node[:, :, 0] = 0.0    # interface nodes of a segment share its angle
    idx = -np.ones((nz, nr, n_axial), dtype=np.int64)
    cyl = []
    for k in range(nz):
        for j in range(nr):
            for l in range(n_axial):
                idx[k, j, l] = len(cyl)
                th = 2 * np.pi * k / nz + dth[k % z] + dth_node[k % z, j, l]
                cyl.append((radii[j] + dr[k % z, j, l], th, 0.2 * l + dz[k % z, j, l]))
    edges, kinds, owner = [], [], []
    node_owner = [k // z for k in range(nz) for j in range(nr) for l in range(n_axial)]
    offs = [(dk, dj, dl) for dk in (0, 1) for dj in (-1, 0, 1) for dl in (-1, 0, 1)
            if (dk, dj, dl) > (0, 0, 0)]
    for k in range(nz):
        for j in range(nr):
            for l in range(n_axial):
                for o, (dk, dj, dl) in enumerate(offs):
                    j2, l2 = j + dj, l + dl
                    if 0 <= j2 < nr and 0 <= l2 < n_axial:
                        edges.append((idx[k, j, l], idx[(k + dk) % nz, j2, l2]))
                        kinds.append((k % z) * len(offs) + o)
                        owner.append(k // z)
    n_ring = len(cyl)
    tips = []
    for s in range(n):
        k = s * z + z // 2
        root = [idx[(k + dk) % nz, nr - 1, l] for dk in (-1, 0, 1) for l in range(n_axial)]
        th = 2 * np.pi * k / nz + dth[k % z]
        prev = []
        for b in range(blade):
            cyl.append((radii[-1] + 0.3 * (b + 1), th + 0.01 * b, 0.2 * (n_axial - 1) / 2))
            me = len(cyl) - 1
            node_owner.append(s)
            for o, p in enumerate(root + prev):
                edges.append((p, me))
                kinds.append(1000 + 100 * b + o)
                owner.append(s)
            prev = [me]
        tips.append(len(cyl) - 1)
    cyl = np.array(cyl)
    loc = np.column_stack([cyl[:, 0] * np.cos(cyl[:, 1]), cyl[:, 0] * np.sin(cyl[:, 1]),
                           cyl[:, 2]])
    rot = _rotation_to(axis)
    coords = loc @ rot.T + np.asarray(origin, float)
    edges = np.array(edges)
    kinds = np.array(kinds)
    kval = {q: 1e6 * (0.7 + 0.6 * rng.random()) for q in np.unique(kinds)}
    kax = np.array([kval[q] for q in kinds])
    mvals = 0.02 * (1 + 0.3 * rng.random(z))
    masses = np.array([mvals[(i // (nr * n_axial)) % z] if i < n_ring else 0.03
                       for i in range(len(cyl))])
    K, M = truss(coords, edges, kax, masses)
    iface_nodes = idx[:, :, 0].ravel()
    th_if = cyl[iface_nodes, 1]
    er = np.column_stack([np.cos(th_if), np.sin(th_if), 0 * th_if]) @ rot.T
    et = np.column_stack([-np.sin(th_if), np.cos(th_if), 0 * th_if]) @ rot.T
    ea = np.tile(rot[:, 2], (len(th_if), 1))
    frames = np.stack([et, er, ea], axis=1)         # t1 tangential, t2 radial, n axial
    dofs = 3 * np.arange(len(cyl))[:, None] + np.arange(3)
    # sector 0 alone: its edges and masses, its nodes plus the right boundary (station Z)
    owner = np.array(owner)
    node_owner = np.array(node_owner)
    left = idx[0].ravel()
    right = idx[z % nz].ravel()
    snodes = np.union1d(np.nonzero(node_owner == 0)[0], right)
    Ks, Ms = truss(coords, edges[owner == 0], kax[owner == 0],
                   np.where(node_owner == 0, masses, 0.0))
    sd = dofs[snodes].ravel()
    Ks, Ms = Ks[sd][:, sd].tocsr(), Ms[sd][:, sd].tocsr()
    pos = -np.ones(len(cyl), dtype=np.int64)
    pos[snodes] = np.arange(snodes.size)
    g0 = np.nonzero(node_owner[iface_nodes] == 0)[0]
    node_dofs = 3 * np.arange(snodes.size)[:, None] + np.arange(3)
    sector = {"K": Ks, "M": Ms, "nodes": snodes, "node_dofs": node_dofs,
              "left": pos[left], "right": pos[right],
              "ground_nodes": pos[iface_nodes[g0]], "ground_frames": frames[g0]}
    return {"sector": sector, "node_owner": node_owner, "K": K, "M": M, "coords": coords,
            "dofs": dofs, "iface_nodes": iface_nodes, "tips": np.array(tips),
            "frames": frames, "rot": rot,
            "k_ground": np.tile(np.asarray(k_ground, float), (len(iface_nodes), 1)),
            "n_sectors": n, "nz": nz}


def stuck_rotor(axis, origin, **kw):
    """tuned_rotor with its interface nodes tied to ground by their contact stiffnesses:
    adds "pairs" (the ContactPairs) and "Kt" (dense stuck stiffness) to the dict."""
    from frirom.reduction.interface import ContactPairs, stick_stiffness
    r = tuned_rotor(axis=axis, origin=origin, **kw)
    nodes = r["iface_nodes"]
    r["pairs"] = ContactPairs(r["dofs"][nodes], -np.ones((len(nodes), 3), int), r["frames"],
                              r["k_ground"])
    r["Kt"] = (r["K"] + stick_stiffness(r["pairs"], r["K"].shape[0])).toarray()
    return r
