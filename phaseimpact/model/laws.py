r"""Contact laws, each defined once (seed eq. 2 and 8; docs/physics.md §3).

A law is one :class:`LawEntry` in :data:`REGISTRY`: its kernel code, its flags and the
parameters it reads. The kernels below (compiled with numba, callable from Python too) give
the contact force ``P(delta, deltadot)``, its partial derivatives and the contact potential;
the right-hand side, the Jacobian, the event functions and the energy ledger
(:mod:`phaseimpact.model.rhs`) are composed from them, so a law's physics lives here only.

==========================  ===============================================================
``abrate``                  ``K delta^alpha`` for ``delta > 0``, else 0 (eq. 2);
                            ``bilateral=True``: ``K |delta|^alpha sgn(delta)`` (seed Fig. 3)
``hunt-crossley``           ``(K + kappa deltadot) delta^alpha`` for ``delta > 0``;
                            ``clamp=True`` keeps ``P >= 0``
``hunt-crossley-approx``,   Hunt-Crossley form with ``kappa = chi(e) K / v`` from a
``lankarani-nikravesh``,    coefficient of restitution ``e`` (the damping's only source)
``flores``, ``gonthier``
``paper``                   ``(K + kappa deltadot) |delta|^alpha sgn(deltadot)`` (eq. 8):
                            a Filippov system. ``contact="printed"`` (default) reads
                            ``|delta|`` literally, so the law also acts in tension;
                            ``contact="unilateral"`` sets ``P = 0`` for ``delta <= 0``
==========================  ===============================================================

Modes (``paper``): ``+1``/``-1`` while slipping with that sign of ``deltadot``, ``STUCK`` (0)
while ``deltadot = 0`` holds, ``PLAIN`` (2) reads ``sgn(deltadot)`` literally (what a fixed-step
method sees). Every other law runs in mode ``+1``.

Adding a law: write its kernel branch in :func:`contact_force`, :func:`force_partials` and
:func:`contact_potential` under a new code, and register a :class:`LawEntry`; the conformance
tests (``tests/test_laws.py``) pick it up from :func:`law_variants`.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .._jit import kernel
from ..parameters import Parameters, require, require_choice

__all__ = [
    "LawEntry", "REGISTRY", "LAWS", "CONTACT_READINGS", "ContactLaw", "as_law", "law_variants",
    "contact_force", "force_partials", "contact_potential", "hertz_power",
    "STUCK", "PLAIN",
]

# Kernel codes (integers: the compiled loop dispatches on them, no strings inside it).
ABRATE, ABRATE_BILATERAL, HUNT_CROSSLEY, HUNT_CROSSLEY_CLAMPED, PAPER_PRINTED, PAPER_UNILATERAL = range(6)
STUCK, PLAIN = 0, 2
CONTACT_READINGS = ("printed", "unilateral")


@kernel(python=True, inline="always")
def hertz_power(ad, alpha):
    """``ad**alpha`` for ``ad >= 0``; Hertz's 3/2 as the cheaper ``ad*sqrt(ad)``."""
    if alpha == 1.5:
        return ad * math.sqrt(ad)
    return ad**alpha


@kernel
def _sign(x):
    return 1.0 if x > 0 else (-1.0 if x < 0 else 0.0)


@kernel(inline="always")
def is_filippov(code):
    """Whether the law's sign factor needs stick/slip modes (``paper``)."""
    return code == PAPER_PRINTED or code == PAPER_UNILATERAL


@kernel(python=True)
def contact_force(code, delta, deltadot, mode, K, damping, alpha):
    """Contact force ``P`` (N, positive pushing the bodies apart) while slipping or free.

    ``mode`` is ignored except by ``paper`` (sign factor); the stuck force of ``paper`` is not a
    function of ``(delta, deltadot)`` and comes from :func:`phaseimpact.model.rhs.stick_force`.
    """
    if code == ABRATE:
        return K * hertz_power(delta, alpha) if delta > 0 else 0.0
    if code == ABRATE_BILATERAL:
        return K * hertz_power(abs(delta), alpha) * _sign(delta)
    if code == HUNT_CROSSLEY or code == HUNT_CROSSLEY_CLAMPED:
        if delta <= 0:
            return 0.0
        force = (K + damping * deltadot) * hertz_power(delta, alpha)
        return max(force, 0.0) if code == HUNT_CROSSLEY_CLAMPED else force
    # paper (eq. 8)
    if code == PAPER_UNILATERAL and delta <= 0:
        return 0.0
    sign = _sign(deltadot) if mode == PLAIN else float(mode)
    return (K + damping * deltadot) * hertz_power(abs(delta), alpha) * sign


