"""Make the vane-with-hooks case: the sector's CalculiX matrices and its two decks.

    python cases/paper_hooks/make_paper_hooks.py [--size coarse|paper] [--out DIR]
        [--law normal1d|normal2d] [--interlock contact|tied]
    frirom run results/paper_hooks/coarse/rom2.toml      # ROM_II: 40 GSI modes
    frirom run results/paper_hooks/coarse/rom1.toml      # ROM_I: every contact DoF

Writes DIR (default results/paper_hooks/<size>) with the ccx model of
cases/models/hooks.py (job ``hooks``, not committed) and ``rom1.toml`` / ``rom2.toml``
filled from the template hooks.toml: ROM_I keeps every hook (and lug) DoF nonlinear
(Craig-Bampton only), ROM_II reduces them by 20 free + 20 full-stick GSI modes. Both reduce
the cyclic boundary by Tran's interface modes (``boundary_modes``).

The hooks are one contact group of ``--law`` (normal1d, the default: one tangent,
circumferential; normal2d: friction in the face's plane, the paper's law, whose ROM_I
stops before the slipping members' peaks: README). The interlocking lug is, with ``--interlock
contact`` (default), a contact of the same law preloaded by :data:`F_LUG` so that it stays
stuck (normal1d: two groups on the lug's pairs, one per tangent, circumferential and
axial, each with half the normal stiffness and preload; normal2d: one group), or, with
``tied``, the lug's face sharing its nodes with the platform (the rigid limit: the
reference for the contact).
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "models"))
from hooks import make_hooks  # noqa: E402

#: total tangential and normal contact stiffness of the two hooks [N/m], split over the
#: node pairs (so the coarse and the paper-size meshes model the same joint)
KT_TOTAL, KN_TOTAL = 2.0e9, 4.0e9

#: the interlocking lug's contact (8 node pairs on both meshes): stiffness per pair [N/m],
#: stiff against the sector (the tied lug is its rigid limit), friction coefficient, and
#: the total preload [N], high enough that the lug stays stuck over the f0 family
KT_LUG, KN_LUG, MU_LUG, F_LUG = 2.0e11, 2.0e11, 0.3, 3.0e5

LAWS = ("normal1d", "normal2d")
INTERLOCKS = ("contact", "tied")

#: per size: CB modes, Tran boundary modes, harmonics, frequency range [Hz], load [N]
SETTINGS = {
    "coarse": dict(CB=30, TRAN=40, H=1, F0=165.0, F1=195.0, F=5.0),
    "paper": dict(CB=100, TRAN=100, H=1, F0=120.0, F1=145.0, F=5.0),
}
#: damping ratio at the middle of the frequency range (mass-proportional damping)
ZETA = 0.003
GSI = "method = \"gsi\"\nfree = {free}\nstick = {stick}"
#: ROM_II's interlocking lug (a contact), a joint of its own beside the hooks' GSI modes:
#: reduced by its own LUG_STICK full-stick GSI modes ("own", the default; measured on the
#: coarse mesh at 1 000 N: 12 modes equal the physical lug within 2e-5 in peak amplitude,
#: 6 within 3.5e-3, README), kept "physical" (its 8 pairs' 48 DoFs), or "shared": in the
#: span of the hooks' GSI basis (the paper's 40 modes then miss at 1 000 N)
LUG_REDUCTIONS = ("own", "physical", "shared")
LUG_STICK = 12
NONE = "method = \"none\""


def deck_text(rom: str, size: str, n_pairs: int, f0: float, n_gsi: int = 40,
              changes=(), pairs=None, law: str = "normal1d", lug=None,
              f_lug: float = F_LUG, lug_reduction: str = "own") -> str:
    """The deck of ``rom`` ('rom1' or 'rom2') for a mesh of n_pairs hook pairs, hook
    preload f0 [N, the total over all pairs: n0 = f0 / n_pairs], n_gsi GSI modes (half free,
    half stick), contact ``law`` (normal1d or normal2d); pairs: :func:`hook_geometry` of
    the model (the preload's loads; None: no preload loads, the faces pushed apart by n0);
    lug: :func:`hook_geometry` of the lug (LUG_V, LUG_C) for the contact interlocking with
    total preload f_lug [N] (None: the model's lug is tied, no lug contact);
    lug_reduction: ROM_II's lug (:data:`LUG_REDUCTIONS`)."""
    if law not in LAWS:
        raise ValueError(f"law must be one of {LAWS}, got {law!r}")
    if lug_reduction not in LUG_REDUCTIONS:
        raise ValueError(f"lug_reduction must be one of {LUG_REDUCTIONS}, got "
                         f"{lug_reduction!r}")
    s = dict(SETTINGS[size])
    text = (HERE / "hooks.toml").read_text()
    im = NONE if rom == "rom1" else GSI.format(free=n_gsi // 2, stick=n_gsi - n_gsi // 2)
    if rom != "rom1" and lug is not None and lug_reduction != "shared":
        im += ('\nseparate = ["LUG_V", "LUG_C"]     # the lug: a joint of its own'
               + (f"\nseparate_stick = {LUG_STICK}       # its own full-stick modes"
                  if lug_reduction == "own" else ""))
    title = ("ROM_I (every contact DoF)" if rom == "rom1" else
             f"ROM_II ({n_gsi} GSI modes)")
    n0 = f0 / n_pairs
    sets = ["HOOK_V", "HOOK_C"] + (["LUG_V", "LUG_C"] if lug is not None else [])
    preload = preload_loads(pairs, n0) if pairs is not None else ""
    if lug is not None:
        preload += "\n" + preload_loads(lug, f_lug / len(lug[0]))
    s.update(ALPHA=f"{2 * ZETA * 2 * np.pi * (s['F0'] + s['F1']) / 2:.6g}")
    s.update(ROM=title, IM=im, KT=f"{KT_TOTAL / n_pairs:.6g}",
             KN=f"{KN_TOTAL / n_pairs:.6g}", N0=f"{n0:.6g}", LAW=law,
             IFACE="[" + ", ".join(f'"{n}"' for n in sets) + "]",
             LUG=lug_contacts(law, f_lug / len(lug[0])) if lug is not None else "",
             PRELOAD=preload)
    for k, v in s.items():
        text = text.replace(f"@{k}@", str(v))
    for old, new in changes:
        if old not in text:
            raise ValueError(f"hooks.toml has no {old!r}")
        text = text.replace(old, new)
    left = re.search(r"@[A-Z0-9]+@", text)
    if left:
        raise ValueError(f"hooks.toml: placeholder {left.group()} was left unfilled")
    return text


def lug_contacts(law: str, n0: float) -> str:
    """[[contacts]] tables of the interlocking lug, preload n0 per pair [N]: normal2d one
    group; normal1d two groups on the same pairs (tangents circumferential and axial), each
    with half the normal stiffness and preload, so that the stuck lug holds all three
    directions as the tied one does."""
    if law == "normal2d":
        parts = [("lug", "[0.0, 1.0, 0.0]", KN_LUG, n0)]
    else:
        parts = [("lug_t", "[0.0, 1.0, 0.0]", KN_LUG / 2, n0 / 2),
                 ("lug_z", "[0.0, 0.0, 1.0]", KN_LUG / 2, n0 / 2)]
    return "".join(f"""
[[contacts]]                        # the interlocking lug, preloaded to stay stuck
name = "{name}"
law = "{law}"
a = "LUG_V"
b = "LUG_C"
normal = "radial"
tangent = {t}
kt = {KT_LUG:.6g}
kn = {kn:.6g}
mu = {MU_LUG:g}
n0 = {p:.6g}
""" for name, t, kn, p in parts)


def _nset(text: str, name: str) -> np.ndarray:
    block = text.split(f"*NSET, NSET={name}\n", 1)[1].split("*", 1)[0]
    return np.array([int(v) for v in block.replace("\n", ",").split(",") if v.strip()])


def hook_geometry(job: Path, sets=("HOOK_V", "HOOK_C")):
    """The pairs of job.inp's node sets (vane side, casing side; default the hooks): (vane
    nodes (n,), casing nodes (n,), radial unit normals (n, 3)); the two sets list the pairs
    in the same order."""
    text = job.with_suffix(".inp").read_text()
    v, c = _nset(text, sets[0]), _nset(text, sets[1])
    block = text.split("*NODE, NSET=ALL\n", 1)[1].split("*", 1)[0]
    xyz = np.loadtxt(block.splitlines(), delimiter=",")
    pos = xyz[np.searchsorted(xyz[:, 0], v), 1:]
    n = pos * [1.0, 1.0, 0.0]
    return v, c, n / np.linalg.norm(n, axis=1)[:, None]


def hook_pairs(job: Path) -> int:
    """Number of node pairs of the hooks (the HOOK_V set of job.inp)."""
    return len(_nset(job.with_suffix(".inp").read_text(), "HOOK_V"))


def preload_loads(pairs, n0: float) -> str:
    """[[excitation.load]] tables of the hook preload: +n0 n on each vane node, -n0 n on
    its casing node (harmonic 0, x and y components of the radial normal n)."""
    out = []
    for va, ca, n in zip(*pairs):
        for node, sign in ((va, 1.0), (ca, -1.0)):
            for comp, d in ((n[0], "x"), (n[1], "y")):
                if abs(comp) > 1e-14:
                    out.append(f'[[excitation.load]]\ndof = "{node}:{d}"\nharmonic = 0\n'
                               f"amplitude = {sign * n0 * comp:.9g}\n")
    return "\n".join(out)


#: the default hook preload (total over both hooks, N): the case's middle member
F0_DEFAULT = 2000.0


def lug_geometry(job: Path):
    """The lug's pairs (as :func:`hook_geometry`), or None when job.inp's lug is tied."""
    return (hook_geometry(job, ("LUG_V", "LUG_C"))
            if "*NSET, NSET=LUG_V\n" in job.with_suffix(".inp").read_text() else None)


def make(out: Path, size: str = "coarse", f0: float = F0_DEFAULT, law: str = "normal1d",
         interlock: str = "contact") -> Path:
    """Generate the model in ``out`` and write rom1.toml, rom2.toml; returns ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    job = make_hooks(out, size, interlock)
    pairs = hook_geometry(job)
    for rom in ("rom1", "rom2"):
        (out / f"{rom}.toml").write_text(deck_text(rom, size, len(pairs[0]), f0,
                                                   pairs=pairs, law=law,
                                                   lug=lug_geometry(job)))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="coarse", choices=sorted(SETTINGS))
    ap.add_argument("--out", type=Path, default=None,
                    help="folder (default results/paper_hooks/<size>)")
    ap.add_argument("--law", default="normal1d", choices=LAWS,
                    help="contact law of the hooks and the lug (default normal1d)")
    ap.add_argument("--interlock", default="contact", choices=INTERLOCKS,
                    help="the lug: a preloaded contact (default) or tied")
    a = ap.parse_args(argv)
    out = make(a.out or Path("results/paper_hooks") / a.size, a.size, law=a.law,
               interlock=a.interlock)
    print(f"wrote {out}/hooks.* (ccx) and {out}/rom1.toml, {out}/rom2.toml")


if __name__ == "__main__":
    main()
