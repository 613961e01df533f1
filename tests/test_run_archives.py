"""Archives of one run and of a transition search (issue 41, item 2): ``simulate --out`` and
``transitions --out`` write them, :func:`archive.load` gives back the Trajectory or the list of
Transition saved (every array bit for bit), a file xarray re-saved loads too, and ``plot`` refuses
them by their kind."""

import dataclasses
import json

import h5py
import numpy as np
import pytest
from _cli import run

from phaseimpact import archive, seed_parameters, simulate
from phaseimpact.case import load_case
from phaseimpact.continuation import Transition
from phaseimpact.integrate import driver

# kappa 2e12: a ratchet escape (two stick phases, an escape); a step limit: a failed run
RUNS = {"steps": dict(kappa=2e12, save="steps"), "summary": dict(kappa=2e12),
        "failed": dict(kappa=2e12, save="steps", max_steps=20)}
# not sorted by kind, with every optional count missing somewhere
TRANSITIONS = [Transition("grazing", 3.5769941761958e10, 2, 3, 5), Transition("adding-sliding", 1.5e12, 1, None),
               Transition("staircase-end", 2.25e12, None, 2, None)]


def _run(name):
    options = dict(RUNS[name])
    kappa = options.pop("kappa")
    return simulate(seed_parameters(v=1.0, kappa=kappa), "paper", **options)


