"""An independent reference for the compiled driver, written from the physics (docs/physics.md
§3-§5, REFERENCE §1, §3, §5): scipy's ``solve_ivp`` with its own equations of motion, event
functions and restart logic.

It shares exactly one thing with the engine: the law's force function
:func:`phaseimpact.model.forms.contact_force` (the law under test). Everything else (the plate,
the stuck pair, the event functions, the force rate, the stick/slip decisions, the energy, the
settling rules, tolerances and horizon) is written here from the physics, so that a bug in the
engine's event table or transitions shows up as a disagreement instead of being copied. Even the
law's flags are read off the force function itself (:class:`_Case`), not from the registry.

Not a production path (DESIGN principle 3): ``check-law`` (:mod:`phaseimpact.checks`), the tests
and the benchmarks use it to check the engine, and :func:`compare` is the one comparison of an
engine run with an oracle run. A run can be given a budget (``max_nfev`` right-hand side calls,
``seconds`` of wall time): past it the run raises :class:`BudgetExceeded`, so that a law whose
integration grinds (a force that jumps, or overflows beyond the points anyone sampled) gets a
verdict instead of a wait.

The state
---------
Integrated in relative coordinates ``z = (delta, x2, deltadot, x2dot, W)`` (reported as the
physical ``(x1, x2, x1dot, x2dot, W)``): the relative motion has its own error control, so a slip
whose relative speed is 1e-12 of the bodies' speeds keeps its sign, and a stuck pair keeps
``delta`` and ``deltadot = 0`` exactly. With ``P`` the contact force, ``S(x2) = Kb x2 + Km x2^3``
the plate springs (none for a free target; a rigid target is held at ``x2 = 0``),
``M = M1 + M2`` and ``F_req = M1/M S(x2)`` the force that keeps the projectile with the target::

    delta'' = -P/M1 - (P - S)/M2 = M/(M1 M2) (F_req - P)        (rigid: -P/M1)
    x2''    = (P - S)/M2,        W' = P deltadot

Phases and events
-----------------
Each phase is one ``solve_ivp`` call, ended by a terminal event or the horizon; its recorded
(non-terminal) events are kept when they fall strictly after the phase's start.

- **contact** (the force acts; mode ``+1``/``-1`` is the sign factor of ``paper``, ``+1`` for
  every other law): ``delta = 0`` ends it (contact / separation, logged); ``deltadot = 0`` is a
  recorded extremum ("reversal") **in both directions** for laws without stick, and ends the
  phase for a Filippov law (below); ``dP/dt = 0`` from above is a recorded "force-peak" (``dP/dt``
  from central differences of the force function's partials, chained with this module's
  ``delta''``); an energy grown past its limit ends the run ("runaway": twice the initial energy
  for a Filippov law that also acts in tension, ``paper`` printed; a 100-fold guard otherwise).
- **flight** (a unilateral law with ``delta < 0``): ``delta = 0`` from below is a contact;
  ``deltadot = 0`` is a recorded extremum (both directions); a receding projectile beyond the
  plate's reach (``x1 < -A``, ``A`` the largest ``|x2|`` the plate's energy allows) is "settled".
- **stuck** (Filippov laws): the pair moves as one mass on the springs, ``delta`` frozen. Each
  stuck phase runs to the pair's next turning point (``x2dot = 0``). Over such a stretch the
  stick margin ``g = K|delta|^alpha - |F_req|`` (the bound read from the force function at
  ``deltadot = 0``) is smallest at one of its ends, so the stick broke in the stretch exactly
  when ``g < 0`` at its end; the break ("slip") is then located by bisection on the dense output,
  on the violated side, and the slip goes in the direction of ``F_req``. A stick that holds at a
  turning point where ``x2dot`` goes from + to - is a "force-peak" of the stuck force.

Stick/slip (REFERENCE §3, §5): when a slip's ``deltadot`` reaches 0, the pair sticks if
``|F_req| <= K |delta|^alpha`` (velocities set to the common, momentum-conserving one). Else the
motion goes on in the direction of ``F_req``: a "reversal" when that is the other direction, an
unlogged continuation when it is the same (a graze at rounding level). A stick is permanent (the
run is "settled") when the pair's turning point ``A`` (from its energy) keeps
``M1/M S(A) <= K delta*^alpha``. A unilateral law separating from a free or rigid target is
settled at once (nothing brings the bodies together again).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from phaseimpact.model.forms import contact_force
from phaseimpact.model.laws import ContactLaw

__all__ = ["OracleRun", "oracle", "compare", "Agreement", "Budget", "BudgetExceeded"]

# Relative state z = (delta, x2, deltadot, x2dot, W).
D, X2, DD, V2, W = range(5)
#: Horizon when none is given, in the case's slow time (the plate period, else the contact time).
HORIZON_PERIODS = 1e4
RUNAWAY_FACTOR = 2.0  # a Filippov law acting in tension (paper printed): energy doubled
GUARD_FACTOR = 100.0  # every other law: a guard against numerical trouble only
# Gauss-Legendre nodes for the contact potential of the elastic term (the energy guard only).
_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)


def _as_law(law) -> ContactLaw:
    return law if isinstance(law, ContactLaw) else ContactLaw(law)


@dataclass
class OracleRun:
    """What the oracle found: the event log (kinds, times, physical states ``(x1, x2, x1dot,
    x2dot, W)``, forces), the final state, the largest contact force, why it stopped."""

    kinds: list
    times: list
    states: list
    forces: list
    final_state: np.ndarray
    t_stop: float
    max_force: float
    reason: str
    nfev: int

    def of(self, kind):
        return [(t, s) for k, t, s in zip(self.kinds, self.times, self.states, strict=True) if k == kind]


class _Case:
    """The equations of motion of one case under one law, from the physics."""

    def __init__(self, params, law):
        law = _as_law(law)
        self.code = law.code
        self.M1, self.M2 = float(params.M1), float(params.M2)
        self.M = self.M1 + self.M2
        self.K, self.alpha = float(params.K), float(params.alpha)
        self.damping = float(law.kappa(params))
        self.rigid = params.target == "rigid"
        plate = params.target == "plate"
        self.Kb = float(params.Kb) if plate else 0.0
        self.Km = float(params.Km) if plate else 0.0
        self.springs = plate and (self.Kb > 0 or self.Km > 0)
        v = float(params.v)
        m = self.M1 if self.rigid else self.M1 * self.M2 / self.M
        a = self.alpha
        # scales: the undamped indentation of the reduced mass and its contact time
        self.length = ((a + 1) * m * v * v / (2 * self.K)) ** (1 / (a + 1))
        self.contact_time = 3.0 * self.length / v
        period = 2 * math.pi * math.sqrt(self.M2 / self.Kb) if plate and self.Kb > 0 else math.inf
        self.slow = period if math.isfinite(period) else self.contact_time
        self.scale = np.array([self.length, self.length, v, v, 0.5 * self.M1 * v * v])
        # the law's flags, read off its force function
        probe, speed = self.length, 0.3 * v
        self.unilateral = all(self.force(-probe, s, mode) == 0.0 for s in (-speed, 0.0, speed) for mode in (1, -1))
        self.filippov = self.force(probe, speed, 1) != self.force(probe, speed, -1)
        self.energy_factor = RUNAWAY_FACTOR if self.filippov and not self.unilateral else GUARD_FACTOR

    # --- the law (the one thing shared with the engine) and what follows from it
    def force(self, delta, deltadot, mode):
        return contact_force(self.code, delta, deltadot, mode, self.K, self.damping, self.alpha)

    def bound(self, delta):
        """The stick bound ``K |delta|^alpha``: the elastic force's magnitude at ``deltadot = 0``."""
        return abs(self.force(delta, 0.0, 1))

    def potential(self, delta):
        """``int_0^delta P(s, 0) ds`` for a law whose elastic term is conservative (the energy
        guard only); 0 for a Filippov law (friction-like, no potential)."""
        if self.filippov or delta == 0.0:
            return 0.0
        s = 0.5 * delta * (_GL_X + 1.0)
        return 0.5 * delta * float(sum(w * self.force(x, 0.0, 1) for w, x in zip(_GL_W, s, strict=True)))

    # --- the plate
    def spring(self, x2):
        return (self.Kb + self.Km * x2 * x2) * x2

    def spring_energy(self, x2):
        return (0.5 * self.Kb + 0.25 * self.Km * x2 * x2) * x2 * x2

    def required(self, x2):
        """``F_req``: the force that keeps the projectile with the target while stuck."""
        return self.M1 / self.M * self.spring(x2)

    def amplitude(self, energy):
        """The ``X >= 0`` with ``Kb X^2/2 + Km X^4/4 = energy``."""
        if energy <= 0:
            return 0.0
        if self.Km > 0:
            return math.sqrt(2.0 * energy / (0.5 * self.Kb + 0.5 * math.sqrt(self.Kb**2 + 4.0 * self.Km * energy)))
        return math.sqrt(2.0 * energy / self.Kb) if self.Kb > 0 else math.inf

    def energy(self, z):
        v1 = z[DD] + z[V2]
        return (0.5 * self.M1 * v1 * v1 + 0.5 * self.M2 * z[V2] ** 2 + self.spring_energy(z[X2])
                + self.potential(z[D]))

    # --- equations of motion
    def rates(self, z, mode):
        """``(dz/dt, P)`` while the force acts (or in flight, where it is 0)."""
        delta, x2, dd, v2 = z[D], z[X2], z[DD], z[V2]
        P = self.force(delta, dd, mode)
        if self.rigid:
            return np.array([dd, 0.0, -P / self.M1, 0.0, P * dd]), P
        acc_rel = self.M / (self.M1 * self.M2) * (self.required(x2) - P)
        return np.array([dd, v2, acc_rel, (P - self.spring(x2)) / self.M2, P * dd]), P

    def stuck_rates(self, z):
        acc = 0.0 if self.rigid else -self.spring(z[X2]) / self.M
        return np.array([0.0, z[V2], 0.0, acc, 0.0])

    def force_rate(self, z, mode):
        """``dP/dt`` along the motion: central differences of the force function's partials,
        chained with ``delta'``, ``delta''``."""
        delta, dd = z[D], z[DD]
        rates, _ = self.rates(z, mode)
        hd = 1e-5 * max(abs(delta), 1e-9 * self.length)
        hr = 1e-5 * max(abs(dd), 1e-6 * self.scale[DD])
        p_delta = (self.force(delta + hd, dd, mode) - self.force(delta - hd, dd, mode)) / (2 * hd)
        p_rate = (self.force(delta, dd + hr, mode) - self.force(delta, dd - hr, mode)) / (2 * hr)
        return p_delta * dd + p_rate * rates[DD]

    def physical(self, z):
        return np.array([z[D] + z[X2], z[X2], z[DD] + z[V2], z[V2], z[W]])

    def relative(self, y):
        return np.array([y[0] - y[1], y[1], y[2] - y[3], y[3], y[4]])

    def common_velocity(self, z):
        """Stick the relative motion: ``deltadot = 0`` with the pair's momentum kept."""
        z = z.copy()
        if not self.rigid:
            z[V2] = z[V2] + self.M1 / self.M * z[DD]
        z[DD] = 0.0
        return z

    def permanent(self, z):
        """Whether a stick entered at ``z`` holds for ever: the pair's turning point keeps the bound."""
        if not self.springs:
            return True
        A = self.amplitude(0.5 * self.M * z[V2] ** 2 + self.spring_energy(z[X2]))
        return self.required(A) <= self.bound(z[D])

    def slip_mode(self, z):
        """Mode after ``deltadot = 0`` where the stick cannot hold: the direction of ``F_req``."""
        return 1 if self.required(z[X2]) > 0 else -1

    def holds(self, z):
        return abs(self.required(z[X2])) <= self.bound(z[D])


