"""The one hybrid (event-driven) loop, compiled: every trajectory of the project runs here.

Between events the right-hand side of the current mode is smooth and a stepper advances it:
adaptive DOP853 (:mod:`.dop853`), Radau IIA for the rest of a phase whose DOP853 steps stay at
their stability limit (:mod:`.radau5`); or, in an entry of its own (:mod:`.rk4`), the seed's
fixed-step RK4.
After each step the event table (:mod:`.events`) is checked for crossings (:func:`_advance`
steps while none fires); each crossing is located on the step's dense output (:mod:`.rootfind`;
Radau's roots then polished on steps: :func:`_locate_events`); recorded events are logged
(:func:`_record`), and at the first event that changes the phase the state is taken from a
fresh step that ends exactly at the root, the transition is applied and the run restarts there
in the new mode (:func:`_restart`). :func:`run` holds the loop and the run's logs.

Scratch vectors are rows of a few arrays with named rows (``Y_*``, ``G_*``, ``U_*``); the kernels of
one phase (its states, dense output, event values) are in :mod:`.phase`.

Everything here is scalars and small arrays (numba's subset); strings, objects and messages are
made outside (:mod:`.api`). The same source runs uncompiled with ``NUMBA_DISABLE_JIT=1``.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import allocating, kernel
from .._signals import interrupted
from ..model.laws import STUCK
from ..model.rhs import (
    FLIGHT,
    RIGID_,
    SPRINGS_,
    V1,
    V2,
    WORK,
    X1,
    X2,
    contact_side,
    damping_rate,
    energy,
    onto_stuck_orbit,
    relative_slip,
    rhs,
    rhs_integration,
    stick_margin,
    stuck_pair_energy,
)
from . import dop853, flight, radau5
from .dop853 import N_DENSE, N_STAGES, N_STATE
from .events import (
    CONTACT,
    DELTA,
    DELTADOT,
    ENERGY,
    EVENT_KINDS,
    FORCE_PEAK,
    FORCE_RATE,
    N_EVENTS,
    REACH,
    REVERSAL,
    SEPARATION,
    SETTLED,
    SILENT,
    SLIP,
    STICK,
    STICK_BREAK,
    STOP_RUNAWAY,
    STOP_SETTLED,
    crossed,
    departure_sign,
    energy_limit_of,
    initial_mode,
    restarts,
    transition,
)
from .phase import (
    TIME,
    copy_values,
    dense,
    event_at,
    fresh_step,
    integration_state,
    phase_events,
    phase_tolerances,
    physical,
    regularised,
)
from .rootfind import brent, locate, polish_root, s_at_time

# Run status (numerical health) and why the run stopped.
SUCCESS, STEP_SIZE_COLLAPSE, TOO_MANY_STEPS, NON_FINITE, INTERRUPTED = range(5)
STATUSES = ("success", "step-size-collapse", "too-many-steps", "non-finite", "interrupted")
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
# Columns of the event log and of the samples: one float array each, so that a run hands Python
# four arrays (boxing each costs about 0.2 us; eleven were a tenth of a trajectory's time).
EV_T, EV_KIND, EV_MODE, EV_Y, EV_FORCE = 0, 1, 2, 3, 8
N_EV_COLUMNS = 9
SMP_T, SMP_Y, SMP_FORCE, SMP_MODE = 0, 1, 6, 7
N_SMP_COLUMNS = 8

# Summary vector of one run (columns of many runs).
(S_STATUS, S_REASON, S_OUTCOME, S_T_STOP, S_MAX_FORCE, S_MAX_INDENTATION, S_RESTITUTION,
 S_CONTACT_DURATION, S_DISSIPATED, S_LOOP_AREA, S_N_STICK, S_N_CONTACTS, S_T_RUN, S_FIRST_STICK_DELTA,
 S_FIRST_STICK_MARGIN, S_FIRST_STICK_T, S_NSTEPS, S_NFEV, S_MODE) = range(19)
N_SUMMARY = 19

# Named rows of a run's scratch arrays (an allocation costs about 30 ns, a row of one array nothing).
# Physical states (5 numbers): the rate at the state, a step's end state and rate, the state and rate
# at a root, and at a trial point of the root finders.
Y_F, Y_NEW, Y_F_NEW, Y_ROOT, Y_F_ROOT, Y_TRIAL, Y_F_TRIAL = range(7)
N_Y_ROWS = 7
# Event values (N_EVENTS numbers): at a trial point, before and after the step, the roots.
G_TRIAL, G_OLD, G_NEW, G_ROOTS = range(4)
N_G_ROWS = 4
# Integration states (N_STATE numbers): the state and its rate, a step's end, the state at a root,
# at a trial point, scratch, the phase's absolute tolerances; then DOP853's stages (a flight's
# invariants) and the step's interpolant.
U_U, U_FU, U_NEW, U_FU_NEW, U_ROOT, U_FU_ROOT, U_TRIAL, U_TMP, U_ATOL = range(9)
U_STAGES = 9
U_DENSE = U_STAGES + N_STAGES
N_U_ROWS = U_DENSE + N_DENSE
# The running extremes of a run (``stats``), kept up to date by the kernels that take steps.
STAT_MAX_FORCE, STAT_MAX_INDENTATION = 0, 1
N_STATS = 2
#: Event kinds (``events.EVENT_KINDS``): the length of a run's counts.
N_KINDS = len(EVENT_KINDS)
#: Smallest step reduction after a rejection when the observed order is used (else MIN_FACTOR).
OBSERVED_MIN_FACTOR = 0.01
_TINY = np.finfo(np.float64).tiny
_EPS = np.finfo(np.float64).eps


@allocating
def _grow(a, n):
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


@allocating
def push_event(ev, n, t, kind, mode, y, force):
    """Append an event to the log ``ev`` (columns ``EV_*``, grown by doubling); returns the log
    and its new length."""
    if n == ev.shape[0]:
        ev = _grow(ev, n)
    _write_event(ev, n, t, kind, mode, y, force)
    return ev, n + 1


@allocating
def push_sample(smp, n, t, y, mode, force):
    """Append a sample to ``smp`` (columns ``SMP_*``, grown by doubling); returns the samples and
    their new length."""
    if n == smp.shape[0]:
        smp = _grow(smp, n)
    row = smp[n]
    row[SMP_T] = t
    for j in range(5):
        row[SMP_Y + j] = y[j]
    row[SMP_FORCE] = force
    row[SMP_MODE] = mode
    return smp, n + 1


_ADV_END, _ADV_STEP, _ADV_COLLAPSE, _ADV_LIMIT = range(4)


@kernel
def _quiet_start(quiet, y, mode, g):
    """Event values at a restart: the event the run restarts on, and ``delta`` or ``deltadot``
    when exactly zero, leave zero with a known sign (that of ``deltadot``, of the slip's mode) and
    start as that sign times a tiny number, so that a return within the first step is a crossing
    (a brief slip after a stick break). Any other event exactly at zero has no known side and
    cannot fire in the first step (a force extremum at a separation is not a peak)."""
    for col in (DELTA, DELTADOT):
        if col == quiet or g[col] == 0:
            g[col] = departure_sign(col, y, mode) * _TINY
    if quiet != DELTA and quiet != DELTADOT:
        g[quiet] = departure_sign(quiet, y, mode) * _TINY


@kernel(inline="always")  # the hot loop's own code: a call costs more than it
def _dop853_attempt(code, c, mode, side, s, s_bound, u, fu, h_abs, rtol, atol, K, u_new, fu_new):
    """One accepted DOP853 step from ``(s, u)`` (at most to ``s_bound``), first try ``h_abs``.

    Returns ``(ok, s_new, h_next, force_new, evaluations)``; ``ok`` False when the step size
    collapsed. The stages stay in ``K`` for the interpolant.
    """
    evaluations = 0
    rejected = False
    h_rejected = err_rejected = 0.0
    while True:
        if h_abs < 10.0 * (np.nextafter(s, np.inf) - s):
            return False, s, h_abs, 0.0, evaluations
        s_new = min(s + h_abs, s_bound)
        h = s_new - s
        force_new = dop853.step(code, c, mode, side, u, fu, h, K, u_new, fu_new)
        evaluations += 12
        err = dop853.error_norm(K, h, u, u_new, rtol, atol)
        if err < 1.0:
            factor = dop853.MAX_FACTOR if err == 0 else min(dop853.MAX_FACTOR,
                                                           dop853.SAFETY * err**dop853.ERROR_EXPONENT)
            if rejected:
                factor = min(1.0, factor)
            return True, s_new, h * factor, force_new, evaluations
        factor = max(dop853.MIN_FACTOR, dop853.SAFETY * err**dop853.ERROR_EXPONENT)
        if rejected and err < err_rejected and h < h_rejected:
            # a second rejection at the same point: the error falls with the step more slowly than
            # the method's order says (delta^alpha at a contact onset goes as h^2.5); shrink by the
            # observed order instead of rejecting again and again
            observed = math.log(err_rejected / err) / math.log(h_rejected / h)
            if 0.0 < observed < dop853.ORDER:
                factor = min(factor, max(OBSERVED_MIN_FACTOR, (0.5 / err) ** (1.0 / observed)))
        h_rejected, err_rejected = h, err
        h_abs = h * factor
        rejected = True


@kernel
def _advance(code, c, mode, side, s, t_end, u, fu, y, f, force, h_abs, rtol, atol, max_step, flight_step, w_floor,
             energy_limit, next_sample, steps_left, g_old, g_new, fired, K, u_new, fu_new, y_new, f_new, stats, stiff):
    """Take steps in ``s`` from ``(s, u)`` while nothing happens: no event crosses, no sample and
    (regularised phase) not the horizon falls inside. Accepted steps update ``u, fu, y, f, g_old``
    and the running extremes ``stats``. DOP853 until the phase turns stiff (:mod:`.radau5`), Radau
    from then on; a flight in closed form (:mod:`.flight`), in steps that end where the target
    passes its centre or after ``flight_step``, or to ``t_end`` at once when no event can happen
    any more and ``flight_step`` is inf (not saving steps).

    Returns ``(result, s, h, h_abs, h_next, force, force_new, steps, evaluations)``: ``_ADV_STEP``
    leaves the last step (``h``, ``u_new``, ``fu_new``, ``y_new``, ``f_new``, ``g_new``, ``fired``)
    for the caller to look at; ``_ADV_END`` means ``t_end`` was reached. The hot loop is kept small
    on purpose: the compiler optimises it as a whole.
    """
    steps = 0
    evaluations = 0
    h = 0.0
    h_next = h_abs
    force_new = force
    s_bound = t_end if not regularised(side) else math.inf  # a plain phase ends on the horizon
    while u[TIME] < t_end:
        if steps >= steps_left:
            return _ADV_LIMIT, s, h, h_abs, h_next, force, force_new, steps, evaluations
        if side == FLIGHT:  # K: the flight's invariants (it has no stages)
            if flight_step == math.inf and flight.unreachable(K, u):
                s_new = s_bound
            else:
                s_new = min(s + min(h_abs, flight_step), s_bound, flight.next_centre(K, s))
            flight.state_at(c, K, u, s, s_new, u_new)
            force_new = rhs_integration(code, c, u_new, mode, side, fu_new)
            ok, h_next, spent = True, flight_step, 0
        else:
            # a regularised phase advances the time by w ds: its cap on the time step is one on s
            h_abs = min(h_abs, max_step if not regularised(side) else max_step / max(abs(u[0]), w_floor))
            if radau5.due(stiff):  # entered from an accepted state, so that every step has one method
                evaluations += radau5.enter(code, c, mode, side, u, fu, rtol, atol, stiff)
            if radau5.active(stiff):
                ok, s_new, h_next, force_new, spent = radau5.attempt(code, c, mode, side, s, s_bound, u, fu, h_abs,
                                                                     stiff, u_new, fu_new)
            else:
                ok, s_new, h_next, force_new, spent = _dop853_attempt(code, c, mode, side, s, s_bound, u, fu, h_abs,
                                                                      rtol, atol, K, u_new, fu_new)
        evaluations += spent
        if not ok:
            return _ADV_COLLAPSE, s, h, h_next, h_next, force, force_new, steps, evaluations
        h = s_new - s
        steps += 1
        if not regularised(side):
            u_new[TIME] = s_new  # t' = 1: the time is s itself, without the sum's rounding
            for j in range(5):
                y_new[j] = u_new[j]
                f_new[j] = fu_new[j]
            if relative_slip(code, mode, side):
                y_new[V1] = u_new[V1] + u_new[V2]
                f_new[V1] = fu_new[V1] + fu_new[V2]
        else:
            force_new = physical(code, c, mode, side, u_new, y_new, f_new)
            evaluations += 1
        if side != FLIGHT and not radau5.active(stiff):
            radau5.watch(stiff, h * damping_rate(code, c, u_new, mode, side))
        phase_events(code, c, mode, side, energy_limit, u_new, y_new, f_new, force_new, g_new)
        any_fired = False
        for col in range(N_EVENTS):
            fired[col] = crossed(col, g_old, g_new)
            any_fired = any_fired or fired[col]
        if any_fired or u_new[TIME] >= next_sample or (regularised(side) and u_new[TIME] >= t_end):
            return _ADV_STEP, s, h, h_abs, h_next, force, force_new, steps, evaluations
        s = s_new
        copy_values(u_new, u)
        copy_values(fu_new, fu)
        copy_values(y_new, y)
        copy_values(f_new, f)
        copy_values(g_new, g_old)
        force = force_new
        h_abs = h_next
        stats[STAT_MAX_FORCE] = max(stats[STAT_MAX_FORCE], force)
        stats[STAT_MAX_INDENTATION] = max(stats[STAT_MAX_INDENTATION], y[X1] - y[X2])
    return _ADV_END, s, h, h_abs, h_next, force, force_new, steps, evaluations


@kernel(inline="always")
def _interpolant(code, c, mode, side, u, fu, u_new, fu_new, h, K, F, tmp, stiff):
    """The last step's interpolant into ``F`` (a flight's invariants, see :func:`dense`); returns the
    evaluations spent."""
    if side == FLIGHT:
        copy_values(K[0], F[0])  # the flight's invariants
        return 0
    if radau5.active(stiff):
        radau5.dense_coefficients(stiff, F)
        return 0
    dop853.dense_coefficients(code, c, mode, side, u, fu, u_new, fu_new, h, K, F, tmp)
    return 3


@kernel(inline="always")
def _phase_step(code, c, mode, side, u, fu, rtol, atol, t_end, max_step, w_floor, tmp, f1):
    """Initial step of a phase (scipy's rule), in its own independent variable."""
    interval = t_end - u[TIME]
    if interval <= 0:
        return 0.0  # the phase starts on the horizon (an event at t_end): no step follows
    if side == FLIGHT:
        return interval  # closed form: its steps only bracket events (see _advance)
    if regularised(side):
        interval /= max(abs(u[0]), w_floor)
    return dop853.initial_step(code, c, mode, side, u, fu, rtol, atol, interval,
                               max_step if not regularised(side) else max_step / max(abs(u[0]), w_floor), tmp, f1)


@kernel
def _locate_events(code, c, mode, side, settle, energy_limit, s, h, s_horizon, u, fu, g_old, g_new, fired, roots, K,
                   F, u_r, fu_r, stiff, us, ys, fs, gs):
    """Locate the events that fired in the step ``[s, s + h]`` on its interpolant ``F``: their roots
    into ``roots`` (``fired`` cleared where the crossing did not happen or falls after the horizon
    ``s_horizon``), and the first root that restarts the run (polished on steps when the step was
    Radau's). Returns ``(unresolved, restart_col, s_restart, evaluations)``: ``unresolved`` when an
    event left and re-crossed zero inside the step (the caller retries a smaller step);
    ``restart_col`` -1 when no event restarts the run."""
    s_new = s + h
    evaluations = 0
    restart_col = np.int64(-1)
    s_restart = math.inf
    unresolved = False
    for col in range(N_EVENTS):
        if fired[col]:
            roots[col] = locate(code, c, mode, side, energy_limit, col, F, u, s, h, s_new, g_old[col], g_new[col],
                                 us, ys, fs)
            if roots[col] == -math.inf:
                if h > 1e3 * (np.nextafter(s, np.inf) - s):
                    unresolved = True
                else:  # nothing smaller to try: the excursion did not happen
                    fired[col] = False
            elif roots[col] > s_horizon:
                fired[col] = False  # after the horizon
    if unresolved:
        return True, restart_col, s_restart, evaluations
    if fired[DELTADOT] and not fired[DELTA]:
        # an extreme of delta inside the step on the other side of zero: a contact (or
        # separation) and its return both fell inside the step
        d_ext = event_at(code, c, mode, side, energy_limit, 0.0, np.int64(DELTA), F, u, s, h, roots[DELTADOT], us, ys,
                          fs)
        if d_ext * g_old[DELTA] < 0:
            fired[DELTA] = True
            roots[DELTA] = brent(code, c, mode, side, energy_limit, 0.0, np.int64(DELTA), F, u, s, h, s,
                                  roots[DELTADOT], g_old[DELTA], d_ext, us, ys, fs)
    for col in range(N_EVENTS):
        if fired[col] and (restarts(code, col, mode, settle) or col == ENERGY) and roots[col] < s_restart:
            restart_col, s_restart = col, roots[col]
    if restart_col >= 0 and radau5.active(stiff):
        s_restart, spent = polish_root(code, c, mode, side, energy_limit, restart_col, s, u, fu, s_new,
                                        g_old[restart_col], g_new[restart_col], s_restart, K, u_r, fu_r, stiff, ys,
                                        fs, gs)
        evaluations += spent
    return False, restart_col, s_restart, evaluations


@kernel
def _record(code, c, mode, side, settle, stop_kind, stop_count, s, h, s_restart, fired, roots, u, fu, F, K, us, fu_r,
            stiff, ys, fs, ev, n_ev, counts, stats):
    """Log the recorded events (force peaks, reversals, reach) that fired in the step up to
    ``s_restart``, in time order, into ``ev`` (which has a free row for each event column); the
    running extremes ``stats`` follow them. Returns ``(n_ev, stop_record, evaluations)``:
    ``stop_record`` is the root of the event the run was asked to stop at (-1 if none)."""
    evaluations = 0
    stop_record = -1.0
    while True:
        best = np.int64(-1)
        for col in range(N_EVENTS):
            if fired[col] and not (restarts(code, col, mode, settle) or col == ENERGY) \
                    and roots[col] <= s_restart and (best < 0 or roots[col] < roots[best]):
                best = col
        if best < 0:
            break
        fired[best] = False
        if radau5.active(stiff):  # the state from a step to the root: the polynomial is of order 3
            evaluations += fresh_step(code, c, mode, side, s, u, fu, roots[best] - s, K, us, fu_r, stiff)
        else:
            dense(c, side, F, u, s, h, roots[best], us)
        f_ev = physical(code, c, mode, side, us, ys, fs)
        kind = FORCE_PEAK if best == FORCE_RATE else REVERSAL
        if best == REACH:
            kind = SETTLED  # recorded only: the run goes on
        t_ev = us[TIME] if regularised(side) else roots[best]
        _write_event(ev, n_ev, t_ev, kind, mode, ys, f_ev)
        n_ev += 1
        counts[kind] += 1
        stats[STAT_MAX_FORCE] = max(stats[STAT_MAX_FORCE], f_ev)
        stats[STAT_MAX_INDENTATION] = max(stats[STAT_MAX_INDENTATION], ys[X1] - ys[X2])
        if kind == stop_kind and counts[kind] >= stop_count:
            stop_record = roots[best]
            break
    return n_ev, stop_record, evaluations


@kernel
def _restart(code, c, settle, column, mode, side, s, s_restart, h_next, u, fu, u_r, fu_r, y_r, f_r, y, f, K, stiff,
             rtol, atol, atol_u, t_end, max_step, w_floor, tmp, f_tmp, pair_energy):
    """Restart the run at the root ``s_restart`` of event ``column``: the state there from a fresh
    step that ends there (the stages beyond the root belong to the continuation, not to the
    motion), the transition, and the new phase in ``u``, ``fu``, ``y``, ``f``, ``atol_u`` (``K``: a
    flight's invariants). Returns ``(kind, mode, action, side, s, t, h_abs, force, pair_energy,
    evaluations)``."""
    evaluations = 0
    h_r = s_restart - s
    if h_r > 0:
        evaluations += fresh_step(code, c, mode, side, s, u, fu, h_r, K, u_r, fu_r, stiff)
    else:
        copy_values(u, u_r)
    t = s_restart if not regularised(side) else u_r[TIME]
    physical(code, c, mode, side, u_r, y_r, f_r)
    if column == STICK_BREAK and c[SPRINGS_] > 0 and c[RIGID_] == 0:
        onto_stuck_orbit(c, pair_energy, y_r)
    kind, mode, action = transition(code, c, column, y_r, mode, settle)
    if kind == STICK:
        pair_energy = stuck_pair_energy(c, y_r)
    copy_values(y_r, y)
    force = rhs(code, c, y, mode, f)
    new_side = contact_side(code, c, y, mode)
    integration_state(code, mode, new_side, y, t, u)
    s = t if not regularised(new_side) else 0.0
    rhs_integration(code, c, u, mode, new_side, fu)
    evaluations += 2
    radau5.reset(stiff)  # a new phase starts explicit
    phase_tolerances(code, mode, new_side, atol, atol_u)
    if new_side != side:  # the independent variable changes: a fresh initial step
        side = new_side
        h_abs = _phase_step(code, c, mode, side, u, fu, rtol, atol_u, t_end, max_step, w_floor, tmp, f_tmp)
        evaluations += 1
    else:
        h_abs = max(h_next, h_r)
    if side == FLIGHT:
        flight.coefficients(c, u, s, K)
    return kind, mode, action, side, s, t, h_abs, force, pair_energy, evaluations


@allocating
def open_logs(y, mode, force, save_kind, times):
    """The event log and the samples of a run from ``y`` at t = 0 (its contact when it starts on one,
    its first samples). Returns ``(ev, n_ev, smp, n_s, counts, i_time)``: ``counts`` per event kind,
    ``i_time`` the next output time (``SAVE_TIMES``)."""
    # Integer constants passed to compiled callees go as np.int64: a literal argument would compile
    # a second copy of the callee (and of everything it calls) specialised on that value.
    ev = np.empty((64, N_EV_COLUMNS))
    n_ev = np.int64(0)
    smp = np.empty((256 if save_kind != SAVE_SUMMARY else 1, N_SMP_COLUMNS))
    n_s = np.int64(0)
    counts = np.zeros(N_KINDS, np.int64)
    i_time = 0
    if y[X1] == y[X2] and y[V1] > y[V2]:
        ev, n_ev = push_event(ev, n_ev, 0.0, np.int64(CONTACT), mode, y, force)
        counts[CONTACT] += 1
    if save_kind == SAVE_STEPS:
        smp, n_s = push_sample(smp, n_s, 0.0, y, mode, force)
    if save_kind == SAVE_TIMES:
        while i_time < times.shape[0] and times[i_time] <= 0.0:
            smp, n_s = push_sample(smp, n_s, times[i_time], y, mode, force)
            i_time += 1
    return ev, n_ev, smp, n_s, counts, i_time


@allocating(python=True, nogil=True)  # runs side by side in threads (phaseimpact.train's orbit diagrams)
def run(code, c, y0, t_end, rtol, atol, max_step, settle, stop_kind, stop_count, save_kind, times,
        max_steps, max_events, stiff_after):
    """Integrate one trajectory. See :func:`phaseimpact.integrate.simulate` for the meaning.

    Returns ``(summary, events, samples, y_final)``: the event log (columns ``EV_*``) and the
    samples (columns ``SMP_*``) trimmed to their lengths. Adaptive DOP853 (Radau IIA where a
    phase turns stiff) with events: steps while nothing happens (:func:`_advance`), then on the
    step where something did, the events located (:func:`_locate_events`), the recorded ones
    logged (:func:`_record`) and the run restarted at the first that changes the phase
    (:func:`_restart`). The seed's RK4 is :func:`.rk4.run_rk4`.

    The loop is :func:`_run`, which :func:`run_block` calls too: a first compile makes the two
    entries from it (:func:`phaseimpact.integrate.precompile.warmup` compiles both ahead).
    """
    return _run(code, c, y0, t_end, rtol, atol, max_step, settle, stop_kind, stop_count, save_kind, times,
                max_steps, max_events, stiff_after)


@allocating
def _run(code, c, y0, t_end, rtol, atol, max_step, settle, stop_kind, stop_count, save_kind, times,
         max_steps, max_events, stiff_after):
    """:func:`run`'s loop."""
    c = c.copy()  # the run's own: a law's memory is written into it (model.laws.remember)
    y = y0.copy()
    t = 0.0
    mode = initial_mode(code, c, y)
    # scratch vectors as rows of three arrays (layouts Y_*, G_*, U_*)
    rows5 = np.empty((N_Y_ROWS, 5))
    f = rows5[Y_F]
    y_new = rows5[Y_NEW]
    f_new = rows5[Y_F_NEW]
    y_r = rows5[Y_ROOT]
    f_r = rows5[Y_F_ROOT]
    ys = rows5[Y_TRIAL]
    fs = rows5[Y_F_TRIAL]
    force = rhs(code, c, y, mode, f)
    nfev = 1
    nsteps = 0
    energy_limit = energy_limit_of(code, c, y0)
    ev, n_ev, smp, n_s, counts, i_time = open_logs(y, mode, force, save_kind, times)
    max_force = force
    max_indentation = y[X1] - y[X2]
    status = SUCCESS
    reason = HORIZON
    rows7 = np.empty((N_G_ROWS, N_EVENTS))
    gs = rows7[G_TRIAL]
    g_old = rows7[G_OLD]
    g_new = rows7[G_NEW]
    roots = rows7[G_ROOTS]
    fired = np.zeros(N_EVENTS, np.bool_)

    # Plain phases integrate u = (x1, x2, v1, v2, W, t) in s = t; regularised contact phases
    # (side = +-1) integrate u = (w, x2, v1, v2, W, t) in s with dt = w ds (model.rhs.rhs_integration).
    rows6 = np.empty((N_U_ROWS, N_STATE))
    u = rows6[U_U]
    fu = rows6[U_FU]
    u_new = rows6[U_NEW]
    fu_new = rows6[U_FU_NEW]
    u_r = rows6[U_ROOT]
    fu_r = rows6[U_FU_ROOT]
    us = rows6[U_TRIAL]
    tmp6 = rows6[U_TMP]
    atol_u = rows6[U_ATOL]
    K6 = rows6[U_STAGES:U_DENSE]  # DOP853's stages (a flight's invariants)
    F6 = rows6[U_DENSE:]  # the step's interpolant
    w_floor = atol[6] / rtol  # the scale of w = sqrt(|delta|)
    # a flight's steps only bracket events, between the target's passes through its centre; a
    # figure gets a sample every sixteenth of the target's period
    flight_step = math.inf if save_kind != SAVE_STEPS else max_step / 2
    side = contact_side(code, c, y, mode)
    integration_state(code, mode, side, y, 0.0, u)
    phase_tolerances(code, mode, side, atol, atol_u)
    s = 0.0
    rhs_integration(code, c, u, mode, side, fu)
    nfev += 1
    quiet = np.int64(DELTA)
    phase_events(code, c, mode, side, energy_limit, u, y, f, force, g_old)
    _quiet_start(quiet, y, mode, g_old)
    h_abs = _phase_step(code, c, mode, side, u, fu, rtol, atol_u, t_end, max_step, w_floor, tmp6, fu_new)
    nfev += 1
    if side == FLIGHT:
        flight.coefficients(c, u, s, K6)  # kept in K6 for the whole flight (it has no stages)

    stats = np.empty(N_STATS)  # the running extremes (STAT_*) inside the kernels
    next_poll = np.int64(POLL_STEPS)  # _advance returns there (_ADV_LIMIT); resuming it changes no bit
    stiff = radau5.workspace(stiff_after)
    pair_energy = stuck_pair_energy(c, y)  # read while stuck only
    while u[TIME] < t_end:
        if nsteps >= max_steps or n_ev >= max_events:
            status, reason = TOO_MANY_STEPS, FAILED_STOP
            break
        if nsteps >= next_poll:
            next_poll = nsteps + POLL_STEPS
            if interrupted():
                status, reason = INTERRUPTED, FAILED_STOP
                break
        if radau5.failed(stiff):
            break
        next_sample = u[TIME] if save_kind == SAVE_STEPS else (
            times[i_time] if save_kind == SAVE_TIMES and i_time < times.shape[0] else math.inf)
        stats[STAT_MAX_FORCE], stats[STAT_MAX_INDENTATION] = max_force, max_indentation
        result, s, h, h_abs, h_next, force, force_new, d_steps, d_fev = _advance(
            code, c, mode, side, s, t_end, u, fu, y, f, force, h_abs, rtol, atol_u, max_step, flight_step, w_floor,
            energy_limit, next_sample, min(max_steps, next_poll) - nsteps, g_old, g_new, fired, K6, u_new, fu_new,
            y_new, f_new, stats, stiff)
        max_force, max_indentation = stats[STAT_MAX_FORCE], stats[STAT_MAX_INDENTATION]
        nsteps += d_steps
        nfev += d_fev
        if result == _ADV_END:
            break
        if result == _ADV_COLLAPSE:
            status, reason = STEP_SIZE_COLLAPSE, FAILED_STOP
            break
        if result == _ADV_LIMIT:
            if nsteps < max_steps:
                continue  # at next_poll
            status, reason = TOO_MANY_STEPS, FAILED_STOP
            break
        # a step to look at (an event fired in it, a sample or the horizon falls in it); not accepted yet
        s_new = s + h
        any_fired = False
        for col in range(N_EVENTS):
            any_fired = any_fired or fired[col]
        have_dense = False
        stop_record = -1.0
        restart_col = np.int64(-1)
        s_restart = math.inf
        s_horizon = math.inf
        if regularised(side) and u_new[TIME] >= t_end:
            nfev += _interpolant(code, c, mode, side, u, fu, u_new, fu_new, h, K6, F6, tmp6, stiff)
            have_dense = True
            s_horizon = s_at_time(code, c, mode, side, F6, u, s, h, t_end, us, ys, fs)
        if any_fired:
            if not have_dense:
                nfev += _interpolant(code, c, mode, side, u, fu, u_new, fu_new, h, K6, F6, tmp6, stiff)
                have_dense = True
            unresolved, restart_col, s_restart, spent = _locate_events(
                code, c, mode, side, settle, energy_limit, s, h, s_horizon, u, fu, g_old, g_new, fired, roots, K6, F6,
                u_r, fu_r, stiff, us, ys, fs, gs)
            nfev += spent
            if unresolved:
                h_abs = h / 32.0  # an event left and re-crossed zero inside the step: resolve it
                continue
            if n_ev + N_EVENTS > ev.shape[0]:
                ev = _grow(ev, n_ev)  # a free row for each event _record may log
            stats[STAT_MAX_FORCE], stats[STAT_MAX_INDENTATION] = max_force, max_indentation
            n_ev, stop_record, spent = _record(code, c, mode, side, settle, stop_kind, stop_count, s, h, s_restart,
                                               fired, roots, u, fu, F6, K6, us, fu_r, stiff, ys, fs, ev, n_ev, counts,
                                               stats)
            max_force, max_indentation = stats[STAT_MAX_FORCE], stats[STAT_MAX_INDENTATION]
            nfev += spent
        if stop_record >= 0:
            # stopped at a recorded event: the state there from a fresh step that ends at it
            if stop_record > s:
                nfev += fresh_step(code, c, mode, side, s, u, fu, stop_record - s, K6, u_r, fu_r, stiff)
                copy_values(u_r, u)
                if not regularised(side):
                    u[TIME] = stop_record
            force = physical(code, c, mode, side, u, y, f)
            reason = ASKED_STOP
            break
        if save_kind == SAVE_TIMES:
            # samples up to where this step's motion stands: its end, the restart or the horizon
            t_seg = u_new[TIME]
            if restart_col >= 0:
                dense(c, side, F6, u, s, h, s_restart, us)
                t_seg = s_restart if not regularised(side) else us[TIME]
            elif s_horizon < math.inf:
                t_seg = t_end
            while i_time < times.shape[0] and times[i_time] <= t_seg:
                if not have_dense:
                    nfev += _interpolant(code, c, mode, side, u, fu, u_new, fu_new, h, K6, F6, tmp6, stiff)
                    have_dense = True
                s_i = s_at_time(code, c, mode, side, F6, u, s, h, times[i_time], us, ys, fs)
                dense(c, side, F6, u, s, h, s_i, us)
                f_i = physical(code, c, mode, side, us, ys, fs)
                smp, n_s = push_sample(smp, n_s, times[i_time], ys, mode, f_i)
                i_time += 1
        if restart_col < 0 and s_horizon < math.inf:
            # a regularised phase reaches the horizon inside the step: the state there from a fresh step
            nfev += fresh_step(code, c, mode, side, s, u, fu, s_horizon - s, K6, u_r, fu_r, stiff)
            copy_values(u_r, u)
            u[TIME] = t_end  # without the root finder's residue
            force = physical(code, c, mode, side, u, y, f)
            max_force = max(max_force, force)
            max_indentation = max(max_indentation, y[X1] - y[X2])
            if save_kind == SAVE_STEPS:
                smp, n_s = push_sample(smp, n_s, t_end, y, mode, force)
            break
        if restart_col >= 0:
            kind, mode, action, side, s, t, h_abs, force, pair_energy, spent = _restart(
                code, c, settle, restart_col, mode, side, s, s_restart, h_next, u, fu, u_r, fu_r, y_r, f_r, y, f, K6,
                stiff, rtol, atol, atol_u, t_end, max_step, w_floor, tmp6, fu_new, pair_energy)
            nfev += spent
            if kind == SILENT:  # a restart only (the pair at its centre): nothing to log
                quiet = restart_col
                phase_events(code, c, mode, side, energy_limit, u, y, f, force, g_old)
                _quiet_start(quiet, y, mode, g_old)
                continue
            ev, n_ev = push_event(ev, n_ev, t, kind, mode, y, force)
            counts[kind] += 1
            max_force = max(max_force, force)
            max_indentation = max(max_indentation, y[X1] - y[X2])
            if save_kind == SAVE_STEPS:
                smp, n_s = push_sample(smp, n_s, t, y, mode, force)
            if action == STOP_SETTLED:
                reason = SETTLED_STOP
                break
            if action == STOP_RUNAWAY:
                reason = RUNAWAY_STOP
                break
            if kind == stop_kind and counts[kind] >= stop_count:
                reason = ASKED_STOP
                break
            quiet = restart_col
            phase_events(code, c, mode, side, energy_limit, u, y, f, force, g_old)
            _quiet_start(quiet, y, mode, g_old)
            continue
        # the whole step stands
        s = s_new
        copy_values(u_new, u)
        copy_values(fu_new, fu)
        copy_values(y_new, y)
        copy_values(f_new, f)
        force = force_new
        copy_values(g_new, g_old)
        h_abs = h_next
        max_force = max(max_force, force)
        max_indentation = max(max_indentation, y[X1] - y[X2])
        if save_kind == SAVE_STEPS:
            smp, n_s = push_sample(smp, n_s, u[TIME], y, mode, force)

    if radau5.failed(stiff):  # a step to a root did not converge: what follows it is not the motion
        status, reason = STEP_SIZE_COLLAPSE, FAILED_STOP
    t = u[TIME]

    summary = summarize(code, c, y0, y, mode, status, reason, t, max_force, max_indentation, counts,
                         n_ev, ev, nsteps, nfev)
    return summary, ev[:n_ev], smp[:n_s], y


@allocating
def summarize(code, c, y0, y, mode, status, reason, t_stop, max_force, max_indentation, counts,
               n_ev, ev, nsteps, nfev):
    """The summary vector of a run (indices ``S_*``); undefined entries are NaN."""
    s = np.full(N_SUMMARY, np.nan)
    s[S_STATUS] = status
    s[S_REASON] = reason
    s[S_T_STOP] = t_stop
    s[S_MAX_FORCE] = max_force
    s[S_MAX_INDENTATION] = max_indentation
    s[S_DISSIPATED] = energy(code, c, y0) - energy(code, c, y)
    s[S_LOOP_AREA] = y[WORK] - y0[WORK]
    s[S_N_STICK] = counts[STICK]
    s[S_N_CONTACTS] = counts[CONTACT]
    s[S_NSTEPS] = nsteps
    s[S_NFEV] = nfev
    s[S_MODE] = mode
    first_contact = -1
    first_stick = -1
    for i in range(n_ev):
        kind = int(ev[i, EV_KIND])
        if kind == CONTACT and first_contact < 0:
            first_contact = i
        elif kind == SEPARATION and first_contact >= 0 and math.isnan(s[S_CONTACT_DURATION]):
            s[S_CONTACT_DURATION] = ev[i, EV_T] - ev[first_contact, EV_T]
            dd0 = ev[first_contact, EV_Y + V1] - ev[first_contact, EV_Y + V2]
            if dd0 != 0:
                s[S_RESTITUTION] = -(ev[i, EV_Y + V1] - ev[i, EV_Y + V2]) / dd0
        if kind == STICK and first_stick < 0:
            first_stick = i
            s[S_FIRST_STICK_T] = ev[i, EV_T]
            s[S_FIRST_STICK_DELTA] = ev[i, EV_Y + X1] - ev[i, EV_Y + X2]
            s[S_FIRST_STICK_MARGIN] = stick_margin(code, c, ev[i, EV_Y:EV_Y + 5])
        if kind == SEPARATION and first_stick >= 0 and math.isnan(s[S_T_RUN]):
            s[S_T_RUN] = ev[i, EV_T]
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
    return s


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


@allocating(python=True, nogil=True)
def run_block(code, C, Y0, t_end, rtol, ATOL, max_step, settle, stop_kind, stop_count, max_steps, max_events,
              stiff_after, start, stop, step, summary, st_t, st_delta, st_dwell, st_count):
    """Runs ``start, start + step, ...`` (below ``stop``) of a batch, without the GIL (callers run
    blocks in threads; each run's numbers depend on nothing else). Fills ``summary`` (n, N_SUMMARY)
    and the first ``capacity`` stick points of each run; ``st_count`` holds each run's full number
    of stick points. Threads over blocks, not a compiled parallel loop: that would compile the
    driver a second time. A thread's block is every ``step``-th run, not a contiguous range: the
    cost of a run changes smoothly over a sweep or an atlas (many times over near kappa_c), so
    interleaved blocks cost the same to within one run, where contiguous ones left a thread idle
    while another finished an expensive stretch. On Ctrl-C or SIGTERM the rest of the block is
    left with the status ``interrupted``."""
    empty = np.empty(0)
    c = np.empty(C.shape[1])
    y0 = np.empty(Y0.shape[1])
    atol = np.empty(ATOL.shape[1])
    done = 0
    for i in range(start, stop, step):
        done += 1
        if done % POLL_RUNS == 0 and interrupted():
            for j in range(i, stop, step):
                summary[j, S_STATUS] = INTERRUPTED
            break
        # the run reads its own copies: a row of the shared batch arrays would share their reference
        # count, which run (an allocating function) updates, between the threads (a contended cache line)
        copy_values(C[i], c)
        copy_values(Y0[i], y0)
        copy_values(ATOL[i], atol)
        s, events, _, _ = _run(code, c, y0, t_end[i], rtol, atol, max_step[i], settle, stop_kind, stop_count,
                               np.int64(SAVE_SUMMARY), empty, max_steps, max_events, stiff_after)
        copy_values(s, summary[i])
        permanent = s[S_OUTCOME] == PERMANENT_STICK
        st_count[i] = stick_points(events, s[S_T_STOP], permanent, st_t[i], st_delta[i], st_dwell[i])
        if s[S_STATUS] == INTERRUPTED:
            for j in range(i + step, stop, step):
                summary[j, S_STATUS] = INTERRUPTED
            break


