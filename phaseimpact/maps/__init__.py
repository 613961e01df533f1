"""Maps of a state to the next and their analyses, written once over the
:class:`~phaseimpact.maps.base.ImpactMap` interface (:mod:`.base` says how to add a map):
fixed points, orbits, attracting orbits and Lyapunov exponents (:mod:`.base`), orbit diagrams
(:mod:`.orbit_diagram`), basins of attraction (:mod:`.basins`) and continuation of periodic orbits
and their bifurcations (:mod:`.continuation`). The model's impact map, trains of impacts, and the
analyses taking a case, a law and a period: :mod:`.impact` and :mod:`.impact_analyses` (also
:mod:`phaseimpact.train`).

Examples
--------
>>> from phaseimpact import seed_parameters
>>> from phaseimpact.maps import ModelImpactMap, fixed_point
>>> fp = fixed_point(ModelImpactMap(seed_parameters(kappa=3e9), "hunt-crossley", 0.4e-3, rtol=1e-12))
>>> fp.converged, f"{fp.plate[0] * 1e6:.3g} um"
(True, '72.6 um')
"""

from .base import (
    ATTRACTION_RADIUS,
    JACOBIAN_STEP,
    LYAPUNOV_SETTLE,
    MAX_LYAPUNOV_TRANSIENTS,
    AffineMap,
    ImpactMap,
    MapFixedPoint,
    attracting_orbit_of,
    fixed_point,
    iterate,
    lyapunov,
)
from .basins import ATTRACTOR_MATCH, NO_MAP, NOT_CONVERGED, Attractor, Basins, find_basins
from .continuation import (
    BIFURCATION_KINDS,
    BifurcationCurve,
    MapBifurcation,
    MapBranch,
    continue_bifurcation,
    continue_orbit,
)
from .impact import (
    MAX_PERIOD_SWINGS,
    TRAIN_PARAMETERS,
    ImpactTrain,
    ModelImpactMap,
    attracting_orbit,
    check_period,
    impact_map,
    impact_train,
    lyapunov_exponent,
    map_fixed_point,
    map_jacobian,
    period_range,
)
from .impact_analyses import basins, continue_map_bifurcation, continue_map_orbit, orbit_diagram
from .orbit_diagram import OrbitDiagram, sample_attractor

__all__ = [
    "ImpactMap", "AffineMap", "MapFixedPoint", "iterate", "fixed_point", "attracting_orbit_of", "lyapunov",
    "OrbitDiagram", "sample_attractor", "Attractor", "Basins", "find_basins", "MapBifurcation", "MapBranch",
    "BifurcationCurve", "continue_orbit", "continue_bifurcation", "ModelImpactMap", "ImpactTrain", "impact_map",
    "impact_train", "map_fixed_point", "map_jacobian", "attracting_orbit", "lyapunov_exponent", "orbit_diagram",
    "continue_map_orbit", "continue_map_bifurcation", "basins", "period_range", "check_period",
    "TRAIN_PARAMETERS", "MAX_PERIOD_SWINGS", "BIFURCATION_KINDS", "NOT_CONVERGED", "NO_MAP", "ATTRACTOR_MATCH",
    "ATTRACTION_RADIUS", "JACOBIAN_STEP", "LYAPUNOV_SETTLE", "MAX_LYAPUNOV_TRANSIENTS",
]
