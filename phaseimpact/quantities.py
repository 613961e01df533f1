"""Summary quantities of one impact, from a trajectory's events and final state.

All work for summary runs (no samples) as well as dense ones. Undefined quantities are
``None`` (no separation, say), never NaN.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from .integrate import Trajectory

__all__ = ["ImpactQuantities", "impact_quantities"]


@dataclass(frozen=True)
class ImpactQuantities:
    """What one impact produced (SI units).

    Attributes
    ----------
    max_force : float
        Largest contact force, N.
    max_indentation : float
        Largest ``delta = x1 - x2``, m.
    contact_duration : float or None
        First contact to first separation, s.
    restitution : float or None
        ``-deltadot`` at first separation over ``deltadot`` at first contact.
    time_equal_displacement : float or None
        First time after contact begins with ``x1 = x2``, s.
    dissipated_energy : float
        Initial minus final mechanical energy of the run (docs/physics.md §4), J. For ``paper`` the
        elastic term has no potential, so the plastic stick's loss is counted.
    loop_area : float
        ``integral of P d(delta)`` over the run, J: the area of the force-indentation loop
        (equal to the dissipated energy whenever the run ends out of contact).
    """

    max_force: float
    max_indentation: float
    contact_duration: float | None
    restitution: float | None
    time_equal_displacement: float | None
    dissipated_energy: float
    loop_area: float

    def as_dict(self) -> dict:
        return asdict(self)


def impact_quantities(trajectory: Trajectory) -> ImpactQuantities:
    """Derive :class:`ImpactQuantities` from ``trajectory`` (its summary; energies from its own
    initial state, docs/physics.md §4)."""
    if not isinstance(trajectory, Trajectory):
        raise TypeError(f"trajectory = {trajectory!r} has the wrong type ({type(trajectory).__name__}); allowed: a "
                        "Trajectory (from simulate())")
    duration = trajectory.contact_duration
    t_equal = None
    if duration is not None:
        first_contact = trajectory.events_of("contact")[0]
        t_equal = first_contact.t + duration
    return ImpactQuantities(
        max_force=trajectory.max_force,
        max_indentation=trajectory.max_indentation,
        contact_duration=duration,
        restitution=trajectory.restitution,
        time_equal_displacement=t_equal,
        dissipated_energy=trajectory.dissipated_energy,
        loop_area=trajectory.loop_area,
    )
