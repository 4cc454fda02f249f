"""The deck as settings: TOML in, plain validated objects out (see docs/deck.md).

:func:`parse_deck` checks every field of a deck and returns a :class:`DeckSettings`. It
reads no matrix and reduces nothing: what needs the model (a DoF index in range, a label
in ``model.dof_labels``, a node of a node set) is checked by :mod:`frirom.deck.build`.
"""

from __future__ import annotations

import math
import dataclasses
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._errors import MAX_HARMONICS, MAX_OMEGA, InputError, samples_problem
from ..io._common import read_text
from ..reduction.rom import FESource, ReductionSpec
from .fields import Context, DofRef, boolean, dof_ref, file, number, string, table, unknown
from ..solver import SolverOptions
from .schema_analysis import parse_analysis
from .schema_contacts import parse_contacts, parse_preloads
from .schema_fold import parse_fold_locus
from .schema_model import (CyclicSettings, MatrixModel, check_travelling_wave, parse_fe_model,
                           parse_matrix_model, parse_reduction)

try:                                   # Python >= 3.11
    import tomllib
except ModuleNotFoundError:            # pragma: no cover - Python 3.10 with tomli
    try:
        import tomli as tomllib
    except ModuleNotFoundError:
        tomllib = None

#: The solver's defaults: the one place a deck's omitted [solver] / [continuation] key
#: takes its value from (docs/deck.md gives each; tests/test_deck.py checks they agree).
SOLVER_DEFAULTS = SolverOptions()

#: Deck keys that also go by the solver's own name (SolverOptions, the solver's advice):
#: table -> {alias: deck key}.
ALIASES = {"solver": {"max_iter": "max_iterations"},
           "continuation": {"ds": "step", "ds_min": "min_step", "ds_max": "max_step"}}

#: frequency unit -> factor to rad/s
FREQUENCY_UNITS = {"hz": 2.0 * math.pi, "rad/s": 1.0}


@dataclass(frozen=True)
class SolverSettings:
    """``[solver]``.

    harmonics : int
        H >= 1, the highest harmonic.
    samples : int or None
        N >= 2H+1 time samples per period of the AFT (None: the solver's default).
    formulation : str
        ``"condensed"`` or ``"banded"``.
    tol_residual, tol_update : float or None
        Newton tolerances (None: the solver's defaults).
    max_iterations : int or None
        Newton iterations per point (None: the solver's default); the deck also accepts
        the solver's name ``max_iter``.
    stability : bool or "auto"
        Hill stability of every point (false with [reduction.cyclic]); "auto": on where
        affordable, the reason in the run's summary where not; "strip": the whole strip
        |Im s| <= w/2 on reduced models too (else the exponents nearest 0 there); default
        ``SolverOptions.stability``.
    tol_stall : float or None
        A corrector stalling below this residual is accepted (None: the solver's default).
    history : bool
        Carry the contact history along the curve; default ``SolverOptions.history``.
    auto_harmonics, auto_samples : bool
        ``harmonics = "auto"`` / ``samples = "auto"``: :mod:`frirom.auto` chooses them
        before the run (``harmonics`` then holds ``max_harmonics``, the largest allowed;
        ``samples`` None).
    tolerance_auto : float
        Relative error on the response amplitude that the chosen H and N must meet.
    max_harmonics, max_samples : int
        The largest H and N the choice may use.
    harmonics_kept : str, list, dict or None
        Harmonic selection (``SolverOptions.harmonics_kept``): ``"odd"``, ``"even"``, a list
        of harmonics, or a table from contact group name to such a spec; ``"auto"``:
        chosen per unknown before the run (:mod:`frirom.auto_kept`, to
        ``tolerance_auto``); stability is then off (Hill's method would see only the kept
        harmonics).
    """

    harmonics: int
    samples: int | None
    formulation: str
    tol_residual: float | None
    tol_update: float | None
    max_iterations: int | None
    stability: bool | str
    tol_stall: float | None = None
    history: bool = SOLVER_DEFAULTS.history
    auto_harmonics: bool = False
    auto_samples: bool = False
    tolerance_auto: float = 1e-3
    max_harmonics: int = 15
    max_samples: int = 4096
    harmonics_kept: object = None


