"""The TOML deck: the bundled case loads, and every malformed field raises InputError
naming the deck, the key path and what was expected."""

import shutil
from pathlib import Path

import numpy as np
import pytest

from frirom import InputError
from frirom.deck import engine_order_loads, load_deck

ROOT = Path(__file__).resolve().parents[1]
JOINT = ROOT / "cases" / "joint"
BASE = (JOINT / "joint.toml").read_text()


@pytest.fixture
def deckdir(tmp_path):
    for f in ("M.mtx", "K.mtx", "dofs.txt"):
        shutil.copy(JOINT / f, tmp_path / f)
    return tmp_path


def write(deckdir, text):
    p = deckdir / "case.toml"
    p.write_text(text)
    return p


# cases/joint's matrices as its K.mtx and M.mtx write them (lower triangle mirrored), N/m, kg
JOINT_K = np.array([[5.5e6, 0.0, -1.5e6, 0.0, 0.0],
                    [0.0, 8e6, 0.0, 0.0, 0.0],
                    [-1.5e6, 0.0, 2.5e6, -1e6, 0.0],
                    [0.0, 0.0, -1e6, 1.6e6, -6e5],
                    [0.0, 0.0, 0.0, -6e5, 6e5]])
JOINT_M = np.diag([8e-2, 8e-2, 3e-2, 3e-2, 2e-2])
COS30 = 0.8660254037844386      # the decks' direction component, as written


def test_joint_deck_loads():
    d = load_deck(JOINT / "joint.toml")
    assert d.n_dof == 5 and d.harmonics == 5 and d.samples == 64
    assert d.title == "Blade with platform friction damper"
    assert np.array_equal(d.K.toarray(), JOINT_K) and np.array_equal(d.M.toarray(), JOINT_M)
    assert d.dof_labels == ["platform:x", "platform:y", "blade_low:x", "blade_mid:x", "tip:x"]
    assert d.damping["type"] == "modal" and np.array_equal(d.damping["zeta"], [0.003] * 5)
    assert d.F.shape == (5, 6) and d.F[4, 1] == 2.0 and np.count_nonzero(d.F) == 1
    c = d.contacts[0]
    assert c.name == "damper" and c.law == "jenkins" and c.G.shape == (1, 5)
    # a frame already unit to round-off is kept as written, bit for bit (C and Fortran
    # callers given the same numbers solve the same model: tests/capi_compare.py)
    assert np.array_equal(c.G.toarray(), [[COS30, 0.5, 0, 0, 0]])
    assert np.array_equal(c.params, [[1e7, 0.5, 100.0]]) and c.w0 is None
    assert d.formulation == "condensed" and d.frequency_unit == "hz"
    assert d.outputs == [4, 0, 1] and d.output_names[0] == "tip:x"
    assert np.isclose(d.omega_start, 2 * np.pi * 400) and np.isclose(d.omega_end,
                                                                     2 * np.pi * 520)
    assert d.continuation == {"step": 0.02, "max_step": 0.1, "max_points": 1000}
    assert d.solver["stability"] is True        # the deck says so (default false)


def test_frame_not_unit_is_normalised(deckdir):
    d = load_deck(write(deckdir, BASE.replace("directions = [ [0.8660254037844386, 0.5] ]",
                                              "directions = [ [3.0, 4.0] ]")))
    assert np.allclose(d.contacts[0].G.toarray(), [[0.6, 0.8, 0, 0, 0]], rtol=0, atol=1e-16)


