"""Benchmark of large contact interfaces (issue 10): the two-stage flange at the reference
paper's Table 1 size, ROM_I (1 900 DoFs, 200 normal1d pairs) and ROM_II (712 DoFs).

The model is generated at run time by cases/models/flange.py (CalculiX + frirom's own
Craig-Bampton and multi-stage reductions) and cached as npz in --work, so reruns skip ccx
and the reductions. H = 3, 100 AFT samples, EO 2, sweep around the model's EO 2 resonance
(between its free and stuck frequencies) unless --band is given.

For each route (formulation plus options, see ROUTES and --route) and each ROM it prints:
unknowns, time per Newton evaluation and its split (AFT, assembly, factorisation, solves,
receptances: the Fortran timers of frirom.solver), time per FRF, points, and the largest
difference of the answer (harmonics at the output DoFs) from the reference route at the
same frequencies (target <= 1e-8, relative to the largest harmonic). A route whose FRF would
take longer than --budget seconds is *sampled*: solve_point at --samples frequencies gives a
time per evaluation, and the FRF time is extrapolated as that time x the evaluations the same
route needed for the ROM_II FRF (marked "extrap."). The reference ("today's dense path",
--reference) is itself sampled: solve_point from the route's point and contact history at
--checks frequencies of the route's answer. Today's modal route (every mode of ROM_I, route
"condensed-modal") differs from the factorisation by 5e-9 (a stuck point, one Newton step,
the same with tolerances 1e-10 and 1e-12) to 1.4e-8: the round-off of the modal sum sits at
the 1e-8 target on this model.

Scaling (issue 10 item 5): ROM_I models of the same kind with 100, 200, 400, 800 contact
pairs (2, 4, 8, 16 segments per sector; generated like the main one, cached), per size the
first route's FRF: FE DoFs, points, evaluations, LUs, GMRES iterations, seconds per
evaluation (and its split), per point and per FRF (wall and this process's CPU seconds: one
BLAS thread, so CPU seconds are the work, less sensitive to the load of a shared machine),
the generation time, and the growth exponents (least squares, log-log) of the FRF time
(over every size, and over the whole FRFs alone, wall and CPU) and of the time per
evaluation, with the machine load (load averages). Generation on this machine (2 cores shared, load ~6-8): 100
pairs 11 s, 200 pairs 28 s, 400 pairs 90 s, 800 pairs 7-13 min (CB of 63 000 + 66 000 FE
DoFs with 2 550 masters each), so run the 800-pair size once: it is cached. A size whose
whole FRF would exceed --budget (predicted from the largest whole one by the n^3 law of a
dense LU) runs the first --short points of the same sweep, and its FRF time is their time
per point x the points of the largest whole FRF (marked "short").

    OPENBLAS_NUM_THREADS=1 .venv/bin/python cases/bench/large_interface.py [--quick]
        [--pairs 200] [--threads 1] [--route "name:key=value,..."] [--budget 600]

Last lines: the scaling's CPU growth exponent over its whole FRFs (when run), seconds for
the ROM_I FRF and for the ROM_II FRF (first route).
"""

from __future__ import annotations

import argparse
import os
import sys


SCALING = "100,200,400,800"


def _parse(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="a coarse 8-sector model, a few modes: a smoke run of seconds")
    ap.add_argument("--pairs", type=int, default=None,
                    help="contact pairs of the main model (default 200; --quick 16)")
    ap.add_argument("--threads", type=int, default=None,
                    help="BLAS threads (default 1: OPENBLAS_NUM_THREADS=1)")
    ap.add_argument("--work", default=os.environ.get("FRIROM_WORK", "/tmp/frirom_flange"),
                    help="cache folder of the generated models")
    ap.add_argument("--route", action="append", default=[],
                    help="extra route 'name:key=value,...' of SolverOptions fields "
                         "(numbers, true/false, none or strings)")
    ap.add_argument("--only", default=None, help="comma list of route names to run")
    ap.add_argument("--reference", default="dense-dofs",
                    help="the route the answers are compared with")
    ap.add_argument("--budget", type=float, default=600.0,
                    help="seconds above which an FRF (or a scaling point) is sampled")
    ap.add_argument("--samples", type=int, default=2, help="frequencies of a sampled run")
    ap.add_argument("--checks", type=int, default=3,
                    help="frequencies at which a route is compared with the reference")
    ap.add_argument("--scaling", default=SCALING,
                    help="contact pairs of the scaling study ('' to skip)")
    ap.add_argument("--band", default=None, help="sweep 'f1,f2' in Hz")
    ap.add_argument("--roms", default="II,I",
                    help="ROMs of the per-route table ('' for the scaling alone)")
    ap.add_argument("--evals", type=int, default=None,
                    help="evaluations of an FRF for extrapolations when the table does not "
                         "run a ROM_II FRF (e.g. 768, today's condensed ROM_II count)")
    ap.add_argument("--short", type=int, default=12,
                    help="points of the short run of a scaling size whose FRF exceeds "
                         "--budget")
    ap.add_argument("--mem-limit", type=float, default=2.0,
                    help="GB: a route whose estimated matrices exceed it is skipped")
    return ap.parse_args(argv)


