"""Continuation of the periodic orbits of a map and of their bifurcations, over any
:class:`~phaseimpact.maps.base.ImpactMap` with parameters (the model's impact map:
:func:`~phaseimpact.maps.impact_analyses.continue_map_orbit`).

:func:`continue_orbit` follows a branch of period-``k`` orbits by pseudo-arclength continuation
(secant predictor, hybrid-Powell corrector on ``P^k(z) - z = 0`` plus the arclength constraint,
step halved on failure and grown by half on success) and locates its period-doubling, fold,
Neimark–Sacker and grazing points by bisection; :func:`continue_bifurcation` follows such a point in
a second parameter. (:mod:`phaseimpact.continuation.curve` continues a scalar defining function by
natural-parameter steps and Brent's method: another algorithm, so nothing of it is shared here.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..parameters import is_number
from .base import FOUND, ImpactMap, bifurcation_tests, check_count, fixed_point, multipliers_dict, solve

__all__ = ["MapBifurcation", "MapBranch", "BifurcationCurve", "continue_orbit", "continue_bifurcation",
           "BIFURCATION_KINDS"]

#: Kinds of located points: a real multiplier through -1, through +1, a complex pair through the unit
#: circle, and a change of the orbit's structure (for the impact map: its contacts).
BIFURCATION_KINDS = ("period-doubling", "fold", "neimark-sacker", "grazing")


@dataclass(frozen=True)
class MapBifurcation:
    """A located bifurcation of a periodic orbit of a map (the impact map's units in brackets).

    Attributes
    ----------
    kind : str
        ``period-doubling`` (a real multiplier crosses -1: a period-``2k`` orbit is born or dies),
        ``fold`` (a real multiplier crosses +1: two orbits of period ``k`` meet; ``turning`` says
        whether the branch turns back in the parameter there), ``neimark-sacker`` (a complex pair
        crosses the unit circle) or ``grazing`` (the orbit's structure, for the impact map its
        contacts, changes: see :func:`continue_orbit`).
    param : str
        The parameter (``T``, ``kappa`` or ``v``).
    value : float
        The parameter at the point (s, the law's damping unit or m/s).
    plate : ndarray, shape (n,)
        The orbit's state at its first step there (the plate's ``(x2, x2dot)``, m and m/s).
    multipliers : ndarray, shape (n,), complex
        Floquet multipliers there.
    bracket : float
        Width of the final bracket of the bisection in the parameter (its unit): the location's
        accuracy as far as the test function is exact.
    test_value : float
        The test function at the point: ``det(J + I)``, ``det(J - I)``, ``det J - 1`` (``J`` the
        Jacobian of ``P^k``); 0 for grazing.
    contacts : tuple of 2 tuples of int
        The orbit's structure per period on either side (grazing; else both alike): for the impact
        map its contacts, stick phases and overlaps.
    turning : bool
        Fold only: the branch's parameter turns back there (a saddle-node), not a crossing.

    Examples
    --------
    >>> import numpy as np
    >>> MapBifurcation("fold", "T", 1e-3, np.zeros(2), np.array([1.0, 0.3]), 0.0, 0.0, ((1, 0, 0),) * 2).kind
    'fold'
    """

    kind: str
    param: str
    value: float
    plate: np.ndarray
    multipliers: np.ndarray
    bracket: float
    test_value: float
    contacts: tuple
    turning: bool = False

    def as_dict(self) -> dict:
        """The point as JSON-ready numbers.

        Returns
        -------
        dict
            The attributes, multipliers as ``{re, im, abs}``.

        Examples
        --------
        >>> import numpy as np
        >>> b = MapBifurcation("grazing", "T", 1e-3, np.zeros(2), np.array([0.5, 0.2]), 1e-12, 0.0,
        ...                    ((1, 0, 0), (2, 0, 0)))
        >>> b.as_dict()["contacts"]
        [[1, 0, 0], [2, 0, 0]]
        """
        return {"kind": self.kind, "param": self.param, "value": self.value, "plate": self.plate.tolist(),
                "multipliers": multipliers_dict(self.multipliers), "bracket": self.bracket,
                "test_value": self.test_value, "contacts": [list(c) for c in self.contacts],
                "turning": self.turning}


@dataclass(frozen=True)
class MapBranch:
    """A branch of period-``k`` orbits of a map followed over a parameter, with its located
    bifurcations (the impact map's units in brackets).

    Attributes
    ----------
    param : str
        The parameter (``T``, ``kappa`` or ``v``).
    period_k : int
    values : ndarray, shape (n,)
        The parameter along the branch, in the order followed (it turns back at a fold).
    plate : ndarray, shape (n, dim)
        The orbit's state at its first step (the plate's ``(x2, x2dot)`` before its first impact, m
        and m/s).
    multipliers : ndarray, shape (n, dim), complex
    stable : ndarray of bool, shape (n,)
    contacts : ndarray of int, shape (n, len(structure_names))
        The orbit's structure per period: for the impact map its contacts, stick phases and overlaps
        (a projectile still in contact at the next arrival).
    points : list of MapBifurcation
        The located points, in the order met.
    message : str
        Why the branch ends (``reached the end of the range``, or the failure).

    Examples
    --------
    See :func:`~phaseimpact.maps.impact_analyses.continue_map_orbit`.

    >>> MapBranch.__dataclass_fields__["points"].type
    'list'
    """

    param: str
    period_k: int
    values: np.ndarray
    plate: np.ndarray
    multipliers: np.ndarray
    stable: np.ndarray
    contacts: np.ndarray
    points: list
    message: str

    def as_dict(self) -> dict:
        """The branch as JSON-ready lists.

        Returns
        -------
        dict
            ``param``, ``period_k``, ``values``, ``plate``, ``multipliers`` (per point, ``{re, im, abs}``
            each), ``stable``, ``contacts``, ``points`` (:meth:`MapBifurcation.as_dict` each), ``message``.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.maps import continue_map_orbit
        >>> branch = continue_map_orbit(seed_parameters(kappa=3e9), "hunt-crossley", "T", 0.4e-3, 0.45e-3,
        ...                             step=1e-5)
        >>> d = branch.as_dict()
        >>> d["param"], len(d["values"]) >= 3, d["points"]
        ('T', True, [])
        """
        return {"param": self.param, "period_k": self.period_k, "values": self.values.tolist(),
                "plate": self.plate.tolist(), "multipliers": [multipliers_dict(m) for m in self.multipliers],
                "stable": self.stable.tolist(), "contacts": self.contacts.tolist(),
                "points": [p.as_dict() for p in self.points], "message": self.message}


@dataclass(frozen=True)
class BifurcationCurve:
    """A bifurcation of a map followed in a second parameter: where it lies in the first parameter
    at each value of the second.

    Attributes
    ----------
    kind : str
        One of :data:`BIFURCATION_KINDS`.
    param, second : str
        The first parameter (where the point is located) and the second (the grid).
    second_values : ndarray, shape (m,)
        The grid of the second parameter, in the order followed.
    values : ndarray, shape (m,)
        The first parameter at the bifurcation (NaN where it was lost).
    plate : ndarray, shape (m, dim)
        The orbit's state there (the plate's ``(x2, x2dot)``, m and m/s; NaN where lost).
    multipliers : ndarray, shape (m, dim), complex
    bracket : ndarray, shape (m,)
        Each location's final bracket in the first parameter.
    message : str
        ``followed over the whole grid``, or where and why the curve was lost.

    Examples
    --------
    See :func:`~phaseimpact.maps.impact_analyses.continue_map_bifurcation`.

    >>> BifurcationCurve.__dataclass_fields__["second"].type
    'str'
    """

    kind: str
    param: str
    second: str
    second_values: np.ndarray
    values: np.ndarray
    plate: np.ndarray
    multipliers: np.ndarray
    bracket: np.ndarray
    message: str

    def as_dict(self) -> dict:
        """The curve as JSON-ready lists (NaN kept: the CLI writes it as null).

        Returns
        -------
        dict
            The attributes; multipliers as ``{re, im, abs}``.

        Examples
        --------
        >>> import numpy as np
        >>> c = BifurcationCurve("fold", "T", "v", np.array([1.0]), np.array([1e-3]), np.zeros((1, 2)),
        ...                      np.array([[1.0, 0.3]]), np.array([1e-15]), "followed over the whole grid")
        >>> c.as_dict()["values"]
        [0.001]
        """
        return {"kind": self.kind, "param": self.param, "second": self.second,
                "second_values": self.second_values.tolist(), "values": self.values.tolist(),
                "plate": self.plate.tolist(), "multipliers": [multipliers_dict(m) for m in self.multipliers],
                "bracket": self.bracket.tolist(), "message": self.message}




class _Walker:
    """The continuation's working state: the map at a point ``y = (z / scale, value / reference)`` of
    the scaled (state, parameter) space, corrected onto the branch on a hyperplane."""

    def __init__(self, imap, param, k, reference):
        self.imap, self.param, self.k = imap, param, k
        self.scale = np.asarray(imap.continuation_scale, dtype=float)
        self.reference = reference
        self.n = len(self.scale)

    def unscale(self, y):
        return y[:self.n] * self.scale, float(y[self.n] * self.reference)

    def residual(self, y):
        z, value = self.unscale(y)
        end, _ = _signature(self.imap.at(self.param, value), z, self.k)
        return (end - z) / self.scale

    def correct(self, y_pred, y_base, direction, s):
        """The branch's point on the hyperplane ``(y - y_base) . direction = s`` (pseudo-arclength),
        from ``y_pred``: ``y`` or None when the corrector does not converge."""
        def equations(y):
            try:
                r = self.residual(y)
            except ValueError:  # a trial parameter out of the map's range
                return np.full(self.n + 1, 1e6)
            return np.append(r, (y - y_base) @ direction - s)

        y, residual, _ = solve(equations, y_pred)
        return y if residual < FOUND else None

    def describe(self, y):
        """``(multipliers, structure per period, jacobian_accuracy)`` of the orbit at ``y``, or None
        where the map is undefined."""
        z, value = self.unscale(y)
        m = self.imap.at(self.param, value)
        _, structure = _signature(m, z, self.k)
        if structure is None:
            return None
        J, accuracy = m.jacobian(z, self.k)
        return np.linalg.eigvals(J).astype(complex), _counts(structure), accuracy

    def natural(self, value, z):
        """The orbit at ``value`` by :func:`fixed_point` from ``z`` (scaled), or None."""
        fp = fixed_point(self.imap.at(self.param, value), k=self.k, guess=z)
        return np.append(fp.plate / self.scale, value / self.reference) if fp.converged else None


def _signature(imap, z, k):
    """``P^k(z)`` and the structure of each of the ``k`` steps; at a step where the map is undefined,
    the state reached and None."""
    structure = []
    for _ in range(k):
        z, record = imap.step(z)
        counts = imap.structure(record)
        if counts is None:
            return z, None
        structure.append(counts)
    return z, tuple(structure)


def _counts(structure) -> tuple:
    """The structure's counts summed over the orbit's steps."""
    return tuple(int(sum(column)) for column in zip(*structure, strict=True))


def check_range(imap: ImpactMap, param, start, stop):
    """The parameter's name and range checked, before any work."""
    if param not in imap.parameters:
        raise ValueError(f"param = {param!r} is out of range; allowed: one of {', '.join(imap.parameters)}")
    imap.check_parameter(param, start, "start")
    imap.check_parameter(param, stop, "stop")
    if start == stop:
        raise ValueError(f"stop = {stop!r} is out of range; allowed: stop != start ({start!r})")


