"""The model as the arrays of the Fortran run object (fortran/frirom_run.f90, opened
through frirom_f2py's frun_open).

:func:`pack` turns a Model or a CyclicModel, an Excitation and SolverOptions into a
:class:`_Packed`; :meth:`_Packed.run` opens the Fortran run on it once (frirom._run.Run)
and :meth:`_Packed.points` turns the run's points into FRFPoints. Timer slots are read
from Fortran at import (``int_constant``), so no number of the boundary is typed here.
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import scipy.sparse as sp

from ._errors import ParameterError, SizeError, int_constant
from ._routes import (HILL_ROUTES, _Band, _check_hill_memory, _contact_coords, _hill_route,
                      _Modes, _receptance_route)
from .contact import LAWS
from .model import CyclicModel, Excitation, Model
from .results import FRFPoint, amplitude_max

if TYPE_CHECKING:
    from .options import SolverOptions

#: Timer/counter names of each run (seconds, counts) by their 0-based slot in `timings`.
_TIMER_SLOTS = {name: int_constant(slot) - 1 for name, slot in (
    ("aft", "T_AFT"), ("assembly", "T_ASM"), ("factorization", "T_FACT"),
    ("solve", "T_SOLVE"), ("receptance", "T_REC"), ("evaluations", "N_EVAL"),
    ("factorizations", "N_FACT"), ("krylov_iterations", "N_KRYLOV"),
    ("double_factorizations", "N_DOUBLE"), ("hill", "T_HILL"),
    ("fortran_total", "N_TIMERS"))}
TIMER_NAMES = tuple(sorted(_TIMER_SLOTS, key=_TIMER_SLOTS.get))


def add_timings(acc: dict, timings: np.ndarray) -> None:
    """Add one call's timings (N_TIMERS,) to acc (name -> total, TIMER_NAMES order)."""
    for name in TIMER_NAMES:
        acc[name] = acc.get(name, 0.0) + float(timings[_TIMER_SLOTS[name]])


