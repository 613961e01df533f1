"""Material, geometry and the derived model parameters (seed eq. 3-5, 7).

The seed's formulas are used as printed except where REFERENCE §2 corrects them:

* eq. 3 omits the contact compliance ``eta``: ``K = 4 sqrt(R) / (3 eta)`` (Johnson);
* eq. 5a prints ``h``; the bending stiffness needs ``h**3``:
  ``Kb = 4 pi E h^3 / (3 (1 - nu^2) a^2)``;
* eq. 5b (``Km``) is kept as printed, with ``(1 - nu)`` in the denominator offered as
  ``membrane="shivakumar"``.

All quantities are SI: m, kg, Pa, N/m^alpha, N s/m^(1+alpha).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass

__all__ = [
    "Material",
    "Geometry",
    "Parameters",
    "TARGETS",
    "MEMBRANE_FORMULAS",
    "derive_parameters",
    "seed_parameters",
    "STEEL",
]

TARGETS = ("plate", "rigid", "free")
MEMBRANE_FORMULAS = ("printed", "shivakumar")


def require(name: str, value, allowed: str, ok: bool) -> None:
    """Raise ``ValueError`` naming ``name``, its ``value`` and the ``allowed`` range."""
    if not ok:
        raise ValueError(f"{name} = {value!r} is out of range; allowed: {allowed}")


def require_positive(name: str, value) -> None:
    require(name, value, "a finite number > 0", _is_finite(value) and value > 0)


def require_nonnegative(name: str, value) -> None:
    require(name, value, "a finite number >= 0", _is_finite(value) and value >= 0)


def require_choice(name: str, value, choices) -> None:
    require(name, value, "one of " + ", ".join(map(str, choices)), value in choices)


def _is_finite(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material.

    Attributes
    ----------
    E : float
        Young's modulus, Pa (> 0).
    nu : float
        Poisson's ratio, dimensionless (0 <= nu < 0.5).
    rho : float
        Density, kg/m^3 (> 0).
    """

    E: float
    nu: float
    rho: float

    def __post_init__(self):
        require_positive("E", self.E)
        require("nu", self.nu, "0 <= nu < 0.5", _is_finite(self.nu) and 0 <= self.nu < 0.5)
        require_positive("rho", self.rho)


#: Steel, as REFERENCE §2 fixes it for the seed (the seed gives only E).
STEEL = Material(E=2.1e11, nu=0.3, rho=7850.0)


@dataclass(frozen=True)
class Geometry:
    """Projectile and plate geometry (seed eq. 7).

    Attributes
    ----------
    a : float
        Radius of the clamped circular plate (membrane), m.
    h : float
        Plate thickness, m.
    R1 : float
        Radius of the spherical projectile, m.
    R2 : float
        Radius of curvature of the target surface, m.
    """

    a: float = 0.1
    h: float = 0.005
    R1: float = 0.02
    R2: float = 2e3

    def __post_init__(self):
        for name in ("a", "h", "R1", "R2"):
            require_positive(name, getattr(self, name))


