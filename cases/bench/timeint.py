"""Benchmark: explicit against implicit time integration on a reduced FE model.

The coarse lap joint of tests/test_lap_joint_case.py (gmsh + ccx, element size 12 mm; CB
20 + GSI 40 modes: 63 coordinates, 65 normal1d pairs), at 877.65 Hz on the resonance's
flank, started from the harmonic balance state (H = 7, N = 256). Both integrators run in
the same process from the same start: the explicit scheme (central differences, step
count set by the highest mode with every contact stuck) for a few periods, the implicit
one (HHT-alpha) at 128 and 256 steps per period until the period-to-period change is below
1e-6. Prints steps per period, seconds per period and the amplitude at the shaker against
the harmonic balance one; the last line is the time ratio per period.

    python cases/bench/timeint.py [--out DIR]

Needs ccx and gmsh. One core (OPENBLAS_NUM_THREADS=1 is set before numpy loads).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "cases" / "lap_joint"))
sys.path.insert(0, str(ROOT / "tests"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None, help="folder for the matrices")
    ap.add_argument("--explicit-periods", type=int, default=3)
    a = ap.parse_args(argv)
    from test_timeint_implicit import LAP_HZ, hbm_point, lap_deck

    from frirom.timeint import TimeContact, integrate, state_from_harmonics
    out = a.out or Path(tempfile.mkdtemp(prefix="bench_timeint_"))
    out.mkdir(parents=True, exist_ok=True)
    d = lap_deck(out)
    m = d.model()
    act = d.outputs[0]
    w = 2 * np.pi * LAP_HZ
    start = hbm_point(d, w)
    x0, v0 = state_from_harmonics(start.X, w)
    c = d.contacts[0]
    args = (m.M.toarray(), m.C.toarray(), m.K.toarray(),
            [TimeContact(c.law, c.G.toarray(), c.params)], d.F, w)
    kw = dict(H=7, x0=x0, v0=v0, w0=[start.slider.reshape(1, -1, 1)])
    rows = []
    t0 = time.perf_counter()
    r = integrate(*args, periods=a.explicit_periods, min_periods=a.explicit_periods, tol=0.0,
                  **kw)
    rows.append(("explicit", r, time.perf_counter() - t0))
    for n in (128, 256):
        t0 = time.perf_counter()
        r = integrate(*args, periods=300, tol=1e-6, steps_per_period=n, method="implicit",
                      **kw)
        rows.append(("implicit", r, time.perf_counter() - t0))
    print(f"\nlap joint GSI 40: {m.n_dof} coordinates, {c.G.shape[0] // 2} normal1d pairs, "
          f"877.65 Hz, from the HBM state (H = 7, amplitude {start.amp_max[act]:.5e} m)")
    print(f"{'method':>9} {'N':>5} {'periods':>7} {'drift':>8} {'s':>7} {'s/period':>8} "
          f"{'amp/HBM-1':>10}")
    for name, r, t in rows:
        print(f"{name:>9} {r.steps_per_period:5d} {r.periods:7d} {r.drift[0]:8.1e} {t:7.2f} "
              f"{t / r.periods:8.3f} {r.amp_max[0, act] / start.amp_max[act] - 1:+10.2e}")
    per = [t / r.periods for _, r, t in rows]
    print(f"time per period, explicit / implicit N = 128: {per[0] / per[1]:.1f}; "
          f"300 periods: explicit {300 * per[0]:.0f} s, implicit {300 * per[1]:.1f} s")


if __name__ == "__main__":
    from _results import record
    record("timeint", main)
