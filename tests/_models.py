"""Models, decks and reference helpers that several test files share (tests import these
from here, never from another test file; the fixtures built on them live in conftest.py).

* the small-model references of tests/test_verification.py: a model from dense matrices,
  the resonance by a parabola vertex, the SDOF Jenkins oscillator and the peak against
  time integration (also tests/test_normal2d_hbm.py, test_steps.py);
* the Duffing oscillator of tests/test_solver_core.py (also test_peak.py);
* the deck texts of the ccx block (tests/test_reduction_deck.py, test_outputs.py,
  test_show.py, test_paper_hooks_lug.py), of the bladed sector (test_cyclic_deck.py,
  test_modes.py, test_show.py) and of the small lap joint (test_lap_joint_case.py,
  test_auto.py, test_study.py, test_timeint_implicit.py);
* the hooks case's preload and peak (test_paper_hooks.py, test_paper_hooks_lug.py).
"""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import frf, solve_point
from frirom.timeint import integrate

# ---- small models and their references ---------------------------------------------------


def model_of(M, C, K, law, G, params):
    """A Model of dense (M, C, K) and one contact group of the given law."""
    group = ContactGroup(law=law, G=np.asarray(G, float), params=np.atleast_2d(params),
                         name=law)
    return Model(M, K, Damping.matrix(C), [group])


def vertex(x, y):
    """Vertex (x*, y*) of the parabola through three points."""
    a, b, c = np.polyfit(x, y, 2)
    xs = -b / (2 * a)
    return xs, np.polyval([a, b, c], xs)


def peak_of(omega, amp):
    """Resonance frequency and amplitude: parabola through the highest point and its
    neighbours (points sorted by frequency)."""
    o = np.argsort(omega)
    omega, amp = np.asarray(omega)[o], np.asarray(amp)[o]
    i = int(np.clip(np.argmax(amp), 1, omega.size - 2))
    return vertex(omega[i - 1:i + 2], amp[i - 1:i + 2])


def first_harmonic(X):
    """Complex first harmonic a1 - i b1 from real coefficients (..., 2H+1)."""
    return X[..., 1] - 1j * X[..., 2]


# SDOF with a Jenkins element
J_M, J_K, J_C = np.eye(1), np.eye(1), 0.02 * np.eye(1)
J_PAR = [2.0, 0.2, 1.0]          # kt, mu, fn0: slip force 0.2, stuck frequency sqrt(3)
J_F = np.array([[0.0, 0.3]], complex)   # 90 % slip at the peak, 5x below the free one


def run_frf(model, excitation, w0, w1, opts):
    """frf plus the converged points (with their unknowns, to restart from)."""
    points = []
    r = frf(model, excitation, w0, w1, opts, sink=points.append)
    return {"model": model, "excitation": excitation, "opts": opts, "frf": r,
            "points": points}


def compare_peak(run, out, M, C, K, contacts, F):
    """Resonance (omega, max amplitude) of the HBM and of time integration, both on the
    same 0.05 %-spaced grid around the continuation's peak (HBM by solve_point restarted
    from the nearest continuation point). The frequency is the vertex of the first-harmonic
    magnitude (exact on both sides), the amplitude the vertex of max |x(t)|."""
    r, pts = run["frf"], run["points"]
    w_c, _ = peak_of(r.omega, np.abs(first_harmonic(r.X[:, out])))
    grid = w_c * (1 + 5e-4 * np.arange(-12, 13))
    hb = []
    for w in grid:
        near = pts[int(np.argmin(np.abs(r.omega - w)))]
        hb.append(solve_point(run["model"], run["excitation"], w, run["opts"],
                              start={"unknowns": near.unknowns}))
    hX = np.array([p.X[out] for p in hb])
    w_h, _ = peak_of(grid, np.abs(first_harmonic(hX)))
    _, a_h = peak_of(grid, np.array([p.amp_max[out] for p in hb]))
    ti = integrate(M, C, K, contacts, F, grid, H=5, periods=800, tol=2e-6,
                   steps_per_period=512)
    assert ti.drift.max() < 1e-5, ti.drift.max()
    w_t, _ = peak_of(grid, np.abs(first_harmonic(ti.harmonics[:, out])))
    _, a_t = peak_of(grid, ti.amp_max[:, out])
    assert grid[1] < w_t < grid[-2], "time-integration peak not inside the grid"
    assert grid[1] < w_h < grid[-2], "refined HBM peak not inside the grid"
    return (w_h, a_h), (w_t, a_t), ti


