"""The ``frirom`` command line."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import __version__
from ._errors import FriromError


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="frirom", description=__doc__)
    parser.add_argument("--version", action="version", version=f"frirom {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    demo = sub.add_parser("demo", help="hysteresis loops and harmonic content of contact "
                                       "elements, plotted to PNG")
    demo.add_argument("--out", type=Path, default=Path("results/demo"),
                      help="output folder (default: results/demo)")
    demo.set_defaults(func=_demo)
    return parser


def _demo(args) -> int:
    from . import demo
    demo.run(args.out)
    return 0


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