@dataclass(frozen=True)
class DampingSettings:
    """``[damping]``.

    type : str
        ``"rayleigh"``, ``"modal"`` or ``"matrix"``.
    alpha, beta : float
        Rayleigh C = alpha M + beta K; alpha [1/s], beta [s].
    zeta : ndarray, (n_modes,), or None
        Modal damping ratios in [0, 1), lowest mode first.
    every_mode : bool
        ``zeta`` was one number for every mode of the model.
    file : Path or None
        MatrixMarket file of C [N s/m], (n_dof, n_dof).
    """

    type: str
    alpha: float = 0.0
    beta: float = 0.0
    zeta: np.ndarray | None = None
    every_mode: bool = False
    file: Path | None = None


@dataclass(frozen=True)
class Load:
    """One harmonic load of ``[[excitation.load]]`` or ``[[excitation.engine_order]]``.

    dof : DofRef
        The loaded DoF (with [fe_model] a node set loads each of its nodes).
    harmonic : int
        h in 0..H (0: a static load).
    amplitude : complex
        Complex amplitude [N] (phase included): f(t) = Re(amplitude exp(i h omega t)).
    """

    dof: DofRef
    harmonic: int
    amplitude: complex


@dataclass(frozen=True)
class FrequencySettings:
    """``[frequency]``: the range swept, in the deck's unit.

    start, end : float
        Start and end frequency (> 0, different) in ``unit``.
    unit : str
        ``"hz"`` or ``"rad/s"``.
    """

    start: float
    end: float
    unit: str

    @property
    def omega_start(self) -> float:
        """Start [rad/s]."""
        return self.start * FREQUENCY_UNITS[self.unit]

    @property
    def omega_end(self) -> float:
        """End [rad/s]."""
        return self.end * FREQUENCY_UNITS[self.unit]


@dataclass(frozen=True)
class ContinuationSettings:
    """``[continuation]`` (None: the solver's default).

    step, min_step, max_step : float or None
        The solver's dimensionless arc-length steps (first, smallest, largest); the deck
        also accepts the solver's names ``ds``, ``ds_min``, ``ds_max``.
    max_points : int or None
        Points of the curve at most.
    """

    step: float | None = None
    min_step: float | None = None
    max_step: float | None = None
    max_points: int | None = None


@dataclass(frozen=True)
class OutputSettings:
    """``[outputs]``.

    dofs : tuple of DofRef
        DoFs whose harmonics are written.
    plot, csv : bool
        Write frf.png/states.png, frf.csv.
    """

    dofs: tuple
    plot: bool = True
    csv: bool = True


@dataclass(frozen=True)
class DeckSettings:
    """A whole deck, checked.

    path : Path
        The deck file. title : str.
    model : MatrixModel or None
        ``[model]`` (None with ``[fe_model]``).
    fe_model : FESource or None, reduction : ReductionSpec or None
        ``[fe_model]`` and ``[reduction]`` (None with ``[model]``).
    cyclic : CyclicSettings or None
        ``[reduction.cyclic]``.
    solver, damping, frequency, continuation, outputs
        The tables of those names.
    loads : tuple of Load
        Every load of ``[excitation]`` (engine-order entries expanded per sector).
    contacts : tuple of DofContact (with [model]) or NodeSetContact (with [fe_model])
    raw : dict
        The TOML as read.
    modes_auto : ModesAuto or None
        Interface-mode counts ``"auto"`` (frirom.auto); ``reduction`` holds the first rung.
    preloads : tuple of Preload
        ``[[preload]]``: loads whose contacts' n0 and balancing loads are derived.
    """

    path: Path
    title: str
    model: MatrixModel | None
    fe_model: FESource | None
    reduction: ReductionSpec | None
    cyclic: CyclicSettings | None
    solver: SolverSettings
    damping: DampingSettings
    loads: tuple
    contacts: tuple
    frequency: FrequencySettings
    continuation: ContinuationSettings
    outputs: OutputSettings
    raw: dict = field(default_factory=dict, repr=False)
    modes_auto: object = None
    preloads: tuple = ()
    #: ``[analysis]`` (schema_analysis.AnalysisSettings): a forced response by default
    analysis: object = None
    #: ``[fold_locus]`` (schema_fold.FoldLocusSettings), None when absent
    fold_locus: object = None

    @property
    def fe(self) -> bool:
        """True with [fe_model] (DoFs are FE nodes and directions)."""
        return self.model is None


