"""Maps of a state to the next (``P: R^n -> R^n``) and the analyses written once over them.

An :class:`ImpactMap` is what the analyses of this package need from a map: the map itself
(``map(state)``), the scales of its state, and optionally its Jacobian, its parameters and a
discrete structure of each step (the contacts of an impact). Over any such map: :func:`iterate`
(an orbit), :func:`fixed_point` (periodic orbits ``P^k(z) = z`` with their multipliers),
:func:`attracting_orbit_of`, :func:`lyapunov` (here); orbit diagrams
(:mod:`phaseimpact.maps.orbit_diagram`), basins of attraction (:mod:`phaseimpact.maps.basins`),
continuation of periodic orbits and of their bifurcations (:mod:`phaseimpact.maps.continuation`).
The model's impact map is :class:`~phaseimpact.maps.impact.ModelImpactMap`.

How to add a map
----------------
Subclass :class:`ImpactMap` and give it

1. ``scale``: an array of the state's scales, shape ``(n,)``, positive (tolerances and the
   finite-difference steps are fractions of it);
2. ``__call__(state)``: the next state, an array of shape ``(n,)``;
3. optionally ``derivative(state)``: the exact Jacobian of one step, shape ``(n, n)`` (without it
   the Jacobian is taken by central differences);
4. optionally ``parameters`` (the names :meth:`ImpactMap.at` accepts) and ``at(name, value)``: the
   same map at another value of a parameter (orbit diagrams and continuation need it), and
   ``check_parameter`` to refuse values out of range before any work;
5. optionally ``step(state) -> (next state, record)`` and ``structure(record)``: a tuple of counts
   describing the step (a change along a branch is reported as ``grazing``), None where the map
   is undefined (a failed run), with their names in ``structure_names``.

The Hénon map, ``(x, y) -> (1 - a x^2 + y, b x)``, which tests/test_maps.py runs as written::

    class Henon(ImpactMap):
        parameters = ("a", "b")
        scale = np.array([1.0, 1.0])

        def __init__(self, a=1.4, b=0.3):
            self.a, self.b = a, b

        def __call__(self, state):
            x, y = state
            return np.array([1 - self.a * x * x + y, self.b * x])

        def derivative(self, state):
            return np.array([[-2 * self.a * state[0], 1.0], [self.b, 0.0]])

        def at(self, name, value):
            return Henon(**{"a": self.a, "b": self.b, name: value})

Then ``fixed_point(Henon(), guess=(0.6, 0.2))``, ``lyapunov(Henon())``,
``continue_orbit(Henon(a=0.2), "a", 0.2, 0.5)`` (its period doubling at ``a = 3 (1 - b)^2 / 4``)
and ``orbit_diagram(Henon(), "a", values)`` work as for the impact map.
"""

from __future__ import annotations

import functools
import math
import operator
from dataclasses import dataclass

import numpy as np

from ..parameters import is_number

__all__ = ["ImpactMap", "AffineMap", "MapFixedPoint", "iterate", "fixed_point", "attracting_orbit_of", "lyapunov",
           "JACOBIAN_STEP", "ATTRACTION_RADIUS", "LYAPUNOV_SETTLE", "MAX_LYAPUNOV_TRANSIENTS"]

#: Relative step of the finite-difference Jacobian of a map (of the state's scale); ten times it checks it.
JACOBIAN_STEP = 1e-6
#: How far (in the state's scales) the last sample may lie from a stable orbit found from it and still
#: count as on its way there (the samples' distances to it must shrink as well).
ATTRACTION_RADIUS = 1e-2
#: What the start's distance to a stable orbit, and the tangent vector's distance to its direction, have
#: shrunk to when :func:`lyapunov` starts averaging (its transients chosen from the multiplier).
LYAPUNOV_SETTLE = 1e-8
#: Most transient steps :func:`lyapunov` chooses (a multiplier within 2e-4 of the unit circle).
MAX_LYAPUNOV_TRANSIENTS = 100_000
#: Residual (in the state's scales) below which a periodic orbit counts as found.
FOUND = 1e-9


