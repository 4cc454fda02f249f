"""Continuation steps chosen by the curve's shape: a resonance drawn with about a hundred
points whose reported peak (FRF.peak) matches closed forms and a dense continuation."""

import dataclasses

import numpy as np
import pytest
import scipy.optimize
import scipy.sparse as sp

from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.solver import SolverOptions, frf

from _models import J_C, J_F, J_K, J_M, J_PAR, model_of


def oscillator(k3):
    """x'' + 0.02 x' + x + k3 x^3 = 0.1 cos(w t) (unit mass; the cubic law as its contact)."""
    G = sp.csr_matrix(np.array([[1.0]]))
    model = Model(np.eye(1), np.eye(1), Damping.rayleigh(0.0, 0.02),
                  [ContactGroup("cubic", G, [[0.0, k3]], name="cubic")])
    return model, Excitation(np.array([[0.0, 0.1]], complex))


def check_peak(name, r, p, w_ref, a_ref, solve_tol=1e-7):
    """The run's size and its solved peak p against (w_ref, a_ref): <= 120 points, 1e-4
    in amplitude and frequency (the target), and the amplitude within solve_tol: on a
    smooth peak Brent to 2e-3 of two steps along the curve gives it to ~(2e-3)^2, where
    the parabola through the points alone is off by 1e-6 (linear) and 6e-5 (Duffing)."""
    print(f"{name}: {len(r)} points, peak {p.amplitude / a_ref - 1:+.1e} in amplitude, "
          f"{p.omega / w_ref - 1:+.1e} in frequency")
    assert len(r) <= 120 and p.method == "solve"
    assert abs(p.amplitude / a_ref - 1) < min(1e-4, solve_tol)
    assert abs(p.omega / w_ref - 1) < 1e-4


def test_linear_resonance_peak_closed_form():
    """Linear oscillator (zeta = 0.01, a resonance 1 % wide in a range of 1): the peak
    A = F / (2 zeta sqrt(1 - zeta^2)) at w = sqrt(1 - 2 zeta^2). Drawn with <= 120 points
    (107 today), the solved peak within 1e-4 in amplitude and frequency (reached: 5e-10 and
    3e-7; the largest point alone is off by up to (step / width)^2)."""
    model, ex = oscillator(0.0)
    r = frf(model, ex, 0.5, 1.5, SolverOptions(harmonics=1, samples=16), outputs=[0])
    assert r.complete, r.message
    z = 0.01
    a_ref, w_ref = 0.1 / (2 * z * np.sqrt(1 - z**2)), np.sqrt(1 - 2 * z**2)
    check_peak("linear", r, r.peak(0), w_ref, a_ref)


def test_duffing_peak_closed_form():
    """Hardening Duffing (k3 = 0.5), H = 1 (16 samples: the cubic's AFT is exact): every point
    solves G(w, A) = A^2 ((1 - w^2 + 3/8 A^2)^2 + (0.02 w)^2) - 0.01 = 0; the largest A on
    the curve is where also dG/dw = 0: 1 - w^2 + 3/8 A^2 = 2e-4 and
    A^2 (4e-8 + 4e-4 w^2) = 0.01. The curve folds twice (the peak is one step before the
    upper fold); drawn with <= 120 points, its peak within 1e-4 in amplitude and
    frequency (reached: 6e-9 and 7e-7)."""
    model, ex = oscillator(0.5)
    r = frf(model, ex, 0.5, 2.5, SolverOptions(harmonics=1, samples=16), outputs=[0])
    assert r.complete, r.message
    assert r.fold.sum() == 2

    def eqs(v):
        w, A = v
        return [1 - w**2 + 0.375 * A**2 - 2e-4, A**2 * (4e-8 + 4e-4 * w**2) - 0.01]
    w_ref, a_ref = scipy.optimize.fsolve(eqs, [2.0, 2.5], xtol=1e-14)
    check_peak("duffing", r, r.peak(0), w_ref, a_ref)


def test_jenkins_peak_against_dense_continuation():
    """Jenkins SDOF, H = 5, 90 % slip at the peak (tests/test_verification.py), where the
    amplitude has a corner (slopes +13 and -2 per rad/s: a contact state appears there):
    the default steps against a continuation with 25x smaller steps (its own peak solved
    the same way between points 25x closer), 1e-4 (reached: 4e-7 and 3e-7)."""
    model = model_of(J_M, J_C, J_K, "jenkins", [[1.0]], J_PAR)
    o = SolverOptions(harmonics=5, samples=64)
    r = frf(model, Excitation(J_F), 0.8, 1.3, o, outputs=[0])
    dense = frf(model, Excitation(J_F), 0.8, 1.3,
                dataclasses.replace(o, ds=0.004, ds_max=0.004), outputs=[0])
    assert r.complete and dense.complete
    q = dense.peak(0)
    assert q.method == "solve"
    check_peak(f"jenkins ({len(dense)} points dense)", r, r.peak(0), q.omega, q.amplitude,
               solve_tol=1e-4)
