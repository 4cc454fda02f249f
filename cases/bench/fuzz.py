"""The long fuzzing campaign of issue 13: mutated decks and matrix files through the deck
loader and the readers; counts the inputs tried, accepted, refused with a frirom error
(named), crashed (any other exception: a raw traceback) and hung (over --hang seconds).
The target is 0 crashes and 0 hangs in 10 000 decks.

Decks: the bundled [model] decks (cases/joint/joint.toml, cases/bladed_disk) and, with
--lap N, N mutations of the lap-joint [fe_model] deck (its CalculiX matrices are made
once with gmsh + ccx into --work). Each mutated deck is loaded and its solver objects
built as `frirom run` does before the sweep (tests/_mutate.py: load_and_check); each
mutated file is read by its reader. Mutations come from a seeded random.Random: a run is reproducible.

    OPENBLAS_NUM_THREADS=1 python cases/bench/fuzz.py [--decks 10000] [--files 2000]
        [--studies 2000] [--results 2000] [--seed 13] [--lap 100] [--work results/fuzz]

--studies: bundled decks with a [study] table, mutated, read as `frirom study` does
before any member runs (no scheduler is contacted). --results: a small run's frf.h5
edited with h5py (junk datasets, retyped attributes, links, nesting, changed values),
read as `frirom show` and --resume do (tests/_mutate.py: mutate_results).

Prints a table per input kind, then each crash (the first 10) with its input.
"""

from __future__ import annotations

import argparse
import os
import random
import shutil
import signal
import sys
import time
from collections import Counter
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))

from _mutate import (STUDY_TABLE, load_and_check, make_results,  # noqa: E402
                     mutate_bytes, mutate_deck, mutate_results, reader_cases, results_check,
                     study_check, try_input)


OUTCOMES = ("ok", "error", "crash", "hang")


class _Hang(Exception):
    pass


def _alarm(signum, frame):
    raise _Hang()


def timed(run, hang: float):
    """try_input with a wall-clock limit: ('hang', None) past ``hang`` seconds."""
    signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, hang)
    try:
        return try_input(run)
    except _Hang:
        return "hang", None
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)


