"""Why the BRB model's damping at 7 m/s^2 is below the published one: the backbone up to
~10 m/s^2 with one ingredient changed at a time (docs/cases/brb.md, "The damping at
7 m/s^2").

    python cases/brb/damping_study.py [--harmonics 3] [--variants base kt13 ktflat ...]

Variants (each on brb_mode.toml's reduced model, GSI 60 + 60, mu = 0.03):
  base     the deck: kt = 0.82 kn, kn = n0 / 3e-8 m (stiffness proportional to the load)
  kt13     kt proportional to n0^(1/3) (a Hertzian contact's Mindlin stiffness), scaled so
           that the stuck first bending mode stays at the base's frequency: the lightly
           loaded rim stiffer against its slip limit, the clamped middle softer
  ktflat   kt the same for every pair (independent of the load), scaled alike
  kt2      kt halved everywhere (kn kept): softer tangential contact
  kn10     kn ten times smaller (kt kept): larger normal-load variation per unit opening
  gsiN     the interface basis GSI N free + N stick modes instead of 60 + 60 (e.g. gsi30,
           gsi100; a reduction of its own, cached like the deck's)
Prints, per variant, the stuck frequency, and the frequency and damping ratio at the
published 0.1 and 7 m/s^2 (points landed on them: run_brb.exact_at_accelerations).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

#: modal amplitude range: stuck to just past 7 m/s^2 (tip acceleration ~11 m/s^2)
AMPLITUDES = (5.0e-8, 1.0e-5)
VARIANTS = ("base", "kt13", "ktflat", "kt2", "kn10")


def stuck_hz(model, mode: int) -> float:
    from frirom.nonlinear_modes import linear_mode
    return linear_mode(model, mode, "stuck")[1] / (2 * np.pi)


def calibrate(model, mode: int, target: float) -> float:
    """Scale every kt so that the stuck mode is at target Hz (bisection in log scale over
    1e-3 .. 1: the variants stiffen the stuck mode); the scale."""
    kt0 = [g.params[:, 0].copy() for g in model.contacts]

    def err(c):
        for g, k in zip(model.contacts, kt0):
            g.params[:, 0] = c * k
        return stuck_hz(model, mode) - target
    lo, hi = -3.0, 0.0
    if err(10 ** lo) > 0 or err(10 ** hi) < 0:
        raise RuntimeError("damping_study: no kt scale in 1e-3 .. 1 puts the stuck mode "
                           f"at {target:.3f} Hz")
    while hi - lo > 1e-7:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if err(10 ** mid) < 0 else (lo, mid)
    err(10 ** hi)
    return 10 ** hi


def vary(model, name: str):
    """The model with the contact parameters of variant `name` (its groups' parameter
    arrays replaced, the deck's left as they are)."""
    groups = model.contacts
    for g in groups:
        g.params = np.array(g.params, float)
    if name == "base":
        return model
    n = np.array([g.n_elem for g in groups], float)
    kt = np.array([g.params[0, 0] for g in groups])
    n0 = np.array([g.params[0, 3] for g in groups])
    total = np.sum(n * kt)
    if name == "kt13":
        new = n0 ** (1 / 3)
        new *= total / np.sum(n * new)
    elif name == "ktflat":
        new = np.full_like(kt, total / n.sum())
    elif name == "kt2":
        new = 0.5 * kt
    elif name == "kn10":
        for g in groups:
            g.params[:, 1] *= 0.1
        return model
    else:
        raise ValueError(f"--variants: unknown variant {name!r} (one of {VARIANTS})")
    for g, k in zip(groups, new):
        g.params[:, 0] = k
    return model


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--harmonics", type=int, default=3, help="H (the deck's 3)")
    ap.add_argument("--variants", nargs="*", default=list(VARIANTS))
    a = ap.parse_args(argv)
    import run_brb
    from frirom.deck import load_deck
    from frirom.nonlinear_modes import nonlinear_mode
    run_brb.ensure_built()
    deck = load_deck(HERE / "brb_mode.toml")
    an = deck.settings.analysis
    opts = dataclasses.replace(deck.options(), harmonics=a.harmonics, batch=1)
    print(f"{'variant':>8s}  {'kt scale':>8s}  {'stuck Hz':>9s}  {'f(0.1) Hz':>9s}  "
          f"{'f(7) Hz':>9s}  {'zeta(0.1) %':>11s}  {'zeta(7) %':>9s}  {'points':>6s}  "
          f"{'s':>5s}")
    mode = an.mode - 1
    target = stuck_hz(deck.model(), mode)
    for name in a.variants:
        d = deck
        if name.startswith("gsi"):
            n = int(name[3:])
            text = (HERE / "brb_mode.toml").read_text()
            tmp = HERE / f"_study_{name}.toml"
            tmp.write_text(text.replace("free = 60", f"free = {n}")
                           .replace("stick = 60", f"stick = {n}"))
            try:
                d = load_deck(tmp)
                model = d.model()
            finally:
                tmp.unlink()
        else:
            model = vary(deck.model(), name)
        scale = calibrate(model, mode, target) if name in ("kt13", "ktflat") else 1.0
        k = mode
        if name.startswith("gsi"):          # the string modes count differently: the
            k = min(range(12), key=lambda j: abs(stuck_hz(model, j) - target))   # nearest
        t0 = time.perf_counter()
        bb = nonlinear_mode(model, k, AMPLITUDES, an.start, opts,
                            outputs=d.solver_outputs, static=d.F[:, 0].real)
        sec = time.perf_counter() - t0
        (f1, z1), (f7, z7) = run_brb.exact_at_accelerations(
            bb, d, harmonics=a.harmonics, acc=(0.1, 7.0), model=model)
        print(f"{name:>8s}  {scale:>8.4f}  {bb.frequency[0]:>9.3f}  {f1:>9.3f}  {f7:>9.3f}  "
              f"{100 * z1:>11.4f}  {100 * z7:>9.4f}  {len(bb):>6d}  {sec:>5.1f}")
    print("published (Porter & Brake 2023): 168.50 Hz, 167.5 Hz; 0.087 %, 0.43 %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
