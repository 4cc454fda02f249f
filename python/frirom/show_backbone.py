"""`frirom show` at a point of a nonlinear mode's backbone (``OUT/backbone.h5``).

The backbone file keeps the harmonics of every coordinate and the contact history each
point leaves, so the point needs no new solve: the outputs over one period, the contacts'
hysteresis loops, energies and states (:func:`frirom.show.contact_fields`, the same AFT
march as the solver's), and for FE decks the interface maps, as for a forced-response
point. The energy balance is that of the EPMC: the work of the artificial negative damping
xi M x' over a period (the energy the mode dissipates, Backbone.energy) equals what the
contacts and the viscous damping dissipate.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from ._errors import InputError
from .show import (PointState, contact_fields, print_contacts, stored_count, stored_index,
                   viscous_work, write_point)

__all__ = ["backbone_point_state", "pick_backbone_point", "cmd_show_backbone"]


def pick_backbone_point(bb, *, amplitude: float | None = None, point: int | None = None
                        ) -> int:
    """Index of a backbone point: the stored point K (negative from the end), the one
    nearest a modal amplitude (in log), or, neither given, the one of largest damping
    ratio."""
    n = stored_count(bb, "the backbone")
    if point is not None:
        return stored_index(point, n)
    if amplitude is not None:
        lo, hi = float(bb.amplitude.min()), float(bb.amplitude.max())
        if not (amplitude > 0 and lo * (1 - 1e-9) <= amplitude <= hi * (1 + 1e-9)):
            raise InputError(f"--amplitude: {amplitude:g} lies outside the backbone's modal "
                             f"amplitudes ({lo:.4g} .. {hi:.4g})")
        return int(np.argmin(np.abs(np.log(bb.amplitude / amplitude))))
    return int(np.argmax(bb.damping_ratio))


def backbone_point_state(bb, deck, index: int) -> PointState:
    """The PointState of backbone point `index` of the deck's model (no new solve)."""
    model, opts = deck.model(), deck.options()
    n = model.n_dof
    rows = getattr(bb, "harmonic_dofs", None)
    cyclic = hasattr(model, "n_sectors")
    if bb.harmonics.shape[1] != n and not (cyclic and rows is not None
                                           and len(rows) == bb.harmonics.shape[1]
                                           and int(np.max(rows)) < n):
        raise InputError(f"the backbone has {bb.harmonics.shape[1]} coordinates, the deck's "
                         f"model {n}: not the deck it was made with")
    # a cyclic sector above 400 coordinates keeps its contact DoFs and outputs only
    # (Backbone.harmonic_dofs): the others are left zero, which the contacts, outputs and
    # energies do not read
    x = np.zeros((n, bb.harmonics.shape[2]))
    x[np.arange(n) if bb.harmonics.shape[1] == n else rows] = bb.harmonics[index]
    slider = (np.asarray(bb.sliders[index], float) if bb.sliders is not None
              else np.zeros(0))
    contacts = contact_fields(model, x, slider, opts.n_samples)
    omega = float(bb.omega[index])
    if cyclic and bb.harmonics.shape[1] != n:
        visc = _sector_viscous_from_forces(model, np.asarray(rows), opts.n_samples, omega,
                                           float(bb.xi[index]), bb.harmonics[index])
    elif cyclic:
        visc = _sector_viscous(model, x[:, 1::2] - 1j * x[:, 2::2], omega)
    else:
        visc = viscous_work(model.C, x, omega, bb.H)
    dis = float(sum(c.energy.sum() for c in contacts))
    ext = float(bb.energy[index])
    P = deck.output_map
    if P is None:
        P = np.eye(n)[list(deck.outputs)]
    return PointState(omega=omega, index=int(index), x=x, outputs=P @ x,
                      labels=list(deck.output_names), contacts=contacts,
                      balance={"excitation": ext, "contacts": dis, "viscous": visc,
                               "residual": ext - dis - visc})


