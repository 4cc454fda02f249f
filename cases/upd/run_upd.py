"""The under-platform damper case end to end: matrices, the FRF family over the damper's
load and the damper design curve (docs/cases/upd.md).

    python cases/upd/run_upd.py                  # results/upd: family, design curve
    python cases/upd/run_upd.py --stride 2       # a coarse contact model (minutes less)

Steps: the CalculiX matrices if missing (make_upd.py), the study upd_design.toml (one
key path, ``preload[0].load``: every member is upd.toml with another damper load, run by
``frirom study``'s machinery, resumable), then the design curve: the blade's peak response
(TIP_0, x) against the damper's normal load, with the linear limits (the blades without
damper: contacts free; every pair stuck: the preloaded stick stiffness), and its optimum
(the vertex of a parabola in log(load) through the lowest point and its neighbours).
Writes OUT/design.png, OUT/design.csv and the study's family.png / peaks.png.
"""

from __future__ import annotations

import argparse
import csv
import shutil
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import make_upd  # noqa: E402


def linear_peaks(deck, f_lo: float, f_hi: float, n: int = 801) -> dict:
    """Peak amplitude [m] and frequency [Hz] of the first output of the linear limits:
    'free' (the damper's contacts open: the blades alone; the damper is not loaded) and
    'stuck' (every contact stuck and closed: K + G^T Ks G); dense solves on a grid."""
    model, exc = deck.model(), deck.excitation()
    K, M, C = (A.toarray() if hasattr(A, "toarray") else np.asarray(A)
               for A in (model.K, model.M, model.C))
    Ks = model.stuck_stiffness().toarray()
    F = exc.F[:, 1]
    out = deck.outputs[0]
    f = np.linspace(f_lo, f_hi, n)
    res = {}
    for name, Kx in (("free", K), ("stuck", K + Ks)):
        amp = np.array([abs(np.linalg.solve(Kx - w * w * M + 1j * w * C, F)[out])
                        for w in 2 * np.pi * f])
        i = int(np.argmax(amp))
        res[name] = (f[i], amp[i])
    return res


def optimum(loads, peaks) -> tuple[float, float]:
    """(load, peak) at the vertex of the parabola in log(load) through the lowest peak
    and its neighbours (the lowest point itself at an end of the loads)."""
    x, y = np.log(np.asarray(loads, float)), np.asarray(peaks, float)
    i = int(np.nanargmin(y))
    if i == 0 or i == len(y) - 1:
        return float(loads[i]), float(y[i])
    a, b, c = np.polyfit(x[i - 1:i + 2], y[i - 1:i + 2], 2)
    xs = -b / (2 * a)
    return float(np.exp(xs)), float(np.polyval([a, b, c], xs))


def stored_peaks(design_deck, out):
    """(loads, peaks, complete) of the study's members stored in ``out`` so far: the
    largest stored amplitude of TIP_0 x (FRF.peak) of every member with points, complete
    or not: complete, or unfinished but 10 % down past its peak, True; stopped early
    (turned back, failed) False; unfinished before its peak (still running, or killed:
    its largest amplitude so far is a lower bound) None."""
    from frirom.results import FRF
    from frirom.study import load_study
    loads, peaks, ok = [], [], []
    for m in load_study(design_deck).members:
        h5 = Path(out) / "members" / m["name"] / "frf.h5"
        if not h5.is_file():
            continue
        r = FRF.load(h5)
        if len(r):
            loads.append(float(next(iter(m["values"].values()))))
            peaks.append(float(r.peak(0).amplitude))
            unfinished = not r.complete and r.message.strip() in ("", "running")
            amp = r.amp_max[:, 0]
            k = int(np.argmax(amp))
            # an unfinished curve already past its peak (10 % down since) has its peak
            passed = unfinished and 0 < k < len(amp) - 1 and amp[-1] < 0.9 * amp[k]
            ok.append(True if passed or r.complete else (None if unfinished else False))
    return loads, peaks, ok


