"""Trajectory generators over one compiled event-driven driver (:mod:`.driver`).

==================  ======================================================================
``simulate``        one run, a :class:`Trajectory` (samples optional, event log, summary)
``simulate_many``   many runs in parallel threads, :class:`Columns` (struct of arrays)
``exact``           the default integrator: DOP853 between events, stick and slip of
                    ``paper`` located on the dense output and restarted exactly at the root
``rk4``             the seed's classic fixed-step RK4 on eq. 8 read literally (it chatters)
==================  ======================================================================

Examples
--------
>>> from phaseimpact import seed_parameters
>>> from phaseimpact.integrate import INTEGRATORS, simulate
>>> INTEGRATORS
('exact', 'rk4')
>>> tr = simulate(seed_parameters(v=1.0, kappa=1e9), "hunt-crossley")
>>> tr.status, tr.outcome
('success', 'rebound')
>>> print(f"{tr.max_force:.4g} N, e = {tr.restitution:.3f}")
4760 N, e = 0.924
"""

from .api import INTEGRATORS, RTOL_RANGE, Scales, scales, simulate
from .batch import simulate_many
from .events import EVENT_KINDS
from .result import OUTCOMES, STATUSES, Columns, Event, Trajectory

__all__ = ["simulate", "simulate_many", "Trajectory", "Columns", "Event", "Scales", "scales", "STATUSES",
           "OUTCOMES", "EVENT_KINDS", "INTEGRATORS", "RTOL_RANGE"]
