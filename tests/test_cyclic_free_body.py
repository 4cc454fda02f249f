"""A body held only by its contacts in a cyclic sector (issue 29 item 1): an
under-platform damper that crosses the sector boundary, pressed against its own blade's
platform and the next blade's, with nothing else holding it.

The rotor: N = 4 lumped sectors, each a blade (a tip mass on a spring to a platform mass,
the platform on springs to the ground, in the sector's own tangential/radial frame) and a
damper mass (tangential and radial DoFs, K = 0 on it). Contact "own": the damper against
this sector's platform; contact "next": against the next sector's platform (the columns
of the next sector in G). normal1d contacts, engine-order 1 travelling wave on the tips.

References, without cyclic reduction: the same rotor assembled whole (N blades, N
dampers, 2 N contacts), solved by frirom as a Model (its own free-body route, checked
against closed forms in tests/test_free_bodies.py) and by scipy for the static position.
On main the sector's modes were refused ("harmonic index 0 has a rigid-body (zero
frequency) mode"). Tolerances: the cyclic reduction is exact for a travelling wave and
both routes keep every mode, so the responses agree to Newton's tolerance (1e-7
relative); the static position under the centrifugal load (contacts unloaded, the damper
pressed up by its load alone) to 1e-8 against the stuck structure's linear solve.
"""

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from frirom.model import ContactGroup, Damping, Excitation, Model
from frirom.options import SolverOptions
from frirom.reduction.cyclic import CyclicSector, cyclic_model, sector_free_bodies
from frirom.solver import solve_point

N, EO, H = 4, 1, 3
# sector DoFs: 0 tip, 1 platform x (tangential), 2 platform y (radial), 3 damper x, 4 damper y
NS = 5
MT, MP, MD = 1.0, 0.4, 0.05
KB, KPX, KPY = 1.0e4, 3.0e4, 5.0e4
KT, KN, MU = 2.0e4, 4.0e4, 0.3
ALPHA = 2.0                                       # C = ALPHA M (mass-proportional)


def sector_matrices():
    K = np.zeros((NS, NS))
    K[np.ix_([0, 1], [0, 1])] += KB * np.array([[1, -1], [-1, 1]])
    K[1, 1] += KPX
    K[2, 2] += KPY
    M = np.diag([MT, MP, MP, MD, MD])
    return sp.csr_matrix(K), sp.csr_matrix(M)


def params(n0):
    return np.array([[KT, KN, MU, n0]])


def sector_contacts(n0):
    """own: damper - own platform; next: damper - next sector's platform (columns NS..)."""
    own = np.zeros((2, 2 * NS))
    own[0, 3], own[0, 1] = 1.0, -1.0              # u: tangential slip
    own[1, 4], own[1, 2] = 1.0, -1.0              # v: closure (damper pushed up)
    nxt = np.zeros((2, 2 * NS))
    nxt[0, 3], nxt[0, NS + 1] = 1.0, -1.0
    nxt[1, 4], nxt[1, NS + 2] = 1.0, -1.0
    return [ContactGroup(law="normal1d", G=own, params=params(n0), name="own"),
            ContactGroup(law="normal1d", G=nxt, params=params(n0), name="next")]


def full_model(n0):
    """The whole rotor: sector s's DoFs at s * NS .. ; its 'next' contact reads sector
    (s + 1) mod N."""
    Ks, Ms = sector_matrices()
    n = N * NS
    K = sp.block_diag([Ks] * N).tocsr()
    M = sp.block_diag([Ms] * N).tocsr()
    own, nxt = (np.zeros((2 * N, n)) for _ in range(2))
    for s in range(N):
        a, b = s * NS, ((s + 1) % N) * NS
        own[2 * s, a + 3], own[2 * s, a + 1] = 1.0, -1.0
        own[2 * s + 1, a + 4], own[2 * s + 1, a + 2] = 1.0, -1.0
        nxt[2 * s, a + 3], nxt[2 * s, b + 1] = 1.0, -1.0
        nxt[2 * s + 1, a + 4], nxt[2 * s + 1, b + 2] = 1.0, -1.0
    p = np.repeat(params(n0), N, axis=0)
    g = [ContactGroup(law="normal1d", G=own, params=p, name="own"),
         ContactGroup(law="normal1d", G=nxt, params=p, name="next")]
    return Model(M, K, Damping.rayleigh(ALPHA, 0.0), g)


def sector_model(n0):
    Ks, Ms = sector_matrices()
    empty = np.zeros((0, 3), dtype=np.int64)       # blades coupled by the dampers alone
    cs = CyclicSector(NS, N, empty, empty, np.array([0.0, 0.0, 1.0]), np.zeros(3))
    return cyclic_model(cs, Ks, Ms, sector_contacts(n0), EO, H,
                        damping=Damping.rayleigh(ALPHA, 0.0)), cs


def preload_loads(groups, n):
    """Harmonic-0 loads that balance the contacts' preloads at the assembled position:
    F0 = G^T f(G x = 0), f = (0, n0) per element (normal1d: f_n = max(n0 + kn v, 0))."""
    f0 = np.zeros(n)
    for g in groups:
        f = np.zeros(g.G.shape[0])
        f[1::2] = g.params[:, 3]
        f0 += g.G.T @ f
    return f0


