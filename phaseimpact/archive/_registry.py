"""The archive kinds: one :class:`ArchiveKind` record each, in :data:`REGISTRY`, by name.

:func:`~phaseimpact.archive.save`, :func:`~phaseimpact.archive.load`,
:func:`~phaseimpact.archive.describe`, :func:`~phaseimpact.archive.to_xarray` and
:func:`~phaseimpact.archive.kind_of` find a result's kind here (:func:`record_of`) or a file's by its
``kind`` attribute (:func:`record_named`); nothing else in the package lists the kinds' writers and
readers. The shipped kinds are registered by their family's module: ``sweep`` and ``atlas``
(:mod:`._grid`), ``critical-curve`` (:mod:`._curve`), ``trajectory`` and ``transitions``
(:mod:`._runs`), ``impact-train``, ``orbit-diagram``, ``map-branch`` and ``basins`` (:mod:`._trains`).

Adding an archive kind
----------------------
A kind is one record; the file's header (CF attributes, the case and law, ``created``), the
digests (``text_sha256``, ``data_sha256``), the atomic write, the checks on load and the
overwrite rule come with it.

1. Write ``write(f, result, created, context)``: the header first (:func:`._cf._header`, or
   :func:`._trains._train_header` for a result of one case and law given to ``save``), then the
   variables, made with :func:`._cf._coordinate` and :func:`._cf._variable` (units, flags, a
   Fletcher-32 checksum each). ``context`` (:class:`._common._Context`) holds the case, law and
   settings given to ``save``.
2. Write ``read(f, version)``: the result back from the open file, every array checked as it is read
   (:func:`._common._shaped`, :func:`._common._checked_codes`; a :class:`._common._Damaged` names
   what is wrong), then :func:`._digests._check_metadata` (the digests).
3. :func:`register_kind` an :class:`ArchiveKind`: its ``name`` (the ``kind`` attribute), ``holds``
   (whether a result is of this kind), the two functions, and optionally ``axes(f, version)`` (what
   :func:`~phaseimpact.archive.describe` and the overwrite rule compare), ``carries_case`` (the
   result holds its own case and law, as a sweep does: ``save`` then refuses ``params=``) and
   ``resumable`` (``--resume`` completes it).

For example (``tests/test_archive_registry.py`` runs it), a kind for a plain array of forces::

    import numpy as np
    from phaseimpact.archive import ArchiveKind, register_kind
    from phaseimpact.archive._cf import _header, _variable
    from phaseimpact.archive._common import _shaped
    from phaseimpact.archive._digests import _check_metadata

    class Forces(np.ndarray): ...          # the result type

    def write(f, result, created, context):
        _header(f, "forces", context.law, context.base, None, None, "", created, "phaseimpact forces")
        _variable(f, "force", np.asarray(result), ("sample",), long_name="contact force", units="N")

    def read(f, version):
        n = f["force"].shape[0]
        result = _shaped(f, "force", (n,)).view(Forces)
        _check_metadata(f)
        return result

    register_kind(ArchiveKind("forces", lambda r: isinstance(r, Forces), write, read))

``unregister_kind("forces")`` removes it again. A kind shipped with the package goes in its
family's module (or a new one imported by ``phaseimpact/archive/__init__.py``), with its name
added to :data:`~phaseimpact.archive.KINDS`, :data:`~phaseimpact.archive.RUN_KINDS` or
:data:`~phaseimpact.archive.TRAIN_KINDS` and its layout to the package docstring.
"""

from __future__ import annotations

import io
from collections.abc import Callable
from dataclasses import dataclass, replace

import h5py
import numpy as np

from ._common import _DATA_DIGEST, _LIBVER, _TEXT_DIGEST, _XARRAY_EXTRA, _Context, created_timestamp
from ._digests import _digests_text, _file_pieces, _texts_digest


