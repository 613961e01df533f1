"""The clamped circular laminate's stiffnesses and the contact compliance of its impacted face
(docs/physics.md §8): what :meth:`phaseimpact.model.laminate.Laminate.plate_terms` reads of a
laminate (:mod:`phaseimpact.model.laminate`: its plies and classical lamination theory, whose
conventions these follow). Pure functions of the layup, no I/O.

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

import math

from .._lazy import NumPyOnFirstUse
from ..parameters import (
    LENGTH_RANGE,
    MEMBRANE_FORMULAS,
    MODULUS_RANGE,
    is_finite_number,
    require,
    require_choice,
    require_in,
)

# NumPy is imported when a stiffness is first computed: the commands that integrate nothing
# (``cases``, ``params`` of an isotropic plate) import this module but never NumPy.
np = NumPyOnFirstUse(globals())

__all__ = [
    "lekhnitskii_rigidity", "olsson_rigidity", "isotropic_part",
    "bending_stiffness", "membrane_stiffness", "shear_stiffness", "bending_shear_stiffness",
    "yang_sun_compliance", "transversely_isotropic_compliance", "top_ply_compliance",
]


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
    >>> from phaseimpact.model.plate_stiffness import olsson_rigidity
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
    >>> from phaseimpact.model.plate_stiffness import lekhnitskii_rigidity
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
    >>> from phaseimpact.model.plate_stiffness import isotropic_part
    >>> isotropic_part(np.array([[4.0, 1.0, 0.0], [1.0, 4.0, 0.0], [0.0, 0.0, 1.5]]))
    (4.0, 1.0)
    """
    M = np.asarray(M, dtype=float)
    return (float((3 * M[0, 0] + 3 * M[1, 1] + 2 * M[0, 1] + 4 * M[2, 2]) / 8),
            float((M[0, 0] + M[1, 1] + 6 * M[0, 1] - 4 * M[2, 2]) / 8))


def _radius(a) -> None:
    require_in("a", a, LENGTH_RANGE, "m")


def bending_stiffness(laminate, a: float) -> float:
    """Linear stiffness of a clamped circular laminate under a central load, ``Kb = 16 pi D* / a^2``.

    ``D*`` is :func:`lekhnitskii_rigidity` of :meth:`~phaseimpact.model.laminate.Laminate.reduced_bending_stiffness`
    (``= D`` when ``B = 0``). For an isotropic plate this is eq. 5a with ``h^3``,
    ``4 pi E h^3 / (3 (1 - nu^2) a^2)``.

    Parameters
    ----------
    laminate : phaseimpact.model.laminate.Laminate
    a : float
        Plate radius, m.

    Returns
    -------
    float
        ``Kb``, N/m.

    Examples
    --------
    The seed plate (docs/physics.md §2: 1.20830e7 N/m) as two steel plies at any angles:

    >>> from phaseimpact.model.laminate import Laminate, Ply
    >>> from phaseimpact.model.plate_stiffness import bending_stiffness
    >>> steel = [Ply.isotropic(2.1e11, 0.3, 7850.0, 0.0025, angle=t) for t in (0, 30)]
    >>> print(f"{bending_stiffness(Laminate(tuple(steel)), 0.1):.5e}")
    1.20830e+07
    """
    _radius(a)
    return 16 * math.pi * lekhnitskii_rigidity(laminate.reduced_bending_stiffness()) / a**2


