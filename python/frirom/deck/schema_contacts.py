"""The deck's ``[[contacts]]`` tables as settings: elements between DoFs (with [model]) or
pairs between node sets (with [fe_model]). The law table is :data:`frirom.contact.LAWS`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._errors import InputError
from ..contact import LAWS
from .fields import Context, dof_ref, finite, number, per_element, string, unknown, vector
from .schema_model import CyclicSettings

#: parameters that must be >= 0 (n0 may be negative: an initial gap)
_NONNEGATIVE = {"kt", "kn", "mu", "fn0", "k1"}


@dataclass(frozen=True)
class ContactElement:
    """One element of a ``[[contacts]]`` table with [model].

    a : tuple of DofRef
        The node DoFs of side a (n_nd of them).
    b : tuple of DofRef or None
        As many DoFs of side b, or None for the ground.
    frame : ndarray, (n_dir, n_nd)
        Unit vectors of the law's local directions in the node DoFs.
    key : str
        Key path of the element (``contacts[0].elements[1]``).
    """

    a: tuple
    b: tuple | None
    frame: np.ndarray
    key: str


@dataclass(frozen=True)
class DofContact:
    """A ``[[contacts]]`` table with [model]: elements joining DoFs of the matrices.

    name, law : str
        The group's name and its law (a key of :data:`frirom.contact.LAWS`).
    elements : tuple of ContactElement
        n_elem elements.
    params : ndarray, (n_elem, n_par)
        Law parameters in the order of ``LAWS[law].parameters`` (SI units).
    w0 : ndarray, (n_elem, n_slider), or None
        Initial slider positions [m] (None: zeros).
    patch : float or None
        The contact patch's extent along the tangents [m] (key ``patch``): a relative
        tangential displacement beyond it is warned about (frirom.held).
    """

    name: str
    law: str
    elements: tuple
    params: np.ndarray
    w0: np.ndarray | None
    patch: float | None = None


@dataclass(frozen=True)
class NodeSetContact:
    """A ``[[contacts]]`` table with [fe_model]: pairs between node sets.

    name, law : str
        As for :class:`DofContact`.
    a, b : str, str or None
        Node sets of the two sides (b None: the ground).
    normal : str or tuple
        A 3-vector, or ``"axial"``, ``"radial"`` or ``"tangential"`` (about reduction.axis).
    tangent : tuple or None
        A 3-vector for the first tangential direction.
    tol : float or None
        Pair matching distance [m].
    params : ndarray, (n_par,)
        Law parameters, the same for every pair.
    w0 : ndarray, (n_slider,), or None
        Initial slider position [m].
    stick : tuple of 2 float
        (kt, kn) [N/m] of the full-stick interface modes (kn 0 for a law without).
    key : str
        Key path of the table (``contacts[0]``).
    b_sector : int
        0: side b in sector 0; 1: side b in the next sector (cyclic).
    patch : float or None
        The contact patch's extent along the tangents [m] (key ``patch``; None: side a's
        node set's extent along each tangent, frirom.deck.build).
    """

    name: str
    law: str
    a: str
    b: str | None
    normal: object
    tangent: tuple | None
    tol: float | None
    params: np.ndarray
    w0: np.ndarray | None
    stick: tuple
    key: str
    b_sector: int = 0
    patch: float | None = None


@dataclass(frozen=True)
class Preload:
    """A ``[[preload]]`` table: one body's load (a damper's centrifugal load, a bolt's
    clamping force) carried by the normal preloads of some contacts, given once.

    load : float
        The load on the body [N], > 0.
    direction : tuple of 3 float
        Its unit direction (global axes).
    contacts : tuple of str
        The ``[[contacts]]`` tables (laws with ``n0``) that carry it: their ``n0`` per pair
        and the balancing harmonic-0 loads are derived from the load
        (:meth:`frirom.deck.build.Builder.add_preloads`).
    body : str
        ``"a"`` or ``"b"``: the side of those contacts the loaded body is on.
    key : str
        Key path (``preload[0]``).
    """

    load: float
    direction: tuple
    contacts: tuple
    body: str
    key: str


def parse_preloads(ctx: Context, raw: dict, fe: bool) -> list:
    """Every ``[[preload]]`` table, checked (the contacts it names: by
    :func:`parse_contacts`)."""
    pls = raw.get("preload", [])
    if isinstance(pls, dict):
        pls = [pls]
    if not isinstance(pls, list):
        raise ctx.error("preload", "an array of tables [[preload]]", pls)
    out = []
    for i, t in enumerate(pls):
        key = f"preload[{i}]"
        if not isinstance(t, dict):
            raise ctx.error(key, "a table [[preload]]", t)
        if not fe:
            raise ctx.error(key, "[fe_model] (a preload is spread over node-set contacts; "
                            "with [model] give each element's n0 or fn0)")
        unknown(ctx, t, {"load", "direction", "contacts", "body"}, key)
        load = number(ctx, t, "load", f"{key}.load", required=True, positive=True)
        d = np.array(vector(ctx, t, "direction", f"{key}.direction"))
        names = t.get("contacts")
        if (not isinstance(names, list) or not names
                or not all(isinstance(x, str) for x in names)):
            raise ctx.error(f"{key}.contacts", "a non-empty list of [[contacts]] names", names)
        body = string(ctx, t, "body", f"{key}.body", default="a", choices=("a", "b"))
        out.append(Preload(load=float(load), direction=tuple(_unit(d)),
                           contacts=tuple(names), body=body, key=key))
    return out


def parse_contacts(ctx: Context, raw: dict, fe: bool, labels: bool,
                   cyclic: CyclicSettings | None, preloads=()) -> list:
    """Every ``[[contacts]]`` table, checked (``fe``, ``labels`` as :func:`dof_ref`);
    ``preloads``: the [[preload]] tables, whose contacts get their ``n0`` from them."""
    cons = raw.get("contacts", [])
    if not isinstance(cons, list):
        raise ctx.error("contacts", "an array of tables [[contacts]]", cons)
    if cyclic is not None and not cons:
        raise ctx.error("contacts", "at least one [[contacts]] table with "
                        "[reduction.cyclic] (a cyclic sector is solved for its contacts)")
    derived = {n for p in preloads for n in p.contacts}
    contacts = [_contact(ctx, c, f"contacts[{i}]", fe, labels, cyclic, derived)
                for i, c in enumerate(cons)]
    names = [c.name for c in contacts]
    for i, nm in enumerate(names):
        if nm in names[:i]:
            raise ctx.error(f"contacts[{i}].name", "a name not used by another contact", nm)
    seen = {}
    for p in preloads:
        for j, nm in enumerate(p.contacts):
            if nm not in names:
                raise ctx.error(f"{p.key}.contacts[{j}]", "the name of a [[contacts]] table "
                                f"({', '.join(names) or 'none'})", nm)
            if nm in seen:
                raise ctx.error(f"{p.key}.contacts[{j}]", f"a contact no other preload "
                                f"carries ({seen[nm]} does)", nm)
            seen[nm] = p.key
            c = contacts[names.index(nm)]
            if "n0" not in LAWS[c.law].parameters:
                raise ctx.error(f"{p.key}.contacts[{j}]", "a contact whose law has a normal "
                                f"preload n0 (normal1d, normal2d), not {c.law!r}", nm)
            if not isinstance(c.normal, tuple):
                raise ctx.error(f"{c.key}.normal", "a 3-vector normal with a [[preload]] "
                                "(the load's balance needs the faces' directions)", c.normal)
    return contacts


def _contact(ctx, c, key, fe, labels, cyclic, derived=frozenset()):
    if not isinstance(c, dict):
        raise ctx.error(key, "a table [[contacts]]", c)
    law = _user_law(ctx, c, key)
    if law is None:
        law = string(ctx, c, "law", f"{key}.law", required=True,
                     choices=tuple(k for k, v in LAWS.items() if v.code > 0))
    if fe:
        return _node_set_contact(ctx, c, key, law, cyclic, derived)
    dirs, pnames = LAWS[law].directions, LAWS[law].parameters
    ndir = len(dirs)
    unknown(ctx, c, {"name", "law", "elements", "directions", "w0", "patch"} | set(pnames),
            key)
    name = string(ctx, c, "name", f"{key}.name", default=key)
    els = c.get("elements")
    if not isinstance(els, list) or not els:
        raise ctx.error(f"{key}.elements", "a non-empty list of {a = ..., b = ...} "
                        "tables", els)
    # local frame: directions (ndir vectors, node-DoF length) shared or per element
    dv = c.get("directions")
    elements = []
    for e, el in enumerate(els):
        ek = f"{key}.elements[{e}]"
        if not isinstance(el, dict):
            raise ctx.error(ek, "a table {a = [DoFs], b = [DoFs] | \"ground\"}", el)
        unknown(ctx, el, {"a", "b", "directions"}, ek)
        a = _side(ctx, el.get("a"), f"{ek}.a", labels, allow_ground=False)
        b = _side(ctx, el.get("b", "ground"), f"{ek}.b", labels, allow_ground=True)
        frame = el.get("directions", dv)
        fk = f"{ek}.directions" if "directions" in el else f"{key}.directions"
        if frame is None:
            if len(a) == ndir:
                frame = np.eye(ndir).tolist()
            else:
                raise ctx.error(f"{key}.directions", f"{ndir} direction vectors "
                                f"({', '.join(dirs)}) of length {len(a)} (node DoFs)")
        elements.append(ContactElement(a=a, b=b, frame=_frame(ctx, frame, fk, len(a), dirs),
                                       key=ek))
    params, w0 = _law_parameters(ctx, c, key, law, len(els))
    return DofContact(name=name, law=law, elements=tuple(elements), params=params, w0=w0,
                      patch=number(ctx, c, "patch", f"{key}.patch", positive=True))


def _side(ctx, v, key, labels, allow_ground):
    """The DoFs of one side of an element (None: the ground)."""
    if v is None:
        raise ctx.error(key, "a DoF or list of DoFs (missing)")
    if isinstance(v, str) and v.lower() == "ground":
        if allow_ground:
            return None
        raise ctx.error(key, "DoFs (only side b may be \"ground\")", v)
    items = v if isinstance(v, list) else [v]
    if not items:
        raise ctx.error(key, "a non-empty list of DoFs", v)
    return tuple(dof_ref(ctx, x, f"{key}[{i}]" if isinstance(v, list) else key, False, labels)
                 for i, x in enumerate(items))


def _frame(ctx, frame, key, nd, dirs) -> np.ndarray:
    """(n_dir, nd) unit direction vectors of a local frame."""
    ndir = len(dirs)
    if not isinstance(frame, list) or len(frame) != ndir:
        raise ctx.error(key, f"{ndir} direction vectors ({', '.join(dirs)})", frame)
    D = np.empty((ndir, nd))
    for d, vec in enumerate(frame):
        if (not isinstance(vec, list) or len(vec) != nd
                or any(isinstance(x, bool) or not isinstance(x, (int, float))
                       or not finite(x) for x in vec)):
            raise ctx.error(f"{key}[{d}]", f"a list of {nd} numbers (one per node DoF)", vec)
        D[d] = vec
        nrm = np.linalg.norm(D[d])
        if not np.isfinite(nrm) or nrm == 0.0:
            raise ctx.error(f"{key}[{d}]", "a non-zero finite vector", vec)
        D[d] = _unit(D[d])
    return D


def _unit(v: np.ndarray) -> np.ndarray:
    """v / |v|; a vector already unit to round-off is kept as written: dividing by its
    norm (1 - 1e-16) would move it by an ulp, and C or Fortran callers given the same
    numbers would solve another model at round-off."""
    nrm = np.linalg.norm(v)
    return v if abs(nrm - 1.0) <= 4.0 * np.finfo(float).eps else v / nrm


def _user_law(ctx, c, key):
    """The name of the user law a contact's ``law = "module:function"`` names (loaded
    and registered: frirom.laws.load_law, register), None for a built-in law's name."""
    from ..laws import load_law, register
    v = c.get("law")
    if not (isinstance(v, str) and ":" in v):
        return None
    try:
        return register(load_law(v, allowed=ctx.allow_code, where=f"{key}.law"))
    except ImportError as exc:
        raise ctx.error(f"{key}.law", "an importable 'module:function'", f"{v} ({exc})") \
            from None
    except InputError as exc:
        raise InputError(f"{ctx.path}: {exc}") from None


