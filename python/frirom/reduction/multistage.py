"""Multi-stage (MS) spatial-Fourier reduction of circular interfaces (Eq. 20-23).

The interface of a cyclic stage of N sectors is cut into NZ radial line segments (groups of
nodes at the same angle around the rotor axis, Z per sector, n_l DoFs each, Eq. 20). Its
DoFs, in the cylindrical components (radial, tangential, axial) of each node, are
x_i = (F_{NZ,NZ} (x) I_{n_l}) a (Eq. 23) with the orthonormal real Fourier matrix of Eq. 21
and the column order of Eq. 22; keeping only the columns of a few harmonic indices reduces
the interface. The basis given to :func:`frirom.reduction.interface.reduce_interface` also
holds the rotation from cylindrical to global components, so it applies to the model's own
(global x, y, z) DoFs and stays orthonormal.

Phase convention: phi_k = 2 pi k / NZ with k = 0 for the first segment at or after the
reference angle (Eq. 21 counts from k = 1; the spans of the retained columns are the same).

A tuned stage excited by an engine order EO responds in the harmonic indices
h = z N +- EO (Eq. 1); time harmonic j of the response carries spatial index j EO. With Z
segments per sector these fold into the family h = +-(j EO) mod N over 0..NZ/2
(:func:`harmonic_indices`); keeping that family makes the reduction exact for a tuned stage
(see tests/test_multistage.py). Coupled stages of N_1 and N_2 sectors form an assembly of
gcd(N_1, N_2) sectors, whose families are taken modulo that gcd (:func:`stage_indices`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.linalg import block_diag

from .._errors import InputError, SizeError
from .interface import InterfaceReduction

__all__ = ["RadialSegments", "MultistageInterface", "cylindrical_frame", "fourier_matrix",
           "fourier_columns", "harmonic_indices", "stage_indices", "shared_indices",
           "radial_line_segments", "travelling_wave_selection", "travelling_wave_pairs",
           "ms_basis", "harmonic_content",
           "stage_contact_matrix", "assemble"]


# --------------------------------------------------------------------------------------------
# real Fourier matrix and harmonic indices
# --------------------------------------------------------------------------------------------

def _column_table(nz: int):
    """(harmonic index, kind) of the columns of F_{NZ,NZ} in the order of Eq. 22."""
    rbar = nz // 2
    cols = [(0, "0")]
    even = nz % 2 == 0
    last_c = rbar - 1 if even else rbar
    cols += [(h, "c") for h in range(1, last_c + 1)]
    if even and nz > 1:
        cols.append((rbar, "n"))           # alternating (-1)^k column
    cols += [(h, "s") for h in range(last_c, 0, -1)]
    return cols


def fourier_matrix(nz: int, phi: np.ndarray | None = None) -> np.ndarray:
    """Real orthonormal Fourier matrix F_{NZ,NZ} (Eq. 21, columns ordered as Eq. 22).

    Row k samples angle phi_k = 2 pi k / NZ; passing ``phi`` (angles from the reference,
    any values) evaluates the same band-limited columns there (trigonometric interpolation).
    """
    if int(nz) != nz or nz < 1:
        raise InputError(f"fourier_matrix: NZ must be a positive integer, got {nz}")
    nz = int(nz)
    if phi is None:
        phi = 2.0 * np.pi * np.arange(nz) / nz
    phi = np.asarray(phi, dtype=float)
    F = np.empty((phi.size, nz))
    for j, (h, kind) in enumerate(_column_table(nz)):
        if kind == "0":
            F[:, j] = 1.0 / np.sqrt(nz)
        elif kind == "n":
            F[:, j] = np.cos(h * phi) / np.sqrt(nz)
        elif kind == "c":
            F[:, j] = np.sqrt(2.0 / nz) * np.cos(h * phi)
        else:
            F[:, j] = np.sqrt(2.0 / nz) * np.sin(h * phi)
    return F


def fourier_columns(nz: int, indices) -> np.ndarray:
    """Column numbers of F_{NZ,NZ} that hold the harmonic ``indices`` (0..NZ/2), Eq. 22."""
    idx = np.unique(np.asarray(indices, dtype=np.int64).ravel())
    if idx.size and (idx.min() < 0 or idx.max() > nz // 2):
        raise InputError(f"harmonic indices must lie in 0..NZ/2 = 0..{nz // 2}, got "
                         f"{idx.tolist()}")
    return np.array([j for j, (h, _) in enumerate(_column_table(nz)) if h in set(idx)],
                    dtype=np.int64)


def harmonic_indices(engine_orders, n_sectors: int, n_segments: int,
                     time_harmonics=(1,)) -> np.ndarray:
    """Spatial harmonic indices (0..NZ/2) excited by engine orders (Eq. 1).

    Time harmonic j of an EO excitation has spatial index j*EO (j = 0, the static part, has
    index 0); over a stage of N sectors it couples to every index z N +- j*EO, folded into
    0..NZ/2 (NZ = ``n_segments``, the number of radial line segments of the whole stage).
    """
    n = int(n_sectors)
    nz = int(n_segments)
    if n < 1 or nz < n or nz % n:
        raise InputError(f"harmonic_indices: NZ = {nz} must be a positive multiple of the "
                         f"sector count N = {n}")
    eos = np.atleast_1d(np.asarray(engine_orders, dtype=np.int64))
    out = set()
    for eo in eos:
        for j in np.atleast_1d(np.asarray(time_harmonics, dtype=np.int64)):
            if j < 0:
                raise InputError("harmonic_indices: time harmonics must be >= 0")
            s = (j * eo) % n
            for h in range(nz // 2 + 1):
                if h % n == s or (-h) % n == s:
                    out.add(h)
    return np.array(sorted(out), dtype=np.int64)


def stage_indices(engine_orders, sector_counts, n_segments, time_harmonics=(1,)) -> list:
    """Harmonic indices to keep on each of several coupled stages.

    Stages of N_1, N_2, ... sectors coupled together form a cyclic assembly of
    gcd(N_1, N_2, ...) sectors, so the aliasing families are taken modulo that gcd.
    n_segments: NZ of each stage. Returns one index array per stage.
    """
    counts = [int(c) for c in np.atleast_1d(sector_counts)]
    nzs = [int(c) for c in np.atleast_1d(n_segments)]
    if len(counts) != len(nzs):
        raise SizeError(f"stage_indices: {len(counts)} sector counts for {len(nzs)} stages")
    g = int(np.gcd.reduce(counts))
    return [harmonic_indices(engine_orders, g, nz, time_harmonics) for nz in nzs]


def shared_indices(engine_orders, sector_counts, n_segments: int,
                   time_harmonics=(1,)) -> np.ndarray:
    """Harmonic indices (0..NZ/2) that every stage's aliasing family shares.

    For each engine order EO and time harmonic j, stage s of N_s sectors carries the family
    z N_s +- j EO (:func:`harmonic_indices`); the indices kept are those in the families of
    all stages at once (for each (EO, j), the intersection over the stages), united over
    (EO, j). With N_1 = 50, N_2 = 60, EO 2: {2 j} (an index h = k mod N_1 and -k mod N_2
    needs 2k = 0 mod gcd = 10); with 5 and 6 sectors the Chinese remainder theorem adds the
    mixed signs, e.g. 8 = -2 mod 5 = 2 mod 6 for j = 1. n_segments: NZ, a common multiple of
    the sector counts (both faces have NZ radial line segments). This is the set that
    couples the stages on their common spatial harmonics; the exact set of the tuned
    assembly is the larger family modulo gcd(N_1, N_2) (:func:`stage_indices`).
    """
    counts = [int(c) for c in np.atleast_1d(sector_counts)]
    if not counts:
        raise SizeError("shared_indices: no sector count")
    out = set()
    for eo in np.atleast_1d(np.asarray(engine_orders, dtype=np.int64)):
        for j in np.atleast_1d(np.asarray(time_harmonics, dtype=np.int64)):
            fam = [set(harmonic_indices(eo, n, n_segments, (j,)).tolist()) for n in counts]
            out |= set.intersection(*fam)
    return np.array(sorted(out), dtype=np.int64)


_MS_LABEL = re.compile(r"\bms h=(\d+) ")


def travelling_wave_selection(labels, engine_order: int, n_sectors: int,
                              harmonics: int) -> np.ndarray:
    """Which time harmonics of each coordinate a tuned rotor's travelling wave can move.

    Under an engine-order ``engine_order`` (e) travelling wave, a rotor that is cyclically
    symmetric with ``n_sectors`` (N) sectors, contacts included, responds in a travelling
    wave: its time harmonic h lives only on the spatial indices z N +- h e (h = 0: the
    family of index 0). An MS coordinate of index p (label ``"... ms h=p ..."``, see
    :meth:`MultistageInterface.labels`) is therefore identically zero at every other
    time harmonic. Stages of different sector counts: pass N = their gcd (the assembly's
    sectors). labels: (n_dof,) the model's DoF labels; harmonics: H.

    Returns (n_dof, H+1) bool, for :class:`frirom.solver.SolverOptions` ``selection``:
    True where harmonic h of a DoF is an unknown; a DoF without an MS label (a modal or
    physical coordinate) keeps every harmonic. Raises InputError when no label is an MS
    coordinate.
    """
    n = int(n_sectors)
    e = int(engine_order)
    if n < 1:
        raise InputError(f"travelling_wave_selection: n_sectors must be >= 1, got {n}")
    sel = np.ones((len(labels), int(harmonics) + 1), dtype=bool)
    hh = np.arange(int(harmonics) + 1)
    found = False
    for i, lab in enumerate(labels):
        m = _MS_LABEL.search(str(lab))
        if m is None:
            continue
        found = True
        p = int(m.group(1))
        sel[i] = ((p - hh * e) % n == 0) | ((p + hh * e) % n == 0)
    if not found:
        raise InputError("travelling_wave_selection: no DoF is a multi-stage (MS) "
                         "coordinate (labels 'ms h=<index>'); the selection needs an MS "
                         "interface reduction")
    return sel


_MS_KIND = re.compile(r"\bms h=(\d+) ([0ncs]) ")


def travelling_wave_pairs(labels, engine_order: int, n_sectors: int,
                          harmonics: int) -> np.ndarray:
    """The direction of a tuned rotor's travelling wave: pairs of the selection's unknowns.

    The EO ``engine_order`` (e) load of sector s has the phase exp(-2 pi i e s / N)
    (:func:`frirom.reduction.cyclic.engine_order_loads`), so time harmonic h of the
    response is a wave cos(h w t - q phi) with q = h e (mod N), phi the MS angle (sectors
    numbered the way the MS angle grows). On an MS index p with cosine column c and sine
    column s (labels ``"ms h=p c ..."``, ``"ms h=p s ..."``, same stage, node and
    component), that is a(s, sin) = sigma a(c, cos) and a(s, cos) = -sigma a(c, sin), with
    sigma = +1 where p = +h e (mod N) and -1 where p = -h e: two unknowns of four. No pair
    at h = 0, for p = 0 or NZ/2 (no sine column) or where p = h e and p = -h e both hold
    (2 h e = 0 mod N: a standing wave is possible).

    Returns (n_dof, H+1) int, for :class:`frirom.solver.SolverOptions` ``pairs``:
    ``pairs[c, h] = sigma (k + 1)`` for the cosine DoF c and its sine DoF k, 0 elsewhere.
    Raises InputError when no label is an MS coordinate.
    """
    n = int(n_sectors)
    e = int(engine_order)
    travelling_wave_selection(labels, e, n, harmonics)        # the same checks
    out = np.zeros((len(labels), int(harmonics) + 1), dtype=np.int64)
    where = {str(lab): i for i, lab in enumerate(labels)}
    for i, lab in enumerate(labels):
        m = _MS_KIND.search(str(lab))
        if m is None or m.group(2) != "c":
            continue
        k = where.get(str(lab)[:m.start(2)] + "s" + str(lab)[m.end(2):])
        if k is None:
            continue
        p = int(m.group(1))
        for h in range(1, int(harmonics) + 1):
            fwd, bwd = (p - h * e) % n == 0, (p + h * e) % n == 0
            if fwd != bwd:
                out[i, h] = (1 if fwd else -1) * (k + 1)
    return out


# --------------------------------------------------------------------------------------------
# geometry: cylindrical frame and radial line segments
# --------------------------------------------------------------------------------------------

def cylindrical_frame(axis=(0.0, 0.0, 1.0), reference=None) -> np.ndarray:
    """Orthonormal rows (e1, e2, e_axis): angles are measured from e1 towards e2."""
    a = np.asarray(axis, dtype=float)
    if a.shape != (3,) or np.linalg.norm(a) == 0:
        raise InputError("cylindrical_frame: axis must be a nonzero 3-vector")
    a = a / np.linalg.norm(a)
    if reference is None:
        reference = np.eye(3)[np.argmin(np.abs(a))] if abs(a[0]) > 0.9 else np.eye(3)[0]
    e1 = np.asarray(reference, dtype=float) - np.dot(reference, a) * a
    if np.linalg.norm(e1) < 1e-12:
        raise InputError("cylindrical_frame: reference direction is parallel to the axis")
    e1 /= np.linalg.norm(e1)
    return np.vstack([e1, np.cross(a, e1), a])


@dataclass
class RadialSegments:
    """Radial line segments of a stage interface.

    nodes: (NZ, n_per) indices into the node list, segments in increasing angle from the
        first one, nodes of a segment ordered by (axial, radial) position;
    theta: (NZ,) segment angles [rad] in [theta_0, theta_0 + 2 pi);
    radius, axial: (n_per,) common positions of the nodes along every segment;
    n_sectors: N; frame: (3, 3) rows e1, e2, axis; origin: (3,) point on the axis.
    """

    nodes: np.ndarray
    theta: np.ndarray
    radius: np.ndarray
    axial: np.ndarray
    n_sectors: int
    frame: np.ndarray
    origin: np.ndarray

    @property
    def n_segments(self) -> int:
        return self.nodes.shape[0]

    @property
    def per_sector(self) -> int:
        return self.n_segments // self.n_sectors

    @property
    def equally_spaced(self) -> bool:
        d = self.theta - self.theta[0] - 2 * np.pi * np.arange(self.n_segments) / self.n_segments
        return bool(np.all(np.abs(d) * max(self.radius.max(), 1e-300) < self._tol))

    _tol: float = 0.0


def radial_line_segments(coords, n_sectors: int, origin=(0.0, 0.0, 0.0),
                         axis=(0.0, 0.0, 1.0), reference=None,
                         tol: float | None = None) -> RadialSegments:
    """Group the interface nodes of a whole stage into radial line segments.

    coords: (n_nodes, 3) global coordinates of the stage's interface nodes (all N sectors);
    tol: length tolerance [model units] on positions (default 1e-6 x the largest radius).
    Raises InputError naming the first inconsistent segment when the interface is not
    cyclically periodic with ``n_sectors`` sectors.
    """
    x = np.asarray(coords, dtype=float)
    if x.ndim != 2 or x.shape[1] != 3 or x.shape[0] == 0:
        raise SizeError(f"radial_line_segments: coords must be (n_nodes, 3), got {x.shape}")
    frame = cylindrical_frame(axis, reference)
    o = np.asarray(origin, dtype=float)
    loc = (x - o) @ frame.T
    r = np.hypot(loc[:, 0], loc[:, 1])
    ax = loc[:, 2]
    if tol is None:
        tol = 1e-6 * max(r.max(), np.abs(ax).max(), 1e-300)
    if np.any(r <= tol):
        raise InputError("radial_line_segments: interface nodes lie on the rotor axis")
    th = np.mod(np.arctan2(loc[:, 1], loc[:, 0]), 2 * np.pi)
    order = np.argsort(th)
    ths = th[order]
    # split where consecutive angles differ by more than the tolerance at that radius
    gap = np.diff(ths) * np.minimum(r[order][1:], r[order][:-1]) > tol
    starts = np.concatenate([[0], np.nonzero(gap)[0] + 1])
    groups = np.split(order, starts[1:])
    # a group straddling theta = 0 appears as the first and the last group
    if len(groups) > 1 and (ths[0] + 2 * np.pi - ths[-1]) * r[order].min() <= tol:
        groups[0] = np.concatenate([groups[-1], groups[0]])
        groups.pop()
    nz = len(groups)
    n = int(n_sectors)
    if n < 1 or nz % n:
        raise InputError(f"radial_line_segments: found {nz} radial line segments, not a "
                         f"multiple of the {n} sectors: the interface is not cyclically "
                         "periodic (or tol is too small/large)")
    seg_theta = np.array([np.angle(np.mean(np.exp(1j * th[g]))) for g in groups])
    seg_theta = np.mod(seg_theta, 2 * np.pi)
    by_angle = np.argsort(seg_theta)
    groups = [groups[k] for k in by_angle]
    seg_theta = seg_theta[by_angle]
    n_per = len(groups[0])
    nodes = np.empty((nz, n_per), dtype=np.int64)
    pos0 = None
    for k, g in enumerate(groups):
        if len(g) != n_per:
            raise InputError(f"radial_line_segments: segment {k} (angle "
                             f"{np.degrees(seg_theta[k]):.6g} deg) has {len(g)} nodes, "
                             f"segment 0 has {n_per}: not cyclically periodic")
        key = np.lexsort((np.round(r[g] / tol), np.round(ax[g] / tol)))
        g = g[key]
        pos = np.column_stack([r[g], ax[g]])
        if pos0 is None:
            pos0 = pos
        elif np.abs(pos - pos0).max() > 10 * tol:
            raise InputError(f"radial_line_segments: the nodes of segment {k} (angle "
                             f"{np.degrees(seg_theta[k]):.6g} deg) are not at the radial and "
                             "axial positions of segment 0: not cyclically periodic")
        nodes[k] = g
    z = nz // n
    dth = seg_theta[z:] - seg_theta[:-z]
    bad = np.nonzero(np.abs(dth - 2 * np.pi / n) * r.max() > 10 * tol)[0]
    if bad.size:
        k = int(bad[0])
        raise InputError(f"radial_line_segments: segments {k} and {k + z} are "
                         f"{np.degrees(dth[k]):.6g} deg apart, expected "
                         f"{360.0 / n:.6g} deg for {n} sectors: not cyclically periodic")
    seg = RadialSegments(nodes=nodes, theta=seg_theta, radius=pos0[:, 0], axial=pos0[:, 1],
                         n_sectors=n, frame=frame, origin=o)
    seg._tol = 10 * tol
    return seg


# --------------------------------------------------------------------------------------------
# the MS basis
# --------------------------------------------------------------------------------------------

@dataclass
class MultistageInterface:
    """MS basis of one stage: interface DoFs (n_i,) and basis (n_i, n_k), orthonormal.

    interface: model DoFs ordered segment by segment, node by node, x y z (Eq. 20);
    basis: Rot @ (F[:, retained] (x) I_{n_l}) with Rot the cylindrical-to-global rotation;
    indices: retained harmonic indices; columns: (harmonic index, kind, dof in segment) of
    each reduced coordinate, kind '0', 'c', 's' or 'n' (alternating).
    """

    segments: RadialSegments
    indices: np.ndarray
    interface: np.ndarray
    basis: np.ndarray
    columns: list

    def labels(self, stage: str = "") -> list:
        comp = ("r", "t", "a")
        return [f"{stage}ms h={h} {kind} node{d // 3} {comp[d % 3]}"
                for h, kind, d in self.columns]

    def evaluate(self, theta) -> np.ndarray:
        """Global displacements of a segment placed at angles ``theta`` (trig. interpolation).

        Returns (n_theta, 3*n_per, n_k): rows node-major x y z, for the retained harmonics.
        Needs equally spaced segments (angle = 2 pi k / NZ from segment 0).
        """
        seg = self.segments
        if not seg.equally_spaced:
            raise InputError("MultistageInterface.evaluate: the radial line segments are not "
                             "equally spaced; Fourier interpolation between them is undefined")
        th = np.atleast_1d(np.asarray(theta, dtype=float))
        nz = seg.n_segments
        cols = fourier_columns(nz, self.indices)
        fk = fourier_matrix(nz, th - seg.theta[0])[:, cols]          # (n_t, n_c)
        n_l = 3 * seg.nodes.shape[1]
        eye = np.eye(n_l)
        cyl = fk[:, None, :, None] * eye[None, :, None, :]           # (n_t, n_l, n_c, n_l)
        cyl = cyl.reshape(th.size, n_l, -1)
        rot = _rotations(th, seg.frame)                               # (n_t, 3, 3) cyl->glob
        npn = n_l // 3
        out = np.einsum("tij,tnjk->tnik", rot, cyl.reshape(th.size, npn, 3, -1))
        return out.reshape(th.size, n_l, -1)


def _rotations(theta, frame):
    """(n, 3, 3) columns: radial, tangential, axial unit vectors in global components."""
    c, s = np.cos(theta), np.sin(theta)
    er = c[:, None] * frame[0] + s[:, None] * frame[1]
    et = -s[:, None] * frame[0] + c[:, None] * frame[1]
    ea = np.broadcast_to(frame[2], er.shape)
    return np.stack([er, et, ea], axis=2)


def ms_basis(coords, dofs, n_sectors: int, indices, origin=(0.0, 0.0, 0.0),
             axis=(0.0, 0.0, 1.0), reference=None, tol=None) -> MultistageInterface:
    """MS interface basis of a stage.

    coords: (n_nodes, 3) interface node coordinates of the whole stage; dofs: (n_nodes, 3)
    model DoF indices of their global x, y, z displacements; indices: harmonic indices to
    keep (0..NZ/2), e.g. from :func:`harmonic_indices`. Every interface node must have its 3
    translations as model DoFs.
    """
    seg = radial_line_segments(coords, n_sectors, origin, axis, reference, tol)
    d = np.asarray(dofs, dtype=np.int64)
    if d.shape != (len(np.asarray(coords)), 3):
        raise SizeError(f"ms_basis: dofs must be (n_nodes, 3) = ({len(coords)}, 3), got "
                        f"{d.shape}")
    nz, n_per = seg.nodes.shape
    n_l = 3 * n_per
    idx = np.unique(np.asarray(indices, dtype=np.int64).ravel())
    cols = fourier_columns(nz, idx)
    if cols.size == 0:
        raise InputError("ms_basis: no harmonic index to keep")
    F = fourier_matrix(nz)[:, cols]                                   # (NZ, n_c)
    table = _column_table(nz)
    basis_cyl = np.kron(F, np.eye(n_l))                               # (NZ n_l, n_c n_l)
    # rotate each node's cylindrical components to global at its own angle
    x = np.asarray(coords, dtype=float)
    loc = (x - seg.origin) @ seg.frame.T
    th_node = np.arctan2(loc[:, 1], loc[:, 0])[seg.nodes.ravel()]     # segment-major order
    rot = _rotations(th_node, seg.frame)                              # (NZ n_per, 3, 3)
    b = basis_cyl.reshape(nz * n_per, 3, -1)
    basis = np.einsum("nij,njk->nik", rot, b).reshape(nz * n_l, -1)
    interface = d[seg.nodes.ravel()].ravel()
    if np.unique(interface).size != interface.size or interface.min() < 0:
        raise InputError("ms_basis: interface DoFs must be distinct model DoFs >= 0")
    columns = [(table[c][0], table[c][1], j) for c in cols for j in range(n_l)]
    return MultistageInterface(segments=seg, indices=idx, interface=interface, basis=basis,
                               columns=columns)


def harmonic_content(coords, values, n_sectors: int, origin=(0.0, 0.0, 0.0),
                     axis=(0.0, 0.0, 1.0), reference=None, tol=None) -> np.ndarray:
    """Energy of interface displacement fields per spatial harmonic index (Eq. 21-23).

    coords: (n_nodes, 3) interface nodes of a whole stage; values: (n_nodes, 3, n_f) global
    x y z displacements of ``n_f`` fields (e.g. the cosine and sine parts of each time
    harmonic of a forced response). The fields are rotated to cylindrical components, grouped
    in radial line segments and projected on the full real Fourier basis F_{NZ,NZ}; as F is
    orthonormal, the squared coefficients split sum |x|^2 exactly by index. Returns
    (NZ/2 + 1, n_f): energy [units^2] of harmonic index h = 0..NZ/2 in field f.
    """
    seg = radial_line_segments(coords, n_sectors, origin, axis, reference, tol)
    v = np.asarray(values, dtype=float)
    if v.ndim == 2:
        v = v[:, :, None]
    if v.shape[:2] != (len(np.asarray(coords)), 3):
        raise SizeError(f"harmonic_content: values must be (n_nodes, 3, n_f), got {v.shape}")
    nz, n_per = seg.nodes.shape
    x = np.asarray(coords, dtype=float)
    loc = (x - seg.origin) @ seg.frame.T
    th = np.arctan2(loc[:, 1], loc[:, 0])[seg.nodes.ravel()]
    rot = _rotations(th, seg.frame)                                   # cyl -> global
    cyl = np.einsum("nji,njf->nif", rot, v[seg.nodes.ravel()])        # (NZ n_per, 3, n_f)
    cyl = cyl.reshape(nz, 3 * n_per, -1)
    a = np.einsum("kc,klf->clf", fourier_matrix(nz), cyl)             # (NZ, n_l, n_f)
    e = np.sum(a ** 2, axis=1)
    out = np.zeros((nz // 2 + 1, e.shape[1]))
    for j, (h, _) in enumerate(_column_table(nz)):
        out[h] += e[j]
    return out


# --------------------------------------------------------------------------------------------
# coupling stages
# --------------------------------------------------------------------------------------------

def assemble(parts) -> InterfaceReduction:
    """Block-diagonal assembly of reduced stages (no coupling: contacts couple them).

    parts: InterfaceReduction objects; the assembled R maps to the stacked physical DoFs of
    the parts in the given order; ``kept``/``interface`` are offset accordingly.
    """
    K = block_diag(*[p.K for p in parts])
    M = block_diag(*[p.M for p in parts])
    R = sp.block_diag([p.R for p in parts]).tocsr()
    offs = np.cumsum([0] + [p.R.shape[0] for p in parts])
    inter = np.concatenate([p.interface + o for p, o in zip(parts, offs)])
    kept = np.concatenate([p.kept + o for p, o in zip(parts, offs)])
    basis = sp.block_diag([p.basis for p in parts]).toarray()
    labels = sum([[f"stage{j + 1} {s}" for s in p.labels] for j, p in enumerate(parts)], [])
    return InterfaceReduction(K=K, M=M, R=R, interface=inter, basis=basis, kept=kept,
                              labels=labels)


def stage_contact_matrix(stage_a: MultistageInterface, stage_b: MultistageInterface,
                         frames, n_red_a: int, n_red_b: int, offset_b: int | None = None,
                         tol=None) -> sp.csr_matrix:
    """Contact map between two MS-reduced stages with non-matching interface meshes.

    One contact element per interface node of stage A; its side B is the point of stage B
    at the same angle and at the same (radial, axial) position along the segment, whose
    displacement is the Fourier series of stage B's retained harmonics evaluated there
    (both sides on common spatial harmonics). Stage B's segments must be equally spaced and
    carry the same (radial, axial) positions as stage A's (within tol).

    frames: (n_elem, n_dir, 3) local directions per element (elements ordered as
    stage_a.interface nodes, i.e. segment by segment); n_red_a, n_red_b: sizes of the two
    reduced models (interface modes first, as :func:`reduce_interface` orders them), stacked
    as in :func:`assemble`. Returns G (n_elem*n_dir, n_red_a + n_red_b).
    """
    sa, sb = stage_a.segments, stage_b.segments
    fr = np.asarray(frames, dtype=float)
    nz_a, np_a = sa.nodes.shape
    n_elem = nz_a * np_a
    if fr.ndim != 3 or fr.shape[0] != n_elem or fr.shape[2] != 3:
        raise SizeError(f"stage_contact_matrix: frames must be (n_elem={n_elem}, n_dir, 3), "
                        f"got {fr.shape}")
    if not np.allclose(sa.frame[2], sb.frame[2]) or not np.allclose(sa.origin, sb.origin):
        raise InputError("stage_contact_matrix: the stages must share the rotor axis")
    if tol is None:
        tol = max(sa._tol, sb._tol)
    # position of each A node along B's segments
    match = np.empty(np_a, dtype=np.int64)
    for p in range(np_a):
        d = np.hypot(sb.radius - sa.radius[p], sb.axial - sa.axial[p])
        q = int(np.argmin(d))
        if d[q] > tol:
            raise InputError(f"stage_contact_matrix: stage A segment node {p} at radius "
                             f"{sa.radius[p]:.6g}, axial {sa.axial[p]:.6g} has no stage B "
                             "node at the same position")
        match[p] = q
    n_dir = fr.shape[1]
    # angle of stage A's segments, measured in stage B's reference frame
    ref_b = np.arctan2(np.dot(sa.frame[1], sb.frame[0]), np.dot(sa.frame[0], sb.frame[0]))
    th_a = sa.theta - ref_b
    ev_b = stage_b.evaluate(th_a)                                     # (nz_a, 3 np_b, n_kb)
    ba = stage_a.basis.reshape(nz_a, np_a, 3, -1)
    eb = ev_b.reshape(nz_a, -1, 3, ev_b.shape[2])[:, match]           # (nz_a, np_a, 3, n_kb)
    fr4 = fr.reshape(nz_a, np_a, n_dir, 3)
    ga = np.einsum("spdc,spck->spdk", fr4, ba).reshape(n_elem * n_dir, -1)
    gb = np.einsum("spdc,spck->spdk", fr4, eb).reshape(n_elem * n_dir, -1)
    n_ka, n_kb = ga.shape[1], gb.shape[1]
    if offset_b is None:
        offset_b = n_red_a
    G = np.zeros((n_elem * n_dir, n_red_a + n_red_b))
    G[:, :n_ka] = ga
    G[:, offset_b:offset_b + n_kb] -= gb
    return sp.csr_matrix(G)
