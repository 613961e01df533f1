"""A step of the hybrid loop (:mod:`.driver`) and the events in it: compiled kernels that read and
write one run's workspace (:mod:`.record`) and allocate nothing.

:func:`advance` takes steps while nothing happens: adaptive DOP853 (:mod:`.dop853`), Radau IIA for
the rest of a phase whose DOP853 steps stay at their stability limit (:mod:`.radau5`), a flight in
closed form (:mod:`.flight`); :func:`phase_step` is a phase's first step and
:func:`step_interpolant` the dense output of the step :func:`advance` left. :func:`locate_events`
locates the events that fired in that step on its interpolant (:mod:`.rootfind`; Radau's roots
then polished on steps), :func:`record_events` logs the recorded ones (:mod:`.logs`), and
:func:`restart` restarts the run at the first that changes the phase: the state from a fresh step
that ends exactly at the root, the transition (:mod:`.events`) and the new phase;
:func:`quiet_start` sets the event values a phase starts from. The loop that calls them and the
entries are in :mod:`.driver`.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import kernel
from ..model.rhs import (
    FLIGHT,
    RIGID_,
    SPRINGS_,
    V1,
    V2,
    X1,
    X2,
    contact_side,
    damping_rate,
    onto_stuck_orbit,
    relative_slip,
    rhs,
    rhs_integration,
    stuck_pair_energy,
)
from . import dop853, flight, radau5
from .events import (
    DELTA,
    DELTADOT,
    ENERGY,
    FORCE_PEAK,
    FORCE_RATE,
    N_EVENTS,
    REACH,
    REVERSAL,
    SETTLED,
    STICK,
    STICK_BREAK,
    crossed,
    departure_sign,
    restarts,
    transition,
)
from .logs import log_event
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
from .record import (
    G_NEW,
    G_OLD,
    G_ROOTS,
    I_MODE,
    I_NFEV,
    I_SETTLE,
    I_SIDE,
    I_STOP_COUNT,
    I_STOP_KIND,
    R_ENERGY_LIMIT,
    R_FLIGHT_STEP,
    R_FORCE,
    R_FORCE_NEW,
    R_H,
    R_H_ABS,
    R_H_NEXT,
    R_MAX_STEP,
    R_PAIR_ENERGY,
    R_RTOL,
    R_S,
    R_T_END,
    R_W_FLOOR,
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
    U_TMP,
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
    W_STIFF,
    W_U,
    W_Y,
    Y_F,
    Y_F_NEW,
    Y_F_ROOT,
    Y_F_TRIAL,
    Y_NEW,
    Y_ROOT,
    Y_STATE,
    Y_TRIAL,
)
from .rootfind import brent, locate, polish_root
from .spacing import ulp_above

#: Smallest step reduction after a rejection when the observed order is used (else MIN_FACTOR).
OBSERVED_MIN_FACTOR = 0.01
_TINY = np.finfo(np.float64).tiny

ADV_END, ADV_STEP, ADV_COLLAPSE, ADV_LIMIT, ADV_NEEDS_RADAU = range(5)


@kernel
def quiet_start(quiet, y, mode, g):
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


@kernel(forceinline=True)  # the hot loop's own code: a call costs more than it
def _dop853_attempt(code, ws, s, s_bound, h_abs):
    """One accepted DOP853 step from ``(s, u)`` (row ``U_U``; at most to ``s_bound``) into rows
    ``U_NEW``, ``U_FU_NEW``, first try ``h_abs``.

    Returns ``(ok, s_new, h_next, force_new, evaluations)``; ``ok`` False when the step size
    collapsed. The stages stay in rows ``U_STAGES`` for the interpolant.
    """
    c, ints, ur, rtol = ws[W_C], ws[W_INT], ws[W_U], ws[W_REAL][R_RTOL]
    mode, side, u, fu, atol, K, u_new, fu_new = (ints[I_MODE], ints[I_SIDE], ur[U_U], ur[U_FU], ur[U_ATOL],
                                                 ur[U_STAGES:U_DENSE], ur[U_NEW], ur[U_FU_NEW])
    evaluations = 0
    rejected = False
    h_rejected = err_rejected = 0.0
    while True:
        if not h_abs >= 10.0 * ulp_above(s):  # a NaN step (from a NaN rate) collapses too: never a loop without end
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
def advance(code, ws, next_sample, steps_left):
    """Take steps in ``s`` from the run's state (record ``R_S``, rows ``U_U``, ``U_FU``, ``Y_STATE``,
    ``Y_F``) while nothing happens: no event crosses, no sample (``next_sample``) and (regularised
    phase) not the horizon falls inside; at most ``steps_left``. Accepted steps update those rows,
    ``G_OLD`` and the running extremes ``W_STATS``. DOP853 until the phase turns stiff (:mod:`.radau5`), Radau
    from then on; a flight in closed form (:mod:`.flight`), in steps that end where the target
    passes its centre or after ``flight_step``, or to ``t_end`` at once when no event can happen
    any more and ``flight_step`` is inf (not saving steps).

    Returns ``(result, steps, evaluations)``, and ``s, h, h_abs, h_next, force, force_new`` in the
    record (:func:`_advanced`): ``ADV_STEP`` leaves the last step (``R_H``, rows ``U_NEW``,
    ``U_FU_NEW``, ``Y_NEW``, ``Y_F_NEW``, ``G_NEW``, ``fired``) for the caller to look at;
    ``ADV_END`` means ``t_end`` was reached. The hot loop is kept small and its state in local
    variables on purpose: the compiler optimises it as a whole.
    """
    real, ints, c, ur, yr, g, stats, stiff = (ws[W_REAL], ws[W_INT], ws[W_C], ws[W_U], ws[W_Y], ws[W_G],
                                              ws[W_STATS], ws[W_STIFF])
    mode, side, s, t_end, force, h_abs = ints[I_MODE], ints[I_SIDE], real[R_S], real[R_T_END], real[R_FORCE], \
        real[R_H_ABS]
    max_step, w_floor, energy_limit = real[R_MAX_STEP], real[R_W_FLOOR], real[R_ENERGY_LIMIT]
    u, fu, u_new, fu_new = ur[U_U], ur[U_FU], ur[U_NEW], ur[U_FU_NEW]
    y, f, y_new, f_new, g_old, g_new, fired = yr[Y_STATE], yr[Y_F], yr[Y_NEW], yr[Y_F_NEW], g[G_OLD], g[G_NEW], \
        ws[W_FIRED]
    steps = 0
    evaluations = 0
    h = 0.0
    h_next = h_abs
    force_new = force
    s_bound = t_end if not regularised(side) else math.inf  # a plain phase ends on the horizon
    while u[TIME] < t_end:
        if steps >= steps_left:
            _advanced(real, s, h, h_abs, h_next, force, force_new)
            return ADV_LIMIT, steps, evaluations
        if side == FLIGHT:
            ok, s_new, h_next, force_new, spent = _flight_attempt(code, ws, s, s_bound, h_abs)
        else:
            # a regularised phase advances the time by w ds: its cap on the time step is one on s
            h_abs = min(h_abs, max_step if not regularised(side) else max_step / max(abs(u[0]), w_floor))
            if radau5.due(stiff):  # entered from an accepted state, so that every step has one method
                if ws[W_RADAU] is None:  # an engine compiled without Radau: the caller runs this again with it
                    _advanced(real, s, h, h_abs, h_next, force, force_new)
                    return ADV_NEEDS_RADAU, steps, evaluations
                evaluations += radau5.enter(code, c, mode, side, u, fu, real[R_RTOL], ur[U_ATOL], ws[W_RADAU])
            if radau5.active(stiff):
                ok, s_new, h_next, force_new, spent = radau5.attempt(code, c, mode, side, s, s_bound, h_abs,
                                                                     ws[W_RADAU], (u, fu, u_new, fu_new))
            else:
                ok, s_new, h_next, force_new, spent = _dop853_attempt(code, ws, s, s_bound, h_abs)
        evaluations += spent
        if not ok:
            _advanced(real, s, h, h_next, h_next, force, force_new)
            return ADV_COLLAPSE, steps, evaluations
        h = s_new - s
        steps += 1
        force_new, spent = _step_end(code, ws, s_new, force_new)
        evaluations += spent
        if side != FLIGHT and not radau5.active(stiff):
            radau5.watch(stiff, h * damping_rate(code, c, u_new, mode, side))
        phase_events(code, c, mode, side, energy_limit, u_new, y_new, f_new, force_new, g_new)
        any_fired = False
        for col in range(N_EVENTS):
            fired[col] = crossed(col, g_old, g_new)
            any_fired = any_fired or fired[col]
        if any_fired or u_new[TIME] >= next_sample or (regularised(side) and u_new[TIME] >= t_end):
            _advanced(real, s, h, h_abs, h_next, force, force_new)
            return ADV_STEP, steps, evaluations
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
    _advanced(real, s, h, h_abs, h_next, force, force_new)
    return ADV_END, steps, evaluations


@kernel(forceinline=True)  # the hot loop's own code, like the two below
def _flight_attempt(code, ws, s, s_bound, h_abs):
    """A flight's step (closed form, the flight's invariants in rows ``U_STAGES``), as
    :func:`_dop853_attempt` returns it: to ``s_bound`` at once when no event can happen any more
    and no step is kept, else at most ``R_FLIGHT_STEP`` and to the target's next pass through its
    centre."""
    c, ints, ur, flight_step = ws[W_C], ws[W_INT], ws[W_U], ws[W_REAL][R_FLIGHT_STEP]
    u, u_new, K = ur[U_U], ur[U_NEW], ur[U_STAGES:U_DENSE]
    if flight_step == math.inf and flight.unreachable(K, u):
        s_new = s_bound
    else:
        s_new = min(s + min(h_abs, flight_step), s_bound, flight.next_centre(K, s))
    flight.state_at(c, K, u, s, s_new, u_new)
    force_new = rhs_integration(code, c, u_new, ints[I_MODE], ints[I_SIDE], ur[U_FU_NEW])
    return True, s_new, flight_step, force_new, 0


@kernel(forceinline=True)
def _step_end(code, ws, s_new, force_new):
    """The physical state and rate at a step's end (rows ``Y_NEW``, ``Y_F_NEW`` from ``U_NEW``,
    ``U_FU_NEW``); returns ``(force, evaluations)``."""
    c, ints, ur, yr = ws[W_C], ws[W_INT], ws[W_U], ws[W_Y]
    mode, side, u_new, fu_new, y_new, f_new = ints[I_MODE], ints[I_SIDE], ur[U_NEW], ur[U_FU_NEW], yr[Y_NEW], \
        yr[Y_F_NEW]
    if regularised(side):
        return physical(code, c, mode, side, u_new, y_new, f_new), 1
    u_new[TIME] = s_new  # t' = 1: the time is s itself, without the sum's rounding
    for j in range(5):
        y_new[j] = u_new[j]
        f_new[j] = fu_new[j]
    if relative_slip(code, mode, side):
        y_new[V1] = u_new[V1] + u_new[V2]
        f_new[V1] = fu_new[V1] + fu_new[V2]
    return force_new, 0


@kernel(forceinline=True)
def _advanced(real, s, h, h_abs, h_next, force, force_new):
    """Where :func:`advance` stands, into the run's record."""
    real[R_S], real[R_H], real[R_H_ABS], real[R_H_NEXT], real[R_FORCE], real[R_FORCE_NEW] = (
        s, h, h_abs, h_next, force, force_new)