def _event(fn, terminal, direction, name):
    fn.terminal = terminal
    fn.direction = direction
    fn.name = name
    return fn


def _side(z):
    return 1 if z[D] > 0 else (-1 if z[D] < 0 else (1 if z[DD] > 0 else -1))


def _break_point(case, sol, t_end, delta):
    """The first time the stick margin is negative on the stretch ``sol`` (which ends at
    ``t_end`` with a negative margin), on its violated side, by bisection on the dense output."""
    bound = case.bound(delta)

    def margin(t):
        return bound - abs(case.required(sol.sol(t)[X2]))

    ts = sol.t
    k = len(ts) - 1
    while k > 0 and margin(ts[k]) < 0:
        k -= 1
    a, b = ts[k], t_end
    if margin(a) < 0:  # violated from the start: cannot happen (the stick held there)
        return a
    while b - a > 4 * np.finfo(float).eps * max(abs(a), abs(b)):
        mid = 0.5 * (a + b)
        if mid <= a or mid >= b:
            break
        if margin(mid) < 0:
            b = mid
        else:
            a = mid
    return b


class BudgetExceeded(RuntimeError):
    """A run went past its budget of right-hand side calls or wall time (its message says which)."""


class Budget:
    """A budget of right-hand side calls and wall time for scipy runs: :meth:`spend` is called
    once per evaluation and raises :class:`BudgetExceeded` past either limit (None: no limit).
    ``solve_ivp`` has no step limit of its own."""

    def __init__(self, max_nfev=None, seconds=None):
        self.max_nfev = max_nfev
        self.seconds = seconds
        self.nfev = 0
        self._deadline = math.inf if seconds is None else time.monotonic() + seconds

    def spend(self):
        self.nfev += 1
        if self.max_nfev is not None and self.nfev > self.max_nfev:
            raise BudgetExceeded(f"no result within {self.max_nfev} right-hand side calls")
        if time.monotonic() > self._deadline:
            raise BudgetExceeded(f"no result within {self.seconds:g} s ({self.nfev} right-hand side calls)")


