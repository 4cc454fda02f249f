"""Hill's stability verdict on the flange's ROM_I checked by time integration (issue 30).

At a point of a ROM_I curve run with stability on (its frf.h5), the harmonic balance
point is solved again there (Newton from the stored unknowns and contact history, Hill's
route at s = 0: the largest real part of the exponents nearest 0, ``floquet_max_re``),
and the reduced model is integrated in time (frirom.timeint, implicit HHT, the point's
sliders) twice in one batch: started on the HB solution, and started 1 % off it (the
vibration, i.e. the displacements and velocities less their static part, scaled by
1.01). The difference of the two runs d(t) is the perturbation (the run started on the
HB point absorbs the truncation of the balance, H harmonics); its size max |d(t)| over a
period and all DoFs, every period, gives by a least-squares slope of its logarithm
over the last half of the integration (60 periods; after the fast modes' transient and the stuck
sliders' settling) the growth (> 1) or decay (< 1) per period, set against Hill's
exp(max Re s T), T = 2 pi / omega.

    python cases/paper_flange/stability_ti.py --work WORK --frf RUN/frf.h5 \\
        [--freqs F1 F2 ...] [--periods 60] [--steps 128] [--out results.json]

Without --freqs the points are chosen on the curve: the stuck point at the lower end of
the band, the slipping stable point of largest amplitude and, where Hill flags any, the
unstable point of largest amplitude. Writes the rows to --out (JSON) and prints them.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent


def time_contacts(model, slider):
    """frirom.timeint contacts of the model's groups, and their sliders (1, n_elem, n_sl)
    from a point's history (FRFPoint.slider layout: groups concatenated, row-major)."""
    from frirom.contact import LAWS
    from frirom.timeint import TimeContact
    tcs, w0, off = [], [], 0
    for g in model.contacts:
        ne, nsl = g.n_elem, LAWS[g.law].n_slider
        G = g.G.toarray() if hasattr(g.G, "toarray") else np.asarray(g.G, float)
        tcs.append(TimeContact(g.law, G, g.params, name=g.name))
        w0.append(np.asarray(slider[off:off + ne * nsl], float).reshape(1, ne, nsl))
        off += ne * nsl
    return tcs, w0


