"""Reduced models of FE matrices: Craig-Bampton + interface reduction, cached in HDF5.

The deck (frirom.deck, docs/deck.md) parses ``[fe_model]``, ``[reduction]`` and the
node-set contacts into a :class:`FESource`, a :class:`ReductionSpec` and
:class:`PairSpec` s; :func:`build_reduced_model` turns them into a :class:`ReducedModel`
(K, M, the map T back to the FE DoFs, the physical contact pairs). The model is saved under a
key made of its content: the matrix files' bytes, the reduction settings, the contact
geometry and the version of frirom's reduction code (:func:`rom_key`), in a cache shared
by every deck (:func:`cache_file`), and read back (without even parsing the FE files) while
none of them changes: decks that differ in friction coefficients, preloads, excitation,
damping, harmonics or frequencies share one reduced model, whatever their names. Contact
stiffnesses enter the key only when full-stick interface modes are asked for.

A cyclic sector (``ReductionSpec.cyclic``: the left and right boundary node sets) keeps
its boundary DoFs as Craig-Bampton masters (physical coordinates of the reduced model,
never reduced by interface modes) and stores their nodes' coordinates, so that the deck
can match the boundaries (:func:`frirom.reduction.cyclic.cyclic_sector`) and compute the
modes of every nodal diameter after the cache. A contact with ``PairSpec.b_sector = 1``
joins sector 0's set ``a`` to set ``b`` of the next sector (matched after rotating ``b`` by
+2 pi / N about the axis); its G has the two blocks of :class:`frirom.model.CyclicModel`.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import time
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path

import h5py
import numpy as np
import scipy.sparse as sp
from scipy.linalg import block_diag
from scipy.spatial import cKDTree

from .. import io as fio
from .._errors import InputError
from .._h5check import seal, verify
from ..io import DIRECTION_NAMES
from .cb import craig_bampton
from .cyclic import axis_rotation
from .contact_basis import enrich_from_specs
from .interface import ContactPairs, contact_matrix, gsi_basis, local_frames, reduce_interface
from .multistage import harmonic_indices, ms_basis, radial_line_segments

__all__ = ["FESource", "PairSpec", "ReductionSpec", "ReducedModel", "build_reduced_model",
           "read_fe_model", "pairs_from_node_sets", "rom_key", "cache_file", "FORMATS"]

#: format -> (file roles, required roles); see docs/deck.md, [fe_model]
FORMATS = {
    "calculix": (("job", "inp"), ("job",)),
    "mtx": (("stiffness", "mass", "dofs", "inp"), ("stiffness", "mass")),
    "abaqus": (("stiffness", "mass", "dofs", "inp"), ("stiffness", "mass")),
    "hbmat": (("stiffness", "mass", "mapping", "inp"), ("stiffness", "mass")),
    "op4": (("file", "dofs", "inp"), ("file",)),
}
CACHE_VERSION = 3
#: Environment variable naming the folder of the shared reduced-model cache (default: a
#: folder .frirom_cache beside the FE files).
CACHE_ENV = "FRIROM_CACHE"
#: Interface modes without Craig-Bampton condense the interface from the whole FE model:
#: refused above this many (FE DoFs x interface DoFs); the lap joint's 6 720 x 630 takes
#: minutes (issue 13's parser "hang").
GUYAN_WORK_MAX = 2_000_000


@dataclass(frozen=True)
class FESource:
    """Where the FE matrices come from: format, files by role (absolute paths), and the
    format's options (abaqus ``layout``, op4 ``stiffness_name``/``mass_name``)."""

    format: str
    files: dict
    options: dict = field(default_factory=dict)

    def paths(self) -> list:
        """Every file the model is read from (those that exist), for the fingerprint."""
        f = dict(self.files)
        if self.format == "calculix":
            job = f.pop("job")
            f.update({s: job.with_suffix(s) for s in (".sti", ".mas", ".dof")})
            f.setdefault("inp", job.with_suffix(".inp"))
        return [Path(p) for _, p in sorted(f.items()) if p is not None]


@dataclass(frozen=True)
class PairSpec:
    """A set of contact pairs between two node sets (``b`` None: ground).

    normal: a 3-vector or 'axial' / 'radial' / 'tangential'; tangent: optional 3-vector for
    the first tangential direction; n_dir: local directions kept (3: t1, t2, n; 2: t1, n;
    1: t1); kt, kn: stick stiffness [N/m] (full-stick modes); tol: matching distance [m]
    (default 1e-6 of the model size); key: the deck key path used in error messages;
    b_sector: 0 (side b in sector 0) or 1 (side b in the next sector of a cyclic sector,
    ``ReductionSpec.sectors`` and ``axis``/``origin`` give the rotation).
    """

    name: str
    a: str
    b: str | None
    normal: object
    n_dir: int
    kt: float
    kn: float
    tangent: object = None
    tol: float | None = None
    key: str = ""
    b_sector: int = 0
    mu: float | None = None              # contact-driven basis: friction coefficient and
    n0: float | None = None              # normal load per pair (None: from a [[preload]])


