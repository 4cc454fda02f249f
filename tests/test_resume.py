"""Killed, resumed, locked, refused: a run killed at any moment and resumed gives exactly
the points of the uninterrupted run; frf.h5 stays readable whatever the moment; the
results folder takes one run at a time; --resume refuses a changed deck; exit codes.

"Exactly" is bit for bit (tolerance 0): the resumed run starts from a checkpoint (the last
point of a call into Fortran) with the state the uninterrupted run had there (step,
arc-length scale, tangent, sliders, call boundaries), and the arithmetic is
deterministic (FFTW_ESTIMATE plans, fixed thread count). The deck is cases/joint/joint.toml
(friction damper, ~165 points, 3 s), a real stick-slip curve with a contact history.
"""

import os
import shutil
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest

from _models import resume_into, resume_refuses_changed_mu_and_h, run_then_kill
from frirom.cli import main
from frirom.deck import load_deck
from frirom.results import FRF, FRFWriter
from frirom.solver import frf

ROOT = Path(__file__).resolve().parents[1]
JOINT = ROOT / "cases" / "joint"
#: every array of a point that the solver decides (time_s is wall-clock, not compared)
POINT_ARRAYS = ("omega", "parameter", "X", "amp_max", "state_fractions", "slider",
                "iterations", "fold", "stable")


#: a kill whose checkpoint lies after the tip's peak (test_killed_anywhere...)
PEAK_CUT = 87


class Killed(BaseException):
    """Stands for SIGKILL in-process: nothing after it runs, the writer is not closed."""


@pytest.fixture
def deck(tmp_path):
    for f in ("M.mtx", "K.mtx", "dofs.txt", "joint.toml"):
        shutil.copy(JOINT / f, tmp_path / f)
    d = tmp_path / "joint.toml"
    d.write_text(d.read_text().replace("[outputs]\n", "[outputs]\nplot = false\n"))
    return d


@pytest.fixture(scope="module")
def joint():
    d = load_deck(JOINT / "joint.toml")
    return d, d.model(), d.excitation(), d.options()


def _writer(path, d, append=False):
    return FRFWriter(path, d.outputs, [c.name for c in d.contacts], d.harmonics,
                     append=append)


def _same(a: FRF, b: FRF, what: str) -> None:
    assert len(a) == len(b), what
    for name in POINT_ARRAYS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name),
                                      err_msg=f"{what}: {name}")


@pytest.mark.slow
def test_killed_anywhere_then_resumed_equals_uninterrupted(joint, tmp_path):
    """Kill after k points (k = 5: before the first checkpoint; 21: on one; 37, 48: inside
    a call; 48 also with a torn record, rows written for point 49 in some datasets only),
    reopen, resume: the file equals the uninterrupted run's, bit for bit. 430-480 Hz:
    the resonance, stick to slip and back (~60 points)."""
    d, model, exc, opts = joint
    w0, w1 = 2 * np.pi * 430.0, 2 * np.pi * 480.0
    ref_path = tmp_path / "ref.h5"
    w = _writer(ref_path, d)
    full = frf(model, exc, w0, w1, opts, outputs=d.outputs, sink=w.append)
    w.close(full.complete, full.message)
    ref = FRF.load(ref_path)
    assert full.complete and len(ref) > 50
    stick = ref.state_fractions[:, 0, 0]
    assert stick[0] == stick[-1] == 1.0 and stick.min() < 0.6     # sticks, slips, sticks
    assert all(full.peak(j).method == "solve" for j in range(len(d.outputs)))
    assert full.peak(0).index + 2 < PEAK_CUT - 10   # resumed after the peak's points
    for k, torn in ((5, False), (21, False), (37, False), (48, True), (PEAK_CUT, False)):
        path = tmp_path / f"cut{k}.h5"
        w = _writer(path, d)

        def dying(p, w=w, k=k):
            if w._commit[0] == k:
                raise Killed
            w.append(p)
        with pytest.raises(Killed):
            frf(model, exc, w0, w1, opts, outputs=d.outputs, sink=dying)
        if torn:        # the next point's rows in some datasets: killed inside append
            for name in ("omega", "X", "slider"):
                w.f[name].resize(k + 1, axis=0)
        w.f.close()             # not w.close(): the file stays "running", as after SIGKILL
        cut = FRF.load(path)
        assert len(cut) == k and not cut.complete and cut.message == "running"
        np.testing.assert_array_equal(cut.X, ref.X[:k])
        try:
            start = FRFWriter.resume_point(path)
        except Exception as e:      # noqa: BLE001 - before the first checkpoint
            assert k < 11 and "no point to resume from" in str(e)
            start = None
        w = _writer(path, d, append=True)
        assert w.repaired == (1 if torn else 0)
        n0 = start["n_points"] if start else 0
        assert w.dropped == k - n0 and (start is None or (n0 - 1) % 10 == 0)
        rest = frf(model, exc, w0, w1, opts, outputs=d.outputs, sink=w.append, start=start)
        w.close(rest.complete, rest.message)
        _same(FRF.load(path), ref, f"killed after {k}")
        # the peaks solved on the whole curve (the points before the resume too), the
        # uninterrupted run's to the bit
        for j in range(len(d.outputs)):
            assert rest.peak(j) == full.peak(j), (k, j, rest.peak(j), full.peak(j))


