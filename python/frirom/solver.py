"""Harmonic balance solver: one frequency, or pseudo-arc-length continuation in frequency
or in a load factor. Python packs the model into arrays; Newton, continuation, AFT and the
linear algebra run in Fortran (frirom_hbm, frirom_newton, frirom_banded).

Formulations (same answer, different cost):

* ``'condensed'`` (Eq. 5-9): unknowns are the harmonics of the contact DoFs only; for
  models with few contact DoFs (reduced models).
* ``'banded'``: all DoFs x harmonics in reverse Cuthill-McKee order, banded LU; for
  unreduced FE and lumped models with many contact DoFs.

A :class:`frirom.model.CyclicModel` (one sector of a tuned rotor under an engine-order
travelling wave) is solved in the condensed formulation with receptances from the modes of
each harmonic's own nodal diameter (time harmonic h on h EO mod N): exact for the
travelling-wave response of the whole rotor, at the cost of one sector.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp

from . import _kernels
from ._errors import ParameterError, SizeError, raise_for_status
from .contact import LAWS
from .model import CyclicModel, Excitation, Model
from .results import FRF, FRFPoint, amplitude_max

LAW_CODES = {name: law.code for name, law in LAWS.items()}   # Fortran law codes
FORMULATIONS = {"condensed": 1, "banded": 2}
#: Largest Hill eigenproblem (2 n_dof (2H+1)) computed; above it stability is skipped.
HILL_MAX = 4000
#: Names of the Fortran timers/counters returned with each run (seconds, counts).
TIMER_NAMES = ("aft", "assembly", "factorization", "solve", "receptance", "evaluations",
               "factorizations", "fortran_total")


def _add_timings(acc: dict, t) -> None:
    for k, v in zip(TIMER_NAMES, t):
        acc[k] = acc.get(k, 0.0) + float(v)


@dataclass
class SolverOptions:
    """Settings of the harmonic balance solver.

    harmonics: H (harmonics 0..H); samples: AFT time samples per period (>= 2H+1; default
    max(64, 8(2H+1))); formulation: 'condensed' or 'banded'; tol_residual: ||R|| relative to
    the size of the terms of R; tol_update: ||dy|| relative to ||y||; tol_stall: after
    max_iter, a residual stagnating below this is accepted (contact state changing inside
    one time sample makes R non-differentiable; 0 disables); ds, ds_min, ds_max:
    arc-length steps in scaled variables (unknowns / |first point|, parameter / range);
    max_points: points per run; parameter: 'frequency' or 'load'; reuse_jacobian: keep a
    factorisation while Newton contracts by a factor 10 per iteration (a corrector that
    fails with reuse is retried with a fresh Jacobian at every iteration); batch: points
    per call into Fortran (sink granularity); stability: Hill's method at every point
    (dense eigen-solve of size 2 n_dof (2H+1), up to 4000); history: carry the contact
    history along the curve (each point starts its sliders where the previous converged
    point's closed cycles left them; False restarts every point from the model's w0, which
    makes a contact stuck all cycle snap back to it); modes: condensed formulation
    only, receptances by superposition of this many lowest modes (mass-normalised, damping
    ratios from Damping.modal or the diagonal of Phi^T C Phi) instead of factorising the
    dynamic stiffness at every frequency (truncation: no residual flexibility).
    """

    harmonics: int = 3
    samples: int | None = None
    formulation: str = "condensed"
    tol_residual: float = 1e-8
    tol_update: float = 1e-8
    tol_stall: float = 0.0
    max_iter: int = 25
    ds: float = 0.02
    ds_min: float = 1e-6
    ds_max: float = 0.1
    max_points: int = 2000
    parameter: str = "frequency"
    reuse_jacobian: bool = True
    stability: bool = False
    history: bool = True
    modes: int | None = None
    batch: int = 10

    def check(self) -> None:
        if not (isinstance(self.harmonics, (int, np.integer)) and 0 <= self.harmonics <= 200):
            raise ParameterError(f"options.harmonics: expected an integer 0..200, got "
                                 f"{self.harmonics!r}")
        if self.samples is not None and self.samples < 2 * self.harmonics + 1:
            raise ParameterError(f"options.samples: need >= 2H+1 = {2 * self.harmonics + 1}"
                                 f", got {self.samples}")
        if self.formulation not in FORMULATIONS:
            raise ParameterError(f"options.formulation: expected one of "
                                 f"{sorted(FORMULATIONS)}, got {self.formulation!r}")
        if self.parameter not in ("frequency", "load"):
            raise ParameterError("options.parameter: expected 'frequency' or 'load'")
        if not (np.isfinite(self.tol_stall) and self.tol_stall >= 0):
            raise ParameterError("options.tol_stall: expected a number >= 0")
        for nm in ("tol_residual", "tol_update", "ds", "ds_min", "ds_max"):
            v = getattr(self, nm)
            if not (np.isfinite(v) and v > 0):
                raise ParameterError(f"options.{nm}: expected a positive number, got {v}")
        if self.ds_min > self.ds_max:
            raise ParameterError("options.ds_min must not exceed options.ds_max")
        if self.modes is not None and (self.modes < 1 or self.formulation != "condensed"):
            raise ParameterError("options.modes: a positive number of modes, with "
                                 "formulation 'condensed'")
        if self.max_iter < 1 or self.max_points < 1 or self.batch < 1:
            raise ParameterError("options.max_iter, max_points and batch must be >= 1")

    @property
    def n_samples(self) -> int:
        return self.samples or max(64, 8 * (2 * self.harmonics + 1))


def _csr(a: sp.csr_matrix):
    a = sp.csr_matrix(a)
    a.sort_indices()
    idx = a.indices.astype(np.int32) + 1
    x = a.data.astype(float)
    if idx.size == 0:     # f2py needs at least one entry
        idx, x = np.ones(1, np.int32), np.zeros(1)
    return a.indptr.astype(np.int32) + 1, idx, x


def _modes(model: Model, nm: int):
    """Lowest nm mass-normalised modes, natural frequencies (rad/s) and damping ratios."""
    import scipy.linalg as sla
    n = model.n_dof
    if nm > n:
        raise ParameterError(f"options.modes: {nm} modes for a model with {n} DoFs")
    if n <= 3000 or nm > n // 2:
        w2, phi = sla.eigh(model.K.toarray(), model.M.toarray(), subset_by_index=[0, nm - 1])
    else:
        from scipy.sparse.linalg import eigsh
        w2, phi = eigsh(model.K.tocsc(), k=nm, M=model.M.tocsc(), sigma=0.0, which="LM")
        order = np.argsort(w2)
        w2, phi = w2[order], phi[:, order]
        phi = phi / np.sqrt(np.einsum("ir,ir->r", phi, model.M @ phi))
    if np.any(w2 <= 0):
        raise ParameterError("options.modes: the model has rigid-body (zero-frequency) modes; "
                             "modal superposition needs a constrained model")
    w = np.sqrt(w2)
    if model.damping.kind == "modal" and model.damping.zeta.size >= nm:
        z = model.damping.zeta[:nm].copy()
    else:
        z = np.einsum("ir,ir->r", phi, model.C @ phi) / (2.0 * w)
    return np.asfortranarray(phi), w, z


class _Packed:
    """The model as the Fortran arrays of hbm_continue (built once per run)."""

    def __init__(self, model, excitation: Excitation, opts: SolverOptions,
                 outputs, load_part: str = "dynamic"):
        if not isinstance(model, (Model, CyclicModel)):
            raise ParameterError("model: expected a frirom.model.Model or CyclicModel")
        if not isinstance(excitation, Excitation):
            raise ParameterError("excitation: expected a frirom.model.Excitation")
        opts.check()
        self.model, self.opts = model, opts
        H = opts.harmonics
        n = model.n_dof
        self.H, self.nc, self.n_dof = H, 2 * H + 1, n
        self.form = FORMULATIONS[opts.formulation]
        fe = excitation.real_harmonic(n, H)
        if load_part not in ("static", "dynamic"):
            raise ParameterError("load_part: expected 'static' or 'dynamic'")
        if opts.parameter == "frequency":
            self.fe0, self.fe1, self.mode = fe, np.zeros_like(fe), 1
        else:
            self.mode = 2
            mask = np.zeros(self.nc, bool)
            mask[0 if load_part == "static" else slice(1, None)] = True
            self.fe1 = np.where(mask, fe, 0.0)
            self.fe0 = fe - self.fe1
        if isinstance(model, CyclicModel):
            self._init_cyclic(model, outputs)
            return
        self.K, self.M, self.C = (_csr(model.K), _csr(model.M), _csr(model.C))
        self.nl = model.nonlinear_dofs()
        if self.form == 1 and self.nl.size == 0:
            raise ParameterError("formulation 'condensed' needs contact DoFs; the model has "
                                 "no contact group (use 'banded')")
        # contact groups
        groups = model.contacts
        G = self._groups(groups, n)
        self.G = _csr(G)
        # RCM over K, M, C and the contact couplings
        pat = (abs(model.K) + abs(model.M) + abs(model.C)).tocsr()
        if groups:
            pat = pat + (abs(G).T @ abs(G))
        pat = (pat + pat.T + sp.identity(n)).tocsr()
        pat.sort_indices()
        perm, info, msg = _kernels.hbm_rcm(pat.indptr.astype(np.int32) + 1,
                                           pat.indices.astype(np.int32) + 1)
        raise_for_status(info, msg.decode(errors="replace"))
        self.perm = perm
        # outputs (0-based in Python)
        if outputs is None:
            outputs = np.arange(n) if n <= 100 else self.nl
        self._set_outputs(outputs)
        self.out_f = self.outputs
        self.ny = (self.nl.size if self.form == 1 else n) * self.nc
        self.stability = bool(opts.stability)
        if self.stability and 2 * n * self.nc > HILL_MAX:
            warnings.warn(f"frirom: Hill stability skipped: its dense eigenproblem would have "
                          f"size 2 n_dof (2H+1) = {2 * n * self.nc} > {HILL_MAX}",
                          RuntimeWarning, stacklevel=3)
            self.stability = False
        self._no_modes(n)
        if opts.modes:
            self.phi, self.wmodes, self.zmodes = _modes(model, int(opts.modes))
            self.nmodes = self.wmodes.size

    def _groups(self, groups, ncol: int):
        """Pack the contact groups; returns their stacked G (rows, ncol)."""
        self.group_names = [g.name for g in groups]
        self.ne_tot = int(sum(g.n_elem for g in groups))
        self.group_sizes = [g.n_elem for g in groups]
        if not groups:
            self.nw = 0
            self.ginfo = np.zeros((3, 0), np.int32, order="F")
            self.params, self.w0 = np.zeros(1), np.zeros(1)
            return sp.csr_matrix((0, ncol))
        self.ginfo = np.array([[LAW_CODES[g.law], g.n_elem, g.n_dir] for g in groups],
                              dtype=np.int32).T.copy(order="F")
        self.params = np.concatenate([g.params.ravel() for g in groups])
        w0 = [g.w0.ravel() for g in groups]
        self.nw = int(sum(a.size for a in w0))
        self.w0 = np.concatenate(w0) if self.nw else np.zeros(1)
        return sp.vstack([sp.csr_matrix(g.G, shape=(g.G.shape[0], ncol)) if
                          g.G.shape[1] == ncol else
                          sp.hstack([g.G, sp.csr_matrix((g.G.shape[0], ncol - g.G.shape[1]))])
                          for g in groups]).tocsr()

    def _no_modes(self, nrows: int) -> None:
        """The mode arrays of hbm_continue, unused (nmodes = hmodes = 0) but shaped as f2py
        wants them: real modes (nrows, 1) and per-harmonic modes (nrows, 1, H+1)."""
        H = self.H
        self.nmodes = self.hmodes = 0
        self.phi, self.wmodes, self.zmodes = np.zeros((nrows, 1)), np.ones(1), np.zeros(1)
        self.psi = np.zeros((nrows, 1, H + 1), complex, order="F")
        self.wharm, self.zharm = np.ones((1, H + 1)), np.zeros((1, H + 1))

    def _set_outputs(self, outputs) -> None:
        n = self.n_dof
        self.outputs = np.asarray(outputs, dtype=int).ravel()
        if self.outputs.size == 0:
            self.outputs = np.zeros(1, dtype=int)
        if np.any(self.outputs < 0) or np.any(self.outputs >= n):
            raise SizeError(f"outputs: DoF indices must be in 0..{n - 1}")

    def _init_cyclic(self, model: CyclicModel, outputs) -> None:
        """A cyclic sector as a condensed system on the DoFs the solver reads: contact DoFs
        of sector 0 and of the next sector (columns n.. of G, shapes times exp(i k_h alpha)),
        outputs and loaded DoFs; receptances from the modes of each harmonic's nodal
        diameter (hbm_set_modes_harmonic); K, M, C are not used (empty)."""
        o, n, H = self.opts, self.n_dof, self.H
        if self.form != 1:
            raise ParameterError("options.formulation: a cyclic sector is solved in the "
                                 "'condensed' formulation (receptances per nodal diameter)")
        if o.modes:
            raise ParameterError("options.modes: a cyclic model brings its own modes per "
                                 "nodal diameter (frirom.reduction.cyclic.cyclic_model)")
        if o.stability:
            raise ParameterError("options.stability: Hill's method is not implemented for "
                                 "cyclic sectors (perturbations of every nodal diameter)")
        G = self._groups(model.contacts, 2 * n)
        cols = np.unique(G.indices)
        if outputs is None:
            outputs = np.arange(n) if n <= 100 else cols[cols < n]
        self._set_outputs(outputs)
        loaded = np.nonzero(np.any(self.fe0 != 0, axis=1) | np.any(self.fe1 != 0, axis=1))[0]
        rows = np.unique(np.concatenate([cols, self.outputs, loaded]))
        nr = rows.size
        at = -np.ones(2 * n, dtype=np.int64)
        at[rows] = np.arange(nr)
        self.nl = at[cols]
        self.out_f = at[self.outputs]
        G = sp.csr_matrix((G.data, at[G.indices], G.indptr), shape=(G.shape[0], nr))
        self.G = _csr(G)
        real = rows[rows < n]
        fe0, fe1 = np.zeros((nr, self.nc)), np.zeros((nr, self.nc))
        fe0[at[real]], fe1[at[real]] = self.fe0[real], self.fe1[real]
        self.fe0, self.fe1, self.n_dof = fe0, fe1, nr
        self._no_modes(nr)
        alpha = 2 * np.pi / model.n_sectors
        per = [model.modes_of(model.harmonic_index(h)) for h in range(H + 1)]
        nm = max(m.omega.size for m in per)
        self.hmodes = nm
        self.psi = np.zeros((nr, nm, H + 1), complex, order="F")
        self.wharm = np.ones((nm, H + 1), order="F")
        self.zharm = np.zeros((nm, H + 1), order="F")
        nb = rows >= n
        for h, m in enumerate(per):
            r = m.omega.size
            self.psi[~nb, :r, h] = m.psi[rows[~nb]]
            self.psi[nb, :r, h] = m.psi[rows[nb] - n] * np.exp(1j * m.k * alpha)
            self.wharm[:r, h], self.zharm[:r, h] = m.omega, m.zeta
        empty = _csr(sp.csr_matrix((nr, nr)))
        self.K = self.M = self.C = empty
        self.perm = np.arange(1, nr + 1, dtype=np.int32)
        self.ny = self.nl.size * self.nc
        self.stability = False

    def set_history(self, slider) -> None:
        """Initial sliders of all contact elements (the history of the point a run starts
        from; the layout of FRFPoint.slider); None keeps the model's w0."""
        if slider is None:
            return
        slider = np.asarray(slider, dtype=float).ravel()
        if slider.size != self.nw:
            raise SizeError(f"start.slider: {slider.size} values, the model's contact "
                            f"elements have {self.nw} sliders")
        if not np.all(np.isfinite(slider)):
            raise ParameterError("start.slider: contains NaN or Inf")
        if self.nw:
            self.w0 = slider.copy()

    def call(self, y0, lam0, tan0, start_mode, ds, lam_end, lam_lo, yscale, lscale, maxpts,
             omega_fix=0.0):
        """One hbm_continue call from the current contact history self.w0; the history
        the last point leaves becomes self.w0 for the next call."""
        o = self.opts
        nl = (self.nl + 1).astype(np.int32) if self.nl.size else np.ones(1, np.int32)
        res = _kernels.hbm_continue(
            self.form, o.n_samples, *self.K, *self.M, *self.C, self.perm, nl,
            np.asfortranarray(self.fe0), np.asfortranarray(self.fe1), self.mode, omega_fix,
            self.ginfo, *self.G, self.params, self.w0, (self.out_f + 1).astype(np.int32),
            y0, lam0, tan0, start_mode, ds, o.ds_min, o.ds_max, lam_end, lam_lo,
            o.tol_residual, o.tol_update, o.tol_stall, o.max_iter, int(o.reuse_jacobian),
            yscale, lscale, maxpts, max(self.ne_tot, 1), int(self.stability), self.nmodes,
            np.asfortranarray(self.phi), self.wmodes, self.zmodes, self.hmodes,
            np.asfortranarray(self.psi), np.asfortranarray(self.wharm),
            np.asfortranarray(self.zharm), int(o.history), nh=self.H,
            ndof=self.n_dof, nnl=self.nl.size or 1)
        r = SimpleNamespace(**dict(zip(
            ("ys", "lams", "tans", "iters", "xo", "states", "hill_re", "sliders", "npts",
             "finished", "ds_out", "timings", "info", "msg"), res)))
        r.msg = r.msg.decode(errors="replace")
        if r.npts > 0 and self.nw and o.history:
            self.w0 = r.sliders[:self.nw, r.npts - 1].copy()
        return r

    def pad_start(self, y, H_from: int) -> np.ndarray:
        """Unknowns of a solution with H_from harmonics, extended or cut to this H."""
        y = np.asarray(y, dtype=float)
        nrow = self.nl.size if self.form == 1 else self.n_dof
        nc_from = 2 * H_from + 1
        if y.size != nrow * nc_from:
            raise SizeError(f"start: {y.size} unknowns do not match H = {H_from} for this "
                            "model and formulation")
        m = min(nc_from, self.nc)
        out = np.zeros(self.ny)
        if self.form == 1:      # harmonic-major: y[j + nnl c]
            out[:nrow * m] = y[:nrow * m]
        else:                   # DoF-major in RCM order: y[c + nc p]
            out.reshape(nrow, self.nc)[:, :m] = y.reshape(nrow, nc_from)[:, :m]
        return out

    def points(self, res, omega_fix, t_call):
        ys, lams, tans, iters, xo = res.ys, res.lams, res.tans, res.iters, res.xo
        states, hill_re, npts = res.states, res.hill_re, res.npts
        pts = []
        for k in range(npts):
            st = np.zeros((len(self.group_sizes), 3))
            e0 = 0
            for g, ne in enumerate(self.group_sizes):
                st[g] = states[:, e0:e0 + ne, k].mean(axis=1)
                e0 += ne
            X = np.array(xo[:, :, k])
            om = lams[k] if self.mode == 1 else omega_fix
            pts.append(FRFPoint(omega=float(om), parameter=float(lams[k]),
                                unknowns=ys[:, k].copy(), tangent=tans[:, k].copy(), X=X,
                                amp_max=amplitude_max(X), state_fractions=st,
                                iterations=int(iters[k]), time_s=t_call / max(npts, 1),
                                stable=bool(hill_re[k] <= 1e-7 * max(abs(om), 1.0)),
                                floquet_max_re=float(hill_re[k]),
                                slider=res.sliders[:self.nw, k].copy()))
        return pts