def check_walk(span, k, step, max_points, xtol) -> float:
    """The walk's options checked; the step (default a fiftieth of the span)."""
    check_count("k", k, 1, 64)
    if step is None:
        step = span / 50
    if not (is_number(step) and math.isfinite(step) and 0 < step <= span):
        raise ValueError(f"step = {step!r} is out of range; allowed: 0 < step <= |stop - start| = {span:g}")
    check_count("max_points", max_points, 3, 100_000)
    if not (is_number(xtol) and 1e-14 <= xtol <= 1e-3):
        raise ValueError(f"xtol = {xtol!r} is out of range; allowed: 1e-14 <= xtol <= 1e-3")
    return step


def continue_orbit(imap: ImpactMap, param: str, start: float, stop: float, *, k: int = 1, guess=None,
                   step: float | None = None, max_points: int = 500, xtol: float = 1e-9) -> MapBranch:
    """Follow a branch of period-``k`` orbits of a map from ``param = start`` towards ``stop``
    (pseudo-arclength continuation), and locate its bifurcations.

    The first two points come from :func:`~phaseimpact.maps.base.fixed_point` (at ``start`` from
    ``guess``, then a tenth of a step on); each next point is predicted along the secant of the last
    two and corrected onto the branch on the hyperplane normal to it, in the scaled space
    ``(z / continuation_scale, 10 value / |stop - start|)``. The step halves when the correction
    fails or lands farther from the prediction than the step itself, and grows by half again up to
    ``step`` after a success; the branch turns freely at a fold and ends when it leaves the range,
    or where the map ends (:meth:`~phaseimpact.maps.base.ImpactMap.end_reason`).

    Between neighbouring points each test function is watched for a change of sign: ``det(J + I)``
    (period doubling), ``det(J - I)`` (fold), ``det J - 1`` with a complex pair of a two-dimensional
    map (Neimark–Sacker), ``J`` the Jacobian of ``P^k``; a change of the orbit's structure
    (:meth:`~phaseimpact.maps.base.ImpactMap.structure` summed over the period) is a grazing. Each
    is located by bisection along the segment (each trial point corrected onto the branch) until
    the segment is shorter than ``xtol`` in the scaled space.

    Parameters
    ----------
    imap : ImpactMap
        A map with parameters (:meth:`~phaseimpact.maps.base.ImpactMap.at`).
    param : str
        One of ``imap.parameters``.
    start, stop : float
        The range (start != stop), as :meth:`~phaseimpact.maps.base.ImpactMap.check_parameter` allows.
    k : int, default 1
        The orbit's period in steps, 1 to 64.
    guess : array, shape (n,), optional
        A state near the orbit at ``start``; default 50 steps from the map's origin.
    step : float, optional
        The largest step along the branch, in the parameter's unit (> 0); default ``|stop - start| / 50``.
    max_points : int, default 500
        Points at most, 3 to 100000.
    xtol : float, default 1e-9
        Length of the final bisection segment in the scaled space, 1e-14 to 1e-3.

    Returns
    -------
    MapBranch
        An empty branch (``message`` says why) when no orbit is found at ``start``.

    Raises
    ------
    ValueError
        A parameter name, range, ``k``, step, ``max_points`` or ``xtol`` out of range.

    Examples
    --------
    The logistic map ``x -> r x (1 - x)``: its fixed point ``1 - 1/r`` doubles its period at
    ``r = 3``, where its multiplier ``2 - r`` passes -1:

    >>> from phaseimpact.maps.base import ImpactMap
    >>> class Logistic(ImpactMap):
    ...     parameters, scale = ("r",), np.array([1.0])
    ...     def __init__(self, r):
    ...         self.r = r
    ...     def __call__(self, state):
    ...         return self.r * state * (1 - state)
    ...     def at(self, name, value):
    ...         return Logistic(value)
    >>> branch = continue_orbit(Logistic(2.5), "r", 2.5, 3.2, guess=[0.6])
    >>> [(p.kind, f"{p.value:.6f}") for p in branch.points]
    [('period-doubling', '3.000000')]
    """
    check_range(imap, param, start, stop)
    step = check_walk(abs(stop - start), k, step, max_points, xtol)
    return walk(imap, param, float(start), float(stop), int(k), guess, step, max_points, xtol)


