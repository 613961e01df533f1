"""Exact event-driven integration of one trajectory, with scipy's solvers underneath.

Between events the right-hand side is smooth, so any of scipy's ``OdeSolver`` classes
integrates it to its tolerance; at each event (located with ``brentq`` on the solver's dense
output) the run restarts from the corrected state in the new mode. For ``paper`` this resolves
stick and slip exactly instead of chattering across ``deltadot = 0``.
"""

from __future__ import annotations

import functools

import numpy as np
import scipy.integrate
from scipy.optimize import brentq

from ..model import ContactLaw, coefficients, contact_force, energy, initial_state, rhs
from ..parameters import Parameters
from ._events import (
    DELTA,
    DELTADOT,
    FORCE_RATE,
    RUNAWAY_ENERGY_FACTOR,
    Event,
    crossed,
    departure_sign,
    event_values,
    initial_mode,
    transition,
)
from ._trajectory import Recorder, Save, Trajectory, state_scale

SCIPY_METHODS = ("DOP853", "RK45", "Radau", "BDF", "LSODA")
_EPS = np.finfo(float).eps
_TINY = np.finfo(float).tiny


def integrate_exact(params: Parameters, law: ContactLaw, t_end: float, *, save: Save,
                    stop_when_settled: bool, rtol: float = 1e-10, atol: float | None = None,
                    method: str = "auto", max_steps: int = 1_000_000,
                    max_events: int = 10_000, initial=None, stop_on=()) -> Trajectory:
    """Integrate from seed eq. 6 (or ``initial``) to ``t_end``; see :func:`phaseimpact.simulate`."""
    # Trial steps of a runaway may overflow; the solver rejects them and the energy event or
    # the finiteness check ends the run with a status, so the warnings carry no information.
    with np.errstate(over="ignore", invalid="ignore"):
        return _integrate(params, law, t_end, save, stop_when_settled, rtol, atol, method,
                          max_steps, max_events, initial, _stop_counts(stop_on))


def _integrate(params, law, t_end, save, stop_when_settled, rtol, atol, method, max_steps,
               max_events, initial, stop_on) -> Trajectory:
    method = choose_method(params, law) if method == "auto" else method
    solver_class = getattr(scipy.integrate, method)
    c = coefficients(params, law)
    y = initial_state(params.v)
    impact_energy = float(energy(y, c, law))
    if initial is not None:
        y[:4] = initial
    atol_vector = (rtol if atol is None else atol) * state_scale(params, c)
    energy_limit = RUNAWAY_ENERGY_FACTOR * max(float(energy(y, c, law)), impact_energy)
    recorder = Recorder(c, law, save)
    mode, t = initial_mode(law, y, c), 0.0
    if y[0] == y[1] and y[2] > y[3]:
        recorder.event(Event("contact", 0.0, y.copy(), float(contact_force(y, c, law, mode)), mode))
    elif save.kind == "steps":
        recorder.sample(0.0, y, mode)
    if save.kind == "times":
        _sample_times(recorder, save.times, -np.inf, 0.0, lambda s: y, mode)

    nfev = nsteps = 0
    quiet = DELTA  # the event whose zero the run starts on
    status, message, settled = "success", f"reached t_end = {t_end:g} s", False
    stopped = False
    while t < t_end and status == "success" and not (settled or stopped):
        solver = solver_class(functools.partial(_phase_rhs, c=c, law=law, mode=mode), t, y, t_end,
                              rtol=rtol, atol=atol_vector)
        g_old, y_old, t_accepted = event_values(y, c, law, mode, energy_limit), y.copy(), t
        for col in {quiet, *np.flatnonzero(g_old == 0)}:
            g_old[col] = departure_sign(col, y, mode) * _TINY
        while True:
            step_message = solver.step()
            nsteps += 1
            failure = None
            if solver.status == "failed":
                failure = "step-size-collapse", f"t = {solver.t:.6g} s: {step_message}"
            elif not np.all(np.isfinite(solver.y)):
                failure = "non-finite", f"the state became non-finite at t = {solver.t:.6g} s"
            elif nsteps >= max_steps or len(recorder.events) >= max_events:
                failure = "too-many-steps", (f"stopped at t = {solver.t:.6g} s after {nsteps} steps and "
                                             f"{len(recorder.events)} events (limits {max_steps}, {max_events})")
            if failure is not None:
                (status, message), t, y = failure, t_accepted, y_old.copy()  # the last good state
                break
            t_old, t_new, y_new = solver.t_old, solver.t, solver.y
            g_new = event_values(y_new, c, law, mode, energy_limit)
            fired = np.flatnonzero(crossed(g_old, g_new))
            restart = None
            if fired.size:
                dense = solver.dense_output()
                roots = sorted((_root(dense, col, t_old, t_new, g_old[col], c, law, mode, energy_limit), col)
                               for col in fired)
                for t_root, col in roots:
                    y_root = dense(t_root)
                    if col != FORCE_RATE and (col != DELTADOT or law.is_filippov):
                        # The run restarts here: take the state from a fresh integration up to the
                        # root, not the interpolant (|delta|^alpha is only C^1 at delta = 0, and the
                        # step's stages beyond the root spoil the interpolant there).
                        y_root, extra = _integrate_to(solver_class, c, law, mode, t_old, y_old, t_root,
                                                      rtol, atol_vector)
                        nfev += extra
                    change = transition(col, t_root, y_root, mode, c, law, stop_when_settled)
                    kind = change.event.kind
                    stop_here = kind in stop_on and len(recorder.events_of(kind)) + 1 >= stop_on[kind]
                    if change.restart or stop_here:
                        if save.kind == "times":
                            _sample_times(recorder, save.times, t_old, t_root, dense, mode)
                        recorder.event(change.event)
                        restart = (t_root, change, col, stop_here)
                        break
                    recorder.event(change.event)
            if restart is not None:
                t, change, quiet, stop_here = restart
                y, mode = change.state, change.mode
                if change.stop == "runaway":
                    status = "runaway"
                    message = (f"energy exceeded {RUNAWAY_ENERGY_FACTOR:g} x the impact energy at "
                               f"t = {t:.6g} s: the contact force feeds the motion")
                elif change.stop == "settled":
                    settled = True
                    message = f"outcome settled at t = {t:.6g} s ({change.event.kind})"
                elif stop_here:
                    stopped = True
                    kind = change.event.kind
                    message = f"stopped at {kind} event {stop_on[kind]}, t = {t:.6g} s, as asked"
                break
            recorder.extremes(y_new, mode)
            _samples(recorder, save, solver.dense_output() if save.kind == "times" else None,
                     t_old, t_new, y_new, mode)
            g_old, y_old, t_accepted = g_new, y_new.copy(), t_new
            if solver.status == "finished":
                t, y = t_new, y_new.copy()
                break
        nfev += solver.nfev
    return recorder.finish(params=params, t_end=t_end, t_stop=t, y=y, mode=mode, settled=settled,
                           status=status, message=message, nfev=nfev, nsteps=nsteps,
                           integrator=f"exact[{method}, rtol={rtol:g}]")


