"""Mistuned bladed disks: the annulus built from the Craig-Bampton sector against the
cyclic sector solution (tuned, with friction and stuck) and against the full FE rotor with
its blades stiffened (linear, mistuned); deviations from std/seed, lists and files;
Whitehead's bound on a linear Monte Carlo; percentile confidence intervals."""

from __future__ import annotations

import numpy as np
import pytest

from _mistuned import disk
from frirom import InputError, ParameterError, SizeError
from frirom.mistuning import (MistunedDisk, linear_response, monte_carlo, sample_deviations,
                              statistics)
from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.reduction.cyclic import CyclicSector, axis_rotation, cyclic_model
from frirom.reduction.mistuning import (blade_deviations_from_file, deviations,
                                        mistuning_sector, whitehead_bound)
from frirom.solver import SolverOptions, solve_point

N, EO, H = 6, 2, 3
ALPHA, BETA = 2.0, 2e-6
OPTS = dict(harmonics=H, samples=16 * N, tol_residual=1e-11, tol_update=1e-11, max_iter=40)


@pytest.fixture(scope="module")
def built():
    d = disk(N)
    ms = mistuning_sector(d["sector"], d["Ks"], d["Ms"], 12, d["blade"], keep=d["keep"])
    return d, ms


def _cyclic(d, ms, contacts):
    sec = CyclicSector(n_dof=ms.n_reduced, n_sectors=N, left=ms.left, right=ms.right,
                       axis=ms.axis, origin=np.zeros(3))
    return cyclic_model(sec, ms.K, ms.M, contacts, EO, H, damping=Damping.rayleigh(ALPHA, BETA))


def _complex(X, h):
    return X[..., 2 * h - 1] - 1j * X[..., 2 * h]


@pytest.mark.parametrize("mu", [0.3, 1e8])
def test_tuned_annulus_equals_cyclic_sector(built, mu):
    """Zero deviations: every blade tip of the annulus equals the cyclic sector's, shifted
    by the engine-order phase, to 1e-8 relative, friction slipping (mu 0.3) or stuck."""
    d, ms = built
    groups = [ContactGroup(g.law, g.G, np.where(np.array(g.params) == 0.3, mu, g.params),
                           name=g.name) for g in ms.reduce_contacts(d["contacts"])]
    cm = _cyclic(d, ms, groups)
    F = ms.T.T @ d["F"]
    tip_r = list(ms.reduced(d["tip"]))
    ann = ms.model(None, Damping.rayleigh(ALPHA, BETA), groups)
    ex = ms.excitation(F, EO)
    out = [ms.position(p, s) for s in range(N) for p in tip_r]
    w1 = cm.modes_of((-EO) % N).omega[0]
    for w in (0.95 * w1, 1.0 * w1):
        pc = solve_point(cm, Excitation(F), w, SolverOptions(**OPTS), outputs=tip_r)
        pa = solve_point(ann, ex, w, SolverOptions(**OPTS), outputs=out)
        Xa = pa.X.reshape(N, 3, -1)
        scale = np.abs(pc.X).max()
        for s in range(N):
            for h in range(1, H + 1):
                ph = np.exp(-1j * h * EO * s * 2 * np.pi / N)
                err = np.abs(_complex(Xa[s], h) - _complex(pc.X, h) * ph).max() / scale
                assert err < 1e-8, (mu, w, s, h, err)
            assert np.abs(Xa[s][:, 0] - pc.X[:, 0]).max() / scale < 1e-8


def _blade_elements(K, blade, c):
    """A blade-elements matrix for the root term: K's blade rows and columns, and on the
    root (the DoFs they reach) (1 + c) K_rB K_BB^-1 K_Br, so that the blade's condensed
    root stiffness is S = c K_rB K_BB^-1 K_Br."""
    K = sp_csr(K)
    rest = np.setdiff1d(np.arange(K.shape[0]), blade)
    root = rest[np.unique(K[blade][:, rest].nonzero()[1])]
    Kbr = K[blade][:, root].toarray()
    Ke = np.zeros(K.shape)
    Ke[np.ix_(blade, blade)] = K[blade][:, blade].toarray()
    Ke[np.ix_(blade, root)] = Kbr
    Ke[np.ix_(root, blade)] = Kbr.T
    Ke[np.ix_(root, root)] = (1 + c) * Kbr.T @ np.linalg.solve(Ke[np.ix_(blade, blade)], Kbr)
    return Ke, root


