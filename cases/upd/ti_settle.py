"""Time integration of the UPD case's reduced model run until it settles, against the HBM
(docs/cases/upd.md, "Verification"): verify_upd.ti_check's start (the HBM solution, its
displacements, velocities and contact sliders at t = 0) and scheme (HHT-alpha, 128 steps
a period), but integrated in chunks, each continuing from the previous chunk's end state
(TimeResult.restart: Newmark's own x, v and the sliders, so the chunks join exactly), until
the change between the last two periods, relative to max |x|, is below --tol (default
1e-3) or --max-periods is reached. After every chunk one line goes to --out: periods so
far, the change a period, the first harmonic of TIP_0 x and its difference from HBM.

    python cases/upd/ti_settle.py --work DIR --load 200 --freq 1973.367 \
        --out cases/upd/results/ti_settle_200.txt
    python cases/upd/ti_settle.py --work DIR --load 50 --frf DESIGN/members/m000/frf.h5 \
        --freq 1960.27 --out cases/upd/results/ti_settle_50.txt

DIR holds the matrices (make_upd.py; --stride 2 for the coarse model the docs use) and
upd.toml; --frf: a design-curve member's curve at that load, whose point nearest --freq
starts Newton (needed at the light-load fold); --state FILE.npz keeps the end state after
every chunk, and the same command with a larger --max-periods goes on from it.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def settle(work, load: float, freq_hz: float, out: Path, H: int = 3, frf_h5=None,
           chunk: int = 20, max_periods: int = 600, tol: float = 1e-3,
           steps: int = 128, state_file=None) -> dict:
    """Integrate in chunks of ``chunk`` periods until the change a period is below
    ``tol``; one line per chunk appended to ``out``. state_file: an .npz where the end
    state (x, v, sliders, periods so far) is kept after every chunk, and from which a
    later call goes on when it exists. Returns the last line's figures."""
    from frirom.timeint import integrate
    from verify_upd import hbm_start
    d, m, e, p, w, (x0, v0, tcs, w0) = hbm_start(work, load, freq_hz, H, frf_h5)
    Md, Cd, Kd = m.M.toarray(), m.C.toarray(), m.K.toarray()
    o = d.outputs[0]
    a_h = float(np.hypot(p.X[o, 1], p.X[o, 2]))
    out.parent.mkdir(parents=True, exist_ok=True)
    with open(out, "a") as fh:
        fh.write(f"# load {load} N, {w / 2 / np.pi:.4f} Hz, H = {H}, {steps} steps a "
                 f"period, HHT-alpha; HBM first harmonic of TIP_0 x {a_h:.6e} m, "
                 f"states {np.round(p.state_fractions, 3).tolist()}\n"
                 "# periods  change_per_period  ti_first_harmonic_m  ti_minus_hbm  "
                 "max_ti_m  seconds\n")
    state = {"x0": x0, "v0": v0, "w0": w0}
    done, t0, row = 0, time.perf_counter(), {}
    if state_file is not None and Path(state_file).exists():
        z = np.load(state_file)
        state = {"x0": z["x"], "v0": z["v"],
                 "w0": [z[f"w{i}"] for i in range(len(w0))]}
        done = int(z["periods"])
        with open(out, "a") as fh:
            fh.write(f"# going on from {state_file} after {done} periods\n")
    while done < max_periods:
        ti = integrate(Md, Cd, Kd, tcs, e.F, w, H=H, periods=chunk, min_periods=chunk,
                       tol=0.0, steps_per_period=steps, method="implicit", **state)
        state = ti.restart()
        done += ti.periods
        if state_file is not None:
            np.savez(state_file, x=state["x0"], v=state["v0"], periods=done,
                     **{f"w{i}": w for i, w in enumerate(state["w0"])})
        a_t = float(np.hypot(ti.harmonics[0, o, 1], ti.harmonics[0, o, 2]))
        row = {"load": load, "freq": w / 2 / np.pi, "periods": done,
               "drift": float(ti.drift[0]), "hbm": a_h, "ti": a_t, "rel": a_t / a_h - 1,
               "max_ti": float(ti.amp_max[0, o]),
               "slip_ti": np.round(ti.state_fractions[0], 3).tolist()}
        with open(out, "a") as fh:
            fh.write(f"{done:9d}  {row['drift']:.3e}  {a_t:.6e}  {row['rel']:+.4%}  "
                     f"{row['max_ti']:.6e}  {time.perf_counter() - t0:.0f}\n")
        if row["drift"] < tol:
            break
    with open(out, "a") as fh:
        fh.write(f"# {'settled' if row['drift'] < tol else 'NOT settled'} after {done} "
                 f"periods: TI - HBM {row['rel']:+.3%}, change a period "
                 f"{row['drift']:.2e}; TI states {row['slip_ti']}\n")
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, required=True)
    ap.add_argument("--load", type=float, required=True)
    ap.add_argument("--freq", type=float, required=True)
    ap.add_argument("--frf", type=Path, default=None)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--harmonics", type=int, default=3)
    ap.add_argument("--chunk", type=int, default=20)
    ap.add_argument("--max-periods", type=int, default=600)
    ap.add_argument("--tol", type=float, default=1e-3)
    ap.add_argument("--state", type=Path, default=None,
                    help="an .npz keeping the end state after every chunk; a run with "
                         "the same file goes on from it")
    a = ap.parse_args(argv)
    os.environ.setdefault("FRIROM_CACHE", str(a.work / "cache"))
    print(settle(a.work, a.load, a.freq, a.out, a.harmonics, a.frf, a.chunk,
                 a.max_periods, a.tol, state_file=a.state))


if __name__ == "__main__":
    main()
