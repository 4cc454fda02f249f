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


def synthesise_deck(deck, callback=None):
    """The backbone of a ``kind = "from_backbone"`` deck's [analysis] and the forced
    response over its [frequency] under its harmonic-1 loads synthesised from it
    (frirom.nlm_synthesis): (Backbone, FRF, backbone seconds, synthesis seconds)."""
    from . import nlm_synthesis  # noqa: F401  (its imports out of the timing)
    from .model import Excitation
    from .nonlinear_modes import nonlinear_mode
    an = deck.settings.analysis
    model, options = deck.model(), deck.options()
    F = np.asarray(deck.F)
    static = F[:, 0].real if np.any(F[:, 0]) else None
    t0 = time.perf_counter()
    bb = nonlinear_mode(model, an.mode - 1, an.amplitudes, an.start, options,
                        outputs=deck.solver_outputs, static=static, callback=callback)
    t1 = time.perf_counter()
    load = np.zeros((F.shape[0], 2), complex)
    load[:, 1] = F[:, 1]
    if F.shape[1] > 2 and np.any(F[:, 2:]):
        raise InputError(f"{deck.path}: excitation: a from_backbone deck takes harmonic-1 "
                         "loads only (the synthesis is single-harmonic in the load)")
    frf = bb.forced_response(Excitation(load), (deck.omega_start, deck.omega_end))
    t2 = time.perf_counter()
    frf.output_labels = list(deck.output_names)
    frf.group_names = ["contacts (mean)"] if frf.state_fractions.shape[1] else []
    frf.meta = dict(deck.result_meta(), method="snmt")
    return bb, frf, t1 - t0, t2 - t1


def run_synthesis_deck(args, deck, out: Path) -> int:
    """``[analysis] kind = "from_backbone"``: OUT/backbone.h5 (.csv, .png) and the
    synthesised OUT/frf.h5, frf.csv, frf.png; exit code as `frirom run`."""
    from .backbone import plot_backbone, save_csv, save_h5
    from .plots import plot_frf
    from ._resume import deck_fingerprint
    if args.resume:
        raise InputError("--resume: a from_backbone run is not resumable (its backbone "
                         "takes seconds: run it again)")
    shutil.copyfile(deck.path, out / "deck.toml")
    an = deck.settings.analysis
    print(f"frirom: forced response synthesised from nonlinear mode {an.mode} ({an.start} "
          f"start), modal amplitude {an.amplitudes[0]:g} .. {an.amplitudes[1]:g}")
    bb, frf, tb, ts = synthesise_deck(deck)
    attrs = {"deck_fingerprint": deck_fingerprint(deck),
             "deck_path": str(deck.path.resolve())}
    save_h5(bb, out / "backbone.h5", attrs)
    frf.save_h5(out / "frf.h5")
    names = deck.output_names
    written = [out / "backbone.h5", out / "frf.h5"]
    if deck.csv:
        save_csv(bb, out / "backbone.csv", names)
        frf.save_csv(out / "frf.csv")
        written += [out / "backbone.csv", out / "frf.csv"]
    if deck.plot and len(frf):
        plot_backbone(bb, 0, names[0] if names else None,
                      title=f"{deck.title}: nonlinear mode {an.mode}").savefig(
                          out / "backbone.png")
        plot_frf(frf, output_names=names, unit=deck.frequency_unit,
                 title=deck.title).savefig(
                     out / "frf.png")
        written += [out / "backbone.png", out / "frf.png"]
    print(f"frirom: backbone of {len(bb)} points in {tb:.2f} s, forced response of "
          f"{len(frf)} points synthesised in {1e3 * ts:.1f} ms; wrote "
          + ", ".join(str(p) for p in written))
    for j, name in enumerate(names):
        p = frf.peak(j)
        f = p.omega / (2 * np.pi) if deck.frequency_unit == "hz" else p.omega
        unit = "Hz" if deck.frequency_unit == "hz" else "rad/s"
        print(f"frirom: peak of {name}: {p.amplitude:.6g} at {f:.6g} {unit}")
    if bb.status != "done" or not frf.complete:
        print(f"frirom: incomplete: backbone {bb.status} ({bb.message}); "
              f"{frf.message}", file=sys.stderr)
        return EXIT_STOPPED
    return EXIT_OK
