"""Settings of the harmonic balance solver (:class:`SolverOptions`), checked once, read
by :mod:`frirom._pack` (the model's packing and route policy) and :mod:`frirom.solver`
(which re-exports them). The numerical defaults are Fortran's (frirom._run.DEFAULTS, the
run_settings of fortran/frirom_run.f90), the one place they are written.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._errors import MAX_HARMONICS, ParameterError, check_integer, samples_problem
from ._run import DEFAULTS
from .harmonics import default_samples

#: Names of the formulations (SolverOptions.formulation).
FORMULATIONS = ("condensed", "banded")


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
        Without it Newton takes the Jacobian at every iterate from its line-search
        evaluation (no extra one): on small models about 15 % faster (the friction beam of
        cases/bench/run.py, 15 unknowns: 810 evaluations against 1 327).
    stability : bool, "auto" or "strip"
        Hill's method at every point: the Floquet exponents in the strip |Im s| <= omega/2
        (and the centred copies of modes above (H + 1/2) omega); a dense eigen-solve of
        size 2 n_dof (2H+1) up to :data:`HILL_MAX`, shift-invert Arnoldi about s = 0 above
        (strip only). Above HILL_MAX a reduced model (receptances from real modes) gets
        the exponents nearest s = 0 only, through the point solve's own Newton matrix
        (folds and the resonant mode's pair; docs/theory.md, "Stability: Hill's
        method"); "strip" asks for the whole strip there too (Neimark-Sacker
        and period doubling of modes far from resonance), at many times the cost.
        "auto": on where affordable (frirom._pack.resolve_stability: at most
        HILL_AUTO_MAX Hill unknowns, not with a selection, contact coordinates or a cyclic
        sector), off otherwise, the reason in FRF.solver_info.
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
        :data:`MODES_MAX` DoFs whose band LUs over an FRF (``_routes.EIG_EVALS``
        evaluations) would cost more than one dense eigen-solve (a reduced model) and
        whose damping the modes diagonalise, else 'sparse' when the band LU would cost
        more than ``_routes.SPARSE_FLOPS`` per harmonic, else 'factorization'. The choice is in
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
    harmonics_kept : str, sequence of int, dict or None
        Harmonic selection: the harmonics the nonlinear DoFs are solved for, the others held
        at zero and their equations dropped (Galerkin on the kept harmonics; outputs are
        the linear response to the contact forces on the kept harmonics). ``"odd"``
        (1, 3, 5, ...: a symmetric nonlinearity under a harmonic load, e.g. Duffing or a
        friction contact without preload, has no even harmonics), ``"even"``, or a list
        such as ``[0, 1, 2, 3, 5]``; or a dict from contact group (name or 0-based index)
        to such a spec, for the DoFs of that group only (a DoF in several groups keeps what
        any of them keeps; DoFs of groups not named keep every harmonic); or a bool mask
        (n_dof, H+1) per DoF and harmonic (what :func:`frirom.auto_kept.choose_kept`
        gives). The linear part
        is exact at every harmonic (receptances); what the selection neglects is reported
        per point as its leak (``FRFPoint.leak``, the contact forces on the dropped
        harmonics over those on the kept ones), with a warning above :data:`LEAK_TOL`. A
        load on a dropped harmonic of a nonlinear DoF is refused. Same requirements as
        ``selection`` (with which it combines: both must keep a harmonic).
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

    # the defaults of Fortran's run_settings (frirom._run.DEFAULTS), the one place they
    # are written: C callers get the same from frirom_settings_default
    harmonics: int = DEFAULTS["harmonics"]
    samples: int | None = None
    formulation: str = "condensed"
    tol_residual: float = DEFAULTS["tol_residual"]
    tol_update: float = DEFAULTS["tol_update"]
    tol_stall: float = DEFAULTS["tol_stall"]
    max_iter: int = DEFAULTS["max_iter"]
    ds: float = DEFAULTS["ds"]
    ds_min: float = DEFAULTS["ds_min"]
    ds_max: float = DEFAULTS["ds_max"]
    max_points: int = DEFAULTS["max_points"]
    parameter: str = "frequency"
    reuse_jacobian: bool = bool(DEFAULTS["reuse_jacobian"])
    stability: bool | str = bool(DEFAULTS["stability"])
    history: bool = bool(DEFAULTS["history"])
    modes: int | None = None
    batch: int = DEFAULTS["batch"]
    refine_peak: bool = True
    coordinates: str = "auto"
    receptances: str = "auto"
    krylov: bool = False
    selection: np.ndarray | None = field(default=None, repr=False)
    pairs: np.ndarray | None = field(default=None, repr=False)
    orbits: bool = True
    harmonics_kept: object = field(default=None, repr=False)

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
        if isinstance(self.stability, str) and self.stability not in ("auto", "strip"):
            raise ParameterError(f"options.stability: expected true, false, 'auto' or "
                                 f"'strip', got {self.stability!r}")
        for nm in ("refine_peak", "krylov", "history", "reuse_jacobian", "orbits") + \
                (("stability",) if not isinstance(self.stability, str) else ()):
            if not isinstance(getattr(self, nm), (bool, np.bool_)):
                raise ParameterError(f"options.{nm}: expected true or false, got "
                                     f"{getattr(self, nm)!r}")
        if self.coordinates == "contact" and self.stability in (True, "strip"):
            raise ParameterError("options.coordinates: 'contact' cannot be used with "
                                 "stability (Hill's method needs the contact DoFs)")
        kh = self.harmonics_kept
        if kh is not None and not (isinstance(kh, np.ndarray) and kh.dtype == bool):
            for spec in (kh.values() if isinstance(kh, dict) else [kh]):
                kept_harmonics(spec, self.harmonics, "options.harmonics_kept")
        if self.selection is not None or self.harmonics_kept is not None:
            what = ("options.selection: a travelling-wave selection" if self.selection
                    is not None else "options.harmonics_kept: a harmonic selection")
            for bad, why in ((self.formulation != "condensed", "the 'condensed' formulation"),
                             (self.stability in (True, "strip"),
                              "stability = false (Hill's method would see "
                                              "only perturbations inside the selection)"),
                             (self.krylov, "krylov = false (direct solves)"),
                             (self.coordinates == "contact", "coordinates 'dofs' or 'auto'")):
                if bad:
                    raise ParameterError(f"{what} needs {why}")
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


def kept_harmonics(spec, H: int, where: str = "harmonics_kept") -> np.ndarray:
    """The harmonics 0..H a selection spec keeps (SolverOptions.harmonics_kept): 'odd',
    'even' or a list of distinct integers in 0..H; (H+1,) bool. ParameterError naming
    ``where`` otherwise."""
    keep = np.zeros(H + 1, dtype=bool)
    if isinstance(spec, str):
        if spec not in ("odd", "even"):
            raise ParameterError(f"{where}: expected 'odd', 'even' or a list of harmonics "
                                 f"in 0..{H}, got {spec!r}")
        keep[(1 if spec == "odd" else 0)::2] = True
    else:
        try:
            hs = [int(h) for h in spec]
            ok = all(float(h) == float(g) for h, g in zip(hs, spec))
        except (TypeError, ValueError):
            ok = False
        if not ok or not hs or len(set(hs)) != len(hs) or min(hs) < 0 or max(hs) > H:
            raise ParameterError(f"{where}: expected 'odd', 'even' or a list of distinct "
                                 f"harmonics in 0..{H} (harmonics = {H}), got {spec!r}")
        keep[hs] = True
    if not keep.any():
        raise ParameterError(f"{where}: {spec!r} keeps no harmonic of 0..{H}")
    return keep
