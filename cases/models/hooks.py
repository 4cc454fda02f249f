"""A vane segment hooked into a casing sector (paper section 3.2.1), as a CalculiX deck.

    python cases/models/hooks.py --size coarse --out /tmp/hooks      # deck + ccx matrices

One sector of N of a stator stage, axis z, the sector spanning theta in [-alpha/2, alpha/2]
(alpha = 2 pi / N), meshed with structured 20-node hexahedra (C3D20) in cylindrical
coordinates (r, theta, z), so that the faces in contact match node to node:

- the casing: a shell r in [R_c, R_c + t_c] over z in [-e, L + e], clamped at both ends
  (its flanges, node set FIX), with a front and a rear hook rail r in [R_h, R_c] over
  z in [0, a] and [L - a, L]; it runs through the cyclic boundaries (node sets LEFT and
  RIGHT, theta = -alpha/2 and +alpha/2);
- the vane segment: an outer platform r in [R_p, R_h] over z in [0, L] whose front and
  rear ends are the vane's hooks, an airfoil (a flat plate in the (r, z) plane at
  theta = 0, one cell thick) and an inner platform; it stops short of the cyclic
  boundaries (a gap of one cell each side), so it touches the casing only at the hooks
  and the interlocking;
- the hooks: the vane's platform and the casing's rails are separate meshes facing each
  other on the cylinder r = R_h (node sets HOOK_V, vane side, and HOOK_C, casing side,
  node to node; the contact elements of the deck join them);
- the interlocking: a lug of the casing (r in [R_h, R_c], mid-length, over the airfoil's
  theta cell) whose face r = R_h faces the vane's platform. ``interlock="contact"``
  (default): the lug and the platform are separate meshes matching node to node (node
  sets LUG_V, vane side, and LUG_C, casing side, in pair order), joined by the deck's
  preloaded interlocking contact elements; ``interlock="tied"``: the lug's face shares
  its nodes with the platform (the stuck, rigid limit of that contact: the reference).

Node sets: HOOK_V, HOOK_C (contact faces; the vane's side first), AIRFOIL (nodes of the
airfoil's mid-chord line on its pressure side, the excitation/response points),
CASING_OUT (nodes of the casing's outer surface on the mid-sector line), ACTIVE = both,
EXC (the airfoil node at mid-span), OUT (the airfoil node nearest the inner platform),
LEFT, RIGHT, FIX, ALL, and LUG_V, LUG_C with the contact interlocking, and MOUNT (the
vane's nodes on the inner platform's inner face r = R_i).

The soft mount: grounded springs (SPRING1, x, y and z) on the MOUNT nodes, K_MOUNT in all
per direction, which put the vane's six rigid-body modes near 1 Hz. With the contact
interlocking nothing else holds the vane when the contacts are left out, and the cyclic
sector's modes (computed without contacts, as the solver's modal model needs) would
have rigid-body modes at every nodal diameter. The springs are in both variants, so that
the contact lug and the tied one differ by the lug alone; their effect on the 120-200 Hz
resonances is about K_MOUNT / (the modes' modal stiffness), below 1e-4.
 ``size`` "coarse" (tests) or "paper" (about 450 contact DoFs per
hook side, as in the paper). Nothing generated is committed.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ccx import matrix_storage_steps, nset, run_ccx, solid_material  # noqa: E402

#: the paper's steel (section 3.3.1): E 210 GPa, nu 0.33, rho 7800 kg/m^3
STEEL_PAPER = dict(E=2.1e11, nu=0.33, rho=7800.0)

#: mesh sizes: cells across the vane half-width (theta, each side of the airfoil), along
#: one hook (z), along the airfoil span (r) and chord (z), CB and Tran modes of the deck
SIZES = {
    "coarse": dict(n_theta=1, n_hook=1, n_span=4, n_chord=2, sectors=24),
    "paper": dict(n_theta=4, n_hook=2, n_span=8, n_chord=4, sectors=24),
}

# geometry [m]
R_I, T_I = 0.300, 0.004          # inner platform
R_P, R_H = 0.400, 0.406          # outer platform r in [R_P, R_H]; hook faces at r = R_H
R_C, T_C = 0.416, 0.008          # casing shell r in [R_C, R_C + T_C]
L, A_HOOK, E_FL = 0.050, 0.012, 0.010   # axial length, hook length, casing flange overhang
C0, C1 = 0.015, 0.035            # airfoil chord z in [C0, C1]
LUG = 0.006                      # axial length of the interlocking lug (mid-length)
THICK = 0.004                    # airfoil thickness at r = R_P
K_MOUNT = 12.0                   # soft mount of the vane [N/m per direction, all springs]


def _subdivide(breaks, counts):
    """Lattice coordinates: each interval [breaks[i], breaks[i+1]] in counts[i] cells."""
    out = [breaks[0]]
    for x0, x1, n in zip(breaks[:-1], breaks[1:], counts):
        out += list(np.linspace(x0, x1, n + 1)[1:])
    return np.array(out)


def hooks_mesh(n_theta=1, n_hook=1, n_span=4, n_chord=2, sectors=24,
               interlock="contact"):
    """Structured C3D20 mesh of the vane-casing sector; interlock "contact" (the lug's face
    and the platform's as separate matching nodes) or "tied" (shared nodes).

    Returns node ids (n,), coordinates (n, 3), connectivity (ne, 20) and the node sets.
    """
    alpha = 2 * np.pi / sectors
    half = alpha / 2
    dth = THICK / R_P / 2
    gap = (half - dth) / (n_theta + 1)          # one empty cell each side of the vane
    # cell grids: r, theta, z (edges of the cells)
    r_edges = _subdivide([R_I, R_I + T_I, R_P, R_H, R_C, R_C + T_C], [1, n_span, 1, 1, 1])
    t_edges = _subdivide([-half, -half + gap, -dth, dth, half - gap, half],
                         [1, n_theta, 1, n_theta, 1])
    zm0, zm1 = L / 2 - LUG / 2, L / 2 + LUG / 2
    z_edges = _subdivide([-E_FL, 0.0, A_HOOK, C0, zm0, zm1, C1, L - A_HOOK, L, L + E_FL],
                         [1, n_hook, 1, n_chord, 1, n_chord, 1, n_hook, 1])
    rc = 0.5 * (r_edges[:-1] + r_edges[1:])
    tc = 0.5 * (t_edges[:-1] + t_edges[1:])
    zc = 0.5 * (z_edges[:-1] + z_edges[1:])
    R, T, Z = np.meshgrid(rc, tc, zc, indexing="ij")
    in_vane_t = np.abs(T) < half - gap
    hook_z = (Z < A_HOOK) | (Z > L - A_HOOK)
    casing = ((R > R_C) & (R < R_C + T_C)) | \
             ((R > R_H) & (R < R_C) & hook_z & (Z > 0) & (Z < L)) | \
             ((R > R_H) & (R < R_C) & (np.abs(Z - L / 2) < LUG / 2) & (np.abs(T) < dth))
    vane = in_vane_t & (((R > R_P) & (R < R_H) & (Z > 0) & (Z < L)) |
                        ((R > R_I + T_I) & (R < R_P) & (np.abs(T) < dth) &
                         (Z > C0) & (Z < C1)) |
                        ((R < R_I + T_I) & (Z > C0 - A_HOOK / 2) & (Z < C1 + A_HOOK / 2)))
    # half-spacing lattice (C3D20 midside nodes)
    def fine(e):
        f = np.empty(2 * e.size - 1)
        f[0::2] = e
        f[1::2] = 0.5 * (e[:-1] + e[1:])
        return f
    rf, tf, zf = fine(r_edges), fine(t_edges), fine(z_edges)
    corners = [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0),
               (0, 0, 2), (2, 0, 2), (2, 2, 2), (0, 2, 2)]
    mids = [(1, 0, 0), (2, 1, 0), (1, 2, 0), (0, 1, 0),
            (1, 0, 2), (2, 1, 2), (1, 2, 2), (0, 1, 2),
            (0, 0, 1), (2, 0, 1), (2, 2, 1), (0, 2, 1)]
    ids: dict = {}          # (body, i, j, k) -> node id
    elems = []

    def node(body, key):
        if (body,) + key not in ids:
            ids[(body,) + key] = len(ids) + 1
        return ids[(body,) + key]

    # the tie: the vane's platform nodes on r = R_H under the lug are the casing's
    j_h = 2 * int(np.argmin(np.abs(r_edges - R_H)))
    for body, mask in (("c", casing), ("v", vane)):
        for a, b, c in zip(*np.nonzero(mask)):
            keys = [(2 * a + di, 2 * b + dj, 2 * c + dk) for di, dj, dk in corners + mids]
            elems.append([node(body, k) for k in keys])
    lug_face = [k[1:] for k in ids if k[0] == "c" and k[1] == j_h
                and abs(zf[k[3]] - L / 2) <= LUG / 2 + 1e-12 and abs(tf[k[2]]) <= dth + 1e-12]
    lug_pairs = [(ids[("v",) + k], ids[("c",) + k]) for k in lug_face if ("v",) + k in ids]
    if interlock not in ("contact", "tied"):
        raise ValueError(f"interlock must be 'contact' or 'tied', got {interlock!r}")
    remap = dict(lug_pairs) if interlock == "tied" else {}
    elems = np.array([[remap.get(n, n) for n in e] for e in elems], dtype=np.int64)
    keys = np.array([k[1:] for k in ids], dtype=np.int64)
    body = np.array([k[0] for k in ids])
    nid = np.array(list(ids.values()), dtype=np.int64)
    keep = ~np.isin(nid, list(remap))
    keys, body, nid = keys[keep], body[keep], nid[keep]
    r, t, z = rf[keys[:, 0]], tf[keys[:, 1]], zf[keys[:, 2]]
    xyz = np.column_stack([r * np.cos(t), r * np.sin(t), z])
    # renumber 1..n
    new = {int(o): i + 1 for i, o in enumerate(nid)}
    elems = np.vectorize(new.get)(elems)
    nid = np.arange(1, nid.size + 1)
    eps = 1e-9
    on_face = (np.abs(r - R_H) < eps) & ((z < A_HOOK + eps) | (z > L - A_HOOK - eps)) & \
        (z > -eps) & (z < L + eps) & (np.abs(t) < half - gap + eps)
    hook_v = nid[on_face & (body == "v")]
    hook_c = nid[on_face & (body == "c")]
    # pair them in the same order (same lattice key)
    kv = {tuple(k): n for k, n, b in zip(keys, nid, body) if b == "v"}
    hook_v = np.array([kv[tuple(k)] for k, n, b in zip(keys, nid, body)
                       if b == "c" and on_face[n - 1]], dtype=np.int64)
    fix = nid[(np.abs(z + E_FL) < eps) | (np.abs(z - L - E_FL) < eps)]
    left = nid[np.abs(t + half) < eps]
    right = nid[np.abs(t - half) < eps]
    # airfoil pressure side (theta = -dth), mid-chord line; casing outer mid-sector line
    zmid = zf[np.argmin(np.abs(zf - 0.5 * (C0 + C1)))]
    airfoil = nid[(body == "v") & (np.abs(t + dth) < eps) & (np.abs(z - zmid) < eps)
                  & (r > R_I + T_I + eps) & (r < R_P - eps)]
    airfoil = airfoil[np.argsort(xyz[airfoil - 1, 0])]
    casing_out = nid[(np.abs(r - R_C - T_C) < eps) & (np.abs(t) < eps) & (z > eps)
                     & (z < L - eps)]
    ra = np.hypot(xyz[airfoil - 1, 0], xyz[airfoil - 1, 1])
    exc = airfoil[[int(np.argmin(np.abs(ra - 0.5 * (R_I + R_P))))]]
    out = airfoil[[int(np.argmin(ra))]]
    mount = nid[(body == "v") & (np.abs(r - R_I) < eps)]
    sets = {"MOUNT": mount}
    if interlock == "contact":        # the lug's pairs, vane side first, in the same order
        sets["LUG_V"] = np.array([new[v] for v, _ in lug_pairs], dtype=np.int64)
        sets["LUG_C"] = np.array([new[c] for _, c in lug_pairs], dtype=np.int64)
    sets.update(HOOK_V=hook_v, HOOK_C=hook_c, HOOKS=np.union1d(hook_v, hook_c),
                AIRFOIL=airfoil, CASING_OUT=casing_out,
                ACTIVE=np.union1d(airfoil, casing_out), EXC=exc, OUT=out, LEFT=left,
                RIGHT=right, FIX=fix)
    return nid, xyz, elems, sets


def write_hooks_deck(path, size="coarse", n_ref_modes=0, material=STEEL_PAPER,
                     interlock="contact") -> Path:
    """Mesh the sector and write its CalculiX deck (matrix storage); returns the path."""
    if size not in SIZES:
        raise ValueError(f"size must be one of {sorted(SIZES)}, got {size!r}")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    ids, xyz, elems, sets = hooks_mesh(**SIZES[size], interlock=interlock)
    with open(path, "w") as fh:
        fh.write(f"** vane segment hooked into a casing sector, C3D20, size {size}, "
                 f"interlocking {interlock}\n")
        fh.write("*NODE, NSET=ALL\n")
        for i, (x, y, z) in zip(ids, xyz):
            fh.write(f"{i}, {x:.12g}, {y:.12g}, {z:.12g}\n")
        fh.write("*ELEMENT, TYPE=C3D20, ELSET=EALL\n")
        for e, conn in enumerate(elems, start=1):
            items = [str(e)] + [str(c) for c in conn]
            fh.write(", ".join(items[:16]) + ",\n" + ", ".join(items[16:]) + "\n")
        for name, nodes in sets.items():
            fh.write(nset(name, nodes))
        fh.write(soft_mount(sets["MOUNT"], len(elems) + 1))
        fh.write(solid_material(material) + "*BOUNDARY\nFIX, 1, 3\n"
                 + matrix_storage_steps(n_ref_modes))
    return path


def soft_mount(nodes, first: int) -> str:
    """SPRING1 elements (numbered from ``first``) grounding ``nodes`` in x, y and z, with
    K_MOUNT per direction shared equally: the CalculiX text."""
    k = K_MOUNT / len(nodes)
    out = []
    for d in (1, 2, 3):
        e0 = first + (d - 1) * len(nodes)
        out.append(f"*ELEMENT, TYPE=SPRING1, ELSET=EMOUNT{d}\n")
        out += [f"{e0 + j}, {n}\n" for j, n in enumerate(nodes)]
        out.append(f"*SPRING, ELSET=EMOUNT{d}\n{d}\n{k:.9g}\n")
    return "".join(out)


def make_hooks(out, size="coarse", interlock="contact") -> Path:
    """Write and run the deck in ``out`` (job ``hooks``) unless ccx's files are there, newer
    than this generator and of the same size and interlocking; returns the job path."""
    out = Path(out)
    job = out / "hooks"
    gen = Path(__file__).stat().st_mtime
    done = all(job.with_suffix(s).exists() and job.with_suffix(s).stat().st_mtime > gen
               for s in (".inp", ".sti", ".mas", ".dof"))
    stamp = out / "hooks.size"
    tag = size if interlock == "contact" else f"{size} {interlock}"
    if done and stamp.exists() and stamp.read_text() == tag:
        return job
    run_ccx(write_hooks_deck(job.with_suffix(".inp"), size, interlock=interlock),
            expect=(".sti", ".mas", ".dof"))
    stamp.write_text(tag)
    return job


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="coarse", choices=sorted(SIZES))
    ap.add_argument("--out", default="hooks")
    ap.add_argument("--interlock", default="contact", choices=("contact", "tied"))
    a = ap.parse_args(argv)
    job = make_hooks(Path(a.out), a.size, a.interlock)
    print(f"wrote {job}.inp/.sti/.mas/.dof")


if __name__ == "__main__":
    main()
