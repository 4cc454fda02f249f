"""Decks with [reduction.cyclic]: one sector of a tuned bladed disk (ccx's bladed_sector
model), contacts to ground and to the next sector, the CyclicModel they build, checked
against CalculiX's own *CYCLIC SYMMETRY MODEL frequencies."""

import os
import shutil
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

import bladed_sector  # cases/models/bladed_sector.py
import make_bladed_sector  # cases/bladed_sector/make_bladed_sector.py
from _models import N_SEC, write_cyclic_deck as write
from frirom._errors import InputError
from frirom.deck import load_deck
from frirom.model import CyclicModel
from frirom.reduction.cyclic import axis_rotation

CASES = Path(__file__).resolve().parents[1] / "cases"


@pytest.fixture(scope="module")
def sector_dir(tmp_path_factory):
    """ccx's cyclic eigenvalues (flange face clamped) and two sector.inp runs: 'inner' (only
    the inner edge of the flange face clamped) and 'clamped' (the whole face, as cyclic.inp)."""
    if shutil.which("ccx") is None:
        pytest.skip("ccx (calculix-ccx) not installed")
    out = tmp_path_factory.mktemp("cyclic_deck")
    for sub, clamp in (("inner", "inner"), ("clamped", "flange")):
        cyc, sec = bladed_sector.write_sector_decks(out / sub, N_SEC, n_modes=4,
                                                    sector_clamp=clamp)
        bladed_sector.run_ccx(sec, expect=(".sti", ".mas", ".dof"))
        if sub == "clamped":
            bladed_sector.run_ccx(cyc, expect=(".dat",))
    ref = bladed_sector.read_cyclic_eigenvalues(out / "clamped" / "cyclic.dat")
    return out, ref


def _error(folder, match, **kw):
    with pytest.raises(InputError, match=match) as exc:
        load_deck(write(folder, "bad.toml", **kw))
    assert "bad.toml" in str(exc.value)


def test_cyclic_model_modes_match_ccx(sector_dir, capsys):
    """Whole flange face clamped in sector.inp (LEFT dependent, as in ccx), a contact of
    1 N/m at the rim (the model needs one; the modes are without contacts anyway): the
    CyclicModel's modes of every nodal diameter the harmonics need are ccx's cyclic ones
    (CB error only)."""
    out, ref = sector_dir
    d = load_deck(write(out, "clamped.toml", job="clamped/sector", cache="clamped.rom.h5",
                        contact_set="RIM_R", interface='"RIM_R"', kp="1.0",
                        cyclic_extra='dependent = "left"', h=4))
    m = d.model()
    assert isinstance(m, CyclicModel) and m.n_sectors == N_SEC and m.engine_order == 2
    # EO 2, H = 4: k_h = -2h mod 12 = 0, 10, 8, 6, 4 -> one of k, N - k each: 0, 10, 8, 6
    assert sorted(m.modes) == [0, 6, 8, 10]
    assert any("harmonic indices k = [0, 10, 8, 6]" in line and "nodal diameters 0, 2, 4, 6"
               in line for line in d.log), d.log
    errs = {}
    for k, sm in m.modes.items():
        nd = min(k, N_SEC - k)
        f_ccx = np.sqrt(ref[nd]) / (2 * np.pi)
        f = sm.omega[: f_ccx.size] / (2 * np.pi)
        assert np.all(f >= f_ccx * (1 - 1e-6))        # Rayleigh-Ritz: CB from above
        errs[nd] = np.abs(f / f_ccx - 1).max()
        assert np.allclose(sm.zeta, 0.005)
        # mass-normalised on the sector: psi^H M psi = I over the sector's DoFs
        Mk = sm.psi.conj().T @ d.M @ sm.psi
        assert np.abs(Mk - np.eye(Mk.shape[0])).max() < 1e-8
    with capsys.disabled():
        print("\ncyclic deck (CB 30) vs ccx cyclic, 2 modes per ND, max rel. freq. error: "
              + ", ".join(f"ND {k}: {e:.1e}" for k, e in sorted(errs.items())))
    # CB with 30 fixed-interface modes: ~1e-6 (test_cyclic.py measures the convergence);
    # ccx prints 7 significant digits
    assert max(errs.values()) < 2e-5


