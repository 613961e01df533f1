"""Orbit diagrams of a map: its attractor sampled after transients at each value of a parameter
(the model's impact map: :func:`~phaseimpact.maps.impact_analyses.orbit_diagram`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .base import ImpactMap, check_count

__all__ = ["OrbitDiagram", "sample_attractor"]


@dataclass(frozen=True)
class OrbitDiagram:
    """A map's attractor over a parameter: ``samples`` states after ``transients`` steps.

    Attributes
    ----------
    param : str
        The parameter (``T``, ``kappa`` or ``v`` for the impact map).
    values : ndarray, shape (n,)
    plate : ndarray, shape (n, samples, dim)
        The state before each sampled step (the plate's ``(x2, x2dot)`` just before each sampled impact).
    peak_force : ndarray, shape (n, samples)
        What ``observe`` gave of each sampled step (the impact's largest contact force, N; NaN without
        ``observe``).
    distinct : ndarray of int, shape (n,)
        Distinct points among the samples (to 1e-6 of the state's scales): 1 on a fixed point,
        ``k`` on a period-``k`` orbit, ``samples`` when irregular (or not settled).

    Examples
    --------
    From :func:`sample_attractor` or :func:`~phaseimpact.maps.impact_analyses.orbit_diagram`:

    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.maps import orbit_diagram
    >>> d = orbit_diagram(seed_parameters(kappa=3e9), "hunt-crossley", "T", [0.4e-3], transients=2, samples=3)
    >>> d.param, d.plate.shape, d.peak_force.shape
    ('T', (1, 3, 2), (1, 3))
    """

    param: str
    values: np.ndarray
    plate: np.ndarray
    peak_force: np.ndarray
    distinct: np.ndarray


def sample_attractor(imap: ImpactMap, param: str, values, *, transients: int = 200, samples: int = 50,
                     observe=None, n_jobs: int = 1) -> OrbitDiagram:
    """Iterate a map from its origin at each of ``values`` of ``param`` and keep the last ``samples``
    states: an orbit diagram.

    Parameters
    ----------
    imap : ImpactMap
        A map with parameters.
    param : str
        One of ``imap.parameters``.
    values : sequence of float
        The parameter's values, each as :meth:`~phaseimpact.maps.base.ImpactMap.check_parameter` allows.
    transients, samples : int, default 200, 50
        Steps dropped (0 to 100000), then kept (1 to 100000), at each value.
    observe : callable, optional
        Of a step's record (:meth:`~phaseimpact.maps.base.ImpactMap.step`), a number kept with each
        sample (:attr:`OrbitDiagram.peak_force`).
    n_jobs : int, default 1
        Values computed side by side (threads; the result does not depend on it).

    Returns
    -------
    OrbitDiagram
        ``distinct`` counts the distinct samples to 1e-6 of the state's scales.

    Raises
    ------
    ValueError
        A parameter name, values, or number of transients or samples out of range.

    Examples
    --------
    The logistic map settles on 1, 2 and 4 points below its first three period doublings:

    >>> from phaseimpact.maps.base import ImpactMap
    >>> class Logistic(ImpactMap):
    ...     parameters, scale = ("r",), np.array([1.0])
    ...     def __init__(self, r=3.0):
    ...         self.r = r
    ...     def __call__(self, state):
    ...         return self.r * state * (1 - state)
    ...     def at(self, name, value):
    ...         return Logistic(value)
    ...     @property
    ...     def origin(self):
    ...         return np.array([0.3])
    >>> sample_attractor(Logistic(), "r", [2.8, 3.2, 3.5], transients=2000, samples=8).distinct.tolist()
    [1, 2, 4]
    """
    if param not in imap.parameters:
        raise ValueError(f"param = {param!r} is out of range; allowed: one of {', '.join(imap.parameters)}")
    values = check_values(values)
    for value in values:
        imap.check_parameter(param, float(value), param)
    check_counts(transients, samples)
    return diagram(imap, param, values, transients, samples, observe, n_jobs)


def check_values(values) -> np.ndarray:
    """``values`` as a non-empty 1-d array of finite numbers, else a ValueError."""
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or len(values) < 1 or not np.all(np.isfinite(values)):
        raise ValueError("values must be a non-empty 1-d sequence of finite numbers")
    return values


def check_counts(transients, samples) -> None:
    """Transients (0 to 100000) and samples (1 to 100000) checked."""
    check_count("transients", transients, 0, 100_000)
    check_count("samples", samples, 1, 100_000)


def _column(imap, transients, samples, observe):
    """The ``samples`` states after ``transients`` steps from the origin, and what ``observe`` saw."""
    imap.check()
    states = np.empty((samples, len(imap.scale)))
    observed = np.full(samples, np.nan)
    z = imap.origin
    for n in range(transients + samples):
        following, record = imap.step(z)
        if n >= transients:
            states[n - transients] = z
            if observe is not None:
                observed[n - transients] = observe(record)
        z = following
    return states, observed


def diagram(imap, param, values, transients, samples, observe, n_jobs) -> OrbitDiagram:
    """:func:`sample_attractor` on checked arguments."""
    from ..continuation._parallel import map_in_threads

    columns = map_in_threads(lambda value: _column(imap.at(param, float(value)), transients, samples, observe),
                             values, n_jobs)
    return assembled(imap, param, values, np.stack([c[0] for c in columns]), np.stack([c[1] for c in columns]))


def assembled(imap, param, values, plate, observed) -> OrbitDiagram:
    """The diagram of the sampled states ``plate`` (values x samples x dim) and what was observed of each
    step, with its counts of distinct points (to 1e-6 of ``imap``'s scales)."""
    scale = np.asarray(imap.scale, dtype=float)
    distinct = np.array([len(np.unique(np.round(col / scale / 1e-6), axis=0)) for col in plate])
    return OrbitDiagram(param, values, plate, observed, distinct)
