"""The entry points over the registry: :func:`save`, :func:`load`, :func:`describe`,
:func:`to_xarray` and :func:`kind_of` find the kind's record (:mod:`._registry`) and leave the
layout to it; the atomic write, the header checks and the retries are here, once for every kind."""

from __future__ import annotations

import contextlib
import os
from dataclasses import replace

import h5py

from .._atomic import atomic_path, release_reserve
from ..continuation.grid import Grid
from ..integrate.result import Trajectory
from ..parameters import Parameters
from ._common import (
    _LIBVER,
    SCHEMA_VERSION,
    _attr_str,
    _base_parameters,
    _Context,
    _Damaged,
    _int_attr,
    _json_attr,
    _law,
    _law_source,
    _real_attr,
    _Refusal,
    created_timestamp,
)
from ._digests import _check_metadata
from ._files import _archive_path, _as_disk_error, _is_archive, _reading, _reserve, _retrying
from ._registry import REGISTRY, ArchiveKind, record_named, record_of


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
        One of :data:`KINDS`, :data:`RUN_KINDS` or :data:`TRAIN_KINDS` (or a kind added with
        :func:`~phaseimpact.archive.register_kind`).

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
    if isinstance(result, Grid):  # the grid of a sweep or atlas to come
        return "sweep" if len(result.axes) == 1 else "atlas"
    record = record_of(result)
    if record is None:
        raise TypeError(f"cannot archive a {type(result).__name__}")
    return record.name


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
    record = _record(result, "archive")
    context = _context(record, result, params, law, settings, required=True)
    _write_file(record, result, os.fspath(path), force=force, spare_rows=0, context=context)
    return os.fspath(path)


def _record(result, verb: str) -> ArchiveKind:
    """The record of ``result``'s kind, or the TypeError of :func:`save` (``verb`` "archive") and
    :func:`to_xarray` ("convert")."""
    record = record_of(result)
    if record is None:
        raise TypeError(f"cannot {verb} a {type(result).__name__}; allowed: a SweepResult or a CriticalCurve, a "
                        "Trajectory, a list of Transition, or an ImpactTrain, OrbitDiagram, MapBranch or Basins")
    return record


def _write_file(record: ArchiveKind, result, path: str, *, force: bool, spare_rows: int, context: _Context):
    """Write a whole archive atomically; a sweep's stick variables get ``spare_rows`` free rows.
    Returns the sweep's per-point ``(stick_first, stick_count, piece digests)`` (None for another kind)."""
    created = created_timestamp()  # a bad SOURCE_DATE_EPOCH is refused before anything is written
    layout = None if record.prepare is None else record.prepare(result)
    context = replace(context, layout=layout, spare_rows=spare_rows)
    with atomic_path(path, "path") as tmp:
        if not force and os.path.isfile(path) and not _is_archive(path):
            raise ValueError(f"path = {path!r} exists and is not a phaseimpact archive; refusing to replace it "
                             "(force=True replaces it)")
        try:
            with h5py.File(tmp, "w", libver=_LIBVER) as f:
                fd = f.id.get_vfd_handle()
                try:
                    _reserve(f, 0)  # the header, attributes and small datasets
                    pieces = record.fill(f, result, created, context)
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
    record = _record(result, "convert")
    return record.to_xarray(result, _context(record, result, params, law, settings, required=False))


def _context(record: ArchiveKind, result, params, law, settings, *, required: bool) -> _Context:
    """The context of a result that does not carry its case (``required``: an archive needs its case and
    law); a result that carries them (a sweep, a curve) takes none, a trajectory its Case and settings only."""
    from ..case import Case
    from ..model import as_law

    given = params is not None or law is not None or settings is not None
    if record.carries_case:
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
    known = tuple(REGISTRY)
    if kind not in known:
        raise _Damaged(f"attribute kind = {kind!r} is out of range; allowed: one of {', '.join(known)}")
    return version


def _check_law_defined(f, path: str) -> None:
    """Refuse, as what it is, an archive of a user law not defined in this process (not damage):
    its results need the law's entry (name, units). A case that records its law file defines it
    (the file is run, as :func:`._common._base` would)."""
    from ..model import LAWS
    from ..model import REGISTRY as DEFINED_LAWS

    name = _json_attr(f, "law", dict).get("name")
    if not isinstance(name, str) or name in DEFINED_LAWS or name in LAWS:
        return  # a shipped law's, a defined one's, or damage that the readers name
    impact = _json_attr(f, "case", dict).get("impact") if "case" in f.attrs else None
    law_file = impact.get("law_file") if isinstance(impact, dict) else None
    if isinstance(law_file, str) and os.path.isfile(law_file):
        from ..model.userlaw import load_law_file

        try:
            load_law_file(law_file)
        except ValueError as error:
            raise _Refusal(f"{path!r} holds work of law {name!r}, a user law of the case's law file, which fails: "
                           f"{error}") from None
        if name in DEFINED_LAWS:
            return
    raise _Refusal(f"{path!r} holds work of law {name!r}, a user law: define it first (--law-file FILE, or "
                   "phaseimpact.define_law in Python)")


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
        return record_named(_attr_str(f, "kind")).read(f, version)


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
    with _reading(path) as f:
        version = _checked_header(f, path)
        _check_law_defined(f, path)
        kind = _attr_str(f, "kind")
        law = _law(f).as_dict()
        law_source = _law_source(f)
        params = _json_attr(f, "parameters", dict)
        record = record_named(kind)
        axes = {} if record.axes is None else record.axes(f, version)
        if version >= 3:
            _check_metadata(f, data=False)
        return {"kind": kind, "law": law, "law_source": law_source, "parameters": params, "axes": axes,
                "t_end": _real_attr(f, "t_end"), "rtol": _real_attr(f, "rtol"), "schema_version": version}
