"""Every command and code block of README.md is run by a test, and its links resolve.

- The two commands are those .ci/run runs (CI runs them on every submission).
- The Python example runs as a script; its peak must lie between the model's linear
  resonances with the friction element free and stuck (scipy's eigenvalues, independent
  of frirom), and the curve must start and end at the range's ends.
- The Fortran/C block is run by tests/test_install.py (slow: it builds the library).
- A block of any other kind fails `test_every_block_is_run`, so a new block needs a test.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import scipy.linalg as sl

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
import readme_program

BLOCKS = readme_program.blocks(README)


def ci_commands() -> list[str]:
    """The commands .ci/run runs after changing to the repository root."""
    lines = [ln.strip() for ln in (ROOT / ".ci" / "run").read_text().splitlines()]
    return [ln for ln in lines if ln.startswith("bash ")]


def kind(block) -> str:
    """Which test runs a README block: 'ci', 'python' or 'install' ('' for none)."""
    if block.lang == "python":
        return "python"
    if block.lang == "sh" and readme_program.commands(block) == ci_commands():
        return "ci"
    if block.lang == "sh" and "examples/frf_joint.f90" in block.code:
        return "install"
    return ""


def test_every_block_is_run():
    untested = [f"README.md:{b.line} ({b.lang})" for b in BLOCKS if not kind(b)]
    assert not untested, f"blocks no test runs: {untested}"
    assert sorted(kind(b) for b in BLOCKS) == ["ci", "install", "python"]


def test_two_commands_are_what_ci_runs():
    first = next(b for b in BLOCKS if b.lang == "sh")
    assert readme_program.commands(first) == ["bash scripts/setup.sh", "bash scripts/test.sh"]
    assert ci_commands() == readme_program.commands(first)


def test_readme_is_a_front_door():
    """At most ~150 lines, and no commit hashes (history lives in CHANGELOG.md)."""
    text = README.read_text()
    assert len(text.splitlines()) <= 150
    hashes = re.findall(r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}\b", text)
    assert not hashes, f"commit hashes in the README: {hashes}"


def test_links_resolve():
    text = README.read_text()
    links = re.findall(r"\]\(([^)#]+)\)", text)
    assert links, "no links found"
    missing = [ln for ln in links if "://" not in ln and not (ROOT / ln).exists()]
    assert not missing, f"README links to missing files: {missing}"


def test_python_example_runs(tmp_path):
    code = next(b for b in BLOCKS if b.lang == "python").code
    script = tmp_path / "example.py"
    script.write_text(code)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", MPLBACKEND="Agg")
    out = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env, check=True,
                         capture_output=True, text=True, timeout=120).stdout
    m = re.fullmatch(r"(\d+) points, peak (\S+) m at (\S+) Hz\n", out)
    assert m, out
    n, amp, f_peak = int(m[1]), float(m[2]), float(m[3])
    # the example's model, linear limits: the Jenkins element free (no spring) and stuck
    # (kt on the first mass)
    K = np.array([[3e6, -1e6], [-1e6, 1e6]])
    M = np.diag([0.05, 0.02])
    f_free = np.sqrt(sl.eigh(K, M, eigvals_only=True)[0]) / (2 * np.pi)
    K[0, 0] += 1e6
    f_stuck = np.sqrt(sl.eigh(K, M, eigvals_only=True)[0]) / (2 * np.pi)
    assert f_free < f_peak < f_stuck, (f_free, f_peak, f_stuck)
    assert n > 20 and amp > 0


def test_one_version():
    """meson.build holds the version; the package metadata, frirom.__version__ and the
    CLI read it, and pyproject.toml does not write it."""
    import frirom
    written = re.findall(r"^\s*version: '([^']+)'", (ROOT / "meson.build").read_text(), re.M)
    assert len(written) == 1
    assert frirom.__version__ == written[0]
    pyproject = (ROOT / "pyproject.toml").read_text()
    assert 'dynamic = ["version"]' in pyproject
    assert not re.search(r"^version\s*=", pyproject, re.M)
    out = subprocess.run([sys.executable, "-m", "frirom.cli", "--version"], check=True,
                         capture_output=True, text=True).stdout
    assert out.strip() == f"frirom {written[0]}"


def test_licence_and_citation_files():
    import yaml
    for name in ("LICENSE", "NOTICE", "CITATION.cff", "CHANGELOG.md", "CONTRIBUTING.md"):
        assert (ROOT / name).is_file(), name
    assert "BSD 3-Clause" in (ROOT / "LICENSE").read_text()
    assert "FFTW" in (ROOT / "NOTICE").read_text()
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0" and cff["license"] == "BSD-3-Clause"
    doi = cff["preferred-citation"]["doi"]
    assert f"doi:{doi}" in README.read_text()
