"""What makes ``frirom run --resume`` safe: one run per results folder (an OS lock), and
the deck's fingerprint, compared key by key with the one the results were made with.

Exit codes of ``frirom run`` (README, ``frirom run --help``): :data:`EXIT_OK`,
:data:`EXIT_INPUT`, :data:`EXIT_STOPPED`, :data:`EXIT_INTERRUPTED`.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from ._errors import InputError

EXIT_OK = 0             #: the run reached the end of its range
EXIT_INPUT = 2          #: bad input, refused resume, results folder in use: nothing computed
EXIT_STOPPED = 3        #: the run stopped before the end of its range (its points are kept)
EXIT_INTERRUPTED = 130  #: Ctrl-C (SIGINT); the points are kept, continue with --resume

#: Deck keys a resumed run may change: they extend the run, not its points.
EXTENDABLE = ("frequency.end", "continuation.max_points")

LOCK_NAME = ".frirom.lock"


class ResultsLock:
    """An exclusive OS lock (fcntl.flock) on OUT/.frirom.lock, held while the object
    lives and released by the OS when the process dies, however it dies. Taken before
    anything in OUT is opened: a second run on the same folder is refused untouched, or,
    with ``wait`` > 0 seconds, waited for that long first (a study's member whose worker
    outlived a killed study: the OS frees the lock when that worker dies)."""

    def __init__(self, folder: Path, wait: float = 0.0):
        self.fd = None
        try:
            import fcntl
        except ImportError:         # not POSIX: no lock (documented)
            return
        path = Path(folder) / LOCK_NAME
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        import time
        t_end = time.monotonic() + wait
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except OSError:
                if time.monotonic() < t_end:
                    time.sleep(0.1)
                    continue
                holder = os.read(fd, 64).decode(errors="replace").strip() or "?"
                os.close(fd)
                raise InputError(f"{folder}: another frirom run (pid {holder}) is writing "
                                 "these results; wait for it to end, or choose another "
                                 "--out") from None
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        self.fd = fd

    def release(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None


def _flatten(value, key: str, out: dict) -> dict:
    """{'a.b[2].c': leaf} of a TOML document."""
    if isinstance(value, dict):
        for k, v in value.items():
            _flatten(v, f"{key}.{k}" if key else str(k), out)
    elif isinstance(value, list) and any(isinstance(v, (dict, list)) for v in value):
        for i, v in enumerate(value):
            _flatten(v, f"{key}[{i}]", out)
    else:
        out[key] = value
    return out


def deck_fingerprint(deck) -> str:
    """JSON of the deck's keys (flattened, 'section.key': value) and the SHA-256 of every
    file it names (a string value that is a file relative to the deck), so a changed
    matrix file counts as a changed deck."""
    keys = _flatten(deck.raw, "", {})
    files = {}
    for k, v in keys.items():
        vals = v if isinstance(v, list) else [v]
        for j, s in enumerate(vals):
            if isinstance(s, str) and s and (deck.path.parent / s).is_file():
                h = hashlib.sha256()
                with open(deck.path.parent / s, "rb") as fh:
                    for block in iter(lambda: fh.read(1 << 20), b""):
                        h.update(block)
                name = k if len(vals) == 1 else f"{k}[{j}]"
                files[name] = f"{s} sha256:{h.hexdigest()}"
    return json.dumps({"keys": keys, "files": files}, sort_keys=True, default=str)


def _show(v) -> str:
    return json.dumps(v, default=str) if not isinstance(v, str) else repr(v)


def deck_changes(old: str, new: str, allowed=EXTENDABLE) -> list[str]:
    """The differences between two deck fingerprints, one line per key ('contacts[0].mu:
    0.5 then, 0.4 now'), the keys in `allowed` left out."""
    a, b = json.loads(old), json.loads(new)
    lines = []
    for kind in ("keys", "files"):
        x, y = a.get(kind, {}), b.get(kind, {})
        for k in sorted(set(x) | set(y)):
            if k in allowed or x.get(k) == y.get(k):
                continue
            what = "" if kind == "keys" else "file of "
            if kind == "files" and k in x and k in y and \
                    x[k].split(" sha256:")[0] == y[k].split(" sha256:")[0]:
                lines.append(f"file of {k} ({x[k].split(' sha256:')[0]}): content changed")
            elif k not in y:
                lines.append(f"{what}{k}: {_show(x[k])} then, removed now")
            elif k not in x:
                lines.append(f"{what}{k}: absent then, {_show(y[k])} now")
            else:
                lines.append(f"{what}{k}: {_show(x[k])} then, {_show(y[k])} now")
    return lines
