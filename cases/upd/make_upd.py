"""Write the UPD case's CalculiX matrices and references next to upd.toml (gmsh-free
structured hexahedra + ccx, not committed).

    python cases/upd/make_upd.py                 # upd.inp/.sti/.mas/.dof, free.dat, stuck.dat
    frirom modes cases/upd/upd.toml

Two blades and a strip damper under both platforms (cases/models/upd.py): the matrices
(``*FREQUENCY, SOLVER=MATRIXSTORAGE``), and CalculiX's own eigenfrequencies of the blades
alone (free.dat) and of the assembly with the contact pairs joined by the deck's kt, kn
springs (stuck.dat): the references of the linear limits.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "models"))
from upd import RETAINER, write_upd  # noqa: E402


def make(out=HERE, h: float = 0.002, stride: int = 1, retainer: float = RETAINER) -> Path:
    """Mesh, run ccx three times; returns the job path (out/upd). stride 2: every other
    lattice point of the contact patches (a coarse contact model for quick tests);
    retainer [N/m]: the damper's soft elastic support per direction (0: the damper held
    only by its contacts; cases/models/upd.py)."""
    return write_upd(Path(out), h, stride=stride, retainer=retainer)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", type=float, default=0.002, help="lattice spacing [m]")
    ap.add_argument("--out", type=Path, default=HERE, help="folder (default: this one)")
    ap.add_argument("--stride", type=int, default=1,
                    help="contact pairs at every stride-th lattice point (2: coarse)")
    ap.add_argument("--retainer", type=float, default=RETAINER,
                    help="the damper's retainer, N/m per direction (0: none)")
    a = ap.parse_args(argv)
    print(f"wrote {make(a.out, a.h, a.stride, a.retainer)}.sti/.mas/.dof, free.dat, stuck.dat")


if __name__ == "__main__":
    main()
