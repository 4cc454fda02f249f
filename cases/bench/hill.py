"""Benchmark: cost of Hill stability per point, against the harmonic balance solve itself.

For each model and H: the time of solve_point with and without stability (minimum of
`--repeat` runs, the same process), their difference (Hill's cost per point) and its
ratio to the solve. The dense path (dgeev with eigenvectors, 2 n_dof (2H+1) <= HILL_MAX)
is set against numpy's eig and eigvals at the same size (LAPACK dgeev with and without
eigenvectors: the cost of the eigenvectors the selection needs for the modes above
(H + 1/2) omega); above HILL_MAX frirom uses shift-invert Arnoldi about s = 0, and the
dense numpy solve is timed for scale only with --dense-ref (minutes at these sizes).

    python cases/bench/hill.py [--quick] [--repeat 3] [--flange WORK [--rom1]]

Above HILL_MAX a condensed system with receptances from real modes (a reduced model)
takes Hill's route at s = 0 ('near0': the exponents nearest 0 by real shift-invert
Arnoldi, each solve by Woodbury through the point solve's own Newton matrix and the LU it
holds), or with --strip (stability = "strip") the modal route over the whole strip (the
modes diagonal per harmonic, the contacts by Woodbury on the contact DoFs); the others
the banded one. "F solve" and "F Hill" are the Fortran run's own times (the solve
without stability, T_HILL with it), free of the Python packing the wall times include.
Per model the table gives the Hill unknowns, the route, its memory
(frirom._routes.hill_bytes), seconds per point with and without stability, and
|max Re s - the banded path's| where that path fits (dense ROM of 80 DoFs).
--flange WORK: the paper flange's ROM_II (WORK/rom2.toml, made by
cases/paper_flange/paper_flange.py make --work WORK) and, with --rom1, ROM_I, one point
each mid-band; the last line is ROM_I's stability cost per point relative to its solve
and its memory (targets <= 1x, <= 2 GiB). Writes cases/bench/results/hill.json.

Models: the Duffing oscillator plus n uncoupled linear oscillators (sparse), a chain of n
masses with a cubic spring (banded), and the tet10 cantilever of
cases/models/cantilever_pad.py reduced to 33 coordinates (dense; needs gmsh and ccx).
One core (OPENBLAS_NUM_THREADS=1 is set before numpy loads).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402

from frirom.model import ContactGroup, Damping, Excitation, Model  # noqa: E402
from frirom.solver import HILL_MAX, SolverOptions, solve_point  # noqa: E402

HERE = Path(__file__).resolve().parent


def duffing_plus(n_extra):
    """Duffing DoF (x'' + 0.02 x' + x + 0.5 x^3 = 0.1 cos) and n_extra oscillators at
    2.2 .. 60 rad/s, uncoupled."""
    w = np.r_[1.0, np.linspace(2.2, 60.0, n_extra)]
    z = np.r_[0.01, np.full(n_extra, 0.02)]
    n = w.size
    G = sp.csr_matrix(([1.0], ([0], [0])), shape=(1, n))
    F = np.zeros((n, 2), complex)
    F[0, 1] = 0.1
    return (Model(sp.identity(n), sp.diags(w ** 2), Damping.matrix(sp.diags(2 * z * w)),
                  [ContactGroup("cubic", G, [[0.0, 0.5]])]), Excitation(F), 1.5)


def cubic_chain(n):
    """n unit masses on springs 1 (fixed-free), Rayleigh 0.01 M, a cubic spring at the
    free end, forced at the first mass near the first mode."""
    K = sp.diags([2.0 * np.ones(n), -np.ones(n - 1), -np.ones(n - 1)], [0, 1, -1]).tolil()
    K[n - 1, n - 1] = 1.0
    G = sp.csr_matrix(([1.0], ([0], [n - 1])), shape=(1, n))
    F = np.zeros((n, 2), complex)
    F[0, 1] = 0.01
    w1 = 2 * np.sin(np.pi / (2 * (2 * n + 1)))
    return (Model(sp.identity(n), K.tocsr(), Damping.rayleigh(0.01, 0.0),
                  [ContactGroup("cubic", G, [[0.0, 0.1]])]), Excitation(F), 1.05 * w1)


def cantilever(H, tmp):
    """The 33-coordinate cantilever at 503 Hz (11 % of the pad slipping)."""
    sys.path.insert(0, str(HERE.parent / "models"))
    import cantilever_pad
    from frirom.deck import load_deck
    if not (tmp / "cant.sti").exists():
        cantilever_pad.make(tmp)
    (tmp / f"c{H}.toml").write_text(cantilever_pad.deck_text(H=H, samples=128))
    d = load_deck(tmp / f"c{H}.toml")
    return d.model(), d.excitation(), 2 * np.pi * 503.0


def dense_rom(n, seed=3):
    """A reduced-model-like system (tests/test_hill_modal.dense_reduced): dense M, K of n
    DoFs, Rayleigh damping, a Jenkins element and a cubic spring; forced near mode 1."""
    sys.path.insert(0, str(HERE.parents[1] / "tests"))
    from test_hill_modal import dense_reduced
    model, ex = dense_reduced(n, seed)
    return model, ex, 1.1


def flange_deck(work: Path, rom: str):
    from frirom.deck import load_deck
    d = load_deck(work / f"{rom}.toml")
    return d.model(), d.excitation(), 0.5 * (d.omega_start + d.omega_end), d.options()


def route_memory(model, H, o, strip=False):
    """Hill's route and memory [bytes] for this model and options (as _pack decides)."""
    import frirom._routes as rt
    n = model.n_dof
    nl = model.nonlinear_dofs().size
    modal = o.get("formulation", "condensed") == "condensed" and (
        o.get("receptances") == "modes" or "flange" in o.get("_tag", ""))
    route = rt._hill_route(n, H, 1 if modal else 0, nl, strip=strip)
    if route in ("modal", "near0"):
        return route, rt.hill_bytes(n, H, 0, (n, nl), near0=route == "near0")
    return route, rt.hill_bytes(n, H, n - 1 if route == "banded" else 0)


def timed(model, ex, w, o, repeat):
    """Best wall time of solve_point, its point, and the best Fortran times (the run's
    total and Hill's, T_HILL) over the repeats."""
    best, fort, hill = np.inf, np.inf, np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        p = solve_point(model, ex, w, o)
        best = min(best, time.perf_counter() - t)
        fort = min(fort, p.timings.get("fortran_total", np.nan))
        hill = min(hill, p.timings.get("hill", np.nan))
    return best, p, fort, hill


def numpy_dense(m):
    """Seconds of numpy eigvals and eig on a random m x m matrix (LAPACK dgeev N / V)."""
    a = np.random.default_rng(0).standard_normal((m, m))
    t = time.perf_counter()
    np.linalg.eigvals(a)
    t1 = time.perf_counter()
    np.linalg.eig(a)
    return t1 - t, time.perf_counter() - t1


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes only")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--dense-ref", action="store_true",
                    help="time numpy's dense eig above HILL_MAX too (slow)")
    ap.add_argument("--flange", help="paper flange work folder (rom2.toml, rom1.toml)")
    ap.add_argument("--rom1", action="store_true", help="with --flange: ROM_I too")
    ap.add_argument("--strip", action="store_true",
                    help='stability = "strip" (the whole strip on reduced models)')
    a = ap.parse_args(argv)
    cases = [("duffing+osc", 80, 3), ("duffing+osc", 400, 3), ("chain", 80, 3),
             ("chain", 400, 3)]
    if a.quick:
        cases = cases[:1] + cases[2:3]
    tmp = Path(tempfile.mkdtemp(prefix="bench_hill_"))
    try:
        import gmsh  # noqa: F401
        import shutil
        if shutil.which("ccx") and not a.quick:
            cases += [("cantilever", 33, 3), ("cantilever", 33, 7)]
    except ImportError:
        pass
    if not a.quick:
        cases += [("dense-rom", 80, 3), ("dense-rom", 300, 3)]
    else:
        cases += [("dense-rom", 80, 3)]
    if a.flange:
        cases += [("flange ROM_II", 0, 3)] + ([("flange ROM_I", 0, 3)] if a.rom1 else [])
    rows = []
    print(f"HILL_MAX = {HILL_MAX} (dense up to 2 n_dof (2H+1))")
    print(f"{'model':>14} {'n_dof':>6} {'H':>2} {'Hill n':>7} {'route':>7} {'MiB':>8} "
          f"{'solve s':>8} {'Hill s':>8} {'Hill/solve':>10} {'F solve':>8} {'F Hill':>8} "
          f"{'max Re':>10} {'|dRe|':>9}")
    for name, n, H in cases:
        ref = None
        rep = a.repeat
        if name == "duffing+osc":
            model, ex, w = duffing_plus(n)
            o = dict(harmonics=H, samples=32, formulation="condensed")
        elif name == "chain":
            model, ex, w = cubic_chain(n)
            o = dict(harmonics=H, samples=32, formulation="banded")
        elif name == "dense-rom":
            model, ex, w = dense_rom(n)
            o = dict(harmonics=H, samples=128, formulation="condensed", receptances="modes")
            if n <= 100:
                ref = dict(harmonics=H, samples=128, formulation="banded")
        elif name.startswith("flange"):
            model, ex, w, dopts = flange_deck(Path(a.flange),
                                              "rom1" if name.endswith("_I") else "rom2")
            H = dopts.harmonics
            o = {f: getattr(dopts, f) for f in ("harmonics", "samples", "formulation",
                                                 "receptances", "modes")}
            o["_tag"] = "flange"
            rep = 1
        else:
            model, ex, w = cantilever(H, tmp)
            o = dict(harmonics=H, samples=128)
        tag = o.pop("_tag", "")
        route, mem = route_memory(model, H, dict(o, _tag=tag), a.strip)
        stab = "strip" if a.strip else True
        t0, _, f0, _ = timed(model, ex, w, SolverOptions(**o, stability=False), rep)
        t1, p, _, fh = timed(model, ex, w, SolverOptions(**o, stability=stab), rep)
        d_re = float("nan")
        if ref is not None:
            pr = solve_point(model, ex, w, SolverOptions(**ref, stability=True))
            d_re = abs(pr.floquet_max_re - p.floquet_max_re)
        nh = model.n_dof * (2 * H + 1)
        row = dict(model=name, n_dof=model.n_dof, H=H, hill_unknowns=2 * nh, route=route,
                   memory_bytes=int(mem), solve_s=t0, hill_s=t1 - t0,
                   hill_per_solve=(t1 - t0) / t0, solve_fortran_s=f0, hill_fortran_s=fh,
                   hill_per_solve_fortran=fh / f0,
                   peak_rss_bytes=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
                   max_re=p.floquet_max_re,
                   stable=bool(p.stable), abs_diff_re_banded=d_re, omega=w)
        rows.append(row)
        print(f"{name:>14} {model.n_dof:6d} {H:2d} {2 * nh:7d} {route:>7} {mem / 2**20:8.1f} "
              f"{t0:8.3f} {t1 - t0:8.3f} {(t1 - t0) / t0:10.2f} {f0:8.3f} {fh:8.3f} "
              f"{p.floquet_max_re:+10.3e} {d_re:9.1e}", flush=True)
    try:
        # the common results file (cases/bench/_results.py, record() in __main__) where
        # there is one: the rows as its data
        from _results import add
    except ImportError:
        add = None
    if add is not None:
        add(models=rows)
    else:
        out = HERE / "results" / "hill.json"
        out.parent.mkdir(exist_ok=True)
        out.write_text(json.dumps(rows, indent=1))
        print(f"wrote {out}")
    last = [r for r in rows if r["model"] == "flange ROM_I"]
    if last:
        r = last[0]
        print(f"{'paper' if r['n_dof'] > 1000 else 'coarse (--quick)'} flange ROM_I "
              f"({r['n_dof']} DoFs, route {r['route']}): stability costs "
              f"{r['hill_per_solve']:.2f}x its solve per point (wall; Fortran "
              f"{r['hill_per_solve_fortran']:.2f}x) (target <= 1x), Hill "
              f"{r['memory_bytes'] / 2**30:.3f} GiB, process peak "
              f"{r['peak_rss_bytes'] / 2**30:.2f} GiB (target <= 2 GiB)")


if __name__ == "__main__":
    from _results import record
    record("hill", main)
