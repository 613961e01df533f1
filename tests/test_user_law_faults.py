"""User laws that go wrong: an edited law file, a law that raises or gives NaN at run time, signals
while user code runs, and the law file's own edges (issue 37, items 1 and 5)."""

import hashlib
import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest
from _registry import restored_registry

from phaseimpact import define_law, seed_parameters, simulate
from phaseimpact.cli import main
from phaseimpact.model import REGISTRY
from phaseimpact.model.userlaw import UserLawError, load_law_file

GOOD = textwrap.dedent('''\
    import math

    import phaseimpact


    def force(delta, deltadot, K, gamma, alpha):
        return max((K * delta + gamma * deltadot) * math.sqrt(delta), 0.0)


    phaseimpact.define_law("fault-kk", force, damping=("gamma", None), damping_power=1.5)
    ''')
RAISES_DEEP = textwrap.dedent('''\
    import phaseimpact


    def force(delta, deltadot, K, kappa, alpha):
        if delta > 3e-5:  # beyond define_law's sample points
            raise ValueError("too deep")
        return K * delta ** alpha


    phaseimpact.define_law("raises-deep", force)
    ''')
SLOW = textwrap.dedent('''\
    import math

    import phaseimpact


    def force(delta, deltadot, K, kappa, alpha):
        s = 0.0
        for i in range(2000000):  # ~20 ms a call: the engine looks for signals every 4096 steps (minutes)
            s += math.sin(i * delta)
        return K * delta ** alpha * (1.0 + 1e-30 * s)


    phaseimpact.define_law("slow", force)
    ''')


@pytest.fixture(scope="module", autouse=True)
def _registry_restored():
    with restored_registry():
        yield


def _cli(*args, timeout=240):
    """The command line in a process of its own (signals, stdout and exit codes as a user sees them)."""
    env = {**os.environ, "PYTHONPATH": os.path.dirname(os.path.dirname(os.path.abspath(__file__)))}
    return subprocess.run([sys.executable, "-m", "phaseimpact.cli", *args], capture_output=True, text=True,
                          timeout=timeout, env=env)


