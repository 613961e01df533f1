"""Which plate model an impact calls for: the infinite plate's point impedance, Zener's
inelasticity parameter and Olsson's mass criterion (docs/physics.md §8). Pure functions, no I/O.

* An infinite Kirchhoff plate under a point force ``P`` moves at the load point with
  ``P / (8 sqrt(D rho h))`` (Zener 1941; Goldsmith, *Impact*, 1960): a dashpot
  ``c = 8 sqrt(D rho h)``; for an orthotropic plate ``D`` is Olsson's effective rigidity.
* Zener's ``lambda``: the ratio of the ball's momentum to the impulse the dashpot takes over the
  Hertz indentation scale, ``lambda = M1 v / (c delta*)`` with ``delta* = (M1 v^2 / K)^(2/5)``.
* Olsson's mass criterion (Olsson 2000, Composites A 31:879): wave-controlled below an
  impactor/plate mass ratio of 0.23, quasi-static above 2.
"""

from __future__ import annotations

import math

from ..parameters import LENGTH_RANGE, Material, is_number, require, require_in
from .plate_stiffness import olsson_rigidity

__all__ = [
    "infinite_plate_impedance", "zener_lambda", "plate_mass", "mass_ratio", "impact_regime",
    "model_for_regime", "regime_report", "REGIMES", "SMALL_MASS_RATIO", "LARGE_MASS_RATIO",
]

#: Olsson's (2000) bounds on the impactor/plate mass ratio: below the first the response is
#: controlled by flexural waves that have not reached the boundary, above the second it is quasi-static.
SMALL_MASS_RATIO = 0.23
LARGE_MASS_RATIO = 2.0
#: The regimes, by increasing mass ratio. "boundary-controlled" names Olsson's range between the two
#: bounds: the waves reach the boundary during the contact, but the plate is not yet quasi-static.
REGIMES = ("wave-controlled", "boundary-controlled", "quasi-static")
#: The target model each regime calls for: the infinite plate (a dashpot) or the spring-mass plate.
_MODELS = {"wave-controlled": "infinite", "boundary-controlled": "plate", "quasi-static": "plate"}


def _positive(name: str, value, unit: str) -> None:
    require(name, value, f"a finite number > 0 ({unit})", is_number(value) and math.isfinite(value) and value > 0)


def infinite_plate_impedance(rigidity: float, areal_density: float) -> float:
    """Point impedance of an infinite plate, ``c = 8 sqrt(D rho h)`` (Zener 1941).

    The load point of an infinite Kirchhoff plate moves with velocity ``P / c`` under a point
    force ``P``: the plate takes the contact as a dashpot and radiates ``P^2 / c`` as flexural waves.

    Parameters
    ----------
    rigidity : float
        Bending rigidity ``D`` (isotropic) or ``D*`` (:func:`olsson_rigidity`), N m.
    areal_density : float
        Mass per unit area ``rho h``, kg/m^2.

    Returns
    -------
    float
        ``c``, N s/m.

    Examples
    --------
    The seed plate (steel, h = 5 mm; docs/physics.md §8):

    >>> from phaseimpact.model.regime import infinite_plate_impedance
    >>> D = 2.1e11 * 0.005**3 / (12 * (1 - 0.3**2))
    >>> print(f"{infinite_plate_impedance(D, 7850.0 * 0.005):.3f} N s/m")
    2457.328 N s/m
    """
    _positive("rigidity", rigidity, "N m")
    _positive("areal_density", areal_density, "kg/m^2")
    return 8 * math.sqrt(rigidity * areal_density)


