"""``frirom run`` on a nonlinear-mode deck (``[analysis] kind = "nonlinear_mode"``): the
backbone by frirom.nonlinear_mode into OUT/backbone.h5 (kept up to date after every
segment, resumable with --resume), OUT/backbone.csv and OUT/backbone.png."""

from __future__ import annotations

import shutil
import sys
import time
from pathlib import Path

import numpy as np

from ._errors import InputError
from ._resume import EXIT_INTERRUPTED, EXIT_OK, EXIT_STOPPED


def run_mode_deck(args, deck, out: Path) -> int:
    """The backbone of the deck's [analysis]; exit code as `frirom run`."""
    from ._resume import deck_changes, deck_fingerprint
    from .backbone import load_h5, plot_backbone, save_csv, save_h5
    from .nonlinear_modes import nonlinear_mode

    an = deck.settings.analysis
    h5 = out / "backbone.h5"
    fingerprint = deck_fingerprint(deck)
    before, resume = None, None
    if args.resume:
        if not h5.exists():
            raise InputError(f"{h5}: nothing to resume (run without --resume first)")
        before, attrs = load_h5(h5)
        changes = deck_changes(str(attrs.get("deck_fingerprint", "{}")), fingerprint,
                               allowed=("continuation.max_points",))
        if changes:
            raise InputError(f"{deck.path}: changed since {h5} was written (only "
                             "continuation.max_points may change on --resume):\n  "
                             + "\n  ".join(changes) + "\nrun without --resume (the "
                             "folder's results are replaced)")
        resume = before.checkpoint()
        if before.status != "going" and before.status != "max_points":
            resume = None           # finished: only the files are written again
        elif resume is None:
            before = None           # no segment ended yet: start again
        else:
            before = before.head(resume["n_points"])
            print(f"frirom: resuming after point {resume['n_points']} (the last "
                  "checkpoint)", file=sys.stderr)
    else:
        shutil.copyfile(deck.path, out / "deck.toml")
    model, options = deck.model(), deck.options()
    static = deck.F[:, 0].real if np.any(deck.F[:, 0]) else None
    print(f"frirom: nonlinear mode {an.mode} ({an.start} start) of {model.n_dof} "
          f"coordinates, {sum(g.n_elem for g in model.contacts)} contact elements, H = "
          f"{deck.harmonics}, modal amplitude {an.amplitudes[0]:g} .. {an.amplitudes[1]:g}")
    attrs = {"deck_fingerprint": fingerprint, "deck_path": str(deck.path.resolve())}

    def keep(bb):
        save_h5(bb if before is None else before.extended(bb), h5, attrs)

    t0 = time.perf_counter()
    done = before is not None and resume is None
    if not done:
        try:
            bb = nonlinear_mode(model, an.mode - 1, an.amplitudes, an.start, options,
                                outputs=deck.solver_outputs, static=static, callback=keep,
                                resume=resume)
        except KeyboardInterrupt:
            print(f"frirom: interrupted; {h5} keeps every finished segment: continue with "
                  f"`frirom run {args.deck} --out {out} --resume`", file=sys.stderr)
            return EXIT_INTERRUPTED
        full = bb if before is None else before.extended(bb)
        save_h5(full, h5, attrs)
    else:
        full = before
    elapsed = time.perf_counter() - t0
    names = deck.output_names
    written = [h5]
    if deck.csv:
        save_csv(full, out / "backbone.csv", names)
        written.append(out / "backbone.csv")
    if deck.plot and len(full):
        plot_backbone(full, 0, names[0] if names else None,
                      title=f"{deck.title}: nonlinear mode {an.mode} ({an.start} start)"
                      ).savefig(out / "backbone.png")
        written.append(out / "backbone.png")
    print(f"frirom: {len(full)} points in {elapsed:.1f} s; wrote "
          + ", ".join(str(p) for p in written))
    if len(full):
        for i in sorted({0, len(full) // 2, len(full) - 1}):
            print(f"frirom: a = {full.amplitude[i]:.4g}: {full.frequency[i]:.6g} Hz, "
                  f"damping ratio {full.damping_ratio[i]:.4g}, energy per cycle "
                  f"{full.energy[i]:.4g} J")
    if full.status != "done":
        print(f"frirom: the backbone stopped early ({full.status}): {full.message}",
              file=sys.stderr)
        return EXIT_STOPPED
    return EXIT_OK
