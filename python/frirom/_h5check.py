"""Checks of the HDF5 files frirom reads back that it wrote: reduced-model cache entries
(:mod:`frirom.reduction.rom`) and results files (:mod:`frirom.results`).

Each such file carries ``content_sha256``: the SHA-256 of every dataset (name, type, shape
and bytes) and every other attribute, in name order, computed when the writer closes it.
A reader recomputes it: a mismatch means the file changed after frirom wrote it (damage
or an edit), and the reader rebuilds (a cache entry) or refuses naming the file (results).
What frirom never writes is refused before any value is used: links to other files or
inside the file, storage outside the file, nesting deeper than its own layout, text where
numbers belong. The checksum finds damage, not a forger (who can recompute it): a results
file or cache folder is as trusted as the folder it lives in (docs/security.md).
"""

from __future__ import annotations

import hashlib
import json

import numpy as np

from ._errors import InputError

#: attribute holding the checksum
DIGEST = "content_sha256"
#: deepest group nesting of a file frirom writes (cache: pairs/<name>/<dataset>)
MAX_DEPTH = 3
#: most objects (groups + datasets) a file may hold before it is refused unread
MAX_OBJECTS = 100_000


def _attr_bytes(v) -> bytes:
    """Bytes standing for a value: its type, shape and content."""
    if isinstance(v, str):
        return b"s" + v.encode("utf-8", "surrogatepass")
    if isinstance(v, bytes):
        return b"b" + v
    a = np.asarray(v)
    if a.dtype.kind == "O":
        return b"o" + json.dumps([str(x) for x in a.ravel()]).encode() + str(a.shape).encode()
    return a.dtype.str.encode() + str(a.shape).encode() + a.tobytes()


def content_digest(f, path="file") -> str:
    """SHA-256 (hex) of an open h5py.File's groups, datasets and attributes in name order,
    the root's DIGEST attribute left out. Refuses (InputError naming the file and the
    object) what frirom never writes: soft and external links, storage outside the file,
    nesting past MAX_DEPTH, more than MAX_OBJECTS objects."""
    import h5py
    h = hashlib.sha256()
    count = [0]

    def attrs(o):
        for k in sorted(o.attrs):
            if not (o.name == "/" and k == DIGEST):
                h.update(b"\0attr:" + k.encode() + b"=" + _attr_bytes(o.attrs[k]))

    def visit(g, depth):
        attrs(g)
        for name in sorted(g):
            link = g.get(name, getlink=True)
            full = f"{g.name.rstrip('/')}/{name}"
            if not isinstance(link, h5py.HardLink):
                raise InputError(f"{path}: {full}: a link ({type(link).__name__}); frirom "
                                 "writes none: the file was changed after frirom wrote it")
            count[0] += 1
            if count[0] > MAX_OBJECTS:
                raise InputError(f"{path}: more than {MAX_OBJECTS} objects: not a file "
                                 "frirom wrote")
            obj = g[name]
            if isinstance(obj, h5py.Group):
                if depth + 1 >= MAX_DEPTH:
                    raise InputError(f"{path}: {full}: groups nested deeper than frirom "
                                     f"writes them ({MAX_DEPTH} levels)")
                h.update(b"\0group:" + full.encode())
                visit(obj, depth + 1)
            elif isinstance(obj, h5py.Dataset):
                if obj.external or obj.is_virtual:
                    raise InputError(f"{path}: {full}: data stored outside the file; "
                                     "frirom writes none")
                a = obj[()]
                h.update(b"\0data:" + full.encode() + b":" + _attr_bytes(a))
                attrs(obj)
            else:
                raise InputError(f"{path}: {full}: an object frirom does not write")

    visit(f, 0)
    return h.hexdigest()


def seal(f) -> None:
    """Write the DIGEST attribute of an open, writable h5py.File (its last change)."""
    if DIGEST in f.attrs:
        del f.attrs[DIGEST]
    f.attrs[DIGEST] = content_digest(f, f.filename)


def unseal(f) -> None:
    """Remove the DIGEST of a file about to change (a run resumed into it)."""
    if DIGEST in f.attrs:
        del f.attrs[DIGEST]


def verify(f, path) -> bool:
    """Check an open h5py.File against its DIGEST: True if it matches, False if the file
    has none (written before checksums, or by a run that never closed it); InputError
    naming the file if it differs (or its structure is one frirom never writes)."""
    stored = f.attrs.get(DIGEST)
    actual = content_digest(f, path)
    if stored is None:
        return False
    if isinstance(stored, bytes):
        stored = stored.decode(errors="replace")
    if not isinstance(stored, str) or stored != actual:
        raise InputError(f"{path}: content checksum mismatch: the file changed after frirom "
                         "wrote it (damaged or edited); its values are not used")
    return True


