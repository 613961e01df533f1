"""HDF5 archives of sweeps and ``kappa_c(v)`` curves, readable with plain h5py.

Schema (``schema_version`` 2; the README has the full table)::

    /                      attrs: schema_version, package_version, kind ("sweep" | "critical-curve"),
                                  law (JSON), parameters (JSON, SI), case (JSON, when the base is a case),
                                  engine, rtol, t_end (s; NaN: each run until its outcome settles),
                                  created (ISO 8601 UTC; from SOURCE_DATE_EPOCH when set)
    /sweep                 attrs: axes (JSON list of axis names, C order)
    /sweep/<axis>          (n_i,) float64  the axis values (an HDF5 dimension scale), e.g. /sweep/kappa
    /sweep/status          shape  str      success, step-size-collapse, ...; "" where not computed
    /sweep/outcome         shape  str      permanent-stick, ratchet-escape, rebound, runaway, ...
    /sweep/stop_reason     shape  str      horizon, settled, runaway, asked, failed
    /sweep/<column>        shape  float64 or int64, with a units attribute: max_force (N), n_stick, ...
    /sweep/sticks/point    (m,)   int64    flat (C order) index of the point each stick phase belongs to
    /sweep/sticks/t, delta, dwell (m,) float64  s, m, s (inf: a permanent stick)
    /curve                 attrs: param, what, rtol, contact_index, message
    /curve/<param>         (k,)   float64  the second parameter, e.g. /curve/v (m/s)
    /curve/kappa           (k,)   float64  the continued kappa_c (or kappa_2, grazing); NaN where lost
    /curve/requested       (k,)   bool     asked for (False: an intermediate step)
    /curve/closed_form, predicted  (k,) float64

Strings are variable-length UTF-8; plain h5py returns them as bytes unless read through
``dataset.asstr()[()]``. Files are written to a temporary file in the same folder and renamed
over the target, under the path's write lock (:mod:`phaseimpact._atomic`), so a reader (or a
crash) only ever sees the previous file or the complete new one. Archives of schema 1 (phaseimpact
0.1) still load.
"""

from __future__ import annotations

import datetime
import json
import math
import os

import h5py
import numpy as np

from . import __version__
from ._atomic import atomic_path
from .continuation import CriticalCurve, SweepResult
from .continuation.grid import Axis, Grid
from .integrate import OUTCOMES, STATUSES
from .integrate import driver as _driver
from .integrate.result import SUMMARY_COLUMNS
from .model import ContactLaw
from .parameters import Parameters

__all__ = ["SCHEMA_VERSION", "KINDS", "save", "load", "describe", "same_work", "check_overwrite"]

SCHEMA_VERSION = 2
KINDS = ("sweep", "critical-curve")
_STR = h5py.string_dtype("utf-8")
STOP_REASONS = _driver.STOP_REASONS
_UNITS = {name: unit for name, _, _, unit in SUMMARY_COLUMNS}


# ------------------------------------------------------------------------------------------------
# Plain values for JSON and HDF5 attributes
# ------------------------------------------------------------------------------------------------

def _plain(value):
    """``json.dumps(default=...)``: NumPy scalars and arrays as plain Python numbers and lists."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"cannot store a {type(value).__name__} in an archive")


def _json(obj) -> str:
    return json.dumps(obj, default=_plain, sort_keys=True)


def _float(value) -> float:
    return math.nan if value is None else float(value)


def created_timestamp() -> str:
    """Now, or ``SOURCE_DATE_EPOCH`` (seconds since 1970, UTC) when set: reproducible builds."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
    if epoch:
        try:
            moment = datetime.datetime.fromtimestamp(int(epoch), datetime.timezone.utc)
        except (ValueError, OverflowError, OSError):
            raise ValueError(f"SOURCE_DATE_EPOCH = {epoch!r} is out of range; allowed: an integer number of "
                             "seconds since 1970-01-01 UTC") from None
    else:
        moment = datetime.datetime.now(datetime.timezone.utc)
    return moment.isoformat(timespec="seconds")


def _base_attrs(base) -> dict:
    from .case import Case

    if isinstance(base, Case):
        return {"parameters": _json(base.parameters().as_dict()), "case": _json(base.as_dict())}
    if isinstance(base, Parameters):
        return {"parameters": _json(base.as_dict())}
    raise TypeError(f"cannot archive a base of type {type(base).__name__}")