def test_ctrl_c_inside_append_waits_for_the_record(joint, tmp_path, monkeypatch):
    """SIGINT arriving while a point is being written: KeyboardInterrupt comes after the
    record is whole (every dataset one row longer, committed)."""
    d, model, exc, opts = joint
    path = tmp_path / "a.h5"
    w = _writer(path, d)
    pts = []
    frf(model, exc, d.omega_start, d.omega_end,
        opts.__class__(**{**opts.__dict__, "max_points": 3}), outputs=d.outputs,
        sink=pts.append)
    real = FRFWriter._append
    w.append(pts[0])
    # Python's own SIGINT handler (gmsh, imported by other tests, installs SIG_DFL)
    old = signal.signal(signal.SIGINT, signal.default_int_handler)

    def interrupted(self, p):
        os.kill(os.getpid(), signal.SIGINT)       # lands in the middle of the record
        time.sleep(0.05)
        real(self, p)
    monkeypatch.setattr(FRFWriter, "_append", interrupted)
    try:
        with pytest.raises(KeyboardInterrupt):
            w.append(pts[1])
            time.sleep(0.05)    # the handler runs at the next bytecode after append
    finally:
        signal.signal(signal.SIGINT, old)
    w.close(False, "interrupted")
    with h5py.File(path, "r") as f:
        assert list(f.attrs["committed"][:1]) == [2]
        assert {f[n].shape[0] for n in ("omega", "X", "slider", "time_s", "fold")} == {2}


def test_unequal_datasets_from_before_are_repaired(joint, tmp_path):
    """A file from before the commit record with datasets of unequal length (Ctrl-C in
    the old append): read as its shortest dataset, cut to it when reopened to resume."""
    d, model, exc, opts = joint
    path = tmp_path / "old.h5"
    w = _writer(path, d)
    frf(model, exc, d.omega_start, d.omega_end,
        opts.__class__(**{**opts.__dict__, "max_points": 12}), outputs=d.outputs,
        sink=w.append)
    w.close(False, "stopped")
    with h5py.File(path, "a") as f:
        del f.attrs["committed"], f.attrs["content_sha256"]    # both came later
        for name in ("omega", "parameter", "X"):
            f[name].resize(13, axis=0)
    assert len(FRF.load(path)) == 12
    w = _writer(path, d, append=True)
    assert w.repaired == 1 and w.dropped == 0
    w.close(False, "")
    with h5py.File(path, "r") as f:
        assert f["omega"].shape[0] == f["fold"].shape[0] == 12


