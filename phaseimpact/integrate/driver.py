"""The one hybrid (event-driven) loop, compiled: every trajectory of the project runs here.

Between events the right-hand side of the current mode is smooth and a stepper advances it
(:mod:`.step`): adaptive DOP853 (:mod:`.dop853`), Radau IIA for the rest of a phase whose DOP853
steps stay at their stability limit (:mod:`.radau5`), a flight in closed form (:mod:`.flight`); or,
in an entry of its own (:mod:`.rk4`), the seed's fixed-step RK4.
After each step the event table (:mod:`.events`) is checked for crossings (:func:`.step.advance`
steps while none fires); each crossing is located on the step's dense output (:mod:`.rootfind`;
Radau's roots then polished on steps: :func:`.step.locate_events`); recorded events are logged
(:func:`.step.record_events`, the logs' kernels in :mod:`.logs`), and at the first event that
changes the phase the state is taken from a fresh step that ends exactly at the root, the
transition is applied and the run restarts there in the new mode (:func:`.step.restart`). Here:
:func:`_start`, :func:`_loop` and :func:`summarize`, the per-point kernels: they read and write one
run's workspace (:mod:`.record`) and allocate nothing; the run's status, stop reason, outcome and
summary (``S_*``). :func:`run_point` runs one point of a batch in them (no event log; the summary
and the stick points follow the events as they happen), :func:`run_block` many in one workspace,
and :func:`run` one trajectory with logs that grow between passes of the loop. The kernels of one
phase (its states, dense output, event values) are in :mod:`.phase`.

Everything here is scalars and small arrays (numba's subset); strings, objects and messages are
made outside (:mod:`.api`). The same source runs uncompiled with ``NUMBA_DISABLE_JIT=1``.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import allocating, kernel
from .._signals import interrupted
from ..model.forms import STUCK
from ..model.rhs import (
    FLIGHT,
    V1,
    V2,
    WORK,
    X1,
    X2,
    contact_side,
    energy,
    rhs,
    rhs_integration,
    stick_margin,
    stuck_pair_energy,
)
from . import flight, radau5
from .claims import claim
from .events import CONTACT, DELTA, N_EVENTS, SILENT, STICK, STOP_RUNAWAY, STOP_SETTLED, energy_limit_of, initial_mode
from .logs import N_EV_COLUMNS, N_SMP_COLUMNS, add_sample, close_sticks, grow, log_event
from .phase import (
    TIME,
    copy_values,
    dense,
    fresh_step,
    integration_state,
    phase_events,
    phase_tolerances,
    physical,
    regularised,
)
from .record import (
    G_NEW,
    G_OLD,
    I_HAVE_DENSE,
    I_LOGGING,
    I_MAX_EVENTS,
    I_MAX_STEPS,
    I_MODE,
    I_N_EV,
    I_N_S,
    I_N_STICK,
    I_NEXT_POLL,
    I_NFEV,
    I_NSTEPS,
    I_OPEN_STICK,
    I_REASON,
    I_SAVE_KIND,
    I_SETTLE,
    I_SIDE,
    I_STATUS,
    I_STOP_COUNT,
    I_STOP_KIND,
    I_TIME_INDEX,
    N_SUMMARY,
    R_CONTACT_DURATION,
    R_CONTACT_SPEED,
    R_CONTACT_T,
    R_ENERGY_LIMIT,
    R_FLIGHT_STEP,
    R_FORCE,
    R_FORCE_NEW,
    R_H,
    R_H_ABS,
    R_H_NEXT,
    R_MAX_STEP,
    R_PAIR_ENERGY,
    R_RESTITUTION,
    R_RTOL,
    R_S,
    R_STICK_T,
    R_STIFF_AFTER,
    R_T_END,
    R_T_RUN,
    R_T_STOP,
    R_W_FLOOR,
    ST_DELTA,
    ST_DWELL,
    ST_T,
    STAT_MAX_FORCE,
    STAT_MAX_INDENTATION,
    U_ATOL,
    U_DENSE,
    U_FU,
    U_FU_NEW,
    U_FU_ROOT,
    U_NEW,
    U_ROOT,
    U_STAGES,
    U_TRIAL,
    U_U,
    W_ATOL,
    W_C,
    W_COUNTS,
    W_FIRED,
    W_G,
    W_INT,
    W_RADAU,
    W_REAL,
    W_STATS,
    W_STICKS,
    W_STIFF,
    W_SUMMARY,
    W_U,
    W_Y,
    Y_F,
    Y_F_NEW,
    Y_F_TRIAL,
    Y_FIRST_STICK,
    Y_NEW,
    Y_START,
    Y_STATE,
    Y_TRIAL,
    carve,
    workspace,
)
from .rootfind import s_at_time
from .step import (
    ADV_COLLAPSE,
    ADV_END,
    ADV_LIMIT,
    ADV_NEEDS_RADAU,
    advance,
    locate_events,
    phase_step,
    quiet_start,
    record_events,
    restart,
    step_interpolant,
)

# Run status (numerical health) and why the run stopped.
SUCCESS, STEP_SIZE_COLLAPSE, TOO_MANY_STEPS, NON_FINITE, INTERRUPTED = range(5)
STATUSES = ("success", "step-size-collapse", "too-many-steps", "non-finite", "interrupted")
#: A run of an engine compiled without its stiff solver (``radau`` None, :func:`.record.carve`) that
#: turned stiff: it stopped there, and its caller runs it again with Radau (:func:`.api.radau_marker`).
#: Never a result: no name in ``STATUSES``.
NEEDS_RADAU = len(STATUSES)
#: Steps between two looks for Ctrl-C or SIGTERM (``_signals.interrupted``, a system call):
#: milliseconds of work, so a run stops well within a second at no measurable cost.
POLL_STEPS = 4096
#: Runs of a block between two looks (each long run also looks every POLL_STEPS steps).
POLL_RUNS = 64
HORIZON, SETTLED_STOP, RUNAWAY_STOP, ASKED_STOP, FAILED_STOP = range(5)
STOP_REASONS = ("horizon", "settled", "runaway", "asked", "failed")
# Outcome classes (docs/physics.md §5).
FAILED, PERMANENT_STICK, RATCHET_ESCAPE, REBOUND, RUNAWAY_OUTCOME, BOUNDED, UNSETTLED = range(7)
OUTCOMES = ("failed", "permanent-stick", "ratchet-escape", "rebound", "runaway", "bounded", "unsettled")
# Save kinds.
SAVE_SUMMARY, SAVE_STEPS, SAVE_TIMES = range(3)
# Summary vector of one run (columns of many runs).
(S_STATUS, S_REASON, S_OUTCOME, S_T_STOP, S_MAX_FORCE, S_MAX_INDENTATION, S_RESTITUTION,
 S_CONTACT_DURATION, S_DISSIPATED, S_LOOP_AREA, S_N_STICK, S_N_CONTACTS, S_T_RUN, S_FIRST_STICK_DELTA,
 S_FIRST_STICK_MARGIN, S_FIRST_STICK_T, S_NSTEPS, S_NFEV, S_MODE) = range(19)

_EPS = np.finfo(np.float64).eps


# ------------------------------------------------------------------------------------------------
# One run: the loop (its logs: .logs; its record and workspace: .record)
# ------------------------------------------------------------------------------------------------
#: What :func:`_loop` returns: the run ended, or its logs must grow before it goes on.
RUN_DONE, RUN_LOG_FULL = range(2)
#: The options of a run, a tuple: relative tolerance, whether to stop once settled, the event kind
#: and count to stop at (-1: none), the step and event caps, DOP853 steps at the stability limit
#: before Radau (0: never). The same for every run of a batch.
OPT_RTOL, OPT_SETTLE, OPT_STOP_KIND, OPT_STOP_COUNT, OPT_MAX_STEPS, OPT_MAX_EVENTS, OPT_STIFF_AFTER = range(7)
#: A batch of runs (:func:`run_block`), a tuple of arrays with a row or entry per run: coefficients,
#: start states, horizons, absolute tolerances (n, 7), largest steps.
B_C, B_Y0, B_T_END, B_ATOL, B_MAX_STEP = range(5)
#: What :func:`run_block` fills, a tuple of arrays with a row or entry per run: the summaries, the
#: stick points' times, depths and dwells (their first ``capacity``), their numbers.
O_SUMMARY, O_STICK_T, O_STICK_DELTA, O_STICK_DWELL, O_STICK_COUNT = range(5)


@kernel
def _set_options(ws, options, t_end, max_step, save_kind):
    """A run's options (the tuple ``OPT_*``), horizon, largest step and save kind into its record."""
    real, ints = ws[W_REAL], ws[W_INT]
    real[R_T_END], real[R_RTOL], real[R_MAX_STEP], real[R_STIFF_AFTER] = (t_end, options[OPT_RTOL], max_step,
                                                                          options[OPT_STIFF_AFTER])
    ints[I_SETTLE], ints[I_STOP_KIND], ints[I_STOP_COUNT] = (options[OPT_SETTLE], options[OPT_STOP_KIND],
                                                             options[OPT_STOP_COUNT])
    ints[I_SAVE_KIND], ints[I_MAX_STEPS] = save_kind, options[OPT_MAX_STEPS]
    ints[I_MAX_EVENTS] = options[OPT_MAX_EVENTS]