def read_toml(path: Path) -> dict:
    """The deck file's TOML as a dict; InputError if missing, unreadable or not TOML."""
    if tomllib is None:
        raise InputError(f"{path}: reading a deck needs Python >= 3.11 (tomllib) "
                         "or the 'tomli' package")
    if path.is_dir():
        raise InputError(f"{path}: cannot read the deck (a folder, not a file)")
    if not path.exists():
        raise InputError(f"{path}: deck file does not exist")
    text = read_text(path)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML: {exc}") from None


def parse_deck(path, raw: dict | None = None, allow_code=()) -> DeckSettings:
    """Read and check a deck file; raises :class:`frirom.InputError` on any bad field.

    ``raw``: the deck's TOML as a dict, used instead of reading ``path`` (a study member:
    the deck with some keys replaced, :mod:`frirom.study`); relative file names stay
    relative to ``path``. A ``[study]`` table is checked by :func:`frirom.study.parse_study`
    and ignored here. ``allow_code``: modules a user contact law may import (load_deck).
    """
    path = Path(path)
    raw = read_toml(path) if raw is None else raw
    ctx = Context(path)
    ctx.allow_code = tuple(allow_code)
    unknown(ctx, raw, {"title", "model", "fe_model", "reduction", "damping", "excitation",
                       "contacts", "solver", "frequency", "continuation", "outputs",
                       "study", "preload", "analysis", "fold_locus"}, "")
    title = string(ctx, raw, "title", "title", default=path.stem)

    # structure: [model] (matrices as they are) or [fe_model] + [reduction]
    model = source = spec = cyc = modes_auto = None
    if "fe_model" in raw or "reduction" in raw:
        if "model" in raw:
            raise ctx.error("model", "either [model] (matrices used as they are) or "
                            "[fe_model] + [reduction] (FE matrices to reduce), not both")
        source = parse_fe_model(ctx, table(ctx, raw, "fe_model"))
        spec, cyc, modes_auto = parse_reduction(ctx, table(ctx, raw, "reduction"))
    else:
        model = parse_matrix_model(ctx, table(ctx, raw, "model"))
    fe = model is None
    labels = not fe and model.dof_labels is not None

    analysis = parse_analysis(ctx, raw, fe, labels)
    nlm = analysis.nonlinear_mode
    if analysis.nodal_diameter is not None:
        if not (nlm and cyc is not None):
            raise ctx.error("analysis.nodal_diameter", "only in a nonlinear-mode deck with "
                            "[reduction.cyclic]", analysis.nodal_diameter)
        if analysis.nodal_diameter >= cyc.sectors:
            raise ctx.error("analysis.nodal_diameter", f"an integer 0..{cyc.sectors - 1} "
                            "(reduction.cyclic.sectors - 1)", analysis.nodal_diameter)
        # the sector's modes are computed for the nodal diameters of the mode's harmonics
        cyc = dataclasses.replace(cyc, engine_order=analysis.nodal_diameter)
    solver = _solver(ctx, table(ctx, raw, "solver"), cyc)
    H = solver.harmonics
    damping = _damping(ctx, table(ctx, raw, "damping"), fe)
    loads = _excitation(ctx, table(ctx, raw, "excitation", required=not nlm), H, fe, labels,
                        cyc)
    if nlm:
        for ld in loads:
            if ld.harmonic != 0:
                raise ctx.error("excitation.load", "static loads only (harmonic = 0) in a "
                                "nonlinear-mode deck ([analysis] kind = "
                                "\"nonlinear_mode\")", ld.harmonic)
    preloads = parse_preloads(ctx, raw, fe)
    contacts = parse_contacts(ctx, raw, fe, labels, cyc, preloads)
    if spec is not None and spec.contact_driven is not None:
        # the [[preload]] tables give the contact-driven basis its n0 (rom key included)
        spec = dataclasses.replace(spec, contact_driven=dataclasses.replace(
            spec.contact_driven, preloads=tuple(
                (float(p.load), tuple(float(x) for x in p.direction), p.body,
                 tuple(p.contacts)) for p in preloads)))
    frequency = (None if nlm and "frequency" not in raw else
                 _frequency(ctx, table(ctx, raw, "frequency")))
    continuation = _continuation(ctx, table(ctx, raw, "continuation", required=False))
    outputs = _outputs(ctx, table(ctx, raw, "outputs"), fe, labels)
    if analysis.output is not None:
        outputs = dataclasses.replace(outputs, dofs=(analysis.output,) + outputs.dofs)
    if spec is not None and spec.travelling_wave:
        check_travelling_wave(ctx, raw, solver)
    if isinstance(solver.harmonics_kept, dict):
        names = [c.name for c in contacts]
        for name in solver.harmonics_kept:
            if name not in names:
                raise ctx.error(f"solver.harmonics_kept.{name}", f"a contact group's name "
                                f"(groups: {names})", name)
    return DeckSettings(path=path, title=title, model=model, fe_model=source, reduction=spec,
                        cyclic=cyc, solver=solver, damping=damping, loads=tuple(loads),
                        contacts=tuple(contacts), frequency=frequency,
                        continuation=continuation, outputs=outputs, raw=raw,
                        modes_auto=modes_auto, preloads=tuple(preloads),
                        analysis=analysis, fold_locus=parse_fold_locus(ctx, raw))


