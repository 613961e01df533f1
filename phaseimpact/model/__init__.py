"""All physics, no I/O: contact laws (:mod:`.laws`), equations of motion and energy
(:mod:`.rhs`), restitution (:mod:`.restitution`)."""

from .. import _lazy
from .laws import CONTACT_READINGS, LAWS, PLAIN, REGISTRY, STUCK, ContactLaw, LawEntry, as_law, law_variants

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