def test_normal1d_frame_and_solver_objects(deckdir):
    text = BASE.replace('law = "jenkins"', 'law = "normal1d"').replace(
        "directions = [ [0.8660254037844386, 0.5] ]",
        "directions = [ [0.8660254037844386, 0.5], [-0.5, 0.8660254037844386] ]").replace(
        "fn0 = 100.0", "kn = 2.0e7\nn0 = 100.0\nw0 = 1e-6")
    d = load_deck(write(deckdir, text))
    c = d.contacts[0]
    Gd = c.G.toarray()
    assert c.law == "normal1d" and np.allclose(Gd @ Gd.T, np.eye(2))   # orthonormal frame
    assert np.allclose(Gd, [[COS30, 0.5, 0, 0, 0], [-0.5, COS30, 0, 0, 0]], rtol=0, atol=1e-15)
    assert np.array_equal(c.params, [[1e7, 2e7, 0.5, 100.0]])
    assert c.w0.shape == (1, 1) and np.all(c.w0 == 1e-6)
    model, exc, opts = d.model(), d.excitation(), d.options()
    assert model.n_dof == 5 and model.contacts[0].name == "damper"
    assert np.array_equal(model.K.toarray(), JOINT_K)
    assert np.array_equal(model.M.toarray(), JOINT_M)
    g = model.contacts[0]
    assert g.law == "normal1d" and np.array_equal(g.params, c.params)
    assert np.array_equal(g.G.toarray(), Gd)
    assert model.damping.kind == "modal" and np.all(model.damping.zeta == 0.003)
    assert exc.F.shape == (5, 6) and np.array_equal(exc.F, d.F)
    assert opts.harmonics == 5 and opts.samples == 64 and opts.formulation == "condensed"
    assert (opts.ds, opts.ds_max, opts.max_points) == (0.02, 0.1, 1000)
    assert opts.stability


def test_node_to_node_element_and_engine_order(deckdir):
    text = BASE.replace('b = "ground"', 'b = ["blade_low:x", "blade_mid:x"]')
    text = text.replace("[[excitation.load]]", """[[excitation.engine_order]]
eo = 1
dofs = [2, 3, 4]
amplitude = 1.0

[[excitation.load]]""")
    d = load_deck(write(deckdir, text))
    G = d.contacts[0].G.toarray()
    # relative displacement a - b along the face: platform (x, y) minus blade_low, blade_mid
    assert np.allclose(G, [[COS30, 0.5, -COS30, -0.5, 0.0]], rtol=0, atol=1e-15)
    # engine order 1 over the 3 DoFs (3 sectors): unit loads, sector s lags by 2 pi s / 3
    lag = np.exp(-2j * np.pi * np.arange(3) / 3)
    assert np.allclose(d.F[[2, 3], 1], lag[:2], rtol=0, atol=1e-15)
    assert np.isclose(d.F[4, 1], 2.0 + lag[2])
    assert np.count_nonzero(d.F) == 3


def test_engine_order_loads_pattern():
    F = engine_order_loads(6, [0, 2, 4], eo=2, n_sectors=3, amplitude=2.0)
    assert np.allclose(F[[0, 2, 4], 1], 2.0 * np.exp(-2j * np.pi * 2 * np.arange(3) / 3))


