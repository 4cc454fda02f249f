"""One point of a forced response, as an engineer reads it (`frirom show`).

The point is solved again from the unknowns and contact history stored with it in
``frf.h5`` (one Newton step at a stored point; a short Newton solve at a frequency between
points), with every coordinate of the model kept, so that everything follows from it:

- the outputs over one period (the FE DoFs the deck names, through the reduction basis);
- per contact element (pair): its relative displacements and forces over the closed cycle
  (the solver's AFT march, same samples, same history), the energy it dissipates per
  period, the fraction of the period it sticks, slips and is lifted off, its peak normal
  force and slip amplitude;
- the power balance of the period: the work of the excitation equals the energy the
  contacts and the viscous damping dissipate (:attr:`PointState.balance`).

:func:`write_point` writes these as CSV and PNG (time histories, hysteresis loops of chosen
or of the most dissipative contacts, dissipated energy per contact); the interface maps and
the VTK export are in :mod:`frirom.maps`.
"""

from __future__ import annotations

import csv
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ._errors import FriromError, InputError
from .contact import LAWS, aft, time_histories
from .model import CyclicModel
from .results import FRF, _series

__all__ = ["PointState", "ContactField", "load_run", "pick_point", "point_state",
           "write_point", "parse_frequency"]


@dataclass
class ContactField:
    """One contact group at a point: per element (pair) e of n_elem.

    tau (N,) phase, rad; u, f (n_elem, n_dir, N) relative displacements [m] and forces
    [N] over the closed cycle in the law's directions (``directions``); energy (n_elem,)
    dissipated per period [J]; states (n_elem, 3) stick, slip, lift-off fractions of the
    period; fn_max (n_elem,) peak normal force [N] (the law's constant fn0 for 'jenkins',
    0 without a normal direction); slip (n_elem,) slip amplitude [m], half the range of the
    slider's travel u_t - f_t / kt over the period.
    """

    name: str
    law: str
    directions: tuple
    tau: np.ndarray
    u: np.ndarray
    f: np.ndarray
    energy: np.ndarray
    states: np.ndarray
    fn_max: np.ndarray
    slip: np.ndarray

    @property
    def n_elem(self) -> int:
        return self.energy.size


@dataclass
class PointState:
    """The full periodic state at one frequency.

    omega rad/s; index: the stored point it was solved from; x (n_dof, 2H+1) harmonics of
    every model coordinate; outputs (n_out, 2H+1) of the deck's outputs; labels (n_out,);
    contacts: ContactField per group; balance: {'excitation', 'contacts', 'viscous'} work
    per period [J] (for a cyclic sector per sector, the viscous part from the modes of
    each harmonic's nodal diameter) and 'residual' = excitation - contacts - viscous.
    held: frirom.held.Held per group, what the free-body pin decided ([]: no free body);
    patch: warnings of pairs sliding beyond their contact patch (frirom.held).
    """

    omega: float
    index: int
    x: np.ndarray
    outputs: np.ndarray
    labels: list
    contacts: list
    balance: dict = field(default_factory=dict)
    held: list = field(default_factory=list)
    patch: list = field(default_factory=list)

    @property
    def frequency_hz(self) -> float:
        return self.omega / (2.0 * np.pi)


def load_run(out, deck_path=None):
    """(FRF, Deck) of a result folder (or an frf.h5 file) written by ``frirom run``.

    The deck is the one the run was made with (``deck_path`` of the file, else
    ``OUT/deck.toml``'s source), read again; `deck_path` overrides it. A deck whose text
    differs from the one stored in the file is refused (the point could not be solved
    again as it was made).
    """
    from .deck import load_deck
    out = Path(out)
    h5 = out / "frf.h5" if out.is_dir() else out
    if not h5.is_file():
        raise InputError(f"{h5}: no result file (run `frirom run DECK --out {out}` first)")
    frf = FRF.load(h5)
    path = Path(deck_path) if deck_path else Path(frf.meta.get("deck_path", ""))
    if not str(path) or not path.is_file():
        raise InputError(f"{h5}: the deck it was made with is not found "
                         f"({path or 'not recorded'}); give it with --deck")
    stored = frf.meta.get("deck_text")
    if stored is not None and path.read_text() != stored:
        raise InputError(f"{path}: differs from the deck the results in {h5} were made "
                         "with (stored in the file as deck_text); rerun it")
    return frf, load_deck(path)


