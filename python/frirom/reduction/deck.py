"""The reduction part of a deck: FE matrices -> Craig-Bampton -> interface reduction, cached.

A deck (TOML, see docs/reduction.md) names the FE matrix files with their format in
``[fe_model]`` and the reduction in ``[reduction]``::

    [fe_model]
    format = "calculix"              # calculix | mtx | abaqus | hbmat | op4
    job = "sector"                   # calculix: job name (.sti/.mas/.dof + .inp)

    [reduction]
    interface = ["IFACE_A", "IFACE_B"]   # node sets whose x y z DoFs become masters
    active = ["TIP"]                     # response / excitation node sets (kept physical)
    fixed_interface_modes = 40           # Craig-Bampton modes (0: Guyan); omit: no CB
    cache = "sector.rom.h5"              # default <deck name>.rom.h5

    [reduction.interface_modes]
    method = "gsi"                       # none | gsi | ms
    free = 20                            # gsi: free and full-stick modes (per side)
    stick = 20
    per_side = true                      # gsi: separate modes for side A and side B
    # ms: sectors = 24, engine_orders = [2], time_harmonics = [1, 2, 3],
    #     axis = [0, 0, 1], origin = [0, 0, 0]

    [[reduction.pairs]]                  # contact pairs, matched by coordinates
    name = "flange"
    a = "IFACE_A"
    b = "IFACE_B"                        # or "ground"
    normal = [0.0, 0.0, 1.0]             # or "radial" / "axial" / "tangential"
    kt = 1.0e8                           # N/m, tangential stick stiffness
    kn = 4.0e8                           # N/m, normal stick stiffness
    directions = 3                       # local directions: 1 (t), 2 (t, n), 3 (t1, t2, n)

:func:`build_reduced_model` returns a :class:`ReducedModel` (K, M, the contact map of each
pair set on the reduced coordinates, labels, recovery of the FE DoFs). It is saved to the
cache file together with a fingerprint of the matrix files and of the reduction settings,
and reused while neither changes: editing friction coefficients, preloads, harmonics or
frequencies in the rest of the deck does not recompute it (kt, kn enter the fingerprint
only when full-stick modes are asked for).
"""

from __future__ import annotations

import hashlib
import json
import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from .._errors import InputError
from .interface import ContactPairs, contact_matrix, gsi_basis, local_frames, reduce_interface

__all__ = ["ReducedModel", "build_reduced_model", "read_fe_model", "pairs_from_node_sets",
           "load_reduction_deck"]

FORMATS = ("calculix", "mtx", "abaqus", "hbmat", "op4")
CACHE_VERSION = 1


class _Ctx:
    def __init__(self, path):
        self.path = Path(path)

    def error(self, key, expected, got=None):
        msg = f"{self.path}: {key}: expected {expected}"
        if got is not None:
            s = repr(got)
            msg += f", got {s[:77] + '...' if len(s) > 80 else s}"
        return InputError(msg)

    def keys(self, d, allowed, prefix):
        for k in d:
            if k not in allowed:
                raise self.error(f"{prefix}.{k}", "one of the known keys "
                                 + ", ".join(sorted(allowed)) + " (unknown key)")

    def int(self, d, key, prefix, lo=0, default=None):
        v = d.get(key, default)
        if v is None:
            raise self.error(f"{prefix}.{key}", f"an integer >= {lo}")
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            raise self.error(f"{prefix}.{key}", f"an integer >= {lo}", v)
        return v

    def num(self, d, key, prefix, positive=True):
        v = d.get(key)
        ok = isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v)
        if not ok or (positive and v <= 0):
            raise self.error(f"{prefix}.{key}", "a number > 0" if positive else "a number", v)
        return float(v)

    def sets(self, d, key, prefix, required=True):
        v = d.get(key)
        if v is None and not required:
            return []
        if isinstance(v, str):
            v = [v]
        if not isinstance(v, list) or not v or not all(isinstance(s, str) for s in v):
            raise self.error(f"{prefix}.{key}", "a node-set name or a list of names", v)
        return v

    def vec(self, d, key, prefix, n=3, default=None):
        v = d.get(key, default)
        if (not isinstance(v, list) or len(v) != n
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)):
            raise self.error(f"{prefix}.{key}", f"a list of {n} numbers", v)
        return np.asarray(v, float)

    def file(self, d, key, prefix, base, required=True):
        v = d.get(key)
        if v is None and not required:
            return None
        if not isinstance(v, str) or not v:
            raise self.error(f"{prefix}.{key}", "a file name", v)
        p = Path(v) if os.path.isabs(v) else base / v
        return p


