"""Files and figures of a nonlinear mode's backbone (frirom.nonlinear_modes.Backbone):
backbone.h5 (every array, the run's state and the checkpoint a resume continues from),
backbone.csv (one row per point) and backbone.png (frequency and damping ratio against
the modal amplitude and against the amplitude at an output DoF).

The HDF5 file is written whole after every segment into a temporary file that then
replaces it, so a run cut short leaves the last complete file.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ._errors import InputError
from .nonlinear_modes import _POINT_FIELDS, Backbone

__all__ = ["save_h5", "load_h5", "save_csv", "plot_backbone"]

_SCALARS = ("mode", "start", "omega0", "H", "status", "message")


def save_h5(bb: Backbone, path, attrs: dict | None = None) -> None:
    """Write bb (and attrs, e.g. the deck's fingerprint) to path, atomically."""
    import h5py
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    with h5py.File(tmp, "w") as f:
        for name in _POINT_FIELDS + ("output_dofs", "harmonic_dofs"):
            v = getattr(bb, name)
            if v is not None:
                f.create_dataset(name, data=np.asarray(v))
        f.create_dataset("frequency_hz", data=bb.frequency)
        f.create_dataset("damping_ratio", data=bb.damping_ratio)
        for name in _SCALARS:
            f.attrs[name] = getattr(bb, name)
        f.attrs["lscale"] = bb.lscale
        if bb.nodal_diameter is not None:
            f.attrs["nodal_diameter"] = int(bb.nodal_diameter)
        for k, v in (attrs or {}).items():
            f.attrs[k] = v
    os.replace(tmp, path)


def load_h5(path) -> tuple[Backbone, dict]:
    """The Backbone of save_h5's file and its extra attributes."""
    import h5py
    try:
        with h5py.File(path, "r") as f:
            arrays = {k: f[k][()] for k in _POINT_FIELDS + ("output_dofs", "harmonic_dofs")
                      if k in f}
            attrs = {k: f.attrs[k] for k in f.attrs}
    except OSError as exc:
        raise InputError(f"{path}: cannot be read as a backbone file ({exc})") from None
    kw = {k: attrs.pop(k) for k in _SCALARS}
    kw["lscale"] = float(attrs.pop("lscale", 0.0))
    if "nodal_diameter" in attrs:
        kw["nodal_diameter"] = int(attrs.pop("nodal_diameter"))
    for k in ("start", "status", "message"):
        kw[k] = kw[k].decode() if isinstance(kw[k], bytes) else str(kw[k])
    kw["mode"], kw["H"], kw["omega0"] = int(kw["mode"]), int(kw["H"]), float(kw["omega0"])
    return Backbone(**arrays, **kw), attrs


def save_csv(bb: Backbone, path, output_names=None) -> None:
    """One row per point: modal amplitude, frequency (Hz), damping ratio, energy per cycle
    (J), mean slip fraction of the contact elements, harmonic-1 amplitude per output."""
    names = list(output_names or [f"output{j}" for j in range(bb.outputs.shape[1])])
    header = ["amplitude", "frequency_hz", "damping_ratio", "energy_per_cycle_J",
              "slip_fraction"] + [f"amp_{n}" for n in names]
    np.savetxt(path, bb.table(), delimiter=",", header=",".join(header), comments="",
               fmt="%.12g")


def plot_backbone(bb: Backbone, output: int = 0, output_name: str | None = None,
                  title: str | None = None) -> Figure:
    """Frequency (Hz) and damping ratio against the modal amplitude (top) and against the
    harmonic-1 amplitude at output `output` (bottom), log amplitude axes."""
    fig = Figure(figsize=(9.0, 6.4), dpi=130, layout="constrained")
    axs = fig.subplots(2, 2)
    xs = [(bb.amplitude, "modal amplitude a [sqrt(kg) m]")]
    if bb.outputs.shape[1] > output:
        xs.append((bb.output_amplitude(output), f"amplitude at {output_name or output} "
                   "(harmonic 1) [m]"))
    for row, (x, label) in enumerate(xs):
        ax_f, ax_d = axs[row]
        ax_f.semilogx(x, bb.frequency, "-o", ms=2.5)
        ax_f.set_ylabel("frequency [Hz]")
        ax_d.semilogx(x, 100 * bb.damping_ratio, "-o", ms=2.5, color="C3")
        ax_d.set_ylabel("damping ratio [%]")
        for ax in (ax_f, ax_d):
            ax.set_xlabel(label)
            ax.grid(True, which="both", alpha=0.3)
    if len(xs) == 1:
        for ax in axs[1]:
            ax.set_visible(False)
    fig.suptitle(title or f"Nonlinear mode {bb.mode + 1} ({bb.start} start): backbone")
    return fig
