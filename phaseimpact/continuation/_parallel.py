"""Where work is split across threads, processes or machines: the only joblib/Dask importer.

``threads`` (default) runs chunks in this process on ``n_jobs`` numba threads; ``loky`` runs
chunks in ``n_jobs`` joblib worker processes; ``dask`` sends them to a ``dask.distributed``
cluster: a ``Client`` the caller holds, a scheduler's address, or an in-process local cluster;
``cuda`` runs each chunk on a GPU, one thread per point (:mod:`phaseimpact.cuda`).
With Dask, ``n_jobs`` is the number of tasks in flight (any number up to :data:`MAX_DASK_TASKS`,
-1 for every thread of the cluster's workers), not this machine's cores, and every worker loads
or compiles the engine once before the first chunk (:func:`warm_workers`). Every run is
independent of its chunk and thread, so results are bit-identical whatever the backend and job
count.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import warnings

import numpy as np

from .. import _signals
from ..integrate.batch import run_batch

__all__ = ["BACKENDS", "run_chunks", "check_jobs", "check_scheduler", "connect", "warm_workers", "tasks_in_flight",
           "MAX_DASK_TASKS"]

BACKENDS = ("threads", "loky", "dask", "cuda")
MAX_JOBS = 4 * (os.cpu_count() or 1)
#: Tasks in flight on a Dask cluster (its size is not this machine's).
MAX_DASK_TASKS = 100_000
#: Scheduler connection timeout, s.
CONNECT_TIMEOUT = 5


def check_jobs(n_jobs, backend: str, scheduler, law=None) -> int:
    """Validate the parallel settings before any work (for ``cuda``: the ``law`` and the GPU);
    returns the job count (>= 1)."""
    if backend not in BACKENDS:
        raise ValueError(f"backend = {backend!r} is out of range; allowed: one of {', '.join(BACKENDS)}")
    if backend == "cuda":
        from .. import cuda

        cuda.check(law)
    top = MAX_DASK_TASKS if backend == "dask" else MAX_JOBS
    if isinstance(n_jobs, bool) or not isinstance(n_jobs, (int, np.integer)) or not (
            n_jobs == -1 or 1 <= n_jobs <= top):
        every = "every thread of the cluster's workers" if backend == "dask" else "all cores"
        raise ValueError(f"jobs = {n_jobs!r} is out of range; allowed: an integer 1..{top}, or -1 for {every}")
    if scheduler is not None and backend != "dask":
        raise ValueError(f"scheduler = {scheduler!r} is only read with backend 'dask', not {backend!r}")
    if scheduler is not None and not isinstance(scheduler, str) and not _is_client(scheduler):
        raise ValueError(f"scheduler = {scheduler!r} is out of range; allowed: a scheduler address (str) or a "
                         "dask.distributed.Client")
    if n_jobs == -1 and backend == "dask":
        return -1  # the cluster's threads, once connected
    return (os.cpu_count() or 1) if n_jobs == -1 else int(n_jobs)


def _is_client(value) -> bool:
    return type(value).__name__ == "Client" and type(value).__module__.startswith("distributed")


def check_scheduler(address: str) -> int:
    """Refuse an address where no Dask scheduler answers, within :data:`CONNECT_TIMEOUT` s
    (before any work: a ``Client`` on a dead address would wait, then fail in its clean-up).
    Returns the threads of its workers (from the scheduler's identity)."""
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
    return sum(int(w.get("nthreads", 0)) for w in answer.get("workers", {}).values())


def connect(scheduler, n_jobs: int):
    """``(client, owned)``: the caller's ``Client`` as it is, or one of ours (closed after the work):
    to ``scheduler``'s address, or an in-process local cluster without one."""
    if _is_client(scheduler):
        return scheduler, False
    try:
        from dask.distributed import Client
    except ImportError as error:  # pragma: no cover - depends on the install
        raise ValueError("backend = 'dask' needs dask.distributed: pip install 'phaseimpact[dask]'") from error
    if scheduler is None:
        threads = (os.cpu_count() or 1) if n_jobs == -1 else n_jobs
        # the scheduler's HTTP server on a free port: its default, 8787, warns when another cluster has it
        return Client(processes=False, n_workers=1, threads_per_worker=threads, dashboard_address="127.0.0.1:0",
                      scheduler_kwargs={"dashboard": False}), True
    check_scheduler(scheduler)
    return Client(scheduler, timeout=CONNECT_TIMEOUT), True


def _warm() -> bool:
    from ..integrate.precompile import warmup

    return warmup()["compiled"]


def warm_workers(client) -> dict:
    """Load, or compile once, the engine on every worker of ``client`` (``phaseimpact warmup`` in
    each): ``{worker address: whether it compiled}``. A worker then keeps it for every later task."""
    return client.run(_warm)


def cluster_threads(client) -> int:
    """Threads of all the cluster's workers: ``n_jobs = -1`` with Dask."""
    return max(1, sum(client.nthreads().values()))


def tasks_in_flight(n_jobs: int, scheduler) -> int:
    """Dask's ``n_jobs``: as given, or for -1 the threads of the cluster's workers (a ``Client``'s,
    a scheduler's, or this machine's cores for a local cluster); chunks are sized from it."""
    if n_jobs != -1:
        return n_jobs
    if _is_client(scheduler):
        return cluster_threads(scheduler)
    if scheduler is not None:
        return max(1, check_scheduler(scheduler))
    return os.cpu_count() or 1


def _run_task(batch, rtol, settle, stop_on):
    """A chunk as a worker's task (a joblib process or a Dask worker's thread). After Ctrl-C or
    SIGTERM its run ends at once without running again (:func:`._signals.stopping_with_the_caller`)
    and the task returns None, which nobody reads: the caller is stopping. A raised
    ``KeyboardInterrupt`` would print a worker's traceback or break Dask's event loop."""
    with _signals.stopping_with_the_caller():
        try:
            return run_batch(batch, rtol=rtol, settle=settle, stop_on=stop_on)
        except KeyboardInterrupt:
            return None


_END = object()
#: What joblib and Dask say while a stopped run is torn down: the one line the caller prints is enough.
_TEARDOWN_WARNING = r".*tasks which were still being processed by the workers have been cancelled"


@contextlib.contextmanager
def _quiet_teardown():
    """joblib's warning on cancelled tasks and ``distributed``'s log of tasks that ended with
    CancelledError, silenced while the work of a stopped caller is cancelled and its cluster closed."""
    log = logging.getLogger("distributed")
    level = log.level
    log.setLevel(logging.CRITICAL)
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=_TEARDOWN_WARNING, category=UserWarning)
            yield
    finally:
        log.setLevel(level)


