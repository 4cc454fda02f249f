"""Benchmark: nonlinear-mode backbones and forced responses synthesised from them (single
nonlinear mode theory) against harmonic balance forced responses of the same models.

Per model: the backbone (EPMC, frirom.nonlinear_mode: points, seconds), one forced
response synthesised from it (Backbone.forced_response: milliseconds, the median of
--repeat), one HBM forced response over the same range under the same load (frirom.frf:
points, seconds), the synthesis's peak error against the HBM (amplitude and frequency at
the first output) and the speed ratio HBM / synthesis (and HBM / (backbone + synthesis):
what one curve costs from nothing).

    python cases/bench/modes.py [--quick] [--repeat 20] [--work DIR] [--size 0.012]

Models: the lumped blade with its friction damper (cases/joint/joint.toml, 5 DoFs, H = 5,
2 N at the tip), and the lap joint (cases/lap_joint/lap_joint.toml: two plates meshed by
gmsh, CalculiX matrices, Craig-Bampton + GSI, normal1d friction with a bolt preload on
every node pair; --size the element size, 0.012 m: 65 pairs), skipped without gmsh and
ccx or with --quick. The Brake-Reuss beam (cases/brb/brb_mode.toml: CB + GSI 60 + 60,
86 normal2d elements over the lap, H = 3, mu = 0.03; built by cases/brb/build_brb.py when
gmsh and ccx are there, else skipped; --quick or --no-brb skip it): its backbone from the
stuck joint to the end of microslip (seconds wall and CPU, points), frequency and damping
ratio at the published tip accelerations 0.1, 7 and 65 m/s^2 (points landed on them by
run_brb.exact_at_accelerations, timed apart) against the published backbone (Porter &
Brake 2023, cases/brb/run_brb.py PUBLISHED), with the deck's own step control; then the
same for the reduced interface with the contact-driven basis (cases/brb/brb_cd_mode.toml,
row "BRB CD", appended to the last line). The joint
and lap joint backbones from the stuck mode with continuation steps of at most 0.01 in
log10 a (the microslip range resolved: the synthesis interpolates the backbone).
One core (OPENBLAS_NUM_THREADS=1 is set before numpy loads). Writes
cases/bench/results/modes.json; the last line gives the seconds per backbone and the
synthesis's peak error and speed ratio, and the BRB's backbone seconds and its three points.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import frirom  # noqa: E402
from frirom.deck import load_deck  # noqa: E402
from frirom.nonlinear_modes import linear_mode, nonlinear_mode  # noqa: E402

HERE = Path(__file__).resolve().parent
CASES = HERE.parent


def lap_joint_deck(work: Path, size: float) -> Path | None:
    """The lap joint's deck in `work` with its CalculiX matrices (None: no gmsh/ccx)."""
    if shutil.which("ccx") is None:
        return None
    try:
        import gmsh  # noqa: F401
    except ImportError:
        return None
    sys.path.insert(0, str(CASES / "lap_joint"))
    import make_lap_joint
    if not (work / "lap.sti").exists():
        make_lap_joint.make(work, size=size)
    shutil.copy(CASES / "lap_joint" / "lap_joint.toml", work / "lap_joint.toml")
    return work / "lap_joint.toml"


def bench_brb(deck_name: str = "brb_mode.toml") -> dict | None:
    """The BRB backbone of a deck of cases/brb as cases/brb/run_brb.py runs it (None: no
    gmsh/ccx to build it)."""
    brb = CASES / "brb"
    if not (brb / "brb.sti").exists():
        if shutil.which("ccx") is None:
            return None
        try:
            import gmsh  # noqa: F401
        except ImportError:
            return None
    sys.path.insert(0, str(brb))
    import run_brb
    run_brb.ensure_built(log=lambda *a: None)
    d = load_deck(brb / deck_name)
    t0 = time.perf_counter()
    model = d.model()                       # the reduction (cached after the first run)
    t_model = time.perf_counter() - t0
    c0 = time.process_time()
    bb, deck, sec = run_brb.backbone(brb / deck_name)
    cpu = time.process_time() - c0
    t0 = time.perf_counter()
    at = run_brb.exact_at_accelerations(bb, brb / deck_name)
    t_land = time.perf_counter() - t0
    pts = [{"acc": acc, "f": float(f), "zeta": float(z), "f_pub": fp, "zeta_pub": zp,
            "df_rel": float(f / fp - 1), "dzeta": float(z - zp)}
           for (acc, fp, zp), (f, z) in zip(run_brb.PUBLISHED, at)]
    return {"model": "BRB", "deck": deck_name, "n_dof": model.n_dof,
            "reduction_s": float(d.reduced.build_seconds),
            "n_contact": int(sum(g.n_elem for g in model.contacts)), "H": d.harmonics,
            "samples": deck.options().samples, "backbone_points": len(bb),
            "backbone_s": sec, "backbone_cpu_s": cpu, "model_s": t_model, "landing_s": t_land,
            "backbone_status": bb.status, "published": pts}


