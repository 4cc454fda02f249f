"""Contact laws written by the user, in Python (or in C through ctypes), and their AFT.

A user law is a :class:`UserLaw`: names of its directions and parameters, the size of its
slider state, and a function that marches one period::

    def force(u, params, w):
        '''u (n_elem, n_dir, N) relative displacements at the N samples of one period;
        params (n_elem, n_par); w (n_elem, n_slider) slider state at the period's start.
        Returns f (n_elem, n_dir, N), the forces the elements exert against u (the sign of
        the built-in laws), and w_end (n_elem, n_slider), the state after the last sample.'''

The function is vectorised over the elements (and over the samples when the law has no
memory); a law with sliders loops over the samples itself, as the built-in marches do.
:func:`aft` repeats the period from the closing state until every element's state returns
to where the period started (to ``tol`` relative to the displacement amplitude), exactly as
the Fortran AFT does for the built-in laws, then takes the harmonics of the forces of the
closed period.

Jacobian d(force harmonics)/d(displacement harmonics):

* ``jacobian`` supplied (laws without state only): ``jacobian(u, params)`` returns the
  same-sample derivative d f_k / d u_k, (n_elem, n_dir, n_dir, N); the harmonic Jacobian is
  then the Galerkin projection E^+ diag(d f) E (E the (N, 2H+1) basis), exact for a law
  without memory;
* otherwise (and always for laws with state) by central differences on the harmonic
  coefficients: coefficient j of every element is moved by +-h_j, h_j = sqrt(eps) *
  max(amplitude of the element's displacement, 1e-12 m) (per element), and the
  perturbed AFT is closed again from the closed cycle's state. Cost: 2 n_dir (2H+1) AFTs;
  accuracy O(h^2) where the forces are smooth in x and O(h) at a contact event within
  h of a sample (about 1e-8 relative). Where one side is flat (a one-sided difference
  below 1e-3 of the other: an element stuck at its friction limit, slipping on one side)
  the flat side is taken, the slipping side the built-in analytical Jacobians take, so
  that Newton converges on the kink (the central mean would halve the error per
  iteration). The solver's user laws use the same scheme (frirom_user_law).

Code from a deck. A deck may name a law ``"package.module:function"`` (a function returning
a :class:`UserLaw`, or a :class:`UserLaw` object). A deck that names code runs code, so
:func:`load_law` imports it only when the module is in ``allowed`` (the CLI's
``--allow-code MODULE``), or when an installed package declares it under the entry-point
group ``frirom.laws``; never because a deck says so (see docs/security.md).
"""

from __future__ import annotations

import ctypes
import importlib
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ._errors import ParameterError, SizeError, ConvergenceError, as_floats, check_number
from .harmonics import default_samples, element_harmonics, n_harmonics, basis

ENTRY_POINT_GROUP = "frirom.laws"


@dataclass(frozen=True)
class UserLaw:
    """A contact law written by the user (see the module docstring for ``force``)."""

    name: str
    directions: tuple[str, ...]
    parameters: tuple[str, ...]
    n_slider: int
    force: Callable
    jacobian: Callable | None = None
    #: address of a C function of the solver's signature (:data:`SOLVER_LAW`) the solver
    #: calls directly, without Python, when every user-law group of a run has it
    native: int | None = None

    def __post_init__(self):
        if not callable(self.force):
            raise ParameterError(f"user law {self.name!r}: force must be callable")
        if self.jacobian is not None and self.n_slider > 0:
            raise ParameterError(f"user law {self.name!r}: a supplied jacobian is the "
                                 f"same-sample derivative, exact only for laws without state "
                                 f"(n_slider = 0); leave it out for the difference scheme")
        if len(self.directions) < 1 or self.n_slider < 0:
            raise ParameterError(f"user law {self.name!r}: needs >= 1 direction and "
                                 f"n_slider >= 0")

    @property
    def n_dir(self) -> int:
        return len(self.directions)


@dataclass
class UserAftResult:
    """Output of :func:`aft` (the layout of :class:`frirom.contact.AftResult`)."""

    forces: np.ndarray            #: (n_elem, n_dir, 2H+1), N
    jacobian: np.ndarray | None   #: (n_elem, n_dir(2H+1), n_dir(2H+1)), N/m
    periods: np.ndarray           #: (n_elem,) periods marched
    slider: np.ndarray            #: (n_elem, n_slider) state entering the closed cycle