def walk(imap, param, start, stop, k, guess, step, max_points, xtol) -> MapBranch:
    """:func:`continue_orbit` on checked arguments."""
    reference = abs(stop - start) / 10
    work = _Walker(imap, param, k, reference)
    low, high = min(start, stop), max(start, stop)
    sign = 1.0 if stop > start else -1.0
    ys, infos = [], []
    for value, where in ((start, "at"), (start + sign * step / 10, "one step from")):
        y = work.natural(value, guess if not ys else ys[-1][:work.n] * work.scale)
        info = None if y is None else work.describe(y)
        if info is None:
            return _branch(work, ys, infos, [], f"no period-{k} orbit found {where} {param} = {start:g}")
        ys.append(y), infos.append(info)

    ds_max = step / reference
    ds, message = ds_max / 10, "reached the end of the range"
    while len(ys) < max_points:
        tangent = (ys[-1] - ys[-2]) / np.linalg.norm(ys[-1] - ys[-2])
        y_pred = ys[-1] + ds * tangent
        y = work.correct(y_pred, ys[-1], tangent, ds)
        info = None if y is None or np.linalg.norm(y - y_pred) > ds else work.describe(y)
        if info is None:
            ds /= 2
            if ds < ds_max * 1e-6:
                message = f"the branch could not be followed past {param} = {ys[-1][work.n] * reference:g}"
                break
            continue
        value = y[work.n] * reference
        if not low <= value <= high:
            break
        ys.append(y), infos.append(info)
        reason = imap.end_reason(info[1])
        if reason:  # kept, so that the onset is located as a grazing
            message = f"from {param} = {value:g} on {reason}"
            break
        ds = min(ds * 1.5, ds_max)
    else:
        message = f"stopped after max_points = {max_points} points"
    points = []
    for i in range(len(ys) - 1):
        points += _locate(work, ys, infos, i, xtol)
    return _branch(work, ys, infos, points, message)


