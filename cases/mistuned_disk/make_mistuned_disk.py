"""Write the tuned sector of the 24-blade lattice disk (tests/_mistuned.py, the one
cases/bench/mistuning.py uses) to ``sector.npz`` beside this script, for the deck
``mistuned_disk.toml``:

    python cases/mistuned_disk/make_mistuned_disk.py

The file holds the sector's stiffness and mass (MatrixMarket-free: CSR arrays), its cyclic
boundaries, the blade DoFs (the blade clamped at its root carries the mistuning), the
masters the reduction keeps, the blade-tip output DoF, the engine-order load of sector 0 and
the shroud contact from each blade tip to the next (jenkins, 2 n columns)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "tests"))
from _mistuned import disk  # noqa: E402

N_BLADES = 24


def main() -> Path:
    from frirom.mistuning_deck import write_sector
    d = disk(N_BLADES, ground=False)
    out = HERE / "sector.npz"
    tip = int(d["tip"][0])          # x of the tip, as cases/bench/mistuning.py
    write_sector(out, d["Ks"], d["Ms"], d["sector"], blade=d["blade"], keep=d["keep"],
                 output=tip, F=d["F"], contacts=d["contacts"])
    print(f"wrote {out}: {d['Ks'].shape[0]} DoFs per sector, {N_BLADES} sectors")
    return out


if __name__ == "__main__":
    main()