def _assert_same_trajectory(a, b):
    for field in dataclasses.fields(a):
        x, y = getattr(a, field.name), getattr(b, field.name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes(), field.name
        else:
            assert type(x) is type(y) and x == y, field.name
    assert a.message == b.message and len(a.events) == len(b.events)
    assert all(e.kind == f.kind and e.t == f.t and e.state.tobytes() == f.state.tobytes() and e.mode == f.mode
               for e, f in zip(a.events, b.events, strict=True))


@pytest.mark.parametrize("name", sorted(RUNS))
def test_a_trajectory_loads_back_bit_for_bit(name, tmp_path):
    tr = _run(name)
    assert (len(tr.t) > 0) == ("save" in RUNS[name]) and tr.ok == (name != "failed")
    path = archive.save(tr, tmp_path / "run.nc")
    back = archive.load(path)
    _assert_same_trajectory(tr, back)
    assert back.message == tr.message and back.n_stick == tr.n_stick and back.status == tr.status
    held = archive.describe(path)
    assert held["kind"] == "trajectory" and held["t_end"] == tr.t_end and held["axes"] == {}


def test_a_damaged_trajectory_archive_is_refused_naming_the_damage(tmp_path):
    path = archive.save(_run("steps"), tmp_path / "run.nc")
    with h5py.File(path, "r+") as f:
        f["event_kind"][0] = 99
    with pytest.raises(archive.DamagedArchiveError, match="event_kind"):
        archive.load(path)


def test_a_run_a_user_law_ended_loads_back_with_its_message(tmp_path):
    import math

    from phaseimpact import define_law

    define_law("nan-deep-archived", lambda d, dd, K, k, a: math.nan if d > 3e-5 else K * d ** a)
    tr = simulate(seed_parameters(kappa=1e4), "nan-deep-archived", save="steps")
    assert tr.status == "non-finite" and tr.law_fault and tr.message.startswith("law 'nan-deep-archived'")
    back = archive.load(archive.save(tr, tmp_path / "fault.nc"))
    _assert_same_trajectory(tr, back)
    assert back.law_fault == tr.law_fault


def test_transitions_load_back_bit_for_bit_in_increasing_kappa(tmp_path):
    path = archive.save(TRANSITIONS, tmp_path / "found.nc", params=seed_parameters(), law="paper",
                        settings={"kappa_min": 1e8, "kappa_max": 1e13, "rtol": 1e-10})
    back = archive.load(path)
    assert back == sorted(TRANSITIONS, key=lambda t: t.kappa) == TRANSITIONS
    assert [np.float64(t.kappa).tobytes() for t in back] == [np.float64(t.kappa).tobytes() for t in TRANSITIONS]
    assert archive.describe(path)["kind"] == "transitions"
    assert archive.load(archive.save([], tmp_path / "none.nc", params=seed_parameters(), law="paper")) == []


def test_a_trajectory_archive_names_its_case_and_refuses_another_case(tmp_path):
    case = load_case("sand-gelcoat")
    tr = simulate(case.parameters(), "thornton", 1e-5)
    with h5py.File(archive.save(tr, tmp_path / "run.nc", params=case, settings={"rtol": 1e-10}), "r") as f:
        assert json.loads(f.attrs["case"])["name"] == "sand-gelcoat" and f.attrs["base"] == "case"
        assert json.loads(f.attrs["settings"]) == {"rtol": 1e-10} and f.attrs["rtol"] == 1e-10
    with pytest.raises(ValueError, match="params is not the trajectory's case"):
        archive.save(tr, tmp_path / "other.nc", params=load_case("seed"))
    with pytest.raises(TypeError, match="carries its own law"):
        archive.save(tr, tmp_path / "other.nc", law="paper")


@pytest.mark.parametrize("engine", ("h5netcdf", "netcdf4"))
def test_an_xarray_resave_of_either_kind_loads_as_the_archive(engine, tmp_path):
    xr = pytest.importorskip("xarray")
    pytest.importorskip({"h5netcdf": "h5netcdf", "netcdf4": "netCDF4"}[engine])
    tr = _run("steps")
    for name, result, context in (("run", tr, {}), ("found", TRANSITIONS,
                                                    {"params": seed_parameters(), "law": "paper"}),
                                  ("none", [], {"params": seed_parameters(), "law": "paper"})):
        path = archive.save(result, tmp_path / f"{name}.nc", **context)
        copy = tmp_path / f"{name}-copy.nc"
        with xr.open_dataset(path) as ds:
            ds.to_netcdf(copy, engine=engine)
        back = archive.load(copy)
        if name == "run":
            _assert_same_trajectory(tr, back)
        else:
            assert back == result


def test_to_xarray_of_a_trajectory_is_its_archive_in_memory(tmp_path):
    xr = pytest.importorskip("xarray")
    tr = _run("steps")
    with xr.open_dataset(archive.save(tr, tmp_path / "run.nc")) as ds:
        in_memory = archive.to_xarray(tr)
        assert set(ds.variables) == set(in_memory.variables)
        assert float(ds.first_stick_t) == tr.summary[driver.S_FIRST_STICK_T]
        assert np.array_equal(ds.force.values, tr.force)


# ------------------------------------------------------------------------------------------------
# The command line
# ------------------------------------------------------------------------------------------------

SIMULATE = ["simulate", "--kappa", "2e12"]
FIND = ["transitions", "--law", "hunt-crossley", "--kappa-min", "1e8", "--kappa-max", "1e12", "--samples", "40"]


def test_simulate_out_writes_the_run_it_prints(tmp_path):
    code, plain, err = run([*SIMULATE, "--json"])
    assert code == 0, err
    out = tmp_path / "run.nc"
    code, stdout, err = run([*SIMULATE, "--out", out, "--json"])
    assert code == 0, err
    printed, alone = json.loads(stdout), json.loads(plain)
    assert printed.pop("out") == str(out) and alone.pop("out") is None
    assert printed == alone  # keeping the steps changes nothing of the run
    back = archive.load(out)
    expected = simulate(seed_parameters(v=1.0, kappa=2e12), "paper", save="steps", stop_when_settled=True)
    _assert_same_trajectory(expected, back)
    assert back.max_force == printed["max_force"] and len(back.t) > 0
    with h5py.File(out, "r") as f:
        assert json.loads(f.attrs["case"])["name"] == "seed" and json.loads(f.attrs["law"])["name"] == "paper"


def test_transitions_out_writes_what_it_prints(tmp_path):
    out = tmp_path / "found.nc"
    code, stdout, err = run([*FIND, "--out", out, "--json"])
    assert code == 0, err
    printed = json.loads(stdout)
    assert printed["out"] == str(out)
    assert [t.as_dict() for t in archive.load(out)] == printed["transitions"] and printed["transitions"]
    code, stdout, _ = run([*FIND, "--out", out])
    assert code == 0 and f"wrote {out} ({len(printed['transitions'])} transitions)" in stdout


@pytest.mark.parametrize(("argv", "other"), [
    (SIMULATE, ["simulate", "--kappa", "3e12"]),
    (SIMULATE, ["simulate", "--kappa", "2e12", "--rtol", "1e-9"]),
    (FIND, [a.replace("1e12", "1e11") for a in FIND]),
    (FIND, ["simulate", "--law", "hunt-crossley"]),
])
def test_out_refuses_other_work_and_foreign_files_unless_force(argv, other, tmp_path):
    out = tmp_path / "held.nc"
    assert run([*argv, "--out", out])[0] == 0
    assert run([*argv, "--out", out])[0] == 0  # the same work again: replaced without --force
    before = out.read_bytes()
    code, _, err = run([*other, "--out", out])
    assert code == 2 and "holds other work" in err and "--force" in err
    assert out.read_bytes() == before
    assert run([*other, "--out", out, "--force"])[0] == 0
    assert archive.describe(out)["kind"] == ("trajectory" if other[0] == "simulate" else "transitions")
    notes = tmp_path / "notes.txt"
    notes.write_text("mine")
    code, _, err = run([*argv, "--out", notes])
    assert code == 2 and "not a phaseimpact archive" in err and notes.read_text() == "mine"


@pytest.mark.parametrize(("argv", "kind"), [(SIMULATE, "trajectory"), (FIND, "transitions")])
def test_plot_refuses_them_by_their_kind(argv, kind, tmp_path):
    out = tmp_path / "held.nc"
    assert run([*argv, "--out", out])[0] == 0
    code, _, err = run(["plot", out, "--out", tmp_path / "fig.png"])
    assert code == 2 and f"is a {kind} archive, which plot does not draw" in err
    assert "damaged" not in err and len(err.strip().splitlines()) == 1 and not (tmp_path / "fig.png").exists()