def _digest(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


# -- 1. a law's identity includes its source -------------------------------------------------------

def test_an_edited_law_file_is_other_work_for_resume_and_overwrite(tmp_path, capsys):
    law = tmp_path / "l.py"
    law.write_text(GOOD)
    out = tmp_path / "kk.nc"
    sweep = ["sweep", "--law-file", str(law), "--law", "fault-kk", "--axis", "kappa=1e3:1e6:3:log", "--out",
             str(out), "--no-progress"]
    assert main(sweep) == 0
    import h5py

    with h5py.File(out, "r") as f:
        recorded = f.attrs["law_source"]
    assert recorded == REGISTRY["fault-kk"].native.identity
    assert main([*sweep, "--resume"]) == 0  # the same law: the same work
    capsys.readouterr()
    before = _digest(out)
    law.write_text(GOOD.replace("max((K", "max((2 * K"))  # the force doubled
    for extra in (["--resume"], []):
        assert main([*sweep, *extra]) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1
        assert "law 'fault-kk': its source changed" in err and "Traceback" not in err
        assert _digest(out) == before  # nothing mixed, nothing replaced


def test_a_constant_the_force_reads_is_part_of_its_identity():
    def make(value):
        def force(delta, deltadot, K, kappa, alpha):
            return value * K * delta ** alpha
        return force

    first = define_law("scaled", make(1.0)).native.identity
    again = define_law("scaled", make(1.0)).native.identity
    other = define_law("scaled", make(2.0)).native.identity
    assert first == again != other


def test_a_shipped_law_archive_has_no_law_source(tmp_path):
    import h5py

    from phaseimpact.archive import save
    from phaseimpact.continuation import sweep

    path = save(sweep(seed_parameters(), "paper", [1e9, 1e13]), tmp_path / "s.nc")
    with h5py.File(path, "r") as f:
        assert "law_source" not in f.attrs


def _said(stderr: str) -> list:
    """The lines of a command's stderr, less the one-time first-compile announcement (a cold cache)."""
    return [line for line in stderr.strip().splitlines() if not line.startswith("phaseimpact: compiling the engine")]


def test_a_user_law_archive_without_its_law_is_not_called_damaged(tmp_path):
    law = tmp_path / "l.py"
    law.write_text(GOOD.replace("fault-kk", "elsewhere-kk"))
    out = tmp_path / "kk.nc"
    assert main(["sweep", "--law-file", str(law), "--law", "elsewhere-kk", "--axis", "kappa=1e3:1e5:2:log",
                 "--out", str(out), "--no-progress"]) == 0
    law.unlink()
    done = _cli("plot", str(out), "--out", str(tmp_path / "p.png"))
    assert done.returncode == 2
    assert _said(done.stderr) == [
        f"phaseimpact: error: {str(out)!r} holds work of law 'elsewhere-kk', a user law: define it first "
        "(--law-file FILE, or phaseimpact.define_law in Python)"]
    assert "damaged" not in done.stderr


# -- 2. a law that raises or gives NaN at run time -------------------------------------------------

def test_a_law_that_raises_beyond_the_samples_ends_its_run_with_one_line(tmp_path):
    law = tmp_path / "raises_deep.py"
    law.write_text(RAISES_DEEP)
    start = time.monotonic()
    done = _cli("simulate", "--law-file", str(law), "--law", "raises-deep", "--kappa", "1e4", "--json")
    elapsed = time.monotonic() - start
    assert done.returncode == 1, done.stderr
    lines = _said(done.stderr)
    assert len(lines) == 1 and "Exception ignored" not in done.stderr, done.stderr[:2000]
    assert lines[0].startswith("phaseimpact: numerical failure: non-finite: law 'raises-deep': its force raised "
                               "ValueError (too deep) at delta = 3")
    out = json.loads(done.stdout)
    assert out["status"] == "non-finite" and "raised ValueError" in out["message"]
    print(f"raising law: simulate ended in {elapsed:.1f} s (process start, law compile and run)")


def test_a_nan_law_from_python_names_the_law_and_delta():
    import math

    define_law("nan-deep", lambda d, dd, K, k, a: math.nan if d > 3e-5 else K * d ** a)
    tr = simulate(seed_parameters(kappa=1e4), "nan-deep")
    assert tr.status == "non-finite" and tr.outcome == "failed"
    assert tr.message.startswith("law 'nan-deep': its force returned nan at delta = ")
    delta = float(tr.message.split("delta = ")[1].split(" m")[0])
    assert delta > 3e-5  # where the law returned it, not the last good state
    define_law("nan-deep", lambda d, dd, K, k, a: K * d ** a)  # the same name, a good law: no fault left over
    assert simulate(seed_parameters(kappa=1e4), "nan-deep").ok


def test_a_finite_but_unphysical_force_names_the_law_and_delta_not_stiffness(capsys):
    """A force of 1e300 N is finite, but no run can go on with it: the run ends naming the law, the
    value and delta (it said "the step size collapsed (stiffness ...)")."""
    from phaseimpact.model.userlaw import FORCE_LIMIT

    assert FORCE_LIMIT < 1e300
    define_law("huge-deep", lambda d, dd, K, k, a: 1e300 if d > 3e-5 else K * d ** a)
    tr = simulate(seed_parameters(kappa=1e4), "huge-deep")
    assert tr.status == "non-finite" and tr.outcome == "failed"
    assert tr.message.startswith("law 'huge-deep': its force returned 1e+300 N, beyond the finite physical range "
                                 f"|P| <= {FORCE_LIMIT:g} N, at delta = "), tr.message
    assert float(tr.message.split("delta = ")[1].split(" m")[0]) > 3e-5
    # the audit's law, 1e300 * delta, on the command line: one line with the same words
    define_law("huge", lambda d, dd, K, k, a: 1e300 * d if d > 0 else 0.0)
    assert main(["simulate", "--law", "huge", "--kappa", "1e4"]) == 1
    lines = _said(capsys.readouterr().err)
    assert len(lines) == 1 and "step size collapsed" not in lines[0], lines
    assert lines[0].startswith("phaseimpact: numerical failure: non-finite: law 'huge': its force returned "), lines
    assert "beyond the finite physical range" in lines[0]


def test_a_sweep_of_a_raising_law_marks_only_its_points_non_finite():
    """A point whose law raised is ``non-finite``; its neighbour, which never reached the bad
    region, is a success (the law's one fault record is attributed run by run)."""
    from phaseimpact.continuation import atlas
    from phaseimpact.integrate.driver import NON_FINITE, SUCCESS

    def force(delta, deltadot, K, kappa, alpha):
        if deltadot > 1.5:  # only the faster impact reaches it
            raise ValueError("too fast")
        return K * delta ** alpha

    define_law("raises-fast", force)
    result = atlas(seed_parameters(kappa=1e4), "raises-fast", {"v": [0.5, 2.0]}, n_jobs=2)
    assert result.status.tolist() == [SUCCESS, NON_FINITE]


# -- signals while user code runs ------------------------------------------------------------------

@pytest.mark.parametrize("signum, code, line", [(signal.SIGINT, 130, "phaseimpact: interrupted"),
                                                (signal.SIGTERM, 143, "phaseimpact: terminated (SIGTERM)")])
def test_a_signal_stops_a_slow_law_with_one_line(tmp_path, signum, code, line):
    law = tmp_path / "slow.py"
    law.write_text(SLOW)
    env = {**os.environ, "PYTHONPATH": os.path.dirname(os.path.dirname(os.path.abspath(__file__)))}
    process = subprocess.Popen([sys.executable, "-m", "phaseimpact.cli", "simulate", "--law-file", str(law),
                                "--law", "slow", "--kappa", "1e4"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, env=env, start_new_session=True,
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(12)  # started, the law compiled, the run going (a run of this law takes minutes)
    assert process.poll() is None
    process.send_signal(signum)
    try:
        out, err = process.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        process.kill()
        raise
    assert process.returncode == code, err
    assert err.strip().splitlines() == [line]


# -- 3. the law file's edges -----------------------------------------------------------------------

def test_a_law_file_of_any_name_runs(tmp_path):
    path = tmp_path / "good.txt"
    path.write_text(GOOD.replace("fault-kk", "txt-kk"))
    assert load_law_file(path) == ["txt-kk"]


@pytest.mark.parametrize("body, message", [
    ("import sys\nsys.exit(0)\n", "exited (status 0) while it was run"),
    ("import sys\nsys.exit(3)\n", "exited (status 3) while it was run"),
])
def test_sys_exit_in_a_law_file_is_a_usage_error(tmp_path, capsys, body, message):
    path = tmp_path / "exit.py"
    path.write_text(body)
    assert main(["simulate", "--law-file", str(path), "--law", "x"]) == 2
    err = capsys.readouterr().err
    assert message in err and str(path) in err and len(err.strip().splitlines()) == 1


def test_a_folder_or_fifo_is_named_as_such(tmp_path):
    folder = tmp_path / "dir.py"
    folder.mkdir()
    with pytest.raises(UserLawError, match="is a folder"):
        load_law_file(folder)
    fifo = tmp_path / "fifo.py"
    os.mkfifo(fifo)
    with pytest.raises(UserLawError, match="is a FIFO"):
        load_law_file(fifo)


def test_a_law_file_without_law_uses_its_one_law_or_refuses(tmp_path, capsys):
    one = tmp_path / "one.py"
    one.write_text(GOOD.replace("fault-kk", "only-kk"))
    assert main(["simulate", "--law-file", str(one), "--kappa", "1e4", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["law"] == "only-kk"
    two = tmp_path / "two.py"
    two.write_text(GOOD.replace("fault-kk", "a-kk") + GOOD.replace("fault-kk", "b-kk").split("import math")[1])
    assert main(["simulate", "--law-file", str(two), "--kappa", "1e4"]) == 2
    err = capsys.readouterr().err
    assert "defines 2 laws (a-kk, b-kk)" in err and "--law NAME" in err


def test_a_case_with_a_law_file_and_no_law_takes_its_one_law(tmp_path):
    from phaseimpact.case import load_case

    (tmp_path / "one.py").write_text(GOOD.replace("fault-kk", "case-one"))
    text = load_case("seed").to_toml().replace('law = "paper"\n', 'law_file = "one.py"\n')
    (tmp_path / "c.toml").write_text(text.replace("kappa = 0.0", "kappa = 1e4"))
    assert load_case(tmp_path / "c.toml").impact["law"] == "case-one"


def test_a_printing_law_file_leaves_json_intact(tmp_path):
    path = tmp_path / "printer.py"
    path.write_text('print("hello from the law file")\n' + GOOD.replace("fault-kk", "printer"))
    done = _cli("simulate", "--law-file", str(path), "--law", "printer", "--kappa", "1e4", "--json")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["law"] == "printer"
    assert "hello from the law file" in done.stderr


def test_define_law_refuses_what_it_cannot_honour():
    def force(delta, deltadot, K, kappa, alpha):
        return K * delta ** alpha

    with pytest.raises(UserLawError, match=r"unilateral = 'no' is out of range; allowed: True or False"):
        define_law("x", force, unilateral="no")
    with pytest.raises(UserLawError, match="description = 'a\\\\nb' is out of range; allowed: one line"):
        define_law("x", force, description="a\nb")

    class Force:
        def __call__(self, delta, deltadot, K, kappa, alpha):
            return 0.0

    with pytest.raises(UserLawError, match=r"^force = .* is a callable object; allowed: a Python function"):
        define_law("x", Force())
    assert "x" not in REGISTRY


def test_numba_colour_codes_leave_the_message(monkeypatch):
    monkeypatch.setenv("NUMBA_COLOR_SCHEME", "dark_bg")

    class Settings:
        scale = 1.0

    settings = Settings()
    with pytest.raises(UserLawError, match="numba cannot compile") as info:
        define_law("pyobj", lambda d, dd, K, k, a: settings.scale * d)
    assert "\x1b" not in str(info.value)


def test_loky_workers_define_the_user_law_again():
    from phaseimpact.continuation import sweep

    define_law("loky-kk", lambda d, dd, K, k, a: K * d ** a)
    threads = sweep(seed_parameters(), "loky-kk", [1e9, 1e11, 1e13])
    processes = sweep(seed_parameters(), "loky-kk", [1e9, 1e11, 1e13], n_jobs=2, backend="loky")
    assert list(processes.values["max_force"]) == list(threads.values["max_force"])


def test_loky_workers_run_a_law_file(tmp_path, capsys):
    law = tmp_path / "good.py"
    law.write_text(GOOD.replace("fault-kk", "loky-file"))
    common = ["sweep", "--law-file", str(law), "--law", "loky-file", "--axis", "kappa=1e3:1e6:3:log", "--no-progress"]
    assert main([*common, "--out", str(tmp_path / "t.nc")]) == 0
    assert main([*common, "--out", str(tmp_path / "l.nc"), "--backend", "loky", "--jobs", "2"]) == 0
    from phaseimpact.archive import load

    assert list(load(tmp_path / "t.nc").values["max_force"]) == list(load(tmp_path / "l.nc").values["max_force"])
