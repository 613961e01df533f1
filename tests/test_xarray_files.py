"""Files that xarray wrote (issue 41, item 2): an unchanged re-save of an archive (both engines) loads
as the archive it came from and plots; a subset loads when it is still a consistent archive, and is
otherwise refused as xarray's copy (never as "damaged"); attributes read as netCDF stores them
(length-1 arrays) as well as scalars."""

import h5py
import numpy as np
import pytest
from _cli import run

from phaseimpact import archive, seed_parameters
from phaseimpact.continuation import atlas, critical_curve, refine_boundaries, sweep
from phaseimpact.train import impact_train

xr = pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")
pytest.importorskip("netCDF4")

ENGINES = ("h5netcdf", "netcdf4")
TRAIN_PARAMS = seed_parameters(kappa=3e9)


@pytest.fixture(scope="module")
def results():
    return {"sweep": sweep(seed_parameters(), "paper", [1e9, 1e12, 1e13]),
            "atlas": atlas(seed_parameters(), "paper", {"kappa": np.geomspace(1e11, 1e13, 3), "v": [1.0, 2.0]}),
            "critical-curve": critical_curve(seed_parameters(), "paper", "v", [1.0, 2.0]),
            "impact-train": impact_train(TRAIN_PARAMS, "hunt-crossley", 3e-3, 3)}


@pytest.fixture(scope="module")
def archives(results, tmp_path_factory):
    folder = tmp_path_factory.mktemp("xarray-files")
    train = {"params": TRAIN_PARAMS, "law": "hunt-crossley"}
    return {kind: archive.save(r, folder / f"{kind}.nc", **(train if kind == "impact-train" else {}))
            for kind, r in results.items()}


def _resave(path, out, engine="h5netcdf", change=lambda ds: ds):
    with xr.open_dataset(path) as ds:
        change(ds).to_netcdf(out, engine=engine)
    return out


def _assert_same(a, b, where=""):
    """Every field of two results equal, arrays bit for bit (dtype included)."""
    if hasattr(a, "__dataclass_fields__"):
        assert type(a) is type(b), where
        for name in a.__dataclass_fields__:
            _assert_same(getattr(a, name), getattr(b, name), f"{where}.{name}")
    elif isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for key in a:
            _assert_same(a[key], b[key], f"{where}[{key!r}]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _assert_same(x, y, f"{where}[{i}]")
    elif isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape, where
        assert np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"), where
    elif isinstance(a, float) and np.isnan(a):
        assert isinstance(b, float) and np.isnan(b), where
    else:
        assert a == b, where


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("kind", ("sweep", "atlas", "critical-curve", "impact-train"))
def test_an_unchanged_xarray_resave_loads_as_the_archive(kind, engine, archives, tmp_path):
    copy = _resave(archives[kind], tmp_path / "copy.nc", engine)
    with h5py.File(copy, "r") as f:  # netCDF stores numbers as length-1 arrays: what failed before
        assert f.attrs["schema_version"].shape == (1,)
    _assert_same(archive.load(archives[kind]), archive.load(copy), kind)
    assert archive.describe(copy)["schema_version"] == archive.SCHEMA_VERSION


def test_an_xarray_resave_plots(archives, tmp_path):
    copy = _resave(archives["atlas"], tmp_path / "copy.nc", "netcdf4")
    code, _, err = run(["plot", copy, "--out", tmp_path / "atlas.png"])
    assert code == 0, err
    assert (tmp_path / "atlas.png").read_bytes()[:4] == b"\x89PNG"


def test_attributes_are_read_as_scalars_or_length_1_arrays(archives, tmp_path):
    path = tmp_path / "arrays.nc"
    path.write_bytes(open(archives["critical-curve"], "rb").read())
    with h5py.File(path, "r+") as f:
        for key in ("schema_version", "contact_index", "rtol", "t_end"):
            f.attrs[key] = np.atleast_1d(f.attrs[key])
    _assert_same(archive.load(archives["critical-curve"]), archive.load(path))
    with h5py.File(path, "r+") as f:  # a longer array is no number: damage, named
        f.attrs["rtol"] = np.array([1e-10, 1e-9])
    with pytest.raises(archive.DamagedArchiveError, match=r"attribute rtol = \[1e-10, 1e-09\]"):
        archive.load(path)


def test_a_consistent_subset_loads_as_that_part_of_the_grid(archives, results, tmp_path):
    whole = results["atlas"]
    part = archive.load(_resave(archives["atlas"], tmp_path / "part.nc", change=lambda ds: ds.isel(kappa=[0, 1])))
    assert part.grid.shape == (2, 2)
    np.testing.assert_array_equal(part.grid.axes[0].values, whole.grid.axes[0].values[:2])
    np.testing.assert_array_equal(part.outcome, whole.outcome.reshape(3, 2)[:2].ravel())
    np.testing.assert_array_equal(part.values["max_force"], whole.values["max_force"].reshape(3, 2)[:2].ravel())


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize(("change", "reason"), [
    (lambda ds: ds.sel(v=1.0), "variable v has shape ()"),  # the axis became a scalar
    (lambda ds: ds.sel(v=[2.0]), "stick_point disagrees"),  # rows of points no longer in the grid
])
def test_a_subset_that_is_no_archive_is_refused_as_xarrays_copy(change, reason, engine, archives, tmp_path):
    subset = _resave(archives["atlas"], tmp_path / "subset.nc", engine, change)
    with pytest.raises(ValueError, match="written by xarray") as refused:
        archive.load(subset)
    assert not isinstance(refused.value, archive.DamagedArchiveError) and "damaged" not in str(refused.value)
    assert reason in str(refused.value)
    code, _, err = run(["plot", subset, "--out", tmp_path / "subset.png"])
    assert code != 0 and "written by xarray" in err and "damaged" not in err


def test_extras_left_out_by_xarray_are_named(results, tmp_path):
    grid = results["atlas"]
    found = refine_boundaries(grid, "kappa", refine_rtol=1e-4)
    refined = grid.__class__(grid.grid, grid.t_end, grid.settings, status=grid.status, outcome=grid.outcome,
                             stop_reason=grid.stop_reason, stick_point=grid.stick_point, stick_t=grid.stick_t,
                             stick_delta=grid.stick_delta, stick_dwell=grid.stick_dwell,
                             extras={"boundaries": {"axis": found.axis, "points": found.points,
                                                    "below": found.below, "above": found.above}})
    refined.values.update(grid.values)
    path = archive.save(refined, tmp_path / "refined.nc")
    _assert_same(archive.load(path).extras, refined.extras)
    with pytest.raises(ValueError, match=r"written by xarray .*/extras .*xarray writes the root group only"):
        archive.load(_resave(path, tmp_path / "copy.nc"))


def test_a_changed_phaseimpact_file_is_still_damaged(archives, tmp_path):
    """The xarray reading applies to netCDF writers' files only: phaseimpact's own file, changed, is damage."""
    path = tmp_path / "changed.nc"
    path.write_bytes(open(archives["atlas"], "rb").read())
    with h5py.File(path, "r+") as f:
        f.attrs["extras_digest"] = "0" * 64
    with pytest.raises(archive.DamagedArchiveError, match="extras_digest"):
        archive.load(path)
