"""Benchmark of the reference paper's two applications (issue 11): for every member of each
family, the model sizes (FE, ROM_I, ROM_II, nonlinear DoFs), the reduction time, the time
of one ROM_I and one ROM_II FRF measured in this run (ROM_I may be sampled at a few points
and extrapolated while it is slow: marked "extrap."), the speed-up, and the errors of
ROM_II's peak amplitude and frequency against ROM_I's.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python cases/bench/paper.py [--quick] [--work DIR]
        [--case paper_flange|paper_hooks]

Rows come from ``bench_rows(work, quick)`` of cases/paper_flange/paper_flange.py (ROM_II
with index 2, the paper's, with the whole EO 2 family, and that family solved for the
travelling wave's (index, harmonic) pairs only: "fam.TW") and of the module in
cases/paper_hooks/ that offers it, when there is one. At paper size the flange's ROM_I
peaks come from the case's stored run (``paper_flange.py family`` first, minutes per ROM_I
FRF); ``--quick`` runs the coarse models whole in seconds.

Last line: the speed-up of each application (median over its members) and the worst
errors of each ROM_II against the paper's targets (1 % amplitude, 0.1 % frequency).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import sys
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

CASES = Path(__file__).resolve().parents[1]
TARGET_AMP, TARGET_FREQ = 0.01, 0.001


def _module(path: Path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    mod = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(path.parent))
    spec.loader.exec_module(mod)
    return mod


def providers() -> dict:
    """{application: bench_rows function} of the cases that offer one."""
    out = {}
    for name in ("paper_flange", "paper_hooks"):
        folder = CASES / name
        for path in sorted(folder.glob("*.py")) if folder.is_dir() else []:
            if "def bench_rows(" in path.read_text():
                out[name] = _module(path).bench_rows
                break
    return out


def print_table(rows: list) -> None:
    print(f"{'case':<7} {'member':<16} {'ROM_II':<7} {'FE':>7} {'ROM_I':>6} {'ROM_II':>6} "
          f"{'nl I':>5} {'nl II':>5} {'unk II':>6} {'red. s':>7} {'ROM_I FRF s':>16} "
          f"{'ROM_II s':>8} {'speed-up':>8} {'amp err':>9} {'freq err':>9}")
    for r in rows:
        t1 = f"{r['rom1_frf_s']:.1f}" + (" extrap." if r["rom1_extrapolated"] else
                                         " stored" if r.get("rom1_stored") else "")
        bad = (abs(r["peak_amp_err"]) > TARGET_AMP or abs(r["peak_freq_err"]) > TARGET_FREQ)
        print(f"{r['case']:<7} {r['member']:<16} {r.get('rom2', ''):<7} {r['fe_dofs']:7d} "
              f"{r['rom1_dofs']:6d} {r['rom2_dofs']:6d} {r['rom1_nonlinear']:5d} "
              f"{r['rom2_nonlinear']:5d} {r.get('rom2_unknowns', 0) or '':>6} "
              f"{r['reduction_s']:7.1f} {t1:>16} "
              f"{r['rom2_frf_s']:8.2f} {r['speedup']:7.1f}x {100 * r['peak_amp_err']:8.3f}% "
              f"{100 * r['peak_freq_err']:8.4f}%" + ("  ABOVE TARGET" if bad else "")
              + ("" if r.get("complete", True) else "  INCOMPLETE (an FRF stopped early)"))


#: the Fortran timers of a FRF (frirom.results.FRF.timings), in the profile's order
PARTS = ("aft", "assembly", "receptance", "factorization", "solve")


def print_profile(rows: list) -> None:
    """Where each FRF's time goes, for rows that carry a ``profile`` ({ROM: (seconds,
    points, FRF.timings summed over its sweeps)}): points, evaluations (residuals, with or
    without Jacobian) per point, ms per evaluation, and the shares of the AFT with the
    projections G x and G^T f (aft), the contact Jacobian's projection and J's assembly
    (assembly), the receptances, the LUs, the solves, the rest of the Fortran and Python
    (per batch: the points' post-processing). Last column: the speed-up ROM_II would have
    if only its AFT remained (ROM_I's FRF time / ROM_II's AFT time): the AFT floor."""
    prof = [r for r in rows if r.get("profile")]
    if not prof:
        return
    print(f"{'case':<7} {'member':<16} {'ROM':<12} {'s':>7} {'points':>6} {'ev/pt':>6} "
          f"{'ms/ev':>6} " + " ".join(f"{k[:6]:>6}" for k in PARTS)
          + f" {'F rest':>6} {'Python':>6} {'AFT floor':>9}")
    seen = set()
    for r in prof:
        aft2 = r["profile"]["ROM_II"][2].get("aft", 0.0)
        for rom, (t, pts, tim) in r["profile"].items():
            floor = (f"{r['rom1_frf_s'] / aft2:8.0f}x" if rom == "ROM_II" and aft2 > 0
                     else "")
            rom = rom if rom == "ROM_I" else f"{rom} {r.get('rom2', '')}".strip()
            if not tim or not pts or (r["case"], r["member"], rom) in seen:
                continue
            seen.add((r["case"], r["member"], rom))    # ROM_I once per member
            ev = tim.get("evaluations", 0.0)
            shares = [tim.get(k, 0.0) / t for k in PARTS]
            rest = tim.get("fortran_total", 0.0) / t - sum(shares)
            print(f"{r['case']:<7} {r['member']:<16} {rom:<12} {t:7.2f} {pts:6d} "
                  f"{ev / pts:6.1f} {1e3 * t / max(ev, 1):6.2f} "
                  + " ".join(f"{100 * x:5.0f}%" for x in shares)
                  + f" {100 * rest:5.0f}% {100 * (1 - tim.get('fortran_total', 0.0) / t):5.0f}%"
                  + f" {floor:>9}")
    print("shares of each FRF's time: aft (the AFT of every contact element, with G x and "
          "G^T f), assembly (G^T J_loc G and J), receptances, LUs, solves, the rest of the "
          "Fortran, Python; AFT floor: ROM_I's FRF time / ROM_II's AFT time")


def summary(rows: list) -> str:
    """The last line: median speed-up per case, worst errors per case and ROM_II kind."""
    parts, errs = [], []
    for case in dict.fromkeys(r["case"] for r in rows):
        rc = [r for r in rows if r["case"] == case]
        main = [r for r in rc if r.get("rom2", "") in ("", "h=2", "gsi40")] or rc
        ext = " (ROM_I extrapolated)" if any(r["rom1_extrapolated"] for r in main) else ""
        parts.append(f"{case} {np.median([r['speedup'] for r in main]):.1f}x{ext}")
        tw = [r for r in rc if r.get("rom2", "") == "fam.TW"]
        if tw:      # the exact family ROM_II solved for the travelling wave's pairs only
            parts.append(f"{case} fam.TW {np.median([r['speedup'] for r in tw]):.1f}x "
                         f"({min(r['speedup'] for r in tw):.1f}-"
                         f"{max(r['speedup'] for r in tw):.1f}x)")
        for kind in dict.fromkeys(r.get("rom2", "") for r in rc):
            rk = [r for r in rc if r.get("rom2", "") == kind and r.get("complete", True)]
            n_out = sum(1 for r in rc if r.get("rom2", "") == kind) - len(rk)
            label = f"{case} {kind}".strip()
            out = f" ({n_out} incomplete, not compared)" if n_out else ""
            errs.append(f"{label} {100 * max(abs(r['peak_amp_err']) for r in rk):.3f} % / "
                        f"{100 * max(abs(r['peak_freq_err']) for r in rk):.4f} %{out}"
                        if rk else f"{label}: none compared{out}")
    return ("speed-up ROM_I -> ROM_II: " + ", ".join(parts)
            + "; worst peak errors (amplitude / frequency): " + ", ".join(errs))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the coarse models (seconds)")
    ap.add_argument("--work", default=None,
                    help="folder of the cases' models and results (default results/)")
    ap.add_argument("--case", choices=("paper_flange", "paper_hooks"), default=None,
                    help="one application only (default both)")
    a = ap.parse_args(argv)
    base = Path(a.work or "results").resolve()
    rows = []
    provs = {k: f for k, f in providers().items() if a.case in (None, k)}
    for name, fn in provs.items():
        work = base / (name + ("_quick" if a.quick else ""))
        rows += fn(work, a.quick)
    missing = ({a.case} if a.case else {"paper_flange", "paper_hooks"}) - set(provs)
    print(f"paper benchmark ({'quick: coarse models' if a.quick else 'paper size'}), "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}"
          + (f"; no bench_rows in cases/{', cases/'.join(sorted(missing))}" if missing else ""))
    print_table(rows)
    print("extrap.: ROM_I sampled by solve_point, FRF time = s/evaluation x the evaluations "
          "of the (exact) family ROM_II's FRF; stored: ROM_I's whole FRF as timed by the "
          "case's own run (paper_flange.py family); errors: largest over the outputs' peaks; "
          "unk II: ROM_II's condensed unknowns (its LU's size); fam.TW: the family ROM_II "
          "solved only for the tuned rotor's travelling-wave (index, harmonic) pairs")
    print_profile(rows)
    print(summary(rows))


if __name__ == "__main__":
    from _results import record
    record("paper", main)
