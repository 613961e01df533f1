"""Material, geometry and the derived model parameters (seed eq. 3-5, 7).

The seed's formulas are used as printed except where docs/physics.md §2 corrects them:

* eq. 3 omits the contact compliance ``eta``: ``K = 4 sqrt(R) / (3 eta)`` (Johnson);
* eq. 5a prints ``h``; the bending stiffness needs ``h**3``:
  ``Kb = 4 pi E h^3 / (3 (1 - nu^2) a^2)``;
* eq. 5b (``Km``) is kept as printed, with ``(1 - nu)`` in the denominator offered as
  ``membrane="shivakumar"``.

All quantities are SI: m, kg, Pa, N/m^alpha, N s/m^(1+alpha). Every numeric field accepts any
real number type (Python or NumPy, a 0-d array included; ``bool`` is not a number) and is stored as a
plain ``float``. Materials, geometry and the impact speed are bounded by generous physical ranges
(:data:`MODULUS_RANGE`, ...): a value beyond them is a typo or a unit slip, refused with its own name
instead of overflowing a derived quantity.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import sys
from collections.abc import Mapping
from dataclasses import dataclass

__all__ = [
    "FIRST_YIELD_FACTOR",
    "Material",
    "Geometry",
    "Parameters",
    "TARGETS",
    "MEMBRANE_FORMULAS",
    "GEOMETRY_NAMES",
    "MATERIAL_NAMES",
    "OVERRIDE_NAMES",
    "derive_parameters",
    "parameters_with",
    "seed_parameters",
    "dotted_overrides",
    "STEEL",
    "MODULUS_RANGE",
    "DENSITY_RANGE",
    "STRENGTH_RANGE",
    "LENGTH_RANGE",
    "R2_RANGE",
    "V_RANGE",
    "KAPPA_MAX",
]

TARGETS = ("plate", "rigid", "free", "infinite")
#: Targets whose contact moves the projectile's mass alone (:attr:`Parameters.reduced_mass` is ``M1``).
M1_ALONE_TARGETS = ("rigid", "infinite")
MEMBRANE_FORMULAS = ("printed", "shivakumar")
BODIES = ("projectile", "plate")
MATERIAL_FIELDS = ("E", "nu", "rho", "yield_strength")
GEOMETRY_NAMES = ("a", "h", "R1", "R2")

# Physical ranges of the inputs (SI). Every real material and size lies well inside them; beyond
# them a derived quantity (M1, K, Kb...) overflows or underflows, or the run cannot be resolved.
#: Young's modulus, Pa: soft gels (1e3) to beyond diamond (1.2e12).
MODULUS_RANGE = (1e3, 1e13)
#: Density, kg/m^3: aerogels (0.1) to beyond osmium (2.26e4).
DENSITY_RANGE = (1e-1, 1e5)
#: Yield (or compressive) strength, Pa.
STRENGTH_RANGE = (1e3, 1e12)
#: Plate radius, thickness and projectile radius, m: a nanometre to a kilometre.
LENGTH_RANGE = (1e-9, 1e3)
#: Radius of curvature of the target, m (a flat target is a large R2).
R2_RANGE = (1e-9, 1e12)
#: Impact speed, m/s: quasi-static to far beyond any Hertz contact.
V_RANGE = (1e-6, 1e4)
#: Largest damping coefficient of the inputs, N s/m^(1+alpha) (the seed's kappa_c is about 1.5e12).
KAPPA_MAX = 1e18


def require(name: str, value, allowed: str, ok: bool) -> None:
    """Raise ``ValueError`` naming ``name``, its ``value`` and the ``allowed`` range."""
    if not ok:
        raise ValueError(f"{name} = {value!r} is out of range; allowed: {allowed}")


# The checks below test before they call ``require``: a case is validated on every ``replace``
# (a loop over kappa makes one per run), and most inputs pass.

def require_positive(name: str, value) -> None:
    if not (is_finite_number(value) and value > 0):
        require(name, value, "a finite number > 0", False)


def require_nonnegative(name: str, value) -> None:
    if not (is_finite_number(value) and value >= 0):
        require(name, value, "a finite number >= 0", False)


def require_in(name: str, value, bounds: tuple, unit: str = "") -> None:
    """``low <= value <= high`` for finite numbers; the message gives the range and the unit."""
    low, high = bounds
    if not (is_finite_number(value) and low <= value <= high):
        require(name, value, f"{low:g} <= {name} <= {high:g}" + (f" ({unit})" if unit else ""), False)


def require_choice(name: str, value, choices) -> None:
    if value not in choices:
        require(name, value, "one of " + ", ".join(map(str, choices)), False)


def is_number(value) -> bool:
    """True for any real number type (int, float, NumPy scalars and 0-d arrays), False for ``bool``."""
    if type(value) is float or type(value) is int:  # the common case, without the ABC checks below
        return True
    np = sys.modules.get("numpy")  # a NumPy value means NumPy is imported: asking costs no import
    if np is not None and isinstance(value, np.ndarray):  # a 0-d array is a scalar (a reduction's result)
        return value.ndim == 0 and value.dtype.kind in "iuf"
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def is_finite_number(value) -> bool:
    """True for a finite real number (:func:`is_number`)."""
    if type(value) is float:  # the common case
        return math.isfinite(value)
    return is_number(value) and math.isfinite(value)


def _store_floats(obj, names) -> None:
    # Frozen dataclasses: normalise NumPy and integer inputs to plain floats after validation,
    # so that results, JSON output and equality never depend on the caller's number type.
    for name in names:
        value = getattr(obj, name)
        if value is not None and type(value) is not float:
            object.__setattr__(obj, name, float(value))


def validate_material(values: Mapping, prefix: str = "") -> None:
    """Check the fields of a :class:`Material` given as a mapping.

    Parameters
    ----------
    values : Mapping
        ``E``, ``nu``, ``rho`` and optionally ``yield_strength``.
    prefix : str
        Prepended to the field names in error messages (``"plate."``, ``"projectile_"``).

    Raises
    ------
    ValueError
        Naming the (prefixed) field, its value and the allowed range.
    """
    require_in(prefix + "E", values["E"], MODULUS_RANGE, "Pa")
    nu = values["nu"]
    require(prefix + "nu", nu, "0 <= nu < 0.5", is_finite_number(nu) and 0 <= nu < 0.5)
    require_in(prefix + "rho", values["rho"], DENSITY_RANGE, "kg/m^3")
    strength = values.get("yield_strength")
    if strength is not None:
        low, high = STRENGTH_RANGE
        require(prefix + "yield_strength", strength, f"{low:g} <= {prefix}yield_strength <= {high:g} (Pa), or absent",
                is_finite_number(strength) and low <= strength <= high)


def validate_geometry(values: Mapping, prefix: str = "") -> None:
    """Check the fields of a :class:`Geometry` (m, within :data:`LENGTH_RANGE`, ``R2`` within
    :data:`R2_RANGE`); messages name ``prefix + field``."""
    for name in GEOMETRY_NAMES:
        require_in(prefix + name, values[name], R2_RANGE if name == "R2" else LENGTH_RANGE, "m")


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material.

    Attributes
    ----------
    E : float
        Young's modulus, Pa (:data:`MODULUS_RANGE`).
    nu : float
        Poisson's ratio, dimensionless (0 <= nu < 0.5).
    rho : float
        Density, kg/m^3 (:data:`DENSITY_RANGE`).
    yield_strength : float or None
        Yield (or, for brittle and polymeric materials, compressive) strength, Pa
        (:data:`STRENGTH_RANGE`), if known.
        It drives the validity check of elastic Hertz contact (first yield at ``p0 ≈ 1.6 Y``).

    Examples
    --------
    >>> from phaseimpact.parameters import Material
    >>> Material(E=7e10, nu=0.33, rho=2700, yield_strength=2.75e8)  # aluminium; stored as floats
    Material(E=70000000000.0, nu=0.33, rho=2700.0, yield_strength=275000000.0)
    >>> Material(E=2.1e14, nu=0.3, rho=7850.0)  # GPa taken for Pa
    Traceback (most recent call last):
        ...
    ValueError: E = 210000000000000.0 is out of range; allowed: 1000 <= E <= 1e+13 (Pa)
    """

    E: float
    nu: float
    rho: float
    yield_strength: float | None = None

    def __post_init__(self):
        validate_material(vars(self))  # its fields: numbers, read only
        _store_floats(self, MATERIAL_FIELDS)


