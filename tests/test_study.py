"""Studies (frirom.study, `frirom study`): members equal the deck run alone, resume member
by member and point by point, Dask equals serial, a lost worker / killed study resumed.

All on the bundled joint case made coarse (H = 1, 16 samples, 440-500 Hz, large steps):
each member is about a second.
"""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import h5py
import numpy as np
import pytest

from _models import coarse_joint_deck, copy_job, small_lap_joint_deck
from frirom import InputError
from frirom.cli import main
from frirom.deck import load_deck
from frirom.deck.schema_study import member_raw, parse_study, set_key
from frirom.results import FRF
from frirom.study import curve_distance, load_study, run_study, smallest_within

ROOT = Path(__file__).resolve().parents[1]
JOINT = ROOT / "cases" / "joint"

BASE = coarse_joint_deck()

STUDY = """
[study]
scheduler = "serial"
[study.parameters]
"excitation.load[0].amplitude" = [1.0, 4.0]
"contacts[0].mu" = [0.3, 0.5]
"""


def write_case(folder: Path, study: str = STUDY, step: float = 0.2, samples: int = 16) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for f in ("M.mtx", "K.mtx", "dofs.txt"):
        shutil.copy(JOINT / f, folder / f)
    deck = folder / "study.toml"
    deck.write_text(BASE.replace("STEP", str(step)).replace("samples = 16",
                                                             f"samples = {samples}") + study)
    return deck


def member_arrays(h5, name):
    with h5py.File(h5, "r") as f:
        g = f["members"][name]
        return {k: g[k][()] for k in ("omega", "X", "amp_max", "state_fractions")}


def test_key_paths_and_errors(tmp_path):
    raw = {"contacts": [{"mu": 0.5}], "solver": {"harmonics": 1}}
    set_key(raw, "contacts[0].mu", 0.2)
    set_key(raw, "solver.samples", 32)          # a new key in an existing table
    assert raw == {"contacts": [{"mu": 0.2}], "solver": {"harmonics": 1, "samples": 32}}
    for key, words in (("contacts[1].mu", "contacts[1]"), ("solvr.harmonics", "solvr"),
                       ("contacts.mu", "array of tables"), ("a..b", "names and [index]")):
        with pytest.raises(InputError, match=words.replace("[", r"\[").replace("]", r"\]")):
            set_key(dict(raw), key, 1)
    deck = write_case(tmp_path, STUDY.replace("contacts[0].mu", "contacts[3].mu"))
    with pytest.raises(InputError, match=r'study.parameters."contacts\[3\].mu"'):
        load_study(deck)
    deck = write_case(tmp_path, STUDY.replace("0.3, 0.5", "-0.3, 0.5"))
    with pytest.raises(InputError, match=r"study member 0 .*contacts\[0\]\.mu"):
        load_study(deck)
    bad = STUDY.replace('scheduler = "serial"', 'combine = "zip"\nscheduler = "serial"')
    bad = bad.replace("[0.3, 0.5]", "[0.3, 0.5, 0.7]")
    with pytest.raises(InputError, match="one length"):
        parse_study(deck, tomllib.loads(BASE.replace("STEP", "0.2") + bad))
    assert "study" not in member_raw({"study": {}, "a": 1}, {})


@pytest.mark.slow
def test_member_equals_deck_run_alone(tmp_path):
    """A member's curve equals the deck edited by hand (text) and run by `frirom run`
    (1e-10: the same computation, so the same numbers up to round-off; measured 0)."""
    deck = write_case(tmp_path / "case")
    res = run_study(deck, tmp_path / "out", quiet=True, log=lambda s: None)
    assert [s["complete"] for s in res["summaries"]] == [True] * 4
    # member m002: amplitude 4, mu 0.3 (product order: the last key fastest)
    assert res["study"].members[2]["values"] == {"excitation.load[0].amplitude": 4.0,
                                                 "contacts[0].mu": 0.3}
    alone = tmp_path / "case" / "alone.toml"
    alone.write_text(BASE.replace("STEP", "0.2").replace("amplitude = 2.0", "amplitude = 4.0")
                     .replace("mu = 0.5", "mu = 0.3"))
    assert main(["run", str(alone), "--out", str(tmp_path / "alone"), "--quiet"]) == 0
    ref = FRF.load(tmp_path / "alone" / "frf.h5")
    got = member_arrays(res["file"], "m002")
    assert got["omega"].shape == ref.omega.shape
    for k in ("omega", "X", "amp_max", "state_fractions"):
        assert np.allclose(got[k], getattr(ref, k), rtol=1e-10, atol=0), k
    # the study file keeps the values; members differ (the sweep did something)
    with h5py.File(res["file"], "r") as f:
        assert f["members/m002"].attrs["value:contacts[0].mu"] == 0.3
    peaks = [s["peaks"][0][1] for s in res["summaries"]]
    assert len(set(np.round(peaks, 12))) == 4
    assert all((tmp_path / "out" / p).is_file() for p in ("family.png", "peaks.png"))


