"""Forced response results: the FRF object, its HDF5/CSV files, and an appending HDF5
writer for long runs that can be reopened to resume."""

from __future__ import annotations

import contextlib
import csv
import functools
import os
import signal
import threading
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import _h5check, _kernels
from ._errors import CODES, InputError, SizeError, raise_for_status

_NONFINITE = CODES["FRIROM_ERR_NONFINITE"]


def _series(X: np.ndarray, t: np.ndarray) -> tuple:
    """x, x' and x'' of the real Fourier series X (rows, 2H+1) at the times t (rows, m)
    (rad, one period = 2 pi): three (rows, m) arrays."""
    h = np.arange(1, (X.shape[-1] - 1) // 2 + 1)
    ht = h * t[..., None]                             # (rows, m, H)
    c, s = np.cos(ht), np.sin(ht)
    a, b = X[:, None, 1::2], X[:, None, 2::2]         # (rows, 1, H)
    even, odd = a * c + b * s, b * c - a * s          # d/dt (a cos + b sin) = h (b cos - a sin)
    return (X[:, None, 0] + even.sum(axis=-1), (h * odd).sum(axis=-1),
            -(h * h * even).sum(axis=-1))


def amplitude_max(X: np.ndarray, return_time: bool = False):
    """max over one period of |x(t)| for real harmonic coefficients X (..., 2H+1).

    x(t) = a0 + sum_h a_h cos(h t) + b_h sin(h t) is a trigonometric polynomial of degree H:
    its extrema are roots of x'(t), which times (1 + u^2)^d is a real polynomial of degree
    2d in u = tan(t / 2) (d: the effective degree, the highest harmonic above round-off).
    Its roots (companion-matrix eigenvalues) give candidate times t = 2 atan(u), also
    polished by a Newton step on x'; |x| is evaluated there and at 2(2H+1) equally spaced
    times (t = pi among them), and the largest value is kept. Every candidate is a real
    time, so the result never exceeds the true maximum, and it equals it to round-off
    (complex roots only add harmless candidates). The algorithm is the Fortran library's
    (fortran/frirom_peak.f90), the one the C API and frirom_solve report.

    Parameters
    ----------
    X : ndarray (..., 2H+1)
        Real harmonics [a0, a1, b1, ..., aH, bH] (any unit).
    return_time : bool
        Also return where the maximum is reached.

    Returns
    -------
    amp : ndarray (...)
        max_t |x(t)|, the unit of X; NaN where X has a NaN or Inf.
    t : ndarray (...), only with return_time
        A time of the maximum, rad in [0, 2 pi) (phase of the fundamental).
    """
    X = np.asarray(X, dtype=float)
    if X.ndim == 0 or X.shape[-1] % 2 != 1:
        raise SizeError(f"amplitude_max: X must be (..., 2H+1) harmonics, got shape {X.shape}")
    lead, nc = X.shape[:-1], X.shape[-1]
    Xf = np.ascontiguousarray(X.reshape(-1, nc))
    if Xf.shape[0] == 0:
        amp = t = np.zeros(lead)
    else:
        # a C-ordered (rows, 2H+1) array is the Fortran (2H+1, rows) one: no copy
        amp, t, info, msg = _kernels.peak_amplitudes(Xf.T)
        if info not in (0, _NONFINITE):            # a non-finite row: NaN, not an error
            raise_for_status(info, msg.decode(errors="replace"))
        amp, t = amp.reshape(lead), t.reshape(lead)
    return (amp, t) if return_time else amp


def harmonic_table(X: np.ndarray) -> tuple:
    """Amplitude and phase of each harmonic of real coefficients X (..., 2H+1).

    x(t) = a0 + sum_h A_h cos(h omega t + phi_h): A_h = hypot(a_h, b_h),
    phi_h = atan2(-b_h, a_h) (rad), the angle of the complex amplitude a_h - i b_h.

    Returns
    -------
    amplitude : ndarray (..., H+1)
        [a0 (the mean, signed), A_1, ..., A_H], the unit of X.
    phase : ndarray (..., H+1)
        [0, phi_1, ..., phi_H], rad in (-pi, pi].
    """
    X = np.asarray(X, float)
    amp = np.concatenate([X[..., :1], np.hypot(X[..., 1::2], X[..., 2::2])], axis=-1)
    ph = np.concatenate([np.zeros_like(X[..., :1]), np.arctan2(-X[..., 2::2], X[..., 1::2])],
                        axis=-1)
    return amp, ph


def output_columns(labels: list, H: int) -> list:
    """CSV column names of the outputs: per output its true peak over the period, its mean
    and the amplitude and phase (deg) of each harmonic."""
    head = []
    for lab in labels:
        head += [f"{lab} amp_max", f"{lab} h0"]
        for h in range(1, H + 1):
            head += [f"{lab} h{h} amp", f"{lab} h{h} phase_deg"]
    return head


def output_values(X: np.ndarray, amp_max: np.ndarray) -> list:
    """One CSV row's output values (X (n_out, 2H+1), amp_max (n_out,)), as output_columns."""
    amp, ph = harmonic_table(X)
    row = []
    for j in range(X.shape[0]):
        row += [repr(float(amp_max[j])), repr(float(amp[j, 0]))]
        for h in range(1, amp.shape[1]):
            row += [repr(float(amp[j, h])), f"{np.degrees(ph[j, h]):.6f}"]
    return row


#: attributes of a result file saying how it was made (FRF.meta); method: "snmt" for a
#: forced response synthesised from a nonlinear mode (frirom.nlm_synthesis)
META_KEYS = ("deck_path", "deck_text", "solver_settings", "model_fingerprint",
             "frirom_version", "method")


@dataclass
class FRFPoint:
    """One converged point of a continuation run (what `sink` receives)."""

    omega: float            #: excitation frequency, rad/s
    parameter: float        #: continuation parameter (omega, or the load factor)
    unknowns: np.ndarray    #: (n_unknowns,) solver unknowns (formulation dependent)
    tangent: np.ndarray     #: (n_unknowns+1,) unit tangent in scaled variables
    X: np.ndarray           #: (n_out, 2H+1) harmonics at the output DoFs
    amp_max: np.ndarray     #: (n_out,) max over the period of |x(t)|
    state_fractions: np.ndarray  #: (n_groups, 3) stick, slip, lift-off
    iterations: int
    time_s: float
    fold: bool = False
    stable: bool = True
    floquet_max_re: float = 0.0  #: largest real part of the Floquet exponents, 1/s
    yscale: float = 0.0     #: scale of the unknowns in the arc length the tangent refers to
    #: (n_slider_total,) contact history this point leaves: the slider each element's closed
    #: cycle starts with, groups concatenated, (n_elem, n_slider) row-major per group (the
    #: w0 a run restarted from this point needs; a contact stuck all cycle keeps it).
    #: With SolverOptions(history=False) it is the w0 every point started from.
    slider: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: arc-length step the run continues with after this point when the point ends a call
    #: into Fortran (a checkpoint: resuming there repeats the uninterrupted run exactly);
    #: NaN for the other points
    ds_next: float = float("nan")
    #: at a checkpoint, the state of the LU the solver holds (frirom._run.Run.lu_state):
    #: a resumed run makes it again and continues bit for bit; None elsewhere
    held_lu: np.ndarray | None = None
    #: travelling-wave selection (SolverOptions.selection): |contact forces off the
    #: selection| / |on it| at this point (or the preloads' own, if larger); None without one
    leak: float | None = None


@dataclass
class Peak:
    """Largest amplitude of one output over an FRF (:meth:`FRF.peak`)."""

    omega: float        #: rad/s
    amplitude: float    #: max over the period of |x(t)|, the unit of X
    index: int          #: the point it was found at or next to (method 'solve': the
                        #: candidate point whose neighbours bracket it)
    #: how it was found: 'point' (the largest point itself), 'parabola' (through it and its
    #: neighbours, in chord length), 'solve' (solved on the curve between its neighbours)
    method: str = "point"


@dataclass
class FRF:
    """Frequency (or load) response at the output DoFs.

    omega (n_pts,) rad/s; parameter (n_pts,) the continuation parameter; X (n_pts, n_out,
    2H+1) real harmonic coefficients [a0, a1, b1, ...]; amp_max (n_pts, n_out);
    state_fractions (n_pts, n_groups, 3) stick/slip/lift-off; stable, fold (n_pts,) bool;
    iterations (n_pts,) int; time_s (n_pts,) s; slider (n_pts, n_slider_total) the contact
    history each point leaves (FRFPoint.slider; None in files written before it was kept).
    """

    omega: np.ndarray
    X: np.ndarray
    amp_max: np.ndarray
    state_fractions: np.ndarray
    stable: np.ndarray
    fold: np.ndarray
    iterations: np.ndarray
    time_s: np.ndarray
    parameter: np.ndarray | None = None
    output_dofs: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    group_names: list = field(default_factory=list)
    parameter_name: str = "omega"
    complete: bool = True
    message: str = ""
    stability_computed: bool = False
    slider: np.ndarray | None = None
    #: Fortran time split of the run: aft, assembly, factorization, solve, receptance (s),
    #: evaluations, factorizations, krylov_iterations, double_factorizations (counts),
    #: hill (s, Hill's method: the cost of stability), fortran_total (s)
    timings: dict = field(default_factory=dict)
    #: (n_out,) Peak per output solved on the curve by the solver (None: not computed)
    peaks: list | None = None
    #: how the system was solved: formulation, unknowns, receptance route (the solver's
    #: choice, printed by ``frirom run``)
    solver_info: str = ""
    #: (n_out,) the outputs as the deck names them ("ACTIVE:z", "1234:UX"); default
    #: "dof<j>" from output_dofs
    output_labels: list = field(default_factory=list)
    #: (n_pts, n_unknowns) the solver unknowns of each point (what ``frirom show``
    #: restarts from; None when not kept)
    unknowns: np.ndarray | None = None
    #: how the result was made: META_KEYS (deck text, solver settings as JSON, reduced
    #: model's fingerprint, frirom version), strings
    meta: dict = field(default_factory=dict)
    #: (n_pts,) FRFPoint.leak of each point (None without a travelling-wave selection; NaN
    #: for points a resumed run's file held from before the leak was kept)
    leak: np.ndarray | None = None
    #: bifurcations of the curve (frirom._bifurcation.Bifurcation: folds located on it, stability
    #: changes away from folds); None when not searched
    bifurcations: list | None = None

    @property
    def labels(self) -> list:
        """(n_out,) output names: output_labels, or dof<j> (j = -1: a recovered DoF)."""
        if len(self.output_labels) == self.X.shape[1]:
            return list(self.output_labels)
        return [f"dof{d}" for d in self.output_dofs][:self.X.shape[1]] or \
            [f"output {j}" for j in range(self.X.shape[1])]

    @property
    def frequency_hz(self) -> np.ndarray:
        """(n_pts,) excitation frequency, Hz."""
        return np.asarray(self.omega, float) / (2.0 * np.pi)

    @property
    def harmonics(self) -> int:
        return (self.X.shape[-1] - 1) // 2

    def peak(self, output: int = 0) -> Peak:
        """The largest amplitude of one output over the curve, refined between points.

        The solver's peak (``peaks``, solved on the curve) when there is one; otherwise the
        point of largest ``amp_max`` and its two neighbours joined by a parabola in omega
        (in the chord length of the curve, omega / frequency span and amplitude / largest
        amplitude, when the three straddle a fold): its vertex gives the amplitude, the
        parabola through the three frequencies the frequency. A maximum at an end of the
        curve is the point itself.

        Parameters
        ----------
        output : int
            Column of ``amp_max`` (position in ``output_dofs``).

        Returns
        -------
        Peak
            omega (rad/s), amplitude (unit of X), index of the largest point, method.
        """
        if len(self) == 0:
            raise InputError("FRF.peak: the curve has no points")
        if not -self.amp_max.shape[1] <= output < self.amp_max.shape[1]:
            raise InputError(f"FRF.peak: output {output} out of range "
                             f"({self.amp_max.shape[1]} outputs)")
        if self.peaks is not None:
            return self.peaks[output]
        a = np.asarray(self.amp_max[:, output], float)
        w = np.asarray(self.omega, float)
        i = int(np.argmax(a))
        if not 0 < i < len(a) - 1 or a[i] <= 0:
            return Peak(float(w[i]), float(a[i]), i)
        ww, aa = w[i - 1:i + 2], a[i - 1:i + 2]
        if (ww[1] - ww[0]) * (ww[2] - ww[1]) > 0:
            s = ww                      # frequency increases (or decreases) through i
        else:                           # a fold next to i: chord length of the curve
            span = (w.max() - w.min()) or 1.0
            s = np.r_[0.0, np.cumsum(np.hypot(np.diff(ww) / span, np.diff(aa) / a[i]))]
        ca = np.polyfit(s - s[1], aa, 2)
        if not ca[0] < 0:
            return Peak(float(w[i]), float(a[i]), i)
        sv = min(max(-ca[1] / (2 * ca[0]), s[0] - s[1]), s[2] - s[1])
        cw = np.polyfit(s - s[1], ww, 2)
        return Peak(float(np.polyval(cw, sv)), max(float(np.polyval(ca, sv)), float(a[i])),
                    i, "parabola")

    def __len__(self) -> int:
        return self.omega.size

    @classmethod
    def from_points(cls, points: list, output_dofs, group_names, parameter_name="omega",
                    **kw) -> "FRF":
        def stack(name, shape_tail, dtype=float):
            if not points:
                return np.zeros((0,) + shape_tail, dtype=dtype)
            return np.array([getattr(p, name) for p in points], dtype=dtype)
        n_out = len(output_dofs)
        nc = points[0].X.shape[1] if points else 1
        return cls(omega=stack("omega", ()), parameter=stack("parameter", ()),
                   X=stack("X", (n_out, nc)), amp_max=stack("amp_max", (n_out,)),
                   state_fractions=stack("state_fractions", (len(group_names), 3)),
                   stable=stack("stable", (), bool), fold=stack("fold", (), bool),
                   iterations=stack("iterations", (), int), time_s=stack("time_s", ()),
                   leak=(stack("leak", ()) if points and all(p.leak is not None
                                                             for p in points) else None),
                   slider=(np.array([p.slider for p in points], dtype=float) if points
                           else np.zeros((0, 0))),
                   unknowns=(np.array([p.unknowns for p in points], dtype=float)
                             if points else None),
                   output_dofs=np.asarray(output_dofs, dtype=int),
                   group_names=list(group_names), parameter_name=parameter_name, **kw)

    # ---- files ------------------------------------------------------------------------
    _ARRAYS = ("omega", "parameter", "X", "amp_max", "state_fractions", "stable", "fold",
               "iterations", "time_s", "output_dofs")

    def save_h5(self, path) -> None:
        """Write every array and the run status to an HDF5 file."""
        import h5py
        with h5py.File(path, "w") as f:
            for name in self._ARRAYS:
                v = getattr(self, name)
                f.create_dataset(name, data=np.asarray(v if v is not None else self.omega))
            if self.slider is not None:
                f.create_dataset("slider", data=np.asarray(self.slider, dtype=float))
            if self.leak is not None:
                f.create_dataset("leak", data=np.asarray(self.leak, dtype=float))
            _save_readable(f, self)
            if self.peaks is not None:
                f.create_dataset("peak_omega", data=[p.omega for p in self.peaks])
                f.create_dataset("peak_amplitude", data=[p.amplitude for p in self.peaks])
                f.create_dataset("peak_index", data=[p.index for p in self.peaks])
                f.attrs["peak_method"] = np.array([p.method for p in self.peaks], dtype="S")
            if self.bifurcations is not None:
                _save_bifurcations(f, self.bifurcations)
            f.attrs["group_names"] = np.array(self.group_names, dtype="S")
            f.attrs["parameter_name"] = self.parameter_name
            f.attrs["complete"] = self.complete
            f.attrs["message"] = self.message
            f.attrs["stability_computed"] = self.stability_computed
            f.attrs["solver_info"] = self.solver_info
            _h5check.seal(f)

    def save_csv(self, path) -> None:
        """One row per point: frequency (Hz, rad/s), the load parameter of a load curve,
        stable, fold, iterations, time, then per output (named as in the deck) the true
        peak over the period, the mean and each harmonic's amplitude and phase
        (x_h = A cos(h omega t + phase), deg), then the state fractions per group and,
        with a travelling-wave selection, the leak (FRFPoint.leak)."""
        load = self.parameter_name != "omega"
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            head = ["f_hz", "omega_rad_s"] + ([self.parameter_name] if load else [])
            head += ["stable", "fold", "iterations", "time_s"]
            head += output_columns(self.labels, self.harmonics)
            for g in self.group_names:
                head += [f"{g}_stick", f"{g}_slip", f"{g}_liftoff"]
            head += ["leak"] if self.leak is not None else []
            w.writerow(head)
            par = self.parameter if self.parameter is not None else self.omega
            fhz = self.frequency_hz
            for i in range(len(self)):
                row = [repr(float(fhz[i])), repr(float(self.omega[i]))]
                row += [repr(float(par[i]))] if load else []
                row += [int(self.stable[i]), int(self.fold[i]), int(self.iterations[i]),
                        f"{self.time_s[i]:.6g}"]
                row += output_values(self.X[i], self.amp_max[i])
                row += [f"{s:.6g}" for s in self.state_fractions[i].ravel()]
                row += [f"{self.leak[i]:.3g}"] if self.leak is not None else []
                w.writerow(row)

    def save_bifurcations_csv(self, path) -> None:
        """One row per bifurcation (FRF.bifurcations): kind, frequency (Hz, rad/s), the
        parameter, the point after it, whether it was located on the curve, the parameter
        part of the tangent there (0 at a fold), then each output's max over the period."""
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["kind", "f_hz", "omega_rad_s", "parameter", "index",
                        "located", "t_lam"] + [f"{lab}_max" for lab in self.labels])
            for b in self.bifurcations or []:
                w.writerow([b.kind, repr(b.omega / (2.0 * np.pi)), repr(b.omega),
                            repr(b.parameter), b.index, int(b.located), f"{b.t_lam:.3g}"]
                           + [repr(float(a)) for a in b.amp_max])

    @classmethod
    def load(cls, path) -> "FRF":
        """Read a file written by save_h5 or by FRFWriter."""
        import h5py
        try:
            f = h5py.File(path, "r")
        except OSError as exc:
            raise InputError(f"{path}: cannot open as HDF5 ({exc})") from None
        with f:
            missing = [n for n in cls._ARRAYS if n not in f]
            if missing:
                raise InputError(f"{path}: not a frirom FRF file (missing {missing})")
            _h5check.check_results(f, path)     # checksum, types, shapes, attributes
            n = _committed_rows(f, path)[0]    # rows beyond: a torn record
            kw = {k: f[k][...] if k == "output_dofs" else f[k][:n] for k in cls._ARRAYS}
            _h5check.check_finite(kw, path)
            kw["stable"] = kw["stable"].astype(bool)
            kw["fold"] = kw["fold"].astype(bool)
            # files written before the contact history was kept have no slider
            kw["slider"] = f["slider"][:n] if "slider" in f else None
            if kw["slider"] is not None and kw["slider"].shape[0] != kw["omega"].shape[0]:
                raise InputError(f"{path}: 'slider' has {kw['slider'].shape[0]} rows for "
                                 f"{kw['omega'].shape[0]} points")
            # runs without a travelling-wave selection (and older files) keep no leak
            kw["leak"] = f["leak"][:n] if "leak" in f else None
            if kw["leak"] is not None and kw["leak"].shape[0] != kw["omega"].shape[0]:
                raise InputError(f"{path}: 'leak' has {kw['leak'].shape[0]} rows for "
                                 f"{kw['omega'].shape[0]} points")
            if "peak_omega" in f:
                kw["peaks"] = [Peak(float(w), float(a), int(i), m.decode()) for w, a, i, m in
                               zip(f["peak_omega"], f["peak_amplitude"], f["peak_index"],
                                   f.attrs["peak_method"])]
            if "bif_kind" in f.attrs:
                kw["bifurcations"] = _load_bifurcations(f, path)
            if "unknowns" in f and f["unknowns"].shape[0] == kw["omega"].shape[0]:
                kw["unknowns"] = f["unknowns"][...]
            kw["output_labels"] = _h5check.attr_texts(f, path, "output_labels")
            kw["meta"] = {k: _h5check.attr_text(f, path, k) for k in META_KEYS
                          if k in f.attrs}
            txt = functools.partial(_h5check.attr_text, f, path)
            return cls(**kw,
                       group_names=_h5check.attr_texts(f, path, "group_names"),
                       parameter_name=txt("parameter_name", "omega"),
                       complete=_h5check.attr_bool(f, path, "complete", True),
                       message=txt("message", ""),
                       stability_computed=_h5check.attr_bool(f, path, "stability_computed",
                                                             False),
                       solver_info=txt("solver_info", ""))