def _run(packed: _Packed, lam_start, lam_end, omega_fix, sink, start, H_start,
         keep_unknowns=False):
    o = packed.opts
    lscale = abs(lam_end - lam_start) or 1.0
    points, message, complete = [], "", True
    timings: dict = {}
    t0 = time.perf_counter()
    if start is None:
        y0 = np.zeros(packed.ny)
        tan0 = np.zeros(packed.ny + 1)
        mode, lam0 = 0, float(lam_start)
    else:
        if isinstance(start, FRFPoint):
            start = {"parameter": start.parameter, "unknowns": start.unknowns,
                     "tangent": start.tangent, "yscale": start.yscale,
                     "slider": start.slider}
        packed.set_history(start.get("slider"))
        y0 = packed.pad_start(start["unknowns"], H_start if H_start is not None else packed.H)
        lam0 = float(start.get("parameter", start.get("omega")))
        tan = start.get("tangent")
        # without the history the point was computed with (a file from before it was
        # kept), the saved point need not solve the equations: re-solve it first
        unknown_history = packed.nw and o.history and start.get("slider") is None
        if tan is None or H_start not in (None, packed.H) or unknown_history:
            mode, tan0 = 0, np.zeros(packed.ny + 1)   # re-solve, then continue
        else:
            mode, tan0 = 1, np.asarray(tan, dtype=float)
            if tan0.size != packed.ny + 1:
                raise SizeError("start.tangent: size does not match the unknowns")
    ds = o.ds
    lam_lo = float(lam_start) - 0.02 * (lam_end - lam_start)
    prev_t = None
    skip_first = False
    if mode == 0:
        # First solve at fixed parameter with a purely relative update test; the size of
        # that solution then scales the arc length, and the next call (start_mode 0 from
        # the converged point, one Newton iteration) computes the tangent in that scaling.
        res = packed.call(y0, lam0, tan0, 2, ds, lam_end, lam_lo, 1e-300, lscale, 1,
                          omega_fix)
        _add_timings(timings, res.timings)
        if res.info != 0 and packed.mode == 1 and start is None:
            # Newton from the linear solution failed (strong slip or lift-off): reach the
            # first point by continuation in the excitation level from the static state.
            y_h = _homotopy_start(packed, lam0)
            if y_h is not None:
                res = packed.call(y_h, lam0, tan0, 2, ds, lam_end, lam_lo, 1e-300, lscale,
                                  1, omega_fix)
        raise_for_status(res.info, res.msg)
        p = packed.points(res, omega_fix, time.perf_counter() - t0)[0]
        t0 = time.perf_counter()
        points.append(p)        # handed to sink once its tangent is known (next call)
        y0, skip_first = p.unknowns, True
    yscale = float(np.linalg.norm(y0)) or 1.0
    if mode == 1:
        prev_t = tan0[-1]
        # keep the arc-length scaling the saved tangent was computed with
        if start.get("yscale"):
            yscale = float(start["yscale"])
    while len(points) < o.max_points:
        maxpts = min(o.batch, o.max_points - len(points)) + int(skip_first)
        res = packed.call(y0, lam0, tan0, mode, ds, lam_end, lam_lo, yscale, lscale,
                          maxpts, omega_fix)
        t_call = time.perf_counter() - t0
        t0 = time.perf_counter()
        finished, ds_out, info = res.finished, res.ds_out, res.info
        _add_timings(timings, res.timings)
        new = packed.points(res, omega_fix, t_call)
        for p in new:
            p.yscale = yscale
        if skip_first and new:
            prev_t = new[0].tangent[-1]
            points[-1].tangent = new[0].tangent
            points[-1].yscale = yscale
            if sink is not None:
                sink(points[-1])
            new = new[1:]
        elif skip_first and sink is not None:
            sink(points[-1])
        skip_first = False
        for p in new:
            if prev_t is not None and prev_t != 0 and np.sign(p.tangent[-1]) != np.sign(prev_t):
                p.fold = True
            prev_t = p.tangent[-1]
            points.append(p)
            if sink is not None:
                sink(p)
        if info != 0:
            message = res.msg.strip()
            if info == 20 and packed.nw:
                message += (" [with friction contacts this is usually a corner of the "
                            "solution curve: a contact state switching at one of the "
                            f"N = {o.n_samples} AFT samples, e.g. lift-off onset; more "
                            "samples (256 recommended) make the corners milder]")
            if not points:
                raise_for_status(info, message)
            complete = False
            warnings.warn(f"frirom: continuation stopped early, {len(points)} points kept: "
                          f"{message}", RuntimeWarning, stacklevel=3)
            break
        if not points:
            break
        last = points[-1]
        y0, lam0, tan0, ds, mode = last.unknowns, last.parameter, last.tangent, ds_out, 1
        # the arc length measures unknowns against the largest solution so far: near a
        # resonance 100x above the first point, steps would otherwise crawl in frequency
        ny0 = float(np.linalg.norm(y0))
        if ny0 > 2.0 * yscale:
            tan0 = tan0.copy()
            tan0[:-1] *= yscale / ny0
            tan0 /= np.linalg.norm(tan0)
            yscale = ny0
        if finished:
            break
    else:
        complete = False
        message = f"stopped after max_points = {o.max_points} points"
    if complete and points and points[-1].parameter != lam_end:
        complete = False
        message = (f"the solution curve turned back and left the range through "
                   f"{points[-1].parameter:.6g} (start {lam_start:.6g})")
    name = "omega" if packed.mode == 1 else "load"
    out = FRF.from_points(points, packed.outputs, packed.group_names, parameter_name=name,
                          complete=complete, message=message,
                          stability_computed=packed.stability)
    out.timings = timings
    if keep_unknowns and points:
        out._last_unknowns = points[-1].unknowns
        out._last_slider = points[-1].slider
    return out


