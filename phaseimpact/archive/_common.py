"""The bottom of the archive package: the schema's constants, the errors, plain values for JSON and
HDF5 attributes, and the checked readers of attributes and variables that every kind's reader uses
(each raises :class:`_Damaged` naming what is wrong). Imports nothing else of the package."""

from __future__ import annotations

import datetime
import json
import math
import os
from dataclasses import dataclass

import h5py
import numpy as np

from ..continuation.grid import Axis
from ..integrate import OUTCOMES, STATUSES
from ..integrate import driver as _driver
from ..integrate.result import SUMMARY_COLUMNS
from ..model import ContactLaw
from ..parameters import Parameters

#: The layout written (module docstring); schemas 1 and 2 still load, a newer one is refused.
SCHEMA_VERSION = 5
#: What an archive holds: a sweep (one axis), an atlas (two or more) or a continued curve.
KINDS = ("sweep", "atlas", "critical-curve")
#: What an archive of the impact map holds (phaseimpact.train): an ImpactTrain, an OrbitDiagram, a MapBranch
#: or Basins. Apart from KINDS, whose archives the command line's sweeps complete and resume.
TRAIN_KINDS = ("impact-train", "orbit-diagram", "map-branch", "basins")
#: What an archive of one run or of a transition search holds: a Trajectory (``simulate --out``) or the
#: list of Transition of :func:`~phaseimpact.continuation.transitions` (``transitions --out``).
RUN_KINDS = ("trajectory", "transitions")
#: CF 1.9 and later allow int64 variables (the counts and stick rows).
CONVENTIONS = "CF-1.11"
#: The global attribute ``references``: where the equations and the outcome classes are defined.
REFERENCES = ("docs/physics.md of phaseimpact (equations, corrections, outcome classes); the seed paper: "
              "\"An improved model for the damped impact of composite materials applicable to wind turbine blades\"")
#: Points of one chunk of a grid variable (a C-order slab; 64 KiB of float64).
CHUNK_POINTS = 8192
#: Rows of one chunk of the stick variables.
CHUNK_ROWS = 8192
STOP_REASONS = _driver.STOP_REASONS
_UNITS = {name: unit for name, _, _, unit in SUMMARY_COLUMNS}
_CODES = {"status": STATUSES, "outcome": OUTCOMES, "stop_reason": STOP_REASONS}
_LONG_NAMES = {
    "status": "numerical health of the run", "outcome": "outcome class (docs/physics.md section 5)",
    "stop_reason": "why the run stopped", "t_stop": "time the run stopped", "max_force": "largest contact force",
    "max_indentation": "largest indentation", "restitution": "coefficient of restitution (first contact)",
    "contact_duration": "duration of the first contact", "dissipated_energy": "energy dissipated",
    "loop_area": "work of the contact force (area of the force-indentation loop)",
    "n_stick": "number of stick phases", "n_contacts": "number of contacts",
    "t_run": "time the first stick broke (ratchet escape)", "first_stick_delta": "indentation of the first stick",
    "first_stick_margin": "margin of the first stick (negative: it breaks)", "nsteps": "integrator steps",
    "nfev": "right-hand side evaluations", "stick_first": "row of the point's first stick phase",
    "stick_count": "number of stick phases stored", "stick_point": "flat (C order) index of the grid point",
    "stick_t": "time the stick phase began", "stick_delta": "indentation of the stick phase",
    "stick_dwell": "duration of the stick phase (inf: permanent)",
}
#: Root attribute: the axes' netCDF names (schemas 3 and 4 called it ``dimensions``, which CF 1.9 made the
#: attribute of a domain variable: CF readers inherit root attributes, and took every variable as one).
_AXIS_DIMENSIONS = "axis_dimensions"
#: Integer variables that locate the stick rows: no _FillValue (xarray keeps them integers, so that they
#: index), -1 below valid_min (CF readers take it as missing).
_ROW_INDICES = {
    "stick_first": "-1 (below valid_min): no stick phase, or the point is not computed",
    "stick_count": "-1 (below valid_min): the point is not computed",
    "stick_point": "-1 (below valid_min): an unused row (room for the stick phases a checkpoint has still to write)",
}
#: Datasets of a sweep that are not summary columns (an axis must not take these names).
_RESERVED = ("status", "outcome", "stop_reason", "stick_first", "stick_count", "stick_point", "stick_t",
             "stick_delta", "stick_dwell", "stick", "extras")
