"""Orbit diagrams, basins and continuation of the model's impact map: each function takes the
case, the law and the period, checks them before any work, and runs the generic analysis of
:mod:`phaseimpact.maps` on :class:`~phaseimpact.maps.impact.ModelImpactMap`."""

from __future__ import annotations

import numpy as np

from ..integrate.api import check_rtol
from ..model import as_law
from ..parameters import Parameters
from .basins import Basins, check_grid, check_settling, find
from .continuation import (
    BifurcationCurve,
    MapBifurcation,
    MapBranch,
    check_range,
    check_second,
    check_walk,
    check_window,
    follow,
    walk,
)
from .impact import TRAIN_PARAMETERS, ModelImpactMap, check_period
from .orbit_diagram import OrbitDiagram, assembled, check_counts, check_values, diagram

__all__ = ["orbit_diagram", "continue_map_orbit", "continue_map_bifurcation", "basins"]


def _peak_force(run) -> float:
    return run.max_force


#: Where :func:`orbit_diagram` runs: threads of this process, or a GPU (:mod:`phaseimpact.cuda`).
ORBIT_DIAGRAM_BACKENDS = ("threads", "cuda")


def orbit_diagram(params: Parameters, law, param: str, values, *, period: float | None = None,
                  transients: int = 200, samples: int = 50, rtol: float = 1e-10, n_jobs: int = 1,
                  backend: str = "threads") -> OrbitDiagram:
    """Iterate the impact map at each of ``values`` of ``param`` and keep the last ``samples`` states.

    The values are independent, the impacts of one value are not (each starts from the state the
    last one left): ``threads`` runs values side by side, each its impacts in turn; ``cuda`` runs
    impact ``n`` of every value as one GPU launch (one thread per value, the per-point kernel of
    :mod:`phaseimpact.cuda`), ``transients + samples`` launches in turn. A launch is as wide as the
    number of values: a few values leave most of the GPU idle. Both take each impact's inputs as
    :meth:`~phaseimpact.maps.impact.ModelImpactMap.step` does and the same arithmetic follows (the
    per-point path without an event log, whose numbers are :func:`~phaseimpact.simulate`'s): the
    diagrams are bit-identical where both run the same compiled (or uncompiled) code
    (``tests/test_cuda.py``).

    Parameters
    ----------
    params : Parameters
        The case.
    law : ContactLaw or str
    param : {"T", "kappa", "v"}
        The parameter varied: the period between arrivals, the damping or the speed.
    values : sequence of float
        The parameter's values (s, N s/m^(1+alpha) or m/s).
    period : float, optional
        The period (s) when ``param`` is not ``T``.
    transients, samples : int, default 200, 50
        Impacts dropped (0 to 100000), then kept (1 to 100000), at each value.
    rtol : float, default 1e-10
        The integrator's relative tolerance.
    n_jobs : int, default 1
        Values computed side by side (threads; the result does not depend on it; not read by ``cuda``).
    backend : {"threads", "cuda"}, default "threads"
        ``cuda``: each impact of every value at once on a GPU (above); refused before any work for
        a user law or without a usable GPU.

    Returns
    -------
    OrbitDiagram

    Raises
    ------
    ValueError
        A parameter name, values, period, number of transients or samples, or backend out of range.

    Examples
    --------
    Two periods, a handful of impacts each (the transients are far from over: ``distinct`` counts
    the samples, not yet an orbit's period):

    >>> from phaseimpact import seed_parameters
    >>> d = orbit_diagram(seed_parameters(kappa=3e9), "hunt-crossley", "T", [0.4e-3, 3e-3], transients=5,
    ...                   samples=3)
    >>> d.plate.shape, d.distinct.tolist()
    ((2, 3, 2), [3, 3])
    >>> [f"{f:.3g}" for f in d.peak_force[:, 0]]
    ['8.38e+03', '4.39e+03']
    """
    law = as_law(law)
    if param not in TRAIN_PARAMETERS:
        raise ValueError(f"param = {param!r} is out of range; allowed: one of {', '.join(TRAIN_PARAMETERS)}")
    values = check_values(values)
    if param != "T":
        period = check_period(period, params)
    else:
        for value in (values.min(), values.max()):
            check_period(float(value), params, "T")
    check_counts(transients, samples)
    if backend not in ORBIT_DIAGRAM_BACKENDS:
        raise ValueError(f"backend = {backend!r} is out of range; allowed: one of {', '.join(ORBIT_DIAGRAM_BACKENDS)}")
    imap = ModelImpactMap(params, law, period, check_rtol(rtol))  # the GPU's runs do not pass through simulate
    if backend == "cuda":
        from .. import cuda

        cuda.check(law)
        return _diagram_on_gpu(imap, param, values, transients, samples)
    return diagram(imap, param, values, transients, samples, _peak_force, n_jobs)


