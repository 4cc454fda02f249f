"""The backbone of a friction system against its free decay by time integration.

The lumped blade with its friction damper (cases/joint/joint_mode.toml) is started on
its nonlinear mode (the EPMC backbone's motion at a modal amplitude, the damper's slider
where a stick-slip cycle leaves it) and let go: frirom.timeint (central differences,
written from the contact physics alone, nothing of the HBM or the EPMC) integrates the
decay. Each cycle of the motion projected on the mode gives an instantaneous frequency
(between up-crossings of zero) and a decay rate (log decrement over the two neighbouring
cycles / 4 pi = damping ratio), compared with the backbone's at the cycle's amplitude
(the same projection of the backbone's motion).

What the comparison can give: the EPMC describes a motion whose amplitude does not
change, so it holds while the damping ratio changes little over a cycle's amplitude
range. Measured: in stick (linear) frequency and damping to 3e-6 (the time step's
(2 pi / 1024)^2 / 24 frequency shift is 1.6e-6); in microslip and gross slip, where D is
1-3 % and changes by less than 20 % over a cycle, the frequency to 2.3e-3 and the damping
ratio to 1.6e-2 relatively. Where the decay crosses the end of microslip D falls five-fold
within a cycle and the cycle-wise comparison means nothing: those cycles are left out by
that criterion (stated in the test).
"""

import dataclasses
from pathlib import Path

import numpy as np

from frirom.deck import load_deck
from frirom.nonlinear_modes import nonlinear_mode
from frirom.timeint import TimeContact, integrate


def _dense(A):
    return np.asarray(A.toarray() if hasattr(A, "toarray") else A, float)


def test_free_decay_follows_the_backbone():
    deck = load_deck(Path(__file__).parents[1] / "cases" / "joint" / "joint_mode.toml")
    model = deck.model()
    opts = dataclasses.replace(deck.options(), ds_max=0.02, ds=0.02, samples=256)
    bb = nonlinear_mode(model, 0, (1e-7, 1e-3), "stuck", opts)
    assert bb.status == "done"
    M, C, K = _dense(model.M), _dense(model.C), _dense(model.K)
    cons = [TimeContact(g.law, _dense(g.G), g.params) for g in model.contacts]
    H, N, P = bb.H, 1024, 12                      # steps per cycle, cycles integrated
    tau = 2 * np.pi * np.arange(256) / 256
    basis = np.vstack([np.ones_like(tau)] + [f(h * tau) for h in range(1, H + 1)
                                             for f in (np.cos, np.sin)])
    checked = {"linear": 0, "slip": 0}
    for a in (1e-6, 1e-4, 3e-4):
        i = int(np.argmin(abs(np.log(bb.amplitude / a))))
        X = bb.harmonics[i]
        psi = X[:, 1] / np.sqrt(X[:, 1] @ M @ X[:, 1])
        qb = np.einsum("i,ij,pjc->pc", psi, M, bb.harmonics) @ basis
        Ab = 0.5 * (qb.max(axis=1) - qb.min(axis=1))       # the backbone's, projected
        o = np.argsort(Ab)
        x0 = X[:, 0] + X[:, 1::2].sum(axis=1)
        v0 = bb.omega[i] * (np.arange(1, H + 1) * X[:, 2::2]).sum(axis=1)
        w0 = []
        for g in cons:              # Jenkins slider at a turning point of the cycle
            u0 = g.G @ x0
            kt, mu, fn = g.params[:, 0], g.params[:, 1], g.params[:, 2]
            w0.append((u0 - np.clip(kt * u0, -mu * fn, mu * fn) / kt)[:, None])
        # one "period" of the integrator spans P cycles: its samples are the whole decay
        r = integrate(M, C, K, cons, np.zeros((M.shape[0], 2), complex), bb.omega[i] / P,
                      periods=1, min_periods=1, steps_per_period=P * N, x0=x0, v0=v0,
                      w0=w0, method="explicit", H=1)
        dt = 2 * np.pi * P / (bb.omega[i] * r.steps_per_period)
        q = r.samples[0] @ M @ psi
        up = np.flatnonzero((q[:-1] < 0) & (q[1:] >= 0))
        tc = (up - q[up] / (q[up + 1] - q[up])) * dt
        A = np.array([0.5 * np.ptp(q[up[k]:up[k + 1]]) for k in range(up.size - 1)])
        assert A.size >= P - 2
        for k in range(1, A.size - 1):
            w = 2 * np.pi / (tc[k + 1] - tc[k])
            D = np.log(A[k - 1] / A[k + 1]) / (4 * np.pi)
            wb, Db = (np.interp(np.log(A[k]), np.log(Ab[o]), v[o])
                      for v in (bb.omega, bb.damping_ratio))
            Dr = [np.interp(np.log(A[j]), np.log(Ab[o]), bb.damping_ratio[o])
                  for j in (k - 1, k + 1)]
            if abs(Dr[0] - Dr[1]) > 0.2 * Db:
                continue            # D changes too fast across the cycle (end of microslip)
            if a == 1e-6:           # stick: the modal damping 0.3 % of the free modes
                assert abs(w / wb - 1) < 1e-5 and abs(D / Db - 1) < 1e-5
                checked["linear"] += 1
            elif Db > 0.0035:       # slipping (after it stops, the cycles next to it mix)
                assert abs(w / wb - 1) < 3e-3, (a, k, w / wb - 1)
                assert abs(D / Db - 1) < 3e-2, (a, k, D / Db - 1)
                checked["slip"] += 1
    print("cycles compared:", checked)
    assert checked["linear"] >= 8 and checked["slip"] >= 12
