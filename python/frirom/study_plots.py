"""Figures of a study (matplotlib, no pyplot): the members' FRFs overlaid, their peaks
against the swept parameter, and the speed-against-accuracy chart of a convergence study.
Each function builds a Figure and returns it; :func:`frirom.study.run_study` saves them."""

from __future__ import annotations

import textwrap

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure

from .plots import frequency_axis


def _short(key: str) -> str:
    """``excitation.load[0].amplitude`` -> ``load[0].amplitude`` (legend text)."""
    parts = key.split(".")
    return ".".join(parts[-2:]) if len(parts) > 2 else key


def _label(values: dict, width: int = 0) -> str:
    """``load[0].amplitude = 2, contacts[0].n0 = 50`` (wrapped at ``width`` characters
    on the commas when width > 0: a legend entry that stays inside the figure)."""
    text = ", ".join(f"{_short(k)} = {v:g}" if isinstance(v, (int, float)) else
                     f"{_short(k)} = {v}" for k, v in values.items())
    return "\n".join(textwrap.wrap(text, width)) if width else text


#: Legend text width in characters (family.png: the legend sits beside the axes, inside
#: the figure).
LEGEND_WIDTH = 30


def plot_family(study, frfs, summaries, *, unit: str = "hz", linear=None,
                per_load: str | None = None) -> Figure:
    """Every member's FRF at the studied output on one axes (the paper's Fig. 6 style):
    max amplitude over a period against frequency, one colour per member (in run order),
    unstable stretches dashed, each member's peak marked.

    study : frirom.study.Study; frfs : list of FRF (per member); summaries : list of dict
    (per member, :func:`frirom.study.run_member`); unit : "hz" or "rad/s"; linear :
    optional {"free": (omega (n,) rad/s, amp (n,)), "stuck": ...} drawn thin and grey;
    per_load : a swept key path (a load amplitude): each curve is divided by its value
    (amplitude per unit load: the linear limits are then one curve each).
    """
    j = study.settings.output
    fig = Figure(figsize=(9.0, 4.8), dpi=130, layout="constrained")
    ax = fig.add_subplot()
    cmap = colormaps["viridis"]
    n = len(frfs)
    for i, (m, fr, s) in enumerate(zip(study.members, frfs, summaries)):
        col = cmap(i / max(n - 1, 1) * 0.9)
        if len(fr) == 0:
            continue
        f, xlabel = frequency_axis(fr.omega, unit)
        scale = abs(float(m["values"][per_load])) or 1.0 if per_load else 1.0
        a = fr.amp_max[:, j] / scale
        st = np.asarray(fr.stable, bool)
        ax.plot(f, np.where(st, a, np.nan), color=col, lw=1.4,
                label=_label(m["values"], LEGEND_WIDTH))
        if not st.all():
            ax.plot(f, np.where(st, np.nan, a), color=col, lw=1.0, ls="--")
        w, pa = s["peaks"][j]
        ax.plot(frequency_axis(w, unit)[0], pa / scale, "o", color=col, ms=4)
        if not s["complete"]:
            ax.plot(f[-1], a[-1], "x", color="r", ms=8, mew=2)
    if linear:
        for name, ls in (("free", ":"), ("stuck", "-.")):
            if name in linear:
                w, a = linear[name]
                ax.plot(frequency_axis(w, unit)[0], a, color="0.5", lw=0.9, ls=ls,
                        label=f"linear, contacts {name}")
    fs = np.concatenate([frequency_axis(fr.omega, unit)[0] for fr in frfs if len(fr)]
                        or [np.zeros(0)])
    if fs.size > 1:                   # the linear curves do not widen the axis
        pad = 0.02 * np.ptp(fs)
        ax.set_xlim(fs.min() - pad, fs.max() + pad)
    ax.set_xlabel(frequency_axis(1.0, unit)[1])
    ax.set_ylabel("max amplitude over a period" + (" / load amplitude" if per_load else ""))
    names = study.raw.get("outputs", {}).get("dofs", [])
    out = names[j] if j < len(names) else f"output {j}"
    title = study.raw.get("title", study.path.stem)
    ax.set_title(f"{title}: {study.kind}, {out}", fontsize=10)
    pos = np.concatenate([fr.amp_max[:, j] for fr in frfs if len(fr)] or [np.ones(1)])
    if per_load:
        pos = np.concatenate([fr.amp_max[:, j] / (abs(float(m["values"][per_load])) or 1.0)
                              for m, fr in zip(study.members, frfs) if len(fr)]
                             or [np.ones(1)])
    pos = pos[pos > 0]
    if pos.size and pos.max() / pos.min() > 30:
        ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    # what the markers are, in black: their colours are the members'
    ax.plot([], [], "o", color="k", ms=4, label="peak (solved)")
    if not all(s["complete"] for s in summaries):
        ax.plot([], [], "x", color="r", ms=8, mew=2, label="curve stopped here")
    if any(not np.asarray(fr.stable, bool).all() for fr in frfs if len(fr)):
        ax.plot([], [], color="k", lw=1.0, ls="--", label="unstable (Hill)")
    # beside the axes, inside the figure (constrained layout makes room): never over the
    # curves, never cut off
    fig.legend(loc="outside right upper", fontsize=7)
    return fig