def test_stuck_flange_contact_gives_ccx_clamped_frequency(sector_dir, capsys):
    """Inner edge clamped, outer edge on ground contacts of huge stiffness: the stuck
    sector (K + G^T k G projected on ND 2 by the deck's CyclicSector) has ccx's clamped ND-2
    frequency. Checks the ROM, the contacts' G on the dependent boundary and the cyclic
    matching; the penalty error kn/k_structure is measured at two penalties."""
    out, ref = sector_dir
    f_ccx = np.sqrt(ref[2][0]) / (2 * np.pi)
    err = {}
    for kp in (1e12, 1e13):
        d = load_deck(write(out, kp=f"{kp:.1e}"))
        cs, g = d.cyclic["sector"], d.contacts[0].G
        Ks = sp.csr_matrix(d.K) + g.T @ (kp * g)
        kk, mk = cs.matrices(Ks, sp.csr_matrix(d.M), 2)
        lam = sla.eigh(kk.toarray(), mk.toarray(), eigvals_only=True, subset_by_index=[0, 0])
        err[kp] = np.sqrt(lam[0]) / (2 * np.pi) / f_ccx - 1
        # without the contacts the sector is softer (only the inner edge is clamped)
        free = d.cyclic["modes"][10].omega[0] / (2 * np.pi)
        assert free < f_ccx * (1 - 1e-3)
    with capsys.disabled():
        print(f"\nstuck flange (CB 30) vs ccx clamped ND 2 ({f_ccx:.3f} Hz): rel. error "
              + ", ".join(f"k = {k:.0e}: {e:+.1e}" for k, e in err.items()))
    # measured: 1e12 -> ~1e-7 .. 1e-5 (penalty), 1e13 -> < 1e-6 (CB + ccx's 7 digits)
    assert abs(err[1e13]) < 5e-6 and abs(err[1e12]) < 5e-5


def test_neighbour_contact_kinematics(sector_dir):
    """b_sector = 1 between the rim nodes of RIGHT and those of the next sector's LEFT
    (coinciding nodes): a rigid rotation about the axis, the same field in every sector's
    own frame, gives no relative displacement; a translation along x does; and every
    cyclic mode (sector 1 = sector 0 x exp(i k 2 pi / N) in its own frame) gives none."""
    out, _ = sector_dir
    extra = ('\n[[contacts]]\nname = "rim"\nlaw = "normal2d"\na = "RIM_R"\nb = "RIM_L"\n'
             'b_sector = 1\nnormal = "tangential"\nkt = 1.0e8\nkn = 1.0e8\nmu = 0.2\n'
             'n0 = 10.0\n')
    d = load_deck(write(out, "rim.toml", interface='["FLANGE_C", "RIM_R", "RIM_L"]',
                        cache="rim.rom.h5", contact_extra=extra))
    rom, n = d.reduced, d.n_dof
    g = [c for c in d.contacts if c.name == "rim"][0].G
    assert g.shape == (3 * 3, 2 * n)
    Q = axis_rotation(2 * np.pi / N_SEC)
    nodes = np.concatenate([rom.node_sets["RIM_R"], rom.node_sets["RIM_L"]])
    xyz, dofs = rom.coordinates(nodes), rom.node_dofs(nodes)
    assert np.all(dofs >= 0)

    def field(u):
        q = np.zeros(n)
        q[dofs.ravel()] = np.array([u(p) for p in xyz]).ravel()
        return q

    theta = 1e-3
    rot = field(lambda p: theta * np.cross([0.0, 0.0, 1.0], p))
    tr = field(lambda p: np.array([1e-4, 0.0, 0.0]))
    scale = theta * 0.2
    assert np.abs(g @ np.concatenate([rot, rot])).max() < 1e-12 * scale
    rel = g @ np.concatenate([tr, tr])
    expect = np.linalg.norm((np.eye(3) - Q) @ [1e-4, 0, 0])     # |x - Q x|, 2 sin(pi/N)
    # each pair's local (t1, t2, n) relative displacement has the norm of (I - Q) e_x
    assert np.allclose(np.linalg.norm(rel.reshape(-1, 3), axis=1), expect, rtol=1e-12)
    # the wrong sign of the rotation (Q^T) would not cancel the rotation: the check bites
    for k, sm in d.cyclic["modes"].items():
        ph = np.exp(1j * k * 2 * np.pi / N_SEC)
        r = g @ np.vstack([sm.psi, sm.psi * ph])
        assert np.abs(r).max() < 1e-10 * np.abs(sm.psi[dofs.ravel()]).max(), k


