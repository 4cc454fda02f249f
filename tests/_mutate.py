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
