"""The deck's build step: settings in, the model's matrices and the solver's objects out.

:func:`build_deck` turns a :class:`frirom.deck.schema.DeckSettings` into a :class:`Deck`:
it reads the matrices of ``[model]`` (or builds or reuses the reduced model of
``[fe_model]``), resolves every DoF reference against them, assembles the contact
matrices G and the load matrix F, and with ``[reduction.cyclic]`` computes the sector's
modes (:mod:`frirom.deck.build_cyclic`). :meth:`Deck.model`, :meth:`Deck.excitation` and
:meth:`Deck.options` then give the solver's objects.
"""

from __future__ import annotations

import dataclasses
import hashlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from .._errors import FriromError, InputError
from ..contact import LAWS
from ..io import DIRECTION_NAMES, read_mtx
from ..io._common import read_text
from ..model import ContactGroup, CyclicModel, Damping, Excitation, Model, check_definite
from ..reduction.contact_basis import preload_n0
from ..reduction.multistage import (cylindrical_frame, travelling_wave_pairs,
                                     travelling_wave_selection)
from ..reduction.rom import (PairSpec, build_reduced_model, cache_file, rom_key,
                             same_reduction)
from ..options import SolverOptions
from .build_cyclic import check_sector_contacts, cyclic_modes, cyclic_sector_of
from .fields import Context, DofRef
from .schema import DeckSettings
from .schema_model import MATRIX_FORMATS


@dataclass
class ContactSpec:
    """One contact group on the model's coordinates (no solver objects).

    name, law : str
        The group's name and law (a key of :data:`frirom.contact.LAWS`).
    G : scipy.sparse.csr_matrix, (n_elem*n_dir, n_dof)
        Row e*n_dir + d: local relative displacement d of element e.
    params : ndarray, (n_elem, n_par)
        Law parameters (SI units).
    w0 : ndarray, (n_elem, n_slider), or None
        Initial slider positions [m].
    patch : float, ndarray (n_tangential,) or None
        The contact patch's extent along the tangents [m] (frirom.held.patch_warnings).
    """

    name: str
    law: str
    G: sp.csr_matrix
    params: np.ndarray
    w0: np.ndarray | None
    patch: object = None