def _save_bifurcations(f, bifs: list) -> None:
    """FRF.bifurcations as attributes of an open HDF5 file (bif_*)."""
    n_out = f["amp_max"].shape[1] if f["amp_max"].ndim == 2 else 1
    f.attrs["bif_kind"] = np.array([b.kind for b in bifs], dtype="S")
    f.attrs["bif_omega"] = np.array([b.omega for b in bifs], float)
    f.attrs["bif_parameter"] = np.array([b.parameter for b in bifs], float)
    f.attrs["bif_index"] = np.array([b.index for b in bifs], int)
    f.attrs["bif_located"] = np.array([b.located for b in bifs], int)
    f.attrs["bif_t_lam"] = np.array([b.t_lam for b in bifs], float)
    f.attrs["bif_amp_max"] = np.array([np.ravel(b.amp_max) for b in bifs],
                                      float).reshape(len(bifs), n_out)


def store_bifurcations(path, bifs: list) -> None:
    """Add FRF.bifurcations to a closed result file (an FRFWriter's, after its run):
    the bif_* attributes, the file sealed again."""
    import h5py
    with h5py.File(path, "a") as f:
        _save_bifurcations(f, bifs)
        _h5check.seal(f)


def _load_bifurcations(f, path) -> list:
    from ._bifurcation import Bifurcation
    kinds = [k.decode() if isinstance(k, bytes) else str(k)
             for k in np.atleast_1d(f.attrs["bif_kind"])]
    if not kinds:
        return []
    cols = [np.atleast_1d(f.attrs[f"bif_{k}"]) for k in
            ("omega", "parameter", "index", "located", "t_lam")]
    amp = np.asarray(f.attrs["bif_amp_max"], float).reshape(len(kinds), -1)
    if any(c.shape[0] != len(kinds) for c in cols):
        raise InputError(f"{path}: the stored bifurcations (bif_*) disagree in size")
    return [Bifurcation(k, float(w), float(p), amp[i], int(j), bool(loc), float(t))
            for i, (k, w, p, j, loc, t) in enumerate(zip(kinds, *cols))]


