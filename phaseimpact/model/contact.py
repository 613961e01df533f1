"""Contact mechanics of the undamped impact: Hertz scales, the contact a peak force makes, and
whether elastic Hertz contact (or Thornton's elastic-perfectly plastic sphere) and the plate model
hold there (docs/physics.md §4; Johnson 1985, *Contact Mechanics*, §4.2, §11.4; Thornton 1997).

Pure functions of :class:`~phaseimpact.parameters.Parameters` and the materials, no I/O:
:func:`hertz_scales`, :func:`hertz_contact`, :func:`validity`, :func:`validity_for_force`,
:func:`plastic_contact`, :func:`plastic_validity`.
"""

from __future__ import annotations

import math

from ..parameters import FIRST_YIELD_FACTOR, Geometry, Material, Parameters, require_nonnegative
from .laminate import Laminate

__all__ = [
    "CONTACT_RATIO_LIMIT",
    "R1_TO_PLATE_LIMIT",
    "THICKNESS_TO_PLATE_LIMIT",
    "hertz_scales",
    "hertz_contact",
    "validity",
    "validity_for_force",
    "plastic_contact",
    "plastic_validity",
]

#: Hertz theory assumes a contact radius small against the radius: ``a0 / R`` above this is out of range
#: (assumed limit; Johnson 1985, §4.1 requires ``a << R``).
CONTACT_RATIO_LIMIT = 0.3
#: The plate model (a clamped plate struck at its centre, a quarter of its mass moving) needs the ball
#: to fit on the plate: ``R1 <= a`` (assumed limit).
R1_TO_PLATE_LIMIT = 1.0
#: Kirchhoff bending (eq. 5a) needs a thin plate: ``h <= 0.2 a``, a span of ten thicknesses (assumed
#: limit; thick plates need shear deformation, Timoshenko & Woinowsky-Krieger 1959, §§ 39-40).
THICKNESS_TO_PLATE_LIMIT = 0.2


def _tau(alpha: float) -> float:
    """``tau`` of the contact time ``T = 2 tau delta_max / v`` for ``P = K delta^alpha``.

    From energy conservation, ``t(delta_max) = delta_max/v * int_0^1 (1 - x^p)^(-1/2) dx`` with
    ``p = alpha + 1``, i.e. ``sqrt(pi) Gamma(1 + 1/p) / Gamma(1/p + 1/2)``; for Hertz (``p = 5/2``)
    ``sqrt(pi) Gamma(7/5) / Gamma(9/10) = 1.4716376...`` (docs/physics.md §4).
    """
    p = alpha + 1.0
    return math.sqrt(math.pi) * math.gamma(1.0 + 1.0 / p) / math.gamma(1.0 / p + 0.5)


def hertz_scales(params: Parameters, plate_material: Material | None = None) -> dict:
    """Closed-form scales of the undamped impact of the reduced mass (docs/physics.md §4, Johnson §11.4).

    Parameters
    ----------
    params : Parameters
        Uses ``M1, M2, K, Kb, alpha, v, target`` and the effective radius ``R`` (m).
    plate_material : Material or Laminate, optional
        If it gives a ``yield_strength``, the result also holds ``first_yield_pressure``
        (``1.6 Y``, Pa) and ``pressure_to_first_yield`` (``p0 / 1.6 Y``).

    Returns
    -------
    dict
        ``contact_time`` (s): ``T = 2 tau delta_max / v``, ``3.218065... (m^2/(K^2 v))^(1/5)`` for
        Hertz; ``plate_period`` (s): ``2 pi sqrt(M2/Kb)`` (inf for a rigid or free target);
        ``indentation`` (m): ``delta_max = (5 m v^2/(4K))^(2/5)``; ``peak_force`` (N):
        ``K delta_max^alpha``; ``contact_radius`` (m): ``a0 = sqrt(R delta_max)``;
        ``peak_pressure`` (Pa): ``p0 = 3 F / (2 pi a0^2)``. ``m`` is the reduced mass
        (``M1`` for a rigid target). The last two are ``None`` when ``params.R`` is ``None``;
        for ``alpha != 3/2`` they are Hertz estimates only.

    Raises
    ------
    TypeError
        If ``params`` is not a Parameters, or ``plate_material`` neither a Material nor None.

    Examples
    --------
    >>> from phaseimpact.case import load_case
    >>> from phaseimpact.model.contact import hertz_scales
    >>> from phaseimpact.parameters import seed_parameters
    >>> s = hertz_scales(seed_parameters(v=1.0))
    >>> print(f"{s['contact_time']:.4g} s, {s['indentation']:.4g} m, {s['peak_force']:.4g} N, "
    ...       f"{s['peak_pressure']:.4g} Pa")
    0.000108 s, 3.669e-05 m, 4836 N, 3.146e+09 Pa
    >>> case = load_case("hail-laminate")
    >>> print(f"{hertz_scales(case.parameters(), case.plate)['pressure_to_first_yield']:.3g}")
    7.31
    """
    if not isinstance(params, Parameters):
        raise TypeError(f"params has the wrong type ({type(params).__name__}); allowed: Parameters")
    if plate_material is not None and not isinstance(plate_material, Material | Laminate):
        raise TypeError(f"plate_material has the wrong type ({type(plate_material).__name__}); allowed: Material, "
                        "Laminate or None")
    delta = params.hertz_indentation
    force = params.K * delta**params.alpha
    out = {
        "contact_time": 2.0 * _tau(params.alpha) * delta / params.v,
        "plate_period": params.target_period,
        "indentation": delta,
        "peak_force": force,
        "contact_radius": None,
        "peak_pressure": None,
    }
    if params.R is not None:
        out.update(hertz_contact(force, params))
        if plate_material is not None and plate_material.yield_strength is not None:
            limit = FIRST_YIELD_FACTOR * plate_material.yield_strength
            out["first_yield_pressure"] = limit
            out["pressure_to_first_yield"] = out["peak_pressure"] / limit
    return out


