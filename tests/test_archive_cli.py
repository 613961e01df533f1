"""HDF5 archive and command line: schema, atomic writes, one writer at a time, resume after a kill."""

import importlib
import importlib.util
import json
import os
import re
import shlex
import subprocess
import sys
import textwrap
import time

import h5py
import numpy as np
import pytest

from phaseimpact import _atomic, archive, seed_parameters
from phaseimpact.archive import _common
from phaseimpact.cli import main
from phaseimpact.continuation import sweep
from phaseimpact.model import ContactLaw

CLI = [sys.executable, "-m", "phaseimpact.cli"]
SWEEP = ["sweep", "--law", "paper", "--v", "1", "--axis", "kappa=1e9:1e14:40:log",
         "--no-progress"]


def run_cli(*args, cwd=None, env=None):
    return subprocess.run([*CLI, *args], capture_output=True, text=True, timeout=600, cwd=cwd, env=env)


@pytest.fixture(scope="module")
def small_sweep():
    return sweep(seed_parameters(), ContactLaw("paper"), np.geomspace(1e9, 1e14, 8))


# ------------------------------------------------------------------------------------------------
# Schema (the layout, xarray and plain h5py: tests/test_archive.py)
# ------------------------------------------------------------------------------------------------

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
    with pytest.raises(ValueError, match="not a phaseimpact archive"):  # never replaced without force
        archive.save(small_sweep, text)
    assert text.read_text() == "hello"


def test_schema_1_archives_still_load(tmp_path):
    """An archive written by phaseimpact 0.1 (schema 1) loads into today's result."""
    path = tmp_path / "v1.h5"
    params = seed_parameters()
    with h5py.File(path, "w") as f:
        f.attrs.update({"schema_version": 1, "package_version": "0.1.0", "kind": "sweep", "integrator": "batch",
                        "law": json.dumps({"name": "paper", "restitution": None, "bilateral": False,
                                           "clamp": False}),
                        "parameters": json.dumps({k: v for k, v in params.as_dict().items() if k != "R"}),
                        "rtol": 1e-10, "min_dwell": -1.0, "t_end": 0.01, "created": "2025-01-01T00:00:00+00:00"})
        g = f.create_group("sweep")
        g["kappa"] = [1e9, 1e12, 1e13]
        g["n_asymptotic"] = np.array([1, 2, -1])
        g.create_dataset("outcome", data=np.array(["stick", "runaway", ""], dtype=object), dtype=h5py.string_dtype())
        g.create_dataset("status", data=np.array(["success", "runaway", ""], dtype=object),
                         dtype=h5py.string_dtype())
        for name in ("max_force", "max_indentation", "restitution", "dissipated_energy"):
            g[name] = [1.0, 2.0, np.nan]
        g["points/offsets"] = np.array([0, 1, 3, 3])
        g["points/delta"], g["points/deltadot"], g["points/dwell"] = [1e-5, 2e-5, 3e-5], [0.0] * 3, [1.0] * 3
    back = archive.load(path)
    assert list(back.outcome_names()) == ["permanent-stick", "runaway", "not computed"]
    assert list(back.done) == [True, True, False]  # the missing point is computed on resume
    assert list(back.values["n_stick"]) == [1, 2, -1]
    assert archive.describe(path)["axes"]["kappa"].tolist() == [1e9, 1e12, 1e13]


def test_numpy_scalars_are_stored_as_plain_numbers(tmp_path):
    """float32 / int64 inputs are accepted and the archive holds plain JSON numbers (defect 7)."""
    params = seed_parameters(v=np.float32(1.0))
    result = sweep(params, ContactLaw("hunt-crossley"), np.geomspace(1e9, 1e11, 3), t_end=np.float32(2e-3),
                   rtol=np.float64(1e-10), n_jobs=np.int64(1))
    path = tmp_path / "np.h5"
    archive.save(result, path)
    with h5py.File(path, "r") as f:
        stored = json.loads(f.attrs["parameters"])
        assert type(stored["v"]) is float and stored["v"] == 1.0
        assert isinstance(f.attrs["t_end"], (float, np.floating))
    assert archive.load(path).t_end == pytest.approx(2e-3, rel=1e-6)
    assert json.loads(_common._json({"a": np.float32(0.5), "b": np.int64(3), "c": np.arange(2)})) == \
        {"a": 0.5, "b": 3, "c": [0, 1]}