def _branch(work, ys, infos, points, message) -> MapBranch:
    n, dim = len(ys), work.n
    plate = np.array([y[:dim] * work.scale for y in ys]).reshape(n, dim)
    multipliers = np.array([m for m, _, _ in infos], dtype=complex).reshape(n, dim)
    contacts = np.array([c for _, c, _ in infos], int).reshape(n, len(work.imap.structure_names))
    return MapBranch(work.param, work.k, np.array([y[dim] * work.reference for y in ys]), plate, multipliers,
                     np.all(np.abs(multipliers) < 1, axis=1), contacts, points, message)


def _bisect(work, ys, infos, i, kind, xtol):
    """Bisection of the segment from branch point ``i`` for the change of ``kind``: ``(lo, hi, y, info)``,
    the bracket in the segment's fraction and the last point corrected inside it."""
    a, b = ys[i], ys[i + 1]
    chord = b - a
    length = float(np.linalg.norm(chord))
    direction = chord / length
    lo, hi = 0.0, 1.0
    left = bifurcation_tests(infos[i][0])[kind] if kind != "grazing" else infos[i][1]
    y_mid, info_mid = a, infos[i]
    while (hi - lo) * length > xtol:
        sigma = 0.5 * (lo + hi)
        y = work.correct(a + sigma * chord, a, direction, sigma * length)
        info = None if y is None else work.describe(y)
        if info is None:  # the corrector failed inside the segment: keep the bracket reached
            break
        here = bifurcation_tests(info[0])[kind] if kind != "grazing" else info[1]
        if (here == left) if kind == "grazing" else (here * left > 0):
            lo = sigma
        else:
            hi = sigma
        y_mid, info_mid = y, info
    return lo, hi, y_mid, info_mid


