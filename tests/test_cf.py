"""Archives read right by CF tools (issue 27, part 3): compliance-checker at the CF version the files
declare, cfdm (the CF reference reader), cf_units (UDUNITS: every units attribute converts to the
dimension the physics gives, and none carries a fractional power UDUNITS would misread), xarray with
both engines, cf_xarray, and ``to_xarray`` identical to opening the archive. One archive of each
kind: a sweep, an atlas with refined class boundaries and a critical curve, all of the paper law."""

import json
import re

import h5py
import numpy as np
import pytest

from phaseimpact import archive, seed_parameters
from phaseimpact.continuation import atlas, critical_curve, refine_boundaries, sweep
from phaseimpact.integrate import OUTCOMES

xr = pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")
pytest.importorskip("netCDF4")
cf_units = pytest.importorskip("cf_units")

KINDS = ("sweep", "atlas", "critical-curve")
#: A fixed creation time, so that to_xarray and save write the same attributes (created, history).
EPOCH = "1700000000"
ALPHA = seed_parameters().alpha  # 1.5: Hertz

#: The dimension of every variable, in SI base units, from the physics (docs/physics.md): a force is
#: kg m s-2, an energy kg m2 s-2; counts, codes and ratios are pure numbers.
SI = {"v": "m s-1", "max_force": "kg m s-2", "max_indentation": "m", "restitution": "1", "contact_duration": "s",
      "dissipated_energy": "kg m2 s-2", "loop_area": "kg m2 s-2", "n_stick": "1", "n_contacts": "1", "nsteps": "1",
      "nfev": "1", "t_run": "s", "t_stop": "s", "first_stick_delta": "m", "first_stick_margin": "1", "stick_t": "s",
      "stick_delta": "m", "stick_dwell": "s"}
#: Eq. 8's damping force kappa delta^alpha deltadot is in N: kappa is N s m-(1 + alpha), for alpha = 1.5
#: kg m-1.5 s-1, a fractional power that no units attribute may state.
KAPPA_SI = {"kg": 1.0, "m": -1.5, "s": -1.0}
#: The variables holding kappa (the axis of a sweep or atlas, the values of a curve).
KAPPA_VARIABLES = ("kappa", "closed_form", "predicted")


def _boundaries(result):
    """The extras ``phaseimpact atlas --refine kappa`` stores (phaseimpact/cli/grids.py)."""
    found = refine_boundaries(result, "kappa", refine_rtol=1e-4)
    assert len(found) >= 1  # the atlas straddles kappa_c: there is a boundary to store
    return {"axis": found.axis, "points": found.points, "below": found.below, "above": found.above,
            "rtol": found.rtol}


@pytest.fixture(scope="module")
def results():
    grid = atlas(seed_parameters(), "paper", {"kappa": np.geomspace(1e11, 1e13, 3), "v": [1.0, 2.0]})
    grid.extras["boundaries"] = _boundaries(grid)
    return {"sweep": sweep(seed_parameters(), "paper", [1e9, 1e12, 1e13]), "atlas": grid,
            "critical-curve": critical_curve(seed_parameters(), "paper", "v", [1.0, 2.0])}


@pytest.fixture(scope="module")
def archives(results, tmp_path_factory):
    folder = tmp_path_factory.mktemp("cf")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SOURCE_DATE_EPOCH", EPOCH)
        return {kind: archive.save(result, folder / f"{kind}.nc") for kind, result in results.items()}


def _datasets(path):
    """The attributes of every variable of the file (not the netCDF dimensions without one), by path."""
    found = {}

    def visit(name, node):
        if isinstance(node, h5py.Dataset) and not _text(node.attrs.get("NAME", "")).startswith("This is a netCDF"):
            found[name] = dict(node.attrs)

    with h5py.File(path, "r") as f:
        f.visititems(visit)
    return found


def _text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _exponents(units: str) -> dict:
    """A product of powers (``N s m-2.5``) in SI base units, ``{symbol: exponent}``."""
    base = {"N": {"kg": 1, "m": 1, "s": -2}, "kg": {"kg": 1}, "m": {"m": 1}, "s": {"s": 1}}
    out = {}
    for word in units.split():
        symbol, power = re.fullmatch(r"([A-Za-z]+)(-?[\d.]*)", word).groups()
        for unit, exponent in base[symbol].items():
            out[unit] = out.get(unit, 0) + exponent * float(power or 1)
    return {k: v for k, v in out.items() if v}


