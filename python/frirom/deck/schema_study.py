"""The ``[study]`` table of a deck: which keys to sweep, how, and where to run (docs/deck.md).

A study member is the deck with some keys replaced: :func:`set_key` writes a value at a
key path (``contacts[0].mu``, ``excitation.load[1].amplitude``, ``solver.harmonics``) of
the TOML dict, and the member is parsed by the same :func:`frirom.deck.parse_deck` as a
deck run alone. This module only checks the table and the paths; running is
:mod:`frirom.study`.
"""

from __future__ import annotations

import copy
import itertools
import re
from dataclasses import dataclass
from pathlib import Path

from .._errors import InputError
from .fields import Context, file, number, string, unknown

KINDS = ("family", "convergence")
#: GSI counts climbed by ``free``/``stick = "auto"`` (those up to max_modes, then max_modes)
GSI_LADDER = (5, 10, 20, 30, 40, 60, 80, 120, 160, 240, 320)
_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)$")
_ADDRESS = re.compile(r"(tcp|tls)://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9](?:[A-Za-z0-9.-]*"
                      r"[A-Za-z0-9])?):(\d{1,5})/?")


def check_address(address) -> tuple:
    """(protocol, host, port) of a Dask scheduler address ``tcp://HOST:PORT`` or
    ``tls://HOST:PORT``; InputError for anything else."""
    m = _ADDRESS.fullmatch(str(address)) if isinstance(address, str) else None
    if m is None or not 0 < int(m.group(3)) < 65536:
        raise InputError(f"scheduler {address!r}: expected \"local\", \"serial\" or a Dask "
                         "scheduler address tcp://HOST:PORT or tls://HOST:PORT (port "
                         "1..65535)")
    return m.group(1), m.group(2).strip("[]"), int(m.group(3))


def scheduler_and_workers(ctx: Context, st: dict) -> tuple:
    """study.scheduler (``"local"``, ``"serial"`` or a checked address; default local) and
    study.workers (None or 1..1024) of a ``[study]`` table, for every study kind."""
    sched = string(ctx, st, "scheduler", "study.scheduler", default="local")
    if sched not in ("local", "serial"):
        try:
            check_address(sched)
        except InputError as exc:
            raise ctx.error("study.scheduler", str(exc).split(": expected ", 1)[1],
                            sched) from None
    workers = number(ctx, st, "workers", "study.workers", integer=True, minimum=1,
                     maximum=1024)
    return sched, workers

@dataclass(frozen=True)
class StudySettings:
    """``[study]``, checked.

    kind : str
        ``"family"`` (one FRF per combination) or ``"convergence"`` (a ladder of model
        sizes, the last rung the reference).
    parameters : tuple of (str, tuple)
        (key path, values) in the deck's order.
    combine : str
        ``"product"`` (every combination, the last key fastest) or ``"zip"`` (the i-th
        value of every key together; equal lengths).
    scheduler : str
        ``"local"`` (a distributed.LocalCluster), ``"serial"`` (this process) or a Dask
        scheduler address (``"tcp://host:8786"``).
    workers : int or None
        LocalCluster workers (None: one per core).
    output : int
        Position in outputs.dofs of the output whose peak is studied.
    tolerance : float
        Convergence: relative error on the peak (amplitude and frequency) a model must
        meet.
    base : Path or None
        ``study.base``: the deck the members vary (relative to this deck's folder); None:
        this deck itself (its other tables).
    """

    kind: str
    parameters: tuple
    combine: str
    scheduler: str = "local"
    workers: int | None = None
    output: int = 0
    tolerance: float = 0.01
    base: Path | None = None

    def size(self) -> int:
        """How many members, without making them."""
        import math
        lens = [len(v) for _, v in self.parameters]
        return math.prod(lens) if self.combine == "product" else min(lens, default=0)

    def members(self) -> list:
        """One dict {key path: value} per member, in run order."""
        keys = [k for k, _ in self.parameters]
        lists = [v for _, v in self.parameters]
        combos = itertools.product(*lists) if self.combine == "product" else zip(*lists)
        return [dict(zip(keys, c)) for c in combos]