# ------------------------------------------------------------------------------------------------
# Writing
# ------------------------------------------------------------------------------------------------

def save(result: SweepResult | CriticalCurve, path, *, force: bool = False) -> str:
    """Write ``result`` to ``path`` atomically (temporary file, fsync, rename) under its write lock.

    Parameters
    ----------
    result : SweepResult or CriticalCurve
    path : str or path-like
    force : bool
        Replace ``path`` even if it exists and is not a phaseimpact archive. Without it such a file
        is refused (``ValueError``); an existing archive is replaced. (The command line also refuses
        an archive of other work: see :func:`check_overwrite`.)

    Raises ``ValueError`` (before writing anything) for a path that cannot be written, and
    :class:`phaseimpact._atomic.PathLockedError` if another process is writing ``path``.
    """
    if not isinstance(result, (SweepResult, CriticalCurve)):
        raise TypeError(f"cannot archive a {type(result).__name__}")
    path = os.fspath(path)
    with atomic_path(path, "path") as tmp:
        if not force and os.path.isfile(path) and not _is_archive(path):
            raise ValueError(f"path = {path!r} exists and is not a phaseimpact archive; refusing to replace it "
                             "(force=True replaces it)")
        with h5py.File(tmp, "w") as f:
            if isinstance(result, SweepResult):
                _write_sweep(f, result)
            else:
                _write_curve(f, result)
    return path


def _header(f, kind: str, law: ContactLaw, base, t_end, rtol, engine: str) -> None:
    f.attrs["schema_version"] = SCHEMA_VERSION
    f.attrs["package_version"] = __version__
    f.attrs["kind"] = kind
    f.attrs["law"] = _json(law.as_dict())
    for key, value in _base_attrs(base).items():
        f.attrs[key] = value
    f.attrs["engine"] = str(engine)
    f.attrs["rtol"] = _float(rtol)
    f.attrs["t_end"] = _float(t_end)
    f.attrs["created"] = created_timestamp()


def _dataset(group, name, data, units=None, dtype=None):
    d = group.create_dataset(name, data=data, dtype=dtype)
    if units is not None:
        d.attrs["units"] = units
    return d


def _names(codes: np.ndarray, names) -> np.ndarray:
    table = np.array([*names, ""], dtype=object)
    codes = np.asarray(codes).astype(np.int64)
    return table[np.where(codes < 0, len(names), codes)]


def _codes(strings: np.ndarray, names) -> np.ndarray:
    lookup = {name: i for i, name in enumerate(names)}
    lookup[""] = -1
    try:
        return np.array([lookup[s] for s in strings.ravel()], dtype=np.int8).reshape(strings.shape)
    except KeyError as error:
        raise ValueError(f"unknown code {error.args[0]!r}; allowed: one of {', '.join(names)}") from None


def _write_sweep(f, r: SweepResult) -> None:
    _header(f, "sweep", r.law, r.grid.base, r.t_end, r.settings.get("rtol"), r.settings.get("engine", ""))
    g = f.create_group("sweep")
    shape = r.grid.shape
    g.attrs["axes"] = _json(list(r.grid.names))
    scales = []
    for axis in r.grid.axes:
        d = _dataset(g, axis.name, np.asarray(axis.values, dtype=float), _axis_units(axis.name))
        d.attrs["log"] = bool(axis.log)
        d.make_scale(axis.name)
        scales.append(d)

    def gridded(name, data, units=None, dtype=None):
        d = _dataset(g, name, np.asarray(data).reshape(shape), units, dtype)
        for i, scale in enumerate(scales):
            d.dims[i].attach_scale(scale)
        return d

    gridded("status", _names(r.status, STATUSES), dtype=_STR)
    gridded("outcome", _names(r.outcome, OUTCOMES), dtype=_STR)
    gridded("stop_reason", _names(r.stop_reason, STOP_REASONS), dtype=_STR)
    for name, values in r.values.items():
        gridded(name, values, _UNITS.get(name, ""))
    s = g.create_group("sticks")
    s.attrs["layout"] = "indexed ragged: row j is a stick phase of the point with flat (C order) index point[j]"
    _dataset(s, "point", np.asarray(r.stick_point, dtype=np.int64), "1")
    _dataset(s, "t", np.asarray(r.stick_t, dtype=float), "s")
    _dataset(s, "delta", np.asarray(r.stick_delta, dtype=float), "m")
    _dataset(s, "dwell", np.asarray(r.stick_dwell, dtype=float), "s")


