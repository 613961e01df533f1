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
contents (:func:`._digests._dataset_digest`), checked by :func:`load`; a file written before it, killed while a
checkpoint wrote in place, or copied by another netCDF writer (xarray), loads unverified by it.
:func:`load` and :func:`describe` also check the
content (codes within their tables, finite axes, scalar attributes; :func:`load`: a finite
``max_force`` where a run succeeded, counts >= -1 at computed points) and refuse a damaged file with a
:class:`DamagedArchiveError` (a ``ValueError``) that names it and the damage; what a checkpoint
in progress leaves at points not yet committed and in unused stick rows is not damage.

The package, bottom up: :mod:`._common` (constants, errors, checked attribute readers), :mod:`._cf`
(CF names, units, variables, the header), :mod:`._digests`, :mod:`._files` (disk space, opening for
reading), :mod:`._registry` (the archive kinds, one record each; its docstring says how to add one),
one module per result family registering its kinds (:mod:`._grid`, :mod:`._curve`, :mod:`._runs`,
:mod:`._trains`; :mod:`._legacy` reads schemas 1 and 2), :mod:`._io` (``save``, ``load``,
``describe``, ``to_xarray``), :mod:`._checkpoint` and :mod:`._overwrite` (the overwrite rule and
``open_for_resume``). None imports this face.
"""


from __future__ import annotations

# isort: off
# the families first, in the order of the kinds (KINDS, RUN_KINDS, TRAIN_KINDS): each registers its own
from . import _grid  # noqa: F401
from . import _curve  # noqa: F401
from . import _runs  # noqa: F401
from . import _trains  # noqa: F401
# isort: on
from ._cf import axis_units as axis_units
from ._cf import kappa_units as kappa_units
from ._cf import netcdf_name as netcdf_name
from ._cf import unit_attributes
from ._checkpoint import Checkpoint
from ._common import (
    CHUNK_POINTS,
    KINDS,
    RUN_KINDS,
    SCHEMA_VERSION,
    TRAIN_KINDS,
    TRANSITION_KINDS,
    DamagedArchiveError,
    created_timestamp,
)
from ._common import CONVENTIONS as CONVENTIONS
from ._figure_data import save_h5
from ._grid import stick_phases
from ._io import describe, kind_of, load, save, to_xarray
from ._overwrite import check_overwrite, open_for_resume, same_work
from ._registry import REGISTRY, ArchiveKind, record_named, record_of, register_kind, unregister_kind

__all__ = ["SCHEMA_VERSION", "KINDS", "TRAIN_KINDS", "RUN_KINDS", "TRANSITION_KINDS",
           "CHUNK_POINTS", "Checkpoint", "save", "load", "describe", "same_work",
           "check_overwrite", "open_for_resume", "kind_of", "created_timestamp", "DamagedArchiveError", "to_xarray",
           "stick_phases", "unit_attributes", "ArchiveKind", "REGISTRY", "register_kind", "unregister_kind",
           "record_named", "record_of", "save_h5"]

for _name in __all__:  # the public face names them (reprs, pickles, help): phaseimpact.archive.save
    if callable(globals()[_name]):
        globals()[_name].__module__ = __name__
del _name