def _law_parameters(ctx, c, key, law, ne, derived=()):
    """(params (ne, n_par), w0 (ne, n_slider) or None) of a contact table; the parameters
    in ``derived`` come from elsewhere (a [[preload]]: 0 here) and must not be given."""
    pnames, nsl = LAWS[law].parameters, LAWS[law].n_slider
    params = np.empty((ne, len(pnames)))
    for j, p in enumerate(pnames):
        if p in derived:
            if p in c:
                raise ctx.error(f"{key}.{p}", "no value: a [[preload]] carried by this "
                                "contact derives it", c[p])
            params[:, j] = 0.0
            continue
        params[:, j] = per_element(ctx, c, p, f"{key}.{p}", ne, required=True,
                                   nonneg=p in _NONNEGATIVE)
    if "kt" in pnames and np.any(params[:, 0] <= 0):
        raise ctx.error(f"{key}.kt", "a positive tangential stiffness (N/m)")
    if "kn" in pnames and np.any(params[:, 1] <= 0):
        raise ctx.error(f"{key}.kn", "a positive normal stiffness (N/m)")
    w0 = None
    if "w0" in c:
        if nsl == 0:
            raise ctx.error(f"{key}.w0", f"no initial slider for law {law!r} (it has none)")
        w0 = np.repeat(per_element(ctx, c, "w0", f"{key}.w0", ne)[:, None], nsl, axis=1)
    return params, w0


