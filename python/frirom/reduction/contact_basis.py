"""A contact-driven enrichment of a GSI interface basis: the static responses of the stuck
interface to the friction-force changes of the contact elements that slip first.

A GSI basis (frirom.reduction.interface) spans the interface's characteristic constraint
modes, free and full-stick: smooth shapes over the whole interface. Microslip is local: a
few lightly loaded elements slip while their neighbours stick, and the interface deforms
in the shape their friction-force change excites, which a smooth basis represents only
with many modes. This module adds those shapes directly:

1. the stuck linear mode phi (mass-normalised) of the structure with every contact element
   a spring of its stick stiffness, chosen by its frequency;
2. each element's slip-onset modal amplitude a_e = mu n0_e / (kt_e |g_t,e phi|), the
   amplitude at which the stuck mode's tangential force reaches the Coulomb limit (and,
   for laws with a normal stiffness, its lift-off amplitude n0_e / (kn_e |g_n,e phi|));
3. for the elements that slip first (the first n by onset, or every element with an onset
   below a given amplitude), the static responses of the stuck interface, (K_c + K_s) u =
   g_e,d^T with K_c the Guyan-condensed master partition (the same one the CC modes use),
   K_s the stick springs of every element and g_e,d the unit relative force of element e in
   direction d (both tangents; the normal too on request): attachment modes of the
   interface (residual flexibility, MacNeal 1971) restricted to the slip-prone elements;
4. their interface rows Gram-Schmidt orthonormalised against the retained GSI vectors in
   the same (Euclidean, interface-row) inner product GSI uses, in order of onset, vectors
   whose orthogonal remainder is below ``tol`` of their norm dropped.

The choice follows the problem-oriented trial vectors of Witteveen & Pichler (joint trial
vectors from trial vector derivatives, Multibody Syst. Dyn. 40 (2017) 407), which add
static responses to contact forces to a component mode basis, but ranks the elements by
their slip onset in the mode of interest and uses unit forces (so that, with every element
included, every friction-force change's static response lies in the span).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .._errors import InputError, NumericalError, SingularMatrixError
from .interface import ContactPairs, _as_index, _check_pair, contact_matrix, gram_schmidt
from .interface import guyan_condense, stick_stiffness

__all__ = ["StuckMode", "stuck_mode", "slip_onset", "static_responses",
           "orthonormal_append", "ContactDrivenInfo", "contact_driven_basis", "preload_n0"]

#: default drop tolerance: a vector whose component orthogonal to the basis is below this
#: fraction of its norm adds nothing the basis does not already hold
DROP_TOL = 1e-6


@dataclass(frozen=True)
class StuckMode:
    """The stuck linear mode: shape (n,) mass-normalised, frequency [Hz]."""

    shape: np.ndarray
    frequency: float


def stuck_mode(K, M, pairs: ContactPairs, frequency: float) -> StuckMode:
    """The mode of K + G^T k_stick G (every contact element a spring of its stick stiffness)
    whose frequency is nearest ``frequency`` [Hz], mass-normalised, sign fixed (largest
    entry positive)."""
    _check_pair(K, M)
    if not (np.isfinite(frequency) and frequency > 0):
        raise InputError(f"stuck_mode: frequency must be > 0 Hz, got {frequency}")
    n = K.shape[0]
    Ks = sp.csr_matrix(K) + stick_stiffness(pairs, n)
    sigma = (2 * np.pi * frequency) ** 2
    k = min(n - 2, 6)
    try:
        if n <= 400:
            lam, phi = sla.eigh(Ks.toarray(), sp.csr_matrix(M).toarray())
        else:
            lam, phi = spla.eigsh(Ks.tocsc(), k=k, M=sp.csc_matrix(M), sigma=sigma)
    except (np.linalg.LinAlgError, RuntimeError, ValueError) as exc:
        raise NumericalError(f"stuck_mode: eigen-solve near {frequency} Hz failed ({exc})"
                             ) from exc
    j = int(np.argmin(np.abs(lam - sigma)))
    v = phi[:, j]
    v = v / np.sqrt(v @ (M @ v))
    v = v * np.sign(v[np.argmax(np.abs(v))])
    return StuckMode(v, float(np.sqrt(max(lam[j], 0.0)) / (2 * np.pi)))


def slip_onset(pairs: ContactPairs, mode: np.ndarray, slip_force: np.ndarray,
               n0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Slip-onset and lift-off modal amplitudes of every element, (n_elem,) each.

    mode: (n,) mass-normalised mode shape (modal amplitude q: x = q mode); slip_force:
    (n_elem,) Coulomb limit mu n0 [N]; n0: (n_elem,) normal preload [N] for the lift-off
    amplitude (inf where the law has no normal direction or n0 is None). The frames' last
    direction is the normal when the pairs have a normal stiffness (n_dir 2 or 3), else
    every direction is tangential. Elements the mode does not load get inf.
    """
    n_elem, n_dir, _ = pairs.frames.shape
    g = contact_matrix(pairs, mode.size) @ mode
    u = np.asarray(g).reshape(n_elem, n_dir)
    normal = n0 is not None and n_dir > 1
    nt = n_dir - 1 if normal else n_dir
    ft = np.linalg.norm(u[:, :nt] * pairs.stiffness[:, :nt], axis=1)
    with np.errstate(divide="ignore"):
        slip = np.where(ft > 0, np.asarray(slip_force, float) / np.where(ft > 0, ft, 1.0),
                        np.inf)
        lift = np.full(n_elem, np.inf)
        if normal:
            fn = np.abs(u[:, -1] * pairs.stiffness[:, -1])
            lift = np.where(fn > 0, np.asarray(n0, float) / np.where(fn > 0, fn, 1.0), np.inf)
    return slip, lift