#: Steel, as docs/physics.md §2 fixes it for the seed (the seed gives only E; no yield strength).
STEEL = Material(E=2.1e11, nu=0.3, rho=7850.0)


@dataclass(frozen=True)
class Geometry:
    """Projectile and plate geometry (seed eq. 7); lengths within :data:`LENGTH_RANGE` (``R2``:
    :data:`R2_RANGE`).

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

    Examples
    --------
    >>> from phaseimpact.parameters import Geometry
    >>> Geometry()  # the seed's (eq. 7)
    Geometry(a=0.1, h=0.005, R1=0.02, R2=2000.0)
    >>> print(f"R = {Geometry(R1=0.005).effective_radius:.6g} m")
    R = 0.00499999 m
    """

    a: float = 0.1
    h: float = 0.005
    R1: float = 0.02
    R2: float = 2e3

    def __post_init__(self):
        validate_geometry(vars(self))
        _store_floats(self, GEOMETRY_NAMES)

    @property
    def effective_radius(self) -> float:
        """``R = R1 R2 / (R1 + R2)``, m (docs/physics.md §2)."""
        return self.R1 * self.R2 / (self.R1 + self.R2)


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
        Impact speed of the projectile, m/s (initial condition eq. 6; :data:`V_RANGE`).
    target : str
        ``"plate"`` (eq. 1), ``"rigid"`` (target held fixed), ``"free"`` (no springs) or
        ``"infinite"`` (the infinite plate: a dashpot of :attr:`impedance` at the load point,
        docs/physics.md §8; ``M2``, ``Kb``, ``Km`` take no part).
    R : float or None
        Effective contact radius ``R1 R2/(R1+R2)``, m, filled by :func:`derive_parameters`; not
        used by the equations of motion, only by contact radius and pressure (Hertz). ``None``
        when the parameters are given directly without it.
    limiting_pressure : float or None
        Thornton's limiting contact pressure ``p_y``, Pa, read by the ``thornton`` law only: the
        Hertz peak pressure at first yield, ``1.60 Y`` of the weaker body with a ``yield_strength``
        (:data:`FIRST_YIELD_FACTOR`), filled by :func:`derive_parameters`; ``None`` without one.
    impedance : float or None
        The infinite plate's point impedance ``c = 8 sqrt(D* rho h)``, N s/m (Zener 1941;
        ``D*`` Olsson's effective rigidity, ``D`` for an isotropic plate; docs/physics.md §8),
        filled by :func:`derive_parameters`; read by the ``infinite`` target only, which needs it.

    Examples
    --------
    Usually derived (:func:`seed_parameters`, :func:`derive_parameters`), but the numbers can be
    given directly:

    >>> from phaseimpact.parameters import Parameters
    >>> p = Parameters(M1=0.26, M2=0.31, K=2.2e10, Kb=1.2e7, Km=1.7e11, v=2.0)
    >>> print(f"{p.reduced_mass:.4g} kg, {p.target_period:.4g} s, {p.hertz_indentation:.4g} m")
    0.1414 kg, 0.00101 s, 6.35e-05 m
    >>> p.R is None, p.yield_velocity is None
    (True, True)
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
    R: float | None = None
    limiting_pressure: float | None = None
    impedance: float | None = None

    def __post_init__(self):
        for name in ("M1", "M2", "K", "alpha"):
            require_positive(name, getattr(self, name))
        require_in("v", self.v, V_RANGE, "m/s")
        for name in ("Kb", "Km", "kappa"):
            require_nonnegative(name, getattr(self, name))
        require_choice("target", self.target, TARGETS)
        for name in ("R", "limiting_pressure", "impedance"):
            value = getattr(self, name)
            if value is not None:
                require(name, value, "a finite number > 0, or None", is_finite_number(value) and value > 0)
        if self.target == "infinite":
            require("impedance", self.impedance, "a finite number > 0 (N s/m) for target 'infinite': the plate's "
                    "point impedance 8 sqrt(D rho h), which derive_parameters fills", self.impedance is not None)
        _store_floats(self, ("M1", "M2", "K", "Kb", "Km", "alpha", "kappa", "v", "R", "limiting_pressure",
                             "impedance"))

    def replace(self, **changes) -> Parameters:
        """A copy with ``changes`` applied (and validated); unknown names raise ``ValueError``.

        Parameters
        ----------
        **changes
            New values of any fields (``kappa=1e9``, ``v=13.0``, ``target="rigid"``, ``M1=0.01``,
            ...), in the units of the attributes (SI). Derived fields are not re-derived: a new
            ``K`` is taken as given.

        Returns
        -------
        Parameters
            A new, validated instance; ``self`` is unchanged.

        Raises
        ------
        ValueError
            For an unknown name (the message lists the fields) or a value out of range.

        Examples
        --------
        >>> from phaseimpact.parameters import seed_parameters
        >>> p = seed_parameters(v=1.0)
        >>> q = p.replace(kappa=1e9, v=13.0)
        >>> q.kappa, q.v, q.M1 == p.M1
        (1000000000.0, 13.0, True)
        >>> p.replace(kapa=1e9)
        Traceback (most recent call last):
            ...
        ValueError: unknown parameter 'kapa'; allowed: M1, M2, K, Kb, Km, alpha, kappa, v, target, R, ...
        """
        _reject_unknown(changes, PARAMETER_NAMES)
        # the fields with the changes, validated by __post_init__ as a new instance is: what
        # dataclasses.replace does through a generic __init__, in half the time (a loop over kappa
        # makes one a run)
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__, **changes)
        new.__post_init__()
        return new

    @property
    def target_period(self) -> float:
        """Small-amplitude period of the target on its springs, s (inf without springs)."""
        if self.target != "plate" or self.Kb == 0:
            return math.inf
        return 2 * math.pi * math.sqrt(self.M2 / self.Kb)

    @property
    def reduced_mass(self) -> float:
        """Mass of the relative motion during contact, kg (``M1`` against a rigid target or the
        massless load point of the infinite plate)."""
        if self.target in M1_ALONE_TARGETS:
            return self.M1
        return self.M1 * self.M2 / (self.M1 + self.M2)

    @property
    def yield_velocity(self) -> float | None:
        """Impact speed at which the Hertz peak pressure reaches :attr:`limiting_pressure`, m/s
        (Thornton 1997, eq. 7): ``v_y = sqrt(4 K delta_y^(5/2) / (5 m))`` (the undamped Hertz
        impact's energy ``2/5 F_y delta_y``) with ``delta_y = R (pi p_y / (2 E*))^2``,
        ``E* = 3 K / (4 sqrt(R))`` and ``m`` the reduced mass; for a sphere on a rigid wall
        ``v_y = (pi^2 / sqrt(40)) sqrt(p_y^5 / (E*^4 rho)) = 1.56 sqrt(p_y^5 / (E*^4 rho))``.
        None without a limiting pressure or a radius."""
        if self.limiting_pressure is None or self.R is None:
            return None
        e_star = 0.75 * self.K / math.sqrt(self.R)
        delta_y = self.R * (0.5 * math.pi * self.limiting_pressure / e_star) ** 2
        return math.sqrt(4.0 * self.K * delta_y**2.5 / (5.0 * self.reduced_mass))

    @property
    def hertz_indentation(self) -> float:
        """Largest indentation of the undamped impact of the reduced mass, m (docs/physics.md §4):
        ``((alpha+1) m v^2 / (2K))^(1/(alpha+1))``, ``(5 m v^2/(4K))^(2/5)`` for Hertz."""
        return indentation_of(self.alpha, self.reduced_mass, self.v, self.K)

    def as_dict(self) -> dict:
        """The parameters as a plain dict (for JSON; ``None`` stays ``None``).

        Returns
        -------
        dict
            ``{field: value}`` in the order of the attributes (SI units).

        Examples
        --------
        >>> from phaseimpact.parameters import seed_parameters
        >>> d = seed_parameters(v=13.0).as_dict()
        >>> list(d)[:5], d["v"], d["limiting_pressure"]
        (['M1', 'M2', 'K', 'Kb', 'Km'], 13.0, None)
        """
        return dataclasses.asdict(self)


