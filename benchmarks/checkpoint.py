"""Checkpoint cost of a large atlas: in place (``archive.Checkpoint``) against a whole rewrite (``archive.save``).

A (kappa, v) atlas of ``--points`` points (default 1e6, 1000 x 1000) is filled chunk by chunk
(``--chunk`` points, as the threads backend of ``atlas`` does) with synthetic columns and stick
phases (1 to 3 per point; the engine is not run: this measures the archive alone), and after each
chunk the archive is checkpointed. Printed: median, 90th percentile and largest time of the in-place
checkpoints, how many checkpoints rewrote the whole file (the first one, and any that ran out of
stick rows), bytes written per checkpoint (``wchar`` of /proc/self/io, Linux), and for comparison
the median time of ``archive.save`` of the finished atlas, which every checkpoint cost before the
in-place writes (schema 2).

    python benchmarks/checkpoint.py [--points 1000000] [--chunk 4096] [--no-fsync] [--folder DIR]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import emit, machine  # noqa: E402

from phaseimpact import archive, seed_parameters  # noqa: E402
from phaseimpact._atomic import exclusive  # noqa: E402
from phaseimpact.continuation import Axis, Grid, SweepResult  # noqa: E402
from phaseimpact.integrate.result import SUMMARY_COLUMNS, Columns  # noqa: E402
from phaseimpact.model import ContactLaw  # noqa: E402


def written_bytes() -> int | None:
    """Bytes this process has passed to write calls so far (None where /proc/self/io is missing)."""
    try:
        with open("/proc/self/io", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("wchar:"):
                    return int(line.split()[1])
    except OSError:
        return None
    return None


def synthetic_columns(n: int, rng: np.random.Generator) -> Columns:
    """Columns of ``n`` made-up runs (all successful), 1 to 3 stick phases each."""
    values = {}
    for name, _, dtype, _ in SUMMARY_COLUMNS:
        values[name] = rng.integers(0, 5, n).astype(dtype) if dtype is np.int64 else rng.random(n)
    count = rng.integers(1, 4, n).astype(np.int64)
    m = int(count.sum())
    return Columns(np.zeros(n, np.int8), rng.integers(1, 6, n).astype(np.int8), np.ones(n, np.int8), values, count,
                   rng.random(m), rng.random(m), rng.random(m))


def percentile(values, q):
    return float(np.percentile(values, q)) if values else math.nan


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1_000_000, help="atlas points (a square grid)")
    parser.add_argument("--chunk", type=int, default=4096, help="points per checkpoint (default: 4096)")
    parser.add_argument("--no-fsync", action="store_true", help="checkpoints without fsync after each step")
    parser.add_argument("--folder", default=None, help="where to write (default: a temporary folder)")
    args = parser.parse_args(argv)

    side = max(2, int(round(math.sqrt(args.points))))
    grid = Grid(seed_parameters(), ContactLaw("paper"), (Axis.make("kappa", np.geomspace(1e10, 1e14, side)),
                                                       Axis.make("v", np.linspace(0.5, 13.0, side))))
    rng = np.random.default_rng(1)
    emit(machine())
    emit(f"atlas {grid.shape[0]} x {grid.shape[1]} = {grid.size} points, checkpoint every {args.chunk} points, "
         f"fsync {'off' if args.no_fsync else 'on'}")

    with tempfile.TemporaryDirectory(dir=args.folder) as folder:
        path = os.path.join(folder, "atlas.h5")
        result = SweepResult(grid, None, {"rtol": 1e-10, "engine": "synthetic", "version": "benchmark"})
        checkpoint = archive.Checkpoint(path, fsync=not args.no_fsync)
        in_place, rewrite, written = [], [], []
        lock = exclusive(path)  # held for the whole atlas, as the command line does
        lock.__enter__()
        for lo in range(0, grid.size, args.chunk):
            idx = np.arange(lo, min(lo + args.chunk, grid.size))
            result.store(idx, synthetic_columns(idx.size, rng))
            rewrites, before = checkpoint.rewrites, written_bytes()
            start = time.perf_counter()
            checkpoint(result)
            elapsed = time.perf_counter() - start
            after = written_bytes()
            if checkpoint.rewrites > rewrites:
                rewrite.append(elapsed)
            else:
                in_place.append(elapsed)
                if before is not None and after is not None:
                    written.append(after - before)
        lock.__exit__(None, None, None)
        size = os.path.getsize(path)
        emit(f"file {size / 1e6:.1f} MB, {len(result.stick_point)} stick phases")
        emit(f"in place: {len(in_place)} checkpoints, median {1e3 * statistics.median(in_place):.1f} ms, "
             f"90th percentile {1e3 * percentile(in_place, 90):.1f} ms, largest {1e3 * max(in_place):.1f} ms")
        if written:
            emit(f"  bytes written per in-place checkpoint: median {statistics.median(written) / 1e6:.2f} MB "
                 f"(the new points' chunks), largest {max(written) / 1e6:.2f} MB")
        emit(f"whole rewrites: {len(rewrite)} ({', '.join(f'{1e3 * t:.0f} ms' for t in rewrite)})")
        saves = []
        for _ in range(3):
            start = time.perf_counter()
            archive.save(result, os.path.join(folder, "whole.h5"))
            saves.append(time.perf_counter() - start)
        whole = os.path.getsize(os.path.join(folder, "whole.h5"))
        emit(f"archive.save of the finished atlas (each checkpoint's cost before): median "
             f"{1e3 * statistics.median(saves):.0f} ms, {whole / 1e6:.1f} MB")
        start = time.perf_counter()
        back = archive.load(path)
        elapsed = time.perf_counter() - start
        same = all(np.array_equal(back.values[k], v) for k, v in result.values.items())
        emit(f"archive.load of the checkpointed atlas: {1e3 * elapsed:.0f} ms; the same as in memory: {same}")


if __name__ == "__main__":
    main()
