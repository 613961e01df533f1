"""Settings of a case, ``--set NAME=VALUE`` (:data:`SETTABLE`): parsing them, and applying them to a
:class:`~phaseimpact.case.Case` (:func:`apply_settings`; :meth:`~phaseimpact.case.Case.with_settings`).
Every value is checked against its range before a case is returned.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

from .parameters import V_RANGE, Geometry, _replace_material, is_number, require_in, validate_geometry

__all__ = ["SETTABLE", "QUANTITIES", "GEOMETRY_KEYS", "apply_settings", "parse_setting"]

#: Every name ``--set NAME=VALUE`` accepts (each key of the case schema but the text ones):
#: ``{name: (unit, description)}`` (SI units). The schema's own spellings ``geometry.a`` and
#: ``impact.v`` are accepted too.
SETTABLE = {
    "projectile.E": ("Pa", "Young's modulus of the projectile"),
    "projectile.nu": ("-", "Poisson's ratio of the projectile (0 <= nu < 0.5)"),
    "projectile.rho": ("kg/m^3", "density of the projectile"),
    "projectile.yield_strength": ("Pa", "yield (or crushing) strength of the projectile; drives the validity check"),
    "plate.E": ("Pa", "Young's modulus of the plate (target)"),
    "plate.nu": ("-", "Poisson's ratio of the plate (0 <= nu < 0.5)"),
    "plate.rho": ("kg/m^3", "density of the plate"),
    "plate.yield_strength": ("Pa", "yield (or compressive) strength of the plate; drives the validity check"),
    "a": ("m", "radius of the clamped circular plate"),
    "h": ("m", "plate thickness"),
    "R1": ("m", "radius of the spherical projectile"),
    "R2": ("m", "radius of curvature of the target surface"),
    "v": ("m/s", "impact speed"),
    "kappa": ("law's unit", "damping coefficient of a law damped by kappa, in the unit its entry gives "
                            "(N s/m^2.5 for a Hunt-Crossley-type law on Hertz contact)"),
    "restitution": ("-", "coefficient of restitution (the restitution laws, hunt-crossley)"),
    "target": ("", "what is hit: plate, rigid, free or infinite"),
    "law": ("", "contact law"),
    "contact": ("", "law paper's reading of |delta|^alpha: printed or unilateral"),
}
#: The settable quantities the equations of motion read (axes of an atlas, parameters of a curve);
#: a yield strength only drives the validity check.
QUANTITIES = ("projectile.E", "projectile.nu", "projectile.rho", "plate.E", "plate.nu", "plate.rho",
              "a", "h", "R1", "R2", "v")
_TEXT_SETTINGS = ("target", "law", "contact")
_IMPACT_SETTINGS = ("v", "kappa", "restitution", "target", "law", "contact")
#: The keys of a case's ``[geometry]`` table, each a setting of the same name (m).
GEOMETRY_KEYS = ("a", "h", "R1", "R2")


def _settable_list() -> str:
    return ", ".join(f"{name} ({unit})" if unit else name for name, (unit, _) in SETTABLE.items())


_ALIASES = {**{f"geometry.{n}": n for n in GEOMETRY_KEYS}, **{f"impact.{n}": n for n in _IMPACT_SETTINGS}}


def setting_name(name: str) -> str:
    """The name of a setting as :data:`SETTABLE` spells it (``geometry.a`` is ``a``, ``impact.v`` is ``v``)."""
    name = str(name).strip()
    return _ALIASES.get(name, name)


def parse_setting(text: str) -> tuple[str, float | str]:
    """Parse one ``NAME=VALUE`` (``--set``) into ``(name, value)``; the range is checked later.

    Parameters
    ----------
    text : str
        ``NAME=VALUE``: a name of :data:`SETTABLE` (or the schema's ``geometry.a``, ``impact.v``
        spellings) and a number in its SI unit, or a word for ``target``, ``law``, ``contact``.
        Blanks around the name and the value are ignored.

    Returns
    -------
    tuple of (str, float or str)
        The name as :data:`SETTABLE` spells it and the value (a float; a str for the text settings).

    Raises
    ------
    ValueError
        Without ``=``, for a name not in :data:`SETTABLE` (the message lists them), or a value that
        is not a number (the text settings ``target``, ``law``, ``contact`` take a word).

    Examples
    --------
    >>> from phaseimpact.settings import parse_setting
    >>> parse_setting("plate.E=7e10"), parse_setting("impact.v = 13"), parse_setting("target=rigid")
    (('plate.E', 70000000000.0), ('v', 13.0), ('target', 'rigid'))
    >>> parse_setting("v=fast")
    Traceback (most recent call last):
        ...
    ValueError: v = 'fast' is not a number; allowed: a number in m/s
    """
    if not isinstance(text, str) or "=" not in text:
        raise ValueError(f"a setting is NAME=VALUE, got {text!r}; names: {_settable_list()}")
    name, _, raw = text.partition("=")
    name = setting_name(name)
    return name, _setting_value(name, raw)


def _setting_value(name: str, raw) -> float | str:
    if name not in SETTABLE:
        raise ValueError(f"unknown setting {name!r}; allowed: {_settable_list()}")
    if name in _TEXT_SETTINGS:
        return str(raw).strip()  # checked against its choices with the case
    unit = SETTABLE[name][0]
    if is_number(raw):
        return float(raw)
    try:
        return float(str(raw).strip())
    except ValueError:
        raise ValueError(f"{name} = {raw!r} is not a number; allowed: a number in {unit}") from None


def apply_settings(case, settings):
    """Apply ``--set`` settings to a case and return the new, validated case.

    Parameters
    ----------
    case : phaseimpact.case.Case
        The base case.
    settings : iterable of str, or Mapping
        ``["plate.E=1e9", "R1=0.001", ...]``, or ``{"plate.E": 1e9, ...}`` (values numbers or
        strings). Names are the keys of :data:`SETTABLE` (SI units), or the schema's spellings
        (``geometry.a``, ``impact.kappa``). Later settings win.

    Returns
    -------
    phaseimpact.case.Case
        A new case with the settings applied and validated; ``case`` is unchanged.

    Raises
    ------
    ValueError
        Naming the setting, its value and the allowed range.

    Examples
    --------
    >>> from phaseimpact.case import seed_case
    >>> from phaseimpact.settings import apply_settings
    >>> case = apply_settings(seed_case(), {"plate.E": 7e10, "geometry.R1": 0.005, "v": 13})
    >>> case.plate.E, case.geometry.R1, case.impact["v"]
    (70000000000.0, 0.005, 13.0)
    >>> apply_settings(seed_case(), ["v=2e4"])
    Traceback (most recent call last):
        ...
    ValueError: v = 20000.0 is out of range; allowed: 1e-06 <= v <= 10000 (m/s)
    """
    if isinstance(settings, Mapping):
        pairs = [(setting_name(name), _setting_value(setting_name(name), raw)) for name, raw in settings.items()]
    elif isinstance(settings, str):
        pairs = [parse_setting(settings)]
    else:
        pairs = [parse_setting(text) for text in settings]
    values = {
        "projectile": {},  # the changes of each material
        "plate": {},
        "geometry": dataclasses.asdict(case.geometry),
        "impact": dict(case.impact),
    }
    for name, value in pairs:
        if "." in name:
            body, _, key = name.partition(".")
            values[body][key] = value
        elif name in _IMPACT_SETTINGS:
            values["impact"][name] = value
        else:
            values["geometry"][name] = value
    projectile, plate = (_replace_material(getattr(case, body), f"{body}.", values[body]) if values[body]
                         else getattr(case, body) for body in ("projectile", "plate"))
    validate_geometry(values["geometry"])
    require_in("v", values["impact"]["v"], V_RANGE, "m/s")
    return dataclasses.replace(
        case,
        projectile=projectile,
        plate=plate,
        geometry=Geometry(**values["geometry"]),
        impact=values["impact"],
    )
