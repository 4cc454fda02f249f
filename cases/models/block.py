"""A clamped steel block meshed with hexahedra, written as a CalculiX deck, and ccx runs.

    python cases/models/block.py --nx 12 --ny 4 --nz 4 --out /tmp/block   # deck + matrices

The block [0, L] x [0, W] x [0, H] is clamped on x = 0 (node set FIX). Node sets:
IFACE, the nodes of the free end x = L inside a central patch (the contact interface of a
lap joint); ACTIVE, the node at the middle of the top edge (a response/excitation point);
ALL. Elements: C3D8 (8-node) or C3D20 (20-node). The deck has up to two steps: a
``*FREQUENCY`` step whose eigenvalues ccx prints in ``job.dat`` (the independent reference),
then ``*FREQUENCY, SOLVER=MATRIXSTORAGE``, which writes job.sti/.mas/.dof and ends the run.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ccx import (STEEL, matrix_storage_steps, nset, run_ccx,  # noqa: E402,F401  (re-exported)
                 solid_material)



def block_mesh(nx, ny, nz, size=(0.2, 0.05, 0.05), order=1):
    """Nodes (ids, xyz) and hexahedra (connectivity, ccx node order) of a structured block.

    order 1: C3D8; order 2: C3D20 (midside nodes on the same lattice at half spacing).
    """
    L, W, H = size
    f = 2 if order == 2 else 1
    gx, gy, gz = f * nx + 1, f * ny + 1, f * nz + 1
    nid = -np.ones((gx, gy, gz), dtype=np.int64)

    def keep(i, j, k):
        if order == 1:
            return True
        return ((i % 2) + (j % 2) + (k % 2)) <= 1     # no face/body centres in C3D20

    ids, xyz = [], []
    for k in range(gz):
        for j in range(gy):
            for i in range(gx):
                if keep(i, j, k):
                    nid[i, j, k] = len(ids) + 1
                    ids.append(len(ids) + 1)
                    xyz.append((L * i / (gx - 1), W * j / (gy - 1), H * k / (gz - 1)))
    elems = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                a, b, c = f * i, f * j, f * k
                corners = [(0, 0, 0), (f, 0, 0), (f, f, 0), (0, f, 0),
                           (0, 0, f), (f, 0, f), (f, f, f), (0, f, f)]
                conn = [nid[a + di, b + dj, c + dk] for di, dj, dk in corners]
                if order == 2:
                    mids = [(1, 0, 0), (2, 1, 0), (1, 2, 0), (0, 1, 0),
                            (1, 0, 2), (2, 1, 2), (1, 2, 2), (0, 1, 2),
                            (0, 0, 1), (2, 0, 1), (2, 2, 1), (0, 2, 1)]
                    conn += [nid[a + di, b + dj, c + dk] for di, dj, dk in mids]
                elems.append(conn)
    return np.array(ids), np.array(xyz), np.array(elems, dtype=np.int64)


def write_block_deck(path, nx=12, ny=4, nz=4, size=(0.2, 0.05, 0.05), order=1,
                     n_ref_modes=20, patch=0.6, material=STEEL):
    """Write the CalculiX deck of the clamped block; returns the deck path.

    n_ref_modes : eigenpairs ccx computes in the first step (0: matrix storage only).
    patch : side of the central interface patch on x = L as a fraction of W and H.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    ids, xyz, elems = block_mesh(nx, ny, nz, size, order)
    L, W, H = size
    tol = 1e-9 * max(size)
    fix = ids[np.abs(xyz[:, 0]) < tol]
    end = np.abs(xyz[:, 0] - L) < tol
    inpatch = (np.abs(xyz[:, 1] - W / 2) <= patch * W / 2 + tol) & \
              (np.abs(xyz[:, 2] - H / 2) <= patch * H / 2 + tol)
    iface = ids[end & inpatch]
    top = np.abs(xyz[:, 2] - H) < tol
    d = np.hypot(xyz[:, 0] - L / 2, xyz[:, 1] - W / 2) + np.where(top, 0.0, np.inf)
    active = ids[[int(np.argmin(d))]]
    etype = "C3D20" if order == 2 else "C3D8"
    with open(path, "w") as fh:
        fh.write(f"** clamped block {nx} x {ny} x {nz} {etype}, size {size} m\n")
        fh.write("*NODE, NSET=ALL\n")
        for i, (x, y, z) in zip(ids, xyz):
            fh.write(f"{i}, {x:.12g}, {y:.12g}, {z:.12g}\n")
        fh.write(f"*ELEMENT, TYPE={etype}, ELSET=EALL\n")
        for e, conn in enumerate(elems, start=1):
            items = [str(e)] + [str(c) for c in conn]
            # ccx data lines hold at most 16 entries: continue long elements
            fh.write(", ".join(items[:16]) + ("," if len(items) > 16 else "") + "\n")
            if len(items) > 16:
                fh.write(", ".join(items[16:]) + "\n")
        for name, nodes in (("FIX", fix), ("IFACE", iface), ("ACTIVE", active)):
            fh.write(nset(name, nodes))
        fh.write(solid_material(material))
        fh.write("*BOUNDARY\nFIX, 1, 3\n" + matrix_storage_steps(n_ref_modes))
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nx", type=int, default=12)
    ap.add_argument("--ny", type=int, default=4)
    ap.add_argument("--nz", type=int, default=4)
    ap.add_argument("--order", type=int, default=1, choices=(1, 2))
    ap.add_argument("--modes", type=int, default=20, help="reference modes ccx computes")
    ap.add_argument("--out", default="block")
    a = ap.parse_args(argv)
    out = Path(a.out)
    deck = write_block_deck(out / "block.inp", a.nx, a.ny, a.nz, order=a.order,
                            n_ref_modes=a.modes)
    job = run_ccx(deck)
    print(f"wrote {job}.inp/.sti/.mas/.dof/.dat")


if __name__ == "__main__":
    main()
