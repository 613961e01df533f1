"""Continuation over the damping ``kappa``: sweeps, the critical damping and ``kappa_c(v)``.

This is the only layer that knows about joblib. A sweep is split into chunks of points, each
advanced by the batched integrator, whose result for a point is bit-identical whatever batch it
runs in: results are identical for any ``n_jobs``, chunking and backend. ``backend="dask"`` runs the same chunks on a
``dask.distributed`` cluster through joblib's Dask backend.

The critical damping (REFERENCE §5) is the smallest ``kappa`` at which the number of
asymptotic points of the trajectory changes from one to two. :func:`critical_damping`
brackets it on a coarse log grid, refines the bracket (Brent's method on a smooth indicator
where the law has one, else bisection on the count) and re-checks it at a tighter
integration tolerance.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field

import joblib
import numpy as np
from scipy.optimize import brentq
from tqdm.auto import tqdm

from .analysis import classify_outcome, find_asymptotic_points
from .integrate import simulate, simulate_batch
from .integrate._events import stick_margin
from .model import ContactLaw, as_law, coefficients
from .parameters import Parameters
from .quantities import impact_quantities

__all__ = [
    "PointResult",
    "SweepResult",
    "CriticalDamping",
    "CriticalCurve",
    "evaluate_point",
    "count_up_to",
    "sweep",
    "locate_transition",
    "critical_damping",
    "critical_curve",
    "phase_portrait",
    "BACKENDS",
]

BACKENDS = ("loky", "dask")
#: Points per task (advanced as one batch): about four tasks per worker, within these bounds.
#: A member's result is bit-identical whatever batch it runs in, so chunking changes no number.
CHUNK_MIN, CHUNK_MAX = 16, 256


@dataclass(frozen=True)
class PointResult:
    """What a sweep keeps of one ``kappa``: counts, points, outcome and the scene's quantities."""

    kappa: float
    n_asymptotic: int
    points: np.ndarray  # (k, 2): (delta, deltadot), m and m/s
    dwell: np.ndarray  # (k,), s
    outcome: str
    status: str
    message: str
    max_force: float
    max_indentation: float
    restitution: float | None
    dissipated_energy: float


def evaluate_point(params: Parameters, law: ContactLaw, t_end: float, *, rtol: float = 1e-10,
                   min_dwell: float | None = None) -> PointResult:
    """Integrate one point (exact, summary only, stopping once settled) and summarise it.

    Numerical trouble is a status of the point (``runaway``, ``step-size-collapse``...), and an
    unexpected error in one point is recorded as status ``error`` with outcome ``failed``, so
    a long sweep always carries on.
    """
    try:
        trajectory = simulate(params, law, t_end, rtol=rtol)
    except (ArithmeticError, RuntimeError, ValueError) as error:
        return _failed_point(params.kappa, error)
    return summarise_point(trajectory, min_dwell)


def summarise_point(trajectory, min_dwell: float | None = None) -> PointResult:
    """What a sweep keeps of one trajectory."""
    points = find_asymptotic_points(trajectory, min_dwell=min_dwell)
    outcome = classify_outcome(trajectory, points)
    q = impact_quantities(trajectory)
    return PointResult(
        kappa=trajectory.params.kappa, n_asymptotic=len(points), points=points.points, dwell=points.dwell,
        outcome=outcome.kind, status=trajectory.status, message=trajectory.message,
        max_force=q.max_force, max_indentation=q.max_indentation, restitution=q.restitution,
        dissipated_energy=q.dissipated_energy,
    )


def _failed_point(kappa, error) -> PointResult:
    return PointResult(kappa, 0, np.empty((0, 2)), np.empty(0), "failed", "error",
                       f"{type(error).__name__}: {error}", np.nan, np.nan, None, np.nan)


def _evaluate_chunk(params, law, kappas, t_end, rtol, min_dwell):
    """One task of a sweep: the chunk's points advanced together by :func:`simulate_batch`.

    A member's result does not depend on the batch it runs in, so chunking (and therefore
    ``n_jobs``) cannot change any number.
    """
    members = [params.replace(kappa=float(k)) for k in kappas]
    try:
        trajectories = simulate_batch(members, law, t_end, rtol=rtol)
    except (ArithmeticError, RuntimeError, ValueError):
        return [evaluate_point(p, law, t_end, rtol=rtol, min_dwell=min_dwell) for p in members]
    return [summarise_point(tr, min_dwell) for tr in trajectories]


