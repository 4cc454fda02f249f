"""An FRF with 2-D friction contacts through the onset of partial slip, against time
integration.

The model: a platform node (x, y in the contact plane, z normal) under a tip mass that
moves it on a thin ellipse, held by eight normal2d elements in parallel whose preloads
are spread (0.1 to 0.8), so that along the curve one element after another reaches the
onset of partial slip. There plain marching contracts the 2-D slider mismatch about 0.99
a period and did not close in 200 periods: the continuation stopped at 0.60 rad/s ("not
closed after 200 periods", forcing 0.1) or crawled to max_points (forcing 0.05), where
the march with Newton steps on the slider (frirom_aft_march) runs through in a few
hundred points.

Tolerances: those of tests/test_verification.py (the issue 3 criteria), whose peak
comparison (compare_peak, now in tests/_models.py) this reuses: peak amplitude within 1 %
and resonance frequency within 0.2 % of time integration (central differences, N = 512,
its own contact return maps); the H = 5 truncation dominates.
"""

import numpy as np
import pytest

from frirom import contact
from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import SolverOptions
from frirom.timeint import TimeContact

from _models import compare_peak, run_frf

NE = 8                                   # parallel contact elements
M2 = np.diag([1.0, 1.0, 1.0, 0.5])      # platform x, y, z; tip
K2 = np.array([[3.0, 0.4, 0.0, -1.0], [0.4, 3.6, 0.0, -0.6], [0.0, 0.0, 4.0, 0.0],
               [-1.0, -0.6, 0.0, 1.6]])
C2 = 0.01 * K2 + 0.01 * M2
G2 = np.zeros((3 * NE, 4))
for _e in range(NE):
    G2[3 * _e, 0] = G2[3 * _e + 1, 1] = G2[3 * _e + 2, 2] = 1.0
# kt, kn, mu, n0 per element: together kt = kn = 2, preloads 0.1 ... 0.8 (sum 3.6)
PAR2 = np.stack([np.full(NE, 2.0 / NE), np.full(NE, 2.0 / NE), np.full(NE, 0.3),
                 np.linspace(0.1, 0.8, NE) / NE], axis=1)
F2 = np.zeros((4, 2), complex)
F2[3, 1] = 0.1


@pytest.fixture(scope="module")
def normal2d_run():
    group = ContactGroup(law="normal2d", G=G2, params=PAR2, name="platform")
    m = Model(M2, K2, Damping.matrix(C2), [group])
    opts = SolverOptions(harmonics=5, samples=64, ds=0.02, ds_max=0.02, max_points=1500)
    return run_frf(m, Excitation(F2), 0.5, 1.5, opts)


def test_normal2d_frf_runs_through_the_onset_of_partial_slip(normal2d_run):
    r = normal2d_run["frf"]
    assert r.complete, r.message
    assert r.omega[-1] == pytest.approx(1.5)
    # the six elements of larger preload stick all cycle somewhere and slip elsewhere: each
    # goes through its onset of partial slip along the curve (per-element states by the
    # AFT at every point); the two lightest slip all along
    assert r.X.shape[1] == 4
    x = np.einsum("rd,pdc->prc", G2, r.X).reshape(len(r), NE, 3, -1)
    stuck = np.zeros((len(r), NE), bool)
    for k, p in enumerate(normal2d_run["points"]):    # from the slider each point left
        a = contact.aft("normal2d", x[k], PAR2, 64, w0=p.slider.reshape(NE, 2),
                        jacobian=False)
        stuck[k] = a.states[:, 0] == 1.0
    assert np.all((~stuck).any(axis=0)), stuck.sum(axis=0)
    assert stuck.any(axis=0).sum() >= 6, stuck.sum(axis=0)


@pytest.mark.slow
def test_normal2d_peak_against_time_integration(normal2d_run):
    con = TimeContact("normal2d", G2, PAR2)
    (w_h, a_h), (w_t, a_t), ti = compare_peak(normal2d_run, 3, M2, C2, K2, [con], F2)
    i = np.argmin(np.abs(ti.omega - w_t))
    assert ti.state_fractions[i, :, 1].max() > 0.2        # the contacts slip at the peak
    print(f"normal2d peak: HBM {w_h:.6f} rad/s {a_h:.6f}, time integration {w_t:.6f} rad/s "
          f"{a_t:.6f}: {a_h / a_t - 1:.2e} in amplitude, {w_h / w_t - 1:.2e} in frequency")
    assert abs(a_h / a_t - 1) < 1e-2, (a_h, a_t)
    assert abs(w_h / w_t - 1) < 2e-3, (w_h, w_t)