def parse_frequency(text: str, unit: str = "hz") -> float:
    """rad/s of "470Hz", "470 hz", "2950rad/s" or a bare number in the deck's unit."""
    m = re.fullmatch(r"\s*([-+0-9.eE]+)\s*(hz|rad/s)?\s*", str(text), re.IGNORECASE)
    if not m:
        raise InputError(f"--at: expected a frequency like 470Hz or 2950rad/s, got {text!r}")
    v = float(m.group(1))
    u = (m.group(2) or unit).lower()
    return v * 2.0 * np.pi if u == "hz" else v


def stored_count(stored, what: str) -> int:
    """len(stored), an InputError naming ``what`` when it holds no point."""
    n = len(stored)
    if n == 0:
        raise InputError(f"{what} holds no point")
    return n


def stored_index(point: int, n: int) -> int:
    """--point (negative from the end) as an index into n stored points."""
    if not -n <= point < n:
        raise InputError(f"--point: expected an index in {-n}..{n - 1}, got {point}")
    return point % n


def pick_point(frf: FRF, *, at: float | None = None, point: int | None = None,
               peak: bool = False) -> tuple[int, float]:
    """(stored point index, omega rad/s) of one choice: a frequency (the stored point
    nearest in frequency starts the solve; on a folded curve, the first of the nearest
    ones), a point index (negative from the end), or the peak of the first output."""
    n = stored_count(frf, "the result")
    if point is not None:
        k = stored_index(point, n)
        return k, float(frf.omega[k])
    if peak:
        p = frf.peak(0)
        return int(p.index), float(p.omega)
    if at is None:
        raise InputError("choose a point: --at FREQ, --point K or --peak")
    lo, hi = float(np.min(frf.omega)), float(np.max(frf.omega))
    if not lo <= at <= hi:
        raise InputError(f"--at: {at / 2 / np.pi:.6g} Hz lies outside the curve "
                         f"({lo / 2 / np.pi:.6g} .. {hi / 2 / np.pi:.6g} Hz)")
    return int(np.argmin(np.abs(frf.omega - at))), float(at)


def _next_sector(model: CyclicModel, x: np.ndarray) -> np.ndarray:
    """Harmonics of the next sector's coordinates (in its own frame) from sector 0's:
    harmonic h times exp(i k_h 2 pi / N)."""
    y = x.copy()
    H = (x.shape[1] - 1) // 2
    alpha = 2.0 * np.pi / model.n_sectors
    for h in range(1, H + 1):
        k = model.modes_of(model.harmonic_index(h)).k
        c = (x[:, 2 * h - 1] - 1j * x[:, 2 * h]) * np.exp(1j * k * alpha)
        y[:, 2 * h - 1], y[:, 2 * h] = c.real, -c.imag
    return y