def _aliased(ctx, d: dict, table_name: str) -> dict:
    """``d`` with each alias of :data:`ALIASES` renamed to its deck key (both given: an
    error naming the two)."""
    out = dict(d)
    for alias, key in ALIASES[table_name].items():
        if alias in out:
            if key in out:
                raise ctx.error(f"{table_name}.{alias}", f"either {table_name}.{key} or its "
                                f"alias {table_name}.{alias}, not both", out[alias])
            out[key] = out.pop(alias)
    return out


def _solver(ctx, sol, cyc) -> SolverSettings:
    unknown(ctx, sol, {"harmonics", "samples", "formulation", "tol_residual",
                       "tol_update", "max_iterations", "stability", "tolerance_auto",
                       "max_harmonics", "max_samples", "tol_stall", "history",
                       "harmonics_kept", *ALIASES["solver"]}, "solver")
    sol = _aliased(ctx, sol, "solver")
    auto = _auto(ctx, sol, cyc)
    H = auto["max_harmonics"] if auto["auto_harmonics"] else number(
        ctx, sol, "harmonics", "solver.harmonics", required=True, integer=True, minimum=1,
        maximum=MAX_HARMONICS)
    N = None if auto["auto_samples"] else number(ctx, sol, "samples", "solver.samples",
                                                 integer=True)
    if N is not None and samples_problem(H, N):
        raise ctx.error("solver.samples", samples_problem(H, N), N)
    if auto["auto_samples"] and samples_problem(H, auto["max_samples"]):
        raise ctx.error("solver.max_samples", samples_problem(H, auto["max_samples"]),
                        auto["max_samples"])
    form = string(ctx, sol, "formulation", "solver.formulation", default="condensed",
                  choices=("condensed", "banded"))
    tols = []
    for k in ("tol_residual", "tol_update"):
        v = number(ctx, sol, k, f"solver.{k}", positive=True)
        tols.append(None if v is None else float(v))
    max_it = number(ctx, sol, "max_iterations", "solver.max_iterations", integer=True,
                    minimum=1)
    # "auto": on where affordable (frirom._pack.resolve_stability)
    stability = sol.get("stability", SOLVER_DEFAULTS.stability)
    if not (isinstance(stability, bool) or stability in ("auto", "strip")):
        raise ctx.error("solver.stability", 'true or false (or "auto", "strip")', stability)
    stall = number(ctx, sol, "tol_stall", "solver.tol_stall", nonneg=True)
    history = boolean(ctx, sol, "history", "solver.history", SOLVER_DEFAULTS.history)
    kept = _harmonics_kept(ctx, sol.get("harmonics_kept"), H)
    if kept is not None:
        if cyc is not None:
            raise ctx.error("solver.harmonics_kept", "no harmonic selection with "
                            "[reduction.cyclic] (a sector's harmonics live on their own nodal "
                            "diameters)", sol["harmonics_kept"])
        if form != "condensed":
            raise ctx.error("solver.formulation", "'condensed' with solver.harmonics_kept",
                            form)
        if sol.get("stability") is True:
            raise ctx.error("solver.stability", "false with solver.harmonics_kept (Hill's "
                            "method would see only the kept harmonics)", True)
        stability = False
    if cyc is not None:
        if form != "condensed":
            raise ctx.error("solver.formulation", "'condensed' with [reduction.cyclic] "
                            "(a cyclic sector is solved on its modal receptances)", form)
        if sol.get("stability") is True:
            raise ctx.error("solver.stability", "false with [reduction.cyclic] (Hill "
                            "stability is not implemented for cyclic sectors)", True)
        stability = False
    return SolverSettings(harmonics=H, samples=N, formulation=form, tol_residual=tols[0],
                          tol_update=tols[1], max_iterations=max_it, stability=stability,
                          tol_stall=None if stall is None else float(stall), history=history,
                          harmonics_kept=kept, **auto)


