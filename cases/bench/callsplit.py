"""Where one ROM_II FRF of the paper cases spends its wall time, call by call into Fortran
(issue 11's speed-up): per kind of call on the Fortran run object (open: the set-up;
start: the first solve; advance: continuation segments; solve: peak-refinement solves)
the count, wall seconds, the Fortran timers (AFT, assembly, LU, solves, receptances) and
the rest of the Fortran time (the evaluations' untimed products), and the Python time
outside the calls; every part also as a fraction of the FRF's wall time measured in the
same run (min over --repeat runs).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python cases/bench/callsplit.py \
        --flange WORK F0 | --hooks WORK F0 [--repeat 3] [--no-pairs]

--no-pairs: the flange's travelling-wave ROM_II with its selection only (both directions
of the wave; before SolverOptions.pairs), for a before/after comparison.

WORK is a case's work folder made by its make script (paper_flange.py: the folder with
rom1.toml, whose travelling-wave ROM_II is built from ROM_I; paper_hooks: the folder with
the hooks model, rom2_gsi40.toml is (re)written into it). Nothing is timed in the test suite.
"""

from __future__ import annotations

import argparse
import collections
import dataclasses
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "cases" / "paper_flange"), str(ROOT / "cases" / "paper_hooks")]

import numpy as np  # noqa: E402

from frirom import _pack, _run  # noqa: E402
from frirom.solver import frf  # noqa: E402

TIMED = ("aft", "assembly", "factorization", "solve", "receptance")


def _problem(args):
    """(frf positional arguments, keyword arguments) of the chosen case at F0."""
    if args.flange:
        import paper_flange as pf
        work, f0 = Path(args.flange[0]), float(args.flange[1])
        d1, _ = pf.load(work, "rom1")
        quick = json.loads((work / "case.json").read_text())["quick"]
        d = pf.derived(d1, "rom2_tw", pf.QUICK if quick else pf.PAPER)
        model, exc = d.model(), d.excitation()
        exc.F[:, 1:] *= f0 / pf.F0_DECK
        opts = dataclasses.replace(d.options(), stability=False)
        if getattr(args, "no_pairs", False):
            opts = dataclasses.replace(opts, pairs=None)
        return ("flange TW ROM_II", f0, (model, exc, d.omega_start, d.omega_end, opts),
                dict(outputs=d.outputs))
    import paper_hooks as ph
    work, f0 = Path(args.hooks[0]), float(args.hooks[1])
    rom = ph.Rom(work, "rom2", "paper" if "paper" in work.name else "coarse", 40)
    rom.set_preload(f0)
    return ("hooks ROM_II", f0, (rom.model, rom.excitation, rom.deck.omega_start,
                                 rom.deck.omega_end, rom.options),
            dict(outputs=rom.deck.outputs))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--flange", nargs=2, metavar=("WORK", "F0"))
    g.add_argument("--hooks", nargs=2, metavar=("WORK", "F0"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-pairs", action="store_true")
    args = ap.parse_args(argv)
    name, f0, fargs, fkw = _problem(args)
    slots = _pack._TIMER_SLOTS
    # n, wall, fortran, timed, evals, LUs
    stats = collections.defaultdict(lambda: np.zeros(6))
    methods = {k: getattr(_run.Run, k) for k in ("__init__", "start", "advance", "solve")}
    zero = np.zeros(len(slots))

    def counted(kind, fn):
        def wrap(self, *a, **kw):
            t0 = time.perf_counter()
            r = fn(self, *a, **kw)
            tm = zero if r is None else (r if isinstance(r, np.ndarray) else r.timings)
            dt = time.perf_counter() - t0
            stats[kind] += [1, dt, dt if r is None else tm[slots["fortran_total"]],
                            sum(tm[slots[k]] for k in TIMED), tm[slots["evaluations"]],
                            tm[slots["factorizations"]]]
            return r
        return wrap

    best = None
    for k, fn in methods.items():
        setattr(_run.Run, k, counted(k.strip("_").replace("init", "open"), fn))
    try:
        for _ in range(args.repeat):
            stats.clear()
            t0 = time.perf_counter()
            r = frf(*fargs, **fkw)
            wall = time.perf_counter() - t0
            if best is None or wall < best[0]:
                best = (wall, {k: v.copy() for k, v in stats.items()}, len(r))
    finally:
        for k, fn in methods.items():
            setattr(_run.Run, k, fn)
    wall, st, npts = best
    print(f"{name} at F0 = {f0:g}: {npts} points, {wall:.3f} s (min of {args.repeat})")
    print(r.solver_info)
    print("peaks (amplitude m, frequency Hz): " + ", ".join(
        f"{r.peak(k).amplitude:.10e} at {r.peak(k).omega / (2 * np.pi):.8f}"
        for k in range(r.X.shape[1])))
    print(f"{'call kind':<14}{'calls':>6}{'evals':>7}{'wall s':>9}{'timers s':>10}"
          f"{'other F s':>10}{'ms/call':>9}{'of FRF':>8}")
    tot = np.zeros(6)
    for kind, v in sorted(st.items()):
        tot += v
        print(f"{kind:<14}{v[0]:6.0f}{v[4]:7.0f}{v[1]:9.3f}{v[3]:10.3f}{v[2] - v[3]:10.3f}"
              f"{1e3 * v[1] / v[0]:9.1f}{v[1] / wall:8.1%}")
    py = wall - tot[1]
    print(f"{'all calls':<14}{tot[0]:6.0f}{tot[4]:7.0f}{tot[1]:9.3f}{tot[3]:10.3f}"
          f"{tot[2] - tot[3]:10.3f}{1e3 * tot[1] / tot[0]:9.1f}{tot[1] / wall:8.1%}")
    print(f"python outside the calls: {py:.3f} s ({py / wall:.1%}); untimed Fortran per "
          f"evaluation {1e3 * (tot[2] - tot[3]) / tot[4]:.2f} ms; {tot[5]:.0f} Jacobians")


if __name__ == "__main__":
    from _results import record
    record("callsplit", main)