@dataclass
class Deck:
    """A checked and built deck. Frequencies in rad/s; F complex (n_dof, H+1);
    continuation steps are the solver's dimensionless arc-length steps."""

    path: Path
    title: str
    M: sp.csr_matrix
    K: sp.csr_matrix
    damping: dict             # {'type': 'rayleigh', 'alpha':, 'beta':} | modal | matrix
    F: np.ndarray
    contacts: list            # ContactSpec
    harmonics: int
    samples: int | None       # None: the solver's default
    formulation: str
    omega_start: float
    omega_end: float
    frequency_unit: str
    continuation: dict        # the [continuation] keys given
    solver: dict              # the [solver] tolerances given, 'stability', 'history'
    outputs: list             # DoF indices (-1: an FE DoF recovered through output_map)
    output_names: list        # as the deck names them ("ACTIVE:z", "1234:UX", "tip:x")
    dof_labels: list | None = None
    plot: bool = True
    csv: bool = True
    raw: dict = field(default_factory=dict, repr=False)
    reduced: object = None    # frirom.reduction.rom.ReducedModel with [fe_model]
    log: list = field(default_factory=list)   # what the reduction did (built / reused)
    #: with [reduction.cyclic]: {'sector': CyclicSector, 'modes': {k: SectorModes},
    #: 'engine_order', 'single_index' (None or k*), 'sign', 'seconds'}
    cyclic: dict | None = None
    settings: DeckSettings | None = field(default=None, repr=False)
    #: (n_out, n_dof) with [fe_model]: x_out = output_map @ x, the rows of the reduction
    #: basis T of the FE DoFs named in [outputs] (sector 0's with [reduction.cyclic])
    output_map: np.ndarray | None = None
    #: with ``harmonics_kept = "auto"``: the chosen selection (n_dof, H+1) bool (None:
    #: every harmonic), set by frirom.auto.resolve_deck
    kept_auto: np.ndarray | None = field(default=None, repr=False)

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    def fingerprint(self) -> str:
        """sha256 naming the model: the reduced model's cache key with [fe_model], else a
        hash of the M, K (and damping matrix) arrays."""
        if self.reduced is not None and getattr(self.reduced, "fingerprint", ""):
            return self.reduced.fingerprint
        h = hashlib.sha256()
        for A in (self.M, self.K, self.damping.get("C")):
            if A is not None:
                A = sp.csr_matrix(A)
                for part in (A.indptr, A.indices, A.data):
                    h.update(np.ascontiguousarray(part).tobytes())
        return h.hexdigest()

    def result_meta(self) -> dict:
        """What a result file keeps of how it was made (frirom.results.META_KEYS)."""
        import json

        from .. import __version__
        opts = dataclasses.asdict(self.options())
        for key in ("selection", "pairs"):
            if opts[key] is not None:           # the deck key that made it, not the array
                opts[key] = "travelling_wave"
        return {"deck_path": str(self.path.resolve()), "deck_text": self.path.read_text(),
                "solver_settings": json.dumps(opts, sort_keys=True, default=str),
                "model_fingerprint": self.fingerprint(), "frirom_version": __version__}

    @property
    def solver_outputs(self):
        """The solver's ``outputs``: the DoF indices, or output_map when an output is an FE
        DoF the reduction does not keep as a coordinate."""
        if self.output_map is not None and min(self.outputs, default=0) < 0:
            return self.output_map
        return list(self.outputs)

    def damping_object(self) -> Damping:
        """The model's :class:`frirom.model.Damping` from the [damping] table."""
        d = self.damping
        if d["type"] == "rayleigh":
            return Damping.rayleigh(d["alpha"], d["beta"])
        if d["type"] == "modal":
            return Damping.modal(d["zeta"])
        return Damping.matrix(d["C"])

    def model(self):
        """The solver's Model, or its CyclicModel with [reduction.cyclic]."""
        groups = [ContactGroup(law=c.law, G=c.G, params=c.params, w0=c.w0, name=c.name,
                               patch=c.patch) for c in self.contacts]
        if self.cyclic is not None:
            c = self.cyclic
            return CyclicModel(n_dof=self.n_dof, n_sectors=c["sector"].n_sectors,
                               engine_order=c["engine_order"], modes=c["modes"],
                               contacts=groups, sign=c["sign"],
                               single_index=c["single_index"], dof_labels=self.dof_labels,
                               stuck_modes=c.get("free", False))
        return Model(self.M, self.K, self.damping_object(), groups,
                     dof_labels=self.dof_labels)

    def excitation(self) -> Excitation:
        """The solver's Excitation: the loads F (n_dof, H+1) [N]."""
        return Excitation(self.F)

    def travelling_wave_selection(self) -> np.ndarray:
        """``[reduction.interface_modes] travelling_wave = true``: (n_dof, H+1) bool, the
        (coordinate, harmonic) pairs the deck's engine-order travelling wave moves
        (:func:`frirom.reduction.multistage.travelling_wave_selection`)."""
        return travelling_wave_selection(self.dof_labels, self._eo(),
                                         self.settings.reduction.sectors, self.harmonics)

    def travelling_wave_pairs(self) -> np.ndarray:
        """``travelling_wave = true``: (n_dof, H+1) int, the wave's direction on the
        selection (:func:`frirom.reduction.multistage.travelling_wave_pairs`)."""
        return travelling_wave_pairs(self.dof_labels, self._eo(),
                                     self.settings.reduction.sectors, self.harmonics)

    def _eo(self) -> int:
        eos = self.raw["excitation"]["engine_order"]
        return int((eos if isinstance(eos, dict) else eos[0])["eo"])

    def options(self) -> SolverOptions:
        """The solver's SolverOptions from the [solver] and [continuation] tables."""
        kw = {"harmonics": self.harmonics, "samples": self.samples,
              "formulation": self.formulation}
        for key, name in (("tol_residual", "tol_residual"), ("tol_update", "tol_update"),
                          ("max_iterations", "max_iter"), ("stability", "stability"),
                          ("tol_stall", "tol_stall"), ("history", "history"),
                          ("harmonics_kept", "harmonics_kept")):
            if key in self.solver and self.solver[key] != "auto":
                kw[name] = self.solver[key]
        for key, name in (("step", "ds"), ("min_step", "ds_min"), ("max_step", "ds_max"),
                          ("max_points", "max_points")):
            if key in self.continuation:
                kw[name] = self.continuation[key]
        red = self.settings.reduction if self.settings is not None else None
        if red is not None and red.travelling_wave:
            kw["selection"] = self.travelling_wave_selection()
            kw["pairs"] = self.travelling_wave_pairs()
        if self.kept_auto is not None:
            kw["harmonics_kept"] = np.asarray(self.kept_auto, bool)
        opts = SolverOptions(**kw)
        if opts.ds_min > opts.ds_max or not opts.ds_min <= opts.ds <= opts.ds_max:
            # keep the user's steps consistent with the solver's defaults for the others
            lo, hi = min(opts.ds_min, opts.ds), max(opts.ds_max, opts.ds)
            opts.ds_min, opts.ds_max = lo, hi
        return opts