def test_sector_with_a_damper_is_free_and_held_by_its_contacts():
    cm, cs = sector_model(10.0)
    assert cm.free_bodies()
    assert full_model(10.0).free_bodies()
    Ks, Ms = sector_matrices()
    assert not sector_free_bodies(cs, Ks + sp.diags([0, 0, 0, 1.0, 1.0]), Ms,
                                  sector_contacts(10.0), [0, 1, 2])
    # the stuck sector's frequencies at every index equal the stuck whole rotor's
    full = full_model(10.0)
    Kst = (full.K + full.stuck_stiffness()).toarray()
    w_full = np.sqrt(sla.eigh(Kst, full.M.toarray(), eigvals_only=True))
    w_cyc = np.sort(np.concatenate(
        [cm.modes_of(k).omega for k in range(N)]))
    np.testing.assert_allclose(w_cyc, w_full, rtol=1e-10)


@pytest.mark.parametrize("w,n0,f_tip,slip", [(75.0, 50.0, 2.0, 0.0), (60.0, 5.0, 20.0, 0.4),
                                             (90.0, 20.0, 20.0, 0.4), (85.0, 5.0, 20.0, 0.9)])
def test_travelling_wave_response_equals_the_whole_rotor(w, n0, f_tip, slip):
    """Engine order 1 on the tips: the sector's response (cyclic reduction, stuck modes,
    free-body route) equals sector 0 of the whole rotor solved as one Model; from stuck
    all cycle to gross slip on both contacts (the damper's tangential mean then decided
    by the pin on the contacts' means in both). Measured: 4e-15 to 1.1e-10."""
    cm, _ = sector_model(n0)
    F = np.zeros((NS, H + 1), complex)
    f0 = preload_loads(cm.contacts, 2 * NS)
    F[:, 0] = f0[:NS] + f0[NS:]                    # sector 1's share is sector 0's own
    F[0, 1] = f_tip
    full = full_model(n0)
    Ff = np.zeros((N * NS, H + 1), complex)
    Ff[:, 0] = preload_loads(full.contacts, N * NS)
    for s in range(N):                             # sector s lags by 2 pi EO s / N
        Ff[s * NS, 1] = f_tip * np.exp(-2j * np.pi * EO * s / N)
    o = SolverOptions(harmonics=H, formulation="condensed")
    pc = solve_point(cm, Excitation(F), w, o, outputs=np.arange(NS))
    pf = solve_point(full, Excitation(Ff), w, o, outputs=np.arange(NS))
    assert pc.state_fractions[:, 1].min() >= slip
    if slip == 0.0:
        assert np.all(pc.state_fractions[:, 0] == 1.0)
    np.testing.assert_allclose(pc.X, pf.X, atol=1e-8 * np.abs(pf.X).max())
    # what the pin decided is reported as for a Model (frirom show's held lines)
    from frirom.held import held_directions
    from frirom.show import contact_fields
    held = held_directions(cm, contact_fields(cm, pc.X, np.asarray(pc.slider, float),
                                              o.n_samples))
    assert [h.group for h in held] == ["own", "next"]
    assert all(h.tangential.size == (0 if slip == 0.0 else 1) for h in held)


def test_static_position_under_the_centrifugal_load():
    """Contacts unloaded (n0 = 0), the damper pushed up by P: harmonic 0 of the sector's
    solution equals the whole rotor's (frirom, as a Model) and the linear static solve of
    the stuck rotor with the free-body pin on the contacts' means (FREE_PIN Ks added to
    Ks at harmonic 0: it is part of the solved equations; without it the damper's lift
    differs by 0.4 %, as in the two-blade case, tests/test_upd_nonlinear.py)."""
    from frirom.contact import stuck_stiffness
    from frirom.held import FREE_PIN
    P = 30.0
    cm, _ = sector_model(0.0)
    F = np.zeros((NS, 2), complex)
    F[4, 0] = P                                    # up, towards the platforms
    F[0, 1] = 1e-6                                 # a vanishing dynamic load
    p = solve_point(cm, Excitation(F), 60.0, SolverOptions(harmonics=1),
                    outputs=np.arange(NS))
    full = full_model(0.0)
    Ff = np.zeros((N * NS, 2), complex)
    Ff[4::NS, 0] = P
    Ff[0::NS, 1] = 1e-6 * np.exp(-2j * np.pi * EO * np.arange(N) / N)
    pf = solve_point(full, Excitation(Ff), 60.0, SolverOptions(harmonics=1),
                     outputs=np.arange(NS))
    Kp = full.K.copy()
    for g in full.contacts:
        ks = (1.0 + FREE_PIN) * stuck_stiffness(g.law, g.params).ravel()
        Kp = Kp + g.G.T @ sp.diags(ks) @ g.G
    x = sp.linalg.spsolve(sp.csc_matrix(Kp), Ff[:, 0].real)
    assert np.all(p.state_fractions[:, 0] == 1.0)    # closed and stuck
    assert x[4] > 0 and x[2] > 0                     # damper and platforms pushed up
    np.testing.assert_allclose(p.X[:, 0], pf.X[:, 0], rtol=0, atol=1e-10 * x.max())
    np.testing.assert_allclose(p.X[:, 0], x[:NS], rtol=0, atol=1e-8 * x.max())