def duffing():
    """Unit-mass Duffing oscillator x'' + 0.02 x' + x + 0.5 x^3 = 0.1 cos(w t)."""
    G = sp.csr_matrix(np.array([[1.0]]))
    model = Model(np.eye(1), np.eye(1), Damping.rayleigh(0.0, 0.02),
                  [ContactGroup("cubic", G, [[0.0, 0.5]], name="duffing")])
    return model, Excitation(np.array([[0.0, 0.1]], complex))


# ---- the ccx block (cases/models/block.py) with a GSI interface --------------------------

GSI_DECK = """
[fe_model]
format = "calculix"
job = "block"

[reduction]
interface = "IFACE"
active = ["ACTIVE"]
fixed_interface_modes = 30

[reduction.interface_modes]
method = "gsi"
free = 6
stick = 6

[[contacts]]
name = "end"
law = "normal2d"
a = "IFACE"
b = "ground"
normal = [1.0, 0.0, 0.0]
kt = {kt}
kn = 8.0e8
mu = {mu}
n0 = 100.0

[damping]
type = "modal"
zeta = 0.01

[[excitation.load]]
dof = "ACTIVE:z"
amplitude = 1.0

[solver]
harmonics = {h}

[frequency]
start = 100.0
end = 200.0

[outputs]
dofs = ["ACTIVE:z", "ACTIVE:x"]
"""

#: the block of GSI_DECK (CB + GSI: the interface DoFs are not coordinates), two
#: harmonics, few samples, 140..160 Hz: a few seconds per run; {outputs} a TOML list
OUTPUTS_DECK = (GSI_DECK.format(kt="2.0e8", h=2, mu=0.5)
                .replace("harmonics = 2", "harmonics = 2\nsamples = 64")
                .replace("start = 100.0\nend = 200.0", "start = 140.0\nend = 160.0")
                .replace('dofs = ["ACTIVE:z", "ACTIVE:x"]', "plot = false\ndofs = {outputs}"))


# ---- one sector of ccx's bladed disk (cases/models/bladed_sector.py) ----------------------

N_SEC = 12

CYCLIC_DECK = """
[fe_model]
format = "calculix"
job = "{job}"

[reduction]
interface = {interface}
active = "TIP"
{cb}
cache = "{cache}"
{reduction_extra}

[reduction.cyclic]
sectors = {sectors}
left = "LEFT"
right = "RIGHT"
engine_order = 2
{cyclic_extra}

[[contacts]]
name = "flange"
law = "normal2d"
a = "{contact_set}"
normal = [0.0, 0.0, -1.0]
kt = {kp}
kn = {kp}
mu = 1.0e3
n0 = 1.0e6
{contact_extra}

[damping]
type = "modal"
zeta = 0.005

[[excitation.load]]
dof = "TIP:z"
amplitude = 1.0
{excitation_extra}

[solver]
harmonics = {h}
{solver_extra}

[frequency]
start = 600.0
end = 720.0

[outputs]
dofs = ["TIP:z"]
"""

CYCLIC_BASE = dict(job="inner/sector", interface='"FLANGE_C"',
                   cb="fixed_interface_modes = 30", cache="inner.rom.h5", reduction_extra="",
                   sectors=N_SEC, cyclic_extra="", contact_set="FLANGE_C", kp="1.0e13",
                   contact_extra="", excitation_extra="", h=3, solver_extra="")


def write_cyclic_deck(folder, name="deck.toml", **kw):
    """CYCLIC_DECK with CYCLIC_BASE's fields, those given replaced, written to folder/name."""
    p = Path(folder) / name
    p.write_text(CYCLIC_DECK.format(**{**CYCLIC_BASE, **kw}))
    return p


# ---- the lap joint of cases/lap_joint, small (conftest.py: lap_joint_mesh) ----------------


def copy_job(src, dst, job="lap"):
    """Copy ccx's files of ``job`` (.inp/.sti/.mas/.dof...) from folder src to folder dst
    (made if missing); returns dst."""
    dst = Path(dst)
    dst.mkdir(parents=True, exist_ok=True)
    for f in Path(src).glob(f"{job}.*"):
        shutil.copy(f, dst / f.name)
    return dst


def small_lap_joint_deck(n_modes: int | None, mu: str = "0.3") -> str:
    """The case's deck, small; n_modes None: CB only (no interface reduction)."""
    from convergence import deck_text          # cases/lap_joint/convergence.py
    return deck_text(n_modes, 1, [
        ('dof = "ACTIVE:z"\namplitude = 20.0', 'dof = "ACTIVE:z"\namplitude = 12.0'),
        ("amplitude = 20.0", "amplitude = 32.0"), ("amplitude = -20.0", "amplitude = -32.0"),
        ("n0 = 20.0", "n0 = 32.0"), ("samples = 32", "samples = 16"),
        ("start = 700.0", "start = 825.0"), ("end = 1000.0", "end = 880.0"),
        ("mu = 0.3", f"mu = {mu}")])