class ImpactMap:
    """A map ``P`` of a state to the next: the interface of the analyses of :mod:`phaseimpact.maps`
    (the module's guide says how to add one).

    Attributes
    ----------
    scale : ndarray, shape (n,)
        The state's scales (a subclass sets it).
    parameters : tuple of str
        Names :meth:`at` accepts (none by default).
    structure_names : tuple of str
        Names of the counts :meth:`structure` gives per step (none by default).
    positive_parameters : tuple of str
        Parameters that stay positive (a two-parameter continuation keeps its windows above 0).
    states : str
        What its states are, for messages (``states of the map`` by default).

    Examples
    --------
    >>> m = AffineMap([[0.5, 0.0], [0.0, -0.5]], [1.0, 1.0])
    >>> isinstance(m, ImpactMap), m((0.0, 0.0)).tolist()
    (True, [1.0, 1.0])
    """

    parameters: tuple[str, ...] = ()
    structure_names: tuple[str, ...] = ()
    positive_parameters: tuple[str, ...] = ()
    states = "states of the map"

    def __call__(self, state) -> np.ndarray:
        raise NotImplementedError(f"{type(self).__name__} does not define __call__(state), the next state")

    @property
    def origin(self) -> np.ndarray:
        """Where iterations start by default: the zero state (the plate at rest for the impact map)."""
        return np.zeros(len(self.scale))

    @property
    def continuation_scale(self) -> np.ndarray:
        """The state's scales in the continuation's space (default :attr:`scale`)."""
        return np.asarray(self.scale, dtype=float)

    def step(self, state):
        """One step and its record.

        Parameters
        ----------
        state : array, shape (n,)

        Returns
        -------
        (ndarray, object)
            The next state and what the map records of the step (None by default; the engine's run
            for the impact map), which :meth:`structure` reads.

        Examples
        --------
        >>> AffineMap([[2.0]], [1.0]).step([3.0])
        (array([7.]), None)
        """
        return np.asarray(self(state), dtype=float), None

    def structure(self, record) -> tuple | None:
        """The counts that describe a step (:attr:`structure_names`), None where the map is undefined.

        Parameters
        ----------
        record : object
            The second item of :meth:`step`.

        Returns
        -------
        tuple of int or None
            Empty by default.

        Examples
        --------
        >>> AffineMap([[2.0]], [1.0]).structure(None)
        ()
        """
        return ()

    def end_reason(self, counts) -> str | None:
        """Why the map ends at an orbit with these counts per period (a continuation stops there).

        Parameters
        ----------
        counts : tuple of int
            :meth:`structure` summed over the orbit's steps.

        Returns
        -------
        str or None
            None by default (the map goes on).

        Examples
        --------
        >>> AffineMap([[2.0]], [1.0]).end_reason(()) is None
        True
        """
        return None

    def derivative(self, state) -> np.ndarray | None:
        """The exact Jacobian of one step, or None (the default) for central differences.

        Parameters
        ----------
        state : array, shape (n,)

        Returns
        -------
        ndarray, shape (n, n), or None

        Examples
        --------
        >>> AffineMap([[2.0]], [1.0]).derivative([0.0]).tolist()
        [[2.0]]
        """
        return None

    def jacobian(self, state, k: int = 1) -> tuple[np.ndarray, float]:
        """The Jacobian of ``P^k`` at ``state`` and its accuracy.

        Exact (the product of :meth:`derivative` along the orbit, accuracy 0) where the map gives
        its derivative; else by central differences with the steps :data:`JACOBIAN_STEP` and
        ``10 JACOBIAN_STEP`` of the scales, the accuracy being the largest relative change of an
        entry between the two (in the state's scales).

        Parameters
        ----------
        state : array, shape (n,)
        k : int, default 1
            The power of the map.

        Returns
        -------
        (ndarray, float)
            Shape (n, n), and the accuracy.

        Examples
        --------
        >>> J, accuracy = AffineMap([[0.5, 1.0], [0.0, 0.5]], [0.0, 0.0]).jacobian([1.0, 1.0], k=2)
        >>> J.tolist(), accuracy
        ([[0.25, 1.0], [0.0, 0.25]], 0.0)
        """
        z = np.asarray(state, dtype=float)
        first = self.derivative(z)
        if first is not None:
            J = np.asarray(first, dtype=float)
            for _ in range(k - 1):
                z = np.asarray(self(z), dtype=float)
                J = np.asarray(self.derivative(z), dtype=float) @ J
            return J, 0.0
        return _central_jacobian(lambda x: _power(self, x, k), z, np.asarray(self.scale, dtype=float))

    def at(self, name: str, value: float) -> ImpactMap:
        """The same map at ``name = value``.

        Parameters
        ----------
        name : str
            One of :attr:`parameters`.
        value : float

        Returns
        -------
        ImpactMap

        Raises
        ------
        ValueError
            For a map without parameters (the default).

        Examples
        --------
        >>> AffineMap([[2.0]], [1.0]).at("a", 1.0)
        Traceback (most recent call last):
        ...
        ValueError: name = 'a' is out of range; allowed: one of the map's parameters (none)
        """
        raise ValueError(f"name = {name!r} is out of range; allowed: one of the map's parameters "
                         f"({', '.join(self.parameters) or 'none'})")

    def check_parameter(self, name: str, value, label: str) -> float:
        """``value`` of parameter ``name`` as a float, checked before any work.

        Parameters
        ----------
        name : str
            One of :attr:`parameters`.
        value : float
        label : str
            The argument's name, for the message.

        Returns
        -------
        float

        Raises
        ------
        ValueError
            A value that is not a finite number (the default's only check).

        Examples
        --------
        >>> AffineMap([[2.0]], [1.0]).check_parameter("a", 2, "start")
        2.0
        """
        if not (is_number(value) and math.isfinite(value)):
            raise ValueError(f"{label} = {value!r} is out of range; allowed: a finite number")
        return float(value)

    def check(self) -> None:
        """Refuse a map that cannot be iterated, before any work (nothing to check by default).

        Examples
        --------
        >>> AffineMap([[2.0]], [1.0]).check()
        """


