"""The seed's fixed-step RK4 (eq. 8 read literally, no events resolved, so its chattering across
``deltadot = 0`` stays visible): an entry of its own beside :func:`.driver.run`, returning what it
returns."""

from __future__ import annotations

import math

import numpy as np

from .._jit import allocating, kernel
from .._signals import interrupted
from ..model.forms import PLAIN
from ..model.rhs import X1, X2, energy, rhs
from .driver import (
    FAILED_STOP,
    HORIZON,
    INTERRUPTED,
    NON_FINITE,
    POLL_STEPS,
    RUNAWAY_STOP,
    SAVE_STEPS,
    SUCCESS,
    TOO_MANY_STEPS,
    new_logs,
    open_logs,
    summarize,
)
from .events import CONTACT, SEPARATION, energy_limit_of
from .logs import add_sample, grow, log_event
from .phase import copy_values
from .record import (
    I_LOGGING,
    I_MODE,
    I_N_EV,
    I_N_S,
    I_NFEV,
    I_NSTEPS,
    I_REASON,
    I_SAVE_KIND,
    I_STATUS,
    R_T_STOP,
    STAT_MAX_FORCE,
    STAT_MAX_INDENTATION,
    W_C,
    W_INT,
    W_REAL,
    W_STATS,
    W_SUMMARY,
    W_Y,
    Y_START,
    Y_STATE,
    workspace,
)

# Scratch rows (5 numbers): the rate at the state, a stage's argument, the step's end and its rate, the stages.
RK_F, RK_TMP, RK_Y_NEW, RK_F_NEW, RK_K = range(5)
N_RK_ROWS = RK_K + 4


@kernel(forceinline=True)  # the loop's own arithmetic
def _rk4_step(code, c, y, mode, h, rows):
    """One classic RK4 step of ``h`` from ``y`` into row ``RK_Y_NEW``; returns whether it is finite."""
    tmp, y_new, k1, k2, k3, k4 = rows[RK_TMP], rows[RK_Y_NEW], rows[RK_K], rows[RK_K + 1], rows[RK_K + 2], \
        rows[RK_K + 3]
    rhs(code, c, y, mode, k1)
    for j in range(5):
        tmp[j] = y[j] + 0.5 * h * k1[j]
    rhs(code, c, tmp, mode, k2)
    for j in range(5):
        tmp[j] = y[j] + 0.5 * h * k2[j]
    rhs(code, c, tmp, mode, k3)
    for j in range(5):
        tmp[j] = y[j] + h * k3[j]
    rhs(code, c, tmp, mode, k4)
    finite = True
    for j in range(5):
        y_new[j] = y[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
        finite = finite and math.isfinite(y_new[j])
    return finite


@allocating(python=True, nogil=True)
def run_rk4(code, c, y0, t_end, save_kind, times, max_steps, rk4_step, rk4_every):
    """The seed's classic RK4: eq. 8's plain right-hand side, fixed steps ``rk4_step``, nothing
    resolved (a contact or separation is logged where ``delta`` changed sign, its time interpolated
    linearly); with ``save_kind`` steps, every ``rk4_every``-th step is kept. Returns what
    :func:`run` does. An entry of its own, not a branch of :func:`run`: the first compile of a run
    that does not ask for it leaves it out."""
    ws = workspace(c.shape[0], 0, None)  # the run's record, logs and summary (driver.run's); no Radau
    ints, stats, y = ws[W_INT], ws[W_STATS], ws[W_Y][Y_STATE]
    copy_values(c, ws[W_C])
    copy_values(y0, ws[W_Y][Y_START])
    copy_values(y0, y)
    t = 0.0
    mode = np.int64(PLAIN)
    ints[I_MODE], ints[I_SAVE_KIND], ints[I_LOGGING] = mode, save_kind, 1
    rows = np.empty((N_RK_ROWS, 5))
    y_new, f_new = rows[RK_Y_NEW], rows[RK_F_NEW]
    force = rhs(code, c, y, mode, rows[RK_F])
    nfev = 1
    nsteps = 0
    energy_limit = energy_limit_of(code, c, y0)
    ev, smp = new_logs(save_kind, times)
    open_logs(ws, ev, smp, times, force)
    status = SUCCESS
    reason = HORIZON
    while t < t_end:
        if nsteps >= max_steps:
            status, reason = TOO_MANY_STEPS, FAILED_STOP
            break
        if nsteps % POLL_STEPS == 0 and nsteps > 0 and interrupted():
            status, reason = INTERRUPTED, FAILED_STOP
            break
        h = min(rk4_step, t_end - t)
        finite = _rk4_step(code, c, y, mode, h, rows)
        nfev += 4
        nsteps += 1
        if not finite:
            status, reason = NON_FINITE, FAILED_STOP
            break
        force_new = rhs(code, c, y_new, mode, f_new)
        d_old = y[X1] - y[X2]
        d_new = y_new[X1] - y_new[X2]
        if (d_old <= 0 < d_new) or (d_old > 0 >= d_new):
            kind = CONTACT if d_new > 0 else SEPARATION
            t_cross = t + h * d_old / (d_old - d_new)  # linear: RK4 resolves no event
            if ints[I_N_EV] == ev.shape[0]:
                ev = grow(ev, ints[I_N_EV])
            log_event(ws, ev, t_cross, kind, mode, y_new, force_new)
        t += h
        for j in range(5):
            y[j] = y_new[j]
        stats[STAT_MAX_FORCE] = max(stats[STAT_MAX_FORCE], force_new)
        stats[STAT_MAX_INDENTATION] = max(stats[STAT_MAX_INDENTATION], d_new)
        if save_kind == SAVE_STEPS and (nsteps % rk4_every == 0 or t >= t_end):
            if ints[I_N_S] == smp.shape[0]:
                smp = grow(smp, ints[I_N_S])
            add_sample(ws, smp, t, y, mode, force_new)
        if energy(code, c, y) > energy_limit:
            reason = RUNAWAY_STOP
            break
    ints[I_STATUS], ints[I_REASON], ints[I_NSTEPS], ints[I_NFEV] = status, reason, nsteps, nfev
    ws[W_REAL][R_T_STOP] = t
    summarize(code, ws)
    return ws[W_SUMMARY].copy(), ev[:ints[I_N_EV]], smp[:ints[I_N_S]], y.copy()
