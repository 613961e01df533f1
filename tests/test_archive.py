"""HDF5 archive (schema 4): labelled arrays for xarray, plain h5py, bit-for-bit round trips, schema 1
and 2 files, checkpoints written in place (only the new points) and crash-safe (kills between the
data and the commit, then a resume that gives the numbers of an uninterrupted run)."""

import importlib
import json
import os
import re
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest

from phaseimpact import archive, seed_parameters
from phaseimpact.archive import _digests
from phaseimpact.case import seed_case
from phaseimpact.continuation import Axis, Grid, SweepResult, atlas, critical_curve
from phaseimpact.integrate import driver
from phaseimpact.integrate.result import SUMMARY_COLUMNS, Columns
from phaseimpact.model import ContactLaw

xr = pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")

ROOT = Path(__file__).resolve().parents[1]
AXES = {"kappa": np.geomspace(1e11, 1e13, 7), "v": np.linspace(0.5, 13, 4)}
#: The commit whose figures/data still hold archives of schema 1 (phaseimpact 0.1).
SCHEMA_1_COMMIT = "2fbbf97"
CODES = ("status", "outcome", "stop_reason")
STICKS = ("stick_point", "stick_t", "stick_delta", "stick_dwell")
sweep_module = importlib.import_module("phaseimpact.continuation.sweep")


@pytest.fixture(scope="module")
def small_atlas():
    """7 x 4 points of the paper law around kappa_c (0.3 s): permanent sticks and ratchet escapes."""
    return atlas(seed_parameters(), "paper", AXES)


@pytest.fixture
def chunks_of_5(monkeypatch):
    """Chunks of 5 points: the 28-point atlas is checkpointed 6 times."""
    monkeypatch.setattr(sweep_module, "CHUNK_THREADS", 5)


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def assert_same_result(back: SweepResult, result: SweepResult, *, sticks_in_order: bool = True) -> None:
    """Every array bit for bit, the grid (axes, log flags, law, base), t_end and settings."""
    assert back.grid.names == result.grid.names
    for a, b in zip(back.grid.axes, result.grid.axes, strict=True):
        assert same_bits(a.values, b.values) and a.log == b.log
    assert back.grid.law == result.grid.law and back.grid.base == result.grid.base
    assert type(back.grid.base) is type(result.grid.base)
    assert back.t_end == result.t_end and back.settings == result.settings
    for name in CODES:
        assert same_bits(getattr(back, name), getattr(result, name)), name
    assert list(back.values) == list(result.values)
    for name, values in result.values.items():
        assert same_bits(back.values[name], values), name
    if sticks_in_order:
        for name in STICKS:
            assert same_bits(getattr(back, name), getattr(result, name)), name
    else:  # the same stick phases of each point, wherever their rows are
        def by_point(r):
            order = np.argsort(r.stick_point, kind="stable")
            return [getattr(r, name)[order] for name in STICKS]
        for x, y in zip(by_point(back), by_point(result), strict=True):
            assert same_bits(x, y)


# ------------------------------------------------------------------------------------------------
# xarray: labelled N-d arrays, coordinates, units, fill values, ragged stick phases
# ------------------------------------------------------------------------------------------------

def test_atlas_opens_in_xarray_as_labelled_arrays(tmp_path, small_atlas):
    path = archive.save(small_atlas, tmp_path / "atlas.h5")
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert dict(ds.sizes) == {"kappa": 7, "v": 4, "stick": len(small_atlas.stick_point)}
        assert list(ds.coords) == ["kappa", "v"]
        assert np.array_equal(ds.kappa.values, AXES["kappa"]) and np.array_equal(ds.v.values, AXES["v"])
        for name in ("status", "outcome", "max_force", "n_stick", "t_run", "stick_first"):
            assert ds[name].dims == ("kappa", "v"), name
        assert ds.stick_t.dims == ("stick",) and ds.stick_point.dims == ("stick",)
        # UDUNITS has no fractional power: kappa's unit is stated beside units, not in it (test_cf.py)
        assert "units" not in ds.kappa.attrs and ds.kappa.attrs["fractional_units"] == "N s m-2.5"
        assert ds.kappa.attrs["long_name"] == "kappa [N s m-2.5]"
        assert ds.kappa.attrs["log"] == 1 and ds.v.attrs["log"] == 0
        assert ds.v.attrs["units"] == "m s-1" and ds.max_force.attrs["units"] == "N"
        assert ds.dissipated_energy.attrs["units"] == "J" and ds.stick_dwell.attrs["units"] == "s"
        assert ds.attrs["Conventions"] == "CF-1.11" and ds.attrs["kind"] == "atlas"
        assert ds.attrs["schema_version"] == archive.SCHEMA_VERSION and ds.attrs["contact"] == "printed"
        # sel by value, nearest grid point
        kappa, v = 1.6e12, 1.1
        i, j = np.argmin(abs(AXES["kappa"] - kappa)), np.argmin(abs(AXES["v"] - v))
        point = ds.sel(kappa=kappa, v=v, method="nearest")
        assert point.max_force.item() == small_atlas.max_force.reshape(7, 4)[i, j]
        assert point.n_stick.item() == small_atlas.values["n_stick"].reshape(7, 4)[i, j]
        # codes: CF flags, no strings needed
        assert ds.outcome.attrs["flag_meanings"].split() == list(driver.OUTCOMES)
        assert list(ds.outcome.attrs["flag_values"]) == list(range(len(driver.OUTCOMES)))
        assert np.array_equal(ds.outcome.values.ravel(), small_atlas.outcome)
        for name in ("status", "outcome", "stop_reason"):  # integer codes, not floats with NaN (a colour bar)
            assert ds[name].dtype == np.int8 and "_FillValue" not in ds[name].attrs, name
            assert list(ds[name].attrs["valid_range"]) == [0, len(ds[name].attrs["flag_meanings"].split()) - 1]
        # long-form stick rows: the flat (C order) index of each row's point, an integer that indexes
        assert ds.stick_point.dtype == np.int64 and ds.stick_point.attrs["valid_min"] == 0
        assert "instance_dimension" not in ds.stick_point.attrs and "featureType" not in ds.attrs
        flat = ds.stack(point=("kappa", "v"))
        of_rows = flat.isel(point=ds.stick_point.values)
        assert np.array_equal(of_rows.kappa.values, small_atlas.kappa[np.unravel_index(
            small_atlas.stick_point, (7, 4))[0]])
        assert np.array_equal(np.bincount(ds.stick_point.values, minlength=28), small_atlas.values["n_stick"])