@pytest.mark.slow
def test_resume_member_by_member_and_point_by_point(tmp_path, monkeypatch):
    """A study interrupted in member m001 after 15 points: run again, m000 (finished) is
    not recomputed (its member.json untouched), m001 continues from its last checkpoint
    (point 11, the end of a batch: FRFWriter.resume_point; the 15 points kept bit for
    bit) and reaches the end of the range; its peak matches the
    uninterrupted study's within 1e-4 (both solved on the curve by the solver, from
    neighbours that differ after the restart; measured 1e-5)."""
    import frirom.solver as solver
    deck = write_case(tmp_path / "case")
    clean = run_study(deck, tmp_path / "clean", quiet=True, log=lambda s: None)

    real = solver.frf
    calls = {"n": 0}

    def interrupted(*a, sink=None, **kw):
        calls["n"] += 1

        def stop(p):
            sink(p)
            if calls["n"] == 2 and stop.k == 14:
                raise KeyboardInterrupt
            stop.k += 1
        stop.k = 0
        return real(*a, sink=stop, **kw)

    monkeypatch.setattr(solver, "frf", interrupted)
    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        run_study(deck, out, quiet=True, log=lambda s: None)
    monkeypatch.setattr(solver, "frf", real)
    first = (out / "members" / "m000" / "member.json").stat().st_mtime_ns
    assert not (out / "members" / "m001" / "member.json").exists()
    part = FRF.load(out / "members" / "m001" / "frf.h5")
    assert len(part) == 15 and not part.complete
    res = run_study(deck, out, quiet=True, log=lambda s: None)
    assert (out / "members" / "m000" / "member.json").stat().st_mtime_ns == first
    s1 = res["summaries"][1]
    assert s1["resumed"] and s1["complete"]
    got = member_arrays(res["file"], "m001")
    assert np.array_equal(got["X"][:15], part.X)
    assert got["omega"][-1] == pytest.approx(2 * np.pi * 500.0, rel=1e-12)
    a_ref = clean["summaries"][1]["peaks"][0][1]
    assert abs(s1["peaks"][0][1] - a_ref) <= 1e-4 * a_ref
    for i in (0, 2, 3):
        assert res["summaries"][i]["peaks"] == clean["summaries"][i]["peaks"]


@pytest.mark.slow
def test_convergence_ladder_and_choice(tmp_path):
    """A ladder over H (samples with it) on the joint: the errors against the richest rung
    fall; the chosen rung meets the tolerance and is the smallest that does. Checked
    independently: the rungs' peak errors recomputed from study.h5 and compared with the
    table, and the choice against a separate richer run (H = 9, N = 128) within 2 tol (the
    tolerance is met against the ladder's top, which is itself off the richer run by its
    own error, measured 1e-3)."""
    ladder = """
[study]
kind = "convergence"
scheduler = "serial"
tolerance = 0.01
[study.parameters]
"solver.harmonics" = [1, 3, 5, 7]
"solver.samples" = [8, 16, 32, 64]
"""
    deck = write_case(tmp_path / "case", ladder)
    res = run_study(deck, tmp_path / "out", quiet=True, log=lambda s: None)
    table, choice = res["table"], res["choice"]
    assert [r["values"]["solver.harmonics"] for r in table] == [1, 3, 5, 7]
    ref = member_arrays(res["file"], "m003")
    for r, m in zip(table, ("m000", "m001", "m002", "m003")):
        a = member_arrays(res["file"], m)
        d = curve_distance(np.c_[a["omega"], a["amp_max"][:, 0]],
                           np.c_[ref["omega"], ref["amp_max"][:, 0]])
        assert d == pytest.approx(r["distance"], rel=1e-12)
    assert table[-1]["error"] == 0 and table[0]["error"] > table[1]["error"]
    assert choice is smallest_within(table, 0.01)
    assert choice is not None and choice["error"] <= 0.01
    assert all(r["error"] > 0.01 or r["distance"] > 0.01 for r in table
               if r["unknowns"] < choice["unknowns"])
    # a richer reference computed separately
    rich = tmp_path / "case" / "rich.toml"
    rich.write_text(BASE.replace("STEP", "0.2").replace("harmonics = 1", "harmonics = 9")
                    .replace("samples = 16", "samples = 128"))
    assert main(["run", str(rich), "--out", str(tmp_path / "rich"), "--quiet"]) == 0
    pk = FRF.load(tmp_path / "rich" / "frf.h5").peak(0)
    w, a = res["summaries"][table.index(choice)]["peaks"][0]
    assert abs(a - pk.amplitude) <= 2 * 0.01 * pk.amplitude
    assert abs(w - pk.omega) <= 2 * 0.01 * pk.omega
    text = (tmp_path / "out" / "convergence.txt").read_text()
    assert "smallest model within 0.01" in text and (tmp_path / "out" / "pareto.png").is_file()


