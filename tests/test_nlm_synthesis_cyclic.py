"""Forced responses of a cyclic sector synthesised from its backbone (single nonlinear mode
theory, frirom.nlm_synthesis, on a frirom.nonlinear_mode of a CyclicModel) against the
harmonic balance forced response of the same cyclic model under the travelling-wave
engine-order load (frirom.frf: a continuation in frequency that knows nothing of the
backbone).

The projection is the sector's: harmonic 1 of the mode mass-normalised over the sector in
the modes of its nodal diameter k_1 (psi^H M_k psi = I), the load sector 0's harmonic 1
F_1 (sector s carries it delayed by s k / N of a period), q = psi_1^H F_1.

- A sector of one DoF (a mass on a spring, a Jenkins damper to the next sector's mass) at
  H = 1: the travelling wave's shape cannot change, so the modal equation is the harmonic
  balance itself and the two differ by the backbone's interpolation only (as the
  single-DoF Jenkins oscillator of tests/test_nlm_synthesis.py).
- The lattice rotor of tests/_rotor.py (7 sectors, preloaded normal1d ground contacts,
  Jenkins dampers between neighbouring blade tips), light Rayleigh damping (0.05 % of
  critical at the stuck mode), H = 3, engine order 2 (harmonic 1 on nodal diameter 5),
  the tip load from stick to gross slip of the tip dampers.
"""

import numpy as np
import pytest
import scipy.sparse as sp

import frirom
from _rotor import N, rotor, rotor_sector, sector_contacts
from frirom import ParameterError
from frirom.model import ContactGroup, Damping, Excitation
from frirom.nonlinear_modes import nonlinear_mode
from frirom.reduction.cyclic import CyclicSector, cyclic_model

EO = 2


def peak_errors(s, r, j=0):
    ps, ph = s.peak(j), r.peak(j)
    return ps.amplitude / ph.amplitude - 1, ps.omega / ph.omega - 1


def test_one_dof_sector_h1_is_the_harmonic_balance():
    """One DoF per sector (m = 1 kg, k = 1e4 N/m, a Jenkins damper kt = 2e3 N/m, slip force
    1 N, to the next sector's mass; 0.5 1/s mass-proportional damping), H = 1: the peaks
    of the synthesis and of the HBM agree to the backbone's interpolation at slip onset,
    in microslip and in gross slip: amplitude within 1e-3 (seen 3.0e-4, 6.3e-5, 8.7e-6),
    frequency 2e-3 (seen 7.2e-4, 2.7e-4, 2.0e-5; the friction-flattened top makes it
    sensitive). The start is the stuck travelling wave: omega_0^2 = k + kt |1 - e^{i k_1
    2 pi / N}|^2, k_1 = 5."""
    sector = CyclicSector(n_dof=1, n_sectors=N, left=np.zeros(0, int),
                          right=np.zeros(0, int), axis=np.array([0.0, 0.0, 1.0]),
                          origin=np.zeros(3))
    damper = ContactGroup("jenkins", sp.csr_matrix(np.array([[1.0, -1.0]])), (2e3, 0.5, 2.0),
                          name="tips")
    cm = cyclic_model(sector, sp.csr_matrix([[1e4]]), sp.csr_matrix([[1.0]]), [damper], EO,
                      1, damping=Damping.rayleigh(0.5, 0.0))
    opts = frirom.SolverOptions(harmonics=1, samples=16 * N, tol_residual=1e-11,
                                tol_update=1e-11, max_iter=40, ds=0.005, ds_max=0.01)
    bb = nonlinear_mode(cm, 0, (1e-5, 1e-1), "stuck", opts)
    assert bb.nodal_diameter == 5
    w0 = np.sqrt(1e4 + 2e3 * abs(1 - np.exp(2j * np.pi * 5 / N)) ** 2)
    assert bb.omega0 == pytest.approx(w0, rel=1e-12)
    lo, hi = 0.9 * bb.omega.min(), 1.05 * bb.omega0
    for f in (0.3, 1.0, 3.0):
        F = np.zeros((1, 2), complex)
        F[0, 1] = f
        s = bb.forced_response(Excitation(F), (lo, hi))
        r = frirom.frf(cm, Excitation(F), lo, hi, opts)
        ea, ew = peak_errors(s, r)
        print(f"one-DoF sector {f} N: peak amplitude {ea:+.2e}, frequency {ew:+.2e}")
        assert s.complete and r.complete
        assert abs(ea) < 1e-3 and abs(ew) < 2e-3