def _homotopy_start(packed: _Packed, omega: float):
    """Unknowns at omega reached by load continuation of the dynamic excitation from 0 to
    1 (None if that fails too); packed.w0 becomes the contact history that path leaves."""
    o = SolverOptions(**{**packed.opts.__dict__, "parameter": "load"})
    lp = _Packed.__new__(_Packed)
    lp.__dict__.update(packed.__dict__)
    lp.w0 = packed.w0.copy()
    lp.opts = o
    lp.mode = 2
    lp.stability = False
    fe = packed.fe0
    mask = np.zeros(packed.nc, bool)
    mask[1:] = True
    lp.fe1 = np.where(mask, fe, 0.0)
    lp.fe0 = fe - lp.fe1
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            r = _run(lp, 0.0, 1.0, omega, None, None, None, keep_unknowns=True)
    except Exception:       # noqa: BLE001 - the caller reports the original failure
        return None
    if not r.complete or not r.parameter.size or r.parameter[-1] != 1.0:
        return None
    packed.set_history(r._last_slider)
    return r._last_unknowns


def frf(model: Model | CyclicModel, excitation: Excitation, omega_start: float,
        omega_end: float, options: SolverOptions | None = None, outputs=None, sink=None,
        start=None, start_harmonics: int | None = None) -> FRF:
    """Forced response from omega_start to omega_end (rad/s) by pseudo-arc-length
    continuation in frequency, through turning points.

    outputs: DoF indices (0-based) whose harmonics are kept (default: all DoFs up to 100,
    else the contact DoFs). sink(point) receives every converged FRFPoint as it comes.
    start: resume from {'parameter' (or 'omega'), 'unknowns', 'tangent'} of a saved point
    (e.g. FRFWriter.resume_point); with start_harmonics != options.harmonics the unknowns
    of that lower-H solution are padded and re-solved first.
    A run that cannot continue returns the points made so far (frf.complete False,
    frf.message says why) and warns.
    """
    options = options or SolverOptions()
    if options.parameter != "frequency":
        options = SolverOptions(**{**options.__dict__, "parameter": "frequency"})
    for nm, v in (("omega_start", omega_start), ("omega_end", omega_end)):
        if not (np.isfinite(v) and v > 0):
            raise ParameterError(f"{nm}: expected a positive frequency in rad/s, got {v}")
    if omega_start == omega_end:
        raise ParameterError("omega_start and omega_end must differ")
    packed = _Packed(model, excitation, options, outputs)
    return _run(packed, float(omega_start), float(omega_end), 0.0, sink, start,
                start_harmonics)


