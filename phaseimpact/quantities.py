"""Summary quantities of one impact, from a trajectory's events and final state.

All work for summary runs (no samples) as well as dense ones. Undefined quantities are
``None`` (no separation, say), never NaN.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from .integrate import Trajectory
from .model import WORK, coefficients, energy, initial_state

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
        Initial minus final mechanical energy, J.
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
    """Derive :class:`ImpactQuantities` from ``trajectory``."""
    c = coefficients(trajectory.params, trajectory.law)
    contacts = trajectory.events_of("contact")
    separations = trajectory.events_of("separation")
    first_contact = contacts[0] if contacts else None
    first_separation = next((e for e in separations if first_contact and e.t > first_contact.t), None)
    duration = restitution = t_equal = None
    if first_contact is not None and first_separation is not None:
        duration = first_separation.t - first_contact.t
        t_equal = first_separation.t
        if first_contact.deltadot != 0:
            restitution = -first_separation.deltadot / first_contact.deltadot
    y0 = initial_state(trajectory.params.v)
    law = trajectory.law
    dissipated = float(energy(y0, c, law) - energy(trajectory.final_state, c, law))
    return ImpactQuantities(
        max_force=trajectory.max_force,
        max_indentation=trajectory.max_indentation,
        contact_duration=duration,
        restitution=restitution,
        time_equal_displacement=t_equal,
        dissipated_energy=dissipated,
        loop_area=float(trajectory.final_state[WORK]),
    )
