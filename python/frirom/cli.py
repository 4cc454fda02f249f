"""frirom: nonlinear forced response of frictionally damped structures.

    frirom run DECK [--out DIR] [--resume]    forced response of a deck (docs/deck.md)
    frirom run A.toml B.toml DIR/ ...         several decks (and every *.toml of DIR) in
                                              one go; --out is then their parent folder
    frirom demo [--out DIR]                   contact hysteresis loops and harmonics
    frirom show OUT --at 470Hz | --point K | --peak
                                              one point of a run: time histories,
                                              hysteresis loops, energy, interface maps
    frirom study DECK [--out DIR]             a family or convergence study ([study])
    frirom modes DECK [--out DIR]             natural frequencies, linear FRFs free/stuck

Exit codes of `frirom run` on several decks: 0 every run reached the end of its frequency
range; 2 a deck is wrong (the message names the field); 3 a run stopped before the end of
its range (its points are kept: see --resume); 4 the operating system refused a file
(disk full, read-only or missing folder, a file where a folder belongs: the message names
the path and what to do; committed points are kept); 130 interrupted (Ctrl-C stops the
batch at once); the code of the first deck that did not end with 0, after all of them
have run. `frirom study`: 0 every member complete, 1 a member stopped before the end of
its range, 5 a member failed (named in the summary; the others ran and are kept), 2 and 4
as above.
"""

from __future__ import annotations

import argparse
import errno
import math
import os
import re
import shutil
import sys
import time
import warnings
from pathlib import Path

from . import __version__
from ._errors import FriromError, InputError, with_hz
from ._resume import EXIT_INPUT, EXIT_INTERRUPTED, EXIT_OK, EXIT_STOPPED


_RUN_EPILOG = """\
One run at a time writes a results folder (a second one on the same --out is refused).
The same deck on the same build gives the same points bit for bit, and a run killed at any
moment then resumed gives the points the uninterrupted run would have.

exit codes:
  0    the run reached the end of its frequency range
  2    bad input, refused --resume, or the folder is in use: nothing computed
  3    the run stopped before the end of its range (continuation failure, max_points,
       the curve turned back); where and why are printed, the points are in OUT/frf.h5
  4    the operating system refused a file (disk full, read-only folder, a file where a
       folder belongs, a folder where a file belongs): the path and what to do are
       printed; every committed point is kept (continue with --resume)
  130  interrupted (Ctrl-C); the points are kept, continue with --resume
"""

#: Exit code of an operating-system error on a file (the message names the path).
EXIT_SYSTEM = 4
#: Exit code of `frirom study` when a member failed (the others ran).
EXIT_MEMBER_FAILED = 5


def _add_run(sub) -> None:
    p = sub.add_parser(
        "run", help="compute the forced response of a deck",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Compute the forced response (FRF) described by a TOML deck. Points are "
        "appended to OUT/frf.h5 as they converge (an interrupted run continues with "
        "--resume); at the end OUT/frf.csv, OUT/frf.png and OUT/states.png are written.",
        epilog=_RUN_EPILOG)
    p.add_argument("decks", type=Path, nargs="+", metavar="DECK",
                   help="the TOML deck (see docs/deck.md); several decks, or folders whose "
                   "*.toml decks all run, in one go")
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default: results/<deck name>); with several decks "
                   "the parent folder of one subfolder per deck (OUT/<deck name>)")
    p.add_argument("--resume", action="store_true",
                   help="continue the run stored in OUT/frf.h5 from its last checkpoint "
                   "(the same points as an uninterrupted run); refused if the deck or a file "
                   "it names changed, except frequency.end and continuation.max_points, "
                   "which may extend the run (each deck's own folder with several decks)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--allow-code", action="append", default=[], metavar="MODULE",
                   help="let the decks' contact laws 'MODULE:function' import MODULE (a "
                   "deck that names code runs code: never without this, or an installed "
                   "entry point in the group frirom.laws; docs/security.md)")
    p.set_defaults(func=cmd_run_decks)


def _add_demo(sub) -> None:
    demo = sub.add_parser("demo", help="hysteresis loops and harmonic content of contact "
                                       "elements, plotted to PNG")
    demo.add_argument("--out", type=Path, default=Path("results/demo"),
                      help="output folder (default: results/demo)")
    demo.set_defaults(func=_demo)


def _demo(args) -> int:
    from . import demo
    demo.run(args.out)
    return 0


