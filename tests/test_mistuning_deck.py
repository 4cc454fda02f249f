"""Mistuning decks: `frirom run` / `frirom study` on a deck with [mistuning] give the
same amplification factors as the API (frirom.mistuning) on the same sector, the outputs
are written, and malformed fields are named."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from _mistuned import disk
from frirom import InputError
from frirom.cli import main
from frirom.mistuning import MistunedDisk, monte_carlo
from frirom.mistuning_deck import parse_mistuning_deck, write_sector
from frirom.model import Damping
from frirom.reduction.mistuning import deviations, mistuning_sector

N, EO = 6, 2
F0, F1 = 195.4, 264.4   # Hz, 0.85..1.15 x the first ND-2 mode of the 6-blade lattice disk

DECK = f"""title = "test disk"
[model]
sector = "sector.npz"
fixed_interface_modes = 12
[mistuning]
MISTUNING
[damping]
alpha = 2.0
beta = 2.0e-6
[excitation]
engine_order = {EO}
[solver]
harmonics = 3
linear_points = 101
[frequency]
start = {F0}
end = {F1}
STUDY
"""


@pytest.fixture(scope="module")
def sector(tmp_path_factory):
    d = disk(N, ground=False)
    folder = tmp_path_factory.mktemp("mdeck")
    write_sector(folder / "sector.npz", d["Ks"], d["Ms"], d["sector"], blade=d["blade"],
                 keep=d["keep"], output=int(d["tip"][0]), F=d["F"], contacts=d["contacts"])
    return d, folder


def _deck(folder, mistuning="std = 0.04\nseed = 3", study=""):
    p = folder / "disk.toml"
    p.write_text(DECK.replace("MISTUNING", mistuning).replace("STUDY", study))
    return p


def _api(d):
    ms = mistuning_sector(d["sector"], d["Ks"], d["Ms"], 12, d["blade"], keep=d["keep"])
    return MistunedDisk(ms, ms.reduce_contacts(d["contacts"]), ms.T.T @ d["F"], EO,
                        int(ms.reduced(d["tip"][0])[0]),
                        (2 * np.pi * F0, 2 * np.pi * F1), Damping.rayleigh(2.0, 2e-6),
                        n_linear=101)


def test_run_deck_equals_api(sector, tmp_path, capsys):
    d, folder = sector
    deck = _deck(folder, "deviations = [0.03, -0.02, 0.05, 0.0, -0.04, 0.01]",
                 '[study]\nkind = "mistuning"\ninterfaces = ["stuck", "free"]\n')
    # a [study] with a deviations list is refused (each sample draws its own)
    with pytest.raises(InputError, match="mistuning.std"):
        parse_mistuning_deck(deck)
    deck = _deck(folder, "deviations = [0.03, -0.02, 0.05, 0.0, -0.04, 0.01]")
    text = deck.read_text() + '[outputs]\ndofs = ["x"]\n'
    bad = folder / "bad.toml"
    bad.write_text(text)
    with pytest.raises(InputError, match="bad.toml: outputs"):
        parse_mistuning_deck(bad)
    assert main(["run", str(deck), "--out", str(tmp_path)]) == 0
    res = json.loads((tmp_path / "mistuning.json").read_text())
    md = _api(d)
    delta = deviations(N, values=[0.03, -0.02, 0.05, 0.0, -0.04, 0.01])
    ref = md.response(delta, "friction").peak / md.response(None, "friction").peak
    assert abs(res["states"]["friction"]["amplification"] - ref) < 1e-8 * ref
    rows = list(csv.reader(open(tmp_path / "blades.csv")))
    assert rows[0] == ["blade", "deviation", "amplitude_friction"] and len(rows) == N + 1
    assert (tmp_path / "blades_friction.png").exists()
    assert "amplification" in capsys.readouterr().out


@pytest.mark.slow
@pytest.mark.parametrize("scheduler", ["serial", "local"])
def test_study_deck_equals_serial_monte_carlo(sector, tmp_path, capsys, scheduler):
    """The deck's study equals monte_carlo run serially; 'local': one LocalCluster of two
    workers for both interface states."""
    d, folder = sector
    deck = _deck(folder, study='[study]\nkind = "mistuning"\nsamples = 4\n'
                 f'interfaces = ["stuck", "free"]\nscheduler = "{scheduler}"\n'
                 'workers = 2\n')
    assert main(["study", str(deck), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "stuck 2/4: amplification mean" in out and "free 4/4" in out
    st = json.loads((tmp_path / "statistics.json").read_text())
    md = _api(d)
    for state in ("stuck", "free"):
        ref = monte_carlo(md, 4, 0.04, seed=3, interfaces=state)
        assert abs(st["statistics"][state]["mean"] - ref["stats"]["mean"]) < 1e-10
    rows = list(csv.reader(open(tmp_path / "amplification.csv")))
    assert rows[0] == ["sample", "af_stuck", "af_free"] and len(rows) == 5
    assert (tmp_path / "amplification.png").exists()
    assert (tmp_path / "envelope_stuck.png").exists()
    # a rerun reads every finished sample back: no sample computed, the same statistics
    assert main(["study", str(deck), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "stuck 2/4" not in out and "stuck 4/4: amplification mean" in out
    assert json.loads((tmp_path / "statistics.json").read_text()) == st


@pytest.mark.parametrize("mistuning,study,match", [
    ("std = 0.8", "", "mistuning.std: expected a number at most 0.5"),
    ("std = 0.01\ndeviations = [0.0]", "", "mistuning: expected exactly one of"),
    ("std = 0.01\nsigma = 2", "", "mistuning.sigma: expected one of the known keys"),
    ("deviations = [0.1, -1.5]", "", "mistuning.deviations: expected a list"),
    ("std = 0.01", '[study]\nkind = "family"', "study.kind: expected"),
    ("std = 0.01", '[study]\nkind = "mistuning"\ninterfaces = ["stick"]',
     "study.interfaces: expected"),
    ("std = 0.01", '[study]\nkind = "mistuning"\nscheduler = "host:1"',
     "study.scheduler: expected"),
    ("std = 0.01\nmean = 0.02", '[study]\nkind = "mistuning"', "mistuning.mean"),
])
def test_bad_fields_are_named(tmp_path, mistuning, study, match):
    with pytest.raises(InputError, match=match):
        parse_mistuning_deck(_deck(tmp_path, mistuning, study))


def test_missing_sector_file_and_address_from_deck(tmp_path):
    deck = _deck(tmp_path, study='[study]\nkind = "mistuning"\nscheduler = '
                 '"tcp://127.0.0.1:8786"')
    with pytest.raises(InputError, match="model.sector: .*does not exist"):
        main_raise(["run", str(deck), "--out", str(tmp_path / "o")])
    with pytest.raises(InputError, match="trust-deck-scheduler"):
        from frirom.mistuning_deck import run_mistuning_study
        run_mistuning_study(deck, tmp_path / "o")


def main_raise(argv):
    from frirom.cli import build_parser
    a = build_parser().parse_args(argv)
    return a.func(a)


def test_sector_file_with_blade_stiffness(sector, tmp_path):
    """A sector file with the blade elements' matrix: the deck's disk carries the root
    term (keep_root) and equals the API's; a blade matrix that is not the blade's is an
    error naming the deck and the sector file."""
    from test_mistuning import _blade_elements

    from frirom.mistuning_deck import build_disk
    d, _ = sector
    Ke, root = _blade_elements(d["Ks"], d["blade"], 0.5)
    kw = dict(blade=d["blade"], keep=d["keep"], output=int(d["tip"][0]), F=d["F"],
              contacts=d["contacts"])
    write_sector(tmp_path / "sector.npz", d["Ks"], d["Ms"], d["sector"], blade_stiffness=Ke,
                 **kw)
    md = parse_mistuning_deck(_deck(tmp_path))
    disk_ = build_disk(md)
    ms = mistuning_sector(d["sector"], d["Ks"], d["Ms"], 12, d["blade"], keep=d["keep"],
                          blade_stiffness=Ke, keep_root=True)
    assert disk_.sector.root_K is not None
    delta = deviations(N, 0.04, seed=3)
    assert np.allclose(disk_.sector.stiffness(delta).toarray(), ms.stiffness(delta).toarray(),
                       rtol=1e-12, atol=1e-9 * np.abs(ms.K).max())
    bad = Ke.copy()
    bad[d["blade"][0], d["blade"][0]] *= 2
    write_sector(tmp_path / "sector.npz", d["Ks"], d["Ms"], d["sector"], blade_stiffness=bad,
                 **kw)
    with pytest.raises(InputError, match=r"disk.toml: model.sector: .*blade block differs"):
        build_disk(parse_mistuning_deck(_deck(tmp_path)))