@kernel(forceinline=True)
def _room(ws, ev, smp, times):
    """Whether the logs hold what one more pass of the loop may add: an event per column and the
    restart's, two samples (steps) or every output time left (times)."""
    ints = ws[W_INT]
    samples = 0
    if ints[I_SAVE_KIND] == SAVE_STEPS:
        samples = 2
    elif ints[I_SAVE_KIND] == SAVE_TIMES:
        samples = times.shape[0] - ints[I_TIME_INDEX]
    return ints[I_N_EV] + N_EVENTS + 1 <= ev.shape[0] and ints[I_N_S] + samples <= smp.shape[0]


@kernel
def open_logs(ws, ev, smp, times, force):
    """The logs and the summary's trackers of a run from row ``Y_STATE`` at t = 0 in mode
    ``I_MODE``: its contact when it starts on one, its first samples, the running extremes."""
    real, ints, y = ws[W_REAL], ws[W_INT], ws[W_Y][Y_STATE]
    mode = ints[I_MODE]
    for k in (I_N_EV, I_N_S, I_N_STICK, I_OPEN_STICK, I_TIME_INDEX, I_NSTEPS):
        ints[k] = 0
    ints[I_STATUS], ints[I_REASON] = SUCCESS, HORIZON
    for k in (R_CONTACT_T, R_CONTACT_SPEED, R_CONTACT_DURATION, R_RESTITUTION, R_STICK_T, R_T_RUN):
        real[k] = math.nan
    counts = ws[W_COUNTS]
    for k in range(counts.shape[0]):
        counts[k] = 0
    if y[X1] == y[X2] and y[V1] > y[V2]:
        log_event(ws, ev, 0.0, np.int64(CONTACT), mode, y, force)
    if ints[I_SAVE_KIND] == SAVE_STEPS:
        add_sample(ws, smp, 0.0, y, mode, force)
    if ints[I_SAVE_KIND] == SAVE_TIMES:
        while ints[I_TIME_INDEX] < times.shape[0] and times[ints[I_TIME_INDEX]] <= 0.0:
            add_sample(ws, smp, times[ints[I_TIME_INDEX]], y, mode, force)
            ints[I_TIME_INDEX] += 1
    ws[W_STATS][STAT_MAX_FORCE] = force
    ws[W_STATS][STAT_MAX_INDENTATION] = y[X1] - y[X2]


