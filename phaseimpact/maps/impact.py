"""The model's impact map: a projectile of the case arrives every ``period`` seconds on the plate
as the previous impacts left it (docs/physics.md §7).

The impact map ``P`` takes the plate's state ``z = (x2, x2dot)`` just before impact ``n`` (a fresh
projectile touching the plate, ``x1 = x2``, at the case's speed ``v``) to its state just before impact
``n + 1``: one run of the engine over ``[0, period]`` with stick, slip, separation and any further
contact of that projectile resolved as for a single impact; the projectile is then taken away (a
stream of grains hits fresh places of a blade) and the next one arrives. :class:`ModelImpactMap` is
that map as an :class:`~phaseimpact.maps.base.ImpactMap`; the functions here and in
:mod:`phaseimpact.maps.impact_analyses` take the case, the law and the period, check them, and run
the generic analyses of :mod:`phaseimpact.maps` on it: :func:`impact_train` (the response to ``N``
impacts), :func:`map_fixed_point` (periodic orbits of period ``k`` with their Floquet multipliers),
:func:`map_jacobian`, :func:`attracting_orbit` and :func:`lyapunov_exponent`.

A projectile still in contact when the next one arrives (a period shorter than the contact) has
no meaning in this model: such a run is reported (``overlap``), never silently cut.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..integrate import driver as drv
from ..integrate import simulate
from ..integrate.api import summary_run
from ..model import as_law
from ..parameters import Parameters, is_number
from .base import ImpactMap, MapFixedPoint, attracting_orbit_of, check_count, check_samples, fixed_point, lyapunov

__all__ = ["ModelImpactMap", "ImpactTrain", "impact_map", "impact_train", "map_fixed_point", "map_jacobian",
           "attracting_orbit", "lyapunov_exponent", "period_range", "check_period", "TRAIN_PARAMETERS",
           "MAX_PERIOD_SWINGS"]

#: Parameters the impact map varies (the period ``T``, s; the damping ``kappa``; the speed ``v``, m/s).
TRAIN_PARAMETERS = ("T", "kappa", "v")

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
    from ..integrate import scales
    from ..integrate.api import MIN_HORIZON_CONTACT_TIMES

    contact_time = scales(params).contact_time
    swing = params.target_period if math.isfinite(params.target_period) else contact_time
    swing_name = "plate periods" if math.isfinite(params.target_period) else "contact times"
    why = (f"from {MIN_HORIZON_CONTACT_TIMES:g} of the contact time {contact_time:.3g} s, below which nothing can be "
           f"resolved, to {MAX_PERIOD_SWINGS:g} {swing_name} ({swing:.3g} s), beyond which the plate's state at the "
           "next arrival is lost to rounding")
    return MIN_HORIZON_CONTACT_TIMES * contact_time, MAX_PERIOD_SWINGS * swing, why


def check_period(period, params: Parameters, name: str = "period") -> float:
    """``period`` as a float within :func:`period_range`, else a ValueError naming ``name``.

    Parameters
    ----------
    period : float
        Time between arrivals, s.
    params : Parameters
        The case.
    name : str, default "period"
        The argument's name, for the message.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        Not a finite number > 0, or outside :func:`period_range`.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> check_period(3e-3, seed_parameters())
    0.003
    """
    if not (is_number(period) and math.isfinite(period) and period > 0):
        raise ValueError(f"{name} = {period!r} is out of range; allowed: a finite number > 0 (s)")
    shortest, longest, why = period_range(params)
    if not shortest <= period <= longest:
        raise ValueError(f"{name} = {period!r} is out of range; allowed: {shortest:.3g} <= {name} <= {longest:.3g} s "
                         f"({why})")
    return float(period)


class ModelImpactMap(ImpactMap):
    """The impact map of the model: the plate's ``(x2, x2dot)`` just before an arrival to its state
    just before the next (module docstring). Nothing is checked on construction (a continuation's
    trial points need none); :meth:`check` checks the period.

    Parameters
    ----------
    params : Parameters
        The case (``v``, m/s: each projectile's speed).
    law : ContactLaw or str
    period : float or None
        Time between arrivals, s (None where a continuation in ``T`` sets it through :meth:`at`).
    rtol : float, default 1e-10
        The integrator's relative tolerance.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> m = ModelImpactMap(seed_parameters(kappa=3e9), "hunt-crossley", 3e-3)
    >>> f"{m((0.0, 0.0))[1]:.3g} m/s", m.parameters
    ('0.172 m/s', ('T', 'kappa', 'v'))
    """

    parameters = TRAIN_PARAMETERS
    structure_names = ("contacts", "stick phases", "overlaps")
    positive_parameters = ("T", "v")
    states = "plate states (x2, x2dot)"

    def __init__(self, params: Parameters, law, period: float | None, rtol: float = 1e-10):
        self.params, self.law, self.period, self.rtol = params, as_law(law), period, rtol

    @property
    def scale(self) -> np.ndarray:
        """The scales of ``(x2, x2dot)``: the Hertz indentation (m) and the impact speed (m/s)."""
        return np.array([self.params.hertz_indentation, self.params.v])

    @property
    def continuation_scale(self) -> np.ndarray:
        """The scales on the plate's swing: ``(v / omega, v)``, ``omega = sqrt(Kb/M2)`` (the Hertz ones
        without springs): a branch rotating once in phase is of length about 2 pi."""
        params = self.params
        if params.target == "plate" and params.Kb > 0:
            return np.array([params.v / math.sqrt(params.Kb / params.M2), params.v])
        return self.scale

    def step(self, state):
        """One impact: the plate's state just before the next arrival, and the engine's run.

        Parameters
        ----------
        state : 2 numbers
            ``(x2, x2dot)`` (m, m/s) just before the impact.

        Returns
        -------
        (ndarray, Trajectory)
            The next ``(x2, x2dot)`` and the run over ``[0, period]``.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> z, run = ModelImpactMap(seed_parameters(kappa=3e9), "hunt-crossley", 3e-3).step((0.0, 0.0))
        >>> run.status, f"{run.max_force:.4g} N"
        ('success', '4629 N')
        """
        run = simulate(self.params, self.law, self.period, rtol=self.rtol, initial=self._arrival(state),
                       stop_when_settled=False)
        return np.array([run.final_state[1], run.final_state[3]]), run

    def _arrival(self, state) -> tuple:
        x2, x2dot = (float(state[0]), float(state[1]))
        return (x2, x2, self.params.v, x2dot)

    def _summary(self, state):
        """:meth:`step`'s run on the per-point path (no event log: fixed points, Jacobians and
        trains read only its summary): its summary vector (``driver.S_*``) and its state
        ``(x1, x2, x1dot, x2dot, W)`` at the next arrival."""
        return summary_run(self.params, self.law, self.period, rtol=self.rtol, initial=self._arrival(state),
                           stop_when_settled=False)

    def __call__(self, state) -> np.ndarray:
        y = self._summary(state)[1]
        return np.array([y[1], y[3]])

    def structure(self, record) -> tuple | None:
        """An impact's contacts, stick phases and overlap (1 when its projectile is still in contact at
        the next arrival); None when the run failed.

        Parameters
        ----------
        record : Trajectory
            The run of :meth:`step`.

        Returns
        -------
        (int, int, int) or None

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> m = ModelImpactMap(seed_parameters(kappa=3e9), "hunt-crossley", 3e-3)
        >>> m.structure(m.step((0.0, 0.0))[1])
        (2, 0, 0)
        """
        if record.status != "success":
            return None
        return int(record.n_contacts), int(record.n_stick), int(record.final_state[0] - record.final_state[1] > 0)

    def end_reason(self, counts) -> str | None:
        """A projectile still in contact at the next arrival ends the map (no impact map in this model).

        Parameters
        ----------
        counts : (int, int, int)
            Contacts, stick phases and overlaps per period of an orbit.

        Returns
        -------
        str or None

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> ModelImpactMap(seed_parameters(), "paper", 1e-3).end_reason((2, 0, 1))
        'a projectile is still in contact when the next arrives (no impact map in this model)'
        """
        if counts[2] > 0:
            return "a projectile is still in contact when the next arrives (no impact map in this model)"
        return None

    def at(self, name: str, value: float) -> ModelImpactMap:
        """The map at ``name = value`` (``T`` the period, else a parameter of the case).

        Parameters
        ----------
        name : {"T", "kappa", "v"}
        value : float

        Returns
        -------
        ModelImpactMap

        Raises
        ------
        ValueError
            A value the case refuses (``kappa`` < 0, ``v`` <= 0).

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> ModelImpactMap(seed_parameters(), "paper", 1e-3).at("v", 2.0).params.v
        2.0
        """
        if name == "T":
            return ModelImpactMap(self.params, self.law, value, self.rtol)
        if name not in self.parameters:
            raise ValueError(f"name = {name!r} is out of range; allowed: one of {', '.join(self.parameters)}")
        return ModelImpactMap(self.params.replace(**{name: value}), self.law, self.period, self.rtol)

    def check_parameter(self, name: str, value, label: str) -> float:
        """``value`` of ``name`` checked: ``T``, ``v`` > 0, ``kappa`` >= 0, ``T`` within :func:`period_range`.

        Parameters
        ----------
        name : {"T", "kappa", "v"}
        value : float
        label : str
            The argument's name, for the message.

        Returns
        -------
        float

        Raises
        ------
        ValueError
            A value out of range, named with ``label``.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> ModelImpactMap(seed_parameters(), "paper", 1e-3).check_parameter("v", -1.0, "start")
        Traceback (most recent call last):
        ...
        ValueError: start = -1.0 is out of range; allowed: v > 0
        """
        if not (is_number(value) and math.isfinite(value)):
            raise ValueError(f"{label} = {value!r} is out of range; allowed: a finite number")
        if name == "T" and value <= 0 or name == "v" and value <= 0 or name == "kappa" and value < 0:
            raise ValueError(f"{label} = {value!r} is out of range; allowed: {name} "
                             f"{'>= 0' if name == 'kappa' else '> 0'}")
        if name == "T":
            check_period(value, self.params, label)
        return float(value)

    def check(self) -> None:
        """Refuse a period out of :func:`period_range`.

        Raises
        ------
        ValueError
            The period out of range.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> ModelImpactMap(seed_parameters(), "paper", -1.0).check()
        Traceback (most recent call last):
        ...
        ValueError: period = -1.0 is out of range; allowed: a finite number > 0 (s)
        """
        check_period(self.period, self.params)


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
    return ModelImpactMap(params, law, period, rtol).step(plate)


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
    period = check_period(period, params)
    impacts = check_count("impacts", impacts, 1, 100_000)
    imap = ModelImpactMap(params, law, period, rtol)
    states = np.empty((impacts + 1, 2))
    states[0] = plate
    rows = np.full((impacts, 5), np.nan)
    overlap = np.zeros(impacts, bool)
    status = []
    for n in range(impacts):
        summary, y = imap._summary(states[n])
        states[n + 1] = y[1], y[3]
        rows[n] = (summary[drv.S_MAX_FORCE], summary[drv.S_DISSIPATED], summary[drv.S_RESTITUTION],
                   0.5 * params.M1 * (params.v**2 - y[2]**2), summary[drv.S_N_CONTACTS])
        overlap[n] = y[0] - y[1] > 0
        status.append(drv.STATUSES[int(summary[drv.S_STATUS])])
    omega = math.sqrt(params.Kb / params.M2) if params.target == "plate" and params.Kb > 0 else math.inf
    amplitude = np.hypot(states[:, 0], states[:, 1] / omega) if math.isfinite(omega) else np.abs(states[:, 0])
    return ImpactTrain(period, states, rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3], rows[:, 4].astype(np.int64),
                       amplitude, overlap, status)


def map_jacobian(params: Parameters, law, period: float, plate, *, k: int = 1, rtol: float = 1e-12):
    """The Jacobian of ``P^k`` at ``plate`` by central differences, and its accuracy: the largest
    relative change of an entry between the steps :data:`~.base.JACOBIAN_STEP` and ``10 JACOBIAN_STEP``
    of the state's scales.

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
    return ModelImpactMap(params, law, period, rtol).jacobian(plate, k)


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
    law = as_law(law)
    period = check_period(period, params)
    return fixed_point(ModelImpactMap(params, law, period, rtol), k=k, guess=guess)


