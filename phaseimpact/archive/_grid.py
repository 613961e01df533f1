"""Grid results: sweeps (one axis) and atlases (two or more), their stick rows and ``/extras``; the
archive kinds ``sweep`` and ``atlas`` (written whole here, in place by :mod:`._checkpoint`), and
:func:`stick_phases`."""

from __future__ import annotations

import os
from dataclasses import dataclass

import h5py
import numpy as np

from ..continuation import SweepResult
from ..continuation.grid import Grid
from ..integrate import OUTCOMES, STATUSES
from ..integrate import driver as _driver
from ._cf import (
    _axis_names,
    _dimension,
    _fill_of,
    _flags,
    _grid_axes,
    _header,
    _long_name,
    _slab_chunks,
    axis_units,
    unit_attributes,
)
from ._common import (
    _AXIS_DIMENSIONS,
    _CHECKED,
    _CODES,
    _RESERVED,
    _ROW_INDICES,
    _UNITS,
    _XARRAY_EXTRA,
    CHUNK_POINTS,
    CHUNK_ROWS,
    STOP_REASONS,
    _attr_str,
    _axis_values,
    _base,
    _base_parameters,
    _checked_axis,
    _Context,
    _Damaged,
    _data,
    _gridded,
    _json,
    _json_attr,
    _law,
    _log_flag,
    _out_of_range,
    _rtol,
    _settings,
    _short,
    _t_end,
)
from ._digests import _check_metadata, _digest
from ._files import _fixed
from ._legacy import _read_sweep_v1, _read_sweep_v2
from ._registry import ArchiveKind, register_kind


@dataclass
class _Layout:
    """Stick rows of a sweep arranged for the file: each point's rows contiguous."""

    point: np.ndarray
    t: np.ndarray
    delta: np.ndarray
    dwell: np.ndarray
    first: np.ndarray
    count: np.ndarray


def _sweep_layout(r: SweepResult) -> _Layout:
    n = r.grid.size
    for name in ("status", "outcome", "stop_reason"):
        codes = np.asarray(getattr(r, name))
        if codes.shape != (n,):
            raise ValueError(f"{name} has shape {codes.shape}; allowed: ({n},), one code per grid point")
    point = np.asarray(r.stick_point, dtype=np.int64)
    columns = [np.asarray(getattr(r, f"stick_{k}"), dtype=float) for k in ("t", "delta", "dwell")]
    if any(c.shape != point.shape for c in columns) or point.ndim != 1:
        raise ValueError("stick_point, stick_t, stick_delta and stick_dwell must be 1-d arrays of one length")
    if point.size and (point.min() < 0 or point.max() >= n):
        raise ValueError(f"stick_point is out of range; allowed: flat indices 0 <= i < {n}")
    computed = np.asarray(r.status) >= 0
    if point.size and not computed[point].all():
        raise ValueError("stick phases of points that are not computed (status -1) cannot be archived")
    if point.size:
        starts = np.concatenate([[0], np.flatnonzero(point[1:] != point[:-1]) + 1])
        in_order = bool((point[1:] >= point[:-1]).all())  # as a sweep computes them (cheap to check)
        if not in_order and np.unique(point[starts]).size != starts.size:
            # a point's rows are apart: group them, in order
            order = np.argsort(point, kind="stable")
            point = point[order]
            columns = [c[order] for c in columns]
            starts = np.concatenate([[0], np.flatnonzero(point[1:] != point[:-1]) + 1])
    else:
        starts = np.empty(0, dtype=np.int64)
    count = np.bincount(point, minlength=n).astype(np.int64, copy=False)
    count[~computed] = -1
    first = np.full(n, -1, dtype=np.int64)
    first[point[starts]] = starts
    return _Layout(point, *columns, first, count)