@kernel
def _start(code, ws, ev, smp, times):
    """A run from the start state (row ``Y_START``), coefficients (``W_C``, the run's own: a law's
    memory is written into them, model.forms.remember), tolerances (``W_ATOL``) and options of its
    workspace, at t = 0: its mode, logs, phase and first step."""
    real, ints, c, yr, ur = ws[W_REAL], ws[W_INT], ws[W_C], ws[W_Y], ws[W_U]
    y, f, u, fu, atol_u = yr[Y_STATE], yr[Y_F], ur[U_U], ur[U_FU], ur[U_ATOL]
    copy_values(yr[Y_START], y)
    mode = initial_mode(code, c, y)
    force = rhs(code, c, y, mode, f)
    ints[I_MODE], ints[I_NFEV] = mode, 1
    energy_limit = energy_limit_of(code, c, y)
    open_logs(ws, ev, smp, times, force)
    fired = ws[W_FIRED]
    for k in range(N_EVENTS):
        fired[k] = False
    # Plain phases integrate u = (x1, x2, v1, v2, W, t) in s = t; regularised contact phases
    # (side = +-1) integrate u = (w, x2, v1, v2, W, t) in s with dt = w ds (model.rhs.rhs_integration).
    rtol, max_step = real[R_RTOL], real[R_MAX_STEP]
    w_floor = ws[W_ATOL][6] / rtol  # the scale of w = sqrt(|delta|)
    # a flight's steps only bracket events, between the target's passes through its centre; a
    # figure gets a sample every sixteenth of the target's period
    real[R_FLIGHT_STEP] = math.inf if ints[I_SAVE_KIND] != SAVE_STEPS else max_step / 2
    side = contact_side(code, c, y, mode)
    integration_state(code, mode, side, y, 0.0, u)
    phase_tolerances(code, mode, side, ws[W_ATOL], atol_u)
    rhs_integration(code, c, u, mode, side, fu)
    g_old = ws[W_G][G_OLD]
    phase_events(code, c, mode, side, energy_limit, u, y, f, force, g_old)
    quiet_start(np.int64(DELTA), y, mode, g_old)
    ints[I_SIDE], real[R_W_FLOOR] = side, w_floor
    h_abs = phase_step(code, ws)
    if side == FLIGHT:
        flight.coefficients(c, u, 0.0, ur[U_STAGES:U_DENSE])  # kept for the whole flight (it has no stages)
    radau5.clear(ws[W_STIFF], real[R_STIFF_AFTER])
    radau5.clear_arrays(ws[W_RADAU])
    ints[I_NFEV], ints[I_NEXT_POLL] = 3, POLL_STEPS
    real[R_S], real[R_H_ABS], real[R_FORCE] = 0.0, h_abs, force
    real[R_ENERGY_LIMIT], real[R_PAIR_ENERGY] = energy_limit, stuck_pair_energy(c, y)  # the pair's: read while stuck


