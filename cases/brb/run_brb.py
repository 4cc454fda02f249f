"""The Brake-Reuss beam's backbone in one command: build the case if it is not built
(cases/brb/build_brb.py), run the first bending mode's nonlinear mode (brb_mode.toml,
EPMC), and set it beside the published backbone (docs/cases/brb.md).

    python cases/brb/run_brb.py                 # coarse mesh, H = 3 (a few minutes)
    python cases/brb/run_brb.py --mu 0.1 0.6    # the friction coefficient's effect
    python cases/brb/run_brb.py --deck brb_cb_mode.toml --out results/brb_cb_mode

Writes results/brb_mode/: backbone.csv, backbone.h5 and backbone.png of the deck's run,
compare.csv (frequency and damping ratio at the published tip accelerations, every mu)
and compare.png (the backbones against tip acceleration with the published points).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE.parent / "models"))

#: the published backbone (Porter & Brake 2023, flat interface, EPMC; tmdsimpy
#: examples/structures/results/brb_epmc_flat.yaml): tip acceleration [m/s^2],
#: frequency [Hz], damping ratio
PUBLISHED = ((0.1, 168.50, 0.00087), (7.0, 167.5, 0.0043), (65.0, 156.7, 0.0306))
#: the whole published backbone (the same file, every fourth point, rounded): tip
#: acceleration [m/s^2], frequency [Hz], damping ratio
PUBLISHED_CURVE = ((0.1091, 168.50, 0.0008728), (0.2715, 168.50, 0.0008933),
                   (0.7211, 168.48, 0.0009554), (1.913, 168.38, 0.001328),
                   (5.052, 167.92, 0.002882), (13.11, 166.15, 0.0079),
                   (32.92, 162.62, 0.01525), (65.31, 156.67, 0.03063))
#: CalculiX's stuck first bending mode must be the one the backbone starts from
START_TOL = 1e-3


def ensure_built(log=print) -> None:
    """Build the case next to its decks unless its matrices are there."""
    if not (HERE / "brb.sti").exists():
        import build_brb
        log("run_brb: building the case (gmsh, ccx, the static preload)")
        build_brb.make(HERE, log=log)


def tip_acceleration(bb, out: int = 0) -> np.ndarray:
    """Harmonic-1 acceleration amplitude [m/s^2] at output `out` along the backbone."""
    return (2 * np.pi * np.asarray(bb.frequency)) ** 2 * bb.output_amplitude(out)


def at_accelerations(bb, acc=tuple(p[0] for p in PUBLISHED)) -> np.ndarray:
    """(frequency [Hz], damping ratio) at tip accelerations acc (log interpolation along
    the backbone; nan outside it)."""
    a = np.log(tip_acceleration(bb))
    if np.any(np.diff(a) <= 0):
        raise ValueError("run_brb: the tip acceleration does not grow along the backbone")
    out = []
    for x in np.log(acc):
        if a[0] <= x <= a[-1]:
            out.append((np.interp(x, a, bb.frequency), np.interp(x, a, bb.damping_ratio)))
        else:
            out.append((np.nan, np.nan))
    return np.array(out)


def backbone(deck_path=HERE / "brb_mode.toml", mu=None, harmonics=None, amplitudes=None,
             check_start=True):
    """The deck's backbone (frirom.nonlinear_mode), optionally with every contact's
    friction coefficient mu, H = harmonics or other modal amplitudes; returns
    (backbone, deck, seconds)."""
    from frirom.deck import load_deck
    from frirom.nonlinear_modes import nonlinear_mode
    deck = load_deck(deck_path)
    an = deck.settings.analysis
    model, options = deck.model(), deck.options()
    if mu is not None:
        for g in model.contacts:
            g.params[:, 2] = mu              # normal2d: kt, kn, mu, n0
    if harmonics is not None:
        options = dataclasses.replace(options, harmonics=harmonics)
    static = deck.F[:, 0].real if np.any(deck.F[:, 0]) else None
    t0 = time.perf_counter()
    bb = nonlinear_mode(model, an.mode - 1, amplitudes or an.amplitudes, an.start, options,
                        outputs=deck.solver_outputs, static=static)
    if check_start:
        from upd import read_eigenfrequencies
        ref = read_eigenfrequencies(Path(deck_path).parent / "stuck.dat")[6]
        if abs(bb.frequency[0] / ref - 1) > START_TOL:
            raise RuntimeError(f"run_brb: the backbone starts at {bb.frequency[0]:.4f} Hz, "
                               f"not on CalculiX's stuck first bending mode {ref:.4f} Hz: "
                               "[analysis] mode picks another mode")
    return bb, deck, time.perf_counter() - t0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mu", type=float, nargs="*", default=[],
                    help="friction coefficients to run besides the deck's")
    ap.add_argument("--deck", default="brb_mode.toml",
                    help="the deck next to this script (brb_cb_mode.toml: ROM_I, slow)")
    ap.add_argument("--out", type=Path, default=ROOT / "results" / "brb_mode")
    a = ap.parse_args(argv)
    ensure_built()
    from frirom.backbone import plot_backbone, save_csv, save_h5
    a.out.mkdir(parents=True, exist_ok=True)
    runs = []
    for mu in [None] + list(a.mu):
        bb, deck, sec = backbone(HERE / a.deck, mu=mu)
        m = float(deck.model().contacts[0].params[0, 2]) if mu is None else mu
        print(f"run_brb: mu = {m:g}: {len(bb)} points in {sec:.1f} s, "
              f"{bb.frequency[0]:.3f} -> {bb.frequency[-1]:.3f} Hz"
              + ("" if bb.status == "done" else f" (stopped early: {bb.message})"))
        runs.append((m, bb))
        if mu is None:
            save_h5(bb, a.out / "backbone.h5", {"deck_path": str(deck.path)})
            save_csv(bb, a.out / "backbone.csv", deck.output_names)
            plot_backbone(bb, 0, deck.output_names[0], title=deck.title).savefig(
                a.out / "backbone.png")
    rows = []
    print("run_brb: tip acc. [m/s^2] | published f [Hz], zeta [%] | this model (mu): "
          "f [Hz] (diff), zeta [%]")
    for m, bb in runs:
        for (acc, f_p, z_p), (f, z) in zip(PUBLISHED, at_accelerations(bb)):
            rows.append((m, acc, f_p, z_p, f, z))
            print(f"  {acc:6.1f} | {f_p:7.2f}, {100 * z_p:5.3f} | mu = {m:g}: {f:8.3f} "
                  f"({100 * (f / f_p - 1):+.2f} %), {100 * z:6.3f}")
    np.savetxt(a.out / "compare.csv", np.array(rows), delimiter=",",
               header="mu, tip acceleration [m/s^2], published f [Hz], published zeta, "
                      "f [Hz], zeta", fmt="%.8g")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for m, bb in runs:
        acc = tip_acceleration(bb)
        ax[0].semilogx(acc, bb.frequency, label=f"frirom, mu = {m:g}")
        ax[1].loglog(acc, 100 * bb.damping_ratio, label=f"frirom, mu = {m:g}")
    pub, cur = np.array(PUBLISHED), np.array(PUBLISHED_CURVE)
    ax[0].semilogx(cur[:, 0], cur[:, 1], "k--", lw=1)
    ax[1].loglog(cur[:, 0], 100 * cur[:, 2], "k--", lw=1)
    ax[0].semilogx(pub[:, 0], pub[:, 1], "ko", label="Porter & Brake 2023 (EPMC, flat)")
    ax[1].loglog(pub[:, 0], 100 * pub[:, 2], "ko", label="Porter & Brake 2023 (EPMC, flat)")
    ax[0].set(xlabel="tip acceleration [m/s²]", ylabel="frequency [Hz]")
    ax[1].set(xlabel="tip acceleration [m/s²]", ylabel="damping ratio [%]")
    ax[0].legend(fontsize=8)
    fig.suptitle("Brake-Reuss beam, first bending mode: backbone")
    fig.savefig(a.out / "compare.png", dpi=110)
    plot_preload(HERE / "preload.csv").savefig(a.out / "preload.png", dpi=110)
    print(f"run_brb: wrote {a.out}/backbone.csv, backbone.h5, backbone.png, compare.csv, "
          "compare.png, preload.png")


def plot_preload(csv):
    """The lap's normal preload per pair (build_brb.py's preload.csv) over the interface,
    with the bolts' holes and washers."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import brb
    x, y, n0, _ = np.loadtxt(csv, delimiter=",", unpack=True)
    xc = brb.GEOMETRY["length"] / 2
    fig, ax = plt.subplots(figsize=(8, 2.6), constrained_layout=True)
    on = n0 > 0
    sc = ax.scatter(1e3 * (x[on] - xc), 1e3 * y[on], c=n0[on], s=60, cmap="viridis")
    ax.scatter(1e3 * (x[~on] - xc), 1e3 * y[~on], s=20, facecolors="none",
               edgecolors="0.5", label="open")
    for o in brb.BOLTS["offsets"]:
        for r, st in ((brb.BOLTS["hole"] / 2, "-"), (brb.BOLTS["washer"], ":")):
            ax.add_patch(plt.Circle((1e3 * o, 1e3 * brb.GEOMETRY["width"] / 2), 1e3 * r,
                                    fill=False, ls=st, color="k"))
    ax.set(aspect="equal", xlabel="x from the lap's centre [mm]", ylabel="y [mm]",
           title=f"normal preload per pair [N]: {on.sum()} of {on.size} pairs closed, "
                 f"{n0.sum():.0f} N")
    fig.colorbar(sc, ax=ax)
    ax.legend(loc="upper right", fontsize=7)
    return fig


if __name__ == "__main__":
    main()
