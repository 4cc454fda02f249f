"""meson test and tests/test_install.py: the whole-solve programs of examples/ (frf_joint.f90
through frirom_solve, frf_joint.c through frirom_frf) reproduce frirom.solver.frf on the
joint deck.

Usage: python capi_compare.py PROGRAM [PROGRAM ...]. Each program prints
"omega amp(tip:x) amp(platform:x) amp(platform:y)" per point, then "complete FLAG NPTS".
The reference is the deck solved in Python with the programs' route (receptances by
factorisation, no stability: contact coordinates, as the library chooses). Tolerance: the
same points (count and completion), frequencies and peak amplitudes within 1e-12 of their
largest value: the programs and Python run the same driver on the same numbers (measured
0: bit for bit). It was 1e-7 while the deck normalised the already-unit contact direction
(cos 30, sin 30) by its norm 1 - 1e-16, one ulp off the programs' G, which the continuation
carried along the 164 points to 4e-10. tests/test_install.py builds the library again with
the README's commands (other compiler flags) and allows 1e-8 (measured 7.2e-10).
"""

import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
TOL = 1e-12


def run(program):
    out = subprocess.run([program], capture_output=True, text=True, check=True).stdout
    rows, complete = [], None
    for line in out.splitlines():
        words = line.split()
        if words and words[0] == "complete":
            complete = (words[1] in ("T", "1"), int(words[2]))
        elif len(words) == 4:
            rows.append([float(w) for w in words])
    return np.array(rows), complete


def main(programs, tol: float = TOL):
    """0 when every program reproduces Python's FRF within tol (TOL: the same build of
    the library as the Python extension; another build, with its own compiler flags,
    differs by its round-off carried along the curve)."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    from frirom.deck import load_deck
    from frirom.solver import frf

    deck = load_deck(ROOT / "cases" / "joint" / "joint.toml")
    opts = dataclasses.replace(deck.options(), receptances="factorization", stability=False,
                               refine_peak=False)
    labels = ["tip:x", "platform:x", "platform:y"]
    outputs = [deck.dof_labels.index(lab) for lab in labels]
    ref = frf(deck.model(), deck.excitation(), deck.omega_start, deck.omega_end, opts,
              outputs=outputs)
    bad = 0
    for prog in programs:
        rows, complete = run(prog)
        name = Path(prog).name
        if complete != (ref.complete, ref.omega.size) or rows.shape != (ref.omega.size, 4):
            print(f"{name}: {complete} points {rows.shape}, Python {ref.complete} "
                  f"{ref.omega.size}")
            bad += 1
            continue
        e_om = np.abs(rows[:, 0] - ref.omega).max() / np.abs(ref.omega).max()
        e_amp = (np.abs(rows[:, 1:] - ref.amp_max).max(axis=0) / ref.amp_max.max(axis=0)).max()
        ok = e_om <= tol and e_amp <= tol
        bad += not ok
        print(f"{name}: {rows.shape[0]} points, complete {complete[0]}; relative error "
              f"omega {e_om:.1e}, amplitude {e_amp:.1e} (tolerance {tol:g}) "
              f"{'ok' if ok else 'FAILED'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