@kernel
def _loop(code, ws, ev, smp, times):
    """The run's loop: steps while nothing happens (:func:`_take_steps`), then on the step where
    something did, the events located and logged (:func:`_look_at_step`) and the run restarted,
    stopped or the step accepted (:func:`_after_step`). Returns ``RUN_DONE``, or ``RUN_LOG_FULL``
    when the run keeps logs (``I_LOGGING``) and they may not hold one more pass: the caller grows
    them and calls again, and the run goes on exactly where it stood."""
    real, ints, u, stiff = ws[W_REAL], ws[W_INT], ws[W_U][U_U], ws[W_STIFF]
    while u[TIME] < real[R_T_END]:
        if ints[I_LOGGING] != 0 and not _room(ws, ev, smp, times):
            return RUN_LOG_FULL
        if ints[I_NSTEPS] >= ints[I_MAX_STEPS] or ints[I_N_EV] >= ints[I_MAX_EVENTS]:
            ints[I_STATUS], ints[I_REASON] = TOO_MANY_STEPS, FAILED_STOP
            break
        if ints[I_NSTEPS] >= ints[I_NEXT_POLL]:
            ints[I_NEXT_POLL] = ints[I_NSTEPS] + POLL_STEPS
            if interrupted():
                ints[I_STATUS], ints[I_REASON] = INTERRUPTED, FAILED_STOP
                break
        if radau5.failed(stiff):
            break
        result = _take_steps(code, ws, times)
        if result == ADV_END:
            break
        if result == ADV_COLLAPSE:
            ints[I_STATUS], ints[I_REASON] = STEP_SIZE_COLLAPSE, FAILED_STOP
            break
        if result == ADV_NEEDS_RADAU:
            ints[I_STATUS], ints[I_REASON] = NEEDS_RADAU, FAILED_STOP
            break
        if result == ADV_LIMIT:
            if ints[I_NSTEPS] < ints[I_MAX_STEPS]:
                continue  # at the next poll
            ints[I_STATUS], ints[I_REASON] = TOO_MANY_STEPS, FAILED_STOP
            break
        # a step to look at (an event fired in it, a sample or the horizon falls in it); not accepted yet
        restart_col, s_restart, s_horizon, stop_record = _look_at_step(code, ws, ev)
        if restart_col == _RETRY:
            continue  # an event left and re-crossed zero inside the step: a smaller one resolves it
        if _after_step(code, ws, ev, smp, times, restart_col, s_restart, s_horizon, stop_record):
            break
    if radau5.failed(stiff):  # a step to a root did not converge: what follows it is not the motion
        ints[I_STATUS], ints[I_REASON] = STEP_SIZE_COLLAPSE, FAILED_STOP
    real[R_T_STOP] = u[TIME]
    return RUN_DONE


_RETRY = -2  # _look_at_step: the step is to be retried smaller


@kernel(forceinline=True)
def _take_steps(code, ws, times):
    """Steps of the current phase while nothing happens (:func:`advance`); returns its result."""
    ints, u = ws[W_INT], ws[W_U][U_U]
    save_kind, i_time, nsteps = ints[I_SAVE_KIND], ints[I_TIME_INDEX], ints[I_NSTEPS]
    next_sample = u[TIME] if save_kind == SAVE_STEPS else (
        times[i_time] if save_kind == SAVE_TIMES and i_time < times.shape[0] else math.inf)
    result, d_steps, d_fev = advance(code, ws, next_sample, min(ints[I_MAX_STEPS], ints[I_NEXT_POLL]) - nsteps)
    ints[I_NSTEPS], ints[I_NFEV] = nsteps + d_steps, ints[I_NFEV] + d_fev
    return result