# --------------------------------------------------------------------------------------------
# FE model and contact pairs
# --------------------------------------------------------------------------------------------

def read_fe_model(table: dict, base: Path, ctx: _Ctx | None = None, prefix="fe_model"):
    """FEModel from a ``[fe_model]`` table (files relative to ``base``). Returns (model,
    list of files read)."""
    from .. import io as fio
    ctx = ctx or _Ctx(base / "deck.toml")
    if not isinstance(table, dict):
        raise ctx.error(prefix, "a table", table)
    fmt = table.get("format")
    if fmt not in FORMATS:
        raise ctx.error(f"{prefix}.format", "one of " + ", ".join(FORMATS), fmt)
    allowed = {"calculix": {"format", "job", "inp"},
               "mtx": {"format", "stiffness", "mass", "dofs"},
               "abaqus": {"format", "stiffness", "mass", "dofs", "inp", "layout"},
               "hbmat": {"format", "stiffness", "mass", "mapping"},
               "op4": {"format", "file", "stiffness_name", "mass_name", "dofs"}}[fmt]
    ctx.keys(table, allowed, prefix)
    if fmt == "calculix":
        job = ctx.file(table, "job", prefix, base)
        inp = ctx.file(table, "inp", prefix, base, required=False)
        model = fio.read_calculix(job, inp=inp)
        files = [job.with_suffix(s) for s in (".sti", ".mas", ".dof")]
        files.append(inp if inp is not None else job.with_suffix(".inp"))
    elif fmt == "mtx":
        k, m = ctx.file(table, "stiffness", prefix, base), ctx.file(table, "mass", prefix, base)
        d = ctx.file(table, "dofs", prefix, base, required=False)
        model = fio.read_matrix_market(k, m, d)
        files = [k, m] + ([d] if d else [])
    elif fmt == "abaqus":
        k, m = ctx.file(table, "stiffness", prefix, base), ctx.file(table, "mass", prefix, base)
        d = ctx.file(table, "dofs", prefix, base, required=False)
        inp = ctx.file(table, "inp", prefix, base, required=False)
        layout = table.get("layout", "auto")
        model = fio.read_abaqus(k, m, fmt=layout, dofs=d, inp=inp)
        files = [f for f in (k, m, d, inp) if f is not None]
    elif fmt == "hbmat":
        k, m = ctx.file(table, "stiffness", prefix, base), ctx.file(table, "mass", prefix, base)
        mp = ctx.file(table, "mapping", prefix, base, required=False)
        model = fio.read_hbmat(k, m, mp)
        files = [f for f in (k, m, mp) if f is not None]
    else:
        f = ctx.file(table, "file", prefix, base)
        d = ctx.file(table, "dofs", prefix, base, required=False)
        model = fio.read_op4(f, table.get("stiffness_name", "KAA"),
                             table.get("mass_name", "MAA"), d)
        files = [f] + ([d] if d else [])
    if model.M is None:
        raise ctx.error(f"{prefix}.mass", "a mass matrix (reduction needs M)")
    return model, [Path(f) for f in files if Path(f).exists()]


def _node_dofs(model, nodes):
    """(n, 3) matrix indices of the x y z DoFs of node ids (-1 where constrained)."""
    key = {(int(a), int(b)): i for i, (a, b) in enumerate(model.dofs)}
    return np.array([[key.get((int(nd), c), -1) for c in (1, 2, 3)] for nd in nodes],
                    dtype=np.int64)


