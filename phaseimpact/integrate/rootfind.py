"""Root finders of the event functions on a step: Brent's method on the dense output, Newton's
on a flight's closed form, the first zero of an event in a step (:func:`locate`), where a
regularised phase reaches a given time, and Radau's roots polished on steps."""

from __future__ import annotations

import math

import numpy as np

from .._jit import kernel
from ..model.rhs import FLIGHT, M2_, RIGID_, V1, V2, X2, spring_force
from .events import DELTA, DELTADOT, REACH
from .phase import TIME, TIME_COLUMN, event_at, fresh_step, phase_events, physical, regularised
from .record import (
    G_TRIAL,
    I_MODE,
    I_SIDE,
    R_ENERGY_LIMIT,
    R_H,
    R_S,
    U_FU_ROOT,
    U_ROOT,
    U_U,
    W_C,
    W_G,
    W_INT,
    W_REAL,
    W_U,
    W_Y,
    Y_F_TRIAL,
    Y_TRIAL,
)

_EPS = np.finfo(np.float64).eps


@kernel(forceinline=True)
def brent(code, ws, column, target, xa, xb, fa, fb):
    """Zero of event ``column`` (:func:`~.phase.event_at`) in ``[xa, xb]`` (signs of ``fa``, ``fb``
    differ): scipy's brentq."""
    xpre, xcur, fpre, fcur = xa, xb, fa, fb
    xblk = fblk = spre = scur = 0.0
    xtol = 4.0 * _EPS * max(abs(xa), abs(xb))
    for _ in range(200):
        if fpre != 0 and fcur != 0 and (fpre < 0) != (fcur < 0):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        tol = 0.5 * (xtol + 4.0 * _EPS * abs(xcur))
        sbis = 0.5 * (xblk - xcur)
        if fcur == 0 or abs(sbis) < tol:
            return xcur
        if abs(spre) > tol and abs(fcur) < abs(fpre):
            if xpre == xblk:
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - tol):
                spre, scur = scur, stry
            else:
                spre = scur = sbis
        else:
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > tol else (tol if sbis > 0 else -tol)
        fcur = event_at(code, ws, column, target, xcur)
    return xcur


@kernel
def flight_rate(c, column, y):
    """The time derivative of event ``column`` in a flight, where ``delta``, ``deltadot`` and the
    reach test are the events that can fire (NaN for the others)."""
    if column == DELTA:
        return y[V1] - y[V2]
    if column == DELTADOT:
        return 0.0 if c[RIGID_] > 0 else spring_force(c, y[X2]) / c[M2_]  # -x2'', the projectile uniform
    if column == REACH:
        return -y[V1]  # -(x1 + A), the reach A constant in a flight
    return math.nan


@kernel(forceinline=True)
def flight_root(code, ws, column, a, b, fa, fb):
    """Zero of event ``column`` in ``[a, b]`` (signs of ``fa``, ``fb`` differ) of a flight: Newton's
    method on the closed form with the event's exact rate, kept inside the bracket (bisection
    where it would leave it). Three or four evaluations where Brent's method on the same bracket
    takes ten or more, each an elliptic function."""
    # converged when the Newton correction is below 1e-14 of the bracket: the next one would be
    # below rounding (quadratic convergence); the event values' own rounding keeps the correction
    # from shrinking to machine epsilon of s
    c, ys = ws[W_C], ws[W_Y][Y_TRIAL]
    tol = 1e-14 * (b - a) + 4.0 * _EPS * abs(b)
    x = a - fa * (b - a) / (fb - fa)
    for _ in range(100):
        g = event_at(code, ws, column, 0.0, x)
        if g == 0:
            return x
        left = (g < 0) == (fa < 0)
        if left:
            a, fa = x, g
        else:
            b, fb = x, g
        rate = flight_rate(c, column, ys)
        step = g / rate if rate != 0 else math.inf
        inward = step < 0 if left else step > 0  # towards the bracket's other end, where the root is
        if b - a <= tol or (inward and abs(step) <= tol):
            return x
        x -= step
        if not (a < x < b):
            x = 0.5 * (a + b)
    return x


