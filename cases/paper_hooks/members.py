"""The paper hooks' f0 members one sweep at a time, and Fig. 6 from the sweeps run.

    python cases/paper_hooks/members.py run rom2 300 up [--law normal2d] [--size paper]
    python cases/paper_hooks/members.py plot [--law normal2d] [--size paper]

``run`` sweeps one ROM (rom1, or rom2 with 40 + 12 GSI modes) at one hook preload f0
[N] over the deck's range, upwards or downwards, without the second sweep
``paper_hooks.py`` adds after a stop (so that each direction's stop, if any, is seen), and
writes ``members/<law>_<rom>_<f0>_<way>.json`` in the work folder (points, seconds, the
peak, complete, the last frequency and the stop message, the curve). A paper-size ROM_I
sweep takes minutes to a quarter of an hour: one at a time. ``plot`` draws every sweep
written: ROM_I lines, ROM_II markers, downward sweeps dashed / open, one colour per f0,
and prints the table (points, seconds, peak, where a sweep stops).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import make_paper_hooks as mk  # noqa: E402
import paper_hooks as ph  # noqa: E402


def run(work: Path, size: str, law: str, rom: str, f0: float, way: str) -> dict:
    """One sweep; returns (and writes) its record."""
    r = ph.Rom(work, rom, size, 40, law=law)
    r.set_preload(f0)
    t0 = time.perf_counter()
    out = dict(rom=rom, f0=f0, way=way, law=law, size=size)
    try:
        res, dt = r.frf(reverse=(way == "down"))
        f = res.omega / (2 * np.pi)
        pk = res.peak(0)
        out.update(points=len(res), seconds=dt, complete=bool(res.complete),
                   last=float(f[-1]), peak_f=float(pk.omega / (2 * np.pi)),
                   peak_a=float(pk.amplitude), message=str(res.message or "")[:400],
                   f=f.tolist(), a=res.amp_max[:, 0].tolist())
    except Exception as exc:       # no first point: recorded, not hidden
        out.update(error=f"{type(exc).__name__}: {str(exc)[:300]}",
                   seconds=time.perf_counter() - t0, complete=False)
    folder = work / "members"
    folder.mkdir(exist_ok=True)
    (folder / f"{law}_{rom}_{f0:g}_{way}.json").write_text(json.dumps(out))
    return out


def row(rec: dict) -> str:
    """'points, seconds, peak' or where the sweep stops."""
    if "error" in rec:
        return f"no first point ({rec['error'][:60]})"
    s = f"{rec['points']}, {rec['seconds']:.0f} s"
    if rec["complete"]:
        return s + f", {rec['peak_a']:.4e} m at {rec['peak_f']:.3f} Hz"
    return s + f", stops at {rec['last']:.2f} Hz"


def plot(work: Path, law: str, path: Path) -> str:
    """Fig. 6 from the sweeps written; returns the table (markdown)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    recs = [json.loads(p.read_text()) for p in sorted((work / "members").glob(f"{law}_*.json"))]
    f0s = sorted({r["f0"] for r in recs})
    colours = dict(zip(f0s, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for r in recs:
        if "f" not in r:
            continue
        c = colours[r["f0"]]
        if r["rom"] == "rom1":
            ax.plot(r["f"], r["a"], "-" if r["way"] == "up" else "--", color=c, lw=1.2)
        else:
            step = max(1, len(r["f"]) // 40)
            ax.plot(r["f"][::step], r["a"][::step], "o" if r["way"] == "up" else "x",
                    mfc="none", color=c, ms=4)
    for f0 in f0s:
        ax.plot([], [], "s", color=colours[f0], label=f"f0 = {f0:g} N")
    ax.plot([], [], "k-", label="ROM_I up (dashed: down)")
    ax.plot([], [], "ko", mfc="none", label="ROM_II 40 + 12 up (x: down)")
    ax.set_xlim(128.0, 140.0)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("airfoil amplitude (OUT:y) [m]")
    ax.set_title(f"Vane segment with hooks, {law}: FRF over the hook preload f0")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    by = {(r["rom"], r["f0"], r["way"]): r for r in recs}
    lines = ["| f0 (N) | ROM_II up | ROM_II down | ROM_I up | ROM_I down |",
             "|---|---|---|---|---|"]
    for f0 in f0s:
        cells = [row(by[k]) if k in by else "not run"
                 for k in (("rom2", f0, "up"), ("rom2", f0, "down"),
                           ("rom1", f0, "up"), ("rom1", f0, "down"))]
        lines.append(f"| {f0:,.0f} | ".replace(",", " ") + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=("run", "plot"))
    ap.add_argument("rest", nargs="*", help="run: rom f0 way (rom1|rom2, N, up|down)")
    ap.add_argument("--size", default="paper", choices=sorted(mk.SETTINGS))
    ap.add_argument("--law", default="normal2d", choices=mk.LAWS)
    ap.add_argument("--work", type=Path, default=None)
    a = ap.parse_args(argv)
    work = a.work or Path("results/paper_hooks") / a.size
    if a.what == "run":
        if len(a.rest) != 3 or a.rest[0] not in ("rom1", "rom2") or a.rest[2] not in (
                "up", "down"):
            ap.error("run needs: rom1|rom2 f0 up|down")
        out = run(work, a.size, a.law, a.rest[0], float(a.rest[1]), a.rest[2])
        print(f"{a.law} {out['rom']} f0 = {out['f0']:g} N {out['way']}: {row(out)}"
              + (f" ({out.get('message')})" if out.get("message") else ""))
    else:
        path = work / f"fig6_{a.law}.png"
        print(plot(work, a.law, path))
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