_NOT_A_VARIABLE = "This is a netCDF dimension but not a netCDF variable."
#: Every dataset that holds data carries a Fletcher-32 checksum per chunk (HDF5's own filter, which
#: netCDF-4, h5netcdf and h5py all read): damaged bytes fail the read instead of loading as numbers.
_CHECKED = {"fletcher32": True}
#: The HDF5 file format of HDF5 1.8 (read by netCDF-C >= 4.1 and h5py): its superblock and object
#: headers (attributes included) carry checksums, so most damaged metadata is refused too. Pinned,
#: so that a newer HDF5 writes the same bytes. Not 1.10's format: its superblock marks the file open
#: while a checkpoint writes in place, which refuses readers then and every open after a kill -9.
#: What its metadata checksums leave out is checked on load: the chunk index (a v1 B-tree, see
#: :func:`._digests._check_storage`) and the global heap of variable-length strings (:data:`_TEXT_DIGEST`).
_LIBVER = ("v108", "v108")
#: Root attribute: SHA-256 of the file's text attributes, which HDF5 keeps in its global heap (no
#: checksum there: a changed digit of the case JSON would load silently).
_TEXT_DIGEST = "text_sha256"
#: Root attribute: the SHA-256 of each dataset's contents (:func:`._digests._dataset_digest`), JSON ``{path: hex}`` in a
#: fixed-length text, so that a checkpoint rewrites it in place. Fletcher-32 passes a chunk whose data and
#: checksum were both zeroed or filled with 0xFF; this digest does not.
_DATA_DIGEST = "data_sha256"
#: What :data:`_DATA_DIGEST` holds while a checkpoint writes in place: a file killed then has nothing to be
#: verified against (:func:`load` takes it unverified, as an archive written before data digests); the next
#: checkpoint rewrites it whole.
_IN_PROGRESS = '{"checkpoint": "in progress"}'
#: Elements (C order) per piece of a dataset's digest: a checkpoint hashes again only the pieces it wrote.
_DIGEST_PIECE = 8192
#: Root attribute of an archive of a user law: the law's source digest (:attr:`ContactLaw.source`; its
#: functions and law file). ``--resume`` and overwrites compare it: an edited law is other work.
_LAW_SOURCE = "law_source"


#: The kinds of :class:`~phaseimpact.continuation.Transition`.
TRANSITION_KINDS = ("adding-sliding", "staircase-end", "grazing")
#: The state's components, as a Trajectory's ``y`` holds them: (netCDF name, unit, long name).
_STATE = (("x1", "m", "projectile displacement"), ("x2", "m", "target displacement"),
          ("x1dot", "m s-1", "projectile velocity"), ("x2dot", "m s-1", "target velocity"),
          ("contact_work", "J", "work of the contact force"))
_YES_NO = ("no", "yes")


#: How to install what to_xarray and stick_phases need (the package is installed from a checkout or a wheel).
_XARRAY_EXTRA = ("install the extra phaseimpact[xarray] (in a checkout: pip install -e '.[xarray]'; with a wheel: "
                 "pip install 'phaseimpact-VERSION-py3-none-any.whl[xarray]'), or pip install xarray h5netcdf")


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
    """Now, or ``SOURCE_DATE_EPOCH`` (seconds since 1970, UTC) when set: reproducible builds.

    Returns
    -------
    str
        ISO 8601 in UTC, to the second (the archives' ``created`` attribute).

    Raises
    ------
    ValueError
        For a ``SOURCE_DATE_EPOCH`` that is not an integer number of seconds in range.

    Examples
    --------
    >>> import os
    >>> from phaseimpact.archive import created_timestamp
    >>> os.environ["SOURCE_DATE_EPOCH"] = "0"
    >>> created_timestamp()
    '1970-01-01T00:00:00+00:00'
    >>> del os.environ["SOURCE_DATE_EPOCH"]
    >>> created_timestamp().endswith("+00:00")
    True
    """
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
    from ..case import Case

    if isinstance(base, Case):
        return {"base": "case", "parameters": _json(base.parameters().as_dict()), "case": _json(base.as_dict())}
    if isinstance(base, Parameters):
        params = _json(base.as_dict())
        return {"base": "parameters", "parameters": params, "case": params}
    raise TypeError(f"cannot archive a base of type {type(base).__name__}")


def _base_parameters(base) -> Parameters:
    return base if isinstance(base, Parameters) else base.parameters()


@dataclass(frozen=True)
class _Context:
    """What a result that does not carry it was computed with: the case (Parameters or Case), the law
    and the call's other settings (``rtol``, ``period``, ``kappa_min``, ...); any of them None. A sweep's
    writer also reads ``layout`` (its stick rows as the file holds them, ``_grid._Layout``; None: from
    the result) and ``spare_rows`` (free stick rows for a checkpoint to fill)."""

    base: object = None
    law: ContactLaw | None = None
    settings: dict | None = None
    layout: object = None
    spare_rows: int = 0