def deck_sources(work: Path, lap: bool) -> dict:
    """{name: deck path in work/} with the files each deck needs copied next to it."""
    out = {}
    for name, deck in (("joint", ROOT / "cases/joint/joint.toml"),
                       ("bladed_disk", ROOT / "cases/bladed_disk/bladed_disk.toml")):
        d = work / name
        d.mkdir(parents=True, exist_ok=True)
        for f in deck.parent.iterdir():
            if f.suffix in (".mtx", ".txt", ".toml"):
                shutil.copy(f, d / f.name)
        out[name] = d / deck.name
    if lap:
        d = work / "lap_joint"
        d.mkdir(parents=True, exist_ok=True)
        if not (d / "lap.sti").is_file():
            sys.path.insert(0, str(ROOT / "cases/lap_joint"))
            from make_lap_joint import make
            make(d)
        shutil.copy(ROOT / "cases/lap_joint/lap_joint.toml", d / "lap_joint.toml")
        out["lap_joint"] = d / "lap_joint.toml"
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--decks", type=int, default=10000, help="mutated decks to try")
    ap.add_argument("--files", type=int, default=2000, help="mutated matrix files to try")
    ap.add_argument("--seed", type=int, default=13)
    ap.add_argument("--hang", type=float, default=60.0, help="seconds that make a hang")
    ap.add_argument("--lap", type=int, default=0,
                    help="mutated lap-joint [fe_model] decks to try (a changed reduction is "
                    "rebuilt: seconds to a minute each)")
    ap.add_argument("--studies", type=int, default=2000, help="mutated study decks to try")
    ap.add_argument("--results", type=int, default=2000,
                    help="hostile results files to try")
    ap.add_argument("--work", type=Path, default=ROOT / "results" / "fuzz")
    a = ap.parse_args(argv)
    rnd = random.Random(a.seed)
    sources = deck_sources(a.work, a.lap > 0)
    texts = {k: p.read_text() for k, p in sources.items()}
    counts = {k: Counter() for k in list(sources) + [c[0] for c in reader_cases()]
              + ["study", "results"]}
    crashes, slowest = [], (0.0, "")
    t_start = time.perf_counter()
    names = ["bladed_disk", "joint"]
    plan = [names[i % 2] for i in range(a.decks)] + ["lap_joint"] * a.lap
    for i, name in enumerate(plan):
        data = mutate_deck(texts[name], rnd)
        path = sources[name].with_name("fuzzed.toml")
        path.write_bytes(data)
        t0 = time.perf_counter()
        outcome, exc = timed(lambda: load_and_check(path), a.hang)
        dt = time.perf_counter() - t0
        slowest = max(slowest, (dt, f"{name} deck {i}"))
        counts[name][outcome] += 1
        counts[name]["named"] += outcome == "error" and path.name in str(exc)
        if outcome in ("crash", "hang"):
            crashes.append((name, outcome, exc, data))
    readers = reader_cases()
    for i in range(a.files):
        name, files, read = readers[i % len(readers)]
        folder = a.work / "files" / name
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        victim = rnd.choice(sorted(files))
        data = None
        for f, content in files.items():
            b = mutate_bytes(content, rnd) if f == victim else content
            data = b if f == victim else data
            (folder / f).write_bytes(b)
        outcome, exc = timed(lambda: read(folder), a.hang)
        counts[name][outcome] += 1
        counts[name]["named"] += outcome == "error" and str(folder) in str(exc)
        if outcome in ("crash", "hang"):
            crashes.append((f"{name}/{victim}", outcome, exc, data))
    for i in range(a.studies):
        name = ("bladed_disk", "joint")[i % 2]
        data = mutate_deck(texts[name] + STUDY_TABLE, rnd)
        path = sources[name].with_name("fuzzed_study.toml")
        path.write_bytes(data)
        outcome, exc = timed(lambda: study_check(path), a.hang)
        counts["study"][outcome] += 1
        counts["study"]["named"] += outcome == "error" and path.name in str(exc)
        if outcome in ("crash", "hang"):
            crashes.append((f"study of {name}", outcome, exc, data))
    if a.results:
        src = make_results(a.work / "results_src")
        dst = a.work / "results_src" / "fuzzed.h5"
        for i in range(a.results):
            what = mutate_results(src, dst, rnd)
            outcome, exc = timed(lambda: results_check(dst), a.hang)
            counts["results"][outcome] += 1
            counts["results"]["named"] += outcome == "error" and str(dst) in str(exc)
            if outcome in ("crash", "hang"):
                crashes.append(("results", outcome, exc, what.encode()))
    total = time.perf_counter() - t_start

    print(f"fuzz: seed {a.seed}, {a.decks + a.lap} decks, {a.files} files, {a.studies} "
          f"study decks, {a.results} results files, {total:.0f} s")
    print(f"{'input':<16}{'tried':>8}{'accepted':>10}{'refused':>10}{'named':>8}"
          f"{'crashed':>9}{'hung':>6}")
    tot = Counter()
    for k, c in counts.items():
        tot.update(c)
        print(f"{k:<16}{sum(c[o] for o in OUTCOMES):>8}{c['ok']:>10}{c['error']:>10}"
              f"{c['named']:>8}{c['crash']:>9}{c['hang']:>6}")
    print(f"{'all':<16}{sum(tot[o] for o in OUTCOMES):>8}{tot['ok']:>10}{tot['error']:>10}"
          f"{tot['named']:>8}{tot['crash']:>9}{tot['hang']:>6}")
    print("named: refusals whose message names the deck or file given")
    print(f"slowest input: {slowest[1]}, {slowest[0]:.2f} s")
    for name, outcome, exc, data in crashes[:10]:
        print(f"\n{outcome} on {name}: {type(exc).__name__}: {exc}\n{data[:1500]!r}")
    return 1 if crashes else 0


if __name__ == "__main__":
    from _results import record
    sys.exit(record("fuzz", main))