def _frirom(*args, script=None):
    """`frirom ARGS` (or the Python `script` with ARGS) in another process."""
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    head = ["-c", script] if script else ["-m", "frirom.cli"]
    return subprocess.Popen([sys.executable, *head, *map(str, args)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _peak_lines(p) -> list:
    return [x for x in p.stdout.read().splitlines() if x.startswith("frirom: peak of")]


#: `frirom run` that SIGKILLs itself when its file holds K points, before the next
#: record or (WHERE = "inside") in the middle of it: some datasets have its row
_DYING_RUN = """
import os, signal, sys
from frirom import results
from frirom.cli import main
k, where = int(sys.argv[1]), sys.argv[2]
real = results.FRFWriter._append
def dying(self, p):
    if self._commit[0] == k:
        if where == "inside":
            for name in ("slider", "omega", "X"):
                self.f[name].resize(k + 1, axis=0)
                self.f[name][k] = getattr(p, name)
            self.f.flush()
        os.kill(os.getpid(), signal.SIGKILL)
    real(self, p)
results.FRFWriter._append = dying
sys.exit(main(sys.argv[3:]))
"""


@pytest.mark.slow
def test_sigkill_then_resume_equals_uninterrupted(deck, tmp_path):
    """`frirom run` killed by SIGKILL at several moments (before the first checkpoint,
    inside a record, between records), each time resumed: frf.h5 is readable after every
    kill, the torn record is removed and said so, and the finished file equals an
    uninterrupted run's (run in another process: the same build gives the same points bit
    for bit)."""
    ref = _frirom("run", deck, "--out", tmp_path / "ref", "--quiet")
    assert ref.wait(300) == 0, ref.stderr.read()
    ref_peaks = _peak_lines(ref)
    ref = FRF.load(tmp_path / "ref" / "frf.h5")
    out = tmp_path / "out"
    resume = []
    for k, where in ((5, "before"), (48, "inside"), (77, "before")):
        p = _frirom(str(k), where, "run", deck, "--out", out, "--quiet", *resume,
                    script=_DYING_RUN)
        assert p.wait(300) == -signal.SIGKILL, p.stderr.read()
        err = p.stderr.read()
        if resume and k == 77:
            assert "removed a torn last record" in err
        cut = FRF.load(out / "frf.h5")        # readable
        assert len(cut) == k and not cut.complete
        resume = ["--resume"]
    p = _frirom("run", deck, "--out", out, "--quiet", "--resume")
    assert p.wait(300) == 0, p.stderr.read()
    _same(FRF.load(out / "frf.h5"), ref, "after SIGKILLs")
    # the resumed run reports the uninterrupted run's solved peaks (the deck's last
    # checkpoint, 71, lies past the peaks)
    peaks = _peak_lines(p)
    assert peaks == ref_peaks and len(peaks) == 3 and all("(solve)" in x for x in peaks)


@pytest.mark.slow
def test_second_run_on_a_folder_is_refused_until_the_first_dies(deck, tmp_path, capsys):
    """A run holding OUT's lock (another process) makes a second run on OUT exit 2 with
    frf.h5 untouched; once the holder dies (SIGKILL), the lock is gone."""
    from frirom._resume import ResultsLock
    out = tmp_path / "out"
    deck.write_text(deck.read_text().replace("max_points = 1000", "max_points = 12"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        assert main(["run", str(deck), "--out", str(out), "--quiet"]) == 3
    before = (out / "frf.h5").read_bytes()
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time; from frirom._resume import ResultsLock; "
         "lock = ResultsLock(sys.argv[1]); print('locked', flush=True); time.sleep(60)",
         str(out)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        capsys.readouterr()
        for extra in ([], ["--resume"]):
            assert main(["run", str(deck), "--out", str(out), "--quiet", *extra]) == 2
            err = capsys.readouterr().err
            assert f"another frirom run (pid {holder.pid})" in err and str(out) in err
        assert (out / "frf.h5").read_bytes() == before
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait(30)
    ResultsLock(out).release()      # free again


@pytest.mark.slow
def test_resume_refuses_a_changed_deck(deck, tmp_path, capsys):
    """--resume names each change (a key, a matrix file's content); frequency.end and
    continuation.max_points may change (they extend the run); a shorter range may not."""
    out = tmp_path / "out"
    text = deck.read_text()
    deck.write_text(text.replace("max_points = 1000", "max_points = 31"))
    assert main(["run", str(deck), "--out", str(out), "--quiet"]) == 3
    capsys.readouterr()
    err = resume_refuses_changed_mu_and_h(deck, text, out, capsys, main)
    assert "continuation.max_points:" not in err          # may change
    deck.write_text(text)
    k = deck.with_name("K.mtx")
    k.write_text(k.read_text() + "\n")
    assert main(["run", str(deck), "--out", str(out), "--quiet", "--resume"]) == 2
    assert "file of model.stiffness (K.mtx): content changed" in capsys.readouterr().err
    shutil.copy(JOINT / "K.mtx", k)
    deck.write_text(text.replace("end = 520.0", "end = 500.0"))
    assert main(["run", str(deck), "--out", str(out), "--quiet", "--resume"]) == 2
    assert "frequency.end: --resume may extend the range" in capsys.readouterr().err
    # allowed: more points, then a longer range after the run completed
    deck.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        assert main(["run", str(deck), "--out", str(out), "--quiet", "--resume"]) == 0
    deck.write_text(text.replace("end = 520.0", "end = 540.0"))
    assert main(["run", str(deck), "--out", str(out), "--quiet", "--resume"]) == 0
    r = FRF.load(out / "frf.h5")
    assert r.complete and r.omega[-1] == pytest.approx(2 * np.pi * 540.0)
    assert np.all(np.diff(r.omega[-20:]) > 0)


def test_resume_refuses_an_unreadable_file(deck, tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "frf.h5").write_bytes(b"not HDF5 at all")
    assert main(["run", str(deck), "--out", str(out), "--quiet", "--resume"]) == 2
    err = capsys.readouterr().err
    assert "cannot be read as HDF5" in err and "run without --resume" in err


@pytest.mark.slow
def test_exit_code_3_says_where_and_why(deck, tmp_path, capsys):
    """A continuation that stops at its minimum step exits 3 with the frequency and the
    reason; the points are kept; --resume with the same deck stops at the same point."""
    deck.write_text(deck.read_text().replace(
        "[continuation]\n", "[continuation]\nmin_step = 0.02\n").replace(
        'formulation = "condensed"', 'formulation = "condensed"\nmax_iterations = 3'))
    out = tmp_path / "out"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        assert main(["run", str(deck), "--out", str(out), "--quiet"]) == 3
        err = capsys.readouterr().err
        first = FRF.load(out / "frf.h5")
        assert "stopped before the end of its range at" in err and "Hz after" in err
        assert "continuation stopped" in err and "exit code 3" in err
        assert "the same deck resumed stops at the same place" in err
        assert not first.complete and 0 < len(first)
        assert main(["run", str(deck), "--out", str(out), "--quiet", "--resume"]) == 3
    _same(FRF.load(out / "frf.h5"), first, "resumed failure")


def test_help_documents_exit_codes(capsys):
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    text = capsys.readouterr().out
    for code in ("0 ", "2 ", "3 ", "130"):
        assert f"\n  {code}" in text, code


@pytest.mark.slow
def test_resume_exact_when_the_solver_carries_its_lu(tmp_path):
    """A large condensed system carries its LU (the GMRES preconditioner) from point to
    point and across calls into Fortran; a checkpoint keeps what that LU depends on (the
    unknowns, parameter and contact history of the Jacobian it factorises, and the
    counters that decide the next one: Run.lu_state), the resume factorises it again, and
    the run killed and resumed gives the uninterrupted points bit for bit. Random reduced
    model (cases/bench/condensed.py): 60 normal1d contacts, 360 modes, 840 unknowns, large
    enough that Fortran holds the LU (checked). Tolerance 0. Resumed without that state
    (a fresh LU at the checkpoint, as files from before it were kept), the points differ
    at the GMRES tolerance: the state is what makes the resume exact."""
    from condensed import F_RES, reduced_model

    from frirom import _kernels
    from frirom.solver import SolverOptions
    model, exc = reduced_model(n=360, nc=60, seed=5)
    assert _kernels.hbm_lu_holds(3, 120, 360) == 1
    out = np.arange(4)
    opts = SolverOptions(harmonics=3, samples=64, max_points=34, refine_peak=False,
                         stability=False)
    w0, w1 = 2 * np.pi * F_RES * 0.99, 2 * np.pi * F_RES * 1.01

    def writer(path, append=False):
        return FRFWriter(path, out, ["interface"], 3, append=append)

    def run(sink, start=None):
        return frf(model, exc, w0, w1, opts, outputs=out, sink=sink, start=start)
    full, ref, path = run_then_kill(run, writer, tmp_path, 15)
    assert len(ref) == 34 and full.timings["krylov_iterations"] > 0
    start = FRFWriter.resume_point(path)
    assert start["n_points"] == 11 and start["held_lu"][0] == 1.0
    start, rest = resume_into(run, writer, path)
    _same(FRF.load(path), ref, "resumed with a carried LU")
    # a tampered state is refused by name, not used (a flag of -1 made GMRES run on a
    # Jacobian never formed: tests/fuzz_capi.c found it through the C checkpoint)
    from frirom import FriromError
    for at, junk in ((7, -1.0), (0, 0.5), (3, -2.0)):
        bad = dict(start, held_lu=start["held_lu"].copy())
        bad["held_lu"][at] = junk
        with pytest.raises(FriromError, match="held LU state"):
            frf(model, exc, w0, w1, opts, outputs=out, start=bad)
    # the same resume with a fresh LU: not the uninterrupted path (7.9e-13 off with one
    # BLAS thread; at point 21 the fresh LU happens to give the same path)
    del start["held_lu"]
    fresh = frf(model, exc, w0, w1, opts, outputs=out, start=start)
    n = min(len(fresh), len(ref) - 11)
    assert np.max(np.abs(fresh.X[:n] - ref.X[11:11 + n])) > 0.0
