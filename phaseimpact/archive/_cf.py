"""CF conventions: netCDF names, UDUNITS units (``fractional_units`` where a power is not an
integer), CF flags, coordinate and plain variables, netCDF dimensions without a variable, and the
root attributes every archive starts with (:func:`_header`)."""

from __future__ import annotations

import re

import numpy as np

from .._version import __version__
from ..continuation.sweep import ENGINE as _ENGINE
from ..model import ContactLaw
from ._common import (
    _CHECKED,
    _LAW_SOURCE,
    _NOT_A_VARIABLE,
    _RESERVED,
    _UNITS,
    CONVENTIONS,
    REFERENCES,
    SCHEMA_VERSION,
    _base_attrs,
    _base_parameters,
    _Context,
    _float,
    _json,
)

# ------------------------------------------------------------------------------------------------
# Names and units that netCDF tools and unit parsers read
# ------------------------------------------------------------------------------------------------

def netcdf_name(name: str) -> str:
    """An axis name as a netCDF / Python identifier: ``plate.E`` -> ``plate_E``."""
    safe = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return safe if re.match(r"[A-Za-z_]", safe) else "_" + safe


def _g(x: float) -> str:
    return f"{x:.6g}"


def _udunits(text: str) -> str:
    """``kg/m^3`` -> ``kg m-3``, ``m/s`` -> ``m s-1``, ``-`` -> ``1`` (UDUNITS and pint read these)."""
    text = text.strip()
    if text in ("", "-"):
        return "1"
    top, _, bottom = text.partition("/")
    words = [re.sub(r"\^\(?([-\d.]+)\)?", r"\1", w) for w in top.split()]
    for w in bottom.split():
        unit, _, power = w.partition("^")
        power = power.strip("()") or "1"
        words.append(f"{unit}-{power}" if not power.startswith("-") else f"{unit}{power[1:]}")
    return " ".join(words)


def kappa_units(alpha: float, law=None) -> str:
    """Units of the damping coefficient set by ``kappa``, from the law's entry (e.g. ``N s m-2.5``
    for ``(K + kappa deltadot) delta^alpha`` with Hertz, ``N s m-1.5`` for Kuwabara-Kono);
    ``N s m-(1+alpha)`` without a law. A power of m that is not an integer makes it a
    ``fractional_units`` attribute, not ``units`` (:func:`unit_attributes`)."""
    if law is not None:
        from ..model.laws import as_law

        return _udunits(as_law(law).entry.damping_udunits(alpha))  # a user law's own unit may read N s/m^1.5
    return f"N s m-{_g(1 + alpha)}"


def axis_units(name: str, alpha: float, law=None) -> str:
    """Units of a grid axis or curve parameter in UDUNITS syntax (``alpha``: the base case's
    exponent; ``law``: whose entry gives the damping's unit); see :func:`unit_attributes`."""
    from ..settings import SETTABLE

    fixed = {"kappa": kappa_units(alpha, law), "K": f"N m-{_g(alpha)}", "v": "m s-1", "M1": "kg", "M2": "kg",
             "Kb": "N m-1", "Km": "N m-3", "alpha": "1", "R": "m"}
    if name in fixed:
        return fixed[name]
    return _udunits(SETTABLE[name][0]) if name in SETTABLE else "1"


#: A product of powers in UDUNITS syntax with integer exponents (``N s m-2``, ``kg m-3``, ``1``).
_INTEGER_POWERS = re.compile(r"1|[A-Za-z]+-?\d*( [A-Za-z]+-?\d*)*")