def _diagram_on_gpu(imap: ModelImpactMap, param: str, values, transients: int, samples: int) -> OrbitDiagram:
    """:func:`orbit_diagram`'s ``cuda`` backend on checked arguments: impact ``n`` of every value in
    one launch. Each value's run gets what :meth:`ModelImpactMap.step` gives :func:`~phaseimpact.simulate`
    (the case's packed coefficients and tolerances, the period as horizon, the arrival as initial state,
    no stop when settled); its summary gives the peak force, its final state the next arrival."""
    from ..integrate import driver as d
    from ..integrate.batch import summary_runs

    maps = [imap.at(param, float(value)) for value in values]
    for m in maps:
        m.check()
    cases, horizons = [m.params for m in maps], [m.period for m in maps]
    n = len(maps)
    plate = np.empty((n, samples, 2))
    peak_force = np.empty((n, samples))
    z = np.stack([m.origin for m in maps]).astype(float)
    for step in range(transients + samples):
        arrivals = np.column_stack([z[:, 0], z[:, 0], [p.v for p in cases], z[:, 1]])  # ModelImpactMap._arrival
        summary, final = summary_runs(imap.law, cases, horizons, rtol=imap.rtol, stop_when_settled=False,
                                      arrivals=arrivals)
        if step >= transients:
            plate[:, step - transients] = z
            peak_force[:, step - transients] = summary[:, d.S_MAX_FORCE]
        z = final[:, [1, 3]]
    return assembled(imap, param, values, plate, peak_force)