PARAMETER_NAMES = tuple(f.name for f in dataclasses.fields(Parameters))
#: First yield under a Hertz contact at ``p0 = 1.60 Y`` (von Mises, nu = 0.3; Johnson 1985, §4.2 and §11.4).
FIRST_YIELD_FACTOR = 1.60
#: Material names accepted by :func:`seed_parameters`: ``projectile_E``, ..., ``plate_yield_strength``.
MATERIAL_NAMES = tuple(f"{body}_{field}" for body in BODIES for field in MATERIAL_FIELDS)
#: Every name :func:`seed_parameters` and :func:`parameters_with` accept as an override.
OVERRIDE_NAMES = GEOMETRY_NAMES + MATERIAL_NAMES + PARAMETER_NAMES + ("membrane",)


def _reject_unknown(names, allowed) -> None:
    unknown = [name for name in names if name not in allowed]
    if unknown:
        label = "parameter" if len(unknown) == 1 else "parameters"
        raise ValueError(f"unknown {label} {', '.join(map(repr, unknown))}; allowed: {', '.join(allowed)}")


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
    """Derive ``M1, M2, K, Kb, Km`` (and ``R``) from materials and geometry (seed eq. 3-5, docs/physics.md §2).

    Parameters
    ----------
    projectile : Material
        Material of the ball.
    plate : Material or Laminate
        Material of the plate, or a :class:`~phaseimpact.model.laminate.Laminate` (docs/physics.md
        §8: its areal density, ``K`` with its top ply's half-space compliance, ``Kb`` from its
        bending stiffness, or Abrate's ``Kbs`` when its plies give ``G13, G23``, ``Km`` from ``A``);
        ``geometry.h`` must then be the plies' total thickness.
    geometry : Geometry
        Plate radius and thickness, projectile and target radii.
    membrane : {"printed", "shivakumar"}
        ``Km`` with ``(1 - nu^2)`` as eq. 5b prints it, or ``(1 - nu)`` as in Shivakumar's table.
    alpha, kappa, v, target
        Passed through to :class:`Parameters`: contact exponent, damping (N s/m^(1+alpha)),
        impact speed (m/s), one of :data:`TARGETS`.

    Returns
    -------
    Parameters
        ``M1`` (kg), ``M2`` (kg, a quarter of the plate), ``K`` (N/m^1.5), ``Kb`` (N/m), ``Km``
        (N/m^3), the effective radius ``R`` (m), the infinite plate's ``impedance``
        ``8 sqrt(D* rho h)`` (N s/m, docs/physics.md §8) and, when a material gives a
        ``yield_strength``, the ``limiting_pressure`` ``1.6 Y`` (Pa) of the weaker one.

    Raises
    ------
    ValueError
        For an unknown ``membrane`` formula or a value out of range.

    Examples
    --------
    A 5 mm steel ball on an aluminium plate at 13 m/s:

    >>> from phaseimpact.parameters import STEEL, Geometry, Material, derive_parameters
    >>> aluminium = Material(E=7e10, nu=0.33, rho=2700.0, yield_strength=2.75e8)
    >>> p = derive_parameters(STEEL, aluminium, Geometry(R1=0.005), v=13.0)
    >>> print(f"M1 = {p.M1:.4g} kg, M2 = {p.M2:.4g} kg, K = {p.K:.4g} N/m^1.5, Kb = {p.Kb:.4g} N/m")
    M1 = 0.00411 kg, M2 = 0.106 kg, K = 5.525e+09 N/m^1.5, Kb = 4.113e+06 N/m
    >>> print(f"p_y = {p.limiting_pressure:.4g} Pa")
    p_y = 4.4e+08 Pa
    """
    require_choice("membrane", membrane, MEMBRANE_FORMULAS)
    g = geometry
    if isinstance(plate, Material):
        E, nu = plate.E, plate.nu
        areal_density = plate.rho * g.h
        M2 = 0.25 * plate.rho * math.pi * g.a**2 * g.h  # a quarter of the plate (this order: bit for bit)
        plate_compliance = (1 - nu**2) / E  # eq. 4
        Kb = 4.0 * math.pi * E * g.h**3 / (3.0 * (1 - nu**2) * g.a**2)  # eq. 5a with h^3
        km_denominator = (1 - nu**2) if membrane == "printed" else (1 - nu)
        Km = (353 - 191 * nu) * math.pi * E * g.h / (648 * km_denominator * g.a**2)  # eq. 5b
        rigidity = E * g.h**3 / (12 * (1 - nu**2))
    else:  # a laminate (model.laminate.Laminate, docs/physics.md §8): it gives its own plate terms
        if not hasattr(plate, "plate_terms"):
            raise TypeError(f"plate has the wrong type ({type(plate).__name__}); allowed: Material or Laminate")
        require("h", g.h, f"the plies' total thickness {plate.thickness!r} m (h of a laminate is the sum of its "
                "plies)", math.isclose(g.h, plate.thickness, rel_tol=1e-12))
        areal_density, plate_compliance, Kb, Km, rigidity = plate.plate_terms(g.a, membrane)
        M2 = 0.25 * math.pi * g.a**2 * areal_density  # a quarter of the plate takes part
    M1 = projectile.rho * 4.0 / 3.0 * math.pi * g.R1**3
    eta = (1 - projectile.nu**2) / projectile.E + plate_compliance  # eq. 4
    R = g.effective_radius
    K = 4.0 * math.sqrt(R) / (3.0 * eta)  # eq. 3 with eta restored
    if not isinstance(plate, Material) and plate.has_shear:
        Kb = _bending_shear(plate, g.a, R, K, M1 * M2 / (M1 + M2), v)
    strengths = [m.yield_strength for m in (projectile, plate) if m.yield_strength is not None]
    p_y = FIRST_YIELD_FACTOR * min(strengths) if strengths else None
    impedance = 8 * math.sqrt(rigidity * areal_density)  # Zener's point impedance (docs/physics.md §8)
    return Parameters(M1=M1, M2=M2, K=K, Kb=Kb, Km=Km, alpha=alpha, kappa=kappa, v=v, target=target, R=R,
                      limiting_pressure=p_y, impedance=impedance)


