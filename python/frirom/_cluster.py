"""Where a study's members run: serially in this process, on a local Dask cluster, or on
a running Dask scheduler that the user named (command line or FRIROM_SCHEDULER; a deck's
address only with --trust-deck-scheduler), checked before any client connects
(:func:`probe_scheduler`), with TLS when configured. :class:`_Runner` hands members out and
collects their summaries; a member that fails is kept as :class:`Failed`.
"""

from __future__ import annotations

import os
from pathlib import Path

from ._errors import InputError
from ._optional import require
from .deck.schema_study import StudySettings, check_address

#: Environment variable naming the Dask scheduler a study connects to (as --scheduler).
SCHEDULER_ENV = "FRIROM_SCHEDULER"
#: Seconds to reach a Dask scheduler (the TCP connection, its first message, the client's
#: handshake) before the study is refused.
CONNECT_TIMEOUT = 10.0
#: Largest first message [bytes] a scheduler may send: a Dask handshake is a few hundred
#: bytes; anything else answering on that port is refused before the client reads it (an
#: HTTP or SSH server's first bytes read as a length would ask for exbibytes).
PROBE_MAX_BYTES = 1 << 26
#: Most LocalCluster workers a study may ask for.
MAX_WORKERS = 1024
#: Environment of frirom's LocalCluster workers: one BLAS/OpenMP thread each, so that n
#: workers use n cores and not n times the machine.
ONE_THREAD = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
#: Dask settings of frirom's LocalCluster workers (see :func:`local_workers`).
QUIET_WORKER = {"distributed.worker.profile.enabled": False,
                "distributed.admin.tick.interval": "1s",
                "distributed.admin.system-monitor.interval": "5s",
                "distributed.worker.memory.monitor-interval": "1s",
                "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}
#: Dask settings of the scheduler of frirom's LocalCluster (see :func:`local_workers`):
#: no heartbeat limit on its workers.
PATIENT_SCHEDULER = {"distributed.scheduler.worker-ttl": None}


def probe_scheduler(address: str, timeout: float = CONNECT_TIMEOUT) -> None:
    """Check that a Dask scheduler answers at a tcp:// ``address`` before a Client is
    made: it must accept the connection and send the length of a handshake-sized first
    message within ``timeout`` s. InputError naming the address otherwise (nothing
    listens, nothing is said, or a length no handshake has)."""
    import socket
    import struct
    proto, host, port = check_address(address)
    if proto != "tcp":
        return              # TLS: the handshake itself checks the certificates
    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            sock.settimeout(timeout)
            head = b""
            while len(head) < 8:
                part = sock.recv(8 - len(head))
                if not part:
                    raise InputError(f"scheduler {address}: closed the connection without "
                                     "a Dask handshake: not a Dask scheduler")
                head += part
    except socket.timeout:
        raise InputError(f"scheduler {address}: no Dask handshake within {timeout:g} s "
                         "(not a Dask scheduler, or unreachable)") from None
    except OSError as exc:
        raise InputError(f"scheduler {address}: cannot connect ({exc})") from None
    (n,) = struct.unpack("<Q", head)
    if n > PROBE_MAX_BYTES:
        raise InputError(f"scheduler {address}: its first message announces {n} bytes, "
                         "no Dask handshake does: not a Dask scheduler (refused before "
                         "reading it)")


def check_workers(workers) -> int | None:
    """The LocalCluster worker count (None: one per core), checked."""
    if workers is None:
        return None
    from ._errors import check_integer
    return check_integer("--workers (study.workers)", workers, minimum=1,
                         maximum=MAX_WORKERS, cls=InputError)


def _security(proto: str, tls: dict | None):
    """distributed.Security of a connection: the certificate files given (``tls``: ca,
    cert, key) or, without them, Dask's own configuration (distributed.comm.tls.*);
    None for tcp:// without certificates."""
    from distributed.security import Security
    tls = {k: v for k, v in (tls or {}).items() if v is not None}
    for k, v in tls.items():
        if not Path(v).is_file():
            raise InputError(f"--tls-{k} {v}: no such file")
    if tls and proto != "tls":
        raise InputError("TLS certificates are given but the scheduler address is not "
                         "tls://HOST:PORT: a tcp:// connection would not use them")
    if tls:
        return Security(tls_ca_file=tls.get("ca"), tls_client_cert=tls.get("cert"),
                        tls_client_key=tls.get("key"), require_encryption=True)
    sec = Security()            # from Dask's configuration, if any
    if proto == "tls" and not sec.tls_ca_file:
        raise InputError("a tls:// scheduler needs certificates: give --tls-ca (and "
                         "--tls-cert, --tls-key) or set distributed.comm.tls.ca-file "
                         "(and .client.cert, .client.key) in Dask's configuration")
    return sec if proto == "tls" or sec.require_encryption else None


def local_workers(n: int):
    """A LocalCluster of ``n`` one-thread worker processes (its HTTP server on a free
    port) set up so that n workers come near n times one on a machine of n cores:

    - one BLAS/OpenMP thread per worker (:data:`ONE_THREAD`);
    - glibc's allocator left to its own: Dask's nanny starts workers with
      ``MALLOC_TRIM_THRESHOLD_=65536``, which also freezes glibc's mmap threshold, so that
      every large array is mapped from the kernel and handed back afresh. Measured on a
      mistuned FRF (cases/bench/mistuning.py): 10x the page faults, 16-24 % more CPU per
      sample, the whole gap between two workers and twice one. The variable is dropped;
      a variable of the caller's own environment still wins;
    - Dask's statistical profiler off: it samples the task thread's stack every 10 ms,
      15-30 % more CPU per friction sample; the workers' event-loop tick, system and
      memory monitors at 1-5 s instead of 20-500 ms (an idle worker: 2.2 % of a core,
      then 0.26 %);
    - no heartbeat limit (:data:`PATIENT_SCHEDULER`): a member holds its worker's GIL for
      as long as one call into Fortran takes (a batch of continuation points: minutes on
      the UPD case at H = 3), the worker's event loop cannot answer meanwhile, and
      Dask's scheduler took such a worker for dead after ``worker-ttl`` (5 minutes),
      restarted it and ran the member again, up to KilledWorker. A worker that really
      dies is still noticed: its nanny sees the process end and the scheduler loses
      its connection (tests/test_mistuning_cluster.py kills one). A scheduler the user
      runs keeps its own limit: give it ``distributed.scheduler.worker-ttl`` above the
      longest member, or null (docs/deck.md, ``[study]``).
    """
    import dask
    from dask.distributed import LocalCluster
    with dask.config.set({**QUIET_WORKER, **PATIENT_SCHEDULER}):
        # the scheduler's HTTP server on a free port: dashboard_address=None still takes
        # :8787, and warns where another cluster holds it (seen in a CI run)
        return LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                            dashboard_address=":0", env=ONE_THREAD)


