"""Figures of a forced response (matplotlib). Each function builds a
:class:`matplotlib.figure.Figure` without pyplot, so no backend and no global state are
involved, and returns it; the caller saves it (``fig.savefig(path)``, as `frirom run`
does).

Both functions take an FRF-like object with ``omega`` (n_pts,) rad/s, ``amp_max``
(n_pts, n_out), ``stable`` (n_pts,) bool, ``fold`` (n_pts,) bool and
``state_fractions`` (n_pts, n_groups, 3) (stick, slip, lift-off).
"""

from __future__ import annotations

import matplotlib as mpl
import numpy as np
from matplotlib.figure import Figure

__all__ = ["plot_frf", "plot_states", "frequency_axis", "fold_marks", "relevant_outputs"]

_UNITS = {"hz": (1.0 / (2.0 * np.pi), "frequency [Hz]"),
          "rad/s": (1.0, "frequency [rad/s]")}


def frequency_axis(omega, unit: str = "hz"):
    """Frequencies in the plot unit and the axis label; omega in rad/s."""
    scale, label = _UNITS[unit.lower()]
    return np.asarray(omega, float) * scale, label


def _runs(mask):
    """Index ranges [i0, i1) of consecutive equal values of a boolean array."""
    mask = np.asarray(mask, bool)
    if mask.size == 0:
        return []
    cuts = np.flatnonzero(np.diff(mask.astype(np.int8))) + 1
    starts = np.r_[0, cuts]
    ends = np.r_[cuts, mask.size]
    return [(int(a), int(b), bool(mask[a])) for a, b in zip(starts, ends)]


def relevant_outputs(amp, share: float = 1e-3) -> np.ndarray:
    """(n_out,) bool: outputs whose largest amplitude reaches `share` of the largest one's.

    A DoF that stays near round-off (a stuck or symmetric direction) is drawn but does not
    set the amplitude axis."""
    amp = np.asarray(amp, float).reshape(len(amp), -1)
    top = np.nanmax(np.abs(amp), axis=0) if amp.size else np.zeros(amp.shape[1])
    return top >= share * max(float(np.max(top, initial=0.0)), 1e-300)


