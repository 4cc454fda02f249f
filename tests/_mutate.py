"""Mutations of decks and matrix files for the fuzzers (tests/test_fuzz.py and
cases/bench/fuzz.py): a hostile but fair user's edits, drawn from a ``random.Random``
(hypothesis's ``st.randoms()`` in the tests, a seeded one in the benchmark).

:func:`try_input` runs frirom on one mutated input and sorts the outcome: accepted, a
frirom error (the wanted refusal), or a crash (any other exception: a raw traceback).
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: Values a user might type in place of a deck value (TOML text).
VALUES = ["-1", "0", "1", "-0.0", "1e300", "-1e300", "1e-300", "nan", "inf", "-inf", "64.5",
          "1000000000000000000000000000000", "2147483647", "3000000000", "-2147483649",
          '"abc"', '""', "true", "[]", "[1.7]", "[-1]", "{}", "[[1, 2]]", '"tip:x"',
          '"ground"', '"s0:tip"', '["tip:x", 1]', "500", "1e8", '"\u00e9"', "[0.0, 0.0, 0.0]",
          "[1.0, 0.0]", "[[0.0, 0.0]]", '"ACTIVE:z"', '"CONTACT_A"', "12", "0.5",
          "1" + "0" * 400, "[1" + "0" * 400 + ", 0.0]", '"cubic"', '"normal2d"']
#: Bytes a damaged or mis-encoded file holds.
BYTES = [b"\xff", b"\xe9", b"\x00", b"\xc3(", b"\r", b"\n", b"\t", b"[", b"]", b"=", b'"',
         b"#", b"{", b"}", b",", b".", b"-", b"e", b"9" * 12]
_KEY = re.compile(r"^(\s*)([A-Za-z0-9_\"\.-]+)(\s*=\s*)(.*)$")


def mutate_deck(text: str, rnd) -> bytes:
    """1 to 3 edits of a TOML deck: delete a line or a table, change a value or a key,
    duplicate a line, insert bytes, truncate."""
    lines = text.splitlines()
    for _ in range(rnd.randint(1, 3)):
        if not lines:
            break
        op = rnd.randrange(8)
        i = rnd.randrange(len(lines))
        m = _KEY.match(lines[i])
        if op == 0:                                   # delete a line
            del lines[i]
        elif op == 1:                                 # delete a table (header to next one)
            heads = [j for j, s in enumerate(lines) if s.lstrip().startswith("[")]
            if heads:
                h = rnd.choice(heads)
                nxt = [j for j in heads if j > h]
                del lines[h:nxt[0] if nxt else len(lines)]
        elif op in (2, 3) and m:                      # another value
            lines[i] = m.group(1) + m.group(2) + m.group(3) + rnd.choice(VALUES)
        elif op == 4 and m:                           # another key (a known one or a typo)
            keys = [k.group(2) for k in map(_KEY.match, lines) if k]
            new = rnd.choice(keys + [m.group(2) + "s", m.group(2)[:-1] or "x"])
            lines[i] = m.group(1) + new + m.group(3) + m.group(4)
        elif op == 5:                                 # duplicate a line
            lines.insert(i, lines[i])
        elif op == 6 and m:                           # scale a number
            try:
                v = float(m.group(4).split("#")[0])
            except ValueError:
                continue
            f = rnd.choice([-1.0, 0.0, 1e-9, 1e6, 1e300, 0.5])
            lines[i] = m.group(1) + m.group(2) + m.group(3) + repr(v * f)
        else:                                         # truncate the deck here
            lines = lines[:i] + [lines[i][:rnd.randrange(len(lines[i]) + 1)]]
    data = ("\n".join(lines) + "\n").encode()
    if rnd.random() < 0.15:                           # raw bytes somewhere
        k = rnd.randrange(len(data) + 1)
        data = data[:k] + rnd.choice(BYTES) + data[k:]
    return data


def mutate_bytes(data: bytes, rnd) -> bytes:
    """1 to 4 byte-level edits of a text file: insert, delete, replace, truncate."""
    data = bytearray(data)
    for _ in range(rnd.randint(1, 4)):
        k = rnd.randrange(len(data) + 1)
        op = rnd.randrange(4)
        if op == 0:
            data[k:k] = rnd.choice(BYTES)
        elif op == 1 and data:
            del data[k:k + rnd.randint(1, 8)]
        elif op == 2 and data:
            data[k:k + 1] = rnd.choice(BYTES)
        else:
            del data[k:]
    return bytes(data)


#: Readers and one valid input each: (name, {file: bytes}, function of the folder).
def reader_cases():
    import frirom.io as fio
    mtx = (b"%%MatrixMarket matrix coordinate real symmetric\n% K\n3 3 5\n1 1 2.0\n"
           b"2 1 -1.0\n2 2 2.0\n3 2 -1.0\n3 3 1.0\n")
    dof = b"1.1\n1.2\n2.1\n"
    sti = b"1 1 2.0\n1 2 -1.0\n2 2 2.0\n2 3 -1.0\n3 3 1.0\n"
    mas = b"1 1 1.0\n2 2 1.0\n3 3 1.0\n"
    inp = b"*NODE\n1, 0.0, 0.0, 0.0\n2, 1.0, 0.0, 0.0\n*NSET, NSET=A\n1, 2\n"
    mapping = b" Matrix Eqn   Node       DOF\n1 1 UX\n2 1 UY\n3 2 UX\n"
    abq = b"1,1, 1,1, 2.0\n1,2, 1,1, -1.0\n1,2, 1,2, 2.0\n"
    table = b"1 1\n1 2\n2 1\n"
    return [
        ("mtx", {"a.mtx": mtx}, lambda d: fio.read_mtx(d / "a.mtx")),
        ("mtx-model", {"k.mtx": mtx, "m.mtx": mtx, "d.txt": table},
         lambda d: fio.read_matrix_market(d / "k.mtx", d / "m.mtx", d / "d.txt")),
        ("calculix", {"j.dof": dof, "j.sti": sti, "j.mas": mas, "j.inp": inp},
         lambda d: fio.read_calculix(d / "j")),
        ("ansys-mapping", {"k.mapping": mapping},
         lambda d: fio.read_ansys_mapping(d / "k.mapping")),
        ("abaqus", {"s.mtx": abq}, lambda d: fio.read_abaqus(d / "s.mtx")),
        ("dof-table", {"d.txt": table}, lambda d: fio.read_dof_table(d / "d.txt")),
    ]


def try_input(run):
    """Run ``run()``: 'ok', 'error' (a frirom error: a named refusal) or 'crash' (any other
    exception), and the exception."""
    from frirom import FriromError
    try:
        run()
    except FriromError as exc:
        return "error", exc
    except Exception as exc:      # noqa: BLE001 - what the fuzzer looks for
        return "crash", exc
    return "ok", None


def load_and_check(path):
    """What ``frirom run`` does with a deck before the sweep: load it, build the solver's
    objects and check its options."""
    from frirom.deck import load_deck
    d = load_deck(path)
    d.model()
    d.excitation()
    d.options().check()
    return d


# ---- issue 25: study decks and results files ---------------------------------------------
#: A [study] table appended to a bundled deck before it is mutated (its scheduler, counts
#: and key paths are what the mutations hit).
STUDY_TABLE = """
[study]
kind = "family"
combine = "product"
scheduler = "serial"
workers = 2
output = 0
[study.parameters]
"contacts[0].mu" = [0.3, 0.5]
"excitation.load[0].amplitude" = [1.0, 2.0]
"""


def study_check(path):
    """What ``frirom study`` does before any member runs: read the study and its members'
    decks, choose the scheduler (a deck's address is refused, never connected to)."""
    import os
    from frirom.study import check_workers, choose_scheduler, load_study
    os.environ.pop("FRIROM_SCHEDULER", None)
    s = load_study(path)
    choose_scheduler(s.settings, None, path=path)
    check_workers(s.settings.workers)
    return s


def _junk(rnd, shape):
    import numpy as np
    kind = rnd.randrange(8)
    if kind == 0:
        return np.full(shape, np.nan)
    if kind == 1:
        return np.array([b"text"] * max(int(np.prod(shape)), 1))
    if kind == 2:
        return np.zeros(shape[:1] + tuple(s + 1 for s in shape[1:]))
    if kind == 3:
        return np.full(shape, np.inf)
    if kind == 4:
        return np.zeros(())
    if kind == 5:
        return np.zeros(shape, dtype=np.int8) - 1
    if kind == 6:
        return np.zeros((0,) + tuple(shape[1:]))
    return np.ones(shape)


def mutate_results(src: Path, dst: Path, rnd) -> str:
    """Copy the results file ``src`` to ``dst`` and make 1-3 hostile edits with h5py: a
    dataset replaced by junk (NaN, text, other shapes, overflow, empty) or deleted, an
    attribute given another type or bad JSON, an external or soft link, deep nesting, a
    value changed (the checksum kept or removed). Returns what was done."""
    import shutil
    import h5py
    import numpy as np
    shutil.copyfile(src, dst)
    done = []
    with h5py.File(dst, "a") as f:
        for _ in range(rnd.randint(1, 3)):
            names = sorted(k for k in f if isinstance(f.get(k, getlink=True), h5py.HardLink)
                           and isinstance(f[k], h5py.Dataset))
            attrs = sorted(f.attrs)
            op = rnd.randrange(9)
            if op == 0 and names:
                n = rnd.choice(names)
                shape = f[n].shape
                del f[n]
                f[n] = _junk(rnd, shape)
                done.append(f"dataset {n} junk")
            elif op == 1 and names:
                n = rnd.choice(names)
                del f[n]
                done.append(f"dataset {n} deleted")
            elif op == 2 and attrs:
                a = rnd.choice(attrs)
                f.attrs[a] = rnd.choice([np.nan, "{bad json", 3, np.arange(4), b"\xff\xfe",
                                         "", np.array([1.5, np.inf])])
                done.append(f"attribute {a} retyped")
            elif op == 3 and f.get(f"ext{len(done)}", getlink=True) is None:
                f[f"ext{len(done)}"] = h5py.ExternalLink("/etc/hostname", "/")
                done.append("external link")
            elif op == 4 and names and f.get(f"soft{len(done)}", getlink=True) is None:
                f[f"soft{len(done)}"] = h5py.SoftLink("/" + rnd.choice(names))
                done.append("soft link")
            elif op == 5:
                g = f
                for i in range(rnd.randint(2, 60)):
                    g = g.require_group(f"n{i}")
                done.append("nesting")
            elif op == 6 and names:
                n = rnd.choice(names)
                d = f[n]
                if d.dtype.kind == "f" and d.size:
                    a = d[()]
                    a.flat[rnd.randrange(a.size)] = rnd.choice([np.nan, -1.0, 1e300, 0.0])
                    d[...] = a
                    done.append(f"value of {n} changed")
            elif op == 7 and "content_sha256" in f.attrs:
                del f.attrs["content_sha256"]
                done.append("checksum removed")
            elif op == 8 and attrs:
                a = rnd.choice(attrs)
                del f.attrs[a]
                done.append(f"attribute {a} deleted")
    return "; ".join(done) or "unchanged"


def results_check(path):
    """What ``frirom show`` and ``--resume`` read of a results file."""
    from frirom.results import FRF, FRFWriter
    frf = FRF.load(path)
    if len(frf):
        frf.peak(0)
    try:
        FRFWriter.resume_point(path)
    except Warning:
        pass
    return frf


def make_results(folder: Path) -> Path:
    """A small finished run of the joint case (H = 1, coarse steps): its frf.h5."""
    import shutil
    from frirom.cli import main
    folder.mkdir(parents=True, exist_ok=True)
    for f in ("M.mtx", "K.mtx", "dofs.txt"):
        shutil.copy(ROOT / "cases" / "joint" / f, folder / f)
    text = (ROOT / "cases" / "joint" / "joint.toml").read_text()
    text = (text.replace("harmonics = 5", "harmonics = 1").replace("samples = 64", "samples = 16")
            .replace("step = 0.02", "step = 0.1"))
    (folder / "joint.toml").write_text(text)
    if main(["run", str(folder / "joint.toml"), "--out", str(folder / "out"), "--quiet"]) != 0:
        raise RuntimeError("the results file for the fuzzer could not be made")
    return folder / "out" / "frf.h5"