@kernel(python=True)
def force_partials(code, delta, deltadot, mode, K, damping, alpha):
    """``(dP/ddelta, dP/ddeltadot)`` of :func:`contact_force` (exact; zero where ``P`` is 0).

    At ``delta = 0`` the Hertz stiffness ``alpha K |delta|^(alpha-1)`` is exactly zero for
    ``alpha > 1``, which a finite difference would blur.
    """
    ad = abs(delta)
    stiffness = alpha * hertz_power(ad, alpha) / ad if ad > 0 else 0.0  # d|delta|^alpha / d|delta|
    if code == ABRATE:
        return (K * stiffness, 0.0) if delta > 0 else (0.0, 0.0)
    if code == ABRATE_BILATERAL:
        return K * stiffness, 0.0
    if code == HUNT_CROSSLEY or code == HUNT_CROSSLEY_CLAMPED:
        if delta <= 0:
            return 0.0, 0.0
        if code == HUNT_CROSSLEY_CLAMPED and K + damping * deltadot <= 0:
            return 0.0, 0.0
        return (K + damping * deltadot) * stiffness, damping * hertz_power(ad, alpha)
    if code == PAPER_UNILATERAL and delta <= 0:
        return 0.0, 0.0
    sign = _sign(deltadot) if mode == PLAIN else float(mode)
    return sign * (K + damping * deltadot) * stiffness * _sign(delta), sign * damping * hertz_power(ad, alpha)


@kernel(python=True)
def contact_potential(code, delta, K, alpha):
    """Potential of the elastic term, ``K |delta|^(alpha+1)/(alpha+1)`` (J), for the laws whose
    elastic term is conservative; 0 for ``paper``, whose elastic term acts like friction."""
    if code == PAPER_PRINTED or code == PAPER_UNILATERAL:
        return 0.0
    if delta <= 0 and code != ABRATE_BILATERAL:
        return 0.0
    ad = abs(delta)
    return K * ad * hertz_power(ad, alpha) / (alpha + 1.0)


@dataclass(frozen=True)
class LawEntry:
    """A registered contact law.

    Attributes
    ----------
    name : str
    code : int
        Kernel code (options may select a variant, see :attr:`ContactLaw.code`).
    damping : {None, "kappa", "restitution"}
        The law's one source of damping: the parameter ``kappa``, a coefficient of
        restitution, or none.
    filippov : bool
        The law's sign factor needs stick/slip modes (``paper``).
    unilateral : bool
        The law acts only while ``delta > 0`` (before options).
    conservative : bool
        The elastic term has a potential (docs/physics.md §4 energy ledger).
    chi : callable or None
        Damping factor ``chi(e)`` of a restitution law, ``kappa = chi(e) K / v``.
    description : str
    """

    name: str
    code: int
    damping: str | None
    filippov: bool
    unilateral: bool
    conservative: bool
    chi: object = None
    description: str = ""


REGISTRY: dict[str, LawEntry] = {}


def register(entry: LawEntry) -> LawEntry:
    REGISTRY[entry.name] = entry
    return entry


register(LawEntry("abrate", ABRATE, None, False, True, True,
                  description="Hertz contact, no damping (seed eq. 2)"))
register(LawEntry("paper", PAPER_PRINTED, "kappa", True, False, False,
                  description="eq. 8: (K + kappa deltadot) |delta|^alpha sgn(deltadot)"))
register(LawEntry("hunt-crossley", HUNT_CROSSLEY, "kappa", False, True, True,
                  description="(K + kappa deltadot) delta^alpha for delta > 0"))
for _name, _chi, _text in (
    ("hunt-crossley-approx", lambda e: 1.5 * (1 - e), "chi = 3(1-e)/2"),
    ("lankarani-nikravesh", lambda e: 0.75 * (1 - e * e), "chi = 3(1-e^2)/4"),
    ("flores", lambda e: 1.6 * (1 - e) / e, "chi = 8(1-e)/(5e)"),
    ("gonthier", lambda e: (1 - e * e) / e, "chi = (1-e^2)/e"),
):
    register(LawEntry(_name, HUNT_CROSSLEY, "restitution", False, True, True, chi=_chi,
                      description=f"K delta^alpha (1 + chi deltadot / v), {_text}"))

LAWS = tuple(REGISTRY)