@dataclass(frozen=True)
class Parameters:
    """The numbers the equations of motion use (seed eq. 1, 2, 8).

    Attributes
    ----------
    M1 : float
        Projectile mass, kg.
    M2 : float
        Effective target mass, kg.
    K : float
        Hertz contact stiffness, N/m^alpha.
    Kb : float
        Linear (bending) target stiffness, N/m.
    Km : float
        Cubic (membrane) target stiffness, N/m^3.
    alpha : float
        Contact exponent (3/2 for Hertz).
    kappa : float
        Damping characteristic of eq. 8, N s/m^(1+alpha) (>= 0).
    v : float
        Impact speed of the projectile, m/s (initial condition eq. 6).
    target : str
        ``"plate"`` (eq. 1), ``"rigid"`` (target held fixed) or ``"free"`` (no springs).
    """

    M1: float
    M2: float
    K: float
    Kb: float
    Km: float
    alpha: float = 1.5
    kappa: float = 0.0
    v: float = 1.0
    target: str = "plate"

    def __post_init__(self):
        for name in ("M1", "M2", "K", "alpha", "v"):
            require_positive(name, getattr(self, name))
        for name in ("Kb", "Km", "kappa"):
            require_nonnegative(name, getattr(self, name))
        require_choice("target", self.target, TARGETS)

    def replace(self, **changes) -> Parameters:
        """A copy with ``changes`` applied (and validated)."""
        return dataclasses.replace(self, **changes)

    @property
    def target_period(self) -> float:
        """Small-amplitude period of the target on its springs, s (inf without springs)."""
        if self.target != "plate" or self.Kb == 0:
            return math.inf
        return 2 * math.pi * math.sqrt(self.M2 / self.Kb)

    @property
    def reduced_mass(self) -> float:
        """Mass of the relative motion during contact, kg."""
        if self.target == "rigid":
            return self.M1
        return self.M1 * self.M2 / (self.M1 + self.M2)

    @property
    def hertz_indentation(self) -> float:
        """Largest indentation of the undamped impact of the reduced mass, m (REFERENCE §4):
        ``((alpha+1) m v^2 / (2K))^(1/(alpha+1))``, ``(5 m v^2/(4K))^(2/5)`` for Hertz."""
        a = self.alpha
        return ((a + 1) * self.reduced_mass * self.v**2 / (2 * self.K)) ** (1 / (a + 1))

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def derive_parameters(
    projectile: Material = STEEL,
    plate: Material = STEEL,
    geometry: Geometry = Geometry(),
    *,
    membrane: str = "printed",
    alpha: float = 1.5,
    kappa: float = 0.0,
    v: float = 1.0,
    target: str = "plate",
) -> Parameters:
    """Derive ``M1, M2, K, Kb, Km`` from materials and geometry (seed eq. 3-5, REFERENCE §2).

    Parameters
    ----------
    projectile, plate : Material
        Materials of the ball and of the plate.
    geometry : Geometry
        Plate radius and thickness, projectile and target radii.
    membrane : {"printed", "shivakumar"}
        ``Km`` with ``(1 - nu^2)`` as eq. 5b prints it, or ``(1 - nu)`` as in Shivakumar's table.
    alpha, kappa, v, target
        Passed through to :class:`Parameters`.
    """
    require_choice("membrane", membrane, MEMBRANE_FORMULAS)
    g, E, nu = geometry, plate.E, plate.nu
    M1 = projectile.rho * 4.0 / 3.0 * math.pi * g.R1**3
    M2 = 0.25 * plate.rho * math.pi * g.a**2 * g.h  # a quarter of the plate takes part
    eta = (1 - projectile.nu**2) / projectile.E + (1 - nu**2) / E  # eq. 4
    R = g.R1 * g.R2 / (g.R1 + g.R2)
    K = 4.0 * math.sqrt(R) / (3.0 * eta)  # eq. 3 with eta restored
    Kb = 4.0 * math.pi * E * g.h**3 / (3.0 * (1 - nu**2) * g.a**2)  # eq. 5a with h^3
    km_denominator = (1 - nu**2) if membrane == "printed" else (1 - nu)
    Km = (353 - 191 * nu) * math.pi * E * g.h / (648 * km_denominator * g.a**2)  # eq. 5b
    return Parameters(M1=M1, M2=M2, K=K, Kb=Kb, Km=Km, alpha=alpha, kappa=kappa, v=v, target=target)


def seed_parameters(v: float = 1.0, **overrides) -> Parameters:
    """The seed's case (eq. 7, steel, REFERENCE §2) at impact speed ``v`` (m/s).

    ``overrides`` may name any :class:`Parameters` field (``kappa=1e9``, ``target="rigid"``)
    or ``membrane="shivakumar"``.
    """
    membrane = overrides.pop("membrane", "printed")
    params = derive_parameters(membrane=membrane, v=v)
    return params.replace(**overrides) if overrides else params
