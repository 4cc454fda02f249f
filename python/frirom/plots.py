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

__all__ = ["plot_frf", "plot_states", "frequency_axis"]

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


def plot_frf(frf, *, output_names=None, unit: str = "hz", title: str | None = None,
             amplitude_unit: str = "m", log: bool | None = None, ax=None,
             linear: dict | None = None) -> Figure:
    """Max amplitude over a period against frequency, one curve per output.

    Stable stretches are solid, unstable dashed (Hill's method, ``frf.stable``); folds
    (``frf.fold``) are marked with a black diamond.

    Parameters
    ----------
    frf : FRF-like
        See the module docstring; ``amp_max`` may also be (n_pts,).
    output_names : list of str, optional
        Legend entry per output (n_out,); default ``output j``.
    unit : {"hz", "rad/s"}
        Frequency axis unit.
    title : str, optional
        Axes title; default "Forced response".
    amplitude_unit : str
        Unit shown on the amplitude axis.
    log : bool, optional
        Logarithmic amplitude axis; default when the amplitudes span more than 30x.
    ax : matplotlib.axes.Axes, optional
        Draw on these axes; default a new 7.5 x 4.6 in Figure at 130 dpi.
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
    names = output_names or [f"output {j}" for j in range(amp.shape[1])]
    own = ax is None
    if own:
        fig = Figure(figsize=(7.5, 4.6), dpi=130)
        ax = fig.add_subplot()
    fig = ax.figure
    colors = mpl.rcParams["axes.prop_cycle"].by_key()["color"]
    for j in range(amp.shape[1]):
        col = colors[j % len(colors)]
        for a, b, st in _runs(stable):
            # join each stretch to the next point so the curve has no gaps
            sl = slice(a, min(b + 1, f.size))
            ax.plot(f[sl], amp[sl, j], color=col, lw=1.6 if st else 1.2,
                    ls="-" if st else "--",
                    label=names[j] if a == 0 else None)
        if fold.any():
            ax.plot(f[fold], amp[fold, j], "D", color="k", ms=4.5, zorder=5,
                    label="fold" if j == 0 else None)
    for kind, ls in (("free", ":"), ("stuck", "-.")):
        if linear and kind in linear:
            wl, al = linear[kind]
            al = np.asarray(al, float).reshape(len(wl), -1)
            for j in range(al.shape[1]):
                ax.plot(frequency_axis(wl, unit)[0], al[:, j], color=colors[j % len(colors)],
                        lw=0.8, ls=ls, alpha=0.7,
                        label=f"linear, contacts {kind}" if j == 0 else None)
            if f.size > 1:              # the reference curves do not widen the axis
                pad = 0.02 * (f.max() - f.min())
                ax.set_xlim(f.min() - pad, f.max() + pad)
    if log is None:
        pos = amp[amp > 0]
        log = pos.size > 0 and pos.max() / pos.min() > 30.0
    if log:
        ax.set_yscale("log")
        # a DoF that stays at round-off (a stuck or symmetric direction) would stretch
        # the axis over twenty decades: show six below the largest amplitude
        pos = amp[amp > 0]
        if pos.size:
            ax.set_ylim(bottom=max(pos.min(), 1e-6 * pos.max()) / 2)
    if not stable.all():
        ax.plot([], [], color="0.3", ls="--", label="unstable (Hill)")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(f"max amplitude over a period [{amplitude_unit}]")
    ax.set_title(title or "Forced response")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="best", fontsize=8)
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
        Frequency axis unit (used when the frequency is monotone along the path; else
        the panels are drawn against the point index).
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
    # along a continuation path the frequency can turn back: plot against the point order
    # mapped to frequency only when it is monotone
    mono = np.all(np.diff(f) > 0) or np.all(np.diff(f) < 0)
    xs = f if mono else np.arange(f.size)
    order = np.argsort(xs) if mono else slice(None)
    colors = ("#2b8cbe", "#f39c12", "#c0392b")
    for g in range(ng):
        ax = axes[g, 0]
        ax.stackplot(xs[order], *(sf[order, g, k] for k in range(3)), colors=colors,
                     labels=("stick", "slip", "lift-off"), alpha=0.85)
        ax.set_ylim(0.0, 1.0)
        ax.set_ylabel("fraction of period")
        ax.set_title(names[g], fontsize=9, loc="left")
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), fontsize=8, ncol=3,
                      frameon=False, borderaxespad=0.2)
    axes[-1, 0].set_xlabel(xlabel if mono else "point along the continuation path")
    fig.suptitle(title or "Contact states", fontsize=11)
    fig.tight_layout()
    return fig
