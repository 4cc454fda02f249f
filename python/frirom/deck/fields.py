"""Typed readers of TOML values: each checks one field and names it in its error.

Every reader takes a :class:`Context` (the deck file), the TOML table ``d`` the field
lives in, the field's name in it and its key path in the deck (``contacts[2].mu``), and
raises :class:`frirom.InputError` reading ``<deck>: <key>: expected <what>, got <value>``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._errors import InputError
from ..io._common import DIRECTION_NAMES


class Context:
    """Builds InputErrors that name the deck file and the key path.

    Parameters
    ----------
    path : Path
        The deck file; relative file names in it are relative to ``path.parent``.
    """

    def __init__(self, path: Path):
        self.path = path
        self.base = path.parent
        #: modules a contact law 'module:function' may import (--allow-code)
        self.allow_code: tuple = ()

    def error(self, key: str, expected: str, got=None) -> InputError:
        """``InputError("<deck>: <key>: expected <expected>[, got <got>]")``."""
        msg = f"{self.path}: {key}: expected {expected}"
        if got is not None:
            shown = repr(got)
            if len(shown) > 80:
                shown = shown[:77] + "..."
            msg += f", got {shown}"
        return InputError(msg)


def finite(x) -> bool:
    """True for a finite number (a TOML integer too large for a float is not)."""
    try:
        return math.isfinite(x)
    except OverflowError:
        return False


def table(ctx: Context, d, key: str, required: bool = True) -> dict:
    """The sub-table at ``key`` (its last dotted part is looked up in ``d``); {} if absent
    and not required."""
    parts = key.split(".")
    v = d.get(parts[-1]) if isinstance(d, dict) else None
    if v is None:
        if required:
            raise ctx.error(key, "a table [" + key + "]")
        return {}
    if not isinstance(v, dict):
        raise ctx.error(key, "a table", v)
    return v


def unknown(ctx: Context, d: dict, allowed, prefix: str) -> None:
    """Reject a key of ``d`` not in ``allowed`` (``prefix``: the table's key path)."""
    for k in d:
        if k not in allowed:
            where = f"{prefix}.{k}" if prefix else k
            raise ctx.error(where, "one of the known keys " + ", ".join(sorted(allowed))
                            + " (unknown key)")


#: The largest integer a deck field may hold: the Fortran interface's 32-bit integers.
MAX_INT = 2**31 - 1


def number(ctx: Context, d, name, key, *, default=None, required=False, positive=False,
           nonneg=False, integer=False, minimum=None, maximum=None):
    """A finite int or float (``integer``: an int), optionally > 0, >= 0, >= minimum or
    <= maximum. Integers are at most :data:`MAX_INT`; other numbers come back as float
    (a TOML integer too big for a float is refused as not finite)."""
    if name not in d:
        if required:
            raise ctx.error(key, "a number (missing)")
        return default
    v = d[name]
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ctx.error(key, "an integer" if integer else "a number", v)
    if integer and not isinstance(v, int):
        raise ctx.error(key, "an integer", v)
    if integer:
        top = MAX_INT if maximum is None else maximum
        if v > top or v < -MAX_INT:
            raise ctx.error(key, f"an integer at most {top}" if v > 0 else
                            f"an integer >= {-MAX_INT}", v)
    else:
        try:
            v = float(v)
        except OverflowError:
            v = math.inf
        if not math.isfinite(v):
            raise ctx.error(key, "a finite number", d[name])
        if maximum is not None and v > maximum:
            raise ctx.error(key, f"a number at most {maximum:g}", v)
    if positive and v <= 0:
        raise ctx.error(key, "a positive number", v)
    if nonneg and v < 0:
        raise ctx.error(key, "a number >= 0", v)
    if minimum is not None and v < minimum:
        raise ctx.error(key, f"a number >= {minimum}", v)
    return v


def string(ctx: Context, d, name, key, *, default=None, required=False, choices=None):
    """A string; with ``choices`` one of them, case-insensitive, returned lower-case."""
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


def boolean(ctx: Context, d, name, key, default: bool) -> bool:
    """true or false."""
    if name not in d:
        return default
    v = d[name]
    if not isinstance(v, bool):
        raise ctx.error(key, "true or false", v)
    return v


def file(ctx: Context, d, name, key) -> Path:
    """A file name, made absolute relative to the deck's folder (not checked to exist)."""
    v = d.get(name)
    if not isinstance(v, str) or not v:
        raise ctx.error(key, "a file name (relative to the deck's folder)", v)
    p = Path(v)
    return p if p.is_absolute() else ctx.base / p


def names(ctx: Context, d, name, key, required: bool) -> list:
    """A node-set name or a non-empty list of names ([] if absent and not required)."""
    v = d.get(name)
    if v is None and not required:
        return []
    if isinstance(v, str):
        v = [v]
    if not isinstance(v, list) or not v or not all(isinstance(s, str) and s for s in v):
        raise ctx.error(key, "a node-set name or a non-empty list of names", v)
    return v


def integers(ctx: Context, d, name, key, required=False, minimum=None) -> tuple:
    """A non-empty list of integers (>= minimum), as a tuple; () if absent."""
    v = d.get(name)
    if v is None and not required:
        return ()
    if (not isinstance(v, list) or not v
            or any(isinstance(x, bool) or not isinstance(x, int) or abs(x) > MAX_INT
                   for x in v)
            or (minimum is not None and min(v) < minimum)):
        what = "integers" if minimum is None else f"integers >= {minimum}"
        raise ctx.error(key, f"a non-empty list of {what}", v)
    return tuple(v)


def vector(ctx: Context, d, name, key, default=None, nonzero=True) -> tuple:
    """A 3-vector of finite floats (``nonzero``: not all zero)."""
    v = d.get(name, default)
    if (not isinstance(v, (list, tuple)) or len(v) != 3
            or any(isinstance(x, bool) or not isinstance(x, (int, float))
                   or not finite(x) for x in v)
            or (nonzero and not any(v))):
        raise ctx.error(key, "a list of 3 finite numbers"
                        + (", not all zero" if nonzero else ""), v)
    return tuple(float(x) for x in v)


def per_element(ctx: Context, c, p, key, ne, required=False, nonneg=False) -> np.ndarray:
    """(ne,) values of a number given once for all elements or as a list of ne numbers;
    zeros if absent and not required."""
    if p not in c:
        if required:
            raise ctx.error(key, f"a number or a list of {ne} numbers (missing)")
        return np.zeros(ne)
    v = c[p]
    vals = v if isinstance(v, list) else [v] * ne
    if len(vals) != ne:
        raise ctx.error(key, f"a number or a list of {ne} numbers (one per element)", v)
    out = np.empty(ne)
    for i, x in enumerate(vals):
        k = f"{key}[{i}]" if isinstance(v, list) else key
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not finite(x):
            raise ctx.error(k, "a finite number", x)
        if nonneg and x < 0:
            raise ctx.error(k, "a number >= 0", x)
        out[i] = x
    return out


# ---- DoF references: checked for form here, resolved against the model by the build ----

#: direction names of FE DoFs ("NODE:DIR" references), lower case -> direction 1..6
_DIRECTIONS = {"x": 1, "y": 2, "z": 3,
               **{name.lower(): d for d, name in DIRECTION_NAMES.items()},
               **{str(d): d for d in DIRECTION_NAMES}}


@dataclass(frozen=True)
class NodeDof:
    """A "NODE:DIR" DoF of a deck with [fe_model].

    node : int or str
        A node id, or the name of a node set (one node, or each node for a load).
    direction : int
        1..6 (UX, UY, UZ, ROTX, ROTY, ROTZ; see :data:`frirom.io.DIRECTION_NAMES`).
    text : str
        The reference as written in the deck.
    """

    node: int | str
    direction: int
    text: str


@dataclass(frozen=True)
class DofRef:
    """A DoF named in the deck, not yet resolved against the model's size or labels.

    value : int, str or NodeDof
        With [model]: a 0-based DoF index (int) or a label of ``model.dof_labels`` (str);
        with [fe_model]: a :class:`NodeDof`.
    key : str
        Its key path in the deck (``excitation.load[0].dof``), for error messages.
    """

    value: int | str | NodeDof
    key: str


def dof_ref(ctx: Context, v, key: str, fe: bool, labels: bool) -> DofRef:
    """Check the form of a DoF reference (``fe``: a deck with [fe_model]; ``labels``:
    [model] gives ``dof_labels``)."""
    if fe:
        if isinstance(v, str) and v.count(":") == 1:
            node, d = (s.strip() for s in v.split(":"))
            dn = _DIRECTIONS.get(d.lower())
            if node.upper().startswith("N") and node[1:].isdigit():
                node = node[1:]
            if dn is not None and node:
                return DofRef(NodeDof(int(node) if node.isdigit() else node, dn, v), key)
        raise ctx.error(key, "a DoF \"NODE:DIR\": a node id or node set name, "
                        "and x, y, z (or UX..ROTZ, 1..6)", v)
    if isinstance(v, bool):
        raise ctx.error(key, "a DoF index (integer) or label (string)", v)
    if isinstance(v, int):
        return DofRef(v, key)
    if isinstance(v, str):
        if not labels:
            raise ctx.error(key, "a DoF index (labels need model.dof_labels)", v)
        return DofRef(v, key)
    raise ctx.error(key, "a DoF index (integer) or label (string)", v)