def _add_show(sub) -> None:
    p = sub.add_parser(
        "show", help="one point of a run: outputs over a period, hysteresis loops, "
                     "dissipated energy, interface maps, VTK",
        description="Solve one point of a finished (or stopped) run again from what "
        "OUT/frf.h5 stores and write, in OUT/show_<f>Hz: time.csv/png (outputs over one "
        "period), hysteresis.csv/png (tangential force against relative displacement and "
        "normal force of the chosen or most dissipative contacts), contacts.csv and "
        "energy.png (per contact element: dissipated energy, stick/slip/lift-off fractions, "
        "peak normal force, slip amplitude); with an FE deck also maps.png (the fields on "
        "the contact face) and with --vtk point.vtu for ParaView.")
    p.add_argument("out", type=Path, help="the run's output folder (or its frf.h5, or "
                   "a nonlinear mode's backbone.h5)")
    which = p.add_mutually_exclusive_group()
    which.add_argument("--at", metavar="FREQ",
                       help="frequency, e.g. 470Hz, 2950rad/s, or a number in the deck's unit")
    which.add_argument("--point", type=int, metavar="K", help="stored point K (from 0; "
                       "negative from the end)")
    which.add_argument("--peak", action="store_true",
                       help="the peak of the first output (the default); of a backbone: "
                       "its point of largest damping ratio")
    which.add_argument("--amplitude", type=float, metavar="A", default=None,
                       help="a backbone (OUT/backbone.h5): the point nearest modal "
                       "amplitude A")
    p.add_argument("--contact", action="append", metavar="GROUP:E", default=None,
                   help="a contact element to draw (repeatable); default the most "
                   "dissipative ones")
    p.add_argument("--top", type=int, default=4, help="how many of the most dissipative "
                   "contacts to draw (default 4)")
    p.add_argument("--along", type=int, default=0, metavar="N",
                   help="also map the contact pairs along the curve at N points (FE decks)")
    p.add_argument("--vtk", action="store_true", help="write point.vtu (meshio) for "
                   "ParaView (FE decks)")
    p.add_argument("--frames", type=int, default=0, metavar="N",
                   help="with --vtk: also N frames over the period")
    p.add_argument("--phase", action="store_true",
                   help="also write OUT/frf_phase.png (amplitude and phase of h1)")
    p.add_argument("--deck", type=Path, default=None,
                   help="the deck (default: the one recorded in frf.h5)")
    p.add_argument("--dir", type=Path, default=None,
                   help="folder for the files (default OUT/show_<f>Hz)")
    p.set_defaults(func=cmd_show)


def cmd_show(args) -> int:
    out = Path(args.out)
    bb = (out if out.name == "backbone.h5" else
          out / "backbone.h5" if out.is_dir() and not (out / "frf.h5").exists() else None)
    if bb is not None and bb.is_file():
        from .show_backbone import cmd_show_backbone
        return cmd_show_backbone(args, bb)
    if out.is_dir() and (out / "frf.h5").is_file() and (out / "backbone.h5").is_file():
        from .results import FRF
        if FRF.load(out / "frf.h5").meta.get("method") == "snmt":
            raise InputError(f"{out / 'frf.h5'}: synthesised from the nonlinear mode (kind "
                             f"from_backbone), no solved point to show; show a point of "
                             f"its backbone: frirom show {out / 'backbone.h5'} "
                             "[--amplitude A | --point K]")
    if args.amplitude is not None:
        raise InputError(f"--amplitude: {out} holds no backbone.h5 (a nonlinear-mode run)")
    from .show import cmd_show as run
    return run(args)


