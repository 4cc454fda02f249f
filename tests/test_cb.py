"""Craig-Bampton reduction of CalculiX-exported matrices against CalculiX itself.

The block model (cases/models/block.py) is meshed, written as a deck and run through ccx
at test time; ccx's own *FREQUENCY eigenvalues (job.dat, 7 significant digits) are the
independent reference.
"""

import os
import shutil

import numpy as np
import pytest
import scipy.linalg as sl
import scipy.sparse.linalg as spla

from frirom import InputError
from frirom.io import read_calculix, read_ccx_eigenvalues
from frirom.reduction.cb import craig_bampton
from frirom.reduction.eigen import eigsh_shift_invert

import block  # cases/models/block.py

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx not installed")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

N_REF = 20


@pytest.fixture(scope="module", params=[1, 2], ids=["C3D8", "C3D20"])
def ccx_block(request, tmp_path_factory):
    out = tmp_path_factory.mktemp(f"block{request.param}")
    dims = (12, 4, 4) if request.param == 1 else (8, 2, 2)
    deck = block.write_block_deck(out / "block.inp", *dims, order=request.param,
                                  n_ref_modes=N_REF)
    job = block.run_ccx(deck)
    return read_calculix(job), read_ccx_eigenvalues(job.with_suffix(".dat"))


def test_reader_and_eigen_solver_reproduce_ccx(ccx_block):
    """Full-model eigenvalues of the read matrices equal ccx's to its 7 printed digits."""
    model, ref = ccx_block
    assert ref.size == N_REF
    assert model.constrained.shape[0] == 3 * model.node_sets["FIX"].size
    lam, phi, _ = eigsh_shift_invert(model.K, model.M, N_REF)
    assert np.max(np.abs(lam / ref - 1)) < 2e-6          # 7 digits in job.dat
    assert np.max(np.abs(phi.T @ (model.M @ phi) - np.eye(N_REF))) < 1e-10


def test_cb_frequencies_converge_to_ccx(ccx_block):
    """CB frequencies of the first 10 modes: upper bounds (Rayleigh-Ritz), error falling
    as fixed-interface modes are added, below 0.1 % with 80 modes."""
    model, ref = ccx_block
    n_check = 10
    errors = []
    for k in (5, 10, 20, 40, 80):
        cb = craig_bampton(model, k, interface="IFACE", active="ACTIVE")
        w = sl.eigh(cb.K, cb.M, eigvals_only=True)[:n_check]
        rel = np.sqrt(w / ref[:n_check]) - 1                # frequency error
        assert rel.min() > -2e-6, (k, rel.min())            # bound, up to ccx's digits
        errors.append(np.abs(rel).max())
    print("CB max frequency error over the first 10 modes:", errors)
    assert all(b < a for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < 1e-3, errors


def test_cb_static_response_is_exact_and_expansion_consistent(ccx_block):
    """A load on master DoFs: the CB static solution expanded to all DoFs equals the full
    static solution (constraint modes are exact statics), and energies match."""
    model, _ = ccx_block
    cb = craig_bampton(model, 12, interface="IFACE", active="ACTIVE")
    f = np.zeros(model.n_dof)
    act = model.dof_indices("ACTIVE", directions=(3,))
    f[act] = 100.0
    x_full = spla.spsolve(model.K.tocsc(), f)
    fr = np.zeros(cb.K.shape[0])
    fr[cb.master_position(model.dofs[act])] = 100.0
    x_cb = cb.expand(np.linalg.solve(cb.K, fr))
    assert np.max(np.abs(x_cb - x_full)) < 1e-9 * np.max(np.abs(x_full))
    q = np.random.default_rng(1).standard_normal((cb.K.shape[0], 3))
    x = cb.expand(q)
    assert np.allclose(x.T @ (model.K @ x), q.T @ cb.K @ q, rtol=1e-9, atol=0)
    assert np.allclose(x.T @ (model.M @ x), q.T @ cb.M @ q, rtol=1e-9, atol=0)


def test_cb_bad_input(ccx_block):
    model, _ = ccx_block
    with pytest.raises(InputError, match="unknown node set"):
        craig_bampton(model, 5, interface="NOSUCHSET")
    with pytest.raises(InputError, match="FIX.*constrained|constrained"):
        craig_bampton(model, 5, interface="FIX")
    with pytest.raises(InputError, match="no master"):
        craig_bampton(model, 5)


@pytest.mark.slow
def test_cb_lap_joint_gmsh_tet10(tmp_path):
    """Lap joint of two plates meshed by gmsh (C3D10), both contact faces as masters: the
    first 10 CB frequencies converge to ccx's, below 0.1 % with 40 fixed-interface modes.
    Element size 10 mm (4416 DoFs, 65 nodes per contact face): max errors 4.6e-2, 3.9e-3,
    8.2e-4, 2.2e-4 with 5, 10, 20, 40 modes (8 mm, 6720 DoFs: 4.4e-2 ... 2.3e-4, 3x the
    time)."""
    pytest.importorskip("gmsh")
    import lap_joint

    job = block.run_ccx(lap_joint.write_lap_joint_deck(tmp_path / "lap.inp", size=0.010,
                                                       n_ref_modes=12))
    model = read_calculix(job)
    ref = read_ccx_eigenvalues(job.with_suffix(".dat"))
    assert model.node_sets["CONTACT_A"].size == model.node_sets["CONTACT_B"].size > 10
    errors = []
    for k in (5, 10, 20, 40):
        cb = craig_bampton(model, k, interface="IFACE", active="ACTIVE")
        w = sl.eigh(cb.K, cb.M, eigvals_only=True)[:10]
        rel = np.sqrt(w / ref[:10]) - 1
        assert rel.min() > -2e-6
        errors.append(np.abs(rel).max())
    print("lap joint CB max frequency error over the first 10 modes:", errors)
    assert all(b < a for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < 1e-3, errors