def load_curve(model: Model | CyclicModel, excitation: Excitation, omega: float,
               scale_start: float, scale_end: float, options: SolverOptions | None = None,
               outputs=None, sink=None, start=None, part: str = "dynamic") -> FRF:
    """Continuation in a load factor s at fixed frequency omega: the excitation is
    F_other + s F_part, where part is 'dynamic' (harmonics >= 1: excitation level) or
    'static' (harmonic 0: preload)."""
    options = options or SolverOptions()
    options = SolverOptions(**{**options.__dict__, "parameter": "load"})
    if not (np.isfinite(omega) and omega > 0):
        raise ParameterError(f"omega: expected a positive frequency in rad/s, got {omega}")
    if scale_start == scale_end:
        raise ParameterError("scale_start and scale_end must differ")
    packed = _Packed(model, excitation, options, outputs, load_part=part)
    return _run(packed, float(scale_start), float(scale_end), float(omega), sink, start, None)


def solve_point(model: Model | CyclicModel, excitation: Excitation, omega: float,
                options: SolverOptions | None = None, outputs=None, start=None,
                start_harmonics: int | None = None) -> FRFPoint:
    """The periodic response at one frequency omega (rad/s), Newton from the linear
    solution, or from start (an FRFPoint, or a dict with 'unknowns' of a solution with
    start_harmonics harmonics, default options.harmonics, padded with zeros, and/or
    'slider', the contact history to start from: FRFPoint.slider; without 'unknowns'
    Newton starts from the linear solution). Without a slider the model's w0 is the
    history. If Newton from the linear solution fails, the point is
    reached by continuation in the excitation level. The returned point's slider is the
    history it leaves (pass the point as the next start to follow a path)."""
    options = options or SolverOptions()
    options = SolverOptions(**{**options.__dict__, "parameter": "frequency"})
    if not (np.isfinite(omega) and omega > 0):
        raise ParameterError(f"omega: expected a positive frequency in rad/s, got {omega}")
    packed = _Packed(model, excitation, options, outputs)
    if isinstance(start, FRFPoint):
        start = {"unknowns": start.unknowns, "slider": start.slider}
    if start is not None:
        packed.set_history(start.get("slider"))
    cold = start is None or start.get("unknowns") is None
    y0 = np.zeros(packed.ny) if cold else packed.pad_start(
        start["unknowns"], options.harmonics if start_harmonics is None else start_harmonics)
    t0 = time.perf_counter()
    res = packed.call(y0, float(omega), np.zeros(packed.ny + 1), 2, options.ds,
                      float(omega) * 1.1, 0.0, 1e-300, float(omega), 1)
    if res.info != 0 and cold:
        # Newton from the linear solution failed: continuation in the excitation level
        y_h = _homotopy_start(packed, float(omega))
        if y_h is not None:
            res = packed.call(y_h, float(omega), np.zeros(packed.ny + 1), 2, options.ds,
                              float(omega) * 1.1, 0.0, 1e-300, float(omega), 1)
    raise_for_status(res.info, res.msg)
    pt = packed.points(res, 0.0, time.perf_counter() - t0)[0]
    pt.output_dofs = packed.outputs
    pt.timings = {}
    _add_timings(pt.timings, res.timings)
    return pt
