"""The state of one run: a workspace of fixed-size arrays with named rows, and the run's record
(its scalars) in two of them.

A run's whole state lives in a workspace: a tuple of views (:func:`carve`) of one float64 buffer
of :func:`workspace_size` numbers, its integer, flag and complex members viewed as such. The buffer
is made once per thread and chunk of runs by the host (:func:`.batch.run_batch`, which hands it to
:func:`.driver.run_block`), once per point of a GPU launch (:mod:`phaseimpact.cuda`), or once per
trajectory (:func:`workspace`, for :func:`.driver.run`), never inside the per-point kernels, which
allocate nothing: the form a GPU thread needs too (numba-cuda compiles tuples of arrays and
constant indices; it has no ``structref``). A scratch vector is a row of one array (an allocation
costs about 30 ns, a row nothing).
"""

from __future__ import annotations

import numpy as np
from numba import types
from numba.extending import overload

from .._jit import allocating, kernel
from . import radau5
from .dop853 import N_DENSE, N_STAGES, N_STATE
from .events import EVENT_KINDS, N_EVENTS

#: Event kinds (``events.EVENT_KINDS``): the length of a run's counts.
N_KINDS = len(EVENT_KINDS)
#: The summary vector's length (``driver.S_*``).
N_SUMMARY = 19

# Named rows of the workspace's arrays.
# Physical states (5 numbers): the rate at the state, a step's end state and rate, the state and rate
# at a root, and of the root finders; the run's state, its start and its first stick.
Y_F, Y_NEW, Y_F_NEW, Y_ROOT, Y_F_ROOT, Y_TRIAL, Y_F_TRIAL, Y_STATE, Y_START, Y_FIRST_STICK = range(10)
N_Y_ROWS = 10
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

# Members of the workspace tuple (numba indexes a tuple's members of different types by constants).
# W_STIFF: the controller of Radau's tuple (radau5.carve's member CTL), which watches for
# stiffness in every run; W_RADAU: the whole tuple where the engine is compiled with its stiff
# solver, None where it is not (:func:`carve`). Apart, so that an engine without the solver carries
# none of its arrays, and one with it carries them once (a tuple goes by value: each array costs
# the calls that take the workspace some seven LLVM parameters).
(W_REAL, W_INT, W_C, W_ATOL, W_Y, W_G, W_FIRED, W_U, W_STATS, W_COUNTS, W_SUMMARY, W_STICKS, W_STIFF,
 W_RADAU) = range(14)
# The run's record: its scalars (W_REAL) ...
(R_S, R_H, R_H_ABS, R_H_NEXT, R_FORCE, R_FORCE_NEW, R_T_END, R_RTOL, R_MAX_STEP, R_STIFF_AFTER, R_FLIGHT_STEP,
 R_W_FLOOR, R_ENERGY_LIMIT, R_PAIR_ENERGY, R_T_STOP, R_CONTACT_T, R_CONTACT_SPEED, R_CONTACT_DURATION, R_RESTITUTION,
 R_STICK_T, R_T_RUN) = range(21)
N_REAL = 21
# ... and its integers (W_INT): phase, counters, options, log lengths (I_N_EV counts the events
# also when no log is kept: I_LOGGING 0) and the stick points (I_N_STICK of them, those from
# I_OPEN_STICK on still waiting for their slip).
(I_MODE, I_SIDE, I_NSTEPS, I_NFEV, I_NEXT_POLL, I_TIME_INDEX, I_N_EV, I_N_S, I_STATUS, I_REASON, I_SETTLE,
 I_STOP_KIND, I_STOP_COUNT, I_SAVE_KIND, I_MAX_STEPS, I_MAX_EVENTS, I_N_STICK, I_OPEN_STICK, I_LOGGING,
 I_HAVE_DENSE) = range(20)
N_INT = 20
N_ATOL = 7  # absolute tolerances of (x1, x2, v1, v2, W, t, w)
# Rows of the stick points (W_STICKS): time, depth and dwell of each stick phase.
ST_T, ST_DELTA, ST_DWELL = range(3)