@dataclass(frozen=True)
class ModesAuto:
    """``[reduction.interface_modes]`` counts given as ``"auto"`` (frirom.auto chooses them).

    keys : tuple of str
        ``("free", "stick")`` or one of them (GSI), or ``("time_harmonics",)`` (MS: the
        harmonic indices that the engine orders excite through time harmonics 0..j).
    tolerance : float
        Relative change of the peak amplitude and frequency allowed (tail estimate).
    largest : int
        ``max_modes`` (GSI: the largest count of an auto key) or ``max_time_harmonic``
        (MS: the largest j).
    """

    keys: tuple
    tolerance: float = 0.01
    largest: int = 40

    def rungs(self) -> list:
        """The ladder: one dict {key: value} per rung, smallest first. GSI: every auto
        key the same count, :data:`GSI_LADDER` up to ``largest``; MS: time harmonics
        (1,), (0, 1), (0, 1, 2), ... up to ``largest``."""
        if self.keys == ("time_harmonics",):
            return [{"time_harmonics": (1,)}] + [{"time_harmonics": tuple(range(j + 1))}
                                                 for j in range(1, self.largest + 1)]
        counts = [n for n in GSI_LADDER if n < self.largest] + [self.largest]
        return [{k: n for k in self.keys} for n in counts]


def parse_modes_auto(ctx: Context, im: dict, method: str) -> tuple:
    """``"auto"`` counts of a ``[reduction.interface_modes]`` table and their keys
    (``tolerance_auto``, ``max_modes`` / ``max_time_harmonic``).

    Returns (table, ModesAuto or None): the table with each ``"auto"`` replaced by the
    first rung and the auto keys removed (what the reduction parser then checks), and
    the settings.
    """
    pre = "reduction.interface_modes"
    cand = {"gsi": ("free", "stick"), "ms": ("time_harmonics",)}.get(method, ())
    keys = tuple(k for k in cand if im.get(k) == "auto")
    big = "max_time_harmonic" if method == "ms" else "max_modes"
    given = [k for k in ("tolerance_auto", "max_modes", "max_time_harmonic") if k in im]
    if not keys:
        if given:
            raise ctx.error(f"{pre}.{given[0]}", f"{' or '.join(cand) or 'a count'} = "
                            "\"auto\" (it only bounds that choice)", im[given[0]])
        return im, None
    for k in given:
        if k not in ("tolerance_auto", big):
            raise ctx.error(f"{pre}.{k}", f"{big} with method = {method!r}", im[k])
    tol = float(number(ctx, im, "tolerance_auto", f"{pre}.tolerance_auto", default=0.01,
                       positive=True, maximum=0.5))
    if method == "ms":
        if "engine_orders" not in im:
            raise ctx.error(f"{pre}.engine_orders", 'the engine orders whose harmonic '
                            'indices time_harmonics = "auto" climbs (missing)')
        largest = number(ctx, im, big, f"{pre}.{big}", default=5, integer=True, minimum=1)
    else:
        largest = number(ctx, im, big, f"{pre}.{big}", default=40, integer=True,
                         minimum=GSI_LADDER[1])
    auto = ModesAuto(keys=keys, tolerance=tol, largest=int(largest))
    first = auto.rungs()[0]
    out = {k: v for k, v in im.items() if k not in given}
    out.update({k: list(v) if isinstance(v, tuple) else v for k, v in first.items()})
    return out, auto


def split_key(key: str) -> list:
    """``"contacts[0].mu"`` -> ``["contacts", 0, "mu"]``; InputError for a malformed path."""
    out = []
    for part in key.split("."):
        m = _PART.match(part)
        if m is None:
            raise InputError(f"key path {key!r}: expected names and [index] parts joined "
                             "by dots, like 'contacts[0].mu' or 'solver.harmonics'")
        out.append(m.group(1))
        out.extend(int(i) for i in re.findall(r"\[(\d+)\]", m.group(2)))
    return out


