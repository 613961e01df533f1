"""HDF5 archives of sweeps, atlases, continued curves, runs, transitions and trains of impacts: netCDF-4 /
CF-1.11 files (conventionally ``.nc``) that xarray, netCDF4, cfdm and other CF readers open as labelled
arrays, and that plain h5py reads just as well.

Layout (``schema_version`` 5). Every variable of the result is in the root group, so
``xarray.open_dataset(path)`` shows them all, with one dimension per axis::

    / attrs       Conventions "CF-1.11", title, history, source, references (CF's), schema_version 5,
                  package_version, kind ("sweep": one axis, "atlas": two or more, "critical-curve"; one
                  of RUN_KINDS: "trajectory", "transitions"; or one of TRAIN_KINDS: "impact-train",
                  "orbit-diagram", "map-branch", "basins"), law
                  (JSON), contact (its reading of |delta|^alpha), law_source (a user law's only: the digest
                  of its functions and law file), base ("parameters" or "case"), case (JSON:
                  the Case, or the Parameters), parameters (JSON, SI: the base's Parameters), engine, rtol,
                  t_end (s; NaN: each run until its outcome settles), created (ISO 8601 UTC; from
                  SOURCE_DATE_EPOCH when set), settings (JSON)

    sweep or atlas, grid shape (n_1, ..., n_d) in C order over the axes (attrs axes: the names,
    axis_dimensions: their netCDF names, columns: the summary columns stored, all JSON lists):
    <axis>        (n_i,)  float64  a coordinate variable (HDF5 dimension scale) per axis, named by it
                                   with characters other than letters, digits and _ made _
                                   (plate.E -> plate_E); attrs units (or fractional_units, below),
                                   long_name, parameter (the original name), log (1: a log-spaced axis)
    status        grid    int8     0 success, 1 step-size-collapse, 2 too-many-steps, 3 non-finite;
                                   -1: not computed, outside valid_range (flag_values, flag_meanings;
                                   no _FillValue, so that xarray keeps the codes as integers)
    outcome       grid    int8     failed, permanent-stick, ratchet-escape, rebound, runaway, bounded,
                                   unsettled (flag_values, flag_meanings); -1 as status
    stop_reason   grid    int8     horizon, settled, runaway, asked, failed; -1 as status
    <column>      grid    float64 or int64: every summary column (max_force, n_stick, t_run, ...)
                                   with its units (N, m, s, J, 1); _FillValue NaN or -1 (xarray reads
                                   the counts as float, NaN where not computed: a missing count, never
                                   a -1 in a sum or mean)
    stick_first   grid    int64    row of the point's first stick phase (-1: none or not computed)
    stick_count   grid    int64    its number of stick phases (-1: not computed)
    stick_point   (stick,) int64   flat (C order) index of each row's point; -1: an unused row
    stick_t, stick_delta, stick_dwell  (stick,) float64  s, m, s (dwell inf: a permanent stick)
    stick         a netCDF dimension without a variable: the rows

    The row indices (stick_first, stick_count, stick_point) have no _FillValue (xarray keeps them
    integers, so they index) and valid_min 0: CF readers take -1 as missing. The rows are long-form,
    each point's rows contiguous in a whole file but not in a checkpoint's; not a CF discrete sampling
    geometry (no featureType), whose features need space-time coordinates (CF 9.1) that a grid point
    does not have. :func:`stick_phases` gives the rows of computed points with their coordinates.

    critical curve, k points (attrs param, what, contact_index, message):
    <param>       (k,)  float64    coordinate variable, e.g. v (m s-1)
    kappa         (k,)  float64    the continued kappa_c, kappa_2 or grazing value (long_name says
                                   which), N s m-(1+alpha); NaN where lost
    requested     (k,)  int8       1: asked for, 0: an intermediate step of the continuation
    closed_form, predicted  (k,) float64

    trains of impacts (phaseimpact.train; the case and law are given to save: the results do not carry
    them; attrs period (s) where one period holds for the whole result, also the header's t_end, NaN
    otherwise; settings: the call's other arguments):
    impact-train  arrival (N + 1,) int64 and impact (N,) int64 coordinates (n: the arrival at n period);
                  x2, x2dot, amplitude (arrival) float64 m, m s-1, m: the plate before each arrival (the
                  last: after the last impact); peak_force (N), dissipated_energy (J), restitution (1),
                  energy_in (J) (impact) float64; n_contacts (impact) int64; overlap (impact) int8 flags
                  no yes; status (impact) int8 flags (the statuses)
    orbit-diagram attr param; <param> (n,) float64 coordinate (T: s, kappa, v); x2, x2dot, peak_force
                  (<param>, sample) float64; distinct (<param>,) int64
    map-branch    attrs param, period_k, message; along point (the branch, in the order followed):
                  <param> float64 (not a coordinate: it turns back at a fold), x2, x2dot, stable (int8
                  flags no yes), multiplier_real, multiplier_imag (point, multiplier), contacts (point,
                  structure) int64 (contacts, stick phases, overlaps per period); along bifurcation:
                  bifurcation_kind (int8 flags period-doubling fold neimark-sacker grazing), _value,
                  _x2, _x2dot, _multiplier_real/_imag, _bracket, _test_value, _contacts (bifurcation,
                  side, structure), _turning (int8 flags no yes)
    basins        attrs not_converged, no_map; x2dot (ny,), x2 (nx,) coordinates; labels, impacts (x2dot,
                  x2) int64 (labels: the attractor's index, -1 not converged, -2 a failed run);
                  attractor_period, attractor_count (attractor) int64; attractor_x2, attractor_x2dot
                  (orbit_point) float64: the attractors' points, attractor_period rows each, in order

    runs and transitions (RUN_KINDS; the case and law are the run's, or given to save as a train's):
    trajectory    (a Trajectory; attrs message, law_fault (a run a user law ended), engine: its integrator) t (n,)
                  coordinate (s since the start of the run, cartesian_axis T; empty for a summary run);
                  x1, x2, x1dot, x2dot, contact_work, delta, deltadot, force (t) float64 m, m, m s-1,
                  m s-1, J, m, m s-1, N; mode (t) int64;
                  along event: event_time, event_kind (int8 flags: the event kinds), event_x1 ...
                  event_contact_work, event_force, event_mode; 0-d: status, outcome, stop_reason (int8
                  flags), every summary column (max_force, n_stick, t_run, ...), first_stick_t, final_mode;
                  initial_state, final_state (component,) float64 (attrs components, component_units)
    transitions   (a list of Transition; attrs kappa_min, kappa_max from settings)
                  kappa (n,) float64 coordinate (fractional_units; the transitions in increasing kappa,
                  so ``ds.sel(kappa=..., method="nearest")``); along kappa: kind (int8 flags
                  adding-sliding staircase-end grazing), count_below, count_above, extremum (int64,
                  _FillValue -1: not known)

    Coordinates of a grid (a sweep's or atlas's axes, a curve's or orbit diagram's parameter, basins'
    x2 and x2dot, the transitions' kappa) carry ``cartesian_axis``: X for the last, Y for the one
    before (as xarray plots them), so ``ds.cf.axes`` names them (CF's ``axis`` X and Y would make
    them a longitude and latitude; CF has no standard_name for these parameters). :func:`to_xarray`
    leaves ``_FillValue`` out of the coordinates' encoding, so that ``to_netcdf`` writes a file that
    passes the CF checks too.

    /extras       SweepResult.extras: arrays as datasets, dicts as groups, the rest as JSON in the
                  group's attribute "json" (a group: the xarray root view leaves it out; open it with
                  ``group="extras/boundaries"``). Each array has netCDF dimensions, ``<name>_dim<i>``
                  unless its meaning is known: the refined boundaries of ``atlas --refine``
                  (/extras/boundaries) share ``boundary``; ``points`` (boundary, column) names its
                  columns (the axes) and their units in the attributes columns and column_units;
                  ``below`` and ``above`` are outcome codes (flag_values, flag_meanings).

Units are UDUNITS strings with integer powers (``m s-1``, ``kg m-3``), which cf_units, cfdm and
compliance-checker convert correctly. UDUNITS, and so CF, has no fractional power: it reads
``N s m-2.5`` (kappa of the Hertz laws, alpha = 1.5) as ``0.5 kg m-1 s-1`` and ``N m-1.5`` (K) as
``0.5 kg s-2``, a wrong dimension and a factor 0.5. Such a unit is the attribute
``fractional_units`` (``N s m-2.5``), with no ``units``, a comment saying why, and the unit in the
``long_name`` (``kappa [N s m-2.5]``, xarray's plot label): a CF reader takes the values as pure
numbers, which they are (the numbers of that unit), and no reader converts them wrongly
(:func:`unit_attributes`). CF has no attribute for a log-spaced axis; ``log`` (1 or 0) says it, and
a plot asks for it (``plot(xscale="log")``). A point is computed when its ``status`` is not -1; its
stick phases are rows ``stick_first .. stick_first + stick_count - 1`` (also found through
``stick_point``).

Writing. :func:`save` writes the whole file to a temporary file beside the target, fsyncs it and
renames it over the target, under the path's write lock (:mod:`phaseimpact._atomic`): a reader or a
crash sees the previous file or the complete new one. :class:`Checkpoint` (a sweep's ``on_chunk``)
writes in place instead: the datasets have fixed sizes, uncompressed chunks allocated when the file
is made (C-order slabs of :data:`CHUNK_POINTS` points) and room for more stick phases, so a
checkpoint only overwrites the bytes of the new points and appends their stick phases; no HDF5
metadata changes. It is crash-safe by ordering (each step flushed and fsynced before the next):

0. the data digests (``data_sha256``, below) are marked in progress; points being recomputed (they
   failed before) get status -1 (not computed);
1. the new points' stick phases go to free rows, then their outcome, columns, ``stick_first`` and
   ``stick_count``;
2. their ``status``: the commit;
3. the recomputed points' old stick rows are marked unused; last, the digests of what the file now
   holds (only the pieces written are hashed again).

A kill before step 2 leaves the new points at status -1: not computed, recomputed on resume (their
other variables may hold the interrupted values until then; :func:`load` returns them as not
computed); rows not referenced by a committed point's ``stick_first``/``stick_count`` are ignored by
:func:`load` and reused. A kill during step 2 commits some of the new points, each complete. When the rows run
out (or the file is not an archive of the same grid) a checkpoint rewrites the file atomically as
:func:`save` does, with room for the stick phases still to come. Archives of schema 1
(phaseimpact 0.1), 2 (groups ``/sweep``, ``/curve``), 3 (this layout with ``_FillValue -1`` on the
code variables, which made xarray decode them as floats) and 4 (CF-1.8 with int64 variables, a root
attribute ``dimensions`` that CF 1.9 readers take as a domain variable's, units with fractional
powers, /extras without netCDF dimensions) still load. Train, trajectory and transitions archives are
new kinds of schema 5 (readers of the other kinds are unaffected); :func:`load` gives back a result
equal to the one saved, every array bit for bit.

Integrity. Every chunk of every variable carries a Fletcher-32 checksum (HDF5's filter, which
netCDF-4, h5netcdf and h5py verify on every read); the file format is HDF5 1.8's, whose superblock
and object headers (attributes included) are checksummed; root attribute ``text_sha256`` is the
SHA-256 of the text attributes (HDF5 keeps them in its global heap, without a checksum); the chunk
index (a v1 B-tree, without one) is checked on load. Fletcher-32 passes a chunk whose data and checksum
were both zeroed or filled with 0xFF: root attribute ``data_sha256`` is the SHA-256 of each dataset's
contents (:func:`_dataset_digest`), checked by :func:`load`; a file written before it, killed while a
checkpoint wrote in place, or copied by another netCDF writer (xarray), loads unverified by it.
:func:`load` and :func:`describe` also check the
content (codes within their tables, finite axes, scalar attributes; :func:`load`: a finite
``max_force`` where a run succeeded, counts >= -1 at computed points) and refuse a damaged file with a
:class:`DamagedArchiveError` (a ``ValueError``) that names it and the damage; what a checkpoint
in progress leaves at points not yet committed and in unused stick rows is not damage.
"""

from __future__ import annotations

import contextlib
import datetime
import hashlib
import io
import itertools
import json
import math
import os
import re
import stat
import time
from dataclasses import dataclass

import h5py
import numpy as np

from ._atomic import atomic_path, exclusive, fsync_file, release_reserve, reserve
from ._version import __version__
from .continuation import CriticalCurve, SweepResult, Transition
from .continuation.grid import Axis, Grid
from .continuation.sweep import ENGINE as _ENGINE
from .integrate import OUTCOMES, STATUSES
from .integrate import driver as _driver
from .integrate.events import EVENT_KINDS
from .integrate.result import SUMMARY_COLUMNS, Trajectory
from .model import ContactLaw
from .parameters import Parameters
from .train import (
    BIFURCATION_KINDS,
    NO_MAP,
    NOT_CONVERGED,
    Attractor,
    Basins,
    ImpactTrain,
    MapBifurcation,
    MapBranch,
    OrbitDiagram,
)