def _harmonics_kept(ctx, kept, H: int):
    """``solver.harmonics_kept``: "odd", "even", a list of harmonics in 0..H, or a table
    from contact group name to one of those; checked, None when absent."""
    from ..options import kept_harmonics
    from .._errors import ParameterError
    if kept is None or kept == "auto":
        return kept
    expected = (f"'auto', 'odd', 'even' or a list of distinct harmonics in 0..{H} "
                f"(harmonics = {H})")
    items = kept.items() if isinstance(kept, dict) else [(None, kept)]
    if isinstance(kept, dict) and not kept:
        raise ctx.error("solver.harmonics_kept", "a table naming at least one contact group",
                        kept)
    for name, spec in items:
        key = "solver.harmonics_kept" + ("" if name is None else f".{name}")
        if isinstance(spec, (bool, dict)):
            raise ctx.error(key, expected, spec)
        try:
            kept_harmonics(spec, H, key)
        except ParameterError:
            raise ctx.error(key, expected, spec) from None
    return dict(kept) if isinstance(kept, dict) else (list(kept) if isinstance(kept, list)
                                                      else kept)


def _auto(ctx, sol, cyc) -> dict:
    """``harmonics = "auto"``, ``samples = "auto"`` and their keys (frirom.auto)."""
    out = {f"auto_{k}": sol.get(k) == "auto" for k in ("harmonics", "samples")}
    for k in ("harmonics", "samples"):
        if isinstance(sol.get(k), str) and sol[k] != "auto":
            raise ctx.error(f"solver.{k}", 'an integer or "auto"', sol[k])
    on = out["auto_harmonics"] or out["auto_samples"]
    given = [k for k in ("tolerance_auto", "max_harmonics", "max_samples") if k in sol]
    kept = sol.get("harmonics_kept") == "auto"
    if kept and given == ["tolerance_auto"]:
        given = []              # harmonics_kept = "auto" reads the tolerance too
    if given and not on:
        raise ctx.error(f"solver.{given[0]}", 'harmonics = "auto", samples = "auto" or '
                        'harmonics_kept = "auto" (it only bounds that choice)',
                        sol[given[0]])
    if on and cyc is not None:
        key = "harmonics" if out["auto_harmonics"] else "samples"
        raise ctx.error(f"solver.{key}", "an integer with [reduction.cyclic] (\"auto\" is "
                        "not available for cyclic sectors)", "auto")
    out["tolerance_auto"] = float(number(ctx, sol, "tolerance_auto", "solver.tolerance_auto",
                                         default=1e-3, positive=True, maximum=0.5))
    out["max_harmonics"] = int(number(ctx, sol, "max_harmonics", "solver.max_harmonics",
                                      default=15, integer=True, minimum=3,
                                      maximum=MAX_HARMONICS))
    out["max_samples"] = int(number(ctx, sol, "max_samples", "solver.max_samples",
                                    default=4096, integer=True, minimum=8))
    return out