def _call(law: UserLaw, ut, p, w):
    out = law.force(ut, p, w)
    if not (isinstance(out, tuple) and len(out) == 2):
        raise ParameterError(f"user law {law.name!r}: force must return (f, w_end)")
    f, w_end = np.asarray(out[0], float), np.asarray(out[1], float).reshape(w.shape)
    if f.shape != ut.shape:
        raise SizeError(f"user law {law.name!r}: force returned f of shape {f.shape}; "
                        f"expected {ut.shape}")
    if not np.all(np.isfinite(f)):
        raise ParameterError(f"user law {law.name!r}: force returned non-finite forces")
    return f, w_end


def _close(law, ut, p, w, scale, tol, max_periods):
    """March periods until the state closes; (f, w_start of closed cycle, periods)."""
    periods = np.zeros(ut.shape[0], dtype=int)
    for k in range(1, max_periods + 1):
        f, w_end = _call(law, ut, p, w)
        if law.n_slider == 0:
            return f, w, np.ones(ut.shape[0], dtype=int)
        moved = np.max(np.abs(w_end - w), axis=1) > tol * scale
        periods[~moved & (periods == 0)] = k
        if not moved.any():
            return f, w, periods
        w = w_end
    bad = int(np.flatnonzero(periods == 0)[0])
    raise ConvergenceError(f"user law {law.name!r}: element {bad} not closed after "
                           f"{max_periods} periods")


def aft(law: UserLaw, x, params, n_samples: int | None = None, w0=None,
        jacobian: bool = True, tol: float = 1e-12, max_periods: int = 200) -> UserAftResult:
    """Forces (and Jacobian) of a user law from displacement harmonics.

    The arguments are those of :func:`frirom.contact.aft`: x (n_elem, n_dir, 2H+1), params
    (n_elem, n_par) or a dict, w0 (n_elem, n_slider) or None (zeros).
    """
    check_number("tol", tol, positive=True)
    x = element_harmonics(x, law.n_dir, f"user law {law.name!r}")
    ne, nd, nc = x.shape
    h = n_harmonics(nc)
    n = default_samples(h) if n_samples is None else int(n_samples)
    if n < nc:
        raise SizeError(f"n_samples: expected >= 2H+1 = {nc}, got {n}")
    p = _params(law, params, ne)
    w = np.zeros((ne, law.n_slider)) if w0 is None else \
        np.array(np.broadcast_to(as_floats("w0", w0), (ne, law.n_slider)))
    E = basis(h, n)                                     # (N, 2H+1)
    Ep = np.linalg.pinv(E)                              # (2H+1, N): E^+ = analysis
    ut = x @ E.T                                        # (ne, nd, N)
    scale = np.maximum(np.max(np.abs(ut), axis=(1, 2)), 1e-300)
    f, wc, periods = _close(law, ut, p, w, scale, tol, max_periods)
    fh = f @ Ep.T
    jac = None
    if jacobian and law.jacobian is not None:
        d = np.asarray(law.jacobian(ut, p), float)     # (ne, nd, nd, N)
        if d.shape != (ne, nd, nd, n):
            raise SizeError(f"user law {law.name!r}: jacobian returned {d.shape}; expected "
                            f"{(ne, nd, nd, n)}")
        blk = np.einsum("cn,eabn,nk->eacbk", Ep, d, E)  # (ne, nd, 2H+1, nd, 2H+1)
        jac = blk.reshape(ne, nd * nc, nd * nc)
    elif jacobian:
        jac = np.empty((ne, nd * nc, nd * nc))
        step = np.sqrt(np.finfo(float).eps) * np.maximum(scale, 1e-12)
        for j in range(nd * nc):
            dx = np.zeros_like(x)
            dx[:, j // nc, j % nc] = step
            fp, _, _ = _close(law, (x + dx) @ E.T, p, wc, scale, tol, max_periods)
            fm, _, _ = _close(law, (x - dx) @ E.T, p, wc, scale, tol, max_periods)
            dp = ((fp @ Ep.T) - fh).reshape(ne, nd * nc) / step[:, None]
            dm = (fh - (fm @ Ep.T)).reshape(ne, nd * nc) / step[:, None]
            jac[:, :, j] = _kink_column(dp, dm)
    return UserAftResult(forces=fh, jacobian=jac, periods=periods, slider=wc)


def _kink_column(dp, dm, kink: float = 1e-3):
    """Jacobian columns (ne, m) from the one-sided differences: central, or where one
    side is flat (below ``kink`` of the other: an element at its friction limit, stuck
    on one side) the flat side (slipping, as the built-in analytical Jacobians)."""
    np_, nm = np.linalg.norm(dp, axis=1), np.linalg.norm(dm, axis=1)
    smooth = np.minimum(np_, nm) > kink * np.maximum(np_, nm)
    side = np.where((np_ <= nm)[:, None], dp, dm)
    return np.where(smooth[:, None], 0.5 * (dp + dm), side)


def _params(law: UserLaw, params, ne: int) -> np.ndarray:
    if isinstance(params, dict):
        unknown = set(params) - set(law.parameters)
        missing = [q for q in law.parameters if q not in params]
        if unknown or missing:
            raise ParameterError(f"user law {law.name!r}: parameters {sorted(unknown)} unknown,"
                                 f" {missing} missing; expected {list(law.parameters)}")
        return np.stack([np.broadcast_to(as_floats(f"params[{q!r}]", params[q]), (ne,))
                         for q in law.parameters], axis=1)
    arr = as_floats("params", params)
    if arr.ndim == 1:
        arr = np.broadcast_to(arr, (ne, arr.shape[0]))
    if arr.shape != (ne, len(law.parameters)):
        raise SizeError(f"user law {law.name!r}: params has shape {arr.shape}; expected "
                        f"({ne}, {len(law.parameters)})")
    return np.ascontiguousarray(arr)


# --- C laws through ctypes --------------------------------------------------------------

#: The C signature of a law's period march (column-major arrays, as Fortran lays them):
#: int law(int ne, int ndir, int nsamp, int npar, int nslider, const double *u /* (ne,
#: ndir, N), element fastest */, const double *params /* (ne, npar) */, double *w /* (ne,
#: nslider) in: start, out: end */, double *f /* (ne, ndir, N) */); returns 0 on success.
C_LAW = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_int,
                         ctypes.c_int, ctypes.c_int, ctypes.POINTER(ctypes.c_double),
                         ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_double),
                         ctypes.POINTER(ctypes.c_double))