def _node_set_contact(ctx, c, key, law, cyclic, derived=frozenset()):
    """A [[contacts]] table of a reduced model: node sets a, b, a normal."""
    pnames = LAWS[law].parameters
    unknown(ctx, c, {"name", "law", "a", "b", "b_sector", "normal", "tangent", "tol",
                     "w0", "patch"} | set(pnames), key)
    name = string(ctx, c, "name", f"{key}.name", default=f"contacts{key[9:-1]}")
    a = string(ctx, c, "a", f"{key}.a", required=True)
    b = string(ctx, c, "b", f"{key}.b", default="ground")
    b = None if b.lower() == "ground" else b
    bs = number(ctx, c, "b_sector", f"{key}.b_sector", default=0, integer=True)
    if bs not in (0, 1):
        raise ctx.error(f"{key}.b_sector", "0 (side b in sector 0) or 1 (side b in the "
                        "next sector)", bs)
    if bs == 1 and cyclic is None:
        raise ctx.error(f"{key}.b_sector", "0 without [reduction.cyclic] (a contact with "
                        "the next sector needs a cyclic sector)", bs)
    if bs == 1 and b is None:
        raise ctx.error(f"{key}.b", "a node set of the next sector with b_sector = 1, "
                        "not the ground", "ground")
    normal = c.get("normal")
    if isinstance(normal, str):
        normal = string(ctx, c, "normal", f"{key}.normal",
                        choices=("axial", "radial", "tangential"))
    else:
        normal = vector(ctx, c, "normal", f"{key}.normal")
    tangent = vector(ctx, c, "tangent", f"{key}.tangent") if "tangent" in c else None
    tol = number(ctx, c, "tol", f"{key}.tol", positive=True)
    for p in [*pnames, "w0"]:
        if isinstance(c.get(p), list):
            raise ctx.error(f"{key}.{p}", "a number (the same for every pair of the "
                            "node sets)", c[p])
    params, w0 = _law_parameters(ctx, c, key, law, 1,
                                 ("n0",) if name in derived and "n0" in pnames else ())
    stick = (params[0, 0], params[0, 1] if "kn" in pnames else 0.0)
    return NodeSetContact(name=name, law=law, a=a, b=b, normal=normal, tangent=tangent,
                          tol=tol, params=params[0], w0=None if w0 is None else w0[0],
                          stick=tuple(float(x) for x in stick), key=key, b_sector=bs,
                          patch=number(ctx, c, "patch", f"{key}.patch", positive=True))