class Failed:
    """A task that raised: ``message`` is its exception's class and text."""

    def __init__(self, exc: BaseException):
        self.message = f"{type(exc).__name__}: {' '.join(str(exc).split())}"


class _Runner:
    """Where tasks run: this process, a LocalCluster made here, or a named scheduler."""

    def __init__(self, scheduler: str, workers: int | None, tls: dict | None = None):
        self.client = self.cluster = None
        self.scheduler = scheduler
        if scheduler == "serial":
            return
        workers = check_workers(workers)
        if scheduler != "local":
            proto = check_address(scheduler)[0]
        distributed = require("distributed", "study",
                              "study.scheduler: running members as Dask tasks (or "
                              "scheduler = \"serial\")")
        Client = distributed.Client
        if scheduler == "local":
            self.cluster = local_workers(workers or os.cpu_count() or 1)
            self.client = Client(self.cluster)
        else:
            sec = _security(proto, tls)
            probe_scheduler(scheduler)
            try:
                self.client = Client(scheduler, timeout=CONNECT_TIMEOUT, security=sec)
            except (OSError, TimeoutError) as exc:
                raise InputError(f"scheduler {scheduler}: cannot reach the Dask scheduler "
                                 f"({type(exc).__name__}: {exc})") from None

    @property
    def n_workers(self) -> int:
        if self.client is None:
            return 1
        return max(len(self.client.scheduler_info().get("workers", {})), 1)

    def map(self, fn, jobs: list, on_done=None, poll=None, keep_going: bool = False) -> list:
        """fn(*args) for each args tuple of ``jobs``, results in order; ``on_done(i, r)``
        as each finishes, ``poll()`` about twice a second while waiting. With
        ``keep_going`` a task that raises gives a :class:`Failed` in its place and the
        others run on; without, its exception is raised."""
        out = [None] * len(jobs)
        if self.client is None:
            for i, args in enumerate(jobs):
                try:
                    out[i] = fn(*args)
                except Exception as exc:
                    if not keep_going:
                        raise
                    out[i] = Failed(exc)
                if on_done:
                    on_done(i, out[i])
            return out
        wait = require("distributed", "study", "a Dask study").wait
        futures = {self.client.submit(fn, *args, pure=False): i
                   for i, args in enumerate(jobs)}
        pending = set(futures)
        while pending:
            try:
                done, pending = wait(pending, timeout=0.5, return_when="FIRST_COMPLETED")
            except TimeoutError:                 # nothing finished in 0.5 s
                done = set()
            for f in done:
                i = futures[f]
                try:
                    out[i] = f.result()         # a task's exception is raised here
                except Exception as exc:        # the member's error, or its lost worker
                    if not keep_going:
                        raise
                    out[i] = Failed(exc)
                if on_done:
                    on_done(i, out[i])
            if poll:
                poll()
        return out

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def choose_scheduler(settings: StudySettings, given: str | None, trust_deck: bool = False,
                     path="the deck") -> str:
    """The scheduler a study runs on: ``given`` (the command line or the caller), else the
    environment's FRIROM_SCHEDULER, else the deck's ``study.scheduler`` when it is
    ``"local"`` or ``"serial"``. A deck's own address is used only with ``trust_deck``
    (``--trust-deck-scheduler``): a Dask scheduler can run any code in the process that
    connects to it (docs/security.md), so which one is the user's choice, not a deck's."""
    sched = given or os.environ.get(SCHEDULER_ENV) or None
    if sched is None:
        sched = settings.scheduler
        if sched not in ("local", "serial") and not trust_deck:
            raise InputError(f"{path}: study.scheduler = {sched!r}: frirom connects only to a "
                             "Dask scheduler you name (a scheduler can run any code in the "
                             "process that connects to it, see docs/security.md): give "
                             f"--scheduler {sched} or set {SCHEDULER_ENV}, or "
                             "--trust-deck-scheduler to use the deck's")
    if sched not in ("local", "serial"):
        check_address(sched)
    return sched