def _axis_units(name: str) -> str:
    from .case import SETTABLE

    units = {"kappa": "N s/m^(1+alpha)", "v": "m/s", "M1": "kg", "M2": "kg", "K": "N/m^alpha", "Kb": "N/m",
             "Km": "N/m^3", "alpha": "1", "R": "m"}
    return units.get(name) or SETTABLE.get(name, ("",))[0]


def _write_curve(f, c: CriticalCurve) -> None:
    _header(f, "critical-curve", c.law, c.base, None, c.rtol, "")
    g = f.create_group("curve")
    g.attrs["param"] = c.param
    g.attrs["what"] = c.what
    g.attrs["rtol"] = float(c.rtol)
    g.attrs["contact_index"] = int(c.contact_index)
    g.attrs["message"] = str(c.message)
    values = _dataset(g, c.param, np.asarray(c.values, dtype=float), _axis_units(c.param))
    values.make_scale(c.param)
    for name in ("kappa", "requested", "closed_form", "predicted"):
        data = np.asarray(getattr(c, name), dtype=bool if name == "requested" else float)
        d = _dataset(g, name, data, None if name == "requested" else "N s/m^(1+alpha)")
        d.dims[0].attach_scale(values)


# ------------------------------------------------------------------------------------------------
# Reading
# ------------------------------------------------------------------------------------------------

def _open(path):
    path = os.fspath(path)
    if os.path.isdir(path):
        raise ValueError(f"archive {path!r} is a folder, not a file")
    try:
        return h5py.File(path, "r")
    except FileNotFoundError:
        raise ValueError(f"archive {path!r} does not exist") from None
    except OSError as error:
        raise ValueError(f"{path!r} is not a readable HDF5 file (truncated or foreign): {error}") from None


def _is_archive(path) -> bool:
    try:
        with h5py.File(path, "r") as f:
            return "schema_version" in f.attrs and "kind" in f.attrs
    except OSError:
        return False


def _attr_str(f, key) -> str:
    value = f.attrs[key]
    return value.decode() if isinstance(value, bytes) else str(value)


def _strings(dataset) -> np.ndarray:
    return np.asarray(dataset.asstr()[()], dtype=object)


def _checked_header(f, path) -> int:
    if "schema_version" not in f.attrs or "kind" not in f.attrs:
        raise ValueError(f"{path!r} is not a phaseimpact archive (no schema_version attribute)")
    version = int(f.attrs["schema_version"])
    if version > SCHEMA_VERSION:
        raise ValueError(f"{path!r} has schema_version {version}; this phaseimpact reads up to "
                         f"{SCHEMA_VERSION}: upgrade phaseimpact")
    kind = _attr_str(f, "kind")
    if kind not in KINDS:
        raise ValueError(f"{path!r} has unknown kind {kind!r}; allowed: {', '.join(KINDS)}")
    return version


def _law(f) -> ContactLaw:
    return ContactLaw(**json.loads(_attr_str(f, "law")))


def _base(f):
    if "case" in f.attrs:
        from .case import case_from_dict

        return case_from_dict(json.loads(_attr_str(f, "case")), origin="archive")
    return Parameters(**json.loads(_attr_str(f, "parameters")))


def load(path):
    """Read an archive back: a :class:`SweepResult` or a :class:`CriticalCurve`.

    Raises ``ValueError`` for a missing, foreign, truncated or newer-schema file.
    """
    path = os.fspath(path)
    with _open(path) as f:
        version = _checked_header(f, path)
        kind = _attr_str(f, "kind")
        try:
            if version == 1:
                return _read_sweep_v1(f) if kind == "sweep" else _read_curve_v1(f)
            return _read_sweep(f) if kind == "sweep" else _read_curve(f)
        except (KeyError, OSError, TypeError, json.JSONDecodeError) as error:
            raise ValueError(f"{path!r} is an incomplete or damaged phaseimpact archive: {error}") from None


def _t_end(f):
    t_end = float(f.attrs["t_end"])
    return None if math.isnan(t_end) else t_end


