"""Nonlinear modes of a cyclic sector (frirom.nonlinear_mode on a CyclicModel: one nodal
diameter, a travelling wave) against references that do not use the cyclic machinery.

The rotor is tests/_rotor.py's tuned lattice rotor (N = 7 sectors, normal1d ground
contacts with preload and Jenkins dampers between neighbouring blade tips, Rayleigh
damping). Its nodal diameter 2 at H = 3 has harmonics 0..3 on diameters 0, 5, 3 and 1.

- The whole rotor (no cyclic reduction, all its modes in its receptances): the sector's
  backbone points, expanded to every sector as the travelling wave (sector s: rotated by
  s 2 pi / N, harmonic h times exp(i k_h s 2 pi / N)), satisfy the whole rotor's own EPMC
  equations (its condensed harmonic balance with the same w and xi, and its amplitude row
  with the rotor's modal amplitude sqrt(N) a) to the Newton tolerance. The AFT uses 16 N
  samples so that the time lag between sectors is a whole number of samples.
- The linear limit: the whole rotor's stuck and free eigenfrequencies (a double pair at
  nodal diameter k), undamped.
- The analytical Jacobian against central differences.
"""

import dataclasses

import numpy as np
import pytest
import scipy.linalg as sla

import frirom
from _rotor import ALPHA, BETA, N, full_model, rotor, rotor_sector, sector_contacts
from frirom import ParameterError, _kernels
from frirom._pack import pack
from frirom._run import Run
from frirom.model import Damping, Excitation
from frirom.nonlinear_modes import nonlinear_mode
from frirom.nonlinear_modes_cyclic import cyclic_linear_mode, open_cyclic
from frirom.reduction.cyclic import axis_rotation, cyclic_model

H, KND = 3, 2
OPTS = dict(harmonics=H, samples=16 * N, tol_residual=1e-12, tol_update=1e-12, max_iter=40)


def _rotor_models(damping):
    r, K, Ks, glob = rotor()
    s = r["sector"]
    n_s = Ks.shape[0]
    sector = rotor_sector(r, N)
    cm = cyclic_model(sector, Ks, s["M"], sector_contacts(r, glob, n_s), KND, H,
                      damping=damping)
    full = full_model(r, K)
    full.damping = damping
    return r, cm, full


@pytest.fixture(scope="module")
def models():
    return _rotor_models(Damping.rayleigh(ALPHA, BETA))


@pytest.fixture(scope="module")
def backbone(models):
    cm = models[1]
    return nonlinear_mode(cm, 0, (1e-6, 1e-1), "stuck", frirom.SolverOptions(**OPTS))