@dataclass
class SweepResult:
    """A sweep over ``kappa``; ``n_asymptotic == -1`` marks a point not yet computed.

    Attributes
    ----------
    kappa : ndarray (n,)
        Damping values, N s/m^(1+alpha).
    n_asymptotic : ndarray of int (n,)
        Number of asymptotic points in ``(delta, deltadot)``, or -1.
    outcome, status : ndarray of str (n,)
        :data:`phaseimpact.analysis.OUTCOMES` and trajectory status ("" if not computed).
    max_force, max_indentation, restitution, dissipated_energy : ndarray (n,)
        N, m, -, J (NaN only where not computed or undefined; the archive documents this).
    points, dwell : list of ndarray
        Per point, the asymptotic points ``(k, 2)`` and their dwell times ``(k,)``.
    params, law, t_end, settings
        What was swept and how (``rtol``, ``min_dwell``).
    """

    kappa: np.ndarray
    params: Parameters
    law: ContactLaw
    t_end: float
    settings: dict
    n_asymptotic: np.ndarray = None
    outcome: np.ndarray = None
    status: np.ndarray = None
    max_force: np.ndarray = None
    max_indentation: np.ndarray = None
    restitution: np.ndarray = None
    dissipated_energy: np.ndarray = None
    points: list = field(default=None)
    dwell: list = field(default=None)
    critical: CriticalDamping | None = None

    def __post_init__(self):
        n = len(self.kappa)
        self.kappa = np.asarray(self.kappa, dtype=float)
        defaults = {
            "n_asymptotic": np.full(n, -1, dtype=int), "outcome": np.full(n, "", dtype=object),
            "status": np.full(n, "", dtype=object), "max_force": np.full(n, np.nan),
            "max_indentation": np.full(n, np.nan), "restitution": np.full(n, np.nan),
            "dissipated_energy": np.full(n, np.nan),
        }
        for name, value in defaults.items():
            if getattr(self, name) is None:
                setattr(self, name, value)
        if self.points is None:
            self.points = [np.empty((0, 2)) for _ in range(n)]
        if self.dwell is None:
            self.dwell = [np.empty(0) for _ in range(n)]

    @property
    def done(self) -> np.ndarray:
        return self.n_asymptotic >= 0

    def store(self, index: int, point: PointResult) -> None:
        self.n_asymptotic[index] = point.n_asymptotic
        self.outcome[index] = point.outcome
        self.status[index] = point.status
        self.max_force[index] = point.max_force
        self.max_indentation[index] = point.max_indentation
        self.restitution[index] = np.nan if point.restitution is None else point.restitution
        self.dissipated_energy[index] = point.dissipated_energy
        self.points[index] = point.points
        self.dwell[index] = point.dwell

    def first_split(self) -> int | None:
        """Index ``i`` of the first change of the count from 1 (at ``i``) to 2 or more (at ``i + 1``)."""
        n = self.n_asymptotic
        hits = np.flatnonzero((n[:-1] == 1) & (n[1:] >= 2))
        return int(hits[0]) if hits.size else None


def _check_kappas(kappas) -> np.ndarray:
    kappas = np.asarray(kappas, dtype=float)
    if kappas.ndim != 1 or kappas.size == 0 or not np.all(np.isfinite(kappas)) or np.any(kappas < 0):
        raise ValueError("kappa values are out of range; allowed: a non-empty 1-d array of finite numbers >= 0")
    return kappas