def _read_sweep(f) -> SweepResult:
    g = f["sweep"]
    names = json.loads(_attr_str(g, "axes"))
    axes = tuple(Axis(name, g[name][()], bool(g[name].attrs.get("log", False))) for name in names)
    grid = Grid(_base(f), _law(f), axes)
    settings = {"rtol": float(f.attrs["rtol"]), "engine": _attr_str(f, "engine"),
                "version": _attr_str(f, "package_version")}
    values = {}
    for name, _, dtype, _ in SUMMARY_COLUMNS:
        if name in g:
            values[name] = g[name][()].reshape(-1).astype(dtype)
    result = SweepResult(grid, _t_end(f), settings,
                         status=_codes(_strings(g["status"]).reshape(-1), STATUSES),
                         outcome=_codes(_strings(g["outcome"]).reshape(-1), OUTCOMES),
                         stop_reason=_codes(_strings(g["stop_reason"]).reshape(-1), STOP_REASONS),
                         stick_point=g["sticks/point"][()], stick_t=g["sticks/t"][()],
                         stick_delta=g["sticks/delta"][()], stick_dwell=g["sticks/dwell"][()])
    result.values.update(values)
    return result


def _read_curve(f) -> CriticalCurve:
    g = f["curve"]
    param = _attr_str(g, "param")
    return CriticalCurve(param, g[param][()], g["kappa"][()], g["requested"][()].astype(bool), g["closed_form"][()],
                         g["predicted"][()], _attr_str(g, "what"), _law(f), _base(f), float(g.attrs["rtol"]),
                         int(g.attrs["contact_index"]), _attr_str(g, "message"))


#: Schema 1 (phaseimpact 0.1) outcome names in today's terms.
_V1_OUTCOMES = {"stick": "permanent-stick", "rest": "permanent-stick", "rebound": "rebound", "runaway": "runaway",
                "bounded-oscillation": "bounded", "failed": "failed", "": ""}


def _v1_parameters(f) -> Parameters:
    return Parameters(**json.loads(_attr_str(f, "parameters")))


def _read_sweep_v1(f) -> SweepResult:
    g = f["sweep"]
    kappa = g["kappa"][()]
    grid = Grid(_v1_parameters(f), _law(f), (Axis.make("kappa", kappa),))
    settings = {"rtol": float(f.attrs["rtol"]), "engine": _attr_str(f, "integrator"),
                "version": _attr_str(f, "package_version")}
    n_asymptotic = g["n_asymptotic"][()]
    old_status = _strings(g["status"])
    status = np.where(np.isin(old_status, ("success", "runaway")), "success", old_status)
    status = np.where(n_asymptotic < 0, "", np.where(status == "error", "non-finite", status))
    outcome = np.array([_V1_OUTCOMES.get(s, "failed") for s in _strings(g["outcome"])], dtype=object)
    reason = np.where(n_asymptotic < 0, "", np.where(outcome == "runaway", "runaway", "horizon"))
    offsets = g["points/offsets"][()]
    result = SweepResult(grid, float(f.attrs["t_end"]), settings,
                         status=_codes(np.asarray(status, dtype=object), STATUSES),
                         outcome=_codes(outcome, OUTCOMES), stop_reason=_codes(np.asarray(reason, dtype=object),
                                                                                 STOP_REASONS),
                         stick_point=np.repeat(np.arange(len(kappa)), np.diff(offsets)),
                         stick_t=np.full(int(offsets[-1]), np.nan), stick_delta=g["points/delta"][()],
                         stick_dwell=g["points/dwell"][()])
    for name in ("max_force", "max_indentation", "restitution", "dissipated_energy"):
        result.values[name] = g[name][()].astype(float)
    result.values["n_stick"] = n_asymptotic.astype(np.int64)
    return result


def _read_curve_v1(f) -> CriticalCurve:
    g = f["curve"]
    v = g["v"][()]
    message = "; ".join(str(m) for m in _strings(g["message"])) if "message" in g else ""
    return CriticalCurve("v", v, g["kappa_c"][()], np.ones(len(v), dtype=bool), np.full(len(v), np.nan),
                         np.full(len(v), np.nan), "kappa_c", _law(f), _v1_parameters(f), float(f.attrs["rtol"]),
                         1, message)


