"""frirom: nonlinear forced response of frictionally damped structures.

``import frirom`` gives the documented names below; each is the object of the module it
lives in (``frirom.Model is frirom.model.Model``), imported when first used so that
``import frirom`` stays quick. The hot kernels are Fortran (``frirom._kernels``, one f2py
extension); errors are :class:`frirom.FriromError` subclasses carrying the Fortran status
message.

Model and solver
    Model, ContactGroup, Damping, Excitation, CyclicModel, SolverOptions, frf,
    solve_point, load_curve, FRF, FRFPoint, Peak
Decks
    load_deck, parse_deck, build_deck, Deck
Readers of FE matrices (one per format, each returning an FEModel)
    read_calculix, read_matrix_market, read_abaqus, read_hbmat, read_op4, FEModel
Reductions
    craig_bampton, gsi_basis, reduce_interface, ms_basis, cyclic_sector, cyclic_model,
    modal_damping, rayleigh_coefficients
"""

from importlib import import_module
from importlib.metadata import PackageNotFoundError, version as _dist_version

from ._errors import (ConvergenceError, FactorizationError, FriromError, InputError,
                      NonFiniteError, NumericalError, ParameterError, SamplesError,
                      SingularMatrixError, SizeError)

try:    # the one version: pyproject.toml's [project] version, as installed
    __version__ = _dist_version("frirom")
except PackageNotFoundError:     # a source tree on sys.path without an install
    __version__ = "0+unknown"

#: public name -> the module that defines it (relative to this package)
_LAZY = {
    "Model": ".model", "ContactGroup": ".model", "Damping": ".model",
    "Excitation": ".model", "CyclicModel": ".model",
    "SolverOptions": ".solver", "frf": ".solver", "solve_point": ".solver",
    "load_curve": ".solver",
    "nonlinear_mode": ".nonlinear_modes", "Backbone": ".nonlinear_modes",
    "FRF": ".results", "FRFPoint": ".results", "Peak": ".results",
    "load_deck": ".deck", "parse_deck": ".deck", "build_deck": ".deck", "Deck": ".deck",
    "FEModel": ".io", "read_calculix": ".io", "read_matrix_market": ".io",
    "read_abaqus": ".io", "read_hbmat": ".io", "read_op4": ".io",
    "craig_bampton": ".reduction.cb", "gsi_basis": ".reduction.interface",
    "reduce_interface": ".reduction.interface", "ms_basis": ".reduction.multistage",
    "cyclic_sector": ".reduction.cyclic", "cyclic_model": ".reduction.cyclic",
    "modal_damping": ".reduction.damping",
    "rayleigh_coefficients": ".reduction.damping",
}

_ERRORS = ["FriromError", "InputError", "SizeError", "ParameterError", "NonFiniteError",
           "SamplesError", "NumericalError", "ConvergenceError", "SingularMatrixError",
           "FactorizationError"]

__all__ = list(_LAZY) + _ERRORS


def __getattr__(name):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'frirom' has no attribute {name!r}")
    value = getattr(import_module(module, __name__), name)
    globals()[name] = value          # later look-ups skip this function
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