def indentation_of(alpha: float, reduced_mass: float, v: float, K: float) -> float:
    """:attr:`Parameters.hertz_indentation` of plain floats, m: one expression for a case and for the
    cases of a batch packed on columns (Python's ``**``, whose bits numpy's power need not give)."""
    return ((alpha + 1) * reduced_mass * v**2 / (2 * K)) ** (1 / (alpha + 1))


def _bending_shear(laminate, a: float, R: float, K: float, reduced_mass: float, v: float) -> float:
    """Abrate's ``Kbs`` (docs/physics.md §8): the shear stiffness's load spread over the Hertz contact
    radius ``c = sqrt(R delta)`` at the undamped impact's largest indentation ``delta`` (eq. 3, the
    plate target's reduced mass), so that ``Kb`` then depends on the impact speed."""
    c = math.sqrt(R * (5.0 * reduced_mass * v**2 / (4.0 * K)) ** 0.4)
    require("contact radius", c, f"c < a = {a:g} m (the shear stiffness of plies with G13, G23 spreads the load "
            "over the Hertz contact radius at the peak; give no G13, G23 for bending alone)", c < a)
    return laminate.bending_shear(a, c)


def _replace_material(material, prefix: str, changes: Mapping):
    if not isinstance(material, Material):  # a laminate: only its strength is one number
        bad = [name for name in changes if name != "yield_strength"]
        if bad:
            raise ValueError(f"{prefix}{bad[0]} = {changes[bad[0]]!r} does not apply to a laminate plate; allowed: "
                             f"{prefix}yield_strength (its moduli and density are set per ply, [[plate.ply]])")
        return dataclasses.replace(material, **changes)
    values = {**dataclasses.asdict(material), **changes}
    validate_material(values, prefix)  # so that the message names e.g. "plate_E", not "E"
    return Material(**values)


