"""
Hysteresis of a friction element
================================

One Jenkins element (a tangential spring kt in series with a Coulomb slider of limit
mu fn0) driven by u(t) = A cos(t). :func:`frirom.contact.time_histories` returns the
closed cycle; the loop's area is the energy dissipated per cycle, which has a closed form
for this law: 4 mu fn0 (A - mu fn0 / kt) once the element slips (A > mu fn0 / kt), zero
while it sticks.
"""

import matplotlib.pyplot as plt
import numpy as np

from frirom import contact

kt, mu, fn0 = 1e5, 0.3, 100.0           # N/m, -, N: slips beyond A = mu fn0 / kt = 0.3 mm
amplitudes = np.array([0.2e-3, 0.5e-3, 1.0e-3, 2.0e-3])   # m

# x[e, d, :] = [a0, a1, b1, ...] of direction d of element e; H = 1 here
x = np.zeros((amplitudes.size, 1, 3))
x[:, 0, 1] = amplitudes
tau, u, f = contact.time_histories("jenkins", x, [kt, mu, fn0], n_samples=1024)

fig, ax = plt.subplots(figsize=(6, 4))
for k, a in enumerate(amplitudes):
    loop_u = np.append(u[k, 0], u[k, 0, 0])
    loop_f = np.append(f[k, 0], f[k, 0, 0])
    # the loop's area, the work of the force over one cycle (trapezoids around the loop)
    work = 0.5 * np.sum((loop_f[1:] + loop_f[:-1]) * np.diff(loop_u))
    exact = 4 * mu * fn0 * max(a - mu * fn0 / kt, 0.0)
    print(f"A = {a * 1e3:.1f} mm: dissipated {abs(work) * 1e3:8.4f} mJ, "
          f"closed form {exact * 1e3:8.4f} mJ")
    ax.plot(loop_u * 1e3, loop_f, label=f"A = {a * 1e3:.1f} mm")
ax.set_xlabel("relative displacement u (mm)")
ax.set_ylabel("friction force (N)")
ax.legend()
fig.tight_layout()