def _node_id(ref) -> int:
    """The node id of a deck DoF reference "NODE:DIR" (fields.dof_ref's rule: digits, or
    N + digits); ValueError for a node set name."""
    node = str(ref).split(":")[0].strip()
    if node[:1].upper() == "N" and node[1:].isdigit():
        node = node[1:]
    if not node.isdigit():
        raise ValueError(f"{ref!r}: a node set, not a node id")
    return int(node)


def check_wave_sectors(ctx: Context, raw: dict, rom, spec) -> None:
    """``travelling_wave = true``: each ``[[excitation.engine_order]]``'s DoFs are one per
    sector, 360 / n_sectors degrees apart about the reduction's axis, every load listed
    in the same direction, as the model's geometry says (nodes without stored coordinates,
    node sets: not checked). A wrong ``n_sectors`` would make a load that is no wave of
    the rotor; a load listed the other way round is the wave running backwards (with the
    others, a standing wave): the selection of ``reduction.interface_modes.sectors`` would
    drop what they move. Raises the field's error."""
    eos = raw.get("excitation", {}).get("engine_order", [])
    frame = cylindrical_frame(spec.axis)
    first = None
    for k, eo in enumerate([eos] if isinstance(eos, dict) else eos):
        ns = int(eo.get("n_sectors", len(eo["dofs"])))
        if ns <= 2:                 # no direction to tell
            continue
        try:
            # the node ids as the deck's DoF references read them (a node set: no check)
            nodes = [_node_id(d[0] if isinstance(d, list) else d) for d in eo["dofs"]]
            xyz = rom.coordinates(nodes) - np.asarray(spec.origin, float)
        except (ValueError, InputError):
            continue
        phi = np.arctan2(xyz @ frame[1], xyz @ frame[0])
        step = np.angle(np.exp(1j * np.diff(phi)))          # wrapped to (-pi, pi]
        pitch = 2 * np.pi / ns
        sense = 1 if np.all(np.abs(step - pitch) < 1e-3 * pitch) else (
            -1 if np.all(np.abs(step + pitch) < 1e-3 * pitch) else 0)
        where = (f"with reduction.interface_modes.travelling_wave = true; its DoFs sit "
                 f"{np.degrees(step).round(3).tolist()} deg apart about the reduction's axis")
        if not sense and np.ptp(step) < 1e-3 * pitch:    # evenly, but not 360/ns
            raise ctx.error(f"excitation.engine_order[{k}].n_sectors", f"the sector count "
                            f"of the rotor, 360 deg / their spacing, {where}", ns)
        if not sense:
            raise ctx.error(f"excitation.engine_order[{k}].dofs", f"one DoF per sector, in "
                            f"order about the axis, 360 / n_sectors = {360 / ns:.6g} deg "
                            f"apart, {where}", None)
        if first is None:
            first, k0 = sense, k
        elif sense and sense != first:
            raise ctx.error(f"excitation.engine_order[{k}].dofs", "sectors listed in the "
                            f"direction of excitation.engine_order[{k0}]'s about the axis "
                            "(listed the other way, the same eo is the wave running "
                            "backwards, and the two a standing wave), with "
                            "reduction.interface_modes.travelling_wave = true", None)


