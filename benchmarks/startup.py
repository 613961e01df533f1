"""Start-up: the first-ever compile of the engine (empty numba cache), the warm load, and the
command line's start-up.

Cold: a fresh process with ``NUMBA_CACHE_DIR`` pointing to an empty temporary directory (numba
then neither reads nor writes the in-tree caches) imports phaseimpact and makes one call of
each compiled entry a session needs: ``simulate`` (Hunt-Crossley, ``paper``, the seed's RK4,
saved steps) and ``simulate_many`` (the parallel loop), with the kernels compiled for linking only
(the default, ``phaseimpact/_jit.py``) and, alternating with it, as whole libraries
(``PHASEIMPACT_LINKED_ONLY=0``, numba's own way). Warm: the same in a second process on
the now filled cache. Then whole commands on the project's own cache (medians of 5): the ones that
integrate nothing (``cases``, ``params``, ``--version``, ``--help``: they import neither numba nor
SciPy, target <= 0.3 s), ``python -c "import phaseimpact"``, ``phaseimpact simulate`` and
``phaseimpact warmup`` (a warm cache: it only loads). A user's first command, ``phaseimpact simulate``
on an empty cache, is timed alongside the cold sessions.

    python benchmarks/startup.py [--quick]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import VENV_BIN, emit, load, machine, save_section, save_targets, table, target  # noqa: E402

SESSION = r"""
import json, time
t0 = time.perf_counter()
import phaseimpact
from phaseimpact import seed_parameters, simulate, simulate_many
out = {"import phaseimpact": time.perf_counter() - t0}
p = seed_parameters(v=1.0, kappa=3e9)
for name, call in (
        ("simulate hunt-crossley", lambda: simulate(p, "hunt-crossley", 2e-3)),
        ("simulate paper", lambda: simulate(p, "paper", None, stop_on="slip")),
        ("simulate rk4", lambda: simulate(p, "paper", 2e-4, integrator="rk4")),
        ("simulate save=steps", lambda: simulate(p, "hunt-crossley", 2e-3, save="steps")),
        ("simulate_many (parallel)", lambda: simulate_many([p, p.replace(kappa=1e12)], "paper", n_threads=2))):
    t = time.perf_counter()
    call()
    out[name] = time.perf_counter() - t
out["total"] = time.perf_counter() - t0
print(json.dumps(out))
"""


def session(cache_dir: str, linked_only: bool = True) -> dict:
    env = {**os.environ, "NUMBA_CACHE_DIR": cache_dir, "PHASEIMPACT_LINKED_ONLY": str(int(linked_only))}
    start, cpu = time.perf_counter(), _children_cpu()
    res = subprocess.run([str(VENV_BIN / "python"), "-c", SESSION], env=env, capture_output=True, text=True,
                         check=True)
    out = json.loads(res.stdout.strip().splitlines()[-1])
    out["process"] = time.perf_counter() - start
    out["cpu"] = _children_cpu() - cpu
    return out


def _children_cpu() -> float:
    """CPU seconds (user + system) of the finished child processes: unlike wall time, not
    lengthened by other jobs on a shared machine."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def cold_command(cmd: list[str]) -> tuple[float, float]:
    """Wall and CPU time of one command on an empty cache: a user's first command."""
    with tempfile.TemporaryDirectory(prefix="numba-cold-") as cache:
        env = {k: v for k, v in os.environ.items() if k != "PHASEIMPACT_LINKED_ONLY"}
        env["NUMBA_CACHE_DIR"] = cache
        start, cpu = time.perf_counter(), _children_cpu()
        subprocess.run(cmd, env=env, capture_output=True, check=True)
        return time.perf_counter() - start, _children_cpu() - cpu


def seconds(sessions: list[dict]) -> str:
    return ", ".join(f"{run['process']:.1f}" for run in sessions)


def cpu_seconds(sessions: list[dict]) -> str:
    return ", ".join(f"{run['cpu']:.1f}" for run in sessions)


