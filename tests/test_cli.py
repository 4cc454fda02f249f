"""The command line: `frirom demo` writes its figures and a CSV whose harmonics carry the
closed-form Jenkins energy (4 mu N (A - mu N/kt), within 1e-4 at N = 512: <= 10/N^2
relative from the sampling, see test_contact)."""

import csv

import numpy as np

from frirom.cli import main


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
