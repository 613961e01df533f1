"""The two-process first compile (phaseimpact/integrate/precompile.py): from an empty numba cache,
every kernel is compiled once, this process compiles none of the helper's, and the compiled engine
gives bit for bit the results of the project's cache.

A cold session costs a whole first compile (20-50 s on two cores). What it checks depends only on
the engine's sources (the digest that also names the cache, phaseimpact/_jit.py), this file's
session and the versions of Python, numba and llvmlite: its output is kept in pytest's cache under
that key, and a test run on unchanged sources reuses it (``PHASEIMPACT_COLD_TESTS=1`` runs it
anyway; ``pytest --cache-clear`` forgets it).
"""

from __future__ import annotations

import gc
import hashlib
import json
import os
import platform
import subprocess
import sys

import numpy as np
import pytest

from phaseimpact import _jit, seed_parameters, simulate, simulate_many
from phaseimpact.integrate import precompile

# Runs one cold session: records every phaseimpact function numba compiles in this process, then
# the numbers of three runs and a batch.
COLD_SESSION = r"""
import gc, json
from numba.core import event
compiled, nested_collecting, depth = [], [], [0]
class Recorder(event.Listener):
    def on_start(self, ev):
        f = ev.data["dispatcher"].py_func
        if f.__module__.startswith("phaseimpact"):
            compiled.append(f.__module__ + "." + f.__name__)
        if depth[0]:  # compiled inside another function's compile
            nested_collecting.append(gc.isenabled())
        depth[0] += 1
    def on_end(self, ev):
        depth[0] -= 1
event.register("numba:compile", Recorder())
from phaseimpact import seed_parameters, simulate, simulate_many
p = seed_parameters(v=1.0, kappa=3e9)
runs = [simulate(p, "hunt-crossley", 2e-3), simulate(p.replace(kappa=2e12), "paper", None, stop_on="slip"),
        simulate(p.replace(kappa=1e14, v=5.0), "paper", 2e-3)]
cols = simulate_many([p, p.replace(kappa=1e12), p.replace(kappa=1e14, v=5.0)], "paper", n_threads=2)
print(json.dumps({"compiled": compiled, "nested_collecting": nested_collecting, "collecting_after": gc.isenabled(),
                  "runs": [[float(x) for x in r.summary] + [float(x) for x in r.final_state] for r in runs],
                  "max_force": [float(x) for x in cols.max_force], "t_run": [float(x) for x in cols.t_run]}))
"""

def _session_key() -> str:
    import llvmlite
    import numba

    parts = (_jit.engine_digest(), COLD_SESSION, sys.version, numba.__version__, llvmlite.__version__,
             platform.machine(), platform.processor())
    return hashlib.sha256(repr(parts).encode()).hexdigest()[:24]