class AffineMap(ImpactMap):
    """``z -> A z + b``: the impact map of the impulsive limit (docs/physics.md §7) is one.

    Parameters
    ----------
    matrix : array, shape (n, n)
    offset : array, shape (n,)
    scale : array, shape (n,), optional
        The state's scales; default 1 each.

    Examples
    --------
    Its fixed point is ``(I - A)^-1 b``:

    >>> fp = fixed_point(AffineMap([[0.5, 0.0], [0.0, -0.5]], [1.0, 1.0]))
    >>> [f"{x:.4f}" for x in fp.plate], fp.stable
    (['2.0000', '0.6667'], True)
    """

    def __init__(self, matrix, offset, scale=None):
        self.matrix = np.asarray(matrix, dtype=float)
        self.offset = np.asarray(offset, dtype=float)
        self.scale = np.ones(len(self.offset)) if scale is None else np.asarray(scale, dtype=float)

    def __call__(self, state) -> np.ndarray:
        return self.matrix @ np.asarray(state, dtype=float) + self.offset

    def derivative(self, state) -> np.ndarray:
        """``A``.

        Parameters
        ----------
        state : array, shape (n,)

        Returns
        -------
        ndarray, shape (n, n)

        Examples
        --------
        >>> AffineMap([[2.0]], [1.0]).derivative([5.0]).tolist()
        [[2.0]]
        """
        return self.matrix


def check_count(name: str, n, low: int, high: int) -> int:
    """``n`` as an int in ``[low, high]``, else a ValueError naming it."""
    if not (isinstance(n, (int, np.integer)) and not isinstance(n, bool) and low <= n <= high):
        raise ValueError(f"{name} = {n!r} is out of range; allowed: an integer, {low} <= {name} <= {high}")
    return int(n)


def _power(imap, z, k):
    for _ in range(k):
        z = imap(z)
    return z


def _central_jacobian(f, z, scale):
    """Central differences of ``f`` at ``z`` with two steps (see :meth:`ImpactMap.jacobian`)."""
    n = len(z)

    def central(step):
        J = np.empty((n, n))
        for j in range(n):
            h = np.zeros(n)
            h[j] = step * scale[j]
            J[:, j] = (f(z + h) - f(z - h)) / (2 * h[j])
        return J

    fine, coarse = central(JACOBIAN_STEP), central(10 * JACOBIAN_STEP)
    norm = np.max(np.abs(fine * scale[None, :] / scale[:, None])) or 1.0
    accuracy = float(np.max(np.abs((fine - coarse) * scale[None, :] / scale[:, None])) / norm)
    return fine, accuracy


