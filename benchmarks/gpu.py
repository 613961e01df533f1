"""The CUDA backend against the CPU threads (issue 39): one prepared script for a GPU machine.

(a) A ``paper`` atlas of ``--side`` x ``--side`` points (kappa x v, as ``benchmarks/atlas.py``:
    geomspace(1e10, 1e15) x geomspace(0.3, 13)) on the GPU (``backend="cuda"``, after a warm-up
    launch that compiles the kernel; the compile time is reported apart) and on ``--threads`` CPU
    threads (``backend="threads"``; 1, 2, 4, 8 and 16, only counts up to ``os.cpu_count()``).
(b) ``--side``^2 Hunt-Crossley trajectories (kappa x v, t_end 2e-3, no settling) on the GPU. The
    comparison with diffrax (JAX) on the same GPU is not in this script: diffrax, jax and equinox
    are not installed here and no wheels are carried with the tree; the row says so.
(c) The GPU's results against the CPU's on the first ``--check`` points of the atlas: statuses,
    outcomes and counts equal, the largest relative difference of every floating column.

Writes ``benchmarks/results/gpu.md`` and ``gpu.json`` (the targets' rows of figures/benchmarks.md).
Without a usable GPU it writes that it was not timed on a GPU, and why.

``--simulator`` runs the same three parts on a tiny grid under numba's CUDA simulator (the engine
uncompiled, one Python thread per point), so that CI checks the script does not rot; its times mean
nothing and it writes ``--results`` (default ``benchmarks/results/gpu_simulator.md``) only.

The GPU's rows come first (a run cut short still prints them), then the CPU's. The kernel's first
compile is timed apart: on an H200 machine (2026-11-28) it had not finished after 559 s
(results/gpu.md), before the engine's calls were kept as calls (results/gpu_compile.md: the PTX
then took about half a minute without a GPU; the driver's assembly of it is not timed yet).

    python benchmarks/gpu.py [--side 1000] [--check 10000] [--threads 1,2,4,8,16]   # a GPU machine
    python benchmarks/gpu.py --simulator [--results FILE.md]     # anywhere, seconds

``bash benchmarks/gpu_machine.sh`` runs it in one lease of a GPU machine, with scale.py.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _simulated() -> bool:
    return os.environ.get("NUMBA_ENABLE_CUDASIM") == "1"


def grid(side: int):
    import numpy as np

    return {"kappa": np.geomspace(1e10, 1e15, side), "v": np.geomspace(0.3, 13, side)}


def compare(gpu, cpu, n: int) -> tuple[bool, float]:
    """(codes and counts equal, largest relative difference of the float columns) on the first n points."""
    import numpy as np

    same = all(np.array_equal(getattr(gpu, name)[:n], getattr(cpu, name)[:n])
               for name in ("status", "outcome", "stop_reason"))
    worst = 0.0
    for name, column in gpu.values.items():
        a, b = column[:n], cpu.values[name][:n]
        if a.dtype.kind in "iub":
            same = same and np.array_equal(a, b)
            continue
        both = np.isfinite(a) & np.isfinite(b)
        same = same and np.array_equal(np.isnan(a), np.isnan(b))
        scale = np.maximum(np.abs(b[both]), np.finfo(float).tiny)
        if both.any():
            worst = max(worst, float(np.max(np.abs(a[both] - b[both]) / scale)))
    return bool(same), worst


def kernel_resources() -> str:
    """The compiled kernel's registers and local memory (spills, arrays) per thread, as numba reports them."""
    from phaseimpact import cuda

    kernel = cuda._kernel()
    try:
        registers = list(kernel.get_regs_per_thread().values())
        local = list(kernel.get_local_mem_per_thread().values())
        most = list(kernel.get_max_threads_per_block().values())
    except AttributeError as why:  # a numba-cuda without these queries: say so, the times still stand
        return f"kernel resources not read ({type(why).__name__}: {why})"
    return (f"The kernel: {registers} registers and {local} bytes of local memory per thread, at most {most} "
            f"threads a block (blocks of {cuda.THREADS_PER_BLOCK})")


def timed(function):
    start = time.perf_counter()
    result = function()
    return time.perf_counter() - start, result


