"""Files on disk: fixed-size datasets whose blocks are reserved before HDF5 writes them (a full disk
is an ``OSError`` before any HDF5 write, never a crash inside it), HDF5 write errors as ``OSError``,
opening an archive for reading (every error of a read becomes a :class:`DamagedArchiveError`) and
reads tried again after a checksum failure (a reader may catch a checkpoint writing)."""

from __future__ import annotations

import contextlib
import os
import re
import stat
import time

import h5py
import numpy as np

from .._atomic import reserve
from ._cf import _fill_of
from ._common import _CHECKED, _LONG_NAMES, DamagedArchiveError, _Damaged, _netcdf_writer, _Refusal, _short


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


def _stamp(path):
    st = os.stat(path)
    return st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns


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
    discarded: :func:`._io._write_file`). An archive built in memory
    (:func:`~phaseimpact.archive.to_xarray`) has no disk to reserve."""
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