@dataclass(frozen=True)
class ContactLaw:
    """A registered law with its options.

    Attributes
    ----------
    name : str
        One of :data:`LAWS`.
    restitution : float or None
        Coefficient of restitution ``e`` in (0, 1]: required by the restitution laws (their
        only damping); for ``hunt-crossley`` it *replaces* ``kappa`` through the exact inverse
        (:func:`phaseimpact.model.restitution.kappa_for_restitution`), and ``kappa`` is then not
        read. Not allowed for ``abrate`` or ``paper``.
    bilateral : bool
        ``abrate`` only: the contact also pulls (``K |delta|^alpha sgn(delta)``).
    clamp : bool
        Hunt-Crossley family only: ``P >= 0`` (no adhesion at the end of contact).
    contact : {"printed", "unilateral"}
        ``paper`` only: the reading of ``|delta|^alpha`` (docs/physics.md §3).
    """

    name: str = "paper"
    restitution: float | None = None
    bilateral: bool = False
    clamp: bool = False
    contact: str = "printed"

    def __post_init__(self):
        require_choice("law", self.name, LAWS)
        require_choice("contact", self.contact, CONTACT_READINGS)
        entry = self.entry
        if self.restitution is not None:
            e = self.restitution
            require("restitution", e, "a number with 1e-6 <= e <= 1",
                    isinstance(e, (int, float, np.floating, np.integer)) and not isinstance(e, bool)
                    and math.isfinite(e) and 1e-6 <= e <= 1)
            object.__setattr__(self, "restitution", float(e))
            if entry.damping != "restitution" and self.name != "hunt-crossley":
                raise ValueError(f"restitution = {e!r} is not read by law {self.name!r}; allowed with the "
                                 "restitution laws and hunt-crossley")
        elif entry.damping == "restitution":
            raise ValueError(f"law {self.name!r} needs a restitution coefficient (restitution in [1e-6, 1])")
        if self.bilateral and self.name != "abrate":
            raise ValueError(f"bilateral = True is only allowed for law 'abrate', not {self.name!r}")
        if self.clamp and entry.code != HUNT_CROSSLEY:
            raise ValueError(f"clamp = True is only allowed for the Hunt-Crossley laws, not {self.name!r}")
        if self.contact != "printed" and not entry.filippov:
            raise ValueError(f"contact = {self.contact!r} is only allowed for law 'paper' "
                             f"(law {self.name!r} is unilateral already)")

    @property
    def entry(self) -> LawEntry:
        return REGISTRY[self.name]

    @property
    def code(self) -> int:
        """Kernel code of this law with its options."""
        code = self.entry.code
        if self.bilateral:
            return ABRATE_BILATERAL
        if self.clamp:
            return HUNT_CROSSLEY_CLAMPED
        if code == PAPER_PRINTED and self.contact == "unilateral":
            return PAPER_UNILATERAL
        return code

    @property
    def is_filippov(self) -> bool:
        return self.entry.filippov

    @property
    def is_unilateral(self) -> bool:
        return self.code in (ABRATE, HUNT_CROSSLEY, HUNT_CROSSLEY_CLAMPED, PAPER_UNILATERAL)

    @property
    def is_conservative(self) -> bool:
        return self.entry.conservative

    @property
    def damping_source(self) -> str | None:
        """``"kappa"``, ``"restitution"`` or None: the one parameter that sets the damping."""
        if self.restitution is not None:
            return "restitution"
        return self.entry.damping

    def reads(self, name: str) -> bool:
        """Whether a parameter named ``name`` changes this law's results (``kappa`` is read only
        by laws whose damping comes from it)."""
        if name == "kappa":
            return self.damping_source == "kappa"
        if name == "restitution":
            return self.damping_source == "restitution"
        return True

    def kappa(self, params: Parameters) -> float:
        """Effective damping coefficient (N s/m^(1+alpha)) of this law for ``params``."""
        source = self.damping_source
        if source is None:
            return 0.0
        if source == "kappa":
            return float(params.kappa)
        if self.entry.chi is not None:
            return float(self.entry.chi(self.restitution) * params.K / params.v)
        from .restitution import kappa_for_restitution  # the exact inverse (hunt-crossley)
        return kappa_for_restitution(self.restitution, params)

    def label(self) -> str:
        """Short description with options, for results and archives."""
        parts = [self.name]
        if self.entry.filippov:
            parts.append(f"contact={self.contact}")
        if self.bilateral:
            parts.append("bilateral")
        if self.clamp:
            parts.append("clamp")
        if self.restitution is not None:
            parts.append(f"e={self.restitution:g}")
        return " ".join(parts)

    def as_dict(self) -> dict:
        return {"name": self.name, "restitution": self.restitution, "bilateral": self.bilateral,
                "clamp": self.clamp, "contact": self.contact}


def as_law(law) -> ContactLaw:
    """Accept a :class:`ContactLaw` or a law name."""
    if isinstance(law, ContactLaw):
        return law
    if isinstance(law, str) and law in REGISTRY:
        return _named_law(law)
    return ContactLaw(law)  # raises the usual error


@functools.cache
def _named_law(name: str) -> ContactLaw:
    return ContactLaw(name)


def law_variants() -> list[ContactLaw]:
    """Every registered law with every option it allows (for conformance tests)."""
    variants = []
    for entry in REGISTRY.values():
        e = 0.6 if entry.damping == "restitution" else None
        variants.append(ContactLaw(entry.name, restitution=e))
        if entry.name == "abrate":
            variants.append(ContactLaw("abrate", bilateral=True))
        if entry.code == HUNT_CROSSLEY:
            variants.append(ContactLaw(entry.name, restitution=e, clamp=True))
        if entry.filippov:
            variants.append(ContactLaw(entry.name, contact="unilateral"))
    return variants
