"""User laws (frirom.laws): Jenkins and normal1d written in Python and in C equal the
built-in laws; the difference-scheme Jacobian against the analytical one; the trust rule
for laws named from a deck."""

import shutil
import subprocess

import numpy as np
import pytest

from frirom import contact, laws

N = 512


def _x(ndir, seed):
    return np.random.default_rng(seed).normal(size=(4, ndir, 7)) * 1e-4


CASES = [("jenkins", laws.jenkins_law, 1, [1e5, 1.0, 3.0], "user_jenkins", ("kt", "mu", "fn0")),
         ("normal1d", laws.normal1d_law, 2, [1e5, 1e5, 0.5, 2.0], "user_normal1d",
          ("kt", "kn", "mu", "n0"))]


@pytest.mark.parametrize("name, make, ndir, p, sym, pn", CASES)
def test_python_user_law_equals_builtin(name, make, ndir, p, sym, pn):
    x = _x(ndir, 1)
    a = contact.aft(name, x, p, n_samples=N)
    b = laws.aft(make(), x, p, n_samples=N)
    assert np.max(np.abs(a.forces - b.forces)) <= 1e-10 * np.max(np.abs(a.forces))
    # central differences vs the analytical Jacobian
    assert np.max(np.abs(a.jacobian - b.jacobian)) <= 1e-6 * np.max(np.abs(a.jacobian))


@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler")
@pytest.mark.parametrize("name, make, ndir, p, sym, pn", CASES)
def test_c_user_law_equals_builtin(tmp_path, name, make, ndir, p, sym, pn):
    lib = tmp_path / "userlaw.so"
    src = __file__.rsplit("/", 1)[0] + "/data/userlaw.c"
    subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", str(lib), src, "-lm"], check=True)
    law = laws.c_law(sym, str(lib), sym, make().directions, pn, 1)
    x = _x(ndir, 2)
    a = contact.aft(name, x, p, n_samples=N, jacobian=False)
    b = laws.aft(law, x, p, n_samples=N, jacobian=False)
    assert np.max(np.abs(a.forces - b.forces)) <= 1e-10 * np.max(np.abs(a.forces))


def test_supplied_jacobian_memoryless():
    x = _x(1, 3) * 1e3
    a = contact.aft("cubic", x, [1e5, 1e12], n_samples=64)
    b = laws.aft(laws.cubic_law(), x, [1e5, 1e12], n_samples=64)
    assert np.max(np.abs(a.forces - b.forces)) <= 1e-10 * np.max(np.abs(a.forces))
    assert np.max(np.abs(a.jacobian - b.jacobian)) <= 1e-10 * np.max(np.abs(a.jacobian))


def test_deck_code_needs_opt_in():
    with pytest.raises(laws.CodeNotAllowedError, match="--allow-code frirom.laws"):
        laws.load_law("frirom.laws:jenkins_law")
    law = laws.load_law("frirom.laws:jenkins_law", allowed=["frirom.laws"])
    assert law.name == "user_jenkins"
    with pytest.raises(laws.ParameterError, match="package.module:function"):
        laws.load_law("nocolon", allowed=["nocolon"])
