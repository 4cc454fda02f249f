"""Benchmark of the harmonic balance solver (issue 3, item 9).

Model: a lumped bladed disk generated here, Nb sectors in a ring, 3 DoFs per sector (disk,
blade platform, blade tip); disk-disk and disk-platform-tip springs; a Jenkins friction
contact between neighbouring platforms (shroud-like), so the number of contact
(nonlinear) DoFs equals Nb; engine-order-3 travelling-wave excitation at the tips.

Prints: time per Newton iteration against contact DoFs (10 ... 3000) and harmonics
(1 ... 7) for both formulations, with the share of AFT, Jacobian assembly, factorisation,
solves and receptances; GFLOP/s of the factorisation against a dgemm timed in the same run;
FRF times; which choices won what; last line: seconds for a 100-point FRF with 1000 contact
DoFs and H = 3 (banded formulation).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python cases/bench/solver.py [--quick]
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings

import numpy as np
import scipy.sparse as sp

from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import SolverOptions, frf, solve_point


def bladed_disk(nb: int, eo: int | None = None, f0: float = 5.0):
    """Ring of nb sectors x (disk, platform, tip); Jenkins platform-platform contacts;
    engine order eo (default nb // 4: neighbouring blades a quarter period apart, so the
    contacts slip alike at every size)."""
    eo = max(1, nb // 4) if eo is None else eo
    md, mp, mt = 2.0, 0.3, 0.5                     # kg
    kd, kdp, kpt = 4e7, 2e7, 5e6                    # N/m: disk ring, disk-platform, blade
    n = 3 * nb
    rows, cols, vals = [], [], []

    def spring(i, j, k):
        rows.extend([i, j, i, j])
        cols.extend([i, j, j, i])
        vals.extend([k, k, -k, -k])

    for s in range(nb):
        d, p, t = 3 * s, 3 * s + 1, 3 * s + 2
        spring(d, 3 * ((s + 1) % nb), kd)
        spring(d, p, kdp)
        spring(p, t, kpt)
        rows.append(d)                              # disk grounded (hub)
        cols.append(d)
        vals.append(1e7)
    K = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    M = sp.diags(np.tile([md, mp, mt], nb)).tocsr()
    # contacts: platform s - platform s+1
    ge = np.arange(nb)
    G = sp.csr_matrix((np.r_[np.ones(nb), -np.ones(nb)],
                       (np.r_[ge, ge], np.r_[3 * ge + 1, 3 * ((ge + 1) % nb) + 1])),
                      shape=(nb, n))
    params = np.tile([1e6, 0.3, 40.0], (nb, 1))     # kt N/m, mu, normal load N
    model = Model(M, K, Damping.rayleigh(0.0, 2e-6),
                  [ContactGroup("jenkins", G, params, name="shroud")])
    F = np.zeros((n, 2), complex)
    F[3 * ge + 2, 1] = f0 * np.exp(-2j * np.pi * eo * ge / nb)
    return model, Excitation(F)


def resonance(nb: int, eo: int | None = None) -> float:
    """Stuck-contact natural frequency (rad/s) of the first family at nodal diameter eo:
    the 3-DoF sector problem of the cyclic model at inter-sector phase 2 pi eo / nb."""
    import scipy.linalg as sla
    eo = max(1, nb // 4) if eo is None else eo
    md, mp, mt = 2.0, 0.3, 0.5
    kd, kdp, kpt, kt = 4e7, 2e7, 5e6, 1e6
    c = 2.0 - 2.0 * np.cos(2 * np.pi * eo / nb)
    K = np.array([[kd * c + kdp + 1e7, -kdp, 0.0],
                  [-kdp, kdp + kpt + kt * c, -kpt],
                  [0.0, -kpt, kpt]])
    return float(np.sqrt(sla.eigh(K, np.diag([md, mp, mt]), eigvals_only=True)[0]))


def dgemm_gflops(n=1500) -> float:
    """Rate of the dgemm frirom's Fortran library links (not numpy's bundled BLAS)."""
    from frirom import _kernels
    return float(_kernels.hbm_dgemm_rate(n, 3))


def fact_flops(form: str, n_unk: int, kl: int | None) -> float:
    if form == "condensed":
        return 2.0 / 3.0 * n_unk**3
    return 2.0 * n_unk * kl * (2 * kl)        # dgbtrf, kl = ku, fill 2kl


def band_kl(model: Model, H: int) -> int:
    from frirom._pack import pack
    pk = pack(model, Excitation(np.zeros((model.n_dof, 1))), SolverOptions(harmonics=H,
                 formulation="banded"), outputs=[0])
    iperm = np.empty_like(pk.perm)
    iperm[pk.perm - 1] = np.arange(model.n_dof)
    pat = (abs(model.K) + abs(model.contacts[0].G.T @ model.contacts[0].G)).tocoo()
    bw = int(np.abs(iperm[pat.row] - iperm[pat.col]).max())
    bw_nat = int(np.abs(pat.row - pat.col).max())
    return (2 * H + 1) * (bw + 1) - 1, bw, bw_nat


def iteration_row(form, nb, H, reuse=False):
    model, ex = bladed_disk(nb)
    w = resonance(nb)
    o = SolverOptions(harmonics=H, samples=max(32, 8 * (2 * H + 1)), formulation=form,
                      reuse_jacobian=reuse, tol_residual=1e-8, tol_update=1e-8)
    t = time.perf_counter()
    p = solve_point(model, ex, w, o, outputs=[2])
    wall = time.perf_counter() - t
    tm = p.timings
    n_unk = p.unknowns.size
    kl = band_kl(model, H)[0] if form == "banded" else None
    nf = max(tm["factorizations"], 1)
    gf = fact_flops(form, n_unk, kl) * nf / max(tm["factorization"], 1e-9) / 1e9
    it = max(tm["evaluations"], 1)
    tot = tm["fortran_total"]
    return dict(form=form, nb=nb, H=H, n=n_unk, iters=p.iterations, evals=int(tm["evaluations"]),
                s_iter=tot / max(p.iterations, 1), wall=wall, aft=tm["aft"] / tot,
                asm=tm["assembly"] / tot, fact=tm["factorization"] / tot,
                solve=tm["solve"] / tot, rec=tm["receptance"] / tot, gflops=gf)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="small sizes only (CI smoke run)")
    args = ap.parse_args()
    warnings.simplefilter("ignore", RuntimeWarning)
    ref = dgemm_gflops(1000 if args.quick else 1500)
    print(f"dgemm reference (the BLAS frirom links, {1000 if args.quick else 1500}^2, same run): "
          f"{ref:.2f} GFLOP/s")
    print("Newton timings at the stuck-contact resonance of each model (EO = Nb/4)")
    sizes = [10, 30, 100] if args.quick else [10, 100, 300, 1000, 3000]
    harms = [1, 3] if args.quick else [1, 3, 5, 7]
    print()
    print("time per Newton iteration (solve_point from the linear solution; "
          "s/iter = Fortran time / iterations)")
    hdr = (f"{'form':>9} {'contacts':>8} {'H':>2} {'unknowns':>8} {'iter':>4} {'s/iter':>9} "
           f"{'AFT':>5} {'asm':>5} {'fact':>5} {'solve':>5} {'recep':>5} {'GF/s':>6} "
           f"{'%dgemm':>6}")
    print(hdr)
    rows = []
    for nb in sizes:
        for H in harms:
            for form in ("condensed", "banded"):
                n_unk = nb * (2 * H + 1)
                if form == "condensed" and n_unk > 2500:
                    est = 2 / 3 * n_unk**3 / (ref * 1e9)
                    print(f"{form:>9} {nb:>8} {H:>2} {n_unk:>8}    -   skipped: dense LU "
                          f"alone ~{est:.1f} s per iteration at the dgemm rate")
                    continue
                r = iteration_row(form, nb, H)
                rows.append(r)
                print(f"{r['form']:>9} {r['nb']:>8} {r['H']:>2} {r['n']:>8} {r['iters']:>4} "
                      f"{r['s_iter']:>9.4f} {r['aft']:>5.0%} {r['asm']:>5.0%} "
                      f"{r['fact']:>5.0%} {r['solve']:>5.0%} {r['rec']:>5.0%} "
                      f"{r['gflops']:>6.2f} {r['gflops'] / ref:>6.0%}")
                sys.stdout.flush()
    # bandwidth won by RCM
    nb_bw = 100 if args.quick else 1000
    m, _ = bladed_disk(nb_bw)
    kl, bw, bw_nat = band_kl(m, 3)
    print()
    print(f"RCM: DoF half-bandwidth {bw} (natural numbering of the ring: {bw_nat}) for "
          f"{nb_bw} sectors; Jacobian half-bandwidth at H=3: {kl}")
    # FRF: reuse on/off, both formulations at a moderate size
    nb_frf = 30 if args.quick else 100
    print()
    print(f"FRF, {nb_frf} contacts, H=3, 0.8..1.1 x stuck resonance, up to 40 points")
    for form in ("condensed", "banded"):
        for reuse in (False, True):
            model, ex = bladed_disk(nb_frf)
            w_res = resonance(nb_frf)
            o = SolverOptions(harmonics=3, samples=56, formulation=form, reuse_jacobian=reuse,
                              max_points=40)
            t = time.perf_counter()
            r = frf(model, ex, 0.8 * w_res, 1.1 * w_res, o, outputs=[2])
            dt = time.perf_counter() - t
            tm = r.timings
            print(f"  {form:>9} reuse={reuse!s:5} points {len(r):3d} {dt:7.2f} s "
                  f"({dt / max(len(r), 1):.3f} s/pt) factorizations {int(tm['factorizations'])}"
                  f" evaluations {int(tm['evaluations'])} complete={r.complete}")
    # headline: 100 points (capped) from 0.9 x the stuck resonance, through the slipping peak
    nb_final = 100 if args.quick else 1000
    model, ex = bladed_disk(nb_final)
    w_res = resonance(nb_final)
    print()
    results = {}
    for reuse in (True, False):
        o = SolverOptions(harmonics=3, samples=56, formulation="banded", max_points=100,
                          ds_max=0.07, reuse_jacobian=reuse)
        t = time.perf_counter()
        r = frf(model, ex, 0.9 * w_res, 1.2 * w_res, o, outputs=[2])
        dt = time.perf_counter() - t
        tm = r.timings
        tot = tm["fortran_total"]
        results[reuse] = (len(r), dt)
        print(f"{nb_final} contacts, H=3, banded, reuse={reuse!s:5}: {len(r)} points, omega "
              f"{r.omega[0]:.0f}..{r.omega[-1]:.0f} rad/s (peak at "
              f"{r.peak(0).omega:.0f}), {r.iterations.mean():.1f} "
              f"iterations/point, {int(tm['factorizations'])} factorisations, {dt:.1f} s; "
              f"AFT {tm['aft'] / tot:.0%}, assembly {tm['assembly'] / tot:.0%}, "
              f"factorisation {tm['factorization'] / tot:.0%}, solves {tm['solve'] / tot:.0%}")
    n_pts, dt = results[True]
    print(f"seconds for a {n_pts}-point FRF with {nb_final} contact DoFs and H = 3 (default "
          f"options): {dt:.1f}")


if __name__ == "__main__":
    from _results import record
    record("solver", main)
