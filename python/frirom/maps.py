"""Interface maps and ParaView export of a point of an FE deck's forced response.

A contact group built from node sets ([[contacts]] with ``a`` and ``b``) has one element
per node pair; its fields (stick/slip/lift-off fraction, dissipated energy, peak normal
force, slip amplitude: :class:`frirom.show.ContactField`) are drawn on the coordinates of
the pairs' side-a nodes, projected on the contact face's plane (its two principal
directions): a 2-D map of the face. :func:`figure_curve_maps` follows the pairs along the
curve; :func:`write_vtk` writes the kept nodes' deformed shape and the contact fields to a
VTK file (meshio) for ParaView.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ._errors import InputError
from .results import _series

__all__ = ["pair_nodes", "face_axes", "figure_maps", "figure_curve_maps", "curve_indices",
           "write_vtk"]

#: (field, title, colour map) of the map panels
_FIELDS = (("stick", "stick fraction", "Blues"), ("slip", "slip fraction", "Oranges"),
           ("liftoff", "lift-off fraction", "Reds"), ("energy", "energy / period [J]",
                                                      "magma_r"),
           ("fn_max", "peak normal force [N]", "viridis"),
           ("slip_amp", "slip amplitude [m]", "cividis"))


def _values(c, name: str) -> np.ndarray:
    """(n_elem,) one field of a ContactField."""
    k = {"stick": 0, "slip": 1, "liftoff": 2}.get(name)
    if k is not None:
        return c.states[:, k]
    return {"energy": c.energy, "fn_max": c.fn_max, "slip_amp": c.slip}[name]


def pair_nodes(deck, name: str) -> tuple[np.ndarray, np.ndarray]:
    """(node ids (n_elem,), coordinates (n_elem, 3)) of the side-a nodes of a node-set
    contact of an FE deck, in element order."""
    rom = deck.reduced
    if rom is None or name not in rom.pairs:
        raise InputError(f"contact {name!r}: interface maps need an FE deck ([fe_model]) "
                         "whose contact is given by node sets")
    dofs_a = np.asarray(rom.pairs[name].dofs_a)
    nodes = np.asarray(rom.fe_dofs)[dofs_a[:, 0], 0]
    return nodes, rom.coordinates(nodes)


def face_axes(xyz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(2-D coordinates (n, 2), axes (2, 3)) of points on a face: the two global axes in
    its plane when its normal (least principal direction of the points) is a global axis,
    else its projection on its two principal directions (centred)."""
    c = xyz - xyz.mean(axis=0)
    _, _, vt = np.linalg.svd(c, full_matrices=False) if len(xyz) > 2 else (0, 0, np.eye(3))
    normal = vt[-1] if len(vt) == 3 else np.cross(vt[0], vt[1])
    k = int(np.argmax(np.abs(normal)))
    if abs(normal[k]) > 0.99:
        ax = np.delete(np.eye(3), k, axis=0)
        return xyz @ ax.T, ax
    ax = vt[:2]
    for i in range(2):          # the largest component positive: stable orientation
        if ax[i, np.argmax(np.abs(ax[i]))] < 0:
            ax[i] = -ax[i]
    return c @ ax.T, ax


def _axis_label(v: np.ndarray) -> str:
    names = {(1.0, 0.0, 0.0): "x", (0.0, 1.0, 0.0): "y", (0.0, 0.0, 1.0): "z"}
    name = names.get(tuple(float(a) for a in v))
    return (f"{name} [mm]" if name else
            "along [" + ", ".join(f"{a:.2g}" for a in v) + "] [mm]")


def _marker_size(uv: np.ndarray, inches: float = 2.6) -> float:
    """Scatter size (points^2) of squares that about tile points spaced as uv's nearest
    neighbours on an axes `inches` wide."""
    if len(uv) < 2:
        return 40.0
    from scipy.spatial import cKDTree
    d = cKDTree(uv).query(uv, k=2)[0][:, 1]
    span = max(float(np.ptp(uv, axis=0).max()), 1e-300)
    return float((0.7 * np.median(d) / span * inches * 72.0) ** 2)


