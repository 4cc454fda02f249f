"""Studies of a deck: FRF families and model-size ladders, run as Dask tasks (docs/deck.md).

A deck's ``[study]`` table (:mod:`frirom.deck.schema_study`) sweeps key paths over value
lists. Each member is the deck with those keys replaced, parsed and built by the same
:func:`frirom.deck.parse_deck` / :func:`frirom.deck.build_deck` as the deck run alone, and
run by :func:`run_member`: its points go to ``OUT/members/<name>/frf.h5`` as they come
(:class:`frirom.results.FRFWriter`), and a finished member leaves ``member.json`` beside it.
A study run again skips every finished member and continues an unfinished one from its last
point, so a lost worker or an interrupted study costs at most the unsaved points of the
members it was running. At the end ``OUT/study.h5`` holds every member (one HDF5 group each,
with its parameter values as attributes) and the plots are drawn.

Members run on a ``distributed.LocalCluster`` (one single-threaded worker process per core),
on a Dask scheduler named by its address, or in this process (``"serial"``). A task gets the
deck path and its overrides, never arrays: with ``[fe_model]`` the reduced models are built
first (one task per distinct reduction) into the content-keyed cache
(:func:`frirom.deck.build.rom_file`), which the members then read back.

A convergence study is a ladder of model sizes (H, N, CB modes, GSI counts, ...); the last
rung is the reference. :func:`convergence_table` gives per rung the errors against it (peak
amplitude, peak frequency, curve distance) and the cost, and :func:`smallest_within` the
smallest model meeting the tolerance.
"""

from __future__ import annotations

import json
import os
import re
import resource
import sys
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ._errors import InputError
from ._h5check import DIGEST, seal
from ._cluster import (CONNECT_TIMEOUT, MAX_WORKERS, PROBE_MAX_BYTES,  # noqa: F401
                       SCHEDULER_ENV, Failed, _Runner, _security, check_workers,
                       choose_scheduler, probe_scheduler)
from ._resume import ResultsLock
from .deck.schema import parse_deck, read_toml
from .deck.schema_study import StudySettings, member_raw, parse_study

__all__ = ["Study", "load_study", "run_member", "run_study", "convergence_table",
           "smallest_within", "curve_distance"]

@dataclass
class Study:
    """A deck with a ``[study]`` table, its members expanded.

    path : Path
        The study's deck file. settings : StudySettings.
    deck : Path
        The deck the members vary: ``study.base``, or ``path`` itself.
    raw : dict
        That deck's TOML (without [study]).
    members : list of dict
        Per member: ``name`` (``m000``...), ``values`` {key path: value} (what the study
        sets and the member's deck is written with), ``rom`` (str: the content-keyed
        cache file of its reduced model, shared by every member and deck with the same
        reduction; None with ``[model]``).
    """

    path: Path
    deck: Path
    raw: dict
    settings: StudySettings
    members: list = field(default_factory=list)

    @property
    def kind(self) -> str:
        return self.settings.kind


#: Most members a study may have without ``force`` (``--force``): each member is a
#: folder, a results file and a task; a study above it is most likely a typo (a product
#: of long lists) and would spend minutes checking members before anything runs.
MAX_MEMBERS = 10_000


def load_study(path, force: bool = False) -> Study:
    """Read a deck's ``[study]`` and check every member's deck (parse only, no matrices);
    an error names the member and its values. A study of more than MAX_MEMBERS members is
    refused unless ``force``."""
    path = Path(path)
    raw = read_toml(path)
    st = parse_study(path, raw, read_toml)
    if st is None:
        raise InputError(f"{path}: no [study] table (see docs/deck.md, 'Studies')")
    n = st.size()
    if n > MAX_MEMBERS and not force:
        raise InputError(f"{path}: study.parameters: {n} members ("
                         + " x ".join(str(len(v)) for _, v in st.parameters)
                         + f"), more than the {MAX_MEMBERS} a study may have without "
                         "--force (frirom.study.MAX_MEMBERS)")
    deck = path
    if st.base is not None:
        deck, raw = st.base, read_toml(st.base)
    from .deck.build import beside_named_cache, rom_file
    base = parse_deck(deck, raw)
    members = []
    for i, values in enumerate(st.members()):
        try:
            rom = rom_file(beside_named_cache(parse_deck(deck, member_raw(raw, values)), base))
        except InputError as exc:
            raise InputError(f"study member {i} ({_label(values)}): {exc}") from None
        members.append({"name": f"m{i:03d}", "values": values,
                        "rom": None if rom is None else str(rom)})
    return Study(path=path, deck=deck, raw=raw, settings=st, members=members)


