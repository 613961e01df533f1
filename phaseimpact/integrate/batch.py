"""Many runs at once: :func:`simulate_many` (summaries of many cases of one law, as
:class:`Columns`) and the layers under it, which the sweeps, grids and curves call directly:
:func:`pack_batch` packs the cases on columns into a :class:`Batch` (bit for bit the per-case
packing of :mod:`.api`), :func:`run_batch` runs one in threads of this process or on a GPU, and
:func:`summary_runs` gives :func:`~.api.summary_run` of many cases in one GPU launch. Each run is
independent of the others, so the numbers do not depend on the thread count, the backend's
threads or how the cases were cut into chunks; the checks, scales and tolerances are
:mod:`.api`'s, and the runs go on the same compiled driver."""

from __future__ import annotations

import functools
import itertools
import math
import numbers
import operator
import queue
import time
from dataclasses import dataclass

import numpy as np

from .. import _signals
from ..model.forms import ALPHA_, DAMP_, GUARD_, IMPEDANCE_, K_, KB_, KM_, LAW_, M1_, M2_, RIGID_, SPRINGS_
from ..model.laws import ContactLaw, as_law
from ..model.rhs import N_COEF, initial_state
from ..parameters import M1_ALONE_TARGETS, Parameters, indentation_of
from . import driver as d
from . import helper_threads, logs
from .api import (
    _NO_TIMES,
    HORIZON_CAP_PERIODS,
    MAX_EVENTS,
    MAX_STEPS,
    MIN_HORIZON_CONTACT_TIMES,
    _checked_initial,
    _initial,
    _packed,
    _stiff_after,
    _stop_on,
    _woken,
    again_with_radau,
    check_bool,
    check_params,
    check_real,
    check_rtol,
    check_t_end,
    hertz_contact_time,
    radau_marker,
    state_tolerances,
    turned_stiff,
)
from .record import workspace_size
from .result import Columns

__all__ = ["simulate_many"]


@dataclass(frozen=True)
class Batch:
    """Packed inputs of many runs of one law: coefficients (n, N_COEF), initial states (n, 5),
    horizons, absolute tolerances (n, 7, see :func:`state_tolerances`) and step caps (n,)."""

    law: ContactLaw
    C: np.ndarray
    Y0: np.ndarray
    t_end: np.ndarray
    atol: np.ndarray
    max_step: np.ndarray

    def __len__(self) -> int:
        return len(self.C)


#: Where :func:`simulate_many` runs: threads of this process, or a GPU (:mod:`phaseimpact.cuda`).
SIMULATE_MANY_BACKENDS = ("threads", "cuda")
#: Most runs packed at a time by :func:`simulate_many` (any size gives the same numbers: runs are
#: independent). Each chunk's end leaves threads idle (its last task), so chunks are large; a
#: chunk's batch and columns take about 10 MB.
PACK_CHUNK = 8192
#: Runs of :func:`simulate_many`'s first chunk in threads; each next one twice as many, up to
#: :data:`PACK_CHUNK`. The first is packed before any run starts, each other one while the one
#: before it runs (8000 cases in one chunk were packed before any run, 4 % of two threads' time).
FIRST_PACK_CHUNK = 1024


def pack_chunks(n: int, threaded: bool) -> list[slice]:
    """How :func:`simulate_many` cuts ``n`` cases into chunks: :data:`PACK_CHUNK` at a time, or in
    threads from :data:`FIRST_PACK_CHUNK` up, doubling (each packed while the one before runs)."""
    size = FIRST_PACK_CHUNK if threaded else PACK_CHUNK
    chunks, start = [], 0
    while start < n:
        chunks.append(slice(start, min(start + size, n)))
        start += size
        size = min(2 * size, PACK_CHUNK)
    return chunks


def pack_batch(params_seq, law: ContactLaw, t_end, rtol: float, initial=None) -> Batch:
    """Pack a sequence of :class:`Parameters` (one law) for :func:`run_batch`."""
    law = as_law(law)
    return _pack(_checked_sequence(params_seq), law, t_end, rtol, initial)


