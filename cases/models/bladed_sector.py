"""One sector of a bladed disk with a flange, as CalculiX decks, and its ccx runs.

    python cases/models/bladed_sector.py --sectors 12 --out /tmp/sector   # decks + ccx runs

The sector (steel, C3D8 hexahedra mapped from a structured (r, theta, z) grid) spans
0 <= theta <= 2 pi / N around the z axis: a disk (r0..r1, 0 <= z <= t), a flange arm at the
bore (r0..r0 + tf, -L <= z <= 0) whose end face z = -L is the flange contact face (node set
FLANGE, clamped in the decks), and a twisted blade (r1..r2) in the middle of the sector.
Node sets: LEFT (theta = 0), RIGHT (theta = 2 pi / N), FLANGE, TIP (a blade-tip node), FIX
(FLANGE without the nodes of LEFT, the dependent cyclic surface: ccx refuses boundary
conditions on it; the cyclic constraint makes them zero anyway), FLANGE_IN and FLANGE_OUT
(the inner (r = r0) and outer edges of the flange face), FLANGE_C (FLANGE_OUT without the
nodes of LEFT: a contact set that holds each node of the rotor once), RIM_L and RIM_R (the
nodes of LEFT and RIGHT at the disk rim, free: faces of a contact with the next sector),
BOLT (the node of FLANGE_IN in the middle of the sector), FLANGE_B (FLANGE without BOLT
and without the nodes of LEFT), FLANGE_CI (FLANGE_C without the nodes of RIGHT: no node of
the cyclic boundaries).

Two decks:
* ``cyclic.inp``: ``*CYCLIC SYMMETRY MODEL`` (LEFT dependent, RIGHT independent) and a
  ``*FREQUENCY`` step with ``*SELECT CYCLIC SYMMETRY MODES`` for nodal diameters 0..N/2;
  ccx prints the eigenvalues of every nodal diameter in ``cyclic.dat`` (the reference).
* ``sector.inp``: the same mesh and boundary conditions without cyclic symmetry and a
  ``*FREQUENCY, SOLVER=MATRIXSTORAGE`` step: ``sector.sti/.mas/.dof``. With
  ``sector_clamp="inner"`` only FLANGE_IN is clamped there (the bolted inner edge), so that
  the outer edge FLANGE_OUT is free for contact elements; with ``sector_clamp="bolt"`` only
  the node BOLT is (one bolt per sector), the rest of the face being free for contacts.
  ``cyclic.inp`` keeps the whole face clamped (the reference a stuck flange contact must
  reproduce).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
# run_ccx is re-exported for the callers of this module
from ccx import (STEEL, matrix_storage_steps, nset, run_ccx,  # noqa: E402,F401
                 solid_material)


def sector_mesh(n_sectors=12, r=(0.10, 0.115, 0.14, 0.17, 0.20, 0.23, 0.26, 0.30),
                n_theta=6, z_disk=(0.0, 0.01, 0.02), z_flange=(-0.04, -0.02),
                blade_cells=(2, 4), twist=0.6, n_copies=1):
    """Nodes (ids, xyz) and C3D8 connectivity of the sector (or of n_copies sectors).

    r: radial grid, the flange arm is the first radial cell, the blade starts at r = 0.20;
    n_theta: angular cells; z_disk / z_flange: axial grids of the disk and of the flange arm
    (below z = 0); blade_cells: angular cell range [a, b) of the blade; twist: blade twist
    [rad/m] (axial offset per unit radius and angle) so that bending and torsion couple;
    n_copies: consecutive sectors meshed together (n_sectors: the whole tuned stage, the
    last sector joined to the first). grid rows are (i, J, k) with J the global angular
    station.
    """
    r = np.asarray(r, float)
    zg = np.concatenate([np.asarray(z_flange, float), np.asarray(z_disk, float)])
    nzf = len(z_flange)                       # axial cells of the flange arm
    alpha = 2 * np.pi / n_sectors
    n_st = n_sectors * n_theta
    ring = n_copies == n_sectors
    i_blade = int(np.searchsorted(r, 0.20 - 1e-12))
    cells = []
    for s in range(n_copies):
        for i in range(len(r) - 1):
            for j in range(n_theta):
                for k in range(len(zg) - 1):
                    flange = i == 0 and k < nzf
                    disk = i < i_blade and k >= nzf
                    blade = (i >= i_blade and k >= nzf
                             and blade_cells[0] <= j < blade_cells[1])
                    if flange or disk or blade:
                        cells.append((i, s * n_theta + j, k))

    def key(i, jj, k):
        return (i, jj % n_st if ring else jj, k)

    used = {}
    for i, jj, k in cells:
        for di in (0, 1):
            for dj in (0, 1):
                for dk in (0, 1):
                    used.setdefault(key(i + di, jj + dj, k + dk), None)
    keys = sorted(used)
    ids = np.arange(1, len(keys) + 1)
    for n, q in zip(ids, keys):
        used[q] = n
    th_mid = 0.5 * (blade_cells[0] + blade_cells[1]) * alpha / n_theta
    xyz = []
    for i, jj, k in keys:
        rr, tt, zz = r[i], jj * alpha / n_theta, zg[k]
        if rr > r[i_blade]:                   # blade nodes: interior of their sector
            local = (jj - (jj // n_theta) * n_theta) * alpha / n_theta
            zz = zz + twist * (rr - r[i_blade]) * (local - th_mid) * rr
        xyz.append((rr * np.cos(tt), rr * np.sin(tt), zz))
    elems = []
    for i, jj, k in cells:
        c = [(i, jj, k), (i + 1, jj, k), (i + 1, jj + 1, k), (i, jj + 1, k),
             (i, jj, k + 1), (i + 1, jj, k + 1), (i + 1, jj + 1, k + 1), (i, jj + 1, k + 1)]
        elems.append([used[key(*q)] for q in c])
    grid = np.array(keys)
    return ids, np.array(xyz), np.array(elems, np.int64), grid, (len(r), n_theta, zg)


# ccx reads at most 20 characters per field: 13 significant digits keep every coordinate
# (sign, exponent included) within that.


def write_sector_decks(out, n_sectors=12, n_modes=8, material=STEEL, sector_clamp="flange",
                       **mesh):
    """Write ``cyclic.inp`` and ``sector.inp`` in ``out``; returns their paths.

    sector_clamp: "flange" (sector.inp clamps FIX, as cyclic.inp), "inner" (sector.inp
    clamps FLANGE_IN only) or "bolt" (BOLT only)."""
    clamps = {"flange": "FIX", "inner": "FLANGE_IN", "bolt": "BOLT"}
    if sector_clamp not in clamps:
        raise ValueError(f"sector_clamp: expected one of {sorted(clamps)}, got "
                         f"{sector_clamp!r}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    ids, xyz, elems, grid, (nr, nth, zg) = sector_mesh(n_sectors, **mesh)
    left = ids[grid[:, 1] == 0]
    right = ids[grid[:, 1] == nth]
    flange = ids[grid[:, 2] == 0]
    fix = np.setdiff1d(flange, left)
    flange_in = ids[(grid[:, 2] == 0) & (grid[:, 0] == 0)]
    flange_out = np.setdiff1d(flange, flange_in)
    flange_c = np.setdiff1d(flange_out, left)
    i_rim = int(np.max(grid[np.isin(ids, left), 0]))     # outermost radial station of LEFT
    rim_l = left[(grid[np.isin(ids, left), 0] == i_rim)]
    rim_r = right[(grid[np.isin(ids, right), 0] == i_rim)]
    bolt = ids[(grid[:, 2] == 0) & (grid[:, 0] == 0) & (grid[:, 1] == nth // 2)]
    flange_b = np.setdiff1d(fix, bolt)
    flange_ci = np.setdiff1d(flange_c, right)
    tip = ids[[int(np.argmax(np.hypot(xyz[:, 0], xyz[:, 1]) + 1e-3 * xyz[:, 2]))]]
    common = []
    common.append(f"** bladed-disk sector with flange, {n_sectors} sectors, C3D8\n")
    common.append("*NODE, NSET=ALL\n")
    common += [f"{i}, {x:.13g}, {y:.13g}, {z:.13g}\n" for i, (x, y, z) in zip(ids, xyz)]
    common.append("*ELEMENT, TYPE=C3D8, ELSET=EALL\n")
    common += [f"{e}, " + ", ".join(str(c) for c in conn) + "\n"
               for e, conn in enumerate(elems, start=1)]
    head = "".join(common)
    mat = solid_material(material)
    paths = []
    for name in ("cyclic", "sector"):
        p = out / f"{name}.inp"
        with open(p, "w") as fh:
            fh.write(head)
            for sname, nodes in (("LEFT", left), ("RIGHT", right), ("FLANGE", flange),
                                 ("FIX", fix), ("TIP", tip), ("FLANGE_IN", flange_in),
                                 ("FLANGE_OUT", flange_out), ("FLANGE_C", flange_c),
                                 ("RIM_L", rim_l), ("RIM_R", rim_r), ("BOLT", bolt),
                                 ("FLANGE_B", flange_b), ("FLANGE_CI", flange_ci)):
                fh.write(nset(sname, nodes))
            fh.write(mat)
            if name == "cyclic":
                fh.write("*SURFACE, NAME=SLEFT, TYPE=NODE\nLEFT\n"
                         "*SURFACE, NAME=SRIGHT, TYPE=NODE\nRIGHT\n"
                         "*TIE, NAME=CYC, CYCLIC SYMMETRY\nSLEFT, SRIGHT\n"
                         f"*CYCLIC SYMMETRY MODEL, N={n_sectors}, NGRAPH=1, TIE=CYC\n"
                         "0., 0., 0., 0., 0., 1.\n")
            clamped = clamps[sector_clamp] if name == "sector" else "FIX"
            fh.write(f"*BOUNDARY\n{clamped}, 1, 3\n")
            if name == "cyclic":
                fh.write(f"*STEP\n*FREQUENCY\n{n_modes}\n"
                         f"*SELECT CYCLIC SYMMETRY MODES, NMIN=0, NMAX={n_sectors // 2}\n"
                         "*END STEP\n")
            else:
                fh.write(matrix_storage_steps())
        paths.append(p)
    return paths


def write_stage_deck(out, n_sectors=12, material=STEEL, **mesh):
    """The whole tuned stage (all sectors meshed), free, with node sets FLANGE (the flange
    contact face of every sector) and TIPS (one blade-tip node per sector, sector 0
    first); ``stage.inp`` with a ``*FREQUENCY, SOLVER=MATRIXSTORAGE`` step."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    ids, xyz, elems, grid, (nr, nth, zg) = sector_mesh(n_sectors, n_copies=n_sectors,
                                                       **mesh)
    flange = ids[grid[:, 2] == 0]
    rad = np.hypot(xyz[:, 0], xyz[:, 1])
    tips = []
    for s in range(n_sectors):
        mine = np.nonzero(grid[:, 1] // nth == s)[0]
        tips.append(ids[mine[np.argmax(rad[mine] + 1e-3 * xyz[mine, 2])]])
    p = out / "stage.inp"
    with open(p, "w") as fh:
        fh.write(f"** bladed-disk stage with flange, {n_sectors} sectors, C3D8\n*NODE\n")
        fh.writelines(f"{i}, {x:.13g}, {y:.13g}, {z:.13g}\n" for i, (x, y, z) in zip(ids, xyz))
        fh.write("*ELEMENT, TYPE=C3D8, ELSET=EALL\n")
        fh.writelines(f"{e}, " + ", ".join(str(c) for c in conn) + "\n"
                      for e, conn in enumerate(elems, start=1))
        fh.write(nset("FLANGE", flange))
        fh.write(nset("TIPS", np.array(tips)))
        fh.write(solid_material(material) + matrix_storage_steps())
    return p


def read_cyclic_eigenvalues(dat) -> dict:
    """{nodal diameter: eigenvalues [rad^2/s^2]} from a ccx cyclic-symmetry ``.dat`` file.

    ccx solves the real form of twice the size, so every eigenvalue of a nodal diameter is
    printed twice (lines 'ND  mode  eigenvalue  omega  f  imag'); the pairs are checked
    (1e-6 relative) and returned once. An unpaired last eigenvalue is dropped.
    """
    raw: dict[int, list] = {}
    for n, line in enumerate(Path(dat).read_text().splitlines(), start=1):
        parts = line.split()
        if len(parts) == 6 and parts[0].isdigit() and parts[1].isdigit():
            try:
                raw.setdefault(int(parts[0]), []).append(float(parts[2]))
            except ValueError:
                raise ValueError(f"{dat}, line {n}: expected an eigenvalue, got {line!r}")
    if not raw:
        raise ValueError(f"{dat}: no cyclic-symmetry eigenvalue lines")
    out = {}
    for nd, vals in raw.items():
        v = np.array(vals[: 2 * (len(vals) // 2)]).reshape(-1, 2)
        if np.any(np.abs(v[:, 0] - v[:, 1]) > 1e-6 * np.abs(v).max()):
            raise ValueError(f"{dat}: eigenvalues of nodal diameter {nd} are not in pairs")
        out[nd] = v.mean(axis=1)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sectors", type=int, default=12)
    ap.add_argument("--modes", type=int, default=8, help="modes per nodal diameter")
    ap.add_argument("--out", default="sector")
    a = ap.parse_args(argv)
    cyc, sec = write_sector_decks(a.out, a.sectors, a.modes)
    run_ccx(cyc, expect=(".dat",))
    run_ccx(sec, expect=(".sti", ".mas", ".dof"))
    for nd, lam in sorted(read_cyclic_eigenvalues(Path(a.out) / "cyclic.dat").items()):
        print(nd, np.sqrt(np.maximum(lam, 0)) / (2 * np.pi))


if __name__ == "__main__":
    main()