def oracle(params, law, t_end=None, *, rtol=1e-12, method="DOP853", settle=True, stop_on=None,
           initial=None, max_phases=100_000, max_nfev=None, seconds=None) -> OracleRun:
    """Integrate one impact of ``params`` under ``law`` from seed eq. 6 (or ``initial``, 4 numbers)
    to ``t_end`` (default: ``HORIZON_PERIODS`` slow times) or until the outcome settles
    (``settle``) or ``stop_on`` (a kind, or ``(kind, count)``) is logged. A step that scipy
    cannot take (a force that is not finite) ends the run with the reason ``"failed"``; past
    ``max_nfev`` right-hand side calls or ``seconds`` of wall time it raises
    :class:`BudgetExceeded`."""
    budget = Budget(max_nfev, seconds)
    case = _Case(params, law)
    horizon = HORIZON_PERIODS * case.slow if t_end is None else float(t_end)
    atol = rtol * case.scale
    y0 = np.array([0.0, 0.0, float(params.v), 0.0, 0.0])
    if initial is not None:
        y0[:4] = initial
    if case.rigid:
        y0[1] = y0[3] = 0.0
    z = case.relative(y0)
    t = 0.0
    limit = case.energy_factor * case.energy(z)
    limit = limit if limit > 0 else math.inf
    stop_kind, stop_count = (stop_on, 1) if isinstance(stop_on, str) else (stop_on or (None, 0))

    mode = _initial_mode(case, z)
    log = []  # (t, kind, z, force)
    max_force = case.force(z[D], z[DD], mode) if mode != "stuck" else case.required(z[X2])
    if z[D] == 0 and z[DD] > 0:
        log.append((0.0, "contact", z.copy(), max_force))
    nfev = 0
    reason = "horizon"

    def force_at(zz, m):
        return case.required(zz[X2]) if m == "stuck" else case.force(zz[D], zz[DD], m)

    def asked():
        return stop_kind is not None and sum(1 for e in log if e[1] == stop_kind) >= stop_count

    for _ in range(max_phases):
        if t >= horizon or reason != "horizon":
            break
        t0 = t
        fun, events, turn_dir = _phase(case, z, mode, limit, settle, budget)
        with np.errstate(over="ignore", invalid="ignore"):  # trial steps of a runaway overflow
            sol = solve_ivp(fun, (t, horizon), z, method=method, rtol=rtol, atol=atol,
                            events=[e for e, _ in events], dense_output=mode == "stuck")
        nfev += sol.nfev
        if sol.status == -1:  # scipy could not take a step: nothing later would be the law's motion
            t, z, reason = float(sol.t[-1]), sol.y[:, -1].copy(), "failed"
            break
        found = []  # (t, kind, z, terminal)
        for (ev, tag), ts, zs in zip(events, sol.t_events, sol.y_events, strict=True):
            for t_ev, z_ev in zip(ts, zs, strict=True):
                if t_ev > t0:
                    found.append((t_ev, tag, z_ev.copy(), ev.terminal))
        for i in range(sol.y.shape[1]):
            max_force = max(max_force, force_at(sol.y[:, i], mode))
        t_last, z_last = float(sol.t[-1]), sol.y[:, -1].copy()
        found.sort(key=lambda e: e[0])
        terminal = next((e for e in found if e[3] and sol.status == 1 and e[0] == t_last), None)
        recorded = [e for e in found if not e[3] and (terminal is None or e[0] <= terminal[0])]
        if mode == "stuck":
            t, z, mode, max_force = _end_stuck(case, sol, z, t_last, z_last, terminal is not None and turn_dir < 0,
                                               log, max_force)
            if asked():
                reason = "asked"
            continue
        stopped = False
        for t_ev, tag, z_ev, _ in recorded:
            P = case.force(z_ev[D], z_ev[DD], mode)
            if tag == "force-peak" and P == 0.0:
                continue
            log.append((t_ev, tag, z_ev, P))
            max_force = max(max_force, P)
            if asked():
                t, z, reason, stopped = t_ev, z_ev, "asked", True
                break
        if stopped:
            break
        t, z = t_last, z_last
        if terminal is None:
            continue  # the horizon
        z, mode, max_force, reason = _at_terminal(case, terminal[1], t, z, mode, log, max_force, settle)
        if reason == "horizon" and asked():
            reason = "asked"
    log.sort(key=lambda e: e[0])
    return OracleRun([e[1] for e in log], [float(e[0]) for e in log], [case.physical(e[2]) for e in log],
                     [float(e[3]) for e in log], case.physical(z), float(t), float(max_force), reason, nfev)


