"""Benchmark of the condensed Jacobian when the contact columns are dense (ROM_II: an
interface reduced to a few GSI modes, every contact row reading every GSI coordinate).

Each contact element adds G_e^T J_e G_e to dF_c/dU; with dense columns that is a sum of
(n_gsi x n_gsi) outer products per element, which the element loops of
contact_assemble did entry by entry. Measured here: one FRF per model in the coordinates
'auto' takes there (the GSI columns), with the Fortran time split (assembly, LU, AFT) and
the outputs at a fixed frequency, so that a run on another build can be compared:

    OPENBLAS_NUM_THREADS=1 .venv/bin/python cases/bench/gsi.py --save results/bench_gsi_ref.json
    ... (other build) ...
    OPENBLAS_NUM_THREADS=1 .venv/bin/python cases/bench/gsi.py --ref results/bench_gsi_ref.json

Models: synthetic ROM_II of the paper_hooks size (cases/bench/condensed.py's reduced
model: 303 DoFs, 154 normal1d contacts, every row on the first 40 or 80 DoFs), H = 1 and
3; and the coarse paper_hooks ROM_II (results/paper_hooks/coarse, made by
cases/paper_hooks/make_paper_hooks.py when ccx is there). Columns: points, FRF time,
assembly, LU and AFT times, evaluations; with --ref the reference's FRF and assembly
times, the speed-ups, and max |X - X_ref| / max |X_ref| at the check frequency.
Last line: the worst assembly speed-up, FRF speed-up and answer difference.

Measured 2026-11-23 (2 cores shared by ~9 jobs, one BLAS thread), element loops (9395d45)
against matrix products (h-gsi), FRF s / assembly s:
    synthetic 40 GSI, H=1       10.33 / 6.711  ->  1.38 / 0.161   (7.5x / 42x)
    synthetic 80 GSI, H=1       50.72 / 40.46  ->  2.93 / 0.652   (17x / 62x)
    synthetic 40 GSI, H=3       45.12 / 37.95  ->  2.64 / 0.855   (17x / 44x)
    paper_hooks coarse ROM_II    1.64 / 1.192  ->  0.27 / 0.035   (6.0x / 34x)
outputs at the check frequency equal to 6e-15.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
from condensed import F_RES, reduced_model  # noqa: E402
from frirom.solver import SolverOptions, frf, solve_point  # noqa: E402


def synthetic(n_iface: int, H: int):
    m, ex = reduced_model(303, 154, n_iface=n_iface)
    return dict(model=m, ex=ex, w0=2 * np.pi * 494.9, w1=2 * np.pi * 547.8,
                wc=2 * np.pi * F_RES * 1.01, opts=dict(harmonics=H, samples=64),
                outputs=np.arange(12))


def hooks():
    work = ROOT / "results" / "paper_hooks" / "coarse"
    if not (work / "rom2.toml").exists():
        import shutil
        if shutil.which("ccx") is None:
            return None
        sys.path.insert(0, str(ROOT / "cases" / "paper_hooks"))
        import make_paper_hooks as mk
        mk.make(work, "coarse")
    from frirom.deck import load_deck
    d = load_deck(work / "rom2.toml")
    o = d.options()
    return dict(model=d.model(), ex=d.excitation(), w0=d.omega_start, w1=d.omega_end,
                wc=2 * np.pi * 180.0, opts=dict(harmonics=o.harmonics, samples=o.n_samples),
                outputs=d.outputs)


def run(case, repeat: int):
    """Minimum over repeat FRFs; the outputs by solve_point at the check frequency."""
    best = None
    for _ in range(repeat):
        o = SolverOptions(**case["opts"], coordinates="auto")
        t = time.perf_counter()
        r = frf(case["model"], case["ex"], case["w0"], case["w1"], o, outputs=case["outputs"])
        wall = time.perf_counter() - t
        tm = r.timings
        row = dict(points=len(r.omega), wall=wall, asm=tm["assembly"],
                   lu=tm["factorization"], aft=tm["aft"], evals=int(tm["evaluations"]),
                   nfact=int(tm["factorizations"]), info=r.solver_info)
        if best is None or row["wall"] < best["wall"]:
            best = row
    p = solve_point(case["model"], case["ex"], case["wc"],
                    SolverOptions(**case["opts"], tol_residual=1e-12, tol_update=1e-12,
                                  max_iter=60), outputs=case["outputs"])
    best["X"] = p.X.tolist()
    return best


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--save", type=Path, help="write this run as the reference (JSON)")
    ap.add_argument("--ref", type=Path, help="compare against a reference run (JSON)")
    ap.add_argument("--repeat", type=int, default=2, help="FRFs per model (minimum kept)")
    ap.add_argument("--quick", action="store_true", help="the two H = 1 synthetic models")
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore", RuntimeWarning)
    cases = {"synthetic 40 GSI, H=1": lambda: synthetic(40, 1),
             "synthetic 80 GSI, H=1": lambda: synthetic(80, 1)}
    if not a.quick:
        cases["synthetic 40 GSI, H=3"] = lambda: synthetic(40, 3)
        cases["paper_hooks coarse ROM_II"] = hooks
    ref = json.loads(a.ref.read_text()) if a.ref else {}
    out = {}
    print(f"{'model':28s} {'pts':>4s} {'FRF s':>7s} {'asm s':>7s} {'LU s':>6s} {'AFT s':>6s} "
          f"{'evals':>5s}" + (f" {'ref FRF':>7s} {'ref asm':>7s} {'x FRF':>6s} {'x asm':>6s}"
                              f" {'diff':>8s}" if ref else ""))
    worst = [np.inf, np.inf, 0.0]
    for name, make in cases.items():
        case = make()
        if case is None:
            print(f"{name:28s} skipped (no ccx)")
            continue
        r = run(case, a.repeat)
        out[name] = r
        line = (f"{name:28s} {r['points']:4d} {r['wall']:7.2f} {r['asm']:7.3f} {r['lu']:6.2f} "
                f"{r['aft']:6.2f} {r['evals']:5d}")
        if name in ref:
            q = ref[name]
            X, Xr = np.array(r["X"]), np.array(q["X"])
            diff = np.abs(X - Xr).max() / np.abs(Xr).max()
            sa, sf = q["asm"] / max(r["asm"], 1e-9), q["wall"] / r["wall"]
            worst = [min(worst[0], sa), min(worst[1], sf), max(worst[2], diff)]
            line += (f" {q['wall']:7.2f} {q['asm']:7.3f} {sf:6.1f} {sa:6.1f} {diff:8.1e}")
        print(line)
    if a.save:
        a.save.parent.mkdir(parents=True, exist_ok=True)
        a.save.write_text(json.dumps(out))
        print(f"reference written to {a.save}")
    if ref:
        print(f"worst speed-up against the reference: assembly {worst[0]:.1f}x, FRF "
              f"{worst[1]:.1f}x; largest output difference {worst[2]:.1e}")


if __name__ == "__main__":
    from _results import record
    record("gsi", main)
