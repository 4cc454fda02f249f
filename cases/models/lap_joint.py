"""A lap joint of two steel plates meshed with gmsh (10-node tetrahedra), as a CalculiX deck.

    python cases/models/lap_joint.py --size 0.006 --out /tmp/lap    # deck + ccx matrices

Plate A spans [0, L] x [0, W] x [0, t], plate B [L - a, 2L - a] x [0, W] x [t, 2t]: they
overlap on [L - a, L] x [0, W] at z = t, where the friction contact will act. Each plate
is meshed on its own (no shared nodes: the contact elements join them later), and clamped
at its far end. Node sets: CONTACT_A (A's face in the overlap), CONTACT_B (B's face in the
overlap), IFACE = both, FIX (clamped faces), ACTIVE (the node nearest the middle of B's
top face), ALL. The deck is written from gmsh's API (nodes, C3D10 elements, node sets), so
none of the surface elements of gmsh's own Abaqus export reach ccx.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ccx import STEEL, run_ccx, write_tet10_deck  # noqa: E402

# gmsh's 10-node tetrahedron numbers its last two edge nodes (2-3, 1-3) the other way
# round from Abaqus/CalculiX C3D10 (1-3, 2-3 in 0-based vertices).
GMSH_TO_C3D10 = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]


def generate_tet10(gmsh, size):
    """Mesh gmsh's current (synchronised) model with straight-sided 10-node tetrahedra of
    size <= `size` [m]: node tags (n,), coordinates (n, 3), C3D10 connectivity (ne, 10)."""
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", size / 4)
    gmsh.option.setNumber("Mesh.ElementOrder", 2)
    gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)     # straight edges: flat faces
    gmsh.model.mesh.generate(3)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    etypes, _, enodes = gmsh.model.mesh.getElements(dim=3)
    if list(etypes) != [11]:
        raise RuntimeError(f"gmsh made element types {list(etypes)}, expected 11 (tet10)")
    elems = enodes[0].reshape(-1, 10)[:, GMSH_TO_C3D10].astype(np.int64)
    return tags, xyz.reshape(-1, 3), elems


def lap_joint_mesh(L=0.1, W=0.03, t=0.005, a=0.03, size=0.006):
    """Nodes (ids, xyz), C3D10 connectivity and node sets of the two plates (gmsh)."""
    from frirom._optional import require
    gmsh = require("gmsh", "mesh", "meshing the lap joint (gmsh)")

    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("lap_joint")
        occ = gmsh.model.occ
        # Each plate is two boxes fused conformingly, so its overlap face is a surface.
        a1, a2 = occ.addBox(0, 0, 0, L - a, W, t), occ.addBox(L - a, 0, 0, a, W, t)
        b1, b2 = occ.addBox(L - a, 0, t, a, W, t), occ.addBox(L, 0, t, L - a, W, t)
        occ.fragment([(3, a1)], [(3, a2)])
        occ.fragment([(3, b1)], [(3, b2)])
        occ.synchronize()
        tags, xyz, elems = generate_tet10(gmsh, size)
        eps = 1e-3 * t          # above the OCC bounding-box tolerance, far below t

        def nodes_in_box(x0, y0, z0, x1, y1, z1):
            ids = []
            for dim, tag in gmsh.model.getEntitiesInBoundingBox(x0 - eps, y0 - eps, z0 - eps,
                                                                x1 + eps, y1 + eps, z1 + eps,
                                                                dim=2):
                n, _, _ = gmsh.model.mesh.getNodes(dim, tag, includeBoundary=True)
                ids.append(n)
            return np.unique(np.concatenate(ids)).astype(np.int64)

        # Faces at z = t: A's top and B's bottom coincide, so split them by volume.
        vols_a = gmsh.model.getEntitiesInBoundingBox(-eps, -eps, -eps, L + eps, W + eps,
                                                     t + eps, dim=3)
        a_nodes = np.unique(np.concatenate([gmsh.model.mesh.getElements(3, tag)[2][0]
                                            for _, tag in vols_a])).astype(np.int64)
        face = nodes_in_box(L - a, 0, t, L, W, t)
        contact_a = np.intersect1d(face, a_nodes)
        contact_b = np.setdiff1d(face, a_nodes)
        fix = np.union1d(nodes_in_box(0, 0, 0, 0, W, t),
                         nodes_in_box(2 * L - a, 0, t, 2 * L - a, W, 2 * t))
        top_b = nodes_in_box(L, 0, 2 * t, 2 * L - a, W, 2 * t)
        pos = xyz[np.searchsorted(tags, top_b)]
        active = top_b[[np.argmin(np.hypot(pos[:, 0] - (1.5 * L - a / 2), pos[:, 1] - W / 2))]]
    finally:
        gmsh.finalize()
    ids = tags.astype(np.int64)
    order = np.argsort(ids)
    sets = dict(CONTACT_A=contact_a, CONTACT_B=contact_b,
                IFACE=np.union1d(contact_a, contact_b), FIX=fix, ACTIVE=active)
    return ids[order], xyz[order], elems, sets


def write_lap_joint_deck(path, size=0.006, n_ref_modes=20, material=STEEL, **geom):
    """Mesh the lap joint and write the CalculiX deck; returns the deck path."""
    ids, xyz, elems, sets = lap_joint_mesh(size=size, **geom)
    return write_tet10_deck(path, f"lap joint, gmsh C3D10, size {size} m", ids, xyz, elems,
                            sets, n_ref_modes, material)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=float, default=0.006, help="element size [m]")
    ap.add_argument("--modes", type=int, default=20)
    ap.add_argument("--out", default="lap_joint")
    a = ap.parse_args(argv)
    job = run_ccx(write_lap_joint_deck(Path(a.out) / "lap.inp", a.size, a.modes))
    print(f"wrote {job}.inp/.sti/.mas/.dof/.dat")


if __name__ == "__main__":
    main()