def _initial_mode(case, z):
    """The mode at the start: +1/-1 (sign factor while slipping; +1 for laws without stick), or
    ``"stuck"``."""
    if case.filippov and z[DD] == 0 and case.holds(z):
        return "stuck"
    if case.filippov:
        return 1 if z[DD] > 0 else (-1 if z[DD] < 0 else case.slip_mode(z))
    return 1


def _phase(case, z, mode, limit, settle, budget):
    """One phase of :func:`oracle` from ``z`` in ``mode``: its right-hand side for scipy, its events
    ``[(event, kind or action tag)]`` and, while stuck, the direction of the turning point it looks
    for (None otherwise)."""
    flight = mode != "stuck" and case.unilateral and _side(z) < 0
    events = []
    turn_dir = None
    if mode == "stuck":
        def fun(_t, zz):
            budget.spend()
            return case.stuck_rates(zz)
        # the pair's next turning point; from a turning point, the next one on the other side
        # (without springs the pair moves on uniformly and nothing pulls it apart)
        going = z[V2] if z[V2] != 0 else -case.spring(z[X2])
        turn_dir = -1 if going > 0 else 1
        if case.springs:
            events.append((_event(lambda _t, zz: zz[V2], True, turn_dir, "turn"), "turn"))
        return fun, events, turn_dir
    m = mode

    def fun(_t, zz, m=m):
        budget.spend()
        return case.rates(zz, m)[0]

    side = _side(z)
    events.append((_event(lambda _t, zz: zz[D], True, -side, "delta"), "delta"))
    if case.filippov and not flight:
        events.append((_event(lambda _t, zz: zz[DD], True, -m, "deltadot"), "deltadot"))
    else:
        events.append((_event(lambda _t, zz: zz[DD], False, 0, "reversal"), "reversal"))
    if not flight:
        def rate(_t, zz, m=m):
            return case.force_rate(zz, m) if case.force(zz[D], zz[DD], m) != 0.0 else -1.0
        events.append((_event(rate, False, -1, "force-peak"), "force-peak"))
        if math.isfinite(limit):
            events.append((_event(lambda _t, zz: limit - case.energy(zz), True, -1, "runaway"), "runaway"))
    elif case.springs and z[DD] + z[V2] < 0:
        def reach(_t, zz):
            A = case.amplitude(0.5 * case.M2 * zz[V2] ** 2 + case.spring_energy(zz[X2]))
            return -(zz[D] + zz[X2] + A)
        events.append((_event(reach, settle, 1, "settled"), "settled"))
    return fun, events, turn_dir