def attracting_orbit(params: Parameters, law, period: float, samples, *, max_period: int = 8,
                     rtol: float = 1e-10) -> MapFixedPoint | None:
    """The stable periodic orbit that consecutive plate states ``samples`` converge to, found by
    converging to it: :func:`map_fixed_point` from the last sample for ``k = 1, 2, ... max_period``;
    the first stable orbit (every multiplier inside the unit circle) counts when the samples approach
    it (their distance to its nearest point shrinks over the samples and ends within
    :data:`~phaseimpact.maps.base.ATTRACTION_RADIUS` of the state's scales). A count of distinct samples alone calls an
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
    samples = check_samples(ModelImpactMap(params, law, period, rtol), samples)
    period = check_period(period, params)
    return attracting_orbit_of(ModelImpactMap(params, law, period, rtol), samples, max_period=max_period)


def lyapunov_exponent(params: Parameters, law, period: float, *, plate=None, iterations: int = 200,
                      transients: int | None = None, rtol: float = 1e-10) -> float:
    """The largest Lyapunov exponent of the impact map (per impact): the mean of ``log |J_n w_n|``
    along the orbit from ``plate`` (default: after 100 impacts from rest), ``w`` renormalised each
    impact; ``J_n`` the map's Jacobian by central differences (:func:`map_jacobian`). Negative on a
    stable periodic orbit (the log of its largest multiplier's modulus), positive when chaotic.

    The mean starts after ``transients`` impacts (``w`` carried along): by default as many as the
    slowest multiplier of the stable orbit the start approaches (:func:`attracting_orbit`) needs to
    bring both the orbit and ``w`` within :data:`~phaseimpact.maps.base.LYAPUNOV_SETTLE` (a fixed count is percents off
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
    period = check_period(period, params)
    return lyapunov(ModelImpactMap(params, law, period, rtol), state=plate, iterations=iterations,
                    transients=transients)