def _add_study(sub) -> None:
    p = sub.add_parser(
        "study", help="run the [study] of a deck: a family of FRFs or a model-size ladder",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Run every member of the deck's [study] table (docs/deck.md) as a Dask "
        "task, into OUT/members/<name>/; finished members are kept, so running again "
        "continues an interrupted study. Writes OUT/study.h5 and the plots.",
        epilog="""\
A member that fails (an error in its deck or its solve, a lost worker) is recorded in
OUT/members/<name>/failed.json and named in the summary; the others run and are kept;
running the study again retries it. Connecting to a scheduler: docs/security.md.

exit codes:
  0    every member reached the end of its frequency range
  1    a member stopped before the end of its range (its points are kept)
  2    bad input (the message names the field), or the folder is in use
  4    the operating system refused a file (the message names the path)
  5    a member failed (named in the summary); the others ran
""")
    p.add_argument("deck", type=Path, help="a TOML deck with a [study] table")
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default: results/<deck name>)")
    p.add_argument("--scheduler", default=None,
                   help='"local" (a LocalCluster, the default), "serial", or a Dask '
                   "scheduler address (tcp://host:8786, tls://host:8786); overrides "
                   "FRIROM_SCHEDULER and study.scheduler. A scheduler can run any code in "
                   "this process: name only one you trust (docs/security.md)")
    p.add_argument("--trust-deck-scheduler", action="store_true",
                   help="connect to the scheduler address the deck's study.scheduler names "
                   "(refused without this flag, --scheduler or FRIROM_SCHEDULER)")
    p.add_argument("--tls-ca", default=None, metavar="FILE",
                   help="CA certificate of a tls:// scheduler (default: Dask's "
                   "configuration, distributed.comm.tls.ca-file)")
    p.add_argument("--tls-cert", default=None, metavar="FILE",
                   help="this client's certificate for a tls:// scheduler")
    p.add_argument("--tls-key", default=None, metavar="FILE",
                   help="this client's private key for a tls:// scheduler")
    p.add_argument("--workers", type=int, default=None,
                   help="LocalCluster workers, 1..1024 (default: study.workers, or one per "
                   "core)")
    p.add_argument("--force", action="store_true",
                   help="run a study of more than 10 000 members (frirom.study.MAX_MEMBERS)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_study)


def _study(args) -> int:
    from .mistuning_deck import is_mistuning_deck, run_mistuning_study
    from .study import run_study
    if is_mistuning_deck(args.deck):        # [mistuning] + [study] kind = "mistuning"
        run_mistuning_study(args.deck, args.out, scheduler=args.scheduler,
                            workers=args.workers, quiet=args.quiet,
                            trust_deck_scheduler=args.trust_deck_scheduler,
                            log=lambda s: print(f"frirom: {s}", flush=True))
        return 0
    tls = {"ca": args.tls_ca, "cert": args.tls_cert, "key": args.tls_key}
    res = run_study(args.deck, args.out, scheduler=args.scheduler, workers=args.workers,
                    quiet=args.quiet, log=lambda s: print(f"frirom: {s}"),
                    trust_deck_scheduler=args.trust_deck_scheduler, tls=tls,
                    force=args.force)
    if any(s.get("failed") for s in res["summaries"]):
        return EXIT_MEMBER_FAILED
    return 0 if all(s["complete"] for s in res["summaries"]) else 1


def _add_modes(sub) -> None:
    p = sub.add_parser(
        "modes", help="linear pre-check: natural frequencies and linear FRFs with the "
        "contacts free and stuck, a suggested frequency range",
        description="Natural frequencies of the deck's structure with the contacts free "
        "and fully stuck (the contact stiffnesses added) in and around [frequency], the "
        "linear free and stuck FRFs at the outputs (OUT/linear.png) and a suggested "
        "frequency range. Nothing nonlinear is solved.")
    p.add_argument("deck", type=Path, help="the TOML deck (see docs/deck.md)")
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default: results/<deck name>)")
    p.add_argument("--allow-code", action="append", default=[], metavar="MODULE",
                   help="let the deck's contact laws 'MODULE:function' import MODULE "
                   "(as frirom run --allow-code)")
    p.set_defaults(func=_modes)


