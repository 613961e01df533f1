"""Damaged archives: every chunk carries a Fletcher-32 checksum, the metadata HDF5 does not checksum is
checked on load, and the content too (codes in range, finite axes, scalar attributes). ``load``,
``plot`` and ``--resume`` refuse a damaged archive naming the file and the damage (ValueError; exit 2
on the command line: the input is unusable, nothing failed to compute), and never carry it forward.
A fuzz of small real archives (byte flips, truncation, attribute and value changes) ends in a valid
result or a ValueError naming the file, never another exception or silently changed numbers."""

import contextlib
import io
import json
import os
import re
import subprocess
import sys

import h5py
import numpy as np
import pytest

from phaseimpact import archive, seed_parameters
from phaseimpact.archive import _digests, _files, _io
from phaseimpact.cli import main
from phaseimpact.continuation import CriticalCurve, SweepResult, atlas, critical_curve, sweep
from phaseimpact.integrate import OUTCOMES, STATUSES
from phaseimpact.integrate import driver as _driver

KAPPAS = np.geomspace(1e9, 1e14, 6)
SWEEP_ARGS = ["sweep", "--law", "paper", "--v", "1", "--axis", "kappa=1e9:1e14:6:log",
              "--no-progress"]


def run(argv):
    """``main(argv)`` in-process: (exit code, stderr)."""
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            code = main([str(a) for a in argv])
        except SystemExit as exit_:
            code = exit_.code
    return code, err.getvalue()


@pytest.fixture(scope="module")
def results():
    """A sweep (6 points), an atlas (3 x 2) and a critical curve (2 values): small real results."""
    return {"sweep": sweep(seed_parameters(), "paper", KAPPAS),
            "atlas": atlas(seed_parameters(), "paper", {"kappa": [1e11, 1.5e12, 1e13], "v": [1.0, 2.0]}),
            "curve": critical_curve(seed_parameters(), "paper", "v", [1.0, 2.0])}


@pytest.fixture(scope="module")
def files(results, tmp_path_factory):
    folder = tmp_path_factory.mktemp("archives")
    return {name: archive.save(result, folder / f"{name}.h5") for name, result in results.items()}


@pytest.fixture(autouse=True)
def no_retry_pauses(monkeypatch):
    """A read that fails a checksum is retried after pauses (a reader racing a checkpoint); not here."""
    monkeypatch.setattr(_files, "_RETRY_PAUSES", ())


def copy(src, dst) -> str:
    with open(src, "rb") as a, open(dst, "wb") as b:
        b.write(a.read())
    return os.fspath(dst)


def _names(f) -> list:
    names = []
    f.visititems(lambda name, node: names.append(name) if isinstance(node, h5py.Dataset) else None)
    return names


def chunks_of(path) -> list:
    """(name, byte offset, size) of every chunk of every dataset."""
    out = []
    with h5py.File(path, "r") as f:
        def visit(name, node):
            if isinstance(node, h5py.Dataset) and node.chunks is not None:
                node.id.chunk_iter(lambda info: out.append((name, info.byte_offset, info.size)))
        f.visititems(visit)
    return out


# ------------------------------------------------------------------------------------------------
# Checksums: on every dataset, read by h5py, xarray (h5netcdf, netCDF4 if installed)
# ------------------------------------------------------------------------------------------------

def test_every_data_variable_is_chunked_with_a_checksum(files):
    for path in files.values():
        with h5py.File(path, "r") as f:
            with_data = [f[name] for name in _names(f) if f[name].id.get_storage_size() > 0]
            assert with_data and all(d.fletcher32 and d.chunks for d in with_data), path
            assert "text_sha256" in f.attrs


@pytest.mark.parametrize("engine", ["h5netcdf", "netcdf4"])
def test_xarray_reads_the_checksummed_archives(files, results, engine):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf" if engine == "h5netcdf" else "netCDF4")
    with xr.open_dataset(files["atlas"], engine=engine) as ds:
        assert np.array_equal(ds.max_force.values.ravel(), results["atlas"].max_force)
        assert ds.max_force.encoding["fletcher32"] and ds.attrs["kind"] == "atlas"
    with xr.open_dataset(files["curve"], engine=engine) as ds:
        assert np.array_equal(ds.kappa.values, results["curve"].kappa, equal_nan=True)