def pairs_from_node_sets(model, set_a: str, set_b: str | None, normal, kt: float, kn: float,
                         n_dir: int = 3, tol: float | None = None,
                         axis=(0.0, 0.0, 1.0), origin=(0.0, 0.0, 0.0)) -> ContactPairs:
    """Contact pairs between the nodes of two node sets at the same position (or ground).

    normal: a 3-vector, or 'axial' / 'radial' / 'tangential' (about ``axis`` through
    ``origin``); the local frame is (t1, t2, n) from :func:`local_frames`, of which n_dir
    = 3 keeps (t1, t2, n), 2 keeps (t1, n) and 1 keeps t1. Stick stiffness (kt[, kt], kn).
    """
    na = model.node_sets.get(set_a.upper())
    if na is None:
        raise InputError(f"unknown node set {set_a!r}; the model has {sorted(model.node_sets)}")
    xa = model.coordinates(na)
    da = _node_dofs(model, na)
    if np.any(da < 0):
        bad = na[np.any(da < 0, axis=1)]
        raise InputError(f"node set {set_a}: node(s) {bad[:5].tolist()} are constrained; "
                         "contact nodes need their x y z DoFs")
    if set_b is None:
        db = -np.ones_like(da)
    else:
        nb = model.node_sets.get(set_b.upper())
        if nb is None:
            raise InputError(f"unknown node set {set_b!r}")
        xb = model.coordinates(nb)
        scale = max(np.abs(xa).max(), np.abs(xb).max(), 1e-300)
        tol = 1e-6 * scale if tol is None else tol
        from scipy.spatial import cKDTree
        dist, j = cKDTree(xb).query(xa)
        far = np.nonzero(dist > tol)[0]
        if far.size:
            raise InputError(f"node {na[far[0]]} of set {set_a} has no node of set {set_b} "
                             f"within {tol:.3g} (nearest {dist[far[0]]:.3g})")
        db = _node_dofs(model, nb[j])
    if isinstance(normal, str):
        a = np.asarray(axis, float) / np.linalg.norm(axis)
        rel = xa - np.asarray(origin, float)
        radial = rel - np.outer(rel @ a, a)
        nvec = {"axial": np.tile(a, (len(na), 1)), "radial": radial,
                "tangential": np.cross(a, radial)}.get(normal)
        if nvec is None:
            raise InputError(f"normal {normal!r}: expected a 3-vector, 'axial', 'radial' "
                             "or 'tangential'")
        tang = np.tile(a, (len(na), 1)) if normal != "axial" else np.cross(a, radial)
    else:
        nvec = np.tile(np.asarray(normal, float), (len(na), 1))
        tang = None
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
    pairs: {name: ContactPairs on the FE DoFs}; T: (n_fe, n_r) map x_fe = T q (CB and
    interface reduction composed; dense with CB, sparse without); from_cache: True when
    read back from the cache file.
    """

    K: np.ndarray
    M: np.ndarray
    T: np.ndarray
    labels: list
    pairs: dict = field(default_factory=dict)
    from_cache: bool = False

    def contact_matrix(self, name: str) -> sp.csr_matrix:
        """G of a pair set on the reduced coordinates, (n_elem*n_dir, n_r)."""
        if name not in self.pairs:
            raise InputError(f"no contact pair set {name!r}; known: {sorted(self.pairs)}")
        return sp.csr_matrix(contact_matrix(self.pairs[name], self.T.shape[0]) @ self.T)

    def dof_index(self, label: str) -> int:
        """Reduced coordinate of a kept physical DoF label ('N12:UX')."""
        try:
            return self.labels.index(label)
        except ValueError:
            raise InputError(f"DoF {label!r} is not a reduced coordinate (only active and "
                             "non-reduced master DoFs are)") from None

    def expand(self, q) -> np.ndarray:
        return self.T @ np.asarray(q)

    def save(self, path, fingerprint: str) -> None:
        import h5py
        with h5py.File(path, "w") as h:
            h.attrs["fingerprint"] = fingerprint
            h.attrs["version"] = CACHE_VERSION
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
            for name, p in self.pairs.items():
                g = h.create_group(f"pairs/{name}")
                for k in ("dofs_a", "dofs_b", "frames", "stiffness"):
                    g.create_dataset(k, data=getattr(p, k))

    @classmethod
    def load(cls, path, fingerprint: str):
        """The cached model, or None if absent, unreadable or built from other inputs."""
        import h5py
        try:
            with h5py.File(path, "r") as h:
                if (h.attrs.get("fingerprint") != fingerprint
                        or h.attrs.get("version") != CACHE_VERSION):
                    return None
                pairs = {}
                for name in h.get("pairs", {}):
                    g = h[f"pairs/{name}"]
                    pairs[name] = ContactPairs(g["dofs_a"][()], g["dofs_b"][()],
                                               g["frames"][()], g["stiffness"][()])
                K, M, T = (_read_matrix(h[k]) for k in ("K", "M", "T"))
                return cls(K=K, M=M, T=T,
                           labels=[s.decode() for s in h["labels"][()]], pairs=pairs,
                           from_cache=True)
        except (OSError, KeyError):
            return None


def _label(model, i):
    nd, d = model.dofs[i]
    names = {1: "UX", 2: "UY", 3: "UZ", 4: "ROTX", 5: "ROTY", 6: "ROTZ"}
    return f"N{nd}:{names.get(int(d), d)}"


def _fingerprint(files, red: dict, pairs_cfg: list, use_stiffness: bool) -> str:
    h = hashlib.sha256()
    h.update(f"frirom-rom-{CACHE_VERSION}".encode())
    for f in sorted(files, key=str):
        h.update(str(Path(f).name).encode())
        with open(f, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 22), b""):
                h.update(chunk)
    cfg = {k: v for k, v in red.items() if k not in ("cache", "pairs")}
    pc = [{k: v for k, v in p.items() if use_stiffness or k not in ("kt", "kn")}
          for p in pairs_cfg]
    h.update(json.dumps([cfg, pc], sort_keys=True, default=str).encode())
    return h.hexdigest()


def load_reduction_deck(path):
    """Parse a TOML deck and build (or reuse) its reduced model."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            deck = tomllib.load(fh)
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror})") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML ({exc})") from None
    return build_reduced_model(deck, path)


