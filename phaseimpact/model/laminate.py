"""Laminated plates: classical lamination theory and the clamped circular plate's stiffnesses
(docs/physics.md §8). Pure functions of the layup, no I/O.

Conventions. Plies are listed from the impacted face down; ``z`` is measured from the mid-plane,
positive in the direction of flight (the impacted face is at ``z = -h/2``). Ply angles are in
degrees from the plate's ``x`` axis. Strains are engineering strains, so ``A``, ``B``, ``D`` are
the usual 3 x 3 matrices of ``(N, M) = [[A, B], [B, D]] (eps0, kappa)`` in the order
``(x, y, xy)`` (Jones, *Mechanics of Composite Materials*, 2nd ed., 1999, ch. 4).

What each stiffness reads (docs/physics.md §8 states the formulas and their sources):

* ``Kb = 16 pi D* / a^2`` with Lekhnitskii's ``D* = (3 D11 + 2 D12 + 4 D66 + 3 D22) / 8`` of the
  reduced bending stiffness ``D - B A^-1 B`` (exact for an isotropic plate: eq. 5a);
* ``Km``: eq. 5b with ``E h / (1 - nu^2)`` and ``nu`` taken from the rotation-averaged (isotropic)
  part of ``A`` (exact for an isotropic or quasi-isotropic ``A``);
* ``Ks = 2 pi k_s G h / (1/2 + ln(a/c))``: the transverse-shear deflection of a Mindlin plate under
  a load spread over a disc of radius ``c``; ``Kbs = (1/Kb + 1/Ks)^-1``;
* the half-space compliance of the top ply: ``1/E3 = 1/E2`` (Yang & Sun 1982), and the exact
  transversely isotropic form for a half-space whose symmetry axis is the surface normal.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass

from ..parameters import (
    DENSITY_RANGE,
    LENGTH_RANGE,
    MODULUS_RANGE,
    STRENGTH_RANGE,
    Material,
    is_number,
    require,
    require_choice,
    require_in,
)


class _NumPyOnFirstUse:
    """NumPy, imported when a laminate is first computed with: the commands that integrate nothing
    (``cases``, ``params`` of an isotropic plate) import this module but never NumPy."""

    def __getattr__(self, name):
        import numpy

        globals()["np"] = numpy
        return getattr(numpy, name)


np = _NumPyOnFirstUse()

__all__ = [
    "Ply", "Laminate", "validate_ply", "transformed_stiffness", "lekhnitskii_rigidity", "olsson_rigidity",
    "isotropic_part",
    "bending_stiffness", "membrane_stiffness", "shear_stiffness", "bending_shear_stiffness",
    "yang_sun_compliance", "transversely_isotropic_compliance", "top_ply_compliance", "as_laminate",
    "MEMBRANE_FORMULAS", "SHEAR_FACTOR",
]

#: ``Km`` as eq. 5b prints it (``1 - nu^2``) or as in Shivakumar's table (``1 - nu``).
MEMBRANE_FORMULAS = ("printed", "shivakumar")
#: Mindlin/Reissner shear correction factor of a homogeneous section.
SHEAR_FACTOR = 5.0 / 6.0
#: A ply's fields, as a case file's ``[[plate.ply]]`` table names them (``G13``, ``G23`` optional).
PLY_FIELDS = ("E1", "E2", "G12", "nu12", "rho", "angle", "thickness", "G13", "G23")


def _finite(value) -> bool:
    return is_number(value) and math.isfinite(value)


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
    require(prefix + "nu12", nu12, f"|nu12| < sqrt(E1/E2) = {bound:g}", _finite(nu12) and abs(nu12) < bound)
    require_in(prefix + "rho", values["rho"], DENSITY_RANGE, "kg/m^3")
    angle = values["angle"]
    require(prefix + "angle", angle, "-360 <= angle <= 360 (degrees)", _finite(angle) and abs(angle) <= 360)
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
                    _finite(self.yield_strength) and low <= self.yield_strength <= high)
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


def olsson_rigidity(D) -> float:
    """Olsson's effective rigidity of an orthotropic plate, ``D* = sqrt(D11 D22 (A + 1) / 2)``.

    ``A = (D12 + 2 D66) / sqrt(D11 D22)`` (Olsson, 1992, AIAA J. 30:1587, and his small-mass
    papers). ``D`` itself for an isotropic plate (``A = 1``); ``D16``, ``D26`` do not enter.

    Parameters
    ----------
    D : array_like
        Bending stiffness, shape (3, 3), N m.

    Returns
    -------
    float
        ``D*``, N m.

    Raises
    ------
    ValueError
        When ``D11``, ``D22`` or ``A + 1`` is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact.model.laminate import olsson_rigidity
    >>> olsson_rigidity(np.array([[9.0, 1.0, 0.0], [1.0, 4.0, 0.0], [0.0, 0.0, 2.5]]))  # A = 1
    6.0
    """
    D = np.asarray(D, dtype=float)
    D11, D22 = float(D[0, 0]), float(D[1, 1])
    for name, value in (("D11", D11), ("D22", D22)):
        require(name, value, "a finite number > 0 (N m)", math.isfinite(value) and value > 0)
    A = (D[0, 1] + 2 * D[2, 2]) / math.sqrt(D11 * D22)
    require("A", float(A), "A = (D12 + 2 D66) / sqrt(D11 D22) > -1", A > -1)
    return math.sqrt(D11 * D22 * (A + 1) / 2)



def lekhnitskii_rigidity(D) -> float:
    """Lekhnitskii's effective rigidity of an orthotropic clamped circular plate under a central load.

    ``D* = (3 D11 + 2 D12 + 4 D66 + 3 D22) / 8``: the centre deflection is ``P a^2 / (16 pi D*)``
    (Lekhnitskii, *Anisotropic Plates*, 1968, as used by Abrate, *Impact on Composite Structures*,
    1998). It is also the rotation average (Tsai and Pagano's invariant ``U1``) of ``D``;
    ``D16``, ``D26`` do not enter.

    Parameters
    ----------
    D : array_like
        Bending stiffness, shape (3, 3), N m.

    Returns
    -------
    float
        ``D*``, N m; ``E h^3 / (12 (1 - nu^2))`` for an isotropic plate.

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact.model.laminate import lekhnitskii_rigidity
    >>> lekhnitskii_rigidity(np.array([[8.0, 1.0, 0.0], [1.0, 8.0, 0.0], [0.0, 0.0, 3.5]]))
    8.0
    """
    D = np.asarray(D, dtype=float)
    return float((3 * D[0, 0] + 2 * D[0, 1] + 4 * D[2, 2] + 3 * D[1, 1]) / 8)


def isotropic_part(M) -> tuple[float, float]:
    """The rotation-averaged (isotropic) part of a stiffness matrix: ``(M11, M12)`` of its average.

    ``U1 = (3 M11 + 3 M22 + 2 M12 + 4 M66) / 8``, ``U4 = (M11 + M22 + 6 M12 - 4 M66) / 8``
    (Tsai and Pagano, 1968): the isotropic matrix ``[[U1, U4, 0], [U4, U1, 0],
    [0, 0, (U1 - U4)/2]]`` nearest the rotations of ``M``. ``M`` itself for an isotropic one.

    Parameters
    ----------
    M : array_like
        Shape (3, 3), e.g. ``A`` (N/m).

    Returns
    -------
    tuple of float
        ``(U1, U4)``, in the unit of ``M``; ``U4 / U1`` is the effective Poisson's ratio.

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact.model.laminate import isotropic_part
    >>> isotropic_part(np.array([[4.0, 1.0, 0.0], [1.0, 4.0, 0.0], [0.0, 0.0, 1.5]]))
    (4.0, 1.0)
    """
    M = np.asarray(M, dtype=float)
    return (float((3 * M[0, 0] + 3 * M[1, 1] + 2 * M[0, 1] + 4 * M[2, 2]) / 8),
            float((M[0, 0] + M[1, 1] + 6 * M[0, 1] - 4 * M[2, 2]) / 8))


def _radius(a) -> None:
    require_in("a", a, LENGTH_RANGE, "m")


def bending_stiffness(laminate: Laminate, a: float) -> float:
    """Linear stiffness of a clamped circular laminate under a central load, ``Kb = 16 pi D* / a^2``.

    ``D*`` is :func:`lekhnitskii_rigidity` of :meth:`Laminate.reduced_bending_stiffness`
    (``= D`` when ``B = 0``). For an isotropic plate this is eq. 5a with ``h^3``,
    ``4 pi E h^3 / (3 (1 - nu^2) a^2)``.

    Parameters
    ----------
    laminate : Laminate
    a : float
        Plate radius, m.

    Returns
    -------
    float
        ``Kb``, N/m.

    Examples
    --------
    The seed plate (docs/physics.md §2: 1.20830e7 N/m) as two steel plies at any angles:

    >>> from phaseimpact.model.laminate import Laminate, Ply, bending_stiffness
    >>> steel = [Ply.isotropic(2.1e11, 0.3, 7850.0, 0.0025, angle=t) for t in (0, 30)]
    >>> print(f"{bending_stiffness(Laminate(tuple(steel)), 0.1):.5e}")
    1.20830e+07
    """
    _radius(a)
    return 16 * math.pi * lekhnitskii_rigidity(laminate.reduced_bending_stiffness()) / a**2


def membrane_stiffness(laminate: Laminate, a: float, membrane: str = "printed") -> float:
    """Cubic (membrane) stiffness of a clamped circular laminate: eq. 5b on the isotropic part of ``A``.

    ``Km = (353 - 191 nu) pi A* / (648 a^2)`` (``printed``, eq. 5b with ``A* = E h / (1 - nu^2)``)
    or ``(353 - 191 nu) pi A* (1 + nu) / (648 a^2)`` (``shivakumar``, i.e. ``E h / (1 - nu)``), with
    ``(A*, nu A*)`` = :func:`isotropic_part` of ``A``. Exact (for the formula) when ``A`` is
    isotropic, as for isotropic and quasi-isotropic layups; otherwise an approximation
    (docs/physics.md §8). ``B`` is not read.

    Parameters
    ----------
    laminate : Laminate
    a : float
        Plate radius, m.
    membrane : {"printed", "shivakumar"}

    Returns
    -------
    float
        ``Km``, N/m^3.

    Examples
    --------
    >>> from phaseimpact.model.laminate import Laminate, Ply, membrane_stiffness
    >>> seed = Laminate((Ply.isotropic(2.1e11, 0.3, 7850.0, 0.005),))
    >>> print(f"{membrane_stiffness(seed, 0.1):.5e}")
    1.65415e+11
    """
    _radius(a)
    require_choice("membrane", membrane, MEMBRANE_FORMULAS)
    A_star, A_12 = isotropic_part(laminate.abd()[0])
    nu = A_12 / A_star
    stretch = A_star if membrane == "printed" else A_star * (1 + nu)
    return (353 - 191 * nu) * math.pi * stretch / (648 * a**2)


def shear_stiffness(laminate: Laminate, a: float, load_radius: float) -> float:
    """Transverse-shear stiffness of a clamped circular plate, ``Ks = 2 pi S / (1/2 + ln(a/c))``.

    A load ``P`` spread uniformly over a disc of radius ``c`` at the centre: the shear force per
    length is ``P r / (2 pi c^2)`` inside and ``P / (2 pi r)`` outside, so the shear part of the
    centre deflection of a Mindlin plate is ``P (1/2 + ln(a/c)) / (2 pi S)``. ``S`` is
    ``sqrt(det)`` of :meth:`Laminate.transverse_shear_stiffness` (``k_s G h`` when isotropic; the
    rotation-invariant strength of the logarithm for an anisotropic one).

    Parameters
    ----------
    laminate : Laminate
        With ``G13, G23`` in every ply.
    a : float
        Plate radius, m.
    load_radius : float
        Radius ``c`` of the loaded disc, m, ``0 < c < a`` (the contact radius at the peak force).

    Returns
    -------
    float
        ``Ks``, N/m.

    Raises
    ------
    ValueError
        For ``c`` outside ``(0, a)``, or plies without ``G13, G23``.

    Examples
    --------
    >>> import math
    >>> from phaseimpact.model.laminate import Laminate, Ply, shear_stiffness
    >>> lam = Laminate((Ply.isotropic(2.1e11, 0.3, 7850.0, 0.005, shear=True),))
    >>> print(f"{shear_stiffness(lam, 0.1, 0.1 / math.e):.6g}")
    1.40969e+09
    """
    _radius(a)
    if not (_finite(load_radius) and 0 < load_radius < a):
        raise ValueError(f"load_radius = {load_radius!r} is out of range; allowed: 0 < load_radius < a = {a:g} (m)")
    S = math.sqrt(np.linalg.det(laminate.transverse_shear_stiffness()))
    return 2 * math.pi * S / (0.5 + math.log(a / load_radius))


def bending_shear_stiffness(Kb: float, Ks: float) -> float:
    """Abrate's combined bending-shear stiffness ``Kbs``: ``1/Kbs = 1/Kb + 1/Ks`` (the seed's ``K_bs``).

    Parameters
    ----------
    Kb, Ks : float
        Bending and shear stiffnesses, N/m, > 0.

    Returns
    -------
    float
        ``Kbs``, N/m, below both.

    Examples
    --------
    >>> from phaseimpact.model.laminate import bending_shear_stiffness
    >>> bending_shear_stiffness(3.0, 6.0)
    2.0
    """
    for name, value in (("Kb", Kb), ("Ks", Ks)):
        require(name, value, "a finite number > 0 (N/m)", _finite(value) and value > 0)
    return Kb * Ks / (Kb + Ks)


def yang_sun_compliance(ply: Ply) -> float:
    """The half-space term of the contact compliance ``eta`` (eq. 4) for a composite top ply: ``1/E3``.

    Yang and Sun (1982), as used by Abrate (1998): a transversely isotropic laminate face
    enters the Hertz modulus through its through-thickness modulus alone, ``E3 = E2`` of the
    ply. For an isotropic ply it gives ``1/E`` where the exact term is ``(1 - nu^2)/E``.

    Parameters
    ----------
    ply : Ply
        The impacted (first) ply.

    Returns
    -------
    float
        ``1/E2``, 1/Pa; ``K = 4 sqrt(R) / (3 ((1 - nu1^2)/E1 + 1/E2))``.

    Examples
    --------
    >>> from phaseimpact.model.laminate import Ply, yang_sun_compliance
    >>> yang_sun_compliance(Ply(E1=1.4e11, E2=1e10, G12=5e9, nu12=0.3, rho=1600.0, angle=0, thickness=1e-4))
    1e-10
    """
    return 1.0 / ply.E2


def transversely_isotropic_compliance(E_p: float, nu_p: float, E_t: float, nu_tp: float, G_t: float) -> float:
    """The half-space term of ``eta`` for a solid transversely isotropic about the surface normal.

    ``1/M`` with the exact indentation modulus in the closed form of Delafargue and Ulm (2004,
    Int. J. Solids Struct. 41:7351), ``M = 2 sqrt((C11 C33 - C13^2) / (C11 (1/C44 +
    2/(sqrt(C11 C33) + C13))))``, the stiffnesses ``C`` from the engineering constants. It gives
    ``(1 - nu^2)/E`` for an isotropic solid; a unidirectional ply, whose symmetry axis lies in
    the surface, is outside its assumptions.

    Parameters
    ----------
    E_p, nu_p : float
        In-plane (surface-plane) modulus, Pa, and Poisson's ratio.
    E_t, nu_tp : float
        Through-thickness modulus, Pa, and Poisson's ratio: a through-thickness stress ``sigma_t``
        strains the surface plane by ``-nu_tp sigma_t / E_t``.
    G_t : float
        Through-thickness shear modulus, Pa.

    Returns
    -------
    float
        ``1/M``, 1/Pa.

    Raises
    ------
    ValueError
        When the constants give no positive-definite stiffness.

    Examples
    --------
    >>> from phaseimpact.model.laminate import transversely_isotropic_compliance
    >>> E, nu = 2.1e11, 0.3
    >>> print(f"{transversely_isotropic_compliance(E, nu, E, nu, E / (2 * (1 + nu))) * E:.12f}")
    0.910000000000
    """
    for name, value in (("E_p", E_p), ("E_t", E_t), ("G_t", G_t)):
        require_in(name, value, MODULUS_RANGE, "Pa")
    compliance = np.array([[1 / E_p, -nu_p / E_p, -nu_tp / E_t],
                           [-nu_p / E_p, 1 / E_p, -nu_tp / E_t],
                           [-nu_tp / E_t, -nu_tp / E_t, 1 / E_t]])
    if not (_finite(nu_p) and _finite(nu_tp) and np.all(np.linalg.eigvalsh(compliance) > 0)):
        raise ValueError(f"nu_p = {nu_p!r}, nu_tp = {nu_tp!r} are out of range; allowed: values that give a "
                         "positive-definite compliance (|nu_p| < 1, nu_tp^2 < (1 - nu_p) E_t / (2 E_p))")
    C = np.linalg.inv(compliance)
    C11, C13, C33 = C[0, 0], C[0, 2], C[2, 2]
    M = 2 * math.sqrt((C11 * C33 - C13**2) / (C11 * (1 / G_t + 2 / (math.sqrt(C11 * C33) + C13))))
    return 1.0 / M



def top_ply_compliance(laminate: Laminate) -> float:
    """The half-space term of the contact compliance ``eta`` (eq. 4) of a laminate's impacted face.

    :func:`transversely_isotropic_compliance` of the top ply taken as a solid transversely isotropic
    about the surface normal (docs/physics.md §8): in the surface plane the rotation average of the
    ply's ``Q`` (:func:`isotropic_part`: ``nu_p = U4/U1``, ``E_p = U1 (1 - nu_p^2)``); through the
    thickness ``E_t = E2`` (the ply's ``E3``), ``nu_tp = nu12 E2/E1`` (its ``nu31``) and
    ``G_t = sqrt(G13 G23)``, or ``G12`` without them (the ply's ``G13`` by its transverse isotropy).
    Chosen over Yang and Sun's ``1/E2`` (:func:`yang_sun_compliance`) because it is exact for an
    isotropic face, ``(1 - nu^2)/E``: a plate given as isotropic plies keeps eq. 3's ``K``.

    Parameters
    ----------
    laminate : Laminate

    Returns
    -------
    float
        1/Pa.

    Raises
    ------
    ValueError
        Naming ``plate.ply[0]`` when its constants give no positive-definite half-space.

    Examples
    --------
    >>> from phaseimpact.model.laminate import Laminate, Ply, top_ply_compliance
    >>> steel = Laminate((Ply.isotropic(2.1e11, 0.3, 7850.0, 0.005),))
    >>> print(f"{top_ply_compliance(steel) * 2.1e11:.12f}")
    0.910000000000
    """
    ply = laminate.plies[0]
    U1, U4 = isotropic_part(ply.reduced_stiffness())
    nu_p = U4 / U1
    G_t = math.sqrt(ply.G13 * ply.G23) if ply.has_shear else ply.G12
    try:
        return transversely_isotropic_compliance(U1 * (1 - nu_p**2), nu_p, ply.E2, ply.nu12 * ply.E2 / ply.E1, G_t)
    except ValueError as exc:
        raise ValueError(f"plate.ply[0] (the impacted ply) as a half-space: {exc}") from None


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
