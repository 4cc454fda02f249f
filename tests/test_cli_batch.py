"""`frirom run` on several decks in one go (issue 12, deliverable 6): one subfolder of
--out per deck, each run exactly as the deck alone (same points: the batch only calls the
single-deck run in a loop, so the curves agree to the last bit), the same resume rules,
and an exit code that says whether every run reached the end of its range."""

import shutil
from pathlib import Path

import numpy as np
import pytest

from frirom.cli import EXIT_INPUT, EXIT_STOPPED, main
from frirom.results import FRF

JOINT = Path(__file__).resolve().parents[1] / "cases" / "joint"


@pytest.fixture
def decks(tmp_path):
    """Two variants of the joint deck (2 N and 3 N at the tip) below the resonance,
    400-440 Hz (a dozen points: fast), no plots, in tmp_path/decks."""
    folder = tmp_path / "decks"
    folder.mkdir()
    for f in ("M.mtx", "K.mtx", "dofs.txt"):
        shutil.copy(JOINT / f, folder / f)
    text = (JOINT / "joint.toml").read_text()
    text = text.replace("end = 520.0", "end = 440.0")
    text = text.replace("[outputs]\n", "[outputs]\nplot = false\n")
    (folder / "a.toml").write_text(text)
    (folder / "b.toml").write_text(text.replace("amplitude = 2.0", "amplitude = 3.0"))
    return folder


@pytest.mark.slow
def test_batch_runs_each_deck_as_alone(decks, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(decks), "--out", str(out), "--quiet"]) == 0
    alone = tmp_path / "alone"
    assert main(["run", str(decks / "b.toml"), "--out", str(alone), "--quiet"]) == 0
    a, b, ref = (FRF.load(p / "frf.h5") for p in (out / "a", out / "b", alone))
    assert a.complete and b.complete and len(b) == len(ref)
    assert np.array_equal(b.omega, ref.omega) and np.array_equal(b.amp_max, ref.amp_max)
    assert b.amp_max.max() > a.amp_max.max()        # the larger load is another run
    text = capsys.readouterr().out
    assert "[2/2]" in text and "2 of 2 runs complete" in text


@pytest.mark.slow
def test_batch_exit_code_and_resume(decks, tmp_path, capsys):
    """A deck whose run stops at max_points makes the batch exit EXIT_STOPPED while
    the other deck still runs to the end; --resume with more points completes it and
    leaves the complete one as it was (exit 0). A deck with an error: EXIT_INPUT."""
    short = decks / "b.toml"
    short.write_text(short.read_text().replace("max_points = 1000", "max_points = 4"))
    out = tmp_path / "out"
    code = main(["run", str(decks / "a.toml"), str(short), "--out", str(out), "--quiet"])
    assert code == EXIT_STOPPED
    assert FRF.load(out / "a" / "frf.h5").complete
    part = FRF.load(out / "b" / "frf.h5")
    assert not part.complete and len(part) == 4
    assert "stopped before the end of its range" in capsys.readouterr().out
    a_before = FRF.load(out / "a" / "frf.h5")
    short.write_text(short.read_text().replace("max_points = 4", "max_points = 1000"))
    assert main(["run", str(decks), "--out", str(out), "--quiet", "--resume"]) == 0
    done = FRF.load(out / "b" / "frf.h5")
    assert done.complete and np.array_equal(done.omega[:4], part.omega)
    assert np.array_equal(FRF.load(out / "a" / "frf.h5").omega, a_before.omega)
    (decks / "c.toml").write_text(short.read_text().replace("mu = 0.5", "mu = -0.5"))
    assert main(["run", str(decks), "--out", str(out), "--quiet"]) == EXIT_INPUT
    captured = capsys.readouterr()
    assert "contacts[0].mu" in captured.err and "2 of 3 runs complete" in captured.out


def test_batch_refuses_clashing_names(decks, tmp_path, capsys):
    other = tmp_path / "other"
    other.mkdir()
    shutil.copy(decks / "a.toml", other / "a.toml")
    assert main(["run", str(decks), str(other), "--quiet"]) == EXIT_INPUT
    assert "same name" in capsys.readouterr().err
    assert main(["run", str(tmp_path / "nothing.toml")]) == EXIT_INPUT