def c_law(name: str, library: str, symbol: str, directions, parameters,
          n_slider: int, solver_symbol: str | None = None) -> UserLaw:
    """A :class:`UserLaw` whose period march is the C function ``symbol`` of the shared
    library ``library`` (signature :data:`C_LAW`); with ``solver_symbol``, the function of
    the solver's signature (:data:`SOLVER_LAW`) the solver then calls directly."""
    lib = ctypes.CDLL(library)
    native = None
    if solver_symbol is not None:
        native = ctypes.cast(getattr(lib, solver_symbol), ctypes.c_void_p).value
    fn = getattr(lib, symbol)
    fn.restype = ctypes.c_int
    fn.argtypes = C_LAW._argtypes_
    directions, parameters = tuple(directions), tuple(parameters)
    ptr = ctypes.POINTER(ctypes.c_double)

    def force(u, params, w):
        ne, nd, n = u.shape
        uf = np.asfortranarray(u)
        pf = np.asfortranarray(params)
        wf = np.asfortranarray(np.array(w, float).reshape(ne, n_slider))
        ff = np.zeros((ne, nd, n), order="F")
        rc = fn(ne, nd, n, pf.shape[1], n_slider, uf.ctypes.data_as(ptr),
                pf.ctypes.data_as(ptr), wf.ctypes.data_as(ptr), ff.ctypes.data_as(ptr))
        if rc != 0:
            raise ParameterError(f"C law {name!r} ({symbol} in {library}) returned {rc}")
        return ff, wf

    law = UserLaw(name, directions, parameters, int(n_slider), force, native=native)
    object.__setattr__(law, "_library", lib)        # the library lives as long as the law
    return law