@dataclass(frozen=True)
class ContactDrivenSpec:
    """``[reduction.interface_modes.contact_driven]`` (docs/deck.md): GSI vectors enriched
    by the static responses to unit friction forces of the elements that slip first in the
    stuck mode nearest ``frequency`` [Hz] (frirom.reduction.contact_basis).

    elements: the first that many by slip onset; amplitude: every element slipping below
    this modal amplitude [sqrt(kg) m]; normal: the unit normal forces too; tol: the drop
    tolerance; preloads: ((load, direction, body, contacts), ...) of the deck's [[preload]]
    tables, which give n0 where the contacts do not.
    """

    frequency: float
    elements: int | None = None
    amplitude: float | None = None
    normal: bool = False
    tol: float = 1e-6
    preloads: tuple = ()


@dataclass(frozen=True)
class ReductionSpec:
    """The ``[reduction]`` table, checked (docs/deck.md).

    cyclic: () or (left, right) node-set names of the cyclic boundaries of a sector (extra
    Craig-Bampton masters kept physical); ``sectors`` is then N (also for ``ms``).
    """

    interface: tuple
    active: tuple = ()
    fixed_interface_modes: int | None = None
    method: str = "none"                 # none | gsi | ms
    free: int = 0
    stick: int = 0
    per_side: bool = False
    separate: tuple = ()                 # gsi: interface sets of a joint of their own,
    separate_stick: int = 0              # reduced by that many stick modes (0: physical)
    sectors: int | None = None
    engine_orders: tuple = ()
    time_harmonics: tuple = (1,)
    harmonic_indices: tuple = ()         # ms: explicit indices (else the EO family)
    travelling_wave: bool = False        # ms: solve only the travelling wave's pairs (not
                                         # a reduction setting: not in rom_key)
    axis: tuple = (0.0, 0.0, 1.0)
    origin: tuple = (0.0, 0.0, 0.0)
    cache: Path | None = None
    cyclic: tuple = ()
    contact_driven: ContactDrivenSpec | None = None


def read_fe_model(src: FESource):
    """The FEModel of a :class:`FESource` (through the readers of frirom.io)."""
    f, o = src.files, src.options
    if src.format == "calculix":
        model = fio.read_calculix(f["job"], inp=f.get("inp"))
    elif src.format == "mtx":
        model = fio.read_matrix_market(f["stiffness"], f["mass"], f.get("dofs"))
    elif src.format == "abaqus":
        model = fio.read_abaqus(f["stiffness"], f["mass"], fmt=o.get("layout", "auto"),
                                dofs=f.get("dofs"), inp=f.get("inp"))
    elif src.format == "hbmat":
        model = fio.read_hbmat(f["stiffness"], f["mass"], f.get("mapping"))
    else:
        model = fio.read_op4(f["file"], o.get("stiffness_name", "KAA"),
                             o.get("mass_name", "MAA"), f.get("dofs"))
    if src.format in ("mtx", "hbmat", "op4") and f.get("inp") is not None:
        # node coordinates and node sets from a *NODE / *NSET file (these formats have none)
        model.node_ids, model.coords, model.node_sets, _ = fio.read_inp(f["inp"])
        model.source.append(str(f["inp"]))
    if model.M is None:
        raise InputError(f"{src.paths()[0]}: no mass matrix (the reduction needs M)")
    return model


def _node_dofs(model, nodes):
    """(n, 3) matrix indices of the x y z DoFs of node ids (-1 where constrained)."""
    key = {(int(a), int(b)): i for i, (a, b) in enumerate(model.dofs)}
    return np.array([[key.get((int(nd), c), -1) for c in (1, 2, 3)] for nd in nodes],
                    dtype=np.int64)