def test_cache_and_modes_after_it(sector_dir):
    """The cyclic boundary sets are in the cache's fingerprint; engine order, modes and
    harmonic index are not (the per-ND modes are recomputed from the cached ROM)."""
    out, _ = sector_dir
    p = write(out, "cache.toml", cache="cache.rom.h5")
    d1 = load_deck(p)
    assert "built" in d1.log[0]
    d2 = load_deck(write(out, "cache.toml", cache="cache.rom.h5",
                         cyclic_extra="harmonic_index = 10\nmodes = 12"))
    assert "reused" in d2.log[0]
    assert list(d2.cyclic["modes"]) == [10] and d2.cyclic["modes"][10].omega.size == 12
    assert "one-index approximation" in d2.log[1]
    np.testing.assert_allclose(d2.cyclic["modes"][10].omega,
                               d1.cyclic["modes"][10].omega[:12], rtol=1e-10)
    m = d2.model()
    assert m.single_index == 10 and m.indices(3) == [10, 10, 10, 10]
    # another boundary set: the cache is rebuilt (RIM_R as the right boundary then fails
    # to match LEFT: the message comes from the new sets, not from a stale cache)
    p.write_text(p.read_text().replace('right = "RIGHT"', 'right = "RIM_R"'))
    with pytest.raises(InputError, match=r"reduction\.cyclic\.left/right: .* 19 left and 3 "
                       "right boundary nodes"):
        load_deck(p)
    # Tran's boundary reduction: fewer coordinates, frequencies from above
    d3 = load_deck(write(out, "cache.toml", cache="cache.rom.h5",
                         cyclic_extra="boundary_modes = 20\nmodes = 4"))
    # built again: the cache last held the ROM with RIM_R as a boundary
    assert "built" in d3.log[0] and "Tran: 20 boundary modes" in d3.log[1]
    for k, sm in d3.cyclic["modes"].items():
        exact = d1.cyclic["modes"][k].omega[:4]
        assert np.all(sm.omega >= exact * (1 - 1e-12))
        assert np.abs(sm.omega / exact - 1).max() < 1e-2