def command_time(cmd: list[str], repeats: int) -> tuple[float, list[float]]:
    # as installed: Python's bytecode cache on (some shells set PYTHONDONTWRITEBYTECODE, which makes
    # every start compile phaseimpact's modules from source, ~0.1 s)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    subprocess.run(cmd, capture_output=True, check=True, env=env)  # warm, and writes the bytecode
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run(cmd, capture_output=True, check=True, env=env)
        times.append(time.perf_counter() - start)
    return statistics.median(times), times


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="one cold compile instead of 3")
    args = ap.parse_args(argv)
    cold_repeats = 1 if args.quick else 3
    start_load = load()
    emit("# Start-up: first-ever compile, warm load, command line\n")
    emit(machine())
    emit(start_load + "\n")
    first_command = [str(VENV_BIN / "phaseimpact"), "simulate", "--law", "hunt-crossley", "--kappa", "3e9"]
    colds, wholes, warms, commands_cold = [], [], [], []
    for i in range(cold_repeats):  # the ways alternate, so that a drifting machine affects them alike
        with tempfile.TemporaryDirectory(prefix="numba-cold-") as cache:
            colds.append(session(cache))
            warms.append(session(cache))
        with tempfile.TemporaryDirectory(prefix="numba-cold-") as cache:
            wholes.append(session(cache, linked_only=False))
        commands_cold.append(cold_command(first_command))
        emit(f"cold {i + 1}: {colds[-1]['process']:.1f} s, CPU {colds[-1]['cpu']:.1f} s (whole libraries: "
             f"{wholes[-1]['process']:.1f} s, CPU {wholes[-1]['cpu']:.1f} s); warm: {warms[-1]['process']:.2f} s; "
             f"first command: {commands_cold[-1][0]:.1f} s, CPU {commands_cold[-1][1]:.1f} s")
    first_time = statistics.median(wall for wall, _ in commands_cold)
    first_cpu = statistics.median(cpu for _, cpu in commands_cold)
    keys = [k for k in colds[0] if k not in ("total", "cpu")]
    rows = [(k, *(f"{statistics.median(run[k] for run in runs):.3g}" for runs in (colds, wholes, warms)))
            for k in keys]
    cold_total = statistics.median(c["process"] for c in colds)
    whole_total = statistics.median(c["process"] for c in wholes)
    cold_cpu = statistics.median(c["cpu"] for c in colds)
    whole_cpu = statistics.median(c["cpu"] for c in wholes)
    py = str(VENV_BIN / "python")
    exe = str(VENV_BIN / "phaseimpact")
    light = {f"phaseimpact {c}": [exe, c] for c in ("cases", "params", "--version", "--help")}
    commands = {
        **light,
        'python -c "import phaseimpact"': [py, "-c", "import phaseimpact"],
        'python -c "import numpy"': [py, "-c", "import numpy"],
        'python -c "import numpy, scipy, numba"': [py, "-c", "import numpy, scipy, numba"],
        "phaseimpact simulate --law hunt-crossley --kappa 3e9": [exe, "simulate", "--law", "hunt-crossley",
                                                                 "--kappa", "3e9"],
        "phaseimpact warmup": [exe, "warmup"],
    }
    cmd_rows = []
    medians = {}
    for label, cmd in commands.items():
        med, all_times = command_time(cmd, 5)
        cmd_rows.append((f"`{label}`", f"{med:.3g}", ", ".join(f"{t:.2f}" for t in all_times)))
        medians[label] = med
        emit(f"{label}: {med:.3g} s")
    light_time = max(medians[label] for label in light)
    end_load = load()
    text = (f"First-ever compile (empty `NUMBA_CACHE_DIR`, one process), median of {cold_repeats}: kernels "
            "compiled for linking only (the default, `phaseimpact/_jit.py`) and as whole libraries "
            "(`PHASEIMPACT_LINKED_ONLY=0`), alternating, and the warm load of the same calls in a second "
            "process:\n\n"
            + table(("step", "cold, linked only [s]", "cold, whole libraries [s]", "warm [s]"), rows)
            + f"\n\nLinked only against whole libraries, wall: {cold_total:.3g} / {whole_total:.3g} s = "
            f"{cold_total / whole_total:.2f} (runs: {seconds(colds)} s against {seconds(wholes)} s); CPU time "
            f"(user + system, not lengthened by other jobs): {cold_cpu:.3g} / {whole_cpu:.3g} s = "
            f"{cold_cpu / whole_cpu:.2f} (runs: {cpu_seconds(colds)} s against "
            f"{cpu_seconds(wholes)} s)."
            + "\n\nA user's first command on an empty cache, `phaseimpact simulate --law hunt-crossley --kappa 3e9` "
            f"(the default; it compiles `run` only): median {first_time:.3g} s wall, {first_cpu:.3g} s CPU (runs: "
            + ", ".join(f"{wall:.1f} s / {cpu:.1f} s CPU" for wall, cpu in commands_cold) + ")."
            + "\n\nWhole commands on the project's cache (warm), median of 5:\n\n"
            + table(("command", "wall, median [s]", "runs [s]"), cmd_rows))
    emit()
    emit(text)
    emit(f"\nat the end: {end_load}")
    save_section("startup" + args.quick * "_quick",
                 f"## Start-up\n\n{machine()}\n\n{start_load} at the start, {end_load} at the end. "
                 "`python benchmarks/startup.py`\n\n" + text)
    save_targets("startup" + args.quick * "_quick", [
        # the compile runs on one core: its CPU time is its wall time on an otherwise idle machine
        target("first command on an empty cache (phaseimpact simulate), CPU time", "<= 30 s",
               f"{first_cpu:.3g} s ({first_time:.3g} s wall under the load above)", bool(first_cpu <= 30),
               "NUMBA_CACHE_DIR=$(mktemp -d) phaseimpact simulate --law hunt-crossley --kappa 3e9"),
        target("commands that integrate nothing (cases, params, --version, --help), warm", "<= 0.3 s",
               f"{light_time:.3g} s (the slowest median)", bool(light_time <= 0.3),
               "time phaseimpact cases|params|--version|--help (median of 5 each)")])
    return 0


if __name__ == "__main__":
    sys.exit(main())
