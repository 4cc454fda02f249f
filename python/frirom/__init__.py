"""frirom: nonlinear forced response of frictionally damped structures.

The hot kernels are Fortran (``frirom._kernels``, one f2py extension); this package is the
thin layer that checks inputs, calls them on numpy arrays and raises
:class:`frirom.FriromError` subclasses carrying the Fortran status message.
"""

from ._errors import (ConvergenceError, FactorizationError, FriromError, InputError,
                      NonFiniteError, NumericalError, ParameterError, SamplesError,
                      SingularMatrixError, SizeError)

__version__ = "0.1.0"

__all__ = ["FriromError", "InputError", "SizeError", "ParameterError", "NonFiniteError",
           "SamplesError", "NumericalError", "ConvergenceError", "SingularMatrixError",
           "FactorizationError"]
