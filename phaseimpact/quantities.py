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

    Made by :func:`impact_quantities`; undefined quantities are None, never NaN.

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

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate
    >>> from phaseimpact.quantities import impact_quantities
    >>> q = impact_quantities(simulate(seed_parameters(v=1.0, kappa=1e9), "hunt-crossley"))
    >>> print(f"{q.max_force:.4g} N, {q.contact_duration:.4g} s, e = {q.restitution:.3f}")
    4760 N, 0.0001095 s, e = 0.924
    """

    max_force: float
    max_indentation: float
    contact_duration: float | None
    restitution: float | None
    time_equal_displacement: float | None
    dissipated_energy: float
    loop_area: float

    def as_dict(self) -> dict:
        """The quantities as a plain dict (for JSON; None stays None).

        Returns
        -------
        dict
            ``{name: value}`` in the order of the attributes.

        Examples
        --------
        >>> from phaseimpact import seed_parameters, simulate
        >>> from phaseimpact.quantities import impact_quantities
        >>> d = impact_quantities(simulate(seed_parameters(kappa=3e9), "paper")).as_dict()
        >>> list(d)[:3], d["restitution"]
        (['max_force', 'max_indentation', 'contact_duration'], None)
        """
        return asdict(self)


def impact_quantities(trajectory: Trajectory) -> ImpactQuantities:
    """Derive :class:`ImpactQuantities` from ``trajectory`` (its summary; energies from its own
    initial state, docs/physics.md §4).

    Works for summary runs (no samples) as well as dense ones: everything is read from the
    summary vector and the event log.

    Parameters
    ----------
    trajectory : Trajectory
        A run of :func:`~phaseimpact.simulate`.

    Returns
    -------
    ImpactQuantities
        Forces in N, lengths in m, times in s, energies in J; None where undefined (no
        separation: no contact duration, restitution or time of equal displacement).

    Raises
    ------
    TypeError
        If ``trajectory`` is not a :class:`~phaseimpact.Trajectory`.

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate
    >>> from phaseimpact.quantities import impact_quantities
    >>> q = impact_quantities(simulate(seed_parameters(v=1.0, kappa=3e9), "paper"))
    >>> print(f"{q.max_force:.4g} N, {q.dissipated_energy:.4g} J")
    4629 N, 0.07114 J
    >>> q.restitution is None  # a permanent stick never separates
    True
    """
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