__all__ = ["SCHEMA_VERSION", "KINDS", "TRAIN_KINDS", "RUN_KINDS", "TRANSITION_KINDS",
           "CHUNK_POINTS", "Checkpoint", "save", "load", "describe", "same_work",
           "check_overwrite", "kind_of", "created_timestamp", "DamagedArchiveError", "to_xarray", "stick_phases",
           "unit_attributes"]

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
#: :func:`_check_storage`) and the global heap of variable-length strings (:data:`_TEXT_DIGEST`).
_LIBVER = ("v108", "v108")
#: Root attribute: SHA-256 of the file's text attributes, which HDF5 keeps in its global heap (no
#: checksum there: a changed digit of the case JSON would load silently).
_TEXT_DIGEST = "text_sha256"
#: Root attribute: the SHA-256 of each dataset's contents (:func:`_dataset_digest`), JSON ``{path: hex}`` in a
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
    from .case import Case

    if isinstance(base, Case):
        return {"base": "case", "parameters": _json(base.parameters().as_dict()), "case": _json(base.as_dict())}
    if isinstance(base, Parameters):
        params = _json(base.as_dict())
        return {"base": "parameters", "parameters": params, "case": params}
    raise TypeError(f"cannot archive a base of type {type(base).__name__}")


def _base_parameters(base) -> Parameters:
    return base if isinstance(base, Parameters) else base.parameters()


def kind_of(result) -> str:
    """The archive kind of a result (or of a :class:`Grid`): ``sweep`` (one axis), ``atlas`` (two or
    more) or ``critical-curve``.

    Parameters
    ----------
    result : SweepResult, Grid, CriticalCurve, Trajectory, list of Transition, ImpactTrain, OrbitDiagram, \
MapBranch or Basins
        What would be archived.

    Returns
    -------
    str
        One of :data:`KINDS`, :data:`RUN_KINDS` or :data:`TRAIN_KINDS`.

    Raises
    ------
    TypeError
        For anything else.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import kind_of
    >>> from phaseimpact.continuation import atlas, sweep
    >>> kind_of(sweep(seed_parameters(), "paper", [1e9, 1e13]))
    'sweep'
    >>> kind_of(atlas(seed_parameters(), "paper", {"kappa": [1e9, 1e13], "v": [1.0, 2.0]}).grid)
    'atlas'
    """
    if isinstance(result, CriticalCurve):
        return "critical-curve"
    if isinstance(result, Trajectory):
        return "trajectory"
    if _transitions_of(result):
        return "transitions"
    if type(result) in _TRAIN_KIND:
        return _TRAIN_KIND[type(result)]
    grid = result.grid if isinstance(result, SweepResult) else result
    if not isinstance(grid, Grid):
        raise TypeError(f"cannot archive a {type(result).__name__}")
    return "sweep" if len(grid.axes) == 1 else "atlas"


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
        from .model.laws import as_law

        return _udunits(as_law(law).entry.damping_udunits(alpha))  # a user law's own unit may read N s/m^1.5
    return f"N s m-{_g(1 + alpha)}"


def axis_units(name: str, alpha: float, law=None) -> str:
    """Units of a grid axis or curve parameter in UDUNITS syntax (``alpha``: the base case's
    exponent; ``law``: whose entry gives the damping's unit); see :func:`unit_attributes`."""
    from .case import SETTABLE

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


def _fixed(group, name, data, dtype, chunks, *, fill=None, fill_attr=True, units=None, dims=(), rows=None):
    """A dataset of fixed size whose chunks are allocated when it is made (writing into it later never
    changes the file's metadata), holding ``data``; with ``rows`` (1-d), ``rows`` long, ``data`` first
    and the fill value after it (spare rows, written without a padded copy of ``data``)."""
    dtype = np.dtype(dtype)
    fill = _fill_of(dtype) if fill is None else dtype.type(fill)
    shape = np.shape(data) if rows is None else (rows,)
    if 0 in shape:
        d = group.create_dataset(name, shape=shape, dtype=dtype, fillvalue=fill)
    else:
        _reserve(group.file, _storage_bytes(shape, chunks, dtype.itemsize))
        dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
        dcpl.set_alloc_time(h5py.h5d.ALLOC_TIME_EARLY)
        # every element is written just below: HDF5 need not write the fill value first
        d = group.create_dataset(name, shape=shape, dtype=dtype, chunks=chunks, fillvalue=fill, fill_time="never",
                                 dcpl=dcpl, **_CHECKED)
        if rows is None:
            d[...] = data
        else:
            n = len(data)
            if n:
                d[:n] = data
            for start in range(n, rows, chunks[0]):  # the spare rows, a chunk at a time
                d[start:min(start + chunks[0], rows)] = np.full(min(chunks[0], rows - start), fill, dtype=dtype)
    if fill_attr:
        d.attrs["_FillValue"] = fill
    if units is not None:
        d.attrs["units"] = units
    if name in _LONG_NAMES:
        d.attrs["long_name"] = _LONG_NAMES[name]
    for i, scale in enumerate(dims):
        d.dims[i].attach_scale(scale)
    return d


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


def _boxes(lo: int, hi: int, shape) -> list:
    """The flat (C order) range ``[lo, hi)`` of a grid as at most ``2 d - 1`` boxes (tuples of slices)."""
    if lo >= hi:
        return []
    if len(shape) == 1:
        return [(slice(lo, hi),)]
    inner = int(np.prod(shape[1:]))
    i0, r0 = divmod(lo, inner)
    i1, r1 = divmod(hi, inner)
    if i0 == i1:
        return [(slice(i0, i0 + 1), *b) for b in _boxes(r0, r1, shape[1:])]
    out = []
    if r0:
        out += [(slice(i0, i0 + 1), *b) for b in _boxes(r0, inner, shape[1:])]
        i0 += 1
    if i1 > i0:
        out.append((slice(i0, i1), *(slice(0, n) for n in shape[1:])))
    if r1:
        out += [(slice(i1, i1 + 1), *b) for b in _boxes(0, r1, shape[1:])]
    return out