def load_member(deck_path, overrides: dict):
    """The built :class:`frirom.deck.Deck` of one member: the deck file with ``overrides``
    {key path: value} written, through the deck parser and builder."""
    from .deck import build_deck
    from .deck.build import beside_named_cache
    deck_path = Path(deck_path)
    raw = read_toml(deck_path)
    return build_deck(beside_named_cache(parse_deck(deck_path, member_raw(raw, overrides)),
                                         parse_deck(deck_path, raw)))


def prepare_member(deck_path, overrides: dict) -> dict:
    """Build (or reuse) one member's reduced model in its cache file: the task that runs
    before the members sharing that reduction. Returns {'seconds': the reduction's build
    time, 'reused': read back from the cache}."""
    deck = load_member(deck_path, overrides)
    rom = deck.reduced
    return {"seconds": float(getattr(rom, "build_seconds", 0.0) or 0.0),
            "reused": bool(getattr(rom, "from_cache", False))}


#: Seconds a member waits for its folder's lock (held by a worker that outlived a killed
#: study until the OS ends it) before it is refused.
LOCK_WAIT = 120.0


def run_member(deck_path, overrides: dict, folder, progress: bool = True) -> dict:
    """Run one member into ``folder`` (a Dask task: paths and values in, a summary out).

    A finished member (``folder/member.json``) returns its summary without running; an
    unfinished one continues from the last checkpoint of ``folder/frf.h5`` (a file that
    cannot be read, or holds no checkpoint, is started again). One process at a time
    writes a member (an OS lock on the folder, waited for up to LOCK_WAIT s). Points are
    flushed as they come; ``folder/points`` counts them for the progress display.

    Returns
    -------
    dict
        ``points``, ``seconds`` (FRF wall time of this call), ``cpu_seconds`` (its CPU
        time: over ``seconds``, the share of a core it had), ``pid`` (the process that ran
        it), ``started``/``ended`` (its FRF's wall-clock interval, s since the epoch),
        ``complete``, ``message``,
        ``peaks`` [(omega rad/s, amplitude)] per output, ``n_dof``, ``n_nl`` (contact
        coordinates), ``harmonics``, ``unknowns`` (n_nl (2H+1), the nonlinear system's
        size), ``rom_seconds``, ``memory_mb`` (estimate: model matrices + the dense
        condensed Jacobian), ``rss_mb`` (the process's peak resident size), ``resumed``.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    done = folder / "member.json"
    if done.is_file():
        return json.loads(done.read_text())
    # one writer per member: a worker of a killed study may still be running it
    lock = ResultsLock(folder, wait=LOCK_WAIT)
    try:
        if done.is_file():
            return json.loads(done.read_text())
        return _run_member_locked(deck_path, overrides, folder, done, progress)
    finally:
        lock.release()


def _run_member_locked(deck_path, overrides, folder: Path, done: Path, progress) -> dict:
    """run_member once the member's folder is locked."""
    from .results import FRF, FRFWriter
    from .solver import frf

    from .auto import resolve_deck
    deck = resolve_deck(load_member(deck_path, overrides), lambda s: None)
    h5 = folder / "frf.h5"
    an = getattr(deck.settings, "analysis", None)
    if an is not None and getattr(an, "from_backbone", False):
        return _run_synthesis_member(deck, overrides, folder, done)
    start = None
    if h5.is_file():
        try:
            if len(FRF.load(h5)) > 0:
                start = FRFWriter.resume_point(h5)
        except (InputError, OSError, KeyError):
            start = None                    # unreadable (killed mid-write): start again
    model, excitation, options = deck.model(), deck.excitation(), deck.options()
    names = [c.name for c in deck.contacts]
    writer = FRFWriter(h5, deck.outputs, names, deck.harmonics, append=start is not None)
    counter = _Counter(folder / "points", len(FRF.load(h5)) if start is not None else 0,
                       progress)

    def sink(point):
        writer.append(point)
        counter.add()

    t0, c0, epoch = time.perf_counter(), time.process_time(), time.time()
    try:
        result = frf(model, excitation, deck.omega_start, deck.omega_end, options,
                     outputs=deck.outputs, sink=sink, start=start)
    except BaseException as exc:
        writer.close(complete=False, message=f"{type(exc).__name__}: {exc}")
        raise
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    writer.close(complete=result.complete, message=result.message)
    counter.flush()
    full = FRF.load(h5)
    if len(full):
        _write_peaks(h5, _peaks(full, result, len(full) - len(result)))
        full = FRF.load(h5)
    n_nl = len(model.nonlinear_dofs())
    H = deck.harmonics
    # bytes of M and K: 12 per stored entry of a sparse matrix, 8 per entry of a dense one
    model_bytes = sum(12.0 * A.nnz if hasattr(A, "nnz") else 8.0 * np.size(A)
                      for A in (deck.M, deck.K))
    summary = {
        "points": len(full), "seconds": seconds, "cpu_seconds": cpu,
        "pid": os.getpid(), "started": epoch, "ended": epoch + seconds,
        "complete": bool(result.complete),
        "message": result.message, "resumed": start is not None,
        "peaks": [[full.peak(j).omega, full.peak(j).amplitude] if len(full) else
                  [float("nan")] * 2 for j in range(len(deck.outputs))],
        "fold": bool(np.any(full.fold)), "n_dof": int(deck.n_dof), "n_nl": int(n_nl),
        "harmonics": int(H), "unknowns": int(n_nl * (2 * H + 1)),
        "rom_seconds": float(getattr(deck.reduced, "build_seconds", 0.0) or 0.0),
        "memory_mb": (model_bytes + 8.0 * (n_nl * (2 * H + 1)) ** 2) / 2 ** 20,
        "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "values": dict(overrides),
    }
    tmp = done.with_suffix(".tmp")
    tmp.write_text(json.dumps(summary, indent=1, default=float))
    os.replace(tmp, done)
    return summary


