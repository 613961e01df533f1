"""Trains of impacts as a map: a projectile of the case arrives every ``period`` seconds on the plate
as the previous impacts left it (docs/physics.md §7).

The impact map ``P`` takes the plate's state ``z = (x2, x2dot)`` just before impact ``n`` (a fresh
projectile touching the plate, ``x1 = x2``, at the case's speed ``v``) to its state just before impact
``n + 1``: one run of the engine over ``[0, period]`` with stick, slip, separation and any further
contact of that projectile resolved as for a single impact; the projectile is then taken away (a
stream of grains hits fresh places of a blade) and the next one arrives. On the map:
:func:`impact_train` (the response to ``N`` impacts), :func:`map_fixed_point` (periodic orbits of
period ``k``: ``P^k(z) = z``, with their Floquet multipliers), :func:`orbit_diagram` (the attractor
sampled after transients over a parameter) and :func:`lyapunov_exponent`.

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
           "orbit_diagram", "lyapunov_exponent", "TRAIN_PARAMETERS"]

#: Parameters an orbit diagram runs over (the period ``T``, s; the damping ``kappa``; the speed ``v``, m/s).
TRAIN_PARAMETERS = ("T", "kappa", "v")
#: Relative step of the finite-difference Jacobian of the map (of the state's scale), and the
#: second step that checks it.
JACOBIAN_STEP = 1e-6


def _check_period(period, params: Parameters) -> float:
    if not (is_number(period) and math.isfinite(period) and period > 0):
        raise ValueError(f"period = {period!r} is out of range; allowed: a finite number > 0 (s)")
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

    Returns
    -------
    (ndarray, Trajectory)
        The plate's ``(x2, x2dot)`` just before the next arrival, and the run over ``[0, period]``.
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
    law : ContactLaw or str
    period : float
        Time between arrivals, s (> 0).
    impacts : int
        Number of impacts, 1 to 100000.
    plate : 2 numbers, default (0, 0)
        ``(x2, x2dot)`` (m, m/s) before the first impact.
    rtol : float

    Returns
    -------
    ImpactTrain

    Raises
    ------
    ValueError
        A period or a number of impacts out of range.
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
    message : str
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
    the state's scales."""
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

    Returns
    -------
    MapFixedPoint
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
    converged = bool(sol.success and res < 1e-9)
    return MapFixedPoint(z, int(k), multipliers, bool(np.all(np.abs(multipliers) < 1)), res, accuracy, converged,
                         "" if converged else f"no periodic orbit found from the guess ({sol.message})")


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
    law : ContactLaw or str
    param : {"T", "kappa", "v"}
    values : sequence of float
        The parameter's values (s, N s/m^(1+alpha) or m/s).
    period : float, optional
        The period (s) when ``param`` is not ``T``.
    transients, samples : int
        Impacts dropped, then kept, at each value.
    rtol : float
    n_jobs : int
        Values computed side by side (threads; the result does not depend on it).

    Returns
    -------
    OrbitDiagram
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


def lyapunov_exponent(params: Parameters, law, period: float, *, plate=None, iterations: int = 200,
                      rtol: float = 1e-10) -> float:
    """The largest Lyapunov exponent of the impact map (per impact): the mean of ``log |J_n w_n|``
    along the orbit from ``plate`` (default: after 100 impacts from rest), ``w`` renormalised each
    impact; ``J_n`` the map's Jacobian by central differences (:func:`map_jacobian`). Negative on a
    stable periodic orbit (the log of its largest multiplier's modulus), positive when chaotic."""
    law = as_law(law)
    period = _check_period(period, params)
    scale = _state_scale(params)
    z = impact_train(params, law, period, 100, rtol=rtol).plate[-1] if plate is None else np.asarray(plate, float)
    w = np.array([1.0, 1.0]) / math.sqrt(2)
    total = 0.0
    for _ in range(iterations):
        J, _ = map_jacobian(params, law, period, z, rtol=rtol)
        w = (J * scale[None, :] / scale[:, None]) @ w  # in the state's scales
        growth = float(np.linalg.norm(w))
        total += math.log(growth)
        w /= growth
        z, _ = impact_map(params, law, period, z, rtol=rtol)
    return total / iterations
