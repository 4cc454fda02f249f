"""Contact laws and the AFT kernel on numpy arrays.

Laws (one group of elements = one law; parameters per element, SI units). The table is
made at import from :data:`LAWS`, whose codes and sizes come from the Fortran law table
(frirom_aft):

{law_table}

Normal force f_n = max(n0 + kn v, 0): v > 0 closes the contact, n0 < 0 is an initial gap
-n0/kn. Forces are those the element exerts against the relative displacement (f_t = kt u
when stuck from zero), so the equations of motion read M x'' + C x' + K x + G^T f = f_e.

Initial slider state ``w0`` (default 0): the tangential spring is unstretched at zero
relative displacement, i.e. in the configuration the FE matrices were built in. A contact
that sticks all cycle then behaves exactly as the linear system with kt springs added (the
full-stick limit), its mean tangential force is kt * mean(u), and nothing depends on how the
march was started. Pass another ``w0`` to model a joint assembled with a pre-slip offset.

Arrays of harmonic coefficients have shape (n_elem, n_dir, 2H+1) in the ordering of
:mod:`frirom.harmonics`. The Jacobian has shape (n_elem, n_dir*(2H+1), n_dir*(2H+1)) with
flat index d*(2H+1) + c, entry [e, i, j] = d force_i / d displacement_j.

Choice of N (time samples per period): N >= 2H+1 is required. Friction forces have kinks,
so the harmonics converge like N^-2 in every regime (error <= 20 N^-2 relative, measured
in tests/test_aft_convergence.py); the default N is the solver's,
:func:`frirom.harmonics.default_samples`. The 2-D law moves its slider exactly along the
interpolated path between samples (slip onset located between them, closed-form turn of
the slip direction), so it is second order on curved slip paths too (circular orbit:
force harmonics within 11 N^-2 of the closed form, tests/test_normal2d_aft.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _kernels
from ._errors import (ParameterError, SamplesError, SizeError, as_floats, check_integer,
                      check_number, raise_for_status, samples_problem)
from .harmonics import default_samples, element_harmonics, n_harmonics


@dataclass(frozen=True)
class Law:
    """A contact law: Fortran code, direction names, parameter names, slider size."""

    name: str
    code: int
    directions: tuple[str, ...]
    parameters: tuple[str, ...]
    n_slider: int

    @property
    def n_dir(self) -> int:
        return len(self.directions)


# What Python adds to frirom_aft's law table: the names of the directions and parameters
# of each law, and a description. The codes, sizes and slider sizes come from Fortran.
_NAMES: dict[str, tuple[tuple[str, ...], tuple[str, ...], str]] = {
    "jenkins": (("u",), ("kt", "mu", "fn0"), "elastic Coulomb, constant normal load"),
    "normal1d": (("u", "v"), ("kt", "kn", "mu", "n0"),
                 "1-D with normal load variation, lift-off"),
    "normal2d": (("u1", "u2", "v"), ("kt", "kn", "mu", "n0"),
                 "in-plane tangential, circular limit"),
    "cubic": (("u",), ("k1", "k3"), "f = k1 u + k3 u^3"),
    "iwan4": (("u",), ("fs", "kt", "chi", "beta"),
              "four-parameter Iwan (Segalman 2005), 31 Jenkins sliders"),
    "iwan": (("u",), tuple(p for s in range(1, 11) for p in (f"k{s}", f"fs{s}")),
             "discrete Iwan: up to 10 parallel Jenkins sliders (k = 0: unused)"),
}
# Units of the parameters, for the table in the module docstring.
_UNITS = {"kt": "N/m", "kn": "N/m", "fn0": "N", "n0": "N", "k1": "N/m", "k3": "N/m^3",
          "fs": "N", **{f"k{s}": "N/m" for s in range(1, 11)},
          **{f"fs{s}": "N" for s in range(1, 11)}}


def _build_laws() -> dict[str, Law]:
    """LAWS from frirom_aft's table (Fortran: codes 1..n_law, sizes, names) and _NAMES.

    Raises RuntimeError at import when the two disagree, so that Python and Fortran can
    never hold different laws.
    """
    *_, n_law = _kernels.law_info(0)
    laws = {}
    for code in range(1, n_law + 1):
        n_dir, n_par, n_slider, name, _ = _kernels.law_info(code)
        name = name.decode().strip()
        if name not in _NAMES:
            raise RuntimeError(f"contact law {code} {name!r} of frirom_aft has no direction "
                               f"and parameter names in frirom.contact._NAMES")
        directions, parameters, _ = _NAMES[name]
        if (len(directions), len(parameters)) != (n_dir, n_par):
            raise RuntimeError(f"contact law {name!r}: frirom_aft has {n_dir} directions and "
                               f"{n_par} parameters, frirom.contact names {directions} and "
                               f"{parameters}")
        laws[name] = Law(name, int(code), directions, parameters, int(n_slider))
    extra = set(_NAMES) - set(laws)
    if extra:
        raise RuntimeError(f"contact laws {sorted(extra)} are not in frirom_aft's table")
    return laws


LAWS: dict[str, Law] = _build_laws()


def _law_table(laws: dict[str, Law]) -> str:
    """The reStructuredText table of the laws for the module docstring."""
    head = ("law", "code", "directions (n_dir)", "parameters (n_par)", "slider",
            "description")
    rows = [(f"``{law.name}``", str(law.code), ", ".join(law.directions),
             ", ".join(f"{p} [{_UNITS[p]}]" if p in _UNITS else p for p in law.parameters),
             str(law.n_slider), _NAMES[law.name][2]) for law in laws.values()]
    widths = [max(len(r[i]) for r in [head, *rows]) for i in range(len(head))]
    rule = "  ".join("=" * w for w in widths)

    def line(row):
        return "  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip()

    return "\n".join([rule, line(head), rule, *map(line, rows), rule])


if __doc__:   # None under python -OO
    __doc__ = __doc__.replace("{law_table}", _law_table(LAWS))

@dataclass
class AftResult:
    """Output of :func:`aft` for n_elem elements at H harmonics."""

    forces: np.ndarray            #: (n_elem, n_dir, 2H+1) force harmonics, N
    jacobian: np.ndarray | None   #: (n_elem, n_dir*(2H+1), n_dir*(2H+1)), N/m
    periods: np.ndarray           #: (n_elem,) periods marched until the cycle closed
    states: np.ndarray            #: (n_elem, 3) fractions of samples in stick, slip, lift-off
    slider: np.ndarray            #: (n_elem, n_slider) slider entering the closed cycle, m


def get_law(law: str | Law) -> Law:
    if isinstance(law, Law):
        return law
    try:
        return LAWS[law]
    except KeyError:
        raise ParameterError(f"unknown contact law {law!r}; expected one of "
                             f"{', '.join(LAWS)}") from None


def stuck_stiffness(law: str | Law, params) -> np.ndarray:
    """(n_elem, n_dir) stiffness [N/m] of each element closed and stuck (kt along the
    tangents, kn along the normal, k1 of a cubic spring): frirom_aft's
    law_stuck_stiffness, what a body held only by its contacts borrows."""
    law = get_law(law)
    p = np.atleast_2d(np.asarray(params, dtype=float))
    ks = _kernels.stuck_stiffness(law.code, law.n_dir, np.asfortranarray(p.T))
    return np.asarray(ks).T


def _params_array(law: Law, params, n_elem: int) -> np.ndarray:
    """(n_par, n_elem) Fortran-ordered parameters from a dict or an (n_elem, n_par) array."""
    if isinstance(params, dict):
        unknown = set(params) - set(law.parameters)
        if unknown:
            raise ParameterError(f"{law.name}: unknown parameter(s) {sorted(unknown)}; "
                                 f"expected {list(law.parameters)}")
        missing = [p for p in law.parameters if p not in params]
        if missing:
            raise ParameterError(f"{law.name}: missing parameter(s) {missing}")
        cols = []
        for p in law.parameters:
            v = as_floats(f"{law.name}: params[{p!r}]", params[p])
            if v.ndim > 1 or (v.ndim == 1 and v.shape[0] != n_elem):
                raise SizeError(f"{law.name}: parameter {p!r} has shape {v.shape}; expected a "
                                f"scalar or ({n_elem},)")
            cols.append(np.broadcast_to(v, (n_elem,)))
        arr = np.stack(cols, axis=1)
    else:
        arr = as_floats(f"{law.name}: params", params)
        if arr.ndim == 1:
            arr = np.broadcast_to(arr, (n_elem, arr.shape[0]))
        if arr.shape != (n_elem, len(law.parameters)):
            raise SizeError(f"{law.name}: params has shape {arr.shape}; expected "
                            f"({n_elem}, {len(law.parameters)}) for {list(law.parameters)}")
    return np.asfortranarray(arr.T)


def _prepare(law, x, params, n_samples, w0, tol, max_periods):
    law = get_law(law)
    check_number("tol", tol, positive=True)
    check_integer("max_periods", max_periods, minimum=1, maximum=2**31 - 1)
    x = element_harmonics(x, law.n_dir, f"{law.name} (directions {list(law.directions)})")
    h = n_harmonics(x.shape[2])
    n_elem = x.shape[0]
    if n_samples is None:
        n_samples = default_samples(h)
    problem = samples_problem(h, n_samples, n_elem * law.n_dir)
    if problem:
        raise SamplesError(f"n_samples: expected {problem} for H = {h}, got {n_samples!r}")
    p = _params_array(law, params, n_elem)
    nsl = max(law.n_slider, 1)
    if w0 is None:
        w = np.zeros((nsl, n_elem), order="F")
    else:
        w = as_floats("w0", w0)
        if law.n_slider == 1 and w.ndim <= 1:
            w = np.broadcast_to(w.reshape(-1), (n_elem,))[None, :] if w.size in (1, n_elem) else w
        if w.ndim == 2 and w.shape == (n_elem, law.n_slider):
            w = w.T
        if w.shape != (law.n_slider, n_elem) or law.n_slider == 0:
            raise SizeError(f"{law.name}: w0 has shape {np.shape(w0)}; expected "
                            f"({n_elem}, {law.n_slider})")
        w = np.asfortranarray(w)
    xf = np.asfortranarray(np.transpose(x, (2, 1, 0)))
    return law, xf, p, w, h, n_elem, n_samples


def aft(law: str | Law, x, params, n_samples: int | None = None, w0=None,
        jacobian: bool = True, tol: float = 1e-12, max_periods: int = 200) -> AftResult:
    """Contact forces of n_elem elements from their relative displacement harmonics.

    Parameters
    ----------
    law : name of the law (see :data:`LAWS`).
    x : (n_elem, n_dir, 2H+1) harmonic coefficients of the local relative displacements, m.
    params : dict of per-law parameters (scalars or (n_elem,) arrays) or an
        (n_elem, n_par) array in the order of ``LAWS[law].parameters``.
    n_samples : time samples per period N (>= 2H+1); default
        :func:`frirom.harmonics.default_samples` (H), the solver's default.
    w0 : initial slider positions (n_elem, n_slider), default 0 (see module doc). Along a
        continuation pass the previous point's ``result.slider``: a contact that enters
        stick-all-cycle then keeps its slider where it last slipped.
    jacobian : also return d forces / d x.
    tol : the march stops when the slider returns to its start within tol times the
        displacement amplitude.
    max_periods : periods marched at most before :class:`frirom.ConvergenceError`.
    """
    law, xf, p, w, h, n_elem, n_samples = _prepare(
        law, x, params, n_samples, w0, tol, max_periods)
    nj = law.n_dir * (2 * h + 1)
    f, jac, periods, states, slider, info, msg = _kernels.aft_eval(
        law.code, n_samples, nj, n_elem if jacobian else 0, xf, p, w, float(tol),
        int(max_periods))
    raise_for_status(info, f"{law.name} AFT: " + msg.decode(errors="replace").strip())
    return AftResult(forces=np.transpose(f, (2, 1, 0)),
                     jacobian=np.transpose(jac, (2, 0, 1)) if jacobian else None,
                     periods=np.asarray(periods), states=np.asarray(states).T,
                     slider=np.asarray(slider).T[:, :law.n_slider])


def time_histories(law: str | Law, x, params, n_samples: int | None = None, w0=None,
                   tol: float = 1e-12, max_periods: int = 200):
    """Relative displacements and forces over the closed cycle, for hysteresis loops.

    Returns (tau, xt, ft): tau (N,) phases in rad; xt, ft (n_elem, n_dir, N).
    """
    law, xf, p, w, h, n_elem, n_samples = _prepare(
        law, x, params, n_samples, w0, tol, max_periods)
    xt, ft, info, msg = _kernels.aft_time(law.code, n_samples, xf, p, w, float(tol),
                                          int(max_periods))
    raise_for_status(info, f"{law.name} AFT: " + msg.decode(errors="replace").strip())
    tau = 2.0 * np.pi * np.arange(n_samples) / n_samples
    return tau, np.transpose(xt, (2, 1, 0)), np.transpose(ft, (2, 1, 0))
