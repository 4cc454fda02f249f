"""`frirom show`: a point of a run solved again, its time histories, hysteresis loops,
dissipated energy (checked by the power balance of the period), interface maps, VTK; and
the readability rules of the FRF and state plots."""

import csv
import dataclasses
import os
import shutil
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest

from frirom._errors import InputError
from frirom.cli import main
from frirom.deck import load_deck
from frirom.plots import fold_marks, plot_frf, plot_states, relevant_outputs
from frirom.results import FRF
from frirom.show import parse_frequency, pick_point, point_state
from frirom.solver import frf

ROOT = Path(__file__).resolve().parents[1]
JOINT = ROOT / "cases" / "joint"


@pytest.fixture(scope="module")
def liftoff():
    """The lift-off joint deck (normal1d, H = 9) over its resonance, a few points."""
    d = load_deck(JOINT / "joint_liftoff.toml")
    o = dataclasses.replace(d.options(), max_points=14)
    w0 = 2 * np.pi * 455.0
    r = frf(d.model(), d.excitation(), w0, 2 * np.pi * 480.0, o, outputs=d.solver_outputs)
    return d, r


def test_power_balance_of_a_period(liftoff):
    """Per period, the work of the excitation equals the energy dissipated by the contact
    (AFT march over the closed cycle, Python side) plus the viscous damping (C from the
    harmonics): the velocity lies in the harmonic basis, so the balance is the harmonic
    balance residual dotted with the velocity. Tolerance 1e-6 of the excitation's work:
    the solver converges |R| to tol_residual = 1e-8 relative, the velocity's harmonics
    weigh up to ~H = 9 times."""
    d, r = liftoff
    assert len(r) >= 5 and r.unknowns.shape[0] == len(r)
    seen = 0.0
    for k in range(0, len(r), 3):
        s = point_state(r, d, k, float(r.omega[k]))
        b = s.balance
        assert b["excitation"] > 0 and b["contacts"] >= 0 and b["viscous"] > 0
        assert abs(b["residual"]) <= 1e-6 * b["excitation"], b
        seen = max(seen, b["contacts"] / b["excitation"])
        # the stored point is reproduced by the re-solve (its outputs, to the tolerance)
        np.testing.assert_allclose(s.outputs, r.X[k], rtol=0,
                                   atol=1e-7 * np.abs(r.X[k]).max())
    assert seen > 0.05            # the contact does dissipate a real share somewhere


def test_energy_per_contact_equals_its_loop_area(liftoff):
    """The energy of an element is its loop's area: the spectral formula (force samples
    times the exact velocity) against the trapezoidal polygon area of the sampled loop,
    which differ by the polygon's O(1/N^2) error (N = 512 here: 1e-3 relative)."""
    d, r = liftoff
    k = int(np.argmax(r.amp_max[:, 0]))
    s = point_state(r, d, k, float(r.omega[k]))
    c = s.contacts[0]
    area = 0.0
    for dd in range(len(c.directions)):
        u, f = c.u[0, dd], c.f[0, dd]
        area += np.sum(0.5 * (f + np.roll(f, -1)) * (np.roll(u, -1) - u))
    assert c.energy[0] > 0
    assert abs(area - c.energy[0]) <= 1e-3 * c.energy[0]
    assert 0.0 <= c.states[0].min() and abs(c.states[0].sum() - 1.0) < 1e-12


def test_pick_point_and_frequency_parsing(liftoff):
    _, r = liftoff
    assert parse_frequency("470Hz") == pytest.approx(2 * np.pi * 470)
    assert parse_frequency("2950 rad/s") == 2950.0
    assert parse_frequency("470", "hz") == pytest.approx(2 * np.pi * 470)
    with pytest.raises(InputError, match="--at"):
        parse_frequency("fast")
    k, w = pick_point(r, at=parse_frequency("458Hz"))
    assert w == pytest.approx(2 * np.pi * 458) and k == np.argmin(abs(r.omega - w))
    assert pick_point(r, point=-1) == (len(r) - 1, r.omega[-1])
    assert pick_point(r, peak=True)[1] == r.peak(0).omega
    with pytest.raises(InputError, match="outside the curve"):
        pick_point(r, at=2 * np.pi * 900)
    with pytest.raises(InputError, match="--point"):
        pick_point(r, point=len(r))