def static_responses(K, M, masters, pairs: ContactPairs, loads) -> np.ndarray:
    """Static responses of the stuck masters to unit relative forces, (n_m, n_loads).

    K, M: the model (M only for the condensation's check of sizes); masters: (n_m,) model
    DoFs (interface and active), which hold every contact DoF; loads: (n_loads,) row
    indices e*n_dir + d of ``contact_matrix(pairs)``: force +1 on side A and -1 on side B
    along direction d of element e. Solves (K_c + K_s) u = g_e,d^T on the masters, K_c the
    Guyan condensation of K onto the masters and K_s the stick springs of every element.
    """
    _check_pair(K, M)
    n = K.shape[0]
    m = _as_index(masters, n, "static_responses masters")
    off = np.setdiff1d(pairs.dofs, m)
    if off.size:
        raise InputError(f"static_responses: contact DoFs {off[:5].tolist()} are not "
                         "masters")
    kc, _ = guyan_condense(K, M, m)
    pos = -np.ones(n, np.int64)
    pos[m] = np.arange(m.size)
    local = ContactPairs(pos[pairs.dofs_a],
                         np.where(pairs.dofs_b >= 0, pos[np.maximum(pairs.dofs_b, 0)], -1),
                         pairs.frames, pairs.stiffness)
    kt = kc + stick_stiffness(local, m.size).toarray()
    rhs = contact_matrix(local, m.size)[np.asarray(loads, np.int64)].toarray().T
    try:
        lu = sla.lu_factor(kt, check_finite=True)
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise SingularMatrixError(f"static_responses: stuck master stiffness: {exc}") from None
    u = sla.lu_solve(lu, rhs)
    if not np.all(np.isfinite(u)) or np.any(np.abs(np.diag(lu[0])) == 0):
        raise SingularMatrixError("static_responses: the stuck master stiffness is singular "
                                  "(a body without support, even through its contacts?)")
    return u


def orthonormal_append(basis: np.ndarray, vectors: np.ndarray, groups=None,
                       tol: float = DROP_TOL) -> tuple[np.ndarray, int]:
    """``basis`` (n_i, n_k) orthonormal with ``vectors`` (n_i, p) appended: each group's
    rows (``groups``: index arrays partitioning the rows, as gsi_basis takes them; default
    one group) Gram-Schmidt orthonormalised against the basis columns that live on that
    group, in order, a vector whose orthogonal remainder is below ``tol`` times its norm
    dropped. Returns (new basis, number of columns added)."""
    n_i = basis.shape[0]
    if groups is None:
        groups = [np.arange(n_i)]
    out, added = [basis], 0
    for g in groups:
        outside = np.setdiff1d(np.arange(n_i), g)
        own = np.nonzero(~np.any(basis[outside] != 0, axis=0))[0]
        q0 = basis[np.ix_(g, own)]
        q = gram_schmidt(vectors[g], vectors.shape[1], q0, tol)
        new = q[:, q0.shape[1]:]
        block = np.zeros((n_i, new.shape[1]))
        block[g] = new
        out.append(block)
        added += new.shape[1]
    return np.hstack(out), added


