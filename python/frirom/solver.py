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

import dataclasses
import re
import time
import warnings
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ._errors import (CODES, MAX_HARMONICS, MAX_OMEGA, ParameterError, SizeError, check_integer,
                      check_number, raise_for_status, samples_problem)
from ._pack import (HILL_MAX, MODES_MAX, ORBIT_TOL, TIMER_NAMES,  # noqa: F401 - public here
                    kept_unknowns)
from ._pack import (START_CONTINUE, START_RESUME, START_SOLVE_ONLY, YSCALE_RELATIVE, _Packed,
                    _split_load, add_timings, pack)
from .harmonics import default_samples
from .model import CyclicModel, Excitation, Model
from ._peak import refine_peaks
from .results import FRF, FRFPoint

#: Names of the formulations (SolverOptions.formulation).
FORMULATIONS = ("condensed", "banded")

#: Largest leak of a travelling-wave selection (FRFPoint.leak) a run accepts without a
#: warning. A tuned rotor leaks at round-off: 5e-10 on the coarse flange in stick (the
#: cyclic symmetry of the mesh and matrices to their digits), 2.5e-9 with slip and
#: lift-off (the closed-cycle iteration of the slipping elements). A force off the
#: selection of 1e-6 of those on it moves the response by about that fraction (times the
#: amplification of an off-selection resonance), far below the 1e-3 the paper's
#: comparisons resolve; a changed preload or stiffness at one of 12 pairs leaks 4e-2 or
#: more, and so do the sliders a re-stuck flange keeps from slipping (4e-3, static part).
LEAK_TOL = 1e-6


def warn_leak(leak: float, omega: float, stacklevel: int, what: str = "") -> None:
    """Warn (RuntimeWarning) when a travelling-wave selection's leak (FRFPoint.leak) is
    above LEAK_TOL; omega: rad/s, where; stacklevel: 1 = the caller of warn_leak, 2 = its
    caller, and so on; what: names the point when it is not one of the run's."""
    if leak > LEAK_TOL:
        warnings.warn(f"frirom: the travelling-wave selection leaks: contact forces off "
                      f"the selection reach {leak:.2g} of those on it at "
                      f"{omega / 2 / np.pi:.6g} Hz{f' ({what})' if what else ''} (tolerance "
                      f"{LEAK_TOL:g}); the rotor, its "
                      "contacts, its load or the contact history carried from point "
                      "to point (sliders frozen at different phases) are not a "
                      "travelling wave there, and the selected solution is not the "
                      "full one (solve without the selection to see how far)",
                      RuntimeWarning, stacklevel=stacklevel + 1)


