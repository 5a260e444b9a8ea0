"""oracles.executors: a local pool's workers start with one BLAS/OpenMP thread each.

The pool runs a process per job; OpenBLAS threads in each would spin against
the other workers. As Dask's nanny does for its workers, the variables are set
for the workers only (the caller's environment is left as it was), and a value
the caller chose is kept.
"""

from __future__ import annotations

import os

from wirecheck.oracles.executors import ExecutorSpec, open_executor

KEYS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def test_pool_workers_get_one_blas_thread_and_the_caller_keeps_its_environment(monkeypatch):
    for key in KEYS:
        monkeypatch.delenv(key, raising=False)
    monkeypatch.setenv("OMP_NUM_THREADS", "3")  # the caller's choice wins
    with open_executor(ExecutorSpec("local", jobs=2), n_tasks=2) as (pool, workers):
        assert workers == 2
        seen = [pool.submit(os.getenv, key).result() for key in KEYS for _ in range(2)]
        during = {key: os.environ.get(key) for key in KEYS}
    assert seen == ["3", "3", "1", "1", "1", "1"]
    after = {key: os.environ.get(key) for key in KEYS}
    assert during == after == {"OMP_NUM_THREADS": "3", "OPENBLAS_NUM_THREADS": None, "MKL_NUM_THREADS": None}