def parameters_with(
    projectile: Material = STEEL,
    plate: Material = STEEL,
    geometry: Geometry = Geometry(),
    *,
    v: float = 1.0,
    **overrides,
) -> Parameters:
    """Derive :class:`Parameters` from materials and geometry, with named overrides.

    Parameters
    ----------
    projectile, plate : Material
        Base materials.
    geometry : Geometry
        Base geometry.
    v : float
        Impact speed, m/s.
    **overrides
        Any of :data:`OVERRIDE_NAMES`: geometry ``a, h, R1, R2`` (m); materials
        ``projectile_E, projectile_nu, projectile_rho, plate_E, plate_nu, plate_rho`` (Pa, -, kg/m^3)
        and ``*_yield_strength`` (Pa); ``membrane``; any :class:`Parameters` field (``kappa``,
        ``target``, ``alpha``, or a derived value such as ``M1``, which then wins over the
        derivation).

    Returns
    -------
    Parameters
        Derived from the changed materials and geometry (:func:`derive_parameters`), then with the
        :class:`Parameters` fields given in ``overrides`` replaced.

    Raises
    ------
    ValueError
        For an unknown name (the message lists the allowed ones) or a value out of range.

    Examples
    --------
    >>> from phaseimpact.parameters import parameters_with
    >>> p = parameters_with(R1=0.005, plate_E=7e10, kappa=1e9)
    >>> print(f"M1 = {p.M1:.4g} kg, K = {p.K:.4g} N/m^1.5, kappa = {p.kappa:g} N s/m^2.5")
    M1 = 0.00411 kg, K = 5.439e+09 N/m^1.5, kappa = 1e+09 N s/m^2.5
    >>> parameters_with(M1=0.01).M1  # a derived value given wins
    0.01
    """
    _reject_unknown(overrides, OVERRIDE_NAMES)
    overrides = dict(overrides)
    geometry_changes = {name: overrides.pop(name) for name in GEOMETRY_NAMES if name in overrides}
    if geometry_changes:
        validate_geometry({**dataclasses.asdict(geometry), **geometry_changes})
        geometry = Geometry(**{**dataclasses.asdict(geometry), **geometry_changes})
    materials = {"projectile": projectile, "plate": plate}
    for body in BODIES:
        changes = {field: overrides.pop(f"{body}_{field}") for field in MATERIAL_FIELDS
                   if f"{body}_{field}" in overrides}
        if changes:
            materials[body] = _replace_material(materials[body], f"{body}_", changes)
    passed = {name: overrides.pop(name) for name in ("alpha", "kappa", "target", "membrane") if name in overrides}
    if "kappa" in passed:  # an input: bounded as on the command line (searches may go beyond it)
        require_in("kappa", passed["kappa"], (0, KAPPA_MAX), "N s/m^(1+alpha)")
    if "v" in overrides:
        v = overrides.pop("v")
    params = derive_parameters(materials["projectile"], materials["plate"], geometry, v=v, **passed)
    return params.replace(**overrides) if overrides else params