def _parallel(n_jobs: int, backend: str, scheduler: str | None):
    """A joblib ``Parallel`` and the context it must run in, for ``backend``."""
    if backend not in BACKENDS:
        raise ValueError(f"backend = {backend!r} is out of range; allowed: one of {', '.join(BACKENDS)}")
    if not (isinstance(n_jobs, int) and (n_jobs >= 1 or n_jobs == -1)):
        raise ValueError(f"jobs = {n_jobs!r} is out of range; allowed: an integer >= 1, or -1 for all cores")
    if backend == "loky":
        return joblib.Parallel(n_jobs=n_jobs, return_as="generator"), None
    try:
        from dask.distributed import Client
    except ImportError as error:  # pragma: no cover - depends on the install
        raise ValueError("backend = 'dask' needs dask.distributed: pip install 'phaseimpact[dask]'") from error
    client = Client(scheduler) if scheduler else Client(processes=False, n_workers=1, threads_per_worker=n_jobs)
    return joblib.Parallel(n_jobs=-1, return_as="generator"), client


def sweep(params: Parameters, law: ContactLaw | str, kappas, *, t_end: float = 0.01, n_jobs: int = 1,
          backend: str = "loky", scheduler: str | None = None, rtol: float = 1e-10,
          min_dwell: float | None = None, progress: bool = False, previous: SweepResult | None = None,
          on_chunk: Callable[[SweepResult], None] | None = None) -> SweepResult:
    """Evaluate every ``kappa`` (see :func:`evaluate_point`); joblib runs chunks in parallel.

    Parameters
    ----------
    params : Parameters
        Base parameters (its ``kappa`` is replaced by each value).
    law : ContactLaw or str
    kappas : array_like
        Damping values (N s/m^(1+alpha)); e.g. ``np.logspace(9, 14, 200)``.
    t_end : float
        Horizon of each run, s.
    n_jobs, backend, scheduler
        joblib workers; ``"dask"`` with a scheduler address (``"tcp://host:8786"``) runs on a
        cluster (without an address, on an in-process local cluster).
    previous : SweepResult, optional
        A partial sweep of the same ``kappas`` to resume: its finished points are kept.
    on_chunk : callable, optional
        Called with the partial result after each chunk (for checkpoints).
    """
    law = as_law(law)
    kappas = _check_kappas(kappas)
    settings = {"rtol": rtol, "min_dwell": -1.0 if min_dwell is None else min_dwell,
                "integrator": "batch[DOP853]"}
    if previous is not None:
        if previous.kappa.shape != kappas.shape or not np.array_equal(previous.kappa, kappas):
            raise ValueError("resume: the archive's kappa values differ from the requested sweep")
        if previous.t_end != t_end or previous.settings.get("rtol") != rtol:
            raise ValueError(f"resume: the archive was computed with t_end = {previous.t_end!r}, "
                             f"rtol = {previous.settings.get('rtol')!r}; asked: t_end = {t_end!r}, rtol = {rtol!r}")
        result = previous
    else:
        result = SweepResult(kappas, params, law, t_end, settings)
    todo = np.flatnonzero(~result.done)
    workers = (os.cpu_count() or 1) if n_jobs == -1 or backend == "dask" else n_jobs
    chunk = int(np.clip(math.ceil(len(todo) / (4 * workers)), CHUNK_MIN, CHUNK_MAX))
    chunks = [todo[i:i + chunk] for i in range(0, len(todo), chunk)]
    if not chunks:
        return result
    parallel, client = _parallel(n_jobs, backend, scheduler)
    tasks = (joblib.delayed(_evaluate_chunk)(params, law, kappas[idx], t_end, rtol, min_dwell) for idx in chunks)
    bar = tqdm(total=len(todo), desc=f"sweep {law.name}", unit="pt", disable=not progress)
    try:
        context = joblib.parallel_config(backend="dask") if client is not None else contextlib.nullcontext()
        with context:
            for idx, points in zip(chunks, parallel(tasks), strict=False):
                for i, point in zip(idx, points, strict=False):
                    result.store(int(i), point)
                bar.update(len(idx))
                if on_chunk is not None:
                    on_chunk(result)
    finally:
        bar.close()
        if client is not None:
            client.close()
    return result


@dataclass(frozen=True)
class Transition:
    """Where a count changes from ``below`` to ``above`` between ``lo`` and ``hi``."""

    value: float
    lo: float
    hi: float
    n_below: int
    n_above: int
    evaluations: int
    method: str