# ------------------------------------------------------------------------------------------------
# What an archive holds, and whether a new result may replace it
# ------------------------------------------------------------------------------------------------

def describe(path) -> dict:
    """The identity of the work an archive holds, read from its header and axes only.

    Returns ``{"kind", "law", "parameters", "axes", "t_end", "rtol", "schema_version"}``
    (``axes``: ``{name: values}``). Raises ``ValueError`` if ``path`` is not a phaseimpact archive.
    """
    path = os.fspath(path)
    with _open(path) as f:
        version = _checked_header(f, path)
        kind = _attr_str(f, "kind")
        try:
            law = ContactLaw(**json.loads(_attr_str(f, "law"))).as_dict()
            params = json.loads(_attr_str(f, "parameters"))
            if kind == "sweep":
                g = f["sweep"]
                names = ["kappa"] if version == 1 else json.loads(_attr_str(g, "axes"))
                axes = {name: g[name][()] for name in names}
            else:
                g = f["curve"]
                param = "v" if version == 1 else _attr_str(g, "param")
                axes = {param: g[param][()]}
            return {"kind": kind, "law": law, "parameters": params, "axes": axes, "t_end": float(f.attrs["t_end"]),
                    "rtol": float(f.attrs["rtol"]), "schema_version": version}
        except (KeyError, OSError, TypeError, ValueError, json.JSONDecodeError) as error:
            raise ValueError(f"{path!r} is an incomplete or damaged phaseimpact archive: {error}") from None


def _same_number(a, b) -> bool:
    a, b = _float(a), _float(b)
    return a == b or (math.isnan(a) and math.isnan(b))


def _axis_text(name, values) -> str:
    values = np.asarray(values, dtype=float).ravel()
    return f"{name}: {len(values)} values from {values[0]:.6g} to {values[-1]:.6g}" if values.size else f"{name}: empty"


def same_work(held: dict, kind: str, law: ContactLaw, params: Parameters, axes: dict, t_end, rtol) -> list[str]:
    """What differs between an archive's :func:`describe` and the work asked for (empty: the same)."""
    differences = []
    if held["kind"] != kind:
        differences.append(f"kind {held['kind']!r}, not {kind!r}")
    if held["law"] != law.as_dict():
        differences.append(f"law {held['law']}, not {law.as_dict()}")
    asked = json.loads(_json(params.as_dict()))
    if held["parameters"] != asked:
        changed = sorted(k for k in set(asked) | set(held["parameters"])
                         if held["parameters"].get(k) != asked.get(k))
        differences.append("parameters " + ", ".join(
            f"{k} = {held['parameters'].get(k)!r} (asked {asked.get(k)!r})" for k in changed))
    if list(held["axes"]) != list(axes) or not all(
            np.array_equal(np.asarray(held["axes"][k], dtype=float), np.asarray(v, dtype=float))
            for k, v in axes.items()):
        differences.append("axes " + ", ".join(_axis_text(k, v) for k, v in held["axes"].items())
                           + " (asked " + ", ".join(_axis_text(k, v) for k, v in axes.items()) + ")")
    if not _same_number(held["t_end"], t_end):
        differences.append(f"t_end {held['t_end']!r}")
    if not _same_number(held["rtol"], rtol):
        differences.append(f"rtol {held['rtol']!r}")
    return differences


def check_overwrite(path, kind: str, law: ContactLaw, params: Parameters, axes: dict, t_end, rtol, *,
                    force: bool = False, name: str = "out") -> None:
    """Refuse (``ValueError``) to replace ``path`` unless it is missing, or an archive of the same work
    (kind, law, parameters, axis values, ``t_end`` and ``rtol``), or ``force`` is set."""
    path = os.fspath(path)
    if force or not os.path.exists(path):
        return
    try:
        held = describe(path)
    except ValueError:
        raise ValueError(f"{name} = {path!r} exists and is not a phaseimpact archive; refusing to overwrite it "
                         "(choose another path, or add --force to replace it)") from None
    differences = same_work(held, kind, law, params, axes, t_end, rtol)
    if differences:
        raise ValueError(f"{name} = {path!r} holds other work ({'; '.join(differences)}); refusing to overwrite it "
                         "(choose another path, or add --force to replace it)")
