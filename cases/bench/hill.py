"""Benchmark: cost of Hill stability per point, against the harmonic balance solve itself.

For each model and H: the time of solve_point with and without stability (minimum of
`--repeat` runs, the same process), their difference (Hill's cost per point) and its
ratio to the solve. The dense path (dgeev with eigenvectors, 2 n_dof (2H+1) <= HILL_MAX)
is set against numpy's eig and eigvals at the same size (LAPACK dgeev with and without
eigenvectors: the cost of the eigenvectors the selection needs for the modes above
(H + 1/2) omega); above HILL_MAX frirom uses shift-invert Arnoldi about s = 0, and the
dense numpy solve is timed for scale only with --dense-ref (minutes at these sizes).

    python cases/bench/hill.py [--quick] [--repeat 3]

Models: the Duffing oscillator plus n uncoupled linear oscillators (sparse), a chain of n
masses with a cubic spring (banded), and the tet10 cantilever of
cases/models/cantilever_pad.py reduced to 33 coordinates (dense; needs gmsh and ccx).
One core (OPENBLAS_NUM_THREADS=1 is set before numpy loads).
"""

from __future__ import annotations

import argparse
import os
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


def timed(model, ex, w, o, repeat):
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        p = solve_point(model, ex, w, o)
        best = min(best, time.perf_counter() - t)
    return best, p


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
    print(f"HILL_MAX = {HILL_MAX} (dense up to 2 n_dof (2H+1))")
    print(f"{'model':>12} {'n_dof':>6} {'H':>2} {'2n':>6} {'path':>8} {'solve s':>8} "
          f"{'Hill s':>8} {'Hill/solve':>10} {'max Re':>10} {'eigvals s':>9} {'eig s':>8}")
    for name, n, H in cases:
        if name == "duffing+osc":
            model, ex, w = duffing_plus(n)
            o = dict(harmonics=H, samples=32, formulation="condensed")
        elif name == "chain":
            model, ex, w = cubic_chain(n)
            o = dict(harmonics=H, samples=32, formulation="banded")
        else:
            model, ex, w = cantilever(H, tmp)
            o = dict(harmonics=H, samples=128)
        t0, _ = timed(model, ex, w, SolverOptions(**o, stability=False), a.repeat)
        t1, p = timed(model, ex, w, SolverOptions(**o, stability=True), a.repeat)
        m = 2 * model.n_dof * (2 * H + 1)
        path = "dense" if m <= HILL_MAX else "arnoldi"
        tn = te = float("nan")
        if path == "dense" or a.dense_ref:
            tn, te = numpy_dense(m)
        print(f"{name:>12} {model.n_dof:6d} {H:2d} {m:6d} {path:>8} {t0:8.3f} {t1 - t0:8.3f} "
              f"{(t1 - t0) / t0:10.1f} {p.floquet_max_re:+10.3e} {tn:9.3f} {te:8.3f}")


if __name__ == "__main__":
    from _results import record
    record("hill", main)