def hertz_contact(force: float, params: Parameters) -> dict:
    """Hertz contact radius and peak pressure for a normal force (Johnson 1985, eq. 4.22-4.24).

    Parameters
    ----------
    force : float
        Normal contact force ``F``, N (>= 0), e.g. a simulation's peak force.
    params : Parameters
        ``K`` and ``R`` (m); the contact modulus is ``E* = 3 K / (4 sqrt(R))`` (inverting
        ``K = 4/3 E* sqrt(R)``), so overrides of ``K`` are honoured.

    Returns
    -------
    dict
        ``contact_radius`` ``a = (3 F R / (4 E*))^(1/3)`` (m) and ``peak_pressure``
        ``p0 = 3 F / (2 pi a^2)`` (Pa); both 0 for ``F = 0``.

    Raises
    ------
    ValueError
        If ``params.R`` is ``None`` (no effective radius), or ``force`` is negative or not finite.

    Examples
    --------
    >>> from phaseimpact.model.contact import hertz_contact
    >>> from phaseimpact.parameters import seed_parameters
    >>> c = hertz_contact(4629.0, seed_parameters(v=1.0))
    >>> print(f"a = {c['contact_radius']:.4g} m, p0 = {c['peak_pressure']:.4g} Pa")
    a = 0.0008443 m, p0 = 3.101e+09 Pa
    >>> hertz_contact(0.0, seed_parameters())
    {'contact_radius': 0.0, 'peak_pressure': 0.0}
    >>> hertz_contact(4629.0, seed_parameters().replace(R=None))
    Traceback (most recent call last):
        ...
    ValueError: R = None: the contact radius needs the effective radius R (derive the parameters ...)
    """
    if params.R is None:
        raise ValueError("R = None: the contact radius needs the effective radius R (derive the parameters "
                         "from materials and geometry, or give Parameters(R=...))")
    require_nonnegative("force", force)
    if force == 0:
        return {"contact_radius": 0.0, "peak_pressure": 0.0}
    e_star = 3.0 * params.K / (4.0 * math.sqrt(params.R))
    a = (3.0 * force * params.R / (4.0 * e_star)) ** (1.0 / 3.0)
    return {"contact_radius": a, "peak_pressure": 3.0 * force / (2.0 * math.pi * a * a)}