def locate_transition(count: Callable[[float], int], lo: float, hi: float, *, rtol: float = 1e-6,
                      indicator: Callable[[float], float] | None = None, log: bool = True,
                      below: int = 1) -> Transition:
    """Narrow ``[lo, hi]`` (``count(lo) == below``, ``count(hi) > below``) to relative width ``rtol``.

    With an ``indicator`` (continuous, >= 0 where the count is ``below``, < 0 beyond) Brent's
    method finds its zero, and the counts on both sides of it confirm it; otherwise, or if
    they do not, bisection on ``count`` (in ``log`` space if asked).
    """
    evaluations = 0
    if indicator is not None:
        def g(s):
            nonlocal evaluations
            evaluations += 1
            return indicator(math.exp(s) if log else s)

        a, b = (math.log(lo), math.log(hi)) if log else (lo, hi)
        try:
            root = brentq(g, a, b, xtol=rtol / 8, rtol=4 * np.finfo(float).eps, maxiter=200)
            root = math.exp(root) if log else root
            half = 0.5 * rtol * abs(root)
            n_lo, n_hi = count(root - half), count(root + half)
            evaluations += 2
            if n_lo == below and n_hi > below:
                return Transition(root, root - half, root + half, n_lo, n_hi, evaluations, "brent")
        except ValueError:
            pass
    n_lo, n_hi = below, None
    while (hi - lo) > rtol * abs(hi):
        mid = math.sqrt(lo * hi) if log and lo > 0 else 0.5 * (lo + hi)
        n_mid = count(mid)
        evaluations += 1
        if n_mid == below:
            lo = mid
        else:
            hi, n_hi = mid, n_mid
    if n_hi is None:
        n_hi = count(hi)
        evaluations += 1
    return Transition(math.sqrt(lo * hi) if log and lo > 0 else 0.5 * (lo + hi), lo, hi, n_lo, n_hi,
                      evaluations, "bisection")


@dataclass(frozen=True)
class CriticalDamping:
    """The critical damping of one law at one speed (REFERENCE §5).

    Attributes
    ----------
    kappa_c : float or None
        N s/m^(1+alpha); None if no split was found.
    bracket : tuple of float
        ``kappa`` with one asymptotic point, and with two.
    n_below, n_above : int
        Counts at the bracket ends.
    rtol : float
        Relative width asked for.
    shift : float or None
        Relative change of ``kappa_c`` when recomputed at ``check_rtol``.
    status : {"success", "not-found", "unconfirmed"}
    message : str
    """

    law: str
    v: float
    kappa_c: float | None
    bracket: tuple
    n_below: int
    n_above: int
    rtol: float
    shift: float | None
    status: str
    message: str
    evaluations: int

    def as_dict(self) -> dict:
        return {"law": self.law, "v": self.v, "kappa_c": self.kappa_c, "bracket": list(self.bracket),
                "rtol": self.rtol, "n_below": self.n_below, "n_above": self.n_above,
                "shift": self.shift, "status": self.status, "message": self.message}


def count_up_to(params: Parameters, law: ContactLaw, t_end: float, enough: int, *, rtol: float = 1e-10,
                min_dwell: float | None = None) -> int:
    """Number of asymptotic points, counted only up to ``enough`` (a scene that asks "one, or more?").

    The run stops at the ``enough``-th stick; that stick counts if it lasts ``min_dwell`` (checked by
    continuing from its state for that long), otherwise the full run decides. Equal to
    ``min(evaluate_point(...).n_asymptotic, enough)``, at a fraction of the cost above ``kappa_c``.
    """
    if not law.is_filippov:
        return min(evaluate_point(params, law, t_end, rtol=rtol, min_dwell=min_dwell).n_asymptotic, enough)
    trajectory = simulate(params, law, t_end, rtol=rtol, stop_on={"stick": enough}, stop_when_settled=True)
    points = find_asymptotic_points(trajectory, min_dwell=min_dwell)
    sticks = trajectory.events_of("stick")
    stopped_at_last = (trajectory.ok and not trajectory.settled and len(sticks) == enough
                       and trajectory.t_stop < trajectory.t_end)
    if not stopped_at_last:
        return min(len(points), enough)
    last = sticks[-1]
    tail_time = min(points.min_dwell, t_end - last.t)
    if tail_time <= 0:
        return min(len(points), enough)
    tail = simulate(params, law, tail_time, rtol=rtol, initial=last.state[:4], stop_on=("slip",))
    if tail.events_of("slip"):  # too short a stick to count: let the whole run decide
        return min(evaluate_point(params, law, t_end, rtol=rtol, min_dwell=min_dwell).n_asymptotic, enough)
    return min(len(points), enough)