def _run_synthesis_member(deck, overrides, folder: Path, done: Path) -> dict:
    """A member whose deck synthesises its forced response from a nonlinear mode
    (``[analysis] kind = "from_backbone"``, frirom.nlm_synthesis): the backbone and the
    synthesis run whole (seconds), frf.h5 is written at the end; ``seconds`` is the
    backbone's and the synthesis' together, ``snmt_seconds`` the synthesis alone."""
    from .cli_modes import synthesise_deck
    t0, c0, epoch = time.perf_counter(), time.process_time(), time.time()
    bb, frf, tb, ts = synthesise_deck(deck)
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    frf.save_h5(folder / "frf.h5")
    (folder / "points").write_text(str(len(frf)))
    model = deck.model()
    n_nl, H = len(model.nonlinear_dofs()), deck.harmonics
    summary = {
        "points": len(frf), "seconds": seconds, "cpu_seconds": cpu, "pid": os.getpid(),
        "started": epoch, "ended": epoch + seconds,
        "complete": bool(frf.complete and bb.status == "done"),
        "message": frf.message or bb.message, "resumed": False,
        "peaks": [[frf.peak(j).omega, frf.peak(j).amplitude] for j in
                  range(len(deck.outputs))],
        "fold": bool(np.any(frf.fold)), "n_dof": int(deck.n_dof), "n_nl": int(n_nl),
        "harmonics": int(H), "unknowns": int(n_nl * (2 * H + 1)),
        "rom_seconds": float(getattr(deck.reduced, "build_seconds", 0.0) or 0.0),
        "memory_mb": 0.0,
        "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "values": dict(overrides), "method": "snmt", "backbone_seconds": tb,
        "backbone_points": len(bb), "snmt_seconds": ts,
    }
    tmp = done.with_suffix(".tmp")
    tmp.write_text(json.dumps(summary, indent=1, default=float))
    os.replace(tmp, done)
    return summary