def pairs_from_node_sets(model, set_a: str, set_b: str | None, normal, kt: float, kn: float,
                         n_dir: int = 3, tol: float | None = None,
                         axis=(0.0, 0.0, 1.0), origin=(0.0, 0.0, 0.0),
                         tangent=None, b_rotation=None) -> ContactPairs:
    """Contact pairs between the nodes of two node sets at the same position (or ground).

    normal: a 3-vector, or 'axial' / 'radial' / 'tangential' (about ``axis`` through
    ``origin``); tangent: optional 3-vector for t1 (projected on the contact plane); the
    local frame is (t1, t2, n) from :func:`local_frames`, of which n_dir = 3 keeps
    (t1, t2, n), 2 keeps (t1, n) and 1 keeps t1. Stick stiffness (kt[, kt], kn).
    b_rotation: (3, 3) rotation about ``origin`` applied to set b's coordinates before the
    matching (side b in the next sector of a cyclic rotor); dofs_b stay those of set b.
    """
    na = model.node_set(set_a)
    xa = model.coordinates(na)
    da = _node_dofs(model, na)
    if np.any(da < 0):
        bad = na[np.any(da < 0, axis=1)]
        raise InputError(f"node set {set_a}: node(s) {bad[:5].tolist()} are constrained; "
                         "contact nodes need their x y z DoFs")
    if set_b is None:
        db = -np.ones_like(da)
    else:
        nb = model.node_set(set_b)
        xb = model.coordinates(nb)
        if b_rotation is not None:
            o = np.asarray(origin, float)
            xb = (xb - o) @ np.asarray(b_rotation, float).T + o
        scale = max(np.abs(xa).max(), np.abs(xb).max(), 1e-300)
        tol = 1e-6 * scale if tol is None else tol
        dist, j = cKDTree(xb).query(xa)
        far = np.nonzero(dist > tol)[0]
        if far.size:
            nxt = " (in the next sector)" if b_rotation is not None else ""
            raise InputError(f"node {na[far[0]]} of set {set_a} has no node of set {set_b}"
                             f"{nxt} within {tol:.3g} (nearest {dist[far[0]]:.3g})")
        if np.unique(j).size != j.size:
            raise InputError(f"nodes of set {set_a} share a node of set {set_b}: the sets "
                             "must face each other node to node")
        db = _node_dofs(model, nb[j])
        if np.any(db < 0):
            raise InputError(f"node set {set_b}: some nodes are constrained; contact nodes "
                             "need their x y z DoFs")
    tang = None if tangent is None else np.tile(np.asarray(tangent, float), (len(na), 1))
    if isinstance(normal, str):
        a = np.asarray(axis, float) / np.linalg.norm(axis)
        rel = xa - np.asarray(origin, float)
        radial = rel - np.outer(rel @ a, a)
        nvec = {"axial": np.tile(a, (len(na), 1)), "radial": radial,
                "tangential": np.cross(a, radial)}.get(normal)
        if nvec is None:
            raise InputError(f"normal {normal!r}: expected a 3-vector, 'axial', 'radial' "
                             "or 'tangential'")
        if tang is None:
            tang = np.tile(a, (len(na), 1)) if normal != "axial" else np.cross(a, radial)
    else:
        nvec = np.tile(np.asarray(normal, float), (len(na), 1))
    fr = local_frames(nvec, tang)
    keep = {3: [0, 1, 2], 2: [0, 2], 1: [0]}.get(n_dir)
    if keep is None:
        raise InputError(f"n_dir must be 1, 2 or 3, got {n_dir}")
    k = np.array([kt, kt, kn])[keep]
    return ContactPairs(da, db, fr[:, keep, :], np.tile(k, (len(na), 1)))


# --------------------------------------------------------------------------------------------
# the reduced model
# --------------------------------------------------------------------------------------------