@kernel(forceinline=True)
def _look_at_step(code, ws, ev):
    """The step :func:`advance` left: where a regularised phase reaches the horizon in it, the
    events that fired located and the recorded ones logged. Returns ``(restart_col, s_restart,
    s_horizon, stop_record)`` (see :func:`locate_events`, :func:`record_events`; inf where none);
    ``restart_col`` is ``_RETRY`` when the step must be retried smaller."""
    real, ints, ur, fired = ws[W_REAL], ws[W_INT], ws[W_U], ws[W_FIRED]
    side, h = ints[I_SIDE], real[R_H]
    any_fired = False
    for col in range(N_EVENTS):
        any_fired = any_fired or fired[col]
    have_dense = False
    stop_record = -1.0
    restart_col = np.int64(-1)
    s_restart = math.inf
    s_horizon = math.inf
    nfev = 0
    if regularised(side) and ur[U_NEW][TIME] >= real[R_T_END]:
        nfev += step_interpolant(code, ws)
        have_dense = True
        s_horizon = s_at_time(code, ws, real[R_T_END])
    if any_fired:
        if not have_dense:
            nfev += step_interpolant(code, ws)
            have_dense = True
        unresolved, restart_col, s_restart, spent = locate_events(code, ws, s_horizon)
        nfev += spent
        if unresolved:
            real[R_H_ABS] = h / 32.0
            ints[I_NFEV] += nfev
            return np.int64(_RETRY), s_restart, s_horizon, stop_record
        stop_record, spent = record_events(code, ws, ev, s_restart)
        nfev += spent
    ints[I_NFEV] += nfev
    ints[I_HAVE_DENSE] = have_dense
    return restart_col, s_restart, s_horizon, stop_record


@kernel(forceinline=True)
def _after_step(code, ws, ev, smp, times, restart_col, s_restart, s_horizon, stop_record):
    """After :func:`_look_at_step`: stop at a recorded event, take the samples in the step, stop on
    the horizon, restart at an event, or accept the whole step. Returns True when the run ends."""
    real, ints, c, ur, yr = ws[W_REAL], ws[W_INT], ws[W_C], ws[W_U], ws[W_Y]
    mode, side, s = ints[I_MODE], ints[I_SIDE], real[R_S]
    u, fu, u_r, y, f = ur[U_U], ur[U_FU], ur[U_ROOT], yr[Y_STATE], yr[Y_F]
    if stop_record >= 0:
        # stopped at a recorded event: the state there from a fresh step that ends at it
        if stop_record > s:
            ints[I_NFEV] += fresh_step(code, ws, stop_record - s, u_r, ur[U_FU_ROOT])
            copy_values(u_r, u)
            if not regularised(side):
                u[TIME] = stop_record
        real[R_FORCE] = physical(code, c, mode, side, u, y, f)
        ints[I_REASON] = ASKED_STOP
        return True
    if ints[I_SAVE_KIND] == SAVE_TIMES:
        _samples_in_step(code, ws, smp, times, restart_col, s_restart, s_horizon)
    if restart_col < 0 and s_horizon < math.inf:
        # a regularised phase reaches the horizon inside the step: the state there from a fresh step
        ints[I_NFEV] += fresh_step(code, ws, s_horizon - s, u_r, ur[U_FU_ROOT])
        copy_values(u_r, u)
        u[TIME] = real[R_T_END]  # without the root finder's residue
        force = physical(code, c, mode, side, u, y, f)
        real[R_FORCE] = force
        _extremes(ws, force, y)
        if ints[I_SAVE_KIND] == SAVE_STEPS:
            add_sample(ws, smp, real[R_T_END], y, mode, force)
        return True
    if restart_col >= 0:
        return _restart_and_log(code, ws, ev, smp, restart_col, s_restart)
    # the whole step stands
    real[R_S] = s + real[R_H]
    copy_values(ur[U_NEW], u)
    copy_values(ur[U_FU_NEW], fu)
    copy_values(yr[Y_NEW], y)
    copy_values(yr[Y_F_NEW], f)
    copy_values(ws[W_G][G_NEW], ws[W_G][G_OLD])
    force = real[R_FORCE_NEW]
    real[R_FORCE], real[R_H_ABS] = force, real[R_H_NEXT]
    _extremes(ws, force, y)
    if ints[I_SAVE_KIND] == SAVE_STEPS:
        add_sample(ws, smp, u[TIME], y, mode, force)
    return False