class _Counter:
    """Points of a member so far, written to a small file at most every 0.3 s."""

    def __init__(self, path: Path, n: int, on: bool):
        self.path, self.n, self.on, self.t = path, n, on, 0.0
        self.flush()

    def add(self) -> None:
        self.n += 1
        if self.on and time.monotonic() - self.t > 0.3:
            self.flush()

    def flush(self) -> None:
        if self.on:
            self.path.write_text(str(self.n))
            self.t = time.monotonic()


def _peaks(full, part, n_before: int) -> list:
    """Per output the peak of the whole curve ``full``: the solver's (solved on the
    curve) when it lies in the part this call computed (``part``, after the first
    ``n_before`` points), else :meth:`FRF.peak` of the file's points."""
    out = []
    for j in range(full.amp_max.shape[1]):
        i = int(np.argmax(full.amp_max[:, j])) if len(full) else 0
        if part.peaks is not None and i >= n_before:
            out.append(replace(part.peaks[j], index=part.peaks[j].index + n_before))
        else:
            out.append(full.peak(j))
    return out


def _write_peaks(h5, peaks) -> None:
    """The solver's refined peaks into a member's file, as FRF.save_h5 stores them."""
    import h5py
    with h5py.File(h5, "a") as f:
        for k in ("peak_omega", "peak_amplitude", "peak_index"):
            if k in f:
                del f[k]
        f.create_dataset("peak_omega", data=[p.omega for p in peaks])
        f.create_dataset("peak_amplitude", data=[p.amplitude for p in peaks])
        f.create_dataset("peak_index", data=[p.index for p in peaks])
        f.attrs["peak_method"] = np.array([p.method for p in peaks], dtype="S")
        seal(f)


def _label(values: dict) -> str:
    return ", ".join(f"{k} = {v}" for k, v in values.items())


def run_study(deck_path, out=None, scheduler: str | None = None, workers: int | None = None,
              quiet: bool = False, log=print, trust_deck_scheduler: bool = False,
              tls: dict | None = None, force: bool = False) -> dict:
    """Run (or continue) the study of a deck into ``out`` and write its file and plots.

    Parameters
    ----------
    deck_path : path of a deck with a ``[study]`` table.
    out : folder, default ``results/<deck name>``.
    scheduler : ``"local"``, ``"serial"`` or a Dask scheduler address; default
        FRIROM_SCHEDULER, else the deck's ``study.scheduler`` (an address from the deck
        only with ``trust_deck_scheduler``: :func:`choose_scheduler`).
    workers : LocalCluster workers; default the deck's ``study.workers`` or one per core.
    quiet : no progress bar. log : callable(str) for the lines printed.
    tls : {'ca', 'cert', 'key'} certificate files of a tls:// scheduler (default: Dask's
        configuration, distributed.comm.tls.*).
    force : run a study of more than MAX_MEMBERS members.

    A member that fails (its deck, its solve, its worker lost) is recorded with its
    message (:func:`failed_summary`, ``summary['failed']``) and named in the log; the
    other members run and are kept. One study at a time writes a folder.

    Returns
    -------
    dict
        ``study`` (:class:`Study`), ``summaries`` (one dict per member, see
        :func:`run_member`), ``file`` (study.h5), ``figures`` (PNG paths), ``seconds``,
        ``table`` and ``choice`` (convergence).
    """
    deck_path = Path(deck_path)
    out = Path(out) if out is not None else Path("results") / deck_path.stem
    study = load_study(deck_path, force=force)
    st = study.settings
    sched = choose_scheduler(st, scheduler, trust_deck_scheduler, deck_path)
    check_workers(workers)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: is a file; expected a folder for the study")
    out.mkdir(parents=True, exist_ok=True)
    lock = ResultsLock(out)         # one study per folder: a second is refused at once
    try:
        return _run_study_locked(study, out, sched, workers, quiet, log, tls)
    finally:
        lock.release()