def test_points_not_computed_are_fill_values_in_xarray(tmp_path, small_atlas, chunks_of_5):
    """An archive in progress: what is not computed reads as missing (NaN), not as a sentinel; the
    code variables stay integers, -1 (outside their valid_range) where not computed."""
    path = tmp_path / "partial.h5"
    checkpoint = archive.Checkpoint(path)

    class Enough(Exception):
        pass

    def two_chunks(result):
        checkpoint(result)
        if checkpoint.in_place == 1:
            raise Enough

    with pytest.raises(Enough):
        atlas(seed_parameters(), "paper", AXES, on_chunk=two_chunks)
    computed = np.arange(28) < 10
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        for name in ("max_force", "n_stick"):  # quantities: missing where not computed
            values = ds[name].values.ravel()
            assert np.isnan(values[~computed]).all() and not np.isnan(values[computed]).any(), name
        for name in ("status", "outcome", "stop_reason", "stick_count"):  # codes and row indices: integers
            values = ds[name].values.ravel()
            assert values.dtype.kind == "i" and (values[~computed] == -1).all() and (values[computed] >= 0).all(), name
        assert np.isnan(ds.max_force.encoding["_FillValue"])
        assert np.array_equal(ds.max_force.values.ravel()[computed], small_atlas.max_force[:10])
        rows = ds.stick_point.values
        assert set(rows[rows >= 0]) <= set(range(10))  # free rows are -1, no point's
        assert (rows == -1).any()
        phases = archive.stick_phases(ds)  # the rows of computed points, never a free row
        assert np.array_equal(phases.stick_point.values, small_atlas.stick_point[small_atlas.stick_point < 10])
        i, j = np.unravel_index(phases.stick_point.values, (7, 4))
        assert np.array_equal(phases.kappa.values, AXES["kappa"][i]) and np.array_equal(phases.v.values, AXES["v"][j])
    back = archive.load(path)
    assert back.done.sum() == 10 and (back.status[10:] == -1).all()
    assert np.isnan(back.max_force[10:]).all() and (back.values["n_stick"][10:] == -1).all()


def _exponents(units: str) -> dict:
    """UDUNITS product of powers (``N s m-2.5``) as {symbol: exponent}; fails on anything else."""
    assert re.fullmatch(r"1|[A-Za-z]+(-?\d+(\.\d+)?)?( [A-Za-z]+(-?\d+(\.\d+)?)?)*", units), units
    out = {}
    for word in units.split() if units != "1" else []:
        symbol, power = re.fullmatch(r"([A-Za-z]+)(-?[\d.]*)", word).groups()
        out[symbol] = out.get(symbol, 0.0) + float(power or 1)
    return out


def test_units_are_products_of_powers_and_kappa_times_rates_is_a_force(tmp_path, small_atlas):
    """Units (``units``, or ``fractional_units`` for a power UDUNITS cannot state) are products of powers;
    eq. 8's damping force kappa delta^alpha deltadot is in N."""
    path = archive.save(small_atlas, tmp_path / "atlas.h5")
    with h5py.File(path, "r") as f:
        units = {name: f[name].attrs.get("units", f[name].attrs.get("fractional_units")) for name in f
                 if {"units", "fractional_units"} & set(f[name].attrs)}
    assert set(units) >= {"kappa", "v", "max_force", "stick_t"}
    exps = {name: _exponents(u) for name, u in units.items()}
    alpha = seed_parameters().alpha
    force = dict(exps["kappa"])
    for symbol, power in (("m", alpha), ("m", 1.0), ("s", -1.0)):  # times delta^alpha (m^alpha), deltadot (m/s)
        force[symbol] = force.get(symbol, 0.0) + power
    assert {k: v for k, v in force.items() if v != 0} == {"N": 1.0} == exps["max_force"]
    assert archive.kappa_units(1.0) == "N s m-2" and archive.axis_units("K", 1.5) == "N m-1.5"
    assert archive.axis_units("plate.rho", 1.5) == "kg m-3" and archive.axis_units("plate.nu", 1.5) == "1"