def _write_sweep(f, r: SweepResult, created: str, context: _Context) -> None:
    layout = context.layout  # _sweep_layout(r), arranged before the file was opened
    spare_rows = context.spare_rows
    grid = r.grid
    shape = grid.shape
    alpha = _base_parameters(grid.base).alpha
    kind = "sweep" if len(grid.axes) == 1 else "atlas"
    title = (f"phaseimpact {kind}: {r.law.name} law, {' x '.join(str(n) for n in shape)} points over "
             f"{', '.join(grid.names)}")
    _header(f, kind, r.law, grid.base, r.t_end, r.settings.get("rtol"), r.settings.get("engine", ""), created, title,
            r.settings)
    dims = _axis_names(grid.names)
    f.attrs["axes"] = _json(list(grid.names))
    f.attrs[_AXIS_DIMENSIONS] = _json(dims)
    columns = list(r.values)
    f.attrs["columns"] = _json(columns)
    f.attrs["extras_digest"] = _digest(r.extras)
    scales = []
    for axis, dim in zip(grid.axes, dims, strict=True):
        d = f.create_dataset(dim, data=np.asarray(axis.values, dtype=float), **_CHECKED)
        d.make_scale(dim)
        units = axis_units(axis.name, alpha, r.law)
        d.attrs.update(unit_attributes(units))
        d.attrs["long_name"] = _long_name(axis.name, units)
        d.attrs["parameter"] = axis.name
        d.attrs["log"] = np.int8(bool(axis.log))
        scales.append(d)
    _grid_axes(scales)
    chunks = _slab_chunks(shape, CHUNK_POINTS)

    def gridded(name, data, dtype, units=None):
        coded = name in _CODES
        d = _fixed(f, name, np.asarray(data).reshape(shape), dtype, chunks, units=units, dims=scales,
                   fill_attr=not coded and name not in _ROW_INDICES)
        if coded:
            _flags(d, _CODES[name])
        return d

    for name in ("status", "outcome", "stop_reason"):
        gridded(name, getattr(r, name), np.int8)
    for name in columns:
        values = np.asarray(r.values[name])
        if values.shape != (grid.size,):
            raise ValueError(f"column {name} has shape {values.shape}; allowed: ({grid.size},)")
        gridded(name, values, values.dtype, _UNITS.get(name))
    gridded("stick_first", layout.first, np.int64)
    gridded("stick_count", layout.count, np.int64)

    rows = layout.point.size + max(0, int(spare_rows))
    stick = _dimension(f, "stick", rows)
    row_chunks = (min(CHUNK_ROWS, max(rows, 1)),)

    _fixed(f, "stick_point", layout.point, np.int64, row_chunks, fill=-1, fill_attr=False, dims=(stick,), rows=rows)
    for name, values, units in (("stick_t", layout.t, "s"), ("stick_delta", layout.delta, "m"),
                                ("stick_dwell", layout.dwell, "s")):
        _fixed(f, name, values, float, row_chunks, units=units, dims=(stick,), rows=rows)
    for name in _ROW_INDICES:
        f[name].attrs["valid_min"] = np.int64(0)
        f[name].attrs["comment"] = _ROW_INDICES[name]
    if r.extras:
        _write_tree(f.create_group("extras"), r.extras, _extras_dimensions(r))


def _extras_dimensions(r: SweepResult) -> dict:
    """Dimensions and attributes of the extras whose meaning is known, as ``{group: {array: (dimension names,
    attributes)}}``: the refined class boundaries of ``phaseimpact atlas --refine`` (``extras["boundaries"]``,
    :class:`~phaseimpact.continuation.Boundaries`), one row per boundary, one column per grid axis."""
    grid = r.grid
    alpha = _base_parameters(grid.base).alpha
    codes = {"flag_values": np.arange(len(OUTCOMES), dtype=np.int8), "flag_meanings": " ".join(OUTCOMES)}
    return {"boundaries": {
        "points": (("boundary", "column"), {
            "long_name": "refined class boundary points, one column per grid axis (columns)",
            "columns": _json(list(grid.names)),
            "column_units": _json([axis_units(name, alpha, r.law) for name in grid.names]),
            "comment": "no units attribute: the columns differ in unit (column_units, in UDUNITS syntax)"}),
        "below": (("boundary",), {"long_name": "outcome class on the low side along the refined axis", **codes}),
        "above": (("boundary",), {"long_name": "outcome class on the high side along the refined axis", **codes}),
    }}