def test_a_chunk_overwritten_with_0xff_is_refused_by_load_plot_and_resume(tmp_path, files):
    """The audit's corrupt_data.h5: max_force's chunk overwritten loaded as all-NaN and plotted."""
    path = copy(files["sweep"], tmp_path / "s.h5")
    _, offset, size = next(c for c in chunks_of(path) if c[0] == "max_force")
    with open(path, "r+b") as handle:
        handle.seek(offset)
        handle.write(b"\xff" * (size - 4))
    with pytest.raises(archive.DamagedArchiveError, match=re.escape(repr(path)) + ".*max_force.*checksum"):
        archive.load(path)
    code, err = run(["plot", path, "--out", tmp_path / "p.png"])
    assert code == 2 and "max_force" in err and path in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "p.png").exists()
    before = open(path, "rb").read()
    code, err = run([*SWEEP_ARGS, "--out", path, "--resume"])
    assert code == 2 and "max_force" in err and path in err
    assert open(path, "rb").read() == before  # the damage is not carried forward (nor anything written)


def test_a_checksum_failure_is_read_again_as_a_reader_may_race_a_checkpoint(monkeypatch, files):
    """A reader may catch a chunk while a checkpoint rewrites it in place: a checksum failure is read
    again (after a pause); damage on disk fails every time (the test above: refused)."""
    monkeypatch.setattr(_files, "_RETRY_PAUSES", (0.0, 0.0))
    real, calls = _io._load, []

    def torn_once(path):
        calls.append(path)
        if len(calls) == 1:
            raise archive.DamagedArchiveError(path, "variable status: checksum", checksum=True)
        return real(path)

    monkeypatch.setattr(_io, "_load", torn_once)
    assert isinstance(archive.load(files["sweep"]), SweepResult) and len(calls) == 2


# ------------------------------------------------------------------------------------------------
# Content: codes, axes, scalar attributes (written through h5py: the checksums hold)
# ------------------------------------------------------------------------------------------------

def _set_element(name, value):
    def change(f):
        data = f[name][()]
        data.flat[1] = value
        f[name][...] = data
    return change


def _set_attr(key, value):
    def change(f):
        f.attrs[key] = value
    return change


DAMAGE = {  # what the audit found (outcome 99, status 7, NaN axis, schema_version [1, 2] and 'abc') and kin
    "outcome 99": (_set_element("outcome", 99), r"outcome = 99 at point 1 is out of range"),
    "status 7": (_set_element("status", 7), r"status = 7 at point 1 is out of range"),
    "NaN axis": (_set_element("kappa", np.nan), r"axis kappa holds nan at index 1"),
    "stop_reason -3": (_set_element("stop_reason", -3), r"stop_reason = -3 at point 1 is out of range"),
    "schema_version [1, 2]": (_set_attr("schema_version", [1, 2]), r"schema_version = \[1, 2\].*an integer"),
    "schema_version 'abc'": (_set_attr("schema_version", "abc"), r"schema_version = 'abc'.*an integer"),
    "t_end text": (_set_attr("t_end", "soon"), r"t_end = 'soon'.*a number"),
    "t_end negative": (_set_attr("t_end", -1.0), r"t_end = -1.0 is out of range"),
    "rtol array": (_set_attr("rtol", np.array([1e-10, 1e-9])), r"rtol = \[1e-10, 1e-09\].*a number"),
}


@pytest.mark.parametrize("damage", list(DAMAGE))
def test_damaged_content_is_refused_naming_the_file_and_the_damage(tmp_path, files, damage):
    change, message = DAMAGE[damage]
    path = copy(files["sweep"], tmp_path / "s.h5")
    with h5py.File(path, "a") as f:
        change(f)
    with pytest.raises(ValueError, match=re.escape(repr(path)) + ".*" + message):
        archive.load(path)
    code, err = run(["plot", path, "--out", tmp_path / "p.png"])
    assert code == 2 and re.search(message, err) and path in err and "Traceback" not in err