def continue_map_orbit(params: Parameters, law, param: str, start: float, stop: float, *,
                       period: float | None = None, k: int = 1, guess=None, step: float | None = None,
                       max_points: int = 500, xtol: float = 1e-9, rtol: float = 1e-12) -> MapBranch:
    """Follow a branch of period-``k`` orbits of the impact map from ``param = start`` towards
    ``stop`` (pseudo-arclength continuation), and locate its bifurcations.

    The first two points come from :func:`~.impact.map_fixed_point` (its Newton, at ``start`` from ``guess``,
    then one step on from the first); each next point is predicted along the secant of the last two
    and corrected onto the branch on the hyperplane normal to it (scipy's hybrid Powell on
    ``P^k(z) - z = 0`` plus that constraint), in the scaled space ``(omega x2 / v, x2dot / v,
    10 value / |stop - start|)`` (``omega = sqrt(Kb/M2)``: a change of the plate's swing by its
    amplitude at speed ``v`` weighs as much as a tenth of the range). The step halves when the
    correction fails or lands farther from the prediction than the step itself, and grows by half
    again up to ``step`` after a success; the branch turns freely at a fold and ends when it leaves
    the range, or at its first point where a projectile is still in contact when the next one
    arrives (the model's map ends there: :func:`~.impact.impact_train`'s ``overlap``).

    Between neighbouring points each test function is watched for a change of sign: ``det(J + I)``
    (period-doubling: a real multiplier through -1), ``det(J - I)`` (fold: a real multiplier through
    +1), ``det J - 1`` with a complex pair (Neimark–Sacker); ``J`` is the Jacobian of ``P^k``
    (:func:`~.impact.map_jacobian`). **Grazing** is where the orbit's contact structure changes: the number of
    contacts or of stick phases that its projectiles make with the plate per period (a projectile
    that left the plate touched again by the swinging plate, tangentially at the grazing point
    itself), or of projectiles still in contact when the next one arrives (the contact's end grazing
    the arrival). Each is located by bisection along the segment between the two points (each trial
    point corrected onto the branch) until the segment is shorter than ``xtol`` in the scaled
    space; for a smooth test function its value at the bisection's midpoint is reported too.

    Parameters
    ----------
    params : Parameters
        The case.
    law : ContactLaw or str
    param : {"T", "kappa", "v"}
        The parameter followed: the period between arrivals (s), the damping (the law's unit) or the
        speed (m/s).
    start, stop : float
        The range, in the parameter's unit (T, v > 0; kappa >= 0; start != stop).
    period : float, optional
        Time between arrivals (s), required when ``param`` is not ``T``.
    k : int, default 1
        The orbit's period in impacts, 1 to 64.
    guess : 2 numbers, optional
        ``(x2, x2dot)`` (m, m/s) near the orbit at ``start``; default the state after 50 impacts from
        rest there (:func:`~.impact.map_fixed_point`).
    step : float, optional
        The largest step along the branch, in the parameter's unit (> 0); default ``|stop - start| / 50``.
    max_points : int, default 500
        Points at most, 3 to 100000.
    xtol : float, default 1e-9
        Length of the final bisection segment in the scaled space, 1e-14 to 1e-3.
    rtol : float, default 1e-12
        The integrator's tolerance.

    Returns
    -------
    MapBranch
        An empty branch (``message`` says why) when no orbit is found at ``start``.

    Raises
    ------
    ValueError
        A parameter name, range, period, ``k``, step, ``max_points`` or ``xtol`` out of range.

    Examples
    --------
    The seed case's period-1 orbit at T = 0.4 to 0.45 ms (0.4 to 0.45 plate periods): stable, no
    bifurcation.

    >>> from phaseimpact import seed_parameters
    >>> branch = continue_map_orbit(seed_parameters(kappa=3e9), "hunt-crossley", "T", 0.4e-3, 0.45e-3,
    ...                             step=1e-5)
    >>> bool(branch.stable.all()), branch.points, branch.message
    (True, [], 'reached the end of the range')
    """
    imap = ModelImpactMap(params, law, period, rtol)
    check_range(imap, param, start, stop)
    if param != "T":
        imap = ModelImpactMap(params, imap.law, check_period(period, params), rtol)
    step = check_walk(abs(stop - start), k, step, max_points, xtol)
    return walk(imap, param, start, stop, int(k), guess, step, max_points, xtol)