def _write_tree(group, tree: dict, known: dict) -> None:
    """``tree`` (``SweepResult.extras``) under ``group``: arrays as datasets with netCDF dimensions (those of
    ``known`` where their sizes agree, else one per array and axis, ``<name>_dim<i>``), the rest as JSON."""
    rest, sizes = {}, {}
    for key, value in tree.items():
        key = str(key)
        if isinstance(value, dict):
            _write_tree(group.create_group(key), value, known.get(key, {}) if isinstance(known.get(key), dict) else {})
            continue
        array = np.asarray(value) if isinstance(value, (np.ndarray, list, tuple)) else None
        if array is None or array.dtype.kind not in "biuf" or not array.size:
            rest[key] = value
            continue
        d = group.create_dataset(key, data=array.astype(np.int8) if array.dtype.kind == "b" else array, **_CHECKED)
        d.attrs["type"] = "bool" if array.dtype.kind == "b" else "array"
        dims, attrs = known.get(key, ((), {}))
        if len(dims) != array.ndim or any(sizes.get(name, n) != n for name, n in zip(dims, array.shape, strict=True)):
            dims, attrs = [f"{key}_dim{i}" for i in range(array.ndim)], {}
        for i, (name, n) in enumerate(zip(dims, array.shape, strict=True)):
            while name in tree or sizes.get(name, n) != n or (name in group and name not in sizes):
                name += "_"  # a name the tree uses, or a dimension of another size
            if name not in sizes:
                sizes[name] = n
                _dimension(group, name, n)
            d.dims[i].attach_scale(group[name])
        d.attrs.update(attrs)
    group.attrs["json"] = _json(rest)


def _owned_rows(first, count, committed) -> np.ndarray:
    """Rows referenced by the committed points' ``stick_first``/``stick_count``, in point order."""
    points = np.flatnonzero(committed & (count > 0) & (first >= 0))
    counts = count[points]
    total = int(counts.sum())
    if total == 0:
        return np.empty(0, dtype=np.int64)
    offsets = np.repeat(np.cumsum(counts) - counts, counts)
    return np.repeat(first[points], counts) + (np.arange(total) - offsets)


def _axes(f) -> tuple:
    names = _json_attr(f, "axes", list)
    dims = _json_attr(f, _AXIS_DIMENSIONS if _AXIS_DIMENSIONS in f.attrs else "dimensions", list)  # schema 3, 4
    if not names or len(names) != len(dims) or not all(isinstance(x, str) for x in names + dims):
        raise _Damaged(f"attributes axes = {_short(names)} and dimensions = {_short(dims)} are out of range; "
                       "allowed: two lists of as many names")
    return tuple(_checked_axis(name, _data(f, dim, ndim=1), _log_flag(f[dim])) for name, dim in zip(names, dims,
                                                                                                  strict=True))


_STICK_VARIABLES = ("stick_point", "stick_t", "stick_delta", "stick_dwell")