class _AfterAStop(logging.Filter):
    """Drops what ``distributed`` logs once this process has acted on a signal (``_signals``) since
    the filter was made. joblib cancels a stopped caller's futures while the signal's exception
    passes through it, before :func:`_quiet_teardown` begins, and a result being gathered then is
    logged ("Couldn't gather 1 keys, rescheduling"): noise beside the one line the caller prints."""

    def __init__(self):
        super().__init__()
        self.since = _signals._acted[0]

    def filter(self, record) -> bool:
        return _signals._acted[0] == self.since


@contextlib.contextmanager
def _quiet_after_a_stop():
    """:class:`_AfterAStop` on the handlers of ``distributed``'s logger (its own, which its child
    loggers' records reach), for the block."""
    quiet, handlers = _AfterAStop(), list(logging.getLogger("distributed").handlers)
    for handler in handlers:
        handler.addFilter(quiet)
    try:
        yield
    finally:
        for handler in handlers:
            handler.removeFilter(quiet)


def run_chunks(batches, *, rtol: float, settle: bool, stop_on, n_jobs: int, backend: str, scheduler=None):
    """Yield the :class:`~phaseimpact.integrate.Columns` of each batch, in order."""
    if backend in ("threads", "cuda"):
        for batch in batches:
            yield run_batch(batch, rtol=rtol, settle=settle, stop_on=stop_on, n_threads=n_jobs, backend=backend)
        return
    client, owned = connect(scheduler, n_jobs) if backend == "dask" else (None, False)
    with _quiet_after_a_stop() if client is not None else contextlib.nullcontext():
        yield from _run_chunks_with(client, owned, batches, rtol, settle, stop_on, n_jobs)


def _run_chunks_with(client, owned: bool, batches, rtol, settle, stop_on, n_jobs):
    """:func:`run_chunks` on joblib's processes, or on ``client``'s Dask cluster (closed after the
    work if ``owned``)."""
    import joblib

    results = None
    stopped = False
    try:
        if client is not None:
            warm_workers(client)
            n_jobs = tasks_in_flight(n_jobs, client)
        context = (joblib.parallel_config(backend="dask", client=client) if client is not None
                   else contextlib.nullcontext())
        with context:
            parallel = joblib.Parallel(n_jobs=n_jobs, return_as="generator")
            results = parallel(joblib.delayed(_run_task)(b, rtol, settle, stop_on) for b in batches)
            while True:
                with warnings.catch_warnings():  # Ctrl-C in here: joblib cancels the tasks and warns of it
                    warnings.filterwarnings("ignore", message=_TEARDOWN_WARNING, category=UserWarning)
                    columns = next(results, _END)
                if columns is _END:
                    return
                if columns is None:  # a worker stopped by a signal (a terminal's Ctrl-C reaches them all)
                    # the last signal acted on here: a worker thread may have taken this thread's deferred
                    # one (SIGTERM stays SIGTERM); Ctrl-C if none, a worker process's own
                    _signals._raise(_signals._acted[1])
                yield columns
    except BaseException:  # Ctrl-C or SIGTERM here, or in the caller between two chunks
        stopped = True
        raise
    finally:
        with _quiet_teardown() if stopped else contextlib.nullcontext():
            if results is not None:
                results.close()
            if owned:
                client.close()


def map_in_threads(function, items, n_jobs: int) -> list:
    """``[function(item) for item in items]`` in ``n_jobs`` threads (joblib), in order. For work
    whose compiled part releases the GIL (the driver's runs): the Python between runs is serial."""
    if n_jobs == 1 or len(items) == 1:
        return [function(item) for item in items]
    import joblib

    return joblib.Parallel(n_jobs=n_jobs, prefer="threads")(joblib.delayed(function)(item) for item in items)