def continue_map_bifurcation(params: Parameters, law, branch: MapBranch, point: MapBifurcation, second: str,
                             values, *, period: float | None = None, window: float | None = None,
                             xtol: float = 1e-9, rtol: float = 1e-12) -> BifurcationCurve:
    """Follow a located bifurcation of ``branch`` in a second parameter (two-parameter continuation).

    A simple, robust scheme: at each value of ``second`` in turn (``values``, in the order given:
    begin next to the case's own value), the branch is followed again (:func:`continue_map_orbit`) over a window of
    the first parameter around the point's previous location, ``value -+ window``, in the direction
    the original branch ran, warm-started from the previous point's state; the point of the same kind
    located there nearest the previous one is the curve's next point. Where none is found the window
    is doubled, up to three times; then the curve is reported lost from that value on.

    Parameters
    ----------
    params : Parameters
        The case of ``branch`` (its value of ``second`` is where the curve starts).
    law : ContactLaw or str
    branch : MapBranch
        From :func:`continue_map_orbit`.
    point : MapBifurcation
        One of ``branch.points``.
    second : {"T", "kappa", "v"}
        The second parameter, not the branch's own.
    values : sequence of float
        The grid of ``second`` (its unit), monotonic, at least 1 value.
    period : float, optional
        Time between arrivals (s) when neither parameter is ``T``.
    window : float, optional
        Half-width of the first parameter's window (its unit, > 0); default a fiftieth of the
        point's value.
    xtol : float, default 1e-9
        As for :func:`continue_map_orbit`.
    rtol : float, default 1e-12

    Returns
    -------
    BifurcationCurve

    Raises
    ------
    ValueError
        A parameter name, grid, window or period out of range, or a point not of ``branch``.

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact import seed_parameters
    >>> p = seed_parameters(kappa=3e9)
    >>> branch = continue_map_orbit(p, "hunt-crossley", "T", 0.9985e-3, 0.9845e-3, step=2e-6)
    >>> pd = branch.points[0]; pd.kind
    'period-doubling'
    >>> curve = continue_map_bifurcation(p, "hunt-crossley", branch, pd, "v", [1.0, 1.02])
    >>> curve.message, bool(np.all(np.isfinite(curve.values)))
    ('followed over the whole grid', True)
    """
    imap = ModelImpactMap(params, law, period, rtol)
    grid = check_second(imap, branch, point, second, values)
    if "T" not in (branch.param, second):
        imap = ModelImpactMap(params, imap.law, check_period(period, params), rtol)
    window = check_window(window, point)
    return follow(imap, branch, point, second, grid, window, xtol)


def basins(params: Parameters, law, period: float, x2_values, x2dot_values, *, iterations: int = 500,
           max_period: int = 16, tol: float = 1e-7, rtol: float = 1e-10, n_jobs: int = 1) -> Basins:
    """The basins of attraction of the impact map in the plate's initial state.

    From each ``(x2, x2dot)`` of the grid the map is iterated until the last ``p`` states repeat the
    ``p`` before them within ``tol`` of the state's scales (Hertz indentation, ``v``) for the
    smallest ``p <= max_period``: the state has reached a periodic attractor, of the shortest period
    ``q`` dividing ``p`` over which those states repeat within :data:`~.basins.ATTRACTOR_MATCH` (a slow
    approach to an orbit can repeat first over a multiple of its period). As in
    :func:`~.impact.impact_train`, a projectile still in contact at the next arrival does not stop the train.
    The
    endpoints are then grouped, in grid order, into attractors: two are one when they have the same
    period and their points agree, in some cyclic order, within :data:`~.basins.ATTRACTOR_MATCH` of the
    scales. The result does not depend on ``n_jobs``.

    Parameters
    ----------
    params : Parameters
        The case.
    law : ContactLaw or str
    period : float
        Time between arrivals, s (> 0).
    x2_values, x2dot_values : sequence of float
        The grid's initial plate positions (m) and velocities (m/s), finite, non-empty.
    iterations : int, default 500
        Impacts at most from each state, 1 to 100000.
    max_period : int, default 16
        Longest period recognised, 1 to 64.
    tol : float, default 1e-7
        Repetition tolerance (of the state's scales), 1e-12 to 1e-4.
    rtol : float, default 1e-10
        The integrator's tolerance.
    n_jobs : int, default 1
        Initial states computed side by side (threads), 1 to 1024.

    Returns
    -------
    Basins

    Raises
    ------
    ValueError
        A period, grid, iteration count, period bound, tolerance or job count out of range.

    Examples
    --------
    At 0.4 plate periods the seed case has one attractor, the period-1 orbit:

    >>> from phaseimpact import seed_parameters
    >>> b = basins(seed_parameters(kappa=3e9), "hunt-crossley", 0.4e-3, [-1e-4, 1e-4], [0.0])
    >>> [a.period for a in b.attractors], b.labels.tolist()
    ([1], [[0, 0]])
    """
    law = as_law(law)
    period = check_period(period, params)
    xs, vs = check_grid("x2_values", x2_values), check_grid("x2dot_values", x2dot_values)
    check_settling(iterations, max_period, tol, n_jobs)
    return find(ModelImpactMap(params, law, period, rtol), xs, vs, iterations, max_period, tol, n_jobs, period)