def in_range_mode(model, lo, hi) -> int:
    """Index of the stuck structure's lowest mode within [lo, hi] rad/s."""
    for k in range(12):
        w = linear_mode(model, k, "stuck")[1]
        if lo <= w <= hi:
            return k
        if w > hi:
            break
    raise RuntimeError("no stuck mode in the deck's frequency range")


def bench(name: str, deck_path: Path, amplitudes, repeat: int) -> dict:
    d = load_deck(deck_path)
    model, exc = d.model(), d.excitation()
    opts = dataclasses.replace(d.options(), stability=False)
    F = np.asarray(exc.F)
    static = F[:, 0].real if np.any(F[:, 0]) else None
    mode = in_range_mode(model, d.omega_start, d.omega_end)
    ob = dataclasses.replace(opts, ds=0.01, ds_max=0.01, max_points=5000)
    t0 = time.perf_counter()
    bb = nonlinear_mode(model, mode, amplitudes, "stuck", ob, outputs=d.solver_outputs,
                        static=static)
    t_bb = time.perf_counter() - t0
    load = frirom.Excitation(np.c_[np.zeros(F.shape[0]), F[:, 1]])
    s = bb.forced_response(load, (d.omega_start, d.omega_end))
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        s = bb.forced_response(load, (d.omega_start, d.omega_end))
        ts.append(time.perf_counter() - t0)
    t_s = float(np.median(ts))
    t0 = time.perf_counter()
    r = frirom.frf(model, exc, d.omega_start, d.omega_end, opts, outputs=d.solver_outputs)
    t_h = time.perf_counter() - t0
    ps, ph = s.peak(0), r.peak(0)
    return {"model": name, "n_dof": model.n_dof,
            "n_contact": int(sum(g.n_elem for g in model.contacts)), "H": d.harmonics,
            "mode": mode + 1, "backbone_points": len(bb), "backbone_s": t_bb,
            "backbone_status": bb.status, "snmt_ms": 1e3 * t_s, "snmt_points": len(s),
            "snmt_complete": bool(s.complete), "hbm_points": len(r), "hbm_s": t_h,
            "err_amp": ps.amplitude / ph.amplitude - 1, "err_freq": ps.omega / ph.omega - 1,
            "speedup": t_h / t_s, "speedup_with_backbone": t_h / (t_bb + t_s),
            "peak_hz": ph.omega / (2 * np.pi)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="the joint only")
    ap.add_argument("--no-brb", action="store_true", help="skip the Brake-Reuss beam")
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--work", type=Path, default=None,
                    help="folder for the lap joint's matrices (default: a temporary one)")
    ap.add_argument("--size", type=float, default=0.012, help="lap joint element size, m")
    args = ap.parse_args(argv)
    rows = [bench("joint", CASES / "joint" / "joint.toml", (1e-7, 3e-3), args.repeat)]
    if not args.quick:
        with tempfile.TemporaryDirectory() as tmp:
            work = args.work or Path(tmp)
            work.mkdir(parents=True, exist_ok=True)
            deck = lap_joint_deck(work, args.size)
            if deck is None:
                print("lap joint: skipped (needs gmsh and ccx)")
            else:
                rows.append(bench("lap joint", deck, (1e-8, 3e-4), args.repeat))
    brb = brb_cd = None
    if not (args.quick or args.no_brb):
        brb = bench_brb()
        if brb is None:
            print("BRB: skipped (needs gmsh and ccx to build cases/brb)")
        else:
            brb_cd = bench_brb("brb_cd_mode.toml")
    from _results import add
    add(models=rows, brb=brb, brb_cd=brb_cd)
    print(f"{'model':>10s}  {'n_dof':>5s}  {'contacts':>8s}  {'H':>2s}  {'bb points':>9s}  "
          f"{'bb s':>6s}  {'SNMT ms':>8s}  {'HBM points':>10s}  {'HBM s':>6s}  "
          f"{'err amp':>9s}  {'err freq':>9s}  {'speed-up':>9s}")
    for r in rows:
        print(f"{r['model']:>10s}  {r['n_dof']:>5d}  {r['n_contact']:>8d}  {r['H']:>2d}  "
              f"{r['backbone_points']:>9d}  {r['backbone_s']:>6.2f}  {r['snmt_ms']:>8.1f}  "
              f"{r['hbm_points']:>10d}  {r['hbm_s']:>6.2f}  {r['err_amp']:>+9.2e}  "
              f"{r['err_freq']:>+9.2e}  {r['speedup']:>8.0f}x")
    last = [f"{r['model']}: backbone {r['backbone_s']:.2f} s ({r['backbone_points']} "
            f"points), SNMT peak error {100 * r['err_amp']:+.2f} % amplitude, "
            f"{100 * r['err_freq']:+.3f} % frequency, {r['speedup']:.0f}x faster than "
            f"one HBM FRF" for r in rows]
    for b, what in ((brb, "CB + GSI"), (brb_cd, "CB + GSI + contact-driven")):
        if b is None:
            continue
        print(f"BRB ({b['deck']}: {what}, {b['n_dof']} coordinates, {b['n_contact']} "
              f"contact elements, H = {b['H']}, N = {b['samples']}): backbone "
              f"{b['backbone_s']:.1f} s wall, {b['backbone_cpu_s']:.1f} s CPU, "
              f"{b['backbone_points']} points ({b['backbone_status']}); reduced model "
              f"{b['model_s']:.1f} s (built in {b['reduction_s']:.1f} s); landing on the "
              f"three accelerations {b['landing_s']:.1f} s")
        print(f"{'tip acc.':>8s}  {'f Hz':>9s}  {'published':>9s}  {'df':>8s}  "
              f"{'zeta %':>7s}  {'published':>9s}  {'dzeta %':>8s}")
        for p in b["published"]:
            print(f"{p['acc']:>8.1f}  {p['f']:>9.3f}  {p['f_pub']:>9.2f}  "
                  f"{100 * p['df_rel']:>+7.2f}%  {100 * p['zeta']:>7.3f}  "
                  f"{100 * p['zeta_pub']:>9.3f}  {100 * p['dzeta']:>+8.3f}")
    if brb is not None:
        last.append(f"BRB: backbone {brb['backbone_s']:.1f} s ({brb['backbone_cpu_s']:.1f} s "
                    f"CPU, {brb['backbone_points']} points), f/zeta at 0.1/7/65 m/s^2 "
                    + ", ".join(f"{p['f']:.2f} Hz/{100 * p['zeta']:.3f} %"
                                for p in brb["published"])
                    + " (published " + ", ".join(f"{p['f_pub']:.2f}/{100 * p['zeta_pub']:.3f}"
                                                 for p in brb["published"]) + ")")
    if brb_cd is not None:
        b = brb_cd
        last.append(f"BRB CD: backbone {b['backbone_s']:.1f} s ({b['backbone_cpu_s']:.1f} s "
                    f"CPU, {b['backbone_points']} points, {b['n_dof']} coordinates), "
                    "f/zeta at 0.1/7/65 m/s^2 "
                    + ", ".join(f"{p['f']:.2f} Hz/{100 * p['zeta']:.3f} %"
                                for p in b["published"]))
    print("; ".join(last))
    return 0


if __name__ == "__main__":
    from _results import record
    sys.exit(record("modes", main))
