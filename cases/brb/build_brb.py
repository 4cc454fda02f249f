"""Build the Brake-Reuss beam case next to brb.toml: gmsh mesh, CalculiX matrices and
CalculiX's own eigenfrequencies (stuck.dat, free.dat), nothing committed.

    python cases/brb/build_brb.py                  # coarse mesh (~3500 nodes, ~1 min)
    python cases/brb/build_brb.py --size fine      # fine mesh (slower)
    frirom modes cases/brb/brb.toml                # linear check: free and stuck limits
    frirom study cases/brb/brb.toml                # forced response at several levels

The model: cases/models/brb.py. The reference springs of stuck.dat are the deck's kt, kn
(read from brb.toml), so the stuck limit of the reduced model and CalculiX's tied model
are the same structure.
"""

from __future__ import annotations

import argparse
import sys
import tomllib
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "models"))
from brb import SIZES, write_brb  # noqa: E402


def contact_stiffness(deck=HERE / "brb.toml"):
    """(kt, kn) of the deck's first [[contacts]] table."""
    with open(deck, "rb") as fh:
        c = tomllib.load(fh)["contacts"][0]
    return float(c["kt"]), float(c["kn"])


def make(out=HERE, size: str = "coarse", references: bool = True) -> Path:
    """Mesh, run ccx (three times with the references); returns the job path (out/brb)."""
    if size not in SIZES:
        raise ValueError(f"build_brb: size {size!r}: expected one of {sorted(SIZES)}")
    kt, kn = contact_stiffness() if references else (None, None)
    return write_brb(Path(out), SIZES[size], kt, kn)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="coarse", choices=sorted(SIZES))
    ap.add_argument("--out", type=Path, default=HERE, help="folder (default: this one)")
    ap.add_argument("--no-references", action="store_true",
                    help="only the matrices, not stuck.dat / free.dat")
    a = ap.parse_args(argv)
    job = make(a.out, a.size, not a.no_references)
    print(f"wrote {job}.inp/.sti/.mas/.dof" + ("" if a.no_references
                                               else ", stuck.dat, free.dat"))


if __name__ == "__main__":
    main()