class _Refusal(ValueError):
    """A refusal whose message is complete (it names the file): passed on unchanged."""


class _Damaged(ValueError):
    """What is wrong with the content of an archive (the message does not name the file)."""

    def __init__(self, reason: str, *, checksum: bool = False):
        super().__init__(reason)
        self.checksum = checksum


class DamagedArchiveError(ValueError):
    """An archive whose bytes or content are damaged; the message names the file and the damage.
    ``reason`` is the damage alone.

    Raised by :func:`load` and :func:`describe`; a ``ValueError``, so a caller that refuses bad
    input catches it with the rest.

    Parameters
    ----------
    path : str
        The archive.
    reason : str
        What is damaged.
    checksum : bool, default False
        The damage is a failed checksum (a read that may succeed when tried again, if a
        checkpoint was rewriting the chunk).

    Attributes
    ----------
    path, reason, checksum
        As given.

    Examples
    --------
    >>> from phaseimpact.archive import DamagedArchiveError
    >>> error = DamagedArchiveError("atlas.nc", "status holds code 9")
    >>> isinstance(error, ValueError), error.reason
    (True, 'status holds code 9')
    >>> str(error)
    "'atlas.nc' is an incomplete or damaged phaseimpact archive: status holds code 9"
    """

    def __init__(self, path: str, reason: str, *, checksum: bool = False):
        super().__init__(f"{path!r} is an incomplete or damaged phaseimpact archive: {reason}")
        self.path, self.reason, self.checksum = path, reason, checksum


def _netcdf_writer(f) -> str | None:
    """The library that wrote the file when it is not phaseimpact: netCDF-C and h5netcdf (xarray's
    ``to_netcdf``) leave ``_NCProperties``, h5py (:func:`save`) does not."""
    try:
        value = f.attrs.get("_NCProperties")
    except Exception:  # unreadable attributes: the damage is reported by the read itself
        return None
    if value is None:
        return None
    text = value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)
    return next((part for part in text.split(",") if part.startswith(("netcdf=", "h5netcdf="))), text)


def _short(value) -> str:
    if isinstance(value, np.ndarray):
        value = value.tolist()
    elif isinstance(value, np.generic):
        value = value.item()
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _attr(node, key):
    """Attribute ``key`` as written: netCDF (so xarray's re-save) stores a number as a length-1 array,
    h5py and :func:`save` as a scalar; both are the same value."""
    value = node.attrs[key]
    if isinstance(value, np.ndarray) and value.shape == (1,):
        return value[0]
    return value


def _attr_str(node, key) -> str:
    value = _attr(node, key)
    if isinstance(value, bytes):
        value = value.decode("utf-8")
    if not isinstance(value, str):
        raise _Damaged(f"attribute {key} = {_short(value)} is out of range; allowed: a text")
    return value


def _strings(dataset) -> np.ndarray:
    return np.asarray(dataset.asstr()[()], dtype=object)


def _int_attr(node, key) -> int:
    value = _attr(node, key)
    if isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)):
        return int(value)
    raise _Damaged(f"attribute {key} = {_short(value)} is out of range; allowed: an integer")


def _real_attr(node, key) -> float:
    value = _attr(node, key)
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_)):
        return float(value)
    raise _Damaged(f"attribute {key} = {_short(value)} is out of range; allowed: a number")


def _json_attr(node, key, kind: type):
    try:
        value = json.loads(_attr_str(node, key))
    except json.JSONDecodeError as error:
        raise _Damaged(f"attribute {key} is not valid JSON ({error})") from None
    if not isinstance(value, kind):
        raise _Damaged(f"attribute {key} = {_short(value)} is out of range; allowed: a JSON {kind.__name__}")
    return value


def _rtol(node) -> float:
    rtol = _real_attr(node, "rtol")
    if not (math.isfinite(rtol) and rtol > 0):
        raise _Damaged(f"attribute rtol = {rtol!r} is out of range; allowed: a positive number")
    return rtol