@pytest.mark.parametrize("c", [0.0, 0.5])
def test_mistuned_annulus_equals_full_fe_rotor(built, c):
    """Complete Craig-Bampton (every fixed-interface mode) and every clamped-blade mode: the
    mistuned annulus equals the full FE rotor whose blade b gets delta_b C^T K_BB C, the
    clamped blade's stiffness acting on its motion relative to its root (C x = x_B - Psi
    x_root, Psi = -K_BB^-1 K_B,root), plus with c > 0 delta_b times the blade's condensed
    root stiffness S = c K_rB K_BB^-1 K_Br (given to the reduction as the blade elements'
    matrix), assembled in physical DoFs and solved directly (no reduction, no cyclic map),
    to 1e-9."""
    d, _ = built
    Ke = _blade_elements(d["Ks"], d["blade"], c)[0] if c else None
    ms = mistuning_sector(d["sector"], d["Ks"], d["Ms"], None, d["blade"], keep=d["keep"],
                          blade_stiffness=Ke)
    delta = deviations(N, 0.05, seed=3)
    damp = Damping.rayleigh(ALPHA, BETA)
    ann = ms.model(delta, damp, interfaces="free")
    F = ms.T.T @ d["F"]
    ex = ms.excitation(F, EO)
    tip_r = list(ms.reduced(d["tip"]))
    out = [ms.position(p, s) for s in range(N) for p in tip_r]
    # the full rotor, global frame
    K0 = d["K"].tocsr()
    K = K0.toarray()
    for s, nodes in enumerate(d["blade_nodes_full"]):
        dofs = (3 * nodes[:, None] + np.arange(3)).ravel()
        rest = np.setdiff1d(np.arange(K.shape[0]), dofs)
        root = rest[np.unique(K0[dofs][:, rest].nonzero()[1])]
        Kbb = K0[dofs][:, dofs].toarray()
        C = np.hstack([np.eye(dofs.size), np.linalg.solve(Kbb, K0[dofs][:, root].toarray())])
        both = np.concatenate([dofs, root])
        K[np.ix_(both, both)] += delta[s] * (C.T @ Kbb @ C)
        K[np.ix_(root, root)] += delta[s] * c * (C[:, dofs.size:].T @ Kbb @ C[:, dofs.size:])
    full = Model(d["M"], sp_csr(K), damp)
    r = d["r"]
    Q = axis_rotation(2 * np.pi / N)
    f0 = d["F"][d["tip"], 1]
    Ff = np.zeros(K.shape[0], complex)
    outs = []
    for s in range(N):
        tip = 3 * r["tips"][s] + np.arange(3)
        Ff[tip] = np.linalg.matrix_power(Q, s) @ f0 * np.exp(-1j * EO * s * 2 * np.pi / N)
        outs.append(tip)
    w1 = _cyclic(d, ms, ms.reduce_contacts(d["contacts"])).modes_of(N - EO).omega[0]
    for w in (0.9 * w1, w1):
        xa = linear_response(ann, ex.F[:, 1], [w], out)[0].reshape(N, 3)
        xf = linear_response(full, Ff, [w], np.concatenate(outs))[0].reshape(N, 3)
        xf = np.array([np.linalg.matrix_power(Q, s).T @ xf[s] for s in range(N)])
        assert np.abs(xa - xf).max() < 1e-9 * np.abs(xf).max()
        # the mistuning shows: blades differ by more than the tolerance
        assert np.ptp(np.linalg.norm(xf, axis=1)) > 1e-3 * np.abs(xf).max()


def test_blade_stiffness_checked(built):
    """The blade elements' matrix: wrong size, a blade block not the sector's, or stiffness
    on DoFs the blade does not reach: each a clear error."""
    d, _ = built
    Ke, root = _blade_elements(d["Ks"], d["blade"], 0.5)
    args = (d["sector"], d["Ks"], d["Ms"], 4, d["blade"])
    with pytest.raises(SizeError, match="blade_stiffness: shape"):
        mistuning_sector(*args, blade_stiffness=Ke[:-1, :-1])
    bad = Ke.copy()
    bad[d["blade"][0], d["blade"][0]] *= 1.01
    with pytest.raises(InputError, match="blade block differs"):
        mistuning_sector(*args, blade_stiffness=bad)
    far = np.setdiff1d(np.arange(Ke.shape[0]), np.concatenate([d["blade"], root]))[0]
    bad = Ke.copy()
    bad[far, far] = 1.0
    with pytest.raises(InputError, match="no coupling to it"):
        mistuning_sector(*args, blade_stiffness=bad)
    ms = mistuning_sector(*args, blade_stiffness=Ke, keep_root=True)
    assert ms.root_K is not None and np.isin(ms.reduced(root), np.arange(ms.n_reduced)).all()