def figure_maps(state, deck) -> Figure:
    """Per contact group, six maps of its face at one point: stick, slip, lift-off
    fraction, dissipated energy, peak normal force, slip amplitude per pair."""
    groups = [c for c in state.contacts if deck.reduced is not None
              and c.name in deck.reduced.pairs]
    if not groups:
        raise InputError("interface maps need an FE deck ([fe_model]) with node-set contacts")
    fig = Figure(figsize=(11.0, 0.6 + 6.2 * len(groups)), dpi=110)
    axes = fig.subplots(2 * len(groups), 3, squeeze=False)
    for gi, c in enumerate(groups):
        _, xyz = pair_nodes(deck, c.name)
        uv, ax2 = face_axes(xyz)
        size = _marker_size(uv)
        for k, (name, title, cmap) in enumerate(_FIELDS):
            ax = axes[2 * gi + k // 3, k % 3]
            v = _values(c, name)
            lim = (0.0, 1.0) if k < 3 else (None, None)
            sc = ax.scatter(uv[:, 0] * 1e3, uv[:, 1] * 1e3, c=v, s=size, marker="s",
                            cmap=cmap, vmin=lim[0], vmax=lim[1], edgecolors="none")
            fig.colorbar(sc, ax=ax, shrink=0.85)
            ax.set_aspect("equal", adjustable="datalim")
            ax.set_title(f"{c.name}: {title}", fontsize=9)
            ax.set_xlabel(_axis_label(ax2[0]), fontsize=7)
            ax.set_ylabel(_axis_label(ax2[1]), fontsize=7)
            ax.tick_params(labelsize=7)
    fig.suptitle(f"Contact interface at {state.frequency_hz:.6g} Hz", fontsize=11)
    fig.tight_layout()
    return fig


def _bins(y: np.ndarray, n_max: int = 30) -> tuple[np.ndarray, np.ndarray]:
    """(bin of each value (n,), bin edges) of positions y: one bin per distinct position
    (to 1e-6 of their range), or n_max equal bins when there are more."""
    span = float(np.ptp(y)) or 1.0
    u = np.unique(np.round(y / (1e-6 * span)))
    if u.size <= n_max:
        centres = u * 1e-6 * span
        mid = (centres[1:] + centres[:-1]) / 2
        half = (np.diff(centres).min() / 2) if centres.size > 1 else 0.5 * span
        edges = np.r_[centres[0] - half, mid, centres[-1] + half]
    else:
        edges = np.linspace(y.min(), y.max(), n_max + 1)
    idx = np.clip(np.searchsorted(edges, y, side="right") - 1, 0, edges.size - 2)
    return idx, edges


def curve_indices(frf, n: int) -> np.ndarray:
    """About n stored points evenly spread in frequency over the curve (the nearest to n
    equally spaced frequencies, and the largest first output's point)."""
    w = np.asarray(frf.omega, float)
    target = np.linspace(w.min(), w.max(), max(n, 2))
    idx = np.abs(w[None, :] - target[:, None]).argmin(axis=1)
    return np.unique(np.r_[idx, int(np.argmax(frf.amp_max[:, 0]))])


def figure_curve_maps(states, deck, unit_scale: float = 1.0 / (2 * np.pi)) -> Figure:
    """Slip fraction, lift-off fraction and dissipated energy of the pairs along the
    curve: x the frequency of each point (Hz, a column per point), y the position along
    the face's first axis (pairs at one position averaged)."""
    if not states:
        raise InputError("no point to draw along the curve")
    names = [c.name for c in states[0].contacts
             if deck.reduced is not None and c.name in deck.reduced.pairs]
    if not names:
        raise InputError("interface maps need an FE deck ([fe_model]) with node-set contacts")
    fields = (("slip", "slip fraction", "Oranges"), ("liftoff", "lift-off fraction", "Reds"),
              ("energy", "energy / period [J]", "magma_r"))
    f = np.array([s.omega * unit_scale for s in states])
    order = np.argsort(f, kind="stable")
    fs = f[order]
    mid = (fs[1:] + fs[:-1]) / 2
    lo = np.r_[fs[0] - (mid[0] - fs[0] if fs.size > 1 else 0.5), mid]
    hi = np.r_[mid, fs[-1] + (fs[-1] - mid[-1] if fs.size > 1 else 0.5)]
    fig = Figure(figsize=(10.5, 0.8 + 3.0 * len(names)), dpi=110)
    axes = fig.subplots(len(names), 3, squeeze=False)
    for gi, name in enumerate(names):
        _, xyz = pair_nodes(deck, name)
        uv, ax2 = face_axes(xyz)
        b, edges = _bins(uv[:, 0])
        count = np.bincount(b, minlength=edges.size - 1)
        for k, (fld, title, cmap) in enumerate(fields):
            ax = axes[gi, k]
            vals = np.array([np.bincount(b, _values(next(c for c in s.contacts
                                                          if c.name == name), fld),
                                         minlength=edges.size - 1) / np.maximum(count, 1)
                             for s in states])[order]
            lim = (0.0, 1.0) if k < 2 else (0.0, max(float(vals.max()), 1e-300))
            for j in range(fs.size):
                qm = ax.pcolormesh([lo[j], hi[j]], edges * 1e3, vals[j][:, None],
                                   cmap=cmap, vmin=lim[0], vmax=lim[1], shading="flat")
            fig.colorbar(qm, ax=ax, shrink=0.85)
            ax.set_title(f"{name}: {title}", fontsize=9)
            ax.set_xlabel("frequency [Hz]", fontsize=8)
            ax.set_ylabel("position " + _axis_label(ax2[0]), fontsize=7)
            ax.tick_params(labelsize=7)
    fig.suptitle("Contact pairs along the curve (mean over the pairs at a position)",
                 fontsize=11)
    fig.tight_layout()
    return fig


def write_vtk(state, deck, path, n_frames: int = 0) -> list:
    """Write the kept nodes of an FE deck (interface, active and cyclic-boundary sets)
    with their response and the contact fields to a VTK unstructured grid (meshio).

    Point data: ``h1_real``, ``h1_imag`` (3-vectors, m: the first harmonic a1 - i b1),
    ``amp_max`` (3-vector, per direction, m), ``displacement`` (3-vector, m, at the time
    the first output peaks: warp by it in ParaView); on the side-a node of each contact
    pair ``<group>_<field>`` for the fields of :func:`figure_maps` (NaN elsewhere).
    n_frames > 0 also writes that many frames of the period (``path`` with ``_kNNN``).
    Returns the paths written.
    """
    from ._optional import require
    from .results import amplitude_max
    meshio = require("meshio", "vtk", "frirom show --vtk (ParaView output)")
    rom = deck.reduced
    if rom is None or rom.node_ids.size == 0:
        raise InputError("VTK export needs an FE deck ([fe_model]) with node coordinates "
                         "(an .inp)")
    nodes, xyz = np.asarray(rom.node_ids), np.asarray(rom.node_xyz, float)
    x = state.x
    disp = np.zeros((nodes.size, 3, x.shape[1]))
    fe = {(int(a), int(d)): i for i, (a, d) in enumerate(np.asarray(rom.fe_dofs))}
    for j, nd in enumerate(nodes):
        for d in range(3):
            i = fe.get((int(nd), d + 1))
            if i is not None:
                row = rom.T[i]
                row = np.asarray(row.toarray()).ravel() if hasattr(row, "toarray") else row
                disp[j, d] = row @ x
    _, t_peak = amplitude_max(state.outputs[:1], return_time=True)
    t_peak = float(np.ravel(t_peak)[0])
    pdata = {"h1_real": disp[:, :, 1], "h1_imag": -disp[:, :, 2],
             "amp_max": amplitude_max(disp),
             "displacement": _series(disp.reshape(-1, x.shape[1]),
                                     np.array([t_peak]))[0].reshape(-1, 3)}
    pos = {int(nd): j for j, nd in enumerate(nodes)}
    for c in state.contacts:
        if c.name not in rom.pairs:
            continue
        ids, _ = pair_nodes(deck, c.name)
        rows = np.array([pos.get(int(i), -1) for i in ids])
        for fld, _, _ in _FIELDS:
            v = np.full(nodes.size, np.nan)
            v[rows[rows >= 0]] = _values(c, fld)[rows >= 0]
            pdata[f"{c.name}_{fld}"] = v
    cells = [("vertex", np.arange(nodes.size).reshape(-1, 1))]
    path = Path(path)
    meshio.write(path, meshio.Mesh(xyz, cells, point_data=pdata))
    written = [path]
    for k in range(n_frames):
        tk = np.array([2.0 * np.pi * k / n_frames])
        d = _series(disp.reshape(-1, x.shape[1]), tk)[0].reshape(-1, 3)
        p = path.with_name(f"{path.stem}_k{k:03d}{path.suffix}")
        meshio.write(p, meshio.Mesh(xyz, cells, point_data={**pdata, "displacement": d}))
        written.append(p)
    return written