def _modes(args) -> int:
    from types import SimpleNamespace

    import numpy as np

    from .deck import load_deck
    from .modes import linear_check
    from .plots import plot_frf
    allow = getattr(args, "allow_code", None)
    deck = load_deck(args.deck, allow_code=allow) if allow else load_deck(args.deck)
    for line in deck.log:
        print(f"frirom: {line}")
    check = linear_check(deck)
    for line in check.lines(deck):
        print(f"frirom: {line}")
    out = args.out if args.out is not None else Path("results") / deck.path.stem
    out.mkdir(parents=True, exist_ok=True)
    n = check.omega.size
    empty = SimpleNamespace(omega=check.omega[:0], amp_max=np.zeros((0, len(deck.outputs))))
    fig = plot_frf(empty, output_names=deck.output_names, unit=deck.frequency_unit,
                   title=f"{deck.title}: linear, contacts free and stuck", log=True,
                   linear=check.linear_curves())
    fig.savefig(out / "linear.png")
    print(f"frirom: wrote {out / 'linear.png'} ({n} frequencies)")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="frirom", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"frirom {__version__}")
    parser.add_argument("--debug", action="store_true",
                        help="show the traceback of an error (also FRIROM_DEBUG=1)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    _add_run(sub)
    _add_demo(sub)
    _add_show(sub)
    _add_study(sub)
    _add_modes(sub)
    return parser


class _Progress:
    """tqdm bar over the frequency range (the furthest frequency reached so far)."""

    def __init__(self, deck, quiet: bool):
        from tqdm import tqdm
        from .plots import frequency_axis
        self._axis = lambda w: float(frequency_axis(w, deck.frequency_unit)[0])
        self.f0 = self._axis(deck.omega_start)
        self.f1 = self._axis(deck.omega_end)
        unit = "Hz" if deck.frequency_unit == "hz" else "rad/s"
        self.bar = tqdm(total=round(abs(self.f1 - self.f0), 6), unit=unit, disable=quiet,
                        dynamic_ncols=True, file=sys.stderr, mininterval=0.2,
                        bar_format="{l_bar}{bar}| {n:.1f}/{total:.1f} " + unit +
                        " [{elapsed}<{remaining}{postfix}]", desc=deck.path.name)
        self.points = 0
        self.done = 0.0

    def update(self, point) -> None:
        self.points += 1
        f = self._axis(point.omega)
        reach = min(max((f - self.f0) / (self.f1 - self.f0), 0.0), 1.0) * self.bar.total
        if reach > self.done:
            self.bar.update(reach - self.done)
            self.done = reach
        self.bar.set_postfix_str(f"{self.points} pts, f={f:.2f}, "
                                 f"amp={float(point.amp_max[0]):.3g}", refresh=False)

    def close(self) -> None:
        self.bar.close()


def cmd_run(args) -> int:
    from ._resume import ResultsLock
    from .auto import resolve_deck
    from .deck import load_deck
    from .mistuning_deck import is_mistuning_deck, run_mistuning_deck

    if is_mistuning_deck(args.deck):        # [mistuning]: frirom.mistuning_deck
        run_mistuning_deck(args.deck, args.out, log=lambda s: print(f"frirom: {s}"))
        return 0
    allow = getattr(args, "allow_code", None)
    deck = load_deck(args.deck, allow_code=allow) if allow else load_deck(args.deck)
    for line in deck.log:
        print(f"frirom: {line}")
    analysis = getattr(deck.settings, "analysis", None)
    mode_deck = analysis is not None and analysis.nonlinear_mode
    linear = None if mode_deck else _linear_lines(deck)
    deck = resolve_deck(deck, lambda s: print(f"frirom: {s}"))
    out = args.out if args.out is not None else Path("results") / deck.path.stem
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: is a file; expected a folder for the results")
    out.mkdir(parents=True, exist_ok=True)
    lock = ResultsLock(out)     # before anything in out is opened or replaced
    try:
        if mode_deck:
            from .cli_modes import run_mode_deck
            return run_mode_deck(args, deck, out)
        if analysis is not None and getattr(analysis, "from_backbone", False):
            from .cli_modes import run_synthesis_deck
            return run_synthesis_deck(args, deck, out)
        return _run_locked(args, deck, out, linear)
    finally:
        lock.release()


def _run_locked(args, deck, out: Path, linear=None) -> int:
    """cmd_run once the results folder is locked."""
    from ._resume import deck_fingerprint
    from .plots import plot_frf, plot_states
    from .results import FRF, FRFWriter, store_bifurcations
    from .solver import frf

    h5 = out / "frf.h5"
    names = [c.name for c in deck.contacts]
    fingerprint = deck_fingerprint(deck)
    start, done = _resume_start(h5, deck, fingerprint) if args.resume else (None, False)
    if not done:
        shutil.copyfile(deck.path, out / "deck.toml")

    kept = getattr(deck.auto, "kept", None) if deck.auto is not None else None
    if kept is not None and kept.selection is not None and args.resume and \
            _stored_restored(h5):
        # the stored run had given the selection up: it goes on with every harmonic
        kept.restored = "(the stored run's: its leak had grown)"
        deck.kept_auto = None
    model, excitation, options = deck.model(), deck.excitation(), deck.options()
    print(f"frirom: {model.n_dof} coordinates, {len(model.nonlinear_dofs())} in contact, "
          f"{sum(g.n_elem for g in model.contacts)} contact elements, H = {deck.harmonics}")
    result = None
    if not done:
        writer = FRFWriter(h5, deck.outputs, names, deck.harmonics, append=args.resume,
                           attrs={"deck_fingerprint": fingerprint,
                                  "omega_range": [deck.omega_start, deck.omega_end],
                                  **({"auto": "\n".join(deck.auto.lines())} if deck.auto
                                     else {})},
                           output_labels=deck.output_names, meta=deck.result_meta())
        if writer.repaired:
            print(f"frirom: {h5}: removed a torn last record (a point whose writing was "
                  "cut short)", file=sys.stderr)
        if args.resume:
            n0 = start["n_points"] if start and "n_points" in start else 0
            print(f"frirom: resuming after point {n0} (the last checkpoint)"
                  + (f"; the {writer.dropped} points after it are computed again"
                     if writer.dropped else ""), file=sys.stderr)
        progress = _Progress(deck, args.quiet)

        def sink(point):
            writer.append(point)
            progress.update(point)

        t0 = time.perf_counter()
        # interface modes "auto": the chosen rung's curve when it is this run's (frirom.auto)
        reuse = None if args.resume else getattr(deck, "auto_response", None)
        try:
            if reuse is not None:
                result = reuse[0]
                for point in reuse[1]:
                    sink(point)
                print("frirom: auto: the chosen rung's curve covers the range with these "
                      "settings: written, not computed again")
            else:
                result = frf(model, excitation, deck.omega_start, deck.omega_end, options,
                             outputs=deck.solver_outputs, sink=sink, start=start)
        except KeyboardInterrupt:
            progress.close()
            writer.close(complete=False, message="interrupted")
            print(f"frirom: interrupted; {h5} keeps every converged point: continue with "
                  f"`frirom run {args.deck} --out {out} --resume`", file=sys.stderr)
            return EXIT_INTERRUPTED
        except BaseException as exc:
            progress.close()
            try:
                writer.close(complete=False, message=f"{type(exc).__name__}: {exc}")
            except OSError:
                pass            # the disk that failed the point may fail this too
            raise
        progress.close()
        writer.close(complete=result.complete, message=result.message)
        if kept is not None and reuse is None and _restore_kept(kept, result):
            # harmonics_kept = "auto": the selection leaked along the curve beyond what
            # the probes saw: the whole curve again with every harmonic, the file replaced
            print(f"frirom: auto: the harmonic selection's {kept.restored}: the curve is "
                  "run again with every harmonic", file=sys.stderr)
            deck.kept_auto = None
            options = deck.options()
            writer = FRFWriter(h5, deck.outputs, names, deck.harmonics, append=False,
                               attrs={"deck_fingerprint": fingerprint,
                                      "omega_range": [deck.omega_start, deck.omega_end],
                                      "auto": "\n".join(deck.auto.lines())},
                               output_labels=deck.output_names, meta=deck.result_meta())
            progress = _Progress(deck, args.quiet)
            result = frf(model, excitation, deck.omega_start, deck.omega_end, options,
                         outputs=deck.solver_outputs, sink=sink)
            progress.close()
            writer.close(complete=result.complete, message=result.message)
        elapsed = time.perf_counter() - t0
        if deck.auto is not None:
            result.solver_info += f"; {deck.auto.summary()}"
            if not result.complete:
                print(f"frirom: auto: the run with the chosen H = {deck.harmonics}, N = "
                      f"{options.n_samples} stopped early: the choice failed here (give "
                      "integers, or more samples)", file=sys.stderr)
        print(f"frirom: {result.solver_info}")
    else:
        elapsed = 0.0

    if result is not None and result.bifurcations is not None:
        # located on the whole curve (a resumed run's points before it too)
        store_bifurcations(h5, result.bifurcations)
    full = FRF.load(h5)
    if deck.csv:
        full.save_csv(out / "frf.csv")
    written = [h5] + ([out / "frf.csv"] if deck.csv else [])
    if deck.csv and full.bifurcations:
        full.save_bifurcations_csv(out / "bifurcations.csv")
        written.append(out / "bifurcations.csv")
    if deck.plot and len(full) > 0:
        figures = {"frf.png": plot_frf(full, output_names=deck.output_names,
                                       unit=deck.frequency_unit, title=deck.title + (
                                           f"\n{deck.auto.title()}" if deck.auto else ""),
                                       linear=linear)}
        if deck.contacts:
            figures["states.png"] = plot_states(full, contact_names=names,
                                                unit=deck.frequency_unit,
                                                title=f"{deck.title}: contact states")
        for name, fig in figures.items():
            fig.savefig(out / name)
            written.append(out / name)
    print(f"frirom: {len(full)} points in {elapsed:.1f} s; wrote "
          + ", ".join(str(p) for p in written))
    for b in full.bifurcations or []:
        fb = b.omega / (2 * math.pi) if deck.frequency_unit == "hz" else b.omega
        unit = "Hz" if deck.frequency_unit == "hz" else "rad/s"
        print(f"frirom: {b.kind} at {fb:.8g} {unit} ("
              + ("located on the curve " if b.located else "")
              + f"between points {b.index - 1} and {b.index})")
    fl = getattr(deck.settings, "fold_locus", None)
    if fl is not None:
        _fold_locus(deck, fl, model, excitation, options, out)
    # a resumed run solved its peaks on the whole curve (the file's points before it too)
    if (args.resume and result is not None and result.peaks is not None and start
            and start.get("before")):
        full.peaks = result.peaks
    _print_peaks(full if args.resume else result, deck)
    if not full.complete:
        _print_stop(full, deck, h5)
        return EXIT_STOPPED
    return EXIT_OK


def _fold_locus(deck, fl, model, excitation, options, out: Path) -> None:
    """[fold_locus]: the folds at each level (frirom.bifurcations), OUT/fold_locus.csv."""
    import csv

    from .bifurcations import fold_locus
    loc = fold_locus(model, excitation, deck.omega_start, deck.omega_end, fl.levels,
                     options, outputs=deck.solver_outputs, part=fl.part)
    path = out / "fold_locus.csv"
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["level", "fold", "f_hz", "omega_rad_s", "located", "complete"]
                   + [f"{n}_max" for n in deck.output_names])
        for i, lv in enumerate(loc.levels):
            for j in range(int(loc.n_folds[i])):
                w.writerow([repr(float(lv)), j, repr(float(loc.omega[i, j] / (2 * math.pi))),
                            repr(float(loc.omega[i, j])), int(loc.located[i, j]),
                            int(loc.complete[i])]
                           + [repr(float(a)) for a in loc.amp_max[i, j]])
    print(f"frirom: fold locus ({fl.part} part) at {loc.levels.size} levels, folds per "
          f"level {loc.n_folds.tolist()}; wrote {path}")