def unit_attributes(units: str) -> dict:
    """The attributes that state a variable's unit, given in UDUNITS syntax (``N s m-2.5``).

    UDUNITS, and with it CF, allows integer exponents only: it reads ``m-2.5`` as ``0.5 m-1``
    (``N s m-2.5`` as ``0.5 kg m-1 s-1``, a wrong dimension and a factor 0.5). A unit with integer
    powers is the ``units`` attribute. Any other (a power such as ``m-2.5``, or a law's own text)
    is ``fractional_units``, with no ``units``: CF then reads the values as pure numbers (CF 3.1,
    "a variable with no units attribute is assumed to be dimensionless"), the numbers of that unit,
    which is how they are meant; no UDUNITS reader converts them wrongly.

    Parameters
    ----------
    units : str
        The unit, e.g. from :func:`axis_units`.

    Returns
    -------
    dict
        ``{"units": units}``, or ``{"fractional_units": units, "comment": ...}``.

    Examples
    --------
    >>> from phaseimpact.archive import unit_attributes
    >>> unit_attributes("N s m-2")
    {'units': 'N s m-2'}
    >>> unit_attributes("N s m-2.5")["fractional_units"]
    'N s m-2.5'
    """
    if _INTEGER_POWERS.fullmatch(units):
        return {"units": units}
    return {"fractional_units": units,
            "comment": f"values in {units}; no units attribute because UDUNITS, which CF units follow, allows "
                       "integer powers only (it would read a power such as m-2.5 as 0.5 m-1)"}


def _long_name(name: str, units: str) -> str:
    """A coordinate's long_name; with the unit when no ``units`` attribute can state it (a plot's label)."""
    return name if "units" in unit_attributes(units) else f"{name} [{units}]"


def _axis_names(names) -> list[str]:
    out = []
    for name in names:
        safe = netcdf_name(name)
        while safe in _RESERVED or safe in _UNITS or safe in out:
            safe += "_axis"
        out.append(safe)
    return out


# ------------------------------------------------------------------------------------------------
# Low-level pieces: fixed-size datasets, dimensions, C-order boxes
# ------------------------------------------------------------------------------------------------


def _fill_of(dtype) -> np.generic:
    dtype = np.dtype(dtype)
    return dtype.type(np.nan) if dtype.kind == "f" else dtype.type(-1)