# ------------------------------------------------------------------------------------------------
# compliance-checker and cfdm
# ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", KINDS)
def test_compliance_checker_reports_no_errors_at_the_declared_cf_version(kind, archives, tmp_path):
    runner = pytest.importorskip("compliance_checker.runner")
    path = archives[kind]
    with h5py.File(path, "r") as f:
        conventions = _text(f.attrs["Conventions"])
        globals_ = {key: _text(f.attrs[key]) for key in ("title", "history", "source", "references")}
    version = re.fullmatch(r"CF-(\d+\.\d+)", conventions).group(1)
    assert tuple(int(x) for x in version.split(".")) >= (1, 9)  # int64 variables are CF 1.9 and later
    assert all(globals_.values()) and kind.replace("-", " ") in globals_["title"]
    assert globals_["history"].startswith("2023-11-14T22:13:20+00:00 phaseimpact")
    runner.CheckSuite.load_all_available_checkers()
    report = tmp_path / "report.json"
    passed, failed = runner.ComplianceChecker.run_checker(str(path), [f"cf:{version}"], 0, "normal",
                                                          output_filename=str(report), output_format="json")
    scores = json.loads(report.read_text())[f"cf:{version}"]
    assert not failed and passed, (scores["high_priorities"], scores["medium_priorities"])
    assert scores["high_count"] == scores["medium_count"] == 0 and scores["possible_points"] > 100
    assert scores["low_count"] == 0, scores["low_priorities"]  # no warning either (title, history, ...)


def _cfdm():
    try:
        import cfdm
    except (ImportError, FileNotFoundError, OSError) as error:  # the UDUNITS-2 C library is loaded on import
        pytest.skip(f"cfdm cannot be imported (it needs the UDUNITS-2 library, libudunits2): {error}")
    return cfdm


@pytest.mark.parametrize("kind", KINDS)
def test_cfdm_reads_every_variable(kind, archives):
    cfdm = _cfdm()
    fields = {f.nc_get_variable().lstrip("/"): f for f in cfdm.read(str(archives[kind]))}
    expected = {"sweep": {"max_force", "outcome", "n_stick", "stick_t", "stick_point"},
                "atlas": {"max_force", "status", "stick_dwell", "extras/boundaries/points",
                          "extras/boundaries/below", "extras/boundaries/above"},
                "critical-curve": {"kappa", "closed_form", "predicted", "requested"}}[kind]
    assert expected <= set(fields), sorted(fields)
    if kind == "critical-curve":  # a fractional power: no units a CF reader could convert wrongly
        kappa = fields["kappa"]
        assert not kappa.has_property("units") and kappa.get_property("fractional_units") == "N s m-2.5"
    else:
        assert fields["max_force"].get_property("units") == "N"
        assert fields["outcome"].get_property("flag_meanings").split() == list(OUTCOMES)
    if kind == "atlas":
        points = fields["extras/boundaries/points"]
        assert points.data.shape == (len(points.data), 2)
        assert json.loads(points.get_property("columns")) == ["kappa", "v"]


# ------------------------------------------------------------------------------------------------
# Units: UDUNITS (cf_units) converts each to the dimension the physics gives
# ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", KINDS)
def test_every_units_attribute_converts_to_its_si_dimension(kind, archives):
    attrs = _datasets(archives[kind])
    units = {name: _text(a["units"]) for name, a in attrs.items() if "units" in a}
    assert units, "no units at all"
    for name, text in units.items():
        assert name in SI, f"{name} has units {text!r}: add its dimension to SI"
        unit = cf_units.Unit(text)
        assert unit.is_convertible(SI[name]), (name, text, SI[name])
        assert unit.convert(1.0, SI[name]) == pytest.approx(1.0, rel=1e-12), (name, text)  # no factor 0.5
    for name in KAPPA_VARIABLES:
        if name in attrs:
            assert "units" not in attrs[name], f"{name}: a fractional power in units (UDUNITS misreads it)"
            assert _exponents(_text(attrs[name]["fractional_units"])) == KAPPA_SI
            assert "integer powers" in _text(attrs[name]["comment"])
    assert {"v", "kappa"} & set(attrs)  # an axis or the curve's parameter is checked
    if kind != "critical-curve":
        assert {"max_force", "dissipated_energy", "stick_t"} <= set(units)


def test_why_a_fractional_power_is_not_a_units_attribute():
    """UDUNITS reads N s m-2.5 as 0.5 kg m-1 s-1: wrong dimension, factor 0.5 (the reason for
    fractional_units); an integer power stays a units attribute that converts exactly."""
    misread = cf_units.Unit("N s m-2.5")
    assert misread.is_convertible("kg m-1 s-1") and misread.convert(1.0, "kg m-1 s-1") == pytest.approx(0.5)
    kuwabara_kono = archive.kappa_units(ALPHA, "kuwabara-kono")  # N s m-1.5
    for text in (archive.kappa_units(ALPHA), archive.axis_units("K", ALPHA), kuwabara_kono):
        assert set(archive.unit_attributes(text)) == {"fractional_units", "comment"}, text
    attrs = archive.unit_attributes(archive.kappa_units(1.0))  # alpha = 1: N s m-2, an integer power
    assert attrs == {"units": "N s m-2"} and cf_units.Unit(attrs["units"]).convert(1.0, "kg m-1 s-1") == 1.0
    assert archive.unit_attributes(archive.axis_units("plate.rho", ALPHA)) == {"units": "kg m-3"}


