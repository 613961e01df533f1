"""The event table of the hybrid system, compiled (docs/physics.md §3, §5).

Each event is a column of :func:`event_values` (one of them: :func:`event_value`), with the
direction that fires it and what the driver does then (:data:`ACTIONS`); :func:`transition`
applies an event located at a state.

==================  =========  =========  ===================================================
column              direction  action     meaning
==================  =========  =========  ===================================================
``DELTA``           both       restart    the contact gap, ``delta`` (minus a law's dent, where
                                          its force ends): contact onset (up), separation (down)
``DELTADOT``        both       restart*   ``deltadot``: extreme indentation; ``paper``
                                          slipping: stick, or a reversal of the slip
``FORCE_RATE``      down       record     ``dP/dt``: a maximum of the contact force
``STICK_BREAK``     down       restart    monotone stick-break distance while stuck: slip
``ENERGY``          down       stop       ``2 E(0) - E``: the energy has doubled (runaway)
``REACH``           up         stop**     ``-(x1 + A)``: a receding projectile is beyond the
                                          reach ``A`` of the plate: no contact can follow
``PAIR_CENTRE``      both       restart    ``x2`` while stuck: the pair passes its centre, where
                                          ``STICK_BREAK`` switches branch (not logged)
==================  =========  =========  ===================================================

(*) record only for laws without stick; (**) stop when the run stops once settled.
"""

from __future__ import annotations

import math

from .._jit import kernel
from ..model.forms import (
    STUCK,
    contact_gap,
    dent_depth,
    has_memory,
    is_filippov,
    is_unilateral,
    partials_of,
    remember,
    stick_bound,
)
from ..model.laws import (
    GUARD_ENERGY_FACTOR,  # noqa: F401 (re-exported)
    RUNAWAY_ENERGY_FACTOR,  # noqa: F401 (re-exported)
)
from ..model.rhs import (
    ALPHA_,
    DAMP_,
    GUARD_,
    K_,
    KB_,
    KM_,
    M1_,
    M2_,
    RIGID_,
    SPRINGS_,
    V1,
    V2,
    X1,
    X2,
    energy,
    stick_break_distance,
    stick_force,
    stick_margin,
    target_reach,
)

DELTA, DELTADOT, FORCE_RATE, STICK_BREAK, ENERGY, REACH, PAIR_CENTRE = range(7)
N_EVENTS = 7

# Event kinds in the log.
CONTACT, SEPARATION, REVERSAL, STICK, SLIP, FORCE_PEAK, SETTLED, RUNAWAY, CENTRE = range(9)
EVENT_KINDS = ("contact", "separation", "reversal", "stick", "slip", "force-peak", "settled", "runaway", "centre")
#: Kinds the driver acts on but does not log.
SILENT = CENTRE
# What a transition asks of the driver.
GO_ON, STOP_SETTLED, STOP_RUNAWAY = 0, 1, 2

# RUNAWAY_ENERGY_FACTOR and GUARD_ENERGY_FACTOR (imported above) are defined with the laws: each
# law's factor travels in its packed coefficients (slot GUARD_, read by energy_limit_of).


@kernel(forceinline=True)
def event_value(code, c, y, f, force, mode, energy_limit, column):
    """Event function ``column`` at ``y`` (``f`` its derivative and ``force`` its contact force,
    read by ``FORCE_RATE`` only, so that a root finder on another event skips the right-hand
    side). Inactive events are held at +-1 so that they never fire."""
    stuck = mode == STUCK
    if column == DELTA:
        return contact_gap(code, c, y[X1], y[X2])
    if column == ENERGY:
        return energy_limit - energy(code, c, y)
    if column == PAIR_CENTRE:
        # the stick-break function jumps where x2 crosses 0: the run restarts there, so that the
        # jump never falls inside a step (a break right after it would be stepped over)
        return y[X2] if stuck and c[SPRINGS_] > 0 else 1.0
    if column == STICK_BREAK:
        return stick_break_distance(code, c, y) if stuck else 1.0
    if column == DELTADOT:
        return 1.0 if stuck else y[V1] - y[V2]
    if column == FORCE_RATE:
        if stuck:  # the stuck force M1/M S(x2) peaks where x2 does
            return (c[KB_] + 3.0 * c[KM_] * y[X2] * y[X2]) * y[V2] * c[M1_] / (c[M1_] + c[M2_])
        if force == 0.0 and is_unilateral(code):
            return -1.0
        deltadot = y[V1] - y[V2]
        p_delta, p_rate = partials_of(code, c, y[X1] - y[X2], deltadot, mode)
        return p_delta * deltadot + p_rate * (f[V1] - f[V2])
    # REACH
    if not stuck and is_unilateral(code) and c[SPRINGS_] > 0 and contact_gap(code, c, y[X1], y[X2]) < 0 \
            and y[V1] < 0:
        return -(y[X1] + target_reach(c, y))
    return -1.0


@kernel(python=True, forceinline=True)
def event_values(code, c, y, f, force, mode, energy_limit, g):
    """All event functions at ``y`` into ``g`` (:func:`event_value`)."""
    for column in range(N_EVENTS):
        g[column] = event_value(code, c, y, f, force, mode, energy_limit, column)


@kernel
def direction(column):
    """+1: the event fires on an increase through zero, -1: on a decrease, 0: on both (the table above).
    A branch, not a lookup in a global array: that costs an array per call in the hot loop."""
    if column == DELTA or column == DELTADOT or column == PAIR_CENTRE:
        return 0
    if column == REACH:
        return 1
    return -1