ARGS = _parse() if __name__ == "__main__" else None
if ARGS is not None:
    _n = str(ARGS.threads or 1)
    os.environ["OPENBLAS_NUM_THREADS"] = _n     # before numpy is imported
    os.environ["OMP_NUM_THREADS"] = _n

import dataclasses  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from frirom.solver import SolverOptions, frf, solve_point  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "models"))
import flange  # noqa: E402

H = 3
SAMPLES = 100
#: name -> SolverOptions fields ("all": the model's DoF count). "condensed": the default
#: route (contact coordinates or DoFs, whichever are fewer; receptances chosen by 'auto');
#: "dense-dofs": the dense path before issue 10 (unknowns on the contact DoFs, receptances
#: by a banded LU per harmonic: the reference); "condensed-modal": the contact DoFs with
#: receptances by superposition of every mode; "banded": the full formulation.
ROUTES = {"condensed": {}, "dense-dofs": {"coordinates": "dofs", "receptances": "factorization"},
          "condensed-modal": {"coordinates": "dofs", "modes": "all"},
          "banded": {"formulation": "banded"}}
TOL = dict(tol_residual=1e-10, tol_update=1e-10)
DIFF_TARGET = 1e-8          # issue 10: the same answers as the dense path to 1e-8


def _value(text: str):
    low = text.strip().lower()
    if low in ("true", "false"):
        return low == "true"
    if low == "none":
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text.strip()


def routes(extra, only):
    out = dict(ROUTES)
    for spec in extra:
        name, _, body = spec.partition(":")
        kw = {}
        for item in filter(None, body.split(",")):
            k, _, v = item.partition("=")
            kw[k.strip()] = _value(v)
        out[name.strip()] = kw
    fields = {f.name for f in dataclasses.fields(SolverOptions)}
    for name, kw in out.items():
        bad = set(kw) - fields
        if bad:
            raise SystemExit(f"route {name!r}: SolverOptions has no field(s) {sorted(bad)}")
    if only:
        keep = [s.strip() for s in only.split(",")]
        out = {k: v for k, v in out.items() if k in keep}
    return out


def options(kw, model=None) -> SolverOptions:
    kw = {k: (model.n_dof if v == "all" else v) for k, v in kw.items()}
    return SolverOptions(harmonics=H, samples=SAMPLES, **{**TOL, **kw})


def estimated_gb(model, kw) -> float:
    """Memory of the route's linear algebra (GB): dense LU of the condensed unknowns, or
    the band of the banded formulation (full band for a dense reduced model)."""
    n_h = 2 * H + 1
    if kw.get("formulation", "condensed") == "banded":
        n = model.n_dof * n_h
        import scipy.sparse as sp
        from scipy.sparse.csgraph import reverse_cuthill_mckee
        pat = (abs(model.K) + abs(model.M)).tocsr()
        for g in model.contacts:
            pat = pat + abs(g.G.T @ g.G)
        p = reverse_cuthill_mckee(sp.csr_matrix(pat), symmetric_mode=True)
        c = pat[p][:, p].tocoo()
        bw = (int(np.max(np.abs(c.row - c.col))) + 1) * n_h
        return 8.0 * (3 * bw + 1) * n / 1e9
    n = model.nonlinear_dofs().size * n_h
    if kw.get("coordinates") != "dofs":
        n = min(n, sum(g.G.shape[0] for g in model.contacts) * n_h)
    # the LU (and, Krylov mode, the current J); R_h per harmonic is n^2 / (2H+1) more
    return 8.0 * (1 + bool(kw.get("krylov"))) * n * n / 1e9


