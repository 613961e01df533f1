"""Phase-space analysis of trajectories: asymptotic points, outcomes, fixed points, portraits.

Definitions follow docs/physics.md §5. An *asymptotic point* of a trajectory, in a phase plane, is
a point where the trajectory comes to rest in that plane for a dwell time that is not
negligible. Two ways to find them:

* ``method="events"`` (default for event-driven trajectories in the ``(delta, deltadot)``
  plane): every stick phase of ``paper`` is a rest of the relative motion, at
  ``(delta*, 0)``; two stick phases separated by a slip are distinct points however close.
* ``method="distance"`` (trajectories without events, e.g. the seed's RK4, and the other
  planes): runs of samples that stay within ``tol`` (relative to the plane's extent) for at
  least ``min_dwell`` become candidates; candidates closer than ``tol`` merge. The tolerance
  biases a critical value near a split; it is reported with the points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .integrate import Trajectory, scales
from .model import V1, V2, X1, X2, ContactLaw, as_law, jacobian, pack
from .model.rhs import KB_, KM_, rhs
from .parameters import Parameters

__all__ = [
    "PLANES",
    "AsymptoticPoints",
    "FixedPoint",
    "EquilibriumSet",
    "find_asymptotic_points",
    "fixed_points",
    "plane_coordinates",
    "phase_portrait",
]

PLANES = (("delta", "deltadot"), ("x1", "x1dot"), ("x2", "x2dot"))


def plane_coordinates(y: np.ndarray, plane) -> tuple[np.ndarray, np.ndarray]:
    """The two coordinates of states ``y`` (shape ``(..., 5)``) in ``plane``."""
    plane = _check_plane(plane)
    if plane[0] == "delta":
        return y[..., X1] - y[..., X2], y[..., V1] - y[..., V2]
    if plane[0] == "x1":
        return y[..., X1], y[..., V1]
    return y[..., X2], y[..., V2]


def _check_plane(plane) -> tuple[str, str]:
    plane = tuple(plane)
    if plane not in PLANES:
        allowed = ", ".join(f"({a}, {b})" for a, b in PLANES)
        raise ValueError(f"plane = {plane!r} is out of range; allowed: {allowed}")
    return plane


@dataclass(frozen=True)
class AsymptoticPoints:
    """Distinct rest points of one trajectory in one plane.

    Attributes
    ----------
    plane : tuple of str
        Coordinate names.
    points : ndarray, shape (k, 2)
        Coordinates (SI units of the plane), in order of first arrival.
    dwell : ndarray, shape (k,)
        Time spent at each point, s (to ``t_end`` for the last one if the run ends there).
    method : {"events", "distance"}
        How they were found.
    tol : float
        Distance tolerance relative to the plane's extent (0 for ``events``).
    min_dwell : float
        Shortest dwell that counts, s.
    """

    plane: tuple
    points: np.ndarray
    dwell: np.ndarray
    method: str
    tol: float
    min_dwell: float

    def __len__(self) -> int:
        return len(self.dwell)


def find_asymptotic_points(trajectory: Trajectory, plane=("delta", "deltadot"), *,
                           method: str | None = None, tol: float = 1e-3,
                           min_dwell: float | None = None) -> AsymptoticPoints:
    """Find the asymptotic points of ``trajectory`` in ``plane`` (docs/physics.md §5).

    Parameters
    ----------
    trajectory : Trajectory
    plane : pair of str
        ``("delta", "deltadot")`` (relative motion, the seed's Fig. 9-10), ``("x1", "x1dot")``
        or ``("x2", "x2dot")``.
    method : {"events", "distance"}, optional
        Defaults to ``events`` for an event-driven trajectory in the relative plane, else
        ``distance`` (which needs samples: ``save="steps"`` or a time grid).
    tol : float
        Distance tolerance for ``distance``, relative to the plane's extent (0 < tol < 1).
    min_dwell : float, optional
        Shortest dwell that counts, s; default 1% of the Hertz contact time.
    """
    plane = _check_plane(plane)
    if not (math.isfinite(tol) and 0 < tol < 1):
        raise ValueError(f"tol = {tol!r} is out of range; allowed: 0 < tol < 1")
    if min_dwell is None:
        min_dwell = 0.01 * scales(trajectory.params).contact_time
    event_driven = not trajectory.integrator.startswith("rk4")
    if method is None:
        method = "events" if event_driven and plane == PLANES[0] else "distance"
    if method == "events":
        if not (event_driven and plane == PLANES[0]):
            raise ValueError("method = 'events' needs an event-driven trajectory and the "
                             "(delta, deltadot) plane; use method = 'distance'")
        points, dwell = _stick_points(trajectory)
        tol = 0.0
    elif method == "distance":
        if len(trajectory.t) < 2:
            raise ValueError("method = 'distance' needs samples: simulate with save='steps' or a time grid")
        points, dwell = _rest_runs(trajectory, plane, tol)
    else:
        raise ValueError(f"method = {method!r} is out of range; allowed: 'events', 'distance'")
    keep = dwell >= min_dwell
    return AsymptoticPoints(plane, points[keep].reshape(-1, 2), dwell[keep], method, tol, min_dwell)


def _stick_points(trajectory: Trajectory):
    """Stick phases of an event-driven run: ``(delta*, 0)`` and how long each lasted."""
    _, delta, dwell = trajectory.stick_points()
    return np.column_stack([delta, np.zeros_like(delta)]), dwell


def _rest_runs(trajectory: Trajectory, plane, tol: float):
    """Maximal runs of samples staying within ``tol`` of their first sample, then merged."""
    a, b = plane_coordinates(trajectory.y, plane)
    scale = np.array([np.ptp(a) or 1.0, np.ptp(b) or 1.0])
    p = np.column_stack([a, b]) / scale
    t = trajectory.t
    candidates, dwell = [], []
    start = 0
    for i in range(1, len(t) + 1):
        if i == len(t) or np.max(np.abs(p[i] - p[start])) > tol:
            if i - start >= 2:
                candidates.append(p[start:i].mean(axis=0))
                dwell.append(t[i - 1] - t[start])
            start = i
    merged, merged_dwell = [], []
    for point, d in zip(candidates, dwell, strict=False):
        for k, other in enumerate(merged):
            if np.max(np.abs(point - other)) <= tol:
                merged_dwell[k] += d
                break
        else:
            merged.append(point)
            merged_dwell.append(d)
    points = np.array(merged, dtype=float).reshape(-1, 2) * scale
    return points, np.array(merged_dwell, dtype=float)


@dataclass(frozen=True)
class FixedPoint:
    """An isolated equilibrium ``(x1, x2, x1dot, x2dot)`` with its Jacobian's eigenvalues."""

    state: np.ndarray
    eigenvalues: np.ndarray
    stability: str  # "stable", "unstable", "neutral" (no eigenvalue with positive real part)


@dataclass(frozen=True)
class EquilibriumSet:
    """A continuum of equilibria, reported as a set (not one arbitrary member).

    ``description`` states the set; ``members`` samples it; ``eigenvalues`` of the dynamics
    transverse to the set (at a sample member) and ``stability`` as for :class:`FixedPoint`.
    """

    description: str
    members: np.ndarray
    eigenvalues: np.ndarray
    stability: str


def _stability(eigenvalues, rtol=1e-9) -> str:
    scale = max(np.max(np.abs(eigenvalues)), 1e-300)
    real = eigenvalues.real / scale
    if np.any(real > rtol):
        return "unstable"
    if np.all(real < -rtol):
        return "stable"
    return "neutral"


def fixed_points(params: Parameters, law: ContactLaw | str = "paper", *,
                 guesses=None, tol: float = 1e-12) -> list:
    """Equilibria of the model: isolated fixed points by Newton, and the sets of equilibria.

    Newton's method runs on the right-hand side with its exact Jacobian from
    each guess of ``(x1, x2)`` (velocities zero); sets are reported as sets: the separated
    states of a unilateral law (``x2`` at a spring equilibrium, ``delta <= 0``), the stick set
    of ``paper`` (``delta`` arbitrary, frozen), and the translations of a free target.
    """
    law = as_law(law)
    c = pack(params, law)
    scale = params.hertz_indentation
    mode = 0 if law.is_filippov else 1
    found: list = []
    if params.target == "plate":
        # Isolated in x2: roots of S(x2) = 0 refined by Newton on the right-hand side.
        roots = []
        starts = guesses if guesses is not None else [(0.0, 0.0), (scale, scale), (-scale, -scale)]
        for x1, x2 in starts:
            y = np.array([x1, x2, 0.0, 0.0, 0.0])
            for _ in range(100):
                f = _rhs(y, c, law, mode)
                J = jacobian(y, params, law, mode)
                try:
                    dy = np.linalg.lstsq(J, -f, rcond=None)[0]
                except np.linalg.LinAlgError:
                    break
                y[:4] += dy
                if np.max(np.abs(dy[:2])) <= tol * scale:
                    break
            if np.all(np.abs(_rhs(y, c, law, mode)) <= 1e-6 * (1 + abs((c[KB_] + c[KM_] * scale**2) * scale))):
                if not any(abs(y[X2] - r) <= 1e-9 * scale for r in roots):
                    roots.append(float(y[X2]))
        for x2 in roots:
            found.extend(_equilibria_at(x2, params, c, law, scale))
    else:
        found.extend(_equilibria_at(0.0, params, c, law, scale))
    return found


def _rhs(y, c, law, mode):
    out = np.empty(5)
    rhs(law.code, c, y, mode, out)
    return out[:4]


def _equilibria_at(x2, params, c, law, scale):
    """The equilibria with the target at ``x2``: a point or a set, with eigenvalues."""
    deltas = np.linspace(-2 * scale, 2 * scale, 5)
    members = np.array([[x2 + d, x2, 0.0, 0.0] for d in deltas])
    where = f"at x2 = {x2:g} m" if params.target != "free" else "with any x2 (free target)"
    if law.is_filippov:
        y = np.array([x2 + scale, x2, 0.0, 0.0, 0.0])
        J = jacobian(y, params, law, 0)
        eig = np.linalg.eigvals(J)
        return [EquilibriumSet(f"stick set: any frozen delta, both at rest, target {where}", members,
                               eig, _stability(eig))]
    if law.is_unilateral:
        y = np.array([x2 - scale, x2, 0.0, 0.0, 0.0])
        J = jacobian(y, params, law, 1)
        eig = np.linalg.eigvals(J)
        separated = members[deltas <= 0]
        return [EquilibriumSet(f"separated states: delta <= 0, both at rest, target {where}", separated,
                               eig, _stability(eig))]
    y = np.array([x2, x2, 0.0, 0.0, 0.0])
    J = jacobian(y, params, law, 1)
    eig = np.linalg.eigvals(J)
    return [FixedPoint(y[:4].copy(), eig, _stability(eig))]


def phase_portrait(params: Parameters, law: ContactLaw | str, kappas=None, *, speeds=None, states=None,
                   t_end: float | None = None, save="steps", rtol: float = 1e-10) -> list[Trajectory]:
    """A family of trajectories to draw in any plane: one per ``kappa`` (seed eq. 6 each), per
    impact speed, or per initial state ``(x1, x2, x1dot, x2dot)`` (exactly one of the three).

    Each keeps its steps (or the times in ``save``) and its events, so
    ``plane_coordinates(tr.y, plane)`` and ``tr.events`` draw it.
    """
    from .integrate import simulate

    law = as_law(law)
    given = [x is not None for x in (kappas, speeds, states)]
    if sum(given) != 1:
        raise ValueError("give exactly one of kappas, speeds= or states=")
    if kappas is not None:
        return [simulate(params.replace(kappa=float(k)), law, t_end, save=save, rtol=rtol)
                for k in np.atleast_1d(kappas)]
    if speeds is not None:
        return [simulate(params.replace(v=float(v)), law, t_end, save=save, rtol=rtol) for v in np.atleast_1d(speeds)]
    states = np.atleast_2d(np.asarray(states, dtype=float))
    if states.shape[1] != 4 or not np.all(np.isfinite(states)):
        raise ValueError("states are out of range; allowed: finite rows (x1, x2, x1dot, x2dot)")
    return [simulate(params, law, t_end, save=save, rtol=rtol, initial=s) for s in states]