#: Above this damping number ``a = kappa v / K`` the contact damping is stiff: the damping rate
#: exceeds the contact frequency by orders of magnitude (benchmarks/stress.py: Hunt-Crossley at
#: kappa = 1e15, v = 1 m/s takes DOP853 83k evaluations, LSODA 3.7k, for the same max force).
STIFF_DAMPING = 1e3


def choose_method(params: Parameters, law: ContactLaw) -> str:
    """The cheapest scipy method for the requested accuracy: DOP853, or LSODA for stiff damping.

    ``paper`` always gets DOP853: its stick and slip need the accurate dense output of an
    explicit high-order method (LSODA there ran into a spurious runaway at kappa = 1e15).
    """
    stiff = law.kappa(params) * params.v / params.K >= STIFF_DAMPING
    return "LSODA" if stiff and not law.is_filippov else "DOP853"


def _stop_counts(stop_on) -> dict:
    """``stop_on`` as ``{kind: n}``: stop at the n-th event of that kind (a bare kind means n = 1)."""
    counts = dict(stop_on) if isinstance(stop_on, dict) else {kind: 1 for kind in stop_on}
    for kind, n in counts.items():
        if not (isinstance(n, int) and n >= 1):
            raise ValueError(f"stop_on[{kind!r}] = {n!r} is out of range; allowed: an integer >= 1")
    return counts


def _integrate_to(solver_class, c, law, mode, t0, y0, t1, rtol, atol):
    """State at ``t1`` integrated from ``(t0, y0)`` with the phase's right-hand side."""
    if t1 <= t0:
        return np.array(y0, dtype=float), 0
    solver = solver_class(functools.partial(_phase_rhs, c=c, law=law, mode=mode), t0, y0, t1,
                          rtol=rtol, atol=atol)
    while solver.status == "running":
        solver.step()
    return (solver.y.copy() if solver.status == "finished" else np.array(y0, dtype=float)), solver.nfev


def _phase_rhs(_t, y, c, law, mode):
    return rhs(y, c, law, mode)


def _root(dense, col, t_old, t_new, g_start, c, law, mode, energy_limit) -> float:
    """Time of the first zero of event ``col`` in ``[t_old, t_new]`` on the dense output.

    A run that restarts on this event's zero (``g_start`` is then a signed tiny number) may
    leave it and come back within one step, as a brief slip does near a grazing stick break;
    the dense output is then sampled to find where the function has left zero, and the
    return is bracketed from there.
    """
    def g(s):
        return event_values(dense(s), c, law, mode, energy_limit)[col]

    expected = np.sign(g_start)
    a = t_old
    if np.sign(g(t_old)) != expected:
        grid = np.linspace(t_old, t_new, 33)[1:]
        signs = np.sign([g(s) for s in grid])
        away = np.flatnonzero(signs == expected)
        if away.size == 0:
            return t_old  # the excursion is below what the step resolves
        back = np.flatnonzero(signs[away[0]:] != expected)
        a = grid[away[0]]
        if back.size:
            t_new = grid[away[0] + back[0]]
            a = grid[away[0] + back[0] - 1]
    g_a, g_b = g(a), g(t_new)
    if np.sign(g_a) == np.sign(g_b) or g_b == 0:
        return t_new
    return brentq(g, a, t_new, xtol=4 * _EPS * max(abs(t_new), 1e-300), rtol=4 * _EPS)


def _samples(recorder: Recorder, save: Save, dense, t_old, t_new, y_new, mode) -> None:
    if save.kind == "steps":
        recorder.sample(t_new, y_new, mode)
    elif save.kind == "times":
        _sample_times(recorder, save.times, t_old, t_new, dense, mode)


def _sample_times(recorder: Recorder, times, t_old, t_new, dense, mode) -> None:
    for s in times[(times > t_old) & (times <= t_new)]:
        recorder.sample(s, dense(s), mode)