def test_deviations_inputs(tmp_path):
    a = deviations(24, 0.03, seed=7)
    assert np.array_equal(a, deviations(24, 0.03, seed=7)) and a.shape == (24,)
    assert abs(a.std() - 0.03) < 0.015
    assert np.array_equal(deviations(3, values=[0.0, 0.01, -0.02]), [0.0, 0.01, -0.02])
    with pytest.raises(SizeError, match="2 values for 3 blades"):
        deviations(3, values=[0.0, 0.1])
    with pytest.raises(ParameterError, match="> -1"):
        deviations(2, values=[0.0, -1.5])
    p = tmp_path / "freq.txt"
    p.write_text("# measured first flap [Hz]\n100\n102\n98\n100\n")
    d = blade_deviations_from_file(p, 4)
    assert np.allclose(d, (np.array([100, 102, 98, 100]) / 100.0) ** 2 - 1)
    with pytest.raises(SizeError, match="freq.txt: 4 blade frequencies for 5 blades"):
        blade_deviations_from_file(p, 5)
    assert np.array_equal(sample_deviations(6, 0.02, 1, 4), sample_deviations(6, 0.02, 1, 4))
    assert not np.array_equal(sample_deviations(6, 0.02, 1, 4),
                              sample_deviations(6, 0.02, 1, 5))


def _disk(built, band=None):
    d, ms = built
    tip_r = list(ms.reduced(d["tip"]))
    cm = _cyclic(d, ms, ms.reduce_contacts(d["contacts"]))
    w1 = cm.modes_of(N - EO).omega[0]
    return MistunedDisk(ms, ms.reduce_contacts(d["contacts"]), ms.T.T @ d["F"], EO,
                        tip_r[0], band or (0.85 * w1, 1.15 * w1),
                        Damping.rayleigh(ALPHA, BETA), n_linear=201)


def test_linear_states_on_the_lattice(built):
    """Stuck and free interfaces on the lattice disk: the tuned blades all peak alike, and
    4 % scatter raises the largest blade. Several mode families share this band, so
    Whitehead's one-family bound does not apply here (measured factors up to 2.4 > 1.72);
    it is checked on the one-family disk below."""
    md = _disk(built)
    md.n_linear = 101
    tuned = md.response(None, "stuck")
    assert np.ptp(tuned.blade_peaks) < 1e-6 * tuned.peak
    delta = deviations(N, 0.04, seed=9)
    for state in ("stuck", "free"):      # the modal Woodbury solve = a sparse LU per point
        w = md.band[0] + np.array([0.3, 0.6]) * (md.band[1] - md.band[0])
        ref = linear_response(md.model(delta, state), md.excitation().F[:, 1], w,
                              md.outputs(), modes=False)
        got = md.linear(delta, state).solve(md.excitation().F[:, 1], w, md.outputs())
        assert np.abs(got - ref).max() < 1e-9 * np.abs(ref).max()
    for state in ("stuck", "free"):
        res = monte_carlo(md, 3, 0.04, seed=1, interfaces=state)
        assert res["af"].mean() > 1.0, res["af"]


def test_statistics_confidence_intervals():
    """Order-statistic intervals hold the true percentile of a known distribution in ~95 %
    of repeated studies and shrink like 1/sqrt n."""
    rng = np.random.default_rng(0)
    true90 = 1.0 + 1.2815515655446004       # 90th percentile of N(1, 1)
    hit = 0
    for _ in range(200):
        st = statistics(1.0 + rng.standard_normal(200), percentiles=(90,))
        p = st["percentiles"][0]
        hit += p["low"] <= true90 <= p["high"]
    assert 0.9 <= hit / 200 <= 0.99, hit
    w = []
    for n in (400, 1600):
        p = statistics(1.0 + rng.standard_normal(n), percentiles=(50,))["percentiles"][0]
        w.append(p["high"] - p["low"])
    assert 1.5 < w[0] / w[1] < 2.7, w


