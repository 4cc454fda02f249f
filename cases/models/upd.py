"""Two blades with an under-platform strip damper, meshed with structured hexahedra, as
CalculiX decks (the bundled UPD case, cases/upd/).

    python cases/models/upd.py --out /tmp/upd     # upd.inp + matrices, and the references

Lattice of spacing ``h`` (default 2 mm); x circumferential, y radial (outwards), z axial.
Blade i (x offset 20 i h): a root block clamped at y = 0, a platform, a thin airfoil; the
platforms of the two blades leave a gap of 2 h. The damper, a strip 10 h x 2 h x 8 h under
the gap, touches each platform's underside (y = 10 h) over 4 h x 8 h. Bodies share no
node: the damper is held only by its contacts. Every face lies on a lattice plane, so the
damper's top nodes and the platforms' underside nodes coincide (node-to-node pairs).

Node sets: DAMPER_L, DAMPER_R (the damper's contact patches), PLAT_0, PLAT_1 (the
platforms' patches), DAMPER (all its nodes), TIP_0, TIP_1 (the airfoils' tip-centre
nodes), FIX (the roots' bottom faces), ALL.

The references: ccx's own eigenfrequencies of the blades without the damper (``free``:
the damper's modes are its rigid motions and ones far above) and of the assembly with the
contact patches joined by springs kt (x, z) and kn (y) pair by pair (``stuck``: SPRING2
elements), written to free.dat and stuck.dat.

The retainer (``retainer`` [N/m], default RETAINER): a soft elastic support of the damper
to the ground, SPRING1 elements on every damper node in x, y and z, the stiffness per
direction split evenly over the nodes. Real dampers sit in a pocket and are kept in place
by it or by a retaining wire; here it gives the damper's rigid motions finite
frequencies (200.8 Hz its translations, 222-228 Hz its rotations: a tenth of the band),
so that once the damper slips on both platforms its mean position is decided by a force
the structure carries in every harmonic, in the HBM and in the time integration alike,
instead of being left free. It is in the matrices (upd.sti) and in stuck.dat (the stuck
frequencies move by 2e-5); free.dat (the blades alone) has no damper. ``retainer = 0``:
the damper held only by its contacts (six rigid motions at 0 Hz).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ccx import (STEEL, matrix_storage_steps, run_ccx, solid_material,  # noqa: E402
                 write_mesh)

#: boxes of each body in lattice units: (x0, x1, y0, y1, z0, z1)
def _blade(i):
    ox = 20 * i
    return [(ox + 7, ox + 13, 0, 10, 0, 10),      # root
            (ox + 1, ox + 19, 10, 12, 0, 10),     # platform
            (ox + 9, ox + 11, 12, 32, 0, 10)]     # airfoil


DAMPER = [(15, 25, 8, 10, 1, 9)]
#: the damper's retainer, N/m per direction (the whole damper): 1.6e4 N/m puts its
#: translations on the retainer near 200 Hz (mass 10.0 g), 1/10 of the band; it is
#: 8.9e-5 of the contacts' stuck tangential stiffness on the full model (90 x 2e6 N/m),
#: 2.7e-4 on the coarse one (30 pairs)
RETAINER = 1.6e4
#: contact patches (x0, x1) at y = 10, z in [1, 9]: left on blade 0, right on blade 1
PATCHES = {"L": (15, 19, 0), "R": (21, 25, 1)}


def _body(boxes):
    """(lattice points (m, 3) int, hexahedra (c, 8) indices into them) of a union of
    boxes."""
    cells = set()
    for x0, x1, y0, y1, z0, z1 in boxes:
        for i in range(x0, x1):
            for j in range(y0, y1):
                for k in range(z0, z1):
                    cells.add((i, j, k))
    cells = sorted(cells)
    corners = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
               (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    pts = sorted({(i + a, j + b, k + c) for i, j, k in cells for a, b, c in corners})
    index = {p: n for n, p in enumerate(pts)}
    hexes = np.array([[index[(i + a, j + b, k + c)] for a, b, c in corners]
                      for i, j, k in cells])
    return np.array(pts), hexes


def upd_mesh(h=0.002, damper=True, stride=1):
    """Node ids, coordinates [m], C3D8 connectivity and node sets of the two blades (and
    the damper). stride: the contact patches' node sets take every stride-th lattice
    point along x and z (2: 3 x 5 pairs a patch instead of 5 x 9; a coarse contact model
    for quick tests, the mesh is the same)."""
    bodies = [_blade(0), _blade(1)] + ([DAMPER] if damper else [])
    ids, xyz, elems, lat = [], [], [], []
    for boxes in bodies:
        pts, hexes = _body(boxes)
        first = len(ids) + 1
        ids += list(range(first, first + len(pts)))
        lat.append(pts)
        xyz.append(pts * h)
        elems.append(hexes + first)
    sets = {}
    for b, pts in enumerate(lat):
        base = 1 + sum(len(p) for p in lat[:b])
        node = base + np.arange(len(pts))
        x, y, z = pts.T
        if b < 2:
            sets[f"TIP_{b}"] = node[(x == 20 * b + 10) & (y == 32) & (z == 5)]
            fix = node[y == 0]
            sets["FIX"] = np.union1d(sets.get("FIX", []), fix).astype(np.int64)
        for side, (x0, x1, blade) in PATCHES.items():
            on = ((y == 10) & (x >= x0) & (x <= x1) & (z >= 1) & (z <= 9)
                  & ((x - x0) % stride == 0) & ((z - 1) % stride == 0))
            if b == 2:
                sets[f"DAMPER_{side}"] = node[on]
            elif b == blade:
                sets[f"PLAT_{blade}"] = node[on]
        if b == 2:
            sets["DAMPER"] = node
    return (np.array(ids), np.vstack(xyz), np.vstack(elems), sets)


def _deck(path, title, ids, xyz, elems, sets, springs=None, n_ref_modes=0, storage=True,
          retainer=0.0):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as fh:
        write_mesh(fh, title, ids, xyz, elems, sets, "C3D8")
        fh.write(solid_material(STEEL))
        if springs is not None:
            pairs, kt, kn = springs
            e0 = len(elems) + 1
            for d in (1, 2, 3):       # every element before the first *SPRING (ccx)
                fh.write(f"*ELEMENT, TYPE=SPRING2, ELSET=SP{d}\n")
                for j, (a, b) in enumerate(pairs):
                    fh.write(f"{e0 + j}, {a}, {b}\n")
                e0 += len(pairs)
            for d, k in ((1, kt), (2, kn), (3, kt)):
                fh.write(f"*SPRING, ELSET=SP{d}\n{d},{d}\n{k:.10e}\n")
        if retainer > 0:
            _retainer(fh, elems, sets, springs, retainer)
        fh.write("*BOUNDARY\nFIX, 1, 3\n")
        if storage:
            fh.write(matrix_storage_steps(n_ref_modes))
        else:
            fh.write(f"*STEP\n*FREQUENCY\n{n_ref_modes}\n*END STEP\n")
    return path


def _retainer(fh, elems, sets, springs, k):
    """SPRING1 elements on every DAMPER node, x, y, z: k [N/m] per direction in all.
    Element numbers follow the C3D8 (and SPRING2) ones."""
    nodes = np.asarray(sets["DAMPER"])
    e0 = len(elems) + 1 + (3 * len(springs[0]) if springs is not None else 0)
    for d in (1, 2, 3):
        fh.write(f"*ELEMENT, TYPE=SPRING1, ELSET=RT{d}\n")
        for j, n in enumerate(nodes):
            fh.write(f"{e0 + j}, {int(n)}\n")
        e0 += len(nodes)
        fh.write(f"*SPRING, ELSET=RT{d}\n{d}\n{k / len(nodes):.10e}\n")


def contact_pairs(xyz, sets):
    """(damper node, platform node) pairs of both patches, matched by position."""
    out = []
    for side, blade in (("L", 0), ("R", 1)):
        a, b = sets[f"DAMPER_{side}"], sets[f"PLAT_{blade}"]
        pb = {tuple(np.round(xyz[n - 1] * 1e6).astype(int)): n for n in b}
        out += [(int(n), int(pb[tuple(np.round(xyz[n - 1] * 1e6).astype(int))])) for n in a]
    return out


def write_upd(out, h=0.002, kt=2.0e6, kn=5.0e6, n_ref_modes=12, stride=1,
              retainer=RETAINER):
    """The matrices (upd.sti/.mas/.dof + upd.inp) and the two references (free.dat,
    stuck.dat); returns the job path. stride: see upd_mesh; retainer [N/m]: the damper's
    elastic support (module docstring; 0: none)."""
    out = Path(out)
    ids, xyz, elems, sets = upd_mesh(h, stride=stride)
    job = run_ccx(_deck(out / "upd.inp", f"UPD, C3D8, h = {h} m", ids, xyz, elems, sets,
                        retainer=retainer))
    pairs = contact_pairs(xyz, sets)
    run_ccx(_deck(out / "stuck.inp", "UPD stuck: patches joined by springs", ids, xyz,
                  elems, sets, (pairs, kt, kn), n_ref_modes, storage=False,
                  retainer=retainer), expect=(".dat",))
    ids0, xyz0, elems0, sets0 = upd_mesh(h, damper=False)
    run_ccx(_deck(out / "free.inp", "UPD free: the blades alone", ids0, xyz0, elems0, sets0,
                  None, n_ref_modes, storage=False), expect=(".dat",))
    return job


def read_eigenfrequencies(dat) -> np.ndarray:
    """The eigenfrequencies [Hz] ccx printed in a .dat file (its E I G E N V A L U E
    table: mode, eigenvalue, rad/time, cycles/time, ...)."""
    lines = Path(dat).read_text().splitlines()
    i = next(k for k, s in enumerate(lines) if "E I G E N V A L U E   O U T P U T" in s)
    out = []
    for s in lines[i + 1:]:
        parts = s.split()
        if len(parts) >= 4 and parts[0].isdigit():
            out.append(float(parts[3]))
        elif out and not s.strip():
            break
    return np.array(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", type=float, default=0.002, help="lattice spacing [m]")
    ap.add_argument("--out", default="upd")
    a = ap.parse_args(argv)
    job = write_upd(Path(a.out), a.h)
    print(f"wrote {job}.inp/.sti/.mas/.dof, free.dat, stuck.dat")


if __name__ == "__main__":
    main()