def membrane_stiffness(laminate, a: float, membrane: str = "printed") -> float:
    """Cubic (membrane) stiffness of a clamped circular laminate: eq. 5b on the isotropic part of ``A``.

    ``Km = (353 - 191 nu) pi A* / (648 a^2)`` (``printed``, eq. 5b with ``A* = E h / (1 - nu^2)``)
    or ``(353 - 191 nu) pi A* (1 + nu) / (648 a^2)`` (``shivakumar``, i.e. ``E h / (1 - nu)``), with
    ``(A*, nu A*)`` = :func:`isotropic_part` of ``A``. Exact (for the formula) when ``A`` is
    isotropic, as for isotropic and quasi-isotropic layups; otherwise an approximation
    (docs/physics.md §8). ``B`` is not read.

    Parameters
    ----------
    laminate : phaseimpact.model.laminate.Laminate
    a : float
        Plate radius, m.
    membrane : {"printed", "shivakumar"}

    Returns
    -------
    float
        ``Km``, N/m^3.

    Examples
    --------
    >>> from phaseimpact.model.laminate import Laminate, Ply
    >>> from phaseimpact.model.plate_stiffness import membrane_stiffness
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


def shear_stiffness(laminate, a: float, load_radius: float) -> float:
    """Transverse-shear stiffness of a clamped circular plate, ``Ks = 2 pi S / (1/2 + ln(a/c))``.

    A load ``P`` spread uniformly over a disc of radius ``c`` at the centre: the shear force per
    length is ``P r / (2 pi c^2)`` inside and ``P / (2 pi r)`` outside, so the shear part of the
    centre deflection of a Mindlin plate is ``P (1/2 + ln(a/c)) / (2 pi S)``. ``S`` is ``sqrt(det)``
    of :meth:`~phaseimpact.model.laminate.Laminate.transverse_shear_stiffness` (``k_s G h`` when
    isotropic; the rotation-invariant strength of the logarithm for an anisotropic one).

    Parameters
    ----------
    laminate : phaseimpact.model.laminate.Laminate
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
    >>> from phaseimpact.model.laminate import Laminate, Ply
    >>> from phaseimpact.model.plate_stiffness import shear_stiffness
    >>> lam = Laminate((Ply.isotropic(2.1e11, 0.3, 7850.0, 0.005, shear=True),))
    >>> print(f"{shear_stiffness(lam, 0.1, 0.1 / math.e):.6g}")
    1.40969e+09
    """
    _radius(a)
    if not (is_finite_number(load_radius) and 0 < load_radius < a):
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
    >>> from phaseimpact.model.plate_stiffness import bending_shear_stiffness
    >>> bending_shear_stiffness(3.0, 6.0)
    2.0
    """
    for name, value in (("Kb", Kb), ("Ks", Ks)):
        require(name, value, "a finite number > 0 (N/m)", is_finite_number(value) and value > 0)
    return Kb * Ks / (Kb + Ks)


def yang_sun_compliance(ply) -> float:
    """The half-space term of the contact compliance ``eta`` (eq. 4) for a composite top ply: ``1/E3``.

    Yang and Sun (1982), as used by Abrate (1998): a transversely isotropic laminate face
    enters the Hertz modulus through its through-thickness modulus alone, ``E3 = E2`` of the
    ply. For an isotropic ply it gives ``1/E`` where the exact term is ``(1 - nu^2)/E``.

    Parameters
    ----------
    ply : phaseimpact.model.laminate.Ply
        The impacted (first) ply.

    Returns
    -------
    float
        ``1/E2``, 1/Pa; ``K = 4 sqrt(R) / (3 ((1 - nu1^2)/E1 + 1/E2))``.

    Examples
    --------
    >>> from phaseimpact.model.laminate import Ply
    >>> from phaseimpact.model.plate_stiffness import yang_sun_compliance
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
    >>> from phaseimpact.model.plate_stiffness import transversely_isotropic_compliance
    >>> E, nu = 2.1e11, 0.3
    >>> print(f"{transversely_isotropic_compliance(E, nu, E, nu, E / (2 * (1 + nu))) * E:.12f}")
    0.910000000000
    """
    for name, value in (("E_p", E_p), ("E_t", E_t), ("G_t", G_t)):
        require_in(name, value, MODULUS_RANGE, "Pa")
    compliance = np.array([[1 / E_p, -nu_p / E_p, -nu_tp / E_t],
                           [-nu_p / E_p, 1 / E_p, -nu_tp / E_t],
                           [-nu_tp / E_t, -nu_tp / E_t, 1 / E_t]])
    if not (is_finite_number(nu_p) and is_finite_number(nu_tp) and np.all(np.linalg.eigvalsh(compliance) > 0)):
        raise ValueError(f"nu_p = {nu_p!r}, nu_tp = {nu_tp!r} are out of range; allowed: values that give a "
                         "positive-definite compliance (|nu_p| < 1, nu_tp^2 < (1 - nu_p) E_t / (2 E_p))")
    C = np.linalg.inv(compliance)
    C11, C13, C33 = C[0, 0], C[0, 2], C[2, 2]
    M = 2 * math.sqrt((C11 * C33 - C13**2) / (C11 * (1 / G_t + 2 / (math.sqrt(C11 * C33) + C13))))
    return 1.0 / M


def top_ply_compliance(laminate) -> float:
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
    laminate : phaseimpact.model.laminate.Laminate

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
    >>> from phaseimpact.model.laminate import Laminate, Ply
    >>> from phaseimpact.model.plate_stiffness import top_ply_compliance
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