@dataclass(frozen=True)
class ArchiveKind:
    """One archive kind: how a result of it is recognised, written, read back and described.

    Parameters
    ----------
    name : str
        The file's ``kind`` attribute (e.g. ``"sweep"``).
    holds : callable
        ``holds(result) -> bool``: whether ``result`` is of this kind.
    write : callable
        ``write(f, result, created, context)``: the header and variables into the open HDF5 file
        ``f`` (``created``: the ISO 8601 time; ``context``: the case, law and settings given to
        ``save``).
    read : callable
        ``read(f, version) -> result``: the result from the open file of schema ``version``, checked
        (its digests included).
    axes : callable, optional
        ``axes(f, version) -> {name: values}``: the axes that identify the work (``describe``);
        None: none.
    carries_case : bool, default False
        The result carries its case, law and settings (``save`` refuses ``params=``).
    resumable : bool, default False
        ``--resume`` completes an archive of this kind (:func:`~phaseimpact.archive.open_for_resume`).
    prepare : callable, optional
        ``prepare(result) -> layout``: checks and arranges the result before any file is opened (its
        errors come before anything is written); ``write`` finds it as ``context.layout``. A sweep's:
        its stick rows, each point's contiguous.

    Examples
    --------
    >>> from phaseimpact.archive import record_named
    >>> sweep = record_named("sweep")
    >>> sweep.resumable, sweep.carries_case, record_named("basins").resumable
    (True, True, False)
    """

    name: str
    holds: Callable[[object], bool]
    write: Callable[..., None]
    read: Callable[..., object]
    axes: Callable[..., dict] | None = None
    carries_case: bool = False
    resumable: bool = False
    prepare: Callable[[object], object] | None = None

    def fill(self, f, result, created: str, context: _Context) -> dict:
        """Write ``result`` into the open file ``f`` with its digests; return its datasets' piece digests
        (:func:`._digests._file_pieces`).

        Parameters
        ----------
        f : h5py.File
            Open for writing, empty.
        result : object
            Of this kind.
        created : str
            The ``created`` attribute (ISO 8601).
        context : _Context
            The case, law and settings given to ``save``.

        Returns
        -------
        dict
            ``{path: (dtype, shape, piece digests)}``.

        Examples
        --------
        >>> import io, h5py
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.archive import record_of
        >>> from phaseimpact.archive._common import _Context
        >>> from phaseimpact.continuation import critical_curve
        >>> curve = critical_curve(seed_parameters(), "paper", "v", [1.0])
        >>> with h5py.File(io.BytesIO(), "w") as f:
        ...     pieces = record_of(curve).fill(f, curve, "2026-01-01T00:00:00+00:00", _Context())
        ...     print(f.attrs["kind"], "kappa" in pieces)
        critical-curve True
        """
        self.write(f, result, created, context)
        pieces = _file_pieces(f)  # read back: the digests are of what the file holds
        f.attrs[_DATA_DIGEST] = np.bytes_(_digests_text(pieces).encode("ascii"))
        f.attrs[_TEXT_DIGEST] = _texts_digest(f)
        return pieces

    def to_xarray(self, result, context: _Context):
        """``result`` as the :class:`xarray.Dataset` of its archive, built in memory (no file written).

        Parameters
        ----------
        result : object
            Of this kind.
        context : _Context
            The case, law and settings (any of them None).

        Returns
        -------
        xarray.Dataset
            Loaded in memory.

        Raises
        ------
        ImportError
            Without xarray and h5netcdf (the message names the extra).

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.archive import record_of
        >>> from phaseimpact.archive._common import _Context
        >>> from phaseimpact.continuation import sweep
        >>> s = sweep(seed_parameters(), "paper", [1e9, 1e13])
        >>> record_of(s).to_xarray(s, _Context()).sizes["kappa"]
        2
        """
        try:
            import h5netcdf  # noqa: F401  (xarray's engine for the in-memory file)
            import xarray
        except ImportError as error:
            raise ImportError(f"to_xarray needs xarray and h5netcdf ({error}): {_XARRAY_EXTRA}") from None
        buffer = io.BytesIO()
        created = created_timestamp()
        if self.prepare is not None:
            context = replace(context, layout=self.prepare(result))
        with h5py.File(buffer, "w", libver=_LIBVER) as f:
            self.fill(f, result, created, context)
        buffer.seek(0)
        with xarray.open_dataset(buffer, engine="h5netcdf") as ds:
            ds = ds.load()
        for name in ds.coords:  # else to_netcdf gives a float coordinate _FillValue NaN, which CF forbids
            ds[name].encoding["_FillValue"] = None
        return ds


#: The archive kinds by name, in the order registered (a file's ``kind`` must be one of them).
REGISTRY: dict[str, ArchiveKind] = {}


def register_kind(record: ArchiveKind) -> ArchiveKind:
    """Add an archive kind (the module docstring's guide).

    Parameters
    ----------
    record : ArchiveKind
        Its name must not be registered already.

    Returns
    -------
    ArchiveKind
        ``record``.

    Raises
    ------
    TypeError
        For anything but an ArchiveKind.
    ValueError
        For a name already registered.

    Examples
    --------
    >>> from phaseimpact.archive import REGISTRY, register_kind
    >>> register_kind(REGISTRY["sweep"])
    Traceback (most recent call last):
    ...
    ValueError: archive kind 'sweep' is already registered; allowed: a new name
    """
    if not isinstance(record, ArchiveKind):
        raise TypeError(f"record has the wrong type ({type(record).__name__}); allowed: an ArchiveKind")
    if record.name in REGISTRY:
        raise ValueError(f"archive kind {record.name!r} is already registered; allowed: a new name")
    REGISTRY[record.name] = record
    return record


def unregister_kind(name: str) -> None:
    """Remove the archive kind ``name`` (a kind a test or session registered).

    Parameters
    ----------
    name : str
        A registered kind.

    Raises
    ------
    ValueError
        For a name not registered.

    Examples
    --------
    >>> from phaseimpact.archive import unregister_kind
    >>> unregister_kind("no-such-kind")
    Traceback (most recent call last):
    ...
    ValueError: archive kind 'no-such-kind' is not registered; allowed: one of sweep, atlas, ...
    """
    if name not in REGISTRY:
        raise ValueError(f"archive kind {name!r} is not registered; allowed: one of {', '.join(REGISTRY)}")
    del REGISTRY[name]


def record_named(name: str) -> ArchiveKind:
    """The record of the archive kind ``name``.

    Parameters
    ----------
    name : str
        A registered kind.

    Returns
    -------
    ArchiveKind
        Its record.

    Raises
    ------
    ValueError
        For a name not registered.

    Examples
    --------
    >>> from phaseimpact.archive import record_named
    >>> record_named("basins").carries_case
    False
    """
    if name not in REGISTRY:
        raise ValueError(f"archive kind {name!r} is not registered; allowed: one of {', '.join(REGISTRY)}")
    return REGISTRY[name]


def record_of(result) -> ArchiveKind | None:
    """The record of the kind that holds ``result``; None when no kind does.

    Parameters
    ----------
    result : object
        What would be archived.

    Returns
    -------
    ArchiveKind or None
        The first registered kind whose ``holds`` accepts it.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import record_of
    >>> from phaseimpact.continuation import sweep
    >>> record_of(sweep(seed_parameters(), "paper", [1e9])).name, record_of("text")
    ('sweep', None)
    """
    return next((record for record in REGISTRY.values() if record.holds(result)), None)
