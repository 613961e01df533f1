"""Trains of impacts as a map: a projectile of the case arrives every ``period`` seconds on the plate
as the previous impacts left it (docs/physics.md §7).

The impact map ``P`` takes the plate's state ``z = (x2, x2dot)`` just before impact ``n`` (a fresh
projectile touching the plate, ``x1 = x2``, at the case's speed ``v``) to its state just before impact
``n + 1``: one run of the engine over ``[0, period]`` with stick, slip, separation and any further
contact of that projectile resolved as for a single impact; the projectile is then taken away (a
stream of grains hits fresh places of a blade) and the next one arrives. On the map:
:func:`impact_train` (the response to ``N`` impacts), :func:`map_fixed_point` (periodic orbits of
period ``k``: ``P^k(z) = z``, with their Floquet multipliers), :func:`orbit_diagram` (the attractor
sampled after transients over a parameter), :func:`lyapunov_exponent`, :func:`continue_map_orbit` (a
branch of periodic orbits followed over a parameter, its period-doubling, fold, Neimark–Sacker and
grazing points located), :func:`continue_map_bifurcation` (such a point followed in a second
parameter) and :func:`basins` (basins of attraction in the plate's initial state).

A projectile still in contact when the next one arrives (a period shorter than the contact) has
no meaning in this model: such a run is reported (``overlap``), never silently cut.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .integrate import simulate
from .model import as_law
from .parameters import Parameters, is_number

__all__ = ["ImpactTrain", "MapFixedPoint", "OrbitDiagram", "impact_map", "impact_train", "map_fixed_point",
           "map_jacobian", "orbit_diagram", "lyapunov_exponent", "TRAIN_PARAMETERS", "MapBifurcation", "MapBranch",
           "BifurcationCurve", "Attractor", "Basins", "continue_map_orbit", "continue_map_bifurcation", "basins",
           "BIFURCATION_KINDS", "NOT_CONVERGED", "NO_MAP", "ATTRACTOR_MATCH", "period_range",
           "MAX_PERIOD_SWINGS", "attracting_orbit", "ATTRACTION_RADIUS", "LYAPUNOV_SETTLE", "MAX_LYAPUNOV_TRANSIENTS"]

#: Parameters an orbit diagram runs over (the period ``T``, s; the damping ``kappa``; the speed ``v``, m/s).
TRAIN_PARAMETERS = ("T", "kappa", "v")
#: Relative step of the finite-difference Jacobian of the map (of the state's scale), and the
#: second step that checks it.
JACOBIAN_STEP = 1e-6


#: Longest period between arrivals, in plate periods (contact times without the plate's springs):
#: beyond it the phase of the plate's swing at the next arrival is lost to rounding.
MAX_PERIOD_SWINGS = 1e6


def period_range(params: Parameters) -> tuple[float, float, str]:
    """The periods between arrivals the impact map can resolve for ``params``.

    Parameters
    ----------
    params : Parameters
        The case: its contact time (Hertz, at its ``v``) and its plate period.

    Returns
    -------
    (float, float, str)
        The shortest and the longest period (s), and why, in words for a message: from
        ``MIN_HORIZON_CONTACT_TIMES`` contact times to :data:`MAX_PERIOD_SWINGS` plate periods
        (contact times on a rigid or free target).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> shortest, longest, _ = period_range(seed_parameters(v=1.0))
    >>> print(f"{shortest:.3g} s to {longest:.4g} s")
    1.08e-17 s to 1004 s
    """
    from .integrate import scales
    from .integrate.api import MIN_HORIZON_CONTACT_TIMES

    contact_time = scales(params).contact_time
    swing = params.target_period if math.isfinite(params.target_period) else contact_time
    swing_name = "plate periods" if math.isfinite(params.target_period) else "contact times"
    why = (f"from {MIN_HORIZON_CONTACT_TIMES:g} of the contact time {contact_time:.3g} s, below which nothing can be "
           f"resolved, to {MAX_PERIOD_SWINGS:g} {swing_name} ({swing:.3g} s), beyond which the plate's state at the "
           "next arrival is lost to rounding")
    return MIN_HORIZON_CONTACT_TIMES * contact_time, MAX_PERIOD_SWINGS * swing, why


def _check_period(period, params: Parameters, name: str = "period") -> float:
    if not (is_number(period) and math.isfinite(period) and period > 0):
        raise ValueError(f"{name} = {period!r} is out of range; allowed: a finite number > 0 (s)")
    shortest, longest, why = period_range(params)
    if not shortest <= period <= longest:
        raise ValueError(f"{name} = {period!r} is out of range; allowed: {shortest:.3g} <= {name} <= {longest:.3g} s "
                         f"({why})")
    return float(period)


def _state_scale(params: Parameters) -> np.ndarray:
    """The scales of ``(x2, x2dot)``: the Hertz indentation and the impact speed."""
    return np.array([params.hertz_indentation, params.v])


def impact_map(params: Parameters, law, period: float, plate, *, rtol: float = 1e-10):
    """One application of the impact map: ``(next plate state, the run)``.

    Parameters
    ----------
    params : Parameters
        The case (``v``, m/s: each projectile's speed).
    law : ContactLaw or str
    period : float
        Time between arrivals, s (> 0).
    plate : 2 numbers
        ``(x2, x2dot)`` (m, m/s) just before the impact.
    rtol : float
        The integrator's relative tolerance.

    Returns
    -------
    (ndarray, Trajectory)
        The plate's ``(x2, x2dot)`` just before the next arrival, and the run over ``[0, period]``.

    Examples
    --------
    One projectile on the plate at rest, the next arriving 3 ms later:

    >>> from phaseimpact import seed_parameters
    >>> z, run = impact_map(seed_parameters(kappa=3e9), "hunt-crossley", 3e-3, (0.0, 0.0))
    >>> run.status, f"{run.max_force:.4g} N", f"{z[1]:.3g} m/s"
    ('success', '4629 N', '0.172 m/s')
    """
    x2, x2dot = (float(plate[0]), float(plate[1]))
    run = simulate(params, law, period, rtol=rtol, initial=(x2, x2, params.v, x2dot), stop_when_settled=False)
    return np.array([run.final_state[1], run.final_state[3]]), run


@dataclass(frozen=True)
class ImpactTrain:
    """The response of the plate to ``N`` impacts, one row per impact ``n`` (arrival at ``n T``).

    Attributes
    ----------
    period : float
        s.
    plate : ndarray, shape (N + 1, 2)
        ``(x2, x2dot)`` just before each arrival (m, m/s); the last row after the last impact.
    peak_force, dissipated_energy, restitution : ndarray, shape (N,)
        Each impact's largest contact force (N), the energy its contact dissipated (J) and its
        coefficient of restitution (relative velocities; NaN if the projectile did not separate).
    energy_in : ndarray, shape (N,)
        Kinetic energy the projectile left in the plate and the contact, ``M1 (v^2 - v_out^2) / 2`` (J).
    n_contacts : ndarray, shape (N,)
    amplitude : ndarray, shape (N + 1,)
        The plate's amplitude before each arrival (m), its build-up: the turning point of its
        undamped linear swing, ``sqrt(x2^2 + (x2dot / omega)^2)``, ``omega = sqrt(Kb/M2)``.
    overlap : ndarray of bool, shape (N,)
        The projectile was still in contact when the next one arrived.
    status : list of str
        Each run's status (``success`` or a failure).

    Examples
    --------
    From :func:`impact_train`:

    >>> from phaseimpact import seed_parameters
    >>> train = impact_train(seed_parameters(kappa=3e9), "hunt-crossley", 3e-3, 3)
    >>> train.plate.shape, train.peak_force.shape, bool(train.overlap.any())
    ((4, 2), (3,), False)
    """

    period: float
    plate: np.ndarray
    peak_force: np.ndarray
    dissipated_energy: np.ndarray
    restitution: np.ndarray
    energy_in: np.ndarray
    n_contacts: np.ndarray
    amplitude: np.ndarray
    overlap: np.ndarray
    status: list

    def as_dict(self) -> dict:
        """The train as JSON-ready lists.

        Returns
        -------
        dict
            ``period`` (s), ``impacts`` (their number) and the attributes as lists (SI units as above).

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> d = impact_train(seed_parameters(kappa=3e9), "hunt-crossley", 3e-3, 2).as_dict()
        >>> d["impacts"], len(d["plate"]), d["status"]
        (2, 3, ['success', 'success'])
        """
        return {"period": self.period, "impacts": len(self.peak_force), "plate": self.plate.tolist(),
                "amplitude": self.amplitude.tolist(), "peak_force": self.peak_force.tolist(),
                "dissipated_energy": self.dissipated_energy.tolist(), "restitution": self.restitution.tolist(),
                "energy_in": self.energy_in.tolist(), "n_contacts": self.n_contacts.tolist(),
                "overlap": self.overlap.tolist(), "status": list(self.status)}


def impact_train(params: Parameters, law, period: float, impacts: int, *, plate=(0.0, 0.0),
                 rtol: float = 1e-10) -> ImpactTrain:
    """``impacts`` impacts, one every ``period`` seconds, on a plate starting at ``plate``.

    Parameters
    ----------
    params : Parameters
        The case (``v``, m/s: each projectile's speed).
    law : ContactLaw or str
    period : float
        Time between arrivals, s (> 0).
    impacts : int
        Number of impacts, 1 to 100000.
    plate : 2 numbers, default (0, 0)
        ``(x2, x2dot)`` (m, m/s) before the first impact.
    rtol : float, default 1e-10
        The integrator's relative tolerance.

    Returns
    -------
    ImpactTrain

    Raises
    ------
    ValueError
        A period or a number of impacts out of range.

    Examples
    --------
    Three impacts 3 ms apart (three plate periods) on the seed case's plate, at rest at first:

    >>> from phaseimpact import seed_parameters
    >>> train = impact_train(seed_parameters(kappa=3e9), "hunt-crossley", 3e-3, 3)
    >>> [f"{f:.3g}" for f in train.peak_force], [f"{e:.3g}" for e in train.restitution]
    (['4.63e+03', '4.14e+03', '4.83e+03'], ['0.868', '0.851', '0.88'])
    >>> [f"{a * 1e6:.3g}" for a in train.amplitude]  # micrometres, before each arrival
    ['0', '27.6', '55.1', '10']
    """
    law = as_law(law)
    period = _check_period(period, params)
    if not (isinstance(impacts, (int, np.integer)) and not isinstance(impacts, bool) and 1 <= impacts <= 100_000):
        raise ValueError(f"impacts = {impacts!r} is out of range; allowed: an integer, 1 <= impacts <= 100000")
    states = np.empty((impacts + 1, 2))
    states[0] = plate
    rows = np.full((impacts, 5), np.nan)
    overlap = np.zeros(impacts, bool)
    status = []
    for n in range(impacts):
        states[n + 1], run = impact_map(params, law, period, states[n], rtol=rtol)
        v_out = run.final_state[2]
        rows[n] = (run.max_force, run.dissipated_energy, run.restitution if run.restitution is not None else np.nan,
                   0.5 * params.M1 * (params.v**2 - v_out**2), run.n_contacts)
        overlap[n] = run.final_state[0] - run.final_state[1] > 0
        status.append(run.status)
    omega = math.sqrt(params.Kb / params.M2) if params.target == "plate" and params.Kb > 0 else math.inf
    amplitude = np.hypot(states[:, 0], states[:, 1] / omega) if math.isfinite(omega) else np.abs(states[:, 0])
    return ImpactTrain(period, states, rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3], rows[:, 4].astype(np.int64),
                       amplitude, overlap, status)


@dataclass(frozen=True)
class MapFixedPoint:
    """A periodic orbit of the impact map: ``P^k(z) = z``.

    Attributes
    ----------
    plate : ndarray, shape (2,)
        ``(x2, x2dot)`` just before the orbit's first impact (m, m/s).
    period_k : int
        ``k``: the orbit repeats every ``k`` impacts.
    multipliers : ndarray, shape (2,), complex
        Floquet multipliers: the eigenvalues of the Jacobian of ``P^k`` at ``plate``.
    stable : bool
        Every multiplier inside the unit circle.
    residual : float
        ``|P^k(z) - z|`` in units of the state's scales (Hertz indentation, v).
    jacobian_accuracy : float
        Largest change of the Jacobian's entries between two finite-difference steps (relative).
    converged : bool
        The residual is below 1e-9.
    message : str
        Empty when converged, else why not.

    Examples
    --------
    From :func:`map_fixed_point`:

    >>> from phaseimpact import seed_parameters
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
            The attributes; ``plate`` as a list (m, m/s), multipliers as ``{re, im, abs}``.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> d = map_fixed_point(seed_parameters(kappa=3e9), "hunt-crossley", 0.4e-3).as_dict()
        >>> [f"{m['abs']:.3f}" for m in d["multipliers"]], d["stable"]
        (['0.450', '0.450'], True)
        """
        return {"plate": self.plate.tolist(), "period_k": self.period_k,
                "multipliers": [{"re": float(m.real), "im": float(m.imag), "abs": float(abs(m))}
                                for m in self.multipliers],
                "stable": self.stable, "residual": self.residual, "jacobian_accuracy": self.jacobian_accuracy,
                "converged": self.converged, "message": self.message}


def _map_k(params, law, period, z, k, rtol):
    for _ in range(k):
        z, _ = impact_map(params, law, period, z, rtol=rtol)
    return z


def map_jacobian(params: Parameters, law, period: float, plate, *, k: int = 1, rtol: float = 1e-12):
    """The Jacobian of ``P^k`` at ``plate`` by central differences, and its accuracy: the largest
    relative change of an entry between the steps ``JACOBIAN_STEP`` and ``10 JACOBIAN_STEP`` of
    the state's scales.

    Parameters
    ----------
    params : Parameters
        The case.
    law : ContactLaw or str
    period : float
        Time between arrivals, s (> 0).
    plate : 2 numbers
        ``(x2, x2dot)`` (m, m/s) where the Jacobian is taken.
    k : int, default 1
        The power of the map (impacts).
    rtol : float, default 1e-12
        The integrator's relative tolerance.

    Returns
    -------
    (ndarray, float)
        The Jacobian, shape (2, 2), in SI units (``d x2'/d x2`` dimensionless, ``d x2'/d x2dot`` in s,
        ``d x2dot'/d x2`` in 1/s), and its accuracy (relative, in the state's scales).

    Examples
    --------
    At the period-1 orbit its eigenvalues are the orbit's Floquet multipliers:

    >>> import numpy as np
    >>> from phaseimpact import seed_parameters
    >>> p = seed_parameters(kappa=3e9)
    >>> fp = map_fixed_point(p, "hunt-crossley", 0.4e-3)
    >>> J, accuracy = map_jacobian(p, "hunt-crossley", 0.4e-3, fp.plate)
    >>> J.shape, [f"{abs(m):.3f}" for m in np.linalg.eigvals(J)], bool(accuracy < 1e-6)
    ((2, 2), ['0.450', '0.450'], True)
    """
    scale = _state_scale(params)
    z = np.asarray(plate, dtype=float)

    def central(step):
        J = np.empty((2, 2))
        for j in range(2):
            h = np.zeros(2)
            h[j] = step * scale[j]
            J[:, j] = (_map_k(params, law, period, z + h, k, rtol) - _map_k(params, law, period, z - h, k, rtol)) / (
                2 * h[j])
        return J

    fine, coarse = central(JACOBIAN_STEP), central(10 * JACOBIAN_STEP)
    norm = np.max(np.abs(fine * scale[None, :] / scale[:, None])) or 1.0
    accuracy = float(np.max(np.abs((fine - coarse) * scale[None, :] / scale[:, None])) / norm)
    return fine, accuracy


def map_fixed_point(params: Parameters, law, period: float, *, k: int = 1, guess=None,
                    rtol: float = 1e-12) -> MapFixedPoint:
    """A periodic orbit of period ``k`` of the impact map (scipy's ``root``, hybrid Powell, in the
    state's scales), with its Floquet multipliers.

    Parameters
    ----------
    params : Parameters
    law : ContactLaw or str
    period : float
        Time between arrivals, s.
    k : int, default 1
        The orbit's period in impacts (1 to 64).
    guess : 2 numbers, optional
        ``(x2, x2dot)`` to start from; default the state after 50 impacts from rest (a stable
        orbit's neighbourhood).
    rtol : float, default 1e-12
        The integrator's relative tolerance.

    Returns
    -------
    MapFixedPoint
        ``converged`` False (``message`` says why) when no orbit is found from the guess.

    Raises
    ------
    ValueError
        A period or ``k`` out of range.

    Examples
    --------
    Impacts 0.4 ms apart (0.4 plate periods) settle on a stable period-1 orbit; with the Abrate law
    and 3 ms the period-1 orbit is unstable (a multiplier below -1):

    >>> from phaseimpact import seed_parameters
    >>> p = seed_parameters(kappa=3e9)
    >>> fp = map_fixed_point(p, "hunt-crossley", 0.4e-3)
    >>> fp.converged, fp.stable, f"{fp.plate[0] * 1e6:.3g} um", f"{fp.plate[1]:.3g} m/s"
    (True, True, '72.6 um', '-0.647 m/s')
    >>> fa = map_fixed_point(p, "abrate", 3e-3)
    >>> fa.stable, sorted(f"{m.real:.3g}" for m in fa.multipliers)
    (False, ['-0.569', '-1.43'])
    """
    from scipy.optimize import root

    law = as_law(law)
    period = _check_period(period, params)
    if not (isinstance(k, (int, np.integer)) and not isinstance(k, bool) and 1 <= k <= 64):
        raise ValueError(f"k = {k!r} is out of range; allowed: an integer, 1 <= k <= 64")
    scale = _state_scale(params)
    if guess is None:
        guess = impact_train(params, law, period, 50, rtol=rtol).plate[-1]
    z0 = np.asarray(guess, dtype=float) / scale

    def residual(u):
        z = u * scale
        return (_map_k(params, law, period, z, k, rtol) - z) / scale

    sol = root(residual, z0, method="hybr", options={"xtol": 1e-13})
    z = sol.x * scale
    res = float(np.max(np.abs(residual(sol.x))))
    J, accuracy = map_jacobian(params, law, period, z, k=k, rtol=rtol)
    multipliers = np.linalg.eigvals(J)
    converged = bool(res < 1e-9)  # hybr may report "no progress" on a solution already at rounding level
    return MapFixedPoint(z, int(k), multipliers, bool(np.all(np.abs(multipliers) < 1)), res, accuracy, converged,
                         "" if converged else f"no periodic orbit found from the guess ({sol.message})")


#: How far (in the state's scales) the last sample may lie from a stable orbit found from it and still
#: count as on its way there (the samples' distances to it must shrink as well).
ATTRACTION_RADIUS = 1e-2


def attracting_orbit(params: Parameters, law, period: float, samples, *, max_period: int = 8,
                     rtol: float = 1e-10) -> MapFixedPoint | None:
    """The stable periodic orbit that consecutive plate states ``samples`` converge to, found by
    converging to it: :func:`map_fixed_point` from the last sample for ``k = 1, 2, ... max_period``;
    the first stable orbit (every multiplier inside the unit circle) counts when the samples approach
    it (their distance to its nearest point shrinks over the samples and ends within
    :data:`ATTRACTION_RADIUS` of the state's scales). A count of distinct samples alone calls an
    orbit with a multiplier near -1 (still converging) irregular.

    Parameters
    ----------
    params : Parameters
    law : ContactLaw or str
    period : float
        Time between arrivals, s.
    samples : array, shape (n, 2)
        Consecutive ``(x2, x2dot)`` (m, m/s) of the map, n >= 2.
    max_period : int, default 8
        Longest period tried (1 to 64).
    rtol : float, default 1e-10
        The integrator's relative tolerance.

    Returns
    -------
    MapFixedPoint or None
        None when no stable orbit of period up to ``max_period`` is found that the samples approach
        (an irregular attractor, a longer period, or a transient not yet near its orbit).

    Raises
    ------
    ValueError
        Samples that are not finite plate states of shape (n, 2) with n >= 2, a period or
        ``max_period`` out of range.

    Examples
    --------
    Just above half a plate period the period-1 orbit converges slowly (a multiplier near -0.96):
    after 200 impacts its 40 samples are still distinct, yet they approach the stable orbit:

    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.integrate import scales
    >>> p = seed_parameters(v=1.0, kappa=3e9)
    >>> T = 0.504 * scales(p).plate_period
    >>> train = impact_train(p, "hunt-crossley", T, 240)
    >>> orbit = attracting_orbit(p, "hunt-crossley", T, train.plate[200:])
    >>> orbit.period_k, f"{min(orbit.multipliers.real):.3f}"
    (1, '-0.963')
    """
    samples = np.asarray(samples, dtype=float)
    if samples.ndim != 2 or samples.shape[1] != 2 or len(samples) < 2 or not np.all(np.isfinite(samples)):
        raise ValueError(f"samples of shape {samples.shape} are out of range; allowed: finite plate states "
                         "(x2, x2dot), shape (n, 2) with n >= 2")
    period = _check_period(period, params)
    if not (isinstance(max_period, (int, np.integer)) and not isinstance(max_period, bool)
            and 1 <= max_period <= 64):
        raise ValueError(f"max_period = {max_period!r} is out of range; allowed: an integer, 1 <= max_period <= 64")
    law = as_law(law)
    scale = _state_scale(params)
    for k in range(1, max_period + 1):
        fp = map_fixed_point(params, law, period, k=k, guess=samples[-1], rtol=rtol)
        if not (fp.converged and fp.stable):
            continue
        points = [fp.plate]
        for _ in range(k - 1):
            points.append(impact_map(params, law, period, points[-1], rtol=rtol)[0])
        points = np.array(points) / scale
        distance = np.min(np.linalg.norm(samples[:, None, :] / scale - points[None, :, :], axis=2), axis=1)
        # on it (to the orbit diagram's 1e-6) or still approaching it
        if distance[-1] <= ATTRACTION_RADIUS and (distance[-1] <= distance[0] or distance.max() < 1e-6):
            return fp
    return None


@dataclass(frozen=True)
class OrbitDiagram:
    """The map's attractor over a parameter: ``samples`` plate states after ``transients`` impacts.

    Attributes
    ----------
    param : str
        ``T``, ``kappa`` or ``v``.
    values : ndarray, shape (n,)
    plate : ndarray, shape (n, samples, 2)
        ``(x2, x2dot)`` just before each sampled impact.
    peak_force : ndarray, shape (n, samples)
    distinct : ndarray of int, shape (n,)
        Distinct points among the samples (to 1e-6 of the state's scales): 1 on a fixed point,
        ``k`` on a period-``k`` orbit, ``samples`` when irregular (or not settled).

    Examples
    --------
    From :func:`orbit_diagram`:

    >>> from phaseimpact import seed_parameters
    >>> d = orbit_diagram(seed_parameters(kappa=3e9), "hunt-crossley", "T", [0.4e-3], transients=2, samples=3)
    >>> d.param, d.plate.shape, d.peak_force.shape
    ('T', (1, 3, 2), (1, 3))
    """

    param: str
    values: np.ndarray
    plate: np.ndarray
    peak_force: np.ndarray
    distinct: np.ndarray


def _diagram_column(params, law, param, value, period, transients, samples, rtol):
    p, T = (params, value) if param == "T" else (params.replace(**{param: value}), period)
    train = impact_train(p, law, T, transients + samples, rtol=rtol)
    return train.plate[transients:-1], train.peak_force[transients:]


def orbit_diagram(params: Parameters, law, param: str, values, *, period: float | None = None,
                  transients: int = 200, samples: int = 50, rtol: float = 1e-10, n_jobs: int = 1) -> OrbitDiagram:
    """Iterate the impact map at each of ``values`` of ``param`` and keep the last ``samples`` states.

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
        Values computed side by side (threads; the result does not depend on it).

    Returns
    -------
    OrbitDiagram

    Raises
    ------
    ValueError
        A parameter name, values, period, or number of transients or samples out of range.

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
    from .continuation._parallel import map_in_threads

    law = as_law(law)
    if param not in TRAIN_PARAMETERS:
        raise ValueError(f"param = {param!r} is out of range; allowed: one of {', '.join(TRAIN_PARAMETERS)}")
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or len(values) < 1 or not np.all(np.isfinite(values)):
        raise ValueError("values must be a non-empty 1-d sequence of finite numbers")
    if param != "T":
        period = _check_period(period, params)
    else:
        for value in (values.min(), values.max()):
            _check_period(float(value), params, "T")
    for name, n in (("transients", transients), ("samples", samples)):
        if not (isinstance(n, (int, np.integer)) and 0 <= n <= 100_000 and (name == "transients" or n >= 1)):
            raise ValueError(f"{name} = {n!r} is out of range; allowed: an integer, "
                             f"{0 if name == 'transients' else 1} <= {name} <= 100000")
    columns = map_in_threads(lambda value: _diagram_column(params, law, param, float(value), period, transients,
                                                           samples, rtol), values, n_jobs)
    plate = np.stack([c[0] for c in columns])
    force = np.stack([c[1] for c in columns])
    scale = _state_scale(params)
    distinct = np.array([len(np.unique(np.round(col / scale / 1e-6), axis=0)) for col in plate])
    return OrbitDiagram(param, values, plate, force, distinct)


#: What the start's distance to a stable orbit, and the tangent vector's distance to its direction, have
#: shrunk to when :func:`lyapunov_exponent` starts averaging (its transients chosen from the multiplier).
LYAPUNOV_SETTLE = 1e-8
#: Most transient impacts :func:`lyapunov_exponent` chooses (a multiplier within 2e-4 of the unit circle).
MAX_LYAPUNOV_TRANSIENTS = 100_000


def _lyapunov_transients(params, law, period, z, rtol):
    """Impacts to discard before averaging: until the slowest multiplier ``mu`` (per impact) of the
    stable orbit the start approaches has shrunk its distance to :data:`LYAPUNOV_SETTLE`,
    ``log(LYAPUNOV_SETTLE) / log |mu|``, a whole number of the orbit's periods; 0 when no such orbit is
    found (an irregular attractor: nothing to wait for). Also the period ``k`` (1 when none)."""
    samples = impact_train(params, law, period, 16, plate=z, rtol=rtol).plate
    orbit = attracting_orbit(params, law, period, samples, rtol=rtol)
    if orbit is None:
        return 0, 1
    k = orbit.period_k
    slowest = float(np.max(np.abs(orbit.multipliers))) ** (1.0 / k)
    if slowest == 0.0:
        return 0, k
    n = math.ceil(math.log(LYAPUNOV_SETTLE) / math.log(slowest) / k) * k
    return min(n, MAX_LYAPUNOV_TRANSIENTS), k


def lyapunov_exponent(params: Parameters, law, period: float, *, plate=None, iterations: int = 200,
                      transients: int | None = None, rtol: float = 1e-10) -> float:
    """The largest Lyapunov exponent of the impact map (per impact): the mean of ``log |J_n w_n|``
    along the orbit from ``plate`` (default: after 100 impacts from rest), ``w`` renormalised each
    impact; ``J_n`` the map's Jacobian by central differences (:func:`map_jacobian`). Negative on a
    stable periodic orbit (the log of its largest multiplier's modulus), positive when chaotic.

    The mean starts after ``transients`` impacts (``w`` carried along): by default as many as the
    slowest multiplier of the stable orbit the start approaches (:func:`attracting_orbit`) needs to
    bring both the orbit and ``w`` within :data:`LYAPUNOV_SETTLE` (a fixed count is percents off
    near a multiplier of -0.96: the start's approach and ``w``'s first turns weigh in the mean).

    Parameters
    ----------
    params : Parameters
        The case.
    law : ContactLaw or str
    period : float
        Time between arrivals, s (> 0).
    plate : 2 numbers, optional
        ``(x2, x2dot)`` (m, m/s) to start from; default the state after 100 impacts from rest.
    iterations : int, default 200
        Impacts averaged over (rounded up to a whole number of the orbit's periods).
    transients : int, optional
        Impacts before the mean (0 to 100000); default chosen from the multiplier as above (0 when no
        stable orbit of period up to 8 is found).
    rtol : float, default 1e-10
        The integrator's relative tolerance.

    Returns
    -------
    float
        The exponent, per impact (dimensionless; divide by ``period`` for a rate in 1/s).

    Raises
    ------
    ValueError
        A period, iterations or transients out of range.

    Examples
    --------
    On the stable period-1 orbit at 0.4 ms it approaches ``log 0.450 = -0.799`` (a complex pair of
    multipliers: ``w`` turns each impact, and the mean converges as ``1 / iterations``):

    >>> from phaseimpact import seed_parameters
    >>> p = seed_parameters(kappa=3e9)
    >>> fp = map_fixed_point(p, "hunt-crossley", 0.4e-3)
    >>> f"{lyapunov_exponent(p, 'hunt-crossley', 0.4e-3, plate=fp.plate, iterations=50):.2f}"
    '-0.78'
    """
    law = as_law(law)
    period = _check_period(period, params)
    for name, n, low in (("iterations", iterations, 1), ("transients", transients, 0)):
        if name == "transients" and n is None:
            continue
        if not (isinstance(n, (int, np.integer)) and not isinstance(n, bool) and low <= n <= 100_000):
            raise ValueError(f"{name} = {n!r} is out of range; allowed: an integer, {low} <= {name} <= 100000")
    scale = _state_scale(params)
    z = impact_train(params, law, period, 100, rtol=rtol).plate[-1] if plate is None else np.asarray(plate, float)
    k = 1
    if transients is None:
        transients, k = _lyapunov_transients(params, law, period, z, rtol)
    iterations = math.ceil(iterations / k) * k
    w = np.array([1.0, 1.0]) / math.sqrt(2)
    total = 0.0
    for n in range(transients + iterations):
        J, _ = map_jacobian(params, law, period, z, rtol=rtol)
        w = (J * scale[None, :] / scale[:, None]) @ w  # in the state's scales
        growth = float(np.linalg.norm(w))
        if n >= transients:
            total += math.log(growth)
        w /= growth
        z, _ = impact_map(params, law, period, z, rtol=rtol)
    return total / iterations


# ------------------------------------------------------------------------------------------------
# Continuation of periodic orbits, their bifurcations, and basins of attraction
# ------------------------------------------------------------------------------------------------

#: Kinds of located points: a real multiplier through -1, through +1, a complex pair through the unit
#: circle, and a change of the orbit's contact structure.
BIFURCATION_KINDS = ("period-doubling", "fold", "neimark-sacker", "grazing")


def _at(params, param, period, value):
    """The case and the period at ``param = value``."""
    return (params, value) if param == "T" else (params.replace(**{param: value}), period)


def _orbit(params, law, period, z, k, rtol):
    """``P^k(z)`` and the orbit's contact structure: each impact's ``(contacts, stick phases, overlap)``
    (overlap 1 when its projectile is still in contact at the next arrival); None for the structure
    when a run failed."""
    structure = []
    for _ in range(k):
        z, run = impact_map(params, law, period, z, rtol=rtol)
        if run.status != "success":
            return z, None
        structure.append((int(run.n_contacts), int(run.n_stick), int(run.final_state[0] - run.final_state[1] > 0)))
    return z, tuple(structure)


def _contacts(structure) -> tuple[int, int, int]:
    """Contacts, stick phases and overlaps per period of the orbit."""
    return tuple(int(sum(column)) for column in zip(*structure, strict=True))


@dataclass(frozen=True)
class MapBifurcation:
    """A located bifurcation of a periodic orbit of the impact map.

    Attributes
    ----------
    kind : str
        ``period-doubling`` (a real multiplier crosses -1: a period-``2k`` orbit is born or dies),
        ``fold`` (a real multiplier crosses +1: two orbits of period ``k`` meet; ``turning`` says
        whether the branch turns back in the parameter there), ``neimark-sacker`` (a complex pair
        crosses the unit circle) or ``grazing`` (the orbit's contact structure changes: see
        :func:`continue_map_orbit`).
    param : str
        ``T``, ``kappa`` or ``v``.
    value : float
        The parameter at the point (s, the law's damping unit or m/s).
    plate : ndarray, shape (2,)
        The orbit's ``(x2, x2dot)`` before its first impact there (m, m/s).
    multipliers : ndarray, shape (2,), complex
        Floquet multipliers there.
    bracket : float
        Width of the final bracket of the bisection in the parameter (its unit): the location's
        accuracy as far as the test function is exact.
    test_value : float
        The test function at the point: ``det(J + I)``, ``det(J - I)``, ``det J - 1`` (``J`` the
        Jacobian of ``P^k``); 0 for grazing.
    contacts : tuple of 2 (int, int, int)
        Contacts, stick phases and overlaps per period of the orbit on either side (grazing; else
        both alike).
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
                "multipliers": _multipliers_dict(self.multipliers), "bracket": self.bracket,
                "test_value": self.test_value, "contacts": [list(c) for c in self.contacts],
                "turning": self.turning}


def _multipliers_dict(multipliers) -> list:
    return [{"re": float(m.real), "im": float(m.imag), "abs": float(abs(m))} for m in multipliers]


@dataclass(frozen=True)
class MapBranch:
    """A branch of period-``k`` orbits of the impact map followed over a parameter, with its
    located bifurcations.

    Attributes
    ----------
    param : str
        ``T``, ``kappa`` or ``v``.
    period_k : int
    values : ndarray, shape (n,)
        The parameter along the branch, in the order followed (it turns back at a fold).
    plate : ndarray, shape (n, 2)
        ``(x2, x2dot)`` of the orbit before its first impact (m, m/s).
    multipliers : ndarray, shape (n, 2), complex
    stable : ndarray of bool, shape (n,)
    contacts : ndarray of int, shape (n, 3)
        Contacts, stick phases and overlaps (a projectile still in contact at the next arrival) per
        period of the orbit.
    points : list of MapBifurcation
        The located points, in the order met.
    message : str
        Why the branch ends (``reached the end of the range``, or the failure).

    Examples
    --------
    See :func:`continue_map_orbit`.

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
        >>> branch = continue_map_orbit(seed_parameters(kappa=3e9), "hunt-crossley", "T", 0.4e-3, 0.45e-3,
        ...                             step=1e-5)
        >>> d = branch.as_dict()
        >>> d["param"], len(d["values"]) >= 3, d["points"]
        ('T', True, [])
        """
        return {"param": self.param, "period_k": self.period_k, "values": self.values.tolist(),
                "plate": self.plate.tolist(), "multipliers": [_multipliers_dict(m) for m in self.multipliers],
                "stable": self.stable.tolist(), "contacts": self.contacts.tolist(),
                "points": [p.as_dict() for p in self.points], "message": self.message}


def _swing_scale(params: Parameters) -> np.ndarray:
    """The scales of ``(x2, x2dot)`` on the plate's swing: ``(v / omega, v)``, ``omega = sqrt(Kb/M2)``
    (the Hertz ones without springs): a branch rotating once in phase is of length about 2 pi."""
    if params.target == "plate" and params.Kb > 0:
        return np.array([params.v / math.sqrt(params.Kb / params.M2), params.v])
    return _state_scale(params)


class _Branch:
    """The continuation's working state: the map at a point ``y = (z / scale, value / reference)`` of
    the scaled (state, parameter) space, corrected onto the branch on a hyperplane."""

    def __init__(self, params, law, param, period, k, reference, rtol):
        self.params, self.law, self.param, self.period, self.k, self.rtol = params, law, param, period, k, rtol
        self.scale = _swing_scale(params)
        self.reference = reference

    def unscale(self, y):
        return y[:2] * self.scale, float(y[2] * self.reference)

    def residual(self, y):
        z, value = self.unscale(y)
        p, T = _at(self.params, self.param, self.period, value)
        end, _ = _orbit(p, self.law, T, z, self.k, self.rtol)
        return (end - z) / self.scale

    def correct(self, y_pred, y_base, direction, s):
        """The branch's point on the hyperplane ``(y - y_base) . direction = s`` (pseudo-arclength),
        from ``y_pred``: ``y`` or None when the corrector does not converge."""
        from scipy.optimize import root

        def equations(y):
            try:
                r = self.residual(y)
            except ValueError:  # a trial parameter out of the case's range
                return np.full(3, 1e6)
            return np.append(r, (y - y_base) @ direction - s)

        sol = root(equations, y_pred, method="hybr", options={"xtol": 1e-13})
        # the residual decides: hybr reports "no progress" on a solution already at rounding level
        if not np.max(np.abs(equations(sol.x))) < 1e-9:
            return None
        return sol.x

    def describe(self, y):
        """``(multipliers, contacts, jacobian_accuracy)`` of the orbit at ``y``, or None without a map."""
        z, value = self.unscale(y)
        p, T = _at(self.params, self.param, self.period, value)
        _, structure = _orbit(p, self.law, T, z, self.k, self.rtol)
        if structure is None:
            return None
        J, accuracy = map_jacobian(p, self.law, T, z, k=self.k, rtol=self.rtol)
        return np.linalg.eigvals(J).astype(complex), _contacts(structure), accuracy


def _tests(multipliers) -> dict:
    """The test functions of the smooth bifurcations (zero at the bifurcation, changing sign)."""
    m1, m2 = multipliers
    complex_pair = abs(m1.imag) > 1e-12
    return {"period-doubling": float(((1 + m1) * (1 + m2)).real), "fold": float(((1 - m1) * (1 - m2)).real),
            "neimark-sacker": float((m1 * m2).real - 1) if complex_pair else math.nan}


def _check_param_value(params, param, value, name):
    if not (is_number(value) and math.isfinite(value)):
        raise ValueError(f"{name} = {value!r} is out of range; allowed: a finite number")
    if param == "T" and value <= 0 or param == "v" and value <= 0 or param == "kappa" and value < 0:
        raise ValueError(f"{name} = {value!r} is out of range; allowed: {param} "
                         f"{'>= 0' if param == 'kappa' else '> 0'}")
    if param == "T":
        _check_period(value, params, name)


def continue_map_orbit(params: Parameters, law, param: str, start: float, stop: float, *,
                       period: float | None = None, k: int = 1, guess=None, step: float | None = None,
                       max_points: int = 500, xtol: float = 1e-9, rtol: float = 1e-12) -> MapBranch:
    """Follow a branch of period-``k`` orbits of the impact map from ``param = start`` towards
    ``stop`` (pseudo-arclength continuation), and locate its bifurcations.

    The first two points come from :func:`map_fixed_point` (its Newton, at ``start`` from ``guess``,
    then one step on from the first); each next point is predicted along the secant of the last two
    and corrected onto the branch on the hyperplane normal to it (scipy's hybrid Powell on
    ``P^k(z) - z = 0`` plus that constraint), in the scaled space ``(omega x2 / v, x2dot / v,
    10 value / |stop - start|)`` (``omega = sqrt(Kb/M2)``: a change of the plate's swing by its
    amplitude at speed ``v`` weighs as much as a tenth of the range). The step halves when the
    correction fails or lands farther from the prediction than the step itself, and grows by half
    again up to ``step`` after a success; the branch turns freely at a fold and ends when it leaves
    the range, or at its first point where a projectile is still in contact when the next one
    arrives (the model's map ends there: :func:`impact_train`'s ``overlap``).

    Between neighbouring points each test function is watched for a change of sign: ``det(J + I)``
    (period-doubling: a real multiplier through -1), ``det(J - I)`` (fold: a real multiplier through
    +1), ``det J - 1`` with a complex pair (Neimark–Sacker); ``J`` is the Jacobian of ``P^k``
    (:func:`map_jacobian`). **Grazing** is where the orbit's contact structure changes: the number of
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
        rest there (:func:`map_fixed_point`).
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
    law = as_law(law)
    if param not in TRAIN_PARAMETERS:
        raise ValueError(f"param = {param!r} is out of range; allowed: one of {', '.join(TRAIN_PARAMETERS)}")
    _check_param_value(params, param, start, "start")
    _check_param_value(params, param, stop, "stop")
    if start == stop:
        raise ValueError(f"stop = {stop!r} is out of range; allowed: stop != start ({start!r})")
    if param != "T":
        period = _check_period(period, params)
    if not (isinstance(k, (int, np.integer)) and not isinstance(k, bool) and 1 <= k <= 64):
        raise ValueError(f"k = {k!r} is out of range; allowed: an integer, 1 <= k <= 64")
    span = abs(stop - start)
    if step is None:
        step = span / 50
    if not (is_number(step) and math.isfinite(step) and 0 < step <= span):
        raise ValueError(f"step = {step!r} is out of range; allowed: 0 < step <= |stop - start| = {span:g}")
    if not (isinstance(max_points, (int, np.integer)) and not isinstance(max_points, bool)
            and 3 <= max_points <= 100_000):
        raise ValueError(f"max_points = {max_points!r} is out of range; allowed: an integer, "
                         "3 <= max_points <= 100000")
    if not (is_number(xtol) and 1e-14 <= xtol <= 1e-3):
        raise ValueError(f"xtol = {xtol!r} is out of range; allowed: 1e-14 <= xtol <= 1e-3")

    reference = span / 10
    work = _Branch(params, law, param, period, int(k), reference, rtol)
    low, high = min(start, stop), max(start, stop)
    sign = 1.0 if stop > start else -1.0

    def natural(value, z):
        p, T = _at(params, param, period, value)
        fp = map_fixed_point(p, law, T, k=work.k, guess=z, rtol=rtol)
        return np.append(fp.plate / work.scale, value / reference) if fp.converged else None

    ys, infos = [], []
    y = natural(start, guess)
    info = None if y is None else work.describe(y)
    if info is None:
        return _branch(work, ys, infos, [], f"no period-{k} orbit found at {param} = {start:g}")
    ys.append(y), infos.append(info)
    y = natural(start + sign * step / 10, y[:2] * work.scale)
    info = None if y is None else work.describe(y)
    if info is None:
        return _branch(work, ys, infos, [], f"no period-{k} orbit found one step from {param} = {start:g}")
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
                message = f"the branch could not be followed past {param} = {ys[-1][2] * reference:g}"
                break
            continue
        value = y[2] * reference
        if not low <= value <= high:
            break
        ys.append(y), infos.append(info)
        if info[1][2] > 0:  # kept, so that the onset is located as a grazing
            message = (f"from {param} = {value:g} on a projectile is still in contact when the next arrives "
                       "(no impact map in this model)")
            break
        ds = min(ds * 1.5, ds_max)
    else:
        message = f"stopped after max_points = {max_points} points"
    points = []
    for i in range(len(ys) - 1):
        points += _locate(work, ys, infos, i, xtol)
    return _branch(work, ys, infos, points, message)


def _branch(work, ys, infos, points, message) -> MapBranch:
    n = len(ys)
    plate = np.array([y[:2] * work.scale for y in ys]).reshape(n, 2)
    multipliers = np.array([m for m, _, _ in infos], dtype=complex).reshape(n, 2)
    return MapBranch(work.param, work.k, np.array([y[2] * work.reference for y in ys]), plate, multipliers,
                     np.all(np.abs(multipliers) < 1, axis=1), np.array([c for _, c, _ in infos], int).reshape(n, 3),
                     points, message)


def _locate(work, ys, infos, i, xtol) -> list:
    """The bifurcations between branch points ``i`` and ``i + 1``, each by bisection on the segment."""
    a, b = ys[i], ys[i + 1]
    chord = b - a
    length = float(np.linalg.norm(chord))
    direction = chord / length

    def point(sigma):
        y = work.correct(a + sigma * chord, a, direction, sigma * length)
        return (y, None) if y is None else (y, work.describe(y))

    found = []
    tests_a, tests_b = _tests(infos[i][0]), _tests(infos[i + 1][0])
    changes = [kind for kind in tests_a if tests_a[kind] * tests_b[kind] < 0]
    if infos[i][1] != infos[i + 1][1]:
        changes.append("grazing")
    for kind in changes:
        lo, hi = 0.0, 1.0
        left = tests_a[kind] if kind != "grazing" else infos[i][1]
        y_mid, info_mid = a, infos[i]
        while (hi - lo) * length > xtol:
            sigma = 0.5 * (lo + hi)
            y, info = point(sigma)
            if info is None:  # the corrector failed inside the segment: keep the bracket reached
                break
            here = _tests(info[0])[kind] if kind != "grazing" else info[1]
            if (here == left) if kind == "grazing" else (here * left > 0):
                lo = sigma
            else:
                hi = sigma
            y_mid, info_mid = y, info
        values = [float((a[2] + s * chord[2]) * work.reference) for s in (lo, hi)]
        z, value = work.unscale(y_mid)
        turning = False
        if kind == "fold":
            # a turn: the parameter at the fold lies beyond both ends of the segment (or the branch's
            # direction in the parameter differs on either side of the segment)
            before = ys[i][2] - ys[i - 1][2] if i > 0 else chord[2]
            after = ys[i + 2][2] - ys[i + 1][2] if i + 2 < len(ys) else chord[2]
            turning = bool(before * after < 0 or (y_mid[2] - a[2]) * (y_mid[2] - b[2]) > 0)
        found.append(MapBifurcation(kind, work.param, value, z, info_mid[0], abs(values[1] - values[0]),
                                    0.0 if kind == "grazing" else _tests(info_mid[0])[kind],
                                    (infos[i][1], infos[i + 1][1]) if kind == "grazing" else (info_mid[1],) * 2,
                                    turning))
    return found


@dataclass(frozen=True)
class BifurcationCurve:
    """A bifurcation of the impact map followed in a second parameter: where it lies in the first
    parameter at each value of the second.

    Attributes
    ----------
    kind : str
        One of :data:`BIFURCATION_KINDS`.
    param, second : str
        The first parameter (where the point is located) and the second (the grid), each ``T``,
        ``kappa`` or ``v``.
    second_values : ndarray, shape (m,)
        The grid of the second parameter, in the order followed.
    values : ndarray, shape (m,)
        The first parameter at the bifurcation (NaN where it was lost).
    plate : ndarray, shape (m, 2)
        The orbit's ``(x2, x2dot)`` there (m, m/s; NaN where lost).
    multipliers : ndarray, shape (m, 2), complex
    bracket : ndarray, shape (m,)
        Each location's final bracket in the first parameter.
    message : str
        ``followed over the whole grid``, or where and why the curve was lost.

    Examples
    --------
    See :func:`continue_map_bifurcation`.

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
                "plate": self.plate.tolist(), "multipliers": [_multipliers_dict(m) for m in self.multipliers],
                "bracket": self.bracket.tolist(), "message": self.message}


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
    law = as_law(law)
    if second not in TRAIN_PARAMETERS or second == branch.param:
        allowed = [p for p in TRAIN_PARAMETERS if p != branch.param]
        raise ValueError(f"second = {second!r} is out of range; allowed: one of {', '.join(allowed)}")
    if not any(point is p for p in branch.points):
        raise ValueError(f"point = {point.kind} at {point.value!r} is out of range; allowed: one of branch.points")
    grid = np.asarray(values, dtype=float)
    if grid.ndim != 1 or len(grid) < 1 or not np.all(np.isfinite(grid)) or (
            len(grid) > 1 and not (np.all(np.diff(grid) > 0) or np.all(np.diff(grid) < 0))):
        raise ValueError("values must be a non-empty, strictly monotonic 1-d sequence of finite numbers")
    for x in grid:
        _check_param_value(params, second, float(x), "values")
    if "T" not in (branch.param, second):
        period = _check_period(period, params)
    if window is None:
        window = abs(point.value) / 50
    if not (is_number(window) and math.isfinite(window) and window > 0):
        raise ValueError(f"window = {window!r} is out of range; allowed: a finite number > 0")

    direction = math.copysign(1.0, branch.values[-1] - branch.values[0])
    m = len(grid)
    found = np.full(m, np.nan)
    plate, multipliers = np.full((m, 2), np.nan), np.full((m, 2), np.nan, dtype=complex)
    bracket = np.full(m, np.nan)
    value, state, message = point.value, point.plate, "followed over the whole grid"
    for j, x in enumerate(grid):
        p, T = _at(params, second, period, float(x)) if second != "T" else (params, float(x))
        here = _relocate(p, law, branch, point.kind, value, state, direction, window, T, xtol, rtol)
        if here is None:
            message = f"lost at {second} = {x:g}: no {point.kind} within the window around {value:g}"
            break
        found[j], plate[j], multipliers[j], bracket[j] = here.value, here.plate, here.multipliers, here.bracket
        value, state = here.value, here.plate
    return BifurcationCurve(point.kind, branch.param, second, grid, found, plate, multipliers, bracket, message)


def _relocate(params, law, branch, kind, value, state, direction, window, period, xtol, rtol):
    """The point of ``kind`` of the branch nearest ``value`` in the window around it, widened up to
    three times; None if none."""
    for _ in range(4):
        start, stop = value - direction * window, value + direction * window
        if branch.param != "kappa":  # T and v stay positive
            start, stop = max(start, value / 2), max(stop, value / 2)
        near = continue_map_orbit(params, law, branch.param, start, stop, period=period, k=branch.period_k,
                                  guess=state, step=window / 5, xtol=xtol, rtol=rtol)
        matches = [p for p in near.points if p.kind == kind]
        if matches:
            return min(matches, key=lambda p: abs(p.value - value))
        window *= 2
    return None


#: Two attractors are one when their points agree within this fraction of the state's scales.
ATTRACTOR_MATCH = 1e-3


@dataclass(frozen=True)
class Attractor:
    """A periodic attractor of the impact map found by :func:`basins`.

    Attributes
    ----------
    plate : ndarray, shape (period, 2)
        The orbit's ``(x2, x2dot)`` before each of its impacts (m, m/s), beginning with the smallest ``x2``.
    period : int
        Impacts per repetition.
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
    """The basins of attraction of the impact map over a grid of the plate's initial state.

    Attributes
    ----------
    period : float
        Time between arrivals, s.
    x2_values, x2dot_values : ndarray, shapes (nx,), (ny,)
        The grid's initial positions (m) and velocities (m/s).
    labels : ndarray of int, shape (ny, nx)
        At ``[i, j]`` (velocity ``x2dot_values[i]``, position ``x2_values[j]``) the index of the
        attractor the train from that state goes to; :data:`NOT_CONVERGED` (-1) where no period up to
        ``max_period`` repeated within ``iterations`` impacts (an irregular attractor, a longer period,
        or a slow approach), :data:`NO_MAP` (-2) where a run failed.
    impacts : ndarray of int, shape (ny, nx)
        Impacts until the orbit repeated (``iterations`` where it did not).
    attractors : list of Attractor
        In the order first met on the grid (rows of ``labels`` then columns).
    not_converged, no_map : int
        Initial states labelled -1 and -2.

    Examples
    --------
    See :func:`basins`.

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


def _settle(params, law, period, z, iterations, max_period, tol, rtol):
    """Iterate from ``z`` until a cycle of period ``p <= max_period`` repeats within ``tol`` of the
    state's scales: ``(cycle (p, 2) or None, impacts, label if none)``."""
    scale = _state_scale(params)
    history = [np.asarray(z, dtype=float)]
    for n in range(1, iterations + 1):
        z, run = impact_map(params, law, period, history[-1], rtol=rtol)
        if run.status != "success":
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


def basins(params: Parameters, law, period: float, x2_values, x2dot_values, *, iterations: int = 500,
           max_period: int = 16, tol: float = 1e-7, rtol: float = 1e-10, n_jobs: int = 1) -> Basins:
    """The basins of attraction of the impact map in the plate's initial state.

    From each ``(x2, x2dot)`` of the grid the map is iterated until the last ``p`` states repeat the
    ``p`` before them within ``tol`` of the state's scales (Hertz indentation, ``v``) for the
    smallest ``p <= max_period``: the state has reached a periodic attractor, of the shortest period
    ``q`` dividing ``p`` over which those states repeat within :data:`ATTRACTOR_MATCH` (a slow
    approach to an orbit can repeat first over a multiple of its period). As in
    :func:`impact_train`, a projectile still in contact at the next arrival does not stop the train.
    The
    endpoints are then grouped, in grid order, into attractors: two are one when they have the same
    period and their points agree, in some cyclic order, within :data:`ATTRACTOR_MATCH` of the
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
    from .continuation._parallel import map_in_threads

    law = as_law(law)
    period = _check_period(period, params)
    grid = []
    for name, values in (("x2_values", x2_values), ("x2dot_values", x2dot_values)):
        values = np.asarray(values, dtype=float)
        if values.ndim != 1 or len(values) < 1 or not np.all(np.isfinite(values)):
            raise ValueError(f"{name} = {values!r} is out of range; allowed: a non-empty 1-d sequence of finite "
                             "numbers")
        grid.append(values)
    for name, n, top in (("iterations", iterations, 100_000), ("max_period", max_period, 64),
                         ("n_jobs", n_jobs, 1024)):
        if not (isinstance(n, (int, np.integer)) and not isinstance(n, bool) and 1 <= n <= top):
            raise ValueError(f"{name} = {n!r} is out of range; allowed: an integer, 1 <= {name} <= {top}")
    if not (is_number(tol) and 1e-12 <= tol <= 1e-4):
        raise ValueError(f"tol = {tol!r} is out of range; allowed: 1e-12 <= tol <= 1e-4")
    xs, vs = grid
    starts = [(x, xdot) for xdot in vs for x in xs]
    ends = map_in_threads(lambda z: _settle(params, law, period, z, iterations, max_period, tol, rtol), starts,
                          n_jobs)
    scale = _state_scale(params)
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
