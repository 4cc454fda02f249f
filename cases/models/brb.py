"""The Brake-Reuss beam (BRB): two beams bolted in a lap joint at the centre, meshed with
gmsh (10-node tetrahedra) and written as CalculiX decks (the bundled case, cases/brb/).

    python cases/models/brb.py --out /tmp/brb            # brb.inp + matrices, references

x along the beam, y across, z normal to the interface. Beam A spans x in [0, Lh] with its
full height h up to x = Lh - lap and its lower half (z < h/2) over the lap; beam B is its
mirror image, upper half over the lap, full height on to x = 2 Lh - lap. The two halves
touch at z = h/2 over the lap (the friction interface). The bolts are not meshed: their
clamping load presses the washers' footprints (WASHER_A, WASHER_B) together, and the
normal preload of each interface pair comes from a static contact solve of the FE model
under those loads (cases/models/brb_preload.py).

The two beams are meshed together (one conforming mesh, so the two faces of the interface
match node for node) and the nodes they share are then duplicated for beam B: the bodies
share no node, the interface pairs coincide exactly.

Free-free as tested, hung on soft strings: each beam hangs on grounded springs (SPRING1,
x, y, z) at its SUSP nodes (two patches of its top face, at its outer end and at the
inner end of its full-height part), K_SUSP per direction and beam, which put the six
rigid-body modes of the joined beam near 10 Hz, far below the first bending mode
(~170 Hz), and hold each beam on its own with the interface open: the solver's static
harmonic needs a structure without rigid-body motion.

Node sets: CONTACT_A, CONTACT_B (A's and B's face of the interface, node to node), IFACE
(both), SUSP (the strings' nodes), EXC (the drive point: top face at x = 0), OUT (the far
tip, top face at x = 2 Lh - lap), ACTIVE (both), WASHER_A, WASHER_B (the washers'
footprints on A's bottom and B's top face over the lap), ALL.

References (written by cases/brb/build_brb.py), CalculiX's own eigenfrequencies of the
full FE model: ``stuck.dat`` with the loaded interface pairs joined by springs kt (x, y)
and kn (z) (the stuck limit the reduced model must reproduce) and ``free.dat`` with the
interface open (two beams on their strings).
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
#: BRB geometry [m], from the Abaqus model of the Rice/Tribomechadynamics tutorial
#: (Nidish96/Abaqus4Joints, assets/parts/HALFBEAM.py; docs/cases/brb.md): each half beam
#: 420 mm long (x = -0.36 .. 0.06 m), 25.4 mm square, half height over the 120 mm lap;
#: assembled 720 mm
GEOMETRY = dict(length=0.72, width=1 * INCH, height=1 * INCH, lap=0.12)
#: the three 5/16 in bolts (same source, and NUTWASHERBOLT_516.py): x offsets from the
#: lap's centre [m], hole diameter [m], washer outer radius [m]
BOLTS = dict(offsets=(-0.03, 0.0, 0.03), hole=0.85e-2, washer=0.34375 * INCH)
#: the tutorial's steel (docs/abqtut.org of the same repository, the model whose
#: matrices tmdsimpy's BRB example uses): E = 200 GPa, nu = 0.29, 7800 kg/m^3
SS304 = dict(E=200e9, nu=0.29, rho=7800.0)
#: element sizes [m]: "coarse" for tests and the bundled run, "fine" behind an option
SIZES = {"coarse": 0.5 * INCH, "fine": 0.25 * INCH}
#: suspension stiffness per direction and beam [N/m]
K_SUSP = 2.0e3


def bolt_hardware(rho=SS304["rho"], E=200e9):
    """(mass [kg], axial stiffness [N/m]) of one bolt with its nut and two washers, from
    the dimensions of the tutorial's NUTWASHERBOLT_516.py: hex head and nut 1/2 in across
    flats, 0.203125 in thick; shank 5/16 in, 1.5 in long; washers 11/32 to 11/16 in,
    1/16 in thick. Stiffness: the shank over the grip (beam height + two washers)."""
    hexa = 3 ** 0.5 / 2 * (0.5 * INCH) ** 2            # hexagon of 1/2 in across flats
    t_hex, r_shank = 0.203125 * INCH, 0.15625 * INCH
    a_shank = np.pi * r_shank ** 2
    washer = np.pi * ((0.34375 * INCH) ** 2 - (0.171875 * INCH) ** 2) * 0.0625 * INCH
    vol = hexa * t_hex + a_shank * 1.5 * INCH + (hexa - a_shank) * t_hex + 2 * washer
    grip = GEOMETRY["height"] + 2 * 0.0625 * INCH
    return rho * vol, E * a_shank / grip


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
    # the washers' footprints: beam B's top face and beam A's bottom face over the lap,
    # within the washer's outer radius of a bolt's axis (the nut and the bolt's head
    # press there; the holes are not meshed)
    xc = length / 2
    in_lap = (x > lh - lap - tol) & (x < lh + tol)
    r = np.min([np.hypot(x - (xc + o), y - width / 2) for o in BOLTS["offsets"]], axis=0)
    under = in_lap & (r < BOLTS["washer"] + tol)
    sets["WASHER_B"] = ids[under & top]
    sets["WASHER_A"] = ids[under & (np.abs(z) < tol)]
    return ids, xyz, elems, sets


def _springs(fh, first, sets, xyz_of, joined=None):
    """SPRING1 suspension on SUSP (K_SUSP per direction and beam, split over its nodes)
    and, with joined = [(a_nodes, b_nodes, kt, kn), ...], SPRING2 elements joining each
    group's interface pairs (a[k] with b[k]) by kt (x, y) and kn (z)."""
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
    for g, (a_nodes, b_nodes, kt, kn) in enumerate(joined or ()):
        for d, k in ((1, kt), (2, kt), (3, kn)):
            fh.write(f"*ELEMENT, TYPE=SPRING2, ELSET=EJ{g}_{d}\n")
            for a, b in zip(a_nodes, b_nodes):
                fh.write(f"{e}, {a}, {b}\n")
                e += 1
            fh.write(f"*SPRING, ELSET=EJ{g}_{d}\n{d},{d}\n{k:.10e}\n")
    return e


