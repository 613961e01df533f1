"""``archive.to_xarray`` on every result (issue 27, part 4) and archives of trains of impacts (issue 26):
each Dataset against the result's own arrays (not against another conversion), units that UDUNITS
reads, train archives loaded back bit for bit, opened by xarray as ``to_xarray`` gives them, and
passing compliance-checker at the CF version they declare. Small cases: the seed plate with
Hunt-Crossley at kappa 3e9, a few impacts every 3 ms (three plate periods)."""

import json
import re

import h5py
import numpy as np
import pytest

from phaseimpact import archive, seed_parameters, simulate
from phaseimpact.continuation import Transition, transitions
from phaseimpact.integrate import OUTCOMES, STATUSES
from phaseimpact.integrate.result import SUMMARY_COLUMNS
from phaseimpact.train import basins, continue_map_orbit, impact_train, orbit_diagram

xr = pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")
cf_units = pytest.importorskip("cf_units")

LAW = "hunt-crossley"
TRANSITION_CODES = {name: code for code, name in enumerate(archive.TRANSITION_KINDS)}
PARAMS = seed_parameters(kappa=3e9)
PERIOD = 3e-3
#: A fixed creation time, so that to_xarray and save write the same attributes (created, history).
EPOCH = "1700000000"
SETTINGS = {"rtol": 1e-10, "period": PERIOD}


@pytest.fixture(scope="module")
def trains():
    """One result of each archived train kind."""
    return {"impact-train": impact_train(PARAMS, LAW, PERIOD, 4),
            "orbit-diagram": orbit_diagram(PARAMS, LAW, "kappa", [2e9, 3e9], period=PERIOD, transients=2,
                                           samples=3),
            # crosses the period doubling near T = 0.9865 ms (train.continue_map_bifurcation's example)
            "map-branch": continue_map_orbit(PARAMS, LAW, "T", 0.9985e-3, 0.9845e-3, step=2e-6),
            "basins": basins(PARAMS, LAW, 0.4e-3, [-1e-4, 1e-4], [0.0])}


@pytest.fixture(scope="module")
def train_archives(trains, tmp_path_factory):
    folder = tmp_path_factory.mktemp("trains")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SOURCE_DATE_EPOCH", EPOCH)
        return {kind: archive.save(r, folder / f"{kind}.nc", params=PARAMS, law=LAW, settings=SETTINGS)
                for kind, r in trains.items()}


