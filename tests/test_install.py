"""The plain meson install serves legacy Fortran codes: library, .mod files, frirom.pc.

Runs the README's Fortran/C block (the library alone, -Dpython=false, into $HOME/.local,
HOME a temporary folder), then compiles and runs
Fortran programs that `use` frirom_aft and frirom_eigen and link with `pkg-config
--cflags --libs frirom`, as a legacy code's makefile would. They check a stuck Jenkins
element against the linear spring (exact) and the first eigenvalue of a spring chain
against its closed form (1e-10; ARPACK + MUMPS through the static library). The whole-solve
programs of examples/ (frf_joint.f90 through frirom_solve, frf_joint.c through frirom.h)
are built by the README's own commands and must reproduce the Python FRF of the joint deck
(tests/capi_compare.py: same points; 1e-8 here, where the library is built again by the
README's commands with their own compiler flags: measured 7.2e-10, the round-off of
differently compiled arithmetic carried along 164 points; the meson test on the build
Python uses holds 1e-12); no test program is built or installed by a
plain build.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

LEGACY = """\
program legacy
    use frirom_kinds, only: wp, ip
    use frirom_aft, only: aft_plan, aft_plan_create, aft_plan_destroy, aft_eval, LAW_JENKINS
    implicit none
    type(aft_plan) :: plan
    integer(ip) :: info
    real(wp) :: x(3, 1, 1), p(3, 1), w0(1, 1), f(3, 1, 1)
    character(len=200) :: msg
    x = 0.0_wp
    x(2, 1, 1) = 1.0e-4_wp
    p(:, 1) = [1.0e5_wp, 0.3_wp, 100.0_wp]
    w0 = 0.0_wp
    call aft_plan_create(plan, 1_ip, 64_ip, info, msg)
    call aft_eval(plan, LAW_JENKINS, x, p, w0, f, info, msg)
    if (info /= 0) error stop 'aft_eval failed'
    if (abs(f(2, 1, 1) - 10.0_wp) > 1.0e-9_wp) error stop 'stuck element is not kt u'
    print '(a,es12.5)', 'legacy ok ', f(2, 1, 1)
    call aft_plan_destroy(plan)
end program legacy
"""


LEGACY_EIGEN = """\
program legacy_eigen
    use frirom_kinds, only: wp, ip
    use frirom_eigen, only: eigen_work, eigen_factor, eigen_modes, eigen_destroy
    implicit none
    integer(ip), parameter :: n = 40
    type(eigen_work) :: work
    integer(ip) :: info, i, krow(2*n - 1), kcol(2*n - 1), mrow(n), mptr(n + 1), mind(n)
    real(wp) :: kval(2*n - 1), mval(n), lam(3), phi(n, 3), exact
    character(len=200) :: msg
    ! fixed-fixed spring chain, k = m = 1: lambda_j = 2 - 2 cos(j pi / (n + 1))
    do i = 1, n
        krow(i) = i
        kcol(i) = i
        kval(i) = 2.0_wp
        mrow(i) = i
        mval(i) = 1.0_wp
        mptr(i) = i
        mind(i) = i
    end do
    mptr(n + 1) = n + 1
    do i = 1, n - 1
        krow(n + i) = i
        kcol(n + i) = i + 1
        kval(n + i) = -1.0_wp
    end do
    call eigen_factor(work, n, krow, kcol, kval, mrow, mrow, mval, 0.0_wp, info, msg)
    if (info /= 0) error stop 'eigen_factor failed'
    call eigen_modes(work, mptr, mind, mval, 3_ip, lam, phi, info, msg)
    if (info /= 0) error stop 'eigen_modes failed'
    exact = 2.0_wp - 2.0_wp*cos(acos(-1.0_wp)/(n + 1))
    if (abs(lam(1) - exact) > 1.0e-10_wp*exact) error stop 'first eigenvalue wrong'
    print '(a,es12.5)', 'legacy eigen ok ', lam(1)
    call eigen_destroy(work)
end program legacy_eigen
"""


def _tool(name):
    here = Path(sys.executable).parent / name
    return str(here) if here.exists() else shutil.which(name)


def _source_copy(dest: Path) -> None:
    """The working tree as git sees it (tracked and new files, not ignored ones)."""
    files = subprocess.run(["git", "ls-files", "-z", "--cached", "--others",
                            "--exclude-standard"], cwd=ROOT, check=True,
                           capture_output=True).stdout.decode().split("\0")
    for name in filter(None, files):
        src = ROOT / name
        if src.is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / name)


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("gfortran") is None or shutil.which("pkg-config") is None
                    or shutil.which("cc") is None or shutil.which("git") is None,
                    reason="needs gfortran, cc, pkg-config and git")
def test_readme_fortran_c_block_and_legacy_programs(tmp_path):
    """The README's Fortran/C block, run as written in a copy of the tree with HOME in
    tmp_path: it installs the library into $HOME/.local and builds examples/frf_joint.f90
    and examples/frf_joint.c, which must reproduce the Python FRF (capi_compare). Then
    legacy programs link the same install through pkg-config."""
    import capi_compare
    import readme_program
    block = next(b for b in readme_program.blocks(ROOT / "README.md")
                 if b.lang == "sh" and "examples/frf_joint.f90" in b.code)
    src, home = tmp_path / "src", tmp_path / "home"
    _source_copy(src)
    home.mkdir()
    env = dict(os.environ, HOME=str(home), OPENBLAS_NUM_THREADS="1",
               PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    env.pop("PKG_CONFIG_PATH", None)
    run = subprocess.run(["bash", "-euo", "pipefail", "-c", block.code], cwd=src, env=env,
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert run.stdout.count("complete") == 2, run.stdout[-2000:]
    exe_f, exe_c = src / "build" / "frf_joint", src / "build" / "frf_joint_c"
    assert capi_compare.main([str(exe_f), str(exe_c)], tol=1e-8) == 0

    prefix = home / ".local"
    pcs = list(prefix.rglob("frirom.pc"))
    assert pcs == [prefix / "lib" / "pkgconfig" / "frirom.pc"], pcs   # README's path
    assert (prefix / "include" / "frirom" / "frirom_aft.mod").exists()
    assert (prefix / "include" / "frirom" / "frirom.h").exists()
    assert (prefix / "include" / "frirom" / "frirom_solve.mod").exists()
    env["PKG_CONFIG_PATH"] = str(pcs[0].parent)
    flags = subprocess.run(["pkg-config", "--cflags", "--libs", "frirom"], check=True,
                           env=env, capture_output=True, text=True).stdout.split()
    for name, text, expect in (("legacy", LEGACY, "legacy ok"),
                               ("legacy_eigen", LEGACY_EIGEN, "legacy eigen ok")):
        f90 = tmp_path / f"{name}.f90"
        f90.write_text(text)
        exe = tmp_path / name
        subprocess.run(["gfortran", str(f90), "-o", str(exe)] + flags, check=True, env=env)
        out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
        assert expect in out
    # no test program is installed or built by `meson install`
    assert not list(prefix.rglob("test_*"))
    assert not list((src / "build" / "lib").rglob("test_aft"))
