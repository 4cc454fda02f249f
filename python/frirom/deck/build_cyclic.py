"""The deck's build step for ``[reduction.cyclic]``: the sector's cyclic boundaries matched on
the reduced model, and the modes of every nodal diameter the harmonics live on."""

from __future__ import annotations

import time
from pathlib import Path

from .._errors import InputError, SingularMatrixError
from ..model import Damping
from ..reduction.cyclic import (CyclicSector, cyclic_sector, needed_indices, sector_free_bodies,
                                sector_modes)
from ..reduction.rom import ReducedModel, ReductionSpec
from .schema_model import CyclicSettings

_PRE = "reduction.cyclic"


def cyclic_sector_of(path: Path, rom: ReducedModel, spec: ReductionSpec,
                     cy: CyclicSettings) -> CyclicSector:
    """The CyclicSector on the reduced coordinates (``path``: the deck, for messages)."""
    L = rom.node_sets[cy.left.upper()]
    R = rom.node_sets[cy.right.upper()]
    try:
        return cyclic_sector(rom.coordinates(L), rom.node_dofs(L), rom.coordinates(R),
                             rom.node_dofs(R), cy.sectors, rom.K.shape[0],
                             origin=spec.origin, axis=spec.axis, tol=cy.tol,
                             nodes_left=L, nodes_right=R, dependent=cy.dependent)
    except InputError as exc:
        raise InputError(f"{path}: {_PRE}.left/right: {exc} (axis {spec.axis} through "
                         f"{spec.origin}: reduction.axis, reduction.origin)") from None


def check_sector_contacts(path: Path, rom: ReducedModel, cs: CyclicSector,
                          contacts) -> dict:
    """Check that no node-set contact holds both images of a boundary node; returns
    {left-boundary node: its right-boundary image}."""
    partner = {int(a): int(b) for a, b in cs.node_pairs}
    for c in contacts:
        p = rom.pairs[c.name]
        sides = [("a", p.dofs_a)] + ([("b", p.dofs_b)] if c.b is not None
                                     and not c.b_sector else [])
        nodes = set()
        for side, d in sides:
            nodes |= {int(x) for x in rom.fe_dofs[d[:, 0], 0]}
        both = sorted(a for a in nodes if partner.get(a) in nodes)
        if both:
            raise InputError(
                f"{path}: {c.key}: node {both[0]} (left boundary) and node "
                f"{partner[both[0]]} (its image on the right boundary) are the same "
                "node of the rotor: the contact would act on it twice; keep one of them "
                "in the contact's node sets")
    return partner


def cyclic_modes(path: Path, cs: CyclicSector, rom: ReducedModel, cy: CyclicSettings,
                 damping: dict, H: int, log, contacts=()) -> dict:
    """Modes of every nodal diameter the harmonics 0..H live on (after the cache).

    damping: the Deck's damping dict (rayleigh or modal); log: called with one line;
    contacts: the deck's ContactGroups on the sector (a body they alone hold, such as a
    damper between this sector's platform and the next one's, makes the modes the stuck
    sector's: frirom.reduction.cyclic.sector_free_bodies). Returns the Deck's ``cyclic``
    dict.
    """
    N, eo, sign = cy.sectors, cy.engine_order, -1
    ks = needed_indices(eo, N, H, sign, cy.single_index)
    damp = (Damping.rayleigh(damping["alpha"], damping["beta"])
            if damping["type"] == "rayleigh" else Damping.modal(damping["zeta"]))
    t0 = time.perf_counter()
    try:
        free = sector_free_bodies(cs, rom.K, rom.M, list(contacts), ks)
    except SingularMatrixError as exc:
        raise InputError(f"{path}: {_PRE}: {exc}") from None
    if free:
        log("cyclic sector: a body held only by its contacts (K alone is singular): the "
            "modes are the stuck sector's, the contacts' stuck stiffness taken back off "
            "their forces")
    modes = {}
    for k in ks:
        try:
            modes[k] = sector_modes(cs, rom.K, rom.M, k, damp, cy.modes, cy.boundary_modes,
                                    stuck_contacts=list(contacts) if free else None)
        except InputError as exc:
            msg = str(exc)
            key = ("boundary_modes" if "tran_reduce" in msg else
                   "modes" if "n_modes" in msg else "sectors")
            if "rigid-body" in msg:
                msg = (f"nodal diameter {k} has a rigid-body (zero-frequency) mode: the "
                       "sector's modes are those without contacts, so it needs supports "
                       "(constrained DoFs in the FE model) at every nodal diameter")
            raise InputError(f"{path}: {_PRE}.{key}: {msg}") from None
    dt = time.perf_counter() - t0
    n_i = cs.independent.size
    nm = {k: m.omega.size for k, m in modes.items()}
    how = ("one-index approximation, harmonic_index = " + str(ks[0])
           if cy.single_index is not None else
           f"k_h = -h EO mod N for h = 0..{H}, EO = {eo}")
    nds = ", ".join(str(min(k, N - k)) for k in modes)
    log(f"cyclic sector: N = {N}, harmonic indices k = {list(modes)} (nodal diameters "
        f"{nds}; {how}); "
        f"{len(modes)} Hermitian eigen-solve(s) of {n_i} coordinates"
        + (f" (Tran: {cy.boundary_modes} boundary modes)" if cy.boundary_modes else "")
        + f", {max(nm.values())} modes each, in {dt:.2f} s")
    return {"sector": cs, "modes": modes, "engine_order": eo,
            "single_index": cy.single_index, "sign": sign, "seconds": dt, "free": free}
