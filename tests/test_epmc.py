"""Nonlinear modes by the extended periodic motion concept (frirom.nonlinear_mode, the run
object's mode 3) against independent references.

References: the describing-function closed form of the single-DoF Jenkins oscillator
(frequency and damping of m x'' + k x + f_J(x) = xi m x' at H = 1), central finite
differences of the residual for the analytical Jacobian (d/dX, d/d omega, d/d xi,
d/d log10 a), and the phase resonances of forced responses (frirom.frf, a separate
continuation in frequency) of a two-DoF friction oscillator at light damping.
"""

import dataclasses

import numpy as np
import pytest

import frirom
from frirom import _kernels
from frirom import ParameterError
from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.nonlinear_modes import _open, linear_mode, nonlinear_mode

M1, K0, KT, MU, FN = 1.0, 1.0e4, 1.0e4, 0.5, 2.0     # slip force 1 N, slip at 0.1 mm


def jenkins_sdof():
    g = ContactGroup(law="jenkins", G=np.array([[1.0]]), params=np.array([[KT, MU, FN]]),
                     name="j")
    return Model(np.array([[M1]]), np.array([[K0]]), Damping.matrix(np.zeros((1, 1))), [g])


def describing_function(A):
    """omega, xi of the SDOF Jenkins oscillator at displacement amplitude A (H = 1):
    -m w^2 A + k A + a1(A) = 0, xi m w A + b1(A) = 0, with the closed-form first harmonic
    (a1, b1) of the Jenkins force under u = A cos (stick ends at ts)."""
    fs = MU * FN
    A = np.asarray(A, float)
    slip = A > fs / KT
    ts = np.arccos(np.clip(1.0 - 2.0 * fs / (KT * A), -1.0, 1.0))
    a1 = np.where(slip, 2 / np.pi * ((2 * fs - KT * A) * np.sin(ts)
                                     + KT * A * (ts / 2 + np.sin(2 * ts) / 4)), KT * A)
    b1 = np.where(slip, 2 / np.pi * ((fs - KT * A) * (1 - np.cos(ts))
                                     + KT * A * np.sin(ts) ** 2 / 2 - fs * (1 + np.cos(ts))),
                  0.0)
    w = np.sqrt((K0 + a1 / A) / M1)
    return w, -b1 / (M1 * A * w)


def test_jenkins_sdof_backbone_is_the_describing_function():
    """H = 1, N = 2^18 samples: frequency and damping ratio to 1e-10 of the closed form
    over stick, microslip and gross slip (the AFT's sampled transitions err by ~N^-2 ~
    1.5e-11 here), and the energy per cycle to 4 fs (A - fs/kt)."""
    opts = frirom.SolverOptions(harmonics=1, samples=2 ** 18, tol_residual=1e-13,
                                tol_update=1e-13)
    bb = nonlinear_mode(jenkins_sdof(), 0, (1e-5, 1e-2), "stuck", opts)
    assert bb.status == "done" and bb.amplitude[-1] == pytest.approx(1e-2, rel=1e-12)
    A = bb.amplitude / np.sqrt(M1)
    w, xi = describing_function(A)
    assert bb.omega0 == pytest.approx(np.sqrt((K0 + KT) / M1), rel=1e-14)
    print("max rel. error: omega", np.abs(bb.omega / w - 1).max(), "damping ratio",
          np.abs(bb.damping_ratio - xi / (2 * w)).max() / (xi / (2 * w)).max())
    assert np.abs(bb.omega / w - 1).max() < 1e-10
    assert np.abs(bb.damping_ratio - xi / (2 * w)).max() < 1e-10 * (xi / (2 * w)).max()
    slip = A > MU * FN / KT
    assert slip[-1] and not slip[0]
    energy = np.where(slip, 4 * MU * FN * (A - MU * FN / KT), 0.0)
    assert np.abs(bb.energy - energy).max() < 1e-9 * energy.max()
    # stuck at the start, slipping at the end
    assert bb.states[0, 0, 0] == pytest.approx(1.0) and bb.states[-1, 1, 0] > 0.5


def two_dof(zeta=1e-3):
    M = np.diag([1.0, 0.5])
    K = np.array([[2e4, -1e4], [-1e4, 1e4]])
    g = ContactGroup(law="jenkins", G=np.array([[1.0, 0.0]]),
                     params=np.array([[2e4, 0.3, 10.0]]), name="j")
    return Model(M, K, Damping.modal([zeta, zeta]), [g])


