"""Independent checks of the UPD case's nonlinear response (docs/cases/upd.md):

* the damper's static position under its load: frirom's nonlinear solve (contacts
  unloaded, n0 = 0, the damper pressed up by its load alone, harmonic 0) against a
  linear static solve of the stuck model (K + G^T Ks G) x = f;
* the response at points of the design curve against frirom's own time integration
  (frirom.timeint, HHT-alpha) of the reduced model, started from the HBM solution (its
  displacements, velocities and contact sliders at t = 0) and run to a steady state.

    python cases/upd/verify_upd.py --work DIR --loads 5 50 5000 --freqs 1950 1960 1985

DIR holds the matrices (make_upd.py) and upd.toml.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np
import scipy.sparse.linalg as spla


def at_load(work, load: float):
    """(deck, model, excitation) of upd.toml with the damper load set to ``load`` [N]:
    the pairs' n0 and the balancing harmonic-0 loads scale with it (both are linear in
    the load: frirom.deck.build.Builder.add_preload)."""
    from frirom.deck import load_deck
    d = load_deck(Path(work) / "upd.toml")
    base = float(d.raw["preload"][0]["load"])
    m, e = d.model(), d.excitation()
    for g in m.contacts:
        g.params[:, 3] *= load / base
    e.F[:, 0] *= load / base
    return d, m, e


def static_check(work, load: float = 200.0) -> dict:
    """The damper pressed up by its load (the balancing loads on its faces, +n0 n; the
    platforms unloaded) against unloaded contacts (n0 = 0): frirom's solve (harmonic 0;
    the dynamic load off) and the linear static solve of the stuck model. Returns the
    largest relative difference over the DoFs and the damper's mean lift [m]."""
    from frirom.model import Excitation
    from frirom.options import SolverOptions
    from frirom.solver import solve_point
    d, m, e = at_load(work, load)
    f0 = e.F[:, 0].real
    fd = np.where(f0 > 0, f0, 0.0)           # side a, the damper's faces (+y)
    for g in m.contacts:
        g.params[:, 3] = 0.0
    exc = Excitation(np.stack([fd, np.zeros_like(fd)], axis=1).astype(complex))
    n = m.n_dof
    p = solve_point(m, exc, 2 * np.pi * 100.0, SolverOptions(harmonics=1),
                    outputs=np.arange(n))
    x_hbm = p.X[:, 0]
    x_lin = spla.spsolve((m.K + m.stuck_stiffness()).tocsc(), fd)
    loaded = fd > 0
    return {"load": load, "err": float(np.abs(x_hbm - x_lin).max() / np.abs(x_lin).max()),
            "lift_hbm": float(x_hbm[loaded].mean()), "lift_lin": float(x_lin[loaded].mean()),
            "states": p.state_fractions.tolist()}


def ti_check(work, load: float, freq_hz: float, H: int = 3, periods: int = 40,
             steps: int = 128, frf_h5=None) -> dict:
    """HBM (H harmonics) at one load and frequency against time integration started
    from it; amplitudes of the first output (TIP_0 x): first harmonic and max |x(t)|.
    frf_h5: a curve of that load (a design-curve member's frf.h5); Newton then starts
    from its point nearest freq_hz (its unknowns and contact history), at that point's
    frequency: in gross slip near resonance Newton from the linear solution fails."""
    from frirom.results import FRF
    from frirom.solver import solve_point
    from frirom.timeint import TimeContact, integrate, state_from_harmonics
    d, m, e = at_load(work, load)
    n, w = m.n_dof, 2 * np.pi * freq_hz
    o = dataclasses.replace(d.options(), harmonics=H, stability=False)
    start, h0 = None, None
    if frf_h5 is not None:
        r = FRF.load(frf_h5)
        i = int(np.argmin(abs(r.omega - w)))
        w = float(r.omega[i])
        start = {"unknowns": r.unknowns[i], "slider": r.slider[i]}
        h0 = int(r.harmonics)
    p = solve_point(m, e, w, o, outputs=np.arange(n), start=start, start_harmonics=h0)
    freq_hz = w / 2 / np.pi
    x0, v0 = state_from_harmonics(p.X[None], np.array([w]))
    tcs, w0, off = [], [], 0
    for g in m.contacts:
        nsl = g.w0.shape[1] if np.ndim(g.w0) == 2 else 2
        tcs.append(TimeContact(g.law, g.G.toarray(), g.params))
        w0.append(np.asarray(p.slider[off:off + g.n_elem * nsl]).reshape(1, g.n_elem, nsl))
        off += g.n_elem * nsl
    ti = integrate(m.M.toarray(), m.C.toarray(), m.K.toarray(), tcs, e.F, w, H=H,
                   periods=periods, min_periods=periods, x0=x0, v0=v0, w0=w0, tol=0.0,
                   steps_per_period=steps, method="implicit")
    out = d.outputs[0]
    a_h = float(np.hypot(p.X[out, 1], p.X[out, 2]))
    a_t = float(np.hypot(ti.harmonics[0, out, 1], ti.harmonics[0, out, 2]))
    return {"load": load, "freq": freq_hz, "hbm": a_h, "ti": a_t, "rel": a_t / a_h - 1,
            "max_hbm": float(p.amp_max[out]), "max_ti": float(ti.amp_max[0, out]),
            "drift": float(ti.drift[0]), "slip_hbm": p.state_fractions.tolist(),
            "slip_ti": ti.state_fractions[0].tolist()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, required=True)
    ap.add_argument("--loads", type=float, nargs="*", default=[])
    ap.add_argument("--freqs", type=float, nargs="*", default=[])
    ap.add_argument("--periods", type=int, default=40)
    a = ap.parse_args(argv)
    print("static:", static_check(a.work))
    for load, f in zip(a.loads, a.freqs):
        print("time integration:", ti_check(a.work, load, f, periods=a.periods))


if __name__ == "__main__":
    main()