def per_eval(t: dict) -> dict:
    n = max(t.get("evaluations", 0.0), 1.0)
    return {k: t.get(k, 0.0) / n for k in ("aft", "assembly", "factorization", "solve",
                                          "receptance", "fortran_total")}


def fmt_split(pe: dict) -> str:
    tot = max(pe["fortran_total"], 1e-300)
    return " ".join(f"{k[:4]} {100 * pe[k] / tot:4.1f}%" for k in
                    ("receptance", "factorization", "assembly", "solve", "aft"))


def sampled(model, exc, outputs, kw, freqs):
    """solve_point along `freqs` (each from the previous point): per-evaluation timings."""
    t, pts, prev = {}, [], None
    t0 = time.perf_counter()
    for f in freqs:
        pt = solve_point(model, exc, 2 * np.pi * f, options(kw, model), outputs=outputs,
                         start=prev)
        for k, v in pt.timings.items():
            t[k] = t.get(k, 0.0) + v
        pts.append(pt)
        prev = pt
    return pts, t, time.perf_counter() - t0


def compare(model, exc, outputs, ref_kw, kw, pts):
    """Largest |X - X_ref| / max|X_ref| over the points: the reference solve_point at the
    point's frequency, from the point's unknowns (same formulation) or its contact history
    alone, so both solve the same equations with the same stuck sliders."""
    same = ref_kw.get("formulation", "condensed") == kw.get("formulation", "condensed")
    worst, t_ref = 0.0, 0.0
    for p in pts:
        start = {"slider": p.slider}
        if same and ref_kw.get("coordinates") == kw.get("coordinates"):
            start["unknowns"] = p.unknowns
        t0 = time.perf_counter()
        r = solve_point(model, exc, p.omega, options(ref_kw, model), outputs=outputs,
                        start=start)
        t_ref += time.perf_counter() - t0
        worst = max(worst, float(np.max(np.abs(p.X - r.X)) / np.max(np.abs(r.X))))
    return worst, t_ref


def pick(pts, n):
    """n points spread over a run (first, peak, last ...)."""
    if len(pts) <= n:
        return list(pts)
    amp = np.array([np.max(p.amp_max) for p in pts])
    idx = sorted(set(np.linspace(0, len(pts) - 1, max(n - 1, 2)).round().astype(int))
                 | {int(np.argmax(amp))})
    return [pts[i] for i in idx][:max(n, 1)]


def run_route(name, kw, model, exc, outputs, band, n_eval_frf, ref_kw, a, label):
    """One route on one ROM: a dict of the row's numbers (or the reason it was skipped)."""
    gb = estimated_gb(model, kw)
    row = dict(route=name, rom=label, gb=gb)
    if gb > a.mem_limit:
        row["skip"] = f"estimated {gb:.1f} GB > --mem-limit {a.mem_limit:g}"
        return row
    f1, f2 = band
    # one sampled point first: unknowns and time per evaluation, decides FRF or sample
    pts, t, wall = sampled(model, exc, outputs, kw, [f1])
    row["unknowns"] = pts[0].unknowns.size
    pe = per_eval(t)
    predicted = pe["fortran_total"] * (n_eval_frf or 0)
    if n_eval_frf is None or predicted <= a.budget:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t0, c0 = time.perf_counter(), time.process_time()
            got = []          # every point with its unknowns and history, for the checks
            res = frf(model, exc, 2 * np.pi * f1, 2 * np.pi * f2, options(kw, model),
                      outputs=outputs, sink=got.append)
            row["frf_s"] = time.perf_counter() - t0
            row["frf_cpu"] = time.process_time() - c0
        row.update(points=len(res), evals=int(res.timings.get("evaluations", 0)),
                   timings=res.timings,
                   complete=res.complete, pe=per_eval(res.timings), extrap=False,
                   peak=float(np.max(res.amp_max)),
                   f_peak=float(res.omega[np.argmax(np.max(res.amp_max, axis=1))]
                                / 2 / np.pi))
        check = pick(got, a.checks)
    else:
        freqs = np.linspace(f1, f2, a.samples + 2)[1:-1]
        pts2, t2, _ = sampled(model, exc, outputs, kw, freqs)
        for k, v in t2.items():
            t[k] = t.get(k, 0.0) + v
        pts += pts2
        row.update(pe=per_eval(t), evals=n_eval_frf, extrap=True, points=None,
                   sampled_evals=int(t.get("evaluations", 0)))
        row["frf_s"] = row["pe"]["fortran_total"] * n_eval_frf
        check = pts[:a.checks]
    if kw == ref_kw:
        row["diff"], row["ref_s"] = 0.0, 0.0
    else:
        row["diff"], row["ref_s"] = compare(model, exc, outputs, ref_kw, kw, check)
    row["n_checks"] = len(check)
    return row


