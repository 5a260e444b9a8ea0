"""Where a run's tasks go: this process, a pool of worker processes, or a Dask cluster.

``local`` (the default): with one job, tasks run in this process; with
``jobs`` > 1 (or when the candidate must be isolated), in a
:class:`~concurrent.futures.ProcessPoolExecutor` of "spawn" workers (an
OSMesa context must never be inherited through ``fork``; oracles.runner).

``dask``: Dask's ``distributed`` scheduler. Without a scheduler address, a
``LocalCluster`` of ``jobs`` worker processes (one thread each) on the
loopback address of this machine; with ``scheduler="tcp://HOST:PORT"``, the
workers someone started with ``dask scheduler`` / ``dask worker`` (docs/datasets.md).
Tasks are submitted through ``Client.get_executor()``, a
:class:`concurrent.futures.Executor`, so callers treat both kinds alike and
gather results in task order: the report does not depend on where a task ran.

Worker processes of a local pool start with one BLAS/OpenMP thread each
(:data:`WORKER_ENVIRON`, unless the caller set those variables), as Dask's
nanny starts its workers: the pool already runs a process per core, and
OpenBLAS's own threads in each would only spin against the other workers.

Connecting is bounded: a scheduler that does not answer, or answers with no
worker, within ``connect_timeout_s`` is an :class:`~wirecheck.core.errors.InputError`.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import re
from dataclasses import dataclass

from wirecheck.core.errors import InputError

EXECUTORS = ("local", "dask")
#: Seconds to reach a scheduler and see a worker: a LAN answers in milliseconds, a cluster's
#: workers register within seconds of starting; more than this is a wrong address or a dead cluster.
DEFAULT_CONNECT_TIMEOUT_S = 10.0
#: Dask's address forms that reach another machine (inproc:// and ucx:// are not for this).
_ADDRESS = re.compile(r"(tcp|tls)://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):([0-9]{1,5})")


@dataclass(frozen=True)
class ExecutorSpec:
    """How to run tasks: ``kind`` in EXECUTORS, ``jobs`` workers, a Dask ``scheduler`` address or None."""

    kind: str = "local"
    jobs: int = 1
    scheduler: str | None = None
    connect_timeout_s: float = DEFAULT_CONNECT_TIMEOUT_S

    def __post_init__(self):
        if self.kind not in EXECUTORS:
            raise ValueError(f"executor {self.kind!r}: expected one of {', '.join(EXECUTORS)}")
        if isinstance(self.jobs, bool) or not isinstance(self.jobs, int) or self.jobs < 1:
            raise ValueError(f"jobs {self.jobs!r}: expected an integer >= 1")
        if self.scheduler is not None:
            if self.kind != "dask":
                raise ValueError(f"scheduler {self.scheduler!r}: only the dask executor has one")
            check_scheduler_address(self.scheduler)
        if not (math.isfinite(self.connect_timeout_s) and self.connect_timeout_s > 0):
            raise ValueError(f"connect_timeout_s {self.connect_timeout_s!r}: expected seconds > 0")

    def to_dict(self) -> dict:
        return {"executor": self.kind, "jobs": self.jobs, "scheduler": self.scheduler}


def check_scheduler_address(address: str, option: str = "--scheduler") -> str:
    """``address`` when it is ``tcp://HOST:PORT`` (or ``tls://``) with a port in 1..65535; InputError otherwise."""
    m = _ADDRESS.fullmatch(address or "")
    if not m or not 1 <= int(m.group(3)) <= 65535:
        raise InputError(
            f"{option} {address!r}: expected tcp://HOST:PORT (the address 'dask scheduler' "
            "prints, e.g. tcp://10.0.0.5:8786)"
        )
    return address


@contextlib.contextmanager
def _quiet_dask():
    """Dask logs its cluster's life (workers starting, closing) at INFO/WARNING: the CLI's output is its own."""
    loggers = [logging.getLogger(n) for n in ("distributed", "tornado")]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for lg, level in zip(loggers, levels):
            lg.setLevel(level)


#: The environment a local pool's workers start with where the caller has not set these
#: (Dask's distributed.nanny.pre-spawn-environ gives its workers the same threads).
WORKER_ENVIRON = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


