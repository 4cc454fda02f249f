"""The command line.

`frirom run` on the bundled joint deck: files written, resume after an interruption
gives the same curve as an uninterrupted run, clear errors for bad decks.
`frirom demo` writes its figures and a CSV whose harmonics carry the closed-form Jenkins
energy (4 mu N (A - mu N/kt), within 1e-4 at N = 512: <= 10/N^2 relative from the
sampling, see test_contact)."""

import csv
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

from _models import resume_refuses_changed_mu_and_h
from frirom.cli import main
from frirom.deck import load_deck
from frirom.results import FRF
from frirom.solver import solve_point

ROOT = Path(__file__).resolve().parents[1]
JOINT = ROOT / "cases" / "joint"


@pytest.fixture
def deck(tmp_path):
    for f in ("M.mtx", "K.mtx", "dofs.txt", "joint.toml"):
        shutil.copy(JOINT / f, tmp_path / f)
    return tmp_path / "joint.toml"


@pytest.mark.slow
def test_run_writes_results(deck, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(deck), "--out", str(out), "--quiet"]) == 0
    for f in ("frf.h5", "frf.csv", "frf.png", "states.png", "deck.toml"):
        assert (out / f).is_file(), f
    r = FRF.load(out / "frf.h5")
    assert r.complete and len(r) > 20
    f = r.omega / (2 * np.pi)
    assert f.min() == pytest.approx(400.0) and f.max() == pytest.approx(520.0)
    with open(out / "frf.csv") as fh:
        rows = list(csv.reader(fh))
    assert len(rows) == len(r) + 1 and "damper_slip" in rows[0]
    # the damper slips near resonance and sticks far from it
    assert r.state_fractions[:, 0, 1].max() > 0.2 and r.state_fractions[0, 0, 0] == 1.0
    assert "points in" in capsys.readouterr().out


@pytest.mark.slow
def test_resume_continues_an_interrupted_run(deck, tmp_path, capsys):
    """A run stopped by max_points exits 3 saying where and why; --resume with the same
    deck stops there again (max_points counts the whole run), with max_points raised (a
    change --resume allows) it goes on, and the finished file equals the uninterrupted
    run bit for bit: 61 and 121 points end calls into Fortran of the uninterrupted run
    too (1 + 10 k, SolverOptions.batch = 10), so the checkpoints are the same."""
    # no figures (test_run_writes_results checks them): the runs here only write frf.h5
    deck.write_text(deck.read_text().replace("[outputs]\n", "[outputs]\nplot = false\n"))
    full = tmp_path / "full"
    assert main(["run", str(deck), "--out", str(full), "--quiet"]) == 0
    ref = FRF.load(full / "frf.h5")
    assert len(ref) > 130
    part = tmp_path / "part"
    short = deck.with_name("short.toml")
    with warnings.catch_warnings():     # the solver's "stopped early" warning
        warnings.simplefilter("ignore", RuntimeWarning)
        for i, n in enumerate((61, 61, 121, 1000)):
            short.write_text(deck.read_text().replace("max_points = 1000",
                                                      f"max_points = {n}"))
            args = ["run", str(short), "--out", str(part), "--quiet"] + ["--resume"] * (i > 0)
            assert main(args) == (0 if n == 1000 else 3), n
            err = capsys.readouterr().err
            if n < 1000:
                assert len(FRF.load(part / "frf.h5")) == n
                assert "stopped before the end of its range at" in err and "Hz after" in err
                assert "raise continuation.max_points" in err and "exit code 3" in err
    r = FRF.load(part / "frf.h5")
    assert r.complete and len(r) == len(ref)
    for name in ("omega", "X", "amp_max", "state_fractions", "slider", "iterations", "fold"):
        np.testing.assert_array_equal(getattr(r, name), getattr(ref, name), err_msg=name)
    # every stored point is a solution of the deck: solve it afresh (from the linear
    # solution, with the contact history stored with the point: a damper stuck all cycle
    # keeps the slider where it last slipped) at a spread of the stored frequencies
    d = load_deck(deck)
    model, exc, opts = d.model(), d.excitation(), d.options()
    assert r.slider.shape == (len(r), 1) and np.all(np.isfinite(r.slider))
    for i in np.linspace(0, len(r) - 1, 12).astype(int):
        p = solve_point(model, exc, r.omega[i], opts, outputs=d.outputs,
                        start={"slider": r.slider[i]})
        assert np.allclose(p.amp_max, r.amp_max[i], rtol=1e-6), i