# --- user laws in the solver -----------------------------------------------------------

#: The solver's law callback (frirom_user_law user_law_fn, frirom.h frirom_user_law_fn):
#: int law(void *ctx, int group, int ne, int ndir, int nsamp, int npar, int nslider,
#: const double *u, const double *params, double *w, double *f), column-major arrays
#: u, f (ne, ndir, N), params (ne, npar), w (ne, nslider): the :data:`C_LAW` march with
#: the context and the 1-based contact group in front.
SOLVER_LAW = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, *([ctypes.c_int] * 6),
                              *([ctypes.POINTER(ctypes.c_double)] * 4))

#: User laws by name, as contact groups name them (:func:`register`); their entries in
#: :data:`frirom.contact.LAWS` carry the negative code the solver evaluates through
#: the run's callback.
USER_LAWS: dict[str, UserLaw] = {}


def register(law: UserLaw) -> str:
    """Make ``law`` usable as a contact group's law (by its name) and return the name.

    The law table :data:`frirom.contact.LAWS` gets an entry with the law's directions,
    parameters and slider size and a negative code (frirom_aft law_user_code); the solver
    evaluates such groups through the run's callback (:func:`solver_callback`). A name
    registered again names the latest law from then on (runs opened before keep theirs).
    """
    from . import _kernels
    from .contact import LAWS, Law
    if not isinstance(law, UserLaw):
        raise ParameterError(f"register: expected a frirom.laws.UserLaw, got {type(law)}")
    old = LAWS.get(law.name)
    if old is not None and old.code > 0:
        raise ParameterError(f"user law {law.name!r}: the name is a built-in law's")
    code = int(_kernels.law_user_code(law.n_dir, len(law.parameters), law.n_slider))
    if code == 0:
        raise ParameterError(f"user law {law.name!r}: the solver takes 1..7 directions, "
                             f"<= 255 parameters and <= 1e6 slider components")
    LAWS[law.name] = Law(law.name, code, law.directions, law.parameters, law.n_slider)
    USER_LAWS[law.name] = law
    return law.name


class _SolverCallback:
    """The ctypes function a run evaluates its user-law groups with; ``address`` goes to
    the run (frun_set_user_law), the object must live as long as the run."""

    def __init__(self, group_laws):
        self.laws = [USER_LAWS.get(name) for name in group_laws]
        self.error: BaseException | None = None
        native = {law.native for law in self.laws if law is not None}
        if len(native) == 1 and None not in native:      # C all the way: no Python
            self._keep = [law for law in self.laws if law is not None]
            self.address = native.pop()
            return
        self._fn = SOLVER_LAW(self._call)
        self.address = ctypes.cast(self._fn, ctypes.c_void_p).value

    def _call(self, ctx, group, ne, nd, n, npar, nsl, u, p, w, f):
        try:
            law = self.laws[group - 1]
            def arr(ptr, shape):
                size = int(np.prod(shape))
                a = np.ctypeslib.as_array(ptr, shape=(max(size, 1),))[:size]
                return a.reshape(shape, order="F")
            ua, pa, wa, fa = arr(u, (ne, nd, n)), arr(p, (ne, npar)), arr(w, (ne, nsl)), \
                arr(f, (ne, nd, n))
            fo, wo = _call(law, ua, pa, wa.copy())
            fa[...] = fo
            wa[...] = wo
            return 0
        except Exception as exc:        # the run reports the law's failure (code 1)
            import warnings
            self.error = exc
            name = getattr(self.laws[group - 1], "name", "?") if 0 < group <= len(self.laws) \
                else "?"
            warnings.warn(f"user law {name!r} (contact group {group}) raised "
                          f"{type(exc).__name__}: {exc}", RuntimeWarning, stacklevel=1)
            return 1


def solver_callback(group_laws) -> _SolverCallback:
    """The callback a run registers for the contact groups whose laws are user laws
    (``group_laws``: each group's law name, in the run's group order)."""
    return _SolverCallback(group_laws)


# --- laws named from a deck -------------------------------------------------------------

class CodeNotAllowedError(ParameterError):
    """A deck names code that the command line did not allow."""