@dataclass
class ReducedModel:
    """Reduced matrices with their way back to the FE model.

    K, M: (n_r, n_r), dense, or CSR for large models without CB; labels: one per reduced
    coordinate ('N12:UX' for a kept physical DoF, 'gsi 3', 'ms h=2 c ...', 'cb mode 5');
    T: (n_fe, n_r) map x_fe = T q (CB and interface reduction composed; dense with CB,
    sparse without); pairs: {name: ContactPairs on the FE DoFs}; fe_dofs: (n_fe, 2) (node,
    direction) of the FE DoFs; node_sets: {NAME: node ids}; from_cache: True when read back
    from the cache file; build_seconds: time the reduction took when it was built;
    node_ids, node_xyz: (n,) ids and (n, 3) coordinates of the nodes of the interface,
    active and cyclic-boundary node sets; b_rotation: {pair-set name: (3, 3) rotation Q} of
    the pair sets whose side b is in the next sector.
    """

    K: np.ndarray
    M: np.ndarray
    T: np.ndarray
    labels: list
    pairs: dict = field(default_factory=dict)
    fe_dofs: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    node_sets: dict = field(default_factory=dict)
    from_cache: bool = False
    build_seconds: float = 0.0
    node_ids: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    node_xyz: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    b_rotation: dict = field(default_factory=dict)
    #: sha256 of the inputs it was built from (the cache key), kept in result files
    fingerprint: str = ""

    @property
    def n_fe(self) -> int:
        return self.T.shape[0]

    def contact_matrix(self, name: str) -> sp.csr_matrix:
        """G of a pair set on the reduced coordinates, (n_elem*n_dir, n_r).

        For a pair set whose side b is in the next sector (``b_rotation``), G is
        (n_elem*n_dir, 2 n_r): [frame A T, -frame Q B T], the second block acting on the
        next sector's coordinates in its own frame (Q rotates them into sector 0's).
        """
        if name not in self.pairs:
            raise InputError(f"no contact pair set {name!r}; known: {sorted(self.pairs)}")
        p = self.pairs[name]
        if name not in self.b_rotation:
            g = sp.csr_matrix(contact_matrix(p, self.n_fe) @ self.T)
            g.eliminate_zeros()
            return g
        Q = np.asarray(self.b_rotation[name], float)
        ground = -np.ones_like(p.dofs_a)
        ga = contact_matrix(ContactPairs(p.dofs_a, ground, p.frames, p.stiffness), self.n_fe)
        gb = contact_matrix(ContactPairs(p.dofs_b, ground, p.frames @ Q, p.stiffness),
                            self.n_fe)
        g = sp.hstack([sp.csr_matrix(ga @ self.T), -sp.csr_matrix(gb @ self.T)]).tocsr()
        g.eliminate_zeros()
        return g

    def coordinates(self, nodes) -> np.ndarray:
        """(n, 3) coordinates of stored nodes (those of the reduction's node sets)."""
        nodes = np.asarray(nodes, np.int64).ravel()
        order = np.argsort(self.node_ids)
        pos = np.searchsorted(self.node_ids, nodes, sorter=order)
        pos = np.minimum(pos, max(len(order) - 1, 0))
        if len(order) == 0 or np.any(self.node_ids[order[pos]] != nodes):
            raise InputError("no stored coordinates for some nodes (only the nodes of the "
                             "interface, active and cyclic-boundary sets are kept)")
        return self.node_xyz[order[pos]]

    def node_dofs(self, nodes) -> np.ndarray:
        """(n, 3) reduced coordinates of the x y z DoFs of nodes kept physical ('N12:UX'),
        -1 where the DoF is absent (constrained in the FE model)."""
        pos = {lab: i for i, lab in enumerate(self.labels)}
        xyz = [DIRECTION_NAMES[d] for d in (1, 2, 3)]
        return np.array([[pos.get(f"N{int(nd)}:{d}", -1) for d in xyz]
                         for nd in np.asarray(nodes).ravel()], dtype=np.int64).reshape(-1, 3)

    def fe_index(self, node: int, direction: int) -> int:
        """Row of the FE DoF (node, direction) in T; InputError if absent/constrained."""
        hit = np.nonzero((self.fe_dofs[:, 0] == node) & (self.fe_dofs[:, 1] == direction))[0]
        if hit.size == 0:
            name = DIRECTION_NAMES.get(direction, direction)
            raise InputError(f"node {node} has no DoF {name} in the FE matrices "
                             "(unknown node or constrained DoF)")
        return int(hit[0])

    def dof_index(self, label: str) -> int:
        """Reduced coordinate of a kept physical DoF label ('N12:UX')."""
        try:
            return self.labels.index(label)
        except ValueError:
            raise InputError(f"DoF {label!r} is not a reduced coordinate (only active and "
                             "non-reduced master DoFs are)") from None

    def load_row(self, node: int, direction: int) -> np.ndarray:
        """Reduced load (n_r,) of a unit force on FE DoF (node, direction): row of T."""
        row = self.T[self.fe_index(node, direction)]
        return np.asarray(row.toarray()).ravel() if sp.issparse(row) else np.asarray(row)

    def expand(self, q) -> np.ndarray:
        return self.T @ np.asarray(q)

    def save(self, path, fingerprint: str) -> None:
        """Write to a temporary file, then rename it: decks run in parallel that build the
        same model never leave a half-written entry."""
        path = Path(path)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        try:
            self._write(tmp, fingerprint)
            os.replace(tmp, path)
        finally:
            tmp.unlink(missing_ok=True)

    def _write(self, path, fingerprint: str) -> None:
        with h5py.File(path, "w") as h:
            h.attrs["fingerprint"] = fingerprint
            h.attrs["version"] = CACHE_VERSION
            h.attrs["build_seconds"] = self.build_seconds
            for k in ("K", "M", "T"):
                a = getattr(self, k)
                if sp.issparse(a):
                    a = sp.csr_matrix(a)
                    g = h.create_group(k)
                    g.attrs["shape"] = a.shape
                    for part in ("data", "indices", "indptr"):
                        g.create_dataset(part, data=getattr(a, part))
                else:
                    h.create_dataset(k, data=a)
            h.create_dataset("labels", data=np.array(self.labels, dtype="S"))
            h.create_dataset("fe_dofs", data=self.fe_dofs)
            h.create_dataset("node_ids", data=self.node_ids)
            h.create_dataset("node_xyz", data=self.node_xyz)
            for name, nodes in self.node_sets.items():
                h.create_dataset(f"node_sets/{name}", data=nodes)
            for name, p in self.pairs.items():
                g = h.create_group(f"pairs/{name}")
                for k in ("dofs_a", "dofs_b", "frames", "stiffness"):
                    g.create_dataset(k, data=getattr(p, k))
                if name in self.b_rotation:
                    g.create_dataset("b_rotation", data=self.b_rotation[name])
            seal(h)         # the content checksum, checked by load

    @classmethod
    def load(cls, path, fingerprint: str, why: list | None = None):
        """The cached model, or None if absent, unreadable, built from other inputs, or
        not as it was written: its content checksum (frirom._h5check) differs or is
        missing, or it holds a non-finite number. ``why`` (a list) gets the reason an
        existing entry is not used."""
        def no(reason):
            if why is not None:
                why.append(reason)
            return None
        if not Path(path).is_file():
            return None
        try:
            with h5py.File(path, "r") as h:
                if (h.attrs.get("fingerprint") != fingerprint
                        or h.attrs.get("version") != CACHE_VERSION):
                    return None         # other inputs: rebuilt as usual, no warning
                if not verify(h, path):
                    return no("it has no content checksum")
                pairs, rot = {}, {}
                for name in h.get("pairs", {}):
                    g = h[f"pairs/{name}"]
                    pairs[name] = ContactPairs(g["dofs_a"][()], g["dofs_b"][()],
                                               g["frames"][()], g["stiffness"][()])
                    if "b_rotation" in g:
                        rot[name] = g["b_rotation"][()]
                sets = {k: v[()] for k, v in h.get("node_sets", {}).items()}
                K, M, T = (_read_matrix(h[k]) for k in ("K", "M", "T"))
                for k, a in (("K", K), ("M", M), ("T", T)):
                    if not np.all(np.isfinite(a.data if sp.issparse(a) else a)):
                        return no(f"its {k} holds a non-finite number")
                return cls(K=K, M=M, T=T,
                           labels=[s.decode() for s in h["labels"][()]], pairs=pairs,
                           fe_dofs=h["fe_dofs"][()], node_sets=sets, from_cache=True,
                           build_seconds=float(h.attrs.get("build_seconds", 0.0)),
                           node_ids=h["node_ids"][()], node_xyz=h["node_xyz"][()],
                           b_rotation=rot, fingerprint=fingerprint)
        except InputError as exc:
            return no(str(exc).split(": ", 1)[-1])
        except (OSError, KeyError, ValueError, TypeError, AttributeError) as exc:
            return no(f"unreadable ({type(exc).__name__}: {exc})")


