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
def test_resume_continues_an_interrupted_run(deck, tmp_path):
    # no figures (test_run_writes_results checks them): the runs here only write frf.h5
    deck.write_text(deck.read_text().replace("[outputs]\n", "[outputs]\nplot = false\n"))
    full = tmp_path / "full"
    assert main(["run", str(deck), "--out", str(full), "--quiet"]) == 0
    ref = FRF.load(full / "frf.h5")
    # the same deck with few points per call: each run stops early, --resume goes on
    short = deck.with_name("short.toml")
    short.write_text(deck.read_text().replace("max_points = 1000", "max_points = 60"))
    assert len(ref) > 120
    part = tmp_path / "part"
    assert main(["run", str(short), "--out", str(part), "--quiet"]) == 0
    first = FRF.load(part / "frf.h5")
    assert not first.complete and len(first) == 60
    for _ in range(20):
        r = FRF.load(part / "frf.h5")
        if r.complete:
            break
        with warnings.catch_warnings():     # the solver's "stopped early" warning
            warnings.simplefilter("ignore", RuntimeWarning)
            assert main(["run", str(short), "--out", str(part), "--quiet", "--resume"]) == 0
    r = FRF.load(part / "frf.h5")
    assert r.complete
    assert np.all(np.diff(r.omega) > 0)               # no repeated point at the joins
    assert r.omega[0] == ref.omega[0] and r.omega[-1] == pytest.approx(ref.omega[-1])
    # every stored point, also those after each resume, is a solution of the deck: solve
    # it afresh (from the linear solution, with the contact history stored with the point:
    # a damper stuck all cycle keeps the slider where it last slipped) at a spread of the
    # stored frequencies
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


def test_resume_without_previous_run(deck, tmp_path, capsys):
    assert main(["run", str(deck), "--out", str(tmp_path / "none"), "--resume"]) == 2
    assert "nothing to resume" in capsys.readouterr().err


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
    try:
        main(["--version"])
    except SystemExit as exc:
        assert exc.code == 0
    assert "frirom" in capsys.readouterr().out
