"""Benchmark of the per-call cost of the solver on small models, where it dominates
(issue 28): the run object opened once (frirom._run.Run, the one continuation driver)
against a solve that sets its model up at every call.

Models:

* the friction beam of the peers' examples (NLvib, tmdsimpy): an 8-node cantilever with
  one Jenkins element (:func:`friction_beam`), 0.3 N at the tip, H = 7, N = 256, the
  forced response from 200 to 500 rad/s over its first bending resonance;
* the bundled joint (cases/joint/joint.toml): 100 one-point solves at frequencies across
  its range, each from the linear solution (solve_point: the model packed and the Fortran
  system set up at every call) and on one open run (Run.solve: set up once).

Prints a table (CPU seconds, min of --repeat) and the ratios measured in the same process,
and writes them with the machine to cases/bench/results/run.json (_results.py). Last
line: the beam's FRF CPU seconds and the per-call speed-up of the open run.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python cases/bench/run.py [--repeat 5]

The script also runs on a build without the run object (before it): then only the
set-up-every-call lines are measured, for before/after figures.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parents[2]

import numpy as np  # noqa: E402
import scipy.linalg as sla  # noqa: E402
import scipy.sparse as sp  # noqa: E402

from frirom.model import ContactGroup, Damping, Excitation, Model  # noqa: E402
from frirom.solver import SolverOptions, frf, solve_point  # noqa: E402


def friction_beam(n_nodes: int = 8, fa: float = 0.3):
    """The friction beam of the peers' examples (NLvib, tmdsimpy): a steel cantilever
    (0.7 m, 30 x 30 mm, E 185 GPa, 7 830 kg/m^3) of n_nodes - 1 Euler-Bernoulli elements
    clamped at node 1, a Jenkins element (kt 1.3e6 N/m, limit force mu N = 1 N) on the
    transverse DoF of node 4, Rayleigh damping C = a M + b K_stuck of 0.8 % and 0.2 % at
    the first two stuck modes, fa (N) at the tip's transverse DoF. Returns the model, its
    excitation and the tip's DoF."""
    E, rho, L, b, h = 185e9, 7830.0, 0.7, 0.03, 0.03
    A, I = b * h, b * h**3 / 12
    n_el = n_nodes - 1
    le = L / n_el
    ke = E * I / le**3 * np.array([[12, 6 * le, -12, 6 * le],
                                   [6 * le, 4 * le**2, -6 * le, 2 * le**2],
                                   [-12, -6 * le, 12, -6 * le],
                                   [6 * le, 2 * le**2, -6 * le, 4 * le**2]])
    me = rho * A * le / 420 * np.array([[156, 22 * le, 54, -13 * le],
                                        [22 * le, 4 * le**2, 13 * le, -3 * le**2],
                                        [54, 13 * le, 156, -22 * le],
                                        [-13 * le, -3 * le**2, -22 * le, 4 * le**2]])
    nd = 2 * n_nodes
    K, M = np.zeros((nd, nd)), np.zeros((nd, nd))
    for e in range(n_el):
        s = slice(2 * e, 2 * e + 4)
        K[s, s] += ke
        M[s, s] += me
    K, M = K[2:, 2:], M[2:, 2:]                      # node 1 clamped
    n = nd - 2
    at = 2 * (4 - 2)                                 # node 4's transverse DoF
    kt = 1.3e6
    Ks = K.copy()
    Ks[at, at] += kt
    w = np.sqrt(sla.eigh(Ks, M, eigvals_only=True, subset_by_index=[0, 1]))
    z = np.array([8e-3, 2e-3])
    ab = np.linalg.solve(np.c_[np.ones(2), w**2], 2 * z * w)
    C = ab[0] * M + ab[1] * Ks
    G = sp.csr_matrix(([1.0], ([0], [at])), shape=(1, n))
    model = Model(sp.csr_matrix(M), sp.csr_matrix(K), Damping.matrix(sp.csr_matrix(C)),
                  [ContactGroup("jenkins", G, (kt, 1.0, 1.0), name="node 4")])
    F = np.zeros((n, 2), complex)
    F[n - 2, 1] = fa
    return model, Excitation(F), n - 2


def cpu(fn, repeat: int) -> tuple[float, object]:
    """Least CPU seconds of this process over `repeat` calls of fn, and its last result."""
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - t0)
    return best, out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args(argv)
    from _results import add
    import warnings
    warnings.simplefilter("ignore", RuntimeWarning)
    try:
        from frirom import _run
        from frirom._pack import pack
    except ImportError:
        _run = None
    rows = {}

    # the friction beam's FRF
    model, ex, tip = friction_beam()
    opts = SolverOptions(harmonics=7, samples=256)
    t, r = cpu(lambda: frf(model, ex, 200.0, 500.0, opts, outputs=[tip]), a.repeat)
    rows["beam_frf_cpu_s"] = t
    rows["beam_points"] = len(r)
    rows["beam_peak_m"] = float(r.peak(0).amplitude)
    rows["beam_peak_hz"] = float(r.peak(0).omega / 2 / np.pi)

    # 100 one-point solves on the joint
    from frirom.deck import load_deck
    deck = load_deck(ROOT / "cases" / "joint" / "joint.toml")
    jm, je, jo = deck.model(), deck.excitation(), deck.options()
    jo.stability = False
    freqs = np.linspace(deck.omega_start, deck.omega_end, 100)
    t_sp, pts = cpu(lambda: [solve_point(jm, je, w, jo) for w in freqs], a.repeat)
    rows["joint_solve_point_100_cpu_s"] = t_sp
    amp_sp = np.array([p.amp_max for p in pts])
    if _run is not None:
        packed = pack(jm, je, jo, None)
        run = packed.run
        ny = packed.ny

        def on_run():
            return [run.solve(_run.SOLVE_FIXED, w, np.zeros(ny), cold=True) for w in freqs]
        t_run, res = cpu(on_run, a.repeat)
        amp_run = np.array([packed.points(q, 0.0)[0].amp_max for q in res])
        rows["joint_run_solve_100_cpu_s"] = t_run
        rows["joint_run_vs_solve_point"] = t_sp / t_run
        rows["joint_run_max_rel_diff"] = float(np.abs(amp_run - amp_sp).max()
                                               / np.abs(amp_sp).max())
    print(f"run object benchmark (CPU s, min of {a.repeat}; OPENBLAS_NUM_THREADS="
          f"{os.environ.get('OPENBLAS_NUM_THREADS')}; {platform.processor() or platform.machine()}"
          f", load {os.getloadavg()[0]:.1f})")
    print(f"{'case':<52}{'CPU s':>10}")
    print(f"{'friction beam, 8 nodes, Jenkins, H 7, N 256: FRF':<52}{t:>10.4f}"
          f"   ({len(r)} points, peak {rows['beam_peak_m']:.6e} m at "
          f"{rows['beam_peak_hz']:.4f} Hz)")
    print(f"{'joint: 100 x solve_point (set up every call)':<52}{t_sp:>10.4f}")
    if _run is not None:
        print(f"{'joint: 100 x Run.solve on one open run':<52}{t_run:>10.4f}"
              f"   ({rows['joint_run_vs_solve_point']:.1f}x; same answers to "
              f"{rows['joint_run_max_rel_diff']:.1e})")
    add(results=rows)
    last = f"beam FRF {t:.4f} s CPU ({len(r)} points)"
    if _run is not None:
        last += f"; one-point solves on an open run {rows['joint_run_vs_solve_point']:.1f}x " \
                "faster than solve_point"
    print(last)


if __name__ == "__main__":
    from _results import record
    record("run", main)