def _expand(r, cm, Xs):
    """Sector 0's real harmonics (n_s, 2H+1) -> the whole rotor's travelling wave."""
    n_ring = r["nz"] * 9                      # 3 radii x 3 axial layers per station
    per = (r["nz"] // N) * 9                  # ring nodes per sector
    nodes = r["sector"]["nodes"]
    own0 = r["node_owner"][nodes] == 0
    Z = np.concatenate([Xs[:, :1], Xs[:, 1::2] - 1j * Xs[:, 2::2]], axis=1)
    X = np.zeros((r["K"].shape[0], Xs.shape[1]))
    Q = axis_rotation(2 * np.pi / N)
    ks = np.array(cm.indices(H))
    for sct in range(N):
        Qs = np.linalg.matrix_power(Q, sct)
        for i, p in enumerate(nodes):
            if not own0[i]:
                continue
            node = (p + sct * per) % n_ring if p < n_ring else p + 2 * sct
            v = (Qs @ Z[3 * i:3 * i + 3]) * np.exp(2j * np.pi * ks * sct / N)
            X[3 * node:3 * node + 3, 0] = v[:, 0].real
            X[3 * node:3 * node + 3, 1::2] = v[:, 1:].real
            X[3 * node:3 * node + 3, 2::2] = -v[:, 1:].imag
    return X


def test_backbone_solves_the_whole_rotor(models, backbone):
    """Eight points from stick through microslip to gross slip of the ground contacts:
    the whole rotor's harmonic balance rows to 1e-11 of the contact DoFs' motion
    (measured 3e-13 .. 8e-13) and its amplitude row to 1e-11 (measured 1.3e-12)."""
    r, cm, full = models
    bb = backbone
    assert bb.status == "done" and bb.nodal_diameter == 5
    # the nonlinearity is real: slip, a damping peak, a frequency drop
    assert bb.states[-1, 1].mean() > 0.3 and bb.damping_ratio.max() > 4 * bb.damping_ratio[0]
    assert bb.omega[-1] < 0.95 * bb.omega[0]
    n = full.n_dof
    Mf = full.M.toarray()
    lam, Phi = sla.eigh(full.K.toarray(), Mf)
    w = np.sqrt(lam)
    zeta = np.einsum("ir,ir->r", Phi, full.C @ Phi) / (2 * w)
    lst, V = sla.eigh((full.K + full.stuck_stiffness()).toarray(), Mf)
    opts = dataclasses.replace(frirom.SolverOptions(**OPTS), formulation="banded")
    packed = pack(full, Excitation(np.zeros((n, 1))), opts, np.arange(n))
    w0 = np.sqrt(lst[0])
    run = Run(packed, mode_shape=(V[:, 0], w0, (Phi, w, zeta)))
    nl, nf = packed.nl, packed.nl.size * (2 * H + 1)
    for i in np.linspace(0, len(bb) - 1, 8).astype(int):
        a = np.sqrt(N) * bb.amplitude[i]
        U = _expand(r, cm, bb.harmonics[i])[nl]
        U[:, 1:] /= a
        y = np.r_[U.T.ravel(), bb.omega[i] / w0, bb.xi[i] / w0]
        res, _, _, info, msg = _kernels.frun_mode_jacobian(run.handle, np.log10(a), y)
        assert info == 0, msg
        assert np.abs(res[:nf]).max() < 1e-11 * np.abs(U).max(), i
        assert abs(res[nf]) < 1e-11, i
    run.close()


def test_linear_limit_is_the_rotor_eigenfrequency():
    """Undamped, contacts stuck at a = 1e-7: the backbone's first point at the whole
    rotor's stuck eigenfrequency of nodal diameter 2 (a double pair: the two travelling
    directions) to 1e-10 (measured 2e-14, 4e-14), xi zero to 1e-10 of it (1e-15).
    (Damped, the linear limit moves off the undamped eigenfrequency by O(zeta^2), 2.3e-7
    here with the Rayleigh damping, which is not proportional to the stuck stiffness.)"""
    r, cm, full = _rotor_models(Damping.rayleigh(0.0, 0.0))
    wf = np.sqrt(sla.eigvalsh((full.K + full.stuck_stiffness()).toarray(),
                              full.M.toarray()))
    bb = nonlinear_mode(cm, 0, (1e-7, 2e-7), "stuck", frirom.SolverOptions(**OPTS))
    q0, w0, k1 = cyclic_linear_mode(cm, 0, "stuck")
    j = np.argsort(np.abs(wf - bb.omega[0]))[:3]
    rel = np.abs(wf[j] / bb.omega[0] - 1)
    assert rel[1] < 1e-10 and rel[2] > 1e-3, rel          # a pair, nothing else near
    assert abs(bb.omega[0] / w0 - 1) < 1e-10
    assert abs(bb.xi[0]) < 1e-10 * w0 and bb.states[0, 0].min() == 1.0


def test_jacobian_against_central_differences(models, backbone):
    """dR/dy and dR/d log10 a of the cyclic mode run at the damping peak (microslip)
    and at the last point (gross slip): relative 1e-6 of the largest entry (measured 3e-12
    and 1.3e-9). Steps of 1e-8: at 1e-6 (1e-7) the differences of the static columns
    cross a sample where an element changes between stick, slip and lift-off (errors
    8e-3, 5e-3 there, and 1e-9 elsewhere)."""
    cm = models[1]
    bb = backbone
    opts = dataclasses.replace(frirom.SolverOptions(**OPTS), stability=False)
    _, run, _, _ = open_cyclic(cm, 0, "stuck", opts)

    def res(yy, ll):
        r, rl, J, info, msg = _kernels.frun_mode_jacobian(run.handle, ll, yy)
        assert info == 0, msg
        return r, rl, J

    for i in (int(np.argmax(bb.damping_ratio)), len(bb) - 1):
        y, lam = bb.y[i], np.log10(bb.amplitude[i])
        r, rl, J = res(y, lam)
        assert np.abs(r).max() < 1e-8 * np.abs(J).max()
        Jfd = np.zeros_like(J)
        for k in range(y.size):
            e = 1e-8 * max(1.0, abs(y[k]))
            ek = np.eye(y.size)[k] * e
            Jfd[:, k] = (res(y + ek, lam)[0] - res(y - ek, lam)[0]) / (2 * e)
        rlfd = (res(y, lam + 1e-8)[0] - res(y, lam - 1e-8)[0]) / 2e-8
        assert np.abs(J - Jfd).max() < 1e-6 * np.abs(J).max(), i
        assert np.abs(rl - rlfd).max() < 1e-6 * np.abs(rl).max(), i
    run.close()


def test_energy_balance_and_resume(models, backbone):
    """The energy per cycle the artificial damping feeds in (Backbone.energy, from the
    modal coordinates of every harmonic) equals what sector 0's contacts dissipate (the
    AFT of frirom show on its harmonics, the tip damper seeing the next sector's motion)
    plus the viscous work, to 1e-9 at the damping peak and in gross slip (measured 2e-14
    and 3e-15; the contacts' share 80 % and 55 %); a run resumed from a checkpoint
    repeats the uninterrupted one bit for bit, and a run with a callback after every
    segment (the points' energies computed once, as they come) has the same energies to
    1e-12 (least squares on fewer right-hand sides at a time)."""
    from frirom.show import contact_fields
    from frirom.show_backbone import _sector_viscous
    cm = models[1]
    bb = backbone
    assert np.all(bb.energy > 0) and np.all(np.diff(bb.energy) > 0)
    for i in (int(np.argmax(bb.damping_ratio)), len(bb) - 1):
        x = bb.harmonics[i]
        contacts = contact_fields(cm, x, bb.sliders[i], OPTS["samples"])
        dis = sum(c.energy.sum() for c in contacts)
        visc = _sector_viscous(cm, x[:, 1::2] - 1j * x[:, 2::2], bb.omega[i])
        assert dis > 0.1 * bb.energy[i]                     # the contacts take a share
        assert abs(bb.energy[i] - dis - visc) < 1e-9 * bb.energy[i], i
    # in stick, xi is the viscous part alone
    assert bb.xi_viscous[0] == pytest.approx(bb.xi[0], rel=1e-6)
    opts = frirom.SolverOptions(**OPTS)
    part = nonlinear_mode(cm, 0, (1e-6, 1e-1), "stuck", opts, max_points=12, batch=4)
    ck = part.checkpoint()
    rest = nonlinear_mode(cm, 0, (1e-6, 1e-1), "stuck", opts, resume=ck, batch=4)
    both = part.head(ck["index"] + 1).extended(rest)
    whole = nonlinear_mode(cm, 0, (1e-6, 1e-1), "stuck", opts, batch=4)
    assert np.array_equal(both.omega, whole.omega) and np.array_equal(both.xi, whole.xi)
    # a callback after every segment (the energies of the points before are kept, only
    # the new ones computed): the same energies as one Backbone made at the end
    seen = []
    cb = nonlinear_mode(cm, 0, (1e-6, 1e-1), "stuck", opts, batch=4,
                        callback=lambda b: seen.append(b.energy))
    assert len(seen) > 3 and np.array_equal(cb.omega, whole.omega)
    for e in (seen[-1], cb.energy):       # least squares on fewer right-hand sides
        assert np.abs(e / whole.energy - 1).max() < 1e-12
    assert np.abs(cb.xi_viscous - whole.xi_viscous).max() < 1e-12 * whole.xi.max()


def test_bad_input(models):
    r, cm, full = models
    opts = frirom.SolverOptions(harmonics=H, samples=16 * N)
    with pytest.raises(ParameterError, match="nodal_diameter"):
        nonlinear_mode(full, 0, (1e-6, 1e-3), "stuck", opts, nodal_diameter=1)
    with pytest.raises(ParameterError, match="nodal_diameter"):
        nonlinear_mode(cm, 0, (1e-6, 1e-3), "stuck", opts, nodal_diameter=N)
    # harmonic 2 of nodal diameter 2 lives on diameter 3 (or 4): drop its modes
    short = dataclasses.replace(cm, modes={k: m for k, m in cm.modes.items() if k != 3})
    with pytest.raises(ParameterError, match="no modes of harmonic index"):
        nonlinear_mode(short, 0, (1e-6, 1e-3), "stuck", opts)
    with pytest.raises(ParameterError, match="options.modes"):
        nonlinear_mode(cm, 0, (1e-6, 1e-3), "stuck", dataclasses.replace(opts, modes=5))
    with pytest.raises(ParameterError, match="mode: expected"):
        nonlinear_mode(cm, 500, (1e-6, 1e-3), "stuck", opts)


def test_large_sector_reports_contact_dofs_and_outputs(models, backbone, monkeypatch):
    """Above _ALL_OUTPUTS sector coordinates the run reports the contact DoFs and the
    outputs only: the same backbone, the outputs' harmonics equal, and the energy per
    cycle and xi's viscous part, then from the contact forces' modal coordinates
    (nonlinear_modes_cyclic._modal_from_forces), equal to those from every DoF's
    harmonics (least squares on each harmonic's modes) to 1e-9 (they were NaN)."""
    import frirom.nonlinear_modes_cyclic as nmc
    cm = models[1]
    monkeypatch.setattr(nmc, "_ALL_OUTPUTS", 50)
    out = [7, 100]
    bb = nonlinear_mode(cm, 0, (1e-6, 1e-1), "stuck", frirom.SolverOptions(**OPTS),
                        outputs=out)
    ref = backbone
    assert bb.harmonics.shape[1] == np.union1d(cm.nonlinear_dofs(), out).size
    assert np.array_equal(bb.omega, ref.omega) and np.array_equal(bb.xi, ref.xi)
    assert np.abs(bb.outputs - ref.harmonics[:, out]).max() < 1e-12 * np.abs(
        ref.harmonics[:, out]).max()
    assert np.all(np.isfinite(bb.energy)) and np.all(np.isfinite(bb.xi_viscous))
    e_en = np.abs(bb.energy / ref.energy - 1).max()
    e_xv = np.abs(bb.xi_viscous - ref.xi_viscous).max() / np.abs(ref.xi).max()
    print(f"energy from forces: relative error {e_en:.1e}, xi_viscous {e_xv:.1e}")
    assert e_en < 1e-9 and e_xv < 1e-9


def test_energy_of_a_sector_above_400_coordinates(monkeypatch):
    """The smallest rotor of tests/_rotor.py whose sector passes _ALL_OUTPUTS (14 stations
    per sector: 411 coordinates, 384 modes per nodal diameter): its backbone's energy per
    cycle and xi's viscous part were NaN (the run reports the contact DoFs only, and the
    modal coordinates were taken from every DoF's harmonics); now from the contact forces,
    they equal a run made to report every DoF (_ALL_OUTPUTS raised: least squares on each
    harmonic's modes) to 1e-9, with the same frequencies and damping; frirom show's
    energy balance at the damping peak (it refused such backbones) balances to 1e-9 and
    equals the all-DoF one."""
    import frirom.nonlinear_modes_cyclic as nmc
    r, K, Ks, glob = rotor(per_sector=14)
    n_s = Ks.shape[0]
    assert nmc._ALL_OUTPUTS < n_s < nmc._ALL_OUTPUTS + 20
    cm = cyclic_model(rotor_sector(r, N), Ks, r["sector"]["M"],
                      sector_contacts(r, glob, n_s), KND, H,
                      damping=Damping.rayleigh(ALPHA, BETA))
    opts = frirom.SolverOptions(**OPTS)
    bb = nonlinear_mode(cm, 0, (1e-6, 1e-1), "stuck", opts)
    assert bb.harmonics.shape[1] < n_s
    monkeypatch.setattr(nmc, "_ALL_OUTPUTS", 1000)
    ref = nonlinear_mode(cm, 0, (1e-6, 1e-1), "stuck", opts)
    assert ref.harmonics.shape[1] == n_s and bb.status == ref.status == "done"
    assert np.array_equal(bb.omega, ref.omega) and np.array_equal(bb.xi, ref.xi)
    assert np.all(np.isfinite(bb.energy)) and np.all(bb.energy > 0)
    assert np.abs(bb.energy / ref.energy - 1).max() < 1e-9
    assert np.abs(bb.xi_viscous - ref.xi_viscous).max() < 1e-9 * np.abs(ref.xi).max()
    # frirom show at the damping peak (backbone_point_state, no files): the energy balance
    # from the kept DoFs equals the one from every DoF's harmonics
    from types import SimpleNamespace
    from frirom.show_backbone import backbone_point_state
    deck = SimpleNamespace(model=lambda: cm, options=lambda: opts, output_map=None,
                           outputs=[int(d) for d in cm.nonlinear_dofs()[:2]],
                           output_names=["a", "b"])
    i = int(np.argmax(ref.damping_ratio))
    part, whole = (backbone_point_state(b, deck, i).balance for b in (bb, ref))
    for k in ("contacts", "viscous"):
        assert abs(part[k] - whole[k]) < 1e-9 * whole["excitation"], k
    print(f"show balance: residual {part['residual'] / part['excitation']:.1e}, "
          f"contacts {part['contacts'] / whole['contacts'] - 1:.1e}")
    assert abs(part["residual"]) < 1e-9 * part["excitation"]