def _run_study_locked(study: Study, out: Path, sched: str, workers, quiet, log, tls) -> dict:
    """run_study once the study's folder is locked."""
    st = study.settings
    log(f"size: {len(study.members)} members, at most {_max_points(study.raw)} points each "
        f"(continuation.max_points); the limit without --force is {MAX_MEMBERS} members")
    n_done = sum((out / "members" / m["name"] / "member.json").is_file()
                 for m in study.members)
    log(f"{st.kind} study of {len(study.members)} members over "
        + ", ".join(f"{k} ({len(v)} values)" for k, v in st.parameters)
        + f" ({st.combine}); {n_done} already finished in {out}")
    t0 = time.perf_counter()
    runner = _Runner(sched, workers or st.workers, tls)
    try:
        log(f"running on {sched}" + (f" ({runner.n_workers} workers)"
                                     if runner.client is not None else ""))
        rom_seconds = _prepare(study, out, runner, log)
        summaries = _run_members(study, out, runner, quiet)
    finally:
        runner.close()
    seconds = time.perf_counter() - t0
    for m, s in zip(study.members, summaries):
        if m["rom"] in rom_seconds:
            s["rom_seconds"] = rom_seconds[m["rom"]]
    res = {"study": study, "summaries": summaries, "seconds": seconds}
    res["file"] = write_study_file(study, out, summaries)
    res.update(_report(study, out, summaries, log))
    return res


def _max_points(raw: dict) -> int:
    """The deck's continuation.max_points (the solver's default without one)."""
    from .solver import SolverOptions
    c = raw.get("continuation", {})
    v = c.get("max_points") if isinstance(c, dict) else None
    return int(v) if isinstance(v, int) else int(SolverOptions.max_points)


def _prepare(study: Study, out: Path, runner: _Runner, log) -> dict:
    """Build each distinct reduced model once (tasks) before the members read them."""
    if "fe_model" not in study.raw and "reduction" not in study.raw:
        return {}
    todo, seen = [], set()
    for m in study.members:
        if m["rom"] not in seen and not (out / "members" / m["name"] / "member.json").is_file():
            seen.add(m["rom"])
            todo.append((m, m["rom"]))
    if not todo:
        return {}
    res = runner.map(prepare_member, [(str(study.deck), m["values"]) for m, _ in todo],
                     keep_going=True)
    ok = [(c, r) for (_, c), r in zip(todo, res) if not isinstance(r, Failed)]
    built = sum(not r["reused"] for _, r in ok)
    log(f"{len(todo)} reduced model(s): {built} built, {len(ok) - built} reused"
        + (f", {len(todo) - len(ok)} failed (their members fail)" if len(ok) < len(todo)
           else ""))
    return {c: r["seconds"] for c, r in ok}


def _run_members(study: Study, out: Path, runner: _Runner, quiet: bool) -> list:
    from tqdm import tqdm
    folders = [out / "members" / m["name"] for m in study.members]
    bar = tqdm(total=len(folders), unit="member", disable=quiet, file=sys.stderr,
               dynamic_ncols=True, desc=study.path.name)

    def poll():
        pts = 0
        for f in folders:
            try:
                pts += int((f / "points").read_text() or 0)
            except (OSError, ValueError):
                pass
        bar.set_postfix_str(f"{pts} points")

    def on_done(i, s):
        bar.update(1)
        poll()

    jobs = [(str(study.deck), m["values"], str(f), runner.client is not None)
            for m, f in zip(study.members, folders)]
    try:
        res = runner.map(run_member, jobs, on_done, poll, keep_going=True)
    finally:
        bar.close()
    n_out = _n_outputs(study)
    return [failed_summary(m, f, r.message, n_out) if isinstance(r, Failed) else r
            for m, f, r in zip(study.members, folders, res)]


def _n_outputs(study: Study) -> int:
    out = study.raw.get("outputs", {})
    dofs = out.get("dofs", []) if isinstance(out, dict) else []
    return max(len(dofs) if isinstance(dofs, list) else 1, study.settings.output + 1)