def bolt_springs(sets, xyz_of):
    """Per bolt, (b_nodes, a_nodes, k) of its shank: each WASHER_B node joined along z to
    the nearest WASHER_A node (in x, y) under the same bolt, the bolt's axial stiffness
    split evenly over its B nodes (k per spring)."""
    _, k_bolt = bolt_hardware()
    wa, wb = np.asarray(sets["WASHER_A"]), np.asarray(sets["WASHER_B"])
    xa, xb = xyz_of(wa), xyz_of(wb)
    ob = np.argmin(np.abs(xb[:, [0]] - bolt_centres()[None, :]), axis=1)
    oa = np.argmin(np.abs(xa[:, [0]] - bolt_centres()[None, :]), axis=1)
    out = []
    for j in range(len(BOLTS["offsets"])):
        ib, ia = np.flatnonzero(ob == j), np.flatnonzero(oa == j)
        if ib.size == 0 or ia.size == 0:
            raise ValueError(f"brb: no washer node under bolt {j + 1}")
        near = [ia[np.argmin(np.hypot(*(xa[ia, :2] - xb[i, :2]).T))] for i in ib]
        out.append((wb[ib], wa[near], k_bolt / ib.size))
    return out


def bolt_centres():
    """x of the bolts' axes [m]."""
    return GEOMETRY["length"] / 2 + np.asarray(BOLTS["offsets"])


def _bolts(fh, first, sets, xyz_of):
    """The bolts' hardware: SPRING2 shanks along z (:func:`bolt_springs`) and its mass as
    MASS elements, half on each washer footprint, evenly per node."""
    m, _ = bolt_hardware()
    e = first
    for j, (nb, na, k) in enumerate(bolt_springs(sets, xyz_of)):
        fh.write(f"*ELEMENT, TYPE=SPRING2, ELSET=EBOLT{j}\n")
        for b, a in zip(nb, na):
            fh.write(f"{e}, {b}, {a}\n")
            e += 1
        fh.write(f"*SPRING, ELSET=EBOLT{j}\n3,3\n{k:.10e}\n")
    for name in ("WASHER_A", "WASHER_B"):
        nodes = np.asarray(sets[name])
        x = xyz_of(nodes)[:, 0]
        which = np.argmin(np.abs(x[:, None] - bolt_centres()[None, :]), axis=1)
        for j in range(len(BOLTS["offsets"])):
            mine = nodes[which == j]
            fh.write(f"*ELEMENT, TYPE=MASS, ELSET=EM{name[-1]}{j}\n")
            for n in mine:
                fh.write(f"{e}, {n}\n")
                e += 1
            fh.write(f"*MASS, ELSET=EM{name[-1]}{j}\n{m / 2 / mine.size:.10e}\n")
    return e


def write_brb_deck(path, size=SIZES["coarse"], material=SS304, joined=None,
                   n_ref_modes=0, storage=True, mesh=None):
    """The CalculiX deck: mesh, suspension, material, and either the matrix-storage step
    (storage) or a *FREQUENCY step of n_ref_modes modes. joined: groups of interface pairs
    joined by springs (the stuck reference; :func:`_springs`). Returns the deck path."""
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
        e = _springs(fh, len(elems) + 1, sets, xyz_of, joined)
        _bolts(fh, e, sets, xyz_of)
        if storage:
            fh.write(matrix_storage_steps(n_ref_modes))
        else:
            fh.write(f"*STEP\n*FREQUENCY\n{n_ref_modes}\n*END STEP\n")
    return path


def write_brb(out, size=SIZES["coarse"]) -> Path:
    """The matrices (brb.sti/.mas/.dof + brb.inp); returns the job path. The bundled case
    (cases/brb/build_brb.py) adds the bolts' preload and CalculiX's references."""
    out = Path(out)
    return run_ccx(write_brb_deck(out / "brb.inp", size, mesh=brb_mesh(size)),
                   expect=(".sti", ".mas", ".dof"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="coarse", choices=sorted(SIZES))
    ap.add_argument("--out", default="brb")
    a = ap.parse_args(argv)
    job = write_brb(Path(a.out), SIZES[a.size])
    print(f"wrote {job}.inp/.sti/.mas/.dof")


if __name__ == "__main__":
    main()