def _checked_sequence(params_seq) -> list:
    if isinstance(params_seq, Parameters) or not hasattr(params_seq, "__iter__"):
        raise TypeError(f"params_seq = {params_seq!r} has the wrong type ({type(params_seq).__name__}); allowed: a "
                        "sequence of Parameters")
    params_seq = list(params_seq)
    if not params_seq:
        raise ValueError("params_seq = [] is out of range; allowed: a non-empty sequence of Parameters")
    for i, p in enumerate(params_seq):
        if type(p) is not Parameters:  # the common case without formatting the name
            check_params(p, f"params_seq[{i}]")
    return params_seq


_NUMBER_FIELDS = operator.attrgetter("M1", "M2", "K", "Kb", "Km", "alpha", "kappa", "v")


def _law_coefficients(law: ContactLaw, params_seq: list) -> list[tuple] | None:
    """Each case's own coefficients of ``law`` (:meth:`~phaseimpact.model.ContactLaw.coefficients`),
    None for a law without them; ``ValueError`` naming the first case that lacks what the law needs."""
    if law.entry.coefficients is None:
        return None
    rows = []
    for i, p in enumerate(params_seq):
        try:
            rows.append(law.coefficients(p))
        except ValueError as error:
            raise ValueError(f"params_seq[{i}]: {error}") from None
    return rows


def _pack(params_seq: list, law: ContactLaw, t_end, rtol: float, initial, coefficients=None) -> Batch:
    """The rows of :func:`~phaseimpact.model.rhs.pack`, :func:`~.api.scales` and the initial states,
    on columns: per case only the fields are read (and what the law computes per case, unless
    ``coefficients`` brings it: :func:`_law_coefficients` of these cases). The same IEEE operations
    in the same order as the per-case code (``hertz_indentation``'s powers stay per case), hence
    the same bits."""
    y0 = initial_state(0.0) if initial is None else np.concatenate([_checked_initial(initial), [0.0]])
    n = len(params_seq)
    fields = itertools.chain.from_iterable(map(_NUMBER_FIELDS, params_seq))  # fromiter: no list of tuples
    M1, M2, K, Kb, Km, alpha, kappa, v = np.fromiter(fields, float, 8 * n).reshape(n, 8).T
    targets = [p.target for p in params_seq]
    kinds = set(targets)

    def of_kind(*names) -> np.ndarray:  # one target in most batches: no list of booleans
        if kinds.isdisjoint(names):
            return np.zeros(n, bool)
        return np.ones(n, bool) if kinds.issubset(names) else np.array([t in names for t in targets])

    springs, rigid = of_kind("plate"), of_kind("rigid")
    C = np.zeros((n, N_COEF))
    C[:, M1_], C[:, M2_], C[:, K_], C[:, ALPHA_] = M1, M2, K, alpha
    C[:, KB_], C[:, KM_] = np.where(springs, Kb, 0.0), np.where(springs, Km, 0.0)
    C[:, DAMP_] = _damping_column(law, params_seq, K, v, kappa)
    C[:, SPRINGS_], C[:, RIGID_], C[:, GUARD_] = springs, rigid, law.runaway_factor
    if coefficients is None:
        coefficients = _law_coefficients(law, params_seq)
    for i, own in enumerate(coefficients or ()):  # None: the law has none of its own
        C[i, LAW_:LAW_ + len(own)] = own
    if "infinite" in kinds:
        C[:, IMPEDANCE_] = [p.impedance if t == "infinite" else 0.0 for p, t in zip(params_seq, targets, strict=True)]
    # Parameters.reduced_mass (IEEE operations, numpy's bits too) and .hertz_indentation (its power
    # Python's, per case: numpy's need not give the same bits)
    reduced_mass = np.where(of_kind(*M1_ALONE_TARGETS), M1, M1 * M2 / (M1 + M2))
    indentation = np.array(list(map(indentation_of, alpha.tolist(), reduced_mass.tolist(), v.tolist(), K.tolist())))
    contact_time = hertz_contact_time(alpha, indentation, v)
    with np.errstate(divide="ignore"):  # Kb = 0: no period (Parameters.target_period)
        period = np.where(springs & (Kb != 0), 2 * math.pi * np.sqrt(M2 / Kb), math.inf)
    finite = np.isfinite(period)
    Y0 = np.tile(y0, (n, 1))
    if initial is None:
        Y0[:, 2] = v
    horizon = HORIZON_CAP_PERIODS * np.where(finite, period, contact_time)
    return Batch(law, C, Y0, _horizons(t_end, horizon, contact_time),
                 state_tolerances(rtol, indentation, v, M1, contact_time), np.where(finite, period / 8, math.inf))


