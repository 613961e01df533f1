"""Write a file so that readers only ever see the old or the complete new version, one writer at a time.

Two pieces, used together by :func:`atomic_path`:

* :func:`exclusive` holds an advisory lock (``fcntl.flock`` on a sidecar ``PATH.lock``; a name too long
  for that is shortened with a digest) for as long as a writer owns ``PATH``. It never waits: a second
  writer gets :class:`PathLockedError` (a ``ValueError``) naming the holder's process id. It is
  re-entrant within one process, so a command can hold it for a whole sweep while each checkpoint's
  :func:`atomic_path` takes it again.
* :func:`atomic_path` writes to a temporary file beside ``PATH`` (named with the writer's process
  id), fsyncs it and renames it over ``PATH``. Temporary files of earlier writers are removed only
  when their process is dead, and only by the lock holder, so a live writer's file is never touched.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import fcntl
import glob
import hashlib
import os
import re
import stat
import tempfile

__all__ = ["PathLockedError", "atomic_path", "exclusive", "check_target", "fsync_file", "fsync_folder", "reserve",
           "release_reserve"]


class PathLockedError(ValueError):
    """Another process is writing the same path."""


_WRITABLE = "allowed: a file path in a folder this process can write"
#: Locks held by this process: absolute path -> [file descriptor, depth].
_HELD: dict[str, list] = {}


#: The longest file name most file systems take (bytes): a sidecar name must fit too.
_NAME_MAX = 255


def _sidecar_stem(name: str, room: int) -> str:
    """``name``, or, when a sidecar made of it would not fit in :data:`_NAME_MAX` (``room`` bytes are
    added), its start and a digest of the whole: the same for every writer of the name, distinct for
    distinct names."""
    if len(os.fsencode(name)) + room <= _NAME_MAX:
        return name
    digest = hashlib.sha256(os.fsencode(name)).hexdigest()[:16]
    keep = os.fsencode(name)[:_NAME_MAX - room - len(digest) - 1].decode("utf-8", "ignore")
    return f"{keep}-{digest}"


def _lock_path(path: str) -> str:
    folder, name = os.path.split(path)
    return os.path.join(folder, _sidecar_stem(name, len(".lock")) + ".lock")


def _holder(lock_file: str) -> str:
    try:
        with open(lock_file, encoding="ascii") as handle:
            pid = handle.read().strip()
    except OSError:
        pid = ""
    return pid if pid.isdigit() else "unknown"


def check_target(path, name: str = "out") -> str:
    """Check, without writing anything, that ``path`` can become a file; return it as ``str``.

    Raises ``ValueError`` naming ``name`` for an empty path, an existing folder, an existing file that
    is not a regular file (a FIFO or device: opening it would wait or write elsewhere), a path below
    a regular file, or a folder this process may not write in.
    """
    path = os.fspath(path)
    if not isinstance(path, str) or not path.strip():
        raise ValueError(f"{name} = {path!r} is out of range; allowed: a file path such as results.h5")
    if os.path.isdir(path):
        raise ValueError(f"{name} = {path!r} is a folder; allowed: a file path (e.g. {os.path.join(path, 'sweep.h5')})")
    try:
        mode = os.stat(path).st_mode
    except OSError:
        mode = None  # nothing there yet (or nothing readable: the checks below say what)
    if mode is not None and not stat.S_ISREG(mode):
        raise ValueError(f"{name} = {path!r} is not a regular file (a FIFO, device or socket); allowed: a path "
                         "to a new or a regular file")
    folder = os.path.dirname(os.path.abspath(path))
    existing = folder
    while not os.path.exists(existing):
        existing = os.path.dirname(existing)
    if not os.path.isdir(existing):
        raise ValueError(f"{name} = {path!r} is out of range: {existing!r} is a file, not a folder; {_WRITABLE}")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise ValueError(f"{name} = {path!r} is out of range: the folder {existing!r} is not writable; {_WRITABLE}")
    return path


@contextlib.contextmanager
def exclusive(path, name: str = "out"):
    """Hold the write lock of ``path`` (sidecar ``PATH.lock``) for the ``with`` block; never wait.

    Raises :class:`PathLockedError` if another process holds it, ``ValueError`` if the lock
    file cannot be created (read-only folder, a path below a file...). Missing folders are created.
    """
    path = check_target(path, name)
    key = os.path.abspath(path)
    if key in _HELD:
        _HELD[key][1] += 1
        try:
            yield path
        finally:
            _HELD[key][1] -= 1
        return
    lock_file = _lock_path(key)
    try:
        os.makedirs(os.path.dirname(key), exist_ok=True)
    except OSError as error:
        raise ValueError(f"{name} = {path!r} cannot be written: cannot create its folder: "
                         f"{error.strerror or error}; {_WRITABLE}") from None
    while True:
        try:
            fd = os.open(lock_file, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as error:
            raise ValueError(f"{name} = {path!r} cannot be written: {error.strerror or error} "
                             f"({lock_file!r}); {_WRITABLE}") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as error:
            os.close(fd)
            if error.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise PathLockedError(f"{path} is being written by another phaseimpact process "
                                      f"(pid {_holder(lock_file)})") from None
            raise ValueError(f"{name} = {path!r}: cannot lock {lock_file!r}: {error.strerror or error}") from None
        # The previous holder unlinks the lock file before releasing it: make sure we locked the
        # file that is on disk now, not one that was removed between our open and our flock.
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(lock_file))
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    try:
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode("ascii"))
    except OSError as error:  # a full disk: nothing can be written, not even the lock's pid
        with contextlib.suppress(OSError):
            os.remove(lock_file)
        os.close(fd)
        raise OSError(error.errno, error.strerror, path) from None
    _HELD[key] = [fd, 1]
    try:
        yield path
    finally:
        _HELD[key][1] -= 1
        if _HELD[key][1] == 0:
            del _HELD[key]
            with contextlib.suppress(OSError):
                os.remove(lock_file)
            os.close(fd)  # releases the lock


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def _remove_dead_writers_temps(folder: str, prefix: str) -> None:
    """Remove ``prefix<pid>-*.tmp`` files whose writer process is gone (caller holds the lock)."""
    pattern = re.compile(re.escape(prefix) + r"(\d+)-[^/]*\.tmp\Z")
    for stale in glob.glob(os.path.join(glob.escape(folder), glob.escape(prefix) + "*.tmp")):
        match = pattern.match(os.path.basename(stale))
        if match and not _alive(int(match.group(1))):
            with contextlib.suppress(FileNotFoundError):
                os.remove(stale)


@contextlib.contextmanager
def atomic_path(path, name: str = "path"):
    """Yield a temporary path beside ``path``; on success fsync it and rename it over ``path``.

    The write lock of ``path`` is held throughout (see :func:`exclusive`; a second writer gets
    :class:`PathLockedError`). On any error (or interruption) the temporary file is removed and
    ``path`` is untouched. The file gets the permissions an ordinary ``open(path, "w")`` would
    give it. Temporary files left by earlier writers of ``path`` that were killed (SIGKILL skips
    all clean-up) are removed first: only those whose process is dead.
    """
    with exclusive(path, name) as path:
        folder = os.path.dirname(os.path.abspath(path))
        # with the pid, mkstemp's 8 characters and ".tmp" (see _remove_dead_writers_temps)
        prefix = f".{_sidecar_stem(os.path.basename(path), 32)}."
        _remove_dead_writers_temps(folder, prefix)
        fd, tmp = tempfile.mkstemp(prefix=f"{prefix}{os.getpid()}-", suffix=".tmp", dir=folder)
        os.close(fd)
        try:
            yield tmp
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)
            with open(tmp, "rb+") as handle:
                os.fsync(handle.fileno())
            os.replace(tmp, path)
            fsync_folder(folder)  # the rename itself survives a power cut
        except BaseException as error:
            if os.path.exists(tmp):
                os.remove(tmp)
            if isinstance(error, OSError) and error.errno is not None and error.filename in (None, tmp):
                # a full disk or a failing write: name the file the user asked for, not our temporary one
                raise OSError(error.errno, error.strerror or str(error), path) from None
            raise


def fsync_folder(folder: str) -> None:
    """fsync a folder, so that a rename in it is on disk (a no-op where folders cannot be opened)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def fsync_file(h5file) -> None:
    """fsync an open HDF5 file (an ``h5py.File`` or its low-level ``FileID``) after its flush, so that
    what HDF5 wrote is on disk before anything written after it."""
    import h5py

    fid = h5file.id if isinstance(h5file, h5py.File) else h5file
    os.fsync(fid.get_vfd_handle())


