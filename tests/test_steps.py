"""Continuation steps chosen by the curve's shape: a resonance drawn with about a hundred
points whose reported peak (FRF.peak) matches closed forms and a dense continuation."""

import dataclasses

import numpy as np
import pytest
import scipy.optimize
import scipy.sparse as sp

from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import SolverOptions, frf

from test_verification import J_C, J_F, J_K, J_M, J_PAR, model_of


def oscillator(k3):
    """x'' + 0.02 x' + x + k3 x^3 = 0.1 cos(w t) (unit mass; the cubic law as its contact)."""
    G = sp.csr_matrix(np.array([[1.0]]))
    model = Model(np.eye(1), np.eye(1), Damping.rayleigh(0.0, 0.02),
                  [ContactGroup("cubic", G, [[0.0, k3]], name="cubic")])
    return model, Excitation(np.array([[0.0, 0.1]], complex))


def test_linear_resonance_peak_closed_form():
    """Linear oscillator (zeta = 0.01, a resonance 1 % wide in a range of 1): the peak
    A = F / (2 zeta sqrt(1 - zeta^2)) at w = sqrt(1 - 2 zeta^2). Reached with <= 120 points
    (the former Newton-effort steps needed ~?): amplitude and frequency within 1e-4."""
    model, ex = oscillator(0.0)
    r = frf(model, ex, 0.5, 1.5, SolverOptions(harmonics=1, samples=16), outputs=[0])
    assert r.complete, r.message
    z = 0.01
    a_ref, w_ref = 0.1 / (2 * z * np.sqrt(1 - z**2)), np.sqrt(1 - 2 * z**2)
    p = r.peak(0)
    print(f"linear: {len(r)} points, peak {p.amplitude / a_ref - 1:+.1e} in amplitude, "
          f"{p.omega / w_ref - 1:+.1e} in frequency")
    assert len(r) <= 120
    assert abs(p.amplitude / a_ref - 1) < 1e-4
    assert abs(p.omega / w_ref - 1) < 1e-4


def test_duffing_peak_closed_form():
    """Hardening Duffing (k3 = 0.5), H = 1 (16 samples: the cubic's AFT is exact): every point
    solves ((1 - w^2) A + 3/8 ... ; the largest A on the curve is where dG/dw = 0 besides
    G(w, A) = 0: 1 - w^2 + 3/8 A^2 = 2e-4 and A^2 (4e-8 + 4e-4 w^2) = 0.01. The curve
    folds twice; drawn with <= 120 points, its peak within 1e-4 in amplitude and frequency."""
    model, ex = oscillator(0.5)
    r = frf(model, ex, 0.5, 2.5, SolverOptions(harmonics=1, samples=16), outputs=[0])
    assert r.complete, r.message
    assert r.fold.sum() == 2

    def eqs(v):
        w, A = v
        return [1 - w**2 + 0.375 * A**2 - 2e-4, A**2 * (4e-8 + 4e-4 * w**2) - 0.01]
    w_ref, a_ref = scipy.optimize.fsolve(eqs, [2.0, 2.5], xtol=1e-14)
    p = r.peak(0)
    print(f"duffing: {len(r)} points, peak {p.amplitude / a_ref - 1:+.1e} in amplitude, "
          f"{p.omega / w_ref - 1:+.1e} in frequency")
    assert len(r) <= 120
    assert abs(p.amplitude / a_ref - 1) < 1e-4
    assert abs(p.omega / w_ref - 1) < 1e-4


def test_jenkins_peak_against_dense_continuation():
    """Jenkins SDOF, H = 5, 90 % slip at the peak (tests/test_verification.py): the default
    steps against a continuation with 25x smaller steps (its own peak refined the same
    way, from points 25x closer: its error is far below the tolerance): 1e-4."""
    model = model_of(J_M, J_C, J_K, "jenkins", [[1.0]], J_PAR)
    o = SolverOptions(harmonics=5, samples=64)
    r = frf(model, Excitation(J_F), 0.8, 1.3, o, outputs=[0])
    dense = frf(model, Excitation(J_F), 0.8, 1.3,
                dataclasses.replace(o, ds=0.004, ds_max=0.004), outputs=[0])
    assert r.complete and dense.complete
    p, q = r.peak(0), dense.peak(0)
    print(f"jenkins: {len(r)} points ({len(dense)} dense), peak "
          f"{p.amplitude / q.amplitude - 1:+.1e} in amplitude, "
          f"{p.omega / q.omega - 1:+.1e} in frequency")
    assert len(r) <= 120
    assert abs(p.amplitude / q.amplitude - 1) < 1e-4
    assert abs(p.omega / q.omega - 1) < 1e-4