def solve(equations, start):
    """scipy's hybrid Powell on ``equations(x) = 0`` from ``start``: ``(x, largest |residual| there,
    scipy's message)``. The residual decides, not scipy's flag: hybr reports "no progress" on a
    solution already at rounding level."""
    from scipy.optimize import root  # imported where used: 0.5 s at start-up

    sol = root(equations, start, method="hybr", options={"xtol": 1e-13})
    return sol.x, float(np.max(np.abs(equations(sol.x)))), sol.message


def bifurcation_tests(multipliers) -> dict:
    """The test functions of the smooth bifurcations of a periodic orbit, zero there and changing
    sign: ``det(J + I)`` (period doubling), ``det(J - I)`` (fold) and, for a complex pair of a
    two-dimensional map, ``det J - 1`` (Neimark–Sacker; NaN otherwise)."""
    m = list(multipliers)
    complex_pair = len(m) == 2 and abs(m[0].imag) > 1e-12
    return {"period-doubling": float(functools.reduce(operator.mul, [1 + x for x in m]).real),
            "fold": float(functools.reduce(operator.mul, [1 - x for x in m]).real),
            "neimark-sacker": float((m[0] * m[1]).real - 1) if complex_pair else math.nan}


def iterate(imap: ImpactMap, state, n: int) -> np.ndarray:
    """The orbit of ``state``: ``n`` steps of the map.

    Parameters
    ----------
    imap : ImpactMap
    state : array, shape (dim,)
    n : int
        Steps, >= 0.

    Returns
    -------
    ndarray, shape (n + 1, dim)
        ``state`` and the states after each step.

    Examples
    --------
    >>> iterate(AffineMap([[0.5]], [1.0]), [0.0], 3).ravel().tolist()
    [0.0, 1.0, 1.5, 1.75]
    """
    states = np.empty((n + 1, len(imap.scale)))
    states[0] = state
    for i in range(n):
        states[i + 1] = imap(states[i])
    return states


@dataclass(frozen=True)
class MapFixedPoint:
    """A periodic orbit of a map: ``P^k(z) = z``.

    Attributes
    ----------
    plate : ndarray, shape (n,)
        The state at the orbit's first step (for the impact map the plate's ``(x2, x2dot)`` just
        before the orbit's first impact, m and m/s).
    period_k : int
        ``k``: the orbit repeats every ``k`` steps.
    multipliers : ndarray, shape (n,), complex
        Floquet multipliers: the eigenvalues of the Jacobian of ``P^k`` at ``plate``.
    stable : bool
        Every multiplier inside the unit circle.
    residual : float
        ``|P^k(z) - z|`` in units of the state's scales (Hertz indentation and ``v`` for the impact map).
    jacobian_accuracy : float
        Largest change of the Jacobian's entries between two finite-difference steps (relative; 0
        for an exact Jacobian).
    converged : bool
        The residual is below 1e-9.
    message : str
        Empty when converged, else why not.

    Examples
    --------
    From :func:`fixed_point` or :func:`~phaseimpact.maps.impact.map_fixed_point`:

    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.maps import map_fixed_point
    >>> fp = map_fixed_point(seed_parameters(kappa=3e9), "hunt-crossley", 0.4e-3)
    >>> fp.period_k, fp.stable, fp.converged
    (1, True, True)
    """

    plate: np.ndarray
    period_k: int
    multipliers: np.ndarray
    stable: bool
    residual: float
    jacobian_accuracy: float
    converged: bool
    message: str

    def as_dict(self) -> dict:
        """The orbit as JSON-ready numbers.

        Returns
        -------
        dict
            The attributes; ``plate`` as a list, multipliers as ``{re, im, abs}``.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.maps import map_fixed_point
        >>> d = map_fixed_point(seed_parameters(kappa=3e9), "hunt-crossley", 0.4e-3).as_dict()
        >>> [f"{m['abs']:.3f}" for m in d["multipliers"]], d["stable"]
        (['0.450', '0.450'], True)
        """
        return {"plate": self.plate.tolist(), "period_k": self.period_k,
                "multipliers": multipliers_dict(self.multipliers),
                "stable": self.stable, "residual": self.residual, "jacobian_accuracy": self.jacobian_accuracy,
                "converged": self.converged, "message": self.message}


def multipliers_dict(multipliers) -> list:
    """Multipliers as JSON-ready ``{re, im, abs}``."""
    return [{"re": float(m.real), "im": float(m.imag), "abs": float(abs(m))} for m in multipliers]


