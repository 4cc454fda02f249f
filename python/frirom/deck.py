"""The frirom input deck: one TOML file, one parser (see docs/deck.md).

A deck names the structure either as assembled matrices used as they are (``[model]``,
MatrixMarket, DoFs by index or label) or as FE matrices to reduce (``[fe_model]`` with
``[reduction]``: Craig-Bampton, GSI or multi-stage interface modes, cached), then the
damping, excitation, contacts, harmonics, frequency range, continuation options and
outputs. With ``[fe_model]``, contacts join node sets (pairs matched by coordinates, local
frame from a normal), and excitation and outputs name FE nodes and directions
(``"ACTIVE:z"``, ``"1234:UX"``): the reduced coordinates never appear in a deck.
``[reduction.cyclic]`` makes the reduced model one sector of a tuned rotor under an
engine-order travelling wave: ``Deck.model()`` is then a :class:`frirom.model.CyclicModel`
whose modes (one Hermitian eigen-solve per nodal diameter the harmonics live on) are
computed by ``load_deck`` after the cached reduction.

``load_deck(path)`` checks every field before any computation, then loads the matrices
(and builds or reuses the reduced model) and returns a :class:`Deck` holding plain
numpy/scipy data; ``Deck.model()``, ``Deck.excitation()`` and ``Deck.options()`` build the
solver's objects from it. Every malformed field raises :class:`frirom.InputError` naming
the deck file, the TOML key path (``contacts[2].mu``) and what was expected.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.io
import scipy.sparse as sp

from ._errors import InputError

try:                                   # Python >= 3.11
    import tomllib
except ModuleNotFoundError:            # pragma: no cover - Python 3.10 with tomli
    try:
        import tomli as tomllib
    except ModuleNotFoundError:
        tomllib = None

__all__ = ["Deck", "ContactSpec", "load_deck", "engine_order_loads", "read_matrix",
           "LAW_PARAMS", "MATRIX_FORMATS"]

#: law -> (local direction names, parameter names, number of slider coordinates)
LAW_PARAMS = {
    "jenkins": (("u",), ("kt", "mu", "fn0"), 1),
    "normal1d": (("u", "v"), ("kt", "kn", "mu", "n0"), 1),
    "normal2d": (("u1", "u2", "v"), ("kt", "kn", "mu", "n0"), 2),
    "cubic": (("u",), ("k1", "k3"), 0),
}

#: parameters that must be >= 0 (n0 may be negative: an initial gap)
_NONNEGATIVE = {"kt", "kn", "mu", "fn0"}

MATRIX_FORMATS = ("mtx",)

_FREQ_UNITS = {"hz": 2.0 * math.pi, "rad/s": 1.0}

#: direction names of FE DoFs ("NODE:DIR" references) -> direction number
_DIR_NUMBERS = {"x": 1, "y": 2, "z": 3, "ux": 1, "uy": 2, "uz": 3, "rotx": 4, "roty": 5,
                "rotz": 6, "1": 1, "2": 2, "3": 3, "4": 4, "5": 5, "6": 6}


class _Ctx:
    """Builds InputErrors that name the deck file and the key path."""

    def __init__(self, path: Path):
        self.path = path

    def error(self, key: str, expected: str, got=None) -> InputError:
        msg = f"{self.path}: {key}: expected {expected}"
        if got is not None:
            shown = repr(got)
            if len(shown) > 80:
                shown = shown[:77] + "..."
            msg += f", got {shown}"
        return InputError(msg)


def _table(ctx, d, key, required=True):
    parts = key.split(".")
    v = d.get(parts[-1]) if isinstance(d, dict) else None
    if v is None:
        if required:
            raise ctx.error(key, "a table [" + key + "]")
        return {}
    if not isinstance(v, dict):
        raise ctx.error(key, "a table", v)
    return v


def _unknown(ctx, d: dict, allowed, prefix: str):
    for k in d:
        if k not in allowed:
            where = f"{prefix}.{k}" if prefix else k
            raise ctx.error(where, "one of the known keys " + ", ".join(sorted(allowed))
                            + " (unknown key)")


def _num(ctx, d, name, key, *, default=None, required=False, positive=False,
         nonneg=False, integer=False, minimum=None):
    if name not in d:
        if required:
            raise ctx.error(key, "a number (missing)")
        return default
    v = d[name]
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ctx.error(key, "an integer" if integer else "a number", v)
    if integer and not isinstance(v, int):
        raise ctx.error(key, "an integer", v)
    if not math.isfinite(v):
        raise ctx.error(key, "a finite number", v)
    if positive and v <= 0:
        raise ctx.error(key, "a positive number", v)
    if nonneg and v < 0:
        raise ctx.error(key, "a number >= 0", v)
    if minimum is not None and v < minimum:
        raise ctx.error(key, f"a number >= {minimum}", v)
    return v


def _str(ctx, d, name, key, *, default=None, required=False, choices=None):
    if name not in d:
        if required:
            raise ctx.error(key, "a string (missing)" if not choices else
                            "one of " + ", ".join(repr(c) for c in choices) + " (missing)")
        return default
    v = d[name]
    if not isinstance(v, str):
        raise ctx.error(key, "a string", v)
    if choices is not None and v.lower() not in choices:
        raise ctx.error(key, "one of " + ", ".join(repr(c) for c in choices), v)
    return v.lower() if choices is not None else v


def _bool(ctx, d, name, key, default):
    if name not in d:
        return default
    v = d[name]
    if not isinstance(v, bool):
        raise ctx.error(key, "true or false", v)
    return v


def read_matrix(path: Path, fmt: str, what: str, deck_path: Path | None = None):
    """Read one matrix file as scipy CSR; ``fmt`` is one of :data:`MATRIX_FORMATS`."""
    where = f"{deck_path}: " if deck_path else ""
    if fmt != "mtx":
        raise InputError(f"{where}model.format: expected one of {MATRIX_FORMATS}, got {fmt!r}")
    if not path.is_file():
        raise InputError(f"{where}{what}: matrix file {path} does not exist")
    try:
        A = scipy.io.mmread(str(path))
    except Exception as exc:     # scipy raises ValueError/IndexError/... for bad files
        raise InputError(f"{path}: not a readable MatrixMarket file ({what}): {exc}") from exc
    A = sp.csr_matrix(A, dtype=float) if not sp.issparse(A) else A.tocsr().astype(float)
    if A.shape[0] != A.shape[1]:
        raise InputError(f"{path}: {what} must be square, got shape {A.shape}")
    if not np.all(np.isfinite(A.data)):
        raise InputError(f"{path}: {what} has non-finite entries")
    return A


@dataclass
class ContactSpec:
    """One contact group as read from the deck (no solver objects)."""

    name: str
    law: str
    G: sp.csr_matrix          # (n_elem*n_dir, n_dof)
    params: np.ndarray        # (n_elem, n_par)
    w0: np.ndarray | None     # (n_elem, n_slider) or None


@dataclass
class Deck:
    """A checked deck. Frequencies in rad/s; F complex (n_dof, H+1); continuation steps
    are the solver's dimensionless arc-length steps."""

    path: Path
    title: str
    M: sp.csr_matrix
    K: sp.csr_matrix
    damping: dict             # {'type': 'rayleigh', 'alpha':, 'beta':} | modal | matrix
    F: np.ndarray
    contacts: list
    harmonics: int
    samples: int | None       # None: the solver's default
    formulation: str
    omega_start: float
    omega_end: float
    frequency_unit: str
    continuation: dict
    solver: dict
    outputs: list             # DoF indices
    output_names: list
    dof_labels: list | None = None
    plot: bool = True
    csv: bool = True
    raw: dict = field(default_factory=dict, repr=False)
    reduced: object = None    # frirom.reduction.rom.ReducedModel with [fe_model]
    log: list = field(default_factory=list)   # what the reduction did (built / reused)
    #: with [reduction.cyclic]: {'sector': CyclicSector, 'modes': {k: SectorModes},
    #: 'engine_order', 'single_index' (None or k*), 'sign', 'seconds'}
    cyclic: dict | None = None

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    # ---- builders of the solver's objects (python/frirom/model.py, solver.py) ----
    def damping_object(self):
        from .model import Damping
        d = self.damping
        if d["type"] == "rayleigh":
            return Damping.rayleigh(d["alpha"], d["beta"])
        if d["type"] == "modal" and self.reduced is not None and self.cyclic is None:
            # the ratios of the reduced model's own modes (python/frirom/reduction/damping.py)
            from .reduction.damping import modal_damping
            return Damping.matrix(modal_damping(self.K, self.M, d["zeta"])[0])
        if d["type"] == "modal":
            return Damping.modal(d["zeta"])
        return Damping.matrix(d["C"])

    def model(self):
        """The solver's Model, or its CyclicModel with [reduction.cyclic]."""
        from .model import ContactGroup, CyclicModel, Model
        groups = [ContactGroup(law=c.law, G=c.G, params=c.params, w0=c.w0, name=c.name)
                  for c in self.contacts]
        if self.cyclic is not None:
            c = self.cyclic
            return CyclicModel(n_dof=self.n_dof, n_sectors=c["sector"].n_sectors,
                               engine_order=c["engine_order"], modes=c["modes"],
                               contacts=groups, sign=c["sign"],
                               single_index=c["single_index"], dof_labels=self.dof_labels)
        return Model(self.M, self.K, self.damping_object(), groups,
                     dof_labels=self.dof_labels)

    def excitation(self):
        from .model import Excitation
        return Excitation(self.F)

    def options(self):
        """The solver's SolverOptions from the [solver] and [continuation] tables."""
        from .solver import SolverOptions
        kw = {"harmonics": self.harmonics, "samples": self.samples,
              "formulation": self.formulation}
        for key, name in (("tol_residual", "tol_residual"), ("tol_update", "tol_update"),
                          ("max_iterations", "max_iter"), ("stability", "stability")):
            if key in self.solver:
                kw[name] = self.solver[key]
        for key, name in (("step", "ds"), ("min_step", "ds_min"), ("max_step", "ds_max")):
            if key in self.continuation:
                kw[name] = self.continuation[key]
        if "max_points" in self.continuation:
            kw["max_points"] = self.continuation["max_points"]
        opts = SolverOptions(**kw)
        if opts.ds_min > opts.ds_max or not opts.ds_min <= opts.ds <= opts.ds_max:
            # keep the user's steps consistent with the solver's defaults for the others
            lo, hi = min(opts.ds_min, opts.ds), max(opts.ds_max, opts.ds)
            opts.ds_min, opts.ds_max = lo, hi
        return opts