@pytest.mark.slow
def test_show_cli_writes_point_maps_and_vtk(tmp_path, capsys):
    """(slow: a run, three re-solves and seven figures, ~12 s under load) A run of an FE deck (the block with a GSI interface), then `frirom show`: CSV and
    PNG of the point, the interface maps, the curve maps and a VTK file whose contact
    fields are those of contacts.csv on the pairs' nodes."""
    import meshio
    if shutil.which("ccx") is None:
        pytest.skip("ccx not installed")
    import block
    from _models import OUTPUTS_DECK
    block.run_ccx(block.write_block_deck(tmp_path / "block.inp", 10, 3, 3, n_ref_modes=0))
    deck = tmp_path / "block.toml"
    deck.write_text(OUTPUTS_DECK.format(outputs='["ACTIVE:z"]')
                    .replace("start = 140.0", "start = 148.0")
                    .replace("end = 160.0", "end = 152.0"))
    out = tmp_path / "out"
    assert main(["run", str(deck), "--out", str(out), "--quiet"]) == 0
    capsys.readouterr()
    assert main(["show", str(out), "--at", "150Hz", "--vtk", "--along", "2",
                 "--dir", str(tmp_path / "pt")]) == 0
    text = capsys.readouterr().out
    assert "solved at 150 Hz" in text and "excitation" in text
    pt = tmp_path / "pt"
    for f in ("time.csv", "time.png", "hysteresis.csv", "hysteresis.png", "contacts.csv",
              "energy.png", "maps.png", "maps_along.png", "point.vtu"):
        assert (pt / f).is_file(), f
    with open(pt / "time.csv") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["t_s", "phase_rad", "ACTIVE:z"] and len(rows) == 257
    with open(pt / "contacts.csv") as fh:
        con = list(csv.DictReader(fh))
    d = load_deck(deck)
    assert len(con) == d.reduced.pairs["end"].dofs_a.shape[0]
    m = meshio.read(pt / "point.vtu")
    e = m.point_data["end_energy"]
    assert np.isfinite(e).sum() == len(con)
    np.testing.assert_allclose(np.sort(e[np.isfinite(e)]),
                               np.sort([float(c["energy_J"]) for c in con]), rtol=1e-12)
    assert m.point_data["displacement"].shape == (m.points.shape[0], 3)
    # a deck changed since the run is refused
    deck.write_text(deck.read_text().replace("mu = 0.5", "mu = 0.4"))
    assert main(["show", str(out), "--point", "0"]) == 2
    assert "differs from the deck" in capsys.readouterr().err


def _folded_curve():
    """A synthetic FRF: one fold pair turning back over 5 Hz, twelve wiggle folds of a
    few mHz, and a DoF at 1e-12 of the others."""
    wig = 480.0 + np.cumsum(np.tile([0.004, -0.003], 7))      # forward 4 mHz, back 3
    f = np.r_[np.linspace(400, 460, 60), np.linspace(460, 455, 10)[1:],
              np.linspace(455, 480, 25)[1:], wig, np.linspace(480.1, 500, 20)]
    omega = 2 * np.pi * f
    a = 1e-4 / (1 + ((f - 458) / 10) ** 2)
    amp = np.stack([a, 0.3 * a, 1e-12 * a / a.max() + 1e-20], axis=1)
    df = np.diff(f)
    fold = np.r_[False, np.sign(df[1:]) != np.sign(df[:-1]), False]
    sf = np.zeros((f.size, 1, 3))
    sf[:, 0, 0], sf[:, 0, 1] = 1 - a / a.max(), a / a.max()
    return FRF(omega=omega, X=np.zeros((f.size, 3, 3)), amp_max=amp, state_fractions=sf,
               stable=np.ones(f.size, bool), fold=fold, iterations=np.ones(f.size, int),
               time_s=np.zeros(f.size))


def test_plots_keep_frequency_mark_few_folds_and_ignore_tiny_dofs():
    r = _folded_curve()
    f = r.omega / (2 * np.pi)
    assert r.fold.sum() > 10
    marks = fold_marks(f, r.amp_max[:, 0], r.fold)
    # the two real turning points (455 and 460 Hz), none of the wiggles
    np.testing.assert_allclose(np.sort(f[marks]), [455.0, 460.0], atol=0.1)
    assert list(relevant_outputs(r.amp_max)) == [True, True, False]
    fig = plot_frf(r, log=True)
    ax = fig.axes[0]
    assert ax.get_ylim()[0] >= 1e-4 * r.amp_max.max() / 1.5   # the tiny DoF does not set it
    assert ax.get_xlabel() == "frequency [Hz]"
    assert len(fig.axes) == 1 and len(plot_frf(r, phase=True).axes) == 2
    st = plot_states(r, contact_names=["lap"])
    sax = st.axes[0]
    assert st.axes[-1].get_xlabel() == "frequency [Hz]"
    # folded: lines against frequency (in path order), not a stacked area
    assert len(sax.lines) == 3 and not sax.collections
    np.testing.assert_allclose(sax.lines[0].get_xdata(), f)


