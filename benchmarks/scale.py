"""Parallel scaling: ``sweep``, ``atlas`` and ``simulate_many`` over 1, 2, 4, ... cores, threads and
processes, with the parallel efficiency and the serial fraction it implies.

Efficiency at ``n`` workers is ``T(1) / (n T(n))``; the serial fraction is Karp and Flatt's
``f = (1/S - 1/n) / (1 - 1/n)`` with ``S = T(1) / T(n)`` (Amdahl's law solved for its serial part:
0 for a perfect scaling, the same ``f`` at every ``n`` when one serial part is all that limits it).
Seed case, rtol 1e-10, each run until its outcome settles: a ``paper`` sweep of ``N`` kappa in
[1e8, 1e13], a ``paper`` atlas over (kappa, v), a ``hunt-crossley`` ``simulate_many`` of ``N``
``Parameters``, and the same cases packed beforehand and run in one ``run_batch`` call (the
engine's threads without simulate_many's packing and chunks: where its time goes). The worker
counts are 1, 2, 4, ... up to the machine's cores; the contenders take turns within each repeat,
and every parallel result is checked bit for bit against the one-worker result.

On a shared machine the speed of one core drifts by tens of per cent from minute to minute, so a
ratio of two medians taken minutes apart measures the drift as much as the scaling. Each repeat
therefore times every worker count of a workload back to back (their order alternating between
repeats), and the efficiency is the median over the repeats of ``T(1) / (n T(n))`` within one
repeat. The same pairing times two controls: ``n`` threads of a compiled arithmetic loop that
touches no memory and shares nothing, and the sweep's points dealt to ``n`` processes that share
nothing (each started beforehand and sweeping its every ``n``-th kappa in one thread). The second
runs the engine's own code with no in-process cost at all (no GIL, no threads to start and join,
no Python between chunks), so whatever it loses, busy cores lose to each other on this machine (a
shared cache, the host's other guests, a lower clock); its split is fixed, so a process that runs
slower also leaves the others idle at the end, where threads take the rest from a counter. "Cores
busy" is the CPU time over ``n`` times the wall time: below 100 % by the idle and serial time of
the run, whatever the speed of a core at that minute.

    python benchmarks/scale.py [--quick] [--n 8000]
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import statistics
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import emit, load, machine, save_section, save_targets, table, target  # noqa: E402

from phaseimpact import seed_parameters, simulate_many  # noqa: E402
from phaseimpact.continuation import Axis, atlas, sweep  # noqa: E402
from phaseimpact.integrate import driver as d  # noqa: E402
from phaseimpact.integrate.api import MAX_EVENTS, MAX_STEPS, _stiff_after, radau_marker  # noqa: E402
from phaseimpact.integrate.batch import PACK_CHUNK, _run_block, pack_batch, run_batch, thread_tasks  # noqa: E402
from phaseimpact.integrate.record import workspace_size  # noqa: E402
from phaseimpact.model import as_law  # noqa: E402

RTOL = 1e-10
#: simulate_many's runs alone: its cases packed beforehand and run in one call (no packing, no chunks).
ENGINE_ONLY = "simulate_many's runs, packed beforehand"
#: The sweep's points dealt to processes that share nothing: the engine's code without in-process costs.
PROCESS_CEILING = "control: the sweep in processes that share nothing"
#: Threads of arithmetic alone: the machine's scaling of compiled threads that touch no memory.
ARITHMETIC_CONTROL = "control: arithmetic only"


def worker_counts() -> list[int]:
    cores = os.cpu_count() or 1
    counts, n = [], 1
    while n < cores:
        counts.append(n)
        n *= 2
    return [*counts, cores]


def karp_flatt(speed_up: float, n: int) -> float:
    return float("nan") if n == 1 else (1 / speed_up - 1 / n) / (1 - 1 / n)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="3 repeats and a quarter of the points")
    ap.add_argument("--n", type=int, default=8000, help="points of the sweep and of simulate_many")
    ap.add_argument("--section", default="scale",
                    help="results/<section>.md and .json (default scale; a GPU machine's run: scale_gpu_machine)")
    ap.add_argument("--worker", nargs=2, type=int, metavar=("I", "OF"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        return _sweep_worker(*args.worker, args.n // 4 if args.quick else args.n)
    n_points = args.n // 4 if args.quick else args.n
    repeats = 3 if args.quick else 9
    side = int(round(n_points ** 0.5))
    params = seed_parameters(v=1.0)
    kappas = _sweep_kappas(n_points)
    plist = [params.replace(kappa=float(k)) for k in np.geomspace(1e8, 1e11, n_points)]
    axes = [Axis("kappa", np.geomspace(1e10, 1e14, side), log=True), Axis("v", np.linspace(0.5, 13.0, side))]
    counts = worker_counts()
    start_load = load()
    emit(f"# Parallel scaling ({n_points} points, rtol {RTOL:g}, workers {counts})\n")
    emit(machine())
    emit(start_load + "\n")

    packed = pack_batch(plist, as_law("hunt-crossley"), None, RTOL)

    def workloads(n):
        return {
            ("sweep", "threads"): lambda: sweep(params, "paper", kappas, n_jobs=n),
            ("sweep", "loky processes"): lambda: sweep(params, "paper", kappas, n_jobs=n, backend="loky"),
            ("atlas", "threads"): lambda: atlas(params, "paper", axes, n_jobs=n),
            ("simulate_many", "threads"): lambda: simulate_many(plist, "hunt-crossley", rtol=RTOL, n_threads=n),
            (ENGINE_ONLY, "threads"): lambda: run_batch(packed, rtol=RTOL, n_threads=n),
        }

    contenders = {(what, how, n): fn for n in counts for (what, how), fn in workloads(n).items()}
    contenders.update({(ARITHMETIC_CONTROL, "threads", n): (lambda n=n: _spin_threads(n)) for n in counts})
    ceilings = {n: _Processes(n, args.quick, args.n) for n in counts}
    for ceiling in ceilings.values():
        ceiling.wait_ready()
    contenders.update({(PROCESS_CEILING, "processes", n): ceilings[n].sweep for n in counts})
    results = {key: fn() for key, fn in contenders.items()}  # warm-up: compiles, starts loky's workers
    times = {key: [] for key in contenders}
    busy = {key: [] for key in contenders}  # CPU time of the process over n times the wall time
    kinds = list(dict.fromkeys((what, how) for what, how, _ in contenders))
    for r in range(repeats):
        for what, how in kinds:
            for n in (counts if r % 2 == 0 else counts[::-1]):  # back to back, the order alternating
                if how == "loky processes" and n > 1 and len(counts) > 2:
                    # loky's one pool is resized to each n, starting new workers (each loads the
                    # engine): a call untimed first, or the 16-core run measured their start (0.14-0.18x)
                    contenders[(what, how, n)]()
                start, cpu = time.perf_counter(), time.process_time()
                result = contenders[(what, how, n)]()
                wall = time.perf_counter() - start
                times[(what, how, n)].append(wall)
                # the ceiling's workers report their own CPU time; loky's cannot be read from here
                used = result.cpu if how == "processes" else time.process_time() - cpu
                busy[(what, how, n)].append(used / (n * wall))
    for ceiling in ceilings.values():
        ceiling.close()
    section = "" if args.section == "scale" else f" --section {args.section}"
    where = "" if args.section == "scale" else f", {os.cpu_count()} cores ({args.section})"
    rows, targets = [], []
    for what, how in kinds:
        one = times[(what, how, 1)]
        reference = results[(what, how, 1)]
        for n in counts:
            t = statistics.median(times[(what, how, n)])
            speed_up = statistics.median(a / b for a, b in zip(one, times[(what, how, n)], strict=True))
            efficiency = speed_up / n
            same = "-" if what == ARITHMETIC_CONTROL else (
                "identical" if _same(reference, results[(what, how, n)]) else "DIFFERENT")
            used = "-" if how == "loky processes" else f"{100 * statistics.median(busy[(what, how, n)]):.0f} %"
            rows.append((what, how, n, f"{t:.3g}", f"{speed_up:.2f}", f"{100 * efficiency:.0f} %", used,
                         f"{karp_flatt(speed_up, n):.3f}" if n > 1 else "-", same))
            emit(f"{what}, {how}, {n}: {t:.3g} s, speed-up {speed_up:.2f}, efficiency {100 * efficiency:.0f} %")
            if n == 2 and how == "threads" and what in ("sweep", "atlas", "simulate_many"):
                targets.append(target(f"{what}: parallel efficiency at 2 threads (issue 36){where}", ">= 95 %",
                                      f"{100 * efficiency:.0f} %", bool(efficiency >= 0.95),
                                      f"python benchmarks/scale.py{section}"))
    pack_us = _packing_us(plist, repeats)
    run_us = 1e6 * statistics.median(times[("simulate_many", "threads", 1)]) / n_points
    emit(f"simulate_many's packing: {pack_us:.2g} us a case, a run {run_us:.3g} us a case on one worker")
    chunk_rows = _chunk_cost(3 * repeats)
    end_load = load()
    header = ("workload", "workers", "n", "time [s]", "speed-up", "efficiency", "cores busy",
              "serial fraction (Karp-Flatt)",
              "result vs 1 worker")
    title = "Parallel scaling" + (f" ({args.section})" if section else "")
    text = (f"## {title}\n\n{machine()}\n\n{start_load} at the start, {end_load} at the end. "
            f"`python benchmarks/scale.py{' --quick' if args.quick else ''}{section}`\n\n"
            f"{n_points} points each (the atlas {side} x {side}), {repeats} repeats; paper for the sweep and the "
            "atlas, hunt-crossley for simulate_many. Times are medians; speed-up and efficiency the medians over "
            "the repeats of T(1)/T(n) timed back to back (the machine's speed drifts between repeats); the "
            "controls are n threads of arithmetic alone, and the sweep's points dealt to n processes that share "
            "nothing, each started beforehand and sweeping every n-th kappa in one thread (the engine's code without "
            "any in-process cost: no GIL, no threads to start and join, no Python between chunks; what it loses, "
            "busy cores lose to each other on this machine, and, its split being fixed, a slower process leaves the "
            "others idle at the end); simulate_many's runs, packed "
            "beforehand, are its cases in one run_batch call, without its packing and chunks (the engine's "
            "threads by themselves); cores busy is the process's CPU "
            "time over n times the wall time (what is left is idle or serial time, whatever the core's "
            "speed). CPU backends only: the GPU's "
            "(backend=\"cuda\") is timed by "
            "benchmarks/gpu.py on a machine with one; no GPU "
            "rows. simulate_many's packing (Python, in the caller while the other workers run the chunk before): "
            f"{pack_us:.2g} us a case "
            f"(process CPU time, median of {3 * repeats}), its runs {run_us:.3g} us a case on one worker.\n\n"
            + table(header, rows)
            + "\n\nThe fixed cost of a threaded chunk: one chunk of "
            f"{CHUNK_COST_RUNS} Hunt-Crossley runs (about a millisecond of work) in n threads, its helpers kept "
            "from the chunk before (run_batch's, phaseimpact.integrate.helper_threads) or started and joined for the "
            f"chunk, as before (medians of {3 * repeats}, taking turns; the results the same bit for bit).\n\n"
            + table(("threads", "helpers kept [ms]", "helpers started for the chunk [ms]", "started / kept"),
                    chunk_rows))
    emit()
    emit(text)
    suffix = "_quick" if args.quick else ""
    save_section(f"{args.section}{suffix}", text)
    save_targets(f"{args.section}{suffix}", targets)
    return 0


SPIN_ITERATIONS = 200_000_000  # about 0.4 s of one core, as long as a sweep


@numba.njit(nogil=True, cache=False)
def _spin(n):
    """Arithmetic on registers alone: no memory traffic, nothing shared between threads."""
    x = 0.0
    for i in range(n):
        x = x * 0.999999 + 1.0 / (1.0 + (i & 1023))
    return x


def _spin_threads(n: int) -> float:
    """``n`` threads, each spinning the same work: the machine's own scaling of compiled threads."""
    with ThreadPoolExecutor(n) as pool:
        return sum(pool.map(_spin, [SPIN_ITERATIONS // n] * n))


#: The columns the process ceiling's workers send back (to check them against one worker's).
_CEILING_COLUMNS = ("max_force", "n_stick", "outcome", "t_run")


def _sweep_kappas(n_points: int) -> np.ndarray:
    return np.geomspace(1e8, 1e13, n_points)


def _sweep_worker(i: int, of: int, n_points: int) -> int:
    """A process of the ceiling: on each line ``go``, the sweep of every ``of``-th kappa from the
    ``i``-th in this process's one thread; replies with its CPU time and the columns (raw bytes as
    hex: no formatting of numbers inside the timed turn)."""
    params, kappas = seed_parameters(v=1.0), _sweep_kappas(n_points)[i::of]
    sweep(params, "paper", kappas, n_jobs=1)  # compiled (or read from the cache) before the first turn
    print("ready", flush=True)
    for _ in sys.stdin:
        cpu = time.process_time()
        result = sweep(params, "paper", kappas, n_jobs=1)
        reply = {"cpu": time.process_time() - cpu}
        for name in _CEILING_COLUMNS:
            column = np.asarray(getattr(result, name))
            reply[name] = [str(column.dtype), column.tobytes().hex()]
        print(json.dumps(reply), flush=True)
    return 0


class _CeilingResult:
    """The columns of the ceiling's workers in point order, and their CPU time together; read from
    their replies when first asked for (not within the timed turn)."""

    def __init__(self, lines: list[str]):
        self._lines = lines

    @functools.cached_property
    def _replies(self) -> list[dict]:
        return [json.loads(line) for line in self._lines]

    @property
    def cpu(self) -> float:
        return sum(reply["cpu"] for reply in self._replies)

    def __getattr__(self, name: str) -> np.ndarray:
        if name not in _CEILING_COLUMNS:
            raise AttributeError(name)
        parts = [np.frombuffer(bytes.fromhex(reply[name][1]), reply[name][0]) for reply in self._replies]
        column = np.empty(sum(part.size for part in parts), parts[0].dtype)
        for i, part in enumerate(parts):
            column[i::len(parts)] = part
        return column


class _Processes:
    """``n`` worker processes (``scale.py --worker i n``), started once before any timing; each
    sweeps its every ``n``-th kappa when told, all at once."""

    def __init__(self, n: int, quick: bool, n_arg: int):
        command = [sys.executable, str(Path(__file__).resolve()), "--n", str(n_arg), *(["--quick"] if quick else [])]
        self.workers = [subprocess.Popen([*command, "--worker", str(i), str(n)], stdin=subprocess.PIPE,
                                         stdout=subprocess.PIPE, text=True) for i in range(n)]

    def wait_ready(self) -> None:
        """Each worker has compiled (or loaded) the engine and swept once (every group starts at once:
        31 processes for 1-16 workers, within a GPU lease's limit for scale.py)."""
        for worker in self.workers:
            line = worker.stdout.readline().strip()
            if line != "ready":
                raise RuntimeError(f"a worker of the process ceiling did not start (said {line!r})")

    def sweep(self) -> _CeilingResult:
        for worker in self.workers:
            worker.stdin.write("go\n")
            worker.stdin.flush()
        return _CeilingResult([worker.stdout.readline() for worker in self.workers])

    def close(self) -> None:
        for worker in self.workers:
            worker.stdin.close()
            worker.wait()


#: Runs of the chunk whose fixed cost is timed (:func:`_chunk_cost`).
CHUNK_COST_RUNS = 32


def _chunk_cost(repeats: int) -> list[tuple]:
    """Wall time of one small chunk in 2, 4, ... 16 threads: helpers kept from the chunk before
    (``batch._run_block``) against helpers started and joined for the chunk (run_batch before
    helper_threads). Each result is checked against the one-thread run's."""
    cases = [seed_parameters(v=1.0, kappa=float(k)) for k in np.geomspace(1e9, 1e11, CHUNK_COST_RUNS)]
    packed = pack_batch(cases, as_law("hunt-crossley"), None, RTOL)
    args = (packed.law.code, (packed.C, packed.Y0, packed.t_end, packed.atol, packed.max_step),
            (RTOL, True, -1, 0, MAX_STEPS, MAX_EVENTS, _stiff_after(True)))
    radau = radau_marker(_stiff_after(True))

    def outputs():
        st = np.empty((3, CHUNK_COST_RUNS, 32))
        return (np.empty((CHUNK_COST_RUNS, d.N_SUMMARY)), st[0], st[1], st[2], np.empty(CHUNK_COST_RUNS, np.int64))

    def kept(n):
        out = outputs()
        _run_block(args, out, np.zeros((n, workspace_size(packed.C.shape[1], 32))), radau)
        return out[0]

    def started(n):
        out, work = outputs(), np.zeros((n, workspace_size(packed.C.shape[1], 32)))
        tasks, claimed = np.array(thread_tasks(CHUNK_COST_RUNS, n), np.int64), np.zeros(1, np.int64)
        helpers = [threading.Thread(target=d.run_block, args=(*args, tasks, claimed, out, ws, radau))
                   for ws in work[1:]]
        for helper in helpers:
            helper.start()
        d.run_block(*args, tasks, claimed, out, work[0], radau)
        for helper in helpers:
            helper.join()
        return out[0]

    reference = kept(1)
    counts = sorted({n for n in (2, 4, 16, os.cpu_count() or 1) if n > 1})
    times = {(how, n): [] for how in (kept, started) for n in counts}
    for r in range(repeats + 1):
        for how in ((kept, started) if r % 2 == 0 else (started, kept)):
            for n in counts:
                start = time.perf_counter()
                summary = how(n)
                if r > 0:  # the first turn starts the helpers kept later
                    times[(how, n)].append(time.perf_counter() - start)
                assert np.array_equal(summary, reference, equal_nan=True), f"{how.__name__}({n}) differs"
    rows = []
    for n in counts:
        a, b = (1e3 * statistics.median(times[(how, n)]) for how in (kept, started))
        rows.append((n, f"{a:.3g}", f"{b:.3g}", f"{b / a:.2f}"))
        emit(f"a chunk of {CHUNK_COST_RUNS} runs in {n} threads: helpers kept {a:.3g} ms, started {b:.3g} ms")
    return rows


def _packing_us(plist: list, repeats: int) -> float:
    """Process CPU time of packing one of simulate_many's chunks, us a case (median)."""
    chunk, law, cpu = plist[:PACK_CHUNK], as_law("hunt-crossley"), []
    for _ in range(3 * repeats):
        start = time.process_time()
        pack_batch(chunk, law, None, RTOL)
        cpu.append(time.process_time() - start)
    return 1e6 * statistics.median(cpu) / len(chunk)


def _same(a, b) -> bool:
    """Bit-identical summary columns (a SweepResult or Columns)."""
    names = ("max_force", "n_stick", "outcome", "t_run") if hasattr(a, "n_stick") else ("max_force",)
    return all(np.array_equal(np.asarray(getattr(a, c)), np.asarray(getattr(b, c)), equal_nan=True) for c in names)


if __name__ == "__main__":
    sys.exit(main())
