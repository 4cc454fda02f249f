"""A damper or bolt load given once (issue 29 item 2): ``[[preload]]`` derives each pair's
n0 and the balancing harmonic-0 loads from the body's load, so a family over the load is
one key path; a normal pointing the wrong way is refused.

Reference: the bundled lap joint's deck, whose bolt is written by hand as n0 = 32 N per
pair and +-32 N harmonic-0 loads on the two faces (docs/deck.md): the same bolt given as
one load (32 N x the pairs) must build the same contact parameters and loads, to
round-off."""

import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from frirom import InputError
from frirom.deck import load_deck

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def lap(tmp_path_factory):
    if shutil.which("ccx") is None:
        pytest.skip("ccx not installed")
    pytest.importorskip("gmsh")
    import make_lap_joint
    from _models import small_lap_joint_deck
    out = tmp_path_factory.mktemp("lap_preload")
    make_lap_joint.make(out, size=0.012)
    return out, small_lap_joint_deck(None)


def _by_load(text, load, direction="[0.0, 0.0, 1.0]", body=None):
    """The hand-written bolt replaced by one [[preload]]."""
    text = text.replace("n0 = 32.0", "")
    text = re.sub(r"\[\[excitation\.load\]\][^\[]*?harmonic = 0\namplitude = -?32\.0\n*", "",
                  text)
    assert "harmonic = 0" not in text
    return text + (f"\n[[preload]]\nload = {load!r}\ndirection = {direction}\n"
                   f'contacts = ["lap"]\n' + (f'body = "{body}"\n' if body else ""))


def test_preload_builds_the_hand_written_bolt(lap, tmp_path, monkeypatch):
    case, text = lap
    monkeypatch.setenv("FRIROM_CACHE", str(tmp_path / "cache"))
    (case / "hand.toml").write_text(text)
    hand = load_deck(case / "hand.toml")
    npairs = hand.contacts[0].params.shape[0]
    assert npairs == 65 and np.all(hand.contacts[0].params[:, 3] == 32.0)
    (case / "one.toml").write_text(_by_load(text, 32.0 * npairs))
    one = load_deck(case / "one.toml")
    assert one.contacts[0].params[:, 3] == pytest.approx(32.0, rel=1e-12)
    np.testing.assert_array_equal(one.contacts[0].params[:, :3], hand.contacts[0].params[:, :3])
    np.testing.assert_allclose(one.F[:, 0], hand.F[:, 0], rtol=0,
                               atol=1e-12 * np.abs(hand.F[:, 0]).max())
    np.testing.assert_array_equal(one.F[:, 1:], hand.F[:, 1:])
    assert any("preload[0]: 2080 N on side a carried by lap n0 = 32 N x 65 pairs" in s
               for s in one.log), one.log
    # the same bolt seen from plate B (side b) pushing the other way: the same model
    (case / "b.toml").write_text(_by_load(text, 32.0 * npairs, "[0.0, 0.0, -1.0]", "b"))
    np.testing.assert_allclose(load_deck(case / "b.toml").F[:, 0], hand.F[:, 0], rtol=0,
                               atol=1e-12 * np.abs(hand.F[:, 0]).max())


@pytest.mark.slow
def test_preload_refuses_a_wrong_normal_and_a_given_n0(lap, tmp_path, monkeypatch):
    case, text = lap
    monkeypatch.setenv("FRIROM_CACHE", str(tmp_path / "cache"))
    (case / "flip.toml").write_text(_by_load(text, 2080.0).replace(
        "normal = [0.0, 0.0, 1.0]", "normal = [0.0, 0.0, -1.0]"))
    with pytest.raises(InputError, match=r"contacts\[0\]\.normal: expected a normal along "
                       r"which preload\[0\]'s load presses the face closed \(it would pull "
                       r"it open, n0 = -32 N per pair\)"):
        load_deck(case / "flip.toml")
    (case / "side.toml").write_text(_by_load(text, 2080.0, "[1.0, 0.0, 0.0]"))
    with pytest.raises(InputError, match=r"preload\[0\]\.direction: expected a load the "
                       r"contacts' normals can carry \(2080 N of it"):
        load_deck(case / "side.toml")
    (case / "both.toml").write_text(_by_load(text, 2080.0).replace(
        "mu = 0.3", "mu = 0.3\nn0 = 32.0"))
    with pytest.raises(InputError, match=r"contacts\[0\]\.n0: expected no value: a "
                       r"\[\[preload\]\] carried by this contact derives it"):
        load_deck(case / "both.toml")


