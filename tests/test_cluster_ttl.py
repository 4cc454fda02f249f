"""A study member longer than the Dask scheduler's worker heartbeat limit (issue 29):
a member that holds the GIL (as a Fortran batch of continuation points does) keeps its
worker's event loop from answering, and the scheduler's ``worker-ttl`` (5 minutes by
default) then took the worker for dead, restarted it and ran the member again, until
KilledWorker. Here the limit is shortened to 1 s and the member holds the GIL for 4 s
(libc's sleep called through ctypes.PyDLL, which keeps the GIL, unlike CDLL): frirom's
local cluster must run it once, to its end. On main the member ran 4 times, each
restart of its worker starting it over (a 2.5 s hold was not caught: the scheduler
checks the limit only every so often)."""

from __future__ import annotations

import ctypes
import os

import pytest

pytest.importorskip("distributed")
pytestmark = pytest.mark.slow           # a LocalCluster's start and the 4 s hold: 9-10 s

HOLD_S = 4


def _member(path: str) -> int:
    """Append this process's pid to ``path``, then hold the GIL HOLD_S seconds."""
    with open(path, "a") as fh:
        fh.write(f"{os.getpid()}\n")
    ctypes.PyDLL(None).sleep(HOLD_S)
    return os.getpid()


def test_member_holding_the_gil_past_the_heartbeat_limit_runs_once(tmp_path):
    import dask

    from frirom._cluster import Failed, _Runner
    log = tmp_path / "runs.txt"
    with dask.config.set({"distributed.scheduler.worker-ttl": "1s"}):
        runner = _Runner("local", 1)
        try:
            out = runner.map(_member, [(str(log),)], keep_going=True)
        finally:
            runner.close()
    assert not isinstance(out[0], Failed), out[0].message
    runs = log.read_text().split()
    assert runs == [str(out[0])], f"the member ran {len(runs)} times: {runs}"