@kernel(forceinline=True)
def phase_step(code, ws):
    """Initial step of the run's phase (scipy's rule; the record's mode and side, rows ``U_U``,
    ``U_FU``, ``U_ATOL``), in its own independent variable."""
    real, ints, ur = ws[W_REAL], ws[W_INT], ws[W_U]
    mode, side, u, t_end, max_step, w_floor = ints[I_MODE], ints[I_SIDE], ur[U_U], real[R_T_END], real[R_MAX_STEP], \
        real[R_W_FLOOR]
    interval = t_end - u[TIME]
    if interval <= 0:
        return 0.0  # the phase starts on the horizon (an event at t_end): no step follows
    if side == FLIGHT:
        return interval  # closed form: its steps only bracket events (see advance)
    if regularised(side):
        interval /= max(abs(u[0]), w_floor)
    cap = max_step if not regularised(side) else max_step / max(abs(u[0]), w_floor)
    return dop853.initial_step(code, ws[W_C], mode, side, u, ur[U_FU], (real[R_RTOL], ur[U_ATOL]), (interval, cap),
                               (ur[U_TMP], ur[U_FU_NEW]))


@kernel(forceinline=True)
def locate_events(code, ws, s_horizon):
    """Locate the events that fired in the step ``[s, s + h]`` (record ``R_S``, ``R_H``) on its
    interpolant: their roots into row ``G_ROOTS`` (``fired`` cleared where the crossing did not
    happen or falls after the horizon ``s_horizon``), and the first root that restarts the run
    (polished on steps when the step was Radau's). Returns ``(unresolved, restart_col, s_restart,
    evaluations)``: ``unresolved`` when an event left and re-crossed zero inside the step (the
    caller retries a smaller step); ``restart_col`` -1 when no event restarts the run."""
    ints, g, fired = ws[W_INT], ws[W_G], ws[W_FIRED]
    mode, s, h = ints[I_MODE], ws[W_REAL][R_S], ws[W_REAL][R_H]
    g_old, g_new, roots = g[G_OLD], g[G_NEW], g[G_ROOTS]
    evaluations = 0
    restart_col = np.int64(-1)
    s_restart = math.inf
    unresolved = False
    for col in range(N_EVENTS):
        if fired[col]:
            roots[col] = locate(code, ws, col, g_old[col], g_new[col])
            if roots[col] == -math.inf:
                if h > 1e3 * ulp_above(s):
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
        d_ext = event_at(code, ws, np.int64(DELTA), 0.0, roots[DELTADOT])
        if d_ext * g_old[DELTA] < 0:
            fired[DELTA] = True
            roots[DELTA] = brent(code, ws, np.int64(DELTA), 0.0, s, roots[DELTADOT], g_old[DELTA], d_ext)
    for col in range(N_EVENTS):
        if fired[col] and (restarts(code, col, mode, ints[I_SETTLE] != 0) or col == ENERGY) and roots[col] < s_restart:
            restart_col, s_restart = col, roots[col]
    if restart_col >= 0 and radau5.active(ws[W_STIFF]):
        s_restart, spent = polish_root(code, ws, restart_col, g_old[restart_col], g_new[restart_col], s_restart)
        evaluations += spent
    return False, restart_col, s_restart, evaluations



