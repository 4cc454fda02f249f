"""The Brake-Reuss beam (BRB): two beams bolted in a lap joint at the centre, meshed with
gmsh (10-node tetrahedra) and written as CalculiX decks (the bundled case, cases/brb/).

    python cases/models/brb.py --out /tmp/brb            # brb.inp + matrices, references

x along the beam, y across, z normal to the interface. Beam A spans x in [0, Lh] with its
full height h up to x = Lh - lap and its lower half (z < h/2) over the lap; beam B is its
mirror image, upper half over the lap, full height on to x = 2 Lh - lap. The two halves
touch at z = h/2 over the lap (the friction interface). The bolts are not meshed: their
clamping load is the deck's [[preload]], spread evenly over the interface.

The two beams are meshed together (one conforming mesh, so the two faces of the interface
match node for node) and the nodes they share are then duplicated for beam B: the bodies
share no node, the interface pairs coincide exactly.

Free-free as tested, hung on soft strings: each beam hangs on grounded springs (SPRING1,
x, y, z) at its SUSP nodes (two patches of its top face, at its outer end and at the
inner end of its full-height part), K_SUSP per direction and beam, which put the six
rigid-body modes of the joined beam near 10 Hz, far below the first bending mode
(~200 Hz), and hold each beam on its own with the interface open: the solver's static
harmonic needs a structure without rigid-body motion.

Node sets: CONTACT_A, CONTACT_B (A's and B's face of the interface, node to node), IFACE
(both), SUSP (the strings' nodes), EXC (the drive point: top face at x = 0), OUT (the far
tip, top face at x = 2 Lh - lap), ACTIVE (both), ALL.

References, CalculiX's own eigenfrequencies of the full FE model: ``stuck.dat`` with every
interface pair joined by springs kt (x, y) and kn (z) (the stuck, tied limit the reduced
model must reproduce) and ``free.dat`` with the interface open (two beams on their
strings).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ccx import matrix_storage_steps, run_ccx, solid_material, write_mesh  # noqa: E402
from lap_joint import generate_tet10  # noqa: E402

INCH = 0.0254
#: nominal BRB geometry [m] (docs/cases/brb.md gives the sources): square section 1 in,
#: lap 4.75 in, overall length 28 in
GEOMETRY = dict(length=28 * INCH, width=1 * INCH, height=1 * INCH, lap=4.75 * INCH)
#: 304 stainless steel: E, nu as in Porter & Brake (2023), density of the handbook
SS304 = dict(E=192.31e9, nu=0.3, rho=8000.0)
#: element sizes [m]: "coarse" for tests and the bundled run, "fine" behind an option
SIZES = {"coarse": 0.5 * INCH, "fine": 0.25 * INCH}
#: suspension stiffness per direction and beam [N/m]
K_SUSP = 2.0e3


def brb_mesh(size=SIZES["coarse"], length=GEOMETRY["length"], width=GEOMETRY["width"],
             height=GEOMETRY["height"], lap=GEOMETRY["lap"]):
    """Node ids, coordinates (n, 3) [m], C3D10 connectivity (ne, 10) and node sets."""
    from frirom._optional import require
    gmsh = require("gmsh", "mesh", "meshing the Brake-Reuss beam (gmsh)")
    if not 0 < lap < length / 2 or min(width, height, size) <= 0:
        raise ValueError(f"brb_mesh: bad geometry length={length}, lap={lap}, "
                         f"width={width}, height={height}, size={size}")
    lh = (length + lap) / 2         # each beam's length
    h2 = height / 2
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("brb")
        occ = gmsh.model.occ
        a1 = occ.addBox(0, 0, 0, lh - lap, width, height)
        a2 = occ.addBox(lh - lap, 0, 0, lap, width, h2)
        b1 = occ.addBox(lh - lap, 0, h2, lap, width, h2)
        b2 = occ.addBox(lh, 0, 0, lh - lap, width, height)
        # one conforming mesh over all four blocks; the beams are split afterwards
        occ.fragment([(3, a1), (3, a2)], [(3, b1), (3, b2)])
        occ.synchronize()
        tags, xyz, elems = generate_tet10(gmsh, size)
        # which volume each element belongs to: its centroid's x and z
        cen = np.zeros((len(elems), 3))
        pos = {int(t): p for t, p in zip(tags, xyz)}
        for k in range(4):
            cen += np.array([pos[int(n)] for n in elems[:, k]])
        cen /= 4
    finally:
        gmsh.finalize()
    on_b = (cen[:, 0] > lh) | ((cen[:, 0] > lh - lap) & (cen[:, 2] > h2))
    ids = np.asarray(tags, dtype=np.int64)
    order = np.argsort(ids)
    ids, xyz = ids[order], xyz[order]
    nodes_a = np.unique(elems[~on_b])
    nodes_b = np.unique(elems[on_b])
    shared = np.intersect1d(nodes_a, nodes_b)
    # beam B gets its own copies of the shared nodes
    new = ids.max() + 1 + np.arange(shared.size)
    remap = dict(zip(shared.tolist(), new.tolist()))
    elems = elems.copy()
    eb = elems[on_b]
    elems[on_b] = np.vectorize(lambda n: remap.get(int(n), int(n)))(eb)
    xyz_shared = xyz[np.searchsorted(ids, shared)]
    ids = np.concatenate([ids, new])
    xyz = np.vstack([xyz, xyz_shared])
    tol = 1e-6 * height
    at = xyz_shared
    in_face = ((np.abs(at[:, 2] - h2) < tol) & (at[:, 0] > lh - lap - tol)
               & (at[:, 0] < lh + tol))
    contact_a, contact_b = shared[in_face], new[in_face]     # pair k: a[k] with b[k]
    x, y, z = xyz.T
    top = np.abs(z - height) < tol
    end_len = 0.5 * INCH
    inner_a = (x > lh - lap - end_len - tol) & (x < lh - lap + tol)
    inner_b = (x > lh - tol) & (x < lh + end_len + tol)
    susp = ids[top & ((x < end_len + tol) | (x > length - end_len - tol) | inner_a
                      | inner_b)]

    def nearest_top(x0):
        cand = np.flatnonzero(top)
        k = cand[np.argmin(np.hypot(x[cand] - x0, y[cand] - width / 2))]
        return ids[[k]]

    exc, out_node = nearest_top(0.0), nearest_top(length)
    sets = dict(CONTACT_A=contact_a, CONTACT_B=contact_b,
                IFACE=np.concatenate([contact_a, contact_b]), SUSP=susp, EXC=exc,
                OUT=out_node, ACTIVE=np.concatenate([exc, out_node]))
    return ids, xyz, elems, sets


def _springs(fh, first, sets, xyz_of, pairs_k=None):
    """SPRING1 suspension on SUSP (K_SUSP per direction and beam, split over its nodes)
    and, with pairs_k = (kt, kn), SPRING2 elements joining the interface pairs."""
    susp = sets["SUSP"]
    beam_b = xyz_of(susp)[:, 0] > xyz_of(sets["OUT"])[0, 0] / 2
    e = first
    for d in (1, 2, 3):
        for side in (False, True):
            nodes = susp[beam_b == side]
            fh.write(f"*ELEMENT, TYPE=SPRING1, ELSET=ES{d}{int(side)}\n")
            for n in nodes:
                fh.write(f"{e}, {n}\n")
                e += 1
            fh.write(f"*SPRING, ELSET=ES{d}{int(side)}\n{d}\n{K_SUSP / len(nodes):.9g}\n")
    if pairs_k is not None:
        kt, kn = pairs_k
        for d, k in ((1, kt), (2, kt), (3, kn)):
            fh.write(f"*ELEMENT, TYPE=SPRING2, ELSET=EJ{d}\n")
            for a, b in zip(sets["CONTACT_A"], sets["CONTACT_B"]):
                fh.write(f"{e}, {a}, {b}\n")
                e += 1
            fh.write(f"*SPRING, ELSET=EJ{d}\n{d},{d}\n{k:.10e}\n")


def write_brb_deck(path, size=SIZES["coarse"], material=SS304, joined=None,
                   n_ref_modes=0, storage=True, mesh=None):
    """The CalculiX deck: mesh, suspension, material, and either the matrix-storage step
    (storage) or a *FREQUENCY step of n_ref_modes modes. joined = (kt, kn): the interface
    pairs joined by springs (the stuck reference). Returns the deck path."""
    ids, xyz, elems, sets = mesh if mesh is not None else brb_mesh(size)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    row = {int(i): k for k, i in enumerate(ids)}

    def xyz_of(nodes):
        return xyz[[row[int(n)] for n in nodes]]

    with open(path, "w") as fh:
        write_mesh(fh, f"Brake-Reuss beam, gmsh C3D10, size {size:.4g} m", ids, xyz,
                   elems, sets, "C3D10")
        fh.write(solid_material(material))
        _springs(fh, len(elems) + 1, sets, xyz_of, joined)
        if storage:
            fh.write(matrix_storage_steps(n_ref_modes))
        else:
            fh.write(f"*STEP\n*FREQUENCY\n{n_ref_modes}\n*END STEP\n")
    return path


def write_brb(out, size=SIZES["coarse"], kt=None, kn=None, n_ref_modes=16) -> Path:
    """The matrices (brb.sti/.mas/.dof + brb.inp) and the references stuck.dat (pairs
    joined by kt, kn) and free.dat (interface open); returns the job path. Without kt,
    kn only the matrices."""
    out = Path(out)
    mesh = brb_mesh(size)
    job = run_ccx(write_brb_deck(out / "brb.inp", size, mesh=mesh),
                  expect=(".sti", ".mas", ".dof"))
    if kt is not None and kn is not None:
        run_ccx(write_brb_deck(out / "stuck.inp", size, joined=(kt, kn), mesh=mesh,
                               n_ref_modes=n_ref_modes, storage=False), expect=(".dat",))
        run_ccx(write_brb_deck(out / "free.inp", size, mesh=mesh, n_ref_modes=n_ref_modes,
                               storage=False), expect=(".dat",))
    return job


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="coarse", choices=sorted(SIZES))
    ap.add_argument("--out", default="brb")
    a = ap.parse_args(argv)
    job = write_brb(Path(a.out), SIZES[a.size])
    print(f"wrote {job}.inp/.sti/.mas/.dof")


if __name__ == "__main__":
    main()