@dataclass
class SolverOptions:
    """Settings of the harmonic balance solver.

    Attributes
    ----------
    harmonics : int
        H: the response keeps harmonics 0..H (2H+1 real coefficients per DoF).
    samples : int or None
        AFT time samples per period, >= 2H+1; None: the default of
        :func:`frirom.harmonics.default_samples` (:attr:`n_samples`).
    formulation : {'condensed', 'banded'}
        'condensed' (Eq. 5-9): unknowns are the contact DoFs' harmonics, receptances from
        the linear part; 'banded': all DoFs x harmonics, banded LU in RCM order.
    tol_residual : float
        Newton converges when ||R|| is below this times the size of the terms of R.
    tol_update : float
        ... and ||dy|| below this times ||y|| (both tests relative: the same in N and mN).
    tol_stall : float
        After max_iter iterations a residual stagnating below this is accepted (a contact
        state changing inside one time sample makes R non-differentiable); 0 disables.
    max_iter : int
        Newton iterations per corrector.
    ds, ds_min, ds_max : float
        Initial, smallest and largest arc-length step, in scaled variables (unknowns /
        |first point|, parameter / range): dimensionless.
    max_points : int
        Points per run; a run that reaches it stops with ``complete`` False (a run resumed
        from a checkpoint counts the points made before it).
    parameter : {'frequency', 'load'}
        The continuation parameter: frequency omega (rad/s) or a load factor (set by
        :func:`frf`, :func:`load_curve` and :func:`solve_point` themselves).
    reuse_jacobian : bool
        Keep a factorisation while Newton contracts by a factor 10 per iteration (a
        corrector that fails with reuse is retried with a fresh Jacobian every iteration).
    stability : bool
        Hill's method at every point: the Floquet exponents in the strip |Im s| <= omega/2
        (and the centred copies of modes above (H + 1/2) omega); a dense eigen-solve of
        size 2 n_dof (2H+1) up to :data:`HILL_MAX`, shift-invert Arnoldi about s = 0 above
        (strip only).
    history : bool
        Carry the contact history along the curve: each point starts its sliders where the
        previous point's closed cycles left them. False restarts every point from the
        model's w0, which makes a contact stuck all cycle snap back to it.
    modes : int or None
        Condensed formulation only: receptances by superposition of this many lowest modes
        (mass-normalised; damping ratios from Damping.modal or the diagonal of
        Phi^T C Phi) instead of factorising the dynamic stiffness at every frequency
        (truncation: no residual flexibility). None: exact receptances.
    batch : int
        Points per call into Fortran: how often `sink` receives points (and where a
        resumed run may start); the points themselves do not depend on it.
    refine_peak : bool
        Frequency runs: solve each output's peak on the curve between the points around
        the largest one (FRF.peaks, FRF.peak; per resonance one to three corrector solves
        on a smooth peak, about ten at a corner, shared by the outputs peaking there).
    coordinates : {'auto', 'dofs', 'contact'}
        Condensed formulation: unknowns are the harmonics of the contact DoFs ('dofs') or
        of the contact elements' local relative displacements G x ('contact'); 'auto' takes
        the shorter ('dofs' when stability is asked: Hill's method needs them).
    receptances : {'auto', 'modes', 'factorization', 'sparse'}
        Condensed formulation, without `modes`: how the receptances T D_h^-1 T^T are
        found at each frequency. 'modes': from all modes of the model, one dense
        eigen-decomposition (exact; needs damping that the modes diagonalise: modal,
        Rayleigh, none); 'factorization': a banded LU of the dynamic stiffness per
        harmonic (any damping); 'sparse': a sparse LU (MUMPS) per harmonic (any
        damping; large unreduced FE). 'auto': 'modes' for a model of at most
        :data:`MODES_MAX` DoFs whose band LUs over an FRF (``_pack.EIG_EVALS``
        evaluations) would cost more than one dense eigen-solve (a reduced model) and
        whose damping the modes diagonalise, else 'sparse' when the band LU would cost
        more than ``_pack.SPARSE_FLOPS`` per harmonic, else 'factorization'. The choice is in
        ``FRF.solver_info``.
    krylov : bool
        Condensed formulation: solve with each new Jacobian by GMRES preconditioned by
        the LU of an earlier one, factorising again only when GMRES needs many
        iterations (same answers, 2-10x fewer dense LUs). Off by default. Measured at ROM_I
        size (2 800 unknowns, cases/bench/condensed.py): GMRES iterations are memory
        bound (~25 ms each, 2 cores shared) and the stale preconditioner needs ~8-18 per
        solve, so the FRF takes as long as with a new LU per Jacobian.
    selection : ndarray or None
        (n_dof, H+1) bool: a travelling-wave selection of the condensed unknowns. Harmonic
        h of nonlinear DoF j is solved for only where ``selection[j, h]``; the others are
        held at zero and their equations dropped. Exact for a tuned rotor under an
        engine-order travelling wave on multi-stage coordinates
        (:func:`frirom.reduction.multistage.travelling_wave_selection`), several times
        fewer unknowns. Each point reports its leak (``FRFPoint.leak``: contact forces off
        the selection over those on it); a run warns above :data:`LEAK_TOL`. Needs the
        condensed formulation in the nonlinear DoFs, no Krylov solves and no stability.
    pairs : ndarray or None
        (n_dof, H+1) int, with ``selection``: the wave's direction, ``pairs[j, h] = s (k +
        1)`` ties harmonic h of nonlinear DoF j to that of k by x_k,sin = s x_j,cos and
        x_k,cos = -s x_j,sin, and each pair's four unknowns become two
        (:func:`frirom.reduction.multistage.travelling_wave_pairs`); 0: no pair. Exact
        when the selection is, for one travelling direction; the leak then also counts
        the other direction.
    orbits : bool
        With ``pairs``: Newton's evaluations run the contact law (AFT) on one contact
        element per orbit, the elements whose motion on the wave is another's turned in
        time (one sector's copies; found from the model, matched to :data:`ORBIT_TOL`,
        with equal parameters), and the Jacobian from those alone (50x less AFT and
        assembly on 50 sectors). Every element still runs at the points kept (contact
        history, states, outputs), where the leak also counts what the orbits left out:
        the AFT samples a turned cycle at other instants, and a carried history need not
        be a wave. No effect without pairs.
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
    refine_peak: bool = True
    coordinates: str = "auto"
    receptances: str = "auto"
    krylov: bool = False
    selection: np.ndarray | None = field(default=None, repr=False)
    pairs: np.ndarray | None = field(default=None, repr=False)
    orbits: bool = True

    def check(self) -> None:
        """Raise ParameterError naming the first invalid field."""
        check_integer("options.harmonics", self.harmonics, minimum=0, maximum=MAX_HARMONICS)
        if self.samples is not None and samples_problem(self.harmonics, self.samples):
            raise ParameterError(f"options.samples: expected "
                                 f"{samples_problem(self.harmonics, self.samples)}, got "
                                 f"{self.samples!r}")
        for nm in ("max_iter", "max_points", "batch"):
            check_integer(f"options.{nm}", getattr(self, nm), minimum=1, maximum=2**31 - 1)
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
        if self.ds > self.ds_max:
            raise ParameterError(f"options.ds: expected a first step at most ds_max = "
                                 f"{self.ds_max:g}, got {self.ds:g}")
        if self.modes is not None and (self.modes < 1 or self.formulation != "condensed"):
            raise ParameterError("options.modes: a positive number of modes, with "
                                 "formulation 'condensed'")
        for nm in ("refine_peak", "krylov", "stability", "history", "reuse_jacobian",
                   "orbits"):
            if not isinstance(getattr(self, nm), (bool, np.bool_)):
                raise ParameterError(f"options.{nm}: expected true or false, got "
                                     f"{getattr(self, nm)!r}")
        if self.coordinates == "contact" and self.stability:
            raise ParameterError("options.coordinates: 'contact' cannot be used with "
                                 "stability (Hill's method needs the contact DoFs)")
        if self.selection is not None:
            for bad, why in ((self.formulation != "condensed", "the 'condensed' formulation"),
                             (self.stability, "stability = false (Hill's method would see "
                                              "only perturbations inside the selection)"),
                             (self.krylov, "krylov = false (direct solves)"),
                             (self.coordinates == "contact", "coordinates 'dofs' or 'auto'")):
                if bad:
                    raise ParameterError(f"options.selection: a travelling-wave selection "
                                         f"needs {why}")
        if self.pairs is not None and self.selection is None:
            raise ParameterError("options.pairs: needs options.selection")
        for nm, allowed in (("coordinates", ("auto", "dofs", "contact")),
                            ("receptances", ("auto", "modes", "factorization", "sparse"))):
            if getattr(self, nm) not in allowed:
                raise ParameterError(f"options.{nm}: expected one of {list(allowed)}, got "
                                     f"{getattr(self, nm)!r}")

    @property
    def n_samples(self) -> int:
        """AFT time samples per period actually used: `samples`, else the measured default
        :func:`frirom.harmonics.default_samples` (1e-4 relative on a friction resonance)."""
        return self.samples or default_samples(self.harmonics)


@dataclass
class _Continuation:
    """One continuation run from lam_start to lam_end: :meth:`start` reaches the first
    point, :meth:`batches` asks Fortran for points `batch` at a time and hands each to
    `sink`, :meth:`finish` makes the FRF. Between calls it holds where the next call
    starts (y0, lam0, tan0, ds, start_mode) and the arc-length scale of the unknowns."""

    packed: _Packed
    lam_start: float
    lam_end: float
    omega_fix: float          # rad/s of a load continuation (0 for frequency)
    sink: Callable[[FRFPoint], None] | None
    points: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)
    y0: np.ndarray | None = None
    lam0: float = 0.0
    tan0: np.ndarray | None = None
    ds: float = 0.0
    start_mode: int = START_CONTINUE
    yscale: float = 1.0
    prev_t: float | None = None   # parameter part of the previous point's tangent
    pending: bool = False         # points[-1] awaits its tangent from the next call
    n_before: int = 0             # points a resumed run made before (count to max_points)
    leak_before: tuple | None = None  # their largest leak and its omega (FRFWriter file)
    t0: float = 0.0               # perf_counter at the start of the current call

    @property
    def lscale(self) -> float:
        return abs(self.lam_end - self.lam_start) or 1.0

    @property
    def lam_lo(self) -> float:
        return self.lam_start - 0.02 * (self.lam_end - self.lam_start)

    def _call(self, y0, start_mode, yscale, maxpts):
        return self.packed.call(y0, self.lam0, self.tan0, start_mode, self.ds, self.lam_end,
                                self.lam_lo, yscale, self.lscale, maxpts, self.omega_fix)

    def start(self, start, H_start) -> None:
        """From nothing, or from a saved point (FRFPoint or dict): resume from its tangent,
        or solve at its parameter first (no tangent, other H or unknown history). A
        checkpoint (dict with 'ds', the step the run continued with, and 'n_points', the
        points made up to it; FRFWriter.resume_point) continues exactly as the
        uninterrupted run did: same step, arc-length scale, history and call boundaries;
        its 'lscale' (parameter range of the run that wrote it) rescales the tangent when
        the range was extended since."""
        p = self.packed
        self.t0 = time.perf_counter()
        self.ds = p.opts.ds
        if start is None:
            self.y0, self.tan0 = np.zeros(p.ny), np.zeros(p.ny + 1)
            self.lam0, self.start_mode = self.lam_start, START_CONTINUE
        else:
            if isinstance(start, FRFPoint):
                start = {"parameter": start.parameter, "unknowns": start.unknowns,
                         "tangent": start.tangent, "yscale": start.yscale,
                         "slider": start.slider}
            p.set_history(start.get("slider"))
            self.y0 = p.pad_start(start["unknowns"], H_start if H_start is not None else p.H)
            self.lam0 = float(start.get("parameter", start.get("omega")))
            tan = start.get("tangent")
            # without the history the point was computed with (a file from before it was
            # kept), the saved point need not solve the equations: re-solve it first; a
            # tangent without a scale (a solve at fixed parameter: solve_point, a run's
            # first point) is in no scale to resume in: from the point, a new tangent
            unknown_history = p.nw and p.opts.history and start.get("slider") is None
            if tan is None or not start.get("yscale") or H_start not in (None, p.H) or \
                    unknown_history:
                self.start_mode, self.tan0 = START_CONTINUE, np.zeros(p.ny + 1)
            else:
                self.start_mode, self.tan0 = START_RESUME, np.asarray(tan, dtype=float)
                if self.tan0.size != p.ny + 1:
                    raise SizeError("start.tangent: size does not match the unknowns")
                self.n_before = int(start.get("n_points", 0))
            # the stored points' worst leak, whichever way the run goes on from them
            self.leak_before = start.get("leak")
        if self.start_mode == START_CONTINUE:
            self._first_point(start is None)
        self.yscale = float(np.linalg.norm(self.y0)) or 1.0
        if self.start_mode == START_RESUME:
            self.prev_t = self.tan0[-1]
            self.yscale = float(start["yscale"])    # the saved tangent's scaling
            if start.get("ds") is not None:
                # a checkpoint: the uninterrupted run's next call, as _advance made it
                tan = self.tan0
                old_l = float(start.get("lscale") or self.lscale)
                if old_l != self.lscale:        # the range changed: same direction
                    tan = tan.copy()
                    tan[-1] *= old_l / self.lscale
                    tan /= np.linalg.norm(tan)
                self._continue_from(self.y0, self.lam0, tan, float(start["ds"]))

    def _first_point(self, cold: bool) -> None:
        """Solve at fixed parameter with a purely relative update test; the size of that
        solution then scales the arc length, and the next call (START_CONTINUE from the
        converged point, one Newton iteration) computes the tangent in that scaling."""
        p = self.packed
        res = self._call(self.y0, START_SOLVE_ONLY, YSCALE_RELATIVE, 1)
        add_timings(self.timings, res.timings)
        if res.info != 0 and p.opts.parameter == "frequency" and cold:
            # Newton from the linear solution failed (strong slip or lift-off): reach the
            # first point by continuation in the excitation level from the static state.
            y_h = _homotopy_start(p, self.lam0)
            if y_h is not None:
                res = self._call(y_h, START_SOLVE_ONLY, YSCALE_RELATIVE, 1)
        raise_for_status(res.info, res.msg)
        first = p.points(res, self.omega_fix, time.perf_counter() - self.t0)[0]
        self.t0 = time.perf_counter()
        self.points.append(first)     # handed to sink once its tangent is known
        self.y0, self.pending = first.unknowns, True

    def _emit(self, p: FRFPoint) -> None:
        if self.sink is not None:
            self.sink(p)

    def _take(self, new: list) -> None:
        """Keep a call's points: the pending first point gets its tangent from the first
        of them; a tangent whose parameter part changes sign marks a fold."""
        if self.pending and new:
            self.prev_t = new[0].tangent[-1]
            self.points[-1].tangent = new[0].tangent
            self.points[-1].yscale = new[0].yscale
            self.points[-1].ds_next = new[0].ds_next
            self._emit(self.points[-1])
            new = new[1:]
        elif self.pending:
            self._emit(self.points[-1])
        self.pending = False
        for p in new:
            if self.prev_t is not None and self.prev_t != 0 and \
                    np.sign(p.tangent[-1]) != np.sign(self.prev_t):
                p.fold = True
            self.prev_t = p.tangent[-1]
            self.points.append(p)
            self._emit(p)

    def batches(self) -> tuple[bool, str]:
        """Continue until lam_end, a failure or max_points; returns (complete, message)."""
        o = self.packed.opts
        while self.n_before + len(self.points) < o.max_points:
            maxpts = min(o.batch, o.max_points - self.n_before - len(self.points)) + \
                int(self.pending)
            self.packed.forget_lu()     # a checkpoint: resume starts here, LU-less
            res = self._call(self.y0, self.start_mode, self.yscale, maxpts)
            t_call = time.perf_counter() - self.t0
            self.t0 = time.perf_counter()
            add_timings(self.timings, res.timings)
            new = self.packed.points(res, self.omega_fix, t_call)
            if new and res.info == 0:
                new[-1].ds_next = res.ds_out      # a checkpoint (FRFWriter.resume_point)
            self._take(new)
            if res.info != 0:
                return False, self._stopped(res.info, res.msg.strip())
            if not self.points:
                return True, ""
            self._advance(res.ds_out)
            if res.finished:
                return True, ""
        return False, f"stopped after max_points = {o.max_points} points"

    def _stopped(self, info: int, message: str) -> str:
        """Explain a run Fortran stopped; raise if it made no point at all."""
        if info == CODES["FRIROM_ERR_CONT"] and self.packed.nw:
            message += _contact_advice(self.packed.opts, message)
        if not self.points and not self.n_before:
            raise_for_status(info, message)
        warnings.warn(f"frirom: continuation stopped early, {len(self.points)} points kept: "
                      f"{message}", RuntimeWarning, stacklevel=5)
        return message

    def _advance(self, ds_out: float) -> None:
        """The next call resumes from the last point, in the arc-length scale of its
        tangent (Fortran grows the scale with the solution after every point, so the path
        does not depend on `batch`)."""
        last = self.points[-1]
        self.yscale = last.yscale
        self._continue_from(last.unknowns, last.parameter, last.tangent, ds_out)

    def _continue_from(self, y, lam, tan, ds) -> None:
        """The next call starts from the converged point (y, lam) with tangent tan (in
        the scale self.yscale) and step ds."""
        self.y0, self.lam0, self.tan0 = y, lam, tan
        self.ds, self.start_mode = ds, START_RESUME

    def finish(self, complete: bool, message: str, keep_unknowns: bool) -> FRF:
        p, pts = self.packed, self.points
        if complete and pts and pts[-1].parameter != self.lam_end:
            complete = False
            message = (f"the solution curve turned back and left the range through "
                       f"{pts[-1].parameter:.6g} (start {self.lam_start:.6g})")
        name = "omega" if p.opts.parameter == "frequency" else "load"
        out = FRF.from_points(pts, p.outputs, p.group_names, parameter_name=name,
                              complete=complete, message=message,
                              stability_computed=p.stability)
        out.timings = self.timings
        out.solver_info = p.info
        if p.keep is not None and (pts or self.leak_before):
            k = int(np.argmax(out.leak)) if pts else 0
            worst, at = (float(out.leak[k]), pts[k].omega) if pts else (-1.0, 0.0)
            if self.leak_before is not None and self.leak_before[0] > worst:
                worst, at = self.leak_before      # a point stored before the resume
            out.solver_info += f"; leak max {worst:.1e}"
            warn_leak(worst, at, stacklevel=4)
        if keep_unknowns and pts:
            out._last_unknowns = pts[-1].unknowns
            out._last_slider = pts[-1].slider
        return out


#: The stalled residual |R|/rref the Fortran corrector reports when it gives up.
_STALLED = re.compile(r"\|R\|/rref\s*=\s*([0-9.Ee+-]+)")


def _contact_advice(opts: SolverOptions, message: str) -> str:
    """What to change after a continuation with friction contacts stopped at ds_min: only
    settings that would change the outcome, computed from the options in use and the
    failure (the last corrector's |R|/rref in `message`).

    The AFT samples the contacts at N points per period; a contact state switching at one
    of them makes the equations piecewise smooth and Newton can stall at a residual below
    the sampling error (which falls like 1/N^2). Advised: tol_stall above a stalled
    residual below 1/N^2 (such a point is then accepted); max_iter when the residual had
    met tol_residual and only the update test was missing; ds_min when it is so large
    that the step could not shrink much; the default N for this H when fewer samples are
    in use.
    """
    N = opts.n_samples
    default_N = dataclasses.replace(opts, samples=None).n_samples
    tips = []
    m = _STALLED.search(message)
    stalled = float(m.group(1)) if m and _is_float(m.group(1)) else None
    if stalled is not None and opts.tol_stall < stalled <= 1.0 / N**2:
        tips.append(f"tol_stall = {float(f'{2.0 * stalled:.0e}'):g} (now "
                    f"{opts.tol_stall:g}): a corrector stalling below it is accepted (the "
                    f"last one stalled at |R|/rref = {stalled:.2e})")
    if stalled is not None and stalled <= opts.tol_residual:
        tips.append(f"max_iter = {2 * opts.max_iter} (now {opts.max_iter}): the last "
                    "corrector had met tol_residual and missed only the update test")
    if opts.ds_min > 1e-4:
        tips.append(f"ds_min = {opts.ds_min / 100:g} (now {opts.ds_min:g}): the step "
                    "could not shrink further")
    if N < default_N:
        tips.append(f"samples = {default_N} (the default for H = {opts.harmonics}; now "
                    f"{N}): smaller corners where a contact state switches")
    text = (f" [N = {N} AFT samples per period (samples = {opts.samples}); where a "
            "contact state switches at one of them the curve has a corner")
    if tips:
        return text + "; try " + "; or ".join(tips) + "]"
    return text + "]"


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _run(packed: _Packed, lam_start, lam_end, omega_fix, sink, start, H_start,
         keep_unknowns=False) -> FRF:
    run = _Continuation(packed, lam_start, lam_end, omega_fix, sink)
    run.start(start, H_start)
    complete, message = run.batches()
    out = run.finish(complete, message, keep_unknowns)
    if packed.opts.refine_peak and packed.opts.parameter == "frequency" and run.points:
        out.peaks, solved = refine_peaks(packed, run.points, lam_end, run.lam_lo, run.lscale)
        if packed.keep is not None:
            k = int(np.argmax([q.leak for q in solved])) if solved else -1
            if k >= 0:
                warn_leak(solved[k].leak, solved[k].omega, stacklevel=3,
                          what="a peak solved between points")
    return out


def _homotopy_start(packed: _Packed, omega: float):
    """Unknowns at omega reached by load continuation of the dynamic excitation from 0 to
    1 (None if that fails too); packed.w0 becomes the contact history that path leaves."""
    fe0, fe1 = _split_load(packed.fe0, "dynamic")
    lp = dataclasses.replace(packed, opts=dataclasses.replace(packed.opts, parameter="load"),
                             fe0=fe0, fe1=fe1, w0=packed.w0.copy(), stability=False)
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
    """Forced response from omega_start to omega_end by pseudo-arc-length continuation in
    frequency, through turning points.

    Parameters
    ----------
    model : Model or CyclicModel
    excitation : Excitation
    omega_start, omega_end : float
        Frequency range, rad/s (either direction).
    options : SolverOptions, optional
        Its ``parameter`` is set to 'frequency'.
    outputs : array_like of int, or (n_out, n_dof) array, optional
        DoF indices (0-based) whose harmonics are kept, or a matrix P whose rows give each
        output as P x (physical DoFs through a reduction basis); default all DoFs up to
        100, else the contact DoFs.
    sink : callable, optional
        ``sink(point)`` receives every converged FRFPoint as it comes.
    start : FRFPoint or dict, optional
        Resume from a saved point: {'parameter' (or 'omega'), 'unknowns', 'tangent',
        'slider', 'yscale'}; a checkpoint (FRFWriter.resume_point) adds 'ds' and
        'n_points' (and 'lscale' when the range was extended) and continues exactly as the
        uninterrupted run did.
    start_harmonics : int, optional
        H of the start's unknowns when it differs from options.harmonics: they are padded
        or cut and re-solved first.

    Returns
    -------
    FRF
        A run that cannot continue returns the points made so far (``complete`` False,
        ``message`` says why) and warns.
    """
    options = options or SolverOptions()
    if options.parameter != "frequency":
        options = dataclasses.replace(options, parameter="frequency")
    for nm, v in (("omega_start [rad/s]", omega_start), ("omega_end [rad/s]", omega_end)):
        check_number(nm, v, positive=True, maximum=MAX_OMEGA)
    if omega_start == omega_end:
        raise ParameterError("omega_start and omega_end must differ")
    packed = pack(model, excitation, options, outputs)
    return _run(packed, float(omega_start), float(omega_end), 0.0, sink, start,
                start_harmonics)


def load_curve(model: Model | CyclicModel, excitation: Excitation, omega: float,
               scale_start: float, scale_end: float, options: SolverOptions | None = None,
               outputs=None, sink=None, start=None, part: str = "dynamic") -> FRF:
    """Continuation in a load factor s at a fixed frequency: the excitation is
    F_other + s F_part.

    Parameters
    ----------
    omega : float
        Frequency, rad/s.
    scale_start, scale_end : float
        Range of the load factor s (dimensionless).
    part : {'dynamic', 'static'}
        The scaled part: harmonics >= 1 (excitation level) or harmonic 0 (preload).
    model, excitation, options, outputs, sink, start
        As in :func:`frf` (``options.parameter`` is set to 'load').

    Returns
    -------
    FRF
        ``parameter`` holds s, ``omega`` the fixed frequency.
    """
    options = options or SolverOptions()
    options = dataclasses.replace(options, parameter="load")
    check_number("omega [rad/s]", omega, positive=True, maximum=MAX_OMEGA)
    check_number("scale_start", scale_start)
    check_number("scale_end", scale_end)
    if scale_start == scale_end:
        raise ParameterError("scale_start and scale_end must differ")
    packed = pack(model, excitation, options, outputs, load_part=part)
    return _run(packed, float(scale_start), float(scale_end), float(omega), sink, start, None)


def solve_point(model: Model | CyclicModel, excitation: Excitation, omega: float,
                options: SolverOptions | None = None, outputs=None, start=None,
                start_harmonics: int | None = None) -> FRFPoint:
    """The periodic response at one frequency, by Newton's method.

    Newton starts from the linear solution, or from `start`; if Newton from the linear
    solution fails, the point is reached by continuation in the excitation level.

    Parameters
    ----------
    omega : float
        Frequency, rad/s.
    start : FRFPoint or dict, optional
        'unknowns' of a solution with `start_harmonics` harmonics (default
        options.harmonics; padded with zeros or cut) and/or 'slider', the contact history
        to start from (FRFPoint.slider). Without 'unknowns' Newton starts from the linear
        solution; without 'slider' the model's w0 is the history.
    model, excitation, options, outputs, start_harmonics
        As in :func:`frf`.

    Returns
    -------
    FRFPoint
        Its ``slider`` is the history it leaves: pass the point as the next start to
        follow a path. ``timings`` holds the Fortran time split (TIMER_NAMES).
    """
    options = options or SolverOptions()
    options = dataclasses.replace(options, parameter="frequency")
    if not (np.isfinite(omega) and omega > 0):
        raise ParameterError(f"omega: expected a positive frequency in rad/s, got {omega}")
    packed = pack(model, excitation, options, outputs)
    if isinstance(start, FRFPoint):
        start = {"unknowns": start.unknowns, "slider": start.slider}
    if start is not None:
        packed.set_history(start.get("slider"))
    cold = start is None or start.get("unknowns") is None
    y0 = np.zeros(packed.ny) if cold else packed.pad_start(
        start["unknowns"], options.harmonics if start_harmonics is None else start_harmonics)
    t0 = time.perf_counter()
    res = packed.call(y0, float(omega), np.zeros(packed.ny + 1), START_SOLVE_ONLY,
                      options.ds, float(omega) * 1.1, 0.0, YSCALE_RELATIVE, float(omega), 1)
    if res.info != 0 and cold:
        # Newton from the linear solution failed: continuation in the excitation level
        y_h = _homotopy_start(packed, float(omega))
        if y_h is not None:
            res = packed.call(y_h, float(omega), np.zeros(packed.ny + 1), START_SOLVE_ONLY,
                              options.ds, float(omega) * 1.1, 0.0, YSCALE_RELATIVE,
                              float(omega), 1)
    raise_for_status(res.info, res.msg)
    pt = packed.points(res, 0.0, time.perf_counter() - t0)[0]
    if pt.leak is not None:
        warn_leak(pt.leak, pt.omega, stacklevel=2)
    pt.output_dofs = packed.outputs
    pt.timings = {}
    add_timings(pt.timings, res.timings)
    return pt
