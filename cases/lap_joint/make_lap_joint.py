"""Write the lap joint's CalculiX matrices next to lap_joint.toml (gmsh + ccx, not committed).

    python cases/lap_joint/make_lap_joint.py              # lap.inp/.sti/.mas/.dof here
    python cases/lap_joint/make_lap_joint.py --size 0.006 --out /tmp/lap
    frirom run cases/lap_joint/lap_joint.toml

Two steel plates 100 x 30 x 5 mm overlapping over 30 mm, each clamped at its far end, meshed
with gmsh (C3D10) by cases/models/lap_joint.py; ccx writes the stiffness and mass matrices
(``*FREQUENCY, SOLVER=MATRIXSTORAGE``). Node sets: CONTACT_A, CONTACT_B (the two faces of
the overlap, node to node), IFACE, FIX, ACTIVE (middle of plate B's top face).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "models"))
from ccx import run_ccx  # noqa: E402
from lap_joint import write_lap_joint_deck  # noqa: E402


def make(out=HERE, size: float = 0.008) -> Path:
    """Mesh, run ccx; returns the job path (out/lap, with .sti/.mas/.dof/.inp)."""
    return run_ccx(write_lap_joint_deck(Path(out) / "lap.inp", size=size, n_ref_modes=0))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=float, default=0.008, help="element size [m]")
    ap.add_argument("--out", type=Path, default=HERE, help="folder (default: this one)")
    a = ap.parse_args(argv)
    print(f"wrote {make(a.out, a.size)}.sti/.mas/.dof")


if __name__ == "__main__":
    main()
