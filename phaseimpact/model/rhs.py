r"""Equations of motion composed from a law's kernels (seed eq. 1 and 8; docs/physics.md §3-§4).

State ``y = (x1, x2, x1dot, x2dot, W)``: projectile and target-centre displacements (m), their
velocities (m/s), and ``W = \int P d(delta)``, the work of the contact force on the relative
motion (J)::

    M1 x1'' = -P
    M2 x2'' = -S(x2) + P,        S(x2) = Kb x2 + Km x2^3   (plate; 0 for a free target)
    delta = x1 - x2,  deltadot = x1dot - x2dot,  W' = P deltadot

A rigid target is held at ``x2 = 0``. While ``paper`` is stuck the bodies move as one of mass
``M1 + M2`` and ``P = F_req = M1/(M1+M2) S(x2)``.

The infinite plate (docs/physics.md §8) is a dashpot: its load point moves with ``x2dot = P / c``,
``c`` the point impedance; its mass and springs take no part. That constraint is implicit in
``x2dot`` for a law whose force depends on ``deltadot``; differentiated once it becomes the
explicit equation ``(c + P_d) x2'' = P_delta deltadot + P_d x1''`` (``P_delta``, ``P_d`` the law's
exact partials), integrated with the others: no solve per evaluation, the same code for every
law, and the constraint holds to the integration's error (it starts exact: ``P = 0 = x2dot``). ``W``
is then the work of the contact force on the projectile, ``W' = P x1dot = P deltadot + P x2dot``:
the contact's own work plus the energy radiated into the plate (``P x2dot = P^2 / c``), so that the
ledger ``E(0) - E(t) = W - (U(t) - U(0))`` with ``E = M1 x1dot^2 / 2 + U`` closes as for the other
targets. Stuck (``paper``), the pair moves as one on the dashpot: ``P = c x1dot``,
``M1 x1'' = -c x1dot``. Coefficients travel packed in one float array (:func:`pack`), the layout
every compiled function reads.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import kernel
from ..parameters import Parameters
from .forms import (  # noqa: F401 (the packed layout, re-exported: the engine's modules read it here)
    ALPHA_,
    DAMP_,
    GUARD_,
    IMPEDANCE_,
    K_,
    KB_,
    KM_,
    LAW_,
    M1_,
    M2_,
    MEMORY_,
    N_COEF,
    N_LAW,
    N_MEMORY,
    PLAIN,
    RIGID_,
    SPRINGS_,
    STUCK,
    contact_gap,
    force_of,
    force_of_root,
    is_filippov,
    partials_of,
    potential_of,
    stick_bound,
)
from .laws import (
    ContactLaw,
    as_law,
)

__all__ = [
    "X1", "X2", "V1", "V2", "WORK", "pack", "N_COEF", "GUARD_",
    "rhs", "rhs_integration", "rhs_values", "contact_side", "damping_rate", "PLAIN_PHASE", "FLIGHT", "energy",
    "relative_slip",
    "stick_force", "stick_orbit", "stick_margin", "stick_break_distance",
    "jacobian", "initial_state",
]

X1, X2, V1, V2, WORK = range(5)


def pack(params: Parameters, law: ContactLaw) -> np.ndarray:
    """The packed coefficient array of ``params`` under ``law`` (springs only on a plate; the
    law's own coefficients; its memory empty).

    Parameters
    ----------
    params : Parameters
        The model's parameters (masses in kg, ``K`` in N/m^alpha, ``Kb`` in N/m, ``Km`` in N/m^3,
        the target's kind).
    law : ContactLaw
        The law with its options (not a name: :func:`~phaseimpact.model.as_law` makes one).

    Returns
    -------
    numpy.ndarray
        Shape ``(N_COEF,)`` = (16,), float: ``M1, M2, K, Kb, Km`` (the springs 0 unless the target
        is a plate), the law's effective damping coefficient (:meth:`ContactLaw.kappa`, N
        s/m^damping_power), ``alpha``, the flags springs and rigid (1.0 or 0.0), the runaway
        guard factor, then the law's own coefficients (from ``LAW_``) and its memory (from
        ``MEMORY_``, zeros), each padded with zeros, and last the infinite plate's impedance
        ``c`` (N s/m; 0 for the other targets).

    Raises
    ------
    ValueError
        When ``params`` lack what the law needs (:meth:`ContactLaw.coefficients`).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.model import ContactLaw, pack
    >>> c = pack(seed_parameters(v=1.0, kappa=1e9), ContactLaw("hunt-crossley"))
    >>> c.shape
    (16,)
    >>> print(f"M1 = {c[0]:.4g} kg, K = {c[2]:.4g} N/m^1.5, kappa = {c[5]:.4g} N s/m^2.5")
    M1 = 0.2631 kg, K = 2.176e+10 N/m^1.5, kappa = 1e+09 N s/m^2.5
    >>> pack(seed_parameters(target="rigid"), ContactLaw("abrate"))[[3, 4, 7, 8]]  # Kb, Km, springs, rigid
    array([0., 0., 0., 1.])
    """
    springs = params.target == "plate"
    own = law.coefficients(params)
    return np.array([params.M1, params.M2, params.K, params.Kb if springs else 0.0,
                     params.Km if springs else 0.0, law.kappa(params), params.alpha,
                     1.0 if springs else 0.0, 1.0 if params.target == "rigid" else 0.0, law.runaway_factor,
                     *own, *(0.0,) * (N_LAW - len(own)), *(0.0,) * N_MEMORY,
                     params.impedance if params.target == "infinite" else 0.0])


@kernel
def spring_force(c, x2):
    """``S(x2) = Kb x2 + Km x2^3``, N."""
    return (c[KB_] + c[KM_] * x2 * x2) * x2


@kernel
def _stick_force_at(c, x2):
    return c[M1_] / (c[M1_] + c[M2_]) * spring_force(c, x2)


@kernel(python=True)
def stick_force(c, y):
    """Force that keeps the projectile with the target while stuck, ``F_req``, N.

    0 on the infinite plate, where a stick always holds: the pair needs the dashpot's ``c x2dot``,
    which at the ``deltadot = 0`` that starts the stick is the slip's own force there,
    ``P(delta, 0+-)`` (the constraint ``c x2dot = P``), at the stick bound, and which then only
    decreases as the pair slows (``M1 x1'' = -c x1dot``). Compared with the bound, the integrated
    ``c x2dot`` would refuse half of these sticks on rounding alone (a slip then went on through
    ``deltadot = 0`` unlogged)."""
    if c[IMPEDANCE_] > 0:
        return 0.0
    return _stick_force_at(c, y[X2])


@kernel
def _load_point_rate(code, c, delta, deltadot, accel, mode, odd):
    """``x2''`` of the infinite plate's load point: ``c x2dot = P(delta, deltadot)`` differentiated,
    ``(P_delta deltadot + P_d x1'') / (c + P_d)``, with the projectile's ``x1'' = accel``;
    ``odd`` = -1 continues ``P_delta`` as an odd function past ``w = 0`` (:func:`rhs_values`)."""
    p_delta, p_rate = partials_of(code, c, delta, deltadot, mode)
    return (odd * p_delta * deltadot + p_rate * accel) / (c[IMPEDANCE_] + p_rate)


#: Phase kinds of the integration (:func:`contact_side`): plain, free flight, or a regularised
#: contact on the side +1 / -1 of ``delta``.
PLAIN_PHASE, FLIGHT = 0, 2


@kernel(python=True)
def contact_side(code, c, y, mode):
    """How the driver integrates the phase that starts at ``y`` in ``mode``.

    ``+1`` or ``-1`` (the sign of ``delta``, or of ``deltadot`` at ``delta = 0``; past a law's dent, of
    :func:`~phaseimpact.model.forms.contact_gap`) while a Hertz
    power law (``alpha = 3/2``) acts: a regularised contact, where the driver integrates
    ``u = (w, x2, x1dot, x2dot, W, t)`` with ``delta = side w^2`` in the time ``s`` with
    ``dt = w ds`` (:func:`rhs_integration`): the ``delta^(3/2)`` singularity at the contact's onset
    and end, which forces an explicit method into tiny and rejected steps, becomes a polynomial.
    :data:`FLIGHT` for a unilateral law on the side ``delta < 0``: no force, continued without one
    past the contact (the contact event ends the phase there). :data:`PLAIN_PHASE` otherwise
    (stuck, the seed's literal reading, other exponents).
    """
    if mode == STUCK or mode == PLAIN:
        return PLAIN_PHASE
    delta = contact_gap(code, c, y[X1], y[X2])  # a law with memory flies inside its dent
    deltadot = y[V1] - y[V2]
    side = 1 if delta > 0 else (-1 if delta < 0 else (1 if deltadot > 0 else (-1 if deltadot < 0 else 0)))
    if side < 0 and force_of(code, c, -1.0, 0.0, mode) == 0.0:
        return FLIGHT  # a unilateral law
    if side == 0 or c[ALPHA_] != 1.5:
        return PLAIN_PHASE
    return side


@kernel(python=True, forceinline=True)
def relative_slip(code, mode, side):
    """Whether a phase integrates ``deltadot`` in place of ``x1dot`` (slot ``V1`` of ``u``): the
    slips of a Filippov law. Near the critical damping a slip's relative speed is 1e-7 to 1e-12 of
    the bodies' own speeds; integrated as ``x1dot - x2dot`` under tolerances on the impact speed its
    sign was noise, and a spurious zero turned a slip that re-sticks into an escape (a stick
    missed, a count wrong). Integrated itself, ``deltadot`` has its own error control
    (docs/physics.md §3)."""
    return side != FLIGHT and (mode == 1 or mode == -1) and is_filippov(code)


@kernel(python=True)
def rhs_values(code, c, u0, x2, v1, v2, mode, side):
    """The rates of a phase of kind ``side`` (:func:`contact_side`) and the contact force:
    ``(du0, dx2, dv1, dv2, dW, dt, P)`` per unit of the phase's independent variable ``s``.

    The integration state is ``u = (u0, x2, x1dot, x2dot, W, t)``; its last two components are
    quadratures, which the rates do not read. Plain and flight phases: ``u0 = x1`` and ``s = t``
    (flight: without a contact force, also past ``delta = 0``). Regularised contact: ``u0 = w``
    with ``delta = side w^2`` and ``dt = w ds``; past ``w = 0`` (where the phase ends on an event)
    the force continues as an odd function of ``w``, so the equations stay smooth across the root.
    Scalars in and out: a stepper keeps its stages in registers (:mod:`..integrate.dop853`).
    In a :func:`relative_slip` phase ``v1`` is ``deltadot`` and its rate is ``deltadot'``.
    """
    relative = relative_slip(code, mode, side)
    deltadot = v1 if relative else v1 - v2
    if side == PLAIN_PHASE:
        if mode == STUCK:
            if c[RIGID_] > 0:
                return v1, v2, 0.0, 0.0, 0.0, 1.0, 0.0
            if c[IMPEDANCE_] > 0:  # the pair on the dashpot: the projectile's energy radiated
                force = c[IMPEDANCE_] * v1
                accel = -force / c[M1_]
                return v1, v2, accel, accel, force * v1, 1.0, force
            accel = -spring_force(c, x2) / (c[M1_] + c[M2_])
            force = _stick_force_at(c, x2)
            return v1, v2, accel, accel, force * deltadot, 1.0, force
        force = force_of(code, c, u0 - x2, deltadot, mode)
        if c[IMPEDANCE_] > 0:
            target = _load_point_rate(code, c, u0 - x2, deltadot, -force / c[M1_], mode, 1.0)
            work = force * (deltadot + v2)
        else:
            target = 0.0 if c[RIGID_] > 0 else (force - spring_force(c, x2)) / c[M2_]
            work = force * deltadot
        if relative:
            return deltadot + v2, v2, -force / c[M1_] - target, target, work, 1.0, force
        return v1, v2, -force / c[M1_], target, work, 1.0, force
    if side == FLIGHT:
        return v1, v2, 0.0, 0.0 if c[RIGID_] > 0 else -spring_force(c, x2) / c[M2_], 0.0, 1.0, 0.0
    w = u0
    delta = side * w * w
    force = force_of_root(code, c, delta, abs(w), deltadot, mode)
    if w < 0:
        force = -force
    if c[IMPEDANCE_] > 0:
        target = w * _load_point_rate(code, c, delta, deltadot, -force / c[M1_], mode, -1.0 if w < 0 else 1.0)
        work = w * force * (deltadot + v2)
    else:
        target = 0.0 if c[RIGID_] > 0 else w * (force - spring_force(c, x2)) / c[M2_]
        work = w * force * deltadot
    projectile = -w * force / c[M1_]
    return (0.5 * side * deltadot, w * v2, projectile - target if relative else projectile, target,
            work, w, force)


@kernel(python=True)
def rhs_integration(code, c, u, mode, side, out):
    """Write ``du/ds`` into ``out`` (shape (6,)) for a phase of kind ``side``; return the contact
    force, N (:func:`rhs_values`)."""
    out[0], out[X2], out[V1], out[V2], out[WORK], out[5], force = rhs_values(code, c, u[0], u[X2], u[V1], u[V2],
                                                                             mode, side)
    return force


@kernel(python=True)
def rhs(code, c, y, mode, out):
    """Write ``dy/dt`` into ``out`` (shape (5,)); return the contact force ``P``, N."""
    # np.int64: a bare constant would be typed as a literal and compile rhs_values a second time
    plain = np.int64(PLAIN_PHASE)
    relative = relative_slip(code, mode, plain)
    v1 = y[V1] - y[V2] if relative else y[V1]
    out[X1], out[X2], out[V1], out[V2], out[WORK], _, force = rhs_values(code, c, y[X1], y[X2], v1, y[V2],
                                                                         mode, plain)
    if relative:
        out[V1] = -force / c[M1_]
    return force


@kernel(python=True, forceinline=True)
def damping_rate(code, c, u, mode, side):
    """How fast the contact damps the relative motion at the integration state ``u`` of a phase
    of kind ``side``: ``dP/d(deltadot) (1/M1 + 1/M2)`` per unit of the phase's independent
    variable (times ``|w|`` in a regularised contact). Zero when stuck or free; negative where
    the law feeds the motion (``paper``'s outward slip)."""
    if mode == STUCK or side == FLIGHT:
        return 0.0
    regularised = side == 1 or side == -1
    delta = side * u[0] * u[0] if regularised else u[X1] - u[X2]
    deltadot = u[V1] if relative_slip(code, mode, side) else u[V1] - u[V2]
    partial = partials_of(code, c, delta, deltadot, mode)[1]
    # the infinite plate's load point follows the contact (x2dot = P / c): the projectile's rate
    rate = partial * (1.0 / c[M1_] + (0.0 if c[RIGID_] > 0 or c[IMPEDANCE_] > 0 else 1.0 / c[M2_]))
    return rate * abs(u[0]) if regularised else rate


@kernel(python=True)
def energy(code, c, y):
    """Mechanical energy (docs/physics.md §4), J: kinetic + target springs + the contact potential
    of laws whose elastic term is conservative. The infinite plate's load point has no mass: what
    the plate takes is radiated, and counted in ``W`` (module docstring)."""
    x2 = y[X2]
    x2sq = x2 * x2
    target_mass = 0.0 if c[IMPEDANCE_] > 0 else c[M2_]
    kinetic = 0.5 * c[M1_] * y[V1] * y[V1] + 0.5 * target_mass * y[V2] * y[V2]
    springs = (0.5 * c[KB_] + 0.25 * c[KM_] * x2sq) * x2sq
    return kinetic + springs + potential_of(code, c, y[X1] - x2)


@kernel
def _orbit_amplitude(c, x2, v, mass):
    """Turning point of an oscillator of ``mass`` on the springs ``S`` through ``(x2, v)``, m."""
    orbit_energy = 0.5 * mass * v * v + (0.5 * c[KB_] + 0.25 * c[KM_] * x2 * x2) * x2 * x2
    root = math.sqrt(c[KB_] * c[KB_] + 4.0 * c[KM_] * orbit_energy)
    if c[KB_] + root <= 0:
        return abs(x2)
    return math.sqrt(4.0 * orbit_energy / (c[KB_] + root))


@kernel
def _spring_potential(c, x2):
    x2sq = x2 * x2
    return (0.5 * c[KB_] + 0.25 * c[KM_] * x2sq) * x2sq


@kernel
def stuck_pair_energy(c, y):
    """Energy of the stuck pair, ``(M1 + M2) v^2/2 + Kb x2^2/2 + Km x2^4/4``, J: conserved while stuck."""
    return 0.5 * (c[M1_] + c[M2_]) * y[V2] * y[V2] + _spring_potential(c, y[X2])


@kernel
def onto_stuck_orbit(c, pair_energy, y):
    """Put the stuck pair's velocity at ``y`` back on its orbit of ``pair_energy`` (same sign).

    A stick that lasts thousands of plate periods near the critical damping (docs/physics.md §5)
    would otherwise carry the integrator's energy drift into every break: at rtol 1e-10 that moved
    the staircase N(kappa) by 0.3 % at kappa_c (1 + 1e-5)."""
    v_sq = 2.0 * (pair_energy - _spring_potential(c, y[X2])) / (c[M1_] + c[M2_])
    v = math.copysign(math.sqrt(max(v_sq, 0.0)), y[V2])
    y[V1] = v
    y[V2] = v


@kernel
def target_reach(c, y):
    """Largest ``|x2|`` the target can reach with its current energy, m."""
    return _orbit_amplitude(c, y[X2], y[V2], c[M2_])


@kernel(python=True)
def stick_orbit(code, c, y):
    """Amplitude ``A`` of the stuck pair's orbit and the ``|x2|`` at which the stick breaks.

    The pair oscillates with conserved energy ``M v^2/2 + Kb x2^2/2 + Km x2^4/4``
    (``M = M1 + M2``); the force it needs, ``M1/M S(x2)``, reaches the bound ``K |delta|^alpha``
    at ``x_break``, the real root of ``Km x^3 + Kb x = M/M1 * bound`` (Cardano). docs/physics.md §5.
    """
    M = c[M1_] + c[M2_]
    amplitude = _orbit_amplitude(c, y[X2], y[V2], M)
    bound = M / c[M1_] * stick_bound(code, y[X1] - y[X2], c[K_], c[DAMP_], c[ALPHA_])
    if c[KM_] > 0:
        p = c[KB_] / (3.0 * c[KM_])
        if p > 0:
            x_break = 2.0 * math.sqrt(p) * math.sinh(math.asinh(bound / (2.0 * c[KM_]) / p**1.5) / 3.0)
        else:
            x_break = (bound / c[KM_]) ** (1.0 / 3.0)
    else:
        x_break = bound / c[KB_] if c[KB_] > 0 else math.inf
    return amplitude, x_break


@kernel(python=True)
def stick_margin(code, c, y):
    """Relative margin of a stick entered at ``y``: ``1 - M1/M S(A) / (K |delta*|^alpha)``.

    ``>= 0``: the stick never breaks (permanent); the critical damping is its root
    (docs/physics.md §5). 1 without target springs (nothing pulls the pair apart).
    """
    if c[SPRINGS_] == 0:
        return 1.0
    amplitude, _ = stick_orbit(code, c, y)
    bound = stick_bound(code, y[X1] - y[X2], c[K_], c[DAMP_], c[ALPHA_])
    required = c[M1_] / (c[M1_] + c[M2_]) * spring_force(c, amplitude)
    if bound <= 0:
        return -math.inf if required > 0 else 1.0
    return 1.0 - required / bound


@kernel(python=True)
def stick_break_distance(code, c, y):
    """Stick-break event function, monotone along each half-swing of the stuck pair, m.

    ``x_break - |x2|`` swinging out and ``x_break - 2A + |x2|`` swinging back (continuous at the
    turning point, where it is ``x_break - A``). A plain ``bound - |F_req|`` only grazes zero at
    the turning point when the violation is small, and a step can jump over it; this one is
    negative at the turning point whenever the orbit leaves the stick bound. +1 when the orbit
    never reaches ``x_break``.
    """
    if c[SPRINGS_] == 0:
        return 1.0
    amplitude, x_break = stick_orbit(code, c, y)
    if amplitude <= x_break:
        return 1.0
    x2 = y[X2]
    if x2 * y[V2] >= 0:
        return x_break - abs(x2)
    return x_break - 2.0 * amplitude + abs(x2)


def initial_state(v: float) -> np.ndarray:
    """Seed eq. 6: ``x1 = x2 = 0``, ``x1dot = v``, ``x2dot = 0``, no work done.

    Parameters
    ----------
    v : float
        The impact speed, m/s.

    Returns
    -------
    numpy.ndarray
        The state ``(x1, x2, x1dot, x2dot, W)``, shape (5,): displacements in m, velocities in
        m/s, the contact work in J.

    Examples
    --------
    >>> from phaseimpact.model import initial_state
    >>> initial_state(1.0)
    array([0., 0., 1., 0., 0.])
    """
    return np.array([0.0, 0.0, float(v), 0.0, 0.0])


def jacobian(y, params: Parameters, law, mode: int = 1) -> np.ndarray:
    """Exact Jacobian of the mechanical right-hand side ``(x1, x2, x1dot, x2dot)``, shape (4, 4).

    Parameters
    ----------
    y : array_like
        The state ``(x1, x2, x1dot, x2dot, ...)`` (m, m/s); components past the fourth (the work
        ``W``) are not read.
    params : Parameters
        The model's parameters.
    law : ContactLaw or str
        The law, or a registered law's name.
    mode : int
        The contact's mode: ``+1``/``-1`` slipping (every law but ``paper`` runs in ``+1``),
        ``STUCK`` (0) for the stuck pair, ``PLAIN`` (2) for the sign read literally.

    Returns
    -------
    numpy.ndarray
        Shape (4, 4): ``J[i, j] = d(dy_i/dt)/dy_j`` with ``y = (x1, x2, x1dot, x2dot)`` (rows 2
        and 3 in 1/s^2 and 1/s); the target's row is zero on a rigid target.

    Raises
    ------
    ValueError
        For the ``infinite`` target, whose load-point equation would need the law's second partials.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.model import jacobian
    >>> p = seed_parameters(v=1.0, kappa=1e9, target="rigid")
    >>> J = jacobian([1e-5, 0.0, 0.5, 0.0], p, "hunt-crossley")
    >>> J.shape
    (4, 4)
    >>> print(f"dx1''/dx1 = {J[2, 0]:.4g} 1/s^2, dx1''/dx1dot = {J[2, 2]:.4g} 1/s")
    dx1''/dx1 = -4.013e+08 1/s^2, dx1''/dx1dot = -120.2 1/s
    >>> J[3].tolist()  # a rigid target does not move
    [0.0, 0.0, 0.0, 0.0]
    """
    if params.target == "infinite":
        raise ValueError("target = 'infinite' has no Jacobian here; allowed: plate, rigid, free (the infinite "
                         "plate's load-point equation needs the law's second partials)")
    law = as_law(law)
    c = pack(params, law)
    y = np.asarray(y, dtype=float)
    J = np.zeros((4, 4))
    J[0, 2] = J[1, 3] = 1.0
    spring_rate = c[KB_] + 3.0 * c[KM_] * y[X2] ** 2
    if c[RIGID_] > 0 and mode == STUCK:
        return J
    if mode == STUCK:
        J[2, 1] = J[3, 1] = -spring_rate / (c[M1_] + c[M2_])
        return J
    P_delta, P_rate = partials_of(law.code, c, y[X1] - y[X2], y[V1] - y[V2], mode)
    dP = np.array([P_delta, -P_delta, P_rate, -P_rate])
    J[2] = -dP / c[M1_]
    if c[RIGID_] == 0:
        J[3] = dP / c[M2_]
        J[3, 1] -= spring_rate / c[M2_]
    return J