def _restore_kept(kept, result) -> bool:
    from .auto_kept import restore
    return restore(kept, result)


def _stored_restored(h5: Path) -> bool:
    """Whether a stored run gave its automatic harmonic selection up (frirom.auto_kept
    restore): its 'auto' lines say so."""
    import h5py
    try:
        with h5py.File(h5, "r") as f:
            text = f.attrs.get("auto", "")
    except (OSError, KeyError):
        return False
    text = text.decode() if isinstance(text, bytes) else str(text)
    return "RESTORED every harmonic" in text


def _resume_start(h5: Path, deck, fingerprint: str):
    """(start, done) of ``frirom run --resume``: the checkpoint to continue from (None:
    from the beginning), done when the stored run is complete and the deck does not
    extend it. Refuses (InputError) a changed deck, listing the changes, a range that is
    not extended, and a file that cannot be read."""
    import h5py
    import numpy as np

    from ._resume import EXTENDABLE, deck_changes
    from .results import FRF, FRFWriter
    if not h5.is_file():
        raise InputError(f"{h5}: nothing to resume (run without --resume first)")
    try:
        h5py.File(h5, "r").close()
    except OSError as exc:
        raise InputError(f"{h5}: cannot be read as HDF5 ({exc}); it cannot be resumed: run "
                         "without --resume (the folder's results are replaced)") from None
    previous = FRF.load(h5)         # refuses a damaged, edited or inconsistent file
    with h5py.File(h5, "r") as f:
        old = f.attrs.get("deck_fingerprint")
        rng = f.attrs.get("omega_range")
    redo = "run without --resume (the results in that folder are replaced) or choose " \
           "another --out"
    if old is None:
        print(f"frirom: {h5} was written before frirom kept the deck's fingerprint: "
              "not checked against the deck", file=sys.stderr)
    else:
        changes = deck_changes(str(old), fingerprint)
        if changes:
            raise InputError(f"{h5}: the deck changed since these results were made (only "
                             f"{' and '.join(EXTENDABLE)} may change on --resume):\n  "
                             + "\n  ".join(changes) + f"\n{redo}")
    extended = rng is not None and float(rng[1]) != deck.omega_end
    if extended and (deck.omega_end - rng[1]) * np.sign(rng[1] - rng[0]) < 0:
        raise InputError(f"{deck.path}: frequency.end: --resume may extend the range, not "
                         f"shorten it ({rng[1]:.6g} rad/s then, {deck.omega_end:.6g} now); "
                         + redo)
    if previous.complete and not extended:
        print(f"frirom: {h5} is already complete ({len(previous)} points); rewriting the "
              "CSV and plots", file=sys.stderr)
        return None, True
    try:
        start = FRFWriter.resume_point(h5)
    except InputError as exc:
        print(f"frirom: {exc}: starting from the beginning", file=sys.stderr)
        return None, False
    if rng is not None:
        start["lscale"] = abs(float(rng[1]) - float(rng[0]))
    return start, False