def set_key(raw: dict, key: str, value) -> None:
    """Write ``value`` at the key path ``key`` of the TOML dict ``raw`` (in place).

    Every table and array index on the way must exist (a typo is an error, not a new
    table); the last name may be new in an existing table (``solver.samples``).
    """
    parts = split_key(key)
    node = raw
    for i, p in enumerate(parts[:-1]):
        where = _path(parts[:i + 1])
        if isinstance(p, int):
            if not isinstance(node, list) or not -len(node) <= p < len(node):
                n = len(node) if isinstance(node, list) else 0
                raise InputError(f"key path {key!r}: {where} is not in the deck "
                                 f"({_path(parts[:i]) or 'the deck'} has {n} entries)")
            node = node[p]
        else:
            if not isinstance(node, dict) or p not in node:
                raise InputError(f"key path {key!r}: the deck has no {where}")
            node = node[p]
            if isinstance(node, list) and parts[i + 1:] and not isinstance(parts[i + 1],
                                                                           int):
                raise InputError(f"key path {key!r}: {where} is an array of tables: "
                                 f"name one entry, like {where}[0]")
    last = parts[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or not -len(node) <= last < len(node):
            raise InputError(f"key path {key!r}: {_path(parts)} is not in the deck")
        node[last] = value
    elif not isinstance(node, dict):
        raise InputError(f"key path {key!r}: {_path(parts[:-1])} is not a table")
    else:
        node[last] = value


def member_raw(raw: dict, values: dict) -> dict:
    """A copy of the deck's TOML without ``[study]`` and with ``values`` written."""
    out = copy.deepcopy({k: v for k, v in raw.items() if k != "study"})
    for key, v in values.items():
        set_key(out, key, v)
    return out


def _path(parts) -> str:
    s = ""
    for p in parts:
        s += f"[{p}]" if isinstance(p, int) else (f".{p}" if s else p)
    return s


def parse_study(path, raw: dict, read=None) -> StudySettings | None:
    """The deck's ``[study]`` table checked (None without one); each key path must name a
    field of the deck (of ``study.base`` when given: ``read(path)`` reads it, and the
    base's TOML is then what the paths are checked on)."""
    if "study" not in raw:
        return None
    ctx = Context(Path(path))
    st = raw["study"]
    if not isinstance(st, dict):
        raise ctx.error("study", "a table [study]", st)
    unknown(ctx, st, {"kind", "parameters", "combine", "scheduler", "workers", "output",
                      "tolerance", "base"}, "study")
    base = None
    if "base" in st:
        base = file(ctx, st, "base", "study.base")
        extra = sorted(set(raw) - {"study"})
        if extra:
            raise ctx.error("study.base", "a deck holding only [study] when it names a "
                            f"base deck (this one also has {extra})", str(base))
        raw = read(base)
        if "study" in raw:
            raise ctx.error("study.base", "a deck without its own [study]", str(base))
    kind = string(ctx, st, "kind", "study.kind", default="family", choices=KINDS)
    combine = string(ctx, st, "combine", "study.combine",
                     default="product" if kind == "family" else "zip",
                     choices=("product", "zip"))
    pars = st.get("parameters")
    if not isinstance(pars, dict) or not pars:
        raise ctx.error("study.parameters", "a table of key paths and value lists, like "
                        "\"contacts[0].mu\" = [0.2, 0.3]", pars)
    params = []
    for key, vals in pars.items():
        where = f'study.parameters."{key}"'
        if not isinstance(vals, list) or not vals:
            raise ctx.error(where, "a non-empty list of values", vals)
        try:
            set_key(member_raw(raw, {}), key, vals[0])
        except InputError as exc:
            raise ctx.error(where, f"a key path of the deck ({exc})") from None
        params.append((key, tuple(vals)))
    if combine == "zip" and len({len(v) for _, v in params}) > 1:
        raise ctx.error("study.parameters", "lists of one length with combine = \"zip\"",
                        {k: len(v) for k, v in params})
    sched, workers = scheduler_and_workers(ctx, st)
    outputs = raw.get("outputs", {}).get("dofs", []) if isinstance(raw.get("outputs"),
                                                                   dict) else []
    output = number(ctx, st, "output", "study.output", default=0, integer=True, minimum=0)
    if isinstance(outputs, list) and output >= max(len(outputs), 1):
        raise ctx.error("study.output", f"a position in outputs.dofs (0..{len(outputs) - 1})",
                        output)
    tol = number(ctx, st, "tolerance", "study.tolerance", default=0.01, positive=True)
    s = StudySettings(kind=kind, parameters=tuple(params), combine=combine, scheduler=sched,
                      workers=workers, output=output, tolerance=float(tol), base=base)
    if kind == "convergence" and s.size() < 2:
        raise ctx.error("study.parameters", "at least two rungs for a convergence study")
    return s