def _damping(ctx, damp, fe) -> DampingSettings:
    dtype = string(ctx, damp, "type", "damping.type", required=True,
                   choices=("rayleigh", "modal", "matrix"))
    if dtype == "rayleigh":
        unknown(ctx, damp, {"type", "alpha", "beta"}, "damping")
        return DampingSettings(
            "rayleigh",
            alpha=float(number(ctx, damp, "alpha", "damping.alpha", default=0.0, nonneg=True)),
            beta=float(number(ctx, damp, "beta", "damping.beta", default=0.0, nonneg=True)))
    if dtype == "modal":
        unknown(ctx, damp, {"type", "zeta"}, "damping")
        z = damp.get("zeta")
        if isinstance(z, (int, float)) and not isinstance(z, bool):
            zeta = number(ctx, damp, "zeta", "damping.zeta", nonneg=True)
            if zeta >= 1:
                raise ctx.error("damping.zeta", "a damping ratio in [0, 1)", zeta)
            return DampingSettings("modal", zeta=np.array([float(zeta)]), every_mode=True)
        if isinstance(z, list) and z:
            zeta = np.array([number(ctx, {"z": zi}, "z", f"damping.zeta[{i}]", nonneg=True)
                             for i, zi in enumerate(z)], float)
            if np.any(zeta >= 1):
                i = int(np.argmax(zeta >= 1))
                raise ctx.error(f"damping.zeta[{i}]", "a damping ratio in [0, 1)", z[i])
            return DampingSettings("modal", zeta=zeta)
        raise ctx.error("damping.zeta", "a damping ratio or a list of ratios "
                        "(one per mode, lowest first)", z)
    unknown(ctx, damp, {"type", "file"}, "damping")
    if fe:
        raise ctx.error("damping.type", "'rayleigh' or 'modal' with [fe_model] (a damping "
                        "matrix file needs [model])", dtype)
    return DampingSettings("matrix", file=file(ctx, damp, "file", "damping.file"))


def _excitation(ctx, exc, H, fe, labels, cyc) -> list:
    """Every load, engine-order entries expanded to one load per sector DoF."""
    unknown(ctx, exc, {"load", "engine_order"}, "excitation")
    out = []
    loads = exc.get("load", [])
    if not isinstance(loads, list):
        raise ctx.error("excitation.load", "an array of tables [[excitation.load]]", loads)
    for key, ld in _tables(ctx, loads, "excitation.load",
                           {"dof", "harmonic", "amplitude", "phase"}):
        if "dof" not in ld:
            raise ctx.error(f"{key}.dof", "a DoF (missing)")
        d = dof_ref(ctx, ld["dof"], f"{key}.dof", fe, labels)
        h = number(ctx, ld, "harmonic", f"{key}.harmonic", default=1, integer=True, minimum=0)
        if h > H:
            raise ctx.error(f"{key}.harmonic", f"a harmonic in 0..solver.harmonics={H}", h)
        amp = number(ctx, ld, "amplitude", f"{key}.amplitude", required=True)
        ph = _phase(ctx, ld, f"{key}.phase")
        if h == 0 and ph not in (0, 0.0):
            raise ctx.error(f"{key}.phase", "0 for a static load (harmonic 0)", ph)
        out.append(Load(d, h, amp * np.exp(1j * np.deg2rad(ph))))
    eos = exc.get("engine_order", [])
    if isinstance(eos, dict):
        eos = [eos]
    if eos and cyc is not None:
        raise ctx.error("excitation.engine_order", "no [[excitation.engine_order]] with "
                        "[reduction.cyclic]: give sector 0's loads in "
                        "[[excitation.load]]; reduction.cyclic.engine_order makes them a "
                        "travelling wave")
    if not isinstance(eos, list):
        raise ctx.error("excitation.engine_order", "an array of tables", eos)
    for key, eo in _tables(ctx, eos, "excitation.engine_order",
                           {"eo", "dofs", "n_sectors", "amplitude", "phase", "harmonic"}):
        order = number(ctx, eo, "eo", f"{key}.eo", required=True, integer=True)
        dofs = eo.get("dofs")
        if not isinstance(dofs, list) or not dofs:
            raise ctx.error(f"{key}.dofs", "a non-empty list: one DoF (or list of DoFs) "
                            "per sector", dofs)
        ns = number(ctx, eo, "n_sectors", f"{key}.n_sectors", default=len(dofs), integer=True,
                    minimum=1)
        h = number(ctx, eo, "harmonic", f"{key}.harmonic", default=1, integer=True, minimum=1)
        if h > H:
            raise ctx.error(f"{key}.harmonic", f"a harmonic in 1..solver.harmonics={H}", h)
        amp = number(ctx, eo, "amplitude", f"{key}.amplitude", required=True)
        ph = _phase(ctx, eo, f"{key}.phase")
        a0 = amp * np.exp(1j * np.deg2rad(ph))
        for s, ds in enumerate(dofs):
            phase = np.exp(-2j * np.pi * order * s / ns)     # as engine_order_loads
            items = ds if isinstance(ds, list) else [ds]
            for j, v in enumerate(items):
                k = f"{key}.dofs[{s}]" + (f"[{j}]" if isinstance(ds, list) else "")
                out.append(Load(dof_ref(ctx, v, k, fe, labels), h, a0 * phase))
    return out