def _locate(work, ys, infos, i, xtol) -> list:
    """The bifurcations between branch points ``i`` and ``i + 1``, each by bisection on the segment."""
    a, b = ys[i], ys[i + 1]
    chord = b - a
    found = []
    tests_a, tests_b = bifurcation_tests(infos[i][0]), bifurcation_tests(infos[i + 1][0])
    changes = [kind for kind in tests_a if tests_a[kind] * tests_b[kind] < 0]
    if infos[i][1] != infos[i + 1][1]:
        changes.append("grazing")
    dim = work.n
    for kind in changes:
        lo, hi, y_mid, info_mid = _bisect(work, ys, infos, i, kind, xtol)
        values = [float((a[dim] + s * chord[dim]) * work.reference) for s in (lo, hi)]
        z, value = work.unscale(y_mid)
        turning = False
        if kind == "fold":
            # a turn: the parameter at the fold lies beyond both ends of the segment (or the branch's
            # direction in the parameter differs on either side of the segment)
            before = ys[i][dim] - ys[i - 1][dim] if i > 0 else chord[dim]
            after = ys[i + 2][dim] - ys[i + 1][dim] if i + 2 < len(ys) else chord[dim]
            turning = bool(before * after < 0 or (y_mid[dim] - a[dim]) * (y_mid[dim] - b[dim]) > 0)
        found.append(MapBifurcation(kind, work.param, value, z, info_mid[0], abs(values[1] - values[0]),
                                    0.0 if kind == "grazing" else bifurcation_tests(info_mid[0])[kind],
                                    (infos[i][1], infos[i + 1][1]) if kind == "grazing" else (info_mid[1],) * 2,
                                    turning))
    return found


