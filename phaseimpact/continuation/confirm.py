"""Counts that check themselves: stick counts of ``paper`` near the critical damping, confirmed by
two physical invariants and by a re-run at a tighter tolerance (docs/physics.md §5).

Near ``kappa_c`` a slip's relative speed is 1e-7 to 1e-12 of the impact speed and a run makes
thousands of stick phases, so a count is the most fragile number the tool reports. A count is
reported as confirmed only when

* the run keeps the invariants of eq. 8 (:func:`stick_sequence_violation`), and
* a re-run at :func:`tighter` tolerance gives the same count, also within its invariants.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..integrate import simulate
from ..integrate.events import EVENT_KINDS

__all__ = ["CONFIRM_FACTOR", "ConfirmedCount", "confirmed_count", "resolution", "stick_sequence_violation", "tighter"]

_STICK, _SLIP, _REVERSAL = (EVENT_KINDS.index(k) for k in ("stick", "slip", "reversal"))
_ESCAPES = ("ratchet-escape", "runaway", "rebound")
#: A count is re-run at the tolerance divided by this (not below the smallest allowed, 1e-13).
CONFIRM_FACTOR = 100.0
_RTOL_FLOOR = 1e-13


def tighter(rtol: float) -> float:
    """The tolerance a count is confirmed at: ``rtol / CONFIRM_FACTOR``, not below 1e-13.

    Parameters
    ----------
    rtol : float
        The integrator tolerance of the count.

    Returns
    -------
    float

    Examples
    --------
    >>> from phaseimpact.continuation.confirm import tighter
    >>> tighter(1e-10), tighter(1e-12)
    (1e-12, 1e-13)
    """
    return max(rtol / CONFIRM_FACTOR, _RTOL_FLOOR)


def resolution(rtol: float, x1, x2, scale: float):
    """The smallest difference of ``x1 - x2`` a run at ``rtol`` resolves: ``rtol (|x1| + |x2| + 2 scale)``
    plus the rounding of the difference.

    The integrator keeps the error of each step within ``rtol |x| + atol`` for each component,
    with ``atol = rtol scale`` (positions: ``scale`` the Hertz indentation; velocities: the impact
    speed; :func:`~phaseimpact.integrate.api.state_tolerances`); a difference of two components
    below the sum of their allowances is not resolved by the run, so it cannot break an invariant.

    Parameters
    ----------
    rtol : float
        The run's integrator tolerance.
    x1, x2 : float or ndarray
        The two components (m, or m/s).
    scale : float
        The scale of their absolute tolerance (m, or m/s).

    Returns
    -------
    float or ndarray

    Examples
    --------
    >>> from phaseimpact.continuation.confirm import resolution
    >>> print(f"{resolution(1e-12, 1.4546e-3, 1.4318e-3, 1.382e-4):.3g} m")
    3.17e-15 m
    """
    rounding = 16 * np.finfo(float).eps * (np.abs(x1) + np.abs(x2))
    return rtol * (np.abs(x1) + np.abs(x2) + 2 * scale) + rounding


def stick_sequence_violation(trajectory, rtol: float = 1e-10) -> str | None:
    """Why the stick phases of a ``paper`` run cannot be the motion of eq. 8, or None.

    Three invariants hold whatever the tolerance:

    * a slip from one stick to the next (no reversal between) moves ``delta`` in the direction of
      its mode: an outward slip (``deltadot > 0``) re-sticks deeper, an inward one shallower;
    * the break of the first stick is followed by a second stick: the first slip above
      ``kappa_c`` goes deeper and is damped, so an escape right after it is a missed re-stick;
    * a run that ends slipping has ``deltadot`` of its mode's sign (else its zero was stepped over).

    Each is tested within what the run resolves (:func:`resolution`): a re-stick against its slip's
    direction by less than ``rtol (|x1| + |x2| + 2 delta_H)`` at each of the two sticks (``delta_H``
    the Hertz indentation, the positions' absolute tolerance over ``rtol``), or a final
    ``deltadot`` of the wrong sign by less than ``rtol (|x1dot| + |x2dot| + 2 v)``, is within the
    integrator's error and no violation; anything larger is.

    Parameters
    ----------
    trajectory : Trajectory
        A run of ``paper`` (or another Filippov law); a summary run is enough (the event log).
    rtol : float, default 1e-10
        The integrator tolerance the run was made with.

    Returns
    -------
    str or None
        The first broken invariant in words (times in s, ``delta`` in m), or None when all hold.

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate
    >>> from phaseimpact.continuation import stick_sequence_violation
    >>> print(stick_sequence_violation(simulate(seed_parameters(kappa=2e12), "paper")))
    None
    """
    kinds = trajectory.event_kind
    y = trajectory.event_y
    delta = y[:, 0] - y[:, 1]
    params = trajectory.params
    resolved = resolution(rtol, y[:, 0], y[:, 1], params.hertz_indentation)
    stuck_at, slip_mode = None, 0
    for i, kind in enumerate(kinds):
        if kind == _STICK:
            tolerance = resolved[i] + resolved[stuck_at] if stuck_at is not None else 0.0
            if stuck_at is not None and slip_mode != 0 and (delta[i] - delta[stuck_at]) * slip_mode < -tolerance:
                direction = "shallower" if slip_mode > 0 else "deeper"
                return (f"the slip of mode {slip_mode:+d} that began at t = {trajectory.event_t[stuck_at]:.9g} s "
                        f"re-stuck {direction} than it stuck (delta {delta[stuck_at]:.12g} -> {delta[i]:.12g} m, "
                        f"{abs(delta[i] - delta[stuck_at]):.3g} m against its direction, more than the "
                        f"{tolerance:.3g} m the run resolves at rtol {rtol:g})")
            stuck_at, slip_mode = i, 0
        elif kind == _SLIP:
            slip_mode = int(trajectory.event_mode[i])
        elif kind == _REVERSAL:
            slip_mode = 0  # a slip that reverses may end on either side
    if trajectory.n_stick == 1 and np.any(kinds == _SLIP) and trajectory.outcome in _ESCAPES:
        return "the first stick broke and the run escaped without a second stick (a missed re-stick)"
    mode, final = trajectory.final_mode, trajectory.final_state
    deltadot = final[2] - final[3]
    if mode in (1, -1) and deltadot * mode < -resolution(rtol, final[2], final[3], params.v):
        return f"the run ended slipping in mode {mode:+d} with deltadot = {deltadot:.3g} m/s of the other sign"
    return None


@dataclass(frozen=True)
class ConfirmedCount:
    """A stick count at one ``kappa`` and how far it can be trusted (:func:`confirmed_count`).

    Attributes
    ----------
    n_stick : int
        Stick phases at the run's tolerance (a lower bound if :attr:`cut`).
    t_run : float or None
        Escape time, s.
    cut : bool
        The horizon ended the run first.
    confirmed : bool
        The invariants hold and the re-run at :func:`tighter` tolerance gives the same count.
    reason : str
        Why not confirmed ("" when confirmed).
    n_stick_tight : int or None
        The count at the tighter tolerance (None if that run was not made or broke an invariant).
    disagree : bool
        Not confirmed only because the two tolerances count differently (no invariant broken).

    Examples
    --------
    >>> from phaseimpact.continuation import ConfirmedCount
    >>> ConfirmedCount(3, 0.01, False, False, "3 stick phases at rtol 1e-10, 4 at rtol 1e-12", 4).disagree
    True
    """

    n_stick: int
    t_run: float | None
    cut: bool
    confirmed: bool
    reason: str = ""
    n_stick_tight: int | None = None

    @property
    def disagree(self) -> bool:
        """Not confirmed only because the two tolerances count differently (no invariant broken)."""
        return self.n_stick_tight is not None and self.n_stick_tight != self.n_stick


def _count(params, law, rtol):
    run = simulate(params, law, None, rtol=rtol)
    if run.status != "success":
        return run, f"the run at rtol {rtol:g} failed: {run.message}"
    return run, stick_sequence_violation(run, rtol)


def confirmed_count(params, law, rtol: float) -> ConfirmedCount:
    """Count the stick phases of ``paper`` at ``params`` and confirm the count (module docstring).

    The run (until its outcome settles) must keep the invariants of
    :func:`stick_sequence_violation`, and a re-run at :func:`tighter` tolerance must keep them too
    and give the same count (and the same cut); a failed run is not confirmed either.

    Parameters
    ----------
    params : Parameters
        The case, with its ``kappa`` (N s/m^(1+alpha)).
    law : ContactLaw or str
        ``paper`` or another Filippov law.
    rtol : float
        Integrator tolerance of the count, within :data:`~phaseimpact.integrate.RTOL_RANGE`.

    Returns
    -------
    ConfirmedCount
        The count at ``rtol``, whether it is confirmed and, if not, why.

    Raises
    ------
    ValueError
        For an argument :func:`~phaseimpact.simulate` refuses.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import confirmed_count
    >>> c = confirmed_count(seed_parameters(v=1.0, kappa=2e12), "paper", 1e-10)
    >>> c.n_stick, c.confirmed, c.n_stick_tight, c.cut
    (2, True, 2, False)
    """
    run, violation = _count(params, law, rtol)
    if violation is not None:
        return ConfirmedCount(run.n_stick, run.t_run, run.cut, False, violation)
    tight = tighter(rtol)
    check, violation = _count(params, law, tight)
    if violation is not None:
        return ConfirmedCount(run.n_stick, run.t_run, run.cut, False, f"at rtol {tight:g}: {violation}")
    if check.n_stick != run.n_stick or check.cut != run.cut:
        return ConfirmedCount(run.n_stick, run.t_run, run.cut, False,
                              f"{run.n_stick} stick phases at rtol {rtol:g}, {check.n_stick} at rtol {tight:g}",
                              check.n_stick)
    return ConfirmedCount(run.n_stick, run.t_run, run.cut, True, "", check.n_stick)
