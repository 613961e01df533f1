"""All physics, no I/O: contact laws (:mod:`.laws`), equations of motion and energy
(:mod:`.rhs`), restitution (:mod:`.restitution`)."""

from .laws import CONTACT_READINGS, LAWS, PLAIN, REGISTRY, STUCK, ContactLaw, LawEntry, as_law, law_variants
from .restitution import hunt_crossley_restitution, kappa_for_restitution
from .rhs import (
    V1,
    V2,
    WORK,
    X1,
    X2,
    initial_state,
    jacobian,
    pack,
)

__all__ = [
    "CONTACT_READINGS", "LAWS", "PLAIN", "REGISTRY", "STUCK", "ContactLaw", "LawEntry", "as_law",
    "law_variants", "hunt_crossley_restitution", "kappa_for_restitution", "V1", "V2", "WORK", "X1", "X2",
    "initial_state", "jacobian", "pack",
]