@kernel(forceinline=True)
def locate(code, ws, column, g_start, g_end):
    """The first zero of event ``column`` in the run's step ``[s0, s1]`` on its dense output.

    A run that restarts on this event's zero (``g_start`` a signed tiny number) may leave it
    and come back within one step, as a brief slip does near a grazing stick break: the dense
    output is then sampled to find where the function has left zero, and the return is
    bracketed from there.
    """
    c, side, ys = ws[W_C], ws[W_INT][I_SIDE], ws[W_Y][Y_TRIAL]
    s0 = ws[W_REAL][R_S]
    s1 = s0 + ws[W_REAL][R_H]
    expected = 1.0 if g_start > 0 else -1.0
    a, ga, b, gb = s0, g_start, s1, g_end
    g0 = event_at(code, ws, column, 0.0, s0)
    if g0 * expected <= 0 and side == FLIGHT and column == DELTA:
        # a flight step holds at most one extremum of delta (flight.py): if delta left zero and
        # came back, it was away at that extremum, the zero of deltadot
        d0 = event_at(code, ws, np.int64(DELTADOT), 0.0, s0)
        d1 = event_at(code, ws, np.int64(DELTADOT), 0.0, s1)
        if not d0 * d1 < 0:
            return -math.inf
        a = flight_root(code, ws, np.int64(DELTADOT), s0, s1, d0, d1)
        ga = event_at(code, ws, column, 0.0, a)
        if ga * expected <= 0:
            return -math.inf
    elif g0 * expected <= 0:
        found_away = False
        prev = s0
        for i in range(1, 33):
            s = s0 + (s1 - s0) * i / 32.0
            gv = event_at(code, ws, column, 0.0, s)
            if not found_away:
                if gv * expected > 0:
                    found_away = True
                    a, ga = s, gv
            elif gv * expected <= 0:
                a, b, gb = prev, s, gv
                ga = event_at(code, ws, column, 0.0, a)
                break
            prev = s
        if not found_away:
            return -math.inf  # the excursion is below what the step resolves: the caller shrinks it
    if gb == 0 or ga * gb > 0:
        return b
    if side == FLIGHT and not math.isnan(flight_rate(c, column, ys)):
        return flight_root(code, ws, column, a, b, ga, gb)
    return brent(code, ws, column, 0.0, a, b, ga, gb)


@kernel(forceinline=True)
def s_at_time(code, ws, time):
    """Where on the run's step the physical time is ``time`` (it lies within the step): ``s``
    itself in a plain phase, a root of ``t(s)`` on the dense output in a regularised one."""
    if not regularised(ws[W_INT][I_SIDE]):
        return time
    s0 = ws[W_REAL][R_S]
    s1 = s0 + ws[W_REAL][R_H]
    fa = ws[W_U][U_U][TIME] - time
    if fa >= 0:
        return s0
    fb = event_at(code, ws, np.int64(TIME_COLUMN), time, s1)
    if fb <= 0:
        return s1
    return brent(code, ws, np.int64(TIME_COLUMN), time, s0, s1, fa, fb)


@kernel(forceinline=True)
def polish_root(code, ws, column, g_start, g_end, x):
    """Refine the root ``x`` of event ``column`` (found on the interpolant of the run's step
    ``[s, s_end]``) on steps from ``s`` that end at the trial points (Illinois' regula falsi).

    Radau's collocation polynomial is of order 3 between its end points: where an event crosses
    slowly (a creep coming to rest) its root could lie several per cent of the phase away. The
    end point of a step carries the method's full order. Returns ``(root, evaluations)``.
    """
    c, ints, ur, yr = ws[W_C], ws[W_INT], ws[W_U], ws[W_Y]
    u_r, fu_r, ys, fs = ur[U_ROOT], ur[U_FU_ROOT], yr[Y_TRIAL], yr[Y_F_TRIAL]
    mode, side, energy_limit, gs = ints[I_MODE], ints[I_SIDE], ws[W_REAL][R_ENERGY_LIMIT], ws[W_G][G_TRIAL]
    s = ws[W_REAL][R_S]
    s_end = s + ws[W_REAL][R_H]
    evaluations = 0
    a, fa, b, fb = s, g_start, s_end, g_end
    if not (fa * fb < 0 and a < x < b):
        return x, evaluations
    best, f_best = x, math.inf
    kept = 0
    for _ in range(40):
        evaluations += fresh_step(code, ws, x - s, u_r, fu_r)
        force = physical(code, c, mode, side, u_r, ys, fs)
        phase_events(code, c, mode, side, energy_limit, u_r, ys, fs, force, gs)
        fx = gs[column]
        if abs(fx) < f_best:
            best, f_best = x, abs(fx)
        if fx == 0:
            break
        if (fx < 0) == (fa < 0):
            a, fa = x, fx
            if kept == -1:
                fb *= 0.5  # the same end kept twice: Illinois' halving keeps the secant moving
            kept = -1
        else:
            b, fb = x, fx
            if kept == 1:
                fa *= 0.5
            kept = 1
        if b - a <= 1e-12 * (s_end - s) + 4.0 * _EPS * abs(b):
            break
        x = (a * fb - b * fa) / (fb - fa)
        if not (a < x < b):
            x = 0.5 * (a + b)
    return best, evaluations
