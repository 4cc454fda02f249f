"""Optional extras: the core needs none of them, and a feature whose package is missing
names the extra that installs it (frirom._optional.require), as pyproject.toml lists it."""

import subprocess
import sys
from pathlib import Path

import pytest

from frirom._optional import MissingExtraError, require

try:
    import tomllib
except ModuleNotFoundError:            # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]

# package imported -> the extra that must install it
FEATURES = {"distributed": "study", "dask": "study", "meshio": "vtk", "gmsh": "mesh",
            "pyyeti": "op4"}


def test_extras_install_what_the_features_import():
    extras = PROJECT["optional-dependencies"]
    for module, extra in FEATURES.items():
        names = [r.split(">")[0].split("=")[0].strip() for r in extras[extra]]
        assert module in names, (module, extra, names)
    core = " ".join(PROJECT["dependencies"])
    assert not any(m in core for m in FEATURES), core


@pytest.mark.parametrize("module, extra", [("distributed", "study"), ("meshio", "vtk"),
                                           ("gmsh", "mesh")])
def test_missing_package_names_its_extra(monkeypatch, module, extra):
    monkeypatch.setitem(sys.modules, module, None)      # import raises ModuleNotFoundError
    with pytest.raises(MissingExtraError, match=rf"pip install 'frirom\[{extra}\]'"):
        require(module, extra, "this feature")


def test_study_without_distributed_names_the_extra(monkeypatch):
    from frirom import study
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(MissingExtraError, match=r"frirom\[study\]"):
        study._Runner("local", 1)


def test_import_frirom_needs_no_extra():
    """`import frirom` and the solver's modules load with every extra blocked."""
    code = ("import sys\n"
            "for m in ('dask', 'distributed', 'meshio', 'gmsh', 'pyyeti'): sys.modules[m] = None\n"
            "import frirom\n"
            "frirom.Model, frirom.frf, frirom.load_deck, frirom.read_calculix\n"
            "import frirom.cli, frirom.study, frirom.maps\n")
    subprocess.run([sys.executable, "-c", code], check=True)
