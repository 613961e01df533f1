"""Basins of attraction of a two-dimensional map over a grid of its initial state (the model's
impact map: :func:`~phaseimpact.maps.impact_analyses.basins`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..parameters import is_number
from .base import ImpactMap, check_count

__all__ = ["Attractor", "Basins", "find_basins", "NOT_CONVERGED", "NO_MAP", "ATTRACTOR_MATCH"]

#: Two attractors are one when their points agree within this fraction of the state's scales.
ATTRACTOR_MATCH = 1e-3


@dataclass(frozen=True)
class Attractor:
    """A periodic attractor of a map found by :func:`find_basins`.

    Attributes
    ----------
    plate : ndarray, shape (period, 2)
        The orbit's states (the plate's ``(x2, x2dot)`` before each of its impacts, m and m/s),
        beginning with the smallest first coordinate.
    period : int
        Steps per repetition.
    count : int
        Initial states of the grid that go to it.

    Examples
    --------
    >>> import numpy as np
    >>> Attractor(np.zeros((1, 2)), 1, 9).as_dict()["period"]
    1
    """

    plate: np.ndarray
    period: int
    count: int

    def as_dict(self) -> dict:
        """The attractor as JSON-ready lists.

        Returns
        -------
        dict
            ``plate``, ``period``, ``count``.

        Examples
        --------
        >>> import numpy as np
        >>> Attractor(np.zeros((2, 2)), 2, 3).as_dict()["plate"]
        [[0.0, 0.0], [0.0, 0.0]]
        """
        return {"plate": self.plate.tolist(), "period": self.period, "count": self.count}


@dataclass(frozen=True)
class Basins:
    """The basins of attraction of a two-dimensional map over a grid of its initial state (the plate's
    for the impact map).

    Attributes
    ----------
    period : float
        Time between arrivals, s (NaN for a map other than the impact map).
    x2_values, x2dot_values : ndarray, shapes (nx,), (ny,)
        The grid's first and second coordinates (the plate's initial positions, m, and velocities, m/s).
    labels : ndarray of int, shape (ny, nx)
        At ``[i, j]`` (velocity ``x2dot_values[i]``, position ``x2_values[j]``) the index of the
        attractor the train from that state goes to; :data:`NOT_CONVERGED` (-1) where no period up to
        ``max_period`` repeated within ``iterations`` impacts (an irregular attractor, a longer period,
        or a slow approach), :data:`NO_MAP` (-2) where a run failed.
    impacts : ndarray of int, shape (ny, nx)
        Steps until the orbit repeated (``iterations`` where it did not).
    attractors : list of Attractor
        In the order first met on the grid (rows of ``labels`` then columns).
    not_converged, no_map : int
        Initial states labelled -1 and -2.

    Examples
    --------
    See :func:`find_basins`.

    >>> Basins.__dataclass_fields__["labels"].type
    'np.ndarray'
    """

    period: float
    x2_values: np.ndarray
    x2dot_values: np.ndarray
    labels: np.ndarray
    impacts: np.ndarray
    attractors: list
    not_converged: int
    no_map: int

    def as_dict(self) -> dict:
        """The basins as JSON-ready lists.

        Returns
        -------
        dict
            The attributes; ``attractors`` as :meth:`Attractor.as_dict` each.

        Examples
        --------
        >>> import numpy as np
        >>> b = Basins(1e-3, np.zeros(1), np.zeros(1), np.zeros((1, 1), int), np.ones((1, 1), int), [], 0, 0)
        >>> b.as_dict()["labels"]
        [[0]]
        """
        return {"period": self.period, "x2_values": self.x2_values.tolist(),
                "x2dot_values": self.x2dot_values.tolist(), "labels": self.labels.tolist(),
                "impacts": self.impacts.tolist(), "attractors": [a.as_dict() for a in self.attractors],
                "not_converged": self.not_converged, "no_map": self.no_map}


#: Labels of :class:`Basins` for initial states that reach no periodic attractor.
NOT_CONVERGED, NO_MAP = -1, -2


def _settle(imap, z, iterations, max_period, tol):
    """Iterate from ``z`` until a cycle of period ``p <= max_period`` repeats within ``tol`` of the
    state's scales: ``(cycle (p, 2) or None, steps, label if none)``."""
    scale = np.asarray(imap.scale, dtype=float)
    history = [np.asarray(z, dtype=float)]
    for n in range(1, iterations + 1):
        z, record = imap.step(history[-1])
        if imap.structure(record) is None:
            return None, n, NO_MAP
        history.append(z)
        for p in range(1, min(max_period, n // 2) + 1):
            # a whole cycle repeated, not a single near-return
            if all(np.max(np.abs(history[-1 - j] - history[-1 - j - p]) / scale) < tol for j in range(p)):
                cycle = np.array(history[-p:])
                # a slow approach to a shorter cycle repeats first at a multiple of its period (a spiral
                # with a multiplier near -1 closes better over two impacts than one): keep the shortest
                q = next(q for q in range(1, p + 1) if p % q == 0 and np.max(
                    np.abs(np.roll(cycle, q, axis=0) - cycle) / scale) < ATTRACTOR_MATCH)
                return cycle[-q:], n, None
    return None, iterations, NOT_CONVERGED


def _same_cycle(a, b, scale) -> bool:
    return len(a) == len(b) and any(np.max(np.abs(np.roll(a, s, axis=0) - b) / scale) < ATTRACTOR_MATCH
                                    for s in range(len(a)))


def find_basins(imap: ImpactMap, first_values, second_values, *, iterations: int = 500, max_period: int = 16,
                tol: float = 1e-7, n_jobs: int = 1) -> Basins:
    """The basins of attraction of a two-dimensional map over a grid of its initial state.

    From each state of the grid the map is iterated until the last ``p`` states repeat the ``p``
    before them within ``tol`` of the state's scales for the smallest ``p <= max_period``: the state
    has reached a periodic attractor, of the shortest period ``q`` dividing ``p`` over which those
    states repeat within :data:`ATTRACTOR_MATCH` (a slow approach to an orbit can repeat first over a
    multiple of its period). The endpoints are then grouped, in grid order, into attractors: two are
    one when they have the same period and their points agree, in some cyclic order, within
    :data:`ATTRACTOR_MATCH` of the scales. The result does not depend on ``n_jobs``.

    Parameters
    ----------
    imap : ImpactMap
        A map of dimension 2.
    first_values, second_values : sequence of float
        The grid's first and second coordinates, finite, non-empty.
    iterations : int, default 500
        Steps at most from each state, 1 to 100000.
    max_period : int, default 16
        Longest period recognised, 1 to 64.
    tol : float, default 1e-7
        Repetition tolerance (of the state's scales), 1e-12 to 1e-4.
    n_jobs : int, default 1
        Initial states computed side by side (threads), 1 to 1024.

    Returns
    -------
    Basins
        Its ``period`` NaN, ``x2_values`` and ``x2dot_values`` the two coordinates.

    Raises
    ------
    ValueError
        A map not of dimension 2, a grid, iteration count, period bound, tolerance or job count out
        of range.

    Examples
    --------
    ``(x, y) -> (y, x / 2)`` sends every state to the origin:

    >>> from phaseimpact.maps.base import AffineMap
    >>> b = find_basins(AffineMap([[0.0, 1.0], [0.5, 0.0]], [0.0, 0.0]), [-1.0, 1.0], [0.0, 2.0], iterations=200)
    >>> [a.period for a in b.attractors], b.labels.tolist()
    ([1], [[0, 0], [0, 0]])
    """
    if len(imap.scale) != 2:
        raise ValueError(f"imap of dimension {len(imap.scale)} is out of range; allowed: a map of dimension 2")
    imap.check()
    xs, vs = check_grid("first_values", first_values), check_grid("second_values", second_values)
    check_settling(iterations, max_period, tol, n_jobs)
    return find(imap, xs, vs, iterations, max_period, tol, n_jobs, math.nan)


def check_grid(name: str, values) -> np.ndarray:
    """One axis of the grid as a non-empty 1-d array of finite numbers, else a ValueError naming it."""
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or len(values) < 1 or not np.all(np.isfinite(values)):
        raise ValueError(f"{name} = {values!r} is out of range; allowed: a non-empty 1-d sequence of finite "
                         "numbers")
    return values


def check_settling(iterations, max_period, tol, n_jobs) -> None:
    """The iteration count, period bound, tolerance and job count checked."""
    for name, n, top in (("iterations", iterations, 100_000), ("max_period", max_period, 64),
                         ("n_jobs", n_jobs, 1024)):
        check_count(name, n, 1, top)
    if not (is_number(tol) and 1e-12 <= tol <= 1e-4):
        raise ValueError(f"tol = {tol!r} is out of range; allowed: 1e-12 <= tol <= 1e-4")


def find(imap, xs, vs, iterations, max_period, tol, n_jobs, period) -> Basins:
    """:func:`find_basins` on checked arguments (``period``: the impact map's, else NaN)."""
    from ..continuation._parallel import map_in_threads

    starts = [(x, xdot) for xdot in vs for x in xs]
    ends = map_in_threads(lambda z: _settle(imap, z, iterations, max_period, tol), starts, n_jobs)
    scale = np.asarray(imap.scale, dtype=float)
    cycles, counts, labels = [], [], np.empty(len(starts), dtype=np.int64)
    for i, (cycle, _, label) in enumerate(ends):
        if cycle is None:
            labels[i] = label
            continue
        index = next((a for a, known in enumerate(cycles) if _same_cycle(known, cycle, scale)), None)
        if index is None:
            index = len(cycles)
            cycles.append(np.roll(cycle, -int(np.argmin(cycle[:, 0])), axis=0))
            counts.append(0)
        counts[index] += 1
        labels[i] = index
    shape = (len(vs), len(xs))
    attractors = [Attractor(c, len(c), n) for c, n in zip(cycles, counts, strict=True)]
    return Basins(period, xs, vs, labels.reshape(shape), np.array([n for _, n, _ in ends]).reshape(shape),
                  attractors, int(np.sum(labels == NOT_CONVERGED)), int(np.sum(labels == NO_MAP)))