def test_a_changed_text_attribute_is_refused_even_where_hdf5_has_no_checksum(tmp_path, files):
    """Text attributes live in HDF5's global heap, which has no checksum: a digit of the case JSON changed
    on disk would load silently; the digest of the texts catches it."""
    path = copy(files["sweep"], tmp_path / "s.h5")
    data = bytearray(open(path, "rb").read())
    with h5py.File(path, "r") as f:
        case = f.attrs["case"]
    assert '"v": 1.0' in case
    at = data.find(case.encode())
    assert at >= 0
    digit = at + case.index('"v": 1.0') + len('"v": ')
    data[digit] = ord("3")  # v = 3.0 instead of 1.0, still valid JSON
    with open(path, "wb") as handle:
        handle.write(data)
    with pytest.raises(ValueError, match="text attributes.*SHA-256"):
        archive.load(path)
    with pytest.raises(ValueError, match="text attributes"):
        archive.describe(path)


def test_a_partial_archive_is_not_damage(tmp_path, results, monkeypatch):
    """Not-computed points may hold anything a killed checkpoint left (here: its new data without their
    commit, and codes out of range), and unused stick rows are free: neither is damage. The killed
    checkpoint left the data digests marked in progress: such a file loads unverified."""
    path = tmp_path / "partial.h5"
    full = results["atlas"]
    checkpoint = archive.Checkpoint(path)
    checkpoint(_first_points(full, 3))

    def killed(self, raw):  # after the new points' data, before their commit
        raise KeyboardInterrupt

    with monkeypatch.context() as patched, pytest.raises(KeyboardInterrupt):
        patched.setattr(archive.Checkpoint, "_flush", killed)
        checkpoint(_first_points(full, 5))
    with h5py.File(path, "a") as f:
        assert json.loads(f.attrs["data_sha256"]) == {"checkpoint": "in progress"}
        for name in ("outcome", "stop_reason"):
            data = f[name][()]
            data.flat[5] = 99  # point 5 is not computed
            f[name][...] = data
        assert f["stick_point"].shape[0] > len(full.stick_point)  # spare rows, fill values
    back = archive.load(path)
    assert back.done.sum() == 3 and back.outcome[5] == -1


def _first_points(full: SweepResult, n: int) -> SweepResult:
    """``full`` with only its first ``n`` points computed (as a checkpoint after one chunk holds it)."""
    status = np.full(full.grid.size, -1, dtype=np.int8)
    status[:n] = full.status[:n]
    keep = full.stick_point < n
    r = SweepResult(full.grid, full.t_end, full.settings, status=status,
                    outcome=np.where(status >= 0, full.outcome, -1).astype(np.int8),
                    stop_reason=np.where(status >= 0, full.stop_reason, -1).astype(np.int8),
                    stick_point=full.stick_point[keep], stick_t=full.stick_t[keep], stick_delta=full.stick_delta[keep],
                    stick_dwell=full.stick_dwell[keep])
    for name, values in full.values.items():
        fill = np.nan if values.dtype.kind == "f" else -1
        r.values[name] = np.where(status >= 0, values, fill).astype(values.dtype)
    return r


