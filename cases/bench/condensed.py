"""Benchmark of the condensed formulation at a large contact interface (issue 10, items
1-3): unknown coordinates (contact DoFs vs contact coordinates G x), receptance route
(banded LU per harmonic vs all modes of the dense reduced model) and the element-block
Jacobian assembly.

Model: a synthetic dense reduced model of ROM_I's size (default 1 900 DoFs, random
M-orthogonal modes from 100 Hz to 20 kHz, one mode at 520 Hz carrying the load, Rayleigh
damping), 200 two-direction normal1d contacts, each reading 6 DoFs (two nodes x 3
directions), so 1 200 contact DoFs but 400 contact coordinates; H = 3, 100 AFT samples.

Prints per route: unknowns, time per Newton evaluation with Jacobian and its breakdown
(receptances, assembly, LU, AFT), the difference of the answers against the old route
(contact DoFs, banded receptances) at the same frequency, and a 100-point FRF time with the
new defaults. Last line: seconds for that FRF.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python cases/bench/condensed.py [--ndof N]
        [--contacts C] [--quick] [--no-old]

Measured 2026-11-23 (2 cores shared by ~8 jobs, load 8-12, one BLAS thread; the same
solve against the build of 0b0395e in the same hour): one Newton solve at 525 Hz,
ROM_I size, before: 8 400 unknowns, 412 s (receptances 85 s, assembly 43 s and LU 63 s
per Jacobian); after ('auto': contact coordinates + all modes): 2 800 unknowns, 9.8 s
with the eigen-decomposition (receptances 0.15 s, assembly 0.05 s and LU 0.83 s per
Jacobian), outputs equal to 1.1e-11. FRF 494.9-547.8 Hz: 94 points in 431 s, 292 s of
it in 175 dense LUs of n = 2 800 (three per point: tangent and corrector refreshes).
ROM_II size: 153 points in 5.9 s (assembly 2.9 s, AFT 1.4 s for 1 464 evaluations);
before: 151 points in 131-203 s, 124-192 s of it receptances.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
import scipy.sparse as sp

from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import SolverOptions, frf, solve_point

F_RES = 520.0      # Hz, the loaded mode


def reduced_model(n: int = 1900, nc: int = 200, seed: int = 1, amp: float = 20.0,
                  n_iface: int = 0):
    """Dense M, K sharing random modes V (M = V diag(m) V^T, K = V diag(k) V^T), Rayleigh
    damping; nc normal1d contacts whose two rows each combine 6 distinct DoFs (ROM_I), or
    with n_iface > 0 all rows combine the first n_iface DoFs (ROM_II: an interface
    reduced to n_iface generalised DoFs)."""
    rng = np.random.default_rng(seed)
    v, _ = np.linalg.qr(rng.standard_normal((n, n)))
    m = rng.uniform(0.5, 2.0, n)
    f = np.geomspace(100.0, 2.0e4, n)
    f[np.argmin(abs(f - F_RES))] = F_RES
    k = m * (2 * np.pi * f) ** 2
    M = (v * m) @ v.T
    K = (v * k) @ v.T
    M, K = 0.5 * (M + M.T), 0.5 * (K + K.T)
    r0 = int(np.argmin(abs(f - F_RES)))
    need = 6 * nc
    if n_iface:
        need = 0
        dofs = np.zeros((nc, 6), dtype=int)
    elif need > n:
        raise SystemExit(f"{nc} contacts need {need} DoFs > {n}")
    if need:
        dofs = rng.permutation(n)[:need].reshape(nc, 6)
    rows, cols, vals = [], [], []
    for e in range(nc):
        for d in range(2):
            w = rng.standard_normal(3)
            w /= np.linalg.norm(w)
            rows += [2 * e + d] * 6
            cols += list(dofs[e])
            vals += list(w) + list(-w)
    G = sp.csr_matrix((vals, (rows, cols)), shape=(2 * nc, n))
    if n_iface:
        Gi = rng.standard_normal((2 * nc, n_iface)) / np.sqrt(n_iface / 6)
        G = sp.hstack([sp.csr_matrix(Gi), sp.csr_matrix((2 * nc, n - n_iface))]).tocsr()
    # normal1d: kt, kn, mu, n0 (N)
    params = np.tile([2e5, 2e5, 0.3, 1.0], (nc, 1))
    wr = 2 * np.pi * F_RES
    model = Model(M, K, Damping.rayleigh(0.0, 2 * 0.002 / wr),
                  [ContactGroup("normal1d", G, params, name="interface")])
    F = np.zeros((n, 2), complex)
    F[:, 1] = amp * (M @ v[:, r0])
    return model, Excitation(F)


def evaluation_row(name, model, ex, w, opts, ref=None):
    """One solve_point; time per evaluation with Jacobian (the cost of a Newton step that
    refactorises) and the difference of the outputs against ref."""
    t = time.perf_counter()
    p = solve_point(model, ex, w, opts, outputs=np.arange(12))
    wall = time.perf_counter() - t
    tm = p.timings
    nf = max(tm["factorizations"], 1)
    row = dict(name=name, n=p.unknowns.size, iters=p.iterations, evals=int(tm["evaluations"]),
               nfact=int(tm["factorizations"]), wall=wall,
               rec=tm["receptance"] / nf, asm=tm["assembly"] / nf,
               fact=tm["factorization"] / nf, aft=tm["aft"] / max(tm["evaluations"], 1),
               X=p.X)
    row["per_eval"] = (tm["receptance"] + tm["assembly"] + tm["factorization"]) / nf
    row["diff"] = (np.abs(p.X - ref).max() / np.abs(ref).max()) if ref is not None else 0.0
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ndof", type=int, default=1900)
    ap.add_argument("--contacts", type=int, default=200)
    ap.add_argument("--quick", action="store_true", help="300 DoFs, 40 contacts")
    ap.add_argument("--no-old", action="store_true",
                    help="skip the routes on the contact DoFs (slow at ROM_I size)")
    ap.add_argument("--points", type=int, default=100)
    a = ap.parse_args()
    if a.quick:
        a.ndof, a.contacts = 300, 40
    warnings.simplefilter("ignore", RuntimeWarning)
    t = time.perf_counter()
    model, ex = reduced_model(a.ndof, a.contacts)
    print(f"model: {a.ndof} DoFs, {a.contacts} normal1d contacts, "
          f"{model.nonlinear_dofs().size} contact DoFs, {2 * a.contacts} contact coordinates "
          f"(built in {time.perf_counter() - t:.1f} s)")
    H = 3
    w = 2 * np.pi * F_RES * 1.01
    base = dict(harmonics=H, samples=100)
    routes = [("dofs + banded LU (old)", dict(coordinates="dofs", receptances="factorization")),
              ("contact + banded LU", dict(coordinates="contact", receptances="factorization")),
              ("dofs + all modes", dict(coordinates="dofs", receptances="modes")),
              ("contact + all modes (auto)", dict(coordinates="auto", receptances="auto"))]
    if a.no_old:          # the contact-DoF rows: 3x the unknowns, minutes at ROM_I size
        routes = [routes[1], routes[3]]
    print(f"\none Newton solve at {w / 2 / np.pi:.1f} Hz, H = {H}, N = 100; per factorisation:"
          " receptances + assembly + LU; diff: max |X - X_ref| / max |X_ref| of 12 outputs "
          "against the first row")
    print(f"{'route':28s} {'unknowns':>8s} {'iters':>5s} {'facts':>5s} {'s/eval':>8s} "
          f"{'rec':>7s} {'asm':>7s} {'LU':>7s} {'AFT ms':>7s} {'wall s':>7s} {'diff':>8s}")
    ref = None
    rows = []
    for name, kw in routes:
        r = evaluation_row(name, model, ex, w, SolverOptions(**base, **kw), ref)
        if ref is None:
            ref = r["X"]
        rows.append(r)
        print(f"{r['name']:28s} {r['n']:8d} {r['iters']:5d} {r['nfact']:5d} "
              f"{r['per_eval']:8.3f} {r['rec']:7.3f} {r['asm']:7.3f} {r['fact']:7.3f} "
              f"{r['aft'] * 1e3:7.2f} {r['wall']:7.1f} {r['diff']:8.1e}")
    if len(rows) > 1:
        print(f"per-evaluation speed-up, last row against the first: "
              f"{rows[0]['per_eval'] / rows[-1]['per_eval']:.1f}x")
    # FRF with the defaults
    f0, f1 = 494.9, 547.8
    o = SolverOptions(**base, max_points=10 * a.points)
    t = time.perf_counter()
    res = frf(model, ex, 2 * np.pi * f0, 2 * np.pi * f1, o, outputs=np.arange(12))
    tf = time.perf_counter() - t
    tm = res.timings
    print(f"\nFRF {f0}-{f1} Hz with the defaults ({res.solver_info}): {len(res.omega)} points, "
          f"{tf:.1f} s; receptances {tm['receptance']:.1f} s, assembly {tm['assembly']:.1f} s,"
          f" LU {tm['factorization']:.1f} s ({int(tm['factorizations'])}), AFT {tm['aft']:.1f} s"
          f" ({int(tm['evaluations'])} evaluations); per 100 points "
          f"{tf * 100 / max(len(res.omega), 1):.1f} s")
    # ROM_II: 12 interface DoFs (312 + 400 modes = 712 DoFs), the same 200 contacts
    m2, ex2 = reduced_model(712, a.contacts, n_iface=12)
    t = time.perf_counter()
    r2 = frf(m2, ex2, 2 * np.pi * f0, 2 * np.pi * f1, o, outputs=np.arange(12))
    t2 = time.perf_counter() - t
    print(f"ROM_II-size FRF ({r2.solver_info}): {len(r2.omega)} points, {t2:.2f} s "
          f"(eigen-decomposition and packing included)")
    print(f"ROM_I-size condensed FRF: {tf:.1f} s for {len(res.omega)} points; "
          f"ROM_II-size: {t2:.2f} s for {len(r2.omega)} points")


if __name__ == "__main__":
    from _results import record
    record("condensed", main)
