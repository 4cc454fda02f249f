"""Benchmark: AFT forces + Jacobian of the contact elements with normal load variation.

frirom's Fortran kernel against a vectorised numpy implementation of the same law (march
vectorised over elements, numpy FFTs, Jacobian by the same chain rule written as dense
einsums), timed in the same run on the same inputs; the numpy results are also checked
against frirom's, so the two compute the same thing. Prints element-samples per second and
the speed-up; the last line is the speed-up at 1 000 elements, H = 3, N = 256.

The 2-D element (normal2d) has no numpy twin: its table gives, for 1 000 elements of two
kinds (a mix of stick, slip and lift-off; cycles within 5 % above the onset of partial
slip), the periods the march needed (mean, max, how many beyond the default limit of 200;
max_periods is raised to 5 000 here so that a plain march closes too) and the time of
forces + Jacobian. Run it with an older build to compare (the march of that build is
the reference: `cd OLD && .venv/bin/python NEW/cases/bench/aft.py --law normal2d`).

    python cases/bench/aft.py [--quick] [--law normal1d|normal2d|both] [--only NE:H:N ...]

--only runs the normal1d table at the given sizes only (e.g. the hooks' ROM_II:
--only 170:3:128 170:3:64 1000:3:256), with repeats enough for stable minima.

Both run on one core (OPENBLAS_NUM_THREADS=1 is set before numpy loads).
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from frirom import contact, harmonics  # noqa: E402


def numpy_aft(x, kt, kn, mu, n0, n_samples, periods=2):
    """Vectorised numpy AFT + Jacobian of the normal1d law: x (ne, 2, 2H+1)."""
    ne, _, nc = x.shape
    h = (nc - 1) // 2
    e = harmonics.basis(h, n_samples)                       # (N, nc)
    p = e.T * np.where(np.arange(nc) == 0, 1.0, 2.0)[:, None] / n_samples   # (nc, N)
    u = x[:, 0] @ e.T                                       # (ne, N)
    v = x[:, 1] @ e.T
    gap = n0[:, None] + kn[:, None] * v
    fn = np.maximum(gap, 0.0)
    # an open sample before a closed one: the slider leaves it at the re-contact point,
    # where the linear interpolant of the normal force crosses zero (and its derivative)
    gap1, u1 = np.roll(gap, -1, axis=1), np.roll(u, -1, axis=1)
    reclose = (gap <= 0.0) & (gap1 > 0.0)
    theta = np.where(reclose, gap / np.where(reclose, gap - gap1, -1.0), 0.0)
    uf = u + theta * (u1 - u)
    e1 = np.roll(e, -1, axis=0)
    dth = (kn[:, None, None] * (gap[:, :, None] * e1 - gap1[:, :, None] * e)
           / np.where(reclose, gap - gap1, -1.0)[:, :, None] ** 2)
    dwopen = np.zeros((ne, n_samples, 2 * nc))
    dwopen[:, :, :nc] = (1 - theta[:, :, None]) * e + theta[:, :, None] * e1
    dwopen[:, :, nc:] = np.where(reclose[:, :, None], (u1 - u)[:, :, None] * dth, 0.0)
    ft = np.empty_like(u)
    w = np.zeros(ne)
    state = np.empty(u.shape, dtype=np.int8)                # 0 lift, 1 stick, 2 slip
    # derivative of the slider w.r.t. the harmonics of u and v, carried along the march
    dw = np.zeros((ne, 2 * nc))
    dft = np.empty((ne, n_samples, 2 * nc))
    rows = np.arange(ne)
    for period in range(periods):
        last = period == periods - 1
        for k in range(n_samples):
            open_ = fn[:, k] <= 0.0
            trial = kt * (u[:, k] - w)
            lim = mu * fn[:, k]
            slip = ~open_ & (np.abs(trial) > lim)
            stick = ~open_ & ~slip
            f = np.where(stick, trial, np.sign(trial) * lim)
            f[open_] = 0.0
            w = np.where(open_, uf[:, k], np.where(slip, u[:, k] - f / kt, w))
            if last:
                ft[:, k] = f
                state[:, k] = np.where(open_, 0, np.where(stick, 1, 2))
                d = np.zeros((ne, 2 * nc))
                d[:, :nc] = np.where(stick[:, None], kt[:, None] * e[k], 0.0)
                d[stick] -= kt[stick, None] * dw[stick]
                s = np.sign(trial) * mu * kn
                d[slip, nc:] = s[slip, None] * e[k]
                dft[:, k] = d
                dwu = np.zeros((ne, 2 * nc))
                dwu[:, :nc] = e[k]
                dw = np.where(open_[:, None], dwopen[:, k],
                              np.where(slip[:, None], dwu - d / kt[:, None], dw))
            else:
                dwu = np.zeros((ne, 2 * nc))
                dwu[:, :nc] = e[k]
                s = np.sign(trial) * mu * kn
                dslip = dwu.copy()
                dslip[:, nc:] -= (s / kt)[:, None] * e[k]
                dw = np.where(open_[:, None], dwopen[:, k], np.where(slip[:, None], dslip, dw))
    del rows
    forces = np.stack([harmonics.to_harmonics(ft, h), harmonics.to_harmonics(fn, h)], axis=1)
    jac = np.zeros((ne, 2 * nc, 2 * nc))
    jac[:, :nc] = np.einsum("ik,ekj->eij", p, dft)
    cn = kn[:, None] * (state != 0)                        # d fn / dv in contact
    jac[:, nc:, nc:] = np.einsum("ik,ek,kj->eij", p, cn, e)
    return forces, jac


def make_inputs(ne, h, rng):
    """Random cycles mixing stick, slip and lift-off across elements."""
    x = np.zeros((ne, 2, 2 * h + 1))
    amp = rng.uniform(0.2e-3, 2e-3, ne)
    x[:, 0, 1] = amp
    x[:, 0, 2] = rng.uniform(-0.3, 0.3, ne) * amp
    x[:, 1, 0] = rng.uniform(-0.2e-3, 0.2e-3, ne)
    x[:, 1, 2] = rng.uniform(0.0, 1.5e-3, ne)
    if h >= 2:
        x[:, 0, 4] = 0.2 * amp
        x[:, 1, 3] = 0.1e-3
    kt = np.full(ne, 1e5)
    kn = np.full(ne, 8e4)
    mu = np.full(ne, 0.4)
    n0 = np.full(ne, 60.0)
    return x, kt, kn, mu, n0


def make_inputs_2d(ne, h, kind, rng):
    """normal2d cycles (ne, 3, 2H+1) and parameters (ne, 4): kind "mixed" (the 1-D mix with
    an out-of-phase second tangential direction: stick, slip, lift-off) or "onset"
    (constant normal load, elliptic motion 0-5 % beyond the stick limit mu n0 / kt)."""
    x = np.zeros((ne, 3, 2 * h + 1))
    if kind == "mixed":
        x1, kt, kn, mu, n0 = make_inputs(ne, h, rng)
        x[:, 0], x[:, 2] = x1[:, 0], x1[:, 1]
        x[:, 1, 2] = rng.uniform(0.0, 0.7, ne) * x1[:, 0, 1]
    else:
        kt, kn, mu, n0 = (np.full(ne, 1e5), np.zeros(ne), np.full(ne, 0.3), np.full(ne, 100.0))
        a = mu * n0 / kt * rng.uniform(1.0, 1.05, ne)
        phi = rng.uniform(0.0, np.pi, ne)
        b = rng.uniform(0.0, 0.3, ne) * a
        x[:, 0, 1] = a
        x[:, 1, 1], x[:, 1, 2] = b * np.cos(phi), b * np.sin(phi)
    return x, np.stack([kt, kn, mu, n0], axis=1)


def bench_normal2d(quick):
    """Table of the 2-D element: periods marched and time of forces + Jacobian."""
    rng = np.random.default_rng(1)
    ne, h, n = (200 if quick else 1000), 3, 256
    print(f"normal2d, {ne} elements, H = {h}, N = {n}, max_periods 5000")
    print(f"{'kind':>6} {'mean per':>8} {'max per':>7} {'> 200':>5} {'s':>9} {'Mel-samp/s':>10}")
    for kind in ("mixed", "onset"):
        x, params = make_inputs_2d(ne, h, kind, rng)
        r = contact.aft("normal2d", x, params, n, max_periods=5000)
        t = best_of(lambda: contact.aft("normal2d", x, params, n, max_periods=5000), 3)
        per = r.periods
        print(f"{kind:>6} {per.mean():8.1f} {per.max():7d} {(per > 200).sum():5d} {t:9.2e} "
              f"{ne * n / t / 1e6:10.2f}", flush=True)


def best_of(fn, repeat):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller grid (smoke run)")
    ap.add_argument("--law", choices=("normal1d", "normal2d", "both"), default="both")
    ap.add_argument("--only", nargs="+", metavar="NE:H:N",
                    help="normal1d sizes to run (elements:harmonics:samples)")
    args = ap.parse_args()
    if args.only:
        args.law = "normal1d"
    if args.law != "normal1d":
        bench_normal2d(args.quick)
    if args.law == "normal2d":
        return
    sizes = (10, 100, 1000) if args.quick else (10, 100, 1000, 10000)
    rng = np.random.default_rng(0)
    print(f"{'elements':>8} {'H':>2} {'N':>4} {'frirom s':>10} {'numpy s':>10} "
          f"{'frirom Mel-samp/s':>18} {'numpy Mel-samp/s':>17} {'speed-up':>9} {'max rel diff':>12}")
    last = None
    grid = [(ne, h, n) for ne in sizes for h in (1, 3, 7) for n in (64, 256)]
    if args.only:
        grid = [tuple(int(v) for v in spec.split(":")) for spec in args.only]
    for ne, h, n in grid:
        x, kt, kn, mu, n0 = make_inputs(ne, h, rng)
        params = np.stack([kt, kn, mu, n0], axis=1)
        rep = max(3, int(2e6 // (ne * n)))
        t_f = best_of(lambda: contact.aft("normal1d", x, params, n), rep)
        r = contact.aft("normal1d", x, params, n)
        rep_np = 1 if ne * n > 1e6 else 3
        t_n = best_of(lambda: numpy_aft(x, kt, kn, mu, n0, n), rep_np)
        fnp, jnp_ = numpy_aft(x, kt, kn, mu, n0, n)
        diff = max(np.abs(fnp - r.forces).max() / np.abs(r.forces).max(),
                   np.abs(jnp_ - r.jacobian).max() / np.abs(r.jacobian).max())
        rate_f, rate_n = ne * n / t_f / 1e6, ne * n / t_n / 1e6
        print(f"{ne:8d} {h:2d} {n:4d} {t_f:10.2e} {t_n:10.2e} {rate_f:18.1f} "
              f"{rate_n:17.2f} {t_n / t_f:9.1f} {diff:12.1e}", flush=True)
        if ne == 1000 and h == 3 and n == 256:
            last = (t_n / t_f, rate_f)
    if last is not None:
        print(f"1000 elements, H = 3, N = 256: frirom/numpy speed-up {last[0]:.1f}x, "
              f"{last[1]:.1f} million element-samples/s")


if __name__ == "__main__":
    from _results import record
    record("aft", main)
