"""All physics, no I/O: contact laws (:mod:`.laws`), equations of motion and energy
(:mod:`.rhs`), restitution (:mod:`.restitution`).

Examples
--------
The shipped laws, one with its options, and the coefficient array the engine reads:

>>> from phaseimpact import seed_parameters
>>> from phaseimpact.model import LAWS, ContactLaw, pack
>>> LAWS[:3]
('abrate', 'paper', 'hunt-crossley')
>>> law = ContactLaw("hunt-crossley", restitution=0.8)
>>> law.label(), law.damping_unit(1.5)
('hunt-crossley e=0.8', 'N s/m^2.5')
>>> pack(seed_parameters(v=1.0), law).shape
(16,)
"""

from .. import _lazy
from .forms import PLAIN, STUCK
from .laws import (
    CONTACT_READINGS,
    LAWS,
    REGISTRY,
    ContactLaw,
    LawEntry,
    as_law,
    law_variants,
)

# Imported on first use: they need NumPy and SciPy, which the command line's parser (it lists the
# laws) and the commands that integrate nothing do not pay for.
_LAZY = {
    "hunt_crossley_restitution": "restitution", "kappa_for_restitution": "restitution",
    "V1": "rhs", "V2": "rhs", "WORK": "rhs", "X1": "rhs", "X2": "rhs", "initial_state": "rhs", "jacobian": "rhs",
    "pack": "rhs",
}

__all__ = [
    "CONTACT_READINGS", "LAWS", "PLAIN", "REGISTRY", "STUCK", "ContactLaw", "LawEntry", "as_law",
    "law_variants", "hunt_crossley_restitution", "kappa_for_restitution", "V1", "V2", "WORK", "X1", "X2",
    "initial_state", "jacobian", "pack",
]

__getattr__, __dir__ = _lazy.attach(__name__, globals(), _LAZY)