def _print_stop(full, deck, h5) -> None:
    """Where and why a run stopped before the end of its range."""
    from .plots import frequency_axis
    where = ""
    if len(full):
        f, label = frequency_axis(full.omega[-1], deck.frequency_unit)
        where = f" at {float(f):.6g} {label[label.index('[') + 1:-1]} after {len(full)} points"
    if "max_points" in full.message:
        hint = "raise continuation.max_points and continue with --resume"
    elif full.message == "interrupted" or full.message.startswith("running"):
        hint = "continue with --resume"
    else:
        hint = ("the same deck resumed stops at the same place: change the deck and run "
                "without --resume")
    print(f"frirom: the run stopped before the end of its range{where}: "
          f"{with_hz(full.message)}; "
          f"the points are in {h5}; {hint} (exit code 3)", file=sys.stderr)


def _deck_files(paths) -> list[Path]:
    """The decks named on the command line: files as given, folders as their *.toml files
    (sorted by name). Raises InputError for a missing path, an empty folder, a deck named
    twice or two decks with the same name (their results would share a folder)."""
    decks = []
    for p in paths:
        if p.is_dir():
            found = sorted(p.glob("*.toml"))
            if not found:
                raise InputError(f"{p}: a folder with no *.toml deck in it")
            decks += found
        elif p.is_file():
            decks.append(p)
        else:
            raise InputError(f"{p}: no such deck file or folder")
    seen = {}
    for d in decks:
        if d.stem in seen:
            same = "is named twice" if d.resolve() == seen[d.stem].resolve() else \
                f"and {seen[d.stem]} have the same name: their results would share a folder"
            raise InputError(f"{d} {same}")
        seen[d.stem] = d
    return decks