def seed_parameters(v: float = 1.0, **overrides) -> Parameters:
    """The seed's case (eq. 7, steel, docs/physics.md §2) at impact speed ``v`` (m/s), with overrides.

    ``overrides`` may name geometry (``a, h, R1, R2``, m), materials (``projectile_E``,
    ``plate_nu``, ... see :data:`MATERIAL_NAMES`), ``membrane="shivakumar"`` or any
    :class:`Parameters` field (``kappa=1e9``, ``target="rigid"``, ``M1=...``); see
    :func:`parameters_with`. Dotted names (``"plate.E"``) go through :func:`dotted_overrides`.

    Parameters
    ----------
    v : float
        Impact speed, m/s (:data:`V_RANGE`).
    **overrides
        Any of :data:`OVERRIDE_NAMES`, in SI units, as :func:`parameters_with` takes them.

    Returns
    -------
    Parameters
        The seed's parameters (``M1 = 0.2631 kg``, ``K = 2.176e10 N/m^1.5``, ...), changed by the
        overrides.

    Raises
    ------
    ValueError
        For an unknown name (the message lists the allowed names) or a value out of range.

    Examples
    --------
    >>> seed_parameters(13.0, R1=0.005, plate_E=7e10).v
    13.0
    >>> p = seed_parameters(kappa=3e9)
    >>> print(f"M1 = {p.M1:.4g} kg, M2 = {p.M2:.4g} kg, K = {p.K:.4g} N/m^1.5")
    M1 = 0.2631 kg, M2 = 0.3083 kg, K = 2.176e+10 N/m^1.5
    """
    return parameters_with(STEEL, STEEL, Geometry(), v=v, **overrides)