def fixed_point(imap: ImpactMap, *, k: int = 1, guess=None) -> MapFixedPoint:
    """A periodic orbit of period ``k`` of a map (scipy's ``root``, hybrid Powell, in the state's
    scales), with its Floquet multipliers.

    Parameters
    ----------
    imap : ImpactMap
    k : int, default 1
        The orbit's period in steps (1 to 64).
    guess : array, shape (n,), optional
        Where to start; default the state after 50 steps from :attr:`ImpactMap.origin` (a stable
        orbit's neighbourhood).

    Returns
    -------
    MapFixedPoint
        ``converged`` False (``message`` says why) when no orbit is found from the guess.

    Raises
    ------
    ValueError
        ``k`` out of range, or a map its :meth:`ImpactMap.check` refuses.

    Examples
    --------
    The logistic map ``x -> r x (1 - x)`` at ``r = 3.2``: its period-2 orbit, stable, with the
    multiplier ``4 + 2 r - r^2 = 0.16``:

    >>> class Logistic(ImpactMap):
    ...     scale = np.array([1.0])
    ...     def __call__(self, state):
    ...         return 3.2 * state * (1 - state)
    >>> fp = fixed_point(Logistic(), k=2, guess=[0.5])
    >>> f"{fp.plate[0]:.6f}", f"{fp.multipliers[0].real:.6f}", fp.stable
    ('0.513045', '0.160000', True)
    """
    imap.check()
    k = check_count("k", k, 1, 64)
    scale = np.asarray(imap.scale, dtype=float)
    if guess is None:
        guess = iterate(imap, imap.origin, 50)[-1]
    z0 = np.asarray(guess, dtype=float) / scale

    def residual(u):
        z = u * scale
        return (_power(imap, z, k) - z) / scale

    x, res, message = solve(residual, z0)
    z = x * scale
    J, accuracy = imap.jacobian(z, k)
    multipliers = np.linalg.eigvals(J)
    converged = bool(res < FOUND)
    return MapFixedPoint(z, int(k), multipliers, bool(np.all(np.abs(multipliers) < 1)), res, accuracy, converged,
                         "" if converged else f"no periodic orbit found from the guess ({message})")


def attracting_orbit_of(imap: ImpactMap, samples, *, max_period: int = 8) -> MapFixedPoint | None:
    """The stable periodic orbit that consecutive states ``samples`` converge to, found by converging
    to it: :func:`fixed_point` from the last sample for ``k = 1, 2, ... max_period``; the first stable
    orbit counts when the samples approach it (their distance to its nearest point shrinks over the
    samples and ends within :data:`ATTRACTION_RADIUS` of the state's scales).

    Parameters
    ----------
    imap : ImpactMap
    samples : array, shape (m, n)
        Consecutive states of the map, m >= 2.
    max_period : int, default 8
        Longest period tried (1 to 64).

    Returns
    -------
    MapFixedPoint or None
        None when no stable orbit of period up to ``max_period`` is found that the samples approach.

    Raises
    ------
    ValueError
        Samples that are not finite states of shape (m, n) with m >= 2, or ``max_period`` out of range.

    Examples
    --------
    The logistic map at ``r = 3.2`` from ``x = 0.3``: its period-2 orbit.

    >>> class Logistic(ImpactMap):
    ...     scale = np.array([1.0])
    ...     def __call__(self, state):
    ...         return 3.2 * state * (1 - state)
    >>> attracting_orbit_of(Logistic(), iterate(Logistic(), [0.3], 40)[30:]).period_k
    2
    """
    samples = check_samples(imap, samples)
    max_period = check_count("max_period", max_period, 1, 64)
    return _attracting(imap, samples, max_period)


def check_samples(imap: ImpactMap, samples) -> np.ndarray:
    """``samples`` as finite states of shape (m, n), m >= 2, else a ValueError."""
    samples = np.asarray(samples, dtype=float)
    n = len(imap.scale)
    if samples.ndim != 2 or samples.shape[1] != n or len(samples) < 2 or not np.all(np.isfinite(samples)):
        raise ValueError(f"samples of shape {samples.shape} are out of range; allowed: finite {imap.states}, "
                         f"shape (n, {n}) with n >= 2")
    return samples


