"""phaseimpact: Abrate's two-degree-of-freedom impact model and the seed paper's damped variant,
analysed as a dynamical system."""

from .integrate import Columns, Event, Trajectory, scales, simulate, simulate_many
from .model import LAWS, ContactLaw, kappa_for_restitution
from .parameters import Geometry, Material, Parameters, derive_parameters, seed_parameters

__version__ = "0.2.0"

__all__ = [
    "Columns", "ContactLaw", "Event", "Geometry", "LAWS", "Material", "Parameters", "Trajectory",
    "derive_parameters", "kappa_for_restitution", "scales", "seed_parameters", "simulate", "simulate_many",
    "__version__",
]
