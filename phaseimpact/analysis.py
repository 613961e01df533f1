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

The *equilibria* of the model (:func:`fixed_points`) come from its equations, not from a
trajectory: for the unilateral laws and ``paper`` they are sets, not isolated points
(docs/physics.md §5, "Equilibria").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .integrate import Trajectory, scales
from .model import STUCK, V1, V2, X1, X2, ContactLaw, as_law, jacobian
from .parameters import Parameters

__all__ = [
    "PLANES",
    "AsymptoticPoints",
    "STABILITY_LABELS",
    "Equilibrium",
    "find_asymptotic_points",
    "fixed_points",
    "plane_coordinates",
    "phase_portrait",
]

#: The phase planes: the relative motion, the projectile's and the target's.
PLANES = (("delta", "deltadot"), ("x1", "x1dot"), ("x2", "x2dot"))


def plane_coordinates(y: np.ndarray, plane) -> tuple[np.ndarray, np.ndarray]:
    """The two coordinates of states ``y`` (shape ``(..., 5)``) in ``plane``.

    Parameters
    ----------
    y : ndarray, shape (..., 5) (or (..., 4))
        States ``(x1, x2, x1dot, x2dot[, W])``, m and m/s (e.g. ``Trajectory.y``).
    plane : pair of str
        One of :data:`PLANES`.

    Returns
    -------
    tuple of ndarray
        The position (m) and the velocity (m/s) of the plane, each of shape ``y.shape[:-1]``.

    Raises
    ------
    ValueError
        For a plane not in :data:`PLANES`, or ``y`` of another shape (the last axis: 4 or 5).

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate
    >>> from phaseimpact.analysis import plane_coordinates
    >>> tr = simulate(seed_parameters(kappa=3e9), "paper", 2e-3, save="steps")
    >>> delta, deltadot = plane_coordinates(tr.y, ("delta", "deltadot"))
    >>> delta.shape == tr.t.shape, f"{delta.max():.4g} m"
    (True, '3.547e-05 m')
    """
    plane = _check_plane(plane)
    y = np.asarray(y)
    if y.ndim < 1 or y.shape[-1] not in (4, 5) or y.dtype.kind not in "fiu":
        raise ValueError(f"y has shape {y.shape} and type {y.dtype}; allowed: states of shape (..., 5) or (..., 4): "
                         "x1, x2, x1dot, x2dot[, W]")
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

    ``len()`` is the number of points.

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate
    >>> from phaseimpact.analysis import find_asymptotic_points
    >>> points = find_asymptotic_points(simulate(seed_parameters(kappa=3e9), "paper"))
    >>> len(points), points.method, points.dwell.tolist()
    (1, 'events', [inf])
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

    Returns
    -------
    AsymptoticPoints
        The points in order of first arrival, with their dwell times.

    Raises
    ------
    TypeError
        If ``trajectory`` is not a Trajectory.
    ValueError
        For a plane not in :data:`PLANES`, ``tol`` out of range, an unknown ``method``,
        ``events`` on a trajectory without events (RK4) or outside the relative plane, or
        ``distance`` on a trajectory without samples.

    Examples
    --------
    A permanent stick is one asymptotic point; above ``kappa_c`` each stick phase is a point of
    its own (docs/physics.md §5):

    >>> from phaseimpact import seed_parameters, simulate
    >>> from phaseimpact.analysis import find_asymptotic_points
    >>> len(find_asymptotic_points(simulate(seed_parameters(kappa=3e9), "paper")))
    1
    >>> points = find_asymptotic_points(simulate(seed_parameters(kappa=2e12), "paper"))
    >>> [f"{d:.3g}" for d in points.points[:, 0]]
    ['7.78e-06', '8.03e-06']

    From samples alone (``distance``), the same permanent stick:

    >>> import numpy as np
    >>> tr = simulate(seed_parameters(kappa=3e9), "paper", 2e-3, save=np.linspace(0, 2e-3, 201))
    >>> points = find_asymptotic_points(tr, method="distance")
    >>> len(points), f"{points.points[0, 0]:.4g} m"
    (1, '3.547e-05 m')
    """
    if not isinstance(trajectory, Trajectory):
        raise TypeError(f"trajectory has the wrong type ({type(trajectory).__name__}); allowed: a Trajectory "
                        "(phaseimpact.simulate)")
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


#: Stability labels of an equilibrium's linearisation (:func:`_stability`), plus "non-smooth" where the
#: contact force has no derivative there (``alpha < 1`` at ``delta = 0``).
STABILITY_LABELS = ("stable", "unstable", "centre", "non-hyperbolic", "non-smooth")


@dataclass(frozen=True)
class Equilibrium:
    """An equilibrium of eq. 1 under a contact law: an isolated point or a set (docs/physics.md §5).

    Attributes
    ----------
    kind : {"point", "set"}
        A set is reported as a set (its conditions and samples), never as one arbitrary member.
    name : {"rest", "separated", "stuck"}
        ``rest``: the bodies at rest in contact at ``delta = 0`` (a bilateral law); ``separated``:
        at rest with ``delta <= 0``, no force (a unilateral law); ``stuck``: ``paper``'s pair at
        rest with ``delta*`` frozen (the sliding set of the Filippov system).
    description : str
        The set in words.
    conditions : dict
        ``{coordinate: condition}``: ``"= 0"``, ``"<= 0"``, ``"> 0"`` or ``"any"`` for ``x1dot``,
        ``x2dot``, ``x2`` and ``delta = x1 - x2``.
    dimension : int
        0 for a point; the number of free coordinates of a set.
    state : ndarray, shape (4,)
        ``(x1, x2, x1dot, x2dot)`` of the member where the linearisation is taken.
    members : ndarray, shape (k, 4)
        Samples of the set (the point itself for a point).
    coordinates : tuple of str
        The coordinates of the linearisation: ``(x1, x2, x1dot, x2dot)``; ``(x1, x1dot)`` on a rigid
        target (``x2`` is held at 0); on ``paper``'s stuck set those of the sliding flow,
        ``(x1, x2, v)`` with ``v = x1dot = x2dot`` (``(x1,)`` on a rigid target).
    eigenvalues : ndarray of complex
        Of the exact Jacobian (:func:`phaseimpact.model.jacobian`) at ``state`` in these
        coordinates, 1/s; those below :data:`ZERO_RTOL` of the largest are 0 (rounding of a zero
        Jordan block); empty where ``stability`` is ``non-smooth``.
    stability : str
        One of :data:`STABILITY_LABELS`, from the eigenvalues alone (:func:`_stability`).
    note : str
        What the linearisation does not say (the nonlinear stability of the set or point).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.analysis import fixed_points
    >>> stuck = fixed_points(seed_parameters(), "paper")[0]
    >>> stuck.kind, stuck.name, stuck.dimension, stuck.coordinates, stuck.stability
    ('set', 'stuck', 1, ('x1', 'x2', 'v'), 'non-hyperbolic')
    """

    kind: str
    name: str
    description: str
    conditions: dict
    dimension: int
    state: np.ndarray
    members: np.ndarray
    coordinates: tuple
    eigenvalues: np.ndarray
    stability: str
    note: str

    def as_dict(self) -> dict:
        """Plain types for JSON; eigenvalues as ``{"re", "im"}`` pairs.

        Returns
        -------
        dict
            The attributes by name; arrays as lists, eigenvalues as ``{"re", "im"}`` (1/s).

        Examples
        --------
        >>> from phaseimpact import ContactLaw, seed_parameters
        >>> from phaseimpact.analysis import fixed_points
        >>> rest = fixed_points(seed_parameters(), ContactLaw("abrate", bilateral=True))[0].as_dict()
        >>> rest["kind"], rest["conditions"]["delta"], [f"{z['im']:.4g}" for z in rest["eigenvalues"]][:2]
        ('point', '= 0', ['6261', '-6261'])
        """
        return {"kind": self.kind, "name": self.name, "description": self.description,
                "conditions": dict(self.conditions), "dimension": self.dimension,
                "state": self.state.tolist(), "members": self.members.tolist(),
                "coordinates": list(self.coordinates),
                "eigenvalues": [{"re": float(z.real), "im": float(z.imag)} for z in self.eigenvalues],
                "stability": self.stability, "note": self.note}


#: Eigenvalues (real parts in :func:`_stability`) below this fraction of the largest modulus are zero.
ZERO_RTOL = 1e-6


def _stability(eigenvalues, rtol=ZERO_RTOL) -> str:
    """Label of a linearisation: ``unstable`` (an eigenvalue with positive real part), ``stable``
    (all negative: hyperbolic sink), ``centre`` (all on the imaginary axis, none zero), else
    ``non-hyperbolic`` (a zero eigenvalue, or zero real parts beside negative ones).

    Real parts count as zero up to ``rtol`` times the largest modulus: a zero Jordan block splits
    by about ``sqrt(eps)`` of the matrix's scale in floating point.
    """
    eigenvalues = np.asarray(eigenvalues, dtype=complex)
    scale = float(np.max(np.abs(eigenvalues), initial=0.0))
    if scale == 0.0:
        return "non-hyperbolic"
    real = eigenvalues.real / scale
    if np.any(real > rtol):
        return "unstable"
    if np.all(real < -rtol):
        return "stable"
    if np.all(np.abs(real) <= rtol) and np.all(np.abs(eigenvalues) / scale > rtol):
        return "centre"
    return "non-hyperbolic"


def fixed_points(params: Parameters, law: ContactLaw | str = "paper") -> list[Equilibrium]:
    """The equilibria of eq. 1 under ``law`` on ``params``' target, each a point or a set.

    At rest the accelerations vanish: ``M1 x1'' + M2 x2'' = -S(x2) = 0`` gives ``x2 = 0`` (the
    only real root of ``S(x2) = Kb x2 + Km x2^3`` with ``Kb, Km >= 0``, not both 0; any ``x2`` for
    a free target), and then ``P = 0`` at ``deltadot = 0``. Which ``delta`` has ``P(delta, 0) = 0``
    is the law's: ``delta <= 0`` for a unilateral law (the separated set), ``delta = 0`` for a
    bilateral one (an isolated point on a plate), every ``delta`` for ``paper``, whose stuck pair
    at rest needs no force, ``M1/(M1+M2) S(0) = 0 <= K |delta*|^alpha`` (the stuck set; with the
    unilateral reading only for ``delta > 0``, the rest being separated). docs/physics.md §5.

    Returns the equilibria with their linearisation (:class:`Equilibrium`); ``kappa`` and ``v``
    move none of them (the damping acts through ``deltadot``, zero at rest), ``v`` sets only the
    spacing of the samples (the Hertz indentation).

    Parameters
    ----------
    params : Parameters
        The case; its ``target`` (plate, rigid, free) decides where the target may rest.
    law : ContactLaw or str, default "paper"
        Any law, with its options (``contact="unilateral"``, ``bilateral=True``...).

    Returns
    -------
    list of Equilibrium
        The separated set (unilateral laws), the stuck set (``paper``) or the rest point
        (bilateral laws), in that order.

    Raises
    ------
    ValueError
        For an unknown law.

    Examples
    --------
    >>> from phaseimpact import ContactLaw, seed_parameters
    >>> from phaseimpact.analysis import fixed_points
    >>> [(e.name, e.stability) for e in fixed_points(seed_parameters(), "abrate")]
    [('separated', 'non-hyperbolic')]
    >>> [(e.name, e.kind) for e in fixed_points(seed_parameters(), ContactLaw("paper", contact="unilateral"))]
    [('separated', 'set'), ('stuck', 'set')]
    >>> [f"{abs(z):.4g}" for z in fixed_points(seed_parameters(), "paper")[0].eigenvalues]
    ['0', '4599', '4599']
    """
    law = as_law(law)
    s = params.hertz_indentation  # spacing of the samples along a set
    rigid = params.target == "rigid"
    # a plate without springs (Kb = Km = 0, API only) holds its centre nowhere: a free target
    x2_free = params.target == "free" or (params.target == "plate" and params.Kb == 0 and params.Km == 0)
    x2_samples = (0.0, s) if x2_free else (0.0,)
    x2_text = "any" if x2_free else "= 0"
    where = ("the target held at x2 = 0 (rigid)" if rigid else
             "the target anywhere, at rest (free)" if x2_free else "the plate at its static equilibrium x2 = 0")
    found = []

    def members(deltas):
        return np.array([[x2 + d, x2, 0.0, 0.0] for x2 in x2_samples for d in deltas])

    def conditions(delta):
        return {"x1dot": "= 0", "x2dot": "= 0", "x2": x2_text, "delta": delta}

    if law.is_unilateral:
        state = np.array([-s, 0.0, 0.0, 0.0])
        eig, coords = _eigenvalues(state, params, law, 1)
        if law.is_filippov:
            bound = "paper's outward slips can feed energy (docs/physics.md §3): no energy bound holds"
        elif not law.is_conservative:
            bound = "the law's elastic term has no potential: no energy bound holds"
        else:  # a potential and a damping kappa >= 0 that only dissipates
            bound = ("the energy (docs/physics.md §4) does not grow and bounds the velocities"
                     + ("" if x2_free or rigid else " and the plate's swing")
                     + ", so motions that start near the set stay near it: the set is stable")
        found.append(Equilibrium(
            "set", "separated",
            f"separated at rest: delta = x1 - x2 <= 0, both at rest, no contact force; {where}",
            conditions("<= 0"), 2 if x2_free else 1, state, members((-2 * s, -s, 0.0)), coords, eig,
            _stability(eig),
            "no member is stable: a velocity perturbation makes the projectile drift (a zero eigenvalue pair, "
            f"a Jordan block) along the set; {bound}"))
    if law.is_filippov:
        unilateral = law.is_unilateral
        deltas = (s, 2 * s) if unilateral else (-2 * s, -s, 0.0, s, 2 * s)
        state = np.array([s, 0.0, 0.0, 0.0])
        eig, coords = _eigenvalues(state, params, law, STUCK)
        holds = ("no springs pull the pair apart: the stick never breaks" if rigid or x2_free else
                 "a small swing A of the pair at sqrt(Kb/(M1+M2)) keeps the stick while M1/(M1+M2) S(A) <= "
                 "K |delta*|^alpha (not at delta* = 0, whose bound is 0)")
        found.append(Equilibrium(
            "set", "stuck",
            f"paper's stuck pair at rest: delta* = x1 - x2 {'> 0' if unilateral else 'any'} frozen, both at rest, "
            f"stick force M1/(M1+M2) S(x2) = 0 within the bound K |delta*|^alpha; {where}",
            conditions("> 0" if unilateral else "any"), 2 if x2_free else 1, state, members(deltas), coords, eig,
            _stability(eig),
            f"eigenvalues of the sliding flow on deltadot = 0; {holds}; a small slip stops in finite time (no "
            "eigenvalue across the set) at a nearby delta*: the set is stable, no member asymptotically stable"))
    if not (law.is_unilateral or law.is_filippov):  # bilateral: P(delta, 0) = 0 only at delta = 0
        state = np.zeros(4)
        if params.alpha < 1:
            eig, coords, label = np.empty(0, dtype=complex), _coordinates(rigid, stuck=False), "non-smooth"
        else:
            eig, coords = _eigenvalues(state, params, law, 1)
            label = _stability(eig)
        energy = ("K |delta|^(alpha+1)/(alpha+1) + M1 x1dot^2/2" if rigid else
                  "the energy of docs/physics.md §4 (contact potential included)")
        degenerate = ("" if params.alpha == 1 else
                      "; for alpha < 1 the contact stiffness is infinite at delta = 0: no linearisation"
                      if params.alpha < 1 else
                      "; the contact stiffness alpha K |delta|^(alpha-1) vanishes at delta = 0 (alpha > 1): the "
                      "linearisation is degenerate")
        found.append(Equilibrium(
            "set" if x2_free else "point", "rest",
            f"at rest in contact at delta = x1 - x2 = 0; {where}", conditions("= 0"), 1 if x2_free else 0,
            state, members((0.0,)), coords, eig, label,
            f"Lyapunov stable{' as a set' if x2_free else ''}: {energy} has a strict minimum "
            f"{'across the set' if x2_free else 'here'} (Lagrange-Dirichlet), not asymptotically (no damping at "
            f"rest){degenerate}"))
    return found


def _coordinates(rigid: bool, stuck: bool) -> tuple:
    if stuck:
        return ("x1",) if rigid else ("x1", "x2", "v")
    return ("x1", "x1dot") if rigid else ("x1", "x2", "x1dot", "x2dot")


def _eigenvalues(state, params, law, mode):
    """Eigenvalues of the exact Jacobian at ``state`` in ``mode``, in the coordinates that move.

    A rigid target's ``(x2, x2dot)`` are held, not dynamics. Stuck, the motion is the sliding flow
    on ``x1dot = x2dot = v`` (an invariant plane of the stuck field): the Jacobian restricted to it.
    """
    rigid = params.target == "rigid"
    stuck = mode == STUCK
    y = state
    if not stuck and not law.is_unilateral and params.alpha == 1:
        # force_partials gives 0 at delta = 0 exactly; for alpha = 1 the stiffness is K at every delta
        y = state + np.array([params.hertz_indentation, 0.0, 0.0, 0.0])
    J = jacobian(y, params, law, mode)
    if stuck:
        embed = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1]])  # (x1, x2, v) -> state
        J = np.linalg.pinv(embed) @ J @ embed
        keep = [0] if rigid else [0, 1, 2]
    else:
        keep = [X1, V1] if rigid else [X1, X2, V1, V2]
    eig = np.linalg.eigvals(J[np.ix_(keep, keep)])
    # rounding noise to exact zeros: a zero Jordan block (the drift along a set) splits by about
    # sqrt(eps) of the matrix's scale, and real parts of a centre by about eps
    scale = float(np.max(np.abs(eig), initial=0.0))
    eig[np.abs(eig) <= ZERO_RTOL * scale] = 0.0
    eig.real[np.abs(eig.real) <= 1e-12 * scale] = 0.0
    return eig, _coordinates(rigid, stuck)


def phase_portrait(params: Parameters, law: ContactLaw | str, kappas=None, *, speeds=None, states=None,
                   t_end: float | None = None, save="steps", rtol: float = 1e-10) -> list[Trajectory]:
    """A family of trajectories to draw in any plane: one per ``kappa`` (seed eq. 6 each), per
    impact speed, or per initial state ``(x1, x2, x1dot, x2dot)`` (exactly one of the three).

    Each keeps its steps (or the times in ``save``) and its events, so
    ``plane_coordinates(tr.y, plane)`` and ``tr.events`` draw it.

    Parameters
    ----------
    params : Parameters
        The base case.
    law : ContactLaw or str
        The law of every run.
    kappas : sequence of float, optional
        Damping values, N s/m^(1+alpha) (N s/m^2.5 for alpha = 3/2).
    speeds : sequence of float, optional
        Impact speeds, m/s.
    states : array of shape (k, 4), optional
        Initial states ``(x1, x2, x1dot, x2dot)``, m and m/s, finite.
    t_end : float, optional
        Horizon of every run, s; default: until its outcome settles.
    save : "steps" or array of times, default "steps"
        What each run keeps, as for :func:`~phaseimpact.simulate`.
    rtol : float, default 1e-10
        Integrator tolerance.

    Returns
    -------
    list of Trajectory
        One per value given, in order (for :func:`phaseimpact.plotting.plot_portraits`).

    Raises
    ------
    ValueError
        Unless exactly one of ``kappas``, ``speeds`` and ``states`` is given, for states that are
        not finite rows of four, or for any argument :func:`~phaseimpact.simulate` refuses.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.analysis import phase_portrait
    >>> runs = phase_portrait(seed_parameters(), "paper", [1e9, 2e12], t_end=2e-3)
    >>> [tr.outcome for tr in runs], all(len(tr.t) > 2 for tr in runs)
    (['bounded', 'ratchet-escape'], True)
    >>> [tr.params.v for tr in phase_portrait(seed_parameters(), "abrate", speeds=[0.5, 1.0], t_end=2e-3)]
    [0.5, 1.0]
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