def load_law(spec: str, allowed=(), where: str = "law") -> UserLaw:
    """The :class:`UserLaw` a deck names as ``"package.module:attribute"``.

    Imported only when ``package.module`` is in ``allowed`` (``--allow-code``) or is
    declared by an installed package under the entry-point group ``frirom.laws``.
    """
    if not isinstance(spec, str) or spec.count(":") != 1 or not all(spec.split(":")):
        raise ParameterError(f"{where}: expected a built-in law or 'package.module:function',"
                             f" got {spec!r}")
    module, attr = spec.split(":")
    if module not in set(allowed) and spec not in _entry_points():
        raise CodeNotAllowedError(
            f"{where} = {spec!r} names Python code, and a deck that names code runs code: "
            f"frirom imports it only when you allow it on the command line "
            f"(--allow-code {module}) or an installed package declares it under the entry "
            f"point group '{ENTRY_POINT_GROUP}'; a deck alone never does (docs/security.md)")
    obj = getattr(importlib.import_module(module), attr, None)
    if obj is None:
        raise ParameterError(f"{where}: module {module!r} has no attribute {attr!r}")
    law = obj if isinstance(obj, UserLaw) else obj()
    if not isinstance(law, UserLaw):
        raise ParameterError(f"{where}: {spec!r} did not give a frirom.laws.UserLaw")
    return law


def _entry_points() -> set[str]:
    """'module:attribute' values declared by installed packages under frirom.laws."""
    from importlib.metadata import entry_points
    return {ep.value.replace(" ", "") for ep in entry_points(group=ENTRY_POINT_GROUP)}


# --- examples: built-in laws written as user laws (templates; checked in the tests) ---------

def _jenkins_force(u, params, w):
    kt, mu, fn0 = params[:, 0], params[:, 1], params[:, 2]
    lim = mu * np.maximum(fn0, 0.0)
    w = w[:, 0].copy()
    f = np.empty_like(u)
    for k in range(u.shape[2]):
        t = kt * (u[:, 0, k] - w)
        slip = np.abs(t) > lim
        fs = np.copysign(lim, t)
        w = np.where(slip, u[:, 0, k] - fs / kt, w)
        f[:, 0, k] = np.where(slip, fs, t)
    return f, w[:, None]


def _normal1d_force(u, params, w):
    kt, kn, mu, n0 = (params[:, i] for i in range(4))
    x, v = u[:, 0, :], u[:, 1, :]
    g = n0[:, None] + kn[:, None] * v
    g1 = np.roll(g, -1, axis=1)
    reclose = (g <= 0.0) & (g1 > 0.0)      # last open sample before the contact recloses
    theta = g / np.where(reclose, g - g1, -1.0)
    x = np.where(reclose, x + theta * (np.roll(x, -1, axis=1) - x), x)
    nf = np.maximum(g, 0.0)
    w = w[:, 0].copy()
    f = np.empty_like(u)
    for k in range(u.shape[2]):
        lim = mu * nf[:, k]
        t = kt * (x[:, k] - w)
        slip = np.abs(t) > lim
        fs = np.copysign(lim, t)
        w = np.where(slip, x[:, k] - fs / kt, w)
        f[:, 0, k] = np.where(slip, fs, t)
    f[:, 1, :] = nf
    return f, w[:, None]


def jenkins_law() -> UserLaw:
    """The built-in ``jenkins`` law written as a user law (kt, mu, fn0; one slider)."""
    return UserLaw("user_jenkins", ("u",), ("kt", "mu", "fn0"), 1, _jenkins_force)


def normal1d_law() -> UserLaw:
    """The built-in ``normal1d`` law (re-contact located between samples) as a user law."""
    return UserLaw("user_normal1d", ("u", "v"), ("kt", "kn", "mu", "n0"), 1, _normal1d_force)


def cubic_law() -> UserLaw:
    """f = k1 u + k3 u^3 as a user law without state, with its same-sample derivative."""
    def force(u, p, w):
        return u * (p[:, 0, None, None] + p[:, 1, None, None] * u * u), w

    def jac(u, p):
        return (p[:, 0, None, None] + 3.0 * p[:, 1, None, None] * u * u)[:, :, None, :]

    return UserLaw("user_cubic", ("u",), ("k1", "k3"), 0, force, jac)