def print_row(r):
    if "skip" in r:
        print(f"  {r['rom']:<7} {r['route']:<22} skipped: {r['skip']}")
        return
    pe = r["pe"]
    pts = "-" if r["points"] is None else str(r["points"])
    frf_s = f"{r['frf_s']:9.1f}" + (" extrap." if r["extrap"] else "        ")
    diff = "reference" if r["diff"] == 0.0 else f"{r['diff']:.1e} ({r['n_checks']} pts)"
    if r["diff"] > DIFF_TARGET:
        diff += f" ABOVE {DIFF_TARGET:g}"
    if r["extrap"]:
        diff += f"; sampled: {r['sampled_evals']} evaluations"
    tm = r.get("timings")
    lus = f"{int(tm['factorizations']):5d} {int(tm['krylov_iterations']):6d}" if tm else \
        f"{'-':>5} {'-':>6}"
    print(f"  {r['rom']:<7} {r['route']:<22} {r['unknowns']:8d} {pe['fortran_total']:10.4f} "
          f"{fmt_split(pe)}  {frf_s} {pts:>6} {r['evals']:6d} {lus}  {diff}")


def header():
    print(f"  {'ROM':<7} {'route':<22} {'unknowns':>8} {'s/eval':>10} split of an evaluation"
          f"{'':>44}{'FRF s':>9}{'':8} {'points':>6} {'evals':>6} {'LUs':>5} {'GMRES':>6}  "
          f"diff vs reference")


def _load() -> str:
    """The machine load (1, 5, 15 min averages) and core count, as uptime prints it."""
    return ("load average " + ", ".join(f"{v:.2f}" for v in os.getloadavg())
            + f" on {os.cpu_count()} cores")


def _exponent(xs, ys) -> float:
    """Least-squares slope of log y against log x."""
    return float(np.polyfit(np.log(xs), np.log(ys), 1)[0])