# ------------------------------------------------------------------------------------------------
# xarray (both engines), cf_xarray, to_xarray
# ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", KINDS)
def test_xarray_engines_agree_and_codes_stay_integers(kind, archives, results):
    with xr.open_dataset(archives[kind], engine="h5netcdf") as h5, \
            xr.open_dataset(archives[kind], engine="netcdf4") as nc:
        assert dict(h5.sizes) == dict(nc.sizes) and set(h5.variables) == set(nc.variables)
        for name in h5.variables:
            assert h5[name].dtype == nc[name].dtype, name
            np.testing.assert_array_equal(h5[name].values, nc[name].values, err_msg=name)
        for ds in (h5, nc):
            names = ("status", "outcome", "stop_reason", "stick_first", "stick_count", "stick_point") \
                if kind != "critical-curve" else ("requested",)
            for name in names:  # codes and row indices: integers after decoding, never floats with NaN
                assert ds[name].dtype.kind == "i", (name, ds[name].dtype)
    if kind == "atlas":
        with xr.open_dataset(archives[kind], engine="netcdf4", group="extras/boundaries") as b:
            found = results[kind].extras["boundaries"]
            assert b.points.dims == ("boundary", "column") and np.array_equal(b.points.values, found["points"])
            assert b.below.dims == ("boundary",) and b.below.attrs["flag_meanings"].split() == list(OUTCOMES)


@pytest.mark.parametrize("kind", ("sweep", "atlas"))
def test_cf_xarray_reads_the_flags(kind, archives, results):
    cf_xarray = pytest.importorskip("cf_xarray")
    assert cf_xarray
    with xr.open_dataset(archives[kind], engine="h5netcdf") as ds:
        assert "CF Axes" in repr(ds.cf) and isinstance(ds.cf.keys(), set)
        # the grid's axes, as xarray plots them (the last along x); no CF coordinate type: a grid of
        # parameters is not space-time (no longitude, latitude, vertical or time)
        assert ds.cf.axes == ({"X": ["kappa"]} if kind == "sweep" else {"X": ["v"], "Y": ["kappa"]})
        assert ds.cf.coordinates == {}
        outcome = results[kind].outcome.reshape(ds.outcome.shape)
        for code, name in enumerate(OUTCOMES):
            np.testing.assert_array_equal((ds.outcome.cf == name).values, outcome == code, err_msg=name)