def fold_marks(f, amp, fold, max_marks: int = 4, share: float = 0.005) -> np.ndarray:
    """Indices of the folds worth marking: those whose turned-back stretch spans more than
    `share` of the frequency range, at most `max_marks` (the widest stretches).

    Folds come in pairs along a sweep: one turns the curve back, the next turns it
    forward again; the stretch between them (to the end for an unpaired last fold) is
    what the pair measures. Round-off wiggles of a stepping continuation (pairs a few
    millihertz apart) are left unmarked."""
    idx = np.flatnonzero(np.asarray(fold, bool))
    f = np.asarray(f, float)
    span = float(np.ptp(f)) if f.size else 0.0
    if idx.size == 0 or span == 0.0:
        return idx[:0]
    first = idx[0::2]
    second = np.r_[idx[1::2], [f.size - 1] * (first.size - idx[1::2].size)].astype(int)
    extent = np.array([np.ptp(f[a:b + 1]) for a, b in zip(first, second)])
    big = np.argsort(-extent)[:max(max_marks // 2, 1)]
    big = big[extent[big] > share * span]
    keep = np.r_[first[big], idx[1::2][big[big < idx[1::2].size]]]
    return np.sort(keep).astype(int)


def plot_frf(frf, *, output_names=None, unit: str = "hz", title: str | None = None,
             amplitude_unit: str = "m", log: bool | None = None, ax=None,
             phase: bool = False, linear: dict | None = None) -> Figure:
    """Max amplitude over a period against frequency, one curve per output.

    The curve is drawn in the order of the continuation, so it stays a line against
    frequency through folds. Stable stretches are solid, unstable dashed (Hill's method,
    ``frf.stable``); the folds that turn the curve back noticeably are marked with open
    circles on the largest output (:func:`fold_marks`). The amplitude axis is set by the
    outputs that matter (:func:`relevant_outputs`): a DoF near round-off does not drag it.

    Parameters
    ----------
    frf : FRF-like
        See the module docstring; ``amp_max`` may also be (n_pts,).
    output_names : list of str, optional
        Legend entry per output (n_out,); default ``frf.output_labels`` or ``output j``.
    unit : {"hz", "rad/s"}
        Frequency axis unit.
    title : str, optional
        Axes title; default "Forced response".
    amplitude_unit : str
        Unit shown on the amplitude axis.
    log : bool, optional
        Logarithmic amplitude axis; default when the relevant amplitudes span more than
        30x. Its bottom is the 5th percentile of the relevant outputs' amplitudes, at most
        four decades below the largest.
    ax : matplotlib.axes.Axes, optional
        Draw on these axes; default a new 7.5 x 4.6 in Figure at 130 dpi.
    phase : bool
        Add a panel below with the phase of the first harmonic of each relevant output
        (x_1 = A cos(omega t + phase), deg in (-270, 90]; needs ``frf.X``); not with
        `ax`.
    linear : dict, optional
        Reference curves {"free": (omega (n,) rad/s, amp (n, n_out)), "stuck": ...}: the
        linear responses with the contacts free (dotted) and stuck (dash-dot), thin, in
        each output's colour (:meth:`frirom.modes.LinearCheck.linear_curves`).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on (``ax.figure`` when `ax` is given).
    """
    f, xlabel = frequency_axis(frf.omega, unit)
    amp = np.asarray(frf.amp_max, float)
    if amp.ndim == 1:
        amp = amp[:, None]
    stable = (np.ones(f.size, bool) if getattr(frf, "stable", None) is None
              else np.asarray(frf.stable, bool))
    fold = (np.zeros(f.size, bool) if getattr(frf, "fold", None) is None
            else np.asarray(frf.fold, bool))
    names = (output_names or list(getattr(frf, "output_labels", None) or [])
             or [f"output {j}" for j in range(amp.shape[1])])
    own = ax is None
    if own:
        fig = Figure(figsize=(7.5, 6.4 if phase else 4.6), dpi=130)
        if phase:
            ax, pax = fig.subplots(2, 1, sharex=True, height_ratios=(2.2, 1.0))
        else:
            ax = fig.add_subplot()
    fig = ax.figure
    refs = {k: (v[0], np.asarray(v[1], float).reshape(len(v[0]), -1))
            for k, v in (linear or {}).items() if k in ("free", "stuck")}
    # the amplitudes that set the axis: the curve's, else (no point) the linear curves'
    scale = amp if amp.shape[0] or not refs else np.vstack([a for _, a in refs.values()])
    rel = relevant_outputs(scale) if scale.size else np.ones(amp.shape[1], bool)
    colors = mpl.rcParams["axes.prop_cycle"].by_key()["color"]
    for j in range(amp.shape[1]):
        col = colors[j % len(colors)]
        label = names[j] if rel[j] else f"{names[j]} (< 1e-3 of the largest)"
        if f.size == 0:                 # linear curves only: name each output's colour
            ax.plot([], [], color=col, lw=1.6, label=label)
        for a, b, st in _runs(stable):
            # join each stretch to the next point so the curve has no gaps
            sl = slice(a, min(b + 1, f.size))
            ax.plot(f[sl], amp[sl, j], color=col, lw=1.6 if st else 1.2,
                    ls="-" if st else "--", label=label if a == 0 else None)
    if f.size and amp.size:
        top = int(np.argmax(np.nanmax(amp, axis=0)))
        marks = fold_marks(f, amp[:, top], fold)
        # where the folds were located on the curve (FRF.bifurcations), mark them there
        bifs = getattr(frf, "bifurcations", None) or []
        at = {b.index: b for b in bifs if b.kind == "fold" and b.located}
        if marks.size:
            fx = [frequency_axis(np.array([at[i].omega]), unit)[0][0] if i in at else f[i]
                  for i in marks]
            fy = [np.ravel(at[i].amp_max)[top] if i in at else amp[i, top] for i in marks]
            ax.plot(fx, fy, "o", mfc="none", mec="k", ms=6, mew=1.0, zorder=5, label="fold")
        ns = [b for b in bifs if b.kind == "ns_or_pd"]
        if ns:
            ax.plot(frequency_axis(np.array([b.omega for b in ns]), unit)[0],
                    [np.ravel(b.amp_max)[top] for b in ns], "x", color="k", ms=7, mew=1.2,
                    zorder=5, label="stability change (NS or PD)")
    for kind, ls in (("free", ":"), ("stuck", "-.")):
        if kind in refs:
            wl, al = refs[kind]
            for j in range(al.shape[1]):
                ax.plot(frequency_axis(wl, unit)[0], al[:, j], color=colors[j % len(colors)],
                        lw=0.8 if f.size else 1.2, ls=ls, alpha=0.7 if f.size else 1.0)
            # the line style's entry in a neutral colour: the colours are the outputs'
            ax.plot([], [], color="0.3", lw=1.0, ls=ls, label=f"linear, contacts {kind}")
            if f.size > 1:              # the reference curves do not widen the axis
                pad = 0.02 * (f.max() - f.min())
                ax.set_xlim(f.min() - pad, f.max() + pad)
    pos = scale[:, rel][scale[:, rel] > 0]
    if log is None:
        log = pos.size > 0 and pos.max() / pos.min() > 30.0
    if log:
        ax.set_yscale("log")
    if pos.size:
        hi = pos.max()
        if log:
            # the bottom: where the relevant outputs spend all but 5 % of the curve (a
            # direction that passes through zero at a few points dips below it), four
            # decades below the largest amplitude at most
            lows = [np.percentile(a[a > 0], 5) for a in scale[:, rel].T if np.any(a > 0)]
            ax.set_ylim(max(min(lows), 1e-4 * hi) / 1.5, hi * 1.5)
        else:
            ax.set_ylim(0.0, hi * 1.08)
    if not stable.all():
        ax.plot([], [], color="0.3", ls="--", label="unstable (Hill)")
    ax.set_ylabel(f"max amplitude over a period [{amplitude_unit}]")
    ax.set_title(title or "Forced response")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    if own and phase:
        X = np.asarray(frf.X, float)
        for j in np.flatnonzero(rel):
            a1 = np.hypot(X[:, j, 1], X[:, j, 2])
            # in (-270, 90]: a lag from 0 through -180 stays continuous; no phase where
            # the first harmonic is below 1e-3 of its largest (a stuck direction's
            # round-off has no phase)
            ph = (np.degrees(np.arctan2(-X[:, j, 2], X[:, j, 1])) + 270.0) % 360.0 - 270.0
            ph[a1 < 1e-3 * max(a1.max(), 1e-300)] = np.nan
            pax.plot(f, ph, color=colors[j % len(colors)], lw=1.2)
        pax.set_ylabel("phase of h1 [deg]")
        pax.set_yticks([-270, -180, -90, 0, 90])
        pax.grid(True, alpha=0.3)
        pax.set_xlabel(xlabel)
    else:
        ax.set_xlabel(xlabel)
    if own:
        fig.tight_layout()
    return fig


def plot_states(frf, *, contact_names=None, unit: str = "hz",
                title: str | None = None) -> Figure:
    """Fraction of the period each contact group spends in stick, slip and lift-off
    against frequency (stacked areas, one panel per group).

    Parameters
    ----------
    frf : FRF-like
        See the module docstring; ``state_fractions`` may also be (n_pts, 3).
    contact_names : list of str, optional
        Panel title per contact group (n_groups,); default ``contact g``.
    unit : {"hz", "rad/s"}
        Frequency axis unit. Stacked areas while the frequency is monotone along the
        path; where the curve folds, three lines (stick, slip, lift-off) in the path's
        order, still against frequency.
    title : str, optional
        Figure title; default "Contact states".

    Returns
    -------
    matplotlib.figure.Figure
        A new 7.5 in wide Figure at 130 dpi, 2 in high per group.
    """
    f, xlabel = frequency_axis(frf.omega, unit)
    sf = np.asarray(frf.state_fractions, float)
    if sf.ndim == 2:
        sf = sf[:, None, :]
    ng = sf.shape[1]
    names = contact_names or [f"contact {g}" for g in range(ng)]
    fig = Figure(figsize=(7.5, 1.2 + 2.0 * max(ng, 1)), dpi=130)
    axes = fig.subplots(max(ng, 1), 1, sharex=True, squeeze=False)
    # along a continuation path the frequency can turn back: a stacked area needs a
    # monotone x, lines in the path's order do not
    mono = np.all(np.diff(f) > 0) or np.all(np.diff(f) < 0)
    order = np.argsort(f)
    colors = ("#2b8cbe", "#f39c12", "#c0392b")
    labels = ("stick", "slip", "lift-off")
    for g in range(ng):
        ax = axes[g, 0]
        if mono:
            ax.stackplot(f[order], *(sf[order, g, k] for k in range(3)), colors=colors,
                         labels=labels, alpha=0.85)
        else:
            for k in range(3):
                ax.plot(f, sf[:, g, k], color=colors[k], lw=1.4, label=labels[k])
        # lines at 0 or 1 must not hide under the frame
        ax.set_ylim((0.0, 1.0) if mono else (-0.03, 1.03))
        ax.set_ylabel("fraction of period")
        ax.set_title(names[g], fontsize=9, loc="left")
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), fontsize=8, ncol=3,
                      frameon=False, borderaxespad=0.2)
    axes[-1, 0].set_xlabel(xlabel)
    fig.suptitle(title or "Contact states", fontsize=11)
    fig.tight_layout()
    return fig