def scaling(a, sizes, kw, main_row, pairs, spec_for, roms, band, sectors, n_modes):
    """Time per FRF against contact pairs (ROM_I of the same kind at each size). A size
    whose FRF fits --budget (predicted from the last measured one by the n^3 LU law) runs
    the whole FRF; a larger one runs the first --short points of the same sweep and its
    FRF time is s/point x the points of the largest whole FRF (marked "short"). The growth
    exponents (least squares over the sizes measured so far, printed after each size) are
    on the FRF time and on the time per Newton evaluation (less sensitive to the load and
    to where a short run stops). Per LU, the receptances cost (contact rows)^2 x (ROM_I
    DoFs) per harmonic and the dense LU (unknowns)^3: with every interface DoF kept in
    ROM_I both grow about like pairs^3, so the FRF stays under pairs^2 only as far as held
    LUs and GMRES (pairs^2 per iteration) replace factorisations; the LU is carried from
    call to call (batches, peak solves), so an FRF needs fewer LUs as they grow dearer.
    Returns the line of the CPU exponent over the whole FRFs, for the benchmark's end."""
    print(f"\nscaling, route {first_route(a)!r}, ROM_I of the same kind (sectors {sectors}, "
          f"{n_modes} CB modes per stage, {2 * sectors} active nodes x 3; every interface DoF "
          "kept)")
    print("  the FE mesh refines circumferentially with the pairs (pairs / sectors angular "
          "cells per sector), so FE DoFs grow like the interface; gen. s = ccx + CB + "
          "assembly (from the cache: the time it took when generated)")
    print(f"  {_load()} at the start")
    print(f"  {'pairs':>6} {'FE DoFs':>7} {'ROM DoFs':>8} {'unknowns':>8} {'points':>6} "
          f"{'evals':>6} {'LUs':>5} {'GMRES':>6} {'s/eval':>8} {'s/point':>8} {'FRF s':>9}"
          f" {'CPU s':>9}  {'gen. s':>7}")
    xs, ys, ye, xw, yw, cw = [], [], [], [], [], []
    last = None          # (unknowns, FRF s, points) of the largest whole FRF
    for p in sizes:
        if p % sectors or p // sectors < 2:
            print(f"  {p:6d} skipped: not >= 2 per sector of {sectors}")
            continue
        rp = roms if p == pairs else flange.flange_roms(spec_for(p), a.work)
        t_gen = rp["t_ccx"] + rp["t_reduce"]
        mp, ep, op = flange.frirom_models(rp, "I")
        gb = estimated_gb(mp, kw)
        if gb > a.mem_limit:
            print(f"  {p:6d} skipped: estimated {gb:.1f} GB > --mem-limit {a.mem_limit:g}")
            continue
        n_u = mp.nonlinear_dofs().size * (2 * H + 1)
        if kw.get("coordinates") != "dofs":
            n_u = min(n_u, sum(g.G.shape[0] for g in mp.contacts) * (2 * H + 1))
        whole = last is None or last[1] * (n_u / last[0]) ** 3 <= a.budget
        if p == pairs and main_row.get("points"):
            res_t, npts, t_frf = main_row["timings"], main_row["points"], main_row["frf_s"]
            c_frf = main_row["frf_cpu"]
            note, whole = "(table above)", True
        else:
            o = options(kw, mp)
            if not whole:
                o = dataclasses.replace(o, max_points=a.short)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t1, c1 = time.perf_counter(), time.process_time()
                res = frf(mp, ep, 2 * np.pi * band[0], 2 * np.pi * band[1], o, outputs=op)
                t_frf, c_frf = time.perf_counter() - t1, time.process_time() - c1
            res_t, npts, note = res.timings, len(res), ""
            if not res.complete:
                note = "INCOMPLETE "
            if not whole:
                note = f"short: {npts} points x {last[2]} points of the {last[3]}-pair FRF"
                t_frf = t_frf / npts * last[2]
                c_frf = c_frf / npts * last[2]
        if whole:
            last = (n_u, t_frf, npts, p)
        n_ev = max(int(res_t["evaluations"]), 1)
        s_eval = res_t.get("fortran_total", 0.0) / n_ev
        print(f"  {p:6d} {sum(rp['sizes']['fe_dofs']):7d} {mp.n_dof:8d} {n_u:8d} {npts:6d} "
              f"{n_ev:6d} {int(res_t['factorizations']):5d} "
              f"{int(res_t['krylov_iterations']):6d} {s_eval:8.3f} "
              f"{t_frf / (last[2] if not whole else npts):8.3f} {t_frf:9.1f} {c_frf:9.1f}"
              f"  {t_gen:7.1f} {note}")
        print(f"         split of an evaluation: {fmt_split(per_eval(res_t))}")
        xs.append(p)
        ys.append(t_frf)
        ye.append(s_eval)
        if whole:
            xw.append(p)
            yw.append(t_frf)
            cw.append(c_frf)
        if len(xs) >= 2 and min(ys) > 0 and min(ye) > 0:
            whole_fit = (f"whole FRFs only ({xw}) {_exponent(xw, yw):.2f}, their CPU time "
                         f"{_exponent(xw, cw):.2f}" if len(xw) >= 2
                         else "whole FRFs only: fewer than 2")
            print(f"         growth exponent over {xs} pairs (least squares, log-log): FRF "
                  f"time {_exponent(xs, ys):.2f} ({whole_fit}), time per evaluation "
                  f"{_exponent(xs, ye):.2f} (target <= 2); {_load()}")
        sys.stdout.flush()
    if len(xw) >= 2:
        return (f"CPU exponent over whole FRFs ({xw} pairs): {_exponent(xw, cw):.2f} "
                "(target <= 2)")
    return "CPU exponent: fewer than 2 whole FRFs"


def first_route(a):
    return next(iter(routes(a.route, a.only)))