def _label(model, i):
    nd, d = model.dofs[i]
    return f"N{nd}:{DIRECTION_NAMES.get(int(d), d)}"


@functools.lru_cache(maxsize=1)
def _code_version() -> str:
    """sha256 of frirom's version and reduction code (the sources of frirom.reduction and
    of the FE readers frirom.io): any change to them invalidates every cached model."""
    from .. import __version__
    h = hashlib.sha256(f"frirom-{__version__}-rom-{CACHE_VERSION}".encode())
    here = Path(__file__).resolve().parent
    for folder in (here, here.parent / "io"):
        for f in sorted(folder.glob("*.py")):
            h.update(f.name.encode())
            h.update(f.read_bytes())
    return h.hexdigest()


def rom_key(source: FESource, spec: ReductionSpec, pairs: list) -> str:
    """The content key of a reduced model: sha256 of the FE files' bytes (by role, not by
    name), the reduction settings, the pair geometry (plus the stick stiffness when
    full-stick modes are asked for) and the reduction code's version. The deck's name and
    the cache location do not enter."""
    h = hashlib.sha256(f"{_code_version()}-{source.format}".encode())
    for i, f in enumerate(source.paths()):
        if not f.is_file():
            continue
        h.update(f"file {i} {f.suffix}".encode())
        with open(f, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 22), b""):
                h.update(chunk)
    h.update(json.dumps([source.options, *_key_settings(spec, pairs)], sort_keys=True,
                        default=str).encode())
    return h.hexdigest()


def _key_settings(spec: ReductionSpec, pairs: list) -> tuple:
    """The reduction settings and pair geometry that enter :func:`rom_key`."""
    cfg = {k: v for k, v in asdict(spec).items() if k not in ("cache", "travelling_wave")}
    cd = spec.contact_driven is not None
    if not cd:
        del cfg["contact_driven"]
    stick = spec.method == "gsi" and spec.stick + spec.separate_stick > 0 or cd
    pc = [{k: v for k, v in asdict(p).items()
           if k != "key" and (stick or k not in ("kt", "kn"))
           and (cd or k not in ("mu", "n0"))} for p in pairs]
    return cfg, pc


def same_reduction(a: tuple, b: tuple) -> bool:
    """Whether two (source, spec, pairs) give the same reduced model by the FE files'
    names and options and :func:`rom_key`'s settings (no file is read)."""
    def text(source, spec, pairs):
        return json.dumps([source.format, [str(p) for p in source.paths()], source.options,
                           *_key_settings(spec, pairs)], sort_keys=True, default=str)
    return text(*a) == text(*b)


