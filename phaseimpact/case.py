"""Impact cases: materials, geometry and impact settings in one object, read from TOML (issue 12).

A case file has this schema (SI units; ``[projectile]`` and ``[plate]`` take the same keys)::

    name = "5 mm steel ball on the seed plate"   # optional (default: the file name)
    description = "..."                          # optional, one line (no line break)
    source = "..."                               # optional, free text: where the numbers come from
    [projectile]   # E (Pa), nu (0 <= nu < 0.5), rho (kg/m^3); optional yield_strength (Pa)
    E = 2.1e11
    nu = 0.3
    rho = 7850.0
    [plate]        # same keys; yield_strength drives the validity check
    E = 2.1e11
    nu = 0.3
    rho = 7850.0
    [geometry]     # a, h, R1, R2 (m)
    a = 0.1
    h = 0.005
    R1 = 0.005
    R2 = 2000.0
    [impact]       # v (m/s); optional kappa (the law's unit, default 0), target (plate|rigid|free,
    v = 13.0       # default plate), law (default paper), contact (printed|unilateral, default
                   # printed), restitution (1e-6 <= e <= 1, default none), law_file (a Python
                   # file defining the law with phaseimpact.define_law, relative to the case file)

A laminate plate gives ``[[plate.ply]]`` tables instead of ``E, nu, rho`` (``[plate]`` then takes
only ``yield_strength``), listed from the impacted face down, each with ``E1, E2, G12`` (Pa),
``nu12``, ``rho`` (kg/m^3), ``angle`` (degrees), ``thickness`` (m) and optionally ``G13, G23`` (Pa,
both or neither: Abrate's bending-shear stiffness). ``geometry.h`` is then the plies' total
thickness: leave it out, or give that same number (docs/physics.md §8)::

    [[plate.ply]]
    E1 = 2.87e10
    E2 = 1.66e10
    G12 = 8.4e9
    nu12 = 0.5
    rho = 1940.0
    angle = 0.0
    thickness = 0.001

Unknown keys, missing keys, wrong types and values out of range raise ``ValueError`` naming the
dotted key, its value and the allowed range; so does an ``[impact]`` value its law never reads
(``kappa`` with ``abrate``, ``restitution`` with ``paper``...), which would be silently ignored.
Named cases ship in ``phaseimpact/cases/`` (:func:`list_cases`); :func:`load_case` takes a name or a
path. The contact mechanics of a case (Hertz scales, validity) are in :mod:`phaseimpact.model.contact`.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

from .parameters import (
    KAPPA_MAX,
    STEEL,
    TARGETS,
    V_RANGE,
    Geometry,
    Material,
    Parameters,
    dotted_overrides,
    is_number,
    parameters_with,
    require,
    require_choice,
    require_in,
    validate_geometry,
    validate_material,
)
from .settings import GEOMETRY_KEYS, apply_settings

if TYPE_CHECKING:
    from .model.laminate import Laminate

__all__ = [
    "Case",
    "CONTACTS",
    "case_from_dict",
    "load_case",
    "list_cases",
    "seed_case",
]


CONTACTS = ("printed", "unilateral")

_MATERIAL_KEYS = {"E": "Pa", "nu": "-", "rho": "kg/m^3", "yield_strength": "Pa"}
_MATERIAL_REQUIRED = ("E", "nu", "rho")
_IMPACT_DEFAULTS = {"kappa": 0.0, "target": "plate", "law": "paper", "contact": "printed", "restitution": None,
                    "law_file": None}
_IMPACT_KEYS = ("v", *_IMPACT_DEFAULTS)
_TOP_KEYS = ("name", "description", "source", "projectile", "plate", "geometry", "impact")
_TABLES = ("projectile", "plate", "geometry", "impact")
_CASES_PACKAGE = "phaseimpact.cases"


def _laws() -> tuple:
    # Imported late: the engine (model) is not needed to describe a case, and importing it here
    # would tie case files to the engine's import time.
    from .model import REGISTRY  # the shipped laws and any defined before (--law-file, define_law)

    return tuple(REGISTRY)


# ---------------------------------------------------------------------------------------------
# Validation helpers (messages name the dotted key, its value and the allowed range)
# ---------------------------------------------------------------------------------------------

def _wrong_type(key: str, value, allowed: str) -> ValueError:
    return ValueError(f"{key} = {value!r} has the wrong type ({type(value).__name__}); allowed: {allowed}")


def _number(key: str, value, allowed: str = "a finite number"):
    if not is_number(value):
        raise _wrong_type(key, value, allowed)
    return float(value)


def _string(key: str, value, allowed: str = "a string") -> str:
    if not isinstance(value, str):
        raise _wrong_type(key, value, allowed)
    return value


def _check_keys(table: Mapping, allowed, where: str) -> None:
    for key in table:
        if key not in allowed:
            dotted = f"{where}.{key}" if where else key
            raise ValueError(f"unknown key {dotted!r}; allowed in {'[' + where + ']' if where else 'the top level'}: "
                             + ", ".join(allowed))


def _missing(key: str, allowed: str) -> ValueError:
    return ValueError(f"missing key {key!r}; allowed: {allowed}")


def _material_from(table, body: str) -> Material:
    if not isinstance(table, Mapping):
        raise _wrong_type(body, table, "a table with keys " + ", ".join(_MATERIAL_KEYS))
    _check_keys(table, tuple(_MATERIAL_KEYS), body)
    for key in _MATERIAL_REQUIRED:
        if key not in table:
            raise _missing(f"{body}.{key}", f"a number in {_MATERIAL_KEYS[key]}")
    values = {key: _number(f"{body}.{key}", value) for key, value in table.items()}
    validate_material(values, f"{body}.")
    return Material(**values)


def _laminate_from(table) -> Laminate:
    """A ``[plate]`` table with ``[[plate.ply]]`` tables: the plies, from the impacted face down."""
    from .model.laminate import PLY_FIELDS, Laminate, Ply, validate_ply

    for key in table:
        if key not in ("ply", "yield_strength"):
            raise ValueError(f"plate.{key} = {table[key]!r} does not go with [[plate.ply]]; allowed in [plate] with "
                             "plies: ply, yield_strength (a laminate's moduli and density are set per ply)")
    plies = table["ply"]
    if not isinstance(plies, list) or not plies:
        raise _wrong_type("plate.ply", plies, "a non-empty array of tables ([[plate.ply]])")
    built = []
    for i, ply in enumerate(plies):
        prefix = f"plate.ply[{i}]."
        if not isinstance(ply, Mapping):
            raise _wrong_type(prefix.rstrip("."), ply, "a table with keys " + ", ".join(PLY_FIELDS))
        values = {key: _number(prefix + key, value) if key in PLY_FIELDS else value for key, value in ply.items()}
        validate_ply(values, prefix)
        built.append(Ply(**values))
    strength = table.get("yield_strength")
    if strength is not None:
        strength = _number("plate.yield_strength", strength)
    try:
        return Laminate(tuple(built), yield_strength=strength)
    except ValueError as exc:
        raise ValueError(f"plate.ply: {exc}" if str(exc).startswith("G13") else f"plate.{exc}") from None


def _plate_from(table) -> Material | Laminate:
    if isinstance(table, Mapping) and "ply" in table:
        return _laminate_from(table)
    return _material_from(table, "plate")


def _geometry_from(table, thickness: float | None = None) -> Geometry:
    """A ``[geometry]`` table; with a laminate's ``thickness`` (m), ``h`` may be left out and must
    otherwise equal it."""
    if not isinstance(table, Mapping):
        raise _wrong_type("geometry", table, "a table with keys a, h, R1, R2")
    _check_keys(table, GEOMETRY_KEYS, "geometry")
    for key in GEOMETRY_KEYS:
        if key not in table and not (key == "h" and thickness is not None):
            raise _missing(f"geometry.{key}", "a finite number > 0 (m)")
    values = {key: _number(f"geometry.{key}", value) for key, value in table.items()}
    if thickness is not None:
        _require_ply_thickness(values.setdefault("h", thickness), thickness, "geometry.h")
    validate_geometry(values, "geometry.")
    return Geometry(**values)


def _require_ply_thickness(h: float, thickness: float, name: str) -> None:
    require(name, h, f"the plies' total thickness {thickness!r} m (leave h out: it is their sum)",
            math.isclose(h, thickness, rel_tol=1e-12))


def _impact_from(table) -> dict:
    """Validate an ``[impact]`` table and fill the defaults of its optional keys."""
    if not isinstance(table, Mapping):
        raise _wrong_type("impact", table, "a table with keys " + ", ".join(_IMPACT_KEYS))
    _check_keys(table, _IMPACT_KEYS, "impact")
    if "v" not in table:
        raise _missing("impact.v", "a finite number > 0 (m/s)")
    out = {**_IMPACT_DEFAULTS, **table}
    out["v"] = _number("impact.v", out["v"], "a finite number > 0 (m/s)")
    require_in("impact.v", out["v"], V_RANGE, "m/s")
    out["kappa"] = _number("impact.kappa", out["kappa"], "a finite number >= 0 (the law's damping unit)")
    require("impact.kappa", out["kappa"], f"0 <= impact.kappa <= {KAPPA_MAX:g} (the law's damping unit)",
            math.isfinite(out["kappa"]) and 0 <= out["kappa"] <= KAPPA_MAX)
    for key, choices in (("target", TARGETS), ("law", _laws()), ("contact", CONTACTS)):
        _string(f"impact.{key}", out[key], "one of " + ", ".join(choices))
        require_choice(f"impact.{key}", out[key], choices)
    if out["restitution"] is not None:
        e = _number("impact.restitution", out["restitution"], "a number with 1e-6 <= e <= 1")
        require("impact.restitution", e, "1e-6 <= impact.restitution <= 1", math.isfinite(e) and 1e-6 <= e <= 1)
        out["restitution"] = e
    return {key: out[key] for key in _IMPACT_KEYS}


def _load_law_file(value, origin: str) -> tuple[str, list]:
    """Run ``impact.law_file`` (its laws then pass ``impact.law``'s check); returns its absolute
    path, so that the case as recorded (archives, JSON) finds it from anywhere, and the names of
    the laws it defines."""
    from .model.userlaw import load_law_file

    path = Path(_string("impact.law_file", value, "a path to a Python file"))
    if not path.is_absolute() and origin not in ("<dict>", "") and Path(origin).suffix == ".toml":
        path = Path(origin).resolve().parent / path
    try:
        names = load_law_file(path)
    except ValueError as exc:
        raise ValueError(f"impact.law_file: {exc}") from None
    return str(path.resolve()), names


def _check_read_by_law(impact: dict) -> None:
    """Refuse an ``[impact]`` value that its law never reads: it would be silently ignored."""
    from .model import REGISTRY

    law, e, kappa = impact["law"], impact["restitution"], impact["kappa"]
    entry = REGISTRY[law]
    if e is not None and entry.damping != "restitution" and not entry.inverse:
        raise ValueError(f"impact.restitution = {e!r} is not read by law {law!r}; allowed: restitution with "
                         + ", ".join(n for n, x in REGISTRY.items() if x.inverse) + " or a restitution law ("
                         + ", ".join(n for n, x in REGISTRY.items() if x.damping == "restitution") + ")")
    if kappa != 0 and not (entry.damping == "kappa" and e is None):
        source = "its damping comes from impact.restitution" if e is not None or entry.damping else "it is undamped"
        raise ValueError(f"impact.kappa = {kappa!r} is not read by law {law!r} ({source}); allowed: no kappa "
                         "with this law, or kappa with "
                         + ", ".join(n for n, x in REGISTRY.items() if x.damping == "kappa") + " (without restitution)")
    if impact["contact"] != "printed" and "contact" not in entry.options:
        raise ValueError(f"impact.contact = {impact['contact']!r} is not read by law {law!r}; allowed: contact "
                         "with law " + ", ".join(n for n, x in REGISTRY.items() if "contact" in x.options))


# ---------------------------------------------------------------------------------------------
# The case
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True, kw_only=True)
class Case:
    """A complete impact case: who hits what, how fast (the TOML schema in this module's docstring).

    Attributes
    ----------
    name : str
        Short name (for shipped cases, the name :func:`load_case` takes).
    description : str
        One line saying what the case is.
    source : str
        Where the numbers come from; assumed values are marked as assumed.
    projectile : Material
        Material of the spherical projectile.
    plate : Material or Laminate
        Material of the target plate, or its plies (:class:`~phaseimpact.model.laminate.Laminate`,
        ``[[plate.ply]]`` in a file).
    geometry : Geometry
        ``a, h, R1, R2`` (m); for a laminate ``h`` is the plies' total thickness.
    impact : dict
        ``v`` (m/s), ``kappa`` (N s/m^2.5), ``target``, ``law``, ``contact`` and ``restitution``
        (``None`` when not given); defaults are filled in for the optional keys. Not hashable.

    Examples
    --------
    >>> from phaseimpact.case import load_case
    >>> case = load_case("hail-laminate")
    >>> case.name, case.impact["v"], case.impact["law"]
    ('hail-laminate', 90.0, 'paper')
    >>> print(f"{case.projectile.E:.3g} Pa, {case.projectile.yield_strength:.3g} Pa, R1 = {case.geometry.R1} m")
    9.2e+09 Pa, 5.9e+06 Pa, R1 = 0.0075 m

    Built directly, with the defaults of the optional ``[impact]`` keys filled in:

    >>> from phaseimpact.case import Case
    >>> from phaseimpact.parameters import STEEL, Geometry
    >>> Case(name="slow", projectile=STEEL, plate=STEEL, geometry=Geometry(R1=0.005), impact={"v": 0.5}).impact
    {'v': 0.5, 'kappa': 0.0, 'target': 'plate', 'law': 'paper', 'contact': 'printed', 'restitution': None,
     'law_file': None}
    """

    name: str
    description: str = ""
    source: str = ""
    projectile: Material
    plate: Material | Laminate
    geometry: Geometry
    impact: dict = field(default_factory=lambda: {"v": 1.0})

    def __post_init__(self):
        for key in ("name", "description", "source"):
            _string(key, getattr(self, key))
        require("name", self.name, "a non-empty string on one line",
                bool(self.name.strip()) and len(self.name.splitlines()) == 1)
        require("description", self.description, "one line (no line break)", len(self.description.splitlines()) <= 1)
        from .model.laminate import Laminate

        for key, cls in (("projectile", Material), ("plate", Material | Laminate), ("geometry", Geometry)):
            if not isinstance(getattr(self, key), cls):
                raise _wrong_type(key, getattr(self, key), "a Material or a Laminate" if key == "plate"
                                  else f"a {cls.__name__}")
        if isinstance(self.plate, Laminate):
            _require_ply_thickness(self.geometry.h, self.plate.thickness, "geometry.h")
        object.__setattr__(self, "impact", _impact_from(self.impact))

    def parameters(self, **overrides) -> Parameters:
        """The model parameters of this case (via :func:`~phaseimpact.parameters.derive_parameters`).

        Parameters
        ----------
        **overrides
            ``v``, ``kappa``, ``target``, any name :func:`~phaseimpact.parameters.parameters_with`
            accepts (``R1``, ``plate_E``, ``membrane``, ...), or a dotted material name passed as
            ``**{"plate.E": 1e9}``. They win over the case's values.

        Returns
        -------
        Parameters
            ``M1, M2, K, Kb, Km`` derived from the case's materials and geometry, with its ``v``
            (m/s), ``kappa`` (N s/m^2.5) and ``target``, the effective radius ``R`` (m) and, with a
            ``yield_strength``, the ``limiting_pressure`` (Pa).

        Raises
        ------
        ValueError
            For an unknown override (the message lists the allowed names) or a value out of range.

        Examples
        --------
        >>> from phaseimpact.case import seed_case
        >>> p = seed_case().parameters(v=13.0, kappa=1e9, **{"plate.E": 7e10})
        >>> print(f"v = {p.v:g} m/s, kappa = {p.kappa:g} N s/m^2.5, K = {p.K:.4g} N/m^1.5")
        v = 13 m/s, kappa = 1e+09 N s/m^2.5, K = 1.088e+10 N/m^1.5
        """
        overrides = dotted_overrides(overrides)
        v = overrides.pop("v", self.impact["v"])
        settings = {"kappa": self.impact["kappa"], "target": self.impact["target"], **overrides}
        return parameters_with(self.projectile, self.plate, self.geometry, v=v, **settings)

    def with_settings(self, settings) -> Case:
        """A copy with ``--set`` settings applied; see :func:`~phaseimpact.settings.apply_settings`.

        Parameters
        ----------
        settings : iterable of str, str, or Mapping
            ``["v=13", "plate.E=7e10", ...]`` or ``{"v": 13.0, ...}``: names of :data:`~phaseimpact.settings.SETTABLE`,
            values in its SI units.

        Returns
        -------
        Case
            The new, validated case; ``self`` is unchanged.

        Raises
        ------
        ValueError
            Naming the setting, its value and the allowed range.

        Examples
        --------
        >>> from phaseimpact.case import seed_case
        >>> case = seed_case().with_settings(["v=13", "R1=0.005"])
        >>> case.impact["v"], case.geometry
        (13.0, Geometry(a=0.1, h=0.005, R1=0.005, R2=2000.0))
        """
        return apply_settings(self, settings)

    def as_dict(self) -> dict:
        """The case as plain JSON- and TOML-able data in the file schema (``None`` values left out).

        Returns
        -------
        dict
            ``name``, ``description``, ``source`` (str) and the tables ``projectile``, ``plate``,
            ``geometry``, ``impact`` (dicts, SI units); :func:`case_from_dict` reads it back.

        Examples
        --------
        >>> from phaseimpact.case import seed_case
        >>> d = seed_case().as_dict()
        >>> list(d)
        ['name', 'description', 'source', 'projectile', 'plate', 'geometry', 'impact']
        >>> d["plate"], d["impact"]
        ({'E': 210000000000.0, 'nu': 0.3, 'rho': 7850.0},
         {'v': 1.0, 'kappa': 0.0, 'target': 'plate', 'law': 'paper', 'contact': 'printed'})
        """
        def material(m: Material | Laminate) -> dict:
            if isinstance(m, Material):
                return {k: v for k, v in dataclasses.asdict(m).items() if v is not None}
            plies = [{k: v for k, v in dataclasses.asdict(p).items() if v is not None} for p in m.plies]
            return {**({} if m.yield_strength is None else {"yield_strength": m.yield_strength}), "ply": plies}

        return {
            "name": self.name,
            "description": self.description,
            "source": self.source,
            "projectile": material(self.projectile),
            "plate": material(self.plate),
            "geometry": dataclasses.asdict(self.geometry),
            "impact": {k: v for k, v in self.impact.items() if v is not None},
        }

    def to_toml(self) -> str:
        """The case as TOML text that :func:`load_case` reads back to an equal case.

        Returns
        -------
        str
            The file schema of this module's docstring: the text keys, then the tables
            ``[projectile]``, ``[plate]``, ``[geometry]``, ``[impact]``; one key per line, numbers
            written in full (SI units), ``None`` values left out.

        Examples
        --------
        >>> from phaseimpact.case import seed_case
        >>> print(seed_case().to_toml())
        name = "seed"
        description = "The seed paper's case (eq. 7): 2 cm steel ball on a 10 cm steel plate, 5 mm thick, at 1 m/s"
        source = "Seed paper eq. 7 (a = 0.1 m, ...; v = 1 m/s is docs/physics.md §1's default (the seed gives no speed)"
        <BLANKLINE>
        [projectile]
        E = 210000000000.0
        nu = 0.3
        rho = 7850.0
        ...
        [impact]
        v = 1.0
        kappa = 0.0
        target = "plate"
        law = "paper"
        contact = "printed"
        <BLANKLINE>
        """
        data = self.as_dict()
        lines = [f"{key} = {_toml_value(data[key])}" for key in ("name", "description", "source")]
        for table in _TABLES:
            scalars = {k: v for k, v in data[table].items() if k != "ply"}
            lines += ["", f"[{table}]"] + [f"{k} = {_toml_value(v)}" for k, v in scalars.items()]
            for ply in data[table].get("ply", ()):
                lines += ["", f"[[{table}.ply]]"] + [f"{k} = {_toml_value(v)}" for k, v in ply.items()]
        return "\n".join(lines) + "\n"

    def save(self, path) -> Path:
        """Write :meth:`to_toml` to ``path`` (UTF-8) and return the path.

        Parameters
        ----------
        path : str or os.PathLike
            The file to write (replaced if it exists); its folder must exist. Name it ``*.toml``
            for :func:`load_case` to read it as a file.

        Returns
        -------
        pathlib.Path
            ``path``.

        Examples
        --------
        >>> import tempfile
        >>> from pathlib import Path
        >>> from phaseimpact.case import load_case, seed_case
        >>> path = seed_case().with_settings(["v=13"]).save(Path(tempfile.mkdtemp()) / "fast.toml")
        >>> path.name, load_case(path).impact["v"]
        ('fast.toml', 13.0)
        """
        path = Path(path)
        path.write_text(self.to_toml(), encoding="utf-8")
        return path


def _toml_value(value) -> str:
    if isinstance(value, str):
        # A JSON string is a valid TOML basic string, except that TOML also wants DEL escaped.
        return json.dumps(value, ensure_ascii=False).replace("\x7f", "\\u007f")
    return repr(float(value))


def case_from_dict(data, origin: str = "<dict>") -> Case:
    """Build a :class:`Case` from data in the file schema (parsed TOML, or JSON from an archive).

    Parameters
    ----------
    data : Mapping
        Top-level keys ``name``, ``description``, ``source`` (optional) and the tables
        ``projectile``, ``plate``, ``geometry``, ``impact``.
    origin : str
        File name or label, put in front of error messages. Also the default ``name``
        (its stem, for a path).

    Returns
    -------
    Case
        The validated case, the optional ``[impact]`` keys filled with their defaults; named
        ``data["name"]``, else the stem of ``origin`` (``"case"`` for the default origin).

    Raises
    ------
    ValueError
        ``"<origin>: ..."`` naming the dotted key, its value and the allowed range.

    Examples
    --------
    >>> from phaseimpact.case import case_from_dict, seed_case
    >>> data = seed_case().as_dict()
    >>> del data["name"]
    >>> data["impact"]["v"] = 13.0
    >>> case = case_from_dict(data, "fast.toml")
    >>> case.name, case.impact["v"]
    ('fast', 13.0)
    >>> data["impact"].update(law="abrate", kappa=1e9)
    >>> case_from_dict(data, "fast.toml")
    Traceback (most recent call last):
        ...
    ValueError: fast.toml: impact.kappa = 1000000000.0 is not read by law 'abrate' (it is undamped); ...
    """
    try:
        if not isinstance(data, Mapping):
            raise _wrong_type("case", data, "a table")
        _check_keys(data, _TOP_KEYS, "")
        for table in _TABLES:
            if table not in data:
                raise ValueError(f"missing table [{table}]")
        text = {key: _string(key, data[key]) for key in ("name", "description", "source") if key in data}
        impact_table = data["impact"]
        if isinstance(impact_table, Mapping) and impact_table.get("law_file") is not None:
            path, names = _load_law_file(impact_table["law_file"], origin)
            impact_table = {**impact_table, "law_file": path}
            if "law" not in impact_table:  # the file's one law; the default paper would ignore the file
                from .model.userlaw import single_law

                impact_table["law"] = single_law(names, path, "impact.law")
        impact = _impact_from(impact_table)
        _check_read_by_law(impact)
        projectile, plate = _material_from(data["projectile"], "projectile"), _plate_from(data["plate"])
        thickness = None if isinstance(plate, Material) else plate.thickness
        return Case(
            name=text.get("name", Path(origin).stem if origin != "<dict>" else "case"),
            description=text.get("description", ""),
            source=text.get("source", ""),
            projectile=projectile,
            plate=plate,
            geometry=_geometry_from(data["geometry"], thickness),
            impact=impact,
        )
    except ValueError as exc:
        raise ValueError(f"{origin}: {exc}") from None


def _read_toml(text: str, origin: str) -> Case:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{origin}: TOML syntax error: {exc}") from None
    return case_from_dict(data, origin)


def _shipped() -> dict:
    """``{name: resource}`` for every ``*.toml`` file shipped in ``phaseimpact/cases``."""
    folder = resources.files(_CASES_PACKAGE)
    return {Path(item.name).stem: item for item in folder.iterdir() if item.name.endswith(".toml")}


def load_case(name_or_path) -> Case:
    """Load a shipped case by name (``"seed"``, ``"sand-gelcoat"``, ...) or a case file (``*.toml``).

    A string without a ``.toml`` suffix and without a path separator is taken as a shipped name.

    Parameters
    ----------
    name_or_path : str or os.PathLike
        A shipped name (:func:`list_cases`), or the path of a case file; a relative
        ``impact.law_file`` in it is read relative to the file.

    Returns
    -------
    Case
        The validated case (:func:`case_from_dict`); named by its ``name`` key, else by the file's stem.

    Raises
    ------
    TypeError
        If ``name_or_path`` is neither a str nor a path.
    ValueError
        Unknown name (the message lists the shipped ones), missing file, TOML syntax error (with
        the file name and the parser's message), or any schema error (see :func:`case_from_dict`).

    Examples
    --------
    >>> from phaseimpact.case import load_case, seed_case
    >>> case = load_case("hail-laminate")
    >>> print(f"{case.impact['v']:g} m/s, {len(case.plate.plies)} plies, h = {case.geometry.h:g} m, "
    ...       f"Y = {case.plate.yield_strength:.3g} Pa")
    90 m/s, 5 plies, h = 0.005 m, Y = 1.13e+08 Pa
    >>> load_case("seed") == seed_case()
    True
    >>> load_case("nope")
    Traceback (most recent call last):
        ...
    ValueError: unknown case 'nope'; shipped cases: ..., seed (or give a path to a .toml file)
    """
    if not isinstance(name_or_path, (str, os.PathLike)):
        raise TypeError(f"name_or_path = {name_or_path!r} has the wrong type ({type(name_or_path).__name__}); "
                        "allowed: a shipped case name (str) or the path of a .toml case file")
    text = str(name_or_path)
    is_name = isinstance(name_or_path, str) and not text.endswith(".toml") and "/" not in text and "\\" not in text
    if is_name:
        shipped = _shipped()
        if text not in shipped:
            raise ValueError(f"unknown case {text!r}; shipped cases: {', '.join(sorted(shipped))} "
                             "(or give a path to a .toml file)")
        return _read_toml(shipped[text].read_text(encoding="utf-8"), f"{text}.toml")
    path = Path(name_or_path)
    if path.exists() and not path.is_file():  # a FIFO would block the read forever
        raise ValueError(f"{path}: not a regular file (a case file is a .toml file)")
    try:
        content = path.read_text(encoding="utf-8-sig")  # a byte-order mark (Windows editors) is not TOML: dropped
    except OSError as exc:
        raise ValueError(f"{path}: cannot read the case file ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: not UTF-8 text ({exc.reason})") from None
    return _read_toml(content, str(path))


def list_cases() -> list[dict]:
    """The shipped cases, ``[{"name", "description", "source"}, ...]``, the seed first.

    Returns
    -------
    list of dict
        One ``{"name": ..., "description": ..., "source": ...}`` (str) per case file in
        ``phaseimpact/cases``: ``"seed"`` first, then the others by name.

    Examples
    --------
    >>> from phaseimpact.case import list_cases
    >>> cases = list_cases()
    >>> cases[0]["name"], "hail-laminate" in [c["name"] for c in cases]
    ('seed', True)
    >>> cases[0]["description"]
    "The seed paper's case (eq. 7): 2 cm steel ball on a 10 cm steel plate, 5 mm thick, at 1 m/s"
    """
    cases = [load_case(name) for name in _shipped()]
    cases.sort(key=lambda c: (c.name != "seed", c.name))
    return [{"name": c.name, "description": c.description, "source": c.source} for c in cases]


def seed_case() -> Case:
    """The seed's case (eq. 7, steel as docs/physics.md §2 fixes it) at 1 m/s, built without a file.

    Returns
    -------
    Case
        Named ``"seed"``: :data:`~phaseimpact.parameters.STEEL` on :data:`~phaseimpact.parameters.STEEL`,
        the default :class:`~phaseimpact.parameters.Geometry` (m), ``v = 1`` m/s, law ``paper``
        undamped; equal to ``load_case("seed")``.

    Examples
    --------
    >>> from phaseimpact.case import seed_case
    >>> case = seed_case()
    >>> case.name, case.geometry, case.impact["v"]
    ('seed', Geometry(a=0.1, h=0.005, R1=0.02, R2=2000.0), 1.0)
    """
    return Case(
        name="seed",
        description="The seed paper's case (eq. 7): 2 cm steel ball on a 10 cm steel plate, 5 mm thick, at 1 m/s",
        source=_SEED_SOURCE,
        projectile=STEEL,
        plate=STEEL,
        geometry=Geometry(),
        impact={"v": 1.0},
    )


_SEED_SOURCE = ("Seed paper eq. 7 (a = 0.1 m, h = 0.005 m, R1 = 0.02 m, R2 = 2e3 m, E1 = E2 = 2.1e11 Pa); "
                "nu = 0.3 and rho = 7850 kg/m^3 are not in the seed: steel as fixed by docs/physics.md §2; "
                "v = 1 m/s is docs/physics.md §1's default (the seed gives no speed)")