def test_a_family_over_the_load_is_one_key_path(lap, tmp_path, monkeypatch):
    # every member's n0 follows its load: one key path instead of n0 and two loads zipped
    from frirom.deck import build_deck, parse_deck
    from frirom.deck.schema import read_toml
    case, text = lap
    monkeypatch.setenv("FRIROM_CACHE", str(tmp_path / "cache"))
    (case / "fam.toml").write_text(_by_load(text, 2080.0))
    raw = read_toml(case / "fam.toml")
    for load in (650.0, 2080.0, 6500.0):
        raw["preload"][0]["load"] = load
        d = build_deck(parse_deck(case / "fam.toml", raw))
        assert d.contacts[0].params[:, 3] == pytest.approx(load / 65, rel=1e-12)


def test_study_key_path_reaches_the_preload(lap):
    from frirom.deck.schema_study import set_key
    _, text = lap
    import tomllib
    raw = tomllib.loads(_by_load(text, 2080.0))
    set_key(raw, "preload[0].load", 650.0)
    assert raw["preload"][0]["load"] == 650.0


def test_parallel_faces_share_one_pressure(lap, tmp_path, monkeypatch):
    # the overlap's pairs as two contacts with the same normal (as a flat strip damper
    # under two platforms): the balance leaves the shares open; each pair gets the same
    # n0, 2080 N / 130 pairs, and the loads are twice the one-contact bolt's
    case, text = lap
    monkeypatch.setenv("FRIROM_CACHE", str(tmp_path / "cache"))
    two = _by_load(text, 2080.0).replace('contacts = ["lap"]', 'contacts = ["lap", "lap2"]')
    block = two[two.index("[[contacts]]"):two.index("[damping]")]
    two = two.replace(block, block + block.replace('name = "lap"', 'name = "lap2"'))
    (case / "two.toml").write_text(two)
    d = load_deck(case / "two.toml")
    for c in d.contacts:
        assert c.params[:, 3] == pytest.approx(16.0, rel=1e-12)
    assert any("statically indeterminate" in s for s in d.log)
    (case / "one.toml").write_text(_by_load(text, 2080.0))
    one = load_deck(case / "one.toml")
    np.testing.assert_allclose(d.F[:, 0], one.F[:, 0], rtol=0,
                               atol=1e-12 * np.abs(one.F[:, 0]).max())


@pytest.mark.slow
def test_hand_written_preload_with_flipped_normal_is_warned(lap, tmp_path, monkeypatch):
    # no [[preload]]: n0 = 32 N and the +-32 N loads by hand, the normal flipped; the
    # loads then push against the preload's balance (factor -1): a warning names the key
    case, text = lap
    monkeypatch.setenv("FRIROM_CACHE", str(tmp_path / "cache"))
    (case / "ok.toml").write_text(text)
    assert not any("WARNING" in s for s in load_deck(case / "ok.toml").log)
    (case / "flip2.toml").write_text(text.replace("normal = [0.0, 0.0, 1.0]",
                                                  "normal = [0.0, 0.0, -1.0]"))
    log = load_deck(case / "flip2.toml").log
    assert any("WARNING: contacts[0].normal = [0.0, 0.0, -1.0]: the deck's harmonic-0 "
               "loads push against the balance of its preload n0" in s and "factor -1.00"
               in s for s in log), log
