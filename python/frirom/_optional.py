"""Optional dependencies: a feature that needs one imports it through :func:`require`,
which names the extra that installs it when it is missing (pyproject.toml's
[project.optional-dependencies]: study, vtk, mesh, op4)."""

from importlib import import_module

from ._errors import InputError


class MissingExtraError(InputError, ModuleNotFoundError):
    """A feature's optional dependency is not installed; the message names the extra."""


def require(module: str, extra: str, feature: str):
    """The module, or MissingExtraError: "<feature> needs <module>: pip install
    'frirom[<extra>]'"."""
    try:
        return import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name is not None and exc.name.split(".")[0] != module.split(".")[0]:
            raise        # the package is there but one of its own imports is broken
        raise MissingExtraError(f"{feature} needs the '{module}' package, which is not "
                                f"installed: pip install 'frirom[{extra}]'") from None