def _phase(ctx, d, key) -> float:
    """A phase in degrees, -360..360 (0 if absent)."""
    ph = number(ctx, d, "phase", key, default=0.0)
    if abs(ph) > 360:
        raise ctx.error(key, "a phase in degrees, -360..360", ph)
    return ph


def _tables(ctx, entries: list, prefix: str, allowed):
    """(key path, table) of each entry of an array of tables, checked for unknown keys."""
    for i, t in enumerate(entries):
        key = f"{prefix}[{i}]"
        if not isinstance(t, dict):
            raise ctx.error(key, "a table", t)
        unknown(ctx, t, allowed, key)
        yield key, t


def _frequency(ctx, fr) -> FrequencySettings:
    unknown(ctx, fr, {"start", "end", "unit"}, "frequency")
    unit = string(ctx, fr, "unit", "frequency.unit", default="hz",
                  choices=tuple(FREQUENCY_UNITS))
    top = MAX_OMEGA / FREQUENCY_UNITS[unit]
    f0 = number(ctx, fr, "start", "frequency.start", required=True, positive=True,
                maximum=top)
    f1 = number(ctx, fr, "end", "frequency.end", required=True, positive=True, maximum=top)
    if f1 == f0:
        raise ctx.error("frequency.end", "a frequency different from frequency.start", f1)
    return FrequencySettings(start=f0, end=f1, unit=unit)


#: The largest arc-length step of a deck (dimensionless; the solver's default largest is
#: 0.1): past it a step jumps over whole resonances.
MAX_STEP = 10.0


def _continuation(ctx, con) -> ContinuationSettings:
    unknown(ctx, con, {"step", "min_step", "max_step", "max_points",
                       *ALIASES["continuation"]}, "continuation")
    con = _aliased(ctx, con, "continuation")
    steps = {}
    for k in ("step", "min_step", "max_step"):
        v = number(ctx, con, k, f"continuation.{k}", positive=True, maximum=MAX_STEP)
        if v is not None:
            steps[k] = float(v)
    if "min_step" in steps and "max_step" in steps and steps["min_step"] > steps["max_step"]:
        raise ctx.error("continuation.min_step", "a value <= continuation.max_step",
                        con["min_step"])
    n = number(ctx, con, "max_points", "continuation.max_points", integer=True, minimum=2)
    return ContinuationSettings(**steps, max_points=n)


def _outputs(ctx, out, fe, labels) -> OutputSettings:
    unknown(ctx, out, {"dofs", "plot", "csv"}, "outputs")
    od = out.get("dofs")
    if not isinstance(od, list) or not od:
        raise ctx.error("outputs.dofs", "a non-empty list of DoFs", od)
    dofs = tuple(dof_ref(ctx, v, f"outputs.dofs[{i}]", fe, labels) for i, v in enumerate(od))
    return OutputSettings(dofs=dofs, plot=boolean(ctx, out, "plot", "outputs.plot", True),
                          csv=boolean(ctx, out, "csv", "outputs.csv", True))
