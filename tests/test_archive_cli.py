"""HDF5 archive and command line: schema, atomic writes, resume after a kill, bad input."""

import json
import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from phaseimpact import archive, seed_parameters
from phaseimpact.cli import main
from phaseimpact.continuation import sweep
from phaseimpact.model import ContactLaw

CLI = [sys.executable, "-m", "phaseimpact.cli"]


def run_cli(*args):
    return subprocess.run([*CLI, *args], capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def small_sweep():
    return sweep(seed_parameters(), ContactLaw("paper"), np.geomspace(1e9, 1e14, 8))


def test_archive_round_trip_and_plain_h5py(tmp_path, small_sweep):
    path = tmp_path / "s.h5"
    archive.save(small_sweep, path)
    with h5py.File(path, "r") as f:  # plain h5py, documented names and units
        assert f.attrs["schema_version"] == archive.SCHEMA_VERSION
        assert f["sweep/kappa"].attrs["units"] == "N s/m^(1+alpha)"
        offsets = f["sweep/points/offsets"][()]
        assert np.array_equal(np.diff(offsets), f["sweep/n_asymptotic"][()])
        assert json.loads(f.attrs["parameters"])["M1"] == small_sweep.params.M1
    back = archive.load(path)
    assert np.array_equal(back.kappa, small_sweep.kappa)
    assert np.array_equal(back.max_force, small_sweep.max_force)
    assert all(np.array_equal(a, b) for a, b in zip(back.points, small_sweep.points, strict=True))
    assert list(back.outcome) == list(small_sweep.outcome)
    assert back.law == small_sweep.law and back.params == small_sweep.params


def test_archive_rejects_foreign_truncated_and_newer(tmp_path, small_sweep):
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["x"] = 1
    with pytest.raises(ValueError, match="not a phaseimpact archive"):
        archive.load(foreign)
    good = tmp_path / "good.h5"
    archive.save(small_sweep, good)
    truncated = tmp_path / "truncated.h5"
    truncated.write_bytes(good.read_bytes()[: os.path.getsize(good) // 3])
    with pytest.raises(ValueError, match="truncated or foreign|damaged"):
        archive.load(truncated)
    with h5py.File(good, "a") as f:
        f.attrs["schema_version"] = archive.SCHEMA_VERSION + 1
    with pytest.raises(ValueError, match="schema_version"):
        archive.load(good)
    text = tmp_path / "text.h5"
    text.write_text("hello")
    with pytest.raises(ValueError, match="not a readable HDF5"):
        archive.load(text)


def test_cli_json_contracts(capsys):
    assert main(["params", "--json"]) == 0
    params = json.loads(capsys.readouterr().out)
    assert set(params) == {"M1", "M2", "K", "Kb", "Km", "alpha", "kappa", "v"}
    assert main(["simulate", "--law", "paper", "--v", "1", "--kappa", "3e12", "--target", "plate",
                 "--t-end", "0.01", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    expected = {"law", "v", "kappa", "target", "status", "message", "max_force", "max_indentation",
                "contact_duration", "restitution", "time_equal_displacement", "dissipated_energy", "loop_area",
                "asymptotic_points", "outcome"}
    assert expected <= set(out)
    assert out["status"] == "runaway" and out["outcome"] == "runaway"
    assert all(set(p) == {"delta", "deltadot", "dwell"} for p in out["asymptotic_points"])
    assert main(["simulate", "--law", "hunt-crossley", "--restitution", "0.8", "--target", "free",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert abs(out["restitution"] - 0.8) < 1e-8  # exact inverse (REFERENCE §4)


@pytest.mark.parametrize("args, name", [
    (["simulate", "--v", "-1"], "v"),
    (["simulate", "--v", "nan"], "v"),
    (["simulate", "--kappa", "-3"], "kappa"),
    (["simulate", "--t-end", "0"], "t-end"),
    (["simulate", "--law", "flores", "--restitution", "1.5"], "restitution"),
    (["simulate", "--law", "nonsense"], "law"),
    (["simulate", "--target", "wall"], "target"),
    (["sweep", "--kappa-min", "1e10", "--kappa-max", "1e9", "--out", "x.h5"], "kappa-min"),
    (["sweep", "--kappa-min", "1e9", "--kappa-max", "1e10", "--num", "0", "--out", "x.h5"], "num"),
    (["sweep", "--kappa-min", "1e9", "--kappa-max", "1e10", "--jobs", "0", "--out", "x.h5"], "jobs"),
    (["critical-curve", "--v-min", "5", "--v-max", "1", "--out", "x.h5"], "v-min"),
])
def test_cli_bad_input_one_line_exit_2(args, name, tmp_path):
    result = subprocess.run([*CLI, *args], capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    message = result.stderr.strip().splitlines()
    assert len(message) == 1 or message[-1].startswith("phaseimpact")
    assert name in message[-1]
    assert not (tmp_path / "x.h5").exists()


@pytest.mark.slow
def test_sweep_killed_then_resumed_equals_uninterrupted(tmp_path):
    """SIGKILL mid-sweep leaves a valid partial archive; --resume completes it without recomputing
    finished points and gives the numbers of an uninterrupted run."""
    args = ["sweep", "--law", "paper", "--v", "1", "--kappa-min", "1e9", "--kappa-max", "1e14", "--num", "64",
            "--no-progress"]
    partial = tmp_path / "partial.h5"
    proc = subprocess.Popen([*CLI, *args, "--out", str(partial)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.time() + 300
    while time.time() < deadline and not partial.exists():
        time.sleep(0.05)
    time.sleep(0.3)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    half = archive.load(partial)  # valid, whatever the moment of the kill
    done_before = half.done.copy()
    assert 0 < done_before.sum() <= 64
    finished = {i: half.max_force[i] for i in np.flatnonzero(done_before)}

    assert run_cli(*args, "--out", str(partial), "--resume").returncode == 0
    resumed = archive.load(partial)
    assert resumed.done.all()
    assert all(resumed.max_force[i] == value for i, value in finished.items())

    full = tmp_path / "full.h5"
    assert run_cli(*args, "--out", str(full)).returncode == 0
    reference = archive.load(full)
    assert np.array_equal(reference.n_asymptotic, resumed.n_asymptotic)
    assert np.array_equal(reference.max_force, resumed.max_force)
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".tmp")]


def test_two_runs_identical_archives_except_creation_time(tmp_path, small_sweep):
    a, b = tmp_path / "a.h5", tmp_path / "b.h5"
    archive.save(small_sweep, a)
    again = sweep(seed_parameters(), ContactLaw("paper"), np.geomspace(1e9, 1e14, 8), n_jobs=2)
    archive.save(again, b)
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        assert {k: str(v) for k, v in fa.attrs.items() if k != "created"} == \
               {k: str(v) for k, v in fb.attrs.items() if k != "created"}
        names = []
        fa.visit(names.append)
        for name in names:
            if isinstance(fa[name], h5py.Dataset):
                x, y = fa[name][()], fb[name][()]
                assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name