def _aligned_boxes(lo: int, hi: int, shape) -> list:
    """Boxes that cover ``[lo, hi)``, widened to whole rows of the leading axes when that costs at most
    ``max(hi - lo, CHUNK_POINTS)`` more points: fewer, larger writes (the points added are written
    with the values they already have)."""
    allowance = max(hi - lo, CHUNK_POINTS)
    for k in range(1, len(shape)):
        unit = int(np.prod(shape[k:]))
        a, b = (lo // unit) * unit, -(-hi // unit) * unit
        if (b - a) - (hi - lo) <= allowance:
            return [(*box, *(slice(0, n) for n in shape[k:])) for box in _boxes(a // unit, b // unit, shape[:k])]
    return _boxes(lo, hi, shape)


#: Gaps of at most this many points between new points are written over (their bytes are the same).
_GAP = 512
_MAX_RUNS = 64


def _runs(indices: np.ndarray) -> list[tuple[int, int]]:
    """Sorted flat indices as ``[lo, hi)`` runs; short gaps are bridged and many runs become one."""
    if indices.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(indices) > _GAP + 1)
    starts = np.concatenate([[0], breaks + 1])
    stops = np.concatenate([breaks, [indices.size - 1]])
    runs = [(int(indices[a]), int(indices[b]) + 1) for a, b in zip(starts, stops, strict=True)]
    if len(runs) > _MAX_RUNS:
        runs = [(runs[0][0], runs[-1][1])]
    return runs


def _stamp(path):
    st = os.stat(path)
    return st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns


def _digest(tree) -> str:
    """A fingerprint of ``SweepResult.extras`` (a checkpoint rewrites the file when they change)."""
    h = hashlib.sha256()

    def walk(obj, key):
        h.update(key.encode())
        if isinstance(obj, dict):
            for k in sorted(obj, key=str):
                walk(obj[k], f"{key}/{k}")
        elif isinstance(obj, np.ndarray):
            h.update(f"{obj.dtype.str}{obj.shape}".encode())
            h.update(np.ascontiguousarray(obj).tobytes())
        else:
            h.update(_json(obj).encode())

    walk(tree, "")
    return h.hexdigest()


# ------------------------------------------------------------------------------------------------
# Writing whole files
# ------------------------------------------------------------------------------------------------

def save(result, path, *, force: bool = False, params=None, law=None, settings: dict | None = None) -> str:
    """Write ``result`` to ``path`` atomically (temporary file, fsync, rename) under its write lock.

    The layout is the module docstring's (netCDF-4 / CF-1.11, schema :data:`SCHEMA_VERSION`); a
    reader or a crash sees the previous file or the complete new one.

    Parameters
    ----------
    result : SweepResult, CriticalCurve, Trajectory, list of Transition, ImpactTrain, OrbitDiagram, \
MapBranch or Basins
        A sweep, an atlas (complete or partial), a continued curve, a run of
        :func:`~phaseimpact.simulate`, what :func:`~phaseimpact.continuation.transitions` returns, or a
        result of :mod:`phaseimpact.train`.
    path : str or path-like
        The archive to write (conventionally ``.nc``: netCDF-4).
    force : bool, default False
        Replace ``path`` even if it exists and is not a phaseimpact archive. Without it such a file
        is refused (``ValueError``); an existing archive is replaced. (The command line also refuses
        an archive of other work: see :func:`check_overwrite`.)
    params : Parameters or Case, optional
        The case of a result that does not carry it (transitions, a train result: required), or the
        Case a trajectory was run from (optional; its parameters must be the run's). Refused for
        a sweep or curve.
    law : ContactLaw or str, optional
        The law of transitions or a train result (required for them, refused for the others).
    settings : dict, optional
        The call's other arguments (transitions, a train result, a trajectory), stored as the JSON
        attribute ``settings``: ``rtol`` (the header's ``rtol``), ``period`` (s: an orbit diagram's or
        branch's over ``kappa`` or ``v``), ``kappa_min``, ``kappa_max`` (transitions), ...

    Returns
    -------
    str
        ``path``.

    Raises
    ------
    TypeError
        If ``result`` is of another type, or ``params``/``law`` are missing for a train result (or
        given for a sweep or curve).
    ValueError
        (Before writing anything) for a path that cannot be written or an existing file that is not
        an archive (without ``force``), and :class:`phaseimpact._atomic.PathLockedError` (a
        ``ValueError``) if another process is writing ``path``.
    OSError
        For a full disk or a failing write (the previous file is kept).

    Examples
    --------
    >>> import os, tempfile
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import load, save
    >>> from phaseimpact.continuation import sweep
    >>> path = os.path.join(tempfile.mkdtemp(), "sweep.nc")
    >>> save(sweep(seed_parameters(), "paper", [1e9, 1e12, 1e13]), path) == path
    True
    >>> load(path).outcome_names().tolist()
    ['permanent-stick', 'permanent-stick', 'ratchet-escape']

    A train of impacts, with the case and law it was computed with:

    >>> from phaseimpact.train import impact_train
    >>> p = seed_parameters(kappa=3e9)
    >>> train = impact_train(p, "hunt-crossley", 3e-3, 3)
    >>> back = load(save(train, os.path.join(tempfile.mkdtemp(), "train.nc"), params=p, law="hunt-crossley"))
    >>> bool((back.peak_force == train.peak_force).all()), back.status
    (True, ['success', 'success', 'success'])
    """
    if not (isinstance(result, _ARCHIVED) or _transitions_of(result)):
        raise TypeError(f"cannot archive a {type(result).__name__}; allowed: a SweepResult or a CriticalCurve, a "
                        "Trajectory, a list of Transition, or an ImpactTrain, OrbitDiagram, MapBranch or Basins")
    context = _context(result, params, law, settings, required=True)
    _write_file(result, os.fspath(path), force=force, spare_rows=0, context=context)
    return os.fspath(path)


#: Disk space reserved beyond a dataset's data while an archive is written (object headers,
#: attributes, the metadata HDF5 writes when the file closes), bytes.
_RESERVE_MARGIN = 1 << 18


def _storage_bytes(shape, chunks, itemsize: int) -> int:
    """Bytes a dataset's allocated chunks (or its contiguous data) take on disk, checksums included."""
    if not chunks:
        return int(np.prod(shape)) * itemsize
    n_chunks = int(np.prod([-(-n // c) for n, c in zip(shape, chunks, strict=True)]))
    return n_chunks * (int(np.prod(chunks)) * itemsize + 4)


def _reserve(f, nbytes: int) -> None:
    """Reserve the disk blocks for the next ``nbytes`` of the archive ``f`` being written.

    HDF5 must never meet a full disk: a failed write leaves objects it can no longer close (their
    finalizers print a traceback each) and the interpreter's exit then crashes inside HDF5 (a
    segfault). Reserved first, a full disk is an ``OSError`` here, before HDF5 writes (and the file is
    discarded: :func:`_write_file`). An archive built in memory (:func:`to_xarray`) has no disk to
    reserve."""
    if f.driver == "fileobj":
        return
    fd = f.id.get_vfd_handle()
    reserve(fd, max(int(f.id.get_filesize()), os.fstat(fd).st_size) + nbytes + _RESERVE_MARGIN)


def _as_disk_error(error: Exception) -> OSError | None:
    """HDF5's report of a failed write (h5py raises it as ValueError or RuntimeError) as an OSError."""
    found = re.search(r"errno = (\d+)", str(error))
    if found is None or "write failed" not in str(error):
        return None
    code = int(found.group(1))
    return OSError(code, os.strerror(code))


def _write_file(result, path: str, *, force: bool, spare_rows: int, context=None):
    """Write a whole archive atomically; a sweep's stick variables get ``spare_rows`` free rows.
    Returns the sweep's per-point ``(stick_first, stick_count, piece digests)`` (None for another kind)."""
    created = created_timestamp()  # a bad SOURCE_DATE_EPOCH is refused before anything is written
    layout = _sweep_layout(result) if isinstance(result, SweepResult) else None
    with atomic_path(path, "path") as tmp:
        if not force and os.path.isfile(path) and not _is_archive(path):
            raise ValueError(f"path = {path!r} exists and is not a phaseimpact archive; refusing to replace it "
                             "(force=True replaces it)")
        try:
            with h5py.File(tmp, "w", libver=_LIBVER) as f:
                fd = f.id.get_vfd_handle()
                try:
                    _reserve(f, 0)  # the header, attributes and small datasets
                    pieces = _write_result(f, result, created, layout, spare_rows, context)
                    _reserve(f, 0)  # what the close writes
                except BaseException:
                    # The close writes what HDF5 still holds (chunks, object headers) at addresses it chose,
                    # which a failed reservation may have given back (tmpfs returns every unwritten block of
                    # the range asked for): that write fails on a full disk and leaves HDF5 objects it cannot
                    # close (a segfault at exit). The file is discarded: give its blocks back, so that the
                    # close finds room.
                    with contextlib.suppress(OSError):
                        os.ftruncate(fd, 0)
                    raise
        except (ValueError, RuntimeError) as error:
            disk = _as_disk_error(error)
            if disk is None:
                raise
            raise disk from None  # atomic_path names the path
        release_reserve(tmp)
    return None if layout is None else (layout.first, layout.count, pieces)


def _write_result(f, result, created: str, layout, spare_rows: int, context=None) -> dict:
    """Write ``result`` into the open file ``f``; return its datasets' piece digests (:func:`_file_pieces`)."""
    if isinstance(result, SweepResult):
        _write_sweep(f, result, created, layout, spare_rows)
    elif isinstance(result, CriticalCurve):
        _write_curve(f, result, created)
    elif _transitions_of(result):
        _write_transitions(f, result, created, context)
    else:
        _WRITERS[type(result)](f, result, created, context)
    pieces = _file_pieces(f)  # read back: the digests are of what the file holds
    f.attrs[_DATA_DIGEST] = np.bytes_(_digests_text(pieces).encode("ascii"))
    f.attrs[_TEXT_DIGEST] = _texts_digest(f)
    return pieces


#: How to install what to_xarray and stick_phases need (the package is installed from a checkout or a wheel).
_XARRAY_EXTRA = ("install the extra phaseimpact[xarray] (in a checkout: pip install -e '.[xarray]'; with a wheel: "
                 "pip install 'phaseimpact-VERSION-py3-none-any.whl[xarray]'), or pip install xarray h5netcdf")


def to_xarray(result, *, params=None, law=None, settings: dict | None = None):
    """``result`` as an in-memory :class:`xarray.Dataset`, no file written.

    The Dataset is the one ``xarray.open_dataset`` gives of the archive :func:`save` writes (it is
    that archive, built in memory), variables, dimensions, units and attributes alike, so code
    written for one reads the other; the module docstring gives every layout. Needs xarray and
    h5netcdf (the extra ``phaseimpact[xarray]``).

    Parameters
    ----------
    result : SweepResult, CriticalCurve, Trajectory, list of Transition, ImpactTrain, OrbitDiagram, \
MapBranch or Basins
        A sweep or atlas, a continued curve, a run of :func:`~phaseimpact.simulate` (with samples
        or a summary run), what :func:`~phaseimpact.continuation.transitions` returns, or a result of
        :mod:`phaseimpact.train`.
    params : Parameters or Case, optional
        The case of a result that does not carry it (transitions, train results): its header
        attributes (``parameters``, ``case``, ``base``) and the unit of ``kappa`` (its ``alpha``).
        Left out, so are they. A trajectory's Case (its parameters must be the run's); refused for
        a sweep or curve.
    law : ContactLaw or str, optional
        Its law, likewise (``law``, ``contact``; the unit of ``kappa``).
    settings : dict, optional
        Its other arguments, the JSON attribute ``settings``: ``rtol`` (the header's), ``period``
        (s), ``kappa_min`` and ``kappa_max`` (transitions: the search interval, also attributes of
        their own).

    Returns
    -------
    xarray.Dataset
        Loaded in memory.

    Raises
    ------
    TypeError
        For a result of another type (the message lists the allowed ones), or ``params``, ``law``
        or ``settings`` given for a result that carries its own.
    ImportError
        When xarray or h5netcdf is not installed (the message names the extra).

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate
    >>> from phaseimpact.archive import to_xarray
    >>> from phaseimpact.continuation import sweep
    >>> ds = to_xarray(sweep(seed_parameters(), "paper", [1e9, 1e12, 1e13]))
    >>> dict(ds.sizes), ds["max_force"].attrs["units"], ds["kappa"].attrs["fractional_units"]
    ({'kappa': 3, 'stick': 4}, 'N', 'N s m-2.5')

    A trajectory: its samples along ``time``, its events along ``event``, its summary as scalars.

    >>> run = to_xarray(simulate(seed_parameters(v=1.0, kappa=3e9), "paper", save="steps"))
    >>> run.force.attrs["units"], run.sizes["event"], run.outcome.attrs["flag_meanings"].split()[int(run.outcome)]
    ('N', 3, 'permanent-stick')

    A train of impacts, with its case and law:

    >>> from phaseimpact.train import impact_train
    >>> p = seed_parameters(kappa=3e9)
    >>> train = to_xarray(impact_train(p, "hunt-crossley", 3e-3, 3), params=p, law="hunt-crossley")
    >>> dict(train.sizes), train.peak_force.attrs["units"], train.attrs["kind"]
    ({'arrival': 4, 'impact': 3}, 'N', 'impact-train')
    """
    if not (isinstance(result, _ARCHIVED) or _transitions_of(result)):
        raise TypeError(f"cannot convert a {type(result).__name__}; allowed: a SweepResult or a CriticalCurve, a "
                        "Trajectory, a list of Transition, or an ImpactTrain, OrbitDiagram, MapBranch or Basins")
    context = _context(result, params, law, settings, required=False)
    try:
        import h5netcdf  # noqa: F401  (xarray's engine for the in-memory file)
        import xarray
    except ImportError as error:
        raise ImportError(f"to_xarray needs xarray and h5netcdf ({error}): {_XARRAY_EXTRA}") from None
    buffer = io.BytesIO()
    with h5py.File(buffer, "w", libver=_LIBVER) as f:
        _write_result(f, result, created_timestamp(),
                      _sweep_layout(result) if isinstance(result, SweepResult) else None, 0, context)
    buffer.seek(0)
    with xarray.open_dataset(buffer, engine="h5netcdf") as ds:
        ds = ds.load()
    for name in ds.coords:  # else to_netcdf gives a float coordinate _FillValue NaN, which CF forbids
        ds[name].encoding["_FillValue"] = None
    return ds


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


def _texts_digest(f) -> str:
    """SHA-256 of the text attributes :func:`load` reads: the root's (but the digests') and those of
    ``/extras`` (object path, name, value)."""
    h = hashlib.sha256()

    def add(name, node):
        # not netCDF's reserved attributes (_NCProperties): the library's; not the data digests, which a
        # checkpoint rewrites in place (they protect themselves: a changed one matches no data)
        for key in sorted(node.attrs):
            value = node.attrs[key] if key not in (_TEXT_DIGEST, _DATA_DIGEST) and not key.startswith("_") else None
            if isinstance(value, bytes):  # netCDF4 (xarray's re-save) writes texts as fixed-length bytes
                value = value.decode("utf-8", "replace")
            if isinstance(value, str):
                h.update(json.dumps([name, key, value]).encode())

    add("/", f)
    if "extras" in f:
        add("extras", f["extras"])
        f["extras"].visititems(add)
    return h.hexdigest()


def _piece_digests(data: np.ndarray) -> list:
    """SHA-256 of each :data:`_DIGEST_PIECE` elements of ``data`` in C order (its bytes as stored)."""
    flat = np.ascontiguousarray(data).reshape(-1)
    if flat.dtype.kind not in "biufc":  # text: its characters, not the addresses of Python objects
        flat = np.array([_json(x.decode() if isinstance(x, bytes) else x) for x in flat.tolist()], dtype=str)
    else:  # the values, whatever the byte order a writer chose (xarray's copy may store big-endian)
        flat = flat.astype(flat.dtype.newbyteorder("<"), copy=False)
    return [hashlib.sha256(flat[i:i + _DIGEST_PIECE].tobytes()).digest()
            for i in range(0, max(flat.size, 1), _DIGEST_PIECE)]


def _little_endian(dtype) -> np.dtype:
    dtype = np.dtype(dtype)
    return dtype.newbyteorder("<") if dtype.kind in "biufc" else dtype


def _dataset_digest(dtype, shape, pieces) -> str:
    """A dataset's digest: of its type, shape and the digests of its pieces; whatever its chunks or filters."""
    h = hashlib.sha256(_json([_little_endian(dtype).str, list(shape)]).encode())
    for piece in pieces:
        h.update(piece)
    return h.hexdigest()


def _file_pieces(f) -> dict:
    """``{path: (dtype, shape, piece digests)}`` of every dataset of the open file ``f`` (each is read whole)."""
    found = {}

    def visit(name, node):
        if isinstance(node, h5py.Dataset):
            found[name] = (node.dtype, node.shape, _piece_digests(node[()]))

    f.visititems(visit)
    return found


def _digests_text(pieces: dict) -> str:
    digests = {name: _dataset_digest(*entry) for name, entry in pieces.items()}
    return json.dumps(digests, sort_keys=True, separators=(",", ":")).ljust(len(_IN_PROGRESS))


def _stored_digests(f) -> dict | None:
    """The digests :data:`_DATA_DIGEST` holds; None where the file has none to check against (written before
    data digests, or killed while a checkpoint wrote in place)."""
    if _DATA_DIGEST not in f.attrs:
        return None
    value = f.attrs[_DATA_DIGEST]
    try:
        stored = json.loads(value.decode("ascii") if isinstance(value, bytes) else value)
    except (TypeError, ValueError, AttributeError):
        stored = None
    if stored == json.loads(_IN_PROGRESS):
        return None
    if not (isinstance(stored, dict) and all(isinstance(v, str) for v in stored.values())):
        raise _Damaged(f"attribute {_DATA_DIGEST} = {_short(value)} is out of range; allowed: the SHA-256 digests "
                       "of the datasets")
    return stored


def _check_data_digests(f) -> None:
    """Every dataset's contents against :data:`_DATA_DIGEST`, where the file has it. Not in a copy that
    another netCDF writer made (xarray's ``to_netcdf``): it carries the attribute over, but a subset or a
    re-encoding is not the data it was computed from; such a copy is checked by its content alone."""
    stored = _stored_digests(f)
    if stored is None or _netcdf_writer(f) is not None:
        return
    pieces = _file_pieces(f)
    for name in sorted(set(stored) | set(pieces)):
        if name not in pieces:
            raise _Damaged(f"variable {name} is missing")
        if name not in stored:
            raise _Damaged(f"variable {name} has no SHA-256 digest in {_DATA_DIGEST} (it was added after the file "
                           "was written)")
        if stored[name] != _dataset_digest(*pieces[name]):
            # checksum: a reader may catch a checkpoint writing in place; read again, as for Fletcher-32
            raise _Damaged(f"variable {name}: its contents do not match their SHA-256 digest {_DATA_DIGEST} (the "
                           "file's bytes were changed after it was written)", checksum=True)


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


def _write_sweep(f, r: SweepResult, created: str, layout: _Layout, spare_rows: int) -> None:
    grid = r.grid
    shape = grid.shape
    alpha = _base_parameters(grid.base).alpha
    kind = kind_of(r)
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


# ------------------------------------------------------------------------------------------------
# Trains of impacts, trajectories and transitions
# ------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class _Context:
    """What a result that does not carry it was computed with: the case (Parameters or Case), the law
    and the call's other settings (``rtol``, ``period``, ``kappa_min``, ...); any of them None."""

    base: object = None
    law: ContactLaw | None = None
    settings: dict | None = None


def _transitions_of(result) -> bool:
    """``result`` is what :func:`~phaseimpact.continuation.transitions` returns: a list of Transition."""
    return isinstance(result, (list, tuple)) and all(isinstance(item, Transition) for item in result)


def _context(result, params, law, settings, *, required: bool) -> _Context:
    """The context of a result that does not carry its case (``required``: an archive needs its case and
    law); a result that carries them (a sweep, a curve) takes none, a trajectory its Case and settings only."""
    from .case import Case
    from .model import as_law

    given = params is not None or law is not None or settings is not None
    if isinstance(result, (SweepResult, CriticalCurve)):
        if given:
            raise TypeError(f"a {type(result).__name__} carries its own case, law and settings; params=, law= and "
                            "settings= are for results that do not (transitions, trains of impacts)")
        return _Context()
    if params is not None and not isinstance(params, (Parameters, Case)):
        raise TypeError(f"params has the wrong type ({type(params).__name__}); allowed: Parameters or Case")
    if settings is not None and not isinstance(settings, dict):
        raise TypeError(f"settings has the wrong type ({type(settings).__name__}); allowed: a dict")
    if isinstance(result, Trajectory):  # it carries its parameters and law; a Case names where they came from
        if law is not None:
            raise TypeError("a Trajectory carries its own law; law= is for results that do not (transitions, trains "
                            "of impacts)")
        if params is not None and _base_parameters(params) != result.params:
            raise ValueError("params is not the trajectory's case: its parameters differ from the run's; allowed: "
                             "the Case the run was made from")
        return _Context(params, None, None if settings is None else dict(settings))
    if required and (params is None or law is None):
        raise TypeError(f"archiving a {type(result).__name__} needs params= and law= (it does not carry the case "
                        "and law it was computed with)")
    return _Context(params, None if law is None else as_law(law), None if settings is None else dict(settings))


def _period_of(result, context: _Context) -> float:
    """The time between arrivals (s) when one holds for the whole result; NaN when it varies (over T) or
    was not given."""
    if isinstance(result, (ImpactTrain, Basins)):
        return float(result.period)
    if getattr(result, "param", None) == "T":
        return math.nan
    return _float((context.settings or {}).get("period"))


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


def _train_header(f, kind: str, context: _Context, period: float, created: str, title: str) -> None:
    settings = context.settings or {}
    _header(f, kind, context.law, context.base, period, settings.get("rtol"), str(settings.get("engine", "")),
            created, title, context.settings)
    if not math.isnan(period):
        f.attrs["period"] = period


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


#: The kinds of :class:`~phaseimpact.continuation.Transition`.
TRANSITION_KINDS = ("adding-sliding", "staircase-end", "grazing")
#: The state's components, as a Trajectory's ``y`` holds them: (netCDF name, unit, long name).
_STATE = (("x1", "m", "projectile displacement"), ("x2", "m", "target displacement"),
          ("x1dot", "m s-1", "projectile velocity"), ("x2dot", "m s-1", "target velocity"),
          ("contact_work", "J", "work of the contact force"))
_YES_NO = ("no", "yes")


def _write_trajectory(f, tr: Trajectory, created: str, context: _Context) -> None:
    settings = context.settings or {}
    found = re.search(r"rtol=([^,\]]+)", tr.integrator)  # the integrator's name rounds it: settings' is exact
    rtol = settings.get("rtol", float(found.group(1)) if found else None)
    _header(f, "trajectory", tr.law, tr.params if context.base is None else context.base, tr.t_end, rtol,
            tr.integrator, created, f"phaseimpact trajectory: {tr.law.name} law, {tr.outcome} ({tr.status})",
            context.settings)
    f.attrs["message"] = tr.message
    if tr.law_fault:  # the message of a run a user law ended is made from it
        f.attrs["law_fault"] = tr.law_fault
    # t, not time: CF's time coordinate (the name time, standard_name time or axis T) needs units "s since
    # <a date>", which xarray decodes to datetime64 (whole nanoseconds; the run's clock starts at 0)
    _coordinate(f, "t", tr.t, "s", "time since the start of the run").attrs["cartesian_axis"] = "T"
    for i, (name, units, long_name) in enumerate(_STATE):
        _variable(f, name, tr.y[:, i], ("t",), long_name=long_name, units=units)
    _variable(f, "delta", tr.delta, ("t",), long_name="indentation x1 - x2", units="m")
    _variable(f, "deltadot", tr.deltadot, ("t",), long_name="relative velocity x1dot - x2dot", units="m s-1")
    _variable(f, "force", tr.force, ("t",), long_name="contact force", units="N")
    _variable(f, "mode", tr.mode, ("t",), long_name="mode (paper: +-1 slipping, 0 stuck)")

    _variable(f, "event_time", tr.event_t, ("event",), long_name="time of the event", units="s")
    _variable(f, "event_kind", tr.event_kind, ("event",), long_name="kind of the event", flags=EVENT_KINDS,
              dtype=np.int8)
    for i, (name, units, long_name) in enumerate(_STATE):
        _variable(f, f"event_{name}", tr.event_y[:, i], ("event",), long_name=f"{long_name} at the event",
                  units=units)
    _variable(f, "event_force", tr.event_force, ("event",), long_name="contact force at the event", units="N")
    _variable(f, "event_mode", tr.event_mode, ("event",), long_name="mode after the event")

    for name, codes, table in (("status", tr.status, STATUSES), ("outcome", tr.outcome, OUTCOMES),
                               ("stop_reason", tr.stop_reason, STOP_REASONS)):
        _variable(f, name, _codes_of([codes], table, name)[0], long_name=_LONG_NAMES[name], flags=table)
    for name, index, dtype, units in SUMMARY_COLUMNS:
        value = np.asarray(tr.summary[index]).astype(dtype)
        _variable(f, name, value, long_name=_LONG_NAMES[name], units=units, fill=value.dtype.kind == "f")
    _variable(f, "first_stick_t", np.float64(tr.summary[_driver.S_FIRST_STICK_T]),
              long_name="time the first stick phase began", units="s", fill=True)
    _variable(f, "final_mode", np.int64(tr.final_mode), long_name="mode at the end of the run")
    components = {"components": " ".join(name for name, _, _ in _STATE),
                  "component_units": _json([units for _, units, _ in _STATE]),
                  "comment": "no units attribute: the components differ in unit (component_units)"}
    _variable(f, "initial_state", tr.initial_state, ("component",), long_name="state at the start", **components)
    _variable(f, "final_state", tr.final_state, ("component",), long_name="state at the end", **components)


def _write_transitions(f, items, created: str, context: _Context) -> None:
    settings = context.settings or {}
    _header(f, "transitions", context.law, context.base, None, settings.get("rtol"), "", created,
            f"phaseimpact transitions: {len(items)} changes of the long-time count over kappa{_by(context)}",
            context.settings)
    for key in ("kappa_min", "kappa_max"):
        if key in settings:
            f.attrs[key] = float(settings[key])
    units = _parameter_units("kappa", context)
    items = sorted(items, key=lambda t: t.kappa)  # the coordinate kappa increases (CF; .sel(kappa=...))

    def count(name):  # None (not confirmed, unbounded) is -1, read by xarray as NaN
        return np.array([-1 if getattr(t, name) is None else getattr(t, name) for t in items], dtype=np.int64)

    _grid_axes([_coordinate(f, "kappa", np.array([t.kappa for t in items], dtype=float), units,
                            "kappa at the transition")])
    _variable(f, "kind", _codes_of([t.kind for t in items], TRANSITION_KINDS, "kind"), ("kappa",),
              long_name="kind of the transition", flags=TRANSITION_KINDS)
    for name, long_name in (("count_below", "long-time count just below"),
                            ("count_above", "long-time count just above"),
                            ("extremum", "grazing: the extremum of delta that touches zero")):
        _variable(f, name, count(name), ("kappa",), long_name=long_name, units="1", fill=True)


def _write_impact_train(f, r: ImpactTrain, created: str, context: _Context) -> None:
    n = len(r.peak_force)
    _train_header(f, "impact-train", context, float(r.period), created,
                  f"phaseimpact impact train: {n} impacts every {r.period:g} s{_by(context)}")
    _coordinate(f, "arrival", np.arange(n + 1, dtype=np.int64), None,
                "arrival n, at n period (the last: after the last impact)")
    _coordinate(f, "impact", np.arange(n, dtype=np.int64), None, "impact n, at n period")
    plate = np.asarray(r.plate, dtype=float)
    _variable(f, "x2", plate[:, 0], ("arrival",), long_name="plate displacement just before the arrival", units="m")
    _variable(f, "x2dot", plate[:, 1], ("arrival",), long_name="plate velocity just before the arrival",
              units="m s-1")
    _variable(f, "amplitude", r.amplitude, ("arrival",), long_name="plate amplitude before the arrival", units="m",
              dtype=float)
    for name, units, long_name in (("peak_force", "N", "largest contact force of the impact"),
                                   ("dissipated_energy", "J", "energy the impact's contact dissipated"),
                                   ("restitution", "1", "coefficient of restitution (NaN: no separation)"),
                                   ("energy_in", "J", "kinetic energy the projectile left in the plate and contact")):
        _variable(f, name, getattr(r, name), ("impact",), long_name=long_name, units=units, dtype=float, fill=True)
    _variable(f, "n_contacts", r.n_contacts, ("impact",), long_name="contacts of the impact", units="1",
              dtype=np.int64)
    _variable(f, "overlap", r.overlap, ("impact",), long_name="projectile still in contact at the next arrival",
              flags=_YES_NO, dtype=np.int8)
    _variable(f, "status", _codes_of(r.status, STATUSES, "status"), ("impact",), long_name=_LONG_NAMES["status"],
              flags=STATUSES)


def _write_orbit_diagram(f, r: OrbitDiagram, created: str, context: _Context) -> None:
    dim = netcdf_name(r.param)
    values = np.asarray(r.values, dtype=float)
    _train_header(f, "orbit-diagram", context, _period_of(r, context), created,
                  f"phaseimpact orbit diagram: {r.plate.shape[1]} samples at {len(values)} values of {r.param}"
                  f"{_by(context)}")
    f.attrs["param"] = r.param
    _grid_axes([_coordinate(f, dim, values, _parameter_units(r.param, context), r.param)])
    dims = (dim, "sample")
    _variable(f, "x2", r.plate[..., 0], dims, long_name="plate displacement just before the sampled impact",
              units="m", dtype=float)
    _variable(f, "x2dot", r.plate[..., 1], dims, long_name="plate velocity just before the sampled impact",
              units="m s-1", dtype=float)
    _variable(f, "peak_force", r.peak_force, dims, long_name="largest contact force of the sampled impact",
              units="N", dtype=float, fill=True)
    _variable(f, "distinct", r.distinct, (dim,), long_name="distinct states among the samples", units="1",
              dtype=np.int64)


def _multipliers(f, prefix: str, values, dims) -> None:
    values = np.asarray(values, dtype=complex)
    for part, name in (("real", values.real), ("imag", values.imag)):
        _variable(f, f"{prefix}multiplier_{part}", np.ascontiguousarray(name), dims,
                  long_name=f"Floquet multipliers, {'real' if part == 'real' else 'imaginary'} part", units="1")


_STRUCTURE = {"structure": "contacts stick_phases overlaps",
              "comment": "per period of the orbit: contacts, stick phases, projectiles still in contact at the "
                         "next arrival"}


def _write_map_branch(f, r: MapBranch, created: str, context: _Context) -> None:
    units = _parameter_units(r.param, context)
    name = netcdf_name(r.param)
    _train_header(f, "map-branch", context, _period_of(r, context), created,
                  f"phaseimpact map branch: period-{r.period_k} orbits over {r.param}, {len(r.values)} points, "
                  f"{len(r.points)} bifurcations{_by(context)}")
    f.attrs["param"] = r.param
    f.attrs["period_k"] = np.int64(r.period_k)
    f.attrs["message"] = str(r.message)
    # the parameter is no coordinate variable: it turns back at a fold (CF coordinates are monotonic)
    _variable(f, name, r.values, ("point",), long_name=f"{r.param} along the branch", units=units, dtype=float)
    plate = np.asarray(r.plate, dtype=float).reshape(-1, 2)
    _variable(f, "x2", plate[:, 0], ("point",), long_name="plate displacement before the orbit's first impact",
              units="m")
    _variable(f, "x2dot", plate[:, 1], ("point",), long_name="plate velocity before the orbit's first impact",
              units="m s-1")
    _multipliers(f, "", np.asarray(r.multipliers).reshape(-1, 2), ("point", "multiplier"))
    _variable(f, "stable", r.stable, ("point",), long_name="every multiplier inside the unit circle",
              flags=_YES_NO, dtype=np.int8)
    _variable(f, "contacts", np.asarray(r.contacts).reshape(-1, 3), ("point", "structure"),
              long_name="contact structure of the orbit", units="1", dtype=np.int64, **_STRUCTURE)
    points = r.points
    dims = ("bifurcation",)
    _variable(f, "bifurcation_kind", _codes_of([p.kind for p in points], BIFURCATION_KINDS, "kind"), dims,
              long_name="kind of the bifurcation", flags=BIFURCATION_KINDS)
    _variable(f, "bifurcation_value", [p.value for p in points], dims, long_name=f"{r.param} at the bifurcation",
              units=units, dtype=float)
    plate = np.array([p.plate for p in points], dtype=float).reshape(-1, 2)
    _variable(f, "bifurcation_x2", plate[:, 0], dims, long_name="plate displacement at the bifurcation", units="m")
    _variable(f, "bifurcation_x2dot", plate[:, 1], dims, long_name="plate velocity at the bifurcation",
              units="m s-1")
    _multipliers(f, "bifurcation_", np.array([p.multipliers for p in points], dtype=complex).reshape(-1, 2),
                 ("bifurcation", "multiplier"))
    _variable(f, "bifurcation_bracket", [p.bracket for p in points], dims,
              long_name=f"width of the final bracket in {r.param}", units=units, dtype=float)
    _variable(f, "bifurcation_test_value", [p.test_value for p in points], dims,
              long_name="test function at the bifurcation (0: grazing)", units="1", dtype=float)
    _variable(f, "bifurcation_contacts", np.array([p.contacts for p in points], dtype=np.int64).reshape(-1, 2, 3),
              ("bifurcation", "side", "structure"), long_name="contact structure on either side", units="1",
              **_STRUCTURE)
    _variable(f, "bifurcation_turning", [p.turning for p in points], dims,
              long_name="fold: the branch turns back in the parameter", flags=_YES_NO, dtype=np.int8)


def _write_basins(f, r: Basins, created: str, context: _Context) -> None:
    _train_header(f, "basins", context, float(r.period), created,
                  f"phaseimpact basins: {len(r.x2dot_values)} x {len(r.x2_values)} initial states, "
                  f"{len(r.attractors)} attractors{_by(context)}")
    f.attrs["not_converged"] = np.int64(r.not_converged)
    f.attrs["no_map"] = np.int64(r.no_map)
    _grid_axes([_coordinate(f, "x2dot", np.asarray(r.x2dot_values, dtype=float), "m s-1", "initial plate velocity"),
                _coordinate(f, "x2", np.asarray(r.x2_values, dtype=float), "m", "initial plate displacement")])
    _variable(f, "labels", r.labels, ("x2dot", "x2"), long_name="attractor reached from the initial state",
              dtype=np.int64, comment=f"the attractor's index; {NOT_CONVERGED}: no period repeated, {NO_MAP}: a run "
                                      "failed")
    _variable(f, "impacts", r.impacts, ("x2dot", "x2"), long_name="impacts until the orbit repeated", units="1",
              dtype=np.int64)
    periods = np.array([a.period for a in r.attractors], dtype=np.int64)
    _variable(f, "attractor_period", periods, ("attractor",), long_name="impacts per repetition of the attractor",
              units="1", comment="also its number of rows along orbit_point (the attractors' rows in order)")
    _variable(f, "attractor_count", [a.count for a in r.attractors], ("attractor",),
              long_name="initial states of the grid that go to the attractor", units="1", dtype=np.int64)
    plate = np.concatenate([np.asarray(a.plate, dtype=float).reshape(-1, 2) for a in r.attractors] or
                           [np.empty((0, 2))])
    _variable(f, "attractor_x2", plate[:, 0], ("orbit_point",), long_name="plate displacement on the attractor",
              units="m")
    _variable(f, "attractor_x2dot", plate[:, 1], ("orbit_point",), long_name="plate velocity on the attractor",
              units="m s-1")


#: Writers of the results that :func:`to_xarray` converts besides sweeps and curves, by type.
_WRITERS = {Trajectory: _write_trajectory, ImpactTrain: _write_impact_train, OrbitDiagram: _write_orbit_diagram,
            MapBranch: _write_map_branch, Basins: _write_basins}
#: The archive kind of each train result.
_TRAIN_KIND = {ImpactTrain: "impact-train", OrbitDiagram: "orbit-diagram", MapBranch: "map-branch",
               Basins: "basins"}
#: What :func:`save` archives and :func:`to_xarray` converts (besides a list of Transition); the
#: TypeErrors of both name them.
_ARCHIVED = (SweepResult, CriticalCurve, Trajectory, *_TRAIN_KIND)


# -- reading trains back ----------------------------------------------------------------------------

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


def _read_impact_train(f) -> ImpactTrain:
    n = _data(f, "impact", ndim=1, kinds="iu").shape[0]
    plate = np.stack([_shaped(f, "x2", (n + 1,)), _shaped(f, "x2dot", (n + 1,))], axis=1)
    rows = {name: _shaped(f, name, (n,)) for name in ("peak_force", "dissipated_energy", "restitution", "energy_in")}
    return ImpactTrain(_real_attr(f, "period"), plate, rows["peak_force"], rows["dissipated_energy"],
                       rows["restitution"], rows["energy_in"], _shaped(f, "n_contacts", (n,), "iu").astype(np.int64),
                       _shaped(f, "amplitude", (n + 1,)), _checked_codes(f, "overlap", _YES_NO, (n,)).astype(bool),
                       [STATUSES[c] for c in _checked_codes(f, "status", STATUSES, (n,))])


def _read_orbit_diagram(f) -> OrbitDiagram:
    param = _attr_str(f, "param")
    values = _checked_axis(param, _data(f, netcdf_name(param), ndim=1), False).values
    n = len(values)
    samples = _data(f, "x2", ndim=2, kinds="f").shape[1]
    plate = np.stack([_shaped(f, "x2", (n, samples)), _shaped(f, "x2dot", (n, samples))], axis=-1)
    return OrbitDiagram(param, values, plate, _shaped(f, "peak_force", (n, samples)),
                        _shaped(f, "distinct", (n,), "iu").astype(np.int64))


def _complex(f, prefix: str, shape: tuple) -> np.ndarray:
    out = np.empty(shape, dtype=complex)  # parts set, not summed: re + 1j * im loses a -0.0 and mixes in NaN
    out.real = _shaped(f, f"{prefix}multiplier_real", shape)
    out.imag = _shaped(f, f"{prefix}multiplier_imag", shape)
    return out


def _read_map_branch(f) -> MapBranch:
    param = _attr_str(f, "param")
    values = _data(f, netcdf_name(param), ndim=1, kinds="f")
    n = len(values)
    m = _data(f, "bifurcation_value", ndim=1, kinds="f").shape[0]
    kinds = _checked_codes(f, "bifurcation_kind", BIFURCATION_KINDS, (m,))
    turning = _checked_codes(f, "bifurcation_turning", _YES_NO, (m,))
    plate = np.stack([_shaped(f, "bifurcation_x2", (m,)), _shaped(f, "bifurcation_x2dot", (m,))], axis=1)
    multipliers = _complex(f, "bifurcation_", (m, 2))
    contacts = _shaped(f, "bifurcation_contacts", (m, 2, 3), "iu").tolist()
    bracket, test = _shaped(f, "bifurcation_bracket", (m,)), _shaped(f, "bifurcation_test_value", (m,))
    points = [MapBifurcation(BIFURCATION_KINDS[kinds[i]], param, float(_shaped(f, "bifurcation_value", (m,))[i]),
                             plate[i], multipliers[i], float(bracket[i]), float(test[i]),
                             tuple(tuple(side) for side in contacts[i]), bool(turning[i])) for i in range(m)]
    return MapBranch(param, _int_attr(f, "period_k"), values,
                     np.stack([_shaped(f, "x2", (n,)), _shaped(f, "x2dot", (n,))], axis=1), _complex(f, "", (n, 2)),
                     _checked_codes(f, "stable", _YES_NO, (n,)).astype(bool),
                     _shaped(f, "contacts", (n, 3), "iu").astype(np.int64), points, _attr_str(f, "message"))


def _read_basins(f) -> Basins:
    xs = _checked_axis("x2", _data(f, "x2", ndim=1), False).values
    vs = _checked_axis("x2dot", _data(f, "x2dot", ndim=1), False).values
    shape = (len(vs), len(xs))
    labels = _shaped(f, "labels", shape, "i").astype(np.int64)
    periods = _data(f, "attractor_period", ndim=1, kinds="iu").astype(np.int64)
    counts = _shaped(f, "attractor_count", periods.shape, "iu").astype(np.int64)
    _out_of_range("labels", labels.reshape(-1), (labels.reshape(-1) < NO_MAP) | (labels.reshape(-1) >= len(periods)),
                  f"{NO_MAP} to {len(periods) - 1}")
    _out_of_range("attractor_period", periods, periods < 1, "a positive integer")
    rows = int(periods.sum())
    plate = np.stack([_shaped(f, "attractor_x2", (rows,)), _shaped(f, "attractor_x2dot", (rows,))], axis=1)
    starts = np.concatenate([[0], np.cumsum(periods)])
    attractors = [Attractor(plate[a:b], int(b - a), int(c)) for a, b, c in zip(starts, starts[1:], counts,
                                                                                 strict=False)]
    return Basins(_real_attr(f, "period"), xs, vs, labels, _shaped(f, "impacts", shape, "iu").astype(np.int64),
                  attractors, _int_attr(f, "not_converged"), _int_attr(f, "no_map"))


def _read_trajectory(f) -> Trajectory:
    t = _data(f, "t", ndim=1, kinds="f")
    samples = np.empty((len(t), _driver.N_SMP_COLUMNS))
    samples[:, _driver.SMP_T] = t
    m = _data(f, "event_time", ndim=1, kinds="f").shape[0]
    events = np.empty((m, _driver.N_EV_COLUMNS))
    events[:, _driver.EV_T] = _shaped(f, "event_time", (m,))
    events[:, _driver.EV_KIND] = _checked_codes(f, "event_kind", EVENT_KINDS, (m,))
    events[:, _driver.EV_MODE] = _shaped(f, "event_mode", (m,), "i")
    for i, (name, _, _) in enumerate(_STATE):
        samples[:, _driver.SMP_Y + i] = _shaped(f, name, t.shape)
        events[:, _driver.EV_Y + i] = _shaped(f, f"event_{name}", (m,))
    samples[:, _driver.SMP_FORCE] = _shaped(f, "force", t.shape)
    samples[:, _driver.SMP_MODE] = _shaped(f, "mode", t.shape, "i")
    events[:, _driver.EV_FORCE] = _shaped(f, "event_force", (m,))
    summary = np.empty(_driver.N_SUMMARY)
    names = {}
    for name, index, table in (("status", _driver.S_STATUS, STATUSES), ("outcome", _driver.S_OUTCOME, OUTCOMES),
                               ("stop_reason", _driver.S_REASON, STOP_REASONS)):
        summary[index] = _checked_codes(f, name, table, ())
        names[name] = table[int(summary[index])]
    for name, index, dtype, _ in SUMMARY_COLUMNS:
        summary[index] = _shaped(f, name, (), "f" if dtype is float else "iu")
    summary[_driver.S_FIRST_STICK_T] = _shaped(f, "first_stick_t", ())
    summary[_driver.S_MODE] = _shaped(f, "final_mode", (), "i")
    tr = Trajectory(samples, events, Parameters(**_json_attr(f, "parameters", dict)), _law(f),
                    _shaped(f, "initial_state", (len(_STATE),)), _shaped(f, "final_state", (len(_STATE),)),
                    _real_attr(f, "t_end"), names["status"], names["stop_reason"], names["outcome"], summary,
                    _attr_str(f, "engine"), _attr_str(f, "law_fault") if "law_fault" in f.attrs else "")
    if tr.message != _attr_str(f, "message"):
        raise _Damaged(f"attribute message = {_short(_attr_str(f, 'message'))} is not the run's: "
                       f"{_short(tr.message)}")
    return tr


def _read_transitions(f) -> list[Transition]:
    kappa = _data(f, "kappa", ndim=1, kinds="f")
    n = len(kappa)
    kinds = _checked_codes(f, "kind", TRANSITION_KINDS, (n,))
    counts = {name: _shaped(f, name, (n,), "i") for name in ("count_below", "count_above", "extremum")}
    for name, values in counts.items():
        _out_of_range(name, values, values < -1, "-1 (not known) or a count >= 0")

    def count(name, i):
        return None if counts[name][i] == -1 else int(counts[name][i])

    return [Transition(TRANSITION_KINDS[kinds[i]], float(kappa[i]), count("count_below", i), count("count_above", i),
                       count("extremum", i)) for i in range(n)]


_READERS = {"impact-train": _read_impact_train, "orbit-diagram": _read_orbit_diagram,
            "map-branch": _read_map_branch, "basins": _read_basins, "trajectory": _read_trajectory,
            "transitions": _read_transitions}


# ------------------------------------------------------------------------------------------------
# Checkpoints written in place
# ------------------------------------------------------------------------------------------------

@dataclass
class _OnDisk:
    """What a checkpointed file holds, mirrored in memory so that a checkpoint reads nothing."""

    stamp: tuple
    shape: tuple
    status: np.ndarray      # int8 per point
    first: np.ndarray       # int64 per point
    count: np.ndarray       # int64 per point
    capacity: int           # stick rows
    free: int               # first free row
    rows: int               # stick rows of committed points (= rows of the result in memory)
    failed: np.ndarray      # committed failed points (recomputed on resume)
    failed_snapshot: dict   # their codes and columns, to see whether a recomputation changed them
    columns: list
    pieces: dict            # every dataset's piece digests (_file_pieces), to update its digest


class Checkpoint:
    """Write a growing sweep or atlas to ``path``: pass it as ``on_chunk`` of
    :func:`~phaseimpact.continuation.atlas` (or ``sweep``), and call :func:`save` once at the end.

    The first call writes the file whole (atomically, as :func:`save`, with room for the stick phases
    still to come); later calls write only the points computed since the previous call, in place, in
    the crash-safe order described in the module docstring. A file that is not an archive of the same
    grid (law, base, axes, ``t_end``, ``rtol``, columns, extras) is rewritten whole, as is one whose
    spare stick rows are used up and one whose data do not match their digests (killed while a
    checkpoint wrote, or written before data digests). ``path``'s write lock is taken for every call
    (re-entrant: a caller may hold it for the whole sweep).

    Parameters
    ----------
    path : str or path-like
    force : bool
        As for :func:`save`: replace a file that is not a phaseimpact archive.
    fsync : bool
        fsync after each step, so that the order also holds after a power cut (not only after a
        killed process). Default True.

    Attributes
    ----------
    path : str
        The archive.
    force, fsync : bool
        As given.
    in_place, rewrites : int
        How many calls wrote in place, and how many rewrote the whole file.
    saved : int or None
        Points done in the last complete checkpoint (None before the first): what the file holds
        even when a call is interrupted while it writes (the file then is not read meanwhile).

    Raises
    ------
    TypeError
        When called with anything but a SweepResult.
    ValueError
        As :func:`save` (a path that cannot be written, another process writing it).
    OSError
        For a full disk or a failing write (the last complete checkpoint is kept).

    Examples
    --------
    >>> import os, tempfile
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import Checkpoint, load, save
    >>> from phaseimpact.continuation import atlas
    >>> checkpoint = Checkpoint(os.path.join(tempfile.mkdtemp(), "atlas.nc"))
    >>> result = atlas(seed_parameters(), "paper", {"kappa": [1e11, 1e13], "v": [1.0, 2.0]}, on_chunk=checkpoint)
    >>> checkpoint.rewrites, checkpoint.in_place
    (1, 0)
    >>> save(result, checkpoint.path) == checkpoint.path
    True
    >>> load(checkpoint.path).summary()["computed"]
    4
    """

    def __init__(self, path, *, force: bool = False, fsync: bool = True):
        self.path = os.fspath(path)
        self.force = bool(force)
        self.fsync = bool(fsync)
        self.in_place = 0
        self.rewrites = 0
        self.saved: int | None = None
        self._disk: _OnDisk | None = None

    def __repr__(self) -> str:
        return f"Checkpoint({self.path!r}, in_place={self.in_place}, rewrites={self.rewrites})"

    def __call__(self, result: SweepResult) -> None:
        """Write ``result``'s points computed since the previous call (the first call: the whole file)."""
        if not isinstance(result, SweepResult):
            raise TypeError(f"Checkpoint writes a SweepResult, not a {type(result).__name__}")
        with exclusive(self.path, "path"):
            try:
                if self._write_in_place(result):
                    self.in_place += 1
                else:
                    self._rewrite(result)
                    self.rewrites += 1
            except BaseException:
                self._disk = None  # whatever happened, read the file again next time
                raise
            self.saved = int(np.count_nonzero(result.done))

    # -- whole file -----------------------------------------------------------------------------

    def _rewrite(self, r: SweepResult) -> None:
        n = r.grid.size
        status = np.asarray(r.status)
        computed = int(np.count_nonzero(status >= 0))
        per_point = max(1.0, len(r.stick_point) / computed) if computed else 2.0
        remaining = n - int(np.count_nonzero(status == _driver.SUCCESS))
        spare = int(math.ceil(1.25 * per_point * remaining)) + 1024
        first, count, pieces = _write_file(r, self.path, force=self.force, spare_rows=spare)
        rows = len(r.stick_point)
        self._disk = _OnDisk(_stamp(self.path), r.grid.shape, status.astype(np.int8, copy=True), first, count,
                             rows + spare, rows, rows, np.empty(0, dtype=np.int64), {}, list(r.values), pieces)
        self._remember_failed(r, np.flatnonzero(status > _driver.SUCCESS))

    def _remember_failed(self, r: SweepResult, failed: np.ndarray) -> None:
        disk = self._disk
        disk.failed = failed
        disk.failed_snapshot = {"outcome": np.asarray(r.outcome)[failed].copy(),
                                "stop_reason": np.asarray(r.stop_reason)[failed].copy(),
                                **{k: np.asarray(v)[failed].copy() for k, v in r.values.items()}}

    # -- reading the file's state ---------------------------------------------------------------

    def _read_disk(self, r: SweepResult) -> _OnDisk | None:
        """The file's state if it is an archive of this schema of ``r``'s grid that can be written in place:
        its data match their digests (a file killed while a checkpoint wrote, or written before data
        digests, is rewritten whole; so no stick row a killed checkpoint wrote stays behind)."""
        path = self.path
        if not os.path.isfile(path) or not _is_archive(path):
            return None
        stamp = _stamp(path)
        with h5py.File(path, "r", locking=False) as f:
            if int(f.attrs["schema_version"]) != SCHEMA_VERSION or not _same_grid(f, r):
                return None
            if any(name not in f for name in ("status", "stick_first", "stick_count", "stick_point")):
                return None
            try:
                stored = _stored_digests(f)
            except _Damaged:
                return None
            pieces = _file_pieces(f)
            if stored != {name: _dataset_digest(*entry) for name, entry in pieces.items()}:
                return None
            status = f["status"][()].reshape(-1)
            first = f["stick_first"][()].reshape(-1).astype(np.int64)
            count = f["stick_count"][()].reshape(-1).astype(np.int64)
            capacity = int(f["stick_point"].shape[0])
            committed = (status >= 0) & (count > 0)
            free = int((first[committed] + count[committed]).max()) if committed.any() else 0
            rows = int(count[committed].sum())
            disk = _OnDisk(stamp, r.grid.shape, status.astype(np.int8), first, count, capacity, free, rows,
                           np.empty(0, dtype=np.int64), {}, json.loads(_attr_str(f, "columns")), pieces)
            failed = np.flatnonzero(status > _driver.SUCCESS)
            disk.failed = failed
            if failed.size:
                snapshot = {}
                for name in ("outcome", "stop_reason", *disk.columns):
                    snapshot[name] = f[name][()].reshape(-1)[failed]
                disk.failed_snapshot = snapshot
        return disk

    # -- in place ---------------------------------------------------------------------------------

    def _write_in_place(self, r: SweepResult) -> bool:
        """Write the points of ``r`` that differ from the file; False when a whole rewrite is needed."""
        disk = self._disk
        if disk is not None and (not os.path.exists(self.path) or disk.stamp != _stamp(self.path)):
            disk = None
        if disk is None:
            try:
                disk = self._disk = self._read_disk(r)
            except OSError:  # unreadable, or open in this process with HDF5 file locking: rewrite it
                disk = None
            if disk is None:
                return False
        if r.grid.shape != disk.shape or list(r.values) != disk.columns:
            return False
        status = np.asarray(r.status)
        new = np.flatnonzero(status != disk.status)
        if disk.failed.size:
            new = np.union1d(new, disk.failed[self._changed_failed(r)])
        if new.size == 0:
            return True
        if np.any(status[new] < 0):
            return False  # a point went back to "not computed": not a continuation of the file
        # the new points' stick phases: appended by SweepResult.store since the last checkpoint, so
        # they lie after the rows of the points committed then, less the rows of recomputed points
        point = np.asarray(r.stick_point, dtype=np.int64)
        failed_rows = int(disk.count[disk.failed].sum()) if disk.failed.size else 0
        start = max(0, disk.rows - failed_rows)
        mine = np.zeros(r.grid.size, dtype=bool)
        mine[new] = True
        window = point[start:]
        if window.size and (window.min() < 0 or window.max() >= r.grid.size):
            return False
        selected = np.flatnonzero(mine[window])
        rows = start + selected
        owner = np.searchsorted(new, window[selected])
        if owner.size and np.any(np.diff(owner) < 0):
            order = np.argsort(owner, kind="stable")
            rows, owner = rows[order], owner[order]
        counts = np.bincount(owner, minlength=new.size).astype(np.int64)
        recomputed = new[disk.status[new] >= 0]
        expected = disk.rows - int(disk.count[recomputed].sum()) + rows.size
        if point.size != expected or disk.free + rows.size > disk.capacity:
            return False  # not the continuation of the file, or no room left: rewrite it whole
        try:
            raw = _Raw(self.path)
        except OSError:  # e.g. open elsewhere in this process with HDF5 file locking: rewrite it
            return False
        free, old_rows = disk.free, _owned_rows(disk.first, disk.count, np.isin(np.arange(r.grid.size), recomputed))
        with raw:
            # a kill from here on leaves a file whose data match no digest: say so first
            raw.set_text(_DATA_DIGEST, _IN_PROGRESS)
            raw.flush_to_disk(self.fsync)
            self._commit(raw, r, new, recomputed, rows, counts)
            self._update_digests(raw, new, np.union1d(np.arange(free, free + rows.size), old_rows))
        self._disk.stamp = _stamp(self.path)  # after the close: what the next call must find
        return True

    def _changed_failed(self, r: SweepResult) -> np.ndarray:
        disk = self._disk
        idx = disk.failed
        changed = np.zeros(idx.size, dtype=bool)
        for name, old in disk.failed_snapshot.items():
            now = np.asarray(getattr(r, name) if name in ("outcome", "stop_reason") else r.values[name])[idx]
            differs = now != old
            if now.dtype.kind == "f":
                differs &= ~(np.isnan(now) & np.isnan(old))
            changed |= differs
        return changed

    def _flush(self, raw) -> None:
        raw.flush_to_disk(self.fsync)

    def _update_digests(self, raw, points: np.ndarray, rows: np.ndarray) -> None:
        """After a commit: hash again the pieces holding the ``points`` and stick ``rows`` written, then
        store the digests (the end of the checkpoint)."""
        disk = self._disk
        gridded = ("status", "outcome", "stop_reason", *disk.columns, "stick_first", "stick_count")
        for names, indices in ((gridded, points), (_STICK_VARIABLES, rows)):
            for k in np.unique(np.asarray(indices, dtype=np.int64) // _DIGEST_PIECE).tolist():
                for name in names:
                    dtype, shape, pieces = disk.pieces[name]
                    lo = k * _DIGEST_PIECE
                    pieces[k] = _piece_digests(raw.read_flat(name, lo, min(lo + _DIGEST_PIECE, int(np.prod(shape)))))[0]
        raw.set_text(_DATA_DIGEST, _digests_text(disk.pieces))
        raw.flush_to_disk(self.fsync)

    def _commit(self, raw, r: SweepResult, new, recomputed, rows, counts) -> None:
        disk = self._disk
        shape = disk.shape
        boxes = [b for lo, hi in _runs(new) for b in _aligned_boxes(lo, hi, shape)]
        old_first, old_count = disk.first[recomputed].copy(), disk.count[recomputed].copy()
        # 0. points recomputed over a committed (failed) state are first marked not computed
        if recomputed.size:
            disk.status[recomputed] = -1
            for lo, hi in _runs(recomputed):
                for box in _boxes(lo, hi, shape):
                    raw.write("status", box, disk.status.reshape(shape))
            self._flush(raw)
        # 1. stick phases to free rows, then every column of the new points
        n_rows = rows.size
        if n_rows:
            lo = disk.free
            raw.write_rows("stick_point", lo, new[np.repeat(np.arange(new.size), counts)])
            for name in ("t", "delta", "dwell"):
                raw.write_rows(f"stick_{name}", lo, np.asarray(getattr(r, f"stick_{name}"), dtype=float)[rows])
        offsets = np.cumsum(counts) - counts
        disk.first[new] = np.where(counts > 0, disk.free + offsets, -1)
        disk.count[new] = counts
        sources = {"outcome": r.outcome, "stop_reason": r.stop_reason, **r.values,
                   "stick_first": disk.first, "stick_count": disk.count}
        for name, values in sources.items():
            grid_values = np.asarray(values).reshape(shape)
            for box in boxes:
                raw.write(name, box, grid_values)
        self._flush(raw)
        # 2. the commit: the new points' status
        disk.status[new] = np.asarray(r.status)[new]
        for box in boxes:
            raw.write("status", box, disk.status.reshape(shape))
        self._flush(raw)
        # 3. rows of recomputed points are no one's now
        for a, c in zip(old_first, old_count, strict=True):
            if a >= 0 and c > 0:
                raw.write_rows("stick_point", int(a), np.full(int(c), -1, dtype=np.int64))
        disk.free += n_rows
        disk.rows = len(r.stick_point)
        touched = np.union1d(disk.failed, new)
        self._remember_failed(r, touched[disk.status[touched] > _driver.SUCCESS])


class _Raw:
    """An archive opened for in-place writes through HDF5's low-level API (no HDF5 file locking: the
    sidecar lock of :mod:`phaseimpact._atomic` keeps writers apart, and readers may look on)."""

    def __init__(self, path: str):
        fapl = h5py.h5p.create(h5py.h5p.FILE_ACCESS)
        fapl.set_file_locking(False, True)
        self.fid = h5py.h5f.open(os.fsencode(path), h5py.h5f.ACC_RDWR, fapl=fapl)
        self._datasets = {}

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        for d in self._datasets.values():
            d.close()
        self._datasets.clear()
        self.fid.close()

    def _dataset(self, name: str):
        d = self._datasets.get(name)
        if d is None:
            d = self._datasets[name] = h5py.h5d.open(self.fid, name.encode())
        return d

    def _put(self, name: str, start: tuple, block: np.ndarray) -> None:
        d = self._dataset(name)
        block = np.ascontiguousarray(block, dtype=d.dtype)
        space = d.get_space()
        space.select_hyperslab(start, block.shape)
        d.write(h5py.h5s.create_simple(block.shape), space, block)

    def write(self, name: str, box: tuple, grid_values: np.ndarray) -> None:
        """Write ``grid_values[box]`` (a grid-shaped array) into the same box of dataset ``name``."""
        self._put(name, tuple(s.start for s in box), grid_values[box])

    def write_rows(self, name: str, lo: int, values: np.ndarray) -> None:
        """Write ``values`` into rows ``lo, lo + 1, ...`` of the 1-d dataset ``name``."""
        self._put(name, (lo,), values)

    def read_flat(self, name: str, lo: int, hi: int) -> np.ndarray:
        """Elements ``lo .. hi - 1`` (C order) of dataset ``name``, as the file holds them."""
        d = self._dataset(name)
        parts = []
        for box in _boxes(lo, hi, d.shape):
            start, count = tuple(s.start for s in box), tuple(s.stop - s.start for s in box)
            block = np.empty(count, dtype=d.dtype)
            space = d.get_space()
            space.select_hyperslab(start, count)
            d.read(h5py.h5s.create_simple(count), space, block)
            parts.append(block.reshape(-1))
        return np.concatenate(parts) if parts else np.empty(0, dtype=d.dtype)

    def set_text(self, name: str, text: str) -> None:
        """Overwrite the root's fixed-length text attribute ``name`` in place (padded with spaces)."""
        attr = h5py.h5a.open(h5py.h5g.open(self.fid, b"/"), name.encode())
        try:
            attr.write(np.array(text.encode("ascii").ljust(attr.dtype.itemsize), dtype=attr.dtype))
        finally:
            attr.close()

    def flush_to_disk(self, fsync: bool) -> None:
        h5py.h5f.flush(self.fid)
        if fsync:
            fsync_file(self.fid)


def _owned_rows(first, count, committed) -> np.ndarray:
    """Rows referenced by the committed points' ``stick_first``/``stick_count``, in point order."""
    points = np.flatnonzero(committed & (count > 0) & (first >= 0))
    counts = count[points]
    total = int(counts.sum())
    if total == 0:
        return np.empty(0, dtype=np.int64)
    offsets = np.repeat(np.cumsum(counts) - counts, counts)
    return np.repeat(first[points], counts) + (np.arange(total) - offsets)


def _same_grid(f, r: SweepResult) -> bool:
    """Whether the open file ``f`` archives the grid, law, base and settings of ``r``."""
    grid = r.grid
    try:
        if _attr_str(f, "kind") != kind_of(r) or json.loads(_attr_str(f, "axes")) != list(grid.names):
            return False
        if json.loads(_attr_str(f, "law")) != json.loads(_json(r.law.as_dict())) or _law_source(f) != r.law.source:
            return False
        base = _base_attrs(grid.base)
        if any(_attr_str(f, key) != value for key, value in base.items()):
            return False
        if not (_same_number(f.attrs["t_end"], r.t_end) and _same_number(f.attrs["rtol"], r.settings.get("rtol"))):
            return False
        if _attr_str(f, "extras_digest") != _digest(r.extras):
            return False
        dims = json.loads(_attr_str(f, _AXIS_DIMENSIONS))
        return all(np.array_equal(f[dim][()], np.asarray(axis.values, dtype=float))
                   for dim, axis in zip(dims, grid.axes, strict=True))
    except (KeyError, TypeError, ValueError):
        return False


# ------------------------------------------------------------------------------------------------
# Reading
# ------------------------------------------------------------------------------------------------

def _open(path):
    path = os.fspath(path)
    if os.path.isdir(path):
        raise ValueError(f"archive {path!r} is a folder, not a file")
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise ValueError(f"archive {path!r} does not exist") from None
    except OSError as error:
        raise ValueError(f"archive {path!r} cannot be read: {error.strerror or error}") from None
    if not stat.S_ISREG(mode):  # opening a FIFO waits for a writer forever; a device is no archive
        raise ValueError(f"archive {path!r} is not a regular file (a FIFO, device or socket); allowed: an HDF5 file")
    try:  # first, as HDF5 would say it after "unable to open file" and a guess at damage
        os.close(os.open(path, os.O_RDONLY))
    except OSError as error:
        raise ValueError(f"archive {path!r} cannot be read: {error.strerror or error}") from None
    try:
        return h5py.File(path, "r")
    except FileNotFoundError:
        raise ValueError(f"archive {path!r} does not exist") from None
    except MemoryError:
        raise
    except Exception as error:  # OSError mostly; a damaged superblock can surface as other h5py errors
        raise ValueError(f"{path!r} is not a readable HDF5 file (truncated, damaged or foreign): {error}") from None


def _is_archive(path) -> bool:
    for locking in (False, None):  # None: as another h5py.File of this process may hold it open
        try:
            with h5py.File(path, "r", locking=locking) as f:
                return "schema_version" in f.attrs and "kind" in f.attrs
        except OSError:
            continue
    return False


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


#: A read that fails a checksum is tried again after these pauses (s): a reader may catch a chunk
#: while a checkpoint rewrites it in place; damage on disk fails every time.
_RETRY_PAUSES = (0.05, 0.25)


def _why(error: BaseException) -> str:
    if isinstance(error, KeyError) and error.args:
        return str(error.args[0])
    text = str(error) or type(error).__name__
    if "checksum" in text.lower():
        return f"HDF5 metadata does not match its checksum (the file's bytes were changed): {text}"
    return text


@contextlib.contextmanager
def _reading(path: str):
    """The archive at ``path`` open for reading. Whatever goes wrong while it is read (an HDF5 error, a
    checksum, a malformed attribute, content out of range) becomes a :class:`DamagedArchiveError`."""
    f = _open(path)
    writer = _netcdf_writer(f)
    try:
        with f:
            yield f
    except (_Refusal, MemoryError):
        raise
    except Exception as error:  # a damaged file reaches h5py, json and numpy in many ways: all are damage
        reason = str(error) if isinstance(error, _Damaged) else _why(error)
        if writer is not None:  # not damage: a netCDF writer's copy, whose content was changed or left out
            raise _Refusal(f"{path!r} was written by xarray (or another netCDF writer: {writer}) without what "
                           f"phaseimpact reads back: {reason}. A subset (.sel, .isel) or an edited Dataset is "
                           "not an archive: open it with xarray, or load the archive it came from") from None
        raise DamagedArchiveError(path, reason, checksum=isinstance(error, _Damaged) and error.checksum) from None


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


def _archive_path(path) -> str:
    """``path`` as text, or a ``TypeError`` naming it (not os.fspath's, which names no argument)."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"path = {_short(path)} has the wrong type ({type(path).__name__}); allowed: the path of an "
                        "archive (str or os.PathLike)")
    return os.fsdecode(path)


def _retrying(read, path: str):
    for pause in (*_RETRY_PAUSES, None):
        try:
            return read(path)
        except DamagedArchiveError as error:
            if not error.checksum or pause is None:
                raise
            time.sleep(pause)


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


def _checked_header(f, path) -> int:
    if "schema_version" not in f.attrs or "kind" not in f.attrs:
        raise _Refusal(f"{path!r} is not a phaseimpact archive (no schema_version attribute)")
    version = _int_attr(f, "schema_version")
    if version > SCHEMA_VERSION:
        raise _Refusal(f"{path!r} has schema_version {version}; this phaseimpact reads up to "
                       f"{SCHEMA_VERSION}: upgrade phaseimpact")
    if version < 1:
        raise _Damaged(f"attribute schema_version = {version} is out of range; allowed: 1 to {SCHEMA_VERSION}")
    kind = _attr_str(f, "kind")
    known = KINDS + RUN_KINDS + TRAIN_KINDS
    if kind not in known:
        raise _Damaged(f"attribute kind = {kind!r} is out of range; allowed: one of {', '.join(known)}")
    return version


def _law(f) -> ContactLaw:
    return ContactLaw(**_json_attr(f, "law", dict))


def _law_source(f) -> str | None:
    """The source digest of the archive's user law (:attr:`ContactLaw.source`); None for a shipped law's."""
    return _attr_str(f, _LAW_SOURCE) if _LAW_SOURCE in f.attrs else None


def _check_law_defined(f, path: str) -> None:
    """Refuse, as what it is, an archive of a user law not defined in this process (not damage):
    its results need the law's entry (name, units). A case that records its law file defines it
    (the file is run, as :func:`_base` would)."""
    from .model import LAWS, REGISTRY

    name = _json_attr(f, "law", dict).get("name")
    if not isinstance(name, str) or name in REGISTRY or name in LAWS:
        return  # a shipped law's, a defined one's, or damage that the readers name
    impact = _json_attr(f, "case", dict).get("impact") if "case" in f.attrs else None
    law_file = impact.get("law_file") if isinstance(impact, dict) else None
    if isinstance(law_file, str) and os.path.isfile(law_file):
        from .model.userlaw import load_law_file

        try:
            load_law_file(law_file)
        except ValueError as error:
            raise _Refusal(f"{path!r} holds work of law {name!r}, a user law of the case's law file, which fails: "
                           f"{error}") from None
        if name in REGISTRY:
            return
    raise _Refusal(f"{path!r} holds work of law {name!r}, a user law: define it first (--law-file FILE, or "
                   "phaseimpact.define_law in Python)")


def _base(f):
    from .case import case_from_dict

    if "base" in f.attrs:  # schema 3 and later: case holds the Case, or the Parameters
        data = _json_attr(f, "case", dict)
        return case_from_dict(data, origin="archive") if _attr_str(f, "base") == "case" else Parameters(**data)
    if "case" in f.attrs:  # schema 2: case only when the base is a case
        return case_from_dict(_json_attr(f, "case", dict), origin="archive")
    return Parameters(**_json_attr(f, "parameters", dict))


def load(path):
    """Read an archive back: a :class:`SweepResult` (with its :class:`Grid`), a :class:`CriticalCurve`, a
    :class:`~phaseimpact.integrate.result.Trajectory`, a list of
    :class:`~phaseimpact.continuation.Transition`, or a train result
    (:class:`~phaseimpact.train.ImpactTrain`, :class:`~phaseimpact.train.OrbitDiagram`,
    :class:`~phaseimpact.train.MapBranch`, :class:`~phaseimpact.train.Basins`); the case and law of
    transitions and train results are in :func:`describe`.

    Points of an archive in progress that are not committed (status -1) come back as not computed,
    whatever else a killed checkpoint left of them. Every chunk's checksum and the content are
    checked (codes in range, finite axes, scalar attributes, stick rows that belong to their points).

    Raises ``ValueError`` naming the file for a missing, foreign, truncated, damaged or newer-schema
    file (:class:`DamagedArchiveError`, naming the damage too, for a damaged one).

    Parameters
    ----------
    path : str or path-like
        An archive written by :func:`save` or :class:`Checkpoint` (schema 1 to
        :data:`SCHEMA_VERSION`).

    Returns
    -------
    SweepResult, CriticalCurve, Trajectory, list of Transition, ImpactTrain, OrbitDiagram, MapBranch or Basins
        A sweep or curve with its base case, law, axes, ``t_end`` and settings, ready to be
        completed (``previous=``) or plotted; a trajectory, the transitions (in increasing kappa) or a
        train result equal to the one saved, every array bit for bit.

    Raises
    ------
    TypeError
        For a ``path`` that is not a str or path-like.
    ValueError
        As above; :class:`DamagedArchiveError` for a damaged file.

    Examples
    --------
    >>> import os, tempfile
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import load, save
    >>> from phaseimpact.continuation import critical_curve
    >>> path = save(critical_curve(seed_parameters(), "paper", "v", [1.0, 2.0]),
    ...             os.path.join(tempfile.mkdtemp(), "curve.nc"))
    >>> curve = load(path)
    >>> type(curve).__name__, curve.what, [f"{k:.4g}" for k in curve.kappa[curve.requested]]
    ('CriticalCurve', 'kappa_c', ['1.499e+12', '9.542e+11'])
    >>> load(os.path.join(tempfile.mkdtemp(), "missing.nc"))
    Traceback (most recent call last):
    ...
    ValueError: ...
    """
    return _retrying(_load, _archive_path(path))


def _load(path: str):
    with _reading(path) as f:
        version = _checked_header(f, path)
        _check_law_defined(f, path)
        kind = _attr_str(f, "kind")
        if kind in _READERS:  # schema 5 on
            result = _READERS[kind](f)
            _check_metadata(f)
            return result
        if version == 1:
            result = _read_sweep_v1(f) if kind == "sweep" else _read_curve_v1(f)
        elif version == 2:
            result = _read_sweep_v2(f) if kind == "sweep" else _read_curve_v2(f)
        else:
            result = _read_curve(f) if kind == "critical-curve" else _read_sweep(f)
        if isinstance(result, SweepResult):
            _check_sweep(result)
        else:
            _check_curve(result)
        if version >= 3:  # last: a value out of range is named as such, not as a changed digest
            _rtol(f)  # the header's copy (describe reads it); a sweep reads its settings
            _check_metadata(f)
    return result


def _check_metadata(f, *, data: bool = True) -> None:
    """The parts of the metadata that HDF5's own checksums leave out: the text attributes (against
    :data:`_TEXT_DIGEST`, where the file has one); with ``data``, the chunk index of every checksummed
    dataset and every dataset's contents (against :data:`_DATA_DIGEST`, where the file has it)."""
    if _TEXT_DIGEST in f.attrs and _attr_str(f, _TEXT_DIGEST) != _texts_digest(f):
        raise _Damaged("its text attributes (case, law, settings, ...) do not match their SHA-256 digest "
                       f"{_TEXT_DIGEST} (the file's bytes were changed)")
    if data:
        _check_storage(f)
        _check_data_digests(f)


def _check_storage(f) -> None:
    """Each chunk of each checksummed dataset is found by its coordinates where HDF5's index says, whole,
    filtered, inside the file and apart from every other chunk. The index (a v1 B-tree) has no checksum:
    a changed key or address would read another dataset's chunk, or nothing, as this one's data."""
    end = f.id.get_filesize()
    spans = []

    def visit(name, node):
        if not isinstance(node, h5py.Dataset) or node.chunks is None or node.size == 0 or not node.fletcher32:
            return
        size = int(np.prod(node.chunks)) * node.dtype.itemsize + 4  # the data and its Fletcher-32 sum
        listed = []
        node.id.chunk_iter(listed.append)  # the chunks found by walking the index
        corners = list(itertools.product(*(range(0, n, c) for n, c in zip(node.shape, node.chunks, strict=True))))
        if sorted(tuple(info.chunk_offset) for info in listed) != corners:
            raise _Damaged(f"variable {name}: its chunk index does not list each chunk once")
        for info in listed:
            try:  # and found by looking each up, as a read does (which compares every field of the keys)
                mask, raw = node.id.read_direct_chunk(info.chunk_offset)
            except (OSError, RuntimeError, ValueError):
                mask, raw = None, b""
            if (info.filter_mask != 0 or info.size != size or mask != 0 or len(raw) != size
                    or info.byte_offset + info.size > end):
                raise _Damaged(f"variable {name}: the index entry of its chunk at {tuple(info.chunk_offset)} is "
                               "damaged")
            spans.append((info.byte_offset, info.size, name))

    f.visititems(visit)
    spans.sort()
    for (a, size, name), (b, _, other) in zip(spans, spans[1:], strict=False):
        if a + size > b:
            raise _Damaged(f"variables {name} and {other}: chunks overlap in the file (a damaged chunk index)")


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


# -- what a loaded result may hold ------------------------------------------------------------------

def _out_of_range(name: str, values: np.ndarray, bad: np.ndarray, allowed: str) -> None:
    if np.any(bad):
        i = int(np.argmax(bad))
        raise _Damaged(f"{name} = {_short(values[i])} at point {i} is out of range; allowed: {allowed}")


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


# -- schema 2 (groups /sweep and /curve, codes as strings) ------------------------------------------

def _codes(strings: np.ndarray, names) -> np.ndarray:
    lookup = {name: i for i, name in enumerate(names)}
    lookup[""] = -1
    try:
        return np.array([lookup[s] for s in strings.ravel()], dtype=np.int8).reshape(strings.shape)
    except KeyError as error:
        raise ValueError(f"unknown code {error.args[0]!r}; allowed: one of {', '.join(names)}") from None


def _read_sweep_v2(f) -> SweepResult:
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


def _read_curve_v2(f) -> CriticalCurve:
    g = f["curve"]
    param = _attr_str(g, "param")
    return CriticalCurve(param, g[param][()], g["kappa"][()], g["requested"][()].astype(bool), g["closed_form"][()],
                         g["predicted"][()], _attr_str(g, "what"), _law(f), _base(f), float(g.attrs["rtol"]),
                         int(g.attrs["contact_index"]), _attr_str(g, "message"))


# -- schema 1 (phaseimpact 0.1) ----------------------------------------------------------------------

#: Schema 1 outcome names in today's terms.
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

    Returns ``{"kind", "law", "law_source", "parameters", "axes", "t_end", "rtol", "schema_version"}``
    (``axes``: ``{name: values}``, names as given, e.g. ``plate.E``). Raises ``ValueError`` if
    ``path`` is not a phaseimpact archive, or its header or axes are damaged.

    Parameters
    ----------
    path : str or path-like
        An archive.

    Returns
    -------
    dict
        ``kind`` (one of :data:`KINDS`, :data:`RUN_KINDS`, :data:`TRAIN_KINDS`), ``law`` (the law as a
        dict), ``law_source`` (a user law's source digest, :attr:`~phaseimpact.model.ContactLaw.source`;
        None for a shipped law), ``parameters`` (the base's :class:`~phaseimpact.Parameters` as a
        dict, SI), ``axes`` (empty for a trajectory or transitions), ``t_end`` (s; NaN: each run
        until its outcome settles), ``rtol`` and ``schema_version``.

    Raises
    ------
    ValueError
        As above (:class:`DamagedArchiveError` for a damaged one).

    Examples
    --------
    >>> import os, tempfile
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import describe, save
    >>> from phaseimpact.continuation import sweep
    >>> path = save(sweep(seed_parameters(), "paper", [1e9, 1e13]), os.path.join(tempfile.mkdtemp(), "s.nc"))
    >>> held = describe(path)
    >>> held["kind"], held["law"]["name"], held["axes"]["kappa"].tolist(), held["t_end"], held["schema_version"]
    ('sweep', 'paper', [1000000000.0, 10000000000000.0], nan, 5)
    """
    return _retrying(_describe, _archive_path(path))


def _describe(path: str) -> dict:
    def axis(node, name, dataset):
        return _checked_axis(name, _data(node, dataset, ndim=1), False).values

    with _reading(path) as f:
        version = _checked_header(f, path)
        _check_law_defined(f, path)
        kind = _attr_str(f, "kind")
        law = _law(f).as_dict()
        law_source = _law_source(f)
        params = _json_attr(f, "parameters", dict)
        if kind in _READERS:
            axes = {}
            if kind == "orbit-diagram":
                param = _attr_str(f, "param")
                axes = {param: axis(f, param, netcdf_name(param))}
        elif version >= 3:
            if kind == "critical-curve":
                param = _attr_str(f, "param")
                axes = {param: axis(f, param, _axis_names([param])[0])}
            else:
                axes = {a.name: a.values for a in _axes(f)}
        elif kind == "sweep":
            g = f["sweep"]
            names = ["kappa"] if version == 1 else _json_attr(g, "axes", list)
            axes = {name: axis(g, name, name) for name in names}
        else:
            g = f["curve"]
            param = "v" if version == 1 else _attr_str(g, "param")
            axes = {param: axis(g, param, param)}
        if version >= 3:
            _check_metadata(f, data=False)
        return {"kind": kind, "law": law, "law_source": law_source, "parameters": params, "axes": axes,
                "t_end": _real_attr(f, "t_end"), "rtol": _real_attr(f, "rtol"), "schema_version": version}


def _same_number(a, b) -> bool:
    a, b = _float(a), _float(b)
    return a == b or (math.isnan(a) and math.isnan(b))


def _axis_text(name, values) -> str:
    values = np.asarray(values, dtype=float).ravel()
    if not values.size:
        return f"{name}: empty"
    # the spacing too: a log and a linear axis with the same ends and NUM must not print alike
    spacing = ""
    if values.size > 2:
        steps = np.diff(values)
        if np.all(values > 0) and np.allclose(np.diff(np.log(values)), np.log(values[1] / values[0]), rtol=1e-9):
            spacing = ", log spaced"
        elif np.allclose(steps, steps[0], rtol=1e-9):
            spacing = ", linear"
        else:
            spacing = ", listed"
    # repr digits: a difference in the 11th digit must show in the message
    return f"{name}: {len(values)} values from {float(values[0])!r} to {float(values[-1])!r}{spacing}"


def _t_end_text(t_end) -> str:
    """``t_end`` as a reader knows it: NaN or None in an archive means each run until it settles."""
    if t_end is None or (isinstance(t_end, float) and math.isnan(t_end)):
        return "none (each run until its outcome settles)"
    return f"{float(t_end)!r} s"


def same_work(held: dict, kind: str, law: ContactLaw, params: Parameters, axes: dict, t_end, rtol) -> list[str]:
    """What differs between an archive's :func:`describe` and the work asked for (empty: the same).

    Parameters
    ----------
    held : dict
        :func:`describe` of the archive.
    kind : str
        One of :data:`KINDS`.
    law : ContactLaw
        The law asked for.
    params : Parameters
        The base case's parameters asked for.
    axes : dict
        ``{name: values}`` asked for, in order.
    t_end : float or None
        The horizon asked for, s (None or NaN: each run until its outcome settles).
    rtol : float
        The integrator tolerance asked for.

    Returns
    -------
    list of str
        One phrase per difference (kind, law, a user law's source, parameters, axes, ``t_end``,
        ``rtol``), each with both values.

    Examples
    --------
    >>> import os, tempfile
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import describe, same_work, save
    >>> from phaseimpact.continuation import sweep
    >>> s = sweep(seed_parameters(), "paper", [1e9, 1e13])
    >>> held = describe(save(s, os.path.join(tempfile.mkdtemp(), "s.nc")))
    >>> same_work(held, "sweep", s.law, seed_parameters(), {"kappa": s.kappa}, None, 1e-10)
    []
    >>> same_work(held, "sweep", s.law, seed_parameters(), {"kappa": s.kappa}, None, 1e-9)
    ['rtol 1e-10 (asked 1e-09)']
    """
    differences = []
    if held["kind"] != kind:
        differences.append(f"kind {held['kind']!r}, not {kind!r}")
    if held["law"] != law.as_dict():
        differences.append(f"law {held['law']}, not {law.as_dict()}")
    elif held.get("law_source") != law.source:
        held_source = held.get("law_source") or "not recorded"
        differences.append(f"law {law.name!r}: its source changed (the archive's was {held_source}, now "
                           f"{law.source or 'a shipped law'}): the law file or functions were edited")
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
        differences.append(f"t_end {_t_end_text(held['t_end'])} (asked {_t_end_text(t_end)})")
    if not _same_number(held["rtol"], rtol):
        differences.append(f"rtol {held['rtol']!r} (asked {rtol!r})")
    return differences


def check_overwrite(path, kind: str, law: ContactLaw, params: Parameters, axes: dict, t_end, rtol, *,
                    force: bool = False, name: str = "out", settings: dict | None = None) -> None:
    """Refuse (``ValueError``) to replace ``path`` unless it is missing, or an archive of the same work
    (kind, law, parameters, axis values, ``t_end``, ``rtol`` and ``settings``), or ``force`` is set.

    The one rule of every command that writes an archive (``--out`` of ``sweep``, ``atlas``,
    ``critical-curve``, ``simulate``, ``transitions``; ``--archive`` of ``train``, ``orbit-diagram``,
    ``map-continuation``, ``basins``).

    Parameters
    ----------
    path : str or path-like
        The file a command would write.
    kind, law, params, axes, t_end, rtol
        The work asked for, as for :func:`same_work`. A critical curve's ``axes`` are the values asked
        for (the archive also holds its continuation's intermediate steps).
    force : bool, default False
        Allow any replacement (the command line's ``--force``).
    name : str, default "out"
        How the message names ``path`` (the command line's option).
    settings : dict, optional
        Compared too where given: a train result's, a run's or a transition search's settings as
        :func:`save` stores them (``period``, ``impacts``, ``rtol``, ``kappa_min``, ...), or a critical
        curve's ``{"what": ...}``.

    Raises
    ------
    ValueError
        For an existing file that is not an archive, a damaged archive, or an archive of other
        work (the message lists the differences).

    Examples
    --------
    >>> import os, tempfile
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import check_overwrite, save
    >>> from phaseimpact.continuation import sweep
    >>> s = sweep(seed_parameters(), "paper", [1e9, 1e13])
    >>> path = save(s, os.path.join(tempfile.mkdtemp(), "s.nc"))
    >>> check_overwrite(path, "sweep", s.law, seed_parameters(), {"kappa": s.kappa}, None, 1e-10)
    >>> check_overwrite(path, "sweep", s.law, seed_parameters(), {"kappa": s.kappa}, None, 1e-9)
    Traceback (most recent call last):
    ...
    ValueError: out = '...s.nc' holds other work (rtol 1e-10 (asked 1e-09)); refusing to overwrite it ...
    """
    path = os.fspath(path)
    if force or not os.path.exists(path):
        return
    try:
        held = describe(path)
        if held["kind"] == kind and settings is not None:
            held_settings = _retrying(_stored_settings, path)
            if kind == "critical-curve":
                curve = load(path)
                held["axes"] = {curve.param: np.asarray(curve.values)[np.asarray(curve.requested, dtype=bool)]}
    except _Refusal as error:  # an archive of a user law not defined here: not comparable, not damaged
        raise ValueError(f"{name} = {path!r} exists and cannot be compared ({error}); refusing to overwrite it "
                         "(choose another path, or add --force to replace it)") from None
    except DamagedArchiveError as error:
        raise ValueError(f"{name} = {path!r} exists and is a damaged phaseimpact archive ({error.reason}); refusing "
                         "to overwrite it (choose another path, or add --force to replace it)") from None
    except ValueError:
        raise ValueError(f"{name} = {path!r} exists and is not a phaseimpact archive; refusing to overwrite it "
                         "(choose another path, or add --force to replace it)") from None
    differences = same_work(held, kind, law, params, axes, t_end, rtol)
    if held["kind"] == kind and settings is not None:
        asked = json.loads(_json(settings))
        differences += [f"{key} {held_settings.get(key)!r} (asked {asked.get(key)!r})"
                        for key in sorted(set(asked) | set(held_settings)) if held_settings.get(key) != asked.get(key)]
    if differences:
        raise ValueError(f"{name} = {path!r} holds other work ({'; '.join(differences)}); refusing to overwrite it "
                         "(choose another path, or add --force to replace it)")


def _stored_settings(path: str) -> dict:
    """What identifies an archive's work beyond :func:`describe`: a train result's settings, a curve's ``what``."""
    with _reading(path) as f:
        if _attr_str(f, "kind") == "critical-curve":
            return {"what": _attr_str(f, "what")} if "what" in f.attrs else {}
        return _json_attr(f, "settings", dict) if "settings" in f.attrs else {}