def main(a):
    t_start = time.perf_counter()
    quick = a.quick
    pairs = a.pairs or (16 if quick else 200)
    sectors = 8 if quick else 50
    if pairs % sectors or pairs // sectors < 2:
        raise SystemExit(f"--pairs: a multiple of the {sectors} sectors, >= 2 per sector")
    n_modes = 10 if quick else 200

    def spec_for(p):
        return flange.FlangeSpec(sectors=sectors, z_per_sector=p // sectors,
                                 n_modes=n_modes, coarse=quick)

    print(f"large_interface: OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}, "
          f"H = {H}, {SAMPLES} samples, work folder {a.work}; {_load()}")
    t0 = time.perf_counter()
    roms = flange.flange_roms(spec_for(pairs), a.work)
    s = roms["sizes"]
    print(f"model: {sectors} sectors x 2 stages, FE DoFs {s['fe_dofs'][0]} + {s['fe_dofs'][1]}"
          f" = {sum(s['fe_dofs'])}; generation ccx {roms['t_ccx']:.1f} s + reduction "
          f"{roms['t_reduce']:.1f} s (this run: {time.perf_counter() - t0:.1f} s, "
          f"{'generated' if roms['generated'] else 'from the cache'})")
    print(f"ROM_I : {s['interface']} interface + {s['active']} active + {s['modes']} modes = "
          f"{s['rom1']} DoFs; {s['pairs']} normal1d pairs ({s['contact_rows']} contact rows)")
    print(f"ROM_II: {s['ms_interface']} interface (MS, indices "
          f"{roms['spec']['ms_indices']}) + {s['active']} active + {s['modes']} modes = "
          f"{s['rom2']} DoFs")
    print(f"EO {roms['spec']['eo']} resonance (linear ROM_I): {roms['f_stuck']:.2f} Hz stuck, "
          f"{roms['f_free']:.2f} Hz free (bolts only)")
    if a.band:
        band = tuple(float(v) for v in a.band.split(","))
    else:
        band = (0.97 * roms["f_free"], 1.03 * roms["f_stuck"])
    print(f"sweep {band[0]:.1f} - {band[1]:.1f} Hz, load {roms['spec']['f0']:g} N per blade")
    rts = routes(a.route, a.only)
    ref_kw = routes(a.route, None).get(a.reference)
    if ref_kw is None:
        raise SystemExit(f"--reference {a.reference!r}: no such route")
    m1, e1, o1 = flange.frirom_models(roms, "I")
    m2, e2, o2 = flange.frirom_models(roms, "II")

    print("\nper route (diff: max |X - X_ref| / max |X_ref| at the output DoFs, reference "
          f"route {a.reference!r} by solve_point from the route's points)")
    header()
    rows = {}
    want = {v.strip() for v in a.roms.split(",") if v.strip()}
    skipped = dict(skip="not asked (--roms)")
    for name, kw in rts.items():
        # the first route's ROM_II FRF is run whole; its evaluations price the others
        n_eval0 = next((r["evals"] for (rn, rom), r in rows.items()
                        if rom == "ROM_II" and r.get("points")), a.evals)
        r2 = dict(skipped, route=name, rom="ROM_II")
        if "II" in want:
            r2 = run_route(name, kw, m2, e2, o2, band, n_eval0, ref_kw, a, "ROM_II")
            print_row(r2)
        n_eval = r2["evals"] if r2.get("points") else n_eval0
        r1 = dict(skipped, route=name, rom="ROM_I")
        if "I" in want:
            r1 = run_route(name, kw, m1, e1, o1, band, n_eval, ref_kw, a, "ROM_I")
            print_row(r1)
        rows[(name, "ROM_II")], rows[(name, "ROM_I")] = r2, r1
        sys.stdout.flush()
    first = next(iter(rts))
    for rom in ("ROM_II", "ROM_I"):
        r = rows[(first, rom)]
        if r.get("points"):
            print(f"  {rom} {first}: peak {r['peak']:.4e} m at {r['f_peak']:.2f} Hz, "
                  f"{'complete' if r['complete'] else 'INCOMPLETE'}")
    print("  extrap.: sampled at a few points; FRF time = s/eval x the evaluations of the "
          "same route's ROM_II FRF")

    # scaling
    scal = [int(v) for v in a.scaling.split(",") if v.strip()] if a.scaling else []
    if quick and a.scaling == SCALING:
        scal = [16, 32]
    grow = None
    if scal:
        grow = scaling(a, scal, rts[first], rows.get((first, "ROM_I"), {}), pairs, spec_for,
                       roms, band, sectors, n_modes)
    print(f"\ntotal benchmark time {time.perf_counter() - t_start:.0f} s; {_load()}")
    if grow:
        print(f"scaling: {grow}")
    r1, r2 = rows[(first, "ROM_I")], rows[(first, "ROM_II")]

    def sec(r):
        return "skipped" if "skip" in r else (f"{r['frf_s']:.1f}"
                                              + (" (extrapolated)" if r["extrap"] else ""))
    print(f"ROM_I FRF s: {sec(r1)}; ROM_II FRF s: {sec(r2)}")


if __name__ == "__main__":
    from _results import record
    record("large_interface", main, ARGS)