def failed_summary(member: dict, folder: Path, message: str, n_out: int) -> dict:
    """The summary of a member whose task raised (see :func:`run_member` for the keys):
    ``failed`` True, ``message`` the error, the points its file kept; also written to
    ``folder/failed.json`` (a study run again retries the member)."""
    points = 0
    try:
        from .results import FRF
        points = len(FRF.load(folder / "frf.h5"))
    except (InputError, OSError):
        pass
    nan = float("nan")
    s = {"failed": True, "message": message, "complete": False, "points": points,
         "seconds": 0.0, "cpu_seconds": 0.0, "pid": 0, "started": nan, "ended": nan,
         "resumed": False, "peaks": [[nan, nan] for _ in range(n_out)], "fold": False,
         "n_dof": 0, "n_nl": 0, "harmonics": 0, "unknowns": 0, "rom_seconds": 0.0,
         "memory_mb": 0.0, "rss_mb": 0.0, "values": dict(member["values"])}
    try:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "failed.json").write_text(json.dumps(s, indent=1, default=float))
    except OSError:
        pass
    return s


def write_study_file(study: Study, out: Path, summaries: list) -> Path:
    """``out/study.h5``: a group ``members/<name>`` per member (its frf.h5 copied, its
    values and summary as attributes), the study's settings as attributes of the root."""
    import h5py
    path = out / "study.h5"
    with h5py.File(path, "w") as f:
        f.attrs["deck"] = str(study.deck)
        f.attrs["study"] = str(study.path)
        f.attrs["kind"] = study.kind
        f.attrs["combine"] = study.settings.combine
        f.attrs["parameters"] = json.dumps([[k, list(v)] for k, v in
                                            study.settings.parameters])
        g = f.create_group("members")
        for m, s in zip(study.members, summaries):
            dst = g.create_group(m["name"])
            src_path = out / "members" / m["name"] / "frf.h5"
            if s.get("failed"):
                dst.attrs["failed"] = s["message"]
            else:
                with h5py.File(src_path, "r") as src:
                    for k in src:
                        src.copy(src[k], dst, name=k)
                    for k, v in src.attrs.items():
                        if k != DIGEST:         # the member file's own checksum
                            dst.attrs[k] = v
            dst.attrs["values"] = json.dumps(m["values"])
            for k, v in m["values"].items():
                if isinstance(v, (int, float, str, bool)):
                    dst.attrs[f"value:{k}"] = v
            dst.attrs["summary"] = json.dumps(s, default=float)
    return path


# ---- reports -----------------------------------------------------------------------------
def _report(study: Study, out: Path, summaries: list, log) -> dict:
    from .results import FRF
    from . import study_plots
    deck = study.raw
    unit = str(deck.get("frequency", {}).get("unit", "hz")).lower()
    j = study.settings.output
    frfs = [_member_frf(out / "members" / m["name"] / "frf.h5", s)
            for m, s in zip(study.members, summaries)]
    res, figs = {}, {}
    for m, s in zip(study.members, summaries):
        if s.get("failed"):
            log(f"{m['name']}: {_label(m['values'])}: FAILED: {s['message']}")
            continue
        w, a = s["peaks"][j]
        f = w / (2 * np.pi) if unit == "hz" else w
        flag = "" if s["complete"] else f"  (stopped: {s['message']})"
        log(f"{m['name']}: {_label(m['values'])}: peak {a:.6g} at {f:.6g} "
            f"{'Hz' if unit == 'hz' else 'rad/s'}, {s['points']} points, "
            f"{s['seconds']:.1f} s{flag}")
    bad = [(m, s) for m, s in zip(study.members, summaries) if s.get("failed")]
    if bad:
        log(f"{len(bad)} of {len(summaries)} members failed (the others ran and are kept; "
            "running the study again retries them): "
            + "; ".join(f"{m['name']} ({_label(m['values'])}): {s['message']}"
                        for m, s in bad))
    if study.kind == "family":
        figs["family.png"] = study_plots.plot_family(study, frfs, summaries, unit=unit,
                                                     linear=_linear(study),
                                                     per_load=_load_key(study))
        figs["peaks.png"] = study_plots.plot_peaks(study, summaries, unit=unit)
    else:
        table = convergence_table(study, frfs, summaries)
        choice = smallest_within(table, study.settings.tolerance)
        res.update(table=table, choice=choice)
        for line in format_table(table, study.settings.tolerance, choice):
            log(line)
        (out / "convergence.txt").write_text(
            "\n".join(format_table(table, study.settings.tolerance, choice)) + "\n")
        figs["pareto.png"] = study_plots.plot_pareto(table, study.settings.tolerance, choice)
        figs["family.png"] = study_plots.plot_family(study, frfs, summaries, unit=unit)
    paths = []
    for name, fig in figs.items():
        fig.savefig(out / name)
        paths.append(out / name)
    log(f"wrote {out / 'study.h5'}, " + ", ".join(str(p) for p in paths))
    res["figures"] = paths
    return res


