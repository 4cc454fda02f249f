"""``frirom demo``: hysteresis loops and harmonic content of contact elements.

A quick look at what the AFT kernel computes, on two bundled cases:

* a Jenkins element (kt = 1e5 N/m, mu = 0.3, N = 100 N) under u = A cos(wt) at amplitudes
  from full stick to gross slip, with the dissipated energy per cycle checked against the
  closed form 4 mu N (A - mu N / kt);
* a 1-D element with normal load variation whose normal motion opens the contact for part
  of the cycle (stick, slip and lift-off in one period).

Writes ``hysteresis.png``, ``harmonics.png`` and ``harmonics.csv`` into the output folder.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from . import contact, harmonics

JENKINS = {"kt": 1.0e5, "mu": 0.3, "fn0": 100.0}
NORMAL1D = {"kt": 1.0e5, "kn": 0.8e5, "mu": 0.4, "n0": 60.0}
N_HARM, N_SAMPLES = 7, 512


def liftoff_cycle() -> np.ndarray:
    """Relative displacement harmonics (1, 2, 2H+1) of the lift-off case, m."""
    x = np.zeros((1, 2, 2 * N_HARM + 1))
    x[0, 0, 1], x[0, 0, 4] = 1.0e-3, 0.2e-3           # u = cos + 0.2 sin 2wt, mm
    x[0, 1, 2], x[0, 1, 3] = 1.2e-3, 0.3e-3           # v = 1.2 sin + 0.3 cos 2wt, mm
    return x


def compute():
    """Everything the demo shows, as numpy arrays (no plotting)."""
    amps = np.array([0.2e-3, 0.5e-3, 1.0e-3, 3.0e-3])
    xj = np.zeros((amps.size, 1, 2 * N_HARM + 1))
    xj[:, 0, 1] = amps
    tau, ut, ft = contact.time_histories("jenkins", xj, JENKINS, N_SAMPLES)
    rj = contact.aft("jenkins", xj, JENKINS, N_SAMPLES, jacobian=False)
    energy = -np.pi * amps * rj.forces[:, 0, 2]
    fs = JENKINS["mu"] * JENKINS["fn0"]
    closed = np.where(amps > fs / JENKINS["kt"], 4 * fs * (amps - fs / JENKINS["kt"]), 0.0)
    xl = liftoff_cycle()
    _, xlt, flt = contact.time_histories("normal1d", xl, NORMAL1D, N_SAMPLES)
    rl = contact.aft("normal1d", xl, NORMAL1D, N_SAMPLES, jacobian=False)
    return dict(tau=tau, amps=amps, ut=ut[:, 0], ft=ft[:, 0], energy=energy, closed=closed,
                jenkins_forces=rj.forces[:, 0], liftoff_x=xlt[0], liftoff_f=flt[0],
                liftoff_forces=rl.forces[0], liftoff_states=rl.states[0])


def hysteresis_figure(res) -> Figure:
    """Jenkins hysteresis loops, the lift-off element's loop and its forces over one
    period; `res` from :func:`compute`. Returns a new 15 x 4.6 in Figure."""
    fig = Figure(figsize=(15, 4.6), layout="constrained")
    axes = fig.subplots(1, 3)
    ax = axes[0]
    for a, u, f, e, c in zip(res["amps"], res["ut"], res["ft"], res["energy"], res["closed"]):
        ax.plot(np.append(u, u[0]) * 1e3, np.append(f, f[0]),
                label=f"A = {a * 1e3:.1f} mm: W = {abs(e) * 1e3:.2f} mJ "
                      f"(closed form {c * 1e3:.2f})")
    ax.set(xlabel="tangential relative displacement u [mm]", ylabel="tangential force [N]",
           title="Jenkins element, kt = 1e5 N/m, mu N = 30 N")
    ax.legend(fontsize=7, loc="upper left", framealpha=0.95)
    ax.grid(alpha=0.3)
    u, v = res["liftoff_x"]
    ftl, fnl = res["liftoff_f"]
    ax = axes[1]
    ax.plot(np.append(u, u[0]) * 1e3, np.append(ftl, ftl[0]), color="C3")
    ax.set(xlabel="tangential relative displacement u [mm]", ylabel="tangential force [N]",
           title="1-D element with normal load variation")
    ax.grid(alpha=0.3)
    ax = axes[2]
    deg = np.degrees(res["tau"])
    ax.plot(deg, ftl, label="tangential force f_t [N]", color="C3")
    ax.plot(deg, fnl, label="normal force f_n [N]", color="C0")
    ax.plot(deg, NORMAL1D["mu"] * fnl, "--", label="friction limit mu f_n [N]", color="C0")
    ax.plot(deg, -NORMAL1D["mu"] * fnl, "--", color="C0")
    s = res["liftoff_states"]
    ax.set(xlabel="phase wt [deg]", ylabel="force [N]",
           title=f"one period: stick {s[0]:.0%}, slip {s[1]:.0%}, lift-off {s[2]:.0%}")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    return fig


def harmonics_figure(res) -> Figure:
    """Force harmonic amplitudes of the Jenkins and the lift-off cases (log bars); `res`
    from :func:`compute`. Returns a new 11 x 4 in Figure."""
    fig = Figure(figsize=(11, 4), layout="constrained")
    axes = fig.subplots(1, 2)
    h = np.arange(N_HARM + 1)
    width = 0.8 / len(res["amps"])
    for i, (a, f) in enumerate(zip(res["amps"], res["jenkins_forces"])):
        offset = (i - (len(res["amps"]) - 1) / 2) * width
        axes[0].bar(h + offset, harmonics.amplitudes(f), width, label=f"A = {a * 1e3:.1f} mm")
    axes[0].set(xlabel="harmonic h", ylabel="force amplitude [N]", yscale="log",
                title="Jenkins: odd harmonics only", ylim=(1e-3, None))
    axes[0].legend(fontsize=7)
    amp_l = harmonics.amplitudes(res["liftoff_forces"])
    axes[1].bar(h - 0.2, amp_l[0], 0.4, label="tangential")
    axes[1].bar(h + 0.2, amp_l[1], 0.4, label="normal")
    axes[1].set(xlabel="harmonic h", ylabel="force amplitude [N]", yscale="log",
                title="normal load variation: mean and even harmonics appear", ylim=(1e-2, None))
    axes[1].legend(fontsize=7)
    return fig


def figures(res) -> dict[str, Figure]:
    """The demo's figures by file name (``hysteresis.png``, ``harmonics.png``)."""
    return {"hysteresis.png": hysteresis_figure(res), "harmonics.png": harmonics_figure(res)}