@kernel(forceinline=True)
def _extremes(ws, force, y):
    """The running extremes (``W_STATS``) after a state the run stands at."""
    stats = ws[W_STATS]
    stats[STAT_MAX_FORCE] = max(stats[STAT_MAX_FORCE], force)
    stats[STAT_MAX_INDENTATION] = max(stats[STAT_MAX_INDENTATION], y[X1] - y[X2])


@kernel(forceinline=True)
def _samples_in_step(code, ws, smp, times, restart_col, s_restart, s_horizon):
    """The output times in the step, up to where its motion stands: its end, the restart or the horizon."""
    real, ints, c, ur, yr = ws[W_REAL], ws[W_INT], ws[W_C], ws[W_U], ws[W_Y]
    mode, side, s, h = ints[I_MODE], ints[I_SIDE], real[R_S], real[R_H]
    u, us, F, ys, fs = ur[U_U], ur[U_TRIAL], ur[U_DENSE:], yr[Y_TRIAL], yr[Y_F_TRIAL]
    have_dense = ints[I_HAVE_DENSE] != 0
    t_seg = ur[U_NEW][TIME]
    if restart_col >= 0:
        dense(c, side, F, u, s, h, s_restart, us)
        t_seg = s_restart if not regularised(side) else us[TIME]
    elif s_horizon < math.inf:
        t_seg = real[R_T_END]
    i_time = ints[I_TIME_INDEX]
    while i_time < times.shape[0] and times[i_time] <= t_seg:
        if not have_dense:
            ints[I_NFEV] += step_interpolant(code, ws)
            have_dense = True
        s_i = s_at_time(code, ws, times[i_time])
        dense(c, side, F, u, s, h, s_i, us)
        f_i = physical(code, c, mode, side, us, ys, fs)
        add_sample(ws, smp, times[i_time], ys, mode, f_i)
        i_time += 1
    ints[I_TIME_INDEX] = i_time


@kernel(forceinline=True)
def _restart_and_log(code, ws, ev, smp, restart_col, s_restart):
    """Restart at the event ``restart_col`` (:func:`restart`), log it and stop where it says so;
    returns True when the run ends."""
    real, ints, yr = ws[W_REAL], ws[W_INT], ws[W_Y]
    kind, action, t = restart(code, ws, restart_col, s_restart)
    mode, y, force = ints[I_MODE], yr[Y_STATE], real[R_FORCE]
    if kind != SILENT:  # SILENT: a restart only (the pair at its centre): nothing to log
        log_event(ws, ev, t, kind, mode, y, force)
        _extremes(ws, force, y)
        if ints[I_SAVE_KIND] == SAVE_STEPS:
            add_sample(ws, smp, t, y, mode, force)
        if action == STOP_SETTLED:
            ints[I_REASON] = SETTLED_STOP
            return True
        if action == STOP_RUNAWAY:
            ints[I_REASON] = RUNAWAY_STOP
            return True
        if kind == ints[I_STOP_KIND] and ws[W_COUNTS][kind] >= ints[I_STOP_COUNT]:
            ints[I_REASON] = ASKED_STOP
            return True
    u, g_old = ws[W_U][U_U], ws[W_G][G_OLD]
    phase_events(code, ws[W_C], mode, ints[I_SIDE], real[R_ENERGY_LIMIT], u, y, yr[Y_F], force, g_old)
    quiet_start(restart_col, y, mode, g_old)
    return False