@dataclass(frozen=True)
class ContactDrivenInfo:
    """What :func:`contact_driven_basis` chose: the stuck mode's frequency [Hz], every
    element's slip-onset and lift-off modal amplitudes [sqrt(kg) m], the elements used (in
    order of onset), the number of vectors formed and of those kept."""

    frequency: float
    onset: np.ndarray
    lift: np.ndarray
    elements: np.ndarray
    formed: int
    kept: int


def contact_driven_basis(K, M, interface, active, pairs: ContactPairs, basis: np.ndarray,
                         slip_force, frequency: float, n0=None, elements: int | None = None,
                         amplitude: float | None = None, normal: bool = False, groups=None,
                         tol: float = DROP_TOL) -> tuple[np.ndarray, ContactDrivenInfo]:
    """A GSI ``basis`` (n_i, n_k) on ``interface`` enriched by contact-driven vectors.

    K, M: the model the GSI basis was built on (CB or FE); interface, active: its master
    DoFs (as gsi_basis takes them); pairs: every contact element (DoFs among the masters);
    slip_force: (n_elem,) mu n0 [N]; n0: (n_elem,) normal preload [N] (lift-off onset; None
    without); frequency [Hz]: the stuck mode nearest it ranks the elements; elements: use
    the first that many elements by slip onset; amplitude: use every element whose onset
    (slip, or lift-off with ``normal``) lies below this modal amplitude [sqrt(kg) m] (one of
    the two; both: the elements satisfying both); normal: also the unit normal force of
    each element used; groups, tol: as :func:`orthonormal_append`.

    Returns (basis (n_i, n_k + kept), ContactDrivenInfo).
    """
    _check_pair(K, M)
    n = K.shape[0]
    i = _as_index(interface, n, "contact_driven_basis interface")
    a = _as_index(active, n, "contact_driven_basis active")
    basis = np.asarray(basis, float)
    if basis.ndim != 2 or basis.shape[0] != i.size:
        raise InputError(f"contact_driven_basis: basis must be (n_i={i.size}, n_k), got "
                         f"{basis.shape}")
    if elements is None and amplitude is None:
        raise InputError("contact_driven_basis: give elements (the first n by slip onset) "
                         "or amplitude (every element slipping below it)")
    if elements is not None and elements < 1:
        raise InputError(f"contact_driven_basis: elements must be >= 1, got {elements}")
    if amplitude is not None and not amplitude > 0:
        raise InputError(f"contact_driven_basis: amplitude must be > 0, got {amplitude}")
    slip_force = np.broadcast_to(np.asarray(slip_force, float), (pairs.n_elem,))
    if n0 is not None:
        n0 = np.broadcast_to(np.asarray(n0, float), (pairs.n_elem,))
    if normal and (n0 is None or pairs.n_dir < 2):
        raise InputError("contact_driven_basis: normal = true needs a law with a normal "
                         "direction and its preload n0")
    mode = stuck_mode(K, M, pairs, frequency)
    onset, lift = slip_onset(pairs, mode.shape, slip_force, n0)
    first = np.minimum(onset, lift) if normal else onset
    order = np.argsort(first, kind="stable")
    order = order[np.isfinite(first[order])]
    if amplitude is not None:
        order = order[first[order] <= amplitude]
    if elements is not None:
        order = order[:elements]
    n_dir = pairs.n_dir
    has_normal = n0 is not None and n_dir > 1
    dirs = list(range(n_dir - 1 if has_normal else n_dir)) + ([n_dir - 1] if normal else [])
    loads = (order[:, None] * n_dir + np.asarray(dirs)[None, :]).ravel()
    if loads.size == 0:
        return basis, ContactDrivenInfo(mode.frequency, onset, lift, order, 0, 0)
    masters = np.concatenate([i, a])
    u = static_responses(K, M, masters, pairs, loads)[:i.size]
    out, kept = orthonormal_append(basis, u, groups, tol)
    return out, ContactDrivenInfo(mode.frequency, onset, lift, order, loads.size, kept)