def test_non_regular_files_are_refused_without_waiting(tmp_path):
    fifo = tmp_path / "fifo.h5"
    os.mkfifo(fifo)
    with pytest.raises(ValueError, match="not a regular file"):
        archive.load(fifo)
    with pytest.raises(ValueError, match="not a regular file"):
        archive.describe(fifo)
    done = subprocess.run([sys.executable, "-m", "phaseimpact.cli", "plot", str(fifo), "--out",
                           str(tmp_path / "p.png")], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and "not a regular file" in done.stderr


# ------------------------------------------------------------------------------------------------
# Fuzz: byte flips, truncation, attribute and value changes of small real archives
# ------------------------------------------------------------------------------------------------

def same_result(a, b) -> bool:
    def bits(x, y):
        x, y = np.asarray(x), np.asarray(y)
        return x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes()

    if type(a) is not type(b):
        return False
    if isinstance(a, CriticalCurve):
        return (all(bits(getattr(a, n), getattr(b, n)) for n in ("values", "kappa", "closed_form", "predicted",
                                                                  "requested"))
                and (a.param, a.what, a.law, a.base, a.rtol, a.contact_index, a.message)
                == (b.param, b.what, b.law, b.base, b.rtol, b.contact_index, b.message))
    return (all(bits(x.values, y.values) and x.log == y.log for x, y in zip(a.grid.axes, b.grid.axes, strict=True))
            and a.grid.names == b.grid.names and a.grid.law == b.grid.law and a.grid.base == b.grid.base
            and a.settings == b.settings and a.t_end == b.t_end and list(a.values) == list(b.values)
            and all(bits(getattr(a, n), getattr(b, n)) for n in ("status", "outcome", "stop_reason", "stick_point",
                                                                  "stick_t", "stick_delta", "stick_dwell"))
            and all(bits(a.values[k], b.values[k]) for k in a.values))


def valid(result) -> bool:
    """What a loaded result may hold whatever the file said: codes in their tables, finite axes."""
    if isinstance(result, CriticalCurve):
        return bool(np.all(np.isfinite(result.values)))
    computed = result.status >= 0
    return (all(np.all(np.isfinite(a.values)) for a in result.grid.axes)
            and bool(np.all((result.status >= -1) & (result.status < len(STATUSES))))
            and bool(np.all(~computed | ((result.outcome >= 0) & (result.outcome < len(OUTCOMES)))))
            and bool(np.all(~computed | ((result.stop_reason >= 0)
                                         & (result.stop_reason < len(_driver.STOP_REASONS))))))


def load_or_refuse(path):
    """``archive.load``: the result, or None when refused with a ValueError naming the file; any other
    exception fails the test (describe is held to the same rule)."""
    for read in (archive.describe, archive.load):
        try:
            result = read(path)
        except ValueError as error:
            assert repr(os.fspath(path)) in str(error), str(error)
            return None
    return result


JUNK = [np.nan, np.inf, -1, 10**6, "abc", "", [1, 2], np.array([[1.5]]), b"\xff\xfe", json.dumps({"a": 1})]


@pytest.mark.parametrize("kind", ["sweep", "atlas", "curve"])
def test_fuzz_flips_truncation_and_attribute_changes(tmp_path, files, kind):
    rng = np.random.default_rng(20261124)
    source = files[kind]
    original = open(source, "rb").read()
    reference = archive.load(source)
    path = os.fspath(tmp_path / f"{kind}.h5")
    in_chunks = [(offset, size) for _, offset, size in chunks_of(source)]
    outcomes = {"refused": 0, "same": 0}

    def write(data):
        with open(path, "wb") as handle:
            handle.write(data)

    for trial in range(60):
        data = bytearray(original)
        if trial < 20:  # a byte of a chunk's data or checksum: always detected (Fletcher-32 sees every burst
            offset, size = in_chunks[rng.integers(len(in_chunks))]  # of up to 16 bits)
            data[offset + int(rng.integers(size))] ^= int(rng.integers(1, 256))
            write(data)
            assert load_or_refuse(path) is None, f"trial {trial}: a flipped data byte was not detected"
            outcomes["refused"] += 1
            continue
        if trial < 45:  # anywhere: 1 to 4 bytes
            for _ in range(int(rng.integers(1, 5))):
                data[int(rng.integers(len(data)))] ^= int(rng.integers(1, 256))
            write(data)
        elif trial < 50:
            write(data[: int(rng.integers(len(data)))])
        else:  # through h5py (checksums recomputed): an attribute, or a value of a dataset
            write(data)
            with h5py.File(path, "a") as f:
                names = [n for n, d in f.items() if isinstance(d, h5py.Dataset) and d.id.get_storage_size()]
                if trial % 2:
                    key = sorted(f.attrs)[int(rng.integers(len(f.attrs)))]
                    junk = JUNK[int(rng.integers(len(JUNK)))]
                    if rng.random() < 0.2:
                        del f.attrs[key]
                    else:
                        f.attrs[key] = junk
                else:
                    d = f[names[int(rng.integers(len(names)))]]
                    values = d[()]
                    values.flat[int(rng.integers(values.size))] = (rng.choice([-7, 99, 127]) if values.dtype.kind == "i"
                                                                   else rng.choice([np.nan, -np.inf, 0.0]))
                    d[...] = values
        result = load_or_refuse(path)
        if result is None:
            outcomes["refused"] += 1
        elif trial < 50:  # bytes changed behind HDF5's back: refused, or nothing that is read changed
            assert same_result(result, reference), f"trial {trial}: damage loaded silently"
            outcomes["same"] += 1
        else:
            assert valid(result), f"trial {trial}: an invalid result loaded"
    assert outcomes["refused"] >= 20 and outcomes["same"] >= 1


# ------------------------------------------------------------------------------------------------
# Data digests: what Fletcher-32 lets through (a chunk and its checksum zeroed or 0xFF)
# ------------------------------------------------------------------------------------------------

def _overwrite_chunk(path, name, byte: bytes) -> None:
    """Overwrite the first chunk of ``name``, data and Fletcher-32 checksum alike, with ``byte``."""
    _, offset, size = next(c for c in chunks_of(path) if c[0] == name)
    with open(path, "r+b") as handle:
        handle.seek(offset)
        handle.write(byte * size)


def _refused_everywhere(path, tmp_path, message):
    """``load``, ``plot`` and ``--resume`` refuse ``path`` in one line naming it and ``message``; the
    resume leaves the file as it was."""
    with pytest.raises(archive.DamagedArchiveError, match=re.escape(repr(path)) + ".*" + message):
        archive.load(path)
    code, err = run(["plot", path, "--out", tmp_path / "p.png"])
    assert code == 2 and re.search(message, err) and path in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "p.png").exists()
    before = open(path, "rb").read()
    code, err = run([*SWEEP_ARGS, "--out", path, "--resume"])
    assert code == 2 and re.search(message, err) and path in err, err
    assert open(path, "rb").read() == before