@kernel(forceinline=True)
def record_events(code, ws, ev, s_restart):
    """Log the recorded events (force peaks, reversals, reach) that fired in the step up to
    ``s_restart``, in time order (:func:`log_event`; ``ev`` has a free row for each event column);
    the running extremes follow them. Returns ``(stop_record, evaluations)``: ``stop_record`` is the
    root of the event the run was asked to stop at (-1 if none)."""
    ints, c, ur, yr, fired, stiff, counts, stats = (ws[W_INT], ws[W_C], ws[W_U], ws[W_Y], ws[W_FIRED], ws[W_STIFF],
                                                    ws[W_COUNTS], ws[W_STATS])
    mode, side, settle, s, h = ints[I_MODE], ints[I_SIDE], ints[I_SETTLE] != 0, ws[W_REAL][R_S], ws[W_REAL][R_H]
    roots, u, us, ys, fs = ws[W_G][G_ROOTS], ur[U_U], ur[U_TRIAL], yr[Y_TRIAL], yr[Y_F_TRIAL]
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
            evaluations += fresh_step(code, ws, roots[best] - s, us, ur[U_FU_ROOT])
        else:
            dense(c, side, ur[U_DENSE:], u, s, h, roots[best], us)
        f_ev = physical(code, c, mode, side, us, ys, fs)
        kind = FORCE_PEAK if best == FORCE_RATE else REVERSAL
        if best == REACH:
            kind = SETTLED  # recorded only: the run goes on
        t_ev = us[TIME] if regularised(side) else roots[best]
        log_event(ws, ev, t_ev, kind, mode, ys, f_ev)
        stats[STAT_MAX_FORCE] = max(stats[STAT_MAX_FORCE], f_ev)
        stats[STAT_MAX_INDENTATION] = max(stats[STAT_MAX_INDENTATION], ys[X1] - ys[X2])
        if kind == ints[I_STOP_KIND] and counts[kind] >= ints[I_STOP_COUNT]:
            stop_record = roots[best]
            break
    return stop_record, evaluations