def _member_frf(h5: Path, summary: dict):
    """A member's FRF for the report: its file, or no point for a failed member whose
    file is missing or unreadable."""
    from .results import FRF
    try:
        return FRF.load(h5)
    except (InputError, OSError):
        if not summary.get("failed"):
            raise
    n = len(summary["peaks"])
    z = np.zeros(0)
    return FRF(omega=z, X=np.zeros((0, n, 1)), amp_max=np.zeros((0, n)),
               state_fractions=np.zeros((0, 0, 3)), stable=z.astype(bool),
               fold=z.astype(bool), iterations=z.astype(int), time_s=z, complete=False,
               message=summary["message"])


def _load_key(study: Study):
    """The swept key that is the amplitude of a load (the family is then drawn per unit
    load), or None."""
    keys = [k for k, _ in study.settings.parameters
            if re.fullmatch(r"excitation\.load\[\d+\]\.amplitude", k)]
    return keys[0] if len(keys) == 1 else None


def _linear(study: Study):
    """The first member's linear free/stuck curves at the studied output (frirom.modes),
    per unit load when the load amplitude is swept; None when they cannot be made."""
    from .modes import linear_check
    m = study.members[0]
    try:
        check = linear_check(load_member(study.deck, m["values"]))
    except (InputError, ValueError, RuntimeError, ArithmeticError):
        return None
    curves = check.linear_curves(study.settings.output)
    key = _load_key(study)
    if key is not None:
        scale = abs(float(m["values"][key])) or 1.0
        curves = {k: (w, a / scale) for k, (w, a) in curves.items()}
    return curves


def curve_distance(a, b) -> float:
    """Distance between two FRF curves: the largest distance from a point of either curve
    to the other polyline, in the plane (omega / span, amplitude / peak) of ``b`` (the
    reference), so 0.01 is 1 % of the frequency span or of the peak.

    a, b : (n, 2) arrays of (omega rad/s, amplitude).
    """
    b = np.asarray(b, float)
    a = np.asarray(a, float)
    scale = np.array([np.ptp(b[:, 0]) or 1.0, np.max(np.abs(b[:, 1])) or 1.0])
    A, B = a / scale, b / scale
    return max(_to_polyline(A, B).max(), _to_polyline(B, A).max())


def _to_polyline(P, Q) -> np.ndarray:
    """Distance of each point of P (n, 2) to the polyline Q (m, 2)."""
    if len(Q) == 1:
        return np.hypot(*(P - Q[0]).T)
    q0, d = Q[:-1], np.diff(Q, axis=0)                          # (m-1, 2)
    L2 = np.maximum((d ** 2).sum(1), 1e-300)
    t = np.clip(((P[:, None, :] - q0) * d).sum(-1) / L2, 0.0, 1.0)   # (n, m-1)
    near = q0 + t[..., None] * d
    return np.sqrt(((P[:, None, :] - near) ** 2).sum(-1)).min(axis=1)