def test_fletcher32_passes_a_zeroed_chunk_with_its_checksum(tmp_path, files):
    """Why the digests: HDF5 reads a chunk whose data and checksum are all zero without an error."""
    path = copy(files["sweep"], tmp_path / "s.h5")
    _overwrite_chunk(path, "max_force", b"\0")
    with h5py.File(path, "r") as f:
        assert (f["max_force"][()] == 0).all()


@pytest.mark.parametrize("name", ["max_force", "n_stick", "outcome", "stick_t", "dissipated_energy"])
def test_a_chunk_zeroed_with_its_checksum_is_refused_by_load_plot_and_resume(tmp_path, files, name):
    path = copy(files["sweep"], tmp_path / "s.h5")
    _overwrite_chunk(path, name, b"\0")
    _refused_everywhere(path, tmp_path, f"variable {name}: its contents do not match their SHA-256 digest")


def test_a_chunk_of_0xff_with_its_checksum_is_refused_by_load_plot_and_resume(tmp_path, files):
    """The audit's corrupt_data.h5 (resume-corrupt, plot-corrupt_data, api-load-corrupt_data): NaN max
    forces at computed points; the invariant names them before the digest does."""
    path = copy(files["sweep"], tmp_path / "s.h5")
    _overwrite_chunk(path, "max_force", b"\xff")
    _refused_everywhere(path, tmp_path, r"max_force = nan at point 0 is out of range")