@pytest.mark.parametrize("formulation", ["condensed", "banded"])
@pytest.mark.parametrize("law", ["jenkins", "normal1d"])
def test_jacobian_against_central_differences(law, formulation):
    """dR/dy (harmonics, omega, xi) and dR/d log10 a of the mode run against central
    differences in microslip (H = 3), both formulations: relative 1e-6 of the largest
    entry."""
    model = two_dof()
    if law == "normal1d":
        model.contacts = [ContactGroup(law="normal1d", G=np.array([[1.0, 0.0], [0.0, 1.0]]),
                                       params=np.array([[2e4, 3e4, 0.3, 10.0]]), name="n")]
    opts = frirom.SolverOptions(harmonics=3, samples=256, formulation=formulation)
    bb = nonlinear_mode(model, 0, (1e-6, 1e-3), "stuck", opts)
    i = int(np.argmax(bb.damping_ratio))
    assert bb.damping_ratio[i] > 0.01
    o2 = dataclasses.replace(opts, formulation="banded", stability=False)
    _, run, _, _ = _open(model, 0, "stuck", o2, condensed=formulation == "condensed")
    y, lam = bb.y[i], np.log10(bb.amplitude[i])

    def res(yy, ll):
        r, rl, J, info, msg = _kernels.frun_mode_jacobian(run.handle, ll, yy)
        assert info == 0, msg
        return r, rl, J

    r, rl, J = res(y, lam)
    assert np.abs(r).max() < 1e-6 * np.abs(J).max()     # a converged point
    Jfd = np.zeros_like(J)
    for k in range(y.size):
        e = 1e-7 * max(1.0, abs(y[k]))
        Jfd[:, k] = (res(y + e * np.eye(y.size)[k], lam)[0]
                     - res(y - e * np.eye(y.size)[k], lam)[0]) / (2 * e)
    rlfd = (res(y, lam + 1e-7)[0] - res(y, lam - 1e-7)[0]) / 2e-7
    assert np.abs(J - Jfd).max() < 1e-6 * np.abs(J).max()
    assert np.abs(rl - rlfd).max() < 1e-6 * np.abs(rl).max()
    run.close()


LAW_GROUPS = {
    "normal1d": dict(G=[[1.0, 0.0], [0.0, 1.0]], params=[[2e4, 3e4, 0.3, 10.0]]),
    "cubic": dict(G=[[1.0, 0.0]], params=[[2e4, 4e12]]),
}


@pytest.mark.parametrize("law", ["jenkins", "normal1d", "cubic"])
def test_formulations_agree(law):
    """The condensed (all modes: exact) and banded mode runs end on the same point:
    frequency, damping and the harmonics of every DoF to 1e-8, at three amplitudes from
    microslip to gross slip (H = 3; a cubic spring: hardening, no damping)."""
    model = two_dof()
    if law in LAW_GROUPS:
        g = LAW_GROUPS[law]
        model.contacts = [ContactGroup(law=law, G=np.array(g["G"]),
                                       params=np.array(g["params"]), name=law)]
    for a1 in (3e-5, 1e-4, 1e-3):
        ends = []
        for formulation in ("condensed", "banded"):
            opts = frirom.SolverOptions(harmonics=3, samples=256, formulation=formulation,
                                        tol_residual=1e-11, tol_update=1e-11)
            bb = nonlinear_mode(model, 0, (1e-6, a1), "stuck", opts)
            assert bb.status == "done" and bb.amplitude[-1] == pytest.approx(a1, rel=1e-12)
            ends.append(bb)
        c, b = ends
        assert c.omega[-1] == pytest.approx(b.omega[-1], rel=1e-8)
        assert c.xi[-1] == pytest.approx(b.xi[-1], rel=1e-8, abs=1e-10 * b.omega[-1])
        assert np.abs(c.harmonics[-1] - b.harmonics[-1]).max() < 1e-8 * np.abs(
            b.harmonics[-1]).max()


def test_forced_responses_peak_on_the_backbone():
    """Phase resonance: forced responses (frirom.frf, load f M phi cos(w t), phi the
    stuck mode, modal damping 0.1 %) cross 90 degrees of phase on the backbone.

    Where the response's harmonic-1 cosine part along M phi changes sign, the frequency
    against the backbone's at the same modal amplitude. The EPMC's xi M x' equals the load
    only while the mode keeps the shape phi; slip at one DoF bends it, so the offset grows
    with the level: seen 2.4e-5, 3.1e-4, 1.3e-3, 4.4e-3 at f = 0.05, 0.2, 0.5, 1 N;
    bounds 1e-4 at the lowest level, 6e-3 at all."""
    model = two_dof()
    opts = frirom.SolverOptions(harmonics=5, samples=512, ds_max=0.02)
    bb = nonlinear_mode(model, 0, (1e-4, 1e-2), "stuck", opts)
    phi, w0 = linear_mode(model, 0, "stuck")
    M = model.M.toarray()
    errs = []
    for f in (0.05, 0.2, 0.5, 1.0):
        F = np.zeros((2, 2), complex)
        F[:, 1] = f * (M @ phi)
        r = frirom.frf(model, Excitation(F), 0.9 * bb.omega.min(), 1.05 * w0, opts)
        pc = r.X[:, :, 1] @ (M @ phi)
        k = np.flatnonzero(np.sign(pc[:-1]) != np.sign(pc[1:]))[0]
        s = pc[k] / (pc[k] - pc[k + 1])
        X = (1 - s) * r.X[k] + s * r.X[k + 1]
        w = (1 - s) * r.omega[k] + s * r.omega[k + 1]
        a = np.sqrt(X[:, 1] @ M @ X[:, 1] + X[:, 2] @ M @ X[:, 2])
        assert bb.amplitude[0] < a < bb.amplitude[-1]
        errs.append(w / np.interp(np.log(a), np.log(bb.amplitude), bb.omega) - 1)
    print("phase resonance against the backbone, relative:", errs)
    assert abs(errs[0]) < 1e-4
    assert np.abs(errs).max() < 6e-3