def _sector_viscous(model, z: np.ndarray, omega: float) -> float:
    """Viscous work per period of a cyclic sector's mode (sector 0) from its harmonics z
    (n_dof, H) = a - i b: harmonic h's modal coordinates q in the modes of its nodal
    diameter (every sector DoF given: least squares, exact), pi omega h^2 sum_r 2 zeta_r
    w_r |q_r|^2."""
    work = 0.0
    for h in range(1, z.shape[1] + 1):
        m = model.modes_of(model.harmonic_index(h))
        q = np.linalg.lstsq(m.psi, z[:, h - 1], rcond=None)[0]
        work += np.pi * omega * h ** 2 * float(np.sum(2 * m.zeta * m.omega * np.abs(q) ** 2))
    return work


def _sector_viscous_from_forces(model, rows, n_samples: int, omega: float, xi: float,
                                X: np.ndarray) -> float:
    """_sector_viscous from the modal coordinates the contact forces give
    (frirom.nonlinear_modes_cyclic._modal_from_forces) when only the DoFs `rows` are
    known (their harmonics X (rows.size, 2H+1))."""
    from .nonlinear_modes_cyclic import _modal_from_forces
    H = (X.shape[1] - 1) // 2
    pers = [model.modes_of(model.harmonic_index(h)) for h in range(H + 1)]
    qs = _modal_from_forces(model, pers, rows, n_samples, np.array([omega]), np.array([xi]),
                            X[None])
    return float(sum(np.pi * omega * h ** 2 * np.sum(2 * pers[h].zeta * pers[h].omega
                                                     * np.abs(q[:, 0]) ** 2)
                     for h, q in enumerate(qs, 1)))


def cmd_show_backbone(args, h5: Path) -> int:
    """`frirom show OUT` where OUT holds backbone.h5: write the point's files."""
    from . import maps
    from .backbone import load_h5
    from .deck import load_deck
    bb, attrs = load_h5(h5)
    path = Path(args.deck) if args.deck else Path(str(attrs.get("deck_path", "")))
    if not str(path) or not path.is_file():
        raise InputError(f"{h5}: the deck it was made with is not found "
                         f"({path or 'not recorded'}); give it with --deck")
    for flag, given in (("--along", args.along), ("--phase", args.phase)):
        if given:
            raise InputError(f"{flag}: for forced responses only (this is a backbone)")
    if args.at is not None:
        raise InputError("--at: a backbone point is chosen by --amplitude A (modal "
                         "amplitude), --point K or --peak (largest damping ratio)")
    if args.vtk and getattr(bb, "harmonic_dofs", None) is not None:
        raise InputError("--vtk: the backbone keeps the contact DoFs and outputs only (a "
                         "cyclic sector above 400 coordinates): the deformed sector needs "
                         "every coordinate")
    deck = load_deck(path)
    k = pick_backbone_point(bb, amplitude=getattr(args, "amplitude", None),
                            point=args.point)
    state = backbone_point_state(bb, deck, k)
    base = h5.parent
    folder = args.dir or base / f"show_a{bb.amplitude[k]:.4g}"
    written = write_point(state, folder, args.contact, args.top)
    if deck.reduced is not None and any(c.name in deck.reduced.pairs
                                        for c in state.contacts):
        fig = maps.figure_maps(state, deck)
        fig.savefig(folder / "maps.png")
        written.append(folder / "maps.png")
    if args.vtk:
        written += maps.write_vtk(state, deck, folder / "point.vtu", args.frames)
    b = state.balance
    print(f"frirom: backbone point {k}: modal amplitude {bb.amplitude[k]:.4g}, "
          f"{state.frequency_hz:.6g} Hz, damping ratio {bb.damping_ratio[k]:.4g}")
    print(f"frirom: energy per cycle: mode {b['excitation']:.6g} J = contacts "
          f"{b['contacts']:.6g} J + viscous {b['viscous']:.6g} J (residual "
          f"{b['residual']:.3g} J)")
    print_contacts(state, args.top, "cycle")
    print("frirom: wrote " + ", ".join(str(p) for p in written), file=sys.stdout)
    return 0