_FALLOC_FL_KEEP_SIZE = 1
_fallocate = getattr(ctypes.CDLL(None, use_errno=True), "fallocate", None)
if _fallocate is not None:
    _fallocate.argtypes = (ctypes.c_int, ctypes.c_int, ctypes.c_int64, ctypes.c_int64)


def reserve(fd: int, end: int) -> None:
    """Allocate the disk blocks of bytes ``0 .. end`` of the open file ``fd`` without changing its
    size (``fallocate(FALLOC_FL_KEEP_SIZE)``), so that a full disk shows here, as an ``OSError``
    (ENOSPC), and not in the middle of a library's later writes into that range. A no-op where the
    system or the file system has no such call."""
    if _fallocate is None or end <= 0:
        return
    if _fallocate(fd, _FALLOC_FL_KEEP_SIZE, 0, end) != 0:
        code = ctypes.get_errno()
        if code in (errno.EOPNOTSUPP, errno.ENOSYS, errno.EINVAL, errno.ENODEV, errno.ESPIPE):
            return
        raise OSError(code, os.strerror(code))


def release_reserve(path: str) -> None:
    """Give back the blocks :func:`reserve` allocated beyond the end of the closed file ``path``
    (a shrinking truncate frees every block past the new end; the bytes stay the same)."""
    size = os.path.getsize(path)
    with contextlib.suppress(OSError):
        os.truncate(path, size + 1)
        os.truncate(path, size)