def check_second(imap: ImpactMap, branch: MapBranch, point: MapBifurcation, second: str, values) -> np.ndarray:
    """The second parameter, the point and the grid checked; the grid."""
    if second not in imap.parameters or second == branch.param:
        allowed = [p for p in imap.parameters if p != branch.param]
        raise ValueError(f"second = {second!r} is out of range; allowed: one of {', '.join(allowed)}")
    if not any(point is p for p in branch.points):
        raise ValueError(f"point = {point.kind} at {point.value!r} is out of range; allowed: one of branch.points")
    grid = np.asarray(values, dtype=float)
    if grid.ndim != 1 or len(grid) < 1 or not np.all(np.isfinite(grid)) or (
            len(grid) > 1 and not (np.all(np.diff(grid) > 0) or np.all(np.diff(grid) < 0))):
        raise ValueError("values must be a non-empty, strictly monotonic 1-d sequence of finite numbers")
    for x in grid:
        imap.check_parameter(second, float(x), "values")
    return grid


def check_window(window, point: MapBifurcation) -> float:
    if window is None:
        window = abs(point.value) / 50
    if not (is_number(window) and math.isfinite(window) and window > 0):
        raise ValueError(f"window = {window!r} is out of range; allowed: a finite number > 0")
    return window


def continue_bifurcation(imap: ImpactMap, branch: MapBranch, point: MapBifurcation, second: str, values, *,
                         window: float | None = None, xtol: float = 1e-9) -> BifurcationCurve:
    """Follow a located bifurcation of ``branch`` in a second parameter (two-parameter continuation).

    At each value of ``second`` in turn (``values``, in the order given: begin next to the map's
    own value) the branch is followed again (:func:`continue_orbit`) over a window of the first
    parameter around the point's previous location, ``value -+ window``, in the direction the
    original branch ran, warm-started from the previous point's state; the point of the same kind
    located there nearest the previous one is the curve's next point. Where none is found the
    window is doubled, up to three times; then the curve is reported lost from that value on.

    Parameters
    ----------
    imap : ImpactMap
        The map of ``branch`` (its value of ``second`` is where the curve starts).
    branch : MapBranch
        From :func:`continue_orbit`.
    point : MapBifurcation
        One of ``branch.points``.
    second : str
        One of ``imap.parameters``, not the branch's own.
    values : sequence of float
        The grid of ``second``, strictly monotonic, at least 1 value.
    window : float, optional
        Half-width of the first parameter's window (> 0); default a fiftieth of the point's value.
    xtol : float, default 1e-9
        As for :func:`continue_orbit`.

    Returns
    -------
    BifurcationCurve

    Raises
    ------
    ValueError
        A parameter name, grid or window out of range, or a point not of ``branch``.

    Examples
    --------
    The Hénon map's period doubling lies at ``a = 3 (1 - b)^2 / 4``:

    >>> from phaseimpact.maps.base import ImpactMap
    >>> class Henon(ImpactMap):
    ...     parameters, scale = ("a", "b"), np.array([1.0, 1.0])
    ...     def __init__(self, a, b):
    ...         self.a, self.b = a, b
    ...     def __call__(self, state):
    ...         return np.array([1 - self.a * state[0] ** 2 + state[1], self.b * state[0]])
    ...     def at(self, name, value):
    ...         return Henon(**{"a": self.a, "b": self.b, name: value})
    >>> m = Henon(0.2, 0.3)
    >>> branch = continue_orbit(m, "a", 0.2, 0.5)
    >>> curve = continue_bifurcation(m, branch, branch.points[0], "b", [0.3, 0.29])
    >>> [f"{a:.6f}" for a in curve.values], [f"{3 * (1 - b) ** 2 / 4:.6f}" for b in (0.3, 0.29)]
    (['0.367500', '0.378075'], ['0.367500', '0.378075'])
    """
    grid = check_second(imap, branch, point, second, values)
    window = check_window(window, point)
    return follow(imap, branch, point, second, grid, window, xtol)


