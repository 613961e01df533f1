"""phaseimpact: Abrate's two-degree-of-freedom impact model and the seed paper's damped variant,
analysed as a dynamical system.

Examples
--------
The seed's case (steel ball on a steel plate, SI units) and its closed-form scales; a run of it is
``simulate(params, "paper")``:

>>> from phaseimpact import LAWS, scales, seed_parameters
>>> params = seed_parameters(v=1.0, kappa=3e9)
>>> print(f"M1 = {params.M1:.4g} kg, K = {params.K:.4g} N/m^1.5")
M1 = 0.2631 kg, K = 2.176e+10 N/m^1.5
>>> print(f"contact time {scales(params).contact_time:.4g} s")
contact time 0.000108 s
>>> LAWS[:3]
('abrate', 'paper', 'hunt-crossley')
"""

from typing import TYPE_CHECKING

from . import _environment, _lazy
from ._version import __version__

# NumPy's f2py reads SOURCE_DATE_EPOCH once, when it is first imported (SciPy and numba import it),
# and crashes on a bad value; so an empty one is unset (it means unset) and a malformed one is hidden
# while f2py imports here, then put back for phaseimpact's own check to refuse with a message. (Only
# then: f2py costs 0.1 s of start-up.)
_environment.unset_empty()
_hidden = _environment.hide_bad_source_date_epoch()
if _hidden is not None:
    try:
        import numpy.f2py  # noqa: F401
    finally:
        _environment.restore_source_date_epoch(_hidden)
del _hidden

# The public names, imported on first use: the engine (numba, SciPy) costs about 0.3 s, which
# the commands that integrate nothing (phaseimpact cases, params, --version) do not pay.
_EXPORTS = {
    "Columns": "integrate", "Event": "integrate", "Trajectory": "integrate", "scales": "integrate",
    "simulate": "integrate", "simulate_many": "integrate",
    "LAWS": "model", "ContactLaw": "model", "kappa_for_restitution": "model",
    "Geometry": "parameters", "Material": "parameters", "Parameters": "parameters",
    "derive_parameters": "parameters", "seed_parameters": "parameters",
    "define_law": "model.userlaw", "check_law": "checks",
}

__all__ = [
    "Columns", "ContactLaw", "Event", "Geometry", "LAWS", "Material", "Parameters", "Trajectory",
    "check_law", "define_law", "derive_parameters", "kappa_for_restitution", "scales", "seed_parameters",
    "simulate", "simulate_many",
    "__version__",
]

__getattr__, __dir__ = _lazy.attach(__name__, globals(), _EXPORTS)

if TYPE_CHECKING:  # what the lazy names are, for type checkers (never run)
    from .checks import check_law
    from .integrate import Columns, Event, Trajectory, scales, simulate, simulate_many
    from .model import LAWS, ContactLaw, kappa_for_restitution
    from .model.userlaw import define_law
    from .parameters import Geometry, Material, Parameters, derive_parameters, seed_parameters