def test_deck_errors(sector_dir):
    out, _ = sector_dir
    cases = [
        (dict(sectors=1), r"reduction\.cyclic\.sectors: expected a number >= 2"),
        (dict(cyclic_extra='foo = 1'), r"reduction\.cyclic\.foo: expected one of"),
        (dict(cyclic_extra='dependent = "middle"'), r"reduction\.cyclic\.dependent"),
        (dict(cyclic_extra='harmonic_index = 12'), r"reduction\.cyclic\.harmonic_index: "
         r"expected \"per_harmonic\" or an integer nodal diameter k\* in 0\.\.11"),
        (dict(cyclic_extra='harmonic_index = "all"'), r"reduction\.cyclic\.harmonic_index"),
        (dict(cyclic_extra='harmonic_index = true'), r"reduction\.cyclic\.harmonic_index"),
        (dict(cyclic_extra='modes = 0'), r"reduction\.cyclic\.modes: expected a number >= 1"),
        (dict(cyclic_extra='modes = 100000'), r"reduction\.cyclic\.modes: sector_modes"),
        (dict(cyclic_extra='boundary_modes = 100000'), r"reduction\.cyclic\.boundary_modes"),
        (dict(sectors=11), r"reduction\.cyclic\.left/right: cyclic_sector: left-boundary "
         r"node \d+ rotated by 32\.7273 deg"),
        (dict(contact_extra='b_sector = 2'), r"contacts\[0\]\.b_sector: expected 0 .* or 1"),
        (dict(contact_extra='b_sector = 1'), r"contacts\[0\]\.b: expected a node set of the "
         "next sector"),
        (dict(contact_set="FLANGE_OUT", interface='"FLANGE_OUT"'),
         r"contacts\[0\]: node \d+ \(left boundary\) and node \d+ \(its image"),
        (dict(solver_extra="stability = true"), r"solver\.stability: expected false with "
         r"\[reduction\.cyclic\] \(Hill stability is not implemented"),
        (dict(solver_extra='formulation = "banded"'), r"solver\.formulation: expected "
         "'condensed'"),
        (dict(excitation_extra='[[excitation.engine_order]]\neo = 2\ndofs = ["TIP:z"]\n'
              'n_sectors = 12\namplitude = 1.0'), r"excitation\.engine_order: expected no"),
        (dict(reduction_extra='[reduction.interface_modes]\nmethod = "ms"\nsectors = 12\n'
              'engine_orders = [2]'), r"reduction\.interface_modes\.method: expected 'none' "
         "or 'gsi' with"),
        (dict(interface='"FLANGE_OUT"', contact_set="FLANGE_C",
              reduction_extra='[reduction.interface_modes]\nmethod = "gsi"\nfree = 4'),
         r"reduction\.interface: node set FLANGE_OUT shares node\(s\)"),
    ]
    for kw, match in cases:
        _error(out, match, **kw)
    # unknown node sets and the missing engine order
    p = write(out, "bad.toml")
    text = p.read_text()
    for old, new, match in (
            ('left = "LEFT"', 'left = "NOPE"', r"reduction\.cyclic\.left: expected a node "
             "set of the model, got 'NOPE'"),
            ('right = "RIGHT"', 'right = "LEFT"', r"reduction\.cyclic\.right: expected a node "
             "set other than"),
            ("engine_order = 2\n", "", r"reduction\.cyclic\.engine_order: expected a number "
             r"\(missing\)"),
            ("[[contacts]]", "[[contactz]]", r"bad\.toml: contactz: expected one of")):
        p.write_text(text.replace(old, new))
        with pytest.raises(InputError, match=match):
            load_deck(p)
    # b_sector without [reduction.cyclic]
    head, tail = text.split("[reduction.cyclic]")
    p.write_text(head + "[[contacts]]" + tail.split("[[contacts]]", 1)[1]
                 .replace("n0 = 1.0e6", "n0 = 1.0e6\nb = \"FLANGE_C\"\nb_sector = 1"))
    with pytest.raises(InputError, match=r"contacts\[0\]\.b_sector: expected 0 without "
                       r"\[reduction\.cyclic\]"):
        load_deck(p)
    # a next-sector set that does not match
    extra = ('\n[[contacts]]\nname = "rim"\nlaw = "jenkins"\na = "RIM_R"\nb = "RIM_R"\n'
             'b_sector = 1\nnormal = "tangential"\nkt = 1.0e8\nmu = 0.2\nfn0 = 10.0\n')
    _error(out, r"contacts\[1\]: node \d+ of set RIM_R has no node of set RIM_R \(in the "
           "next sector\\)", interface='["FLANGE_C", "RIM_R"]', contact_extra=extra)