def _convert(result, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", EPOCH)
    return archive.to_xarray(result, params=PARAMS, law=LAW, settings=SETTINGS)


def _check_units(ds) -> None:
    """Every ``units`` attribute parses in UDUNITS (cf_units); a fractional power is never one."""
    for name, variable in ds.variables.items():
        if "units" in variable.attrs:
            cf_units.Unit(variable.attrs["units"])
            assert not re.search(r"\d\.\d", variable.attrs["units"]), name
        if "fractional_units" in variable.attrs:
            assert "units" not in variable.attrs and variable.attrs["fractional_units"] in variable.attrs["long_name"]


def _flag(ds, name) -> list:
    """The meanings of an integer flag variable's values."""
    assert ds[name].dtype.kind == "i", name  # codes stay integers after decoding
    meanings = ds[name].attrs["flag_meanings"].split()
    assert ds[name].attrs["flag_values"].tolist() == list(range(len(meanings)))
    return [meanings[c] for c in np.atleast_1d(ds[name].values)]


# ------------------------------------------------------------------------------------------------
# A trajectory
# ------------------------------------------------------------------------------------------------

def test_a_trajectory_with_samples():
    tr = simulate(PARAMS, LAW, save="steps")
    ds = archive.to_xarray(tr)
    assert ds.sizes["t"] == len(tr.t) > 10 and ds.sizes["event"] == len(tr.events)
    assert ds.attrs["kind"] == "trajectory" and json.loads(ds.attrs["law"]) == tr.law.as_dict()
    assert json.loads(ds.attrs["parameters"]) == json.loads(json.dumps(tr.params.as_dict()))
    assert ds.attrs["message"] == tr.message and ds.attrs["rtol"] == 1e-10 and ds.attrs["t_end"] == tr.t_end
    np.testing.assert_array_equal(ds.t.values, tr.t)
    for name, expected, units in (("x1", tr.x1, "m"), ("x2", tr.x2, "m"), ("x1dot", tr.y[:, 2], "m s-1"),
                                  ("x2dot", tr.y[:, 3], "m s-1"), ("contact_work", tr.y[:, 4], "J"),
                                  ("delta", tr.delta, "m"), ("deltadot", tr.deltadot, "m s-1"),
                                  ("force", tr.force, "N")):
        np.testing.assert_array_equal(ds[name].values, expected, err_msg=name)
        assert ds[name].dims == ("t",) and ds[name].attrs["units"] == units and ds[name].attrs["long_name"]
    np.testing.assert_array_equal(ds.mode.values, tr.mode)
    # the event log
    assert _flag(ds, "event_kind") == [e.kind for e in tr.events]
    np.testing.assert_array_equal(ds.event_time.values, [e.t for e in tr.events])
    np.testing.assert_array_equal(ds.event_force.values, [e.force for e in tr.events])
    np.testing.assert_array_equal(ds.event_mode.values, [e.mode for e in tr.events])
    np.testing.assert_array_equal(ds.event_x1.values - ds.event_x2.values, [e.delta for e in tr.events])
    # the summary
    assert _flag(ds, "status") == [tr.status] and _flag(ds, "outcome") == [tr.outcome]
    assert _flag(ds, "stop_reason") == [tr.stop_reason]
    assert ds.max_force.item() == tr.max_force and ds.max_force.attrs["units"] == "N"
    assert ds.n_contacts.item() == tr.n_contacts and ds.n_stick.item() == tr.n_stick
    assert ds.restitution.item() == tr.restitution and np.isnan(ds.t_run.item()) and tr.t_run is None
    assert {name for name, *_ in SUMMARY_COLUMNS} <= set(ds.data_vars)
    np.testing.assert_array_equal(ds.initial_state.values, tr.initial_state)
    np.testing.assert_array_equal(ds.final_state.values, tr.final_state)
    assert ds.final_mode.item() == tr.final_mode
    _check_units(ds)


def test_a_summary_run_has_its_events_and_summary_without_samples():
    tr = simulate(PARAMS, LAW, save="summary")
    ds = archive.to_xarray(tr)
    assert ds.sizes["t"] == 0 and ds.sizes["event"] == len(tr.events) > 0
    np.testing.assert_array_equal(ds.event_time.values, tr.event_t)
    assert ds.dissipated_energy.item() == tr.dissipated_energy and _flag(ds, "outcome") == [tr.outcome]
    assert set(_flag(ds, "outcome")) <= set(OUTCOMES) and set(_flag(ds, "status")) <= set(STATUSES)


def test_a_trajectory_carries_its_own_law_and_takes_only_its_own_case():
    run = simulate(PARAMS, LAW, save="summary")
    with pytest.raises(TypeError, match="carries its own law"):
        archive.to_xarray(run, law=LAW)
    with pytest.raises(ValueError, match="params is not the trajectory's case"):
        archive.to_xarray(run, params=PARAMS.replace(v=2.0))
    assert archive.to_xarray(run, params=PARAMS).attrs["parameters"] == archive.to_xarray(run).attrs["parameters"]


# ------------------------------------------------------------------------------------------------
# Transitions
# ------------------------------------------------------------------------------------------------

def test_transitions():
    found = transitions(PARAMS, LAW, 1e8, 1e13, num=80)
    ds = archive.to_xarray(found, params=PARAMS, law=LAW, settings={"kappa_min": 1e8, "kappa_max": 1e13})
    assert ds.sizes["kappa"] == len(found) >= 2 and ds.attrs["kind"] == "transitions"
    assert [t.kappa for t in found] == sorted(t.kappa for t in found)  # as the coordinate orders them
    assert ds.sel(kappa=found[1].kappa).kind.item() == TRANSITION_CODES[found[1].kind]
    assert _flag(ds, "kind") == [t.kind for t in found]
    np.testing.assert_array_equal(ds.kappa.values, [t.kappa for t in found])
    assert ds.kappa.attrs["fractional_units"] == "N s m-2.5" and "units" not in ds.kappa.attrs
    for name in ("count_below", "count_above", "extremum"):
        assert ds[name].values.tolist() == [getattr(t, name) for t in found]
    assert (ds.attrs["kappa_min"], ds.attrs["kappa_max"]) == (1e8, 1e13)
    assert json.loads(ds.attrs["law"])["name"] == LAW
    _check_units(ds)


def test_a_count_that_is_not_known_is_missing_not_minus_one():
    ds = archive.to_xarray([Transition("adding-sliding", 1.5e12, 1, None)])
    assert ds.count_below.item() == 1 and np.isnan(ds.count_above.item()) and np.isnan(ds.extremum.item())
    assert "law" not in ds.attrs  # not given: left out
    assert ds.kappa.attrs["fractional_units"] == "N s m-(1+alpha)"
    assert archive.to_xarray([]).sizes["kappa"] == 0  # none in the range


# ------------------------------------------------------------------------------------------------
# Trains of impacts: the Datasets
# ------------------------------------------------------------------------------------------------

def test_an_impact_train(trains, monkeypatch):
    r = trains["impact-train"]
    ds = _convert(r, monkeypatch)
    assert dict(ds.sizes) == {"arrival": 5, "impact": 4} and ds.attrs["period"] == PERIOD == ds.attrs["t_end"]
    np.testing.assert_array_equal(ds.x2.values, r.plate[:, 0])
    np.testing.assert_array_equal(ds.x2dot.values, r.plate[:, 1])
    np.testing.assert_array_equal(ds.amplitude.values, r.amplitude)
    for name, units in (("peak_force", "N"), ("dissipated_energy", "J"), ("restitution", "1"), ("energy_in", "J"),
                        ("n_contacts", "1")):
        np.testing.assert_array_equal(ds[name].values, getattr(r, name), err_msg=name)
        assert ds[name].dims == ("impact",) and ds[name].attrs["units"] == units
    assert ds.n_contacts.dtype == np.int64
    assert _flag(ds, "status") == r.status and _flag(ds, "overlap") == ["yes" if o else "no" for o in r.overlap]
    assert ds.x2dot.attrs["units"] == "m s-1" and ds.impact.values.tolist() == [0, 1, 2, 3]
    assert json.loads(ds.attrs["settings"]) == SETTINGS and ds.attrs["rtol"] == 1e-10
    _check_units(ds)


def test_an_orbit_diagram(trains, monkeypatch):
    r = trains["orbit-diagram"]
    ds = _convert(r, monkeypatch)
    assert dict(ds.sizes) == {"kappa": 2, "sample": 3} and ds.attrs["param"] == "kappa"
    np.testing.assert_array_equal(ds.kappa.values, r.values)
    assert ds.kappa.attrs["fractional_units"] == "N s m-2.5"
    np.testing.assert_array_equal(ds.x2.values, r.plate[..., 0])
    np.testing.assert_array_equal(ds.x2dot.values, r.plate[..., 1])
    np.testing.assert_array_equal(ds.peak_force.values, r.peak_force)
    np.testing.assert_array_equal(ds.distinct.values, r.distinct)
    assert ds.x2.dims == ("kappa", "sample") and ds.attrs["period"] == PERIOD
    _check_units(ds)


def test_an_orbit_diagram_over_the_period_has_no_single_period(monkeypatch):
    r = orbit_diagram(PARAMS, LAW, "T", [0.4e-3, PERIOD], transients=1, samples=2)
    ds = _convert(r, monkeypatch)
    assert ds["T"].attrs["units"] == "s" and "period" not in ds.attrs and np.isnan(ds.attrs["t_end"])


def test_a_map_branch(trains, monkeypatch):
    r = trains["map-branch"]
    ds = _convert(r, monkeypatch)
    assert ds.sizes["point"] == len(r.values) and ds.sizes["bifurcation"] == len(r.points) >= 1
    np.testing.assert_array_equal(ds["T"].values, r.values)
    assert ds["T"].attrs["units"] == "s" and ds.attrs["period_k"] == r.period_k and ds.attrs["message"] == r.message
    np.testing.assert_array_equal(ds.x2.values, r.plate[:, 0])
    np.testing.assert_array_equal(ds.multiplier_real.values + 1j * ds.multiplier_imag.values, r.multipliers)
    assert _flag(ds, "stable") == ["yes" if s else "no" for s in r.stable]
    np.testing.assert_array_equal(ds.contacts.values, r.contacts)
    assert _flag(ds, "bifurcation_kind") == [p.kind for p in r.points] == ["period-doubling"]
    np.testing.assert_array_equal(ds.bifurcation_value.values, [p.value for p in r.points])
    assert ds.bifurcation_contacts.values.tolist() == [[list(side) for side in p.contacts] for p in r.points]
    _check_units(ds)


def test_basins(trains, monkeypatch):
    r = trains["basins"]
    ds = _convert(r, monkeypatch)
    assert dict(ds.sizes) == {"x2dot": 1, "x2": 2, "attractor": 1, "orbit_point": 1}
    np.testing.assert_array_equal(ds.labels.values, r.labels)
    np.testing.assert_array_equal(ds.impacts.values, r.impacts)
    np.testing.assert_array_equal(ds.x2.values, r.x2_values)
    assert ds.attractor_period.values.tolist() == [a.period for a in r.attractors]
    assert ds.attractor_count.values.tolist() == [a.count for a in r.attractors]
    np.testing.assert_array_equal(np.stack([ds.attractor_x2.values, ds.attractor_x2dot.values], axis=1),
                                  np.concatenate([a.plate for a in r.attractors]))
    assert ds.attrs["period"] == 0.4e-3 and ds.attrs["not_converged"] == r.not_converged
    _check_units(ds)


def test_an_unsupported_type_is_named():
    with pytest.raises(TypeError, match=r"cannot convert a dict; allowed: .*, a Trajectory, .*ImpactTrain"):
        archive.to_xarray({})
    with pytest.raises(TypeError, match=r"cannot archive a dict; allowed: .*, a Trajectory, .*OrbitDiagram"):
        archive.save({}, "unused.nc")


# ------------------------------------------------------------------------------------------------
# Trains of impacts: the archives
# ------------------------------------------------------------------------------------------------

def _same_bits(a, b, where: str) -> None:
    if isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape, where
        assert a.tobytes() == b.tobytes(), where
    elif isinstance(a, (list, tuple)) and a and hasattr(a[0], "__dataclass_fields__"):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _same_object(x, y, f"{where}[{i}]")
    else:
        assert type(a) is type(b) and a == b, where


def _same_object(a, b, where: str = "") -> None:
    assert type(a) is type(b)
    for name in a.__dataclass_fields__:
        _same_bits(getattr(a, name), getattr(b, name), f"{where}.{name}")


@pytest.mark.parametrize("kind", archive.TRAIN_KINDS)
def test_a_train_archive_loads_back_bit_for_bit(kind, trains, train_archives):
    back = archive.load(train_archives[kind])
    _same_object(trains[kind], back, kind)
    held = archive.describe(train_archives[kind])
    assert held["kind"] == kind == archive.kind_of(back) and held["law"]["name"] == LAW
    assert held["parameters"]["kappa"] == 3e9


@pytest.mark.parametrize("kind", archive.TRAIN_KINDS)
def test_to_xarray_is_identical_to_opening_the_train_archive(kind, trains, train_archives, monkeypatch):
    with xr.open_dataset(train_archives[kind]) as opened:
        xr.testing.assert_identical(_convert(trains[kind], monkeypatch), opened.load())


def test_a_train_archive_needs_its_case_and_law(trains, tmp_path):
    with pytest.raises(TypeError, match="needs params= and law="):
        archive.save(trains["impact-train"], tmp_path / "t.nc", law=LAW)
    assert not (tmp_path / "t.nc").exists()


def test_a_damaged_train_archive_is_refused(trains, train_archives, tmp_path):
    path = tmp_path / "damaged.nc"
    path.write_bytes(open(train_archives["impact-train"], "rb").read())
    with h5py.File(path, "r+") as f:
        f["status"][0] = 9  # not a status
    with pytest.raises(archive.DamagedArchiveError, match="status"):
        archive.load(path)


@pytest.mark.parametrize("kind", archive.TRAIN_KINDS)
def test_compliance_checker_reports_no_errors_on_a_train_archive(kind, train_archives, tmp_path):
    runner = pytest.importorskip("compliance_checker.runner")
    path = train_archives[kind]
    with h5py.File(path, "r") as f:
        conventions = f.attrs["Conventions"]
    version = re.fullmatch(r"CF-(\d+\.\d+)", conventions).group(1)
    runner.CheckSuite.load_all_available_checkers()
    report = tmp_path / "report.json"
    passed, failed = runner.ComplianceChecker.run_checker(str(path), [f"cf:{version}"], 0, "normal",
                                                          output_filename=str(report), output_format="json")
    scores = json.loads(report.read_text())[f"cf:{version}"]
    assert not failed and passed, (scores["high_priorities"], scores["medium_priorities"])
    assert scores["high_count"] == scores["medium_count"] == scores["low_count"] == 0, scores["low_priorities"]


def test_train_archives_of_the_command_line_keep_the_case_name_and_description(tmp_path):
    """The command line archives the case it ran (name, description, source), not only its numbers."""
    from _cli import run

    from phaseimpact.case import load_case

    path = tmp_path / "train.nc"
    code, _, err = run(["train", "--law", LAW, "--kappa", "3e9", "--period", "3e-3", "--impacts", "2",
                        "--archive", path])
    assert code == 0, err
    with h5py.File(path, "r") as f:
        assert f.attrs["base"] == "case"
        case = json.loads(f.attrs["case"])
    seed = load_case("seed")
    assert (case["name"], case["description"]) == (seed.name, seed.description) and seed.description
    assert json.loads(xr.open_dataset(path).attrs["case"])["name"] == "seed"