def _reasons(pressure: float, radius: float, params: Parameters, plate_material, projectile_material,
             geometry: Geometry | None) -> str:
    reasons = []
    for role, material in (("target", plate_material), ("projectile", projectile_material)):
        if material is not None and material.yield_strength is not None:
            strength = material.yield_strength
            if pressure > FIRST_YIELD_FACTOR * strength:
                reasons.append(f"peak pressure {pressure:.3g} Pa exceeds 1.6 x yield strength {strength:.3g} Pa "
                               f"of the {role} (first yield at p0 ≈ 1.6 Y, Johnson 1985)")
    ratio = radius / params.R
    if ratio > CONTACT_RATIO_LIMIT:
        reasons.append(f"contact radius {radius:.3g} m is {ratio:.2g} R (Hertz needs a << R; limit "
                       f"{CONTACT_RATIO_LIMIT:g} R)")
    verdicts = ["; ".join(reasons) + ": elastic Hertz contact is out of its range"] if reasons else []
    verdicts += _strength_reasons(plate_material, projectile_material)
    plate = _plate_reasons(geometry, params.target) if geometry is not None else []
    if plate:
        verdicts.append("; ".join(plate) + ": the plate model is out of its range")
    return "; ".join(verdicts) or "ok"


def _strength_reasons(plate_material: Material | None, projectile_material: Material | None) -> list:
    """A yield strength above the material's Young's modulus: no solid yields there (metals at about
    E/1000, the strongest ceramics near E/10), so it is a typo or a unit slip (and leaves thornton elastic)."""
    implausible = [f"yield strength {m.yield_strength:.3g} Pa of the {role} exceeds its Young's modulus "
                   f"E = {_modulus(m):.3g} Pa" for role, m in (("target", plate_material),
                                                               ("projectile", projectile_material))
                   if m is not None and m.yield_strength is not None and m.yield_strength > _modulus(m)]
    if not implausible:
        return []
    return ["; ".join(implausible) + ": no solid yields above E (check the value and its unit, Pa)"]


def _modulus(m: Material | Laminate) -> float:
    """Young's modulus under the contact: a laminate's top ply's through-thickness ``E2``."""
    return m.plies[0].E2 if isinstance(m, Laminate) else m.E


def _plate_reasons(g: Geometry, target: str) -> list:
    """Where the geometry leaves the plate model (seed eq. 5, 7): a ball wider than the plate, a
    plate too thick for thin-plate bending (read only when the plate's springs are)."""
    reasons = []
    if g.R1 > R1_TO_PLATE_LIMIT * g.a:
        reasons.append(f"projectile radius R1 = {g.R1:.3g} m exceeds the plate radius a = {g.a:.3g} m (the ball "
                       "must fit on the plate: R1 <= a)")
    if target == "plate" and g.h > THICKNESS_TO_PLATE_LIMIT * g.a:
        reasons.append(f"plate thickness h = {g.h:.3g} m is {g.h / g.a:.2g} a (thin-plate bending, eq. 5a, needs "
                       f"h <= {THICKNESS_TO_PLATE_LIMIT:g} a)")
    return reasons


def validity(params: Parameters, plate_material: Material | None,
             projectile_material: Material | None = None, geometry: Geometry | None = None) -> str:
    """Whether elastic Hertz contact holds at the closed-form peak of :func:`hertz_scales`.

    Parameters
    ----------
    params : Parameters
        With the effective radius ``R``.
    plate_material : Material, Laminate or None
        Its ``yield_strength`` ``Y`` (Pa), if given, is checked: ``p0 <= 1.6 Y``.
    projectile_material : Material, optional
        The same check for the projectile (a hailstone crushes before the plate yields).
    geometry : Geometry, optional
        Checked against the plate model: ``R1 <= a`` (:data:`R1_TO_PLATE_LIMIT`) and, on a plate
        target, ``h <= 0.2 a`` (:data:`THICKNESS_TO_PLATE_LIMIT`).

    Returns
    -------
    str
        ``"ok"``, or the reasons (joined by ``"; "``): peak pressure beyond first yield, a
        contact radius beyond ``CONTACT_RATIO_LIMIT * R``, a geometry outside the plate model.
        Without any yield strength the pressure is not checked.

    Raises
    ------
    ValueError
        If ``params.R`` is ``None`` (no effective radius).

    Examples
    --------
    >>> from phaseimpact.model.contact import validity
    >>> from phaseimpact.parameters import Geometry, Material, seed_parameters
    >>> params = seed_parameters(v=1.0)
    >>> validity(params, None)  # no yield strength, no geometry: only a0 / R is checked
    'ok'
    >>> mild_steel = Material(E=2.1e11, nu=0.3, rho=7850.0, yield_strength=2.5e8)
    >>> print(validity(params, mild_steel))
    peak pressure 3.15e+09 Pa exceeds 1.6 x yield strength 2.5e+08 Pa of the target (first yield at
    p0 ≈ 1.6 Y, Johnson 1985): elastic Hertz contact is out of its range
    >>> print(validity(params, None, geometry=Geometry(h=0.03)))
    plate thickness h = 0.03 m is 0.3 a (thin-plate bending, eq. 5a, needs h <= 0.2 a): the plate
    model is out of its range
    """
    scales = hertz_scales(params)
    if scales["peak_pressure"] is None:
        raise ValueError("R = None: validity needs the effective radius R")
    return _reasons(scales["peak_pressure"], scales["contact_radius"], params, plate_material, projectile_material,
                    geometry)


