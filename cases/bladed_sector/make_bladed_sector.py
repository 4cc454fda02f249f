"""Write the bladed-disk sector's CalculiX matrices next to bladed_sector.toml (ccx, not
committed), and ccx's own cyclic-symmetry frequencies (the clamped-flange reference).

    python cases/bladed_sector/make_bladed_sector.py          # sector.* and cyclic.* here
    python cases/bladed_sector/make_bladed_sector.py --out /tmp/bs
    frirom run cases/bladed_sector/bladed_sector.toml

One 30-degree sector of a 12-sector steel bladed disk with a flange arm
(cases/models/bladed_sector.py): ``sector.inp`` clamps only one node of the flange face per
sector (node set BOLT, the bolt), so that the rest of the face (FLANGE_B) is free for the
friction contacts of the deck; ccx writes the sector's stiffness and mass matrices
(``*FREQUENCY, SOLVER=MATRIXSTORAGE``). ``cyclic.inp`` is the same sector with the whole
flange face clamped under ``*CYCLIC SYMMETRY MODEL``: ccx's frequencies per nodal diameter,
printed at the end, are what a flange stuck all cycle reproduces.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "models"))
from bladed_sector import read_cyclic_eigenvalues, write_sector_decks  # noqa: E402
from ccx import run_ccx  # noqa: E402


def make(out=HERE, n_sectors: int = 12) -> Path:
    """Write and run the two ccx decks; returns the job path (out/sector)."""
    cyc, sec = write_sector_decks(Path(out), n_sectors, n_modes=4, sector_clamp="bolt")
    run_ccx(cyc, expect=(".dat",))
    return run_ccx(sec, expect=(".sti", ".mas", ".dof"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=HERE, help="folder (default: this one)")
    a = ap.parse_args(argv)
    job = make(a.out)
    print(f"wrote {job}.sti/.mas/.dof")
    print("ccx cyclic model, flange face clamped: frequencies [Hz] per nodal diameter")
    for nd, lam in sorted(read_cyclic_eigenvalues(Path(a.out) / "cyclic.dat").items()):
        print(f"  ND {nd}: " + ", ".join(f"{f:.2f}" for f in np.sqrt(lam) / (2 * np.pi)))


if __name__ == "__main__":
    main()