BAD = [
    # (replace this, with that, the key path and words expected in the message)
    ('harmonics = 5', 'harmonics = 0', "solver.harmonics", ">= 1"),
    ('harmonics = 5', 'harmonics = "five"', "solver.harmonics", "integer"),
    ('samples = 64', 'samples = 8', "solver.samples", ">= 2*harmonics+1"),
    ('formulation = "condensed"', 'formulation = "dense"', "solver.formulation", "banded"),
    ('mu = 0.5', 'mu = -0.5', "contacts[0].mu", ">= 0"),
    ('mu = 0.5', 'mu = [0.5, 0.4]', "contacts[0].mu", "1 numbers"),
    ('mu = 0.5                      # friction coefficient\n', '', "contacts[0].mu",
     "missing"),
    ('kt = 1.0e7', 'kt = 0.0', "contacts[0].kt", "positive"),
    ('law = "jenkins"', 'law = "coulomb"', "contacts[0].law", "normal1d"),
    ('fn0 = 100.0', 'n0 = 100.0', "contacts[0].n0", "unknown key"),
    ('dof = "tip:x"', 'dof = "tip:z"', "excitation.load[0].dof", "label"),
    ('dof = "tip:x"', 'dof = 7', "excitation.load[0].dof", "0..4"),
    ('harmonic = 1\namp', 'harmonic = 9\namp', "excitation.load[0].harmonic", "0..solver"),
    ('amplitude = 2.0 ', 'amplitud = 2.0 ', "excitation.load[0].amplitud", "unknown key"),
    ('start = 400.0', 'start = -400.0', "frequency.start", "positive"),
    ('unit = "Hz"', 'unit = "rpm"', "frequency.unit", "hz"),
    ('mass = "M.mtx"', 'mass = "nothere.mtx"', "model.mass", "does not exist"),
    ('format = "mtx"', 'format = "op4"', "model.format", "mtx"),
    ('type = "modal"', 'type = "hysteretic"', "damping.type", "rayleigh"),
    ('zeta = 0.003', 'zeta = 1.5', "damping.zeta", "[0, 1)"),
    ('directions = [ [0.8660254037844386, 0.5] ]',
     'directions = [ [0.8660254037844386, 0.5], [-0.5, 0.8660254037844386] ]',
     "contacts[0].directions", "1 direction"),
    ('directions = [ [0.8660254037844386, 0.5] ]', 'directions = [ [0.0, 0.0] ]',
     "contacts[0].directions[0]", "non-zero"),
    ('directions = [ [0.8660254037844386, 0.5] ]', 'directions = [ [1.0, 0.5, 0.1] ]',
     "contacts[0].directions[0]", "2 numbers"),
    ('b = "ground"', 'b = ["tip:x"]', "contacts[0].elements[0].b", "2 DoFs"),
    ('b = "ground"', 'b = ["platform:x", "tip:x"]', "contacts[0].elements[0].b",
     "different"),
    ('dofs = ["tip:x", "platform:x", "platform:y"]', 'dofs = []', "outputs.dofs",
     "non-empty"),
    ('max_step = 0.1 ', 'max_step = 0.1\nmin_step = 0.5 ', "continuation.min_step",
     "max_step"),
    ('stability = true ', 'stability = 1 ',
     "solver.stability", "true or false"),
    ('[solver]', '[solvers]', "solvers", "unknown key"),
]


@pytest.mark.parametrize("old,new,key,words", BAD, ids=[b[2] + ":" + b[1][:20] for b in BAD])
def test_malformed_field_names_key(deckdir, old, new, key, words):
    assert old in BASE
    path = write(deckdir, BASE.replace(old, new, 1))
    with pytest.raises(InputError) as info:
        load_deck(path)
    msg = str(info.value)
    assert str(path) in msg and key in msg and words in msg, msg


def test_bad_toml_and_bad_matrix(deckdir):
    p = write(deckdir, BASE.replace("[solver]", "[solver"))
    with pytest.raises(InputError, match="not valid TOML"):
        load_deck(p)
    (deckdir / "M.mtx").write_text("%%MatrixMarket matrix coordinate real general\n5 5 1\n"
                                   "1 1 nonsense\n")
    with pytest.raises(InputError, match="M.mtx"):
        load_deck(write(deckdir, BASE))
    with pytest.raises(InputError, match="does not exist"):
        load_deck(deckdir / "none.toml")


def test_array_stiffness_loads_like_coordinate(deckdir):
    """A dense MatrixMarket ``array`` K (column by column) gives the same deck."""
    K = load_deck(write(deckdir, BASE)).K.toarray()
    (deckdir / "K.mtx").write_text("%%MatrixMarket matrix array real general\n5 5\n"
                                   + "".join(f"{x:.17g}\n" for x in K.ravel(order="F")))
    d = load_deck(write(deckdir, BASE))
    assert np.array_equal(d.K.toarray(), K) and d.K.nnz == np.count_nonzero(K)


def test_nonsymmetric_stiffness(deckdir):
    (deckdir / "K.mtx").write_text("%%MatrixMarket matrix coordinate real general\n5 5 6\n"
                                   "1 1 1e6\n2 2 1e6\n3 3 1e6\n4 4 1e6\n5 5 1e6\n1 2 5e5\n")
    with pytest.raises(InputError, match="model.stiffness.*symmetric"):
        load_deck(write(deckdir, BASE))