@contextlib.contextmanager
def _worker_environ():
    """:data:`WORKER_ENVIRON` in ``os.environ`` while workers are spawned (they inherit it); then removed."""
    added = {k: v for k, v in WORKER_ENVIRON.items() if k not in os.environ}
    os.environ.update(added)
    try:
        yield
    finally:
        for key in added:
            os.environ.pop(key, None)


@contextlib.contextmanager
def _environ_kept():
    """Undo, on leaving, what starting a local cluster wrote into this process's environment.

    Dask's nanny sets its ``distributed.nanny.pre-spawn-environ`` (by default
    ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS``, ``MKL_NUM_THREADS`` = 1 and
    ``MALLOC_TRIM_THRESHOLD_``) in ``os.environ`` of the process that starts it,
    for its workers to inherit, and leaves them there: every later subprocess of
    an API caller (or of a test run) would start numpy with one BLAS thread.
    Only those variables are put back, and only where they changed.
    """
    import os

    import dask

    keys = set(dask.config.get("distributed.nanny.pre-spawn-environ", default={}) or {})
    before = {k: os.environ.get(k) for k in keys}
    try:
        yield
    finally:
        for key, value in before.items():
            if os.environ.get(key) != value:
                if value is None:
                    del os.environ[key]
                else:
                    os.environ[key] = value


@contextlib.contextmanager
def _dask_client(spec: ExecutorSpec, n_workers: int | None = None):
    """A connected ``distributed.Client`` with at least one worker; InputError when there is none in time.

    A local cluster starts ``n_workers`` (default ``spec.jobs``) processes.
    """
    try:
        from distributed import Client, LocalCluster
    except ImportError as exc:  # pragma: no cover - a dependency in pyproject.toml
        raise InputError(
            f"--executor dask: {exc}: expected the 'distributed' package (pip install distributed)"
        ) from None
    with _quiet_dask(), _environ_kept():
        if spec.scheduler is None:
            cluster = LocalCluster(
                n_workers=n_workers or spec.jobs,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address=None,
                silence_logs=logging.CRITICAL,
            )
            try:
                client = Client(cluster)
            except BaseException:
                cluster.close()
                raise
        else:
            cluster = None
            try:
                client = Client(spec.scheduler, timeout=spec.connect_timeout_s)
            except (OSError, TimeoutError) as exc:
                raise InputError(
                    f"--scheduler {spec.scheduler}: no Dask scheduler answered within "
                    f"{spec.connect_timeout_s:g} s ({type(exc).__name__}): expected a running "
                    "'dask scheduler' at that address"
                ) from None
            except TypeError as exc:
                if not spec.scheduler.startswith("tls://"):
                    raise
                # distributed wants an ssl.SSLContext from the Dask config's TLS settings
                raise InputError(
                    f"--scheduler {spec.scheduler}: TLS without certificates ({exc}): expected the "
                    "Dask config's distributed.comm.tls settings, or a tcp:// address"
                ) from None
        try:
            if spec.scheduler is not None:
                try:
                    client.wait_for_workers(1, timeout=spec.connect_timeout_s)
                except (OSError, TimeoutError):
                    raise InputError(
                        f"--scheduler {spec.scheduler}: the scheduler has no worker after "
                        f"{spec.connect_timeout_s:g} s: expected 'dask worker {spec.scheduler}' "
                        "running on at least one machine with wirecheck installed"
                    ) from None
            yield client
        finally:
            client.close()
            if cluster is not None:
                cluster.close()


def heap_for_arrays() -> bool:
    """Undo, in a Dask worker, what ``MALLOC_TRIM_THRESHOLD_`` does to glibc's heap; True if it did.

    Dask's nanny starts its workers with ``MALLOC_TRIM_THRESHOLD_=65536`` (to give
    memory back to the OS sooner). With glibc, any explicit threshold also freezes
    the mmap threshold at 128 KiB, so every image-sized array (a 640x480 frame is
    0.3 to 2.5 MB) is a fresh mmap, page-faulted anew: a mesh took twice as long in
    a Dask worker as in a process-pool worker until this raised both thresholds
    (32 MiB for mmap, glibc's maximum on 64-bit; 64 MiB for trimming). Elsewhere
    (no such variable, or not glibc) nothing changes.
    """
    import ctypes
    import os

    if "MALLOC_TRIM_THRESHOLD_" not in os.environ:
        return False
    try:
        libc = ctypes.CDLL("libc.so.6")
    except OSError:
        return False
    m_trim_threshold, m_mmap_threshold = -1, -3  # glibc's <malloc.h>
    return bool(libc.mallopt(m_mmap_threshold, 32 * 2**20)) and bool(libc.mallopt(m_trim_threshold, 64 * 2**20))