@kernel(forceinline=True)
def restart(code, ws, column, s_restart):
    """Restart the run at the root ``s_restart`` of event ``column``: the state there from a fresh
    step that ends there (the stages beyond the root belong to the continuation, not to the
    motion), the transition, and the new phase in the record (mode, side, ``s``, first step, force)
    and in rows ``U_U``, ``U_FU``, ``Y_STATE``, ``Y_F``, ``U_ATOL`` (``U_STAGES``: a flight's
    invariants). Returns ``(kind, action, t)``."""
    real, ints, c, ur, yr, stiff = ws[W_REAL], ws[W_INT], ws[W_C], ws[W_U], ws[W_Y], ws[W_STIFF]
    mode, side, s = ints[I_MODE], ints[I_SIDE], real[R_S]
    u, fu, u_r, K = ur[U_U], ur[U_FU], ur[U_ROOT], ur[U_STAGES:U_DENSE]
    y, f, y_r = yr[Y_STATE], yr[Y_F], yr[Y_ROOT]
    evaluations = 0
    h_r = s_restart - s
    if h_r > 0:
        evaluations += fresh_step(code, ws, h_r, u_r, ur[U_FU_ROOT])
    else:
        copy_values(u, u_r)
    t = s_restart if not regularised(side) else u_r[TIME]
    physical(code, c, mode, side, u_r, y_r, yr[Y_F_ROOT])
    if column == STICK_BREAK and c[SPRINGS_] > 0 and c[RIGID_] == 0:
        onto_stuck_orbit(c, real[R_PAIR_ENERGY], y_r)
    kind, mode, action = transition(code, c, column, y_r, mode, ints[I_SETTLE] != 0)
    if kind == STICK:
        real[R_PAIR_ENERGY] = stuck_pair_energy(c, y_r)
    copy_values(y_r, y)
    real[R_FORCE] = rhs(code, c, y, mode, f)
    new_side = contact_side(code, c, y, mode)
    integration_state(code, mode, new_side, y, t, u)
    s = t if not regularised(new_side) else 0.0
    rhs_integration(code, c, u, mode, new_side, fu)
    evaluations += 2
    radau5.reset(stiff)  # a new phase starts explicit
    phase_tolerances(code, mode, new_side, ws[W_ATOL], ur[U_ATOL])
    if new_side != side:  # the independent variable changes: a fresh initial step
        side = new_side
        ints[I_MODE], ints[I_SIDE] = mode, side
        h_abs = phase_step(code, ws)
        evaluations += 1
    else:
        h_abs = max(real[R_H_NEXT], h_r)
    if side == FLIGHT:
        flight.coefficients(c, u, s, K)
    ints[I_MODE], ints[I_SIDE], ints[I_NFEV] = mode, side, ints[I_NFEV] + evaluations
    real[R_S], real[R_H_ABS] = s, h_abs
    return kind, action, t


# always inlined, like fresh_step: with their flight branch LLVM's own heuristics stopped inlining
# these small dispatchers into the run, which cost runs without a flight 5-9 %
@kernel(forceinline=True)
def step_interpolant(code, ws):
    """The interpolant of the step :func:`advance` left into rows ``U_DENSE`` (a flight's
    invariants, see :func:`~.phase.dense`); returns the evaluations spent."""
    ints, ur, stiff = ws[W_INT], ws[W_U], ws[W_STIFF]
    side, K, F = ints[I_SIDE], ur[U_STAGES:U_DENSE], ur[U_DENSE:]
    if side == FLIGHT:
        copy_values(K[0], F[0])  # the flight's invariants
        return 0
    if radau5.active(stiff):
        radau5.dense_coefficients(ws[W_RADAU], F)
        return 0
    dop853.dense_coefficients(code, ws[W_C], ints[I_MODE], side, ur[U_U], ur[U_FU], ur[U_NEW], ur[U_FU_NEW],
                              ws[W_REAL][R_H], K, F, ur[U_TMP])
    return 3
