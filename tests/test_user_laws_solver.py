"""User laws in the solver (frirom_user_law through the run's callback): Jenkins and
normal1d written as user laws, in Python and in C, give the built-in laws' response on
the bundled joint decks to 1e-10 at the same frequencies; a deck that names code is
refused without --allow-code."""

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from frirom import InputError, laws
from frirom.deck import load_deck
from frirom.solver import solve_point

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).resolve().parent / "data"


def _deck(tmp_path, name, law, spec):
    """The bundled deck `name` with its contact law replaced by `spec`."""
    src = ROOT / "cases" / "joint"
    for f in ("M.mtx", "K.mtx", "dofs.txt"):
        shutil.copy(src / f, tmp_path / f)
    text = (src / name).read_text()
    text, n = re.subn(rf'law = "{law}"', f'law = "{spec}"', text)
    assert n == 1
    (tmp_path / name).write_text(text)
    return tmp_path / name


def _points(deck, omegas):
    m, e, o = deck.model(), deck.excitation(), deck.options()
    return np.array([solve_point(m, e, w, o).X for w in omegas])


CASES = [("joint.toml", "jenkins", "frirom.laws:jenkins_law", 1),
         ("joint_liftoff.toml", "normal1d", "frirom.laws:normal1d_law", 2)]
# normal1d in Python at H = 9, N = 512: ~10 s a point (the march is a Python loop)
PY_CASES = [CASES[0], pytest.param(*CASES[1], marks=pytest.mark.slow)]


@pytest.mark.parametrize("name, law, spec, ndir", PY_CASES)
def test_python_user_law_deck_equals_builtin(tmp_path, name, law, spec, ndir):
    ref = load_deck(ROOT / "cases" / "joint" / name)
    user = load_deck(_deck(tmp_path, name, law, spec), allow_code=["frirom.laws"])
    w = np.linspace(ref.omega_start, ref.omega_end, 4)
    a, b = _points(ref, w), _points(user, w)
    assert np.max(np.abs(a - b)) <= 1e-10 * np.max(np.abs(a))


@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler")
@pytest.mark.parametrize("formulation", ["condensed", "banded"])
def test_c_user_law_in_solver_equals_builtin(tmp_path, formulation):
    lib = tmp_path / "userlaw.so"
    subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", str(lib), str(DATA / "userlaw.c"),
                    str(DATA / "userlaw_solver.c"), "-lm"], check=True)
    for name, law, _, ndir in CASES:
        make = laws.jenkins_law if ndir == 1 else laws.normal1d_law
        ul = laws.c_law(f"c_{law}", str(lib), f"user_{law}", make().directions,
                        make().parameters, 1, solver_symbol="solver_law")
        assert ul.native
        ref = load_deck(ROOT / "cases" / "joint" / name)
        ref.solver["formulation"] = formulation
        model = ref.model()
        w = np.linspace(ref.omega_start, ref.omega_end, 3)
        a = _points(ref, w)
        g = model.contacts[0]
        model.contacts[0] = type(g)(law=ul, G=g.G, params=g.params, w0=g.w0, name=g.name)
        o, e = ref.options(), ref.excitation()
        b = np.array([solve_point(model, e, x, o).X for x in w])
        assert np.max(np.abs(a - b)) <= 1e-10 * np.max(np.abs(a))


def test_deck_naming_code_is_refused_without_allow_code(tmp_path):
    path = _deck(tmp_path, "joint.toml", "jenkins", "frirom.laws:jenkins_law")
    with pytest.raises(InputError,
                       match=r"joint.toml: contacts\[0\].law = 'frirom.laws:jenkins_law' "
                             r"names Python code.*--allow-code frirom.laws"):
        load_deck(path)
    from frirom.cli import main
    assert main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert not (tmp_path / "o" / "frf.h5").exists()


def _peak(tmp_path, law, params):
    """Resonance (omega, amplitude of tip:x) of the joint deck with the damper's law and
    parameters replaced."""
    from frirom.solver import frf
    src = ROOT / "cases" / "joint"
    for f in ("M.mtx", "K.mtx", "dofs.txt"):
        shutil.copy(src / f, tmp_path / f)
    text = (src / "joint.toml").read_text()
    text = re.sub(r'law = "jenkins".*\n', f'law = "{law}"\n', text)
    text = re.sub(r"kt = .*\nmu = .*\nfn0 = .*\n", params, text)
    text = text.replace("stability = true", "stability = false")
    path = tmp_path / f"{law}.toml"
    path.write_text(text)
    d = load_deck(path)
    r = frf(d.model(), d.excitation(), d.omega_start, d.omega_end, d.options())
    assert r.complete, r.message
    i = int(np.argmax(r.amp_max[:, 0]))
    return r.omega[i], r.amp_max[i, 0]


def test_iwan_deck_between_stuck_and_free(tmp_path):
    """The four-parameter Iwan in microslip: its resonance lies between the linear ones of
    the joint stuck (Jenkins with a slip force beyond reach) and free (mu = 0)."""
    stuck = _peak(tmp_path, "jenkins", "kt = 1.0e7\nmu = 1.0e6\nfn0 = 100.0\n")
    free = _peak(tmp_path, "jenkins", "kt = 1.0e7\nmu = 0.0\nfn0 = 100.0\n")
    iwan = _peak(tmp_path, "iwan4", "fs = 20.0\nkt = 1.0e7\nchi = -0.5\nbeta = 0.1\n")
    assert free[0] < iwan[0] < stuck[0], (free, iwan, stuck)
    # microslip: shifted by a visible fraction of the stuck-free gap, and damped
    assert 0.02 < (stuck[0] - iwan[0]) / (stuck[0] - free[0]) < 0.98
    assert iwan[1] < min(stuck[1], free[1])


def test_python_law_that_raises_is_reported():
    from frirom import FriromError
    from frirom.model import ContactGroup, Damping, Excitation, Model

    def force(u, p, w):
        raise ValueError("no friction table for this temperature")

    law = laws.UserLaw("raising_law", ("u",), ("kt",), 0, force)
    m = Model(np.eye(1), np.eye(1), Damping.matrix(0.02 * np.eye(1)),
              [ContactGroup(law=law, G=np.eye(1), params=[[1.0]])])
    with pytest.warns(RuntimeWarning, match="raising_law.*no friction table"):
        with pytest.raises(FriromError, match="contact group 1: the user law returned 1"):
            solve_point(m, Excitation(np.array([[0.0, 0.3]], complex)), 1.0)
