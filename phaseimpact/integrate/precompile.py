"""The first-ever compile of the engine, on two cores.

Numba compiles one function at a time under a global lock, so the first call of
:func:`.driver.run` or :func:`.driver.run_block` on an empty cache compiles the whole call tree in
one thread while the other core idles. The Radau IIA kernels (:mod:`.radau5`, with the law
kernels they call) do not depend on the explicit stepper, the flight's closed form or the event
root finders, and the driver's mid-level kernels (advance, locate, record, restart) need both.

So when numba is about to compile one of the two entries from scratch (its ``numba:compile`` event
fires only on a cache miss), the compile runs in two processes and three phases, each process
writing to numba's disk cache and loading from it what the other wrote:

1. a helper process compiles the Radau kernels (:data:`HELPER_PART`) while this one compiles the
   rest of the leaves (:data:`LOCAL_PART`);
2. once both are done (the helper says so on its stdout, this process answers on its stdin), the
   mid-level kernels are split the same way (:data:`HELPER_LATE_PART`, :data:`LOCAL_LATE_PART`);
3. this process compiles the run loop (:func:`.driver._run`), then the entry it was asked for
   while the helper compiles the other one (:data:`ENTRIES`: both hold the whole engine, and most
   of their compile is LLVM's, which no second process can share), and waits for the helper at
   the end of its entry's compile.

A cached kernel keeps its LLVM bitcode for inlining into its callers, so the machine code, and
every result, is the same however the cache was filled. On a warm cache nothing here runs. If the
helper fails or is late, this process compiles what is missing itself.

The argument types below are the ones the driver calls the kernels with:
``tests/test_precompile.py`` compiles from an empty cache and checks that no kernel is compiled
twice and that this process compiles none of the helper's. ``PHASEIMPACT_COMPILE_PROCESSES=1``
(the default on a single core) turns the helper off.

The first compile says so on stderr, once per process and only on a cache miss (:func:`announce`);
:func:`warmup` (``phaseimpact warmup``) compiles every entry the commands use ahead of time.
"""

from __future__ import annotations

import functools
import gc
import os
import select
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

from numba import typeof, types
from numba.core import event

from .. import _jit
from .._jit import PROCESSES_VARIABLE, cache_info, mark_complete, processes
from . import dop853, driver, flight, radau5

__all__ = ["HELPER_PART", "LOCAL_PART", "HELPER_LATE_PART", "LOCAL_LATE_PART", "LOOP_PART", "ENTRIES", "compile_part",
           "processes", "announce", "warmup", "PROCESSES_VARIABLE"]

#: Set in the helper's environment: it compiles silently (its output is read only if it fails).
_HELPER_VARIABLE = "PHASEIMPACT_COMPILE_HELPER"
#: A helper that has not finished by then is abandoned (this process compiles what it needs itself).
HELPER_TIMEOUT = 600.0

_ARG_TYPES = {
    "I": types.int64,
    "F": types.float64,
    "B": types.boolean,
    "V": types.float64[::1],
    "M": types.float64[:, ::1],
    "IV": types.int64[::1],
    "BV": types.boolean[::1],
}