@kernel
def crossed(column, g_old, g_new):
    """Whether event ``column`` fires between two evaluations (strict start: a restart at a zero
    is quiet)."""
    d = direction(column)
    if d >= 0 and g_old[column] < 0 and g_new[column] >= 0:
        return True
    return d <= 0 and g_old[column] > 0 and g_new[column] <= 0


@kernel(python=True)
def departure_sign(column, y, mode):
    """Sign event ``column`` takes just after a run restarts on its zero at ``y``."""
    if column == DELTA:
        dd = y[V1] - y[V2]
        return 1.0 if dd >= 0 else -1.0
    if column == DELTADOT:
        return -1.0 if mode < 0 else 1.0
    if column == PAIR_CENTRE:
        return -1.0 if y[V2] < 0 else 1.0
    return 1.0


@kernel(python=True)
def restarts(code, column, mode, settle):
    """Whether an event of ``column`` changes the phase (restart) rather than being recorded."""
    if column == FORCE_RATE:
        return False
    if column == DELTADOT:  # a law with memory goes on from an extremum on its updated branch
        return (is_filippov(code) and mode != 2) or has_memory(code)
    if column == REACH:
        return settle
    return True


@kernel
def _stick_bound(code, c, y):
    return stick_bound(code, y[X1] - y[X2], c[K_], c[DAMP_], c[ALPHA_])


@kernel(python=True)
def initial_mode(code, c, y):
    """Mode of a run starting at ``y``: the sign of ``deltadot``, or stuck (``paper``) when the
    relative velocity is zero and the stick bound holds (seed eq. 6 gives +1)."""
    if not is_filippov(code):
        return 1
    deltadot = y[V1] - y[V2]
    if deltadot > 0:
        return 1
    if deltadot < 0:
        return -1
    required = stick_force(c, y)
    if abs(required) <= _stick_bound(code, c, y):
        return STUCK
    return -1 if required < 0 else 1


@kernel(python=True)
def transition(code, c, column, y, mode, settle):
    """Apply event ``column`` located at ``y`` (corrected in place).

    Returns ``(kind, new_mode, action)``.
    """
    action = GO_ON
    if column == DELTA:
        # the event is a zero gap: remove the root finder's residue (contact_gap's own expression, so
        # that the gap is exactly 0 and the next phase's side is that of deltadot)
        y[X1] = y[X2] + dent_depth(code, c) if has_memory(code) else y[X2]
        deltadot = y[V1] - y[V2]
        kind = CONTACT if deltadot > 0 else SEPARATION
        if (is_filippov(code) or has_memory(code)) and mode != STUCK and deltadot != 0:
            mode = 1 if deltadot > 0 else -1
        if kind == SEPARATION and is_unilateral(code) and c[SPRINGS_] == 0 and settle:
            action = STOP_SETTLED  # a wall or a free target never meets the projectile again
        return kind, mode, action
    if column == DELTADOT:
        if has_memory(code):
            # the mode is the sign of deltadot: the run goes on the other way, on the branch the
            # extremum leaves (a new largest indentation updates the memory)
            remember(code, c, y[X1] - y[X2])
            return REVERSAL, -mode, action
        if not is_filippov(code) or mode == 2:
            return REVERSAL, mode, action
        if is_unilateral(code) and y[X1] - y[X2] <= 0:
            return REVERSAL, -mode, action  # the extreme of delta in flight
        required = stick_force(c, y)
        if abs(required) <= _stick_bound(code, c, y):
            common = 0.0 if c[RIGID_] > 0 else (c[M1_] * y[V1] + c[M2_] * y[V2]) / (c[M1_] + c[M2_])
            y[V1] = common
            y[V2] = common
            if settle and stick_margin(code, c, y) >= 0:
                action = STOP_SETTLED
            return STICK, STUCK, action
        new = 1 if required > 0 else (-1 if required < 0 else 0)
        if new == mode:
            # the forces push deltadot away from zero on the slip's own side, so it cannot have come
            # through zero: rounding at a slip's start (deltadot' = 0 at a break), seen under tiny
            # tolerances. The slip goes on from deltadot = 0, unlogged (a reversal here escaped).
            common = 0.0 if c[RIGID_] > 0 else (c[M1_] * y[V1] + c[M2_] * y[V2]) / (c[M1_] + c[M2_])
            y[V1] = common
            y[V2] = common
            return SILENT, mode, action
        return REVERSAL, (-mode if new == 0 else new), action
    if column == STICK_BREAK:
        return SLIP, (-1 if stick_force(c, y) < 0 else 1), action
    if column == FORCE_RATE:
        return FORCE_PEAK, mode, action
    if column == ENERGY:
        return RUNAWAY, mode, STOP_RUNAWAY
    if column == PAIR_CENTRE:
        # exactly at the centre (delta kept): the stick-break function then starts on the branch
        # of the swing that follows, whatever the root finder's residue
        y[X1] = y[X1] - y[X2]
        y[X2] = 0.0
        return CENTRE, mode, action
    # REACH
    return SETTLED, mode, (STOP_SETTLED if settle else GO_ON)


@kernel(python=True)
def energy_limit_of(code, c, y0):
    """Energy at which a run counts as a runaway: the law's runaway factor (packed, slot
    ``GUARD_``) times the run's own initial energy."""
    e0 = energy(code, c, y0)
    return c[GUARD_] * e0 if e0 > 0 else math.inf
