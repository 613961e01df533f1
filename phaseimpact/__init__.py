"""phaseimpact: Abrate's two-degree-of-freedom impact model and the seed paper's damped variant,
analysed as a dynamical system."""

from .integrate import Event, Save, Trajectory, simulate, simulate_batch
from .model import LAWS, ContactLaw, kappa_for_restitution
from .parameters import Geometry, Material, Parameters, derive_parameters, seed_parameters

__version__ = "0.1.0"

__all__ = [
    "ContactLaw", "Event", "Geometry", "LAWS", "Material", "Parameters", "Save", "Trajectory",
    "derive_parameters", "kappa_for_restitution", "seed_parameters", "simulate", "simulate_batch",
    "__version__",
]