def test_free_start_and_bad_input():
    """From the free mode (contact open: K alone) down from gross slip, the SDOF backbone
    follows the describing function (N = 1024 samples: 1e-4); bad arguments name
    themselves."""
    model = jenkins_sdof()
    opts = frirom.SolverOptions(harmonics=1, samples=1024, formulation="banded")
    bb = nonlinear_mode(model, 0, (10.0, 1.0), "free", opts)
    assert bb.omega0 == pytest.approx(np.sqrt(K0 / M1))
    w, xi = describing_function(bb.amplitude)
    assert np.abs(bb.omega / w - 1).max() < 1e-4
    with pytest.raises(ParameterError, match="start"):
        nonlinear_mode(model, 0, (1e-5, 1e-3), "open", opts)
    with pytest.raises(ParameterError, match="amplitudes"):
        nonlinear_mode(model, 0, (0.0, 1e-3), "stuck", opts)
    with pytest.raises(ParameterError, match="mode"):
        nonlinear_mode(model, 3, (1e-5, 1e-3), "stuck", opts)


def test_resume_continues_bit_for_bit():
    """A run stopped after 2 segments and resumed from its checkpoint makes the
    uninterrupted run's points bit for bit (the contact history restored)."""
    model = two_dof()
    opts = frirom.SolverOptions(harmonics=3, samples=256, batch=5)
    full = nonlinear_mode(model, 0, (1e-6, 1e-2), "stuck", opts)
    part = nonlinear_mode(model, 0, (1e-6, 1e-2), "stuck", opts, max_points=11)
    ck = part.checkpoint()
    assert part.status == "max_points" and ck["n_points"] == 11
    rest = nonlinear_mode(model, 0, (1e-6, 1e-2), "stuck", opts, resume=ck)
    both = part.head(ck["n_points"]).extended(rest)
    assert len(both) == len(full) and both.status == "done"
    assert np.array_equal(both.y, full.y) and np.array_equal(both.amplitude, full.amplitude)


@pytest.mark.slow
def test_deck_run_and_resume(tmp_path):
    """`frirom run` on the bundled nonlinear-mode deck writes backbone.h5/.csv/.png; cut
    by continuation.max_points (exit 3) and resumed with more points, the backbone equals
    the uninterrupted one bit for bit."""
    from pathlib import Path

    from frirom.backbone import load_h5
    from frirom.cli import main
    src = Path(__file__).parents[1] / "cases" / "joint"
    for name in ("M.mtx", "K.mtx", "dofs.txt", "joint_mode.toml"):
        (tmp_path / name).write_bytes((src / name).read_bytes())
    deck = tmp_path / "joint_mode.toml"
    assert main(["run", str(deck), "--out", str(tmp_path / "full"), "--quiet"]) == 0
    for f in ("backbone.h5", "backbone.csv", "backbone.png", "deck.toml"):
        assert (tmp_path / "full" / f).is_file()
    full, _ = load_h5(tmp_path / "full" / "backbone.h5")
    assert full.status == "done" and full.amplitude[-1] == pytest.approx(1e-3)
    # the damper slips: the frequency drops and the damping ratio peaks in between
    assert full.frequency[-1] < 0.97 * full.frequency[0]
    assert full.damping_ratio.max() > 5 * full.damping_ratio[0]
    text = deck.read_text().replace("max_step = 0.05", "max_step = 0.05\nmax_points = 15")
    deck.write_text(text)
    assert main(["run", str(deck), "--out", str(tmp_path / "cut"), "--quiet"]) == 3
    deck.write_text(text.replace("max_points = 15", "max_points = 1000"))
    assert main(["run", str(deck), "--out", str(tmp_path / "cut"), "--resume",
                 "--quiet"]) == 0
    both, _ = load_h5(tmp_path / "cut" / "backbone.h5")
    assert np.array_equal(both.y, full.y) and both.status == "done"
    csv = np.loadtxt(tmp_path / "full" / "backbone.csv", delimiter=",", skiprows=1)
    assert np.allclose(csv[:, 1], full.frequency, rtol=1e-10)
    # a dynamic load in a mode deck is refused, naming the field
    deck.write_text(text + '\n[[excitation.load]]\ndof = "tip:x"\nharmonic = 1\n'
                    'amplitude = 1.0\n')
    assert main(["run", str(deck), "--out", str(tmp_path / "bad"), "--quiet"]) == 2