def test_created_comes_from_source_date_epoch_and_files_are_reproducible(tmp_path, small_sweep, monkeypatch):
    """With SOURCE_DATE_EPOCH (make reproduce sets it) two saves are byte-identical (defect 15)."""
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    a, b = tmp_path / "a.h5", tmp_path / "b.h5"
    archive.save(small_sweep, a)
    time.sleep(1.1)  # a second later: any wall-clock time in the file would now differ
    archive.save(small_sweep, b)
    assert a.read_bytes() == b.read_bytes()
    with h5py.File(a, "r") as f:
        assert f.attrs["created"] == "2023-11-14T22:13:20+00:00"
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "yesterday")
    with pytest.raises(ValueError, match="SOURCE_DATE_EPOCH"):
        archive.save(small_sweep, tmp_path / "c.h5")
    assert not (tmp_path / "c.h5").exists()


def test_results_do_not_depend_on_jobs(tmp_path, small_sweep):
    again = sweep(seed_parameters(), ContactLaw("paper"), np.geomspace(1e9, 1e14, 8), n_jobs=2)
    for name, values in small_sweep.values.items():
        assert np.array_equal(again.values[name], values, equal_nan=values.dtype.kind == "f"), name


# ------------------------------------------------------------------------------------------------
# Command line: JSON contracts
# ------------------------------------------------------------------------------------------------