def plastic_contact(force: float, params: Parameters) -> dict:
    """Contact radius and peak pressure under Thornton's elastic-perfectly plastic sphere (Thornton
    1997, eq. 4-9) for a normal force ``force`` (N) on its loading curve: Hertz
    (:func:`hertz_contact`) up to the yield force ``F_y``; beyond, the pressure is capped at the
    limiting pressure ``p_y`` and the contact grows as ``a^2 = (2 F + F_y) / (2 pi p_y)``.

    Parameters
    ----------
    force : float
        Normal contact force ``F``, N (>= 0), on the loading curve.
    params : Parameters
        ``K`` (N/m^1.5), ``R`` (m) and ``limiting_pressure`` ``p_y`` (Pa; from a
        ``yield_strength``, see :func:`~phaseimpact.parameters.derive_parameters`).

    Returns
    -------
    dict
        ``contact_radius`` (m) and ``peak_pressure`` (Pa): :func:`hertz_contact`'s while its
        pressure is at most ``p_y``, else ``sqrt((2 F + F_y) / (2 pi p_y))`` and ``p_y``.

    Raises
    ------
    ValueError
        If ``params.limiting_pressure`` is ``None``; as :func:`hertz_contact` for a missing ``R``
        or a negative ``force``.

    Examples
    --------
    >>> from phaseimpact.model.contact import plastic_contact
    >>> from phaseimpact.parameters import seed_parameters
    >>> params = seed_parameters(v=1.0, plate_yield_strength=2.5e8)  # p_y = 1.6 Y = 4e8 Pa
    >>> for force in (1.0, 4000.0):  # N: elastic (Hertz), then capped
    ...     c = plastic_contact(force, params)
    ...     print(f"a = {c['contact_radius']:.4g} m, p0 = {c['peak_pressure']:.4g} Pa")
    a = 5.066e-05 m, p0 = 1.861e+08 Pa
    a = 0.001785 m, p0 = 4e+08 Pa
    >>> plastic_contact(1.0, seed_parameters())
    Traceback (most recent call last):
        ...
    ValueError: limiting_pressure = None: the plastic contact needs the limiting pressure p_y (...)
    """
    p_y = params.limiting_pressure
    if p_y is None:
        raise ValueError("limiting_pressure = None: the plastic contact needs the limiting pressure p_y (a case with "
                         "a yield_strength)")
    hertz = hertz_contact(force, params)
    if hertz["peak_pressure"] <= p_y:
        return hertz
    e_star = 0.75 * params.K / math.sqrt(params.R)
    delta_y = params.R * (0.5 * math.pi * p_y / e_star) ** 2
    f_y = params.K * delta_y**1.5
    return {"contact_radius": math.sqrt((2.0 * force + f_y) / (2.0 * math.pi * p_y)), "peak_pressure": p_y}