def _run_one(args, deck: Path, out: Path | None) -> int:
    """cmd_run on one deck of a batch: its exit code (EXIT_INPUT for a deck it could not
    read)."""
    one = argparse.Namespace(**{**vars(args), "deck": deck, "out": out})
    try:
        code = cmd_run(one)
    except FriromError as exc:
        print(f"frirom: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except OSError as exc:
        print(f"frirom: error: {system_error(exc)}", file=sys.stderr)
        return EXIT_SYSTEM
    return code


def cmd_run_decks(args) -> int:
    """`frirom run` on one deck (cmd_run) or on several in one go: each with the same
    resume rules, in its own folder (OUT/<deck name>, or results/<deck name>); a summary
    line per deck; the exit code of the first deck that did not end with 0 (module doc)."""
    decks = _deck_files(args.decks)
    if len(decks) == 1 and not args.decks[0].is_dir():
        args.deck = decks[0]
        return cmd_run(args)
    codes = []
    for i, deck in enumerate(decks):
        out = args.out / deck.stem if args.out is not None else None
        print(f"frirom: [{i + 1}/{len(decks)}] {deck}")
        codes.append(_run_one(args, deck, out))
        if codes[-1] == EXIT_INTERRUPTED:
            print(f"frirom: interrupted; {len(decks) - i - 1} decks not run", file=sys.stderr)
            break
    what = {0: "complete", EXIT_INPUT: "error in the deck", EXIT_STOPPED:
            "stopped before the end of its range", EXIT_INTERRUPTED: "interrupted",
            EXIT_SYSTEM: "a file could not be written or read (see above)"}
    for deck, code in zip(decks, codes):
        print(f"frirom: {deck}: {what.get(code, f'exit code {code}')}")
    bad = [c for c in codes if c != 0]
    print(f"frirom: {codes.count(0)} of {len(decks)} runs complete")
    return bad[0] if bad else 0


def _linear_lines(deck):
    """Print the linear pre-check (frirom.modes); its free/stuck curves for the FRF plot
    (None if it could not be made: the run goes on)."""
    from .modes import linear_check
    try:
        check = linear_check(deck)
    except (FriromError, ValueError, RuntimeError, ArithmeticError) as exc:
        # a failed pre-check (a singular free structure, an eigen-solve) never stops a run
        print(f"frirom: linear pre-check skipped ({type(exc).__name__}: {exc})")
        return None
    for line in check.lines(deck):
        print(f"frirom: {line}")
    return check.linear_curves()


def _print_peaks(result, deck) -> None:
    """One line per output: its largest amplitude over the run (FRF.peak)."""
    from .plots import frequency_axis
    if len(result) == 0:
        return
    names = deck.output_names or [f"output {j}" for j in range(result.amp_max.shape[1])]
    for j, name in enumerate(names):
        p = result.peak(j)
        f, label = frequency_axis(p.omega, deck.frequency_unit)
        unit = label[label.index("[") + 1:-1]
        print(f"frirom: peak of {name}: {p.amplitude:.6g} at {float(f):.6g} {unit} "
              f"({p.method})")




def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Python warnings as frirom messages: one line ``frirom: warning: ...`` with the
    frequencies also in Hz; a RuntimeWarning that is not frirom's own (numpy or scipy
    arithmetic: overflow, invalid value) says so and names where it arose, without the
    source line."""
    text = " ".join(str(message).split())
    if text.startswith("frirom: "):             # frirom's own warnings say what they are
        text = text[len("frirom: "):]
    elif issubclass(category, RuntimeWarning):  # numpy / scipy arithmetic
        text = (f"numerical: {text} (at {Path(filename).name}:{lineno}; --debug shows it "
                "as Python does)")
    print(f"frirom: warning: {with_hz(text)}", file=sys.stderr if file is None else file)


#: What to do about an operating-system error, by errno.
_OS_HINTS = {
    errno.ENOSPC: "no space left on the device: free some, then continue with --resume "
                  "(every committed point is kept)",
    errno.EDQUOT: "disk quota exceeded: free some space, then continue with --resume "
                  "(every committed point is kept)",
    errno.EROFS: "the file system is read-only: choose another --out",
    errno.EACCES: "permission denied: choose another --out or change its permissions",
    errno.EPERM: "permission denied: choose another --out or change its permissions",
    errno.ENOTDIR: "a part of the path is a file, not a folder: choose another --out",
    errno.EISDIR: "a folder is where frirom writes a file: remove or rename it, or choose "
                  "another --out",
    errno.EEXIST: "a file is where frirom makes a folder: choose another --out",
    errno.ENOENT: "no such file or folder",
    errno.ENAMETOOLONG: "the path is too long: choose a shorter --out",
}


def system_error(exc: OSError) -> str:
    """One line for an operating-system error: the path, what happened and what to do.
    h5py's errors carry errno and the file name in their text, read from there."""
    import re
    text = str(exc)
    code = exc.errno
    if code is None:
        m = re.search(r"errno = (\d+)", text)
        code = int(m.group(1)) if m else None
    path = exc.filename
    if path is None:
        m = re.search(r"name = '([^']*)'", text)
        path = m.group(1) if m else None
    what = _OS_HINTS.get(code, exc.strerror or " ".join(text.split()))
    where = f"{os.fspath(path)}: " if path is not None else ""
    return f"{where}{what} ({type(exc).__name__}" + (f", errno {code}" if code else "") + ")"


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 0
    debug = getattr(args, "debug", False) or os.environ.get("FRIROM_DEBUG", "") not in ("",
                                                                                       "0")
    try:
        out = getattr(args, "out", None)
        if out is not None and out.exists() and not out.is_dir():
            raise InputError(f"--out {out}: expected a folder, got an existing file")
        with warnings.catch_warnings():
            if not debug:
                warnings.showwarning = _show_warning
            return args.func(args)
    except FriromError as exc:
        if debug:
            raise
        print(f"frirom: error: {with_hz(' '.join(str(exc).split()))}", file=sys.stderr)
        return 2
    except OSError as exc:
        if debug:
            raise
        print(f"frirom: error: {system_error(exc)}", file=sys.stderr)
        return EXIT_SYSTEM
    except Exception as exc:            # a bug or an unforeseen input: one line, no traceback
        if debug:
            raise
        print(f"frirom: error: {type(exc).__name__}: {' '.join(str(exc).split())} (this is "
              "a frirom bug or an input it does not check: rerun with FRIROM_DEBUG=1 or "
              "--debug for the traceback)", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
