"""The deck's structure tables as settings: ``[model]``, or ``[fe_model]`` + ``[reduction]``
(+ ``[reduction.cyclic]``). Checked, not read: no matrix file is opened here."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..reduction.rom import FORMATS, ContactDrivenSpec, FESource, ReductionSpec
from .schema_study import parse_modes_auto
from .fields import Context, boolean, file, integers, names, number, string, table, unknown, \
    vector

#: formats of the matrix files of [model]
MATRIX_FORMATS = ("mtx",)


@dataclass(frozen=True)
class MatrixModel:
    """``[model]``: assembled matrices used as they are.

    format : str
        One of :data:`MATRIX_FORMATS` (``"mtx"``: MatrixMarket coordinate).
    mass, stiffness : Path
        Absolute paths of M [kg] and K [N/m], (n_dof, n_dof) each.
    dof_labels : Path or None
        A text file of n_dof labels, one per line in matrix order.
    """

    format: str
    mass: Path
    stiffness: Path
    dof_labels: Path | None


@dataclass(frozen=True)
class CyclicSettings:
    """``[reduction.cyclic]``: the reduced model is sector 0 of a tuned rotor.

    sectors : int
        N >= 2 sectors.
    left, right : str
        Node sets of the sector's cyclic boundaries.
    dependent : str
        ``"right"`` or ``"left"``: the boundary eliminated by the cyclic constraint.
    engine_order : int
        EO of the travelling-wave excitation.
    boundary_modes : int or None
        Tran interface modes of the boundary (None: the boundary DoFs are kept).
    modes : int or None
        Sector modes per harmonic index (None: all).
    tol : float or None
        Boundary matching distance [m] (None: relative to the model size).
    single_index : int or None
        None: every harmonic on its own index k_h; k* in 0..N-1: the one-index
        approximation.
    """

    sectors: int
    left: str
    right: str
    dependent: str
    engine_order: int
    boundary_modes: int | None
    modes: int | None
    tol: float | None
    single_index: int | None


def parse_matrix_model(ctx: Context, mdl: dict) -> MatrixModel:
    """The checked ``[model]`` table."""
    unknown(ctx, mdl, {"format", "mass", "stiffness", "dof_labels"}, "model")
    fmt = string(ctx, mdl, "format", "model.format", default="mtx", choices=MATRIX_FORMATS)
    mass = file(ctx, mdl, "mass", "model.mass")
    stiffness = file(ctx, mdl, "stiffness", "model.stiffness")
    labels = file(ctx, mdl, "dof_labels", "model.dof_labels") if "dof_labels" in mdl \
        else None
    return MatrixModel(format=fmt, mass=mass, stiffness=stiffness, dof_labels=labels)


def parse_fe_model(ctx: Context, fe: dict) -> FESource:
    """The checked ``[fe_model]`` table (its files must exist)."""
    fmt = string(ctx, fe, "format", "fe_model.format", required=True, choices=tuple(FORMATS))
    roles, required = FORMATS[fmt]
    opts = {"abaqus": ("layout",), "op4": ("stiffness_name", "mass_name")}.get(fmt, ())
    unknown(ctx, fe, {"format", *roles, *opts}, "fe_model")
    files = {}
    for r in roles:
        if r in fe or r in required:
            files[r] = file(ctx, fe, r, f"fe_model.{r}")
    options = {}
    for o in opts:
        v = string(ctx, fe, o, f"fe_model.{o}",
                   choices=("auto", "matrix", "coordinate") if o == "layout" else None)
        if v is not None:
            options[o] = v
    for r, f in files.items():
        if fmt == "calculix" and r == "job":
            for sfx in (".sti", ".mas", ".dof") + ((".inp",) if "inp" not in files else ()):
                if not f.with_suffix(sfx).is_file():
                    raise ctx.error("fe_model.job", f"a job name whose {sfx} file exists "
                                    "(run ccx with *FREQUENCY, SOLVER=MATRIXSTORAGE)",
                                    str(f.with_suffix(sfx)))
        elif not f.is_file():
            raise ctx.error(f"fe_model.{r}", "an existing file", str(f))
    return FESource(fmt, files, options)


def parse_reduction(ctx: Context, red: dict) -> tuple:
    """The checked ``[reduction]`` table: (ReductionSpec, its ``[reduction.cyclic]``
    CyclicSettings or None, ModesAuto or None: interface-mode counts ``"auto"``, the spec
    then holding the first rung)."""
    if "pairs" in red:
        raise ctx.error("reduction.pairs", "no [[reduction.pairs]]: contact pairs are "
                        "[[contacts]] tables with node sets a, b and a normal")
    unknown(ctx, red, {"interface", "active", "fixed_interface_modes", "cache",
                       "interface_modes", "cyclic", "axis", "origin"}, "reduction")
    iface = names(ctx, red, "interface", "reduction.interface", required=True)
    active = names(ctx, red, "active", "reduction.active", required=False)
    n_cb = number(ctx, red, "fixed_interface_modes", "reduction.fixed_interface_modes",
                  integer=True, minimum=0)
    # a *.h5 file, or a folder of the shared cache; default the shared cache (rom_key)
    cache = file(ctx, red, "cache", "reduction.cache") if "cache" in red else None
    pre = "reduction.interface_modes"
    im = table(ctx, red, pre, required=False)
    method = string(ctx, im, "method", f"{pre}.method", default="none",
                    choices=("none", "gsi", "ms"))
    allowed = {"none": {"method"}, "gsi": {"method", "free", "stick", "per_side",
                                                 "separate", "separate_stick",
                                                 "contact_driven"},
               "ms": {"method", "sectors", "engine_orders", "time_harmonics",
                      "harmonic_indices", "axis", "origin", "travelling_wave"}}[method]
    im, modes_auto = parse_modes_auto(ctx, im, method)
    unknown(ctx, im, allowed, pre)
    kw = {}
    if method == "gsi":
        kw["free"] = number(ctx, im, "free", f"{pre}.free", default=0, integer=True, minimum=0)
        kw["stick"] = number(ctx, im, "stick", f"{pre}.stick", default=0, integer=True,
                             minimum=0)
        if kw["free"] + kw["stick"] == 0:
            raise ctx.error(f"{pre}.free", "free + stick >= 1 GSI modes")
        kw["per_side"] = boolean(ctx, im, "per_side", f"{pre}.per_side", False)
        sep = names(ctx, im, "separate", f"{pre}.separate", required=False)
        up = {s.upper() for s in iface}
        if any(s.upper() not in up for s in sep):
            raise ctx.error(f"{pre}.separate", "node sets of reduction.interface (a joint "
                            "of its own, outside the span of the GSI modes)", sep)
        if sep and {s.upper() for s in sep} >= up:
            raise ctx.error(f"{pre}.separate", "some interface sets left to the GSI modes "
                            "(with every set separate, use method = 'none')", sep)
        kw["separate"] = tuple(sep)
        kw["separate_stick"] = number(ctx, im, "separate_stick", f"{pre}.separate_stick",
                                      default=0, integer=True, minimum=0)
        if kw["separate_stick"] and not sep:
            raise ctx.error(f"{pre}.separate_stick", "with separate = [node sets]",
                            kw["separate_stick"])
        if "contact_driven" in im:
            if sep:
                raise ctx.error(f"{pre}.contact_driven", "no separate joints with the "
                                "contact-driven basis", sep)
            kw["contact_driven"] = parse_contact_driven(
                ctx, table(ctx, im, f"{pre}.contact_driven"), f"{pre}.contact_driven")
    axis = vector(ctx, red, "axis", "reduction.axis", (0.0, 0.0, 1.0))
    origin = vector(ctx, red, "origin", "reduction.origin", (0.0, 0.0, 0.0), nonzero=False)
    kw["axis"], kw["origin"] = axis, origin
    cyc = None
    if "cyclic" in red:
        if method == "ms":
            raise ctx.error(f"{pre}.method", "'none' or 'gsi' with [reduction.cyclic] "
                            "(multi-stage modes are for whole 360-degree stages)", method)
        cyc = parse_cyclic(ctx, table(ctx, red, "reduction.cyclic"))
        if modes_auto is not None:
            raise ctx.error(f"{pre}.{modes_auto.keys[0]}", "an integer with "
                            "[reduction.cyclic] (\"auto\" is not available for cyclic "
                            "sectors)", "auto")
        kw["sectors"] = cyc.sectors
        kw["cyclic"] = (cyc.left, cyc.right)
    if method == "ms":
        kw["sectors"] = number(ctx, im, "sectors", f"{pre}.sectors", required=True,
                               integer=True, minimum=1)
        hi = integers(ctx, im, "harmonic_indices", f"{pre}.harmonic_indices", minimum=0)
        if hi:              # explicit indices: no engine-order family on top
            for k in ("engine_orders", "time_harmonics"):
                if k in im:
                    raise ctx.error(f"{pre}.{k}", "no engine_orders/time_harmonics with "
                                    "harmonic_indices (give one or the other)", im[k])
            kw["harmonic_indices"] = tuple(sorted(set(hi)))
        else:
            kw["engine_orders"] = integers(ctx, im, "engine_orders", f"{pre}.engine_orders",
                                           required=True)
            th = integers(ctx, im, "time_harmonics", f"{pre}.time_harmonics", minimum=0)
            kw["time_harmonics"] = th or (1,)
        kw["axis"] = vector(ctx, im, "axis", f"{pre}.axis", axis)
        kw["origin"] = vector(ctx, im, "origin", f"{pre}.origin", origin, nonzero=False)
        kw["travelling_wave"] = boolean(ctx, im, "travelling_wave", f"{pre}.travelling_wave",
                                        False)
    spec = ReductionSpec(interface=tuple(iface), active=tuple(active),
                         fixed_interface_modes=n_cb, method=method, cache=cache, **kw)
    return spec, cyc, modes_auto


def parse_contact_driven(ctx: Context, cd: dict, pre: str) -> ContactDrivenSpec:
    """``[reduction.interface_modes.contact_driven]``: the stuck mode (``frequency``, Hz)
    whose slip onset ranks the contact elements, and which of them get static responses:
    the first ``elements`` by onset and/or those slipping below ``amplitude`` (modal
    amplitude, sqrt(kg) m); ``normal``: unit normal forces too; ``tol``: drop tolerance."""
    unknown(ctx, cd, {"frequency", "elements", "amplitude", "normal", "tol"}, pre)
    freq = number(ctx, cd, "frequency", f"{pre}.frequency", required=True, positive=True)
    n = number(ctx, cd, "elements", f"{pre}.elements", integer=True, minimum=1)
    amp = number(ctx, cd, "amplitude", f"{pre}.amplitude", positive=True)
    if n is None and amp is None:
        raise ctx.error(f"{pre}.elements", "elements (the first n by slip onset) or "
                        "amplitude (every element slipping below it), or both", None)
    tol = number(ctx, cd, "tol", f"{pre}.tol", default=1e-6, positive=True, maximum=0.5)
    return ContactDrivenSpec(frequency=float(freq), elements=n,
                             amplitude=None if amp is None else float(amp),
                             normal=boolean(ctx, cd, "normal", f"{pre}.normal", False),
                             tol=float(tol))


def parse_cyclic(ctx: Context, cy: dict) -> CyclicSettings:
    """The checked ``[reduction.cyclic]`` table."""
    pre = "reduction.cyclic"
    unknown(ctx, cy, {"sectors", "left", "right", "dependent", "engine_order",
                      "boundary_modes", "modes", "harmonic_index", "tol"}, pre)
    n = number(ctx, cy, "sectors", f"{pre}.sectors", required=True, integer=True, minimum=2)
    sides = {}
    for side in ("left", "right"):
        v = string(ctx, cy, side, f"{pre}.{side}", required=True)
        if not v:
            raise ctx.error(f"{pre}.{side}", "a node-set name", v)
        sides[side] = v
    if sides["left"].upper() == sides["right"].upper():
        raise ctx.error(f"{pre}.right", "a node set other than reduction.cyclic.left",
                        sides["right"])
    dependent = string(ctx, cy, "dependent", f"{pre}.dependent", default="right",
                       choices=("right", "left"))
    eo = number(ctx, cy, "engine_order", f"{pre}.engine_order", required=True, integer=True)
    boundary_modes = number(ctx, cy, "boundary_modes", f"{pre}.boundary_modes", integer=True,
                            minimum=1)
    modes = number(ctx, cy, "modes", f"{pre}.modes", integer=True, minimum=1)
    tol = number(ctx, cy, "tol", f"{pre}.tol", positive=True)
    hi = cy.get("harmonic_index", "per_harmonic")
    expected = (f"\"per_harmonic\" or an integer nodal diameter k* in 0..{n - 1} (the "
                "one-index approximation)")
    if isinstance(hi, str):
        if hi.lower() != "per_harmonic":
            raise ctx.error(f"{pre}.harmonic_index", expected, hi)
        single = None
    elif isinstance(hi, int) and not isinstance(hi, bool) and 0 <= hi < n:
        single = hi
    else:
        raise ctx.error(f"{pre}.harmonic_index", expected, hi)
    return CyclicSettings(sectors=n, left=sides["left"], right=sides["right"],
                          dependent=dependent, engine_order=eo, boundary_modes=boundary_modes,
                          modes=modes, tol=tol, single_index=single)


def check_travelling_wave(ctx: Context, raw: dict, solver) -> int:
    """``[reduction.interface_modes] travelling_wave = true``: the deck's load must be one
    engine order's travelling wave (every ``[[excitation.engine_order]]`` of the same
    ``eo`` at harmonic 1, e.g. two clocked waves, one per stage; static point loads only)
    and the solver condensed without Hill stability. Returns that engine order; raises
    the field's error otherwise."""
    key = "reduction.interface_modes.travelling_wave"
    if solver.formulation != "condensed":
        raise ctx.error("solver.formulation", f"'condensed' with {key} = true",
                        solver.formulation)
    if solver.auto_harmonics:
        raise ctx.error("solver.harmonics", f"an integer with {key} = true (the selection "
                        "is built for one H; choose H with a run without it)", "auto")
    if solver.stability is True:
        raise ctx.error("solver.stability", f"false with {key} = true (Hill's method "
                        "would see only perturbations inside the travelling wave); set "
                        "[solver] stability = false", True)
    exc = raw.get("excitation", {})
    for k, ld in enumerate(exc.get("load", [])):
        if int(ld.get("harmonic", 1)) != 0:
            raise ctx.error(f"excitation.load[{k}].harmonic", f"0 with {key} = true (a "
                            "point load at a harmonic >= 1 is not a travelling wave; "
                            "give it as [[excitation.engine_order]])", ld.get("harmonic", 1))
    eos = exc.get("engine_order", [])
    eos = [eos] if isinstance(eos, dict) else eos
    if not eos:
        raise ctx.error("excitation.engine_order", f"an engine-order travelling wave with "
                        f"{key} = true", None)
    first = int(eos[0]["eo"])
    n = int(raw.get("reduction", {}).get("interface_modes", {}).get("sectors", 1))
    for k, eo in enumerate(eos):
        if int(eo.get("harmonic", 1)) != 1:
            raise ctx.error(f"excitation.engine_order[{k}].harmonic", f"1 with {key} = "
                            "true (the wave's time harmonic 1)", eo.get("harmonic"))
        ns = int(eo.get("n_sectors", len(eo.get("dofs", []))))
        if ns != len(eo.get("dofs", [])) or ns % n:
            raise ctx.error(f"excitation.engine_order[{k}].n_sectors", f"one DoF per "
                            f"sector of the whole stage ({len(eo.get('dofs', []))} given), "
                            f"a multiple of reduction.interface_modes.sectors = {n}, with "
                            f"{key} = true (a wave over every sector of the rotor)", ns)
        # the same wave: e = e_0 modulo the N sectors (the loads' phases alias); -e_0 is
        # the wave running the other way, which with e_0 makes a standing wave
        if (int(eo["eo"]) - first) % n:
            raise ctx.error(f"excitation.engine_order[{k}].eo", f"{first} modulo "
                            f"reduction.interface_modes.sectors = {n} (the engine order of "
                            f"excitation.engine_order[0]), with {key} = true (one "
                            "travelling wave)", eo["eo"])
    return first