# ---- typed reads of attributes, each naming the file and the attribute ------------------
def attr_text(f, path, name: str, default=None) -> str | None:
    """A text attribute (str, or bytes as UTF-8); InputError for anything else."""
    if name not in f.attrs:
        return default
    v = f.attrs[name]
    if isinstance(v, np.ndarray) and v.shape == () and v.dtype.kind in "SUO":
        v = v[()]
    t = _text(v)
    if t is None:
        raise InputError(f"{path}: attribute {name!r}: expected text, got {_shown(v)}")
    return t


def _text(x) -> str | None:
    """x as str (bytes decoded as UTF-8), or None if it is neither."""
    if isinstance(x, bytes):
        try:
            return x.decode()
        except UnicodeDecodeError:
            return None
    return x if isinstance(x, str) else None


def attr_texts(f, path, name: str) -> list:
    """A list-of-text attribute (an array of bytes or str); InputError otherwise."""
    if name not in f.attrs:
        return []
    v = f.attrs[name]
    a = np.atleast_1d(np.asarray(v))
    if a.ndim != 1 or a.dtype.kind not in "SUO":
        raise InputError(f"{path}: attribute {name!r}: expected a list of names, got "
                         f"{_shown(v)}")
    out = [_text(x) for x in a]
    if any(x is None for x in out):
        raise InputError(f"{path}: attribute {name!r}: expected a list of names, got "
                         f"{_shown(v)}")
    return out


def attr_bool(f, path, name: str, default: bool) -> bool:
    """A boolean attribute (bool, or the integer 0/1)."""
    if name not in f.attrs:
        return default
    v = f.attrs[name]
    if isinstance(v, np.ndarray) and v.shape == ():
        v = v[()]
    if isinstance(v, (bool, np.bool_)) or (isinstance(v, (int, np.integer)) and v in (0, 1)):
        return bool(v)
    raise InputError(f"{path}: attribute {name!r}: expected true or false, got {_shown(v)}")


def attr_json(f, path, name: str):
    """A JSON text attribute parsed (None when absent); InputError for bad JSON."""
    text = attr_text(f, path, name)
    if text is None:
        return None
    try:
        return json.loads(text)
    except (ValueError, RecursionError):
        raise InputError(f"{path}: attribute {name!r}: expected JSON text, got "
                         f"{_shown(text)}") from None


def attr_floats(f, path, name: str, n: int | None = None):
    """A finite float array attribute (``n`` values when given); None when absent."""
    if name not in f.attrs:
        return None
    v = f.attrs[name]
    a = np.asarray(v)
    if a.dtype.kind not in "iuf" or (n is not None and a.size != n) \
            or not np.all(np.isfinite(a)):
        raise InputError(f"{path}: attribute {name!r}: expected "
                         f"{n if n is not None else 'some'} finite numbers, got {_shown(v)}")
    return a.astype(float).ravel()


def _shown(v) -> str:
    s = repr(v)
    return s if len(s) <= 80 else s[:77] + "..."


# ---- results files (frirom.results: FRF.save_h5, FRFWriter) ------------------------------
#: per-point datasets of a results file: (ndim, whether every committed value must be
#: finite); slider, unknowns and leak may hold NaN rows (points from before they were kept)
_ROWS = {"omega": (1, True), "parameter": (1, True), "X": (3, True), "amp_max": (2, True),
         "state_fractions": (3, True), "stable": (1, False), "fold": (1, False),
         "iterations": (1, False), "time_s": (1, True), "slider": (2, False),
         "unknowns": (2, False), "leak": (1, False), "frequency_hz": (1, True),
         "harmonic_amplitude": (3, True), "harmonic_phase": (3, True)}
#: datasets of a results file whose rows are not the points (the checkpoint slots) or that
#: may hold more rows than points: their number of dimensions
_NDIM = {"tangent": 2, "yscale": 1, "ck_scalars": 2, "ck_unknowns": 2, "ck_tangent": 2,
         "ck_lu": 2}
#: text attributes of a results file (META_KEYS among them)
_TEXT = ("parameter_name", "message", "solver_info", "deck_path", "deck_text",
         "solver_settings", "model_fingerprint", "frirom_version", "auto", "method")


