"""Continued curves: the archive kind ``critical-curve`` (a :class:`~phaseimpact.continuation.CriticalCurve`)."""

from __future__ import annotations

import math

import numpy as np

from ..continuation import CriticalCurve
from ._cf import _axis_names, _grid_axes, _header, _long_name, axis_units, kappa_units, unit_attributes
from ._common import (
    _CHECKED,
    _attr_str,
    _axis_values,
    _base,
    _base_parameters,
    _checked_axis,
    _Damaged,
    _data,
    _int_attr,
    _law,
    _out_of_range,
    _rtol,
)
from ._digests import _check_metadata
from ._legacy import _read_curve_v1, _read_curve_v2
from ._registry import ArchiveKind, register_kind


def _write_curve(f, c: CriticalCurve, created: str) -> None:
    _header(f, "critical-curve", c.law, c.base, None, c.rtol, "", created,
            f"phaseimpact critical curve: {c.what} of the {c.law.name} law over {c.param}")
    alpha = _base_parameters(c.base).alpha
    dim = _axis_names([c.param])[0]
    f.attrs["param"] = c.param
    f.attrs["what"] = c.what
    f.attrs["contact_index"] = np.int64(c.contact_index)
    f.attrs["message"] = str(c.message)
    values = f.create_dataset(dim, data=np.asarray(c.values, dtype=float), **_CHECKED)
    values.make_scale(dim)
    units = axis_units(c.param, alpha, c.law)
    values.attrs.update(unit_attributes(units))
    values.attrs["long_name"] = _long_name(c.param, units)
    values.attrs["parameter"] = c.param
    _grid_axes([values])
    units = kappa_units(alpha, c.law)
    for name in ("kappa", "closed_form", "predicted"):
        d = f.create_dataset(name, data=np.asarray(getattr(c, name), dtype=float), **_CHECKED)
        d.attrs["_FillValue"] = np.float64(np.nan)
        d.attrs.update(unit_attributes(units))
        d.attrs["long_name"] = _long_name({"kappa": c.what, "closed_form": "closed-form kappa_c (docs/physics.md "
                                           "section 5)", "predicted": "the continuation's prediction"}[name], units)
        d.dims[0].attach_scale(values)
    d = f.create_dataset("requested", data=np.asarray(c.requested, dtype=bool).astype(np.int8), **_CHECKED)
    d.attrs["flag_values"] = np.array([0, 1], dtype=np.int8)
    d.attrs["flag_meanings"] = "intermediate requested"
    d.attrs["long_name"] = "asked for (0: an intermediate step of the continuation)"
    d.dims[0].attach_scale(values)


def _read_curve(f) -> CriticalCurve:
    param = _attr_str(f, "param")
    dim = _axis_names([param])[0]
    values = _checked_axis(param, _data(f, dim, ndim=1), False).values
    requested = _data(f, "requested", ndim=1, kinds="iub")
    _out_of_range("requested", requested, ~np.isin(requested, (0, 1)), "0 or 1")
    return CriticalCurve(param, values, _data(f, "kappa", ndim=1, kinds="f"), requested.astype(bool),
                         _data(f, "closed_form", ndim=1, kinds="f"),
                         _data(f, "predicted", ndim=1, kinds="f"), _attr_str(f, "what"), _law(f), _base(f), _rtol(f),
                         _int_attr(f, "contact_index"), _attr_str(f, "message"))


def _check_curve(c: CriticalCurve) -> None:
    k = len(c.values)
    for name in ("kappa", "closed_form", "predicted", "requested"):
        values = np.asarray(getattr(c, name))
        if values.shape != (k,):
            raise _Damaged(f"variable {name} has shape {values.shape}; allowed: ({k},), one per value of {c.param}")
        if name != "requested":
            _out_of_range(name, values, ~np.isnan(values) & ~(np.isfinite(values) & (values > 0)),
                          "a positive number, or NaN (lost)")
    if c.what not in ("kappa_c", "kappa_2", "grazing"):
        raise _Damaged(f"attribute what = {c.what!r} is out of range; allowed: kappa_c, kappa_2 or grazing")
    if c.contact_index < 0:
        raise _Damaged(f"attribute contact_index = {c.contact_index} is out of range; allowed: an integer >= 0")
    if not (math.isfinite(c.rtol) and c.rtol > 0):
        raise _Damaged(f"attribute rtol = {c.rtol!r} is out of range; allowed: a positive number")


def _read_any_curve(f, version: int) -> CriticalCurve:
    """A critical curve of any schema, checked (:func:`_check_curve`; from schema 3 on, the digests too)."""
    if version == 1:
        result = _read_curve_v1(f)
    elif version == 2:
        result = _read_curve_v2(f)
    else:
        result = _read_curve(f)
    _check_curve(result)
    if version >= 3:  # last: a value out of range is named as such, not as a changed digest
        _rtol(f)
        _check_metadata(f)
    return result


def _curve_axes(f, version: int) -> dict:
    """``{param: values}`` of a critical curve (every step of its continuation)."""
    if version >= 3:
        param = _attr_str(f, "param")
        return {param: _axis_values(f, param, _axis_names([param])[0])}
    g = f["curve"]
    param = "v" if version == 1 else _attr_str(g, "param")
    return {param: _axis_values(g, param, param)}


register_kind(ArchiveKind("critical-curve", lambda r: isinstance(r, CriticalCurve),
                          lambda f, c, created, context: _write_curve(f, c, created), _read_any_curve, _curve_axes,
                          carries_case=True))
