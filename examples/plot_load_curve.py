"""
Load curve: from stick to gross slip
====================================

The two-mass chain of the README at a fixed frequency, with the excitation scaled from
0.1 to 20 N by :func:`frirom.load_curve`. While the friction element sticks, the response
grows linearly with the load (the stuck system's receptance, checked below against a
direct linear solve); once it slips, the ratio moves towards the free system's.
"""

import matplotlib.pyplot as plt
import numpy as np

import frirom

K = np.array([[3e6, -1e6], [-1e6, 1e6]])              # N/m
M = np.diag([0.05, 0.02])                              # kg
damper = frirom.ContactGroup("jenkins", G=[[1.0, 0.0]], params=[1e6, 0.3, 60.0])
model = frirom.Model(M, K, frirom.Damping.rayleigh(0.0, 2e-6), [damper])
load = frirom.Excitation(np.array([0.0, 1.0]))         # 1 N cos(wt) on the second mass
omega = 2 * np.pi * 830.0

curve = frirom.load_curve(model, load, omega, 0.1, 20.0,
                          frirom.SolverOptions(harmonics=3), outputs=[1])
s = curve.parameter

# the stuck system's linear response per newton (damper as a spring kt on mass 1)
Ks = K + np.diag([1e6, 0.0])
C = 2e-6 * K                                            # Rayleigh beta K (free system)
x_stuck = np.linalg.solve(Ks - omega**2 * M + 1j * omega * C, [0.0, 1.0])
print(f"first point: {curve.amp_max[0, 0] / s[0]:.4e} m/N, "
      f"stuck linear {abs(x_stuck[1]):.4e} m/N")

fig, ax = plt.subplots(figsize=(6, 4))
ax.plot(s, curve.amp_max[:, 0] / s, label="per newton of load")
ax.axhline(abs(x_stuck[1]), ls=":", c="k", label="stuck, linear")
ax.set_xlabel("load amplitude (N)")
ax.set_ylabel("tip amplitude / load (m/N)")
ax.legend()
fig.tight_layout()