def _data(node, name: str, *, ndim: int | None = None, kinds: str = "fiub") -> np.ndarray:
    """All of dataset ``name`` (each chunk is read, so each chunk's checksum is checked)."""
    dataset = node.get(name)
    if not isinstance(dataset, h5py.Dataset):
        raise _Damaged(f"variable {name} is missing")
    try:
        data = dataset[()]
    except OSError as error:
        if "filter" in str(error) or "checksum" in str(error).lower():
            raise _Damaged(f"variable {name}: its bytes do not match their Fletcher-32 checksum (they were changed "
                           "after it was written)", checksum=True) from None
        raise _Damaged(f"variable {name} cannot be read: {error}") from None
    data = np.asarray(data)
    if (ndim is not None and data.ndim != ndim) or data.dtype.kind not in kinds:
        raise _Damaged(f"variable {name} has shape {data.shape} and type {data.dtype}; allowed: {ndim}-d numbers")
    return data


def _gridded(f, name: str, shape: tuple, kinds: str = "fiu") -> np.ndarray:
    data = _data(f, name, kinds=kinds)
    if data.shape != tuple(shape):
        raise _Damaged(f"variable {name} has shape {data.shape}; allowed: {tuple(shape)}, the grid's")
    return data.reshape(-1)


def _checked_axis(name: str, values: np.ndarray, log: bool) -> Axis:
    values = np.asarray(values)
    if values.ndim != 1 or values.size == 0 or values.dtype.kind not in "fiu":
        raise _Damaged(f"axis {name} has shape {values.shape} and type {values.dtype}; allowed: a non-empty 1-d "
                       "array of numbers")
    if values.dtype.kind != "f":
        values = values.astype(float)
    bad = ~np.isfinite(values)
    if bad.any():
        i = int(np.argmax(bad))
        raise _Damaged(f"axis {name} holds {_short(values[i])} at index {i}; allowed: finite numbers")
    if log and not np.all(values > 0):
        raise _Damaged(f"axis {name} is marked log but holds {_short(values.min())}; allowed: positive numbers")
    return Axis(name, values, log)


def _log_flag(node) -> bool:
    return bool(_int_attr(node, "log")) if "log" in node.attrs else False


def _law(f) -> ContactLaw:
    return ContactLaw(**_json_attr(f, "law", dict))


def _law_source(f) -> str | None:
    """The source digest of the archive's user law (:attr:`ContactLaw.source`); None for a shipped law's."""
    return _attr_str(f, _LAW_SOURCE) if _LAW_SOURCE in f.attrs else None


def _base(f):
    from ..case import case_from_dict

    if "base" in f.attrs:  # schema 3 and later: case holds the Case, or the Parameters
        data = _json_attr(f, "case", dict)
        return case_from_dict(data, origin="archive") if _attr_str(f, "base") == "case" else Parameters(**data)
    if "case" in f.attrs:  # schema 2: case only when the base is a case
        return case_from_dict(_json_attr(f, "case", dict), origin="archive")
    return Parameters(**_json_attr(f, "parameters", dict))


def _t_end(f):
    t_end = _real_attr(f, "t_end")
    if math.isnan(t_end):
        return None
    if not (math.isfinite(t_end) and t_end > 0):
        raise _Damaged(f"attribute t_end = {t_end!r} is out of range; allowed: a positive number (s), or NaN")
    return t_end


def _settings(f) -> dict:
    if "settings" in f.attrs:
        return _json_attr(f, "settings", dict)
    return {"rtol": _rtol(f), "engine": _attr_str(f, "engine"), "version": _attr_str(f, "package_version")}


def _out_of_range(name: str, values: np.ndarray, bad: np.ndarray, allowed: str) -> None:
    if np.any(bad):
        i = int(np.argmax(bad))
        raise _Damaged(f"{name} = {_short(values[i])} at point {i} is out of range; allowed: {allowed}")


def _checked_codes(f, name: str, table, shape: tuple) -> np.ndarray:
    codes = _data(f, name, kinds="iu")
    if codes.shape != shape:
        raise _Damaged(f"variable {name} has shape {codes.shape}; allowed: {shape}")
    _out_of_range(name, codes.reshape(-1), (codes.reshape(-1) < 0) | (codes.reshape(-1) >= len(table)),
                  f"0 to {len(table) - 1} ({', '.join(table)})")
    return codes


def _shaped(f, name: str, shape: tuple, kinds: str = "f") -> np.ndarray:
    data = _data(f, name, kinds=kinds)
    if data.shape != shape:
        raise _Damaged(f"variable {name} has shape {data.shape}; allowed: {shape}")
    return data


def _same_number(a, b) -> bool:
    a, b = _float(a), _float(b)
    return a == b or (math.isnan(a) and math.isnan(b))


def _axis_values(node, name: str, dataset: str) -> np.ndarray:
    """The values of the 1-d axis ``name`` stored as ``dataset``, checked (finite numbers)."""
    return _checked_axis(name, _data(node, dataset, ndim=1), False).values