# (function, argument types): the roots of each part; numba compiles their callees with them.
HELPER_PART = (
    (radau5.attempt, "I V I I F F V V F STIFF V V"),
    (radau5.fixed_step, "I V I I F V V F STIFF V V"),
    (radau5.dense_coefficients, "STIFF M"),
    (radau5.enter, "I V I I V V F V STIFF"),
    (radau5.watch, "STIFF F"),
    (radau5.due, "STIFF"),
    (radau5.active, "STIFF"),
    (radau5.failed, "STIFF"),
    (radau5.reset, "STIFF"),
    (radau5.workspace, "I"),
    # the Radau kernels alone left this process idle: the logs' kernels and the transitions too
    (driver._summarize, "I V V V I I I F F F IV I M I I"),
    (driver._push_event, "M I F I I V F"),
    (driver._open_logs, "V I F I V"),
    (driver.transition, "I V I V I B"),
)
LOCAL_PART = (
    (dop853.step, "I V I I V V F M V V"),
    (dop853.error_norm, "M F V V F V"),
    (dop853.dense_coefficients, "I V I I V V V V F M M V"),
    (dop853.initial_step, "I V I I V V F V F F V V"),
    (flight.coefficients, "V V F M"),
    (flight.next_centre, "M F"),
    (flight.unreachable, "M V"),
    (driver._locate, "I V I I F I M V F F F F F V V V"),
    (driver._s_at_time, "I V I I M V F F F V V V"),
    (driver._events, "I V I I F V V V F V"),
    (driver._quiet_start, "I V I V"),
    (driver._integration_state, "I I I V F V"),
    (driver._phase_tolerances, "I I I V V"),
    (driver.stick_points, "M F B V V V"),
    (driver.contact_side, "I V V I"),
    (driver.initial_mode, "I V V"),
    (driver.energy_limit_of, "I V V"),
    (driver.restarts, "I I I B"),
)
# Phase 2: the mid-level kernels of the driver's loop, which call the kernels of both parts.
HELPER_LATE_PART = (
    (driver._locate_events, "I V I I B F F F F V V V V BV V M M V V STIFF V V V V"),
    (driver._restart, "I V B I I I F F F V V V V V V V V M STIFF F V V F F F V V F"),
)
LOCAL_LATE_PART = (
    (driver._advance, "I V I I F F V V V V F F F V F F F F F I V V BV M V V V V V STIFF"),
    (driver._record, "I V I I B I I F F F BV V V V M M V V STIFF V V M I IV V"),
)
#: The entries of :mod:`.driver` a first compile makes, by name: the helper compiles the one this
#: process does not.
ENTRIES = {"run": "I V V F F V F B I I I V I I I", "run_block": "I M M V F M V B I I I I I I I I M M M M IV"}
# Phase 3: the run loop here (it takes run's arguments), then the two entries, one in each process.
LOOP_PART = ((driver._run, ENTRIES["run"]),)
#: The helper's lines on stdout and this process's answer on its stdin (phase 3: the entry's name).
_READY, _READY_LATE, _GO = "phase 1 done", "phase 2 done", "go"


_HELPER = f"import {__name__} as part; part.helper_main()"


def helper_main() -> None:
    """The helper process: phase 1, then phase 2 once the first process says its phase 1 is done,
    then the entry the first process names (without the cyclic garbage collector, as an entry's
    compile: see :class:`_FirstCompile`)."""
    gc.disable()
    compile_part(HELPER_PART)
    print(_READY, flush=True)
    if sys.stdin.readline().strip() == _GO:
        compile_part(HELPER_LATE_PART)
        print(_READY_LATE, flush=True)
        name = sys.stdin.readline().strip()
        if name in ENTRIES:
            compile_part(((getattr(driver, name), ENTRIES[name]),))
    # the first process waits for this one to end: skip the interpreter's teardown, which walks the
    # compile's millions of objects (about half a second); everything was written and flushed
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


def compile_part(part) -> None:
    """Compile (or load from the disk cache) every root of ``part`` and its callees."""
    for function, spec in part:
        function.compile(tuple(_arg_type(code) for code in spec.split()))


@functools.cache
def _arg_type(code: str):
    if code == "STIFF":  # the Radau state tuple, typed from the pure-Python workspace (no compile)
        return typeof(radau5.workspace.py_func(0))
    return _ARG_TYPES[code]


def _start_helper():
    """The helper process and the file its error output goes to (None if it cannot start)."""
    # the helper imports this very package, wherever this process found it
    root = str(Path(__file__).resolve().parents[2])
    env = {**os.environ, PROCESSES_VARIABLE: "1", _HELPER_VARIABLE: "1",
           "PYTHONPATH": os.pathsep.join(filter(None, (root, os.environ.get("PYTHONPATH"))))}
    errors = tempfile.TemporaryFile("w+")  # a file, not a pipe: nothing reads it while this process compiles
    try:
        helper = subprocess.Popen([sys.executable, "-c", _HELPER], env=env, stdin=subprocess.PIPE,
                                  stdout=subprocess.PIPE, stderr=errors, text=True)
    except OSError as exc:
        errors.close()
        warnings.warn(f"phaseimpact: the compile helper did not start ({exc}); compiling in one process",
                      RuntimeWarning, stacklevel=3)
        return None
    return helper, errors