def test_bad_deck_gives_clear_error(deck, tmp_path, capsys):
    deck.write_text(deck.read_text().replace("mu = 0.5", "mu = -0.5"))
    assert main(["run", str(deck), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "contacts[0].mu" in err and ">= 0" in err and str(deck) in err


@pytest.mark.slow
def test_resume_refuses_a_changed_deck_after_a_few_points(deck, tmp_path, capsys):
    """The fast variant of tests/test_resume.py's test_resume_refuses_a_changed_deck: a run
    stopped at max_points after 5 points (exit 3), then --resume with another friction
    coefficient and harmonic count exits 2 naming both changes."""
    out = tmp_path / "out"
    text = deck.read_text().replace("max_points = 1000", "max_points = 5")
    deck.write_text(text)
    assert main(["run", str(deck), "--out", str(out), "--quiet"]) == 3
    capsys.readouterr()
    resume_refuses_changed_mu_and_h(deck, text, out, capsys, main)


def test_resume_without_previous_run(deck, tmp_path, capsys):
    assert main(["run", str(deck), "--out", str(tmp_path / "none"), "--resume"]) == 2
    assert "nothing to resume" in capsys.readouterr().err


@pytest.mark.slow
def test_ctrl_c_keeps_points_and_resumes(deck, tmp_path, monkeypatch, capsys):
    """An interrupt (Ctrl-C) after some points: exit code 130, the points are in frf.h5,
    and --resume finishes the curve."""
    import frirom.solver as solver
    real = solver.frf

    def interrupted(*args, sink=None, **kw):
        count = {"n": 0}

        def counting(p):
            sink(p)
            count["n"] += 1
            if count["n"] == 25:
                raise KeyboardInterrupt
        return real(*args, sink=counting, **kw)

    out = tmp_path / "out"
    monkeypatch.setattr(solver, "frf", interrupted)
    assert main(["run", str(deck), "--out", str(out), "--quiet"]) == 130
    assert "--resume" in capsys.readouterr().err
    r = FRF.load(out / "frf.h5")
    assert len(r) == 25 and not r.complete
    monkeypatch.setattr(solver, "frf", real)
    assert main(["run", str(deck), "--out", str(out), "--quiet", "--resume"]) == 0
    assert "resuming after point 21 (the last checkpoint); the 4 points after it are " \
        "computed again" in capsys.readouterr().err
    r = FRF.load(out / "frf.h5")
    assert r.complete and r.omega[-1] == pytest.approx(2 * np.pi * 520.0)
    assert np.all(np.diff(r.omega[:30]) > 0)


def test_demo_writes_figures_and_harmonics(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path)]) == 0
    for name in ("hysteresis.png", "harmonics.png", "harmonics.csv"):
        assert (tmp_path / name).stat().st_size > 1000
    rows = list(csv.reader((tmp_path / "harmonics.csv").open()))
    assert rows[0][:4] == ["case", "force", "a0", "a1"]
    kt, fs = 1.0e5, 30.0
    for row in rows[1:]:
        if row[0].startswith("jenkins"):
            amp = float(row[0].split("=")[1].split()[0])
            energy = -np.pi * amp * float(row[4])
            ref = 4 * fs * (amp - fs / kt) if amp > fs / kt else 0.0
            assert abs(energy - ref) <= 1e-4 * max(ref, 1.0)
    assert "lift-off" in capsys.readouterr().out


def test_version(capsys):
    """`frirom --version` prints exactly "frirom <version>" and exits 0, the version being
    the installed distribution's (importlib.metadata), which frirom.__version__ and
    meson.build's project() version (the one place it is written; the wheel's metadata
    and frirom.pc take it from there) must equal."""
    import importlib.metadata
    import re

    import frirom
    version = importlib.metadata.version("frirom")
    assert re.fullmatch(r"\d+\.\d+\.\d+\S*", version), version
    assert frirom.__version__ == version
    project = re.search(r"^\s*version\s*:\s*'([^']+)'", (ROOT / "meson.build").read_text(),
                        re.M)
    assert project and project.group(1) == version
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out == f"frirom {version}\n"