def write_csv(res, out: Path) -> Path:
    """The force harmonics of both cases as ``harmonics.csv`` in `out`."""
    p = out / "harmonics.csv"
    with p.open("w", newline="") as fh:
        w = csv.writer(fh)
        names = ["a0"] + [f"{c}{k}" for k in range(1, N_HARM + 1) for c in ("a", "b")]
        w.writerow(["case", "force"] + names)
        for a, f in zip(res["amps"], res["jenkins_forces"]):
            w.writerow([f"jenkins A={a:g} m", "f_t"] + [f"{v:.10g}" for v in f])
        for name, f in zip(("f_t", "f_n"), res["liftoff_forces"]):
            w.writerow(["normal1d lift-off", name] + [f"{v:.10g}" for v in f])
    return p


def run(out: Path) -> list[Path]:
    """Compute, save the figures (120 dpi) and the CSV into `out`, print the energy check;
    returns the paths written."""
    res = compute()
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, fig in figures(res).items():
        fig.savefig(out / name, dpi=120)
        paths.append(out / name)
    paths.append(write_csv(res, out))
    for a, e, c in zip(res["amps"], res["energy"], res["closed"]):
        check = (f"relative difference {abs(e - c) / c:.1e}" if c > 0
                 else "full stick: no dissipation")
        print(f"Jenkins A = {a * 1e3:4.1f} mm: dissipated {abs(e) * 1e3:8.4f} mJ/cycle "
              f"(closed form {c * 1e3:8.4f}, {check})")
    s = res["liftoff_states"]
    print(f"normal-load element: stick {s[0]:.0%}, slip {s[1]:.0%}, lift-off {s[2]:.0%} "
          "of the cycle")
    for p in paths:
        print(f"wrote {p}")
    return paths
