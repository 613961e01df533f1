"""The seed's method: classic fixed-step Runge-Kutta 4 on the plain right-hand side.

Kept for reproduction and comparison. It sees eq. 8 literally (``sgn(deltadot)``, no stick
set), so on ``paper`` it chatters across ``deltadot = 0`` with an amplitude that shrinks with
the step; contact onset and separation are found by linear interpolation between steps.
"""

from __future__ import annotations

import math

import numpy as np

from ..model import V1, V2, X1, X2, ContactLaw, coefficients, contact_force, energy, initial_state, rhs
from ..parameters import Parameters
from ._events import RUNAWAY_ENERGY_FACTOR, Event
from ._trajectory import Recorder, Save, Trajectory


def integrate_rk4(params: Parameters, law: ContactLaw, t_end: float, *, save: Save,
                  step: float = 1e-7, every: int = 1, max_steps: int = 50_000_000) -> Trajectory:
    """Integrate with ``ceil(t_end / step)`` equal RK4 steps; keep every ``every``-th state."""
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step = {step!r} is out of range; allowed: a finite number > 0")
    if not (isinstance(every, int) and every >= 1):
        raise ValueError(f"every = {every!r} is out of range; allowed: an integer >= 1")
    n = max(1, math.ceil(t_end / step - 1e-9))
    if n > max_steps:
        raise ValueError(f"step = {step!r} needs {n} steps; allowed: at most max_steps = {max_steps}")
    with np.errstate(over="ignore", invalid="ignore"):
        return _integrate(params, law, t_end, save, t_end / n, n, every)


def _integrate(params, law, t_end, save, h, n, every) -> Trajectory:
    c = coefficients(params, law)
    y = initial_state(params.v)
    energy_limit = RUNAWAY_ENERGY_FACTOR * float(energy(y, c, law))
    recorder = Recorder(c, law, save, plain=True)
    recorder.event(Event("contact", 0.0, y.copy(), 0.0, 1))
    times = save.times if save.kind == "times" else np.empty(0)
    if save.kind == "steps":
        recorder.sample(0.0, y, 1)
    next_time = int(np.searchsorted(times, 0.0, side="right"))
    for s in times[:next_time]:
        recorder.sample(s, y, 1)

    def f(state):
        return rhs(state, c, law)

    status, message = "success", f"reached t_end = {t_end:g} s"
    t, k = 0.0, 0
    for k in range(1, n + 1):
        k1 = f(y)
        k2 = f(y + 0.5 * h * k1)
        k3 = f(y + 0.5 * h * k2)
        k4 = f(y + h * k3)
        y_new = y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        t_new = k * h
        # Checked every step, before the state is accepted: eq. 8's runaway overflows within a
        # few steps, and the run must end on its last finite state.
        if not np.all(np.isfinite(y_new)):
            status, message = "non-finite", f"the state became non-finite at t = {t_new:.6g} s"
            break
        if energy(y_new, c, law) > energy_limit:
            status = "runaway"
            message = f"energy exceeded {RUNAWAY_ENERGY_FACTOR:g} x the impact energy at t = {t_new:.6g} s"
            break
        delta_old, delta_new = y[X1] - y[X2], y_new[X1] - y_new[X2]
        if (delta_old <= 0 < delta_new and k > 1) or delta_old > 0 >= delta_new:
            s = delta_old / (delta_old - delta_new)  # linear interpolation of the crossing
            state = y + s * (y_new - y)
            recorder.event(Event("contact" if delta_new > 0 else "separation", t + s * h, state,
                                 float(contact_force(state, c, law)), 1))
        recorder.extremes(y_new, None)
        while next_time < len(times) and times[next_time] <= t_new:
            s = (times[next_time] - t) / h
            recorder.sample(times[next_time], y + s * (y_new - y), _sign(y))
            next_time += 1
        y, t = y_new, t_new
        if save.kind == "steps" and k % every == 0:
            recorder.sample(t, y, _sign(y))
    return recorder.finish(params=params, t_end=t_end, t_stop=t, y=y, mode=_sign(y), settled=False,
                           status=status, message=message, nfev=4 * k, nsteps=k,
                           integrator=f"rk4[step={h:.3g}]")


def _sign(y) -> int:
    """The sign of ``deltadot``, recorded as the mode of a plain-RHS sample."""
    return int(np.sign(y[V1] - y[V2]))  # y is always finite here
