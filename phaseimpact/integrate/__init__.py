"""Trajectory generators over one compiled event-driven driver (:mod:`.driver`).

==================  ======================================================================
``simulate``        one run, a :class:`Trajectory` (samples optional, event log, summary)
``simulate_many``   many runs in parallel threads, :class:`Columns` (struct of arrays)
``exact``           the default integrator: DOP853 between events, stick and slip of
                    ``paper`` located on the dense output and restarted exactly at the root
``rk4``             the seed's classic fixed-step RK4 on eq. 8 read literally (it chatters)
==================  ======================================================================
"""

from .api import INTEGRATORS, RTOL_RANGE, Scales, scales, simulate, simulate_many
from .events import EVENT_KINDS
from .result import OUTCOMES, STATUSES, Columns, Event, Trajectory

__all__ = ["simulate", "simulate_many", "Trajectory", "Columns", "Event", "Scales", "scales", "STATUSES",
           "OUTCOMES", "EVENT_KINDS", "INTEGRATORS", "RTOL_RANGE"]
