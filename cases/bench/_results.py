"""The results file every benchmark of cases/bench/ writes: what it printed, as data.

A benchmark's ``__main__`` block calls ``record(name, main)``: main runs unchanged while
its standard output is copied, then ``cases/bench/results/<name>.json`` (or the folder in
the environment variable FRIROM_BENCH_RESULTS) receives

- ``machine``: processor, core count, load averages, Python, numpy, OPENBLAS_NUM_THREADS;
- ``commit``: the git commit of the source tree (``dirty``: uncommitted changes) and the
  ``date`` (UTC, ISO 8601), the ``argv`` the benchmark ran with, its ``seconds`` (wall);
- ``rows``: every printed table row, as a list of cells (split on runs of 2+ spaces or
  on ``|``; numbers converted), with the header line above it;
- ``ratios``: each ``<number>x`` a line printed (speed-ups, cost ratios), with its line;
- ``last``: the last line printed (each benchmark's one-line summary);
- ``data``: whatever the benchmark handed to ``add`` (structured results);
- ``output``: every line printed, and ``exit`` (the return code; a failing benchmark
  still writes its file).
"""

from __future__ import annotations

import io
import json
import os
import platform
import re
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RESULTS = Path(__file__).resolve().parent / "results"
_DATA: dict = {}
_NUM = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")
_RATIO = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?)\s?x(?![\w])")


def add(**data) -> None:
    """Structured results for the benchmark's file (its ``data`` entry)."""
    _DATA.update(data)


class _Tee(io.TextIOBase):
    def __init__(self, stream):
        self.stream, self.parts = stream, []

    def write(self, s):
        self.parts.append(s)
        return self.stream.write(s)

    def flush(self):
        self.stream.flush()


def _cell(text: str):
    t = text.strip().rstrip("%")
    if _NUM.match(t):
        return int(t) if re.fullmatch(r"[-+]?\d+", t) else float(t)
    return text.strip()


def rows(lines: list[str]) -> list[dict]:
    """Table rows of printed lines: >= 2 cells and at least one number."""
    out, header = [], None
    for line in lines:
        cells = [c for c in re.split(r"\s{2,}|\s*\|\s*", line.strip()) if c]
        values = [_cell(c) for c in cells]
        numeric = any(isinstance(v, (int, float)) for v in values)
        if len(cells) >= 2 and numeric:
            out.append({"header": header, "cells": values})
        elif len(cells) >= 2:
            header = cells
    return out


def machine() -> dict:
    try:
        import numpy
        npv = numpy.__version__
    except ImportError:
        npv = None
    return {"processor": platform.processor() or platform.machine(),
            "machine": platform.machine(), "system": platform.platform(),
            "cpus": os.cpu_count(), "load": list(os.getloadavg()),
            "python": sys.version.split()[0], "numpy": npv,
            "openblas_threads": os.environ.get("OPENBLAS_NUM_THREADS")}


def commit() -> dict:
    def git(*args):
        try:
            r = subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True,
                               text=True)
        except OSError:         # no git (a source tarball): no commit recorded
            return None
        return r.stdout.strip() if r.returncode == 0 else None
    status = git("status", "--porcelain", "--untracked-files=no")
    return {"commit": git("rev-parse", "HEAD"), "dirty": None if status is None else bool(status)}


def write(name: str, lines: list[str], argv: list[str], seconds: float, code,
          path: Path | None = None) -> Path:
    """The results file of benchmark ``name`` (see the module's docstring)."""
    folder = Path(os.environ.get("FRIROM_BENCH_RESULTS", RESULTS))
    path = Path(path) if path else folder / f"{name}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    body = [ln for ln in lines if ln.strip()]
    doc = {"benchmark": name, "date": datetime.now(timezone.utc).isoformat(timespec="seconds"),
           **commit(), "argv": argv, "seconds": round(seconds, 3), "exit": code,
           "machine": machine(), "rows": rows(body),
           "ratios": [{"ratio": float(m.group(1)), "line": ln.strip()}
                      for ln in body for m in _RATIO.finditer(ln)],
           "last": body[-1].strip() if body else None, "data": _DATA, "output": lines}
    path.write_text(json.dumps(doc, indent=1, default=str) + "\n")
    return path


def record(name: str, main, *args, path: Path | None = None):
    """Run ``main(*args)`` with its printed output copied, then write the results file.
    Returns main's return value (for ``sys.exit``)."""
    tee = _Tee(sys.stdout)
    sys.stdout = tee
    t0, code = time.perf_counter(), None
    try:
        code = main(*args)
    except SystemExit as e:
        code = e.code
        raise
    except BaseException as e:
        code = f"{type(e).__name__}: {e}"
        raise
    finally:
        sys.stdout = tee.stream
        out = write(name, "".join(tee.parts).splitlines(), sys.argv[1:],
                    time.perf_counter() - t0, code, path)
        print(f"results: {out}")
    return code