@kernel
def summarize(code, ws):
    """The summary vector of the run (``W_SUMMARY``, indices ``S_*``; undefined entries NaN), and
    the ends of its last stick phases."""
    real, ints, c, yr, counts = ws[W_REAL], ws[W_INT], ws[W_C], ws[W_Y], ws[W_COUNTS]
    s = ws[W_SUMMARY]
    y0, y, mode, status, reason = yr[Y_START], yr[Y_STATE], ints[I_MODE], ints[I_STATUS], ints[I_REASON]
    for k in range(N_SUMMARY):
        s[k] = math.nan
    s[S_STATUS] = status
    s[S_REASON] = reason
    s[S_T_STOP] = real[R_T_STOP]
    s[S_MAX_FORCE] = ws[W_STATS][STAT_MAX_FORCE]
    s[S_MAX_INDENTATION] = ws[W_STATS][STAT_MAX_INDENTATION]
    s[S_DISSIPATED] = energy(code, c, y0) - energy(code, c, y)
    s[S_LOOP_AREA] = y[WORK] - y0[WORK]
    s[S_N_STICK] = counts[STICK]
    s[S_N_CONTACTS] = counts[CONTACT]
    s[S_NSTEPS] = ints[I_NSTEPS]
    s[S_NFEV] = ints[I_NFEV]
    s[S_MODE] = mode
    s[S_CONTACT_DURATION] = real[R_CONTACT_DURATION]
    s[S_RESTITUTION] = real[R_RESTITUTION]
    if ints[I_N_STICK] > 0:
        stuck = yr[Y_FIRST_STICK]
        s[S_FIRST_STICK_T] = real[R_STICK_T]
        s[S_FIRST_STICK_DELTA] = stuck[X1] - stuck[X2]
        s[S_FIRST_STICK_MARGIN] = stick_margin(code, c, stuck)
    s[S_T_RUN] = real[R_T_RUN]
    if status != SUCCESS:
        outcome = FAILED
    elif reason == RUNAWAY_STOP:
        outcome = RATCHET_ESCAPE if counts[STICK] > 0 else RUNAWAY_OUTCOME
    elif reason == SETTLED_STOP:
        if mode == STUCK:
            outcome = PERMANENT_STICK
        else:
            outcome = RATCHET_ESCAPE if counts[STICK] > 0 else REBOUND
    elif reason == ASKED_STOP:
        outcome = UNSETTLED
    else:
        outcome = BOUNDED
    s[S_OUTCOME] = outcome
    close_sticks(ws, math.inf if outcome == PERMANENT_STICK else real[R_T_STOP])


@allocating
def new_logs(save_kind, times):
    """Empty logs for a run that keeps them: the event log and the samples."""
    rows = 1 if save_kind == SAVE_SUMMARY else (256 if save_kind == SAVE_STEPS else times.shape[0] + 2)
    return np.empty((64, N_EV_COLUMNS)), np.empty((rows, N_SMP_COLUMNS))


@allocating(python=True, nogil=True)  # runs side by side in threads (phaseimpact.train's orbit diagrams)
def run(code, c, y0, atol, t_end, max_step, options, save_kind, times, radau):
    """Integrate one trajectory. See :func:`phaseimpact.integrate.simulate` for the meaning;
    ``options`` is the tuple ``OPT_*``; ``radau`` None compiles and runs the engine without its stiff
    solver (:func:`.record.carve`: a run that turns stiff stops with the status ``NEEDS_RADAU``).

    Returns ``(summary, events, samples, y_final)``: the event log (columns ``EV_*``) and the
    samples (columns ``SMP_*``) trimmed to their lengths. The per-point kernels of
    :func:`run_block` in a workspace of its own, with logs that grow (by doubling) whenever
    :func:`_loop` says they may not hold one more pass. The seed's RK4 is :func:`.rk4.run_rk4`.
    """
    ws = workspace(c.shape[0], 0, radau)
    copy_values(c, ws[W_C])
    copy_values(y0, ws[W_Y][Y_START])
    copy_values(atol, ws[W_ATOL])
    _set_options(ws, options, t_end, max_step, save_kind)
    ints = ws[W_INT]
    ints[I_LOGGING] = 1
    ev, smp = new_logs(save_kind, times)
    _start(code, ws, ev, smp, times)
    while _loop(code, ws, ev, smp, times) == RUN_LOG_FULL:
        ev = grow(ev, ints[I_N_EV])
        smp = grow(smp, ints[I_N_S])
    summarize(code, ws)
    return ws[W_SUMMARY].copy(), ev[:ints[I_N_EV]], smp[:ints[I_N_S]], ws[W_Y][Y_STATE].copy()


@kernel
def run_point(code, ws, batch, options, i):
    """Run ``i`` of ``batch`` (the tuple ``B_*``) in the workspace ``ws``, summary only, without an
    event log: its summary in ``W_SUMMARY``, its stick points in ``W_STICKS`` (the first of
    them, ``I_N_STICK`` in all). Allocates nothing: a thread's whole work for one point."""
    copy_values(batch[B_C][i], ws[W_C])
    copy_values(batch[B_Y0][i], ws[W_Y][Y_START])
    copy_values(batch[B_ATOL][i], ws[W_ATOL])
    _set_options(ws, options, batch[B_T_END][i], batch[B_MAX_STEP][i], np.int64(SAVE_SUMMARY))
    ws[W_INT][I_LOGGING] = 0
    no_log, no_times = ws[W_G][:0], ws[W_G][0, :0]  # log_event writes no event, and nothing samples
    _start(code, ws, no_log, no_log, no_times)
    _loop(code, ws, no_log, no_log, no_times)
    summarize(code, ws)