#: File attribute of an FRFWriter file: [points committed, points up to the last
#: checkpoint, slot of its state in ck_* (-1: none, or the last_* datasets of a file from
#: before checkpoints)]. Rows beyond the first are a torn record (never committed).
_COMMIT = "committed"


def _row_datasets(f) -> list:
    """The per-point (row-resizable) datasets of an FRFWriter file."""
    import h5py
    return [f[k] for k in f if isinstance(f[k], h5py.Dataset) and f[k].maxshape[:1] == (None,)
            and f[k].ndim >= 1]


def _committed_rows(f, path) -> tuple[int, int, int]:
    """(points, points up to the last checkpoint, slot) of an FRFWriter file; a file
    without the commit record (written before it, or by FRF.save_h5) has as many points as
    its shortest per-point dataset."""
    c = f.attrs.get(_COMMIT)
    if c is not None:
        n, nck, slot = (int(v) for v in c)
        short = [d.name for d in _row_datasets(f) if d.shape[0] < n]
        if short or not 0 <= nck <= n:
            raise InputError(f"{path}: inconsistent file: {n} points committed but "
                             f"{short or 'the checkpoint'} disagree; it cannot be repaired, "
                             "start a new run (without --resume)")
        return n, nck, slot
    rows = _row_datasets(f) or ([f["omega"]] if "omega" in f else [])
    n = min((d.shape[0] for d in rows), default=0)
    return n, n, -1