@pytest.mark.slow
def test_dask_equals_serial_and_lost_worker(tmp_path):
    """On a 2-worker LocalCluster the study equals the serial one to 1e-10 (FFTW_MEASURE
    picks its algorithms per process by timing, so round-off differs: measured 2e-13); one
    worker
    killed (SIGKILL) while members run: the study still finishes every member (Dask
    reruns the lost task, which continues from its file); then the whole study killed and
    started again keeps every finished member (member.json untouched)."""
    psutil = pytest.importorskip("psutil")
    pytest.importorskip("distributed")
    # finer steps and more samples: members of a few seconds, no corner to restart on
    deck = write_case(tmp_path / "case", step=0.05, samples=64)
    serial = run_study(deck, tmp_path / "serial", quiet=True, log=lambda s: None)
    out = tmp_path / "dask"
    cmd = [sys.executable, "-m", "frirom.cli", "study", str(deck), "--out", str(out),
           "--scheduler", "local", "--workers", "2", "--quiet"]
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True)
    killed = None
    t0 = time.time()
    while proc.poll() is None and time.time() - t0 < 120:
        running = [p for p in (out / "members").glob("m*/points")
                   if not (p.parent / "member.json").exists() and p.read_text() not in
                   ("", "0")]
        if killed is None and running:
            workers = [c for c in psutil.Process(proc.pid).children(recursive=True)
                       if "multiprocessing" in " ".join(c.cmdline())]
            if workers:
                killed = workers[0].pid
                os.kill(killed, signal.SIGKILL)
        time.sleep(0.05)
    log = proc.communicate(timeout=60)[0].decode()
    assert proc.returncode == 0, log[-2000:]
    assert killed is not None
    sums = [json.loads((out / "members" / f"m{i:03d}" / "member.json").read_text())
            for i in range(4)]
    assert all(s["complete"] for s in sums)
    for i, s in enumerate(sums):
        a, b = member_arrays(out / "study.h5", f"m{i:03d}"), \
            member_arrays(serial["file"], f"m{i:03d}")
        if not s["resumed"]:              # not hit by the kill (or restarted from scratch)
            assert all(np.allclose(a[k], b[k], rtol=1e-10, atol=1e-10 * abs(b[k]).max())
                       for k in a)
        else:                             # continued from its file: the same peak (1e-4)
            ref = serial["summaries"][i]["peaks"][0][1]
            assert abs(s["peaks"][0][1] - ref) <= 1e-4 * ref
    # the whole study killed, then started again
    out2 = tmp_path / "dask2"
    cmd[cmd.index(str(out))] = str(out2)
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    t0 = time.time()
    while time.time() - t0 < 120 and len(list(out2.glob("members/*/member.json"))) < 1:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    kept = {p: p.stat().st_mtime_ns for p in out2.glob("members/*/member.json")}
    assert kept
    assert main(["study", str(deck), "--out", str(out2), "--scheduler", "serial",
                 "--quiet"]) == 0
    assert all(p.stat().st_mtime_ns == t for p, t in kept.items())
    assert len(list(out2.glob("members/*/member.json"))) == 4