def plot_peaks(study, summaries, *, unit: str = "hz") -> Figure:
    """Peak amplitude and peak frequency against the first swept parameter (one line per
    combination of the others); a member whose curve stopped early is a red cross."""
    j = study.settings.output
    keys = [k for k, _ in study.settings.parameters]
    k0 = keys[0]
    fig = Figure(figsize=(7.5, 4.8), dpi=130, layout="constrained")
    axa, axf = fig.subplots(2, 1, sharex=True)
    groups = {}
    for m, s in zip(study.members, summaries):
        rest = tuple((k, str(m["values"][k])) for k in keys[1:]
                     if study.settings.combine == "product")
        groups.setdefault(rest, []).append((m["values"][k0], s))
    numeric = all(isinstance(v, (int, float)) for v, _ in sum(groups.values(), []))
    for rest, items in groups.items():
        x = [v for v, _ in items] if numeric else list(range(len(items)))
        a = [s["peaks"][j][1] for _, s in items]
        f = [frequency_axis(s["peaks"][j][0], unit)[0] for _, s in items]
        lab = ", ".join(f"{_short(k)} = {v}" for k, v in rest) or None
        line, = axa.plot(x, a, "o-", label=lab)
        axf.plot(x, f, "o-", color=line.get_color())
        for xi, ai, fi, (_, s) in zip(x, a, f, items):
            if not s["complete"]:
                axa.plot(xi, ai, "x", color="r", ms=9, mew=2)
                axf.plot(xi, fi, "x", color="r", ms=9, mew=2)
    if not numeric:
        axf.set_xticks(range(len(next(iter(groups.values())))))
        axf.set_xticklabels([str(v) for v, _ in next(iter(groups.values()))])
    axa.set_ylabel("peak amplitude")
    axf.set_ylabel("peak " + frequency_axis(1.0, unit)[1])
    axf.set_xlabel("\n".join(textwrap.wrap(
        k0 + ("  (zipped with " + ", ".join(keys[1:]) + ")"
              if study.settings.combine == "zip" and keys[1:] else ""), 90)))
    for ax in (axa, axf):
        ax.grid(True, alpha=0.3)
    if any(r for r in groups):
        axa.legend(fontsize=7)
    axa.set_title(f"{study.raw.get('title', study.path.stem)}: peak against {_short(k0)}",
                  fontsize=10)
    return fig


def plot_pareto(table, tol: float, choice=None) -> Figure:
    """Speed against accuracy (log-log): per rung the error against the reference (the
    largest of the peak amplitude and frequency errors and the curve distance, as the
    tolerance is applied) over its cost (reduction + FRF seconds); the
    Pareto front joined, the tolerance a horizontal line, the chosen model circled, rungs
    that failed (curve stopped, fold only there, error rising) red crosses with their
    note, the reference's cost a vertical line."""
    fig = Figure(figsize=(7.5, 4.8), dpi=130)
    ax = fig.add_subplot()
    rows = [r for r in table if not r["reference"]]
    floor = 1e-8
    x = np.array([max(r["cost_s"], 1e-3) for r in rows])
    y = np.array([max(r["error"], floor) if np.isfinite(r["error"]) else 1.0 for r in rows])
    ok = np.array([not r["notes"] for r in rows])
    ax.plot(x[ok], y[ok], "o", color="C0", label="rung")
    if (~ok).any():
        ax.plot(x[~ok], y[~ok], "x", color="r", ms=9, mew=2, label="rung that failed")
    front = _pareto(x, y)
    ax.plot(x[front], y[front], "-", color="C0", alpha=0.6, label="Pareto front")
    for r, xi, yi in zip(rows, x, y):
        txt = ", ".join(f"{_short(k).split('.')[-1]}={v}" for k, v in r["values"].items())
        if r["notes"]:
            txt += "\n" + "\n".join(textwrap.wrap("; ".join(r["notes"]), 50)[:3])
        ax.annotate(txt, (xi, yi), textcoords="offset points", xytext=(5, 4), fontsize=7,
                    color="r" if r["notes"] else "0.2")
    ax.axhline(tol, color="g", ls="--", lw=1, label=f"tolerance {tol:g}")
    ref = table[-1]
    ax.axvline(max(ref["cost_s"], 1e-3), color="0.4", ls=":", lw=1,
               label=f"reference ({ref['cost_s']:.2f} s)")
    if choice is not None:
        ax.plot(max(choice["cost_s"], 1e-3), max(choice["error"], floor), "o", ms=14,
                mfc="none", mec="g", mew=2, label="smallest within tolerance")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("cost: reduction + FRF wall time [s]")
    ax.set_ylabel("relative error against the reference\n(peak amplitude, peak frequency, "
                  "curve distance: the largest)", fontsize=9)
    rc = max(ref["cost_s"], 1e-3)
    ax.set_xlim(min(x.min(), rc) / 1.5, max(x.max(), rc) * 3.0)
    ax.set_ylim(top=max(y.max(), tol) * 8.0)      # room for the notes above the points
    ax.set_title("Speed against accuracy", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return fig


def _pareto(x, y) -> np.ndarray:
    """Indices of the points no other point beats in both x and y, by increasing x."""
    order = np.argsort(x, kind="stable")
    keep, best = [], np.inf
    for i in order:
        if y[i] < best:
            keep.append(i)
            best = y[i]
    return np.array(keep, int)