def dotted_overrides(settings: Mapping) -> dict:
    """Translate dotted names (``"plate.E"``, ``"projectile.nu"``) to keyword names (``plate_E``).

    Undotted names pass unchanged; ``seed_parameters(**dotted_overrides({"plate.E": 7e10}))``.

    Parameters
    ----------
    settings : Mapping
        ``{name: value}``; dotted names are ``body.field`` with ``body`` ``projectile`` or
        ``plate`` and ``field`` one of ``E`` (Pa), ``nu``, ``rho`` (kg/m^3), ``yield_strength`` (Pa).

    Returns
    -------
    dict
        The same values under keyword names, in the same order.

    Raises
    ------
    ValueError
        For a dotted name whose body or field is unknown.

    Examples
    --------
    >>> from phaseimpact.parameters import dotted_overrides
    >>> dotted_overrides({"plate.E": 7e10, "v": 13.0})
    {'plate_E': 70000000000.0, 'v': 13.0}
    >>> dotted_overrides({"plate.G": 2.6e10})
    Traceback (most recent call last):
        ...
    ValueError: unknown parameter 'plate.G'; allowed dotted names: projectile.E, projectile.nu, ...
    """
    out = {}
    for name, value in settings.items():
        if "." in name:
            body, _, field = name.partition(".")
            if body not in BODIES or field not in MATERIAL_FIELDS:
                allowed = [f"{b}.{f}" for b in BODIES for f in MATERIAL_FIELDS]
                raise ValueError(f"unknown parameter {name!r}; allowed dotted names: {', '.join(allowed)}")
            name = f"{body}_{field}"
        out[name] = value
    return out