def follow(imap, branch, point, second, grid, window, xtol) -> BifurcationCurve:
    """:func:`continue_bifurcation` on checked arguments."""
    direction = math.copysign(1.0, branch.values[-1] - branch.values[0])
    m, dim = len(grid), len(imap.continuation_scale)
    found = np.full(m, np.nan)
    plate, multipliers = np.full((m, dim), np.nan), np.full((m, dim), np.nan, dtype=complex)
    bracket = np.full(m, np.nan)
    value, state, message = point.value, point.plate, "followed over the whole grid"
    for j, x in enumerate(grid):
        here = _relocate(imap.at(second, float(x)), branch, point.kind, value, state, direction, window, xtol)
        if here is None:
            message = f"lost at {second} = {x:g}: no {point.kind} within the window around {value:g}"
            break
        found[j], plate[j], multipliers[j], bracket[j] = here.value, here.plate, here.multipliers, here.bracket
        value, state = here.value, here.plate
    return BifurcationCurve(point.kind, branch.param, second, grid, found, plate, multipliers, bracket, message)


def _relocate(imap, branch, kind, value, state, direction, window, xtol):
    """The point of ``kind`` of the branch nearest ``value`` in the window around it, widened up to
    three times; None if none."""
    for _ in range(4):
        start, stop = value - direction * window, value + direction * window
        if branch.param in imap.positive_parameters:
            start, stop = max(start, value / 2), max(stop, value / 2)
        near = continue_orbit(imap, branch.param, start, stop, k=branch.period_k, guess=state, step=window / 5,
                              xtol=xtol)
        matches = [p for p in near.points if p.kind == kind]
        if matches:
            return min(matches, key=lambda p: abs(p.value - value))
        window *= 2
    return None