def test_cli_json_contracts(capsys):
    assert main(["params", "--json"]) == 0
    params = json.loads(capsys.readouterr().out)
    assert {"M1", "M2", "K", "Kb", "Km", "alpha", "kappa", "v", "contact_time", "plate_period", "indentation",
            "peak_pressure", "contact_radius", "validity", "case"} <= set(params)
    assert main(["simulate", "--law", "paper", "--v", "1", "--kappa", "3e12", "--target", "plate",
                 "--t-end", "0.01", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    expected = {"law", "contact", "v", "kappa", "target", "status", "stop_reason", "message", "max_force",
                "max_indentation", "contact_duration", "restitution", "time_equal_displacement",
                "dissipated_energy", "loop_area", "n_stick", "t_run", "stick_points", "asymptotic_points",
                "outcome"}
    assert expected <= set(out)
    assert out["status"] == "success" and out["n_stick"] >= 2
    assert all(set(p) == {"delta", "deltadot", "dwell"} for p in out["asymptotic_points"])
    assert main(["simulate", "--law", "hunt-crossley", "--restitution", "0.8", "--target", "free", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert abs(out["restitution"] - 0.8) < 1e-8  # exact inverse (REFERENCE §4)


def test_cli_sweep_summary_readable_and_json(tmp_path, capsys):
    out = tmp_path / "s.h5"
    assert main([*SWEEP, "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert text.startswith(f"wrote {out}: 40 points") and "{" not in text  # no Python dict
    assert "first split (1 -> 2 stick phases) between kappa =" in text
    assert main([*SWEEP, "--out", str(out), "--json"]) == 0  # same work: may be replaced
    summary = json.loads(capsys.readouterr().out)
    assert summary["points"] == 40 and summary["failed"] == 0 and summary["computed"] == 40
    lo, hi = summary["first_split"]
    assert lo < 1.4994e12 < hi  # kappa_c at 1 m/s (closed form, REFERENCE §5)


# ------------------------------------------------------------------------------------------------
# --out: checked first, never silently replaced, one writer at a time
# ------------------------------------------------------------------------------------------------

def test_out_refuses_foreign_file_and_other_work_unless_force(tmp_path, capsys):
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes")
    assert main([*SWEEP, "--out", str(notes)]) == 2
    assert "not a phaseimpact archive" in capsys.readouterr().err
    assert notes.read_text() == "my notes"

    out = tmp_path / "s.h5"
    assert main([*SWEEP, "--out", str(out)]) == 0
    before = out.read_bytes()
    other = [a.replace(":40:", ":41:") for a in SWEEP]  # a different grid
    assert main([*other, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "holds other work" in err and "--force" in err
    assert main([*SWEEP, "--law", "hunt-crossley", "--out", str(out)]) == 2
    assert main([*SWEEP, "--v", "2", "--out", str(out)]) == 2
    assert main([*SWEEP, "--t-end", "0.01", "--out", str(out)]) == 2
    assert out.read_bytes() == before
    assert main([*other, "--out", str(out), "--force"]) == 0
    assert len(archive.load(out).kappa) == 41
    assert main([*SWEEP, "--out", str(notes), "--force"]) == 0
    assert len(archive.load(notes).kappa) == 40


def test_resume_onto_wrong_kind_or_other_work_is_refused(tmp_path, capsys):
    curve = tmp_path / "curve.h5"
    assert main(["critical-curve", "--axis", "v=1:2:2:log", "--no-progress",
                 "--out", str(curve)]) == 0
    before = curve.read_bytes()
    assert main([*SWEEP, "--out", str(curve), "--resume"]) == 2
    err = capsys.readouterr().err
    assert "critical-curve archive, not a sweep" in err and "Traceback" not in err
    out = tmp_path / "s.h5"
    assert main([*SWEEP, "--out", str(out)]) == 0
    assert main([*SWEEP, "--rtol", "1e-9", "--out", str(out), "--resume"]) == 2
    assert "holds other work" in capsys.readouterr().err
    assert curve.read_bytes() == before


LOCK_HOLDER = textwrap.dedent("""
    import sys
    from phaseimpact._atomic import exclusive
    with exclusive(sys.argv[1]):
        print("locked", flush=True)
        sys.stdin.read()  # hold the lock until the test closes stdin
""")


@pytest.fixture
def lock_holder(tmp_path):
    """A second process holding the write lock of a path (no timing: it says when it holds it)."""
    procs = []

    def hold(path):
        proc = subprocess.Popen([sys.executable, "-c", LOCK_HOLDER, str(path)], stdin=subprocess.PIPE,
                                stdout=subprocess.PIPE, text=True)
        procs.append(proc)
        assert proc.stdout.readline().strip() == "locked"
        return proc

    yield hold
    for proc in procs:
        proc.stdin.close()
        proc.wait(timeout=60)


def test_second_writer_gets_exit_2_and_the_live_temp_file_survives(tmp_path, lock_holder):
    out = tmp_path / "s.h5"
    holder = lock_holder(out)
    live_temp = tmp_path / f".s.h5.{holder.pid}-abcdef.tmp"  # the holder's temporary file, mid-write
    live_temp.write_bytes(b"partial")
    result = run_cli(*SWEEP, "--out", str(out))
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert f"is being written by another phaseimpact process (pid {holder.pid})" in result.stderr
    assert live_temp.read_bytes() == b"partial"
    assert not out.exists()
    with pytest.raises(_atomic.PathLockedError, match=str(holder.pid)):
        with _atomic.atomic_path(out):
            pass


def test_stale_temporaries_of_dead_writers_only_are_removed(tmp_path, small_sweep):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead_pid = int(dead.stdout)  # that process has exited
    alive = subprocess.Popen([sys.executable, "-c", "import sys; sys.stdin.read()"], stdin=subprocess.PIPE)
    try:
        stale = tmp_path / f".s.h5.{dead_pid}-x1.tmp"
        live = tmp_path / f".s.h5.{alive.pid}-x2.tmp"
        foreign = tmp_path / ".s.h5.notours.tmp"
        for p in (stale, live, foreign):
            p.write_bytes(b"x")
        archive.save(small_sweep, tmp_path / "s.h5")
        assert not stale.exists() and live.exists() and foreign.exists()
        assert not (tmp_path / "s.h5.lock").exists()  # released and removed
    finally:
        alive.stdin.close()
        alive.wait(timeout=60)


def test_lock_is_reentrant_in_one_process_and_released(tmp_path):
    path = tmp_path / "x.h5"
    with _atomic.exclusive(path):
        with _atomic.atomic_path(path) as tmp:  # a checkpoint inside a held lock
            open(tmp, "wb").write(b"1")
        assert path.read_bytes() == b"1"
    with _atomic.atomic_path(path) as tmp:  # free again
        open(tmp, "wb").write(b"2")
    assert path.read_bytes() == b"2"


# ------------------------------------------------------------------------------------------------
# Interruptions: a kill after a known number of checkpoints; Ctrl-C says how to resume
# ------------------------------------------------------------------------------------------------

KILL_AFTER = textwrap.dedent("""
    import os, signal, sys
    import phaseimpact.archive as archive
    import importlib
    from phaseimpact.cli import main

    sweep_module = importlib.import_module("phaseimpact.continuation.sweep")  # the module, not the function

    sweep_module.CHUNK_THREADS = 16  # small chunks: several checkpoints
    save, saves = archive.Checkpoint.__call__, [0]

    def save_then_die(*args, **kwargs):
        save(*args, **kwargs)
        saves[0] += 1
        if saves[0] == int(os.environ["KILL_AFTER"]):
            os.kill(os.getpid(), signal.SIGKILL)  # no clean-up at all, like a kill -9

    archive.Checkpoint.__call__ = save_then_die
    sys.exit(main(sys.argv[1:]))
""")


@pytest.mark.slow
def test_sweep_killed_after_two_checkpoints_then_resumed_equals_uninterrupted(tmp_path):
    """SIGKILL after the 2nd checkpoint leaves a valid partial archive; --resume completes it without
    recomputing finished points and gives the numbers of an uninterrupted run."""
    args = [a.replace(":40:", ":64:") for a in SWEEP]
    partial = tmp_path / "partial.h5"
    env = {**os.environ, "KILL_AFTER": "2"}
    killed = subprocess.run([sys.executable, "-c", KILL_AFTER, *args, "--out", str(partial)], env=env,
                            capture_output=True, text=True, timeout=600)
    assert killed.returncode == -9
    half = archive.load(partial)
    assert half.done.sum() == 32  # two chunks of 16
    finished = {i: half.max_force[i] for i in np.flatnonzero(half.done)}

    assert run_cli(*args, "--out", str(partial), "--resume").returncode == 0
    resumed = archive.load(partial)
    assert resumed.done.all()
    assert all(resumed.max_force[i] == value for i, value in finished.items())
    full = tmp_path / "full.h5"
    assert run_cli(*args, "--out", str(full)).returncode == 0
    reference = archive.load(full)
    assert np.array_equal(reference.values["n_stick"], resumed.values["n_stick"])
    assert np.array_equal(reference.max_force, resumed.max_force)
    assert not [p for p in os.listdir(tmp_path) if p.endswith((".tmp", ".lock"))]


def test_ctrl_c_during_a_sweep_prints_the_resume_command(tmp_path, monkeypatch, capsys):
    sweep_module = importlib.import_module("phaseimpact.continuation.sweep")
    monkeypatch.setattr(sweep_module, "CHUNK_THREADS", 8)
    save, saves = archive.Checkpoint.__call__, []

    def save_then_interrupt(*args, **kwargs):
        save(*args, **kwargs)
        saves.append(1)
        if len(saves) == 1:
            raise KeyboardInterrupt

    monkeypatch.setattr(archive.Checkpoint, "__call__", save_then_interrupt)
    out = tmp_path / "s.h5"
    assert main([*SWEEP, "--out", str(out)]) == 130
    err = capsys.readouterr().err
    assert "8 of 40 points are saved" in err
    command = re.split(r"[Rr]esume with:\s*", err.strip().splitlines()[-1])[-1]  # one line or two
    words = shlex.split(command)
    assert words[0] == "phaseimpact" and words[-1] == "--resume"
    monkeypatch.setattr(archive.Checkpoint, "__call__", save)
    assert main(words[1:]) == 0  # the printed command completes the sweep
    assert archive.load(out).done.all()


# ------------------------------------------------------------------------------------------------
# Failures are reported, never "done"
# ------------------------------------------------------------------------------------------------

def test_failed_points_exit_1_with_a_message_and_are_recomputed_on_resume(tmp_path, monkeypatch, capsys):
    """A point whose run failed numerically makes the sweep exit 1, says so, and --resume redoes it."""
    from phaseimpact.integrate import driver

    sweep_module = importlib.import_module("phaseimpact.continuation.sweep")

    out = tmp_path / "s.h5"
    real = sweep_module.run_chunks

    def one_failure(*args, **kwargs):
        for columns in real(*args, **kwargs):
            columns.status[0] = driver.STEP_SIZE_COLLAPSE  # as the engine reports a failed run
            yield columns

    monkeypatch.setattr(sweep_module, "run_chunks", one_failure)
    assert main([*SWEEP, "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "1 of 40 points failed numerically (step-size-collapse: 1)" in err and "--resume" in err
    stored = archive.load(out)
    assert stored.status_names()[0] == "step-size-collapse" and not stored.done[0]
    monkeypatch.setattr(sweep_module, "run_chunks", real)
    assert main([*SWEEP, "--out", str(out), "--resume"]) == 0
    assert archive.load(out).done.all()


# ------------------------------------------------------------------------------------------------
# make reproduce: identical bytes for identical results; previews never over committed files
# ------------------------------------------------------------------------------------------------

def test_figures_are_written_atomically_without_version_metadata(tmp_path):
    import matplotlib.pyplot as plt

    from phaseimpact.plotting import save

    paths = []
    for name in ("a.png", "b.png"):
        fig, ax = plt.subplots()
        ax.plot([0, 1], [1, 0])
        paths.append(save(fig, tmp_path / name))
        time.sleep(1.1)  # a second apart: a time stamp in the file would differ
    a, b = (open(p, "rb").read() for p in paths)
    assert a == b and b"Matplotlib" not in a
    assert sorted(os.listdir(tmp_path)) == ["a.png", "b.png"]  # no temporaries, no lock files left


@pytest.mark.parametrize("suffix", [".png", ".pdf", ".svg"])
def test_plot_writes_each_advertised_format_reproducibly(tmp_path, small_sweep, suffix):
    """Each format --out advertises is written (SVG used to fail on PNG's metadata keys), with the same
    bytes twice and no matplotlib version in them."""
    import matplotlib

    from phaseimpact.cli import FIGURE_FORMATS
    from phaseimpact.plotting import FIGURE_FORMATS as WRITTEN

    assert {s.lstrip(".") for s in FIGURE_FORMATS} == set(WRITTEN)
    source = archive.save(small_sweep, tmp_path / "s.h5")
    written = []
    for name in ("a", "b"):
        out = tmp_path / f"{name}{suffix}"
        assert main(["plot", source, "--out", str(out)]) == 0
        written.append(out.read_bytes())
    assert written[0] == written[1] and written[0].lstrip().startswith(FIGURE_FORMATS[suffix])
    assert f"Matplotlib v{matplotlib.__version__}".encode() not in written[0]


def test_portrait_writes_svg_and_refuses_other_formats_before_computing(tmp_path, monkeypatch):
    out = tmp_path / "p.svg"
    assert main(["portrait", "--kappa", "1e9", "--out", str(out)]) == 0
    assert out.read_bytes().startswith(b"<?xml")
    from phaseimpact.cli import figures

    def no_work(*args, **kwargs):
        raise AssertionError("computed before refusing the format")

    monkeypatch.setattr(figures, "_portrait_runs", no_work)
    with pytest.raises(SystemExit) as exit_:
        main(["portrait", "--kappa", "1e9", "--out", str(tmp_path / "p.jpg")])
    assert exit_.value.code == 2


def test_quick_previews_go_to_the_preview_folder(monkeypatch):
    monkeypatch.syspath_prepend(os.path.join(os.path.dirname(__file__), "..", "studies"))  # _cli imports _settle
    spec = importlib.util.spec_from_file_location("studies_cli", os.path.join(os.path.dirname(__file__), "..",
                                                                             "studies", "_cli.py"))
    study_cli = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(study_cli)
    figures = study_cli.FIGURES
    assert study_cli.output_folder(False) == figures and study_cli.output_folder(True) == figures / "preview"
    study = {"FIGURES": figures, "NAME": "x"}
    study_cli.redirect(study, figures / "preview")
    assert study["FIGURES"] == figures / "preview"
    other = {"ROOT": figures}
    study_cli.redirect(other, figures / "preview")
    assert other["ROOT"] == figures / "preview"
    if not (study_cli.ROOT / ".git").exists():
        pytest.skip("not a git checkout (an unpacked sdist): there is no git status to keep clean")
    ignored = subprocess.run(["git", "check-ignore", "-q", "figures/preview/x.png"],
                             cwd=study_cli.ROOT)
    assert ignored.returncode == 0  # previews never show up in git status


def test_study_processes_make_the_committed_grids_on_any_cpu(tmp_path):
    """numpy's SIMD power and log give grids whose last bits depend on the CPU (with AVX-512, 5 of
    the 70 kappa of atlas_paper's ``np.geomspace(1e10, 1e15, 70)`` were one ulp off): a study process
    runs on numpy's baseline code (studies/_cli.py's on_numpy_baseline re-executes it once), where
    that axis is the committed archive's bit for bit."""
    studies = os.path.join(os.path.dirname(__file__), "..", "studies")
    out = tmp_path / "kappa.npy"
    script = tmp_path / "grid.py"
    script.write_text(f"import sys\nsys.path.insert(0, {studies!r})\nimport _cli\n_cli.on_numpy_baseline()\n"
                      f"import numpy as np\nnp.save({str(out)!r}, np.geomspace(1e10, 1e15, 70))\n")
    unset = ("NPY_DISABLE_CPU_FEATURES", "PHASEIMPACT_STUDIES_NUMPY_BASELINE")
    env = {k: v for k, v in os.environ.items() if k not in unset}
    subprocess.run([sys.executable, str(script)], env=env, check=True, timeout=300)
    with h5py.File(os.path.join(studies, "..", "figures", "data", "atlas_paper_printed.h5")) as f:
        committed = np.unique(f["kappa"][()])
    np.testing.assert_array_equal(np.load(out), committed)


def test_a_resume_of_other_work_names_what_differs_with_the_asked_value(tmp_path):
    """The audit's "holds other work (t_end nan)": the held and the asked value both show, in
    words, and axis ends differing in the 11th digit are visible."""
    from _cli import run

    out = tmp_path / "s.h5"
    base = ["sweep", "--law", "paper", "--v", "1", "--axis", "kappa=1e9:1e14:5:log",
            "--no-progress", "--out", out]
    assert run(base)[0] == 0
    code, _, err = run([*base, "--t-end", "0.01", "--resume"])
    assert code == 2 and "t_end none (each run until its outcome settles) (asked 0.01 s)" in err, err
    code, _, err = run([*base[:6], "kappa=1e9:1.0000000001e14:5:log", *base[7:], "--resume"])
    assert code == 2 and "100000000010000.0" in err, err


# ------------------------------------------------------------------------------------------------
# Trains of impacts: --archive and plot
# ------------------------------------------------------------------------------------------------

def test_train_commands_write_archives_that_load_and_plot(tmp_path, capsys):
    from phaseimpact.train import ImpactTrain, OrbitDiagram, impact_train

    hc = ["--law", "hunt-crossley", "--kappa", "3e9"]
    train_nc, diagram_nc = tmp_path / "t.nc", tmp_path / "o.nc"
    assert main(["train", *hc, "--period", "3e-3", "--impacts", "3", "--archive", str(train_nc)]) == 0
    assert main(["orbit-diagram", *hc, "--axis", "T=2e-3:3e-3:3", "--transients", "3", "--samples", "2",
                 "--archive", str(diagram_nc)]) == 0
    loaded = archive.load(train_nc)
    direct = impact_train(seed_parameters(kappa=3e9), "hunt-crossley", 3e-3, 3)
    assert isinstance(loaded, ImpactTrain)
    assert np.array_equal(loaded.plate, direct.plate) and np.array_equal(loaded.peak_force, direct.peak_force)
    assert isinstance(archive.load(diagram_nc), OrbitDiagram)
    assert main(["plot", str(diagram_nc), "--out", str(tmp_path / "o.png")]) == 0
    assert (tmp_path / "o.png").read_bytes().startswith(b"\x89PNG")
    capsys.readouterr()
    assert main(["plot", str(train_nc), "--out", str(tmp_path / "t.png")]) == 2  # a train is not drawn
    assert "impact train" in capsys.readouterr().err and not (tmp_path / "t.png").exists()


def test_train_archive_refuses_a_foreign_file_before_any_work(tmp_path, capsys, monkeypatch):
    import phaseimpact.train as train_module

    notes = tmp_path / "notes.nc"
    notes.write_text("my notes")
    monkeypatch.setattr(train_module, "impact_train", lambda *a, **k: pytest.fail("work started"))
    assert main(["train", "--law", "hunt-crossley", "--kappa", "3e9", "--period", "3e-3", "--archive",
                 str(notes)]) == 2
    assert "not a phaseimpact archive" in capsys.readouterr().err and notes.read_text() == "my notes"


HC = ["--law", "hunt-crossley", "--kappa", "3e9"]
TRAIN_WRITERS = {  # the audit's commands (train-archive-sweep, M-archive-over-atlas-*)
    "train": ["train", *HC, "--period", "3e-3", "--impacts", "2"],
    "orbit-diagram": ["orbit-diagram", *HC, "--axis", "T=1e-3:2e-3:3", "--transients", "3", "--samples", "3"],
    "basins": ["basins", *HC, "--period", "1e-3", "--grid", "2", "--iterations", "5"],
    "map-continuation": ["map-continuation", *HC, "--axis", "T=0.99e-3:0.975e-3:4"],
}


@pytest.mark.parametrize("command", list(TRAIN_WRITERS))
def test_archive_of_train_commands_refuses_other_work_unless_force(tmp_path, capsys, command, small_sweep):
    """``--archive`` follows ``--out``'s rule: a sweep archive (other work) is refused, byte for byte
    unchanged, before any work; ``--force`` replaces it; the same command again replaces its own archive."""
    path = tmp_path / "a.nc"
    archive.save(small_sweep, path)
    before = path.read_bytes()
    argv = [*TRAIN_WRITERS[command], "--archive", str(path)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "holds other work" in err and "kind 'sweep'" in err and "--force" in err and len(err.splitlines()) == 1
    assert path.read_bytes() == before
    assert main([*argv, "--force"]) in (0, 1)
    replaced = archive.describe(path)["kind"]
    assert replaced != "sweep"
    assert main(argv) in (0, 1)  # the same work: replaced without --force
    assert archive.describe(path)["kind"] == replaced


def test_archive_of_a_train_with_other_settings_is_other_work(tmp_path, capsys):
    path = tmp_path / "t.nc"
    assert main([*TRAIN_WRITERS["train"], "--archive", str(path)]) == 0
    before = path.read_bytes()
    capsys.readouterr()
    assert main(["train", *HC, "--period", "3e-3", "--impacts", "3", "--archive", str(path)]) == 2
    assert "impacts 2 (asked 3)" in capsys.readouterr().err and path.read_bytes() == before


def test_critical_curve_out_refuses_other_work_through_the_same_rule(tmp_path, capsys, small_sweep):
    path = tmp_path / "c.nc"
    archive.save(small_sweep, path)
    before = path.read_bytes()
    assert main(["critical-curve", "--axis", "v=0.5:1:2:log", "--out", str(path)]) == 2
    assert "holds other work" in capsys.readouterr().err and path.read_bytes() == before