@contextlib.contextmanager
def _signals_deferred():
    """Hold SIGINT and SIGTERM until the block ends (a Ctrl-C lands between records): the
    Python handlers are swapped for one that notes the signal, which is sent again once
    the old handlers are back (Python runs handlers in the main thread, whichever thread
    the OS chose, so masking the signal in one thread would not do)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got = []
    sigs = (signal.SIGINT, signal.SIGTERM)
    old = {s: signal.signal(s, lambda n, _frame: got.append(n)) for s in sigs}
    try:
        yield
    finally:
        for s in sigs:
            signal.signal(s, old[s])
        for n in dict.fromkeys(got):
            os.kill(os.getpid(), n)


class FRFWriter:
    """Append points to an HDF5 file as they come (resizable datasets, flushed per point).

    A point counts once its record is whole: the file attribute ``committed`` is set after
    every dataset has its row, so a run killed at any moment (SIGKILL, power loss between
    HDF5 flushes aside) leaves a readable file whose extra rows, if any, are a torn record
    that :meth:`FRF.load` ignores and reopening with ``append=True`` removes
    (:attr:`repaired`); SIGINT and SIGTERM wait until the record is whole (main thread).

    Points that end a call into Fortran (``FRFPoint.ds_next`` finite) are checkpoints: the
    file keeps the solver's state there (unknowns, tangent, step, arc-length scale; the
    sliders are in every row), so ``FRFWriter.resume_point(path)`` gives the `start` of
    :func:`frirom.solver.frf` from which the run continues exactly as the uninterrupted one
    would have. Opening with ``append=True`` drops the points after the last checkpoint
    (:attr:`dropped`; the resumed run computes them again, the same). Use as the `sink` of
    frf (``sink=writer.append``).

    Parameters
    ----------
    attrs : dict, optional
        File attributes written on opening (e.g. the deck's fingerprint).
    """

    def __init__(self, path, output_dofs, group_names, harmonics: int,
                 parameter_name: str = "omega", append: bool = False, attrs=None,
                 output_labels=None, meta: dict | None = None):
        import h5py
        self.path = path
        self.repaired = 0   #: rows of a torn last record removed on opening
        self.dropped = 0    #: committed points after the last checkpoint removed on opening
        self.f = h5py.File(path, "a" if append else "w")
        nc = 2 * harmonics + 1
        n_out = len(output_dofs)
        ng = len(group_names)
        if "omega" not in self.f:
            def mk(name, tail, dtype=float):
                self.f.create_dataset(name, shape=(0,) + tail, maxshape=(None,) + tail,
                                      dtype=dtype, chunks=(64,) + tail if all(tail) else True)
            mk("omega", ())
            mk("parameter", ())
            mk("X", (n_out, nc))
            mk("amp_max", (n_out,))
            mk("state_fractions", (ng, 3))
            mk("stable", (), bool)
            mk("fold", (), bool)
            mk("iterations", (), int)
            mk("time_s", ())
            self.f.create_dataset("output_dofs", data=np.asarray(output_dofs, dtype=int))
            self.f.attrs["group_names"] = np.array(list(group_names), dtype="S")
            self.f.attrs["parameter_name"] = parameter_name
            _write_labels_meta(self.f, output_labels, meta)
            self._commit = (0, 0, -1)
        elif self.f["X"].shape[1:] != (n_out, nc):
            shape = self.f["X"].shape[1:]
            self.f.close()
            raise InputError(f"{path}: existing file has X of shape {shape}, this run makes "
                             f"{(n_out, nc)}")
        else:
            self._rewind()
        for k, v in (attrs or {}).items():
            self.f.attrs[k] = v
        self.f.attrs["complete"] = False
        self.f.attrs["message"] = "running"
        _h5check.unseal(self.f)         # sealed again by close()
        self._set_commit(*self._commit)

    def _rewind(self) -> None:
        """Cut every per-point dataset to the last checkpoint (a file from before
        checkpoints: to its shortest dataset)."""
        n, nck, slot = _committed_rows(self.f, self.path)
        rows = _row_datasets(self.f)
        self.repaired = max((d.shape[0] for d in rows), default=0) - n
        self.dropped = n - nck
        for d in rows:
            if d.shape[0] != nck:
                d.resize(nck, axis=0)
        self._commit = (nck, nck, slot)

    def _set_commit(self, n: int, nck: int, slot: int) -> None:
        self._commit = (n, nck, slot)
        self.f.attrs[_COMMIT] = np.array([n, nck, slot], dtype=np.int64)
        self.f.flush()

    def append(self, p: FRFPoint) -> None:
        """Add one point (whole, or not at all if the process dies meanwhile)."""
        with _signals_deferred():
            self._append(p)

    def _append(self, p: FRFPoint) -> None:
        f = self.f
        n, nck, slot = self._commit
        sl = np.asarray(p.slider, dtype=float).ravel()
        if "slider" not in f:
            # points already in a file from before the history was kept: unknown (NaN)
            f.create_dataset("slider", data=np.full((n, sl.size), np.nan),
                             maxshape=(None, sl.size),
                             chunks=(64, sl.size) if sl.size else True)
        elif f["slider"].shape[1] != sl.size:
            raise InputError(f"{self.path}: existing file keeps {f['slider'].shape[1]} "
                             f"sliders per point, this run has {sl.size}")
        f["slider"].resize(n + 1, axis=0)
        f["slider"][n] = sl
        for name in ("omega", "parameter", "X", "amp_max", "state_fractions", "stable",
                     "fold", "iterations", "time_s"):
            d = f[name]
            d.resize(n + 1, axis=0)
            d[n] = getattr(p, name)
        _append_readable(f, n, p)
        if p.leak is not None:      # a travelling-wave selection's run (NaN rows before)
            _append_row(f, "leak", n, p.leak)
        if np.isfinite(p.ds_next):
            # the checkpoint's state goes to the slot the commit does not point at
            slot = 0 if slot != 0 else 1
            lu = np.zeros(1) if p.held_lu is None else p.held_lu     # [0]: none held
            for name, v in (("ck_unknowns", p.unknowns), ("ck_tangent", p.tangent),
                            ("ck_scalars", [n + 1, p.parameter, p.ds_next, p.yscale]),
                            ("ck_lu", lu)):
                v = np.asarray(v, dtype=float)
                if name in f and f[name].shape[1:] != v.shape:
                    del f[name]
                if name not in f:
                    f.create_dataset(name, shape=(2,) + v.shape, dtype=float)
                f[name][slot] = v
            nck = n + 1
        self._set_commit(n + 1, nck, slot)

    def close(self, complete: bool = True, message: str = "") -> None:
        if self.f:
            f, self.f = self.f, None
            try:
                f.attrs["complete"] = complete
                f.attrs["message"] = message
                _h5check.seal(f)
            finally:
                f.close()       # even when the disk refused the attributes

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close(complete=exc[0] is None, message="" if exc[0] is None else str(exc[1]))

    @staticmethod
    def resume_point(path) -> dict:
        """The `start` argument of frirom.solver.frf at the file's last checkpoint:
        {'parameter', 'omega', 'unknowns', 'tangent', 'yscale', 'slider', 'ds' (the step
        the run continued with), 'n_points' (points up to it), 'held_lu' (the solver's
        held factorisation there), 'before' (the points up to it, FRFPoints: the resumed
        run solves its peaks on the whole curve), with a travelling-wave selection 'leak'
        (the largest stored FRFPoint.leak up to it, its omega)}. A file
        written before checkpoints gives its last point without 'ds' (the run resumes with
        the deck's first step); one written before the contact history was kept gives slider None
        (the run resumes from the model's w0, with a warning: a contact stuck all cycle
        there may settle differently)."""
        import h5py
        try:
            f = h5py.File(path, "r")
        except OSError as exc:
            raise InputError(f"{path}: cannot open as HDF5 ({exc})") from None
        with f:
            _h5check.check_results(f, path)
            n, nck, slot = _committed_rows(f, path)
            if slot < 0 and "last_unknowns" in f:       # a file from before checkpoints
                state = {"parameter": float(f.attrs["last_parameter"]),
                         "omega": float(f.attrs["last_omega"]),
                         "unknowns": f["last_unknowns"][...],
                         "tangent": f["last_tangent"][...],
                         "yscale": float(f.attrs.get("last_yscale", 0.0))}
                slider = f["last_slider"][...] if "last_slider" in f else None
            elif nck == 0 or slot < 0:
                raise InputError(f"{path}: no point to resume from (the run stopped "
                                 "before its first checkpoint)")
            else:
                for k in ("ck_scalars", "ck_unknowns", "ck_tangent", "ck_lu"):
                    if k in f and f[k].shape[0] <= slot or k not in f and k != "ck_lu":
                        raise InputError(f"{path}: dataset {k!r}: no checkpoint slot {slot} "
                                         f"(shape {f[k].shape if k in f else 'absent'}); "
                                         "start a new run (without --resume)")
                if f["ck_scalars"].shape[1] < 4:
                    raise InputError(f"{path}: dataset 'ck_scalars': expected 4 values per "
                                     f"checkpoint, got shape {f['ck_scalars'].shape}")
                sc = f["ck_scalars"][slot]
                if int(sc[0]) != nck:
                    raise InputError(f"{path}: inconsistent file: the checkpoint is at point "
                                     f"{int(sc[0])}, the commit record says {nck}")
                state = {"parameter": float(sc[1]), "omega": float(f["omega"][nck - 1]),
                         "unknowns": f["ck_unknowns"][slot], "tangent": f["ck_tangent"][slot],
                         "yscale": float(sc[3]), "ds": float(sc[2]), "n_points": nck}
                if "ck_lu" in f and f["ck_lu"].shape[1] and f["ck_lu"][slot][0] != 0.0:
                    state["held_lu"] = f["ck_lu"][slot]
                slider = f["slider"][nck - 1] if "slider" in f else None
                before = _points_before(f, nck)
                if before:
                    state["before"] = before
                leak = f["leak"][:nck] if "leak" in f else np.zeros(0)
                if np.any(np.isfinite(leak)):   # the worst stored leak: the run warns on it
                    k = int(np.nanargmax(leak))
                    state["leak"] = (float(leak[k]), float(f["omega"][k]))
            if slider is None:
                warnings.warn(f"{path}: written before frirom kept the contact history "
                              "(sliders); resuming from the model's initial sliders w0",
                              RuntimeWarning, stacklevel=2)
            return {**state, "slider": slider}


def _points_before(f, n: int) -> list:
    """The first n points of an FRFWriter file as FRFPoints, for a resumed run's peak
    solve on the whole curve (:func:`frirom.solver.frf` with a checkpoint's 'before');
    [] when the file does not keep what a solve from a point needs (its tangent, scale and
    history: files written before they were kept)."""
    need = ("unknowns", "tangent", "yscale", "slider", "parameter", "X", "amp_max")
    if n == 0 or not all(k in f and f[k].ndim and f[k].shape[0] >= n for k in need):
        return []
    cols = {k: f[k][:n] for k in need + ("omega", "state_fractions", "iterations")}
    if not all(np.all(np.isfinite(cols[k])) for k in ("tangent", "yscale", "slider",
                                                        "iterations")):
        return []
    return [FRFPoint(omega=float(cols["omega"][i]), parameter=float(cols["parameter"][i]),
                     unknowns=cols["unknowns"][i], tangent=cols["tangent"][i],
                     X=cols["X"][i], amp_max=cols["amp_max"][i],
                     state_fractions=cols["state_fractions"][i],
                     iterations=int(cols["iterations"][i]), time_s=0.0,
                     yscale=float(cols["yscale"][i]), slider=cols["slider"][i])
            for i in range(n)]


# ---- the readable datasets of a result file (frequency in Hz, harmonics' amplitude and
# phase, output labels, how it was made) and the unknowns per point (`frirom show`) -------

def _write_labels_meta(f, labels, meta) -> None:
    """Output labels and META_KEYS attributes of an HDF5 file (h5py.File)."""
    if labels is not None and len(labels):
        f.attrs["output_labels"] = np.array([str(x) for x in labels], dtype="S")
    for k, v in (meta or {}).items():
        if k in META_KEYS and v is not None:
            f.attrs[k] = str(v)


def _save_readable(f, frf: FRF) -> None:
    """FRF.save_h5's readable part: frequency_hz, harmonic_amplitude and harmonic_phase
    (n_pts, n_out, H+1), unknowns per point, output labels and META_KEYS."""
    amp, ph = harmonic_table(frf.X)
    f.create_dataset("frequency_hz", data=frf.frequency_hz)
    f.create_dataset("harmonic_amplitude", data=amp)
    f.create_dataset("harmonic_phase", data=ph)
    if frf.unknowns is not None:
        f.create_dataset("unknowns", data=np.asarray(frf.unknowns, float))
    _write_labels_meta(f, frf.labels, frf.meta)


def _append_row(f, name: str, n: int, row) -> None:
    """Write row n of a resizable dataset, made on first use (rows of points already in
    the file before it existed are NaN)."""
    row = np.asarray(row, dtype=float)
    if name not in f:
        f.create_dataset(name, data=np.full((n,) + row.shape, np.nan),
                         maxshape=(None,) + row.shape,
                         chunks=(64,) + row.shape if row.size else True)
    elif f[name].shape[1:] != row.shape:
        raise InputError(f"{f.filename}: existing file has {name} rows of shape "
                         f"{f[name].shape[1:]}, this run makes {row.shape}")
    f[name].resize(n + 1, axis=0)
    f[name][n] = row


def _append_readable(f, n: int, p: FRFPoint) -> None:
    """FRFWriter.append's readable part for point n (see _save_readable)."""
    amp, ph = harmonic_table(p.X)
    _append_row(f, "frequency_hz", n, p.omega / (2.0 * np.pi))
    _append_row(f, "harmonic_amplitude", n, amp)
    _append_row(f, "harmonic_phase", n, ph)
    _append_row(f, "unknowns", n, p.unknowns)
    # with the tangent and its scale, a resumed run solves its peak on the whole curve
    _append_row(f, "tangent", n, p.tangent)
    _append_row(f, "yscale", n, p.yscale)