def test_curve_round_trip_and_xarray(tmp_path):
    curve = critical_curve(seed_parameters(), "paper", "v", [1.0, 2.0, 3.0])
    path = archive.save(curve, tmp_path / "curve.h5")
    back = archive.load(path)
    for name in ("values", "kappa", "closed_form", "predicted", "requested"):
        assert same_bits(getattr(back, name), getattr(curve, name)), name
    assert (back.param, back.what, back.law, back.base, back.rtol, back.contact_index, back.message) == \
        (curve.param, curve.what, curve.law, curve.base, curve.rtol, curve.contact_index, curve.message)
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert ds.kappa.dims == ("v",) and np.array_equal(ds.v.values, curve.values)
        assert ds.kappa.attrs["fractional_units"] == "N s m-2.5" and "units" not in ds.kappa.attrs
        assert ds.kappa.attrs["long_name"] == "kappa_c [N s m-2.5]"
        assert ds.attrs["kind"] == "critical-curve" and ds.attrs["what"] == "kappa_c"
        assert ds.kappa.sel(v=2.0).item() == curve.kappa[curve.values == 2.0][0]
        assert ds.requested.values.tolist() == curve.requested.astype(int).tolist()
    held = archive.describe(path)
    assert held["kind"] == "critical-curve" and np.array_equal(held["axes"]["v"], curve.values)


# ------------------------------------------------------------------------------------------------
# Bit-for-bit round trips, plain h5py, case bases and extras
# ------------------------------------------------------------------------------------------------

def test_round_trip_is_bit_for_bit(tmp_path, small_atlas):
    path = archive.save(small_atlas, tmp_path / "atlas.h5")
    assert_same_result(archive.load(path), small_atlas)
    held = archive.describe(path)
    assert held["kind"] == "atlas" and list(held["axes"]) == ["kappa", "v"]
    assert archive.same_work(held, "atlas", ContactLaw("paper"), seed_parameters(), AXES, None, 1e-10) == []
    assert archive.same_work(held, "atlas", ContactLaw("paper"), seed_parameters(), AXES, 0.01, 1e-10)
    archive.check_overwrite(path, "atlas", ContactLaw("paper"), seed_parameters(), AXES, None, 1e-10)
    with pytest.raises(ValueError, match="holds other work"):
        archive.check_overwrite(path, "atlas", ContactLaw("paper"), seed_parameters(), {"kappa": [1.0]}, None,
                                1e-10)


def test_case_base_dotted_axis_and_extras_round_trip(tmp_path):
    result = atlas(seed_case(), "paper", {"plate.E": [1e11, 2.1e11, 3e11], "kappa": [1e11, 2e12]})
    result.extras.update({"boundary": {"kappa": np.array([1.5e12, 1.6e12]), "flags": np.array([True, False]),
                                       "note": "refined"}, "tolerance": 1e-3})
    path = archive.save(result, tmp_path / "case.h5")
    back = archive.load(path)
    assert_same_result(back, result)
    assert back.extras["tolerance"] == 1e-3 and back.extras["boundary"]["note"] == "refined"
    assert same_bits(back.extras["boundary"]["kappa"], result.extras["boundary"]["kappa"])
    assert same_bits(back.extras["boundary"]["flags"], result.extras["boundary"]["flags"])
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert ds.max_force.dims == ("plate_E", "kappa")
        assert ds.plate_E.attrs["parameter"] == "plate.E" and ds.plate_E.attrs["units"] == "Pa"
        assert ds.attrs["base"] == "case" and json.loads(ds.attrs["case"])["name"] == "seed"
        assert ds.sel(plate_E=2e11, method="nearest").plate_E.item() == 2.1e11
    assert list(archive.describe(path)["axes"]) == ["plate.E", "kappa"]


def test_plain_h5py_reads_everything(tmp_path, small_atlas):
    path = archive.save(small_atlas, tmp_path / "atlas.h5")
    with h5py.File(path, "r") as f:
        assert json.loads(f.attrs["axes"]) == ["kappa", "v"] and f.attrs["kind"] == "atlas"
        assert f["max_force"].dims[0][0].name == "/kappa" and f["max_force"].dims[1][0].name == "/v"
        meanings = f["outcome"].attrs["flag_meanings"].split()
        names = [meanings[c] if c >= 0 else "not computed" for c in f["outcome"][()].ravel()]
        assert names == list(small_atlas.outcome_names())
        first, count = f["stick_first"][()].ravel(), f["stick_count"][()].ravel()
        i = int(np.argmax(count))
        rows = slice(first[i], first[i] + count[i])
        assert np.array_equal(f["stick_delta"][rows], small_atlas.sticks_of(i)[1])
        assert (f["stick_point"][rows] == i).all()
        assert json.loads(f.attrs["parameters"])["M1"] == small_atlas.grid.base.M1
        assert isinstance(f.attrs["t_end"], (float, np.floating)) and np.isnan(f.attrs["t_end"])