def run(side: int, check: int, threads: list[int]) -> tuple[list[list], list[dict], str]:
    """The three parts: the table's rows, the targets' rows and a note."""
    from phaseimpact import seed_parameters
    from phaseimpact.continuation import atlas

    base = seed_parameters()
    axes = grid(side)
    n = side * side
    print(f"compiling the CUDA kernel ({time.strftime('%H:%M:%S')})", flush=True)
    compile_s, _ = timed(lambda: atlas(base, "paper", grid(2), backend="cuda"))
    gpu_s, gpu = timed(lambda: atlas(base, "paper", axes, backend="cuda"))
    atlas_rows = [["(a) paper atlas", n, "GPU (cuda)", gpu_s, f"kernel compile and first launch {compile_s:.3g} s"]]
    print(atlas_rows[-1], flush=True)  # the GPU's rows first: a run cut short by the lease still says them
    hc_s, _ = timed(lambda: atlas(base, "hunt-crossley", axes, t_end=2e-3, backend="cuda"))
    hunt_crossley_row = ["(b) hunt-crossley, t_end 2e-3", n, "GPU (cuda)", hc_s,
                         "diffrax: not compared (diffrax, jax, equinox not installed; no wheels carried)"]
    print(hunt_crossley_row, flush=True)
    cpu = None
    for k in threads:
        cpu_s, cpu = timed(lambda k=k: atlas(base, "paper", axes, n_jobs=k))
        atlas_rows.append(["(a) paper atlas", n, f"CPU, {k} threads", cpu_s, ""])
        print(atlas_rows[-1], flush=True)
    rows = [*atlas_rows, hunt_crossley_row]
    subset = min(check, n)
    same, worst = compare(gpu, cpu, subset)
    rows.append(["(c) GPU vs CPU", subset, "codes and counts equal" if same else "**codes or counts differ**",
                 float("nan"), f"largest relative difference of a float column {worst:.2e}"])
    one = {r[2]: r[3] for r in rows if r[0] == "(a) paper atlas"}
    targets = [
        {"what": f"{n}-point paper atlas on one GPU", "target": "<= 1 s (1e6 points, one H100)",
         "measured": f"{gpu_s:.3g} s", "met": gpu_s <= 1.0 if n >= 10**6 else None,
         "command": "python benchmarks/gpu.py"},
        {"what": f"{n} hunt-crossley trajectories on one GPU", "target": "<= 0.25 s (1e6, one H100)",
         "measured": f"{hc_s:.3g} s", "met": hc_s <= 0.25 if n >= 10**6 else None,
         "command": "python benchmarks/gpu.py"},
    ]
    most = max(threads, default=1)
    if "CPU, 1 threads" in one and most > 1:
        efficiency = one["CPU, 1 threads"] / (most * one[f"CPU, {most} threads"])
        targets.append({"what": f"CPU efficiency at {most} threads", "target": ">= 85 % at 16 threads",
                        "measured": f"{100 * efficiency:.0f} %",
                        "met": efficiency >= 0.85 if most == 16 else None,
                        "command": "python benchmarks/gpu.py"})
    return rows, targets, "GPU vs CPU equal in codes and counts" if same else "GPU vs CPU differ"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--side", type=int, default=1000, help="grid side (default 1000: 1e6 points)")
    ap.add_argument("--check", type=int, default=10_000, help="points compared GPU vs CPU (default 10000)")
    ap.add_argument("--threads", type=lambda text: [int(k) for k in text.split(",")], default=[1, 2, 4, 8, 16],
                    help="CPU thread counts timed on the same atlas, comma separated (default 1,2,4,8,16; "
                         "those above the machine's cores are left out)")
    ap.add_argument("--simulator", action="store_true", help="a tiny grid under numba's CUDA simulator (CI)")
    ap.add_argument("--results", type=Path, default=None, help="where --simulator writes its table")
    args = ap.parse_args(argv)
    if args.simulator and not _simulated():  # the simulator is chosen when numba is imported: a fresh process
        env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1", NUMBA_DISABLE_JIT="1")
        return subprocess.call([sys.executable, __file__, *(argv if argv is not None else sys.argv[1:])], env=env)

    sys.path.insert(0, str(HERE))
    from _common import load, machine, save_section, save_targets, table

    from phaseimpact import cuda

    header = ["part", "points", "where", "time (s)", "note"]
    if args.simulator:
        rows, _, note = run(3, 9, [1, 2])
        text = "\n".join(["## gpu (CUDA simulator)", "", machine(), "",
                          "numba's CUDA simulator on a 3 x 3 grid, the engine uncompiled: checks the script "
                          f"runs; the times mean nothing. {note}.", "", table(header, rows)])
        path = args.results or HERE / "results" / "gpu_simulator.md"
        path.write_text(text + "\n")
        print(text)
        return 0
    missing = cuda.unavailable()
    if missing is not None:
        text = "\n".join(["## gpu", "", machine(), "", f"Not timed on a GPU: {missing}. Run "
                          "`python benchmarks/gpu.py` on a GPU machine.", ""])
        save_section("gpu", text)
        save_targets("gpu", [{"what": "1e6-point paper atlas, 1e6 hunt-crossley trajectories on one GPU",
                              "target": "<= 1 s, <= 0.25 s (one H100)", "measured": "not timed on a GPU",
                              "met": None, "command": "python benchmarks/gpu.py"}])
        print(text)
        return 0
    threads = [k for k in args.threads if k <= (os.cpu_count() or 1)]
    rows, targets, note = run(args.side, args.check, threads)
    import numba.cuda

    device = numba.cuda.get_current_device().name
    device = device.decode() if isinstance(device, bytes) else device
    text = "\n".join(["## gpu", "", machine(), "", f"GPU: {device}; {load()}. {note}. {kernel_resources()}.", "",
                      table(header, rows)])
    save_section("gpu", text)
    save_targets("gpu", targets)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