@pytest.mark.slow
def test_stuck_flange_frf_resonance_at_ccx_frequency(tmp_path, capsys):
    """End to end on the case cases/bladed_sector (its make script, its deck): the deck's
    CyclicModel through the solver (frirom.solver.frf). With kt = kn = 1e13 N/m and
    mu n0 far above the transmitted forces the flange contacts stick all cycle, so the AFT
    is exactly linear: the FRF under EO 2 (harmonic 1 on k = 10, ND 2) equals a direct solve
    of the projected stuck sector with the same modal damping, and its resonance peak is
    ccx's clamped cyclic ND-2 frequency (only the bolt node is clamped in the sector; the
    case's normal1d becomes normal2d so that the stuck contacts hold all three directions)."""
    if shutil.which("ccx") is None:
        pytest.skip("ccx (calculix-ccx) not installed")
    from frirom.solver import frf
    make_bladed_sector.make(tmp_path, N_SEC)
    ref = bladed_sector.read_cyclic_eigenvalues(tmp_path / "cyclic.dat")
    zeta, kp = 0.002, 1.0e13
    text = (CASES / "bladed_sector" / "bladed_sector.toml").read_text()
    # normal2d: both tangential directions stuck (normal1d leaves the radial one free)
    for old, new in (('law = "normal1d"', 'law = "normal2d"'), ("kt = 1.0e9", f"kt = {kp}"), ("kn = 1.0e9", f"kn = {kp}"),
                     ("mu = 0.3", "mu = 1000.0"), ("n0 = 5000.0", "n0 = 1.0e6"),
                     ("amplitude = -5000.0", "amplitude = -1.0e6"),
                     ("start = 640.0", "start = 655.0"), ("end = 665.0", "end = 668.0"),
                     ("max_step = 0.1", "max_step = 0.01"), ("zeta = 0.002", f"zeta = {zeta}")):
        assert text.count("\n" + old) == 1, old           # keys, not the comments
        text = text.replace("\n" + old, "\n" + new)
    p = tmp_path / "stuck.toml"
    p.write_text(text)
    d = load_deck(p)
    m = d.model()
    r = frf(m, d.excitation(), d.omega_start, d.omega_end, d.options(), outputs=d.outputs)
    assert r.complete and np.all(r.state_fractions[:, 0, 0] == 1.0)       # stuck all cycle
    X = r.X[:, 0, :]
    c1 = X[:, 1] - 1j * X[:, 2]                 # harmonic 1: Re(c1 exp(i omega t))
    # direct solve: (K_k + Kc_k + i w C_k - w^2 M_k) y = T(k)^H f0, k = -EO mod N = 10,
    # C_k = M_k Phi diag(2 zeta w_r) Phi^H M_k from the free modes (what the model's
    # modal damping means); the static preload and its balancing load cancel
    cs, g = d.cyclic["sector"], d.contacts[0].G
    T = cs.projection(10)
    Kk = (T.conj().T @ (sp.csr_matrix(d.K) + g.T @ (kp * g)) @ T).toarray()
    Mk = (T.conj().T @ sp.csr_matrix(d.M) @ T).toarray()
    K0 = (T.conj().T @ sp.csr_matrix(d.K) @ T).toarray()
    lam, phi = sla.eigh(K0, Mk)
    Ck = Mk @ phi @ np.diag(2 * zeta * np.sqrt(lam)) @ phi.conj().T @ Mk
    fk = T.conj().T @ d.F[:, 1]
    direct = np.array([(T @ np.linalg.solve(Kk + 1j * w * Ck - w**2 * Mk, fk))[d.outputs[0]]
                       for w in r.omega])
    err_frf = np.abs(c1 - direct).max() / np.abs(direct).max()
    assert np.abs(X[:, 0]).max() < 1e-12 * np.abs(direct).max()         # no static motion
    # resonance: parabola of 1/|x|^2 in w^2 through the three highest points (exact for a
    # single mode); the damped peak lies at w_r sqrt(1 - 2 zeta^2), corrected here
    i = int(np.argmax(np.abs(c1)))
    cf = np.polyfit(r.omega[i - 1:i + 2] ** 2, 1.0 / np.abs(c1[i - 1:i + 2]) ** 2, 2)
    w_peak = np.sqrt(-cf[1] / (2 * cf[0])) / np.sqrt(1 - 2 * zeta**2)
    w_ccx = np.sqrt(ref[2][0])
    err = w_peak / w_ccx - 1
    with capsys.disabled():
        print(f"\nstuck flange FRF ({r.omega.size} points): vs direct solve {err_frf:.1e}; "
              f"resonance {w_peak / (2 * np.pi):.4f} Hz vs ccx ND 2 "
              f"{w_ccx / (2 * np.pi):.4f} Hz: {err:+.1e}")
    # solver tolerances (default Newton, 1e-13 .. 1e-9 measured)
    assert err_frf < 1e-7
    # CB + penalty: ~6e-7 (test above, and here); peak fit and the stuck mode's damping
    # differing from zeta (the free modes') by some %: ~1e-6; ccx's 7 digits
    assert abs(err) < 1e-5
    # the same deck through `frirom run`: the cyclic log lines, the same points in frf.h5
    from frirom.cli import main
    from frirom.results import FRF
    assert main(["run", str(p), "--out", str(tmp_path / "run")]) == 0
    printed = capsys.readouterr().out
    assert "cyclic sector: N = 12, harmonic indices k = [0, 10, 8, 6]" in printed
    saved = FRF.load(tmp_path / "run" / "frf.h5")
    assert saved.omega.size == r.omega.size
    assert np.abs(saved.X - r.X).max() < 1e-12 * np.abs(r.X).max()


