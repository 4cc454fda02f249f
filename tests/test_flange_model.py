"""The two-stage flange model of cases/models/flange.py (issue 10's benchmark model) at a
coarse size: sizes, the stuck-joint answer against the linear solution with the contact
stiffness in K (a closed form), ROM_II against ROM_I, and one slipping point against the
other formulation.
"""

import os
import shutil
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from frirom.solver import SolverOptions, solve_point

import flange  # cases/models/flange.py

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx not installed")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

SECTORS, Z, MODES = 6, 2, 8
OPTS = SolverOptions(harmonics=2, samples=32, tol_residual=1e-11, tol_update=1e-11)


@pytest.fixture(scope="module")
def roms(tmp_path_factory):
    work = tmp_path_factory.mktemp("flange")
    spec = flange.FlangeSpec(sectors=SECTORS, z_per_sector=Z, n_modes=MODES, coarse=True)
    return flange.flange_roms(spec, work, log=lambda *a: None)


def test_sizes_follow_table_1_layout(roms):
    """Interface 3 DoFs x 2 faces per pair, 3 active DoFs per blade, 2 MS columns (index 2:
    cos, sin) x 3 DoFs per stage; a second call reads the npz cache."""
    s = roms["sizes"]
    pairs = SECTORS * Z
    assert s["pairs"] == pairs and s["contact_rows"] == 2 * pairs
    assert s["interface"] == 6 * pairs and s["active"] == 6 * SECTORS
    assert s["rom1"] == 6 * pairs + 6 * SECTORS + 2 * MODES == roms["K"].shape[0]
    assert s["ms_interface"] == 12 and s["rom2"] == 12 + 6 * SECTORS + 2 * MODES
    again = flange.flange_roms(flange.FlangeSpec(**{**roms["spec"], "ms_indices": (2,)}),
                               Path(roms["cache"]).parent)
    assert again["cache"] == roms["cache"]
    assert np.array_equal(again["K"], roms["K"])


def _stuck_linear(roms, which, omega, scale):
    """Harmonic 1 at the outputs with every contact a pair of springs (kt, kn) in K."""
    s = "" if which == "I" else "2"
    K, M, G = roms["K" + s], roms["M" + s], sp.csr_matrix(roms["G" + s])
    kt, kn = roms["params"][0, :2]
    Kc = (G.T @ sp.diags(np.tile([kt, kn], G.shape[0] // 2)) @ G).toarray()
    D = K + Kc - omega ** 2 * M + 1j * omega * roms["beta"] * K
    return np.linalg.solve(D, scale * roms["F" + s][:, 1])[roms["outputs" + s]]


def test_stuck_joint_equals_linear_solution(roms):
    """A load small enough to keep every pair stuck: the harmonic balance answer is the
    linear response with the contact springs in K, and the static preload n0 is balanced
    (harmonic 0 zero). Tolerance 1e-8 relative: Newton converges to 1e-11, the linear solve
    is exact to ~1e-13 for this conditioning."""
    model, exc, out = flange.frirom_models(roms, "I")
    scale = 1e-3
    exc.F[:, 1] *= scale
    omega = 2 * np.pi * roms["f_stuck"] * 0.99
    pt = solve_point(model, exc, omega, OPTS, outputs=out)
    X1 = pt.X[:, 1] - 1j * pt.X[:, 2]
    ref = _stuck_linear(roms, "I", omega, scale)
    assert np.max(np.abs(X1 - ref)) < 1e-8 * np.max(np.abs(ref))
    assert np.max(np.abs(pt.X[:, 0])) < 1e-8 * np.max(np.abs(ref))
    assert np.all(pt.state_fractions[0, 0] == 1.0)         # all stuck


def test_rom2_with_the_family_is_exact_for_the_tuned_rotor(roms, tmp_path):
    """The linear stuck response of ROM_II with the whole EO 2 family of indices ({2, 4}
    for 6 sectors x 2 segments: h = +-2 mod 6 over 0..6) equals ROM_I's (the MS reduction is
    exact for a tuned rotor under its own travelling wave): 1e-8 relative, round-off of
    the two solves. With index 2 alone it is not."""
    from frirom.reduction.multistage import harmonic_indices
    fam = tuple(int(h) for h in harmonic_indices(2, SECTORS, SECTORS * Z))
    assert fam == (2, 4)
    spec = flange.FlangeSpec(**{**roms["spec"], "ms_indices": fam})
    full = flange.flange_roms(spec, tmp_path, log=lambda *a: None)
    omega = 2 * np.pi * roms["f_stuck"] * 0.97
    ref = _stuck_linear(full, "I", omega, 1.0)
    err_family = np.max(np.abs(_stuck_linear(full, "II", omega, 1.0) - ref))
    err_index2 = np.max(np.abs(_stuck_linear(roms, "II", omega, 1.0) - ref))
    assert err_family < 1e-8 * np.max(np.abs(ref))
    assert err_index2 > 1e-4 * np.max(np.abs(ref))


def test_slipping_point_same_in_both_formulations(roms):
    """At the stuck resonance with the model's load the pairs slip; the condensed and the
    banded formulations (independent assembly and linear algebra) agree to 1e-8."""
    model, exc, out = flange.frirom_models(roms, "I")
    omega = 2 * np.pi * roms["f_stuck"]
    a = solve_point(model, exc, omega, OPTS, outputs=out)
    b = solve_point(model, exc, omega, SolverOptions(**{**OPTS.__dict__,
                                                        "formulation": "banded"}),
                    outputs=out, start={"slider": a.slider})
    assert a.state_fractions[0, 1] > 0                       # some slip
    assert np.max(np.abs(a.X - b.X)) < 1e-8 * np.max(np.abs(a.X))


@pytest.mark.parametrize("pull, lifted", [(1.5, True), (-1.5, False)])
def test_pulling_the_stages_apart_opens_the_joint(roms, pull, lifted):
    """A static load of 1.5 n0 per pair pulling stage 1 away from stage 2 (+z on stage 1,
    -z on stage 2) opens the pairs between the bolts (the bolted pairs, held by the bolt
    springs, stay closed: with 2 pairs per sector half the pairs lift off); pushing the
    stages together keeps every pair closed and stuck. Catches a normal pointing the wrong
    way (the pull would then close the joint and the push open it)."""
    model, exc, out = flange.frirom_models(roms, "I")
    n0 = roms["params"][0, 3]
    exc.F[:, 1] = 0.0
    exc.F[roms["contact_a"][:, 2], 0] += pull * n0
    exc.F[roms["contact_b"][:, 2], 0] -= pull * n0
    pt = solve_point(model, exc, 2 * np.pi * roms["f_stuck"], OPTS, outputs=out)
    stick, slip, lift = pt.state_fractions[0]
    assert (lift == 0.5) if lifted else (stick == 1.0)