def test_power_balance_of_a_cyclic_sector(tmp_path_factory):
    """The same balance on a cyclic sector (the bladed sector of tests/test_cyclic_deck.py
    with friction on the flange, EO 2, H = 3): the viscous work comes from the modes of
    each harmonic's nodal diameter and the generalised forces (frirom.show), the contact
    work from the AFT march, the excitation's from the loads; 1e-6 of the excitation's
    work (tol_residual 1e-8). An output on a blade node the reduction does not keep is
    recovered through the sector's basis."""
    if shutil.which("ccx") is None:
        pytest.skip("ccx (calculix-ccx) not installed")
    import bladed_sector
    from _models import N_SEC, write_cyclic_deck
    out = tmp_path_factory.mktemp("cyclic_show")
    _, sec = bladed_sector.write_sector_decks(out / "inner", N_SEC, n_modes=4,
                                              sector_clamp="inner")
    bladed_sector.run_ccx(sec, expect=(".sti", ".mas", ".dof"))
    deck = write_cyclic_deck(out, kp="1.0e9", h=3, solver_extra="samples = 64")
    from frirom.io import read_calculix
    fe = read_calculix(out / "inner" / "sector")
    kept = np.unique(np.concatenate([fe.node_sets[k] for k in ("FLANGE_C", "TIP", "LEFT",
                                                               "RIGHT")]))
    free = np.setdiff1d(np.unique(fe.dofs[:, 0]), kept)
    node = int(free[free.size // 2])
    deck.write_text(deck.read_text().replace("mu = 1.0e3", "mu = 0.3")
                    .replace("n0 = 1.0e6", "n0 = 0.5")
                    .replace('dofs = ["TIP:z"]', f'dofs = ["TIP:z", "{node}:x"]'))
    d = load_deck(deck)
    assert d.outputs[1] == -1          # not a coordinate: recovered through the basis
    o = dataclasses.replace(d.options(), max_points=40)
    r = frf(d.model(), d.excitation(), 2 * np.pi * 600.0, 2 * np.pi * 720.0, o,
            outputs=d.solver_outputs)
    k = int(np.argmax(r.amp_max[:, 0]))
    s = point_state(r, d, k, float(r.omega[k]))
    b = s.balance
    # the solver's outputs (sector basis rows applied to the rows it reads) equal the
    # rows of T times every coordinate of the re-solved point (1e-7: two solves to 1e-8)
    rows = [d.reduced.fe_index(int(fe.node_sets["TIP"][0]), 3), d.reduced.fe_index(node, 1)]
    ref = np.asarray(d.reduced.T[rows]) @ s.x
    np.testing.assert_allclose(r.X[k], ref, rtol=0, atol=1e-7 * np.abs(ref).max())
    assert np.abs(ref[1]).max() > 1e-3 * np.abs(ref).max()
    assert b["contacts"] > 1e-3 * b["excitation"] and b["viscous"] > 0, b
    assert abs(b["residual"]) <= 1e-6 * b["excitation"], b


def test_point_csv_files_hold_plain_numbers(liftoff, tmp_path):
    """Issue 29 item 5: every numeric cell of time.csv, hysteresis.csv and contacts.csv is
    a plain number (hysteresis.csv wrote phase_rad as ``np.float64(...)`` on every row)."""
    from frirom.show import write_point
    d, r = liftoff
    write_point(point_state(r, d, 2, float(r.omega[2])), tmp_path)
    text = {"group", "direction"}
    for name in ("time.csv", "hysteresis.csv", "contacts.csv"):
        with open(tmp_path / name) as fh:
            rows = list(csv.DictReader(fh))
        assert rows, name
        for row in rows:
            for k, v in row.items():
                if k not in text:
                    float(v)        # raises on "np.float64(0.1)"