def _next_phase(helper: subprocess.Popen, ready: str, answer: str) -> bool:
    """Wait for the helper's line ``ready`` and answer; False if the helper failed or is late (this
    process then compiles what is left with the entry). The helper's input is closed on False: it
    ends there."""
    if _heard(helper, ready):
        try:
            helper.stdin.write(answer + "\n")
            helper.stdin.flush()
            return True
        except OSError:  # the helper is gone
            pass
    _close_input(helper)
    return False


def _heard(helper: subprocess.Popen, line: str) -> bool:
    """Whether the helper's next line on its stdout, within :data:`HELPER_TIMEOUT`, is ``line``."""
    try:
        readable, _, _ = select.select([helper.stdout], [], [], HELPER_TIMEOUT)
        return bool(readable) and helper.stdout.readline().strip() == line
    except OSError:  # the helper is gone
        return False


def _close_input(helper: subprocess.Popen) -> None:
    try:
        helper.stdin.close()
    except OSError:
        pass


def _next_phase_after_loop(helper: subprocess.Popen, entry) -> bool:
    """Phase 3: once the helper's phase 2 is done, the run loop here, then the helper is told to
    make the entry other than ``entry``. False if the helper failed or is late."""
    if not _heard(helper, _READY_LATE):
        return False
    compile_part(LOOP_PART)  # with the kernels of both phases, as the helper's entry needs it
    other = next(name for name in ENTRIES if getattr(driver, name) is not entry)
    try:
        helper.stdin.write(other + "\n")
        helper.stdin.close()
    except OSError:
        return False
    return True


def _join(helper: subprocess.Popen, errors) -> None:
    """Wait for the helper; if it failed, say so (this process then compiles its part itself)."""
    with errors:
        try:
            helper.wait(timeout=HELPER_TIMEOUT)
        except subprocess.TimeoutExpired:
            helper.kill()
            helper.wait()
            warnings.warn(f"phaseimpact: the compile helper did not finish in {HELPER_TIMEOUT:.0f} s; "
                          "compiling its part in this process", RuntimeWarning, stacklevel=3)
            return
        if helper.returncode != 0:
            errors.seek(0)
            tail = "\n".join(errors.read().strip().splitlines()[-5:])
            warnings.warn(f"phaseimpact: the compile helper failed (exit {helper.returncode}); compiling "
                          f"its part in this process:\n{tail}", RuntimeWarning, stacklevel=3)


def announce() -> str:
    """The line a first compile writes on stderr (it depends on where the cache is)."""
    info = cache_info()
    if info.path is None:
        return (f"phaseimpact: compiling the engine for this process, about 30 s (one process: nothing is "
                f"cached: {info.reason}; set NUMBA_CACHE_DIR to a writable directory to compile once)")
    if not info.writable:
        return f"phaseimpact: compiling part of the engine for this process (the cache {info.path} is read-only)"
    return f"phaseimpact: compiling the engine once for this machine, about 20 s on 2 cores (cache: {info.path})"


def _is_entry(dispatcher) -> bool:
    """A run loop of the driver, called from Python: what compiles the engine on a cold cache (a
    kernel called from Python, as the tests do, compiles in a second)."""
    return (getattr(dispatcher.py_func, "__module__", "") == driver.__name__
            and not dispatcher.targetoptions.get("no_cpython_wrapper", False))