def read_matrix(path: Path, fmt: str, what: str, deck_path: Path | None = None):
    """One matrix file as scipy CSR, as stored; ``fmt`` is one of :data:`MATRIX_FORMATS`.

    ``what`` names the matrix in messages (its deck key); errors in the file name the file
    and the line (:func:`frirom.io.read_mtx`).
    """
    where = f"{deck_path}: " if deck_path else ""
    if fmt != "mtx":
        raise InputError(f"{where}model.format: expected one of {MATRIX_FORMATS}, got {fmt!r}")
    if not path.is_file():
        raise InputError(f"{where}{what}: matrix file {path} does not exist")
    return read_mtx(path, symmetric=False)


class _Builder:
    """The state of one build: the settings, the model so far and how to name DoFs."""

    def __init__(self, s: DeckSettings):
        self.s = s
        self.ctx = Context(s.path)
        self.n = self.labels = self.rom = None
        self.partner = {}         # cyclic: left-boundary node -> its right-boundary image

    def run(self) -> Deck:
        s, ctx = self.s, self.ctx
        H = s.solver.harmonics
        damping = {"type": s.damping.type}
        if s.damping.type == "rayleigh":
            damping.update(alpha=s.damping.alpha, beta=s.damping.beta)
        elif s.damping.type == "modal":
            damping["zeta"] = s.damping.zeta
        rom, log, cyclic = None, [], None
        if not s.fe:
            M, K = self.matrices()
            n = self.n
            if s.damping.type == "matrix":
                damping["C"] = self.damping_matrix(M)
            elif s.damping.type == "modal" and s.damping.zeta.size > n:
                raise ctx.error("damping.zeta", f"at most {n} modal ratios",
                                s.damping.zeta.size)
            contacts = [self.dof_contact(c) for c in s.contacts]
            try:
                check_definite(K, M, f"model.stiffness ({s.model.stiffness.name})",
                               f"model.mass ({s.model.mass.name})", [c.G for c in contacts],
                               labels=self.labels)
            except FriromError as exc:
                raise InputError(f"{s.path}: {exc}") from None
        else:
            # everything checked: build (or reuse) the reduced model, resolve the nodes
            rom = build_reduced_model(s.fe_model, s.reduction, pair_specs(s), s.path,
                                      log=log.append)
            M, K, n = rom.M, rom.K, rom.K.shape[0]
            self.n, self.rom = n, rom
            if s.cyclic is not None:
                sector = cyclic_sector_of(s.path, rom, s.reduction, s.cyclic)
                self.partner = check_sector_contacts(s.path, rom, sector, s.contacts)
            contacts = [self.reduced_contact(c) for c in s.contacts]
            if getattr(s.reduction, "travelling_wave", False):
                check_wave_sectors(ctx, s.raw, rom, s.reduction)
            if s.damping.type == "modal" and s.damping.zeta.size > n:
                raise ctx.error("damping.zeta", f"at most {n} modal ratios (the reduced "
                                "model's size)", s.damping.zeta.size)
        if s.damping.type == "modal" and s.damping.every_mode and s.cyclic is None:
            damping["zeta"] = np.full(n, s.damping.zeta[0])
        F = np.zeros((n, H + 1), complex)
        for ld in s.loads:
            self.add_load(F, ld.dof, ld.harmonic, ld.amplitude)
        for pl in s.preloads:
            log.append(self.add_preload(F, contacts, pl))
        if s.fe:
            log.extend(self.normal_warnings(F, contacts))
        mode_deck = s.analysis is not None and s.analysis.nonlinear_mode
        if not np.any(F[:, 1:]) and not mode_deck:
            raise ctx.error("excitation", "at least one load on a harmonic >= 1 "
                            "([[excitation.load]] or [[excitation.engine_order]])")
        outputs = [self.coordinate(ref) for ref in s.outputs.dofs]
        omap = (np.array([self.output_row(ref) for ref in s.outputs.dofs]) if s.fe
                else None)
        labels = self.labels
        onames = [ref.value.text if s.fe else (labels[j] if labels else f"dof{j}")
                  for ref, j in zip(s.outputs.dofs, outputs)]
        if s.cyclic is not None:
            cyclic = cyclic_modes(s.path, sector, rom, s.cyclic, damping, H, log.append,
                                  contacts)
        sol = s.solver
        solver = {k: getattr(sol, k) for k in ("tol_residual", "tol_update", "max_iterations",
                                               "tol_stall")
                  if getattr(sol, k) is not None}
        solver["stability"] = sol.stability
        solver["history"] = sol.history
        if sol.harmonics_kept is not None:
            solver["harmonics_kept"] = sol.harmonics_kept
        cont = {k: v for k, v in vars(s.continuation).items() if v is not None}
        return Deck(path=s.path, title=s.title, M=M, K=K, damping=damping, F=F,
                    contacts=contacts, harmonics=H, samples=sol.samples,
                    formulation=sol.formulation,
                    omega_start=s.frequency.omega_start if s.frequency else 0.0,
                    omega_end=s.frequency.omega_end if s.frequency else 0.0,
                    frequency_unit=s.frequency.unit if s.frequency else "hz",
                    continuation=cont, solver=solver, outputs=outputs, output_names=onames,
                    dof_labels=labels if not s.fe else list(rom.labels),
                    plot=s.outputs.plot, csv=s.outputs.csv, raw=s.raw, reduced=rom, log=log,
                    cyclic=cyclic, settings=s, output_map=omap)

    # ---- [model]: matrices used as they are ----
    def matrices(self):
        """(M, K) of [model]; sets the model's size and DoF labels."""
        ctx, m, path = self.ctx, self.s.model, self.s.path
        M = read_matrix(m.mass, m.format, "model.mass", path)
        K = read_matrix(m.stiffness, m.format, "model.stiffness", path)
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
        if m.dof_labels is not None:
            lp = m.dof_labels
            if not lp.is_file():
                raise ctx.error("model.dof_labels", "an existing file of DoF labels", str(lp))
            try:
                text = read_text(lp)
            except InputError as exc:
                raise InputError(f"{path}: model.dof_labels: {exc}") from None
            labels = [s.strip() for s in text.splitlines() if s.strip()]
            if len(labels) != n:
                raise ctx.error("model.dof_labels", f"{n} labels (one per line, matrix "
                                f"order) in {lp}", f"{len(labels)} labels")
            if len(set(labels)) != n:
                raise ctx.error("model.dof_labels", f"unique labels in {lp}")
        self.n, self.labels = n, labels
        return M, K

    def damping_matrix(self, M):
        C = read_matrix(self.s.damping.file, "mtx", "damping.file", self.s.path)
        if C.shape != M.shape:
            raise self.ctx.error("damping.file", f"a matrix of shape {M.shape}", C.shape)
        return C

    def index(self, ref: DofRef) -> int:
        """The 0-based DoF index of a [model] reference (an index or a label)."""
        v, key = ref.value, ref.key
        if isinstance(v, int):
            if not 0 <= v < self.n:
                raise self.ctx.error(key, f"a DoF index in 0..{self.n - 1}", v)
            return v
        try:
            return self.labels.index(v)
        except ValueError:
            raise self.ctx.error(key, "a DoF label listed in model.dof_labels", v) from None

    def dof_contact(self, c) -> ContactSpec:
        """ContactSpec of a [model] contact: G from its elements' DoFs and frames."""
        ndir = LAWS[c.law].n_dir
        rows, cols, vals = [], [], []
        for e, el in enumerate(c.elements):
            a = [self.index(r) for r in el.a]
            b = None if el.b is None else [self.index(r) for r in el.b]
            if b is not None and len(b) != len(a):
                raise self.ctx.error(f"{el.key}.b", f"{len(a)} DoFs like {el.key}.a, or "
                                     "\"ground\"", b)
            if b is not None and set(a) & set(b):
                raise self.ctx.error(f"{el.key}.b", f"DoFs different from {el.key}.a", b)
            D = el.frame
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
        G = sp.csr_matrix((vals, (rows, cols)), shape=(len(c.elements) * ndir, self.n))
        return ContactSpec(name=c.name, law=c.law, G=G, params=c.params, w0=c.w0,
                           patch=c.patch)

    # ---- [fe_model]: node sets of the reduced model ----
    def reduced_contact(self, c) -> ContactSpec:
        """ContactSpec of a node-set contact: its physical pairs mapped by the reduction."""
        G = self.rom.contact_matrix(c.name)
        ne = self.rom.pairs[c.name].n_elem
        return ContactSpec(name=c.name, law=c.law, G=G, params=np.tile(c.params, (ne, 1)),
                           w0=None if c.w0 is None else np.tile(c.w0, (ne, 1)),
                           patch=c.patch if c.patch is not None else self._patch(c))

    def _patch(self, c):
        """Side a's node set's extent [m] along each tangent of the pairs' first frame
        (the contact patch as meshed); None where the nodes' coordinates are not kept."""
        try:
            xyz = self.rom.coordinates(self.rom.node_sets[c.a.upper()])
            frame = np.asarray(self.rom.pairs[c.name].frames, float)[0]
        except (InputError, KeyError, IndexError, AttributeError):
            return None
        dirs = LAWS[c.law].directions
        t = frame[[d for d, nm in enumerate(dirs) if nm != "v"]]
        return np.ptp(xyz @ t.T, axis=0)

    def add_preload(self, F, contacts: list, pl) -> str:
        """A ``[[preload]]``: the normal preload n0 of each pair of its contacts and the
        balancing harmonic-0 loads, from the body's load; returns the log line.

        The body (side ``pl.body`` of each contact) is in equilibrium at zero displacement
        under its load P d and the pairs' preloads: on side a a pair pushes with -n0 n
        (v = n . (x_a - x_b) closes the contact), so sum_c n0_c S_c = s P d with S_c the
        sum of contact c's pair normals and s = 1 (body a) or -1 (body b); one n0 per
        contact, the same on each of its pairs (a uniform pressure on each face). Least
        squares over the contacts; where the balance does not fix the shares (parallel
        faces: statically indeterminate) the one of least sum over pairs of n0^2, which
        is the same n0 on every pair (one pressure). Refused when the normals cannot
        carry the load (residual above 1e-6 P: friction would have to hold the body
        statically) and when an n0 comes out negative (that face would be pulled: its
        normal points the wrong way, or the load's).
        The balancing loads, +n0 n on side a and -n0 n on side b of each pair (as in
        docs/deck.md), are G_n^T n0: the static state then has every face closed with
        normal force n0, and those on the body add up to its load.
        """
        ctx = self.ctx
        specs = {c.name: c for c in contacts}
        settings = {c.name: c for c in self.s.contacts}
        S, G_n, j_n0, npairs = [], [], [], []
        for name in pl.contacts:
            c = specs[name]
            frames = self.rom.pairs[name].frames
            S.append(frames[:, -1, :].sum(axis=0))
            npairs.append(frames.shape[0])
            nd = LAWS[c.law].n_dir
            G_n.append(c.G[nd - 1::nd])
            j_n0.append(LAWS[c.law].parameters.index("n0"))
        A = np.array(S).T                                   # (3, n_contacts)
        sign = 1.0 if pl.body == "a" else -1.0
        target = sign * pl.load * np.asarray(pl.direction)
        n0, miss, rank = preload_n0(A, npairs, target)
        if miss > 1e-6 * pl.load:
            raise ctx.error(f"{pl.key}.direction", "a load the contacts' normals can carry "
                            f"({miss:.4g} N of it is along no face normal: friction would "
                            "have to hold the body statically)", list(pl.direction))
        for name, v in zip(pl.contacts, n0):
            if v <= 0:
                c = settings[name]
                raise ctx.error(f"{c.key}.normal", f"a normal along which {pl.key}'s load "
                                f"presses the face closed (it would pull it open, n0 = "
                                f"{v:.4g} N per pair): a normal points from side a towards "
                                "side b (v = n . (x_a - x_b) closes the contact); flip it, "
                                f"or {pl.key}.direction or .body", list(c.normal))
        parts = []
        for name, v, Gn, j in zip(pl.contacts, n0, G_n, j_n0):
            c = specs[name]
            c.params[:, j] = v
            F[:, 0] += np.asarray(Gn.T @ np.full(Gn.shape[0], v)).ravel()
            parts.append(f"{name} n0 = {v:.6g} N x {Gn.shape[0]} pairs")
        return (f"{pl.key}: {pl.load:g} N on side {pl.body} carried by " + ", ".join(parts)
                + " (and the balancing harmonic-0 loads)"
                + ("; statically indeterminate (parallel faces): one pressure on every pair"
                   if rank < len(pl.contacts) else ""))

    def normal_warnings(self, F, contacts: list) -> list:
        """Warnings for node-set contacts whose preload n0 the deck's harmonic-0 loads
        push the wrong way: the loads that balance a preload are G_n^T n0 (+n0 n on side
        a, -n0 n on side b); static loads that project on it with a factor below -1/2
        balance the preload of the opposite normal, i.e. the normal (or the loads) points
        the wrong way. Contacts of a [[preload]] are balanced by construction."""
        derived = {n for p in self.s.preloads for n in p.contacts}
        out = []
        F0 = np.real(F[:, 0])
        for c, st in zip(contacts, self.s.contacts):
            law = LAWS[c.law]
            if c.name in derived or "n0" not in law.parameters or not np.any(F0):
                continue
            n0 = c.params[:, law.parameters.index("n0")]
            if not np.any(n0 > 0):
                continue
            nd = law.n_dir
            b = np.asarray(c.G[nd - 1::nd].T @ np.clip(n0, 0.0, None)).ravel()
            bb = float(b @ b)
            if bb == 0.0:
                continue
            ratio = float(F0 @ b) / bb
            if ratio < -0.5:
                out.append(f"WARNING: {st.key}.normal = {list(st.normal)}: the deck's "
                           f"harmonic-0 loads push against the balance of its preload n0 "
                           f"(they project on +n0 n / -n0 n of sides a / b with factor "
                           f"{ratio:.2f}, -1 for a normal flipped): the normal points from "
                           "side a towards side b (v = n . (x_a - x_b) closes the contact); "
                           "check its sign, or the loads'")
        return out

    def add_load(self, F, ref: DofRef, h: int, amp: complex):
        """Add a load to F (n, H+1); with [fe_model] a node set loads each of its nodes."""
        if not self.s.fe:
            F[self.index(ref), h] += amp
            return
        nodes = self.fe_nodes(ref)
        key, nd = ref.key, ref.value
        if self.partner:
            both = sorted(a for a in nodes if self.partner.get(a) in nodes)
            if both:
                raise self.ctx.error(key, "a node set holding each node of the rotor once; "
                                     f"node {both[0]} (left cyclic boundary) and node "
                                     f"{self.partner[both[0]]} (its image on the right one) "
                                     "would both be loaded", nd.text)
        try:
            for node in nodes:
                F[:, h] += amp * self.rom.load_row(node, nd.direction)
        except InputError as exc:
            raise InputError(f"{self.s.path}: {key}: {exc}") from None

    def coordinate(self, ref: DofRef) -> int:
        """Model coordinate of an output DoF: a [model] DoF, or a physical DoF the
        reduction keeps; -1 for another FE DoF (recovered by :meth:`output_row`)."""
        if not self.s.fe:
            return self.index(ref)
        lab = f"N{self.output_node(ref)}:{DIRECTION_NAMES[ref.value.direction]}"
        return self.rom.labels.index(lab) if lab in self.rom.labels else -1

    def output_node(self, ref: DofRef) -> int:
        """The one FE node of an output reference ("1234:UX", or a set of one node)."""
        nodes = self.fe_nodes(ref)
        if len(nodes) != 1:
            raise self.ctx.error(ref.key, f"one node (set {ref.value.node} has "
                                 f"{len(nodes)})", ref.value.text)
        return nodes[0]

    def output_row(self, ref: DofRef) -> np.ndarray:
        """(n_r,) the row of the reduction basis T of an output FE DoF: x = row @ q."""
        try:
            return self.rom.load_row(self.output_node(ref), ref.value.direction)
        except InputError as exc:
            raise InputError(f"{self.s.path}: {ref.key}: {exc}") from None

    def fe_nodes(self, ref: DofRef) -> list:
        """Node ids of a "NODE:DIR" reference (a node, or every node of a set)."""
        nd = ref.value
        if not isinstance(nd.node, str):
            return [nd.node]
        ids = self.rom.node_sets.get(nd.node.upper())
        if ids is None:
            raise self.ctx.error(ref.key, "a node id or a node set name (known sets: "
                                 + ", ".join(sorted(self.rom.node_sets)) + ")", nd.text)
        return [int(i) for i in ids]


