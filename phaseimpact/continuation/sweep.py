"""Sweeps and atlases: every point of a grid of named parameters, as columns.

:func:`atlas` evaluates an N-d grid (:mod:`.grid`); :func:`sweep` is its one-axis case over
``kappa``. Each point runs until its outcome settles (or to ``t_end``) on the compiled driver,
chunk by chunk (:mod:`._parallel`); after each chunk the partial result can be checkpointed
(``on_chunk``) and a sweep can be resumed from it (``previous``). Points whose run failed are
recomputed on resume, never taken as done.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from tqdm.auto import tqdm

from .._version import __version__
from ..case import Case
from ..integrate import driver as drv
from ..integrate.api import check_bool, check_rtol, check_t_end, scales
from ..integrate.result import SUMMARY_COLUMNS, ColumnAccess
from ..model.laws import ContactLaw, as_law
from ..parameters import Parameters
from ._parallel import check_jobs, run_chunks, tasks_in_flight
from .grid import Axis, Grid

__all__ = ["SweepResult", "sweep", "atlas", "ENGINE"]

#: The engine named in every result's settings and archive.
ENGINE = "phaseimpact driver: DOP853 (scipy tableau) with located events, numba"
#: Points per chunk: large enough that a chunk's µs-per-point work outweighs its dispatch.
CHUNK_THREADS, CHUNK_MIN, CHUNK_MAX = 4096, 256, 65536
#: Points of one GPU launch: about as many threads as an H100 holds at once (132 x 2048); their
#: workspaces (5.7 kB a point) take 1.5 GB on the device and, while they are made, on the host.
CHUNK_CUDA = 1 << 18


#: The outcome classes and, last, the label of points not computed yet.
OUTCOME_LABELS = drv.OUTCOMES + ("not computed",)


@dataclass
class SweepResult(ColumnAccess):
    """Columns of a grid of runs (points in C order over ``grid.axes``).

    Attributes
    ----------
    grid : Grid
        Base case, law and axes.
    t_end : float or None
        Horizon of every run, s (None: each run goes until its outcome settles, capped).
    settings : dict
        ``rtol``, ``engine``, ``version``.
    status, outcome, stop_reason : ndarray of int8, shape (n,)
        Codes into :data:`~phaseimpact.integrate.STATUSES`, ``OUTCOMES``, ``STOP_REASONS``;
        -1 where the point is not computed yet.
    values : dict of ndarray
        :data:`~phaseimpact.integrate.result.SUMMARY_COLUMNS` (``max_force``, ``n_stick``,
        ``t_run``...); NaN (or -1 for counts) where undefined or not computed.
    stick_point, stick_t, stick_delta, stick_dwell : ndarray
        Every stick phase of every point (an indexed ragged array: ``stick_point`` is the
        point's flat index), in the order computed.
    extras : dict
        Further results stored with the sweep (e.g. ``boundaries``), archived under ``/extras``.

    Made by :func:`atlas` and :func:`sweep` (or :func:`phaseimpact.archive.load`); a new one (no
    columns given) has every point not computed. The summary columns are also read as attributes
    (``result.max_force``).

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import sweep
    >>> s = sweep(seed_parameters(v=1.0), "paper", np.geomspace(1e9, 1e14, 5))
    >>> s.shape, s.outcome_names().tolist()
    ((5,), ['permanent-stick', 'permanent-stick', 'permanent-stick', 'ratchet-escape', 'ratchet-escape'])
    >>> s.n_stick.tolist()
    [1, 1, 1, 2, 2]
    """

    grid: Grid
    t_end: float | None
    settings: dict
    status: np.ndarray = None
    outcome: np.ndarray = None
    stop_reason: np.ndarray = None
    values: dict = None
    stick_point: np.ndarray = None
    stick_t: np.ndarray = None
    stick_delta: np.ndarray = None
    stick_dwell: np.ndarray = None
    extras: dict = field(default_factory=dict)

    def __post_init__(self):
        n = self.grid.size
        for name in ("status", "outcome", "stop_reason"):
            if getattr(self, name) is None:
                setattr(self, name, np.full(n, -1, dtype=np.int8))
        if self.values is None:
            self.values = {name: np.full(n, -1 if dtype is np.int64 else np.nan, dtype=dtype)
                           for name, _, dtype, _ in SUMMARY_COLUMNS}
        for name, dtype in (("stick_point", np.int64), ("stick_t", float), ("stick_delta", float),
                            ("stick_dwell", float)):
            if getattr(self, name) is None:
                setattr(self, name, np.empty(0, dtype=dtype))

    @property
    def law(self) -> ContactLaw:
        """The law of every point."""
        return self.grid.law

    @property
    def shape(self) -> tuple:
        """The grid's shape (one length per axis)."""
        return self.grid.shape

    def axis(self, name: str) -> np.ndarray:
        """The values of the axis ``name``.

        Parameters
        ----------
        name : str
            One of ``grid.names``.

        Returns
        -------
        ndarray of float
            The axis values, SI units.

        Raises
        ------
        ValueError
            If the grid has no axis ``name``.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.continuation import atlas
        >>> a = atlas(seed_parameters(), "paper", {"kappa": [1e9, 1e13], "v": [1.0, 2.0]})
        >>> a.axis("v").tolist()
        [1.0, 2.0]
        """
        for a in self.grid.axes:
            if a.name == name:
                return a.values
        raise ValueError(f"axis {name!r} is not in this result; allowed: {', '.join(self.grid.names)}")

    @property
    def kappa(self) -> np.ndarray:
        """The ``kappa`` axis, N s/m^(1+alpha) (``ValueError`` if there is none)."""
        return self.axis("kappa")

    @property
    def done(self) -> np.ndarray:
        """Points computed without a numerical failure."""
        return self.status == drv.SUCCESS

    @property
    def failed(self) -> np.ndarray:
        """Points computed with a numerical failure (recomputed on resume)."""
        return self.status > drv.SUCCESS

    @property
    def cut(self) -> np.ndarray:
        """Points whose horizon ended the run before the outcome settled (counts are lower bounds)."""
        return self.stop_reason == drv.HORIZON

    def outcome_indices(self) -> np.ndarray:
        """Each point's index into :data:`OUTCOME_LABELS` (the outcomes, then "not computed").

        Returns
        -------
        ndarray of int, shape (size,)

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.continuation import sweep
        >>> sweep(seed_parameters(), "paper", [1e9, 1e13]).outcome_indices().tolist()
        [1, 2]
        """
        return np.where(self.outcome < 0, len(drv.OUTCOMES), self.outcome)

    def outcome_names(self) -> np.ndarray:
        """Each point's outcome class (:data:`OUTCOME_LABELS`; "not computed" for a point not computed yet).

        Returns
        -------
        ndarray of str (object), shape (size,)
            In C order over the axes: ``reshape(shape)`` gives the grid.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.continuation import atlas
        >>> a = atlas(seed_parameters(), "paper", {"kappa": [1e9, 1e13], "v": [1.0, 2.0]})
        >>> a.outcome_names().reshape(a.shape).tolist()
        [['permanent-stick', 'permanent-stick'], ['ratchet-escape', 'ratchet-escape']]
        """
        return np.array(OUTCOME_LABELS, dtype=object)[self.outcome_indices()]

    def status_names(self) -> np.ndarray:
        """Each point's status (:data:`~phaseimpact.integrate.STATUSES`; "not computed" for a
        point not computed yet).

        Returns
        -------
        ndarray of str (object), shape (size,)

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.continuation import sweep
        >>> sweep(seed_parameters(), "paper", [1e9, 1e13]).status_names().tolist()
        ['success', 'success']
        """
        names = np.array(drv.STATUSES + ("not computed",), dtype=object)
        return names[np.where(self.status < 0, len(drv.STATUSES), self.status)]

    def sticks_of(self, index: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stick times, depths and dwells of flat point ``index``, in time order.

        Parameters
        ----------
        index : int
            Flat (C order) point index.

        Returns
        -------
        t, delta, dwell : ndarray
            When each stick phase began (s), its indentation ``delta*`` (m) and its dwell (s; inf
            for a permanent stick); empty for a point without stick phases or not computed.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.continuation import sweep
        >>> t, delta, dwell = sweep(seed_parameters(), "paper", [1e9, 1e13]).sticks_of(0)
        >>> len(t), dwell.tolist()
        (1, [inf])
        """
        keep = self.stick_point == index
        order = np.argsort(self.stick_t[keep], kind="stable")
        return self.stick_t[keep][order], self.stick_delta[keep][order], self.stick_dwell[keep][order]

    def store(self, indices: np.ndarray, columns) -> None:
        """Put a chunk's :class:`~phaseimpact.integrate.Columns` at flat ``indices``.

        A point stored again (a recomputed failure) loses its old stick phases.

        Parameters
        ----------
        indices : array of int
            Flat (C order) indices of the chunk's points.
        columns : Columns
            Their runs, in the same order (:func:`~phaseimpact.simulate_many`).

        Examples
        --------
        >>> from phaseimpact import seed_parameters, simulate_many
        >>> from phaseimpact.continuation import Axis, Grid, SweepResult
        >>> from phaseimpact.model import as_law
        >>> grid = Grid(seed_parameters(), as_law("paper"), (Axis.make("kappa", [1e9, 1e12, 1e13]),))
        >>> r = SweepResult(grid, None, {"rtol": 1e-10})
        >>> r.store([0, 2], simulate_many([grid.parameters_at({"kappa": k}) for k in (1e9, 1e13)], "paper"))
        >>> r.outcome_names().tolist()
        ['permanent-stick', 'not computed', 'ratchet-escape']
        """
        indices = np.asarray(indices, dtype=np.int64)
        if np.any(self.status[indices] >= 0):  # a recomputed (failed) point replaces its old stick phases
            keep = ~np.isin(self.stick_point, indices)
            for name in _STICK_FIELDS:
                setattr(self, name, np.ascontiguousarray(getattr(self, name)[keep]))
        self.status[indices] = columns.status
        self.outcome[indices] = columns.outcome
        self.stop_reason[indices] = columns.stop_reason
        for name, values in columns.values.items():
            self.values[name][indices] = values
        new = (np.repeat(indices, columns.stick_count), columns.stick_t, columns.stick_delta, columns.stick_dwell)
        for name, part in zip(_STICK_FIELDS, new, strict=True):
            setattr(self, name, _append(getattr(self, name), part))

    def summary(self) -> dict:
        """Counts of outcomes and failures, for people.

        Returns
        -------
        dict
            ``{"points", "computed", "failed", "cut_by_horizon", "outcomes": {name: count}}``;
            outcome classes in alphabetical order, only those present.

        Examples
        --------
        >>> import numpy as np
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.continuation import sweep
        >>> sweep(seed_parameters(), "paper", np.geomspace(1e9, 1e14, 5)).summary()
        {'points': 5, 'computed': 5, 'failed': 0, 'cut_by_horizon': 0,
         'outcomes': {'permanent-stick': 3, 'ratchet-escape': 2}}
        """
        counts = np.bincount(self.outcome_indices(), minlength=len(OUTCOME_LABELS))
        return {"points": int(self.grid.size), "computed": int(np.count_nonzero(self.status >= 0)),
                "failed": int(np.count_nonzero(self.failed)), "cut_by_horizon": int(np.count_nonzero(self.cut)),
                "outcomes": {name: int(counts[i]) for i, name in sorted(enumerate(OUTCOME_LABELS), key=lambda x: x[1])
                             if counts[i]}}


_STICK_FIELDS = ("stick_point", "stick_t", "stick_delta", "stick_dwell")


def _append(array: np.ndarray, part: np.ndarray) -> np.ndarray:
    """``array`` followed by ``part``, in a buffer grown geometrically: appending chunk after chunk
    costs time proportional to the data, not to the number of chunks times the data. The factor
    1.5 (not 2) keeps the spare capacity, and the peak while a buffer is copied, small (a 1e6-point
    atlas holds 1.6 million stick points, 52 MB)."""
    n, m = len(array), len(part)
    base = array.base if isinstance(array.base, np.ndarray) and array.base.ndim == 1 else None
    if base is not None and base.dtype == array.dtype and len(base) >= n + m \
            and array.__array_interface__["data"][0] == base.__array_interface__["data"][0]:
        buffer = base
    else:
        buffer = np.empty(max((3 * (n + m)) // 2, 1024), dtype=array.dtype)
        buffer[:n] = array
    buffer[n:n + m] = part
    return buffer[:n + m]


def _axes_text(grid: Grid) -> str:
    # repr digits: axes that differ in the 16th digit must not print alike
    return ", ".join(f"{a.name} {len(a.values)} values {float(a.values[0])!r}..{float(a.values[-1])!r}"
                     for a in grid.axes)


def _check_previous(previous, grid: Grid, t_end, rtol) -> None:
    if not isinstance(previous, SweepResult):
        raise TypeError(f"previous = {previous!r} has the wrong type ({type(previous).__name__}); allowed: a "
                        "SweepResult (an earlier result, or archive.load of its checkpoint) or None")
    same_axes = previous.grid.names == grid.names and all(
        np.array_equal(a.values, b.values) for a, b in zip(previous.grid.axes, grid.axes, strict=True))
    if not same_axes:
        raise ValueError(f"resume: the archive's axes ({_axes_text(previous.grid)}) differ from the requested ones "
                         f"({_axes_text(grid)})")
    if previous.grid.law != grid.law:
        raise ValueError(f"resume: the archive was computed with law {previous.grid.law.label()!r}, "
                         f"asked: {grid.law.label()!r}")
    if previous.t_end != t_end or previous.settings.get("rtol") != rtol:
        raise ValueError(f"resume: the archive was computed with t_end = {previous.t_end!r}, rtol = "
                         f"{previous.settings.get('rtol')!r}; asked: t_end = {t_end!r}, rtol = {rtol!r} (t_end None: "
                         "each run until its outcome settles)")


def atlas(base: Parameters | Case, law: ContactLaw | str, axes, *, t_end: float | None = None, rtol: float = 1e-10,
          n_jobs: int = 1, backend: str = "threads", scheduler=None, progress: bool = False,
          previous: SweepResult | None = None,
          on_chunk: Callable[[SweepResult], None] | None = None) -> SweepResult:
    """Evaluate every point of a grid of named parameters (an atlas).

    Every argument and every axis (:class:`~phaseimpact.continuation.grid.Grid`) is checked before
    any work. Each point runs until its outcome settles (or to ``t_end``) on the compiled driver,
    chunk by chunk; a point whose run fails numerically is stored with its status (never raised)
    and recomputed when the result is completed through ``previous``.

    Parameters
    ----------
    base : Parameters or Case
        The case the axes vary (a :class:`~phaseimpact.case.Case` allows material and geometry
        axes such as ``plate.E`` or ``R1``).
    law : ContactLaw or str
        The law of every point, or its name.
    axes : sequence of Axis, or dict name -> values
        E.g. ``{"kappa": np.geomspace(1e10, 1e14, 400), "v": np.linspace(0.5, 13, 300)}``
        (``kappa`` in N s/m^(1+alpha), ``v`` in m/s); at most ``MAX_POINTS`` points in all.
    t_end : float, optional
        Horizon of every run, s; default: until the outcome settles (capped by the case's scales).
    rtol : float, default 1e-10
        Integrator tolerance, within :data:`~phaseimpact.integrate.RTOL_RANGE`.
    n_jobs : int, default 1
        Workers: an integer from 1 to 4 times the CPU count, or -1 for all cores.
    backend : {"threads", "loky", "dask", "cuda"}, default "threads"
        Threads of this process (``threads``), joblib processes (``loky``), a Dask cluster
        (``dask``, at ``scheduler`` or a local one) or a GPU (``cuda``: one thread per point;
        refused before any work for a user law or without a usable GPU).
    scheduler : str or dask.distributed.Client, optional
        ``dask`` only: a scheduler's address (``tcp://host:8786``), or a ``Client`` you hold (left
        open); default an in-process local cluster. ``n_jobs`` is then the number of tasks in
        flight (-1: every thread of the cluster's workers), and each worker loads or compiles the
        engine once before the first chunk.
    progress : bool, default False
        Draw a progress bar on stderr.
    previous : SweepResult, optional
        A partial result of the same grid (axes, law, ``t_end`` and ``rtol``) to complete: its
        points not computed or failed are run, and it is filled in place and returned.
    on_chunk : callable, optional
        Called with the partial result after each chunk (checkpoints, e.g.
        :class:`phaseimpact.archive.Checkpoint`).

    Returns
    -------
    SweepResult
        Every point's status, outcome, summary columns and stick phases.

    Raises
    ------
    TypeError
        For ``axes`` not a dict or a list of Axis, ``base`` not Parameters or a Case, ``previous``
        not a SweepResult, or ``on_chunk`` not callable.
    ValueError
        For an axis out of range (:class:`~phaseimpact.continuation.grid.Grid`), ``t_end``,
        ``rtol``, ``n_jobs``, ``backend``, ``scheduler`` or ``progress`` out of range, or a
        ``previous`` computed for other work.
    KeyboardInterrupt
        Ctrl-C or SIGTERM; the chunks stored so far stay in the result (and its checkpoint).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import atlas
    >>> a = atlas(seed_parameters(), "paper", {"kappa": [1e11, 1e12, 1e13], "v": [0.5, 2.0]})
    >>> a.shape, a.summary()["outcomes"]
    ((3, 2), {'permanent-stick': 3, 'ratchet-escape': 3})

    Material and geometry axes need a case:

    >>> from phaseimpact.case import load_case
    >>> a = atlas(load_case("seed"), "paper", {"plate.E": [7e10, 2.1e11], "kappa": [1e9, 1e13]})
    >>> a.outcome_names().reshape(a.shape).tolist()
    [['permanent-stick', 'ratchet-escape'], ['permanent-stick', 'ratchet-escape']]
    """
    law = as_law(law)
    if isinstance(axes, dict):
        axes = [Axis.make(k, v) for k, v in axes.items()]
    elif isinstance(axes, str) or not isinstance(axes, list | tuple):
        raise TypeError(f"axes = {axes!r} has the wrong type ({type(axes).__name__}); allowed: a dict name -> values, "
                        "or a list of Axis (parse_axis('kappa=1e9:1e12:50:log') makes one from text)")
    grid = Grid(base, law, tuple(axes))
    rtol = check_rtol(rtol)
    if t_end is not None:
        t_end = check_t_end(t_end, scales(grid.base_parameters()).contact_time)
    jobs = check_jobs(n_jobs, backend, scheduler, law)
    check_bool("progress", progress)
    if on_chunk is not None and not callable(on_chunk):
        raise TypeError(f"on_chunk = {on_chunk!r} has the wrong type ({type(on_chunk).__name__}); allowed: a "
                        "function of the partial result, or None")
    if previous is not None:
        _check_previous(previous, grid, t_end, rtol)
        result = previous
    else:
        result = SweepResult(grid, t_end, {"rtol": rtol, "engine": ENGINE, "version": __version__})
    todo = np.flatnonzero(result.status != drv.SUCCESS)
    if backend == "threads":
        chunk = CHUNK_THREADS
    elif backend == "cuda":  # a launch fills the GPU's threads: as many points as fit its memory at once
        chunk = CHUNK_CUDA
    else:  # four chunks per worker thread (Dask: per task in flight, from the cluster's size for -1)
        jobs = tasks_in_flight(jobs, scheduler) if backend == "dask" else jobs
        chunk = int(np.clip(math.ceil(len(todo) / (4 * jobs)), CHUNK_MIN, CHUNK_MAX))
    chunks = [todo[i:i + chunk] for i in range(0, len(todo), chunk)]
    batches = (grid.batch(idx, t_end, rtol) for idx in chunks)
    bar = tqdm(total=len(todo), desc=f"{'sweep' if len(grid.axes) == 1 else 'atlas'} {law.name}", unit="pt",
               disable=not progress)
    try:
        for idx, columns in zip(chunks, run_chunks(batches, rtol=rtol, settle=True, stop_on=None, n_jobs=jobs,
                                                   backend=backend, scheduler=scheduler), strict=True):
            result.store(idx, columns)
            bar.update(len(idx))
            if on_chunk is not None:
                on_chunk(result)
    finally:
        bar.close()
    return result


def sweep(params: Parameters | Case, law: ContactLaw | str, kappas, **options) -> SweepResult:
    """:func:`atlas` over ``kappa`` alone (N s/m^(1+alpha)), e.g. ``np.geomspace(1e8, 1e13, 2000)``:
    distinct numbers in ``[0, KAPPA_MAX]``.

    Parameters
    ----------
    params : Parameters or Case
        The base case.
    law : ContactLaw or str
        A law that reads ``kappa`` (``paper``, ``hunt-crossley``...).
    kappas : sequence or ndarray of float
        The damping values, N s/m^(1+alpha) (N s/m^2.5 for alpha = 3/2).
    **options
        ``t_end``, ``rtol``, ``n_jobs``, ``backend``, ``scheduler``, ``progress``, ``previous``,
        ``on_chunk``: as for :func:`atlas`.

    Returns
    -------
    SweepResult
        One axis, ``kappa``.

    Raises
    ------
    TypeError, ValueError
        As for :func:`atlas`; ``ValueError`` also for a law that does not read ``kappa``.

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import sweep
    >>> s = sweep(seed_parameters(v=1.0), "paper", np.geomspace(1e9, 1e14, 5))
    >>> s.summary()["outcomes"], int(s.failed.sum())
    ({'permanent-stick': 3, 'ratchet-escape': 2}, 0)

    A partial result is completed through ``previous`` (its points already done are kept):

    >>> from phaseimpact.continuation import sweep
    >>> part = sweep(seed_parameters(), "paper", [1e9, 1e13])
    >>> sweep(seed_parameters(), "paper", [1e9, 1e13], previous=part) is part
    True
    """
    return atlas(params, law, [Axis.make("kappa", kappas)], **options)