def _attracting(imap, samples, max_period):
    scale = np.asarray(imap.scale, dtype=float)
    for k in range(1, max_period + 1):
        fp = fixed_point(imap, k=k, guess=samples[-1])
        if not (fp.converged and fp.stable):
            continue
        points = [fp.plate]
        for _ in range(k - 1):
            points.append(imap(points[-1]))
        points = np.array(points) / scale
        distance = np.min(np.linalg.norm(samples[:, None, :] / scale - points[None, :, :], axis=2), axis=1)
        # on it (to the orbit diagram's 1e-6) or still approaching it
        if distance[-1] <= ATTRACTION_RADIUS and (distance[-1] <= distance[0] or distance.max() < 1e-6):
            return fp
    return None


def _lyapunov_transients(imap, z):
    """Steps to discard before averaging: until the slowest multiplier ``mu`` (per step) of the stable
    orbit the start approaches has shrunk its distance to :data:`LYAPUNOV_SETTLE`,
    ``log(LYAPUNOV_SETTLE) / log |mu|``, a whole number of the orbit's periods; 0 when no such orbit is
    found (an irregular attractor: nothing to wait for). Also the period ``k`` (1 when none)."""
    orbit = _attracting(imap, check_samples(imap, iterate(imap, z, 16)), 8)
    if orbit is None:
        return 0, 1
    k = orbit.period_k
    slowest = float(np.max(np.abs(orbit.multipliers))) ** (1.0 / k)
    if slowest == 0.0:
        return 0, k
    n = math.ceil(math.log(LYAPUNOV_SETTLE) / math.log(slowest) / k) * k
    return min(n, MAX_LYAPUNOV_TRANSIENTS), k


def lyapunov(imap: ImpactMap, *, state=None, iterations: int = 200, transients: int | None = None) -> float:
    """The largest Lyapunov exponent of a map (per step): the mean of ``log |J_n w_n|`` along the orbit
    from ``state``, ``w`` renormalised each step (in the state's scales), ``J_n`` the map's Jacobian.
    Negative on a stable periodic orbit (the log of its largest multiplier's modulus, per step),
    positive when chaotic.

    The mean starts after ``transients`` steps (``w`` carried along): by default as many as the
    slowest multiplier of the stable orbit the start approaches (:func:`attracting_orbit_of`) needs
    to bring both the orbit and ``w`` within :data:`LYAPUNOV_SETTLE`.

    Parameters
    ----------
    imap : ImpactMap
    state : array, shape (n,), optional
        Where to start; default the state after 100 steps from :attr:`ImpactMap.origin`.
    iterations : int, default 200
        Steps averaged over, 1 to 100000 (rounded up to a whole number of the orbit's periods).
    transients : int, optional
        Steps before the mean (0 to 100000); default chosen from the multiplier as above (0 when no
        stable orbit of period up to 8 is found).

    Returns
    -------
    float
        The exponent, per step.

    Raises
    ------
    ValueError
        ``iterations`` or ``transients`` out of range, or a map its :meth:`ImpactMap.check` refuses.

    Examples
    --------
    The logistic map at ``r = 4`` is chaotic with the exponent ``log 2`` (Ulam and von Neumann):

    >>> class Logistic(ImpactMap):
    ...     scale = np.array([1.0])
    ...     def __call__(self, state):
    ...         return 4.0 * state * (1 - state)
    ...     def derivative(self, state):
    ...         return np.array([[4.0 - 8.0 * state[0]]])
    >>> f"{lyapunov(Logistic(), state=[0.3], iterations=20000, transients=0):.2f}"
    '0.69'
    """
    imap.check()
    check_count("iterations", iterations, 1, 100_000)
    if transients is not None:
        check_count("transients", transients, 0, 100_000)
    return _lyapunov(imap, state, iterations, transients)


def _lyapunov(imap, state, iterations, transients):
    scale = np.asarray(imap.scale, dtype=float)
    z = iterate(imap, imap.origin, 100)[-1] if state is None else np.asarray(state, float)
    k = 1
    if transients is None:
        transients, k = _lyapunov_transients(imap, z)
    iterations = math.ceil(iterations / k) * k
    w = np.ones(len(scale)) / math.sqrt(len(scale))
    total = 0.0
    for n in range(transients + iterations):
        J, _ = imap.jacobian(z)
        w = (J * scale[None, :] / scale[:, None]) @ w  # in the state's scales
        growth = float(np.linalg.norm(w))
        if n >= transients:
            total += math.log(growth)
        w /= growth
        z = imap(z)
    return total / iterations