def _damping_column(law: ContactLaw, params_seq: list, K: np.ndarray, v: np.ndarray, kappa: np.ndarray):
    """:meth:`ContactLaw.kappa` of every case (the same operations on columns)."""
    if law.damping_source in (None, "kappa"):
        return 0.0 if law.damping_source is None else kappa
    if law.entry.chi is not None:
        return law.entry.chi(law.restitution) * K / v
    return [law.kappa(p) for p in params_seq]  # the exact inverse: a root per case


def _horizons(t_end, default: np.ndarray, contact_time: np.ndarray) -> np.ndarray:
    """Each case's horizon: ``default``, or ``t_end`` checked against each case's contact time (the
    first case it is too short for is named, as :func:`check_t_end` per case would)."""
    if t_end is None:
        return default
    checked = check_t_end(t_end, contact_time[0])
    too_short = np.flatnonzero(~(MIN_HORIZON_CONTACT_TIMES * contact_time <= checked))
    if too_short.size:
        check_t_end(t_end, contact_time[too_short[0]])
    return np.full(len(contact_time), checked)


def run_batch(batch: Batch, *, rtol: float, settle: bool = True, stop_on=None, n_threads: int = 1,
              capacity: int = 32, stiff: bool = True, backend: str = "threads", meanwhile=None) -> Columns:
    """Run a packed batch in ``n_threads`` threads, or one GPU thread per run (``backend="cuda"``,
    checked by :func:`phaseimpact.cuda.check` first); each run is independent of the others, so the columns
    do not depend on the thread count or on how a sweep was cut into batches. ``meanwhile``: a
    function of no argument that this thread calls once while the other threads run (before the
    runs on the GPU or in one thread)."""
    stop_kind, stop_count = _stop_on(stop_on)
    stiff_after = _stiff_after(stiff)
    n = len(batch)
    summary = np.empty((n, d.N_SUMMARY))
    st = np.empty((3, n, capacity))
    count = np.empty(n, np.int64)
    args = (batch.law.code, (batch.C, batch.Y0, batch.t_end, batch.atol, batch.max_step),
            (rtol, settle, stop_kind, stop_count, MAX_STEPS, MAX_EVENTS, stiff_after))
    outputs = (summary, st[0], st[1], st[2], count)
    threads = max(1, min(int(n_threads), n))
    # each thread's workspace, made here once for the chunk (the compiled runs allocate nothing)
    work = np.zeros((threads, workspace_size(batch.C.shape[1], capacity)))
    if not _signals.installed:
        _signals.install()
    native = batch.law.entry.native
    while True:
        if native is not None:
            native.reset()
        if backend == "cuda":
            from .. import cuda

            if meanwhile is not None:
                meanwhile()
            cuda.run_batch_cuda(*args, outputs)
        else:
            radau = radau_marker(stiff_after)
            _run_block(args, outputs, work, radau, meanwhile)
            if radau is None:
                _again_with_radau(args, outputs, work)
        meanwhile = None  # once, not again if the runs are repeated (an old signal's byte)
        woken = bool(np.any(summary[:, d.S_STATUS] == d.INTERRUPTED)) or _woken(d.SUCCESS, native)
        if not (woken or _signals.deferred):
            break
        _signals.check(woken)  # raises for Ctrl-C or SIGTERM; after an old wake-up, runs again
    if native is not None and native.faulted:
        _mark_law_faults(batch, summary, native, rtol, settle, stop_kind, stop_count, stiff_after)
    # the stick points of every run in run order: each run's first min(count, capacity) from the
    # buffers (one masked gather: a Python loop over the runs was the serial part of a threaded sweep)
    kept = np.arange(capacity) < np.minimum(count, capacity)[:, None]
    points = [st[j][kept] for j in range(3)]
    for i in np.flatnonzero(count > capacity)[::-1]:  # from the last, so earlier offsets stay valid
        # more stick phases than the buffer holds (near kappa_c): rerun this one for all of them
        out = _run_one(batch, i, rtol, settle, stop_kind, stop_count, stiff_after, native)
        k = int(count[i])
        full = np.empty((3, k))
        s = out[0]
        logs.stick_points(out[1], s[d.S_T_STOP], s[d.S_OUTCOME] == d.PERMANENT_STICK, full[0], full[1], full[2])
        offset = int(np.minimum(count[:i], capacity).sum())
        points = [np.concatenate([p[:offset], full[j], p[offset + capacity:]]) for j, p in enumerate(points)]
    return Columns.from_summary(summary, count, *points)