def test_bladed_disk_engine_order_travelling_wave():
    """The tuned 12-sector disk under engine order 2 answers with a travelling wave, also
    with the friction dampers slipping: every blade tip has the same amplitude and sector
    s lags sector 0 by 2 pi 2 s / 12 (cyclic symmetry; checks the engine-order loads, the
    node-to-node contacts and the solver together)."""
    from frirom.solver import frf
    d = load_deck(ROOT / "cases" / "bladed_disk" / "bladed_disk.toml")
    assert len(d.contacts[0].G.toarray()) == 12
    tips = [d.dof_labels.index(f"s{s}:tip") for s in range(12)]
    r = frf(d.model(), d.excitation(), 2 * np.pi * 800, 2 * np.pi * 860, d.options(),
            outputs=tips)
    assert r.complete, r.message
    assert r.state_fractions[:, 0, 1].max() > 0.2          # the dampers slip
    X1 = r.X[:, :, 1] - 1j * r.X[:, :, 2]                 # (n_pts, 12)
    lag = np.exp(-2j * np.pi * 2 * np.arange(12) / 12)
    err = np.abs(X1 - X1[:, :1] * lag).max() / np.abs(X1).max()
    assert err < 1e-8, err
    assert np.allclose(r.amp_max, r.amp_max[:, :1], rtol=1e-8)


def test_per_element_frames_and_parameters(deckdir):
    text = BASE.replace(
        'elements = [ { a = ["platform:x", "platform:y"], b = "ground" } ]',
        'elements = [ { a = ["platform:x", "platform:y"] },\n'
        '             { a = ["platform:x", "platform:y"], b = "ground", '
        'directions = [[0.0, 2.0]] } ]').replace("mu = 0.5 ", "mu = [0.5, 0.2] ")
    d = load_deck(write(deckdir, text))
    G = d.contacts[0].G.toarray()
    # element 0 in the contact's frame, element 1 in its own (0, 2) made unit length
    assert np.allclose(G, [[COS30, 0.5, 0, 0, 0], [0, 1, 0, 0, 0]], rtol=0, atol=1e-15)
    assert np.array_equal(d.contacts[0].params, [[1e7, 0.5, 100.0], [1e7, 0.2, 100.0]])


# --- issue 29 item 3: every hint names a deck key, deck and Python defaults agree -----

def _with(text, table, lines):
    """BASE with ``lines`` added at the top of its [table]."""
    return text.replace(f"[{table}]\n", f"[{table}]\n" + "".join(f"{x}\n" for x in lines), 1)


def test_solver_advice_names_deck_keys(deckdir):
    """Each setting the corrector failure's advice names (frirom.solver._contact_advice of
    the driver's advice bits: a stalled residual below 1/N^2 and below tol_residual, a
    large ds_min, fewer samples than the default) is a key a deck accepts, in [solver] or
    [continuation], and reaches the solver's options with the advised value."""
    import re

    from frirom import _run
    from frirom.solver import SolverOptions, _contact_advice
    opts = SolverOptions(harmonics=5, samples=16, ds_min=1e-3)
    # every advice the driver can give (frirom_run run_advice's bits), stalled at 1e-9
    advice = _contact_advice(opts, sum(_run.ADVISE.values()), 1.0e-9)
    tips = re.findall(r"(?:try |; or )(\w+) = ([0-9.e+-]+)", advice)
    assert {k for k, _ in tips} == {"tol_stall", "max_iter", "ds_min", "samples"}, advice
    for key, value in tips:
        table = "continuation" if key.startswith("ds") else "solver"
        body = BASE.replace("samples = 64\n", "") if key == "samples" else BASE
        d = load_deck(write(deckdir, _with(body, table, [f"{key} = {value}"])))
        o = d.options()
        name = {"samples": "samples"}.get(key, key)
        assert float(getattr(o, name)) == float(value), (key, value)


