"""A full disk and other write errors: one line naming the path and the error, exit 1, the last
complete checkpoint kept, no crash, no lock or temporary file left; non-regular files (FIFO,
device) refused as ``--out`` and as an archive to read, exit 2, before any work.

HDF5 never meets the full disk: :func:`phaseimpact.archive._files._reserve` allocates an archive's blocks
before HDF5 writes into them. HDF5 that met it (before this) left objects it could not close,
printed a traceback from each finalizer and crashed when the interpreter exited (rc 139). The
errors are injected here; a real 2 MiB tmpfs is used too where this process may mount one.
"""

from __future__ import annotations

import contextlib
import errno
import importlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from _cli import run

from phaseimpact import _atomic, archive, seed_parameters
from phaseimpact.archive import _files
from phaseimpact.continuation import sweep
from phaseimpact.model import ContactLaw

CLI = [sys.executable, "-m", "phaseimpact.cli"]
SWEEP = ["sweep", "--law", "paper", "--v", "1", "--no-progress"]


def kappas(num: int) -> list[str]:
    return ["--axis", f"kappa=1e9:1e14:{num}:log"]




def full_disk(*args, **kwargs):
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


@pytest.fixture(scope="module")
def small_sweep():
    return sweep(seed_parameters(), ContactLaw("paper"), np.geomspace(1e9, 1e14, 8))


def test_save_on_a_full_disk_names_the_path_and_keeps_the_previous_file(tmp_path, small_sweep, monkeypatch):
    path = tmp_path / "s.h5"
    archive.save(small_sweep, path)
    before = path.read_bytes()
    monkeypatch.setattr(_files, "reserve", full_disk)
    with pytest.raises(OSError) as raised:
        archive.save(small_sweep, path, force=True)
    assert raised.value.errno == errno.ENOSPC and raised.value.filename == str(path)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.h5"]  # no lock, no temporary file


def test_reserving_changes_no_byte_of_an_archive(tmp_path, small_sweep, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")  # one time stamp, whatever second each is made in
    reserved = tmp_path / "reserved.h5"
    archive.save(small_sweep, reserved)
    monkeypatch.setattr(_files, "reserve", lambda fd, end: None)
    plain = tmp_path / "plain.h5"
    archive.save(small_sweep, plain)
    assert reserved.read_bytes() == plain.read_bytes()


def test_a_sweep_whose_disk_fills_after_its_first_checkpoint_exits_1_and_keeps_it(tmp_path, monkeypatch):
    monkeypatch.setattr(importlib.import_module("phaseimpact.continuation.sweep"), "CHUNK_THREADS", 4)
    path = tmp_path / "s.h5"
    real = _files.reserve

    def fills_once_the_archive_exists(fd, end):  # the first checkpoint fits, the final save does not
        if path.exists():
            full_disk()
        real(fd, end)

    monkeypatch.setattr(_files, "reserve", fills_once_the_archive_exists)
    code, _, err = run([*SWEEP, *kappas(40), "--jobs", "1", "--out", path])
    assert code == 1, err
    assert err.strip() == f"phaseimpact: error: [Errno 28] No space left on device: {str(path)!r}"
    done = archive.load(path).done
    assert 0 < np.count_nonzero(done) <= done.size  # the last checkpoint, complete
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.h5"]


def test_a_lock_that_cannot_be_written_is_not_left_behind(tmp_path, monkeypatch):
    path = tmp_path / "s.h5"
    monkeypatch.setattr(_atomic.os, "write", full_disk)
    with pytest.raises(OSError) as raised, _atomic.exclusive(path):
        pass
    assert raised.value.errno == errno.ENOSPC and raised.value.filename == str(path)
    assert list(tmp_path.iterdir()) == []


def test_an_hdf5_write_failure_reads_as_the_os_error():
    message = ("Unable to synchronously create dataset (file write failed: time = Wed Nov 25 00:37:42 2026\n, "
               "filename = '/tmp/full/.a.h5.12510-x3ss8twg.tmp', file descriptor = 6, errno = 28, error message = "
               "'No space left on device', buf = 0x55f33168d0f5, total write size = 6815)")
    error = _files._as_disk_error(ValueError(message))
    assert isinstance(error, OSError) and error.errno == errno.ENOSPC
    assert _files._as_disk_error(ValueError("Unable to synchronously open object (not found)")) is None


# ------------------------------------------------------------------------------------------------
# A real full disk (a 2 MiB tmpfs; needs the right to mount one)
# ------------------------------------------------------------------------------------------------

@pytest.fixture
def tiny_disk(tmp_path):
    mount = tmp_path / "disk"
    mount.mkdir()
    if shutil.which("mount") is None or os.geteuid() != 0:
        pytest.skip("mounting a 2 MiB tmpfs needs root")
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(mount)], capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.decode().strip()}")
    try:
        yield mount
    finally:
        subprocess.run(["umount", str(mount)], check=False)


def _cli(*args, cwd):
    return subprocess.run([*CLI, *map(str, args)], capture_output=True, text=True, timeout=600, cwd=cwd)


def _said(stderr: str) -> str:
    """stderr without the note of a first compile (a fresh numba cache)."""
    return "\n".join(line for line in stderr.strip().splitlines() if not line.startswith("phaseimpact: compiling"))


