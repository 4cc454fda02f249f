"""frirom: nonlinear forced response of frictionally damped structures.

    frirom run DECK [--out DIR] [--resume]    forced response of a deck (docs/deck.md)
    frirom demo [--out DIR]                   contact hysteresis loops and harmonics
"""

from __future__ import annotations

import argparse
import shutil
import sys
import time
from pathlib import Path

from . import __version__
from ._errors import FriromError, InputError


_RUN_EPILOG = """\
One run at a time writes a results folder (a second one on the same --out is refused).
The same deck on the same build gives the same points bit for bit, and a run killed at any
moment then resumed gives the points the uninterrupted run would have.

exit codes:
  0    the run reached the end of its frequency range
  2    bad input, refused --resume, or the folder is in use: nothing computed
  3    the run stopped before the end of its range (continuation failure, max_points,
       the curve turned back); where and why are printed, the points are in OUT/frf.h5
  130  interrupted (Ctrl-C); the points are kept, continue with --resume
"""


def _add_run(sub) -> None:
    p = sub.add_parser(
        "run", help="compute the forced response of a deck",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Compute the forced response (FRF) described by a TOML deck. Points are "
        "appended to OUT/frf.h5 as they converge (an interrupted run continues with "
        "--resume); at the end OUT/frf.csv, OUT/frf.png and OUT/states.png are written.",
        epilog=_RUN_EPILOG)
    p.add_argument("deck", type=Path, help="the TOML deck (see docs/deck.md)")
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default: results/<deck name>)")
    p.add_argument("--resume", action="store_true",
                   help="continue the run stored in OUT/frf.h5 from its last checkpoint "
                   "(the same points as an uninterrupted run); refused if the deck or a file "
                   "it names changed, except frequency.end and continuation.max_points, "
                   "which may extend the run")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_run)


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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="frirom", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"frirom {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    _add_run(sub)
    _add_demo(sub)
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
    from .deck import load_deck

    deck = load_deck(args.deck)
    for line in deck.log:
        print(f"frirom: {line}")
    out = args.out if args.out is not None else Path("results") / deck.path.stem
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: is a file; expected a folder for the results")
    out.mkdir(parents=True, exist_ok=True)
    lock = ResultsLock(out)     # before anything in out is opened or replaced
    try:
        return _run_locked(args, deck, out)
    finally:
        lock.release()


def _run_locked(args, deck, out: Path) -> int:
    """cmd_run once the results folder is locked."""
    from ._resume import EXIT_OK, EXIT_STOPPED, deck_fingerprint
    from .plots import plot_frf, plot_states
    from .results import FRF, FRFWriter
    from .solver import frf

    h5 = out / "frf.h5"
    names = [c.name for c in deck.contacts]
    fingerprint = deck_fingerprint(deck)
    start, done = _resume_start(h5, deck, fingerprint) if args.resume else (None, False)
    if not done:
        shutil.copyfile(deck.path, out / "deck.toml")

    model, excitation, options = deck.model(), deck.excitation(), deck.options()
    print(f"frirom: {model.n_dof} coordinates, {len(model.nonlinear_dofs())} in contact, "
          f"{sum(g.n_elem for g in model.contacts)} contact elements, H = {deck.harmonics}")
    result = None
    if not done:
        writer = FRFWriter(h5, deck.outputs, names, deck.harmonics, append=args.resume,
                           attrs={"deck_fingerprint": fingerprint,
                                  "omega_range": [deck.omega_start, deck.omega_end]})
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
        try:
            result = frf(model, excitation, deck.omega_start, deck.omega_end, options,
                         outputs=deck.outputs, sink=sink, start=start)
        except KeyboardInterrupt:
            progress.close()
            writer.close(complete=False, message="interrupted")
            print(f"frirom: interrupted; {h5} keeps every converged point: continue with "
                  f"`frirom run {args.deck} --out {out} --resume`", file=sys.stderr)
            return 130
        except BaseException as exc:
            progress.close()
            writer.close(complete=False, message=f"{type(exc).__name__}: {exc}")
            raise
        progress.close()
        writer.close(complete=result.complete, message=result.message)
        elapsed = time.perf_counter() - t0
        print(f"frirom: {result.solver_info}")
    else:
        elapsed = 0.0

    full = FRF.load(h5)
    if deck.csv:
        full.save_csv(out / "frf.csv")
    written = [h5] + ([out / "frf.csv"] if deck.csv else [])
    if deck.plot and len(full) > 0:
        figures = {"frf.png": plot_frf(full, output_names=deck.output_names,
                                       unit=deck.frequency_unit, title=deck.title)}
        if deck.contacts:
            figures["states.png"] = plot_states(full, contact_names=names,
                                                unit=deck.frequency_unit,
                                                title=f"{deck.title}: contact states")
        for name, fig in figures.items():
            fig.savefig(out / name)
            written.append(out / name)
    print(f"frirom: {len(full)} points in {elapsed:.1f} s; wrote "
          + ", ".join(str(p) for p in written))
    # a resumed run's own peaks cover only its part: the whole file's then (between points)
    _print_peaks(full if args.resume else result, deck)
    if not full.complete:
        _print_stop(full, deck, h5)
        return EXIT_STOPPED
    return EXIT_OK


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
        f = h5py.File(h5, "r")
    except OSError as exc:
        raise InputError(f"{h5}: cannot be read as HDF5 ({exc}); it cannot be resumed: run "
                         "without --resume (the folder's results are replaced)") from None
    with f:
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
    previous = FRF.load(h5)         # refuses an inconsistent file
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
    print(f"frirom: the run stopped before the end of its range{where}: {full.message}; "
          f"the points are in {h5}; {hint} (exit code 3)", file=sys.stderr)


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


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 0
    try:
        return args.func(args)
    except FriromError as exc:
        print(f"frirom: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