def zener_lambda(M1: float, v: float, K: float, impedance: float) -> float:
    """Zener's inelasticity parameter of a Hertz impact on an infinite plate.

    ``lambda = M1 v / (c delta*) = M1^(3/5) v^(1/5) K^(2/5) / c``, ``delta* = (M1 v^2 / K)^(2/5)``.
    With ``x = delta*`` times ``s`` and time in ``delta*/v``, ball (``M1 x'' = -P``), Hertz contact
    (``P = K delta^(3/2)``) and plate (``c w' = P``) become ``s'' = -s^(3/2) - lambda (s^(3/2))'``:
    the restitution is a function of ``lambda`` alone, 1 at ``lambda = 0`` (a rigid wall). For an
    isotropic ball on an isotropic plate it is Zener's (1941) ``(pi^(3/5)/sqrt(3)) (R1/h)^2
    (v/c0)^(1/5) (rho1/rho2)^(3/5) (1 + E2 (1 - nu1^2) / (E1 (1 - nu2^2)))^(-2/5)``,
    ``c0 = sqrt(E2 / (rho2 (1 - nu2^2)))`` (docs/physics.md §8).

    Parameters
    ----------
    M1 : float
        Projectile mass, kg.
    v : float
        Impact speed, m/s.
    K : float
        Hertz stiffness, N/m^1.5.
    impedance : float
        Plate impedance ``c`` (:func:`infinite_plate_impedance`), N s/m.

    Returns
    -------
    float
        ``lambda``, dimensionless.

    Examples
    --------
    A 2 mm steel ball (M1 = 2.63056e-4 kg, K = 6.87677e9 N/m^1.5) at 1 m/s on the seed plate
    taken as infinite (c = 2457.328 N s/m), and the seed's 20 mm ball:

    >>> from phaseimpact.model.regime import zener_lambda
    >>> print(f"{zener_lambda(2.63056e-4, 1.0, 6.87677e9, 2457.328):.4g}")
    0.02492
    >>> print(f"{zener_lambda(0.263056, 1.0, 2.17570e10, 2457.328):.4g}")
    2.492
    """
    for name, value, unit in (("M1", M1, "kg"), ("v", v, "m/s"), ("K", K, "N/m^1.5"),
                              ("impedance", impedance, "N s/m")):
        _positive(name, value, unit)
    return M1**0.6 * v**0.2 * K**0.4 / impedance


def plate_mass(areal_density: float, a: float) -> float:
    """Mass of a circular plate of radius ``a``, ``pi a^2 rho h``: Olsson's plate mass.

    (The two-degree-of-freedom model's ``M2`` is a quarter of it.)

    Parameters
    ----------
    areal_density : float
        ``rho h``, kg/m^2.
    a : float
        Plate radius, m.

    Returns
    -------
    float
        kg.

    Examples
    --------
    >>> from phaseimpact.model.regime import plate_mass
    >>> print(f"{plate_mass(7850.0 * 0.005, 0.1):.6f} kg")
    1.233075 kg
    """
    _positive("areal_density", areal_density, "kg/m^2")
    require_in("a", a, LENGTH_RANGE, "m")
    return math.pi * a**2 * areal_density


def mass_ratio(M1: float, plate_mass: float) -> float:
    """The impactor/plate mass ratio ``M1 / M_p`` of Olsson's criterion.

    Parameters
    ----------
    M1 : float
        Projectile mass, kg.
    plate_mass : float
        The plate's mass (:func:`plate_mass`), kg.

    Returns
    -------
    float
        Dimensionless.

    Examples
    --------
    A 100 µm sand grain (2650 kg/m^3) on a 0.1 kg panel:

    >>> import math
    >>> from phaseimpact.model.regime import mass_ratio
    >>> print(f"{mass_ratio(2650.0 * 4 / 3 * math.pi * 50e-6**3, 0.1):.3g}")
    1.39e-08
    """
    _positive("M1", M1, "kg")
    _positive("plate_mass", plate_mass, "kg")
    return M1 / plate_mass


def impact_regime(ratio: float) -> str:
    """The regime by Olsson's mass criterion: one of :data:`REGIMES`.

    ``wave-controlled`` below :data:`SMALL_MASS_RATIO`, ``quasi-static`` above
    :data:`LARGE_MASS_RATIO`, ``boundary-controlled`` from the one to the other (both included).

    Parameters
    ----------
    ratio : float
        Impactor/plate mass ratio (:func:`mass_ratio`), > 0.

    Returns
    -------
    str

    Examples
    --------
    >>> from phaseimpact.model.regime import impact_regime
    >>> impact_regime(1e-8), impact_regime(0.5), impact_regime(3.0)
    ('wave-controlled', 'boundary-controlled', 'quasi-static')
    """
    _positive("ratio", ratio, "dimensionless")
    if ratio < SMALL_MASS_RATIO:
        return REGIMES[0]
    return REGIMES[1] if ratio <= LARGE_MASS_RATIO else REGIMES[2]


