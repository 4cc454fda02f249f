"""Benchmark: the contact laws side by side, built-in and written by the user.

Per law (jenkins, normal1d, normal2d, iwan4, iwan with 10 sliders, Jenkins written as a
Python user law, the same in C): the AFT + Jacobian time per element and per period
marched, and relative to Jenkins; and the AFT error against N: max |f_N - f_ref| /
max |f_ref| of the force harmonics at N = 64 ... 1024 against N = 16 384 (the same law),
with the fitted slope of log(error) against log(N). The displacements are random
(seeded) harmonics at H = 3 with amplitudes spread so that the elements mix stick, slip
and (normal laws) lift-off; normal2d's orbits lift off.

The user laws' AFT is frirom.laws.aft: the period marched by the law's function (the C
one through ctypes), closed as the built-in AFT closes it, the Jacobian by central
differences (2 n_dir (2H+1) closures), the scheme the solver's callback
(frirom_user_law) runs; the solver line times one Newton solve of the bundled joint
deck with the built-in Jenkins, the same law as a Python user law, and in C called by the
solver directly (frirom.laws.c_law solver_symbol: no Python in the loop).

    python cases/bench/laws.py [--quick]

One core (OPENBLAS_NUM_THREADS=1 before numpy loads). The last line gives the normal2d
slope with lift-off and the Python user law's cost relative to the built-in Jenkins.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from frirom import contact, laws  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
H = 3


def _x(ndir: int, ne: int, seed: int, liftoff: bool = False) -> np.ndarray:
    """(ne, ndir, 2H+1) displacement harmonics, amplitudes 0.2..20 x the slip scale 3e-5 m
    (log-spread); the normal direction (last, laws with a normal) around zero so that the
    gap n0 + kn v opens on part of the period."""
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(ne, ndir, 2 * H + 1))
    x /= np.abs(x).max(axis=2, keepdims=True)
    x *= 3e-5 * np.exp(rng.uniform(np.log(0.2), np.log(20.0), size=(ne, 1, 1)))
    if liftoff:
        x[:, -1, :] *= 0.5
        x[:, -1, 0] = 0.0
    return x


def _laws(lib: Path | None):
    """(label, law, ndir, params, lift-off) of every law the benchmark runs."""
    iwan = np.concatenate([np.column_stack([np.full(10, 1e4), np.linspace(0.3, 3.0, 10)])
                           .ravel()])
    out = [("jenkins", "jenkins", 1, [1e5, 1.0, 3.0], False),
           ("normal1d", "normal1d", 2, [1e5, 1e5, 0.5, 2.0], True),
           ("normal2d", "normal2d", 3, [1e5, 1e5, 0.5, 2.0], True),
           ("iwan4", "iwan4", 1, [3.0, 1e5, -0.5, 0.1], False),
           ("iwan (10)", "iwan", 1, list(iwan), False),
           ("python user", laws.jenkins_law(), 1, [1e5, 1.0, 3.0], False)]
    if lib is not None:
        out.append(("C user", laws.c_law("c_jenkins", str(lib), "user_jenkins", ("u",),
                                         ("kt", "mu", "fn0"), 1), 1, [1e5, 1.0, 3.0],
                    False))
    return out


def _aft(law, x, p, n, jacobian=True):
    if isinstance(law, laws.UserLaw):
        return laws.aft(law, x, p, n_samples=n, jacobian=jacobian)
    return contact.aft(law, x, p, n_samples=n, jacobian=jacobian)


def _time(law, x, p, n, repeat):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        r = _aft(law, x, p, n)
        best = min(best, time.perf_counter() - t0)
    return best, float(np.mean(r.periods))


def _errors(law, x, p, ns, nref):
    ref = _aft(law, x, p, nref, jacobian=False).forces
    err = [np.abs(_aft(law, x, p, n, jacobian=False).forces - ref).max() / np.abs(ref).max()
           for n in ns]
    slope = np.polyfit(np.log(ns), np.log(err), 1)[0]
    return err, slope


def _c_library(folder: Path) -> Path | None:
    cc = shutil.which("cc")
    if cc is None:
        return None
    lib = folder / "userlaw.so"
    subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", str(lib),
                    str(ROOT / "tests" / "data" / "userlaw.c"),
                    str(ROOT / "tests" / "data" / "userlaw_solver.c"), "-lm"], check=True)
    return lib


def _solver_times(lib: Path | None) -> list[float]:
    """Seconds of one solve of the joint deck at 465 Hz: built-in Jenkins, the Python
    law, the C law called by the solver directly (NaN without a C compiler)."""
    from frirom.deck import load_deck
    from frirom.solver import solve_point
    d = load_deck(ROOT / "cases" / "joint" / "joint.toml")
    m, e, o = d.model(), d.excitation(), d.options()
    w = 2 * np.pi * 465.0
    times = []
    c = None if lib is None else laws.c_law("c_jenkins_solver", str(lib), "user_jenkins",
                                            ("u",), ("kt", "mu", "fn0"), 1,
                                            solver_symbol="solver_law")
    for law in ("jenkins", laws.jenkins_law(), c):
        if law is None:
            times.append(np.nan)
            continue
        g = m.contacts[0]
        m.contacts[0] = type(g)(law=law, G=g.G, params=g.params, w0=g.w0, name=g.name)
        best = np.inf
        for _ in range(3):
            t0 = time.perf_counter()
            solve_point(m, e, w, o)
            best = min(best, time.perf_counter() - t0)
        times.append(best)
    return times


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer elements and repeats")
    args = ap.parse_args()
    ne, ne_user, repeat = (50, 10, 2) if args.quick else (400, 40, 5)
    n_time, ns, nref = 256, [64, 128, 256, 512, 1024], 16384
    with tempfile.TemporaryDirectory() as tmp:
        lib = _c_library(Path(tmp))
        table = _laws(lib)
        print(f"AFT + Jacobian at H = {H}, N = {n_time} ({ne} elements; user laws {ne_user}); "
              f"error of the force harmonics against N = {nref}")
        print(f"{'law':>12} {'us/elem':>9} {'periods':>7} {'us/elem/period':>14} "
              f"{'vs jenkins':>10} " + " ".join(f"{'e(' + str(n) + ')':>9}" for n in ns)
              + f" {'slope':>6}")
        rows = {}
        for label, law, ndir, p, lift in table:
            m = ne_user if isinstance(law, laws.UserLaw) else ne
            x = _x(ndir, m, 1, lift)
            t, per = _time(law, x, p, n_time, repeat)
            err, slope = _errors(law, _x(ndir, 10, 2, lift), p, ns, nref)
            us = t / m * 1e6
            rows[label] = (us, per, slope)
            ratio = us / rows["jenkins"][0]
            print(f"{label:>12} {us:9.1f} {per:7.2f} {us / per:14.1f} {ratio:10.1f} "
                  + " ".join(f"{e:9.1e}" for e in err) + f" {slope:6.2f}", flush=True)
        tb, tu, tc = _solver_times(lib)
    print(f"solver: one Newton solve of cases/joint/joint.toml at 465 Hz: built-in jenkins "
          f"{tb * 1e3:.1f} ms, Python user law {tu * 1e3:.1f} ms ({tu / tb:.0f}x), C user "
          f"law {tc * 1e3:.1f} ms ({tc / tb:.1f}x)")
    print(f"normal2d AFT error slope with lift-off {rows['normal2d'][2]:.2f}; Python user "
          f"law AFT + Jacobian {rows['python user'][0] / rows['jenkins'][0]:.0f}x the "
          f"built-in Jenkins per element (solver {tu / tb:.0f}x)")


if __name__ == "__main__":
    from _results import record
    record("laws", main)