@pytest.mark.parametrize("kind", KINDS)
def test_to_xarray_is_identical_to_opening_the_archive(kind, archives, results, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", EPOCH)
    memory = archive.to_xarray(results[kind])
    with xr.open_dataset(archives[kind], engine="h5netcdf") as disk:
        xr.testing.assert_identical(memory, disk.load())
    assert memory.attrs["Conventions"] == archive.CONVENTIONS and memory.attrs["title"]


def test_stick_phases_of_an_atlas_file(archives, results):
    grid = results["atlas"]
    rows = archive.stick_phases(archives["atlas"])
    assert rows.sizes["stick"] == len(grid.stick_point) > 0
    np.testing.assert_array_equal(rows.stick_point.values, grid.stick_point)
    i, j = np.unravel_index(grid.stick_point, grid.grid.shape)
    np.testing.assert_array_equal(rows.kappa.values, grid.grid.axes[0].values[i])
    np.testing.assert_array_equal(rows.v.values, grid.grid.axes[1].values[j])
    np.testing.assert_array_equal(rows.stick_delta.values, grid.stick_delta)
    with pytest.raises(ValueError, match="no stick phases"):
        archive.stick_phases(archives["critical-curve"])


# ------------------------------------------------------------------------------------------------
# Exports written by xarray (issue 41, item 3): every to_xarray passes the CF checks as to_netcdf
# writes it; grid axes named for cf_xarray, log axes and flags read by plot_variable
# ------------------------------------------------------------------------------------------------

def _compliance(path, tmp_path) -> dict:
    runner = pytest.importorskip("compliance_checker.runner")
    runner.CheckSuite.load_all_available_checkers()
    report = tmp_path / "report.json"
    runner.ComplianceChecker.run_checker(str(path), ["cf:1.11"], 0, "normal", output_filename=str(report),
                                         output_format="json")
    scores = json.loads(report.read_text())["cf:1.11"]
    return {item["name"]: item["msgs"] for level in ("high_priorities", "medium_priorities", "low_priorities")
            for item in scores[level] if item["msgs"]}


@pytest.fixture(scope="module")
def exports():
    """A Dataset of each kind to_xarray converts that has no archive test above (the archives' kinds
    are checked as files above), with the case and law where the result does not carry them."""
    from phaseimpact import simulate
    from phaseimpact.continuation import Transition
    from phaseimpact.train import basins, impact_train, orbit_diagram

    p = seed_parameters(kappa=3e9)
    given = {"params": p, "law": "hunt-crossley", "settings": {"rtol": 1e-10, "period": 3e-3}}
    return {"trajectory": archive.to_xarray(simulate(seed_parameters(v=1.0, kappa=3e9), "paper", save="steps")),
            "transitions": archive.to_xarray([Transition("staircase-end", 2e12, 2, 1),
                                              Transition("adding-sliding", 1.5e12, 1, None)],
                                             params=p, law="paper", settings={"kappa_min": 1e8, "kappa_max": 1e13}),
            "impact-train": archive.to_xarray(impact_train(p, "hunt-crossley", 3e-3, 3), **given),
            "orbit-diagram": archive.to_xarray(orbit_diagram(p, "hunt-crossley", "kappa", [2e9, 3e9], period=3e-3,
                                                             transients=2, samples=3), **given),
            "basins": archive.to_xarray(basins(p, "hunt-crossley", 0.4e-3, [-1e-4, 1e-4], [0.0]), **given)}


@pytest.mark.parametrize("kind", ("trajectory", "transitions", "impact-train", "orbit-diagram", "basins"))
def test_to_xarray_written_by_xarray_passes_the_cf_checks(kind, exports, tmp_path):
    path = tmp_path / f"{kind}.nc"
    exports[kind].to_netcdf(path)
    assert _compliance(path, tmp_path) == {}
    with h5py.File(path, "r") as f:  # xarray's default, a NaN _FillValue, is refused on a coordinate
        assert not [name for name in exports[kind].coords if "_FillValue" in f[name].attrs]


def test_the_trajectory_time_and_the_transitions_kappa_are_coordinates(exports):
    pytest.importorskip("cf_xarray")  # registers the .cf accessor (an earlier test in this process may not have)
    run = exports["trajectory"]
    assert run.cf.axes == {"T": ["t"]} and run.t.attrs["units"] == "s" and run.force.dims == ("t",)
    found = exports["transitions"]
    assert found.kappa.values.tolist() == [1.5e12, 2e12]  # sorted: a coordinate increases
    assert found.sel(kappa=2e12).count_below.item() == 2 and found.cf.axes == {"X": ["kappa"]}
    assert found.sel(kappa=1.6e12, method="nearest").kind.item() == archive.TRANSITION_KINDS.index("adding-sliding")


def test_basins_and_orbit_diagrams_name_their_axes(exports):
    pytest.importorskip("cf_xarray")  # registers the .cf accessor
    assert exports["basins"].cf.axes == {"X": ["x2"], "Y": ["x2dot"]}
    assert exports["orbit-diagram"].cf.axes == {"X": ["kappa"]}


def test_every_kind_names_its_engine(results, exports):
    from phaseimpact.continuation.sweep import ENGINE

    engines = {kind: archive.to_xarray(r).attrs["engine"] for kind, r in results.items()}
    engines.update({kind: ds.attrs["engine"] for kind, ds in exports.items()})
    assert all(engines.values()), engines
    assert engines["critical-curve"] == engines["transitions"] == engines["basins"] == ENGINE
    assert "DOP853" in engines["trajectory"]  # the run's own integrator line


def test_plot_variable_puts_log_axes_on_log_scales_and_names_flags(results):
    from phaseimpact.plotting import plot_variable

    ds = archive.to_xarray(results["atlas"])
    assert int(ds.kappa.attrs["log"]) == 1 and int(ds.v.attrs["log"]) == 0
    mesh = plot_variable(ds.outcome)  # kappa along y (xarray's order), v along x
    assert (mesh.axes.get_xscale(), mesh.axes.get_yscale()) == ("linear", "log")
    assert [t.get_text() for t in mesh.colorbar.ax.get_yticklabels()] == list(OUTCOMES)
    np.testing.assert_array_equal(mesh.colorbar.get_ticks(), np.arange(len(OUTCOMES)))
    line = plot_variable(ds.max_force.sel(v=1.0))[0]
    assert line.axes.get_xscale() == "log"
    dots = plot_variable(ds.status.sel(v=1.0))[0]
    assert [t.get_text() for t in dots.axes.get_yticklabels()][:2] == ["success", "step-size-collapse"]


def test_to_xarray_without_xarray_names_the_extra(results, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "xarray", None)
    with pytest.raises(ImportError, match=r"phaseimpact\[xarray\]"):
        archive.to_xarray(results["sweep"])