def test_a_sweep_filling_a_real_disk_ends_in_one_line_and_keeps_its_checkpoint(tiny_disk):
    path = tiny_disk / "s.h5"
    done = _cli(*SWEEP, *kappas(8000), "--jobs", "1", "--out", path, cwd=tiny_disk)
    assert done.returncode == 1, done.stderr  # not 139: no crash inside HDF5
    assert _said(done.stderr) == f"phaseimpact: error: [Errno 28] No space left on device: {str(path)!r}"
    assert sorted(p.name for p in tiny_disk.iterdir()) == ["s.h5"]  # no lock, no temporary file
    kept = archive.load(path).done
    assert 0 < np.count_nonzero(kept) < kept.size


def test_commands_on_a_disk_already_full_name_the_path_and_leave_no_lock(tiny_disk, tmp_path):
    archive_path = tmp_path / "s.h5"
    archive.save(sweep(seed_parameters(), ContactLaw("paper"), np.geomspace(1e9, 1e14, 8)), archive_path)
    (tiny_disk / "filler").write_bytes(b"")
    with open(tiny_disk / "filler", "wb") as filler, contextlib.suppress(OSError):
        while True:
            filler.write(b"\0" * 65536)
            filler.flush()
    for argv, out in ((["plot", archive_path], "p.png"), ([*SWEEP, *kappas(20)], "s.h5")):
        done = _cli(*argv, "--out", tiny_disk / out, cwd=tmp_path)
        assert done.returncode == 1, done.stderr
        named = str(tiny_disk / out)
        assert _said(done.stderr) == f"phaseimpact: error: [Errno 28] No space left on device: {named!r}"
        assert sorted(p.name for p in tiny_disk.iterdir()) == ["filler"]


#: A checkpoint of a 40,000-point sweep (about 5 MB): on a 2 MiB tmpfs it fails part way, with 1.0-1.3 MB free.
_CHECKPOINT_40000 = """
import errno, sys
import numpy as np
from phaseimpact import archive, seed_parameters
from phaseimpact.continuation import SweepResult
from phaseimpact.continuation.grid import Axis, Grid
from phaseimpact.model import ContactLaw
grid = Grid(seed_parameters(), ContactLaw("paper"), (Axis("kappa", np.geomspace(1e9, 1e14, 40000), True),))
try:
    archive.Checkpoint(sys.argv[1])(SweepResult(grid, None, {"rtol": 1e-10}))
except OSError as error:
    sys.exit(3 if error.errno == errno.ENOSPC else 4)
"""


@pytest.mark.parametrize("filler_kib", [950, 1000, 1040])
def test_a_checkpoint_meeting_a_full_disk_part_way_raises_and_does_not_crash(tiny_disk, filler_kib):
    """The audit's segfault (rc 139 with 1.0-1.3 MB free): a reservation that fails on tmpfs gives back
    the room kept for the file's close, whose writes then failed inside HDF5. The file is emptied before
    it is closed: ENOSPC, nothing left behind."""
    (tiny_disk / "filler").write_bytes(b"\0" * (filler_kib * 1024))
    done = subprocess.run([sys.executable, "-c", _CHECKPOINT_40000, str(tiny_disk / "s.nc")], capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 3, (done.returncode, done.stderr[-2000:])  # ENOSPC raised; not 139
    assert sorted(p.name for p in tiny_disk.iterdir()) == ["filler"]


# ------------------------------------------------------------------------------------------------
# Non-regular files
# ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("argv", [[*SWEEP, *kappas(5), "--out", "{fifo}"],
                                  ["critical-curve", "--axis", "v=0.5:1:2:log", "--out", "{fifo}"],
                                  ["plot", "{fifo}", "--out", "{dir}/p.png"],
                                  ["plot", "{archive}", "--out", "{fifo_png}"],
                                  [*SWEEP, *kappas(5), "--out", "/dev/null"]])
def test_a_fifo_or_a_device_is_refused_before_any_work(tmp_path, small_sweep, argv):
    fifo, fifo_png = tmp_path / "f.h5", tmp_path / "f.png"
    os.mkfifo(fifo)
    os.mkfifo(fifo_png)
    archive_path = tmp_path / "s.h5"
    archive.save(small_sweep, archive_path)
    words = [w.format(fifo=fifo, fifo_png=fifo_png, dir=tmp_path, archive=archive_path) for w in argv]
    done = _cli(*words, cwd=tmp_path)  # a FIFO opened for writing or reading waits: the timeout says it hung
    named = str(fifo) if "{fifo}" in argv else str(fifo_png) if "{fifo_png}" in argv else "/dev/null"
    assert done.returncode == 2, done.stderr
    assert len(_said(done.stderr).splitlines()) == 1 and repr(named) in done.stderr
    assert "not a regular file" in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.h5", "f.png", "s.h5"]  # no lock, no temporary file
    assert not Path("/dev/null.lock").exists()


def test_a_case_file_that_is_a_fifo_is_refused(tmp_path):
    fifo = tmp_path / "case.toml"
    os.mkfifo(fifo)
    done = _cli("params", "--case", str(fifo), cwd=tmp_path)  # reading a FIFO would wait: the timeout says it hung
    assert done.returncode == 2, done.stderr
    assert "not a regular file" in done.stderr and str(fifo) in done.stderr
