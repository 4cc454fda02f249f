"""A steel cantilever with a friction pad on a side face (gmsh tet10, CalculiX matrices).

    python cases/models/cantilever_pad.py --out /tmp/cant            # deck + ccx matrices
    python cases/models/cantilever_pad.py --out /tmp/cant --size 0.01  # coarse (tests)

The beam [0, L] x [0, W] x [0, T] is clamped on x = 0 and bends in z under a tip load. A
rigid pad (the ground) presses on the side face y = 0 over x0 <= x <= x1: every node of
that patch is one ``normal1d`` contact with the ground (normal -y, i.e. v > 0 when the beam
moves into the pad; friction along z). The beam is split into three boxes fused
conformingly so that the patch is a surface of its own. Node sets: PAD (the patch), FIX,
ACTIVE (the tip node nearest the middle of the top edge), ALL.

:func:`deck_text` writes the frirom deck of the reduced model: Craig-Bampton, GSI interface
modes of the pad, the preload n0 balanced by a static load on the pad nodes, modal
damping. This is the model of issue 9 item 1 (Hill stability of friction resonances).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ccx import STEEL, run_ccx, write_tet10_deck  # noqa: E402
from lap_joint import generate_tet10  # noqa: E402

GEOMETRY = dict(L=0.2, W=0.02, T=0.02, x0=0.08, x1=0.12)   # m


def cantilever_pad_mesh(size=0.006, L=0.2, W=0.02, T=0.02, x0=0.08, x1=0.12):
    """Nodes (ids, xyz), C3D10 connectivity and node sets of the beam (gmsh)."""
    from frirom._optional import require
    gmsh = require("gmsh", "mesh", "meshing the cantilever (gmsh)")

    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("cantilever_pad")
        occ = gmsh.model.occ
        boxes = [occ.addBox(a, 0, 0, b - a, W, T) for a, b in ((0, x0), (x0, x1), (x1, L))]
        occ.fragment([(3, boxes[0])], [(3, b) for b in boxes[1:]])
        occ.synchronize()
        tags, xyz, elems = generate_tet10(gmsh, size)
    finally:
        gmsh.finalize()
    ids = tags.astype(np.int64)
    order = np.argsort(ids)
    ids, xyz = ids[order], xyz[order]
    tol = 1e-6 * L
    pad = ids[(np.abs(xyz[:, 1]) < tol) & (xyz[:, 0] > x0 - tol) & (xyz[:, 0] < x1 + tol)]
    fix = ids[np.abs(xyz[:, 0]) < tol]
    tip = np.flatnonzero((np.abs(xyz[:, 0] - L) < tol) & (np.abs(xyz[:, 2] - T) < tol))
    active = ids[tip[[np.argmin(np.abs(xyz[tip, 1] - W / 2))]]]
    return ids, xyz, elems, dict(PAD=pad, FIX=fix, ACTIVE=active)


def write_cantilever_pad_deck(path, size=0.006, n_ref_modes=0, material=STEEL):
    """Mesh the beam and write its CalculiX deck (matrix storage); returns the path."""
    ids, xyz, elems, sets = cantilever_pad_mesh(size=size, **GEOMETRY)
    return write_tet10_deck(path, f"cantilever with a side pad, gmsh C3D10, size {size} m",
                            ids, xyz, elems, sets, n_ref_modes, material)


def make(out, size=0.006) -> Path:
    """Mesh, run ccx; returns the job path (out/cant with .sti/.mas/.dof/.inp)."""
    return run_ccx(write_cantilever_pad_deck(Path(out) / "cant.inp", size=size))


def deck_text(job="cant", H=3, samples=64, cb_modes=10, gsi=(10, 10), law="normal1d",
              force=2.0, n0=1.0, mu=0.3, kt=3.0e4, kn=1.0e5, zeta=0.002,
              f_range=(480.0, 520.0), stability=True) -> str:
    """The frirom deck of the reduced cantilever (a pad pair per node of PAD).

    force: tip load amplitude [N] (z); n0: preload per pad node [N], balanced by a static
    load; kt, kn [N/m] per node; f_range [Hz]. law 'jenkins' drops the normal direction.
    """
    if law == "normal1d":
        contact = (f'law = "normal1d"\nnormal = [0.0, -1.0, 0.0]\ntangent = [0.0, 0.0, 1.0]\n'
                   f"kt = {kt}\nkn = {kn}\nmu = {mu}\nn0 = {n0}\n")
        preload = ("\n[[excitation.load]]\ndof = \"PAD:y\"\nharmonic = 0\n"
                   f"amplitude = {-n0}\n")
    else:
        contact = (f'law = "jenkins"\nnormal = [0.0, -1.0, 0.0]\ntangent = [0.0, 0.0, 1.0]\n'
                   f"kt = {kt}\nmu = {mu}\nfn0 = {n0}\n")
        preload = ""
    return f"""title = "cantilever with a friction pad, CB + GSI"

[fe_model]
format = "calculix"
job = "{job}"

[reduction]
interface = ["PAD"]
active = "ACTIVE"
fixed_interface_modes = {cb_modes}

[reduction.interface_modes]
method = "gsi"
free = {gsi[0]}
stick = {gsi[1]}

[[contacts]]
name = "pad"
a = "PAD"
{contact}
[damping]
type = "modal"
zeta = {zeta}

[[excitation.load]]
dof = "ACTIVE:z"
amplitude = {force}
{preload}
[solver]
harmonics = {H}
samples = {samples}
stability = {str(stability).lower()}

[frequency]
start = {f_range[0]}
end = {f_range[1]}

[outputs]
dofs = ["ACTIVE:z"]
"""


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=float, default=0.006, help="element size [m]")
    ap.add_argument("--out", type=Path, default=Path("cantilever_pad"))
    ap.add_argument("-H", type=int, default=3, help="harmonics of the deck")
    ap.add_argument("--law", default="normal1d", choices=("normal1d", "jenkins"))
    a = ap.parse_args(argv)
    job = make(a.out, a.size)
    (a.out / "cant.toml").write_text(deck_text(H=a.H, law=a.law))
    print(f"wrote {job}.inp/.sti/.mas/.dof and {a.out / 'cant.toml'}")


if __name__ == "__main__":
    main()