def preload_n0(normal_sums: np.ndarray, n_pairs, target: np.ndarray):
    """One normal preload n0 per contact carrying a body's load: (n0 (n_c,), the part of
    the load along no face normal [N], rank).

    normal_sums: (3, n_c) the sum of each contact's pair normals; n_pairs: (n_c,) its pair
    count; target: (3,) the load the contacts carry (sign: +1 for body a, -1 body b, times
    the load vector). Least squares over the contacts; where the balance does not fix the
    shares (parallel faces), the one of least sum over pairs of n0^2 (unknowns sqrt(pairs)
    n0: lstsq's least-norm answer), which is one pressure on every pair.
    """
    root = np.sqrt(np.asarray(n_pairs, float))
    A = np.asarray(normal_sums, float)
    y, _, rank, _ = np.linalg.lstsq(A / root, np.asarray(target, float), rcond=None)
    n0 = y / root
    return n0, float(np.linalg.norm(A @ n0 - target)), int(rank)


def enrich_from_specs(K0, M0, iface, act, specs, pairs0, prs, basis, groups, cd, pre, log):
    """The GSI ``basis`` of frirom.reduction.rom enriched by :func:`contact_driven_basis`
    (settings ``cd``, a ContactDrivenSpec); the slip limits mu n0 from the pair specs
    ``specs`` (n0 from the contacts or their [[preload]], over the pairs ``prs``), the
    elements from ``pairs0``. ``pre`` names the deck table in messages. Returns (basis,
    number of vectors added)."""
    n0 = {p.name: p.n0 for p in specs}
    for load, direction, body, names in cd.preloads:
        fr = [prs[c].frames for c in names]
        normals = np.array([f[:, -1, :].sum(axis=0) for f in fr]).T
        target = (1.0 if body == "a" else -1.0) * load * np.asarray(direction, float)
        share, _, _ = preload_n0(normals, [f.shape[0] for f in fr], target)
        n0.update({c: v for c, v in zip(names, share) if n0.get(c) is None})
    slip, nload = [], []
    for p in specs:
        if p.mu is None:
            raise InputError(f"{pre}.contact_driven: {p.key} has no friction coefficient "
                             "mu (laws jenkins, normal1d, normal2d)")
        if n0.get(p.name) is None or not n0[p.name] > 0:
            raise InputError(f"{pre}.contact_driven: {p.key} needs its normal load n0 "
                             "(given, or from a [[preload]])")
        slip.append(np.full(pairs0[p.name].n_elem, p.mu * n0[p.name]))
        nload.append(np.full(pairs0[p.name].n_elem, n0[p.name]))
    if len({p.n_dir for p in pairs0.values()}) > 1:
        raise InputError(f"{pre}.contact_driven: all contacts must have the same number of "
                         "local directions")
    allp = ContactPairs(*(np.vstack([getattr(pairs0[p.name], k) for p in specs])
                          for k in ("dofs_a", "dofs_b", "frames", "stiffness")))
    has_n = any(p.kn > 0 for p in specs)
    try:
        out, info = contact_driven_basis(
            K0, M0, iface, act, allp, basis, np.concatenate(slip), cd.frequency,
            np.concatenate(nload) if has_n else None, cd.elements, cd.amplitude, cd.normal,
            groups, cd.tol)
    except InputError as exc:
        raise InputError(f"{pre}.contact_driven: {exc}") from None
    if log:
        on = info.onset[info.elements]
        log(f"contact-driven basis: stuck mode {info.frequency:.4g} Hz, {info.elements.size}"
            f" elements (slip onset {on.min() if on.size else 0:.3g} .. "
            f"{on.max() if on.size else 0:.3g}), {info.formed} static responses, "
            f"{info.kept} kept")
    return out, info.kept
