"""Independent checks of the UPD case's nonlinear response (docs/cases/upd.md):

* the damper's static position under its load: frirom's nonlinear solve (contacts
  unloaded, n0 = 0, the damper pressed up by its load alone, harmonic 0) against a
  linear static solve of the stuck model (K + G^T Ks G) x = f, reduced
  (static_check) and CalculiX's FE matrices (fe_static_check);
* the response at points of the design curve against frirom's own time integration
  (frirom.timeint, HHT-alpha) of the reduced model, started from the HBM solution (its
  displacements, velocities and contact sliders at t = 0) and run to a steady state.

    python cases/upd/verify_upd.py --work DIR --loads 200 5000 --freqs 1973.37 1982.9

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


def fe_static_check(work, load: float = 200.0) -> dict:
    """The damper pressed up by its load against unloaded contacts (as static_check),
    frirom's solve of the reduced model against a linear static solve of the stuck *FE*
    model: CalculiX's own stiffness matrix (upd.sti, 12 771 DoFs, the retainer's SPRING1
    elements in it) with every contact pair joined by the deck's springs (kt along x and
    z, kn along y, as stuck.inp does), the load n0 per pair on the damper's face nodes
    (+y), solved by scipy. Compared on the reduction's physical DoFs (the contact patches
    and the tips): the largest difference over them relative to the largest
    displacement, and the damper's mean lift."""
    import scipy.sparse as sp

    from frirom.io.calculix import read_calculix
    from frirom.model import Excitation
    from frirom.options import SolverOptions
    from frirom.solver import solve_point
    d, m, e = at_load(work, load)
    f0 = e.F[:, 0].real
    fd = np.where(f0 > 0, f0, 0.0)
    for g in m.contacts:
        kt, kn = float(g.params[0, 0]), float(g.params[0, 1])
        g.params[:, 3] = 0.0
    exc = Excitation(np.stack([fd, np.zeros_like(fd)], axis=1).astype(complex))
    p = solve_point(m, exc, 2 * np.pi * 100.0, SolverOptions(harmonics=1),
                    outputs=np.arange(m.n_dof))
    fe = read_calculix(Path(work) / "upd", mass=False)
    row = {(int(n), int(c)): i for i, (n, c) in enumerate(fe.dofs)}
    xyz = dict(zip(fe.node_ids.tolist(), np.round(fe.coords * 1e7).astype(int).tolist()))
    ii, jj, vv = [], [], []
    for side, plat in (("DAMPER_L", "PLAT_0"), ("DAMPER_R", "PLAT_1")):
        at = {tuple(xyz[int(n)]): int(n) for n in fe.node_sets[plat]}
        for a in fe.node_sets[side]:
            b = at[tuple(xyz[int(a)])]
            for c, k in ((1, kt), (2, kn), (3, kt)):
                ra, rb = row[(int(a), c)], row[(b, c)]
                ii += [ra, rb, ra, rb]
                jj += [ra, rb, rb, ra]
                vv += [k, k, -k, -k]
    n_fe = fe.K.shape[0]
    Ks = sp.csr_matrix((vv, (ii, jj)), shape=(n_fe, n_fe))
    labels = d.dof_labels
    phys = [i for i, lab in enumerate(labels) if lab.startswith("N") and ":" in lab]
    dirs = {"x": 1, "y": 2, "z": 3, "UX": 1, "UY": 2, "UZ": 3}
    fe_rows = []
    for i in phys:
        node, c = labels[i][1:].split(":")
        fe_rows.append(row[(int(node), dirs[c])])
    f_fe = np.zeros(n_fe)
    f_fe[fe_rows] = fd[phys]
    x_fe = spla.spsolve((fe.K + Ks).tocsc(), f_fe)[fe_rows]
    x_hbm = p.X[phys, 0]
    loaded = fd[phys] > 0
    return {"load": load, "n_fe": n_fe, "n_compared": len(phys),
            "err": float(np.abs(x_hbm - x_fe).max() / np.abs(x_fe).max()),
            "lift_hbm": float(x_hbm[loaded].mean()), "lift_fe": float(x_fe[loaded].mean()),
            "states": p.state_fractions.tolist()}


#: the damper's mass [kg]: cases/models/upd.py's strip, 10 x 2 x 8 cells of 2 mm, steel
DAMPER_MASS = 7850.0 * (10 * 2 * 8) * 0.002 ** 3


def bounce_ratio(work, d, X, omega: float, load: float) -> float:
    """Gamma = omega^2 Y / (load / m): the platforms' largest radial (y) vibration
    amplitude Y at the contact patches (harmonic 1 of X, the model's DoFs) against the
    damper's centrifugal acceleration. Above 1 the platforms throw the damper off once
    a cycle even when it follows them (a ball on a vibrating table): it bounces."""
    from frirom.io.calculix import read_inp
    sets = read_inp(Path(work) / "upd.inp")[2]
    plat = {int(n) for k in ("PLAT_0", "PLAT_1") for n in sets[k]}
    rows = [i for i, lab in enumerate(d.dof_labels)
            if lab.endswith(":UY") and int(lab[1:lab.index(":")]) in plat]
    y = float(np.hypot(X[rows, 1], X[rows, 2]).max())
    return omega ** 2 * y / (load / DAMPER_MASS)


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
            "drift": float(ti.drift[0]), "gamma": bounce_ratio(work, d, p.X, w, load),
            "slip_hbm": p.state_fractions.tolist(),
            "slip_ti": ti.state_fractions[0].tolist()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, required=True)
    ap.add_argument("--loads", type=float, nargs="*", default=[])
    ap.add_argument("--freqs", type=float, nargs="*", default=[])
    ap.add_argument("--periods", type=int, default=40)
    a = ap.parse_args(argv)
    print("static, reduced model:", static_check(a.work))
    print("static, CalculiX's FE matrices:", fe_static_check(a.work))
    for load, f in zip(a.loads, a.freqs):
        print("time integration:", ti_check(a.work, load, f, periods=a.periods))


if __name__ == "__main__":
    main()
