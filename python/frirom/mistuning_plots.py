"""Figures of a mistuning study (matplotlib, no pyplot): every blade's amplitude at the
largest blade's peak, the amplification factor's histogram and cumulative distribution,
and the largest-blade FRF envelope over the samples against the tuned FRF. Each function
returns a Figure."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .reduction.mistuning import whitehead_bound


def plot_blade_amplitudes(response, tuned=None, title: str = "") -> Figure:
    """Bar chart: each blade's amplitude at the frequency of the largest blade peak
    (localisation), with the tuned peak as a line."""
    fig = Figure(figsize=(7, 3.5), layout="constrained")
    ax = fig.add_subplot()
    a = response.blade_peaks
    ax.bar(np.arange(a.size), a, color="C0", label="mistuned, at its peak")
    if tuned is not None:
        ax.axhline(tuned.peak, color="k", ls="--", label="tuned peak")
    ax.set_xlabel("blade")
    ax.set_ylabel("amplitude [m]")
    ax.set_title(title or "Blade amplitudes at the largest blade's peak")
    ax.legend(loc="upper right")
    return fig


def plot_amplification(factors: dict, n_blades: int | None = None) -> Figure:
    """Histogram and empirical CDF of the amplification factors, one colour per interface
    state ({'friction': af, 'stuck': af, ...}); Whitehead's bound as a line."""
    fig = Figure(figsize=(9, 3.5), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    for i, (name, af) in enumerate(factors.items()):
        af = np.sort(np.asarray(af, float))
        ax1.hist(af, bins=max(5, int(np.sqrt(af.size))), alpha=0.5, color=f"C{i}",
                 label=f"{name} (n = {af.size})")
        ax2.step(af, np.arange(1, af.size + 1) / af.size, where="post", color=f"C{i}",
                 label=name)
    if n_blades is not None:
        for ax in (ax1, ax2):
            ax.axvline(whitehead_bound(n_blades), color="k", ls=":",
                       label="Whitehead (1 + sqrt N) / 2")
    ax1.set_xlabel("amplification factor")
    ax1.set_ylabel("samples")
    ax2.set_xlabel("amplification factor")
    ax2.set_ylabel("cumulative probability")
    ax1.legend(fontsize="small")
    ax2.legend(fontsize="small", loc="lower right")
    return fig


def plot_envelopes(samples, tuned, unit: str = "hz") -> Figure:
    """Largest blade amplitude against frequency: the tuned disk, each sample (thin) and
    the envelope over the samples (the maximum at each frequency, interpolated on the
    tuned grid)."""
    fig = Figure(figsize=(7, 4), layout="constrained")
    ax = fig.add_subplot()
    s = 1 / (2 * np.pi) if unit == "hz" else 1.0
    w = np.linspace(tuned.omega.min(), tuned.omega.max(), 800)
    env = np.zeros_like(w)
    for smp in samples:
        om, e = np.asarray(smp["omega"]), np.asarray(smp["envelope"])
        order = np.argsort(om)
        ax.plot(om * s, e, color="0.75", lw=0.5)
        env = np.maximum(env, np.interp(w, om[order], e[order]))
    ax.plot(w * s, env, color="C3", lw=1.5, label=f"envelope of {len(samples)} samples")
    ax.plot(tuned.omega * s, tuned.envelope, color="k", lw=1.5, label="tuned")
    ax.set_xlabel("frequency [Hz]" if unit == "hz" else "frequency [rad/s]")
    ax.set_ylabel("largest blade amplitude [m]")
    ax.legend()
    return fig
