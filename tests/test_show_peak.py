"""`frirom show --peak` when the peak's solve fails (issue 29 item 5): it falls back to the
highest stored point and names the frequency it tried, instead of stopping with a bare
"newton_correct: no convergence"."""

import os
import re
import shutil
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest

import frirom.show
from frirom._errors import ConvergenceError
from frirom.cli import main
from frirom.results import FRF

JOINT = Path(__file__).resolve().parents[1] / "cases" / "joint"


@pytest.mark.slow
def test_show_peak_falls_back_to_the_highest_stored_point(tmp_path, monkeypatch, capsys):
    for f in ("M.mtx", "K.mtx", "dofs.txt"):
        shutil.copy(JOINT / f, tmp_path / f)
    text = (JOINT / "joint.toml").read_text()
    text = re.sub(r"start = 400.0\nend = 520.0", "start = 455.0\nend = 480.0", text)
    text = text.replace("stability = true", "stability = false")
    (tmp_path / "j.toml").write_text(text)
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "j.toml"), "--out", str(out), "--quiet"]) == 0
    r = FRF.load(out / "frf.h5")
    k = int(np.argmax(r.amp_max[:, 0]))
    peak = r.peak(0)
    assert peak.omega not in r.omega          # the solved peak lies between points
    real = frirom.show.point_state

    def failing(frf, deck, i, omega):         # the peak's re-solve fails, as in issue 29
        if omega not in frf.omega:
            raise ConvergenceError("newton_correct: no convergence")
        return real(frf, deck, i, omega)
    monkeypatch.setattr(frirom.show, "point_state", failing)
    capsys.readouterr()
    assert main(["show", str(out), "--peak", "--dir", str(tmp_path / "pt")]) == 0
    io = capsys.readouterr()
    assert (f"the peak of tip:x at {peak.omega / 2 / np.pi:.6g} Hz could not be solved "
            "again (newton_correct: no convergence)") in io.err, io.err
    assert f"point {k} at {r.omega[k] / 2 / np.pi:.6g} Hz" in io.err
    assert f"point {k} solved at {r.omega[k] / 2 / np.pi:.6g} Hz" in io.out
    assert (tmp_path / "pt" / "hysteresis.csv").is_file()


def test_cli_turns_python_warnings_into_frirom_lines(monkeypatch, capsys):
    # A frirom warning and a numpy RuntimeWarning during a command reach the terminal as
    # one "frirom: warning:" line each, frequencies also in Hz, no Python source line.
    import warnings

    import frirom.cli

    def cmd(args):
        warnings.warn("frirom: continuation stopped early: the range through omega = "
                      "2950.3 rad/s", RuntimeWarning)
        np.log(np.zeros(1))                    # numpy: divide by zero in log
        return 0
    monkeypatch.setattr(frirom.cli, "cmd_show", cmd)
    assert main(["show", "somewhere"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err[0] == ("frirom: warning: continuation stopped early: the range through "
                      f"omega = 2950.3 rad/s ({2950.3 / 2 / np.pi:.6g} Hz)"), err
    assert err[1].startswith("frirom: warning: numerical: divide by zero encountered in "
                             "log (at test_show_peak.py:"), err
    assert len(err) == 2


def test_cli_error_gives_frequencies_in_hz(monkeypatch, capsys):
    import frirom.cli
    from frirom._errors import ConvergenceError

    def cmd(args):
        raise ConvergenceError("continuation: step below ds_min at omega = 2950.3 rad/s")
    monkeypatch.setattr(frirom.cli, "cmd_show", cmd)
    assert main(["show", "somewhere"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith(f"at omega = 2950.3 rad/s ({2950.3 / 2 / np.pi:.6g} Hz)"), err
