"""The BRB backbone on GSI interface bases with and without the contact-driven enrichment
(docs/cases/brb.md, "A contact-driven interface basis").

    python cases/brb/contact_driven_study.py [--harmonics 3 1] [--variants gsi60 ...]
                                             [--amplitudes 5e-8 1.5e-4] [--rebuild]

A variant is ``gsiN`` (GSI N free + N stick modes, brb_mode.toml's basis with N = 60) or
``gsiN+cdK`` (the same enriched by the unit tangential forces of the first K elements by
slip onset; ``cdall``: every element whose slip onset estimated from the stuck mode lies
within the backbone's amplitude range; a trailing ``n``, ``gsi20+cd40n``: the unit normal
forces too, and the elements ordered by the earlier of slip and lift-off).
Per variant and H: coordinates, the reduction's seconds (built here, or as recorded when
it was cached; --rebuild builds every one again), the backbone from stuck to the end of
microslip (points, seconds wall and CPU, N = the deck's 256 samples), and frequency and
damping ratio at 0.1, 7 and 65 m/s^2 (points landed on them:
run_brb.exact_at_accelerations). Writes results/brb_cd/study.csv.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

VARIANTS = ("gsi60", "gsi20+cd20", "gsi20+cd40", "gsi20+cdall")
ACC = (0.1, 7.0, 65.0)
STUCK_HZ = 168.49            # CalculiX's stuck first bending mode (calibrated)


def variant_deck(name: str, amplitude: float) -> str:
    """brb_cd_mode.toml's text with the interface basis of variant ``name``."""
    m = re.fullmatch(r"gsi(\d+)(?:\+cd(\d+|all)(n?))?", name)
    if m is None:
        raise SystemExit(f"--variants: {name!r} is not gsiN or gsiN+cdK / gsiN+cdall")
    text = (HERE / "brb_cd_mode.toml").read_text()
    n = int(m.group(1))
    text = re.sub(r"(?m)^free = \d+", f"free = {n}", text)
    text = re.sub(r"(?m)^stick = \d+", f"stick = {n}", text)
    cd = m.group(2)
    table = re.compile(r"(?ms)^\[reduction\.interface_modes\.contact_driven\].*?(?=^\[)")
    if cd is None:
        return table.sub("", text)
    rows = (f"elements = {int(cd)}\n" if cd != "all" else f"amplitude = {amplitude:g}\n")
    rows += "normal = true\n" if m.group(3) else ""
    return table.sub("[reduction.interface_modes.contact_driven]\nfrequency = 168.5\n"
                     + rows + "\n", text)


def run(name: str, H: int, amplitudes, rebuild: bool) -> dict:
    import run_brb
    from frirom.deck import load_deck
    from frirom.nonlinear_modes import linear_mode, nonlinear_mode
    path = HERE / f"_cd_{name.replace('+', '_')}.toml"
    path.write_text(variant_deck(name, amplitudes[1]))
    try:
        if rebuild:
            from frirom.deck.build import rom_file
            f = rom_file(load_deck(path).settings)
            if f is not None and f.exists():
                f.unlink()
        deck = load_deck(path)
        deck.model()
        red = deck.reduced
        _, model, options, static = run_brb.inputs(deck, harmonics=H)
        # the string modes count as zero or not depending on the basis (linear_mode's
        # threshold is relative to the largest eigenvalue): take the one at 168.5 Hz
        k = min(range(12), key=lambda j: abs(linear_mode(model, j)[1] / (2 * np.pi)
                                             - STUCK_HZ))
        t0, c0 = time.perf_counter(), time.process_time()
        bb = nonlinear_mode(model, k, tuple(amplitudes), "stuck", options,
                            outputs=deck.solver_outputs, static=static)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        at = run_brb.exact_at_accelerations(bb, deck, harmonics=H, acc=ACC)
    finally:
        path.unlink()
    n_cd = sum(lb.startswith("contact-driven") for lb in red.labels)
    return {"variant": name, "H": H, "coordinates": red.K.shape[0], "cd_vectors": n_cd,
            "reduction_s": red.build_seconds, "points": len(bb), "backbone_s": wall,
            "backbone_cpu_s": cpu, "f0": bb.frequency[0],
            **{f"f{a:g}": at[k, 0] for k, a in enumerate(ACC)},
            **{f"zeta{a:g}": at[k, 1] for k, a in enumerate(ACC)}, "status": bb.status}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--harmonics", type=int, nargs="*", default=[3])
    ap.add_argument("--variants", nargs="*", default=list(VARIANTS))
    ap.add_argument("--amplitudes", type=float, nargs=2, default=[5.0e-8, 1.5e-4])
    ap.add_argument("--rebuild", action="store_true")
    ap.add_argument("--out", type=Path, default=ROOT / "results" / "brb_cd")
    a = ap.parse_args(argv)
    import run_brb
    run_brb.ensure_built()
    a.out.mkdir(parents=True, exist_ok=True)
    rows = []
    print(f"{'variant':>12s} {'H':>2s} {'coord':>5s} {'cd':>4s} {'red s':>6s} {'pts':>4s} "
          f"{'bb s':>6s} {'cpu s':>6s} {'f0 Hz':>8s} | "
          + " | ".join(f"f, zeta at {x:g}" for x in ACC))
    for H in a.harmonics:
        for name in a.variants:
            r = run(name, H, a.amplitudes, a.rebuild)
            rows.append(r)
            print(f"{name:>12s} {H:>2d} {r['coordinates']:>5d} {r['cd_vectors']:>4d} "
                  f"{r['reduction_s']:>6.1f} {r['points']:>4d} {r['backbone_s']:>6.1f} "
                  f"{r['backbone_cpu_s']:>6.1f} {r['f0']:>8.3f} | " + " | ".join(
                      f"{r[f'f{x:g}']:.3f} Hz {100 * r[f'zeta{x:g}']:.3f} %" for x in ACC)
                  + ("" if r["status"] == "done" else f" ({r['status']})"), flush=True)
    keys = list(rows[0])
    with open(a.out / "study.csv", "w") as fh:
        fh.write(",".join(keys) + "\n")
        for r in rows:
            fh.write(",".join(str(r[k]) for k in keys) + "\n")
    print("published (Porter & Brake 2023): " + ", ".join(
        f"{x:g} m/s^2 {f:.2f} Hz {100 * z:.3f} %" for x, f, z in run_brb.PUBLISHED))
    print(f"contact_driven_study: wrote {a.out / 'study.csv'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
