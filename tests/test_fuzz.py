"""Property-based fuzzing (hypothesis) of the deck parser and the readers: whatever a
mutated deck or matrix file holds, frirom accepts it or raises one of its own errors, never
a raw Python exception (tests/_mutate.py makes the mutations).

The examples are derandomized (the same inputs on every run, so CI is reproducible) and few
(a few hundred in all, seconds); cases/bench/fuzz.py runs the long campaign (10 000 decks).
"""

from __future__ import annotations

import shutil
import tempfile
import time
from pathlib import Path

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402

from _mutate import (ROOT, STUDY_TABLE, load_and_check, make_results,  # noqa: E402
                     mutate_bytes, mutate_deck, mutate_results, reader_cases, results_check,
                     study_check, try_input)

DECKS = {"joint": ROOT / "cases" / "joint" / "joint.toml",
         "bladed_disk": ROOT / "cases" / "bladed_disk" / "bladed_disk.toml"}
FUZZ = dict(derandomize=True, deadline=None, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])
#: A deck loads in milliseconds; 10 s is a hang (issue 13 found parser runs over 60 s).
HANG_SECONDS = 10.0


@pytest.fixture(scope="module")
def decks(tmp_path_factory):
    """The bundled [model] decks with their matrices in a scratch folder each."""
    out = {}
    for name, deck in DECKS.items():
        d = tmp_path_factory.mktemp(name)
        for f in deck.parent.iterdir():
            if f.suffix in (".mtx", ".txt", ".toml"):
                shutil.copy(f, d / f.name)
        out[name] = d
    return out


def _check(outcome, exc, what):
    assert outcome != "crash", f"{what}: raw {type(exc).__name__}: {exc}"


@settings(max_examples=200, **FUZZ)
@given(name=st.sampled_from(sorted(DECKS)), rnd=st.randoms(use_true_random=False))
def test_mutated_decks_load_or_raise_frirom_errors(decks, name, rnd):
    _fuzz(decks[name] / "fuzzed.toml", mutate_deck(DECKS[name].read_text(), rnd),
          load_and_check)


@settings(max_examples=150, **FUZZ)
@given(case=st.sampled_from(reader_cases()), rnd=st.randoms(use_true_random=False),
       which=st.integers(0, 3))
def test_mutated_files_read_or_raise_frirom_errors(tmp_path, case, rnd, which):
    name, files, read = case
    folder = Path(tempfile.mkdtemp(dir=tmp_path))
    victim = sorted(files)[which % len(files)]
    for f, content in files.items():
        (folder / f).write_bytes(mutate_bytes(content, rnd) if f == victim else content)
    outcome, exc = try_input(lambda: read(folder))
    _check(outcome, exc, f"{name}: {victim}: {(folder / victim).read_bytes()[:400]!r}")


def test_unmutated_inputs_are_accepted(decks):
    """The fuzzers start from valid inputs: each loads (so a mutation is what fails)."""
    for name in DECKS:
        assert try_input(lambda: load_and_check(decks[name] / DECKS[name].name))[0] == "ok"
    for name, files, read in reader_cases():
        assert try_input(lambda: read(_write(files)))[0] == "ok", name


def _write(files):
    d = Path(tempfile.mkdtemp())
    for f, content in files.items():
        (d / f).write_bytes(content)
    return d


@settings(max_examples=100, **FUZZ)
@given(name=st.sampled_from(sorted(DECKS)), rnd=st.randoms(use_true_random=False))
def test_mutated_study_decks_load_or_raise_frirom_errors(decks, name, rnd):
    """Study decks (a bundled deck with a [study] table) mutated: read, members checked
    and the scheduler chosen (never connected to), or a frirom error."""
    _fuzz(decks[name] / "fuzzed_study.toml",
          mutate_deck(DECKS[name].read_text() + STUDY_TABLE, rnd), study_check)


def _fuzz(path, data: bytes, check):
    """Write the mutated deck, run check(path): a clean outcome or a frirom error, in time."""
    path.write_bytes(data)
    t0 = time.perf_counter()
    outcome, exc = try_input(lambda: check(path))
    _check(outcome, exc, data[:2000])
    assert time.perf_counter() - t0 < HANG_SECONDS


@pytest.fixture(scope="module")
def results_file(tmp_path_factory):
    return make_results(tmp_path_factory.mktemp("results"))


@pytest.mark.slow
@settings(max_examples=100, **FUZZ)
@given(rnd=st.randoms(use_true_random=False))
def test_mutated_results_files_load_or_raise_frirom_errors(results_file, tmp_path, rnd):
    """Results files edited with h5py (junk datasets, retyped attributes, links, nesting,
    changed values): read as `frirom show` and --resume do, or refused by a frirom error;
    an accepted file holds finite frequencies and amplitudes."""
    import numpy as np
    dst = Path(tempfile.mkdtemp(dir=tmp_path)) / "frf.h5"
    what = mutate_results(results_file, dst, rnd)
    outcome, exc = try_input(lambda: results_check(dst))
    _check(outcome, exc, what)
    if outcome == "ok":
        from frirom.results import FRF
        f = FRF.load(dst)
        assert np.all(np.isfinite(f.omega)) and np.all(np.isfinite(f.amp_max)), what


@pytest.mark.parametrize("kind", range(8))
def test_every_dataset_junk_without_checksum_is_refused_or_read(results_file, tmp_path,
                                                                 kind):
    """Each dataset of a results file replaced by each kind of junk (NaN, text, other
    shapes, Inf, a scalar, int8, no rows, ones), its checksum removed: read as --resume
    does or refused by a frirom error. The 10 000-deck campaign found a scalar or empty
    checkpoint dataset (ck_lu, yscale) and NaN iterations reaching an IndexError."""
    import shutil
    import h5py
    from _mutate import _junk

    class Kind:
        def randrange(self, n):
            return kind
    with h5py.File(results_file) as f:
        names = sorted(k for k in f if isinstance(f[k], h5py.Dataset))
    for name in names:
        dst = tmp_path / f"{name}.h5"
        shutil.copyfile(results_file, dst)
        with h5py.File(dst, "a") as f:
            del f.attrs["content_sha256"]
            shape = f[name].shape
            del f[name]
            f[name] = _junk(Kind(), shape)
        outcome, exc = try_input(lambda: results_check(dst))
        _check(outcome, exc, f"{name} junk {kind}")