def dask_failure(exc: BaseException) -> str:
    """One line for a task that failed on a Dask worker (a worker died, or lacks wirecheck)."""
    text = " ".join(str(exc).split())[:300]
    return (
        f"a Dask task failed ({type(exc).__name__}: {text}): every worker needs the same wirecheck "
        "installed as this machine, and the mesh files at the same paths (docs/datasets.md)"
    )


def dask_workers(client) -> int:
    """How many workers a Dask client's scheduler has now."""
    return len(client.scheduler_info().get("workers", {}))


@contextlib.contextmanager
def open_executor(spec: ExecutorSpec, n_tasks: int, initializer=None, isolate: bool = False):
    """``(executor, workers)`` for ``n_tasks`` tasks; ``executor`` is None when they should run in this process.

    ``initializer`` runs once in each process-pool worker (Dask workers set
    themselves up on their first task instead). ``isolate``: a worker process
    even for one job, so that a candidate cannot end this process.
    """
    if spec.kind == "dask":
        # a local cluster starts no more workers than there are tasks (like the process pool below)
        with _dask_client(spec, min(spec.jobs, max(n_tasks, 1))) as client:
            client.run(heap_for_arrays)
            if initializer is not None:
                client.run(initializer)  # on every worker, before the first task
            yield client.get_executor(), dask_workers(client)
        return
    workers = min(spec.jobs, n_tasks)
    if workers <= 1 and not isolate:
        yield None, 0
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    workers = max(workers, 1)
    ctx = multiprocessing.get_context("spawn")
    barrier = ctx.Barrier(workers)
    with ProcessPoolExecutor(
        max_workers=workers, mp_context=ctx, initializer=_pool_init, initargs=(initializer, barrier)
    ) as pool:
        try:
            # start every worker now (the pool starts one per task submitted while none is idle, and each
            # waits for the others): the run's time then counts tasks, not interpreters starting
            with _worker_environ():
                for f in [pool.submit(_pool_ready) for _ in range(workers)]:
                    f.result()
            yield pool, workers
        except BaseException:
            _stop_workers(pool)
            raise


def _stop_workers(pool) -> None:
    """End a pool's workers now: the run was interrupted (Ctrl-C, SIGTERM) or failed.

    The pool's own shutdown would wait for the tasks running, each up to a candidate's
    timeout (a hung candidate: 10 s by default). A worker's candidate program dies with it
    (oracles.candidates.subprocess_candidate: it is killed when its parent ends).
    """
    processes = list((getattr(pool, "_processes", None) or {}).values())  # CPython's pid -> Process
    pool.shutdown(wait=False, cancel_futures=True)  # (which forgets them)
    for proc in processes:
        proc.terminate()
    for proc in processes:
        proc.join(timeout=5)


_BARRIER = None


def _pool_init(initializer, barrier) -> None:
    global _BARRIER
    _BARRIER = barrier
    if initializer is not None:
        initializer()


def _pool_ready() -> None:
    """Returns once every worker of the pool has started (each holds one of these tasks meanwhile)."""
    _BARRIER.wait(timeout=600)


def gather_in_order(executor, fn, items, on_result=None) -> list:
    """``[fn(*item) for item in items]`` on ``executor``, results in item order; ``on_result`` on each as gathered.

    A result is dropped by its future as soon as it is gathered (memory stays
    that of the results, not twice); on an error the futures not yet run are
    cancelled and the error is raised.
    """
    on_result = on_result or (lambda result: None)
    futures = [executor.submit(fn, *item) for item in items]
    results = []
    try:
        for i, f in enumerate(futures):
            results.append(f.result())
            futures[i] = None
            on_result(results[-1])
        return results
    except BaseException:
        for f in futures:
            if f is not None:
                f.cancel()
        raise
