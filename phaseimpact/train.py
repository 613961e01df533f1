"""Trains of impacts as a map (docs/physics.md §7): the public face of the model's impact map, kept
where the command line, the archive and users import it. The code lives in :mod:`phaseimpact.maps`
(the generic analyses over any :class:`~phaseimpact.maps.base.ImpactMap`) and its modules
:mod:`~phaseimpact.maps.impact` and :mod:`~phaseimpact.maps.impact_analyses` (the model's map,
taking a case, a law and a period): :func:`impact_train`, :func:`map_fixed_point`,
:func:`orbit_diagram`, :func:`lyapunov_exponent`, :func:`continue_map_orbit`,
:func:`continue_map_bifurcation` and :func:`basins`.

Examples
--------
>>> from phaseimpact import seed_parameters
>>> from phaseimpact.train import impact_train
>>> impact_train(seed_parameters(kappa=3e9), "hunt-crossley", 3e-3, 2).status
['success', 'success']
"""

from .maps.base import ATTRACTION_RADIUS, LYAPUNOV_SETTLE, MAX_LYAPUNOV_TRANSIENTS, MapFixedPoint
from .maps.basins import ATTRACTOR_MATCH, NO_MAP, NOT_CONVERGED, Attractor, Basins
from .maps.continuation import BIFURCATION_KINDS, BifurcationCurve, MapBifurcation, MapBranch
from .maps.impact import (
    MAX_PERIOD_SWINGS,
    TRAIN_PARAMETERS,
    ImpactTrain,
    attracting_orbit,
    impact_map,
    impact_train,
    lyapunov_exponent,
    map_fixed_point,
    map_jacobian,
    period_range,
)
from .maps.impact import check_period as _check_period  # the command line's name for it
from .maps.impact_analyses import basins, continue_map_bifurcation, continue_map_orbit, orbit_diagram
from .maps.orbit_diagram import OrbitDiagram

__all__ = ["ImpactTrain", "MapFixedPoint", "OrbitDiagram", "impact_map", "impact_train", "map_fixed_point",
           "map_jacobian", "orbit_diagram", "lyapunov_exponent", "TRAIN_PARAMETERS", "MapBifurcation", "MapBranch",
           "BifurcationCurve", "Attractor", "Basins", "continue_map_orbit", "continue_map_bifurcation", "basins",
           "BIFURCATION_KINDS", "NOT_CONVERGED", "NO_MAP", "ATTRACTOR_MATCH", "period_range",
           "MAX_PERIOD_SWINGS", "attracting_orbit", "ATTRACTION_RADIUS", "LYAPUNOV_SETTLE", "MAX_LYAPUNOV_TRANSIENTS",
           "_check_period"]