def _end_stuck(case, sol, z, t_last, z_last, peaked, log, max_force):
    """The end of a stuck stretch from ``z`` (scipy's ``sol``, to ``t_last, z_last``): did the stick
    break in it? (its margin is smallest at its end) ``peaked``: it ended at the pair's turning
    point towards the target. Logs what happened; returns ``t, z, mode, max_force``."""
    if case.bound(z[D]) - abs(case.required(z_last[X2])) < 0:
        t_b = _break_point(case, sol, t_last, z[D])
        z_b = sol.sol(t_b)
        z_b[D], z_b[DD] = z[D], 0.0
        mode = case.slip_mode(z_b)
        log.append((t_b, "slip", z_b.copy(), case.force(z_b[D], 0.0, mode)))
        return t_b, z_b, mode, max_force
    if peaked and not case.rigid:
        log.append((t_last, "force-peak", z_last.copy(), case.required(z_last[X2])))
        max_force = max(max_force, case.required(z_last[X2]))
    return t_last, z_last, "stuck", max_force


def _at_terminal(case, tag, t, z, mode, log, max_force, settle):
    """The terminal event ``tag`` of a slipping phase at ``t, z``: logs it; returns ``z, mode,
    max_force`` after it and the run's reason (``"horizon"``: it goes on)."""
    reason = "horizon"
    if tag == "delta":
        z[D] = 0.0  # the event is delta = 0
        kind = "contact" if z[DD] > 0 else "separation"
        if case.filippov and z[DD] != 0:
            mode = 1 if z[DD] > 0 else -1
        log.append((t, kind, z.copy(), case.force(0.0, z[DD], mode)))
        if kind == "separation" and case.unilateral and not case.springs and settle:
            reason = "settled"
    elif tag == "deltadot":  # a Filippov slip comes to relative rest
        if case.holds(z):
            z = case.common_velocity(z)
            mode = "stuck"
            log.append((t, "stick", z.copy(), case.required(z[X2])))
            max_force = max(max_force, case.required(z[X2]))
            if settle and case.permanent(z):
                reason = "settled"
        else:
            new = case.slip_mode(z)
            z = case.common_velocity(z)
            if new != mode:
                mode = new
                log.append((t, "reversal", z.copy(), case.force(z[D], 0.0, mode)))
    elif tag == "runaway":
        log.append((t, "runaway", z.copy(), case.force(z[D], z[DD], mode)))
        reason = "runaway"
    elif tag == "settled":
        log.append((t, "settled", z.copy(), 0.0))
        reason = "settled"
    return z, mode, max_force, reason


