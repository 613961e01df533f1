"""The hybrid (event-driven) structure shared by every exact integrator.

Each trajectory carries a *mode* (see :mod:`phaseimpact.model`): for ``paper`` the sign of
``deltadot`` while slipping and 0 while stuck; for the other laws always 1. Between events the
right-hand side is smooth; integrators locate the zeros of the event functions below, then
call :func:`transition` to record the event, update the mode and correct the state.

Event functions (columns of :func:`event_values`), with the direction that fires them:

==================  =========  ==============================================================
``DELTA``           both       ``delta``: contact onset (up), separation (down); always restarts
``DELTADOT``        both       ``deltadot``: extreme indentation; for ``paper`` stick or reversal
``FORCE_RATE``      down       ``dP/dt``: a maximum of the contact force (recorded only)
``STICK_MARGIN``    down       ``K |delta|^alpha - |F_req|`` while stuck: the stick breaks
``ENERGY_MARGIN``   down       ``2 E0 - E``: energy has doubled, the run is a runaway
``REACH``           up         ``-(x1 + A)``: a receding projectile has left the reach ``A`` of
                               the plate, no further contact is possible
==================  =========  ==============================================================
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import V1, V2, X1, X2, Coefficients, ContactLaw, _power, contact_force, energy, rhs, stick_force

DELTA, DELTADOT, FORCE_RATE, STICK_MARGIN, ENERGY_MARGIN, REACH = range(6)
N_EVENTS = 6
#: +1: fires on an increase through zero, -1: on a decrease, 0: both.
DIRECTIONS = np.array([0, 0, -1, -1, -1, 1])
#: Energy growth (relative to the initial energy) that classifies a run as a runaway.
RUNAWAY_ENERGY_FACTOR = 2.0


def target_reach(y, c: Coefficients):
    """Largest displacement ``A`` the target can reach with its current energy, m."""
    x2, v2 = y[..., X2], y[..., V2]
    target_energy = 0.5 * c.M2 * v2 * v2 + (0.5 * c.Kb + 0.25 * c.Km * x2 * x2) * x2 * x2
    root = np.sqrt(c.Kb * c.Kb + 4.0 * c.Km * target_energy)
    with np.errstate(divide="ignore", invalid="ignore"):
        reach = np.sqrt(4.0 * target_energy / (c.Kb + root))
    return np.where(c.Kb + root > 0, reach, np.abs(x2))


def stick_orbit(y, c: Coefficients):
    """Amplitude ``A`` of the stuck pair's orbit and the ``|x2|`` at which the stick breaks.

    While stuck the pair oscillates on the target springs with conserved energy
    ``M v^2/2 + Kb x2^2/2 + Km x2^4/4`` (``M = M1 + M2``); the force it needs,
    ``F_req = M1/M S(x2)``, grows with ``|x2|`` and reaches the bound ``K |delta|^alpha``
    at ``x_break`` (the real root of ``Km x^3 + Kb x = M/M1 * bound``). REFERENCE §3.
    """
    M = c.M1 + c.M2
    x2, v = y[..., X2], y[..., V2]
    orbit_energy = 0.5 * M * v * v + (0.5 * c.Kb + 0.25 * c.Km * x2 * x2) * x2 * x2
    root = np.sqrt(c.Kb * c.Kb + 4.0 * c.Km * orbit_energy)
    with np.errstate(divide="ignore", invalid="ignore"):
        amplitude = np.sqrt(4.0 * orbit_energy / (c.Kb + root))
        force = M / c.M1 * c.K * _power(np.abs(y[..., X1] - x2), c.alpha)
        # x^3 + 3p x = 2q with p = Kb/(3 Km), q = force/(2 Km): x = 2 sqrt(p) sinh(asinh(q/p^1.5)/3)
        p = c.Kb / (3.0 * c.Km)
        cubic = 2.0 * np.sqrt(p) * np.sinh(np.arcsinh(force / (2.0 * c.Km) / p**1.5) / 3.0)
        x_break = np.where(c.Km > 0, cubic, force / c.Kb)
    return amplitude, x_break


def stick_margin(y, c: Coefficients) -> float:
    """Relative margin ``(x_break - A) / x_break`` of a stick entered at ``y``; >= 0: it never breaks."""
    if c.target != "plate":
        return 1.0
    amplitude, x_break = stick_orbit(y, c)
    return float((x_break - amplitude) / x_break) if x_break > 0 else -1.0


def event_values(y, c: Coefficients, law: ContactLaw, mode, energy_limit, f=None):
    """All event functions at ``y``, shape ``(..., N_EVENTS)``; inactive ones are held at +-1."""
    if f is None:
        f = rhs(y, c, law, mode)
    delta = y[..., X1] - y[..., X2]
    deltadot = y[..., V1] - y[..., V2]
    accel = f[..., V1] - f[..., V2]
    mode = np.asarray(mode)
    g = np.empty(np.shape(delta) + (N_EVENTS,))
    g[..., DELTA] = delta
    g[..., ENERGY_MARGIN] = energy_limit - energy(y, c, law)
    g[..., REACH] = -1.0
    g[..., STICK_MARGIN] = 1.0
    ad = np.abs(delta)
    hertz = _power(ad, c.alpha)
    with np.errstate(divide="ignore", invalid="ignore"):
        hertz_rate = np.where(ad > 0, c.alpha * hertz / ad, 0.0) * np.sign(delta) * deltadot
    damped = c.K + c.kappa * deltadot
    rate = c.kappa * accel * hertz + damped * hertz_rate
    if law.is_filippov:
        stuck = mode == 0
        g[..., DELTADOT] = np.where(stuck, 1.0, deltadot)
        spring_rate = (c.Kb + 3 * c.Km * y[..., X2] ** 2) * y[..., V2] * c.M1 / (c.M1 + c.M2)
        g[..., FORCE_RATE] = np.where(stuck, spring_rate, mode * rate)
        g[..., STICK_MARGIN] = np.where(stuck, _stick_break_distance(y, c), 1.0)
        return g
    g[..., DELTADOT] = deltadot
    if law.bilateral:
        g[..., FORCE_RATE] = rate
        return g
    touching = delta > 0
    if law.clamp:
        touching &= contact_force(y, c, law) > 0
    g[..., FORCE_RATE] = np.where(touching, rate, -1.0)
    if c.target == "plate":
        g[..., REACH] = np.where(delta < 0, -(y[..., X1] + target_reach(y, c)), -1.0)
    return g


def _stick_break_distance(y, c: Coefficients):
    """Stick-break event function, monotone along each half-swing of the stuck pair, m.

    ``x_break - |x2|`` swinging out and ``x_break - 2A + |x2|`` swinging back (continuous at the
    turning point, where it equals ``x_break - A``). A plain ``bound - |F_req|`` grazes zero at
    the turning point when the violation is small, and a step can jump over it; this one has
    its sign at the turning point guaranteed negative whenever the orbit leaves the stick bound.
    Held at +1 when the orbit never reaches ``x_break`` (``A <= x_break``).
    """
    if c.target != "plate":
        return np.ones(np.shape(y[..., X2]))
    amplitude, x_break = stick_orbit(y, c)
    x2 = y[..., X2]
    swing_out = x2 * y[..., V2] >= 0
    distance = np.where(swing_out, x_break - np.abs(x2), x_break - 2 * amplitude + np.abs(x2))
    return np.where(amplitude > x_break, distance, 1.0)


def departure_sign(column: int, y, mode) -> float:
    """The sign event ``column`` takes just after a run restarts on its zero at ``y``.

    Integrators start the new phase with that sign (times a tiny number) in place of the zero,
    so a return to zero within the first step is still seen as a crossing.
    """
    if column == DELTA:
        sign = np.sign(y[V1] - y[V2])
    elif column == DELTADOT:
        sign = mode
    else:
        sign = 1.0
    return float(sign) or 1.0


def crossed(g_old, g_new):
    """Which events fire between two evaluations (strict start, so a restart at a zero is quiet)."""
    up = (g_old < 0) & (g_new >= 0)
    down = (g_old > 0) & (g_new <= 0)
    return np.where(DIRECTIONS > 0, up, np.where(DIRECTIONS < 0, down, up | down))


@dataclass(frozen=True)
class Event:
    """Something that happened along a trajectory.

    Attributes
    ----------
    kind : str
        ``contact``, ``separation``, ``reversal`` (extreme indentation, or a slip reversal for
        ``paper``), ``stick``, ``slip``, ``force-peak``, ``settled`` or ``runaway``.
    t : float
        Time, s.
    state : ndarray, shape (5,)
        ``(x1, x2, x1dot, x2dot, W)`` at ``t`` (after any correction the event applies).
    force : float
        Contact force at ``t``, N.
    mode : int
        Mode after the event (``paper``: +-1 slipping, 0 stuck).
    """

    kind: str
    t: float
    state: np.ndarray
    force: float
    mode: int

    @property
    def delta(self) -> float:
        return float(self.state[X1] - self.state[X2])

    @property
    def deltadot(self) -> float:
        return float(self.state[V1] - self.state[V2])


@dataclass(frozen=True)
class Transition:
    """What an event does: the event to record, the new mode and state, and whether to stop."""

    event: Event | None
    mode: int
    state: np.ndarray
    restart: bool
    stop: str | None = None  # "settled" or "runaway"


def transition(column: int, t: float, y: np.ndarray, mode: int, c: Coefficients,
               law: ContactLaw, stop_when_settled: bool) -> Transition:
    """Apply event ``column`` found at ``(t, y)`` in ``mode`` (scalar coefficients)."""
    y = np.array(y, dtype=float)
    kind, restart, stop = None, False, None
    if column == DELTA:
        y[X1] = y[X2]  # the event is delta = 0; remove the root finder's residue
        deltadot = y[V1] - y[V2]
        kind, restart = ("contact" if deltadot > 0 else "separation"), True
        if kind == "separation" and law.is_unilateral and c.target != "plate" and stop_when_settled:
            stop = "settled"  # two free bodies (or a wall) never meet again once apart
    elif column == DELTADOT:
        kind = "reversal"
        if law.is_filippov:
            restart = True
            required, bound = float(stick_force(y, c)), c.K * abs(y[X1] - y[X2]) ** c.alpha
            if abs(required) <= bound:
                common = (c.M1 * y[V1] + c.M2 * y[V2]) / (c.M1 + c.M2)
                y[V1] = y[V2] = 0.0 if c.target == "rigid" else common
                kind, mode = "stick", 0
                if stop_when_settled and stick_margin(y, c) >= 0:
                    stop = "settled"
            else:
                new = int(np.sign(required))
                mode = -mode if new in (0, mode) else new
    elif column == STICK_MARGIN:
        kind, restart = "slip", True
        mode = int(np.sign(stick_force(y, c))) or 1
    elif column == FORCE_RATE:
        kind = "force-peak"
    elif column == ENERGY_MARGIN:
        kind, stop = "runaway", "runaway"
    elif column == REACH:
        kind = "settled"
        stop = "settled" if stop_when_settled else None
    force = float(contact_force(y, c, law, mode))
    return Transition(Event(kind, t, y.copy(), force, mode), mode, y, restart or stop is not None, stop)


def initial_mode(law: ContactLaw, y, c: Coefficients) -> int:
    """Mode of a run starting at ``y``: the sign of ``deltadot``, or stuck (``paper``) if the
    relative velocity is zero and the stick bound holds (seed eq. 6 gives ``+1``)."""
    deltadot = y[V1] - y[V2]
    if deltadot != 0 or not law.is_filippov:
        return 1 if deltadot >= 0 or not law.is_filippov else -1
    required = float(stick_force(y, c))
    if abs(required) <= c.K * abs(y[X1] - y[X2]) ** c.alpha:
        return 0
    return int(np.sign(required)) or 1