def _velocity_work(x: np.ndarray, y: np.ndarray) -> float:
    """int_0^2pi x'(tau)^T y(tau) dtau for real harmonics x, y (n, 2H+1)."""
    h = np.arange(1, (x.shape[1] - 1) // 2 + 1)
    a, b, p, q = x[:, 1::2], x[:, 2::2], y[:, 1::2], y[:, 2::2]
    return float(np.pi * np.sum(h * (b * p - a * q)))


def contact_fields(model, x: np.ndarray, slider: np.ndarray, n_samples: int) -> list:
    """ContactField per group of `model` for coordinates' harmonics x (n_dof, 2H+1), the
    contact history `slider` (FRFPoint.slider layout) and the AFT samples per period."""
    xx = np.vstack([x, _next_sector(model, x)]) if isinstance(model, CyclicModel) else x
    out, s0 = [], 0
    for g in model.contacts:
        law = LAWS[g.law]
        ne, nd = g.n_elem, law.n_dir
        u = np.asarray(g.G @ xx[:g.G.shape[1]]).reshape(ne, nd, -1)
        ns = ne * law.n_slider
        w0 = (slider[s0:s0 + ns].reshape(ne, law.n_slider) if law.n_slider and
              slider.size >= s0 + ns and np.all(np.isfinite(slider[s0:s0 + ns])) else g.w0)
        s0 += ns
        if not law.n_slider:
            w0 = None
        tau, ut, ft = time_histories(law, u, g.params, n_samples, w0=w0)
        states = aft(law, u, g.params, n_samples, w0=w0, jacobian=False).states
        # energy per period: sum_k f_k . u'(tau_k) 2 pi / N, u' exact from the harmonics
        du = np.stack([_series(u[:, d], tau)[1] for d in range(nd)], axis=1)
        energy = (ft * du).sum(axis=(1, 2)) * (2.0 * np.pi / n_samples)
        par = dict(zip(law.parameters, np.asarray(g.params, float).T))
        if "v" in law.directions:
            fn_max = ft[:, -1].max(axis=1)
        else:
            fn_max = par.get("fn0", np.zeros(ne)) * np.ones(ne)
        if "kt" in par:
            nt = nd - 1 if "v" in law.directions else nd
            w = ut[:, :nt] - ft[:, :nt] / par["kt"][:, None, None]
            slip = 0.5 * np.linalg.norm(w.max(axis=2) - w.min(axis=2), axis=1)
        else:
            slip = np.zeros(ne)
        out.append(ContactField(g.name, g.law, law.directions, tau, ut, ft, energy, states,
                                fn_max, slip))
    return out


def _sector_viscous_work(model: CyclicModel, fe: np.ndarray, contacts: list, omega: float,
                         H: int) -> float:
    """Viscous work per period of a cyclic sector from its modes: harmonic h on nodal
    diameter k_h, modal amplitudes q = psi_ext^H (f_e - G^T f) / (w_m^2 - W^2 + 2 i z_m w_m W)
    (W = h omega; psi_ext: sector 0's rows, then the next sector's times exp(i k alpha);
    f the contact forces' harmonics from the AFT samples), work h pi W sum 2 z_m w_m |q_m|^2
    (modes normalised to unit modal mass over the sector)."""
    from .harmonics import to_harmonics
    n = model.n_dof
    alpha = 2.0 * np.pi / model.n_sectors
    gf = np.zeros((2 * n, 2 * H + 1))
    for g, c in zip(model.contacts, contacts):
        fh = to_harmonics(c.f, H).reshape(-1, 2 * H + 1)
        gf[:g.G.shape[1]] += np.asarray(g.G.T @ fh)
    work = 0.0
    for h in range(1, H + 1):
        m = model.modes_of(model.harmonic_index(h))
        W = h * omega
        f = np.zeros(2 * n, complex)
        f[:n] = fe[:, 2 * h - 1] - 1j * fe[:, 2 * h]
        f -= gf[:, 2 * h - 1] - 1j * gf[:, 2 * h]
        psi = np.vstack([m.psi, m.psi * np.exp(1j * m.k * alpha)])
        q = (psi.conj().T @ f) / (m.omega**2 - W**2 + 2j * m.zeta * m.omega * W)
        work += h * np.pi * W * float(np.sum(2.0 * m.zeta * m.omega * np.abs(q) ** 2))
    return work


def point_state(frf: FRF, deck, index: int, omega: float) -> PointState:
    """Solve the point again at omega from stored point `index` with every coordinate kept
    and compute its outputs, contact fields and power balance."""
    from .solver import solve_point
    model, exc, opts = deck.model(), deck.excitation(), deck.options()
    n = model.n_dof
    start = {"slider": None if frf.slider is None else frf.slider[index]}
    if frf.unknowns is not None and np.all(np.isfinite(frf.unknowns[index])):
        start["unknowns"] = frf.unknowns[index]
    if start["slider"] is not None and not np.all(np.isfinite(start["slider"])):
        start["slider"] = None
    pt = solve_point(model, exc, omega, opts, outputs=np.arange(n), start=start)
    x = np.asarray(pt.X, float)
    P = deck.output_map
    if P is None:
        P = np.eye(n)[list(deck.outputs)]
    contacts = contact_fields(model, x, np.asarray(pt.slider, float), opts.n_samples)
    ext = _velocity_work(x, exc.real_harmonic(n, opts.harmonics))
    if isinstance(model, CyclicModel):
        visc = _sector_viscous_work(model, exc.real_harmonic(n, opts.harmonics), contacts,
                                    omega, opts.harmonics)
    else:
        h = np.arange(1, opts.harmonics + 1)
        a, b = x[:, 1::2], x[:, 2::2]
        C = model.C
        visc = float(omega * np.pi * np.sum(h**2 * (np.einsum("ih,ih->h", a, C @ a)
                                                    + np.einsum("ih,ih->h", b, C @ b))))
    dis = float(sum(c.energy.sum() for c in contacts))
    bal = {"excitation": ext, "contacts": dis, "viscous": visc,
           "residual": ext - dis - visc}
    from .held import held_directions, patch_warnings
    held = held_directions(model, contacts) if hasattr(model, "free_bodies") else []
    return PointState(omega=float(omega), index=int(index), x=x, outputs=P @ x,
                      labels=list(deck.output_names), contacts=contacts, balance=bal,
                      held=held, patch=patch_warnings(model, contacts))


def print_contacts(state, top: int, per: str) -> None:
    """The (at most three) elements that dissipate most, with their states."""
    for g, e in _chosen(state, None, min(top, 3)):
        c = state.contacts[g]
        print(f"frirom: contact {c.name}:{e} dissipates {c.energy[e]:.4g} J per {per} "
              f"(stick {c.states[e, 0]:.0%}, slip {c.states[e, 1]:.0%}, lift-off "
              f"{c.states[e, 2]:.0%})")


def _chosen(state: PointState, chosen, n_top: int) -> list:
    """[(group index, element)] of the contacts to draw: `chosen` ("name:e" or "e" of the
    first group), else the n_top dissipating most."""
    if chosen:
        names = [c.name for c in state.contacts]
        out = []
        for item in chosen:
            g_name, _, e = str(item).rpartition(":")
            g = names.index(g_name) if g_name in names else (0 if not g_name else -1)
            if g < 0 or not e.isdigit() or int(e) >= state.contacts[g].n_elem:
                raise InputError(f"--contact: expected GROUP:ELEMENT with a group of "
                                 f"{names} and an element index, got {item!r}")
            out.append((g, int(e)))
        return out
    flat = [(c.energy[e], g, e) for g, c in enumerate(state.contacts)
            for e in range(c.n_elem)]
    flat.sort(key=lambda t: -t[0])
    return [(g, e) for _, g, e in flat[:n_top]]


def figure_time(state: PointState, n: int = 256) -> Figure:
    """Outputs over one period against time (ms)."""
    fig = Figure(figsize=(7.5, 3.8), dpi=130)
    ax = fig.add_subplot()
    tau = 2.0 * np.pi * np.arange(n + 1) / n
    xt = _series(state.outputs, tau)[0]
    t_ms = tau / state.omega * 1e3
    for j, lab in enumerate(state.labels):
        ax.plot(t_ms, xt[j], lw=1.4, label=lab)
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("displacement [m]")
    ax.set_title(f"Outputs over one period at {state.frequency_hz:.6g} Hz")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def figure_hysteresis(state: PointState, pick: list) -> Figure:
    """Tangential force against relative tangential displacement (left) and normal force
    over the period (right, laws with a normal direction) of the chosen contacts."""
    normal = any("v" in state.contacts[g].directions for g, _ in pick)
    fig = Figure(figsize=(9.0 if normal else 5.5, 4.0), dpi=130)
    ax, bx = fig.subplots(1, 2) if normal else (fig.add_subplot(), None)
    for g, e in pick:
        c = state.contacts[g]
        lab = f"{c.name}:{e} ({c.energy[e]:.3g} J)"
        u0, f0 = np.r_[c.u[e, 0], c.u[e, 0, :1]], np.r_[c.f[e, 0], c.f[e, 0, :1]]
        ax.plot(u0 * 1e6, f0, lw=1.3, label=lab)
        if bx is not None and "v" in c.directions:
            bx.plot(np.degrees(np.r_[c.tau, 2 * np.pi]), np.r_[c.f[e, -1], c.f[e, -1, :1]],
                    lw=1.3, label=lab)
    ax.set_xlabel(f"relative displacement {state.contacts[pick[0][0]].directions[0]} "
                  "[um]" if pick else "relative displacement [um]")
    ax.set_ylabel("tangential force [N]")
    ax.set_title("Hysteresis loops", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    if bx is not None:
        bx.set_xlabel("phase in the period [deg]")
        bx.set_ylabel("normal force [N]")
        bx.set_title("Normal force", fontsize=10)
        bx.grid(True, alpha=0.3)
    fig.suptitle(f"Contacts at {state.frequency_hz:.6g} Hz", fontsize=11)
    fig.tight_layout()
    return fig


def figure_energy(state: PointState) -> Figure:
    """Energy dissipated per period by each contact element, per group."""
    ng = max(len(state.contacts), 1)
    fig = Figure(figsize=(7.5, 1.2 + 2.2 * ng), dpi=130)
    axes = fig.subplots(ng, 1, squeeze=False)[:, 0]
    for ax, c in zip(axes, state.contacts):
        ax.bar(np.arange(c.n_elem), c.energy, width=0.9, color="#c0392b")
        ax.set_ylabel("energy / period [J]")
        ax.set_title(f"{c.name}: {c.energy.sum():.4g} J per period", fontsize=9, loc="right")
        ax.grid(True, axis="y", alpha=0.3)
    axes[-1].set_xlabel("contact element (pair)")
    b = state.balance
    fig.suptitle(f"Dissipated energy at {state.frequency_hz:.6g} Hz (excitation "
                 f"{b['excitation']:.4g} J, viscous {b['viscous']:.4g} J)", fontsize=10)
    fig.tight_layout()
    return fig


def write_point(state: PointState, out: Path, chosen=None, n_top: int = 4) -> list:
    """Write time.csv/png, hysteresis.csv/png, contacts.csv and energy.png of a point to
    the folder `out`; returns the paths."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    n = 256
    tau = 2.0 * np.pi * np.arange(n) / n
    xt = _series(state.outputs, tau)[0]
    with open(out / "time.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["t_s", "phase_rad"] + list(state.labels))
        for i in range(n):
            w.writerow([repr(float(tau[i] / state.omega)), repr(float(tau[i]))]
                       + [repr(float(v)) for v in xt[:, i]])
    written.append(out / "time.csv")
    pick = _chosen(state, chosen, n_top)
    with open(out / "hysteresis.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["group", "element", "phase_rad", "direction", "relative_displacement_m",
                    "force_N"])
        for g, e in pick:
            c = state.contacts[g]
            for d, dn in enumerate(c.directions):
                for i in range(c.tau.size):
                    w.writerow([c.name, e, repr(float(c.tau[i])), dn, repr(float(c.u[e, d, i])),
                                repr(float(c.f[e, d, i]))])
    written.append(out / "hysteresis.csv")
    with open(out / "contacts.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["group", "element", "energy_J", "stick", "slip", "liftoff",
                    "fn_max_N", "slip_amplitude_m"])
        for c in state.contacts:
            for e in range(c.n_elem):
                w.writerow([c.name, e, repr(float(c.energy[e]))]
                           + [f"{v:.6g}" for v in c.states[e]]
                           + [repr(float(c.fn_max[e])), repr(float(c.slip[e]))])
    written.append(out / "contacts.csv")
    figs = {"time.png": figure_time(state)}
    if state.contacts:
        figs["hysteresis.png"] = figure_hysteresis(state, pick)
        figs["energy.png"] = figure_energy(state)
    for name, fig in figs.items():
        fig.savefig(out / name)
        written.append(out / name)
    return written


def cmd_show(args) -> int:
    """`frirom show` (see cli._add_show): solve the chosen point again and write its
    files; prints the power balance and the most dissipative contacts."""
    from . import maps
    from .plots import plot_frf
    frf, deck = load_run(args.out, args.deck)
    at = parse_frequency(args.at, deck.frequency_unit) if args.at is not None else None
    peak = args.peak or (at is None and args.point is None)
    k, omega = pick_point(frf, at=at, point=args.point, peak=peak)
    try:
        state = point_state(frf, deck, k, omega)
    except FriromError as exc:
        if not peak:
            raise
        # the peak lies between stored points: when its solve fails, the highest stored
        # point (solved before, so its start is its own solution) is shown instead
        name = (deck.output_names or ["output 0"])[0]
        k = int(np.argmax(np.asarray(frf.amp_max, float)[:, 0]))
        print(f"frirom: the peak of {name} at {omega / 2 / np.pi:.6g} Hz could not be "
              f"solved again ({exc}); showing the highest stored point instead: point {k} "
              f"at {float(frf.omega[k]) / 2 / np.pi:.6g} Hz", file=sys.stderr)
        omega = float(frf.omega[k])
        state = point_state(frf, deck, k, omega)
    base = args.out if args.out.is_dir() else args.out.parent
    folder = args.dir or base / f"show_{state.frequency_hz:.6g}Hz"
    written = write_point(state, folder, args.contact, args.top)
    fe = deck.reduced is not None and any(c.name in deck.reduced.pairs
                                          for c in state.contacts)
    if fe:
        fig = maps.figure_maps(state, deck)
        fig.savefig(folder / "maps.png")
        written.append(folder / "maps.png")
    if args.along:
        if not fe:
            raise InputError("--along: interface maps need an FE deck ([fe_model]) with "
                             "node-set contacts")
        idx = maps.curve_indices(frf, args.along)
        states = [point_state(frf, deck, int(i), float(frf.omega[i])) for i in idx]
        fig = maps.figure_curve_maps(states, deck)
        fig.savefig(folder / "maps_along.png")
        written.append(folder / "maps_along.png")
    if args.vtk:
        written += maps.write_vtk(state, deck, folder / "point.vtu", args.frames)
    if args.phase:
        fig = plot_frf(frf, output_names=deck.output_names, unit=deck.frequency_unit,
                       title=deck.title, phase=True)
        fig.savefig(base / "frf_phase.png")
        written.append(base / "frf_phase.png")
    b = state.balance
    print(f"frirom: point {k} solved at {state.frequency_hz:.6g} Hz "
          f"({state.omega:.6g} rad/s)")
    print(f"frirom: work per period: excitation {b['excitation']:.6g} J = contacts "
          f"{b['contacts']:.6g} J + viscous {b['viscous']:.6g} J (residual "
          f"{b['residual']:.3g} J)")
    print_contacts(state, args.top, "period")
    from .held import held_lines
    for line in held_lines(state.held):
        print(f"frirom: {line}")
    for line in state.patch:
        print(f"frirom: warning: {line}", file=sys.stderr)
    print("frirom: wrote " + ", ".join(str(p) for p in written))
    return 0