def convergence_table(study: Study, frfs: list, summaries: list) -> list:
    """One row per rung: the rung's values, errors against the last rung (the reference)
    and cost, and the failures seen.

    Errors are relative: ``err_amp`` |A - A_ref| / A_ref of the peak amplitude,
    ``err_freq`` |w - w_ref| / w_ref of its frequency, ``distance`` the
    :func:`curve_distance` to the reference; ``error`` the largest of the three (what the
    tolerance applies to).
    Cost: ``rom_s`` reduction, ``frf_s`` FRF wall time, ``cost_s`` their sum,
    ``memory_mb`` the estimate of :func:`run_member`. ``notes`` lists what failed: the
    curve stopped, a fold only in this model, the error not falling from the previous
    rung (of the same ``method``: 'hbm', or 'snmt' for a forced response synthesised from
    a backbone, ``[analysis] kind = "from_backbone"``, whose cost is the backbone's and
    the synthesis').
    """
    j = study.settings.output
    ref, fref = summaries[-1], frfs[-1]
    wr, ar = ref["peaks"][j]
    cref = np.c_[fref.omega, fref.amp_max[:, j]]
    rows = []
    for i, (m, s, fr) in enumerate(zip(study.members, summaries, frfs)):
        w, a = s["peaks"][j]
        row = {"name": m["name"], "values": m["values"], "n_dof": s["n_dof"],
               "n_nl": s["n_nl"], "unknowns": s["unknowns"], "points": s["points"],
               "err_amp": abs(a - ar) / ar, "err_freq": abs(w - wr) / wr,
               "distance": (curve_distance(np.c_[fr.omega, fr.amp_max[:, j]], cref)
                            if len(fr) and len(cref) else float("inf")),
               "rom_s": s["rom_seconds"], "frf_s": s["seconds"],
               "memory_mb": s["memory_mb"], "reference": i == len(summaries) - 1,
               "complete": s["complete"], "notes": [],
               "method": s.get("method", "hbm")}
        row["cost_s"] = row["rom_s"] + row["frf_s"]
        row["error"] = max(row["err_amp"], row["err_freq"], row["distance"])
        if s.get("failed"):
            row["notes"].append(f"failed: {s['message']}")
        elif not s["complete"]:
            row["notes"].append(f"curve stopped: {s['message']}")
        if s["fold"] and not ref["fold"]:
            row["notes"].append("fold not in the reference")
        if not np.isfinite(row["error"]):
            row["notes"].append("no peak")
        if rows and not row["reference"] and row["error"] > 1.5 * rows[-1]["error"] \
                and rows[-1]["error"] > 0 and rows[-1]["method"] == row["method"]:
            row["notes"].append("error rose from the previous rung")
        rows.append(row)
    return rows


def smallest_within(table: list, tol: float):
    """The rung with the fewest nonlinear unknowns (then fewest DoFs, then cheapest) whose
    peak errors and curve distance (``error``) are within ``tol`` and whose curve reached
    the end, the reference excluded; None if no rung qualifies."""
    ok = [r for r in table if not r["reference"] and r["complete"] and r["error"] <= tol]
    if not ok:
        return None
    return min(ok, key=lambda r: (r["unknowns"], r["n_dof"], r["cost_s"]))


def format_table(table: list, tol: float, choice) -> list:
    """The convergence table as text lines (what the log and convergence.txt show)."""
    keys = list(table[0]["values"])
    head = "  ".join(f"{k:>14s}" for k in keys)
    lines = [f"{head}  {'n_dof':>6s} {'n_nl':>5s} {'unknowns':>8s} {'err_amp':>9s} "
             f"{'err_freq':>9s} {'distance':>9s} {'rom_s':>7s} {'frf_s':>7s} {'mem_MB':>7s}"]
    for r in table:
        vals = "  ".join(f"{str(r['values'][k]):>14s}" for k in keys)
        note = "  reference" if r["reference"] else ""
        if r["notes"]:
            note += "  FAILED? " + "; ".join(r["notes"])
        lines.append(f"{vals}  {r['n_dof']:6d} {r['n_nl']:5d} {r['unknowns']:8d} "
                     f"{r['err_amp']:9.2e} {r['err_freq']:9.2e} {r['distance']:9.2e} "
                     f"{r['rom_s']:7.2f} {r['frf_s']:7.2f} {r['memory_mb']:7.2f}{note}")
    if choice is None:
        lines.append(f"no rung is within {tol:g} of the reference (peak amplitude, peak "
                     "frequency and curve distance): climb higher")
    else:
        lines.append(f"smallest model within {tol:g}: {_label(choice['values'])} "
                     f"({choice['unknowns']} nonlinear unknowns, {choice['cost_s']:.2f} s "
                     f"against {table[-1]['cost_s']:.2f} s for the reference)")
    return lines