@pytest.fixture(scope="module")
def cold_session(tmp_path_factory, request):
    key = f"phaseimpact/cold-session/{_session_key()}"
    kept = request.config.cache.get(key, None)
    if kept is not None and not os.environ.get("PHASEIMPACT_COLD_TESTS"):
        return kept
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path_factory.mktemp("numba-cache")),
               PHASEIMPACT_COMPILE_PROCESSES="2")
    env.pop("NUMBA_DISABLE_JIT", None)
    out = subprocess.run([sys.executable, "-c", COLD_SESSION], env=env, capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "RuntimeWarning" not in out.stderr, out.stderr[-3000:]  # the helper started and succeeded
    assert "compiling the engine once for this machine" in out.stderr  # the cold cache said so, once
    assert out.stderr.count("phaseimpact: compiling") == 1, out.stderr[-3000:]
    session = json.loads(out.stdout.strip().splitlines()[-1])
    request.config.cache.set(key, session)
    return session


def test_cold_compile_compiles_every_kernel_once_and_none_of_the_helpers(cold_session):
    compiled = cold_session["compiled"]
    repeated = {name for name in compiled if compiled.count(name) > 1}
    assert not repeated, f"compiled twice (a signature in precompile.py differs from the driver's): {repeated}"
    # the helper's roots, and every Radau kernel (their callees)
    helper_roots = {f"{f.__module__}.{f.__name__}" for f, _ in precompile.HELPER_PART + precompile.HELPER_LATE_PART}
    here = [name for name in compiled if name in helper_roots or name.rsplit(".", 1)[0] == precompile.radau5.__name__]
    assert not here, f"compiled here although the helper compiles them: {here}"
    # the entries and this process's parts of both phases were compiled here (the cache was empty)
    for function, _ in precompile.LOCAL_PART + precompile.LOCAL_LATE_PART:
        assert f"{function.__module__}.{function.__name__}" in compiled
    assert "phaseimpact.integrate.driver.run" in compiled
    # phase 3: the run loop here, the other entry (simulate_many's) by the helper
    assert "phaseimpact.integrate.driver._run" in compiled
    assert "phaseimpact.integrate.driver.run_block" not in compiled


def test_cold_compile_pauses_the_garbage_collector_and_gives_it_back(cold_session):
    """Off while an entry's call tree compiles (every function compiled inside another's compile),
    on again afterwards."""
    assert len(cold_session["nested_collecting"]) > 50
    assert not any(cold_session["nested_collecting"])
    assert cold_session["collecting_after"] is True


def test_cold_compiled_engine_gives_the_same_numbers(cold_session):
    p = seed_parameters(v=1.0, kappa=3e9)
    runs = [simulate(p, "hunt-crossley", 2e-3), simulate(p.replace(kappa=2e12), "paper", None, stop_on="slip"),
            simulate(p.replace(kappa=1e14, v=5.0), "paper", 2e-3)]
    cols = simulate_many([p, p.replace(kappa=1e12), p.replace(kappa=1e14, v=5.0)], "paper", n_threads=2)
    for cold, run in zip(cold_session["runs"], runs, strict=True):
        np.testing.assert_array_equal(cold, np.concatenate([run.summary, run.final_state]))
    np.testing.assert_array_equal(cold_session["max_force"], cols.max_force)
    np.testing.assert_array_equal(cold_session["t_run"], cols.t_run)


@pytest.mark.parametrize(("value", "expected"), [("1", 1), ("2", 2)])
def test_processes_reads_the_environment(monkeypatch, value, expected):
    monkeypatch.setenv(precompile.PROCESSES_VARIABLE, value)
    assert precompile.processes() == expected


@pytest.mark.parametrize("value", ["0", "3", "two"])
def test_processes_refuses_other_values(monkeypatch, value):
    monkeypatch.setenv(precompile.PROCESSES_VARIABLE, value)
    with pytest.raises(ValueError, match=f"{precompile.PROCESSES_VARIABLE} = '{value}' is out of range"):
        precompile.processes()


def _fake_helper(script: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", script], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)


def test_phase_two_starts_when_the_helper_is_ready():
    """The helper's phase 1 line gets the answer that starts its phase 2."""
    helper = _fake_helper(f"import sys; print({precompile._READY!r}, flush=True); "
                          f"sys.exit(0 if sys.stdin.readline().strip() == {precompile._GO!r} else 3)")
    assert precompile._next_phase(helper, precompile._READY, precompile._GO) is True
    assert helper.wait(timeout=30) == 0


@pytest.mark.parametrize("script", ["import sys; sys.exit(1)", "print('something else', flush=True)"],
                         ids=["died", "garbled"])
def test_phase_two_is_skipped_when_the_helper_fails(script):
    """A helper that ends or answers wrongly: this process compiles the mid-level kernels itself,
    and the helper is not left waiting for an answer."""
    helper = _fake_helper(script + "; import sys; sys.stdin.readline()")
    assert precompile._next_phase(helper, precompile._READY, precompile._GO) is False
    helper.wait(timeout=30)  # its stdin was closed: it does not wait for ever


@pytest.mark.parametrize(("entry", "other"), [("run", "run_block"), ("run_block", "run")])
def test_phase_three_gives_the_helper_the_other_entry(entry, other):
    """After the helper's phase 2 (and the run loop here), the helper is named the entry this
    process does not compile."""
    from phaseimpact.integrate import driver

    helper = _fake_helper(f"import sys; print({precompile._READY_LATE!r}, flush=True); "
                          f"sys.exit(0 if sys.stdin.readline().strip() == {other!r} else 3)")
    assert precompile._next_phase_after_loop(helper, getattr(driver, entry)) is True
    assert helper.wait(timeout=30) == 0


def test_phase_three_is_skipped_when_the_helper_fails():
    from phaseimpact.integrate import driver

    helper = _fake_helper("import sys; sys.exit(1)")
    assert precompile._next_phase_after_loop(helper, driver.run) is False


def test_one_command_process_freezes_what_the_compile_left(monkeypatch):
    """The console script's process (``_jit.ONE_COMMAND``) ends after its command: the objects an
    entry's compile left are frozen out of the collector's reach instead of collected; a library
    process (the default) leaves them to the collector."""
    from types import SimpleNamespace

    from phaseimpact.integrate import driver

    entry = SimpleNamespace(data={"dispatcher": driver.run_rk4})
    assert precompile._is_entry(driver.run_rk4)
    for one_command in (False, True):
        monkeypatch.setattr(_jit, "ONE_COMMAND", one_command)
        listener = precompile._FirstCompile()
        listener.done = True  # no helper process: only the collector's pause is under test
        listener.announced = True
        before = gc.get_freeze_count()
        try:
            listener.on_start(entry)
            assert not gc.isenabled()
            made = [[object()] for _ in range(1000)]  # tracked objects made while the entry compiled
            listener.on_end(entry)
            assert gc.isenabled()
            assert (gc.get_freeze_count() >= before + len(made)) is one_command
        finally:
            gc.unfreeze()
            gc.enable()
