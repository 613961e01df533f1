"""The logs of a run, compiled: its event log and samples (one float array each, columns ``EV_*``
and ``SMP_*``), the kernels that write them and follow each event into the summary's trackers and
the stick points (:func:`log_event`, :func:`add_sample`, :func:`close_sticks`), and the stick
points read back from a log (:func:`stick_points`). Shared by the loop (:mod:`.driver`), its step
kernels (:mod:`.step`) and the RK4 entry (:mod:`.rk4`).
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import allocating, kernel
from ..model.rhs import V1, V2, X1, X2
from .events import CONTACT, SEPARATION, SLIP, STICK
from .phase import copy_values
from .record import (
    I_LOGGING,
    I_N_EV,
    I_N_S,
    I_N_STICK,
    I_OPEN_STICK,
    R_CONTACT_DURATION,
    R_CONTACT_SPEED,
    R_CONTACT_T,
    R_RESTITUTION,
    R_STICK_T,
    R_T_RUN,
    ST_DELTA,
    ST_DWELL,
    ST_T,
    W_COUNTS,
    W_INT,
    W_REAL,
    W_STICKS,
    W_Y,
    Y_FIRST_STICK,
)

# Columns of the event log and of the samples: one float array each, so that a run hands Python
# four arrays (boxing each costs about 0.2 us; eleven were a tenth of a trajectory's time).
EV_T, EV_KIND, EV_MODE, EV_Y, EV_FORCE = 0, 1, 2, 3, 8
N_EV_COLUMNS = 9
SMP_T, SMP_Y, SMP_FORCE, SMP_MODE = 0, 1, 6, 7
N_SMP_COLUMNS = 8


@allocating
def grow(a, n):
    """``a`` in an array twice as long, its first ``n`` rows kept."""
    b = np.empty((max(2 * a.shape[0], 16),) + a.shape[1:], a.dtype)
    copy_values(a.ravel(), b.ravel()[:n * (a.size // max(a.shape[0], 1))])
    return b


@kernel
def _write_event(ev, n, t, kind, mode, y, force):
    """Write an event into row ``n`` of the log ``ev`` (columns ``EV_*``)."""
    row = ev[n]
    row[EV_T] = t
    row[EV_KIND] = kind
    row[EV_MODE] = mode
    for j in range(5):
        row[EV_Y + j] = y[j]
    row[EV_FORCE] = force


@kernel(forceinline=True)
def log_event(ws, ev, t, kind, mode, y, force):
    """An event of the run: counted, written into the log ``ev`` when the run keeps one (it has a
    free row: :func:`_room`), and followed by the summary (the first contact's duration and
    restitution, the first stick, the escape) and the stick points."""
    real, ints, sticks = ws[W_REAL], ws[W_INT], ws[W_STICKS]
    if ints[I_LOGGING] != 0:
        _write_event(ev, ints[I_N_EV], t, kind, mode, y, force)
    ints[I_N_EV] += 1
    ws[W_COUNTS][kind] += 1
    if kind == CONTACT and math.isnan(real[R_CONTACT_T]):
        real[R_CONTACT_T], real[R_CONTACT_SPEED] = t, y[V1] - y[V2]
    elif kind == SEPARATION and not math.isnan(real[R_CONTACT_T]) and math.isnan(real[R_CONTACT_DURATION]):
        real[R_CONTACT_DURATION] = t - real[R_CONTACT_T]
        if real[R_CONTACT_SPEED] != 0:
            real[R_RESTITUTION] = -(y[V1] - y[V2]) / real[R_CONTACT_SPEED]
    n = ints[I_N_STICK]
    if kind == STICK:
        if n == 0:
            real[R_STICK_T] = t
            copy_values(y, ws[W_Y][Y_FIRST_STICK])
        if n < sticks.shape[1]:
            sticks[ST_T, n], sticks[ST_DELTA, n] = t, y[X1] - y[X2]
        ints[I_N_STICK] = n + 1
    if kind == SEPARATION and n > 0 and math.isnan(real[R_T_RUN]):
        real[R_T_RUN] = t
    if kind == SLIP:
        close_sticks(ws, t)


@kernel(forceinline=True)
def close_sticks(ws, end):
    """The stick phases still waiting for their end (a slip, the run's end) end at ``end``."""
    ints, sticks = ws[W_INT], ws[W_STICKS]
    for j in range(ints[I_OPEN_STICK], min(ints[I_N_STICK], sticks.shape[1])):
        sticks[ST_DWELL, j] = end - sticks[ST_T, j]
    ints[I_OPEN_STICK] = ints[I_N_STICK]


@kernel(forceinline=True)
def add_sample(ws, smp, t, y, mode, force):
    """Append a sample to ``smp`` (columns ``SMP_*``; it has a free row: :func:`_room`)."""
    n = ws[W_INT][I_N_S]
    row = smp[n]
    row[SMP_T] = t
    for j in range(5):
        row[SMP_Y + j] = y[j]
    row[SMP_FORCE] = force
    row[SMP_MODE] = mode
    ws[W_INT][I_N_S] = n + 1


@kernel(python=True)
def stick_points(ev, t_stop, permanent, out_t, out_delta, out_dwell):
    """Stick phases of an event log (columns ``EV_*``): time, ``delta*`` and dwell (to the next
    slip; to ``t_stop``, or inf if the last stick is permanent). Writes up to ``len(out_t)``;
    returns their number."""
    n = 0
    cap = out_t.shape[0]
    n_ev = ev.shape[0]
    for i in range(n_ev):
        if ev[i, EV_KIND] != STICK:
            continue
        end = math.inf if permanent else t_stop
        for j in range(i + 1, n_ev):
            if ev[j, EV_KIND] == SLIP:
                end = ev[j, EV_T]
                break
        if n < cap:
            out_t[n] = ev[i, EV_T]
            out_delta[n] = ev[i, EV_Y + X1] - ev[i, EV_Y + X2]
            out_dwell[n] = end - ev[i, EV_T]
        n += 1
    return n