def test_study_of_a_base_deck(tmp_path):
    """``study.base``: the members vary another deck (the bundled family's form); a study
    deck naming a base holds nothing else; the base has no [study] of its own."""
    deck = write_case(tmp_path, "")
    only = tmp_path / "family.toml"
    only.write_text('[study]\nbase = "study.toml"\n' + STUDY.split("\n", 3)[3])
    st = load_study(only)
    assert st.deck == deck and len(st.members) == 4 and "study" not in st.raw
    bad = tmp_path / "bad.toml"
    bad.write_text('title = "x"\n[study]\nbase = "study.toml"\n' + STUDY.split("\n", 3)[3])
    with pytest.raises(InputError, match="study.base: expected a deck holding only"):
        load_study(bad)
    write_case(tmp_path / "b", STUDY)
    bad.write_text('[study]\nbase = "b/study.toml"\n' + STUDY.split("\n", 3)[3])
    with pytest.raises(InputError, match="without its own"):
        load_study(bad)
    bundled = load_study(ROOT / "cases" / "joint" / "joint_family.toml")
    assert bundled.deck == ROOT / "cases" / "joint" / "joint.toml"


@pytest.mark.slow
def test_reduction_ladder_gets_one_cache_per_rung(lap_joint_mesh, tmp_path, monkeypatch):
    """A ladder over GSI counts on the lap joint (coarse mesh, H = 1, a narrow range): each
    rung's reduced model is built once, before the members run, into the content-keyed
    cache shared with the decks (one entry per rung; the deck run alone after the study
    reads the top rung's back), and a rung equals the deck edited by hand and run alone
    (1e-10)."""
    monkeypatch.setenv("FRIROM_CACHE", str(tmp_path / "cache"))
    copy_job(lap_joint_mesh, tmp_path)
    (tmp_path / "lap.toml").write_text(small_lap_joint_deck(16).replace("825.0", "835.0")
                                       .replace("880.0", "860.0"))
    (tmp_path / "ladder.toml").write_text(
        '[study]\nbase = "lap.toml"\nkind = "convergence"\nscheduler = "serial"\n'
        '[study.parameters]\n"reduction.interface_modes.free" = [4, 8]\n'
        '"reduction.interface_modes.stick" = [4, 8]\n')
    lines = []
    res = run_study(tmp_path / "ladder.toml", tmp_path / "out", quiet=True,
                    log=lines.append)
    roms = sorted((tmp_path / "cache").glob("rom-*.h5"))
    assert len(roms) == 2 and all(s["rom_seconds"] > 0 for s in res["summaries"])
    assert "2 reduced model(s): 2 built, 0 reused" in lines, lines
    assert sorted(str(p) for p in roms) == sorted(m["rom"] for m in res["study"].members)
    assert [s["n_nl"] for s in res["summaries"]] == [8, 16]
    assert main(["run", str(tmp_path / "lap.toml"), "--out", str(tmp_path / "alone"),
                 "--quiet"]) == 0
    assert load_deck(tmp_path / "lap.toml").reduced.from_cache
    assert len(list((tmp_path / "cache").glob("rom-*.h5"))) == 2
    ref = FRF.load(tmp_path / "alone" / "frf.h5")
    got = member_arrays(res["file"], "m001")
    assert got["omega"].shape == ref.omega.shape
    assert np.allclose(got["amp_max"], ref.amp_max, rtol=1e-10, atol=0)


@pytest.mark.slow
def test_reduction_ladder_beside_a_named_cache_file(lap_joint_mesh, tmp_path, monkeypatch):
    """A deck that names its cache file (reduction.cache = "*.h5") keeps its own reduced
    model there; a ladder member with another reduction gets its content-keyed entry in
    that file's folder instead of overwriting it (one file per reduction: the deck's
    fingerprint stays in the named file, the other rung's in its own)."""
    monkeypatch.delenv("FRIROM_CACHE", raising=False)
    copy_job(lap_joint_mesh, tmp_path)
    deck = small_lap_joint_deck(16).replace("825.0", "835.0").replace("880.0", "860.0")
    assert deck.count("[reduction]\n") == 1
    (tmp_path / "lap.toml").write_text(deck.replace(
        "[reduction]\n", '[reduction]\ncache = "lap.rom.h5"\n'))
    (tmp_path / "ladder.toml").write_text(
        '[study]\nbase = "lap.toml"\nkind = "convergence"\nscheduler = "serial"\n'
        '[study.parameters]\n"reduction.interface_modes.free" = [4, 8]\n'
        '"reduction.interface_modes.stick" = [4, 8]\n')
    res = run_study(tmp_path / "ladder.toml", tmp_path / "out", quiet=True)
    roms = [Path(m["rom"]) for m in res["study"].members]
    assert len(set(roms)) == 2 and all(p.is_file() for p in roms), roms
    own = load_deck(tmp_path / "lap.toml").reduced
    assert own.from_cache                    # the deck's model, left in its named file
    assert (tmp_path / "lap.rom.h5") in roms
    assert all(p.parent == tmp_path for p in roms)
