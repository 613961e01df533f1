"""The kernels of one phase of a run, shared by the loop (:mod:`.driver`) and the root finders
(:mod:`.rootfind`): the integration state of a phase and its physical state, the step's dense
output, the event values on it, and a step of exactly a given size with the phase's method.

A plain phase integrates ``u = (x1, x2, v1, v2, W, t)`` in ``s = t``; a regularised contact phase
(``side`` +-1) integrates ``u = (w, x2, v1, v2, W, t)`` in ``s`` with ``dt = w ds``
(:func:`~phaseimpact.model.rhs.rhs_integration`).
"""

from __future__ import annotations

import math

from .._jit import kernel
from ..model.forms import dent_depth
from ..model.rhs import FLIGHT, V1, V2, WORK, X1, X2, relative_slip, rhs, rhs_integration
from . import dop853, flight, radau5
from .events import DELTA, DELTADOT, FORCE_RATE, N_EVENTS, event_value, event_values
from .record import (
    I_MODE,
    I_SIDE,
    R_ENERGY_LIMIT,
    R_H,
    R_S,
    U_DENSE,
    U_FU,
    U_STAGES,
    U_TRIAL,
    U_U,
    W_C,
    W_INT,
    W_RADAU,
    W_REAL,
    W_STIFF,
    W_U,
    W_Y,
    Y_F_TRIAL,
    Y_TRIAL,
)

TIME = 5  # the physical time in the integration state u
TIME_COLUMN = N_EVENTS  # a pseudo event column: the physical time minus a target
#: Absolute tolerance of ``deltadot`` in a slip, relative to that of the velocities (which is
#: rtol times the impact speed). A slip's own speed near the critical damping is 1e-7 to 1e-12 of
#: the impact speed, and its sign decides whether the slip re-sticks. 1e-3 is the largest power of
#: ten that counts the seed case at v = 7 m/s, kappa = 4.16865e11 right (4 stick phases; 1e-2 gives
#: 2); it costs a stiff creep far above kappa_c about five times the Radau steps (161 -> 777).
SLIP_SPEED_SCALE = 1e-3


# Copies go element by element on purpose: a slice or row assignment makes numba compile its
# shape-mismatch error messages (string formatting), which was half of the first-ever compile.
# The length comes from dst, not from an argument: a constant argument (5, N_STATE) would
# compile a copy of the function for each value.
@kernel
def copy_values(src, dst):
    """``dst[:] = src[:len(dst)]``."""
    for j in range(dst.shape[0]):
        dst[j] = src[j]


@kernel
def regularised(side):
    """A contact phase integrated in w = sqrt(|delta|) and dt = w ds (side +-1)."""
    return side == 1 or side == -1


@kernel(forceinline=True)
def physical_state(code, mode, side, u, y):
    """Physical state ``y`` at the integration state ``u``."""
    y[X1] = u[X1] if not regularised(side) else u[X2] + side * u[0] * u[0]
    for j in range(1, 5):
        y[j] = u[j]
    if relative_slip(code, mode, side):
        y[V1] = u[V1] + u[V2]


@kernel(forceinline=True)
def physical(code, c, mode, side, u, y, f):
    """Physical state ``y`` and ``dy/dt`` (``f``) at the integration state ``u``; returns the force."""
    physical_state(code, mode, side, u, y)
    return rhs(code, c, y, mode, f)


@kernel
def integration_state(code, mode, side, y, t, u):
    """The integration state of a phase on ``side`` (see :func:`~phaseimpact.model.rhs.rhs_integration`)."""
    u[X1] = y[X1] if not regularised(side) else math.sqrt(abs(y[X1] - y[X2]))
    for j in range(1, 5):
        u[j] = y[j]
    if relative_slip(code, mode, side):
        u[V1] = y[V1] - y[V2]
    u[TIME] = t


@kernel(forceinline=True)  # in the root finders' loops: a call costs more than it
def dense(c, side, F, u0, s0, h, s, out):
    """The integration state at ``s`` inside the step ``[s0, s0 + h]`` from ``u0``: the flight's
    closed form, or the interpolant ``F`` of the step (:func:`_interpolant`)."""
    if side == FLIGHT:
        flight.state_at(c, F, u0, s0, s, out)
    else:
        dop853.dense_eval(F, u0, s0, h, s, out)