def test_single_family_monte_carlo_below_whitehead():
    """The one-DoF-per-blade disk (one mode family; tests/_mistuned.py), 24 blades, 0.1 %
    damping, 30 samples of 2 % blade stiffness scatter with stuck interfaces (linear):
    every amplification factor lies in (1 - 1e-9, (1 + sqrt 24) / 2 = 2.95]; the
    largest blade gains on average (mean 1.066)."""
    from _mistuned import lumped_disk
    n = 24
    d = lumped_disk(n)
    ms = mistuning_sector(d["sector"], d["Ks"], d["Ms"], None, d["blade"], keep=d["tip"])
    sec = CyclicSector(n_dof=ms.n_reduced, n_sectors=n, left=ms.left, right=ms.right,
                       axis=ms.axis, origin=np.zeros(3))
    eo = 3
    Kk, Mk = sec.matrices(sp_csr(ms.K), sp_csr(ms.M), (-eo) % n)
    lam = np.linalg.eigvalsh(np.linalg.solve(np.linalg.cholesky(Mk.toarray()),
                                             np.linalg.solve(np.linalg.cholesky(
                                                 Mk.toarray()), Kk.toarray()).conj().T))
    w = np.sqrt(lam[lam > 0])
    wb = w[np.argmin(np.abs(w - np.sqrt(1e6 / 0.1)))]
    md = MistunedDisk(ms, [], ms.T.T @ d["F"], eo, int(ms.reduced(d["tip"])[0]),
                      (0.9 * wb, 1.1 * wb), Damping.rayleigh(0.0, 2 * 1e-3 / wb),
                      n_linear=401)
    res = monte_carlo(md, 30, 0.02, seed=2, interfaces="stuck")
    af = res["af"]
    assert af.min() > 1 - 1e-9 and af.max() <= whitehead_bound(n), af
    assert af.mean() > 1.03, af.mean()      # measured 1.066


def sp_csr(a):
    import scipy.sparse as sp
    return sp.csr_matrix(a)


def test_mistuning_table(tmp_path):
    from frirom.reduction.mistuning import deviations_from_table
    assert np.array_equal(deviations_from_table({"std": 0.02, "seed": 4}, 8),
                          deviations(8, 0.02, seed=4))
    assert np.array_equal(deviations_from_table({"deviations": [0.01, -0.01]}, 2),
                          [0.01, -0.01])
    (tmp_path / "f.txt").write_text("99\n101\n")
    assert np.allclose(deviations_from_table({"frequencies": "f.txt", "reference": 100.0}, 2,
                                             tmp_path), [0.99**2 - 1, 1.01**2 - 1])
    with pytest.raises(InputError, match="exactly one of"):
        deviations_from_table({"std": 0.1, "deviations": [0, 0]}, 2)
    with pytest.raises(InputError, match=r"unknown key\(s\) \['sed'\]"):
        deviations_from_table({"std": 0.1, "sed": 3}, 2)
    with pytest.raises(InputError, match="seed"):
        deviations_from_table({"std": 0.1, "seed": -1}, 2)


def test_tuned_linear_annulus_equals_cyclic_sector(built):
    """No friction: the annulus with its contacts replaced by their stick stiffness
    (interfaces='stuck', solved linearly through its modes) against the cyclic sector with
    mu = 1e8 under a load 1e-3 times smaller (every contact stuck, none lifts off: the
    sector's solution is linear): first harmonic of every blade tip to 1e-8."""
    d, ms = built
    groups = [ContactGroup(g.law, g.G, np.where(np.array(g.params) == 0.3, 1e8, g.params),
                           name=g.name) for g in ms.reduce_contacts(d["contacts"])]
    cm = _cyclic(d, ms, groups)
    F = 1e-3 * (ms.T.T @ d["F"])
    tip_r = list(ms.reduced(d["tip"]))
    ann = ms.model(None, Damping.rayleigh(ALPHA, BETA), groups, interfaces="stuck")
    ex = ms.excitation(F, EO)
    out = [ms.position(p, s) for s in range(N) for p in tip_r]
    w1 = cm.modes_of((-EO) % N).omega[0]
    for w in (0.95 * w1, 1.1 * w1):
        pc = solve_point(cm, Excitation(F), w, SolverOptions(**OPTS), outputs=tip_r)
        assert np.all(pc.state_fractions[:, 0] == 1.0)          # all stuck
        xa = linear_response(ann, ex.F[:, 1], [w], out)[0].reshape(N, 3)
        for s in range(N):
            ph = np.exp(-1j * EO * s * 2 * np.pi / N)
            err = np.abs(xa[s] - _complex(pc.X, 1) * ph).max() / np.abs(pc.X[:, 1:]).max()
            assert err < 1e-8, (w, s, err)
