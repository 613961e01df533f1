"""Where work is split across threads, processes or machines: the only joblib/Dask importer.

``threads`` (default) runs chunks in this process on ``n_jobs`` numba threads; ``loky`` runs
chunks in ``n_jobs`` joblib worker processes; ``dask`` sends them to a ``dask.distributed``
cluster (``scheduler`` address, or an in-process local cluster). Every run is independent of
its chunk and thread, so results are bit-identical whatever the backend and job count.
"""

from __future__ import annotations

import asyncio
import contextlib
import os

import numpy as np

from ..integrate.api import run_batch

__all__ = ["BACKENDS", "run_chunks", "check_jobs", "check_scheduler", "connect"]

BACKENDS = ("threads", "loky", "dask")
MAX_JOBS = 4 * (os.cpu_count() or 1)
#: Scheduler connection timeout, s.
CONNECT_TIMEOUT = 5


def check_jobs(n_jobs, backend: str, scheduler) -> int:
    """Validate the parallel settings before any work; returns the job count (>= 1)."""
    if backend not in BACKENDS:
        raise ValueError(f"backend = {backend!r} is out of range; allowed: one of {', '.join(BACKENDS)}")
    if isinstance(n_jobs, bool) or not isinstance(n_jobs, (int, np.integer)) or not (
            n_jobs == -1 or 1 <= n_jobs <= MAX_JOBS):
        raise ValueError(f"jobs = {n_jobs!r} is out of range; allowed: an integer 1..{MAX_JOBS}, or -1 for all cores")
    if scheduler is not None and backend != "dask":
        raise ValueError(f"scheduler = {scheduler!r} is only read with backend 'dask', not {backend!r}")
    return (os.cpu_count() or 1) if n_jobs == -1 else int(n_jobs)


def check_scheduler(address: str) -> None:
    """Refuse an address where no Dask scheduler answers, within :data:`CONNECT_TIMEOUT` s
    (before any work: a ``Client`` on a dead address would wait, then fail in its clean-up)."""
    try:
        from distributed.core import rpc
    except ImportError:  # pragma: no cover - depends on the install
        raise ValueError("backend = 'dask' needs dask.distributed: pip install 'phaseimpact[dask]'") from None

    async def identity():
        remote = rpc(address, timeout=CONNECT_TIMEOUT)
        try:
            return await asyncio.wait_for(remote.identity(), CONNECT_TIMEOUT)
        finally:
            await remote.close_rpc()

    try:
        answer = asyncio.run(identity())
    except Exception as error:  # any failure to talk to it means: not a usable scheduler
        # a timeout, or a MemoryError from a garbled reply ("Unable to allocate 3.07 EiB"), says nothing
        # more to the user than that no scheduler answered
        silent = isinstance(error, TimeoutError | asyncio.TimeoutError | MemoryError) or not str(error)
        reason = f"no answer within {CONNECT_TIMEOUT:g} s" if silent else f"{type(error).__name__}: {error}"
        raise ValueError(f"scheduler = {address!r} is out of reach ({reason}); "
                         "allowed: the address of a running Dask scheduler, e.g. tcp://host:8786") from None
    if not (isinstance(answer, dict) and answer.get("type") == "Scheduler"):
        raise ValueError(f"scheduler = {address!r} is out of range: it answers, but is not a Dask scheduler")


def connect(scheduler: str | None, n_jobs: int):
    """A ``dask.distributed`` client (an in-process local cluster without an address)."""
    try:
        from dask.distributed import Client
    except ImportError as error:  # pragma: no cover - depends on the install
        raise ValueError("backend = 'dask' needs dask.distributed: pip install 'phaseimpact[dask]'") from error
    if scheduler is None:
        return Client(processes=False, n_workers=1, threads_per_worker=n_jobs, dashboard_address=None)
    check_scheduler(scheduler)
    return Client(scheduler, timeout=CONNECT_TIMEOUT)


def _run_chunk(batch, rtol, settle, stop_on, threads):
    return run_batch(batch, rtol=rtol, settle=settle, stop_on=stop_on, n_threads=threads)


def run_chunks(batches, *, rtol: float, settle: bool, stop_on, n_jobs: int, backend: str, scheduler=None):
    """Yield the :class:`~phaseimpact.integrate.Columns` of each batch, in order."""
    if backend == "threads":
        for batch in batches:
            yield _run_chunk(batch, rtol, settle, stop_on, n_jobs)
        return
    import joblib

    client = connect(scheduler, n_jobs) if backend == "dask" else None
    try:
        context = joblib.parallel_config(backend="dask") if client is not None else contextlib.nullcontext()
        with context:
            parallel = joblib.Parallel(n_jobs=-1 if client is not None else n_jobs, return_as="generator")
            yield from parallel(joblib.delayed(_run_chunk)(b, rtol, settle, stop_on, 1) for b in batches)
    finally:
        if client is not None:
            client.close()


def map_in_threads(function, items, n_jobs: int) -> list:
    """``[function(item) for item in items]`` in ``n_jobs`` threads (joblib), in order. For work
    whose compiled part releases the GIL (the driver's runs): the Python between runs is serial."""
    if n_jobs == 1 or len(items) == 1:
        return [function(item) for item in items]
    import joblib

    return joblib.Parallel(n_jobs=n_jobs, prefer="threads")(joblib.delayed(function)(item) for item in items)