@pytest.fixture(scope="module")
def rotor_case():
    r, K, Ks, glob = rotor()
    s = r["sector"]
    n_s = Ks.shape[0]
    cm = cyclic_model(rotor_sector(r, N), Ks, s["M"], sector_contacts(r, glob, n_s), EO, 3,
                      damping=Damping.rayleigh(0.5, 5e-7))
    tip = r["tips"]
    th = np.arctan2(r["coords"][tip[0], 1], r["coords"][tip[0], 0])
    loc = -np.ones(glob.max() + 1, dtype=np.int64)
    loc[glob] = np.arange(glob.size)
    td = loc[3 * tip[0] + np.arange(3)]
    F = np.zeros((n_s, 2), complex)
    F[td, 1] = np.array([-np.sin(th), np.cos(th), 0.3])     # per newton of tip load
    # a backbone resolved where the damping ratio peaks (ds_max 0.01 in log10 a)
    opts = frirom.SolverOptions(harmonics=3, samples=16 * N, tol_residual=1e-10,
                                tol_update=1e-10, max_iter=40, ds=0.005, ds_max=0.01)
    bb = nonlinear_mode(cm, 0, (1e-6, 3e-1), "stuck", opts, outputs=list(td))
    return cm, bb, F, td, opts


@pytest.mark.parametrize("level, tol_a, tol_w", [(0.05, 2e-2, 1e-4), (1.0, 0.15, 6e-3),
                                                 (5.0, 4e-2, 5e-4)])
def test_lattice_rotor_against_hbm(rotor_case, level, tol_a, tol_w):
    """The rotor's tip (tangential output) under levels from the tip dampers' slip onset
    (0.05 N: one element in eight of a period slipping; the ground contacts stuck) through
    microslip (1 N) to their gross slip (5 N): peak amplitude -1.3 %, -10.8 %, -2.8 % and
    frequency +1.9e-5, +4.2e-3, +2.0e-4. In the linear limit (0.005 N) the two agree to
    3e-4. The error is largest where the contacts' damping peaks: at 1 N the forced
    deflection at the peak differs from the free mode's at the same modal amplitude by
    1.8 % (modal coordinates), but the relative motion of neighbouring tips, which sets
    the dampers' dissipation, by 13 % (0.578 against 0.668 per unit modal amplitude);
    there the synthesis is a first estimate."""
    cm, bb, F, td, opts = rotor_case
    lo, hi = 0.9 * bb.omega0, 1.05 * bb.omega0
    ex = Excitation(F * level)
    s = bb.forced_response(ex, (lo, hi))
    r = frirom.frf(cm, ex, lo, hi, opts, outputs=list(td))
    ea, ew = peak_errors(s, r)
    print(f"rotor {level} N: tip peak amplitude {ea:+.2e}, frequency {ew:+.2e}")
    assert s.complete and r.complete
    assert abs(ea) < tol_a and abs(ew) < tol_w


def test_cyclic_load_rows(rotor_case):
    """A load that is not the sector's is refused, naming it."""
    cm, bb, F, td, opts = rotor_case
    with pytest.raises(ParameterError, match="load"):
        bb.forced_response(np.ones(5, complex))


def test_large_sector_backbone_synthesises(rotor_case, monkeypatch, tmp_path):
    """A sector above _ALL_OUTPUTS coordinates (forced here on the rotor's 114) keeps only
    its contact DoFs and outputs (Backbone.harmonic_dofs): the load on the whole sector is
    taken on them, and the synthesis equals the one from every DoF's harmonics (1e-10);
    backbone.h5 keeps those rows; a loaded DoF it does not keep is refused, naming the
    load and the way out."""
    import frirom.nonlinear_modes_cyclic as nmc
    cm, bb, F, td, opts = rotor_case
    monkeypatch.setattr(nmc, "_ALL_OUTPUTS", 50)
    small = nonlinear_mode(cm, 0, (1e-6, 3e-1), "stuck", opts, outputs=list(td))
    assert small.harmonic_dofs is not None and bb.harmonic_dofs is None
    assert small.harmonics.shape[1] < F.shape[0]
    lo, hi = 0.9 * bb.omega0, 1.05 * bb.omega0
    ex = Excitation(F * 1.0)
    s, ref = small.forced_response(ex, (lo, hi)), bb.forced_response(ex, (lo, hi))
    assert s.omega.size == ref.omega.size
    assert np.abs(s.omega - ref.omega).max() < 1e-10 * ref.omega.max()
    assert np.abs(s.amp_max - ref.amp_max).max() < 1e-10 * ref.amp_max.max()
    from frirom.backbone import load_h5, save_h5
    save_h5(small, tmp_path / "bb.h5")
    assert np.array_equal(load_h5(tmp_path / "bb.h5")[0].harmonic_dofs, small.harmonic_dofs)
    tip_only = nonlinear_mode(cm, 0, (1e-6, 1e-3), "stuck", opts, outputs=[int(td[0])])
    with pytest.raises(ParameterError, match="load: DoFs .* outputs"):
        tip_only.forced_response(ex, (lo, hi))