@pytest.mark.parametrize(("name", "value", "message"), [
    ("max_force", np.nan, r"max_force = nan at point 0 is out of range; allowed: a finite force"),
    ("n_stick", -7, r"n_stick = -7 at point 0 is out of range; allowed: a count >= 0"),
])
def test_impossible_values_at_computed_points_are_refused_without_a_digest(tmp_path, files, name, value, message):
    """The audit's plot-maxforce_nan, damage-plot-n_stick-neg, damage-resume-n_stick-neg: written through
    h5py (every checksum right) into an archive without data digests (an older one)."""
    path = copy(files["sweep"], tmp_path / "s.h5")
    with h5py.File(path, "a") as f:
        del f.attrs["data_sha256"]
        data = f[name][()]
        data[:] = value
        f[name][...] = data
    _refused_everywhere(path, tmp_path, message)


def test_archives_without_data_digests_still_load(tmp_path, files, results):
    path = copy(files["atlas"], tmp_path / "a.h5")
    with h5py.File(path, "a") as f:
        del f.attrs["data_sha256"]
    assert same_result(archive.load(path), archive.load(files["atlas"]))


def test_the_digest_is_of_the_values_whatever_the_chunks_or_filters(tmp_path, files):
    """SHA-256 over the dtype, the shape and each 8192 elements' bytes in C order, computed here
    independently; a copy of each dataset with other chunks and gzip has the same digests."""
    import hashlib

    path = files["atlas"]
    with h5py.File(path, "r") as f:
        stored = json.loads(f.attrs["data_sha256"])
        datasets = {name: f[name][()] for name in _names(f)}
    assert set(stored) == set(datasets) and {"max_force", "status", "stick_t", "kappa", "v"} <= set(stored)
    other = tmp_path / "rechunked.h5"
    with h5py.File(other, "w") as g:
        for name, data in datasets.items():
            flat = np.ascontiguousarray(data).reshape(-1)
            h = hashlib.sha256(json.dumps([data.dtype.str, list(data.shape)], sort_keys=True).encode())
            for i in range(0, max(flat.size, 1), 8192):
                h.update(hashlib.sha256(flat[i:i + 8192].tobytes()).digest())
            assert stored[name] == h.hexdigest(), name
            if data.ndim and data.size:
                g.create_dataset(name, data=data, chunks=tuple(max(1, n // 2) for n in data.shape), compression="gzip")
            else:
                g.create_dataset(name, data=data)
    with h5py.File(other, "r") as g:
        pieces = _digests._file_pieces(g)
    assert {name: _digests._dataset_digest(*entry) for name, entry in pieces.items()} == stored


def test_a_checkpoint_keeps_the_digests_true_and_a_killed_one_is_rewritten_whole(tmp_path, results, monkeypatch):
    """Each in-place checkpoint ends with the digests of what the file holds (load verifies them); a file
    killed in the middle of one is taken unverified, and the next checkpoint rewrites it whole."""
    path = tmp_path / "a.h5"
    full = results["atlas"]
    checkpoint = archive.Checkpoint(path)
    for n in (2, 4):
        checkpoint(_first_points(full, n))
    assert (checkpoint.rewrites, checkpoint.in_place) == (1, 1)
    assert archive.load(path).done.sum() == 4
    _overwrite_chunk(path, "n_stick", b"\0")  # damage after an in-place checkpoint: found
    with pytest.raises(archive.DamagedArchiveError, match="variable n_stick: its contents do not match"):
        archive.load(path)
    fresh = archive.Checkpoint(path)  # a file whose digests fail is not written in place: rewritten whole
    fresh(_first_points(full, 5))
    assert (fresh.rewrites, fresh.in_place) == (1, 0) and archive.load(path).done.sum() == 5
    with monkeypatch.context() as patched, pytest.raises(KeyboardInterrupt):
        patched.setattr(archive.Checkpoint, "_flush", lambda self, raw: (_ for _ in ()).throw(KeyboardInterrupt))
        fresh(_first_points(full, 6))
    assert archive.load(path).done.sum() == 5  # unverified, the committed points intact
    again = archive.Checkpoint(path)
    again(_first_points(full, 6))
    assert (again.rewrites, again.in_place) == (1, 0)
    with h5py.File(path, "r") as f:
        assert "checkpoint" not in json.loads(f.attrs["data_sha256"])
    assert same_result(archive.load(path), _first_points(full, 6))