def _first_stick_margin(params, law, t_end, rtol):
    """Relative stick margin of the first stick (``paper``): >= 0 iff it never breaks."""
    trajectory = simulate(params, law, t_end, rtol=rtol, stop_on=("stick",), stop_when_settled=False)
    sticks = trajectory.events_of("stick")
    if not sticks:
        return -1.0
    return stick_margin(sticks[0].state, coefficients(params, law))


def critical_damping(params: Parameters, law: ContactLaw | str = "paper", *, kappa_min: float = 1e8,
                     kappa_max: float = 1e15, num: int = 29, rtol: float = 1e-6, t_end: float = 0.01,
                     integrator_rtol: float = 1e-10, check_rtol: float | None = 1e-12,
                     min_dwell: float | None = None, n_jobs: int = 1, bracket: tuple | None = None,
                     ) -> CriticalDamping:
    """Locate ``kappa_c`` where the count of asymptotic points first goes from 1 to 2.

    A log grid of ``num`` values in ``[kappa_min, kappa_max]`` (or a given ``bracket``) gives
    the first bracket; it is refined to relative width ``rtol`` (for ``paper``, Brent's method
    on the first stick's margin, confirmed by the counts either side; else bisection); then
    the refinement is repeated at ``check_rtol`` and the relative ``shift`` reported.
    """
    law = as_law(law)
    if not (0 < kappa_min < kappa_max and math.isfinite(kappa_max)):
        raise ValueError(f"kappa_min = {kappa_min!r}, kappa_max = {kappa_max!r} are out of range; "
                         "allowed: 0 < kappa_min < kappa_max")
    if not (1e-12 <= rtol < 1):
        raise ValueError(f"rtol = {rtol!r} is out of range; allowed: 1e-12 <= rtol < 1")

    evaluations = 0
    if bracket is None:
        grid = sweep(params, law, np.geomspace(kappa_min, kappa_max, num), t_end=t_end, n_jobs=n_jobs,
                     rtol=integrator_rtol, min_dwell=min_dwell)
        evaluations += num
        i = grid.first_split()
        if i is None:
            counts = ", ".join(f"{k:.3g}:{n}" for k, n in zip(grid.kappa, grid.n_asymptotic, strict=False))
            return CriticalDamping(law.name, params.v, None, (kappa_min, kappa_max), -1, -1, rtol, None,
                                   "not-found", f"no change of the count from 1 to 2 on the grid ({counts})",
                                   evaluations)
        bracket = (float(grid.kappa[i]), float(grid.kappa[i + 1]))

    def refine(tolerance):
        def count(kappa):
            return count_up_to(params.replace(kappa=kappa), law, t_end, 2, rtol=tolerance, min_dwell=min_dwell)

        indicator = None
        if law.is_filippov:
            def indicator(kappa):
                return _first_stick_margin(params.replace(kappa=kappa), law, t_end, tolerance)
        return locate_transition(count, *bracket, rtol=rtol, indicator=indicator)

    found = refine(integrator_rtol)
    if check_rtol is None:  # the caller skips the re-check (no protection against artefacts)
        ok = found.n_below == 1 and found.n_above >= 2
        message = f"kappa_c located by {found.method}; not re-checked at a tighter tolerance"
        return CriticalDamping(law.name, params.v, found.value, (found.lo, found.hi), found.n_below,
                               found.n_above, rtol, None, "success" if ok else "unconfirmed", message,
                               evaluations + found.evaluations)
    check = refine(check_rtol)
    evaluations += found.evaluations + check.evaluations
    shift = abs(check.value - found.value) / found.value
    ok = found.n_below == 1 and found.n_above >= 2 and check.n_below == 1 and check.n_above >= 2
    status = "success" if ok and shift <= max(rtol, 10 * check_rtol) else "unconfirmed"
    message = (f"kappa_c located by {found.method}; at rtol {check_rtol:g} it moves by {shift:.2e} (relative)"
               + ("" if ok else f"; counts below/above: {found.n_below}/{found.n_above} and "
                                f"{check.n_below}/{check.n_above} at the tighter tolerance"))
    return CriticalDamping(law.name, params.v, found.value, (found.lo, found.hi), found.n_below,
                           found.n_above, rtol, shift, status, message, evaluations)