@pytest.mark.slow
def test_reduced_fe_deck(block_dir):
    """A nonlinear-mode deck on a reduced FE model (the ccx block, Craig-Bampton + GSI,
    2-D friction with a normal preload; outputs are FE DoFs recovered through the basis):
    the friction lowers the frequency of the stuck structure's third mode and adds
    damping, and both formulations end on the same point (1e-7). (Modes 1 and 2 of the
    square block are a pair 1e-6 apart: a 1:1 resonance whose nonlinear mode the EPMC
    leaves undetermined; Newton stalls there.)"""
    import time

    from _models import GSI_DECK
    from frirom.backbone import load_h5
    from frirom.cli import main
    text = (GSI_DECK.format(kt="2.0e8", h=2, mu=0.5)
            .replace("harmonics = 2", "harmonics = 2\nsamples = 64")
            .replace('[[excitation.load]]\ndof = "ACTIVE:z"\namplitude = 1.0\n', "")
            .replace("[frequency]\nstart = 100.0\nend = 200.0\n", "")
            + '\n[analysis]\nkind = "nonlinear_mode"\nmode = 3\namplitudes = [1e-7, 1e-3]\n'
              'output = "ACTIVE:z"\n')
    ends = {}
    for form in ("condensed", "banded"):
        deck = block_dir / f"mode_{form}.toml"
        deck.write_text(text.replace("samples = 64", f'samples = 64\nformulation = "{form}"'))
        t0 = time.perf_counter()
        assert main(["run", str(deck), "--out", str(block_dir / f"out_{form}"),
                     "--quiet"]) == 0
        bb, _ = load_h5(block_dir / f"out_{form}" / "backbone.h5")
        print(form, len(bb), "points", round(time.perf_counter() - t0, 2), "s",
              bb.frequency[[0, -1]], bb.damping_ratio.max())
        assert bb.frequency[-1] < bb.frequency[0] and bb.damping_ratio.max() > 0.011
        assert bb.outputs.shape[1] == 3            # ACTIVE:z put first, then [outputs]
        ends[form] = bb
    c, b = ends["condensed"], ends["banded"]
    assert c.omega[-1] == pytest.approx(b.omega[-1], rel=1e-7)
    assert c.damping_ratio[-1] == pytest.approx(b.damping_ratio[-1], rel=1e-6)
    # frirom show at the backbone point of largest damping: the interface maps of the FE
    # deck, as for a forced-response point
    out = block_dir / "out_condensed"
    assert main(["show", str(out), "--dir", str(out / "shown")]) == 0
    assert (out / "shown" / "maps.png").is_file()
    assert (out / "shown" / "hysteresis.png").is_file()


@pytest.mark.parametrize("analysis, field", [
    ('kind = "backbone"', "analysis.kind"),
    ('kind = "nonlinear_mode"\namplitudes = [1e-3, 1e-3]', "analysis.amplitudes"),
    ('kind = "nonlinear_mode"\nmode = 0', "analysis.mode"),
    ('kind = "nonlinear_mode"\nstart = "open"', "analysis.start"),
    ('kind = "nonlinear_mode"\nmodes = 1', "analysis"),
    ('kind = "nonlinear_mode"\noutput = "nowhere:x"', "analysis.output"),
])
def test_analysis_table_errors_name_the_field(tmp_path, analysis, field):
    """A bad [analysis] key is an InputError naming the deck and the field."""
    from pathlib import Path

    from frirom import InputError
    from frirom.deck import load_deck
    src = Path(__file__).parents[1] / "cases" / "joint"
    for name in ("M.mtx", "K.mtx", "dofs.txt"):
        (tmp_path / name).write_bytes((src / name).read_bytes())
    text = (src / "joint_mode.toml").read_text()
    start = text.index("[analysis]")
    end = text.index("[model]")
    deck = tmp_path / "d.toml"
    deck.write_text(text[:start] + "[analysis]\n" + analysis + "\n\n" + text[end:])
    with pytest.raises(InputError, match=field.replace(".", r"\.")) as err:
        load_deck(deck)
    assert "d.toml" in str(err.value)