def plastic_validity(force: float, params: Parameters, geometry: Geometry | None = None,
                     plate_material: Material | None = None, projectile_material: Material | None = None) -> str:
    """The regime of an impact under Thornton's law (its peak force ``force``, N): elastic below the
    yield velocity ``v_y``, elastic-plastic above (the model's own range: the pressure is capped at
    ``p_y``); then, as :func:`validity`, a contact radius beyond ``CONTACT_RATIO_LIMIT * R`` and a
    geometry outside the plate model.

    Parameters
    ----------
    force : float
        Peak contact force of the run, N (>= 0), e.g. a simulation's ``max_force``.
    params : Parameters
        With ``R`` (m) and ``limiting_pressure`` (Pa); ``v`` (m/s) is compared with
        :attr:`~phaseimpact.parameters.Parameters.yield_velocity`.
    geometry : Geometry, optional
        Checked against the plate model as in :func:`validity`.
    plate_material, projectile_material : Material, optional
        A yield strength above the material's Young's modulus is reported (no solid yields there).

    Returns
    -------
    str
        The regime, ``"elastic (v = ... v_y, ...)"`` or ``"elastic-plastic (v = ... v_y, ...)"``,
        followed (after ``"; "``) by any reason the model is out of its range.

    Raises
    ------
    ValueError
        If ``params.limiting_pressure`` or ``params.R`` is ``None`` (no yield velocity).

    Examples
    --------
    >>> from phaseimpact.model.contact import plastic_validity
    >>> from phaseimpact.parameters import seed_parameters
    >>> print(plastic_validity(4000.0, seed_parameters(v=1.0, plate_yield_strength=2.5e8)))
    elastic-plastic (v = 174 v_y, v_y = 0.00576 m/s; pressure capped at p_y = 4e+08 Pa: Thornton's range)
    >>> print(plastic_validity(1.0, seed_parameters(v=0.005, plate_yield_strength=2.5e8)))
    elastic (v = 0.868 v_y, v_y = 0.00576 m/s: Thornton's law is Hertz here)
    """
    v_y = params.yield_velocity
    if v_y is None:
        raise ValueError("limiting_pressure = None: the regime needs the limiting pressure p_y (a case with a "
                         "yield_strength)")
    ratio = params.v / v_y
    regime = (f"elastic (v = {ratio:.3g} v_y, v_y = {v_y:.3g} m/s: Thornton's law is Hertz here)" if ratio <= 1
              else f"elastic-plastic (v = {ratio:.3g} v_y, v_y = {v_y:.3g} m/s; pressure capped at "
                   f"p_y = {params.limiting_pressure:.3g} Pa: Thornton's range)")
    reasons = []
    radius = plastic_contact(force, params)["contact_radius"]
    if radius / params.R > CONTACT_RATIO_LIMIT:
        reasons.append(f"contact radius {radius:.3g} m is {radius / params.R:.2g} R (the sphere model needs a << R; "
                       f"limit {CONTACT_RATIO_LIMIT:g} R): out of range")
    if geometry is not None:
        plate = _plate_reasons(geometry, params.target)
        if plate:
            reasons.append("; ".join(plate) + ": the plate model is out of its range")
    reasons += _strength_reasons(plate_material, projectile_material)
    return "; ".join([regime, *reasons])


def validity_for_force(force: float, params: Parameters, plate_material: Material | None,
                       projectile_material: Material | None = None, geometry: Geometry | None = None) -> str:
    """Like :func:`validity`, for an actual peak force ``force`` (N), e.g. from a simulation.

    The pressure is Hertz's ``p0 = 3 F / (2 pi a^2)`` with ``a = (3 F R / (4 E*))^(1/3)``
    (:func:`hertz_contact`).

    Parameters
    ----------
    force : float
        Peak contact force, N (>= 0).
    params : Parameters
        With the effective radius ``R`` (m).
    plate_material : Material, Laminate or None
        Its ``yield_strength`` ``Y`` (Pa), if given, is checked: ``p0 <= 1.6 Y``.
    projectile_material : Material, optional
        The same check for the projectile.
    geometry : Geometry, optional
        Checked against the plate model as in :func:`validity`.

    Returns
    -------
    str
        ``"ok"``, or the reasons joined by ``"; "``, as :func:`validity`.

    Raises
    ------
    ValueError
        As :func:`hertz_contact`: ``params.R`` is ``None``, or ``force`` is negative.

    Examples
    --------
    >>> from phaseimpact.model.contact import validity_for_force
    >>> from phaseimpact.parameters import Material, seed_parameters
    >>> mild_steel = Material(E=2.1e11, nu=0.3, rho=7850.0, yield_strength=2.5e8)
    >>> validity_for_force(1.0, seed_parameters(v=1.0), mild_steel)
    'ok'
    >>> print(validity_for_force(4629.0, seed_parameters(v=1.0), mild_steel))
    peak pressure 3.1e+09 Pa exceeds 1.6 x yield strength 2.5e+08 Pa of the target ...: elastic Hertz
    contact is out of its range
    """
    contact = hertz_contact(force, params)
    return _reasons(contact["peak_pressure"], contact["contact_radius"], params, plate_material,
                    projectile_material, geometry)
