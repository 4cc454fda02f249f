"""The benchmarks' results file (cases/bench/_results.py): what a benchmark printed, as
data, with the machine, the commit and the date."""

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_a_benchmark_run_writes_its_table_ratios_and_last_line(tmp_path):
    script = tmp_path / "toy.py"
    script.write_text(
        "import sys\n"
        f"sys.path.insert(0, {str(ROOT / 'cases' / 'bench')!r})\n"
        "from _results import add, record\n"
        "def main():\n"
        "    print('case        frirom s   numpy s   speed-up')\n"
        "    print('small         0.125     2.5       20.0x')\n"
        "    print('large         1.5e-3    0.3       200x')\n"
        "    add(points=104)\n"
        "    print('largest speed-up 200x at 1 000 elements')\n"
        "    return 3\n"
        "if __name__ == '__main__':\n"
        "    sys.exit(record('toy', main))\n")
    run = subprocess.run([sys.executable, str(script), "--quick"], capture_output=True,
                         text=True, env=dict(os.environ, FRIROM_BENCH_RESULTS=str(tmp_path)))
    assert run.returncode == 3, run.stderr
    assert "speed-up 200x" in run.stdout          # the output still reaches the terminal
    doc = json.loads((tmp_path / "toy.json").read_text())
    assert doc["benchmark"] == "toy" and doc["argv"] == ["--quick"] and doc["exit"] == 3
    assert doc["rows"][0] == {"header": ["case", "frirom s", "numpy s", "speed-up"],
                              "cells": ["small", 0.125, 2.5, "20.0x"]}
    assert doc["rows"][1]["cells"][1] == 1.5e-3
    assert [r["ratio"] for r in doc["ratios"]] == [20.0, 200.0, 200.0]
    assert doc["last"] == "largest speed-up 200x at 1 000 elements"
    assert doc["data"] == {"points": 104}
    assert len(doc["commit"]) == 40 and doc["date"].endswith("+00:00")
    assert doc["machine"]["cpus"] >= 1 and len(doc["machine"]["load"]) == 3


def test_without_git_the_file_is_written_without_a_commit(tmp_path, monkeypatch):
    sys.path.insert(0, str(ROOT / "cases" / "bench"))
    import _results
    monkeypatch.setenv("PATH", "")
    out = _results.write("nogit", ["a  1.0"], [], 0.5, 0, tmp_path / "n.json")
    doc = json.loads(out.read_text())
    assert doc["commit"] is None and doc["dirty"] is None and doc["rows"][0]["cells"] == ["a", 1.0]