def plot_design(loads, peaks, limits, opt, ok):
    """The design curve: peak against load (log), limits dashed, optimum marked."""
    import matplotlib.figure
    fig = matplotlib.figure.Figure(figsize=(6.4, 4.2), layout="constrained")
    ax = fig.add_subplot()
    loads, peaks = np.asarray(loads), np.asarray(peaks) * 1e6
    state = np.array([2 if v is None else int(bool(v)) for v in ok])
    done, stop, going = state == 1, state == 0, state == 2
    ax.semilogx(loads[done], peaks[done], "o-", color="C0", label="HBM: peak of TIP_0 x")
    if np.any(stop):
        ax.semilogx(loads[stop], peaks[stop], "x", color="C3", ms=9,
                    label="curve turned back at a fold (lift-off): largest before it")
    if np.any(going):
        ax.semilogx(loads[going], peaks[going], "^", color="C4", ms=8,
                    label="curve unfinished: largest so far (a lower bound)")
    for name, style, col in (("free", "--", "C1"), ("stuck", ":", "C2")):
        fz, a = limits[name]
        ax.axhline(a * 1e6, ls=style, color=col,
                   label=f"linear, contacts {name} ({fz:.1f} Hz)")
    if opt is not None:
        ax.plot([opt[0]], [opt[1] * 1e6], "*", color="C3", ms=14,
                label=f"optimum: {opt[0]:.3g} N, {opt[1] * 1e6:.3g} um")
    ax.set_xlabel("damper normal load [N]")
    ax.set_ylabel("peak amplitude of TIP_0 x [um]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_title("Under-platform damper: design curve")
    return fig


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("results") / "upd")
    ap.add_argument("--stride", type=int, default=1,
                    help="contact pairs at every stride-th lattice point (2: coarse)")
    ap.add_argument("--work", type=Path, default=None,
                    help="folder of the matrices and decks (default: cases/upd itself)")
    ap.add_argument("--workers", type=int, default=1,
                    help="members run at once (a local Dask cluster; 1: in this process)")
    ap.add_argument("--plot-only", action="store_true",
                    help="draw the design curve from the members stored in OUT so far "
                         "(a study still running or stopped; no solve)")
    a = ap.parse_args(argv)
    from frirom.deck import load_deck
    from frirom.study import run_study
    work = a.work or HERE
    if work != HERE:
        work.mkdir(parents=True, exist_ok=True)
        for name in ("upd.toml", "upd_design.toml"):      # kept if there (edited)
            if not (work / name).exists():
                shutil.copy(HERE / name, work / name)
    if not (work / "upd.sti").exists():
        make_upd.make(work, stride=a.stride)
    if a.plot_only:
        loads, peaks, ok = stored_peaks(work / "upd_design.toml", a.out)
    else:
        if a.workers > 1:
            # a member's solve holds the GIL in Fortran for minutes at H = 3: without
            # this the scheduler takes the silent worker for dead after its 5-minute
            # heartbeat TTL, restarts it and the member starts over
            import dask
            dask.config.set({"distributed.scheduler.worker-ttl": None})
        res = run_study(work / "upd_design.toml", a.out,
                        scheduler="serial" if a.workers <= 1 else "local",
                        workers=a.workers if a.workers > 1 else None)
        loads, peaks, ok = [], [], []
        for s in res["summaries"]:
            loads.append(float(next(iter(s["values"].values()))))
            peaks.append(float(s["peaks"][0][1]))
            ok.append(bool(s.get("complete", False)) and not s.get("failed"))
    order = np.argsort(loads)
    loads, peaks, ok = (list(np.asarray(v)[order]) for v in (loads, peaks, ok))
    deck = load_deck(work / "upd.toml")
    f_lo, f_hi = deck.omega_start / 2 / np.pi, deck.omega_end / 2 / np.pi
    limits = linear_peaks(deck, f_lo, f_hi)
    good = np.array([v is True or v is np.True_ for v in ok])
    opt = (optimum(np.asarray(loads)[good], np.asarray(peaks)[good]) if np.any(good)
           else None)
    a.out.mkdir(parents=True, exist_ok=True)
    with open(a.out / "design.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["load_N", "peak_m", "curve"])
        for row in zip(loads, peaks, ok):
            kind = "unfinished" if row[2] is None else ("peak" if row[2] else "stopped")
            w.writerow([f"{row[0]:.6g}", f"{row[1]:.6e}", kind])
    plot_design(loads, peaks, limits, opt, ok).savefig(a.out / "design.png", dpi=120)
    best = (f"optimum {opt[0]:.4g} N, peak {opt[1]:.4e} m" if opt is not None
            else "no complete curve yet")
    print(f"design curve: {len(loads)} loads ({int(np.sum(good))} complete); {best}; "
          f"linear free {limits['free'][1]:.4e} m at "
          f"{limits['free'][0]:.1f} Hz, stuck {limits['stuck'][1]:.4e} m at "
          f"{limits['stuck'][0]:.1f} Hz; wrote {a.out / 'design.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