# Where the members lie in the buffer (float64 numbers), Radau's first (its complex members at even
# offsets: radau5.carve) and the members whose length depends on the law and the capacity last; the
# flags (bool) take one number per 8.
N_FIRED_NUMBERS = (N_EVENTS + 7) // 8
N_FIXED = (radau5.WORKSPACE_SIZE + N_REAL + N_INT + N_ATOL + N_Y_ROWS * 5 + N_G_ROWS * N_EVENTS + N_FIRED_NUMBERS
           + N_U_ROWS * N_STATE + N_STATS + N_KINDS + N_SUMMARY)

#: Where the rows of ``W_Y`` start in the buffer (a host reads a run's state from there: the GPU's launches).
Y_AT = radau5.WORKSPACE_SIZE + N_REAL + N_INT + N_ATOL


@kernel(python=True, forceinline=True)
def workspace_size(n_coef, capacity):
    """The float64 numbers of a workspace for ``n_coef`` coefficients and ``capacity`` stick points
    (even: consecutive workspaces in one array keep Radau's complex members aligned)."""
    size = N_FIXED + n_coef + 3 * capacity
    return size + size % 2


@kernel(inline="always")  # typed in each caller: its views are the caller's own (counted where it counts)
def carve(buf, n_coef, capacity, radau):
    """The workspace (members ``W_*``) as views of ``buf`` (:func:`workspace_size` numbers, zeros
    or a previous run's: every run sets what it reads); allocates nothing.

    ``radau`` None leaves the stiff solver out of the engine compiled for this workspace: its
    ``W_RADAU`` is None (:func:`radau_member`), numba prunes the branches on it and never compiles
    :mod:`.radau5`'s steps. A run that turns stiff then stops with the status ``NEEDS_RADAU``, and
    its caller runs it again in a workspace whose ``W_RADAU`` is Radau's tuple (``radau`` True;
    :func:`.api.radau_marker`): the same kernels up to the switch, so the same numbers."""
    o = radau5.WORKSPACE_SIZE
    stiff = radau5.carve(buf[:o])
    real = buf[o:o + N_REAL]
    o += N_REAL
    ints = buf[o:o + N_INT].view(np.int64)
    o += N_INT
    atol = buf[o:o + N_ATOL]
    o += N_ATOL
    y = buf[o:o + N_Y_ROWS * 5].reshape((N_Y_ROWS, 5))
    o += N_Y_ROWS * 5
    g = buf[o:o + N_G_ROWS * N_EVENTS].reshape((N_G_ROWS, N_EVENTS))
    o += N_G_ROWS * N_EVENTS
    fired = buf[o:o + N_FIRED_NUMBERS].view(np.bool_)[:N_EVENTS]
    o += N_FIRED_NUMBERS
    u = buf[o:o + N_U_ROWS * N_STATE].reshape((N_U_ROWS, N_STATE))
    o += N_U_ROWS * N_STATE
    stats = buf[o:o + N_STATS]
    o += N_STATS
    counts = buf[o:o + N_KINDS].view(np.int64)
    o += N_KINDS
    summary = buf[o:o + N_SUMMARY]
    o += N_SUMMARY
    c = buf[o:o + n_coef]
    o += n_coef
    sticks = buf[o:o + 3 * capacity].reshape((3, capacity))
    return (real, ints, c, atol, y, g, fired, u, stats, counts, summary, sticks, stiff[radau5.CTL],
            radau_member(radau, stiff))


def radau_member(radau, stiff):
    """The workspace's ``W_RADAU``: None where ``radau`` is None, else Radau's tuple ``stiff``."""
    return None if radau is None else stiff


@overload(radau_member, inline="always", target="generic")  # the CPU and the GPU (phaseimpact.cuda)
def _radau_member(radau, stiff):
    # chosen on radau's type as numba types the caller: a branch on radau would be pruned only for
    # None, and for True would unify None and the tuple into an Optional the kernels cannot index
    if isinstance(radau, types.NoneType):
        return lambda radau, stiff: None
    return lambda radau, stiff: stiff


@allocating(python=True)
def workspace(n_coef, capacity, radau):
    """A workspace of its own (members ``W_*``; one allocation), reused run after run; ``capacity``
    stick points; ``radau`` as for :func:`carve`."""
    return carve(np.zeros(workspace_size(n_coef, capacity)), n_coef, capacity, radau)