def engine_order_loads(n_dof: int, dofs, eo: int, n_sectors: int, amplitude: complex,
                       harmonic: int = 1, H: int = 1) -> np.ndarray:
    """Complex loads (n_dof, H+1) of an engine-order travelling wave.

    ``dofs``: one DoF index per sector (or one list of DoFs per sector, all loaded alike);
    sector s gets amplitude * exp(-i 2 pi eo s / n_sectors) on harmonic ``harmonic``, so
    that f_s(t) = |A| cos(h omega t + arg A - 2 pi eo s / n_sectors): sector s lags sector
    0 by 2 pi eo s / n_sectors (a forward travelling wave for eo > 0).
    """
    F = np.zeros((n_dof, H + 1), complex)
    for s, d in enumerate(dofs):
        phase = np.exp(-2j * np.pi * eo * s / n_sectors)
        for j in np.atleast_1d(d):
            F[int(j), harmonic] += amplitude * phase
    return F


@dataclass
class _NodeSetContact:
    """A contact between node sets as read from a deck with [fe_model]."""

    name: str
    law: str
    a: str
    b: str | None
    normal: object
    tangent: tuple | None
    tol: float | None
    params: np.ndarray        # (n_par,)
    w0: np.ndarray | None     # (n_slider,)
    stick: tuple              # (kt, kn) of the full-stick interface modes
    key: str
    b_sector: int = 0         # 1: side b in the next sector (cyclic)