def test_gsi_interface_with_contacts_on_the_boundary(sector_dir, capsys):
    """GSI modes on an interface set without cyclic-boundary nodes (FLANGE_CI); the contact
    set FLANGE_C also holds a node of RIGHT, a physical coordinate of the reduced model. The
    stuck sector's ND-2 frequency with GSI modes lies above the Craig-Bampton model's (a
    Rayleigh-Ritz subspace of it), equals it once the 15 modes span the 15 interface DoFs,
    and is ccx's clamped one to the CB + penalty error."""
    out, ref = sector_dir
    f_ccx = np.sqrt(ref[2][0]) / (2 * np.pi)

    def stuck_nd2(d, kt):
        cs, g = d.cyclic["sector"], d.contacts[0].G
        kk, mk = cs.matrices(sp.csr_matrix(d.K) + g.T @ (kt * g), sp.csr_matrix(d.M), 2)
        lam = sla.eigh(kk.toarray(), mk.toarray(), eigvals_only=True, subset_by_index=[0, 0])
        return np.sqrt(lam[0]) / (2 * np.pi)

    d_cb = load_deck(write(out, "cbonly.toml", interface='"FLANGE_CI"', cache="cbonly.rom.h5"))
    f_cb, f_clamp = stuck_nd2(d_cb, 1e11), stuck_nd2(d_cb, 1e13)
    errs = []
    for n_free in (3, 6, 15):
        d = load_deck(write(out, "gsi.toml", interface='"FLANGE_CI"', cache="gsi.rom.h5",
                            reduction_extra=("[reduction.interface_modes]\nmethod = \"gsi\"\n"
                                             f"free = {n_free}")))
        labels = d.reduced.labels
        assert sum(lab.startswith("gsi") for lab in labels) == n_free
        assert not any(f"N{nd}:" in lab for nd in d.reduced.node_sets["FLANGE_CI"]
                       for lab in labels)                        # reduced by GSI
        errs.append(stuck_nd2(d, 1e11) / f_cb - 1)
    with capsys.disabled():
        print(f"\nstuck ND 2 (1e13 N/m): CB {f_clamp / f_ccx - 1:+.1e} vs ccx; with 1e11 N/m "
              "GSI (free modes 3, 6, 15) vs CB: " + ", ".join(f"{e:+.1e}" for e in errs))
    # GSI vs CB with 1e11 N/m contacts: the eigen-solve is good to ~1e-10 there (1e13 N/m
    # leaves ~6e-8 of round-off, more than the GSI error on this small interface); measured
    # +1.7e-6 with 3 modes, 2.5e-10 with the 15 that span the interface
    assert all(e > -1e-9 for e in errs) and errs[0] >= errs[1] >= errs[2]
    assert errs[0] > 1e-7 and abs(errs[2]) < 1e-9
    # stuck by 1e13 N/m, the flange is ccx's clamped one to the CB + penalty error (~6e-7)
    assert abs(f_clamp / f_ccx - 1) < 2e-6
    # full-stick GSI modes need every contact node in the interface sets
    _error(out, r"contacts\[0\]: node \d+ is a cyclic-boundary node outside the interface "
           "sets", interface='"FLANGE_CI"', cache="gsi.rom.h5",
           reduction_extra='[reduction.interface_modes]\nmethod = "gsi"\nstick = 3')
    # a load on both images of a boundary node
    _error(out, r"excitation\.load\[1\]\.dof: expected a node set holding each node of the "
           r"rotor once; node \d+ \(left", excitation_extra=(
               '\n[[excitation.load]]\ndof = "FLANGE_OUT:z"\nharmonic = 0\namplitude = 1.0\n'))