def test_foreign_truncated_newer_and_damaged_files_are_refused(tmp_path, small_atlas):
    good = archive.save(small_atlas, tmp_path / "good.h5")
    truncated = tmp_path / "truncated.h5"
    truncated.write_bytes(Path(good).read_bytes()[: os.path.getsize(good) // 2])
    with pytest.raises(ValueError, match="truncated or foreign|damaged"):
        archive.load(truncated)
    damaged = tmp_path / "damaged.h5"
    damaged.write_bytes(Path(good).read_bytes())
    with h5py.File(damaged, "a") as f:  # a committed point whose rows point elsewhere
        f["stick_first"][0, 0] = f["stick_first"][0, 1]
    with pytest.raises(ValueError, match="damaged"):
        archive.load(damaged)
    with h5py.File(good, "a") as f:
        f.attrs["schema_version"] = archive.SCHEMA_VERSION + 1
    with pytest.raises(ValueError, match="upgrade phaseimpact"):
        archive.load(good)


# ------------------------------------------------------------------------------------------------
# Older schemas still load
# ------------------------------------------------------------------------------------------------

def _schema_1_file(tmp_path, name) -> Path:
    """``figures/data/NAME`` as phaseimpact 0.1 wrote it (from git history)."""
    try:
        blob = subprocess.run(["git", "show", f"{SCHEMA_1_COMMIT}:figures/data/{name}"], cwd=ROOT,
                              capture_output=True, check=True, timeout=60).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip(f"git history with {SCHEMA_1_COMMIT} is not available")
    path = tmp_path / name
    path.write_bytes(blob)
    return path


def test_schema_1_files_of_the_old_release_load(tmp_path):
    sweep_file = _schema_1_file(tmp_path, "bifurcation.h5")
    curve_file = _schema_1_file(tmp_path, "critical_curve.h5")
    with h5py.File(sweep_file, "r") as f:
        assert f.attrs["schema_version"] == 1
        n = len(f["sweep/kappa"])
        n_asymptotic = f["sweep/n_asymptotic"][()]
    sweep = archive.load(sweep_file)
    assert sweep.grid.names == ("kappa",) and sweep.grid.size == n
    assert np.array_equal(sweep.values["n_stick"], n_asymptotic)
    assert np.array_equal(np.bincount(sweep.stick_point, minlength=n), np.maximum(n_asymptotic, 0))
    curve = archive.load(curve_file)
    at_1 = np.exp(np.interp(0.0, np.log(curve.values), np.log(curve.kappa)))
    assert curve.what == "kappa_c" and abs(at_1 / 1.4994e12 - 1) < 1e-2  # kappa_c at 1 m/s (REFERENCE §5)
    assert archive.describe(curve_file)["schema_version"] == 1
    # and an old archive can be rewritten in today's schema
    again = archive.load(archive.save(sweep, tmp_path / "v3.h5"))
    assert_same_result(again, sweep)


def _write_schema_2(path, r):
    """An archive as phaseimpact wrote it with schema 2 (the writer of that release, condensed)."""
    def names(codes, table):
        table = np.array([*table, ""], dtype=object)
        return table[np.where(np.asarray(codes) < 0, len(table) - 1, codes)]

    with h5py.File(path, "w") as f:
        f.attrs.update({"schema_version": 2, "package_version": "0.2.0", "engine": r.settings["engine"],
                        "law": json.dumps(r.law.as_dict()), "parameters": json.dumps(r.grid.base.as_dict()),
                        "rtol": r.settings["rtol"], "t_end": np.nan, "created": "2025-01-01T00:00:00+00:00",
                        "kind": "sweep"})
        g = f.create_group("sweep")
        g.attrs["axes"] = json.dumps(list(r.grid.names))
        scales = []
        for axis in r.grid.axes:
            d = g.create_dataset(axis.name, data=axis.values)
            d.attrs["units"], d.attrs["log"] = "N s/m^(1+alpha)", bool(axis.log)
            d.make_scale(axis.name)
            scales.append(d)
        for name, table in (("status", driver.STATUSES), ("outcome", driver.OUTCOMES),
                            ("stop_reason", driver.STOP_REASONS)):
            g.create_dataset(name, data=names(getattr(r, name), table).reshape(r.shape), dtype=h5py.string_dtype())
        for name, values in r.values.items():
            d = g.create_dataset(name, data=values.reshape(r.shape))
            for i, scale in enumerate(scales):
                d.dims[i].attach_scale(scale)
        for name in ("point", "t", "delta", "dwell"):
            g[f"sticks/{name}"] = getattr(r, f"stick_{name}")


def test_schema_2_archives_still_load(tmp_path, small_atlas):
    path = tmp_path / "v2.h5"
    _write_schema_2(path, small_atlas)
    back = archive.load(path)
    assert_same_result(back, small_atlas)
    held = archive.describe(path)
    assert held["schema_version"] == 2 and list(held["axes"]) == ["kappa", "v"]
    checkpoint = archive.Checkpoint(path)  # a checkpoint onto it rewrites it in today's schema
    checkpoint(back)
    assert checkpoint.rewrites == 1 and archive.describe(path)["schema_version"] == archive.SCHEMA_VERSION


def test_schema_4_archives_still_load(tmp_path, small_atlas):
    """Schema 4: CF-1.8, the axes' netCDF names in the root attribute ``dimensions``, a variable-less
    dimension ``point``, /extras arrays without netCDF dimensions."""
    result = SweepResult(small_atlas.grid, small_atlas.t_end, small_atlas.settings, status=small_atlas.status,
                         outcome=small_atlas.outcome, stop_reason=small_atlas.stop_reason,
                         stick_point=small_atlas.stick_point, stick_t=small_atlas.stick_t,
                         stick_delta=small_atlas.stick_delta, stick_dwell=small_atlas.stick_dwell,
                         extras={"boundary": {"kappa": np.array([1.5e12])}})
    result.values.update(small_atlas.values)
    path = archive.save(result, tmp_path / "v4.h5")
    with h5py.File(path, "a") as f:
        f.attrs["schema_version"], f.attrs["Conventions"] = np.int64(4), "CF-1.8"
        f.attrs["dimensions"] = f.attrs["axis_dimensions"]
        del f.attrs["axis_dimensions"]
        group = f["extras/boundary"]
        data = group["kappa"][()]
        del group["kappa"], group["kappa_dim0"]
        group.create_dataset("kappa", data=data).attrs["type"] = "array"
        del f.attrs["data_sha256"]  # schema 4 had no data digests
        f.attrs["text_sha256"] = _digests._texts_digest(f)
    back = archive.load(path)
    assert_same_result(back, result)
    assert same_bits(back.extras["boundary"]["kappa"], result.extras["boundary"]["kappa"])
    assert archive.describe(path)["schema_version"] == 4

# ------------------------------------------------------------------------------------------------
# Checkpoints: in place, only the new points
# ------------------------------------------------------------------------------------------------

def test_each_checkpoint_loads_back_as_the_result_in_memory(tmp_path, monkeypatch, small_atlas, chunks_of_5):
    path = tmp_path / "atlas.h5"
    checkpoint = archive.Checkpoint(path)
    seen = []

    def check(result):
        checkpoint(result)
        assert_same_result(archive.load(path), result)
        seen.append(int(np.count_nonzero(result.status >= 0)))

    reads = []
    read_disk = archive.Checkpoint._read_disk
    monkeypatch.setattr(archive.Checkpoint, "_read_disk", lambda self, r: reads.append(1) or read_disk(self, r))
    result = atlas(seed_parameters(), "paper", AXES, on_chunk=check)
    assert seen == [5, 10, 15, 20, 25, 28]
    assert (checkpoint.rewrites, checkpoint.in_place) == (1, 5)  # made once, then written in place
    assert len(reads) == 1  # only before the file existed: later calls know what it holds
    assert_same_result(result, small_atlas)
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert int((ds.status >= 0).sum()) == 28
    final = archive.save(result, tmp_path / "final.h5")  # the compact file of the end of a run
    assert_same_result(archive.load(final), small_atlas)
    assert os.path.getsize(final) < os.path.getsize(path)  # no spare rows


def big_grid(n_kappa: int, n_v: int = 100) -> Grid:
    return Grid(seed_parameters(), ContactLaw("paper"), (Axis.make("kappa", np.geomspace(1e10, 1e14, n_kappa)),
                                                        Axis.make("v", np.linspace(0.5, 13, n_v))))


def synthetic(n: int, rng, sticks=(1, 4)) -> Columns:
    """Columns of ``n`` made-up successful runs (the engine is not needed to test the archive)."""
    values = {name: (rng.integers(0, 5, n).astype(dtype) if dtype is np.int64 else rng.random(n))
              for name, _, dtype, _ in SUMMARY_COLUMNS}
    count = rng.integers(*sticks, n).astype(np.int64)
    m = int(count.sum())
    return Columns(np.zeros(n, np.int8), rng.integers(1, 6, n).astype(np.int8), np.ones(n, np.int8), values, count,
                   rng.random(m), rng.random(m), rng.random(m))


def _written_bytes():
    try:
        with open("/proc/self/io", encoding="ascii") as handle:
            return next(int(line.split()[1]) for line in handle if line.startswith("wchar:"))
    except (OSError, StopIteration):
        return None


def _chunk_map(path):
    """Byte ranges of every dataset's storage: [(start, stop, name, chunk offset, chunk shape)]."""
    out = []
    with h5py.File(path, "r") as f:
        for name, d in f.items():
            if d.chunks is None:
                if d.id.get_offset() is not None:
                    out.append((d.id.get_offset(), d.id.get_offset() + d.id.get_storage_size(), name, None, None))
                continue
            for i in range(d.id.get_num_chunks()):
                info = d.id.get_chunk_info(i)
                out.append((info.byte_offset, info.byte_offset + info.size, name, info.chunk_offset, d.chunks))
    return sorted(out)


def _checkpoint_three_chunks(path, grid, chunk=4096):
    """A fresh checkpoint, one in place, then a third one measured: (bytes before, bytes after,
    bytes written by the third, its new points, its new rows)."""
    rng = np.random.default_rng(7)
    result = SweepResult(grid, None, {"rtol": 1e-10, "engine": "synthetic", "version": "test"})
    checkpoint = archive.Checkpoint(path, fsync=False)
    for k in range(2):
        result.store(np.arange(k * chunk, (k + 1) * chunk), synthetic(chunk, rng))
        checkpoint(result)
    new = np.arange(2 * chunk, 3 * chunk)
    result.store(new, synthetic(chunk, rng))
    free = checkpoint._disk.free
    rows = np.arange(free, free + int(np.count_nonzero(np.isin(result.stick_point, new))))
    before = Path(path).read_bytes()
    written = _written_bytes()
    checkpoint(result)
    written = None if written is None else _written_bytes() - written
    assert checkpoint.in_place == 2 and checkpoint.rewrites == 1
    assert_same_result(archive.load(path), result)
    return before, Path(path).read_bytes(), written, new, rows


def test_a_checkpoint_changes_only_the_bytes_of_its_new_points(tmp_path):
    grid = big_grid(400)  # 40 000 points, a 7 MB file
    path = tmp_path / "big.h5"
    before, after, _, new, rows = _checkpoint_three_chunks(path, grid)
    assert len(after) == len(before)  # nothing allocated, nothing moved
    changed = np.flatnonzero(np.frombuffer(before, np.uint8) != np.frombuffer(after, np.uint8))
    # of the metadata, only the data digests change: their text, in place, and the 4-byte checksum of the
    # block holding it
    with h5py.File(path, "r") as f:
        digests = bytes(f.attrs["data_sha256"])
    at = after.find(digests)
    assert at > 0 and before.find(digests) < 0
    in_digests = (changed >= at) & (changed < at + len(digests))
    assert np.count_nonzero(~in_digests & (changed >= at - 64) & (changed < at)) <= 4
    changed = changed[~in_digests & ~((changed >= at - 64) & (changed < at))]
    n_columns = len(SUMMARY_COLUMNS) + 2  # and stick_first, stick_count
    assert changed.size <= new.size * (3 + 8 * n_columns) + rows.size * 32
    assert changed.size > new.size  # the new points are there
    storage = _chunk_map(path)
    starts = np.array([s[0] for s in storage])
    multi = np.column_stack(np.unravel_index(new, grid.shape))
    touched = set()
    for byte in changed:
        k = np.searchsorted(starts, byte, side="right") - 1
        assert k >= 0 and byte < storage[k][1], f"byte {byte} changed outside every dataset (metadata)"
        touched.add(k)
    for k in touched:
        _, _, name, offset, shape = storage[k]
        assert offset is not None, f"{name} changed"
        lo, hi = np.array(offset), np.array(offset) + np.array(shape)
        if name.startswith("stick_") and name not in ("stick_first", "stick_count"):
            assert rows[0] < hi[0] and lo[0] <= rows[-1], f"{name}: a chunk without new rows changed"
        else:
            assert np.any(np.all((multi >= lo) & (multi < hi), axis=1)), f"{name}: a chunk without new points changed"


@pytest.mark.skipif(_written_bytes() is None, reason="needs /proc/self/io (Linux)")
def test_checkpoint_cost_follows_the_new_points_not_the_file(tmp_path):
    """Bytes written by a checkpoint of 4096 points: the same for a 10x larger file, and a small part of it."""
    _, small_after, small, _, _ = _checkpoint_three_chunks(tmp_path / "small.h5", big_grid(200))
    _, big_after, big, _, _ = _checkpoint_three_chunks(tmp_path / "big.h5", big_grid(2000))
    assert len(big_after) > 8 * len(small_after)
    assert big < 1.5 * small + 65536
    assert big < len(big_after) / 10


def test_spare_stick_rows_hold_fill_values_and_rows_out_of_point_order_keep_it(tmp_path):
    """The first checkpoint keeps room for the stick phases to come (written a chunk at a time after
    the data): every spare row reads as no point (-1) and NaN. Chunks stored out of point order (a
    recomputed point, another backend's order) keep their order in the final archive: each point's
    rows are together already."""
    grid = big_grid(40)  # 4000 points
    rng = np.random.default_rng(5)
    result = SweepResult(grid, None, {"rtol": 1e-10, "engine": "synthetic", "version": "test"})
    path = tmp_path / "spare.h5"
    result.store(np.arange(2000, 2500), synthetic(500, rng))
    archive.Checkpoint(path, fsync=False)(result)
    rows = len(result.stick_point)
    with h5py.File(path, "r") as f:
        point = f["stick_point"][()]
        assert point.size > rows + 4096  # spare rows for the 3500 points to come, over several chunks
        assert same_bits(point[:rows], result.stick_point) and (point[rows:] == -1).all()
        for name in ("stick_t", "stick_delta", "stick_dwell"):
            assert np.isnan(f[name][rows:]).all() and not np.isnan(f[name][:rows]).any()
    result.store(np.arange(0, 2000), synthetic(2000, rng))  # rows of lower points after higher ones
    archive.save(result, path, force=True)
    back = archive.load(path)
    assert back.stick_point[0] == 2000 and back.stick_point[-1] == 1999
    assert_same_result(back, result)


def test_checkpoint_rewrites_the_file_when_its_stick_rows_run_out(tmp_path):
    grid = big_grid(20)
    rng = np.random.default_rng(3)
    result = SweepResult(grid, None, {"rtol": 1e-10, "engine": "synthetic", "version": "test"})
    path = tmp_path / "rows.h5"
    checkpoint = archive.Checkpoint(path, fsync=False)
    result.store(np.arange(500), synthetic(500, rng, sticks=(0, 1)))  # no stick phases: little room kept
    checkpoint(result)
    result.store(np.arange(500, 1000), synthetic(500, rng, sticks=(6, 9)))
    checkpoint(result)
    assert checkpoint.rewrites == 2 and checkpoint.in_place == 0
    result.store(np.arange(1000, 1100), synthetic(100, rng))
    checkpoint(result)
    assert checkpoint.in_place == 1
    assert_same_result(archive.load(path), result)


def test_checkpoint_refuses_a_foreign_file_and_replaces_other_work(tmp_path, small_atlas):
    notes = tmp_path / "notes.h5"
    notes.write_text("my notes")
    with pytest.raises(ValueError, match="not a phaseimpact archive"):
        archive.Checkpoint(notes)(small_atlas)
    assert notes.read_text() == "my notes"
    archive.Checkpoint(notes, force=True)(small_atlas)
    assert_same_result(archive.load(notes), small_atlas)
    other = atlas(seed_parameters(), "paper", {"kappa": [1e11, 1e12]})
    checkpoint = archive.Checkpoint(notes)
    checkpoint(other)  # an archive of other work is replaced whole, never written into
    assert checkpoint.rewrites == 1
    assert_same_result(archive.load(notes), other)


def test_checkpoint_notices_a_file_replaced_or_held_open(tmp_path, small_atlas, chunks_of_5):
    """A file replaced between checkpoints is read again, never written into blindly; one held open by
    h5py in this process (HDF5 file locking) is rewritten whole instead of failing the sweep."""
    path = tmp_path / "atlas.h5"
    checkpoint = archive.Checkpoint(path)
    calls = []

    def meddle(result):
        calls.append(1)
        if len(calls) == 5:
            with h5py.File(path, "r"):
                checkpoint(result)
        else:
            checkpoint(result)
        if len(calls) == 2:  # someone saves other work over it
            archive.save(atlas(seed_parameters(), "paper", {"kappa": [1e11, 1e12]}), path)

    result = atlas(seed_parameters(), "paper", AXES, on_chunk=meddle)
    assert (checkpoint.rewrites, checkpoint.in_place) == (3, 3)  # the 1st, the 3rd and the 5th (held open)
    assert_same_result(archive.load(path), result)


# ------------------------------------------------------------------------------------------------
# Crash safety: a kill between the data and the commit leaves the previous state; resume completes
# ------------------------------------------------------------------------------------------------

class Killed(BaseException):
    """Stands for a kill: nothing after it runs."""


def die_at_flush(monkeypatch, n: int, then=None):
    """Make the n-th flush of in-place checkpoints (counted from 1) the last thing that happens."""
    flush, calls = archive.Checkpoint._flush, [0]

    def flush_then_die(self, raw):
        flush(self, raw)
        calls[0] += 1
        if calls[0] == n:
            if then is not None:
                then()
            raise Killed

    monkeypatch.setattr(archive.Checkpoint, "_flush", flush_then_die)
    return calls


def test_kill_between_data_and_commit_leaves_the_previous_state_and_resume_completes(
        tmp_path, monkeypatch, small_atlas, chunks_of_5):
    path = tmp_path / "atlas.h5"
    checkpoint = archive.Checkpoint(path)
    states = []

    def keep(result):
        checkpoint(result)
        states.append(archive.load(path))

    # flushes of in-place checkpoints: 1 data, 2 status (2nd checkpoint); 3 data of the 3rd: killed there
    die_at_flush(monkeypatch, 3)
    with pytest.raises(Killed):
        atlas(seed_parameters(), "paper", AXES, on_chunk=keep)
    monkeypatch.undo()
    monkeypatch.setattr(sweep_module, "CHUNK_THREADS", 5)
    previous = archive.load(path)
    assert_same_result(previous, states[-1])  # the state of the 2nd checkpoint, bit for bit
    assert previous.done.sum() == 10
    with h5py.File(path, "r") as f:  # the 3rd chunk's data did reach the file, without its commit
        assert not np.isnan(f["max_force"][()].ravel()[10:15]).any() and (f["status"][()].ravel()[10:15] == -1).all()
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert int((ds.status >= 0).sum()) == 10
    resumed = archive.Checkpoint(path)
    result = atlas(seed_parameters(), "paper", AXES, previous=previous, on_chunk=resumed)
    # 18 points left: 4 chunks; the killed checkpoint left data that match no digest: the first rewrites the
    # file whole, the others write in place
    assert resumed.rewrites == 1 and resumed.in_place == 3
    assert_same_result(archive.load(path), result)
    assert_same_result(result, small_atlas)  # the numbers of an uninterrupted run
    with h5py.File(path, "r") as f:  # the killed checkpoint's rows were reused, no stale ones remain
        point = f["stick_point"][()]
        assert np.array_equal(np.sort(point[point >= 0]), np.sort(small_atlas.stick_point))


def test_a_torn_commit_commits_some_points_each_complete(tmp_path, monkeypatch, small_atlas, chunks_of_5):
    """A kill while the status is written: the points whose status made it are whole, the others not computed."""
    path = tmp_path / "atlas.h5"
    checkpoint = archive.Checkpoint(path)
    latest = []

    def keep(result):
        latest[:] = [result]
        checkpoint(result)

    def half_of_the_commit():
        with h5py.File(path, "r+", locking=False) as f:  # what a torn status write leaves: 2 of the 5 new ones
            status = f["status"][()].ravel()
            status[[10, 12]] = latest[0].status[[10, 12]]
            f["status"][...] = status.reshape(7, 4)

    die_at_flush(monkeypatch, 3, then=half_of_the_commit)
    with pytest.raises(Killed):
        atlas(seed_parameters(), "paper", AXES, on_chunk=keep)
    back = archive.load(path)
    assert np.flatnonzero(back.done).tolist() == [*range(10), 10, 12]
    for i in np.flatnonzero(back.done):
        assert all(same_bits(a, b) for a, b in zip(back.sticks_of(i), small_atlas.sticks_of(i), strict=True))
        for name, values in small_atlas.values.items():
            assert same_bits(back.values[name][i], values[i]), (i, name)
    assert back.outcome[11] == -1 and np.isnan(back.max_force[11])


def test_failed_points_recomputed_across_a_kill(tmp_path, monkeypatch, small_atlas, chunks_of_5):
    """A failed point is recomputed on resume; killed mid-checkpoint it is left not computed (never half
    new, half old), and the next resume gives the uninterrupted numbers."""
    path = tmp_path / "atlas.h5"
    real = sweep_module.run_chunks

    def first_of_each_chunk_fails(*args, **kwargs):
        for columns in real(*args, **kwargs):
            columns.status[0] = driver.STEP_SIZE_COLLAPSE
            yield columns

    monkeypatch.setattr(sweep_module, "run_chunks", first_of_each_chunk_fails)
    atlas(seed_parameters(), "paper", AXES, on_chunk=archive.Checkpoint(path))
    monkeypatch.setattr(sweep_module, "run_chunks", real)
    failed = archive.load(path)
    assert np.flatnonzero(failed.failed).tolist() == [0, 5, 10, 15, 20, 25]
    failed_bytes = path.read_bytes()
    for n in (1, 2):  # killed after marking them not computed (1), after their new data (2)
        path.write_bytes(failed_bytes)
        die_at_flush(monkeypatch, n)
        with pytest.raises(Killed):
            atlas(seed_parameters(), "paper", AXES, previous=archive.load(path), on_chunk=archive.Checkpoint(path))
        monkeypatch.undo()
        monkeypatch.setattr(sweep_module, "CHUNK_THREADS", 5)
        back = archive.load(path)
        assert np.flatnonzero(back.status < 0).tolist() == [0, 5, 10, 15, 20]
        assert np.flatnonzero(back.failed).tolist() == [25]
        assert not np.isin(back.stick_point, [0, 5, 10, 15, 20]).any()
        others = np.setdiff1d(np.arange(28), [0, 5, 10, 15, 20, 25])
        for name, values in small_atlas.values.items():
            assert same_bits(back.values[name][others], values[others]), name
    result = atlas(seed_parameters(), "paper", AXES, previous=archive.load(path), on_chunk=archive.Checkpoint(path))
    assert_same_result(result, small_atlas, sticks_in_order=False)
    assert_same_result(archive.load(path), small_atlas, sticks_in_order=False)


KILL = textwrap.dedent("""
    import importlib, os, signal, sys
    import numpy as np
    from phaseimpact import archive, seed_parameters
    from phaseimpact.continuation import atlas

    importlib.import_module("phaseimpact.continuation.sweep").CHUNK_THREADS = 5
    flush, calls = archive.Checkpoint._flush, [0]

    def flush_then_die(self, raw):
        flush(self, raw)
        calls[0] += 1
        if calls[0] == int(sys.argv[2]):
            os.kill(os.getpid(), signal.SIGKILL)  # no clean-up at all, the HDF5 file is never closed

    archive.Checkpoint._flush = flush_then_die
    atlas(seed_parameters(), "paper", {"kappa": np.geomspace(1e11, 1e13, 7), "v": np.linspace(0.5, 13, 4)},
          on_chunk=archive.Checkpoint(sys.argv[1]))
""")


@pytest.mark.slow
@pytest.mark.parametrize("flushes, done", [(3, 10), (4, 15)])
def test_sigkill_mid_checkpoint_then_resume_equals_uninterrupted(tmp_path, small_atlas, flushes, done, monkeypatch):
    """A real SIGKILL after the 3rd checkpoint's data (3) or its commit (4): load gives the last committed
    state, xarray opens the file, and a resume gives the numbers of an uninterrupted run."""
    path = tmp_path / "atlas.h5"
    killed = subprocess.run([sys.executable, "-c", KILL, str(path), str(flushes)], capture_output=True, text=True,
                            timeout=600)
    assert killed.returncode == -signal.SIGKILL, killed.stderr
    previous = archive.load(path)
    assert previous.done.sum() == done and (previous.status[done:] == -1).all()
    for name, values in small_atlas.values.items():
        assert same_bits(previous.values[name][:done], values[:done]), name
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert int((ds.status >= 0).sum()) == done
    monkeypatch.setattr(sweep_module, "CHUNK_THREADS", 5)
    result = atlas(seed_parameters(), "paper", AXES, previous=previous, on_chunk=archive.Checkpoint(path))
    assert_same_result(result, small_atlas)
    assert_same_result(archive.load(path), small_atlas)


def test_to_xarray_is_the_archive_in_memory(tmp_path, small_atlas, monkeypatch):
    """Same variables, dimensions, attributes and values as the archive opened from disk."""
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")  # one time stamp, whatever second each is made in
    path = archive.save(small_atlas, tmp_path / "atlas.h5")
    memory = archive.to_xarray(small_atlas)
    with xr.open_dataset(path, engine="h5netcdf") as disk:
        xr.testing.assert_identical(memory, disk.load())
    assert memory.max_force.dims == ("kappa", "v") and memory.kappa.attrs["fractional_units"] == "N s m-2.5"
    with pytest.raises(TypeError, match="SweepResult or a CriticalCurve"):
        archive.to_xarray([1, 2])
