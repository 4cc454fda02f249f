"""Build the Brake-Reuss beam case next to its decks: gmsh mesh, CalculiX matrices, the
bolts' preload by a static contact solve, the contact groups, CalculiX's own
eigenfrequencies (stuck.dat, free.dat); nothing committed but the decks' generated block.

    python cases/brb/build_brb.py                  # coarse mesh (~1 min)
    python cases/brb/build_brb.py --size fine      # fine mesh (slower)
    python cases/brb/run_brb.py                    # build if needed, then the backbone
    frirom modes cases/brb/brb.toml                # linear check: free and stuck limits
    frirom run cases/brb/brb_mode.toml             # the first bending mode's backbone

The model: cases/models/brb.py; the preload and the contact parameters:
cases/models/brb_preload.py. The static solve gives every interface pair its normal
preload n0; the loaded pairs are grouped by n0 into the node sets LAP1_A/B .. LAPn_A/B
(appended to brb.inp) and one [[contacts]] + [[preload]] table per group, which this
script writes between the markers of brb.toml and brb_mode.toml (the block changes only
when the mesh does). preload.csv lists every pair: x, y, n0, group.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "models"))
import brb  # noqa: E402
import brb_preload as bp  # noqa: E402
from ccx import run_ccx  # noqa: E402

DECKS = ("brb.toml", "brb_cb.toml", "brb_mode.toml", "brb_cb_mode.toml", "brb_cd_mode.toml")
BEGIN = "# >>> contact groups: written by cases/brb/build_brb.py, do not edit"
END = "# <<< contact groups"


def deck_block(params, mu=bp.MU) -> str:
    """The [[contacts]] and [[preload]] tables of the groups (n0, kt, kn per group) and
    the sizes of the groups (for the loads)."""
    lines = [BEGIN]
    for g, (n0, kt, kn, size) in enumerate(params, 1):
        lines += ["[[contacts]]", f'name = "lap{g}"', 'law = "normal2d"',
                  f'a = "LAP{g}_A"', f'b = "LAP{g}_B"', "normal = [0.0, 0.0, 1.0]",
                  f"kt = {kt:.6e}", f"kn = {kn:.6e}", f"mu = {mu}", "",
                  "[[preload]]", f"load = {n0 * size:.6f}            "
                  f"# {size} pairs x n0 = {n0:.4f} N", "direction = [0.0, 0.0, 1.0]",
                  f'contacts = ["lap{g}"]', ""]
    lines.append(END)
    return "\n".join(lines)


def write_block(deck: Path, block: str) -> bool:
    """Replace the generated block of a deck; True if it changed."""
    text = deck.read_text()
    if BEGIN not in text or END not in text:
        raise ValueError(f"{deck}: no generated block ({BEGIN!r} .. {END!r})")
    i, j = text.index(BEGIN), text.index(END) + len(END)
    new = text[:i] + block + text[j:]
    if new != text:
        deck.write_text(new)
    return new != text


def make(out=HERE, size: str = "coarse", references: bool = True,
         decks=DECKS, deck_dir=HERE, log=print) -> Path:
    """Mesh, matrices, preload, groups, references; returns the job path (out/brb)."""
    from frirom.io import read_calculix
    if size not in brb.SIZES:
        raise ValueError(f"build_brb: size {size!r}: expected one of {sorted(brb.SIZES)}")
    out = Path(out)
    h = brb.SIZES[size]
    mesh = brb.brb_mesh(h)
    job = run_ccx(brb.write_brb_deck(out / "brb.inp", h, mesh=mesh),
                  expect=(".sti", ".mas", ".dof"))
    fe = read_calculix(job)
    ids, coords, elems, sets = mesh
    row = {int(i): k for k, i in enumerate(ids)}
    shanks = brb.bolt_springs(sets, lambda nodes: coords[[row[int(n)] for n in nodes]])
    n0, info = bp.static_preload(fe, brb.bolt_centres(), bolts=shanks)
    if abs(info["total"] - 3 * bp.BOLT_LOAD) > 1e-6 * bp.BOLT_LOAD:
        raise RuntimeError(f"build_brb: the interface carries {info['total']:.6g} N of the "
                           f"bolts' {3 * bp.BOLT_LOAD:.6g} N")
    log(f"build_brb: static preload {info['total']:.1f} N over {info['closed']} of "
        f"{info['pairs']} pairs in contact ({info['iterations']} active-set iterations)")
    a, b, xyz = bp.pair_nodes(fe)
    groups = bp.contact_groups(n0)
    params = [p + (g.size,) for p, g in zip(bp.group_parameters(n0, groups), groups)]
    sets = dict(sets)
    group_of = np.zeros(a.size, int)
    for k, g in enumerate(groups, 1):
        sets[f"LAP{k}_A"], sets[f"LAP{k}_B"] = a[g], b[g]
        group_of[g] = k
    mesh = (ids, coords, elems, sets)
    brb.write_brb_deck(out / "brb.inp", h, mesh=mesh)       # the same deck, + group sets
    np.savetxt(out / "preload.csv", np.column_stack([xyz[:, 0], xyz[:, 1], n0, group_of]),
               delimiter=",", header="x [m], y [m], n0 [N], group (0: open)",
               fmt=["%.6e", "%.6e", "%.6e", "%d"])
    block = deck_block(params)
    for d in decks:
        if write_block(Path(deck_dir) / d, block):
            log(f"build_brb: {d}: contact groups rewritten (the mesh or the joint's "
                "parameters changed)")
    if references:
        joined = [(a[g], b[g], kt, kn) for g, (_, kt, kn, _) in zip(groups, params)]
        run_ccx(brb.write_brb_deck(out / "stuck.inp", h, joined=joined, mesh=mesh,
                                   n_ref_modes=16, storage=False), expect=(".dat",))
        run_ccx(brb.write_brb_deck(out / "free.inp", h, mesh=mesh, n_ref_modes=16,
                                   storage=False), expect=(".dat",))
    return job


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="coarse", choices=sorted(brb.SIZES))
    ap.add_argument("--out", type=Path, default=HERE, help="folder (default: this one)")
    ap.add_argument("--no-references", action="store_true",
                    help="only the matrices, not stuck.dat / free.dat")
    a = ap.parse_args(argv)
    job = make(a.out, a.size, not a.no_references)
    print(f"wrote {job}.inp/.sti/.mas/.dof, preload.csv"
          + ("" if a.no_references else ", stuck.dat, free.dat"))


if __name__ == "__main__":
    main()