def test_history_key_and_aliases(deckdir):
    d = load_deck(write(deckdir, _with(BASE, "solver", ["history = false",
                                                         "tol_stall = 1e-10"])))
    assert d.options().history is False and d.options().tol_stall == 1e-10
    d = load_deck(write(deckdir, _with(BASE, "solver", ["max_iter = 40"])))
    assert d.options().max_iter == 40
    for table, a, b in (("solver", "max_iter = 40", "max_iterations = 30"),
                        ("continuation", "ds_min = 1e-7", "min_step = 1e-6")):
        with pytest.raises(InputError, match=rf"{table}\.{a.split()[0]}: expected either"):
            load_deck(write(deckdir, _with(BASE, table, [a, b])))
    with pytest.raises(InputError, match=r"solver\.tol_stall: expected a number >= 0"):
        load_deck(write(deckdir, _with(BASE, "solver", ["tol_stall = -1.0"])))


# deck key -> SolverOptions attribute, for the defaults docs/deck.md gives
DEFAULTS_DOCUMENTED = {"tol_residual": "tol_residual", "tol_update": "tol_update",
                       "max_iterations": "max_iter", "tol_stall": "tol_stall",
                       "history": "history", "stability": "stability", "step": "ds",
                       "min_step": "ds_min", "max_step": "ds_max",
                       "max_points": "max_points"}


def test_deck_defaults_are_the_solvers_and_documented(deckdir):
    """A deck without the keys gives SolverOptions' own defaults (one place), and
    docs/deck.md's row of each key says that default."""
    import re

    from frirom.solver import SolverOptions
    text = re.sub(r"(?m)^(stability|step|max_step|max_points) = .*\n", "", BASE)
    o, ref = load_deck(write(deckdir, text)).options(), SolverOptions()
    doc = (ROOT / "docs" / "deck.md").read_text()
    for key, name in DEFAULTS_DOCUMENTED.items():
        assert getattr(o, name) == getattr(ref, name), key
        row = re.search(rf"(?m)^\| `{key}`[^|]*\|[^|]*default ([^ |;,]+)", doc)
        assert row, f"docs/deck.md gives no default for {key}"
        want = getattr(ref, name)
        got = row.group(1)
        if isinstance(want, bool):
            assert got == str(want).lower(), key
        else:
            assert float(got) == float(want), key


def test_contact_patch_key(deckdir):
    """[[contacts]] patch (issue 29 item 1): the patch extent reaches the model's group;
    without it none (not checked); a non-positive one is refused by key path."""
    d = load_deck(write(deckdir, _with(BASE, "[contacts]", ["patch = 9e-3"])))
    assert d.model().contacts[0].patch == 9e-3
    assert load_deck(write(deckdir, BASE)).model().contacts[0].patch is None
    with pytest.raises(InputError, match=r"contacts\[0\]\.patch"):
        load_deck(write(deckdir, _with(BASE, "[contacts]", ["patch = -1.0"])))


@pytest.mark.parametrize("form", ["condensed", "banded"])
def test_deck_without_contacts_gives_its_linear_response(deckdir, form):
    """Issue 29 item 5: [[contacts]] is optional in docs/deck.md; a deck without it gave
    "hbm_continue: ny or netot does not match the model" in either formulation. Now it
    solves, and equals the dense linear solve (K - w^2 M + i w C) x = F to 1e-8 (the
    continuation's Newton tolerance) at every point."""
    from frirom.solver import frf
    text = BASE.split("[[contacts]]")[0] + "[solver]" + BASE.split("[solver]")[1]
    text = text.replace('formulation = "condensed"', f'formulation = "{form}"')
    text = text.replace("stability = true", "stability = false")
    d = load_deck(write(deckdir, text))
    model, exc = d.model(), d.excitation()
    assert not model.contacts
    r = frf(model, exc, d.omega_start, d.omega_end, d.options(), outputs=d.outputs)
    assert r.complete and len(r) > 10
    K, M, C = (np.asarray(a.toarray()) for a in (model.K, model.M, model.C))
    for k in range(0, len(r), 5):
        w = r.omega[k]
        x = np.linalg.solve(K - w**2 * M + 1j * w * C, exc.F[:, 1])[d.outputs]
        ref = np.c_[x.real, -x.imag]
        assert np.abs(r.X[k][:, 1:3] - ref).max() <= 1e-8 * np.abs(x).max()