@dataclass(frozen=True)
class CriticalCurve:
    """``kappa_c`` against the impact speed ``v`` (the two-parameter view)."""

    v: np.ndarray
    results: tuple  # CriticalDamping per v

    @property
    def kappa_c(self) -> np.ndarray:
        return np.array([np.nan if r.kappa_c is None else r.kappa_c for r in self.results])


def critical_curve(params: Parameters, law: ContactLaw | str, speeds, *, rtol: float = 1e-6,
                   t_end: float = 0.01, progress: bool = False, **options) -> CriticalCurve:
    """Continue ``kappa_c`` in ``v``: each point's bracket is searched around the previous ``kappa_c``."""
    law = as_law(law)
    speeds = np.asarray(speeds, dtype=float)
    if speeds.ndim != 1 or speeds.size == 0 or not np.all(np.isfinite(speeds) & (speeds > 0)):
        raise ValueError("speeds are out of range; allowed: a non-empty 1-d array of finite numbers > 0")
    results = []
    previous = None
    for v in tqdm(speeds, desc=f"kappa_c(v) {law.name}", unit="v", disable=not progress):
        p = params.replace(v=float(v))
        bracket = _bracket_near(p, law, previous, t_end, options) if previous else None
        result = critical_damping(p, law, rtol=rtol, t_end=t_end, bracket=bracket, **options)
        results.append(result)
        previous = result.kappa_c or previous
    return CriticalCurve(speeds, tuple(results))


def _bracket_near(params, law, kappa, t_end, options, factor=2.0, tries=8):
    """A bracket (count 1, count 2) around ``kappa``, widened geometrically; None if not found."""
    def count(k):
        return evaluate_point(params.replace(kappa=k), law, t_end, rtol=options.get("integrator_rtol", 1e-10),
                              min_dwell=options.get("min_dwell")).n_asymptotic

    lo, hi = kappa / factor, kappa * factor
    for _ in range(tries):
        n_lo, n_hi = count(lo), count(hi)
        if n_lo == 1 and n_hi == 2:
            return lo, hi
        if n_lo != 1:
            lo /= factor
        if n_hi != 2:
            hi *= factor
    return None


def phase_portrait(params: Parameters, law: ContactLaw | str, *, speeds=None, states=None,
                   t_end: float = 0.01, save=None, n_jobs: int = 1, rtol: float = 1e-10) -> list:
    """A family of trajectories, one parallel call, ready to plot in any plane.

    Give ``speeds`` (impact speeds, seed eq. 6 each) or ``states`` (rows
    ``(x1, x2, x1dot, x2dot)``; a grid in a plane is such a set). Each trajectory keeps its
    steps (or the times in ``save``) and its events, so ``plane_coordinates(tr.y, plane)``
    and ``tr.events`` draw it in ``(delta, deltadot)``, ``(x1, x1dot)`` or ``(x2, x2dot)``.
    """
    law = as_law(law)
    if (speeds is None) == (states is None):
        raise ValueError("give exactly one of speeds= or states=")
    save = "steps" if save is None else save
    if speeds is not None:
        jobs = [joblib.delayed(simulate)(params.replace(v=float(v)), law, t_end, save=save, rtol=rtol)
                for v in np.atleast_1d(speeds)]
    else:
        states = np.atleast_2d(np.asarray(states, dtype=float))
        if states.shape[1] != 4 or not np.all(np.isfinite(states)):
            raise ValueError("states are out of range; allowed: finite rows (x1, x2, x1dot, x2dot)")
        jobs = [joblib.delayed(simulate)(params, law, t_end, save=save, rtol=rtol, initial=s) for s in states]
    return list(joblib.Parallel(n_jobs=n_jobs)(jobs))