def cache_file(source: FESource, spec: ReductionSpec, key: str) -> Path:
    """Where the reduced model of this key is kept: ``spec.cache`` when it names a file
    (``*.h5``: that file, checked against the key); else the entry ``rom-<key>.h5`` of the
    shared cache folder: ``spec.cache`` when it names a folder, else $FRIROM_CACHE, else
    ``.frirom_cache`` beside the first FE file."""
    if spec.cache is not None and Path(spec.cache).suffix == ".h5":
        return Path(spec.cache)
    if spec.cache is not None:
        folder = Path(spec.cache)
    elif os.environ.get(CACHE_ENV):
        folder = Path(os.environ[CACHE_ENV])
    else:
        paths = source.paths()
        folder = (paths[0].parent if paths else Path.cwd()) / ".frirom_cache"
    return folder / f"rom-{key[:32]}.h5"


def build_reduced_model(source: FESource, spec: ReductionSpec, pairs=(), deck_path="deck",
                        log=None) -> ReducedModel:
    """Build the reduced model, or read it back from ``spec.cache`` when its fingerprint
    matches; a rebuilt model rewrites the cache. ``log(str)`` gets one line saying which.

    Errors name ``deck_path`` and the deck key concerned (``reduction.interface``,
    ``contacts[i]``, ...).
    """
    where = f"{deck_path}: "
    fp = rom_key(source, spec, list(pairs))
    cache = cache_file(source, spec, fp)
    why = []
    cached = ReducedModel.load(cache, fp, why)
    if cached is not None:
        if log:
            log(f"reduced model reused from {cache} ({cached.K.shape[0]} coordinates; "
                f"built in {cached.build_seconds:.1f} s, not recomputed)")
        return cached
    if why:
        msg = f"reduced model cache {cache} not used ({why[0]}): building it again"
        if log:
            log(msg)
        else:
            warnings.warn(msg, RuntimeWarning, stacklevel=2)

    t0 = time.perf_counter()
    model = read_fe_model(source)
    prs, rot = {}, {}
    for p in pairs:
        if p.b_sector:
            if not spec.cyclic or not spec.sectors:
                raise InputError(f"{where}{p.key}.b_sector: a contact with the next sector "
                                 "needs [reduction.cyclic]")
            rot[p.name] = axis_rotation(2 * np.pi / spec.sectors, spec.axis)
        try:
            prs[p.name] = pairs_from_node_sets(model, p.a, p.b, p.normal, p.kt, p.kn, p.n_dir,
                                               p.tol, axis=spec.axis, origin=spec.origin,
                                               tangent=p.tangent, b_rotation=rot.get(p.name))
        except InputError as exc:
            raise InputError(f"{where}{p.key}: {exc}") from None
    try:
        iface_fe = model.dof_indices(list(spec.interface))
        act_fe = (model.dof_indices(list(spec.active)) if spec.active
                  else np.zeros(0, np.int64))
    except InputError as exc:
        raise InputError(f"{where}reduction.interface/active: {exc}") from None
    cyc_fe = np.zeros(0, np.int64)
    for side, name in zip(("left", "right"), spec.cyclic):
        if name.upper() not in model.node_sets:
            raise InputError(f"{where}reduction.cyclic.{side}: expected a node set of the "
                             f"model, got {name!r} (known: {sorted(model.node_sets)})")
        # constrained boundary nodes (no DoF in the matrices) are allowed: zero on both sides
        cyc_fe = np.union1d(cyc_fe, model.dof_indices(name, missing="ignore"))
    if spec.cyclic and spec.method == "gsi":
        bnodes = np.union1d(*(model.node_sets[s.upper()] for s in spec.cyclic))
        for s in spec.interface:
            shared = np.intersect1d(model.node_sets[s.upper()], bnodes)
            if shared.size:
                raise InputError(f"{where}reduction.interface: node set {s} shares node(s) "
                                 f"{shared[:5].tolist()} with the cyclic boundaries "
                                 "(reduction.cyclic.left/right), whose DoFs must stay "
                                 "physical: with GSI interface modes, take the boundary "
                                 "nodes out of the interface sets (or use method = 'none')")
    keep_fe = np.setdiff1d(cyc_fe, iface_fe)       # boundary DoFs kept physical
    for name, p in prs.items():
        # contact nodes: interface nodes, or cyclic-boundary nodes (physical coordinates)
        off = np.setdiff1d(p.dofs, np.union1d(iface_fe, cyc_fe))
        key = [q.key for q in pairs if q.name == name][0]
        if off.size:
            nd = model.dofs[off[0], 0]
            raise InputError(f"{where}{key}: node {nd} is not in the node sets of "
                             "reduction.interface (contact nodes must be interface nodes"
                             + (" or nodes of the cyclic boundaries)" if spec.cyclic else ")"))
        on_b = np.intersect1d(p.dofs, keep_fe)
        if on_b.size and spec.method == "gsi" and spec.stick:
            raise InputError(f"{where}{key}: node {model.dofs[on_b[0], 0]} is a cyclic-"
                             "boundary node outside the interface sets: full-stick GSI modes "
                             "need every contact node in reduction.interface (use free modes, "
                             "or leave the boundary nodes out of the contact)")
    n_fe = model.n_dof
    # Craig-Bampton on the interface + active node sets
    if spec.fixed_interface_modes is not None:
        try:
            cb = craig_bampton(model, spec.fixed_interface_modes, interface=list(spec.interface),
                               active=list(spec.active) or None,
                               masters=cyc_fe if cyc_fe.size else None)
        except InputError as exc:
            raise InputError(f"{where}reduction.fixed_interface_modes: {exc}") from None
        K0, M0 = cb.K, cb.M
        pos = -np.ones(n_fe, dtype=np.int64)
        pos[cb.master_index] = np.arange(cb.n_masters)
        T0 = np.zeros((n_fe, K0.shape[0]))
        T0[cb.master_index, np.arange(cb.n_masters)] = 1.0
        T0[np.ix_(cb.slave_index, np.arange(cb.n_masters))] = cb.psi
        T0[np.ix_(cb.slave_index, cb.n_masters + np.arange(cb.n_modes))] = cb.phi
        labels0 = [_label(model, i) for i in cb.master_index] + \
            [f"cb mode {j + 1}" for j in range(cb.n_modes)]
    else:
        K0, M0 = model.K, model.M
        pos = np.arange(n_fe)
        T0 = None
        labels0 = [_label(model, i) for i in range(n_fe)]
    iface0, act0 = pos[iface_fe], np.union1d(pos[act_fe], pos[keep_fe])

    def to0(p):
        return ContactPairs(pos[p.dofs_a], np.where(p.dofs_b >= 0, pos[np.maximum(p.dofs_b, 0)],
                                                    -1), p.frames, p.stiffness)

    pairs0 = {k: to0(v) for k, v in prs.items()}
    pre = f"{where}reduction.interface_modes"
    if spec.method != "none" and T0 is None and n_fe * iface0.size > GUYAN_WORK_MAX:
        raise InputError(f"{where}reduction.fixed_interface_modes: expected a number of "
                         f"Craig-Bampton modes (e.g. 20) with interface_modes.method = "
                         f"'{spec.method}' on a model of {n_fe} DoFs: without them the "
                         f"{iface0.size} interface DoFs are condensed from the whole FE model "
                         f"({iface0.size} sparse solves of size {n_fe}: minutes or more)")
    if spec.method == "none":
        basis = None
    elif spec.method == "gsi":
        key = "stick" if spec.stick else "separate_stick"
        if (spec.stick or spec.separate_stick) and not pairs0:
            raise InputError(f"{pre}.{key}: full-stick modes need contacts on node sets "
                             "([[contacts]] with a and b)")
        allp = None
        if (spec.stick or spec.separate_stick) and rot:
            raise InputError(f"{pre}.{key}: full-stick modes with contacts to the next "
                             "sector (b_sector = 1) are not implemented; use free modes")
        if (spec.stick or spec.separate_stick) and pairs0 and not rot:
            if len({p.n_dir for p in pairs0.values()}) > 1:
                raise InputError(f"{pre}.stick: all contacts must have the same number of "
                                 "local directions for the full-stick modes")
            allp = ContactPairs(*(np.vstack([getattr(p, k) for p in pairs0.values()])
                                  for k in ("dofs_a", "dofs_b", "frames", "stiffness")))
        # a joint of its own (spec.separate): masters of the CC eigenproblem beside the
        # active ones, not in the span of the GSI modes of the rest; kept physical, or
        # reduced by its own full-stick modes (below)
        phys = (pos[model.dof_indices(list(spec.separate))] if spec.separate
                else np.zeros(0, np.int64))
        iface_r, act_r = np.setdiff1d(iface0, phys), np.union1d(act0, phys)
        groups = None
        if spec.per_side and pairs0:
            side_a = np.isin(iface_r, np.concatenate([p.dofs_a.ravel()
                                                      for p in pairs0.values()]))
            groups = [g for g in (np.nonzero(side_a)[0], np.nonzero(~side_a)[0]) if g.size]
        try:
            basis, _ = gsi_basis(K0, M0, iface_r, act_r, allp, spec.free, spec.stick,
                                 groups=groups)
        except InputError as exc:
            raise InputError(f"{pre}: {exc}") from None
        mode_labels = [f"gsi {j + 1}" for j in range(basis.shape[1])]
        if spec.separate_stick and phys.size:
            # the separate joint's own full-stick GSI modes (every contact tied), the
            # other interface DoFs now among the CC masters
            try:
                sep, _ = gsi_basis(K0, M0, phys, np.union1d(act0, iface_r), allp, 0,
                                   spec.separate_stick)
            except InputError as exc:
                raise InputError(f"{pre}.separate_stick: {exc}") from None
            basis, iface_r = block_diag(basis, sep), np.concatenate([iface_r, phys])
            mode_labels += [f"gsi separate {j + 1}" for j in range(sep.shape[1])]
        if spec.contact_driven is not None:
            if spec.separate or rot:
                raise InputError(f"{pre}.contact_driven: not with separate joints nor with "
                                 "contacts to the next sector (b_sector = 1)")
            basis, n_cd = enrich_from_specs(K0, M0, iface_r, act_r, pairs, pairs0, prs,
                                          basis, groups, spec.contact_driven, f"{pre}", log)
            mode_labels += [f"contact-driven {j + 1}" for j in range(n_cd)]
    else:
        # one MS basis per interface node set (a stage's face): the radial line segments
        # of one call over two coincident faces would mix the stages' nodes
        bases, ifaces, mode_labels, seen = [], [], [], set()
        for name in spec.interface:
            nodes = np.unique(np.asarray(model.node_sets[name.upper()], np.int64))
            if seen & set(nodes.tolist()):
                raise InputError(f"{where}reduction.interface: node set {name} shares nodes "
                                 "with another interface set; the MS reduction needs one "
                                 "set per stage face")
            seen |= set(nodes.tolist())
            nd = _node_dofs(model, nodes)
            if np.any(nd < 0):
                bad = nodes[np.any(nd < 0, axis=1)]
                raise InputError(f"{where}reduction.interface: expected nodes with free x y z "
                                 f"DoFs for the MS reduction, got constrained node(s) "
                                 f"{bad[:5].tolist()}")
            try:
                xyz = model.coordinates(nodes)
                nz = radial_line_segments(xyz, spec.sectors, spec.origin,
                                          spec.axis).n_segments
                idx = spec.harmonic_indices or harmonic_indices(
                    list(spec.engine_orders), spec.sectors, nz, list(spec.time_harmonics))
                ms = ms_basis(xyz, pos[nd], spec.sectors, idx, spec.origin, spec.axis)
            except InputError as exc:
                raise InputError(f"{pre} (interface set {name}): {exc}") from None
            bases.append(ms.basis)
            ifaces.append(ms.interface)
            mode_labels += ms.labels(f"{name} " if len(spec.interface) > 1 else "")
        basis, iface_r = block_diag(*bases), np.concatenate(ifaces)
        if iface_r.size != iface0.size:
            raise InputError(f"{where}reduction.interface: expected node sets whose nodes "
                             "all keep x y z DoFs for the MS reduction")
    if basis is None:
        K, M, T1, labels = K0, M0, None, labels0
    else:
        r = reduce_interface(K0, M0, iface_r, basis, labels=labels0, mode_labels=mode_labels)
        K, M, T1, labels = r.K, r.M, r.R, r.labels
    if T0 is None:      # no CB: T stays sparse (identity, or the interface basis)
        T = sp.identity(n_fe, format="csr") if T1 is None else T1.tocsr()
    else:
        T = T0 if T1 is None else np.asarray(T1.T @ T0.T).T
    kept_sets = [*spec.interface, *spec.active, *spec.cyclic]
    kept_nodes = np.unique(np.concatenate([np.asarray(model.node_sets[s.upper()], np.int64)
                                           for s in kept_sets]))
    try:
        kept_xyz = np.asarray(model.coordinates(kept_nodes), float).reshape(-1, 3)
    except InputError:
        if spec.cyclic:
            raise InputError(f"{where}reduction.cyclic: the cyclic boundaries need node "
                             "coordinates (fe_model with an .inp)") from None
        kept_nodes, kept_xyz = np.zeros(0, np.int64), np.zeros((0, 3))
    out = ReducedModel(K=K, M=M, T=T, labels=labels, pairs=prs,
                       fe_dofs=np.asarray(model.dofs, np.int64),
                       node_sets={k: np.asarray(v, np.int64)
                                  for k, v in model.node_sets.items()},
                       build_seconds=time.perf_counter() - t0,
                       node_ids=kept_nodes, node_xyz=kept_xyz, b_rotation=rot,
                       fingerprint=fp)
    try:
        cache.parent.mkdir(parents=True, exist_ok=True)
        out.save(cache, fp)
    except OSError as exc:
        raise InputError(f"{where}reduction.cache: cannot write {cache} ({exc})") from None
    if log:
        log(f"reduced model built in {out.build_seconds:.1f} s: {n_fe} FE DoFs -> "
            f"{K.shape[0]} coordinates; saved to {cache}")
    return out


def _read_matrix(node):
    if isinstance(node, h5py.Group):
        return sp.csr_matrix((node["data"][()], node["indices"][()], node["indptr"][()]),
                             shape=tuple(node.attrs["shape"]))
    return node[()]