class _FirstCompile(event.Listener):
    """Says that the engine compiles, pauses the cyclic garbage collector while an entry compiles,
    and splits the first compile of an entry over two processes (each once per process).

    The collector: numba's compiler makes millions of small objects, and each of Python's full
    collections walks every object of the process; they took about a tenth of a first compile
    (measured with ``gc.callbacks``). Paused, the compile holds a few hundred MB more at its peak;
    what it left is collected as usual once the collector runs again, in one collection that walks
    it all (about half a second). The console script (:data:`phaseimpact._jit.ONE_COMMAND`) runs one
    command and ends: there the compile's leftovers are frozen (``gc.freeze``) instead, which saves
    that collection and as long again at the exit, where Python would walk them once more."""

    def __init__(self):
        self.done = False
        self.announced = bool(os.environ.get(_HELPER_VARIABLE))
        self.entries_compiling = 0
        self.paused_gc = False
        self.helper = None  # (entry, helper, its error file) while the helper makes the other entry

    def on_start(self, ev):
        dispatcher = ev.data["dispatcher"]
        if _is_entry(dispatcher):
            if self.entries_compiling == 0 and gc.isenabled():
                gc.disable()
                self.paused_gc = True
            self.entries_compiling += 1
            if not self.announced:
                self.announced = True
                print(announce(), file=sys.stderr, flush=True)
        if self.done or dispatcher not in (driver.run, driver.run_block):
            return
        self.done = True
        info = cache_info()
        if processes() < 2 or info.path is None or not info.writable:
            return  # the helper's work reaches this process through the cache: without one, it is wasted
        helper = _start_helper()
        compile_part(LOCAL_PART)
        if helper is None:
            return
        if _next_phase(helper[0], _READY, _GO):
            compile_part(LOCAL_LATE_PART)
            if _next_phase_after_loop(helper[0], dispatcher):
                self.helper = (dispatcher, *helper)  # joined when this entry is compiled (on_end)
                return
        _close_input(helper[0])
        _join(*helper)

    def on_end(self, ev):
        if self.helper is not None and ev.data["dispatcher"] is self.helper[0]:
            _join(*self.helper[1:])
            self.helper = None
        if _is_entry(ev.data["dispatcher"]):
            self.entries_compiling -= 1
            if self.entries_compiling == 0 and self.paused_gc:
                self.paused_gc = False
                if _jit.ONE_COMMAND:
                    gc.freeze()
                gc.enable()


event.register("numba:compile", _FirstCompile())


def _cache_files(path: Path | None) -> tuple[int, int]:
    if path is None or not path.is_dir():
        return 0, 0
    files = [f for f in path.rglob("*") if f.suffix in (".nbi", ".nbc")]
    return len(files), sum(f.stat().st_size for f in files)


def warmup() -> dict:
    """Compile (or load) every entry the commands use, each law, integrator and output, and mark
    the cache complete, so that other users of a shared install read it.

    Returns where the cache is (``cache``: a path or None, ``writable``, ``reason`` when there is
    none), ``compiled`` (whether anything was compiled here), ``seconds``, and the cache's ``files``
    and ``bytes``."""
    from ..model import law_variants
    from ..parameters import seed_parameters
    from .api import simulate, simulate_many

    info = cache_info()
    start = time.perf_counter()
    entries = (driver.run, driver.run_block, driver.run_rk4)
    before = [entry.stats.cache_misses.copy() for entry in entries]
    p = seed_parameters(v=1.0, kappa=3e9, limiting_pressure=2e9)  # p_y: read by the plastic law only
    stiff = p.replace(kappa=1e14, v=5.0)  # the stiff (Radau) path
    for law in law_variants():
        simulate(p, law, 2e-3)
        simulate_many([p, stiff], law, 2e-3)
    simulate(p, "paper", None, stop_on="slip")
    simulate(stiff, "paper", 2e-3)
    simulate(p, "paper", 2e-4, integrator="rk4")
    simulate(p, "hunt-crossley", 2e-3, save="steps")
    simulate_many([p, p.replace(kappa=1e12)], "paper", n_threads=2)
    compiled = [entry.stats.cache_misses for entry in entries] != before
    mark_complete()
    files, size = _cache_files(info.path)
    return {"cache": None if info.path is None else str(info.path), "writable": info.writable,
            "source": info.source, "reason": info.reason or None, "compiled": compiled,
            "seconds": time.perf_counter() - start, "files": files, "bytes": size}