#: Seconds between two looks of :func:`_run_block` at the helpers' first claims (a waiting helper
#: wakes within tens of microseconds; a new one starts in about 0.1 ms).
_HAND_OVER = 2e-5


def _run_block(args: tuple, outputs: tuple, work: np.ndarray, radau, meanwhile=None) -> None:
    """Every run of the batch in ``args`` (:func:`~.driver.run_block`'s first arguments) in
    ``len(work)`` threads at once (the driver releases the GIL): this one and ``len(work) - 1``
    helpers (:mod:`.helper_threads`: started by an earlier chunk where one has), each in a workspace
    of its own, claiming the tasks of :func:`thread_tasks` from one counter in compiled code;
    ``radau``: :func:`~.api.radau_marker`. No Python between two tasks: a thread pool's hand-offs
    (a queue, a future, the caller woken) left each of two threads idle 3-5 % of a sweep's chunk.
    ``meanwhile``: Python this thread runs while the helpers run, before it waits for them
    (:func:`simulate_many` packs its next chunk); it starts once each helper has claimed a task,
    inside compiled code, where the helpers need the GIL no more until their end. A helper's
    exception is raised here once every helper has ended."""
    tasks = np.array(thread_tasks(len(outputs[d.O_SUMMARY]), len(work)), np.int64)
    claimed = np.zeros(1, np.int64)
    helpers = helper_threads.take(len(work) - 1)
    done = queue.SimpleQueue()  # each helper's end: None, or what it raised
    for helper, ws in zip(helpers, work[1:], strict=True):
        helper.run(functools.partial(d.run_block, *args, tasks, claimed, outputs, ws, radau), done)
    failures = []
    try:
        if meanwhile is not None:
            while claimed[0] < len(helpers) and done.empty():  # a helper that failed first claims nothing
                time.sleep(_HAND_OVER)
            meanwhile()
        d.run_block(*args, tasks, claimed, outputs, work[0], radau)
    finally:
        for _ in helpers:  # a second Ctrl-C in this wait leaves them out of the pool, to end their block alone
            failure = done.get()
            if failure is not None:
                failures.append(failure)
        helper_threads.give_back(helpers)  # all ended: ready for the next chunk
    if failures:
        raise failures[0]


def _again_with_radau(args: tuple, outputs: tuple, work: np.ndarray) -> None:
    """The runs that stopped where they turned stiff (an engine without Radau: :func:`.api.radau_marker`)
    run again with it, their rows of ``outputs`` replaced."""
    status = outputs[d.O_SUMMARY][:, d.S_STATUS]
    again = np.flatnonzero(status == d.NEEDS_RADAU)
    if again.size == 0:
        return
    turned_stiff()
    code, batch, options = args
    rows = tuple(column[again] for column in outputs)
    _run_block((code, tuple(column[again] for column in batch), options), rows, work[:again.size], True)
    for column, row in zip(outputs, rows, strict=True):
        column[again] = row