@kernel
def phase_tolerances(code, mode, side, atol, out):
    """Absolute tolerances of the integration state: ``atol`` is (x1, x2, v1, v2, W, t, w).

    A :func:`relative_slip` phase controls ``deltadot`` relative to itself: its absolute
    tolerance is that of the velocities times :data:`SLIP_SPEED_SCALE`.

    The work ``W`` is a quadrature along the motion that feeds nothing back: it is left out of the
    step control (an infinite tolerance), as ODE codes do with quadratures. Controlled, it chose
    nearly every rejected step inside contact while the motion itself was far more accurate.
    """
    out[0] = atol[0] if not regularised(side) else atol[6]
    for j in range(1, 6):
        out[j] = atol[j]
    out[WORK] = math.inf
    if relative_slip(code, mode, side):
        out[V1] = atol[V1] * SLIP_SPEED_SCALE


@kernel
def phase_events(code, c, mode, side, energy_limit, u, y, f, force, g):
    """Event values at ``u`` (physical ``y``, ``f``, ``force``) into ``g``."""
    event_values(code, c, y, f, force, mode, energy_limit, g)
    if regularised(side) and dent_depth(code, c) == 0.0:  # past a dent the gap is not w: its value from y
        g[DELTA] = side * u[0]  # delta = side w^2 keeps its sign through its root; w changes sign there
    if relative_slip(code, mode, side):
        g[DELTADOT] = u[V1]  # as integrated: x1dot - x2dot of the physical state has lost its digits


# always inlined: the root finders call it ten times an event, and a call passes the whole
# workspace (a tuple of ~20 arrays, ~170 machine words): 6-8 % of a run (benchmarks/trajectory.py --against)
@kernel(forceinline=True)
def event_at(code, ws, column, target, s):
    """Event function ``column`` at ``s`` on the dense output of the run's step (``R_S``, ``R_H``
    from row ``U_U``, interpolant ``U_DENSE``); the pseudo column ``TIME_COLUMN`` is the physical
    time minus ``target`` (horizon and output times of a regularised phase, where ``t`` is a
    component of the state). The state is left in rows ``U_TRIAL`` and ``Y_TRIAL``; the
    right-hand side (``Y_F_TRIAL``) is evaluated only for the force's rate, the one event that
    reads it."""
    c, ints, ur, yr = ws[W_C], ws[W_INT], ws[W_U], ws[W_Y]
    mode, side, us, ys, fs = ints[I_MODE], ints[I_SIDE], ur[U_TRIAL], yr[Y_TRIAL], yr[Y_F_TRIAL]
    dense(c, side, ur[U_DENSE:], ur[U_U], ws[W_REAL][R_S], ws[W_REAL][R_H], s, us)
    if column == TIME_COLUMN:
        return us[TIME] - target
    if column == DELTA and regularised(side) and dent_depth(code, c) == 0.0:
        return side * us[0]  # delta = side w^2 keeps its sign through its root; w changes sign there
    if column == DELTADOT and relative_slip(code, mode, side):
        return us[V1]
    if column == FORCE_RATE:
        force = physical(code, c, mode, side, us, ys, fs)
    else:
        physical_state(code, mode, side, us, ys)
        force = math.nan
    return event_value(code, c, ys, fs, force, mode, ws[W_REAL][R_ENERGY_LIMIT], column)


# always inlined, like the two below: with their flight branch LLVM's own heuristics stopped
# inlining these small dispatchers into the run, which cost runs without a flight 5-9 %
@kernel(forceinline=True)
def fresh_step(code, ws, h, u_new, fu_new):
    """A step of exactly ``h`` from the run's state (``R_S``, row ``U_U``) with the phase's current
    method into ``u_new``, ``fu_new`` (the state at a root, a stop or the horizon); returns the
    evaluations spent."""
    c, ints, ur, stiff = ws[W_C], ws[W_INT], ws[W_U], ws[W_STIFF]
    mode, side, s, u, fu, K = ints[I_MODE], ints[I_SIDE], ws[W_REAL][R_S], ur[U_U], ur[U_FU], ur[U_STAGES:U_DENSE]
    if side == FLIGHT:
        flight.state_at(c, K, u, s, s + h, u_new)  # K: the flight's invariants
        rhs_integration(code, c, u_new, mode, side, fu_new)
        return 0
    if radau5.active(stiff):
        return radau5.fixed_step(code, c, mode, side, s, h, ws[W_RADAU], (u, fu, u_new, fu_new))
    dop853.step(code, c, mode, side, u, fu, h, K, u_new, fu_new)
    return 12
