"""Laminated plates: plies and classical lamination theory (docs/physics.md §8). Pure functions of
the layup, no I/O.

Conventions. Plies are listed from the impacted face down; ``z`` is measured from the mid-plane,
positive in the direction of flight (the impacted face is at ``z = -h/2``). Ply angles are in
degrees from the plate's ``x`` axis. Strains are engineering strains, so ``A``, ``B``, ``D`` are
the usual 3 x 3 matrices of ``(N, M) = [[A, B], [B, D]] (eps0, kappa)`` in the order
``(x, y, xy)`` (Jones, *Mechanics of Composite Materials*, 2nd ed., 1999, ch. 4).

The clamped plate's stiffnesses and its face's contact compliance (what
:meth:`Laminate.plate_terms` reads) are in :mod:`phaseimpact.model.plate_stiffness`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass

from .._lazy import NumPyOnFirstUse
from ..parameters import (
    DENSITY_RANGE,
    LENGTH_RANGE,
    MODULUS_RANGE,
    STRENGTH_RANGE,
    Material,
    is_finite_number,
    require,
    require_in,
)
from .plate_stiffness import (
    bending_shear_stiffness,
    bending_stiffness,
    membrane_stiffness,
    olsson_rigidity,
    shear_stiffness,
    top_ply_compliance,
)

# NumPy is imported when a laminate is first computed with: the commands that integrate nothing
# (``cases``, ``params`` of an isotropic plate) import this module but never NumPy.
np = NumPyOnFirstUse(globals())

__all__ = ["Ply", "Laminate", "validate_ply", "transformed_stiffness", "as_laminate", "SHEAR_FACTOR"]

#: Mindlin/Reissner shear correction factor of a homogeneous section.
SHEAR_FACTOR = 5.0 / 6.0
#: A ply's fields, as a case file's ``[[plate.ply]]`` table names them (``G13``, ``G23`` optional).
PLY_FIELDS = ("E1", "E2", "G12", "nu12", "rho", "angle", "thickness", "G13", "G23")


def validate_ply(values: Mapping, prefix: str = "") -> None:
    """Check a ply's fields given as a mapping (a case file's ``[[plate.ply]]`` table).

    Parameters
    ----------
    values : Mapping
        ``E1, E2, G12, nu12, rho, angle, thickness`` and optionally ``G13, G23`` (see :class:`Ply`).
    prefix : str
        Prepended to the field names in error messages (``"plate.ply[2]."``).

    Raises
    ------
    ValueError
        Naming the (prefixed) field, its value and the allowed range; for a missing or unknown field.

    Examples
    --------
    >>> from phaseimpact.model.laminate import validate_ply
    >>> ply = dict(E1=1.4e11, E2=1e10, G12=5e9, nu12=0.3, rho=1600.0, angle=0, thickness=1e-4)
    >>> validate_ply(ply)
    >>> validate_ply({**ply, "angle": 400}, prefix="plate.ply[1].")
    Traceback (most recent call last):
        ...
    ValueError: plate.ply[1].angle = 400 is out of range; allowed: -360 <= angle <= 360 (degrees)
    """
    missing = [name for name in PLY_FIELDS[:7] if name not in values]
    unknown = [name for name in values if name not in PLY_FIELDS]
    if missing or unknown:
        raise ValueError(f"{prefix.rstrip('.') or 'ply'}: missing {', '.join(missing) or 'nothing'}, unknown "
                         f"{', '.join(unknown) or 'nothing'}; allowed: {', '.join(PLY_FIELDS)} (G13, G23 optional)")
    for name in ("E1", "E2", "G12"):
        require_in(prefix + name, values[name], MODULUS_RANGE, "Pa")
    nu12, bound = values["nu12"], math.sqrt(values["E1"] / values["E2"])
    require(prefix + "nu12", nu12, f"|nu12| < sqrt(E1/E2) = {bound:g}", is_finite_number(nu12) and abs(nu12) < bound)
    require_in(prefix + "rho", values["rho"], DENSITY_RANGE, "kg/m^3")
    angle = values["angle"]
    require(prefix + "angle", angle, "-360 <= angle <= 360 (degrees)", is_finite_number(angle) and abs(angle) <= 360)
    require_in(prefix + "thickness", values["thickness"], LENGTH_RANGE, "m")
    G13, G23 = values.get("G13"), values.get("G23")
    require(prefix + "G13", G13, "both G13 and G23 (Pa), or neither", (G13 is None) == (G23 is None))
    for name, value in (("G13", G13), ("G23", G23)):
        if value is not None:
            require_in(prefix + name, value, MODULUS_RANGE, "Pa")


@dataclass(frozen=True)
class Ply:
    """One orthotropic ply (a unidirectional layer, or an isotropic one with ``E1 = E2``).

    Attributes
    ----------
    E1, E2 : float
        Young's moduli along and across the fibres, Pa (:data:`~phaseimpact.parameters.MODULUS_RANGE`).
        ``E2`` is also the through-thickness modulus ``E3`` (transverse isotropy of the ply).
    G12 : float
        In-plane shear modulus, Pa.
    nu12 : float
        Major Poisson's ratio, dimensionless, ``|nu12| < sqrt(E1/E2)`` (a positive-definite ``Q``).
    rho : float
        Density, kg/m^3.
    angle : float
        Fibre angle from the plate's ``x`` axis, degrees, ``-360 <= angle <= 360``.
    thickness : float
        Ply thickness, m.
    G13, G23 : float or None
        Transverse shear moduli, Pa; both or neither (they switch on the shear stiffness ``Ks``).

    Examples
    --------
    >>> from phaseimpact.model.laminate import Ply
    >>> ply = Ply(E1=1.4e11, E2=1e10, G12=5e9, nu12=0.3, rho=1600.0, angle=45, thickness=1.25e-4)
    >>> ply.angle, ply.has_shear
    (45.0, False)
    >>> Ply(E1=1.4e11, E2=1e10, G12=5e9, nu12=4.0, rho=1600.0, angle=0, thickness=1e-4)
    Traceback (most recent call last):
        ...
    ValueError: nu12 = 4.0 is out of range; allowed: |nu12| < sqrt(E1/E2) = 3.74166
    """

    E1: float
    E2: float
    G12: float
    nu12: float
    rho: float
    angle: float
    thickness: float
    G13: float | None = None
    G23: float | None = None

    def __post_init__(self):
        validate_ply(dataclasses.asdict(self))
        for name in PLY_FIELDS:
            if getattr(self, name) is not None:
                object.__setattr__(self, name, float(getattr(self, name)))

    @classmethod
    def isotropic(cls, E: float, nu: float, rho: float, thickness: float, angle: float = 0.0,
                  shear: bool = False) -> Ply:
        """An isotropic ply: ``E1 = E2 = E``, ``G12 = E / (2 (1 + nu))``.

        Parameters
        ----------
        E : float
            Young's modulus, Pa.
        nu : float
            Poisson's ratio.
        rho : float
            Density, kg/m^3.
        thickness : float
            Ply thickness, m.
        angle : float
            Ply angle, degrees (no effect on an isotropic ply's stiffness).
        shear : bool
            Also give ``G13 = G23 = G12`` (transverse shear on).

        Returns
        -------
        Ply

        Examples
        --------
        >>> from phaseimpact.model.laminate import Ply
        >>> Ply.isotropic(2.1e11, 0.3, 7850.0, 0.005).G12
        80769230769.23077
        """
        G = E / (2 * (1 + nu))
        return cls(E1=E, E2=E, G12=G, nu12=nu, rho=rho, angle=angle, thickness=thickness,
                   G13=G if shear else None, G23=G if shear else None)

    @property
    def has_shear(self) -> bool:
        """Whether the transverse shear moduli ``G13``, ``G23`` are given."""
        return self.G13 is not None

    def reduced_stiffness(self) -> np.ndarray:
        """The plane-stress reduced stiffness ``Q`` in the ply's axes (Jones, ch. 2).

        Returns
        -------
        numpy.ndarray
            ``[[Q11, Q12, 0], [Q12, Q22, 0], [0, 0, Q66]]``, Pa, shape (3, 3).

        Examples
        --------
        >>> from phaseimpact.model.laminate import Ply
        >>> (Ply.isotropic(1e9, 0.25, 1000.0, 1e-3).reduced_stiffness() / 1e9).round(4)
        array([[1.0667, 0.2667, 0.    ],
               [0.2667, 1.0667, 0.    ],
               [0.    , 0.    , 0.4   ]])
        """
        nu21 = self.nu12 * self.E2 / self.E1
        scale = 1.0 / (1.0 - self.nu12 * nu21)
        return np.array([[self.E1 * scale, self.nu12 * self.E2 * scale, 0.0],
                         [self.nu12 * self.E2 * scale, self.E2 * scale, 0.0],
                         [0.0, 0.0, self.G12]])


def transformed_stiffness(ply: Ply) -> np.ndarray:
    """The ply's stiffness ``Q-bar`` in the plate's axes: ``T^-1 Q T^-T`` (Jones, ch. 2; engineering strain).

    Parameters
    ----------
    ply : Ply

    Returns
    -------
    numpy.ndarray
        ``Q-bar``, Pa, shape (3, 3), symmetric; ``Q-bar16``, ``Q-bar26`` vanish at 0 and 90 degrees.

    Examples
    --------
    >>> from phaseimpact.model.laminate import Ply, transformed_stiffness
    >>> ply = Ply(E1=1.4e11, E2=1e10, G12=5e9, nu12=0.3, rho=1600.0, angle=90, thickness=1e-4)
    >>> (transformed_stiffness(ply) / 1e9).round(2) + 0.0  # + 0.0: no -0. from rounding
    array([[ 10.06,   3.02,   0.  ],
           [  3.02, 140.91,   0.  ],
           [  0.  ,   0.  ,   5.  ]])
    """
    theta = math.radians(ply.angle)
    c, s = math.cos(theta), math.sin(theta)
    T = np.array([[c * c, s * s, 2 * c * s], [s * s, c * c, -2 * c * s], [-c * s, c * s, c * c - s * s]])
    T_inv = np.linalg.inv(T)
    Q_bar = T_inv @ ply.reduced_stiffness() @ T_inv.T
    return 0.5 * (Q_bar + Q_bar.T)  # exactly symmetric: rounding of the products is not


@dataclass(frozen=True)
class Laminate:
    """A stack of plies, listed from the impacted face down, and its lamination stiffnesses.

    Attributes
    ----------
    plies : tuple of Ply
        At least one; either every ply gives ``G13, G23`` or none does.
    yield_strength : float or None
        The laminate's through-thickness compressive strength, Pa (:data:`~phaseimpact.parameters.STRENGTH_RANGE`),
        if known: it drives the validity check of elastic Hertz contact, as a
        :class:`~phaseimpact.parameters.Material`'s does.

    Examples
    --------
    A symmetric cross-ply [0/90]s of carbon/epoxy, 1 mm thick:

    >>> from phaseimpact.model.laminate import Laminate, Ply
    >>> ply = dict(E1=1.4e11, E2=1e10, G12=5e9, nu12=0.3, rho=1600.0, thickness=2.5e-4)
    >>> lam = Laminate(tuple(Ply(angle=t, **ply) for t in (0, 90, 90, 0)))
    >>> lam.thickness, lam.areal_density
    (0.001, 1.6)
    >>> A, B, D = lam.abd()
    >>> bool(abs(B).max() < 1e-9 * abs(A).max()), (D / 1.0).round(2)[0]
    (True, array([10.38,  0.25,  0.  ]))
    """

    plies: tuple
    yield_strength: float | None = None

    def __post_init__(self):
        plies = tuple(self.plies) if isinstance(self.plies, list | tuple) else None
        require("plies", self.plies, "a non-empty sequence of Ply", bool(plies) and all(
            isinstance(p, Ply) for p in plies))
        shear = {p.has_shear for p in plies}
        require("G13", [p.G13 for p in plies], "given for every ply or for none", len(shear) == 1)
        object.__setattr__(self, "plies", plies)
        if self.yield_strength is not None:
            low, high = STRENGTH_RANGE
            require("yield_strength", self.yield_strength, f"{low:g} <= yield_strength <= {high:g} (Pa), or absent",
                    is_finite_number(self.yield_strength) and low <= self.yield_strength <= high)
            object.__setattr__(self, "yield_strength", float(self.yield_strength))

    @property
    def thickness(self) -> float:
        """Total thickness ``h``, m."""
        return math.fsum(p.thickness for p in self.plies)

    @property
    def areal_density(self) -> float:
        """Mass per unit area ``rho h = sum rho_k t_k``, kg/m^2."""
        return math.fsum(p.rho * p.thickness for p in self.plies)

    @property
    def has_shear(self) -> bool:
        """Whether every ply gives ``G13, G23`` (transverse shear on)."""
        return self.plies[0].has_shear

    def interfaces(self) -> np.ndarray:
        """Ply interfaces ``z_0 = -h/2 < z_1 < ... < z_n = h/2`` from the mid-plane, m.

        Returns
        -------
        numpy.ndarray
            Shape (n + 1,) for n plies; ``z_0`` is the impacted face.

        Examples
        --------
        >>> from phaseimpact.model.laminate import Laminate, Ply
        >>> Laminate((Ply.isotropic(7e10, 0.33, 2700.0, 1e-3),) * 2).interfaces()
        array([-0.001,  0.   ,  0.001])
        """
        h = self.thickness
        z = np.concatenate(([0.0], np.cumsum([p.thickness for p in self.plies]))) - h / 2
        z[-1] = h / 2  # the cumulative sum's rounding would leave the last face off h/2
        return z

    def abd(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Extensional, coupling and bending stiffnesses (Jones, ch. 4).

        ``A = sum Qk (z_k - z_k-1)``, ``B = sum Qk (z_k^2 - z_k-1^2) / 2``,
        ``D = sum Qk (z_k^3 - z_k-1^3) / 3``, ``Qk`` the ply's :func:`transformed_stiffness`.

        Returns
        -------
        A, B, D : numpy.ndarray
            Shape (3, 3) each: ``A`` in N/m, ``B`` in N, ``D`` in N m.

        Examples
        --------
        An isotropic plate as one ply: ``D11 = E h^3 / (12 (1 - nu^2))``:

        >>> from phaseimpact.model.laminate import Laminate, Ply
        >>> A, B, D = Laminate((Ply.isotropic(2.1e11, 0.3, 7850.0, 0.005),)).abd()
        >>> print(f"{D[0, 0]:.6g} N m, B = {abs(B).max():g}")
        2403.85 N m, B = 0
        """
        z = self.interfaces()
        A, B, D = (np.zeros((3, 3)) for _ in range(3))
        for ply, low, high in zip(self.plies, z[:-1], z[1:], strict=True):
            Q = transformed_stiffness(ply)
            A += Q * (high - low)
            B += Q * (high**2 - low**2) / 2
            D += Q * (high**3 - low**3) / 3
        return A, B, D

    def reduced_bending_stiffness(self) -> np.ndarray:
        """``D - B A^-1 B``: the bending stiffness with the mid-plane free to stretch (N = 0).

        Equal to ``D`` for a symmetric layup (``B = 0``); for ``B != 0`` it is what the bending
        stiffnesses below read, an approximation for a clamped plate (docs/physics.md §8).

        Returns
        -------
        numpy.ndarray
            Shape (3, 3), N m.

        Examples
        --------
        >>> from phaseimpact.model.laminate import Laminate, Ply
        >>> ply = dict(E1=1.4e11, E2=1e10, G12=5e9, nu12=0.3, rho=1600.0, thickness=5e-4)
        >>> lam = Laminate((Ply(angle=0, **ply), Ply(angle=90, **ply)))  # unsymmetric [0/90]
        >>> bool(lam.reduced_bending_stiffness()[0, 0] < lam.abd()[2][0, 0])
        True
        """
        A, B, D = self.abd()
        return D - B @ np.linalg.solve(A, B)

    def transverse_shear_stiffness(self) -> np.ndarray:
        """``sum k_s [[G23', G45'], [G45', G13']] t_k`` in the plate's axes (``x z`` and ``y z``), N/m.

        Each ply's ``(G13, G23)`` rotated by its angle; ``k_s`` is :data:`SHEAR_FACTOR`.

        Returns
        -------
        numpy.ndarray
            Shape (2, 2), ``[[A44, A45], [A45, A55]]`` (``A44`` for ``yz``, ``A55`` for ``xz``).

        Raises
        ------
        ValueError
            When the plies give no ``G13, G23``.

        Examples
        --------
        >>> from phaseimpact.model.laminate import Laminate, Ply
        >>> lam = Laminate((Ply.isotropic(2.1e11, 0.3, 7850.0, 0.005, shear=True),))
        >>> print(f"{lam.transverse_shear_stiffness()[0, 0]:.6g}")
        3.36538e+08
        """
        if not self.has_shear:
            raise ValueError("G13 = None is out of range; allowed: G13 and G23 (Pa) for every ply, for the shear "
                             "stiffness")
        S = np.zeros((2, 2))
        for ply in self.plies:
            theta = math.radians(ply.angle)
            c, s = math.cos(theta), math.sin(theta)
            S += SHEAR_FACTOR * ply.thickness * np.array(
                [[ply.G23 * c * c + ply.G13 * s * s, (ply.G13 - ply.G23) * c * s],
                 [(ply.G13 - ply.G23) * c * s, ply.G13 * c * c + ply.G23 * s * s]])
        return S

    def plate_terms(self, a: float, membrane: str = "printed") -> tuple[float, float, float, float, float]:
        """What :func:`phaseimpact.parameters.derive_parameters` reads of this laminate as a clamped
        circular plate (docs/physics.md §8). The parameters layer sits below the physics: it asks the
        plate for these, never imports this module.

        Parameters
        ----------
        a : float
            Plate radius, m.
        membrane : str
            Eq. 5b's form, ``"printed"`` or ``"shivakumar"`` (:func:`membrane_stiffness`).

        Returns
        -------
        tuple of float
            Areal density (kg/m^2), the top ply's half-space compliance (1/Pa,
            :func:`top_ply_compliance`), ``Kb`` (N/m, :func:`bending_stiffness`), ``Km`` (N/m^3,
            :func:`membrane_stiffness`) and Olsson's effective rigidity ``D*`` (N m,
            :func:`olsson_rigidity`).

        Examples
        --------
        >>> from phaseimpact.model.laminate import Laminate, Ply
        >>> lam = Laminate((Ply.isotropic(2.1e11, 0.3, 7850.0, 0.005),))
        >>> print(", ".join(f"{x:.6g}" for x in lam.plate_terms(0.1)))  # steel: eq. 5a, 5b
        39.25, 4.33333e-12, 1.2083e+07, 1.65415e+11, 2403.85
        """
        return (self.areal_density, top_ply_compliance(self), bending_stiffness(self, a),
                membrane_stiffness(self, a, membrane), olsson_rigidity(self.reduced_bending_stiffness()))

    def bending_shear(self, a: float, load_radius: float) -> float:
        """Abrate's combined bending-shear stiffness ``Kbs`` of this laminate as a clamped circular
        plate: :func:`bending_shear_stiffness` of :func:`bending_stiffness` and :func:`shear_stiffness`.

        Parameters
        ----------
        a : float
            Plate radius, m.
        load_radius : float
            Radius of the loaded disc (the contact radius), m.

        Returns
        -------
        float
            ``Kbs``, N/m.

        Examples
        --------
        >>> from phaseimpact.model.laminate import Laminate, Ply
        >>> lam = Laminate((Ply.isotropic(2.1e11, 0.3, 7850.0, 0.005, shear=True),))
        >>> print(f"{lam.bending_shear(0.1, 1e-4):.6g}")
        1.15923e+07
        """
        return bending_shear_stiffness(bending_stiffness(self, a), shear_stiffness(self, a, load_radius))


def as_laminate(plate, h: float) -> Laminate:
    """A plate as a :class:`Laminate`: itself, or an isotropic :class:`~phaseimpact.parameters.Material`
    as one ply of thickness ``h`` (its ``yield_strength`` kept).

    Parameters
    ----------
    plate : Laminate or Material
    h : float
        Plate thickness, m (read for a Material only).

    Returns
    -------
    Laminate

    Raises
    ------
    TypeError
        For a plate that is neither.

    Examples
    --------
    >>> from phaseimpact.model.laminate import as_laminate
    >>> from phaseimpact.parameters import STEEL
    >>> print(f"{as_laminate(STEEL, 0.005).abd()[2][0, 0]:.6g} N m")
    2403.85 N m
    """
    if isinstance(plate, Laminate):
        return plate
    if not isinstance(plate, Material):
        raise TypeError(f"plate has the wrong type ({type(plate).__name__}); allowed: Material or Laminate")
    return Laminate((Ply.isotropic(plate.E, plate.nu, plate.rho, h),), yield_strength=plate.yield_strength)
