"""Checkpoints of a growing sweep or atlas written in place, in the crash-safe order of the package
docstring (:class:`Checkpoint`), through HDF5's low-level API (:class:`_Raw`)."""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass

import h5py
import numpy as np

from .._atomic import exclusive, fsync_file
from ..continuation import SweepResult
from ..integrate import driver as _driver
from ._common import (
    _AXIS_DIMENSIONS,
    _DATA_DIGEST,
    _DIGEST_PIECE,
    _IN_PROGRESS,
    CHUNK_POINTS,
    SCHEMA_VERSION,
    _attr_str,
    _base_attrs,
    _Context,
    _Damaged,
    _json,
    _law_source,
    _same_number,
)
from ._digests import _dataset_digest, _digest, _digests_text, _file_pieces, _piece_digests, _stored_digests
from ._files import _is_archive, _stamp
from ._grid import _STICK_VARIABLES, _owned_rows
from ._io import _write_file, kind_of
from ._registry import record_of


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
        first, count, pieces = _write_file(record_of(r), r, self.path, force=self.force, spare_rows=spare,
                                           context=_Context())
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
