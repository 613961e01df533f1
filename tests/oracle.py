"""An independent reference for the compiled driver: scipy's ``solve_ivp`` on the same law
entries, with the same event table, phase by phase.

Not a production path (DESIGN principle 3): tests and benchmarks use it to check the engine.
Each phase is one ``solve_ivp`` call whose restart events are terminal; a restart event's
direction is set to the side it must cross next, so a phase that starts on its zero does not
fire at once. Event location, step control and dense output are scipy's own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from phaseimpact.integrate.api import _atol, scales
from phaseimpact.integrate.events import (
    DELTA,
    DELTADOT,
    ENERGY,
    EVENT_KINDS,
    FORCE_RATE,
    N_EVENTS,
    PAIR_CENTRE,
    REACH,
    STICK_BREAK,
    STOP_RUNAWAY,
    STOP_SETTLED,
    departure_sign,
    energy_limit_of,
    event_values,
    initial_mode,
    restarts,
    transition,
)
from phaseimpact.model import as_law, pack
from phaseimpact.model.rhs import energy, rhs

__all__ = ["OracleRun", "oracle"]


@dataclass
class OracleRun:
    """What the oracle found: the event log (kinds, times, states), the final state, max force."""

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


def oracle(params, law, t_end=None, *, rtol=1e-12, method="DOP853", settle=True, stop_on=None,
           initial=None, max_phases=100_000) -> OracleRun:
    law = as_law(law)
    code = law.code
    c = pack(params, law)
    s = scales(params)
    horizon = s.horizon if t_end is None else t_end
    atol = _atol(params, rtol, None)[:5]  # the physical state (x1, x2, x1dot, x2dot, W)
    y = np.array([0.0, 0.0, params.v, 0.0, 0.0])
    if initial is not None:
        y[:4] = initial
    t = 0.0
    mode = initial_mode(code, c, y)
    limit = energy_limit_of(code, c, y)
    out = np.empty(5)
    g = np.empty(N_EVENTS)
    kinds, times, states, forces = [], [], [], []
    force0 = rhs(code, c, y, mode, out)
    if y[0] == y[1] and y[2] > y[3]:
        kinds.append("contact"), times.append(0.0), states.append(y.copy()), forces.append(force0)
    max_force = force0
    nfev = 0
    reason = "horizon"
    stop_kind, stop_count = (stop_on, 1) if isinstance(stop_on, str) else (stop_on or (None, 0))
    for _ in range(max_phases):
        if t >= horizon:
            break

        def fun(_t, yy, mode=mode):
            f = np.empty(5)
            rhs(code, c, yy, mode, f)
            return f

        def column(col, mode=mode):
            def value(_t, yy):
                f = np.empty(5)
                force = rhs(code, c, yy, mode, f)
                event_values(code, c, yy, f, force, mode, limit, g)
                return g[col]
            return value

        f0 = np.empty(5)
        force0 = rhs(code, c, y, mode, f0)
        g0 = np.empty(N_EVENTS)
        event_values(code, c, y, f0, force0, mode, limit, g0)
        events = []
        for col in range(N_EVENTS):
            ev = column(col)
            ev.terminal = bool(restarts(code, col, mode, settle) or col == ENERGY)
            natural = {DELTA: 0, DELTADOT: 0, FORCE_RATE: -1, STICK_BREAK: -1, ENERGY: -1, REACH: 1,
                       PAIR_CENTRE: 0}[col]
            if natural == 0:  # the next crossing is to the other side of where the phase starts
                start = g0[col] if g0[col] != 0 else departure_sign(col, y, mode)
                natural = -1 if start > 0 else 1
            ev.direction = natural
            events.append(ev)
        with np.errstate(over="ignore", invalid="ignore"):  # trial steps of a runaway overflow
            sol = solve_ivp(fun, (t, horizon), y, method=method, rtol=rtol, atol=atol, events=events,
                            dense_output=False)
        nfev += sol.nfev
        # recorded (non-terminal) events, then the terminal one
        terminal = None
        for col in range(N_EVENTS):
            for t_ev, y_ev in zip(sol.t_events[col], sol.y_events[col], strict=True):
                if t_ev <= t:
                    continue
                if events[col].terminal:
                    if terminal is None or t_ev < terminal[0]:
                        terminal = (t_ev, y_ev.copy(), col)
                else:
                    kind = "force-peak" if col == FORCE_RATE else ("settled" if col == REACH else "reversal")
                    f = np.empty(5)
                    force = rhs(code, c, y_ev, mode, f)
                    kinds.append(kind), times.append(t_ev), states.append(y_ev.copy()), forces.append(force)
                    max_force = max(max_force, force)
        if terminal is None:
            y = sol.y[:, -1].copy()
            t = sol.t[-1]
            max_force = max(max_force, max(rhs(code, c, sol.y[:, i], mode, out) for i in range(sol.y.shape[1])))
            break
        t_ev, y_ev, col = terminal
        max_force = max(max_force, *(rhs(code, c, sol.y[:, i], mode, out) for i in range(sol.y.shape[1])))
        kind_code, mode, action = transition(code, c, col, y_ev, mode, settle)
        force = rhs(code, c, y_ev, mode, out)
        if EVENT_KINDS[kind_code] != "centre":  # a restart only, not logged
            kinds.append(EVENT_KINDS[kind_code]), times.append(t_ev), states.append(y_ev.copy()), forces.append(force)
        max_force = max(max_force, force)
        t, y = t_ev, y_ev
        if action == STOP_SETTLED:
            reason = "settled"
            break
        if action == STOP_RUNAWAY:
            reason = "runaway"
            break
        if stop_kind is not None and kinds.count(stop_kind) >= stop_count:
            reason = "asked"
            break
    # order the log in time (recorded events of a phase come before its terminal one)
    order = np.argsort(times, kind="stable")
    return OracleRun([kinds[i] for i in order], [times[i] for i in order], [states[i] for i in order],
                     [forces[i] for i in order], np.asarray(y), float(t), float(max_force), reason, nfev)


def energy_of(params, law, y) -> float:
    law = as_law(law)
    return float(energy(law.code, pack(params, law), np.asarray(y, dtype=float)))