def build_reduced_model(deck: dict, deck_path, progress=None) -> ReducedModel:
    """Build the reduced model of a parsed deck (``[fe_model]`` + ``[reduction]``).

    deck_path: the deck file (relative file names and the default cache name derive from
    it). The cache is reused when its fingerprint matches; otherwise rebuilt and rewritten.
    """
    from .cb import craig_bampton
    from .multistage import harmonic_indices, ms_basis

    ctx = _Ctx(deck_path)
    base = Path(deck_path).parent
    if "reduction" not in deck or not isinstance(deck["reduction"], dict):
        raise ctx.error("reduction", "a table [reduction]", deck.get("reduction"))
    red = deck["reduction"]
    ctx.keys(red, {"interface", "active", "fixed_interface_modes", "cache", "interface_modes",
                   "pairs"}, "reduction")
    iface_sets = ctx.sets(red, "interface", "reduction")
    active_sets = ctx.sets(red, "active", "reduction", required=False)
    n_cb = red.get("fixed_interface_modes")
    if n_cb is not None:
        n_cb = ctx.int(red, "fixed_interface_modes", "reduction")
    im = red.get("interface_modes", {"method": "none"})
    if not isinstance(im, dict):
        raise ctx.error("reduction.interface_modes", "a table", im)
    method = im.get("method", "none")
    if method not in ("none", "gsi", "ms"):
        raise ctx.error("reduction.interface_modes.method", "'none', 'gsi' or 'ms'", method)
    allowed = {"none": {"method"}, "gsi": {"method", "free", "stick", "per_side"},
               "ms": {"method", "sectors", "engine_orders", "time_harmonics", "axis",
                      "origin"}}[method]
    ctx.keys(im, allowed, "reduction.interface_modes")
    pairs_cfg = red.get("pairs", [])
    if not isinstance(pairs_cfg, list) or not all(isinstance(p, dict) for p in pairs_cfg):
        raise ctx.error("reduction.pairs", "an array of tables [[reduction.pairs]]", pairs_cfg)
    n_stick = ctx.int(im, "stick", "reduction.interface_modes", default=0) \
        if method == "gsi" else 0
    cache = ctx.file(red, "cache", "reduction", base, required=False) or \
        Path(deck_path).with_suffix(".rom.h5")

    model, files = read_fe_model(deck.get("fe_model"), base, ctx)
    fp = _fingerprint(files, red, pairs_cfg, n_stick > 0)
    cached = ReducedModel.load(cache, fp)
    if cached is not None:
        return cached

    # contact pairs on the FE DoFs
    pairs = {}
    for i, p in enumerate(pairs_cfg):
        pre = f"reduction.pairs[{i}]"
        ctx.keys(p, {"name", "a", "b", "normal", "kt", "kn", "directions", "tol"}, pre)
        name = p.get("name", f"pairs{i}")
        if not isinstance(name, str) or name in pairs:
            raise ctx.error(f"{pre}.name", "a unique string", name)
        if not isinstance(p.get("a"), str):
            raise ctx.error(f"{pre}.a", "a node-set name", p.get("a"))
        b = p.get("b", "ground")
        if not isinstance(b, str):
            raise ctx.error(f"{pre}.b", "a node-set name or 'ground'", b)
        normal = p.get("normal")
        if not isinstance(normal, str):
            normal = ctx.vec(p, "normal", pre)
        ndir = ctx.int(p, "directions", pre, lo=1, default=3)
        if ndir > 3:
            raise ctx.error(f"{pre}.directions", "1, 2 or 3", ndir)
        try:
            pairs[name] = pairs_from_node_sets(
                model, p["a"], None if b == "ground" else b, normal, ctx.num(p, "kt", pre),
                ctx.num(p, "kn", pre), ndir, ctx.num(p, "tol", pre) if "tol" in p else None,
                axis=im.get("axis", (0.0, 0.0, 1.0)), origin=im.get("origin", (0, 0, 0)))
        except InputError as exc:
            raise InputError(f"{Path(deck_path)}: {pre}: {exc}") from None

    # Craig-Bampton on the interface + active node sets
    iface_fe = model.dof_indices(iface_sets)
    act_fe = model.dof_indices(active_sets) if active_sets else np.zeros(0, np.int64)
    n_fe = model.n_dof
    if n_cb is not None:
        cb = craig_bampton(model, n_cb, interface=iface_sets, active=active_sets or None)
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
    iface0, act0 = pos[iface_fe], pos[act_fe]

    def to0(p):
        return ContactPairs(pos[p.dofs_a], np.where(p.dofs_b >= 0, pos[np.maximum(p.dofs_b, 0)],
                                                    -1), p.frames, p.stiffness)

    pairs0 = {k: to0(v) for k, v in pairs.items()}
    if method == "none":
        basis, iface_r, mode_labels = None, None, None
    elif method == "gsi":
        pre = "reduction.interface_modes"
        n_free = ctx.int(im, "free", pre, default=0)
        if n_free + n_stick == 0:
            raise ctx.error(f"{pre}.free", "free + stick >= 1", n_free)
        if n_stick and not pairs0:
            raise ctx.error("reduction.pairs", "contact pairs for the full-stick modes")
        allp = None
        if pairs0:
            allp = ContactPairs(np.vstack([p.dofs_a for p in pairs0.values()]),
                                np.vstack([p.dofs_b for p in pairs0.values()]),
                                _pad_frames([p.frames for p in pairs0.values()]),
                                _pad_stiff([p.stiffness for p in pairs0.values()]))
        groups = None
        if im.get("per_side", False) and allp is not None:
            side_a = np.isin(iface0, allp.dofs_a)
            groups = [np.nonzero(side_a)[0], np.nonzero(~side_a)[0]]
            groups = [g for g in groups if g.size]
        try:
            basis, _ = gsi_basis(K0, M0, iface0, act0, allp, n_free, n_stick, groups=groups)
        except InputError as exc:
            raise InputError(f"{Path(deck_path)}: {pre}: {exc}") from None
        iface_r = iface0
        mode_labels = [f"gsi {j + 1}" for j in range(basis.shape[1])]
    else:
        pre = "reduction.interface_modes"
        nsec = ctx.int(im, "sectors", pre, lo=1)
        eos = im.get("engine_orders")
        if not isinstance(eos, list) or not eos or not all(isinstance(e, int) for e in eos):
            raise ctx.error(f"{pre}.engine_orders", "a non-empty list of integers", eos)
        th = im.get("time_harmonics", [1])
        if not isinstance(th, list) or not all(isinstance(e, int) and e >= 0 for e in th):
            raise ctx.error(f"{pre}.time_harmonics", "a list of integers >= 0", th)
        axis = ctx.vec(im, "axis", pre, default=[0.0, 0.0, 1.0])
        origin = ctx.vec(im, "origin", pre, default=[0.0, 0.0, 0.0])
        nodes = np.unique(np.concatenate([model.node_sets[s.upper()] for s in iface_sets]))
        nd = _node_dofs(model, nodes)
        if np.any(nd < 0):
            bad = nodes[np.any(nd < 0, axis=1)]
            raise ctx.error("reduction.interface", "nodes with free x y z DoFs for the MS "
                            "reduction", f"constrained node(s) {bad[:5].tolist()}")
        try:
            from .multistage import radial_line_segments
            nz = radial_line_segments(model.coordinates(nodes), nsec, origin, axis).n_segments
            ms = ms_basis(model.coordinates(nodes), pos[nd], nsec,
                          harmonic_indices(eos, nsec, nz, th), origin, axis)
        except InputError as exc:
            raise InputError(f"{Path(deck_path)}: {pre}: {exc}") from None
        if ms.interface.size != iface0.size:
            raise ctx.error("reduction.interface", "node sets whose nodes all keep x y z DoFs "
                            "for the MS reduction")
        basis, iface_r = ms.basis, ms.interface
        mode_labels = ms.labels()
    if basis is None:
        K, M = K0, M0
        T1 = None
        labels = labels0
    else:
        r = reduce_interface(K0, M0, iface_r, basis, labels=labels0, mode_labels=mode_labels)
        K, M, T1, labels = r.K, r.M, r.R, r.labels
    if T0 is None:      # no CB: T stays sparse (identity, or the interface basis)
        T = sp.identity(n_fe, format="csr") if T1 is None else T1.tocsr()
    else:
        T = T0 if T1 is None else np.asarray(T1.T @ T0.T).T
    out = ReducedModel(K=K, M=M, T=T, labels=labels, pairs=pairs)
    try:
        out.save(cache, fp)
    except OSError as exc:
        raise InputError(f"{Path(deck_path)}: reduction.cache: cannot write {cache} "
                         f"({exc})") from None
    return out


def _read_matrix(node):
    import h5py
    if isinstance(node, h5py.Group):
        return sp.csr_matrix((node["data"][()], node["indices"][()], node["indptr"][()]),
                             shape=tuple(node.attrs["shape"]))
    return node[()]


def _pad_frames(frames):
    nd = max(f.shape[1] for f in frames)
    if any(f.shape[1] != nd for f in frames):
        raise InputError("reduction.pairs: all pair sets must have the same number of "
                         "directions for the full-stick modes")
    return np.vstack(frames)


def _pad_stiff(stiff):
    return np.vstack(stiff)