@kernel
def run_point_into(code, ws, batch, options, i, outputs):
    """:func:`run_point`, then its summary and first stick points into row ``i`` of ``outputs``
    (the tuple ``O_*``): one point's whole work in a CPU thread's block or a GPU thread
    (:mod:`phaseimpact.cuda`)."""
    run_point(code, ws, batch, options, i)
    ints, sticks = ws[W_INT], ws[W_STICKS]
    st_t, st_delta, st_dwell = outputs[O_STICK_T], outputs[O_STICK_DELTA], outputs[O_STICK_DWELL]
    copy_values(ws[W_SUMMARY], outputs[O_SUMMARY][i])
    outputs[O_STICK_COUNT][i] = ints[I_N_STICK]
    for j in range(min(ints[I_N_STICK], sticks.shape[1])):
        st_t[i, j], st_delta[i, j], st_dwell[i, j] = sticks[ST_T, j], sticks[ST_DELTA, j], sticks[ST_DWELL, j]


@kernel
def _stop_block(summary, tasks, task, first, claimed):
    """Ctrl-C or SIGTERM seen before run ``first`` of task ``task``: that run and the rest of the task,
    and every task no thread has claimed yet (claimed here, so that no thread starts one), get the
    status ``interrupted``."""
    for i in range(first, tasks[task, 1], tasks[task, 2]):
        summary[i, S_STATUS] = INTERRUPTED
    n_tasks = tasks.shape[0]
    for other in range(claim(claimed, n_tasks), n_tasks):
        for i in range(tasks[other, 0], tasks[other, 1], tasks[other, 2]):
            summary[i, S_STATUS] = INTERRUPTED


@kernel(python=True, nogil=True)
def run_block(code, batch, options, tasks, claimed, outputs, work, radau):
    """Runs the tasks of a batch that this thread claims, without the GIL (callers run one block per
    thread; each run's numbers depend on nothing else). A task is a row ``(start, stop, step)`` of
    ``tasks``, the runs ``start, start + step, ...`` below ``stop``. The threads of a chunk share the
    counter ``claimed`` (an int64 array of one number, 0 at first) and each takes its next task from
    it as it comes free (:func:`.claims.claim`): no Python between two tasks, so no thread waits for
    the GIL there, and a thread slowed by another process takes fewer. Fills ``outputs`` (the tuple
    ``O_*``): the summaries (n, N_SUMMARY), the first ``capacity`` stick points of each run and its
    full number of stick points (more than ``capacity``: the caller runs it again on the full path).
    Threads over blocks, not a compiled parallel loop: that would compile the driver a second time.
    On Ctrl-C or SIGTERM the rest of the thread's task and every task not yet claimed get the status
    ``interrupted`` (:func:`_stop_block`); the other threads stop at their next look.

    ``work`` is the block's workspace, a buffer of :func:`.record.workspace_size` numbers the caller
    made (one per thread); each run goes through :func:`run_point` in it, without an event log;
    ``radau`` as for :func:`run`.
    Allocates nothing, and being a kernel (no reference counting) takes its arguments from Python
    without numba's runtime either: a chunk of runs makes no numba allocation at all."""
    summary = outputs[O_SUMMARY]
    ws = carve(work, batch[B_C].shape[1], outputs[O_STICK_T].shape[1], radau)
    done = 0
    task = claim(claimed, 1)
    while task < tasks.shape[0]:
        start, stop, step = tasks[task, 0], tasks[task, 1], tasks[task, 2]
        for i in range(start, stop, step):
            done += 1
            if done % POLL_RUNS == 0 and interrupted():
                _stop_block(summary, tasks, task, i, claimed)
                return
            run_point_into(code, ws, batch, options, i, outputs)
            if summary[i, S_STATUS] == INTERRUPTED:  # the run itself looked
                _stop_block(summary, tasks, task, i + step, claimed)
                return
        task = claim(claimed, 1)


@kernel(python=True, nogil=True)
def run_held(code, ws, batch, options, i):
    """:func:`run_point` in a workspace the caller holds, for callers that run points one at a time
    (critical searches, the impact map: :func:`.api.summary_run`); the results stay in ``ws`` (its
    summary, stick points and final state ``Y_STATE``). Allocates nothing."""
    run_point(code, ws, batch, options, i)