def growth_per_period(model, excitation, X, omega, slider, *, eps=0.01, periods=60,
                      steps=128) -> dict:
    """Time integration from the HB point (harmonics X (n, 2H+1) of every DoF at omega,
    contact history slider) and 1 % off it, in one batch (one call, every period
    recorded). Per period the difference of the two runs d(t) = x_off - x_on gives the
    deviation max |d| (all DoFs); returns the deviations, their fitted ratio per period
    over the last half ('ratio'), and the two runs' drift.

    Why the last half: a friction contact that stays stuck keeps the offset a
    perturbation leaves in its slider, and those offsets settle over tens of periods (the
    deviation may first grow at a stable point: the coarse flange at 838.7 Hz for 40
    periods, then decays at Hill's rate); the first periods also carry the fast modes'
    transient."""
    from frirom.timeint import integrate, state_from_harmonics
    dense = [a.toarray() if hasattr(a, "toarray") else np.asarray(a, float)
             for a in (model.M, model.C, model.K)]
    X = np.asarray(X, float)
    x0, v0 = state_from_harmonics(X, omega)
    xs = np.stack([x0, x0 + eps * (x0 - X[:, 0])])     # the vibration 1 % larger
    vs = np.stack([v0, (1.0 + eps) * v0])
    tcs, w1 = time_contacts(model, slider)
    w0 = [np.concatenate([w, w]) for w in w1]
    dev = []

    def record(k, samples):
        dev.append(float(np.abs(samples[1] - samples[0]).max()))

    t0 = time.perf_counter()
    r = integrate(*dense, tcs, excitation.F, np.full(2, float(omega)), x0=xs, v0=vs,
                  w0=w0, H=(X.shape[1] - 1) // 2, min_periods=periods, periods=periods,
                  tol=0.0, steps_per_period=steps, method="implicit", on_period=record)
    k = np.arange(1, len(dev) + 1)
    half = slice(len(dev) // 2, None)
    slope = np.polyfit(k[half], np.log(np.maximum(dev, 1e-300))[half], 1)[0]
    return {"ratio": float(np.exp(slope)), "periods": len(dev),
            "steps": int(r.steps_per_period), "deviation": dev,
            "deviation0": float(eps * np.abs(X[:, 1:]).max()), "drift": r.drift.tolist(),
            "stick_slip_lift": r.state_fractions[0].tolist(),
            "seconds": time.perf_counter() - t0}


def check_point(deck, curve, i, **kw) -> dict:
    """Point i of the curve (FRF) solved again with stability (Hill, the deck's route) and
    checked by growth_per_period; one row."""
    from frirom.solver import solve_point
    model, ex = deck.model(), deck.excitation()
    w = float(curve.omega[i])
    o = dataclasses.replace(deck.options(), stability=True)
    t0 = time.perf_counter()
    p = solve_point(model, ex, w, o, outputs=np.arange(model.n_dof),
                    start={"unknowns": curve.unknowns[i], "slider": curve.slider[i]},
                    start_harmonics=(curve.X.shape[2] - 1) // 2)
    t_hb = time.perf_counter() - t0
    T = 2 * np.pi / w
    ti = growth_per_period(model, ex, p.X, w, p.slider, **kw)
    hill = float(np.exp(p.floquet_max_re * T))
    return {"index": int(i), "f_hz": w / (2 * np.pi), "stable_curve": bool(curve.stable[i]),
            "max_re": float(p.floquet_max_re), "hill_ratio": hill,
            "hill_stable": bool(p.floquet_max_re <= 0.0), "ti_ratio": ti["ratio"],
            "ti_stable": bool(ti["ratio"] < 1.0),
            "agree": bool((ti["ratio"] < 1.0) == (p.floquet_max_re <= 0.0)),
            "stick_slip_lift": [float(v) for v in np.ravel(p.state_fractions)],
            "hb_seconds": t_hb, "ti": ti}


def pick(curve, away: int = 5) -> list[int]:
    """The stuck point at the lower band end; the stable slipping point of largest
    amplitude at least `away` points from a fold (next to one an exponent is near 0);
    the middle of the longest unstable stretch (if any)."""
    amp = np.asarray(curve.amp_max).max(axis=1)
    slip = np.asarray(curve.state_fractions)[:, :, 1].max(axis=1)
    st = np.asarray(curve.stable, bool)
    folds = np.flatnonzero(np.asarray(curve.fold, bool))
    near = np.zeros(len(curve), bool)
    for k in folds:
        near[max(k - away, 0):k + away + 1] = True
    out = [0]
    cand = np.flatnonzero(st & (slip > 0) & ~near)
    if cand.size:
        out.append(int(cand[np.argmax(amp[cand])]))
    runs, start = [], None
    for k, u in enumerate(np.r_[~st, False]):
        if u and start is None:
            start = k
        elif not u and start is not None:
            runs.append((k - start, start, k))
            start = None
    if runs:
        _, a, b = max(runs)
        out.append((a + b - 1) // 2)
    return out


def main(argv=None) -> int:
    from frirom.deck import load_deck
    from frirom.results import FRF
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, required=True, help="paper_flange.py's work folder")
    ap.add_argument("--deck", default="rom1_stability.toml")
    ap.add_argument("--frf", type=Path, required=True, help="the deck's run (frf.h5)")
    ap.add_argument("--freqs", type=float, nargs="*", default=None, help="Hz (nearest points)")
    ap.add_argument("--periods", type=int, default=60)
    ap.add_argument("--steps", type=int, default=128, help="HHT steps per period")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "stability_ti.json")
    a = ap.parse_args(argv)
    deck = load_deck(a.work / a.deck)
    curve = FRF.load(a.frf)
    f = curve.omega / (2 * np.pi)
    idx = (pick(curve) if not a.freqs else
           [int(np.argmin(np.abs(f - x))) for x in a.freqs])
    rows = []
    a.out.parent.mkdir(parents=True, exist_ok=True)
    for i in idx:
        r = check_point(deck, curve, i, periods=a.periods, steps=a.steps)
        rows.append(r)
        print(f"{r['f_hz']:.3f} Hz (point {i}): stick/slip/lift-off "
              f"{', '.join(f'{v:.2f}' for v in r['stick_slip_lift'])}; Hill max Re s "
              f"{r['max_re']:+.4g} 1/s -> {r['hill_ratio']:.5f} per period; time "
              f"integration {r['ti_ratio']:.5f} per period ({r['ti']['seconds']:.0f} s); "
              f"{'agree' if r['agree'] else 'DISAGREE'}", flush=True)
        a.out.write_text(json.dumps({"deck": str(a.work / a.deck), "frf": str(a.frf),
                                     "n_dof": int(deck.model().n_dof), "rows": rows},
                                    indent=1))
    print(f"wrote {a.out}")
    return 0 if all(r["agree"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
