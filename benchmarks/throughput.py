"""Sweep throughput: ``sweep`` (threads, loky), ``simulate_many``, a loop of ``simulate`` and a loop of
the scipy oracle; and the 20,000-``kappa`` sweep through the command line, start-up included.

Seed case, v = 1 m/s, ``N`` kappa log-spaced in [1e8, 1e13], each run until its outcome settles
(rtol 1e-10), for ``paper`` (the command line's example) and ``hunt-crossley``. The in-process
contenders take turns within each repeat (medians); the oracle loop (``phaseimpact/_oracle.py``:
``solve_ivp`` DOP853 with the same events) is timed on a random subset and extrapolated. The
command line is timed as a whole process (``phaseimpact sweep ... --out X.h5 --no-progress``,
median of 3), with ``--jobs 1`` (its default) and ``--jobs 2``.

    python benchmarks/throughput.py [--quick] [--n 2000] [--cli-n 20000]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import VENV_BIN, emit, load, machine, save_section, save_targets, table, target  # noqa: E402

from phaseimpact import seed_parameters, simulate, simulate_many  # noqa: E402
from phaseimpact._oracle import oracle  # noqa: E402
from phaseimpact.continuation import sweep  # noqa: E402

LAWS = ("paper", "hunt-crossley")
RTOL = 1e-10


def cli_command(n: int, out: Path, jobs: int) -> list[str]:
    return [str(VENV_BIN / "phaseimpact"), "sweep", "--law", "paper", "--v", "1", "--axis", f"kappa=1e8:1e13:{n}:log",
            "--out", str(out), "--no-progress", "--force", "--jobs", str(jobs)]


def time_cli(n: int, jobs: int, repeats: int) -> tuple[float, list[float]]:
    """Median wall time of the whole command (start-up, compute, archive), s."""
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeats):
            start = time.perf_counter()
            subprocess.run(cli_command(n, Path(tmp) / "sweep.h5", jobs), check=True, capture_output=True)
            times.append(time.perf_counter() - start)
    return statistics.median(times), times


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="3 repeats, oracle on 5 points, CLI once per setting")
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--cli-n", type=int, default=20000)
    args = ap.parse_args(argv)
    repeats = 3 if args.quick else 5
    subset = 5 if args.quick else 20
    cli_repeats = 1 if args.quick else 3
    start_load = load()
    emit(f"# Sweep throughput (N = {args.n}, kappa in [1e8, 1e13], until settled, rtol {RTOL:g})\n")
    emit(machine())
    emit(start_load + "\n")
    params = seed_parameters(v=1.0)
    kappas = np.geomspace(1e8, 1e13, args.n)
    plist = [params.replace(kappa=float(k)) for k in kappas]
    rows, targets = [], []
    for law in LAWS:
        contenders = {
            "sweep, threads, n_jobs=1": lambda law=law: sweep(params, law, kappas, n_jobs=1),
            "sweep, threads, n_jobs=2": lambda law=law: sweep(params, law, kappas, n_jobs=2),
            "simulate_many, n_threads=2": lambda law=law: simulate_many(plist, law, rtol=RTOL, n_threads=2),
            "sweep, loky, n_jobs=2": lambda law=law: sweep(params, law, kappas, n_jobs=2, backend="loky"),
        }
        results = {name: fn() for name, fn in contenders.items()}  # warm-up (loky starts its workers)
        times = {name: [] for name in contenders}
        for _ in range(repeats):
            for name, fn in contenders.items():
                start = time.perf_counter()
                fn()
                times[name].append(time.perf_counter() - start)
        med = {name: statistics.median(t) for name, t in times.items()}
        start = time.perf_counter()
        loop = [simulate(p, law, rtol=RTOL) for p in plist]
        med["loop of simulate"] = time.perf_counter() - start
        rng = np.random.default_rng(0)
        pick = np.sort(rng.choice(args.n, size=subset, replace=False))
        start = time.perf_counter()
        oracle_force = [oracle(plist[i], law, rtol=RTOL).max_force for i in pick]
        oracle_time = (time.perf_counter() - start) / subset * args.n
        ref = results["sweep, threads, n_jobs=2"]
        loop_force = np.array([tr.max_force for tr in loop])
        loop_n = np.array([tr.n_stick for tr in loop])
        same = {name: bool(np.array_equal(res.max_force, ref.max_force) and np.array_equal(res.n_stick, ref.n_stick)
                           and np.array_equal(res.outcome, ref.outcome))
                for name, res in results.items()}
        same_loop = bool(np.array_equal(loop_force, ref.max_force) and np.array_equal(loop_n, ref.n_stick))
        oracle_dis = float(np.max(np.abs(np.array(oracle_force) - ref.max_force[pick]) / ref.max_force[pick]))
        base = med["sweep, threads, n_jobs=2"]
        for name in contenders:
            rows.append((law, name, f"{med[name]:.3g}", f"{args.n / med[name]:.3g}", f"{med[name] / base:.2f}",
                         "identical" if same[name] else "DIFFERENT", f"median of {repeats}"))
        rows.append((law, "loop of simulate (Python)", f"{med['loop of simulate']:.3g}",
                     f"{args.n / med['loop of simulate']:.3g}", f"{med['loop of simulate'] / base:.2f}",
                     "identical" if same_loop else "DIFFERENT", "one run"))
        rows.append((law, "loop of the scipy oracle (same events)", f"{oracle_time:.3g}",
                     f"{args.n / oracle_time:.3g}", f"{oracle_time / base:.0f}",
                     f"max force within {oracle_dis:.1e}", f"extrapolated from {subset} random points"))
        emit(f"{law}: " + ", ".join(f"{k} {v:.3g} s" for k, v in med.items()) + f", oracle loop ~{oracle_time:.3g} s")
        if law == "paper":
            targets.append(target(f"{args.n}-kappa sweep (1e8-1e13), 2 jobs (threads), paper", "<= 0.15 s compute",
                                  f"{base:.3g} s", bool(base <= 0.15), "python benchmarks/throughput.py"))
    cli_rows = []
    fixed, fixed_times = time_cli(2, 1, cli_repeats)
    cli_rows.append(("the same with `--num 2 --jobs 1` (start-up and archive, next to no compute)", f"{fixed:.3g}",
                     ", ".join(f"{t:.3g}" for t in fixed_times), "-", f"{fixed:.3g}"))
    for jobs in (1, 2):
        wall, all_times = time_cli(args.cli_n, jobs, cli_repeats)
        start = time.perf_counter()
        sweep(params, "paper", np.geomspace(1e8, 1e13, args.cli_n), n_jobs=jobs)
        compute = time.perf_counter() - start
        cmd = " ".join(["phaseimpact", *cli_command(args.cli_n, Path("X.h5"), jobs)[1:]])
        cli_rows.append((f"`{cmd}`", f"{wall:.3g}", ", ".join(f"{t:.3g}" for t in all_times), f"{compute:.3g}",
                         f"{wall - compute:.3g}"))
        emit(f"CLI {args.cli_n} jobs={jobs}: {wall:.3g} s (runs {all_times}), in-process sweep {compute:.3g} s")
        targets.append(target(f"{args.cli_n} kappa through the CLI, start-up included (--jobs {jobs})", "<= 2.5 s",
                              f"{wall:.3g} s (compute {compute:.3g} s)", bool(wall <= 2.5),
                              f"time {cmd} (median of {cli_repeats})"))
    end_load = load()
    header = ("law", "method", "time [s]", "points/s", "time / sweep n_jobs=2", "same columns as sweep n_jobs=2",
              "note")
    cli_header = ("command", "wall, median [s]", "runs [s]", "in-process sweep, same jobs [s]",
                  "start-up + archive [s]")
    text = table(header, rows) + "\n\nThe command line, whole process:\n\n" + table(cli_header, cli_rows)
    emit()
    emit(text)
    emit(f"\nat the end: {end_load}")
    save_section("throughput" + args.quick * "_quick",
                 f"## Sweep throughput\n\n{machine()}\n\n{start_load} at the start, {end_load} at the end.\n\n"
                 f"Seed case, v = 1 m/s, N = {args.n} kappa log-spaced in [1e8, 1e13], each run until its outcome "
                 f"settles, rtol {RTOL:g}. `python benchmarks/throughput.py`\n\n" + text)
    save_targets("throughput" + args.quick * "_quick", targets)
    return 0


if __name__ == "__main__":
    sys.exit(main())
