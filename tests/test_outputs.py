"""Physical outputs: FE DoFs recovered through the reduction basis, labelled as the deck
names them, in CSV and HDF5 with Hz, harmonics' amplitude and phase, and how the result
was made."""

import csv
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import h5py
import numpy as np
import pytest

from _models import OUTPUTS_DECK
from frirom import __version__
from frirom._errors import InputError
from frirom.cli import main
from frirom.deck import load_deck
from frirom.io import read_calculix
from frirom.results import FRF, harmonic_table
from frirom.solver import frf, solve_point


@pytest.fixture(scope="module")
def block_case(block_dir):
    """(deck path, FE model, interface node, interior node) of the block (OUTPUTS_DECK:
    the block of tests/test_reduction_deck.py, two harmonics, 140..160 Hz)."""
    out = block_dir
    fe = read_calculix(out / "block")
    iface, act = fe.node_sets["IFACE"], fe.node_sets["ACTIVE"]
    inner = [n for n in np.unique(fe.dofs[:, 0]) if n not in iface and n not in act]
    node_i, node_f = int(iface[0]), int(inner[len(inner) // 2])
    outs = f'["ACTIVE:z", "{node_i}:UX", "{node_f}:z"]'
    path = out / "block.toml"
    path.write_text(OUTPUTS_DECK.format(outputs=outs))
    return path, fe, node_i, node_f


def test_fe_outputs_equal_the_projection_of_every_coordinate(block_case):
    """An output the reduction does not keep (an interface DoF under GSI, an interior
    node) is T[dof] q: the solver's output equals the projection of all coordinates'
    harmonics by the basis row to round-off (1e-12 of the amplitude; both come from the
    same converged point: the second solve starts at the first's converged unknowns)."""
    path, fe, node_i, node_f = block_case
    d = load_deck(path)
    rom = d.reduced
    assert d.output_names == ["ACTIVE:z", f"{node_i}:UX", f"{node_f}:z"]
    assert d.outputs[0] >= 0 and d.outputs[1] == d.outputs[2] == -1
    model, exc, opts = d.model(), d.excitation(), d.options()
    w = 2 * np.pi * 150.0
    p = solve_point(model, exc, w, opts, outputs=d.solver_outputs)
    q = solve_point(model, exc, w, opts, outputs=np.arange(model.n_dof), start=p)
    rows = [rom.fe_index(int(fe.node_sets["ACTIVE"][0]), 3), rom.fe_index(node_i, 1),
            rom.fe_index(node_f, 3)]
    ref = np.asarray(rom.T[rows]) @ q.X
    assert np.abs(ref).max() > 0
    np.testing.assert_allclose(p.X, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    # the kept DoF's basis row is a unit vector: its output is the coordinate itself
    np.testing.assert_allclose(p.X[0], q.X[d.outputs[0]], rtol=0,
                               atol=1e-12 * np.abs(ref).max())


def test_files_label_outputs_and_say_how_they_were_made(block_case, tmp_path):
    """frirom run: CSV columns named as the deck names the outputs, frequency in Hz and
    rad/s, per harmonic amplitude and phase (x_h = A cos(h w t + phase)) reproducing X,
    the true peak; HDF5 the same plus the deck, the settings, the model's fingerprint and
    the version."""
    path, fe, node_i, node_f = block_case
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    r = FRF.load(out / "frf.h5")
    assert len(r) >= 3
    labels = ["ACTIVE:z", f"{node_i}:UX", f"{node_f}:z"]
    assert r.output_labels == labels
    assert r.meta["deck_text"] == path.read_text()
    assert r.meta["frirom_version"] == __version__
    assert r.meta["model_fingerprint"] == load_deck(path).reduced.fingerprint != ""
    assert '"harmonics": 2' in r.meta["solver_settings"]
    assert r.unknowns is not None and r.unknowns.shape[0] == len(r)
    with h5py.File(out / "frf.h5") as f:
        np.testing.assert_allclose(f["frequency_hz"][...], r.omega / (2 * np.pi), rtol=1e-15)
        amp, ph = f["harmonic_amplitude"][...], f["harmonic_phase"][...]
    # amplitude and phase give back the coefficients: a = A cos(phase), b = -A sin(phase)
    np.testing.assert_allclose(amp[..., 1:] * np.cos(ph[..., 1:]), r.X[..., 1::2],
                               rtol=0, atol=1e-12 * np.abs(r.X).max())
    np.testing.assert_allclose(-amp[..., 1:] * np.sin(ph[..., 1:]), r.X[..., 2::2],
                               rtol=0, atol=1e-12 * np.abs(r.X).max())
    with open(out / "frf.csv") as fh:
        rows = list(csv.reader(fh))
    head = rows[0]
    assert head[:2] == ["f_hz", "omega_rad_s"]
    for lab in labels:
        for col in ("amp_max", "h0", "h1 amp", "h1 phase_deg", "h2 amp", "h2 phase_deg"):
            assert f"{lab} {col}" in head
    col = {h: i for i, h in enumerate(head)}
    body = np.array([[float(v) for v in row] for row in rows[1:]])
    np.testing.assert_allclose(body[:, 0] * 2 * np.pi, body[:, 1], rtol=1e-14)
    np.testing.assert_array_equal(body[:, col[f"{node_f}:z amp_max"]], r.amp_max[:, 2])
    np.testing.assert_allclose(body[:, col[f"{node_i}:UX h1 phase_deg"]],
                               np.degrees(harmonic_table(r.X)[1][:, 1, 1]), atol=1e-6)


def test_output_of_a_missing_dof_names_the_key(block_case):
    path, *_ = block_case
    bad = path.with_name("bad.toml")
    bad.write_text(OUTPUTS_DECK.format(outputs='["999999:z"]'))
    with pytest.raises(InputError) as exc:
        load_deck(bad)
    assert "outputs.dofs[0]" in str(exc.value) and "999999" in str(exc.value)


def test_frf_with_an_output_matrix_keeps_its_rows():
    """frirom.solver.frf with outputs given as a matrix: each output is its row times the
    coordinates (here a difference of two DoFs of a lumped chain), exact to round-off."""
    from frirom.model import ContactGroup, Damping, Excitation, Model
    from frirom.solver import SolverOptions
    n = 3
    K = 1e4 * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    model = Model(np.eye(n), K, Damping.rayleigh(0.0, 1e-4),
                  [ContactGroup("jenkins", np.array([[1.0, 0, 0]]), [1e4, 0.3, 1.0])])
    F = np.zeros((n, 2), complex)
    F[-1, 1] = 2.0
    o = SolverOptions(harmonics=3, samples=64, max_points=8)
    P = np.array([[0.0, 1.0, -1.0], [0.0, 0.0, 1.0]])
    a = frf(model, Excitation(F), 40.0, 80.0, o, outputs=P)
    b = frf(model, Excitation(F), 40.0, 80.0, o, outputs=[0, 1, 2])
    assert list(a.output_dofs) == [-1, 2]
    np.testing.assert_allclose(a.X, np.einsum("oj,pjc->poc", P, b.X), rtol=0,
                               atol=1e-12 * np.abs(b.X).max())