def _read_sweep(f) -> SweepResult:
    grid = Grid(_base(f), _law(f), _axes(f))
    shape = grid.shape
    status = _gridded(f, "status", shape, "i").astype(np.int8)
    computed = status >= 0
    codes = {}
    for name in ("outcome", "stop_reason"):
        codes[name] = np.where(computed, _gridded(f, name, shape, "i"), -1).astype(np.int8)
    values = {}
    for name in _json_attr(f, "columns", list):
        if not isinstance(name, str) or name in _RESERVED:
            raise _Damaged(f"attribute columns names {name!r}; allowed: summary columns")
        column = _gridded(f, name, shape)
        if not computed.all():
            column = np.where(computed, column, _fill_of(column.dtype))
        values[name] = column
    first = _gridded(f, "stick_first", shape, "i").astype(np.int64)
    count = _gridded(f, "stick_count", shape, "i").astype(np.int64)
    stick = {name: _data(f, name, ndim=1, kinds="i" if name == "stick_point" else "f") for name in _STICK_VARIABLES}
    capacity = stick["stick_point"].shape[0]
    if any(column.shape != (capacity,) for column in stick.values()):
        raise _Damaged("variables " + ", ".join(_STICK_VARIABLES) + " differ in length")
    rows = _owned_rows(first, count, computed)
    owner = np.repeat(np.flatnonzero(computed & (count > 0) & (first >= 0)),
                      count[computed & (count > 0) & (first >= 0)])
    order = np.argsort(rows, kind="stable")
    rows, owner = rows[order], owner[order]
    if rows.size and (rows[0] < 0 or rows[-1] >= capacity or np.any(np.diff(rows) == 0)):
        raise _Damaged("stick_first/stick_count point outside the stick rows or overlap")
    point = stick["stick_point"][rows]
    if not np.array_equal(point, owner):
        raise _Damaged("stick_point disagrees with stick_first/stick_count")
    result = SweepResult(grid, _t_end(f), _settings(f), status=status, outcome=codes["outcome"],
                         stop_reason=codes["stop_reason"], stick_point=point.astype(np.int64),
                         stick_t=stick["stick_t"][rows], stick_delta=stick["stick_delta"][rows],
                         stick_dwell=stick["stick_dwell"][rows],
                         extras=_read_tree(f["extras"]) if "extras" in f else {})
    if "extras_digest" in f.attrs and _attr_str(f, "extras_digest") != _digest(result.extras):
        raise _Damaged("/extras (atlas --refine's boundaries, ...) is missing or changed: it does not match "
                       "the digest extras_digest" + (" (xarray writes the root group only)" if "extras" not in f
                                                     else ""))
    result.values.update(values)
    return result


def _read_tree(group) -> dict:
    tree = _json_attr(group, "json", dict) if "json" in group.attrs else {}
    for key, item in group.items():
        if isinstance(item, h5py.Group):
            tree[key] = _read_tree(item)
        elif not h5py.h5ds.is_scale(item.id):  # a netCDF dimension (schema 5), not an extra
            data = _data(group, key)
            tree[key] = data.astype(bool) if _attr_str(item, "type") == "bool" else data
    return tree


def _check_sweep(r: SweepResult) -> None:
    """Codes within their tables (the figures and summaries index tables with them), a finite
    ``max_force`` where a run succeeded and counts >= 0 (or -1: not kept, as in archives of schema 1) at
    computed points: what a chunk overwritten with its checksum breaks (0xFF makes NaN and -1; the data
    digests catch the rest). Other NaN are legitimate: not measured."""
    status = np.asarray(r.status)
    computed = status >= 0
    _out_of_range("status", status, (status < -1) | (status >= len(STATUSES)),
                  f"0 to {len(STATUSES) - 1} ({', '.join(STATUSES)}), or -1 (not computed)")
    for name, names in (("outcome", OUTCOMES), ("stop_reason", STOP_REASONS)):
        codes = np.asarray(getattr(r, name))
        _out_of_range(name, codes, computed & ((codes < 0) | (codes >= len(names))),
                      f"0 to {len(names) - 1} ({', '.join(names)}) at a computed point")
    if "max_force" in r.values:
        force = np.asarray(r.values["max_force"])
        _out_of_range("max_force", force, (status == _driver.SUCCESS) & ~np.isfinite(force),
                      "a finite force (N) where the run succeeded")
    for name, column in r.values.items():
        column = np.asarray(column)
        if column.dtype.kind == "i":
            _out_of_range(name, column, computed & (column < -1), "a count >= 0 (or -1: not kept) at a computed "
                          "point")