class _Parser:
    def __init__(self, path: Path):
        self.path = path
        self.ctx = _Ctx(path)
        self.base = path.parent
        self.fe = False
        self.n = self.labels = self.rom = None
        self.cyc = None           # the checked [reduction.cyclic] table
        self.partner = {}         # cyclic: left-boundary node -> its right-boundary image

    def run(self) -> Deck:
        ctx = self.ctx
        if tomllib is None:
            raise InputError(f"{self.path}: reading a deck needs Python >= 3.11 (tomllib) "
                             "or the 'tomli' package")
        try:
            with open(self.path, "rb") as fh:
                raw = tomllib.load(fh)
        except FileNotFoundError:
            raise InputError(f"{self.path}: deck file does not exist") from None
        except OSError as exc:
            raise InputError(f"{self.path}: cannot read the deck ({exc.strerror})") from None
        except tomllib.TOMLDecodeError as exc:
            raise InputError(f"{self.path}: not valid TOML: {exc}") from None
        _unknown(ctx, raw, {"title", "model", "fe_model", "reduction", "damping", "excitation",
                            "contacts", "solver", "frequency", "continuation", "outputs"}, "")
        title = _str(ctx, raw, "title", "title", default=self.path.stem)

        # ---- structure: [model] (matrices as they are) or [fe_model] + [reduction] ----
        if "fe_model" in raw or "reduction" in raw:
            if "model" in raw:
                raise ctx.error("model", "either [model] (matrices used as they are) or "
                                "[fe_model] + [reduction] (FE matrices to reduce), not both")
            source = self.fe_model(_table(ctx, raw, "fe_model"))
            spec = self.reduction(_table(ctx, raw, "reduction"))
            self.fe = True
            M = K = labels = None
            n = None
        else:
            M, K, labels = self.matrices(_table(ctx, raw, "model"))
            n = M.shape[0]
            self.fe = False
        self.n, self.labels = n, labels

        # ---- solver ----
        sol = _table(ctx, raw, "solver")
        _unknown(ctx, sol, {"harmonics", "samples", "formulation", "tol_residual",
                            "tol_update", "max_iterations", "stability"}, "solver")
        H = _num(ctx, sol, "harmonics", "solver.harmonics", required=True, integer=True,
                 minimum=1)
        N = _num(ctx, sol, "samples", "solver.samples", integer=True)
        if N is not None and N < 2 * H + 1:
            raise ctx.error("solver.samples", f"an integer >= 2*harmonics+1 = {2 * H + 1}", N)
        form = _str(ctx, sol, "formulation", "solver.formulation", default="condensed",
                    choices=("condensed", "banded"))
        solver = {}
        for k in ("tol_residual", "tol_update"):
            v = _num(ctx, sol, k, f"solver.{k}", positive=True)
            if v is not None:
                solver[k] = float(v)
        v = _num(ctx, sol, "max_iterations", "solver.max_iterations", integer=True, minimum=1)
        if v is not None:
            solver["max_iterations"] = v
        solver["stability"] = _bool(ctx, sol, "stability", "solver.stability", True)
        if self.cyc is not None:
            if form != "condensed":
                raise ctx.error("solver.formulation", "'condensed' with [reduction.cyclic] "
                                "(a cyclic sector is solved on its modal receptances)", form)
            if sol.get("stability") is True:
                raise ctx.error("solver.stability", "false with [reduction.cyclic] (Hill "
                                "stability is not implemented for cyclic sectors)", True)
            solver["stability"] = False

        damping = self.damping(_table(ctx, raw, "damping"), M)
        loads = self.excitation(_table(ctx, raw, "excitation"), H)

        # ---- contacts ----
        cons = raw.get("contacts", [])
        if not isinstance(cons, list):
            raise ctx.error("contacts", "an array of tables [[contacts]]", cons)
        if self.cyc is not None and not cons:
            raise ctx.error("contacts", "at least one [[contacts]] table with "
                            "[reduction.cyclic] (a cyclic sector is solved for its contacts)")
        contacts = [self.contact(c, f"contacts[{i}]") for i, c in enumerate(cons)]
        names = [c.name for c in contacts]
        for i, nm in enumerate(names):
            if nm in names[:i]:
                raise ctx.error(f"contacts[{i}].name", "a name not used by another contact", nm)

        # ---- frequency ----
        fr = _table(ctx, raw, "frequency")
        _unknown(ctx, fr, {"start", "end", "unit"}, "frequency")
        unit = _str(ctx, fr, "unit", "frequency.unit", default="hz", choices=tuple(_FREQ_UNITS))
        f0 = _num(ctx, fr, "start", "frequency.start", required=True, positive=True)
        f1 = _num(ctx, fr, "end", "frequency.end", required=True, positive=True)
        if f1 == f0:
            raise ctx.error("frequency.end", "a frequency different from frequency.start", f1)
        scale = _FREQ_UNITS[unit]

        # ---- continuation ----
        con = _table(ctx, raw, "continuation", required=False)
        _unknown(ctx, con, {"step", "min_step", "max_step", "max_points"}, "continuation")
        cont = {}
        for k in ("step", "min_step", "max_step"):
            v = _num(ctx, con, k, f"continuation.{k}", positive=True)
            if v is not None:
                cont[k] = float(v)
        if "min_step" in cont and "max_step" in cont and cont["min_step"] > cont["max_step"]:
            raise ctx.error("continuation.min_step", "a value <= continuation.max_step",
                            con["min_step"])
        v = _num(ctx, con, "max_points", "continuation.max_points", integer=True, minimum=2)
        if v is not None:
            cont["max_points"] = v

        # ---- outputs ----
        out = _table(ctx, raw, "outputs")
        _unknown(ctx, out, {"dofs", "plot", "csv"}, "outputs")
        od = out.get("dofs")
        if not isinstance(od, list) or not od:
            raise ctx.error("outputs.dofs", "a non-empty list of DoFs", od)
        out_refs = [(self.dof(v, f"outputs.dofs[{i}]"), f"outputs.dofs[{i}]")
                    for i, v in enumerate(od)]

        # ---- everything checked: build (or reuse) the reduced model, resolve the nodes ----
        rom, log = None, []
        if self.fe:
            from .reduction.rom import PairSpec, build_reduced_model
            pairs = [PairSpec(name=c.name, a=c.a, b=c.b, normal=c.normal, tangent=c.tangent,
                              n_dir=len(LAW_PARAMS[c.law][0]), kt=c.stick[0], kn=c.stick[1],
                              tol=c.tol, key=c.key, b_sector=c.b_sector) for c in contacts]
            rom = build_reduced_model(source, spec, pairs, self.path, log=log.append)
            M, K, n = rom.M, rom.K, rom.K.shape[0]
            self.n, self.rom = n, rom
            if self.cyc is not None:
                sector = self.cyclic_sector(rom, spec, contacts)
            contacts = [self.reduced_contact(c, rom) for c in contacts]
            if damping["type"] == "modal" and damping["zeta"].size > n:
                raise ctx.error("damping.zeta", f"at most {n} modal ratios (the reduced "
                                "model's size)", damping["zeta"].size)
        if (damping["type"] == "modal" and damping["zeta"].size == 1 and damping["all"]
                and self.cyc is None):
            damping["zeta"] = np.full(n, damping["zeta"][0])
        del damping["all"]
        F = np.zeros((n, H + 1), complex)
        for ref, h, amp, key in loads:
            self.add_load(F, ref, h, amp, key)
        if not np.any(F[:, 1:]):
            raise ctx.error("excitation", "at least one load on a harmonic >= 1 "
                            "([[excitation.load]] or [[excitation.engine_order]])")
        outputs = [self.coordinate(ref, key) for ref, key in out_refs]
        onames = [od[i] if self.fe else (labels[j] if labels else f"dof{j}")
                  for i, j in enumerate(outputs)]
        cyclic = None
        if self.cyc is not None:
            cyclic = self.cyclic_modes(sector, rom, damping, H, log.append)

        return Deck(path=self.path, title=title, M=M, K=K, damping=damping, F=F,
                    contacts=contacts, harmonics=H, samples=N, formulation=form,
                    omega_start=f0 * scale, omega_end=f1 * scale, frequency_unit=unit,
                    continuation=cont, solver=solver, outputs=outputs, output_names=onames,
                    dof_labels=labels if not self.fe else list(rom.labels),
                    plot=_bool(ctx, out, "plot", "outputs.plot", True),
                    csv=_bool(ctx, out, "csv", "outputs.csv", True), raw=raw,
                    reduced=rom, log=log, cyclic=cyclic)

    # ---- [model]: matrices used as they are ----
    def matrices(self, mdl):
        ctx = self.ctx
        _unknown(ctx, mdl, {"format", "mass", "stiffness", "dof_labels"}, "model")
        fmt = _str(ctx, mdl, "format", "model.format", default="mtx", choices=MATRIX_FORMATS)
        M = read_matrix(self.file(mdl, "mass", "model.mass"), fmt, "model.mass", self.path)
        K = read_matrix(self.file(mdl, "stiffness", "model.stiffness"), fmt,
                        "model.stiffness", self.path)
        if M.shape != K.shape:
            raise ctx.error("model.stiffness", f"a matrix of the mass matrix's shape "
                            f"{M.shape}", K.shape)
        n = M.shape[0]
        if np.any(M.diagonal() <= 0):
            i = int(np.argmax(M.diagonal() <= 0))
            raise ctx.error("model.mass", f"a mass matrix with a positive diagonal "
                            f"(DoF {i} has {M.diagonal()[i]})")
        for A, key in ((M, "model.mass"), (K, "model.stiffness")):
            asym = abs(A - A.T).max() if A.nnz else 0.0
            if asym > 1e-8 * max(abs(A).max(), 1e-300):
                raise ctx.error(key, "a symmetric matrix", f"max |A - A^T| = {asym:.3g}")
        labels = None
        if "dof_labels" in mdl:
            lp = self.file(mdl, "dof_labels", "model.dof_labels")
            labels = [s.strip() for s in lp.read_text().splitlines() if s.strip()]
            if len(labels) != n:
                raise ctx.error("model.dof_labels", f"{n} labels (one per line, matrix "
                                f"order) in {lp}", f"{len(labels)} labels")
            if len(set(labels)) != n:
                raise ctx.error("model.dof_labels", f"unique labels in {lp}")
        return M, K, labels

    # ---- [fe_model] and [reduction]: FE matrices to reduce ----
    def fe_model(self, fe):
        from .reduction.rom import FORMATS, FESource
        ctx = self.ctx
        fmt = _str(ctx, fe, "format", "fe_model.format", required=True,
                   choices=tuple(FORMATS))
        roles, required = FORMATS[fmt]
        opts = {"abaqus": ("layout",), "op4": ("stiffness_name", "mass_name")}.get(fmt, ())
        _unknown(ctx, fe, {"format", *roles, *opts}, "fe_model")
        files = {}
        for r in roles:
            if r in fe or r in required:
                files[r] = self.file(fe, r, f"fe_model.{r}")
        options = {}
        for o in opts:
            v = _str(ctx, fe, o, f"fe_model.{o}",
                     choices=("auto", "matrix", "coordinate") if o == "layout" else None)
            if v is not None:
                options[o] = v
        src = FESource(fmt, files, options)
        for r, f in files.items():
            if fmt == "calculix" and r == "job":
                for sfx in (".sti", ".mas", ".dof") + ((".inp",) if "inp" not in files else ()):
                    if not f.with_suffix(sfx).is_file():
                        raise ctx.error("fe_model.job", f"a job name whose {sfx} file exists "
                                        "(run ccx with *FREQUENCY, SOLVER=MATRIXSTORAGE)",
                                        str(f.with_suffix(sfx)))
            elif not f.is_file():
                raise ctx.error(f"fe_model.{r}", "an existing file", str(f))
        return src

    def reduction(self, red):
        from .reduction.rom import ReductionSpec
        ctx = self.ctx
        if "pairs" in red:
            raise ctx.error("reduction.pairs", "no [[reduction.pairs]]: contact pairs are "
                            "[[contacts]] tables with node sets a, b and a normal")
        _unknown(ctx, red, {"interface", "active", "fixed_interface_modes", "cache",
                            "interface_modes", "cyclic", "axis", "origin"}, "reduction")
        iface = self.names(red, "interface", "reduction.interface", required=True)
        active = self.names(red, "active", "reduction.active", required=False)
        n_cb = _num(ctx, red, "fixed_interface_modes", "reduction.fixed_interface_modes",
                    integer=True, minimum=0)
        cache = self.file(red, "cache", "reduction.cache") if "cache" in red else \
            self.path.with_suffix(".rom.h5")
        im = _table(ctx, red, "reduction.interface_modes", required=False)
        pre = "reduction.interface_modes"
        method = _str(ctx, im, "method", f"{pre}.method", default="none",
                      choices=("none", "gsi", "ms"))
        allowed = {"none": {"method"}, "gsi": {"method", "free", "stick", "per_side"},
                   "ms": {"method", "sectors", "engine_orders", "time_harmonics", "axis",
                          "origin"}}[method]
        _unknown(ctx, im, allowed, pre)
        kw = {}
        if method == "gsi":
            kw["free"] = _num(ctx, im, "free", f"{pre}.free", default=0, integer=True,
                              minimum=0)
            kw["stick"] = _num(ctx, im, "stick", f"{pre}.stick", default=0, integer=True,
                               minimum=0)
            if kw["free"] + kw["stick"] == 0:
                raise ctx.error(f"{pre}.free", "free + stick >= 1 GSI modes")
            kw["per_side"] = _bool(ctx, im, "per_side", f"{pre}.per_side", False)
        axis = self.vector(red, "axis", "reduction.axis", (0.0, 0.0, 1.0))
        origin = self.vector(red, "origin", "reduction.origin", (0.0, 0.0, 0.0),
                             nonzero=False)
        kw["axis"], kw["origin"] = axis, origin
        if "cyclic" in red:
            if method == "ms":
                raise ctx.error(f"{pre}.method", "'none' or 'gsi' with [reduction.cyclic] "
                                "(multi-stage modes are for whole 360-degree stages)", method)
            cyc = self.cyclic_table(_table(ctx, red, "reduction.cyclic"))
            kw["sectors"] = cyc["sectors"]
            kw["cyclic"] = (cyc["left"], cyc["right"])
            self.cyc = cyc
        if method == "ms":
            kw["sectors"] = _num(ctx, im, "sectors", f"{pre}.sectors", required=True,
                                 integer=True, minimum=1)
            kw["engine_orders"] = self.ints(im, "engine_orders", f"{pre}.engine_orders",
                                            required=True)
            th = self.ints(im, "time_harmonics", f"{pre}.time_harmonics", minimum=0)
            kw["time_harmonics"] = th or (1,)
            kw["axis"] = self.vector(im, "axis", f"{pre}.axis", axis)
            kw["origin"] = self.vector(im, "origin", f"{pre}.origin", origin, nonzero=False)
        return ReductionSpec(interface=tuple(iface), active=tuple(active),
                             fixed_interface_modes=n_cb, method=method, cache=cache, **kw)

    def cyclic_table(self, cy):
        """The checked [reduction.cyclic] table (a dict)."""
        ctx, pre = self.ctx, "reduction.cyclic"
        _unknown(ctx, cy, {"sectors", "left", "right", "dependent", "engine_order",
                           "boundary_modes", "modes", "harmonic_index", "tol"}, pre)
        n = _num(ctx, cy, "sectors", f"{pre}.sectors", required=True, integer=True, minimum=2)
        out = {"sectors": n}
        for side in ("left", "right"):
            v = _str(ctx, cy, side, f"{pre}.{side}", required=True)
            if not v:
                raise ctx.error(f"{pre}.{side}", "a node-set name", v)
            out[side] = v
        if out["left"].upper() == out["right"].upper():
            raise ctx.error(f"{pre}.right", "a node set other than reduction.cyclic.left",
                            out["right"])
        out["dependent"] = _str(ctx, cy, "dependent", f"{pre}.dependent", default="right",
                                choices=("right", "left"))
        out["engine_order"] = _num(ctx, cy, "engine_order", f"{pre}.engine_order",
                                   required=True, integer=True)
        out["boundary_modes"] = _num(ctx, cy, "boundary_modes", f"{pre}.boundary_modes",
                                     integer=True, minimum=1)
        out["modes"] = _num(ctx, cy, "modes", f"{pre}.modes", integer=True, minimum=1)
        out["tol"] = _num(ctx, cy, "tol", f"{pre}.tol", positive=True)
        hi = cy.get("harmonic_index", "per_harmonic")
        expected = (f"\"per_harmonic\" or an integer nodal diameter k* in 0..{n - 1} (the "
                    "one-index approximation)")
        if isinstance(hi, str):
            if hi.lower() != "per_harmonic":
                raise ctx.error(f"{pre}.harmonic_index", expected, hi)
            out["single_index"] = None
        elif isinstance(hi, int) and not isinstance(hi, bool) and 0 <= hi < n:
            out["single_index"] = hi
        else:
            raise ctx.error(f"{pre}.harmonic_index", expected, hi)
        return out

    def cyclic_sector(self, rom, spec, contacts):
        """The CyclicSector on the reduced coordinates; checks the node-set contacts."""
        from .reduction.cyclic import cyclic_sector
        cy, pre = self.cyc, "reduction.cyclic"
        L = rom.node_sets[cy["left"].upper()]
        R = rom.node_sets[cy["right"].upper()]
        try:
            cs = cyclic_sector(rom.coordinates(L), rom.node_dofs(L), rom.coordinates(R),
                               rom.node_dofs(R), cy["sectors"], rom.K.shape[0],
                               origin=spec.origin, axis=spec.axis, tol=cy["tol"],
                               nodes_left=L, nodes_right=R, dependent=cy["dependent"])
        except InputError as exc:
            raise InputError(f"{self.path}: {pre}.left/right: {exc} (axis {spec.axis} through "
                             f"{spec.origin}: reduction.axis, reduction.origin)") from None
        # a contact on both images of a boundary node would count it twice in the rotor
        partner = {int(a): int(b) for a, b in cs.node_pairs}
        self.partner = partner
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
                    f"{self.path}: {c.key}: node {both[0]} (left boundary) and node "
                    f"{partner[both[0]]} (its image on the right boundary) are the same "
                    "node of the rotor: the contact would act on it twice; keep one of them "
                    "in the contact's node sets")
        return cs

    def cyclic_modes(self, cs, rom, damping, H, log):
        """Modes of every nodal diameter the harmonics 0..H live on (after the cache)."""
        from .model import Damping
        from .reduction.cyclic import needed_indices, sector_modes
        cy, pre = self.cyc, "reduction.cyclic"
        N, eo, sign = cy["sectors"], cy["engine_order"], -1
        ks = needed_indices(eo, N, H, sign, cy["single_index"])
        damp = (Damping.rayleigh(damping["alpha"], damping["beta"])
                if damping["type"] == "rayleigh" else Damping.modal(damping["zeta"]))
        t0 = time.perf_counter()
        modes = {}
        for k in ks:
            try:
                modes[k] = sector_modes(cs, rom.K, rom.M, k, damp, cy["modes"],
                                        cy["boundary_modes"])
            except InputError as exc:
                msg = str(exc)
                key = ("boundary_modes" if "tran_reduce" in msg else
                       "modes" if "n_modes" in msg else "sectors")
                if "rigid-body" in msg:
                    msg = (f"nodal diameter {k} has a rigid-body (zero-frequency) mode: the "
                           "sector's modes are those without contacts, so it needs supports "
                           "(constrained DoFs in the FE model) at every nodal diameter")
                raise InputError(f"{self.path}: {pre}.{key}: {msg}") from None
        dt = time.perf_counter() - t0
        n_i = cs.independent.size
        nm = {k: m.omega.size for k, m in modes.items()}
        how = ("one-index approximation, harmonic_index = " + str(ks[0])
               if cy["single_index"] is not None else
               f"k_h = -h EO mod N for h = 0..{H}, EO = {eo}")
        nds = ", ".join(str(min(k, N - k)) for k in modes)
        log(f"cyclic sector: N = {N}, harmonic indices k = {list(modes)} (nodal diameters "
            f"{nds}; {how}); "
            f"{len(modes)} Hermitian eigen-solve(s) of {n_i} coordinates"
            + (f" (Tran: {cy['boundary_modes']} boundary modes)" if cy["boundary_modes"]
               else "") + f", {max(nm.values())} modes each, in {dt:.2f} s")
        return {"sector": cs, "modes": modes, "engine_order": eo,
                "single_index": cy["single_index"], "sign": sign, "seconds": dt}

    def names(self, d, name, key, required):
        v = d.get(name)
        if v is None and not required:
            return []
        if isinstance(v, str):
            v = [v]
        if not isinstance(v, list) or not v or not all(isinstance(s, str) and s for s in v):
            raise self.ctx.error(key, "a node-set name or a non-empty list of names", v)
        return v

    def ints(self, d, name, key, required=False, minimum=None):
        v = d.get(name)
        if v is None and not required:
            return ()
        if (not isinstance(v, list) or not v
                or any(isinstance(x, bool) or not isinstance(x, int) for x in v)
                or (minimum is not None and min(v) < minimum)):
            what = "integers" if minimum is None else f"integers >= {minimum}"
            raise self.ctx.error(key, f"a non-empty list of {what}", v)
        return tuple(v)

    def vector(self, d, name, key, default=None, nonzero=True):
        v = d.get(name, default)
        if (not isinstance(v, (list, tuple)) or len(v) != 3
                or any(isinstance(x, bool) or not isinstance(x, (int, float))
                       or not math.isfinite(x) for x in v)
                or (nonzero and not any(v))):
            raise self.ctx.error(key, "a list of 3 finite numbers"
                                 + (", not all zero" if nonzero else ""), v)
        return tuple(float(x) for x in v)

    # ---- damping, excitation ----
    def damping(self, damp, M):
        ctx, n = self.ctx, self.n
        dtype = _str(ctx, damp, "type", "damping.type", required=True,
                     choices=("rayleigh", "modal", "matrix"))
        if dtype == "rayleigh":
            _unknown(ctx, damp, {"type", "alpha", "beta"}, "damping")
            return {"type": "rayleigh",
                    "alpha": float(_num(ctx, damp, "alpha", "damping.alpha", default=0.0,
                                        nonneg=True)),
                    "beta": float(_num(ctx, damp, "beta", "damping.beta", default=0.0,
                                       nonneg=True)), "all": False}
        if dtype == "modal":
            _unknown(ctx, damp, {"type", "zeta"}, "damping")
            z = damp.get("zeta")
            if isinstance(z, (int, float)) and not isinstance(z, bool):
                zeta = _num(ctx, damp, "zeta", "damping.zeta", nonneg=True)
                if zeta >= 1:
                    raise ctx.error("damping.zeta", "a damping ratio in [0, 1)", zeta)
                return {"type": "modal", "zeta": np.array([float(zeta)]), "all": True}
            if isinstance(z, list) and z:
                zeta = np.array([_num(ctx, {"z": zi}, "z", f"damping.zeta[{i}]", nonneg=True)
                                 for i, zi in enumerate(z)], float)
                if np.any(zeta >= 1):
                    i = int(np.argmax(zeta >= 1))
                    raise ctx.error(f"damping.zeta[{i}]", "a damping ratio in [0, 1)", z[i])
                if n is not None and zeta.size > n:
                    raise ctx.error("damping.zeta", f"at most {n} modal ratios", zeta.size)
                return {"type": "modal", "zeta": zeta, "all": False}
            raise ctx.error("damping.zeta", "a damping ratio or a list of ratios "
                            "(one per mode, lowest first)", z)
        _unknown(ctx, damp, {"type", "file"}, "damping")
        if self.fe:
            raise ctx.error("damping.type", "'rayleigh' or 'modal' with [fe_model] (a damping "
                            "matrix file needs [model])", dtype)
        C = read_matrix(self.file(damp, "file", "damping.file"), "mtx", "damping.file",
                        self.path)
        if C.shape != M.shape:
            raise ctx.error("damping.file", f"a matrix of shape {M.shape}", C.shape)
        return {"type": "matrix", "C": C, "all": False}

    def excitation(self, exc, H):
        """[(DoF reference, harmonic, complex amplitude, key)] of every load."""
        ctx = self.ctx
        _unknown(ctx, exc, {"load", "engine_order"}, "excitation")
        out = []
        loads = exc.get("load", [])
        if not isinstance(loads, list):
            raise ctx.error("excitation.load", "an array of tables [[excitation.load]]", loads)
        for i, ld in enumerate(loads):
            key = f"excitation.load[{i}]"
            if not isinstance(ld, dict):
                raise ctx.error(key, "a table", ld)
            _unknown(ctx, ld, {"dof", "harmonic", "amplitude", "phase"}, key)
            if "dof" not in ld:
                raise ctx.error(f"{key}.dof", "a DoF (missing)")
            d = self.dof(ld["dof"], f"{key}.dof")
            h = _num(ctx, ld, "harmonic", f"{key}.harmonic", default=1, integer=True,
                     minimum=0)
            if h > H:
                raise ctx.error(f"{key}.harmonic", f"a harmonic in 0..solver.harmonics={H}", h)
            amp = _num(ctx, ld, "amplitude", f"{key}.amplitude", required=True)
            ph = _num(ctx, ld, "phase", f"{key}.phase", default=0.0)
            if h == 0 and ph not in (0, 0.0):
                raise ctx.error(f"{key}.phase", "0 for a static load (harmonic 0)", ph)
            out.append((d, h, amp * np.exp(1j * np.deg2rad(ph)), f"{key}.dof"))
        eos = exc.get("engine_order", [])
        if isinstance(eos, dict):
            eos = [eos]
        if eos and self.cyc is not None:
            raise ctx.error("excitation.engine_order", "no [[excitation.engine_order]] with "
                            "[reduction.cyclic]: give sector 0's loads in "
                            "[[excitation.load]]; reduction.cyclic.engine_order makes them a "
                            "travelling wave")
        if not isinstance(eos, list):
            raise ctx.error("excitation.engine_order", "an array of tables", eos)
        for i, eo in enumerate(eos):
            key = f"excitation.engine_order[{i}]"
            if not isinstance(eo, dict):
                raise ctx.error(key, "a table", eo)
            _unknown(ctx, eo, {"eo", "dofs", "n_sectors", "amplitude", "phase", "harmonic"},
                     key)
            order = _num(ctx, eo, "eo", f"{key}.eo", required=True, integer=True)
            dofs = eo.get("dofs")
            if not isinstance(dofs, list) or not dofs:
                raise ctx.error(f"{key}.dofs", "a non-empty list: one DoF (or list of DoFs) "
                                "per sector", dofs)
            ns = _num(ctx, eo, "n_sectors", f"{key}.n_sectors", default=len(dofs),
                      integer=True, minimum=1)
            h = _num(ctx, eo, "harmonic", f"{key}.harmonic", default=1, integer=True,
                     minimum=1)
            if h > H:
                raise ctx.error(f"{key}.harmonic", f"a harmonic in 1..solver.harmonics={H}", h)
            amp = _num(ctx, eo, "amplitude", f"{key}.amplitude", required=True)
            ph = _num(ctx, eo, "phase", f"{key}.phase", default=0.0)
            a0 = amp * np.exp(1j * np.deg2rad(ph))
            for s, ds in enumerate(dofs):
                phase = np.exp(-2j * np.pi * order * s / ns)     # as engine_order_loads
                items = ds if isinstance(ds, list) else [ds]
                for j, v in enumerate(items):
                    k = f"{key}.dofs[{s}]" + (f"[{j}]" if isinstance(ds, list) else "")
                    out.append((self.dof(v, k), h, a0 * phase, k))
        return out

    def add_load(self, F, ref, h, amp, key):
        """Add a load to F (n, H+1); with [fe_model] a node set loads each of its nodes."""
        if not self.fe:
            F[ref, h] += amp
            return
        nodes = self.fe_nodes(ref, key)
        if self.partner:
            both = sorted(a for a in nodes if self.partner.get(a) in nodes)
            if both:
                raise self.ctx.error(key, "a node set holding each node of the rotor once; "
                                     f"node {both[0]} (left cyclic boundary) and node "
                                     f"{self.partner[both[0]]} (its image on the right one) "
                                     "would both be loaded", ref[2])
        try:
            for node in nodes:
                F[:, h] += amp * self.rom.load_row(node, ref[1])
        except InputError as exc:
            raise InputError(f"{self.path}: {key}: {exc}") from None

    def coordinate(self, ref, key):
        """Model coordinate of an output DoF (a kept physical DoF of a reduced model)."""
        if not self.fe:
            return ref
        node, d = self.fe_node(ref, key)
        lab = f"N{node}:{('UX', 'UY', 'UZ', 'ROTX', 'ROTY', 'ROTZ')[d - 1]}"
        if lab not in self.rom.labels:
            raise self.ctx.error(key, "a DoF kept by the reduction (a node of "
                                 "reduction.active, or of reduction.interface without "
                                 "interface modes)", ref[2])
        return self.rom.labels.index(lab)

    def fe_nodes(self, ref, key):
        """Node ids of a parsed "NODE:DIR" reference (a node, or every node of a set)."""
        node, _, text = ref
        if not isinstance(node, str):
            return [node]
        ids = self.rom.node_sets.get(node.upper())
        if ids is None:
            raise self.ctx.error(key, "a node id or a node set name (known sets: "
                                 + ", ".join(sorted(self.rom.node_sets)) + ")", text)
        return [int(i) for i in ids]

    def fe_node(self, ref, key):
        """(node id, direction) of a reference that must name one node."""
        nodes = self.fe_nodes(ref, key)
        if len(nodes) != 1:
            raise self.ctx.error(key, f"one node (set {ref[0]} has {len(nodes)})", ref[2])
        return nodes[0], ref[1]

    def dof(self, v, key):
        """A DoF reference: with [model] the 0-based index (int) or the label; with
        [fe_model] (node id or one-node set name, direction number, text) from "NODE:DIR"."""
        if self.fe:
            if isinstance(v, str) and v.count(":") == 1:
                node, d = (s.strip() for s in v.split(":"))
                dn = _DIR_NUMBERS.get(d.lower())
                if node.upper().startswith("N") and node[1:].isdigit():
                    node = node[1:]
                if dn is not None and node:
                    return (int(node) if node.isdigit() else node, dn, v)
            raise self.ctx.error(key, "a DoF \"NODE:DIR\": a node id or node set name, "
                                 "and x, y, z (or UX..ROTZ, 1..6)", v)
        n_dof, labels = self.n, self.labels
        if isinstance(v, bool):
            raise self.ctx.error(key, "a DoF index (integer) or label (string)", v)
        if isinstance(v, int):
            if not 0 <= v < n_dof:
                raise self.ctx.error(key, f"a DoF index in 0..{n_dof - 1}", v)
            return v
        if isinstance(v, str):
            if labels is None:
                raise self.ctx.error(key, "a DoF index (labels need model.dof_labels)", v)
            try:
                return labels.index(v)
            except ValueError:
                raise self.ctx.error(key, "a DoF label listed in model.dof_labels", v) from None
        raise self.ctx.error(key, "a DoF index (integer) or label (string)", v)

    def file(self, d, name, key) -> Path:
        v = d.get(name)
        if not isinstance(v, str) or not v:
            raise self.ctx.error(key, "a file name (relative to the deck's folder)", v)
        p = Path(v)
        return p if p.is_absolute() else self.base / p

    def contact(self, c, key):
        ctx = self.ctx
        if not isinstance(c, dict):
            raise ctx.error(key, "a table [[contacts]]", c)
        law = _str(ctx, c, "law", f"{key}.law", required=True, choices=tuple(LAW_PARAMS))
        if self.fe:
            return self.node_set_contact(c, key, law)
        dirs, pnames, nsl = LAW_PARAMS[law]
        n, labels = self.n, self.labels
        ndir = len(dirs)
        _unknown(ctx, c, {"name", "law", "elements", "directions", "w0"} | set(pnames), key)
        name = _str(ctx, c, "name", f"{key}.name", default=key)
        els = c.get("elements")
        if not isinstance(els, list) or not els:
            raise ctx.error(f"{key}.elements", "a non-empty list of {a = ..., b = ...} "
                            "tables", els)
        ne = len(els)
        # local frame: directions (ndir vectors, node-DoF length) shared or per element
        dv = c.get("directions")
        rows, cols, vals = [], [], []
        for e, el in enumerate(els):
            ek = f"{key}.elements[{e}]"
            if not isinstance(el, dict):
                raise ctx.error(ek, "a table {a = [DoFs], b = [DoFs] | \"ground\"}", el)
            _unknown(ctx, el, {"a", "b", "directions"}, ek)
            a = self.node(el.get("a"), f"{ek}.a", n, labels, allow_ground=False)
            b = self.node(el.get("b", "ground"), f"{ek}.b", n, labels, allow_ground=True)
            if b is not None and len(b) != len(a):
                raise ctx.error(f"{ek}.b", f"{len(a)} DoFs like {ek}.a, or \"ground\"", b)
            if b is not None and set(a) & set(b):
                raise ctx.error(f"{ek}.b", f"DoFs different from {ek}.a", b)
            frame = el.get("directions", dv)
            fk = f"{ek}.directions" if "directions" in el else f"{key}.directions"
            if frame is None:
                if len(a) == ndir:
                    frame = np.eye(ndir).tolist()
                else:
                    raise ctx.error(f"{key}.directions", f"{ndir} direction vectors "
                                    f"({', '.join(dirs)}) of length {len(a)} (node DoFs)")
            D = self.frame(frame, fk, ndir, len(a), dirs)
            for d in range(ndir):
                for j in range(len(a)):
                    if D[d, j] != 0.0:
                        rows.append(e * ndir + d)
                        cols.append(a[j])
                        vals.append(D[d, j])
                        if b is not None:
                            rows.append(e * ndir + d)
                            cols.append(b[j])
                            vals.append(-D[d, j])
        G = sp.csr_matrix((vals, (rows, cols)), shape=(ne * ndir, n))
        params, w0 = self.law_parameters(c, key, law, ne)
        return ContactSpec(name=name, law=law, G=G, params=params, w0=w0)

    def law_parameters(self, c, key, law, ne):
        """(params (ne, n_par), w0 (ne, n_slider) or None) of a contact table."""
        _, pnames, nsl = LAW_PARAMS[law]
        params = np.empty((ne, len(pnames)))
        for j, p in enumerate(pnames):
            params[:, j] = self.per_element(c, p, f"{key}.{p}", ne, required=True,
                                            nonneg=p in _NONNEGATIVE)
        if law in ("jenkins", "normal1d", "normal2d") and np.any(params[:, 0] <= 0):
            raise self.ctx.error(f"{key}.kt", "a positive tangential stiffness (N/m)")
        if law in ("normal1d", "normal2d") and np.any(params[:, 1] <= 0):
            raise self.ctx.error(f"{key}.kn", "a positive normal stiffness (N/m)")
        w0 = None
        if "w0" in c:
            if nsl == 0:
                raise self.ctx.error(f"{key}.w0", f"no initial slider for law {law!r} "
                                     "(it has none)")
            w0 = np.repeat(self.per_element(c, "w0", f"{key}.w0", ne)[:, None], nsl, axis=1)
        return params, w0

    def node_set_contact(self, c, key, law):
        """A [[contacts]] table of a reduced model: node sets a, b, a normal."""
        ctx = self.ctx
        _, pnames, _ = LAW_PARAMS[law]
        _unknown(ctx, c, {"name", "law", "a", "b", "b_sector", "normal", "tangent", "tol",
                          "w0"} | set(pnames), key)
        name = _str(ctx, c, "name", f"{key}.name", default=f"contacts{key[9:-1]}")
        a = _str(ctx, c, "a", f"{key}.a", required=True)
        b = _str(ctx, c, "b", f"{key}.b", default="ground")
        b = None if b.lower() == "ground" else b
        bs = _num(ctx, c, "b_sector", f"{key}.b_sector", default=0, integer=True)
        if bs not in (0, 1):
            raise ctx.error(f"{key}.b_sector", "0 (side b in sector 0) or 1 (side b in the "
                            "next sector)", bs)
        if bs == 1 and self.cyc is None:
            raise ctx.error(f"{key}.b_sector", "0 without [reduction.cyclic] (a contact with "
                            "the next sector needs a cyclic sector)", bs)
        if bs == 1 and b is None:
            raise ctx.error(f"{key}.b", "a node set of the next sector with b_sector = 1, "
                            "not the ground", "ground")
        normal = c.get("normal")
        if isinstance(normal, str):
            normal = _str(ctx, c, "normal", f"{key}.normal",
                          choices=("axial", "radial", "tangential"))
        else:
            normal = self.vector(c, "normal", f"{key}.normal")
        tangent = self.vector(c, "tangent", f"{key}.tangent") if "tangent" in c else None
        tol = _num(ctx, c, "tol", f"{key}.tol", positive=True)
        for p in [*pnames, "w0"]:
            if isinstance(c.get(p), list):
                raise ctx.error(f"{key}.{p}", "a number (the same for every pair of the "
                                "node sets)", c[p])
        params, w0 = self.law_parameters(c, key, law, 1)
        stick = (params[0, 0], params[0, 1] if law in ("normal1d", "normal2d") else 0.0)
        return _NodeSetContact(name=name, law=law, a=a, b=b, normal=normal, tangent=tangent,
                               tol=tol, params=params[0], w0=None if w0 is None else w0[0],
                               stick=tuple(float(x) for x in stick), key=key,
                               b_sector=bs)

    def reduced_contact(self, c, rom) -> ContactSpec:
        """ContactSpec of a node-set contact: its physical pairs mapped by the reduction."""
        G = rom.contact_matrix(c.name)
        ne = rom.pairs[c.name].n_elem
        return ContactSpec(name=c.name, law=c.law, G=G, params=np.tile(c.params, (ne, 1)),
                           w0=None if c.w0 is None else np.tile(c.w0, (ne, 1)))

    def node(self, v, key, n, labels, allow_ground):
        if v is None:
            raise self.ctx.error(key, "a DoF or list of DoFs (missing)")
        if isinstance(v, str) and v.lower() == "ground":
            if allow_ground:
                return None
            raise self.ctx.error(key, "DoFs (only side b may be \"ground\")", v)
        items = v if isinstance(v, list) else [v]
        if not items:
            raise self.ctx.error(key, "a non-empty list of DoFs", v)
        return [self.dof(x, f"{key}[{i}]" if isinstance(v, list) else key)
                for i, x in enumerate(items)]

    def frame(self, frame, key, ndir, nd, dirs):
        if not isinstance(frame, list) or len(frame) != ndir:
            raise self.ctx.error(key, f"{ndir} direction vectors ({', '.join(dirs)})", frame)
        D = np.empty((ndir, nd))
        for d, vec in enumerate(frame):
            if (not isinstance(vec, list) or len(vec) != nd
                    or any(isinstance(x, bool) or not isinstance(x, (int, float))
                           for x in vec)):
                raise self.ctx.error(f"{key}[{d}]", f"a list of {nd} numbers (one per node "
                                     "DoF)", vec)
            D[d] = vec
            nrm = np.linalg.norm(D[d])
            if not np.isfinite(nrm) or nrm == 0.0:
                raise self.ctx.error(f"{key}[{d}]", "a non-zero finite vector", vec)
            D[d] /= nrm
        return D

    def per_element(self, c, p, key, ne, required=False, nonneg=False):
        if p not in c:
            if required:
                raise self.ctx.error(key, f"a number or a list of {ne} numbers (missing)")
            return np.zeros(ne)
        v = c[p]
        vals = v if isinstance(v, list) else [v] * ne
        if len(vals) != ne:
            raise self.ctx.error(key, f"a number or a list of {ne} numbers (one per element)",
                                 v)
        out = np.empty(ne)
        for i, x in enumerate(vals):
            k = f"{key}[{i}]" if isinstance(v, list) else key
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                raise self.ctx.error(k, "a finite number", x)
            if nonneg and x < 0:
                raise self.ctx.error(k, "a number >= 0", x)
            out[i] = x
        return out


def load_deck(path) -> Deck:
    """Read and check a deck file; raises :class:`frirom.InputError` on any bad field."""
    return _Parser(Path(path)).run()
