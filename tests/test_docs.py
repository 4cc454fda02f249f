"""The documentation builds with warnings as errors (scripts/docs.sh: myst pages, the API
reference from the docstrings, the deck reference), its examples gallery runs, and FORD
writes the Fortran modules' reference (docs/ford.md).

Slow: a whole Sphinx build from scratch (-E) that executes every examples/plot_*.py.
"""

import importlib.util
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
HTML = ROOT / "docs" / "_build" / "html"
NEEDS = ("sphinx", "numpydoc", "myst_parser", "sphinx_gallery")


@pytest.mark.slow
@pytest.mark.skipif(any(importlib.util.find_spec(m) is None for m in NEEDS),
                    reason="needs the docs packages (requirements-dev.txt)")
def test_docs_build_without_warnings_and_gallery_runs():
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    run = subprocess.run(["bash", "scripts/docs.sh", "-E", "-D",
                          "sphinx_gallery_conf.run_stale_examples=1"], cwd=ROOT, env=env,
                         capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-4000:]
    pages = ["index", "install", "deck", "api", "theory", "benchmarks", "changelog",
             "tutorials/first_run", "tutorials/fortran_c", "cases/paper_flange"]
    for page in pages:
        assert (HTML / f"{page}.html").is_file(), page
    # every gallery script ran: its page holds the output it printed
    scripts = sorted((ROOT / "examples").glob("plot_*.py"))
    assert scripts
    for script in scripts:
        page = (HTML / "auto_examples" / f"{script.stem}.html").read_text()
        assert "sphx-glr-script-out" in page, script.name
    joint = (HTML / "auto_examples" / "plot_joint_frf.html").read_text()
    assert "tip peak" in joint and "Hz" in joint
    # the API page documents the public names from their docstrings
    api = (HTML / "api.html").read_text()
    for name in ("frirom.Model", "frirom.frf", "frirom.load_deck", "frirom.craig_bampton"):
        assert f'id="{name}"' in api, name
    # FORD: a page per Fortran module, linked from the API page, with the comments
    assert 'href="fortran/index.html"' in api
    for module in ("frirom_run", "frirom_capi", "frirom_aft", "frirom_hbm"):
        assert (HTML / "fortran" / "module" / f"{module}.html").is_file(), module
    run = (HTML / "fortran" / "module" / "frirom_run.html").read_text()
    assert "How run_start begins" in run