def stick_phases(ds_or_path):
    """The stick phases of a sweep or atlas, one row each, with the grid coordinates of their point.

    Only the rows of computed points are kept (a committed ``status``, the row within the point's
    ``stick_first`` .. ``stick_first + stick_count - 1``): the unused rows of an archive in
    progress (``stick_point`` -1) and rows a killed checkpoint left behind are never mapped to a
    grid point.

    Parameters
    ----------
    ds_or_path : xarray.Dataset, str or path-like
        An archive (schema 3 or later), or the Dataset that ``xarray.open_dataset`` or
        :func:`to_xarray` gives of one.

    Returns
    -------
    xarray.Dataset
        Along dimension ``stick``, in point order: ``stick_t`` (s), ``stick_delta`` (m),
        ``stick_dwell`` (s; inf: permanent) as data, and as coordinates ``stick_point`` (the
        point's flat, C-order index) and each axis (e.g. ``kappa``, ``v``) at the point.

    Raises
    ------
    ValueError
        For a critical curve (it has no stick phases).
    ImportError
        Without xarray and h5netcdf (the message names the extra).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import stick_phases, to_xarray
    >>> from phaseimpact.continuation import sweep
    >>> rows = stick_phases(to_xarray(sweep(seed_parameters(), "paper", [1e9, 1e13])))
    >>> rows.sizes["stick"], rows.kappa.values.tolist()
    (3, [1000000000.0, 10000000000000.0, 10000000000000.0])
    """
    try:
        import xarray
    except ImportError:
        raise ImportError(f"stick_phases needs xarray and h5netcdf: {_XARRAY_EXTRA}") from None
    if not isinstance(ds_or_path, xarray.Dataset):
        with xarray.open_dataset(os.fspath(ds_or_path), engine="h5netcdf") as ds:
            return stick_phases(ds.load())
    ds = ds_or_path
    if "stick_point" not in ds:
        raise ValueError(f"a {ds.attrs.get('kind', 'dataset')} holds no stick phases; allowed: a sweep or atlas")
    def flat(name):  # schemas 3 and 4 had _FillValue -1 here: xarray decoded -1 as NaN
        return ds[name].fillna(-1).values.reshape(-1).astype(np.int64)

    dims = ds["status"].dims
    rows = _owned_rows(flat("stick_first"), flat("stick_count"), flat("status") >= 0)
    point = ds["stick_point"].values[rows]
    out = ds[["stick_t", "stick_delta", "stick_dwell"]].isel(stick=rows)
    index = np.unravel_index(point, ds["status"].shape)
    return out.assign_coords({"stick_point": ("stick", point, ds["stick_point"].attrs),
                              **{dim: ("stick", ds[dim].values[i], ds[dim].attrs) for dim, i in zip(dims, index,
                                                                                                   strict=True)}})


def _read_grid(f, version: int) -> SweepResult:
    """A sweep or atlas of any schema, checked (:func:`_check_sweep`; from schema 3 on, the digests too)."""
    if version == 1:
        result = _read_sweep_v1(f)
    elif version == 2:
        result = _read_sweep_v2(f)
    else:
        result = _read_sweep(f)
    _check_sweep(result)
    if version >= 3:  # last: a value out of range is named as such, not as a changed digest
        _rtol(f)  # the header's copy (describe reads it); a sweep reads its settings
        _check_metadata(f)
    return result


def _grid_axes_of(f, version: int) -> dict:
    """``{name: values}`` of a sweep's or atlas's axes (:func:`~phaseimpact.archive.describe`)."""
    if version >= 3:
        return {a.name: a.values for a in _axes(f)}
    g = f["sweep"]
    names = ["kappa"] if version == 1 else _json_attr(g, "axes", list)
    return {name: _axis_values(g, name, name) for name in names}


def _grid_of(result, ndim_one: bool) -> bool:
    return isinstance(result, SweepResult) and (len(result.grid.axes) == 1) == ndim_one


register_kind(ArchiveKind("sweep", lambda r: _grid_of(r, True), _write_sweep, _read_grid, _grid_axes_of,
                          carries_case=True, resumable=True, prepare=_sweep_layout))
register_kind(ArchiveKind("atlas", lambda r: _grid_of(r, False), _write_sweep, _read_grid, _grid_axes_of,
                          carries_case=True, resumable=True, prepare=_sweep_layout))