def check_results(f, path) -> None:
    """Refuse a results file (an open h5py.File) whose content frirom did not write as
    it is: a checksum mismatch, links, groups, text or non-numeric datasets, datasets of
    the wrong number of dimensions or of sizes that disagree, attributes of the wrong
    type (bad JSON, text where numbers belong). InputError naming the file and the field.
    Finiteness of the values is checked on the committed rows (check_finite)."""
    import h5py
    verify(f, path)
    for name in f:
        d = f[name]
        if not isinstance(d, h5py.Dataset):
            raise InputError(f"{path}: {name}: a group; a results file holds only datasets")
        if d.dtype.kind not in "biuf":
            raise InputError(f"{path}: dataset {name!r}: expected numbers, got "
                             f"{'text' if d.dtype.kind in 'SUO' else d.dtype.str}")
        want = _ROWS[name][0] if name in _ROWS else _NDIM.get(name)
        if want is not None and d.ndim != want:
            raise InputError(f"{path}: dataset {name!r}: expected {want} "
                             f"dimensions, got shape {d.shape}")
    if "output_dofs" in f and f["output_dofs"].ndim != 1:
        raise InputError(f"{path}: dataset 'output_dofs': expected a list, got shape "
                         f"{f['output_dofs'].shape}")
    n_out = f["output_dofs"].shape[0] if "output_dofs" in f else None
    if "X" in f:
        nc = f["X"].shape[2]
        if nc % 2 == 0:
            raise InputError(f"{path}: dataset 'X': expected 2H+1 (odd) harmonic "
                             f"coefficients, got {nc}")
        for name, axis, want in (("X", 1, n_out), ("amp_max", 1, n_out),
                                 ("harmonic_amplitude", 1, n_out),
                                 ("harmonic_amplitude", 2, (nc + 1) // 2),
                                 ("harmonic_phase", 2, (nc + 1) // 2)):
            if name in f and want is not None and f[name].shape[axis] != want:
                raise InputError(f"{path}: dataset {name!r}: shape {f[name].shape} does not "
                                 f"match {n_out} outputs and {nc} harmonic coefficients")
    groups = attr_texts(f, path, "group_names")
    if "state_fractions" in f and f["state_fractions"].shape[1:] != (len(groups), 3):
        raise InputError(f"{path}: dataset 'state_fractions': expected (points, "
                         f"{len(groups)}, 3) for the {len(groups)} contact groups, got "
                         f"{f['state_fractions'].shape}")
    labels = attr_texts(f, path, "output_labels")
    if labels and n_out is not None and len(labels) != n_out:
        raise InputError(f"{path}: attribute 'output_labels': {len(labels)} labels for "
                         f"{n_out} outputs")
    for k in _TEXT:
        attr_text(f, path, k)
    for k in ("complete", "stability_computed"):
        attr_bool(f, path, k, True)
    attr_floats(f, path, "omega_range", 2)
    c = f.attrs.get("committed")
    if c is not None:
        a = np.asarray(c)
        if a.dtype.kind not in "iu" or a.shape != (3,) or a[0] < 0:
            raise InputError(f"{path}: attribute 'committed': expected 3 integers "
                             f"(points, checkpoint, slot), got {_shown(c)}")
        if a[2] >= 0:           # a checkpoint in slot a[2] of the ck_* datasets
            for k, tail in (("ck_unknowns", None), ("ck_tangent", None), ("ck_scalars", 4)):
                d = f.get(k)
                if d is None or d.ndim != 2 or d.shape[0] != 2 or a[2] > 1 \
                        or (tail is not None and d.shape[1] != tail):
                    raise InputError(f"{path}: dataset {k!r}: the checkpoint's state is "
                                     "missing or mis-shaped; the file cannot be resumed")
                if d.dtype.kind not in "iuf" or not np.all(np.isfinite(d[()])):
                    raise InputError(f"{path}: dataset {k!r}: the checkpoint's state holds "
                                     "a non-finite number; the file cannot be resumed")
    fp = attr_json(f, path, "deck_fingerprint")
    if fp is not None and not (isinstance(fp, dict) and isinstance(fp.get("keys", {}), dict)
                               and isinstance(fp.get("files", {}), dict)):
        raise InputError(f"{path}: attribute 'deck_fingerprint': expected the deck's keys "
                         "and files, got other JSON")
    if "peak_omega" in f:
        methods = attr_texts(f, path, "peak_method")
        sizes = {f[k].shape for k in ("peak_omega", "peak_amplitude", "peak_index")
                 if k in f}
        if sizes != {(len(methods),)} or (n_out is not None and len(methods) != n_out):
            raise InputError(f"{path}: the stored peaks (peak_omega, peak_amplitude, "
                             f"peak_index, peak_method) disagree in size or with the "
                             f"{n_out} outputs")
        for k in ("peak_omega", "peak_amplitude"):
            if not np.all(np.isfinite(f[k][()])):
                raise InputError(f"{path}: dataset {k!r}: holds a non-finite number")


def check_finite(arrays: dict, path) -> None:
    """Refuse (InputError naming the file and dataset) a non-finite value in a committed
    row of a dataset that always holds finite ones (``arrays``: {name: array}), or a
    per-point dataset with fewer rows than the file has points."""
    n = len(arrays["omega"]) if arrays.get("omega") is not None else None
    for name, a in arrays.items():
        if n is not None and name in _ROWS and a is not None and a.shape[:1] != (n,):
            raise InputError(f"{path}: dataset {name!r}: {a.shape[0] if a.ndim else 0} rows "
                             f"for {n} points; the file was damaged or edited")
    for name, a in arrays.items():
        if a is not None and _ROWS.get(name, (0, False))[1] and a.dtype.kind == "f" \
                and not np.all(np.isfinite(a)):
            i = int(np.argwhere(~np.isfinite(a))[0][0])
            raise InputError(f"{path}: dataset {name!r}: a non-finite number at point {i}; "
                             "the file was damaged or edited")