def _slab_chunks(shape, target: int) -> tuple:
    """Chunk shape whose chunks are contiguous runs of flat (C order) indices, about ``target`` long."""
    chunks = [1] * len(shape)
    room = max(1, int(target))
    for i in reversed(range(len(shape))):
        if shape[i] <= room:
            chunks[i] = max(1, shape[i])
            room = max(1, room // max(1, shape[i]))
        else:
            chunks[i] = room
            break
    return tuple(chunks)


#: The axis of the last grid dimensions, last first (xarray plots the last along x), as the attribute
#: ``cartesian_axis`` (COARDS, which cf_xarray reads: ``ds.cf.axes`` names them). Not CF's ``axis``: CF
#: readers take a coordinate with axis X or Y for a longitude or latitude (compliance-checker then
#: demands degrees), and the grid's parameters have no CF standard_name; the long_name says what they are.
_GRID_AXES = ("X", "Y")


def _grid_axes(coordinates) -> None:
    for d, axis in zip(reversed(coordinates), _GRID_AXES, strict=False):
        d.attrs["cartesian_axis"] = axis


def _dimension(group, name: str, size: int):
    """A netCDF dimension without a variable (as netCDF-C writes it: an empty dimension scale)."""
    d = group.create_dataset(name, shape=(size,), dtype="f4")
    d.make_scale(f"{_NOT_A_VARIABLE}{size:10d}")
    return d


def _flags(d, names) -> None:
    """CF flags. A point not computed holds -1, outside ``valid_range``: CF readers take it as missing,
    and xarray, which masks only ``_FillValue`` and ``missing_value`` (decoding the variable to
    float), keeps the codes as integers."""
    d.attrs["flag_values"] = np.arange(len(names), dtype=np.int8)
    d.attrs["flag_meanings"] = " ".join(names)
    d.attrs["valid_range"] = np.array([0, len(names) - 1], dtype=np.int8)
    d.attrs["comment"] = "-1 (outside valid_range): not computed"


def _header(f, kind: str, law: ContactLaw | None, base, t_end, rtol, engine: str, created: str, title: str,
            settings=None) -> None:
    """The root attributes; without ``law`` or ``base`` (an in-memory Dataset of a result that does not carry
    them, see :func:`to_xarray`) their attributes are left out."""
    f.attrs["Conventions"] = CONVENTIONS
    f.attrs["title"] = title
    f.attrs["history"] = f"{created} phaseimpact {__version__}: written by phaseimpact.archive"
    f.attrs["source"] = (f"phaseimpact {__version__}: impact simulations "
                         f"({law.name if law is not None else 'unnamed'} contact law, engine "
                         f"{engine or _ENGINE}, rtol {_float(rtol):g})")
    f.attrs["references"] = REFERENCES
    f.attrs["schema_version"] = np.int64(SCHEMA_VERSION)
    f.attrs["package_version"] = __version__
    f.attrs["kind"] = kind
    if law is not None:
        f.attrs["law"] = _json(law.as_dict())
        f.attrs["contact"] = str(law.contact)
        if law.source is not None:  # a user law: its source is part of the work's identity
            f.attrs[_LAW_SOURCE] = law.source
    for key, value in (_base_attrs(base) if base is not None else {}).items():
        f.attrs[key] = value
    f.attrs["engine"] = str(engine) or _ENGINE  # curves, transitions and trains run on the sweeps' engine
    f.attrs["rtol"] = _float(rtol)
    f.attrs["t_end"] = _float(t_end)
    f.attrs["created"] = created
    if settings is not None:
        f.attrs["settings"] = _json(settings)


def _parameter_units(name: str, context: _Context) -> str:
    """Units of a train parameter (``T``, ``kappa``, ``v``) in UDUNITS syntax; kappa's needs the case's
    exponent (and the law's entry)."""
    if name == "T":
        return "s"
    if context.base is None:
        return {"v": "m s-1"}.get(name, "N s m-(1+alpha)")
    return axis_units(name, _base_parameters(context.base).alpha, context.law)


def _by(context: _Context) -> str:
    """`` (<law> law)`` for a title, when the law is known."""
    return f" ({context.law.name} law)" if context.law is not None else ""


def _coordinate(f, name: str, values, units: str | None, long_name: str):
    """A coordinate variable (an HDF5 dimension scale named as its dimension)."""
    values = np.asarray(values)
    d = f.create_dataset(name, data=values, **(_CHECKED if values.size else {}))
    d.make_scale(name)
    if units is not None:
        d.attrs.update(unit_attributes(units))
    d.attrs["long_name"] = long_name if units is None else _long_name(long_name, units)
    return d


def _variable(f, name: str, data, dims=(), *, long_name: str, units: str | None = None, fill: bool = False,
              flags=None, dtype=None, **attrs):
    """A variable on the named dimensions (coordinate variables or netCDF dimensions, made on first use
    with the data's sizes), with a Fletcher-32 checksum where HDF5 allows one (a chunked, non-empty array).
    ``fill``: ``_FillValue`` NaN (or -1: xarray then reads the integers as floats, NaN where missing);
    ``flags``: CF flags, the codes 0, 1, ... meaning ``flags``."""
    data = np.asarray(data, dtype=dtype)
    d = f.create_dataset(name, data=data, **(_CHECKED if data.ndim and data.size else {}))
    if fill:
        d.attrs["_FillValue"] = _fill_of(data.dtype)
    if units is not None:
        d.attrs.update(unit_attributes(units))
    d.attrs["long_name"] = long_name if units is None else _long_name(long_name, units)
    if flags is not None:
        d.attrs["flag_values"] = np.arange(len(flags), dtype=data.dtype)
        d.attrs["flag_meanings"] = " ".join(flags)
    d.attrs.update(attrs)
    for i, (dim, n) in enumerate(zip(dims, data.shape, strict=True)):
        if dim not in f:
            _dimension(f, dim, n)
        d.dims[i].attach_scale(f[dim])
    return d


def _codes_of(names, table, what: str) -> np.ndarray:
    lookup = {name: i for i, name in enumerate(table)}
    bad = [name for name in names if name not in lookup]
    if bad:
        raise ValueError(f"{what} {bad[0]!r} is out of range; allowed: one of {', '.join(table)}")
    return np.array([lookup[name] for name in names], dtype=np.int8)