def model_for_regime(regime: str) -> str:
    """The target model a regime calls for: ``"infinite"`` (wave-controlled) or ``"plate"``.

    Parameters
    ----------
    regime : str
        One of :data:`REGIMES`.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        For an unknown regime.

    Examples
    --------
    >>> from phaseimpact.model.regime import model_for_regime
    >>> model_for_regime("wave-controlled"), model_for_regime("quasi-static")
    ('infinite', 'plate')
    """
    if regime not in _MODELS:
        raise ValueError(f"regime = {regime!r} is out of range; allowed: one of {', '.join(REGIMES)}")
    return _MODELS[regime]


def regime_report(params, plate, geometry) -> dict:
    """Which plate model an impact calls for, as ``params`` reports it (docs/physics.md §8).

    Parameters
    ----------
    params : Parameters
        ``M1``, ``K``, ``v`` and ``target`` are read.
    plate : Material or Laminate
        The plate (a Material is taken as one isotropic ply of thickness ``geometry.h``).
    geometry : Geometry
        ``a`` and ``h`` are read.

    Returns
    -------
    dict
        ``D_star`` (Olsson's rigidity of the reduced bending stiffness, N m), ``plate_impedance``
        (N s/m: ``params.impedance``, the one the ``infinite`` target integrates with, when given),
        ``zener_lambda``, ``plate_mass`` (the whole plate, kg), ``mass_ratio``, ``regime``
        (one of :data:`REGIMES`), ``regime_model`` (``"infinite"`` or ``"plate"``) and
        ``regime_warning``: a sentence when ``params.target`` is a model that does not fit the
        regime, else None. A rigid target is not judged by the mass ratio (it is the ``lambda -> 0``
        limit of the infinite plate: see ``zener_lambda``).

    Examples
    --------
    The seed (a 20 mm steel ball, 0.263 kg, on a 1.233 kg plate) is just below Olsson's 0.23:

    >>> from phaseimpact.model.regime import regime_report
    >>> from phaseimpact.parameters import STEEL, Geometry, seed_parameters
    >>> r = regime_report(seed_parameters(v=1.0), STEEL, Geometry())
    >>> print(f"{r['mass_ratio']:.3f} {r['regime']}, lambda = {r['zener_lambda']:.3g}")
    0.213 wave-controlled, lambda = 2.49
    >>> print(r["regime_warning"])
    the impact is wave-controlled (M1/M_p = 0.213 < 0.23, Olsson 2000): the plate's flexural waves do not reach
    its edge during the contact, so the spring-mass plate (target plate) is out of its range; the infinite plate is
    the model
    """
    if isinstance(plate, Material):  # D* = D: closed form (no lamination theory, no NumPy)
        D_star = plate.E * geometry.h**3 / (12 * (1 - plate.nu**2))
        areal_density = plate.rho * geometry.h
    else:
        D_star = olsson_rigidity(plate.reduced_bending_stiffness())
        areal_density = plate.areal_density
    # the impedance the infinite target integrates with (derive_parameters), where the parameters carry one
    impedance = params.impedance if params.impedance is not None else infinite_plate_impedance(
        D_star, areal_density)
    M_p = plate_mass(areal_density, geometry.a)
    ratio = mass_ratio(params.M1, M_p)
    regime = impact_regime(ratio)
    model = model_for_regime(regime)
    warning = None
    if params.target not in (model, "rigid"):
        bound = (f"< {SMALL_MASS_RATIO:g}" if regime == REGIMES[0] else
                 f"> {LARGE_MASS_RATIO:g}" if regime == REGIMES[2] else
                 f"between {SMALL_MASS_RATIO:g} and {LARGE_MASS_RATIO:g}")
        why = ("the plate's flexural waves do not reach its edge during the contact" if model == "infinite"
               else "the plate's edge takes part in the contact")
        name = {"plate": "the spring-mass plate", "free": "the free plate mass",
                "infinite": "the infinite plate"}[params.target]
        warning = (f"the impact is {regime} (M1/M_p = {ratio:.3g} {bound}, Olsson 2000): {why}, so {name} "
                   f"(target {params.target}) is out of its range; the "
                   + ("infinite" if model == "infinite" else "spring-mass") + " plate is the model")
    return {"D_star": D_star, "plate_impedance": impedance,
            "zener_lambda": zener_lambda(params.M1, params.v, params.K, impedance), "plate_mass": M_p,
            "mass_ratio": ratio, "regime": regime, "regime_model": model, "regime_warning": warning}