#: Tasks a threaded chunk is cut into, per thread. Task j runs the runs j, j + tasks, ... (the cost
#: of a run changes smoothly over a sweep or an atlas, so interleaved tasks cost alike), and a thread
#: that finishes one claims the next: a thread slowed by something else (simulate_many's caller packs
#: the next chunk first; another process shares the core) no longer leaves the others idle at the
#: chunk's end for up to a third of the chunk.
TASKS_PER_THREAD = 16
#: The chunk's last ``1 / TAIL_SHARE`` of its runs go in tasks of their own, smaller, taken last: the
#: task that finishes the chunk, running while the other threads are idle, is short. (One size for all
#: left the threads idle for half a task each at the end of every chunk: 1.6 % of two threads'
#: time, more on many.)
TAIL_SHARE = 8
#: Fewest runs in one of those small tasks (set when a task cost tens of µs of Python to start; a
#: claim in compiled code costs nothing, and this only bounds how finely a small chunk's end is cut).
MIN_TAIL_TASK_RUNS = 8


def thread_tasks(n: int, threads: int) -> list[tuple[int, int, int]]:
    """How :func:`_run_block` cuts ``n`` runs: ``(start, stop, step)`` of each task, every
    ``step``-th run of ``[start, stop)``, in the order the threads take them. :data:`TASKS_PER_THREAD`
    interleaved tasks a thread over the first runs, then the last ``n // TAIL_SHARE`` runs in up to as
    many smaller ones (of at least :data:`MIN_TAIL_TASK_RUNS` runs); all runs in the first kind when
    the smaller would not be smaller."""
    tasks = min(n, TASKS_PER_THREAD * threads)
    tail = n // TAIL_SHARE
    tail_tasks = min(tasks, tail // MIN_TAIL_TASK_RUNS)
    if tail_tasks == 0 or tail / tail_tasks >= (n - tail) / tasks:
        return [(j, n, tasks) for j in range(tasks)]
    head = n - tail
    return [(j, head, tasks) for j in range(tasks)] + [(head + j, n, tail_tasks) for j in range(tail_tasks)]


def _run_one(batch: Batch, i: int, rtol, settle, stop_kind, stop_count, stiff_after, native):
    """Run ``i`` of ``batch`` alone, summary and stick points (again after an old wake-up)."""
    while True:
        if native is not None:
            native.reset()
        out = d.run(batch.law.code, batch.C[i], batch.Y0[i], batch.atol[i], batch.t_end[i], batch.max_step[i],
                    (rtol, settle, stop_kind, stop_count, MAX_STEPS, MAX_EVENTS, stiff_after), d.SAVE_SUMMARY,
                    _NO_TIMES, radau_marker(stiff_after))
        codes = out[0].tolist()  # the summary's numbers: cheaper than reading entries of the array one by one
        if again_with_radau(codes[d.S_STATUS]):
            continue
        woken = _woken(codes[d.S_STATUS], native)
        if not (woken or _signals.deferred):
            return out
        _signals.check(woken)


def summary_runs(law: ContactLaw, params_seq, t_ends, *, rtol: float, stop_when_settled: bool = True,
                 stop_on=None, arrivals=None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`~.api.summary_run` of every case of ``params_seq`` in one GPU launch, one thread each (the
    ``cuda`` backends of the critical curve and the orbit diagram): the summaries (n x
    ``driver.N_SUMMARY``) and final states (n x 5) it would give, from the same inputs. ``t_ends``:
    each run's horizon (None: the case's own); ``arrivals`` (n x 4, optional): each run's initial
    ``(x1, x2, x1dot, x2dot)`` (``W`` from the seed state, as ``initial`` does). The caller checks
    ``law`` and ``rtol`` and calls :func:`phaseimpact.cuda.check` first."""
    from .. import cuda

    packed = [_packed(p, law, rtol) for p in params_seq]  # summary_run's inputs, cached
    starts = np.stack([y0 for _, _, y0, _ in packed])
    if arrivals is not None:
        unusable = np.flatnonzero(~np.all(np.isfinite(arrivals), axis=1))
        if unusable.size:  # the ValueError summary_run would give
            _initial(params_seq[unusable[0]], arrivals[unusable[0]])
        starts[:, :4] = arrivals
    horizons = np.array([s.horizon if t_end is None else check_t_end(t_end, s.contact_time)
                         for (_, _, _, s), t_end in zip(packed, t_ends, strict=True)])
    batch = (np.stack([c for c, _, _, _ in packed]), starts, horizons,
             np.stack([atol for _, atol, _, _ in packed]), np.array([s.max_step for _, _, _, s in packed]))
    stop_kind, stop_count = _stop_on(stop_on)
    options = (rtol, check_bool("stop_when_settled", stop_when_settled), stop_kind, stop_count, MAX_STEPS,
               MAX_EVENTS, _stiff_after(True))
    n = len(packed)
    summary, final = np.empty((n, d.N_SUMMARY)), np.empty((n, 5))
    no_sticks = np.empty((n, 1))  # the stick points are not read: one slot each
    cuda.run_batch_cuda(law.code, batch, options, (summary, no_sticks, no_sticks.copy(), no_sticks.copy(),
                                                   np.empty(n, np.int64)), final)
    return summary, final


def _mark_law_faults(batch: Batch, summary, native, rtol, settle, stop_kind, stop_count, stiff_after) -> None:
    """Give the status ``non-finite`` to the failed runs whose user law raised or gave NaN or inf.

    The law's fault record is one for the whole batch (its runs share the compiled function, in
    several threads): each failed run is run again alone (the same numbers: runs are independent)
    to see whether its law faulted. Only failed runs can be the law's: a run whose law faulted on
    a rejected trial step and then went on is a success."""
    for i in np.flatnonzero(summary[:, d.S_STATUS] != d.SUCCESS):
        _run_one(batch, i, rtol, settle, stop_kind, stop_count, stiff_after, native)
        if native.faulted:
            summary[i, d.S_STATUS] = d.NON_FINITE


def simulate_many(params_seq, law: ContactLaw | str = "paper", t_end: float | None = None, *,
                  rtol: float = 1e-10, stop_when_settled: bool = True, stop_on=None, initial=None,
                  n_threads: int = 1, stiff: bool = True, backend: str = "threads") -> Columns:
    """Many impacts (one per :class:`Parameters` of ``params_seq``), summaries only, as columns.

    Same driver and arguments as :func:`~.api.simulate`; runs go in ``n_threads`` threads inside this
    process and the result is bit-identical for any thread count.

    Parameters
    ----------
    params_seq : sequence of Parameters
        One case per run (non-empty), all integrated with ``law``.
    law : ContactLaw or str, default "paper"
        A law of :data:`phaseimpact.model.LAWS` with its options, or its name.
    t_end : float, optional
        Horizon of every run, s (> 0, and at least ``1e-13`` contact times of each case); default:
        each run until its outcome settles, capped at its :attr:`~.api.Scales.horizon`.
    rtol : float, default 1e-10
        Relative tolerance, within :data:`~.api.RTOL_RANGE`; absolute tolerances from each case's scales.
    stop_when_settled : bool, default True
        Stop each run once nothing can change any more.
    stop_on : str or (str, int), optional
        Stop each run at the n-th event of a kind, as for :func:`~.api.simulate`.
    initial : 4 numbers, optional
        ``(x1, x2, x1dot, x2dot)`` (m, m, m/s, m/s) of every run instead of seed eq. 6.
    n_threads : int, default 1
        Threads of this process (>= 1); the compiled driver releases the GIL.
    stiff : bool, default True
        Radau IIA for stiff phases, as for :func:`~.api.simulate`.
    backend : {"threads", "cuda"}, default "threads"
        ``cuda``: one GPU thread per run, the same per-point kernel compiled for the GPU
        (``n_threads`` is then not read); refused before any work for a user law or without a
        usable GPU.

    Returns
    -------
    Columns
        One entry per run, in the order of ``params_seq``: codes of status, outcome and stop
        reason, the summary columns and the stick phases (a ragged array).

    Raises
    ------
    TypeError
        If ``params_seq`` is not a sequence of :class:`~phaseimpact.Parameters`.
    ValueError
        For an empty ``params_seq``, an unknown law, or any argument out of range (named in the
        message).

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate_many
    >>> base = seed_parameters(v=1.0)
    >>> c = simulate_many([base.replace(kappa=k) for k in (1e9, 1e12, 1e13)], "paper")
    >>> len(c), list(c.outcome_names())
    (3, ['permanent-stick', 'permanent-stick', 'ratchet-escape'])
    >>> c.n_stick.tolist()
    [1, 1, 2]
    """
    law = as_law(law)
    rtol = check_rtol(rtol)
    if t_end is not None:
        t_end = check_real("t_end", t_end, "a finite number > 0", lambda x: x > 0)
    if not (isinstance(n_threads, numbers.Integral) and not isinstance(n_threads, bool) and n_threads >= 1):
        raise ValueError(f"n_threads = {n_threads!r} is out of range; allowed: an integer >= 1")
    _stiff_after(stiff)
    check_bool("stop_when_settled", stop_when_settled)
    _stop_on(stop_on)
    if backend not in SIMULATE_MANY_BACKENDS:
        raise ValueError(f"backend = {backend!r} is out of range; allowed: one of {', '.join(SIMULATE_MANY_BACKENDS)}")
    if backend == "cuda":
        from .. import cuda

        cuda.check(law)
    params_seq = _checked_sequence(params_seq)  # every case, before any run
    # what the law needs of each case, read once: chunks are packed as they run, with these
    own = _law_coefficients(law, params_seq)
    if t_end is not None:  # long enough for the case of the longest contact
        check_t_end(t_end, max(hertz_contact_time(p.alpha, p.hertz_indentation, p.v) for p in params_seq))
    threaded = n_threads > 1 and backend == "threads"
    chunks = [(params_seq[part], None if own is None else own[part]) for part in pack_chunks(len(params_seq), threaded)]
    options = {"rtol": rtol, "settle": stop_when_settled, "stop_on": stop_on, "n_threads": n_threads, "stiff": stiff,
               "backend": backend}
    if not threaded:
        return _joined([run_batch(_pack(cases, law, t_end, rtol, initial, rows), **options) for cases, rows in chunks])
    # Packing is Python (~1.2 us a case on columns, 4 % of a run on two threads): this thread packs
    # the next chunk while the other threads run the chunk before, in compiled code that needs no GIL,
    # and then runs the rest of it beside them (run_batch's meanwhile). Only the first, small chunk is
    # packed before any run starts.
    first_cases, first_coefficients = chunks[0]
    batch, parts = _pack(first_cases, law, t_end, rtol, initial, first_coefficients), []
    for following in [*chunks[1:], None]:
        packed = []

        def pack_following(chunk=following, into=packed) -> None:
            cases, coefficients = chunk
            into.append(_pack(cases, law, t_end, rtol, initial, coefficients))

        parts.append(run_batch(batch, **options, meanwhile=None if following is None else pack_following))
        batch = packed[0] if packed else None
    return _joined(parts)


def _joined(parts: list[Columns]) -> Columns:
    """The columns of consecutive chunks as one."""
    if len(parts) == 1:
        return parts[0]

    def cat(name):
        return np.concatenate([getattr(part, name) for part in parts])

    values = {name: np.concatenate([part.values[name] for part in parts]) for name in parts[0].values}
    return Columns(cat("status"), cat("outcome"), cat("stop_reason"), values, cat("stick_count"), cat("stick_t"),
                   cat("stick_delta"), cat("stick_dwell"))