@dataclass
class Agreement:
    """How an engine run and an oracle run of the same case compare (:func:`compare`):
    ``differences`` lists what disagrees beyond the tolerances (empty: they agree)."""

    differences: list
    n_events: int
    worst_time: float
    worst_force: float

    @property
    def agrees(self) -> bool:
        return not self.differences

    def detail(self) -> str:
        if self.differences:
            return "; ".join(self.differences)
        return (f"{self.n_events} events, times within {self.worst_time:.2g} s, max force relative "
                f"{self.worst_force:.2g}, same stop and final state")


def compare(run, ref: OracleRun, t_end: float) -> Agreement:
    """Compare an engine run (a :class:`~phaseimpact.Trajectory` to ``t_end``) with the oracle's
    run ``ref`` of the same case: the same event kinds in time order (events within 1e-12 s may
    swap), times within ``1e-9 t_end``, the largest force within 1e-9 relative, the same stop
    reason (the engine's ``end`` is the oracle's ``horizon``) and final state (positions within
    1e-12 m, speeds within 1e-9 m/s). Reads only the run's public fields."""
    ours = sorted(zip(np.round(run.event_t, 12), [e.kind for e in run.events], strict=True))
    theirs = sorted(zip(np.round(ref.times, 12), ref.kinds, strict=True))
    differences = []
    kinds_ours, kinds_theirs = [k for _, k in ours], [k for _, k in theirs]
    worst_time = math.inf
    if kinds_ours != kinds_theirs:
        differences.append(f"event kinds differ: engine {kinds_ours[:6]}..., oracle {kinds_theirs[:6]}...")
    else:
        worst_time = max((abs(a - b) for (a, _), (b, _) in zip(ours, theirs, strict=True)), default=0.0)
        if not worst_time <= 1e-9 * t_end:
            differences.append(f"event times differ by {worst_time:.2g} s (allowed {1e-9 * t_end:.2g})")
    worst_force = abs(run.max_force - ref.max_force) / abs(ref.max_force) if ref.max_force else abs(run.max_force)
    if not worst_force <= 1e-9:
        differences.append(f"max force {run.max_force:.10g} N, oracle {ref.max_force:.10g} (relative "
                           f"{worst_force:.2g}, allowed 1e-9)")
    if run.stop_reason != ref.reason and (run.stop_reason, ref.reason) != ("end", "horizon"):
        differences.append(f"stop reason: engine {run.stop_reason}, oracle {ref.reason}")
    positions = np.max(np.abs(np.asarray(run.final_state[:2]) - ref.final_state[:2]))
    speeds = np.max(np.abs(np.asarray(run.final_state[2:4]) - ref.final_state[2:4]))
    if not (positions <= 1e-12 and speeds <= 1e-9):
        differences.append(f"final state differs by {positions:.2g} m, {speeds:.2g} m/s (allowed 1e-12 m, 1e-9 m/s)")
    return Agreement(differences, len(ours), float(worst_time), float(worst_force))