# ---- the vane with hooks of cases/paper_hooks, coarse ------------------------------------

#: the preload with the most slip in the coarse family (40 % of the hooks' cycle at the
#: peak): where the interface modes and the lug are tested hardest
HOOKS_F0 = 1000.0


def hooks_peak(rom, f0):
    """((frequency, amplitude) of the peak, FRF) of a paper_hooks.Rom at preload f0 [N];
    the FRF must be complete and warning-free."""
    import paper_hooks as ph                   # cases/paper_hooks/paper_hooks.py
    rom.set_preload(f0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # an early stop is a failure here
        res, _ = rom.frf()
    assert res.complete
    return ph._peak(res), res


# ---- the bundled joint (cases/joint), coarse: the study and trust tests' deck ---------

_COARSE_JOINT = """title = "joint, coarse"
[model]
format = "mtx"
mass = "M.mtx"
stiffness = "K.mtx"
dof_labels = "dofs.txt"
[damping]
type = "modal"
zeta = 0.003
[[excitation.load]]
dof = "tip:x"
amplitude = 2.0
[[contacts]]
name = "damper"
law = "jenkins"
elements = [ { a = ["platform:x", "platform:y"], b = "ground" } ]
directions = [ [0.8660254037844386, 0.5] ]
kt = 1.0e7
mu = 0.5
fn0 = 100.0
[solver]
harmonics = 1
samples = 16
[frequency]
start = 440.0
end = 500.0
[continuation]
step = {step}
max_step = {max_step}
[outputs]
dofs = ["tip:x", "platform:x"]
plot = false
"""


def coarse_joint_deck(step: str = "0.05", max_step: str = "STEP") -> str:
    """The joint deck (matrices K.mtx, M.mtx, dofs.txt beside it) at H = 1, 16 samples,
    440-500 Hz, outputs tip:x and platform:x, no plot; step and max_step as written into
    [continuation] (the default 'STEP' is a placeholder the study tests replace)."""
    return _COARSE_JOINT.replace("{step}", step).replace("{max_step}", max_step)


def resume_refuses_changed_mu_and_h(deck, text: str, out, capsys, main) -> str:
    """Write `text` with mu 0.5 -> 0.4 and harmonics 5 -> 6 to deck, run `frirom run
    --resume` into out (after a run that stopped early there): it must exit 2 naming both
    changes. Returns the error text."""
    deck.write_text(text.replace("mu = 0.5", "mu = 0.4").replace("harmonics = 5",
                                                                  "harmonics = 6"))
    assert main(["run", str(deck), "--out", str(out), "--quiet", "--resume"]) == 2
    err = capsys.readouterr().err
    assert "the deck changed" in err and "contacts[0].mu: 0.5 then, 0.4 now" in err
    assert "solver.harmonics: 5 then, 6 now" in err
    return err


class Killed(BaseException):
    """Raised by a sink to stop a run as a kill would (not an Exception: nothing in the
    library may catch it)."""


def run_then_kill(run, writer, folder, kill_after: int):
    """The same run twice into HDF5 files of ``folder``: uninterrupted into ref.h5, then
    killed when cut.h5 holds ``kill_after`` points (the file left "running", as after
    SIGKILL). run(sink, start=None) is frf with a sink; writer(path, append) an FRFWriter.
    Returns (the uninterrupted result, ref.h5 loaded, cut.h5's path)."""
    import pytest

    from frirom.results import FRF
    w = writer(folder / "ref.h5", False)
    full = run(w.append)
    w.close(full.complete, full.message)
    ref = FRF.load(folder / "ref.h5")
    path = folder / "cut.h5"
    w = writer(path, False)

    def dying(p):
        if w._commit[0] == kill_after:
            raise Killed
        w.append(p)
    with pytest.raises(Killed):
        run(dying)
    w.f.close()
    return full, ref, path


def resume_into(run, writer, path):
    """Resume the killed run of ``path`` from its last checkpoint into the same file:
    (the start it resumed from, the result of the rest)."""
    from frirom.results import FRFWriter
    start = FRFWriter.resume_point(path)
    w = writer(path, True)
    rest = run(w.append, start)
    w.close(rest.complete, rest.message)
    return start, rest