def pair_specs(settings: DeckSettings) -> list:
    """The contact pairs of an ``[fe_model]`` deck as the reduction takes them."""
    return [PairSpec(name=c.name, a=c.a, b=c.b, normal=c.normal, tangent=c.tangent,
                     n_dir=LAWS[c.law].n_dir, kt=c.stick[0], kn=c.stick[1], tol=c.tol,
                     key=c.key, b_sector=c.b_sector, **_slip_data(c))
            for c in settings.contacts]


def _slip_data(c) -> dict:
    """mu and the normal load (n0, or fn0 of 'jenkins'; None when a [[preload]] derives
    it) of a node-set contact, for the contact-driven interface basis; {} for other laws."""
    pn = LAWS[c.law].parameters
    load = "n0" if "n0" in pn else ("fn0" if "fn0" in pn else None)
    if "mu" not in pn or load is None:
        return {}
    n0 = float(c.params[pn.index(load)])
    return {"mu": float(c.params[pn.index("mu")]), "n0": n0 if n0 > 0 else None}


def rom_file(settings: DeckSettings) -> Path | None:
    """Where the reduced model of an ``[fe_model]`` deck is cached (its content key,
    :func:`frirom.reduction.rom.rom_key`), without building it; None with ``[model]``."""
    if settings.fe_model is None:
        return None
    key = rom_key(settings.fe_model, settings.reduction, pair_specs(settings))
    return cache_file(settings.fe_model, settings.reduction, key)


def beside_named_cache(settings: DeckSettings, base: DeckSettings) -> DeckSettings:
    """``settings`` (a study member, an "auto" rung) with its reduced model in the folder of
    the deck's named cache file when its reduction differs from the deck's own (``base``):
    a ``reduction.cache = "*.h5"`` holds the deck's model only, and other reductions get
    their content-keyed entries beside it instead of overwriting it."""
    cache = None if settings.fe_model is None else settings.reduction.cache
    if (cache is None or Path(cache).suffix != ".h5"
            or base.fe_model is not None and same_reduction(
                (settings.fe_model, settings.reduction, pair_specs(settings)),
                (base.fe_model, base.reduction, pair_specs(base)))):
        return settings
    return dataclasses.replace(settings, reduction=dataclasses.replace(
        settings.reduction, cache=Path(cache).parent))


def build_deck(settings: DeckSettings) -> Deck:
    """The matrices, contacts, loads and outputs of checked settings, as a :class:`Deck`."""
    from ..io._common import QUOTE_UNDER
    token = QUOTE_UNDER.set(Path(settings.path).parent)     # no quotes of other files
    try:
        return _Builder(settings).run()
    finally:
        QUOTE_UNDER.reset(token)
