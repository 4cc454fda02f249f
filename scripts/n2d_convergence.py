"""AFT error of the 2-D friction law (normal2d) against the number of time samples N.

Three regimes: a circular tangential orbit at constant normal load (slips all cycle; the
closed form of the dissipated energy is the reference), a Lissajous orbit at constant
normal load (stick and slip with curved slip paths) and an elliptic orbit with lift-off
(tests/test_aft_convergence.py's 'normal2d'); the last two against the same AFT at
N = 2^16. Prints the errors and the fitted slope of log(error) against log(N) on the upper
envelope, as tests/test_aft_convergence.py does.

    python scripts/n2d_convergence.py
"""

import numpy as np

from frirom import contact

N_FIT = (64, 80, 100, 128, 160, 200, 256, 320, 400, 512, 640, 800, 1024)
N_REF = 2 ** 16
H = 5


def x_of(terms, n_dir=3):
    x = np.zeros((1, n_dir, 2 * H + 1))
    for (d, c), value in terms.items():
        x[0, d, c] = value
    return x


REGIMES = {
    "stick-slip": (x_of({(0, 1): 0.45e-3, (1, 4): 0.4e-3, (1, 1): 0.1e-3}),
                   [1e5, 0.0, 0.3, 100.0]),
    "lift-off": (x_of({(0, 1): 0.1, (1, 2): 0.05, (2, 2): -1.0}), [2.0, 1.5, 0.3, 1.0]),
}


def slope(errors):
    env = np.maximum.accumulate(np.asarray(errors)[::-1])[::-1]
    return np.polyfit(np.log(N_FIT), np.log(env), 1)[0]


def circular():
    amp, kt, mu, fn = 1e-3, 1e5, 0.3, 100.0
    fs = mu * fn
    ref = 2 * np.pi * fs * np.sqrt(amp ** 2 - (fs / kt) ** 2)
    x = x_of({(0, 1): amp, (1, 2): amp})
    errs = []
    for n in N_FIT:
        f = contact.aft("normal2d", x, [kt, 0.0, mu, fn], n, jacobian=False).forces[0]
        errs.append(abs(np.pi * amp * (-f[0, 2] + f[1, 1]) / ref - 1))
    return np.array(errs)


def against_reference(x, params):
    ref = contact.aft("normal2d", x, params, N_REF, jacobian=False)
    scale = np.abs(ref.forces[0]).max(axis=-1)
    errs = []
    for n in N_FIT:
        f = contact.aft("normal2d", x, params, n, jacobian=False).forces[0]
        errs.append((np.abs(f - ref.forces[0]).max(axis=-1) / scale).max())
    return np.array(errs), ref.states[0]


def main():
    rows = [("circular (energy)", circular(), None)]
    for name, (x, p) in REGIMES.items():
        e, st = against_reference(x, p)
        rows.append((name, e, st))
    for name, e, st in rows:
        extra = "" if st is None else f"  states stick/slip/open {np.round(st, 3)}"
        print(f"{name:18s} slope {slope(e):6.3f}  N=256 {e[6]:.3e}  N=1024 {e[-1]:.3e}{extra}")


if __name__ == "__main__":
    main()