def _csr(a) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(indptr, indices, data) of a, 1-based, sorted; one explicit zero if a is empty."""
    a = sp.csr_matrix(a)
    a.sort_indices()
    idx = a.indices.astype(np.int32) + 1
    x = a.data.astype(float)
    if idx.size == 0:     # f2py needs at least one entry
        idx, x = np.ones(1, np.int32), np.zeros(1)
    return a.indptr.astype(np.int32) + 1, idx, x


class _Contacts(NamedTuple):
    """The contact groups packed: stacked G (rows, ncol), law/size table, parameters and
    sliders concatenated group by group."""

    G: sp.csr_matrix
    ginfo: np.ndarray        # (3, n_groups) int32: law code, n_elem, n_dir
    params: np.ndarray       # (sum n_elem n_par,), at least one entry
    w0: np.ndarray           # (nw,), at least one entry
    nw: int                  # sliders in all
    names: list[str]
    sizes: list[int]         # n_elem per group
    laws: tuple = ()         # the law of each group (names; user laws: frirom.laws.USER_LAWS)


def _pack_contacts(groups, ncol: int) -> _Contacts:
    names, sizes = [g.name for g in groups], [g.n_elem for g in groups]
    if not groups:
        return _Contacts(sp.csr_matrix((0, ncol)), np.zeros((3, 0), np.int32, order="F"),
                         np.zeros(1), np.zeros(1), 0, names, sizes, ())
    ginfo = np.array([[LAWS[g.law].code, g.n_elem, g.n_dir] for g in groups],
                     dtype=np.int32).T.copy(order="F")
    params = np.concatenate([g.params.ravel() for g in groups])
    w0 = [g.w0.ravel() for g in groups]
    nw = int(sum(a.size for a in w0))
    G = sp.vstack([sp.csr_matrix(g.G, shape=(g.G.shape[0], ncol)) if g.G.shape[1] == ncol
                   else sp.hstack([g.G, sp.csr_matrix((g.G.shape[0], ncol - g.G.shape[1]))])
                   for g in groups]).tocsr()
    return _Contacts(G, ginfo, params, np.concatenate(w0) if nw else np.zeros(1), nw,
                     names, sizes, tuple(g.law for g in groups))


def _output_map(outputs, n: int):
    """(columns, map) of outputs given as an (n_out, n) matrix (physical DoFs recovered
    through a reduction basis: x_out = map @ x[columns]); (outputs, None) otherwise."""
    if outputs is None or np.ndim(outputs) != 2:
        return outputs, None
    P = np.asarray(outputs.toarray() if sp.issparse(outputs) else outputs, dtype=float)
    if P.shape[1] != n or P.shape[0] == 0 or not np.all(np.isfinite(P)):
        raise SizeError(f"outputs: an output matrix must be finite, (n_out, {n}); got "
                        f"shape {P.shape}")
    cols = np.flatnonzero(np.any(P != 0, axis=0))
    return (cols if cols.size else np.zeros(1, dtype=int)), P[:, cols if cols.size else [0]]


def _map_dofs(P: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """(n_out,) the DoF each output row of P selects (a unit row), -1 for a combination."""
    unit = (np.count_nonzero(P, axis=1) == 1) & (P.max(axis=1) == 1.0)
    return np.where(unit, cols[np.argmax(P != 0, axis=1)], -1)


def _check_outputs(outputs, n: int) -> np.ndarray:
    raw = np.asarray(outputs).ravel()
    if raw.size and (raw.dtype.kind not in "iu" and not (
            raw.dtype.kind == "O" and all(isinstance(v, (int, np.integer))
                                          and not isinstance(v, bool) for v in raw))):
        raise SizeError(f"outputs: expected integer DoF indices, got {raw[:5].tolist()}")
    out = raw.astype(int)
    if out.size == 0:
        out = np.zeros(1, dtype=int)
    if np.any(out < 0) or np.any(out >= n):
        raise SizeError(f"outputs: DoF indices must be in 0..{n - 1}")
    return out


#: SolverOptions.orbits: an element joins an orbit when its motion on the wave is the
#: representative's turned in time to this fraction (Frobenius, over every unknown). The
#: mesh's own symmetry is far finer (coarse flange 2e-15, paper flange 1e-13, matrices
#: from ccx's text files); a misfit d moves the forces by about d.
#: Largest misfit of an element's orbit on the travelling wave (SolverOptions.orbits):
#: |G_e T - Rot(th) G_r T| <= ORBIT_TOL |G_r T| (frirom_hbm hbm_set_orbits).
ORBIT_TOL = 1e-9


@dataclass
class _Packed:
    """The model as the Fortran arrays of the run object (built once per solve by
    :func:`pack`); w0 is the model's contact history (the run's first sliders).

    Rows are the model's DoFs, or for a cyclic sector the DoFs the solver reads (contact
    DoFs of the sector and of the next one, outputs and loaded DoFs). Index arrays for
    Fortran are 1-based (K, M, C, G as (indptr, indices, data); perm), others 0-based.
    """

    opts: SolverOptions       # opts.parameter: 'frequency' or 'load'
    H: int
    n_dof: int                # rows
    fe0: np.ndarray           # (n_dof, 2H+1) N: fixed excitation
    fe1: np.ndarray           # (n_dof, 2H+1) N: excitation scaled by a load parameter
    K: tuple                  # CSR, 1-based, (n_dof, n_dof), N/m; empty: modal route
    M: tuple                  # kg
    C: tuple                  # N s/m
    perm: np.ndarray          # (n_dof,) int32, RCM order (natural: modal route), 1-based
    nl: np.ndarray            # (nnl,) contact DoFs (rows), 0-based
    G: tuple                  # CSR, 1-based, (contact rows, n_dof)
    ginfo: np.ndarray         # (3, n_groups) int32: law code, n_elem, n_dir
    params: np.ndarray        # contact parameters, groups concatenated
    w0: np.ndarray            # (max(nw, 1),) the model's sliders
    nw: int
    group_names: list
    group_sizes: list
    outputs: np.ndarray       # (n_out,) output DoFs of the model, 0-based
    out_f: np.ndarray         # (n_out,) their rows, 0-based
    stability: bool
    modes: _Modes
    tcontact: bool = False    # condensed unknowns in contact coordinates G x
    sparse: bool = False      # condensed receptances by sparse LU (MUMPS)
    info: str = ""            # how the system is solved (FRF.solver_info)
    #: (n_out, len(out_f)) physical outputs from the rows read (outputs given as a
    #: matrix): X = out_map @ x[out_f]; None: X = x[out_f]
    out_map: np.ndarray | None = None
    #: (nnl, H+1) bool: the travelling-wave selection over the nonlinear DoFs nl
    #: (SolverOptions.selection), None: every unknown
    keep: np.ndarray | None = None
    sel_label: str = "travelling-wave selection"   # or "harmonic selection" (the leak's text)
    #: (nnl, H+1) int32: SolverOptions.pairs over nl (s (position in nl + 1)), None: none
    pair: np.ndarray | None = None
    #: SolverOptions.orbits as the run found them: (elements the AFT runs on, largest
    #: misfit), None before the run is opened
    orbits: tuple | None = None
    #: the frequency of a load continuation, rad/s (0 for frequency)
    omega_fix: float = 0.0
    #: the law of each contact group (user laws evaluated through the run's callback)
    group_laws: tuple = ()
    orbit_tol: float = ORBIT_TOL
    #: a body held only by its contacts: the run moves their stuck stiffness into K
    #: (frirom_hbm_free); the modes of the receptance route are K + G^T Ks G's
    free: bool = False
    _run: object = field(default=None, repr=False)

    @property
    def nc(self) -> int:
        return 2 * self.H + 1

    @property
    def ny(self) -> int:
        """Unknowns: harmonics of the contact DoFs or coordinates (condensed) or of all
        rows (banded)."""
        return self.nrow * self.nc

    @property
    def nrow(self) -> int:
        """Unknowns per harmonic coefficient."""
        if self.opts.formulation != "condensed":
            return self.n_dof
        return self.G[0].size - 1 if self.tcontact else self.nl.size

    @property
    def ne_tot(self) -> int:
        return int(sum(self.group_sizes))

    def checked_slider(self, slider) -> np.ndarray | None:
        """Sliders of all contact elements to start from (the layout of FRFPoint.slider),
        checked; None stays None (the run's history)."""
        if slider is None:
            return None
        slider = np.asarray(slider, dtype=float).ravel()
        if slider.size != self.nw:
            raise SizeError(f"start.slider: {slider.size} values, the model's contact "
                            f"elements have {self.nw} sliders")
        if not np.all(np.isfinite(slider)):
            raise ParameterError("start.slider: contains NaN or Inf")
        return slider if self.nw else None

    @property
    def run(self):
        """The Fortran run on this model (frirom._run.Run), opened at first use: the
        continuation, its first point, the homotopy start and the peak solves all run
        on it, set up once."""
        if self._run is None:
            from ._run import Run
            self._run = Run(self, self.omega_fix)
            if self._run.orbits is not None:
                self.orbits = self._run.orbits
                self.info += (f"; AFT of Newton's evaluations on {self.orbits[0]} of "
                              f"{self.ne_tot} contact elements (orbits on the wave, misfit "
                              f"{self.orbits[1]:.1e})")
        return self._run

    def pad_start(self, y, H_from: int) -> np.ndarray:
        """Unknowns of a solution with H_from harmonics, extended or cut to this H."""
        y = np.asarray(y, dtype=float)
        condensed = self.opts.formulation == "condensed"
        nrow = self.nrow
        nc_from = 2 * H_from + 1
        if y.size != nrow * nc_from:
            other = self.nl.size if self.tcontact else self.G[0].size - 1
            hint = ""
            if condensed and y.size == other * nc_from:
                hint = (" (they fit the other condensed unknowns: set options.coordinates = "
                        f"{'dofs' if self.tcontact else 'contact'!r})")
            raise SizeError(f"start: {y.size} unknowns do not match H = {H_from} for this "
                            f"model and formulation{hint}")
        m = min(nc_from, self.nc)
        out = np.zeros(self.ny)
        if condensed:           # harmonic-major: y[j + nnl c]
            out[:nrow * m] = y[:nrow * m]
        else:                   # DoF-major in RCM order: y[c + nc p]
            out.reshape(nrow, self.nc)[:, :m] = y.reshape(nrow, nc_from)[:, :m]
        return out

    def points(self, res, t_call) -> list[FRFPoint]:
        """The converged points of one run call (frirom._run.Points); t_call (s) is
        shared out among them."""
        omega_fix = self.omega_fix
        pts = []
        # every point's maxima in one batch: (n_out, 2H+1, npts) -> (npts, n_out)
        xo = res.xo[:, :, :res.npts]
        if self.out_map is not None:
            xo = np.einsum("oj,jcp->ocp", self.out_map, xo)
        amps = amplitude_max(np.moveaxis(xo, 2, 0))
        # contact-state fractions of every group at every point: (npts, ngroups, 3)
        st_all = np.zeros((res.npts, len(self.group_sizes), 3))
        e0 = 0
        for g, ne in enumerate(self.group_sizes):
            st_all[:, g, :] = res.states[:, e0:e0 + ne, :res.npts].mean(axis=1).T
            e0 += ne
        for k in range(res.npts):
            om = res.lams[k] if self.opts.parameter == "frequency" else omega_fix
            pts.append(FRFPoint(omega=float(om), parameter=float(res.lams[k]),
                                unknowns=res.ys[:, k].copy(), tangent=res.tans[:, k].copy(),
                                X=np.array(xo[:, :, k]), amp_max=amps[k],
                                state_fractions=st_all[k],
                                iterations=int(res.iters[k]), time_s=t_call / max(res.npts, 1),
                                stable=bool(res.hill_re[k] <= 1e-7 * max(abs(om), 1.0)),
                                floquet_max_re=float(res.hill_re[k]),
                                slider=res.sliders[:self.nw, k].copy(),
                                yscale=_scale_known(res.yscales[k]),
                                leak=(float(res.leak[k]) if self.keep is not None
                                      else None),
                                fold=bool(res.fold[k]),
                                ds_next=(float(res.ds_next[k]) if res.ds_next[k] > 0
                                         else float("nan"))))
        return pts


def _scale_known(yscale: float) -> float:
    """A point's arc-length scale, 0 where none is known: a solve at fixed parameter (the
    first point, solve_point) runs with a purely relative update test (yscale 1e-300),
    and its tangent is in no scale a continuation could resume in."""
    return float(yscale) if yscale > 1e-290 else 0.0


def _split_load(fe: np.ndarray, part: str) -> tuple[np.ndarray, np.ndarray]:
    """(fixed, scaled) parts of a real harmonic excitation (n, 2H+1): part 'static' scales
    harmonic 0, 'dynamic' the harmonics >= 1."""
    mask = np.zeros(fe.shape[1], bool)
    mask[0 if part == "static" else slice(1, None)] = True
    fe1 = np.where(mask, fe, 0.0)
    return fe - fe1, fe1


#: stability = "auto" turns Hill's method on up to this many Hill unknowns 2 n_dof (2H+1):
#: the dense eigen-solve (up to 1 000) and small Arnoldi problems; the paper flange's
#: ROM_I (26 600 at H = 3) costs ~150 solves per point
HILL_AUTO_MAX = 2000


def resolve_stability(model, opts: SolverOptions) -> tuple[SolverOptions, str]:
    """opts with stability "auto" made true or false, and why it is off ('' when on, or
    not "auto"): off for a cyclic sector, a selection, contact coordinates or more than
    HILL_AUTO_MAX Hill unknowns."""
    if opts.stability != "auto":
        return opts, ""
    n, H = model.n_dof, opts.harmonics
    nh = 2 * n * (2 * H + 1)
    why = ""
    if isinstance(model, CyclicModel):
        why = "a cyclic sector (Hill's method is not implemented for it)"
    elif opts.selection is not None or opts.harmonics_kept is not None:
        why = "a selection of unknowns (Hill would see only perturbations inside it)"
    elif opts.coordinates == "contact":
        why = "contact coordinates (Hill's method needs the contact DoFs)"
    elif nh > HILL_AUTO_MAX:
        why = (f"{nh} Hill unknowns, more than {HILL_AUTO_MAX} (set stability = true to "
               "compute it anyway)")
    return dataclasses.replace(opts, stability=not why), why


def pack(model: Model | CyclicModel, excitation: Excitation, opts: SolverOptions, outputs,
         load_part: str = "dynamic") -> _Packed:
    """Check the inputs and pack them for the Fortran run; outputs: DoF indices (0-based),
    an (n_out, n_dof) matrix (each output a combination of the DoFs: physical DoFs through
    a reduction basis) or None for the default (all DoFs up to 100, else the contact
    DoFs)."""
    if not isinstance(model, (Model, CyclicModel)):
        raise ParameterError("model: expected a frirom.model.Model or CyclicModel")
    if not isinstance(excitation, Excitation):
        raise ParameterError("excitation: expected a frirom.model.Excitation")
    opts.check()
    opts, skipped = resolve_stability(model, opts)
    label = "travelling-wave selection"
    if opts.harmonics_kept is not None:
        if isinstance(model, CyclicModel):
            raise ParameterError("options.harmonics_kept: not for a cyclic sector (its "
                                 "harmonics already live on their own nodal diameters)")
        opts = dataclasses.replace(opts, selection=harmonic_selection(model, opts))
        label = "harmonic selection"
    fe = excitation.real_harmonic(model.n_dof, opts.harmonics)
    if load_part not in ("static", "dynamic"):
        raise ParameterError("load_part: expected 'static' or 'dynamic'")
    if opts.parameter == "frequency":
        fe0, fe1 = fe, np.zeros_like(fe)
    else:
        fe0, fe1 = _split_load(fe, load_part)
    outputs, P = _output_map(outputs, model.n_dof)
    if isinstance(model, CyclicModel):
        packed = _pack_sector(model, opts, fe0, fe1, outputs)
    else:
        packed = _pack_model(model, opts, fe0, fe1, outputs)
    if P is not None:
        packed.out_map, packed.outputs = P, _map_dofs(P, packed.outputs)
    if opts.selection is not None:
        _select(packed, model, opts.selection, opts.pairs, label)
    if skipped:
        packed.info += f"; stability: off ('auto': {skipped})"
    return packed


def harmonic_selection(model: Model, opts: SolverOptions) -> np.ndarray:
    """SolverOptions.harmonics_kept as a selection (n_dof, H+1) bool, combined with
    SolverOptions.selection when both are given."""
    from .options import kept_harmonics
    H, n, spec = opts.harmonics, model.n_dof, opts.harmonics_kept
    sel = (np.ones((n, H + 1), bool) if opts.selection is None
           else np.asarray(opts.selection, bool))
    if sel.shape != (n, H + 1):
        raise SizeError(f"options.selection: expected (n_dof, H+1) = ({n}, {H + 1}), got "
                        f"{sel.shape}")
    if isinstance(spec, np.ndarray) and spec.dtype == bool:
        if spec.shape != (n, H + 1):
            raise SizeError(f"options.harmonics_kept: a mask must be (n_dof, H+1) = ({n}, "
                            f"{H + 1}), got {spec.shape}")
        return sel & spec
    if not isinstance(spec, dict):
        return sel & kept_harmonics(spec, H, "options.harmonics_kept")[None, :]
    names = [g.name for g in model.contacts]
    per = {}
    for key, s in spec.items():
        if isinstance(key, str):
            if key not in names:
                raise ParameterError(f"options.harmonics_kept: no contact group named "
                                     f"{key!r} (groups: {names})")
            idx = names.index(key)
        elif isinstance(key, (int, np.integer)) and 0 <= key < len(names):
            idx = int(key)
        else:
            raise ParameterError(f"options.harmonics_kept: {key!r} is neither a contact "
                                 f"group's name nor its index 0..{len(names) - 1}")
        per[idx] = kept_harmonics(s, H, f"options.harmonics_kept[{key!r}]")
    keep = np.zeros((n, H + 1), bool)
    touched = np.zeros(n, bool)
    for idx, g in enumerate(model.contacts):
        dofs = np.unique(sp.csr_matrix(g.G).indices)
        keep[dofs] |= per.get(idx, np.ones(H + 1, bool))
        touched[dofs] = True
    return sel & np.where(touched[:, None], keep, True)


def _select(packed: _Packed, model, selection, pairs=None,
            label: str = "travelling-wave selection") -> None:
    """Check SolverOptions.selection against the packed model and set packed.keep: the
    rows of the nonlinear DoFs; loads on them outside the selection are refused (a
    travelling wave of the selection's engine order has none)."""
    if isinstance(model, CyclicModel):
        raise ParameterError("options.selection: not for a cyclic sector (its harmonics "
                             "already live on their own nodal diameters)")
    H = packed.H
    sel = np.asarray(selection)
    if sel.shape != (packed.n_dof, H + 1):
        raise SizeError(f"options.selection: expected (n_dof, H+1) = ({packed.n_dof}, "
                        f"{H + 1}), got {sel.shape}")
    keep = sel[packed.nl].astype(bool)
    if not keep.any():
        raise ParameterError("options.selection: keeps no harmonic of any nonlinear DoF")
    for fe in (packed.fe0, packed.fe1):
        for h in range(H + 1):
            a = np.abs(fe[packed.nl][:, [0] if h == 0 else [2 * h - 1, 2 * h]]).max(axis=1)
            off = np.where(keep[:, h], 0.0, a)
            # 1e-9: the round-off of projecting a cyclic load on the MS columns
            if off.max() > 1e-9 * max(a.max(), 1e-300):
                raise ParameterError(
                    f"options.selection: the excitation loads nonlinear DoF "
                    f"{int(packed.nl[np.argmax(off)])} at harmonic {h}, outside the "
                    "selection (not a travelling wave of the selection's engine order)")
    packed.keep = keep
    packed.sel_label = label
    n = kept_unknowns(keep)
    packed.info += f"; {label}: {n} of {packed.ny} unknowns"
    if pairs is not None:
        packed.pair = _pairs_on_nl(packed, pairs)
        packed.info += f", {n - 2 * int(np.count_nonzero(packed.pair))} in one direction"


def kept_unknowns(keep) -> int:
    """The condensed unknowns a selection keeps (the size of its Newton system): keep is
    (nnl, H+1) bool over the nonlinear DoFs (SolverOptions.selection's rows nl); a kept
    harmonic 0 is one coefficient, a kept harmonic h >= 1 two (cos, sin)."""
    keep = np.asarray(keep, dtype=bool)
    return int(keep[:, 0].sum() + 2 * keep[:, 1:].sum())


def _pairs_on_nl(packed: _Packed, pairs) -> np.ndarray:
    """SolverOptions.pairs (model DoFs) on the nonlinear DoFs nl: (nnl, H+1) int32,
    s (position in nl + 1)."""
    pr = np.asarray(pairs)
    if pr.shape != (packed.n_dof, packed.H + 1) or not np.issubdtype(pr.dtype, np.integer):
        raise SizeError(f"options.pairs: expected (n_dof, H+1) = ({packed.n_dof}, "
                        f"{packed.H + 1}) integers, got {pr.shape} {pr.dtype}")
    pos = np.full(packed.n_dof + 1, -1, dtype=np.int64)
    pos[packed.nl + 1] = np.arange(packed.nl.size)
    off_nl = np.ones(packed.n_dof, bool)
    off_nl[packed.nl] = False
    k = np.abs(pr)
    if np.any(pr[off_nl]) or k.max() > packed.n_dof or np.any(pos[k[k > 0]] < 0):
        raise ParameterError("options.pairs: pairs only between nonlinear DoFs")
    if np.any(pr[:, 0]):
        raise ParameterError("options.pairs: no pair at harmonic 0 (it has no sine)")
    sub = pr[packed.nl]
    out = np.sign(sub) * (pos[np.abs(sub)] + 1)
    out[sub == 0] = 0
    return out.astype(np.int32)


def _pack_model(model: Model, opts: SolverOptions, fe0, fe1, outputs) -> _Packed:
    H, n = opts.harmonics, model.n_dof
    nl = model.nonlinear_dofs()
    note = ""
    if opts.formulation == "condensed" and nl.size == 0:
        # nothing to condense to: the linear response, by the banded LU of all DoFs
        if opts.selection is not None:
            raise ParameterError("options.selection: the model has no contact DoFs to "
                                 "select")
        opts = dataclasses.replace(opts, formulation="banded", modes=None)
        note = ("; no contact DoFs to condense to: the linear response, solved in the "
                "banded formulation")
    groups = model.contacts
    c = _pack_contacts(groups, n)
    band = _Band(model, c.G)
    out = _check_outputs((np.arange(n) if n <= 100 else nl) if outputs is None else outputs, n)
    tcontact, sparse, info = False, False, f"banded: {n * (2 * H + 1)} unknowns"
    hill = None
    modes = _Modes.none(n, H)
    free = model.free_bodies()
    if free:
        note += ("; a body held only by its contacts: their stuck stiffness moved into the "
                 "linear part")
    if opts.formulation == "condensed":
        nrows = c.G.shape[0]
        rmodel = model
        if free:        # the receptances' modes are the stuck structure's
            rmodel = copy.copy(model)
            rmodel.K = sp.csr_matrix(model.K + model.stuck_stiffness())
        modes, route, sparse = _receptance_route(rmodel, opts, H, band)
        # Hill's route at s = 0 (the Newton matrix) works in either coordinates: then
        # stability does not hold the unknowns on the contact DoFs
        near0 = opts.stability and _hill_route(
            n, H, modes.nmodes, nl.size,
            strip=opts.stability == "strip") == "near0"
        tcontact = _contact_coords(dataclasses.replace(opts, stability=False) if near0
                                   else opts, nrows, nl.size)
        nu = nrows if tcontact else nl.size
        info = (f"condensed: {nu * (2 * H + 1)} unknowns, "
                + (f"{nu} contact coordinates G x" if tcontact else f"{nu} contact DoFs")
                + f"; {route}")
    if opts.stability:
        hill = _hill_route(n, H, modes.nmodes, nl.size,
                           strip=opts.stability == "strip")
        if hill == "banded":
            _check_hill_memory(n, H, band.bw)
        elif hill != "near0":
            _check_hill_memory(n, H, 0, modal=(modes.nmodes, nl.size))
        info += "; " + HILL_ROUTES[hill]
    if modes.nmodes and (not opts.stability or hill == "near0"):
        # modal receptances without Hill's method or with its s = 0 route (modes only):
        # Fortran reads neither K, M, C nor the
        # order (frirom_hbm_receptances, _condensed; hbm_setup checks that perm is a
        # permutation), so empty matrices, as for a cyclic sector, and the natural order:
        # no copy and check of the model's matrices at every call into Fortran
        K = M = C = _csr(sp.csr_matrix((n, n)))
        perm = np.arange(1, n + 1, dtype=np.int32)
    else:
        K, M, C, perm = _csr(model.K), _csr(model.M), _csr(model.C), band.perm
    return _Packed(opts=opts, H=H, n_dof=n, fe0=fe0, fe1=fe1,
                   K=K, M=M, C=C, perm=perm, nl=nl,
                   G=_csr(c.G), ginfo=c.ginfo, params=c.params, w0=c.w0, nw=c.nw,
                   group_names=c.names, group_sizes=c.sizes, group_laws=c.laws,
                   outputs=out, out_f=out,
                   stability=bool(opts.stability), modes=modes, tcontact=tcontact, sparse=sparse,
                   info=info + note, free=free)


def _pack_sector(model: CyclicModel, o: SolverOptions, fe0, fe1, outputs) -> _Packed:
    """A cyclic sector as a condensed system on the DoFs the solver reads: contact DoFs
    of sector 0 and of the next sector (columns n.. of G, shapes times exp(i k_h alpha)),
    outputs and loaded DoFs; receptances from the modes of each harmonic's nodal
    diameter (hbm_set_modes_harmonic); K, M, C are not used (empty)."""
    n, H = model.n_dof, o.harmonics
    if o.formulation != "condensed":
        raise ParameterError("options.formulation: a cyclic sector is solved in the "
                             "'condensed' formulation (receptances per nodal diameter)")
    if o.modes:
        raise ParameterError("options.modes: a cyclic model brings its own modes per "
                             "nodal diameter (frirom.reduction.cyclic.cyclic_model)")
    if o.stability:
        raise ParameterError("options.stability: Hill's method is not implemented for "
                             "cyclic sectors (perturbations of every nodal diameter)")
    c = _pack_contacts(model.contacts, 2 * n)
    cols = np.unique(c.G.indices)
    if outputs is None:
        outputs = np.arange(n) if n <= 100 else cols[cols < n]
    out = _check_outputs(outputs, n)
    loaded = np.nonzero(np.any(fe0 != 0, axis=1) | np.any(fe1 != 0, axis=1))[0]
    rows = np.unique(np.concatenate([cols, out, loaded]))
    nr = rows.size
    at = -np.ones(2 * n, dtype=np.int64)
    at[rows] = np.arange(nr)
    G = sp.csr_matrix((c.G.data, at[c.G.indices], c.G.indptr), shape=(c.G.shape[0], nr))
    real = rows[rows < n]
    fe0_r, fe1_r = np.zeros((nr, 2 * H + 1)), np.zeros((nr, 2 * H + 1))
    fe0_r[at[real]], fe1_r[at[real]] = fe0[real], fe1[real]
    alpha = 2 * np.pi / model.n_sectors
    per = [model.modes_of(model.harmonic_index(h)) for h in range(H + 1)]
    nm = max(m.omega.size for m in per)
    modes = _Modes.none(nr, H)
    modes.hmodes = nm
    modes.psi = np.zeros((nr, nm, H + 1), complex, order="F")
    modes.omega_h = np.ones((nm, H + 1), order="F")
    modes.zeta_h = np.zeros((nm, H + 1), order="F")
    nb = rows >= n
    for h, m in enumerate(per):
        r = m.omega.size
        modes.psi[~nb, :r, h] = m.psi[rows[~nb]]
        modes.psi[nb, :r, h] = m.psi[rows[nb] - n] * np.exp(1j * m.k * alpha)
        modes.omega_h[:r, h], modes.zeta_h[:r, h] = m.omega, m.zeta
    empty = _csr(sp.csr_matrix((nr, nr)))
    tcontact = _contact_coords(o, G.shape[0], cols.size)
    nu = G.shape[0] if tcontact else cols.size
    return _Packed(opts=o, H=H, n_dof=nr, fe0=fe0_r, fe1=fe1_r,
                   K=empty, M=empty, C=empty, perm=np.arange(1, nr + 1, dtype=np.int32),
                   nl=at[cols], G=_csr(G), ginfo=c.ginfo, params=c.params, w0=c.w0,
                   nw=c.nw, group_names=c.names, group_sizes=c.sizes, group_laws=c.laws,
                   outputs=out,
                   out_f=at[out], stability=False, modes=modes, tcontact=tcontact,
                   info=f"condensed: {nu * (2 * H + 1)} unknowns, {nu} "
                        + ("contact coordinates G x" if tcontact else "contact DoFs")
                        + "; receptances from each harmonic's nodal-diameter modes")
