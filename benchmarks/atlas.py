"""A 1e6-point (kappa, v) atlas of ``paper``: time and peak memory, in Python and on the command line.

``atlas(seed_parameters(), "paper", {"kappa": geomspace(1e10, 1e15, 1000), "v": geomspace(0.3, 13,
1000)}, n_jobs=2)`` (threads), each run until its outcome settles. Memory: the growth of the
process's peak resident set (``resource.getrusage``) over the atlas, per point, against what the
result's own arrays hold (fixed columns per point, ragged stick points). Issue 9: a 1e6-point
sweep holds only its columns (about 200 bytes per point plus stick points); counted as met when
the fixed columns take at most 250 B/point and the peak grows by at most 1.5 times what the
result's arrays hold (plus 10 MB).

Then the same grid through ``phaseimpact atlas ... --jobs 2 --out FILE.h5 --no-progress`` (the
archive checkpointed after every chunk and rewritten at the end): its wall time and the whole
process's peak resident set (issue 13: <= 60 s and <= 500 MB; MB = 1e6 bytes here).

Not run with ``--quick`` (it takes minutes); ``--side`` sets the grid (default 1000 x 1000).

    python benchmarks/atlas.py [--side 1000] [--quick]
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import VENV_BIN, emit, load, machine, save_section, save_targets, table, target  # noqa: E402

from phaseimpact import seed_parameters  # noqa: E402
from phaseimpact.continuation import atlas  # noqa: E402


def peak_rss() -> int:
    """Peak resident set of this process, bytes (Linux reports kB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def array_bytes(result) -> tuple[int, int]:
    """(bytes of the per-point columns, bytes of the ragged stick-point arrays) of a result."""
    fixed = sum(a.nbytes for a in (result.status, result.outcome, result.stop_reason))
    fixed += sum(a.nbytes for a in result.values.values())
    ragged = sum(a.nbytes for a in (result.stick_point, result.stick_t, result.stick_delta, result.stick_dwell))
    for value in result.extras.values():
        if isinstance(value, np.ndarray):
            fixed += value.nbytes
    return fixed, ragged


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="skip (the atlas takes minutes)")
    ap.add_argument("--side", type=int, default=1000, help="points per axis")
    ap.add_argument("--rtol", type=float, default=1e-10, help="integrator tolerance (atlas default 1e-10)")
    args = ap.parse_args(argv)
    if args.quick:
        emit("atlas: not run with --quick (a 1e6-point atlas takes minutes); run `python benchmarks/atlas.py`")
        return 0
    start_load = load()
    n = args.side * args.side
    emit(f"# Atlas of paper: {args.side} x {args.side} = {n:.3g} points (kappa, v)\n")
    emit(machine())
    emit(start_load + "\n")
    params = seed_parameters()
    axes = {"kappa": np.geomspace(1e10, 1e15, args.side), "v": np.geomspace(0.3, 13.0, args.side)}
    atlas(params, "paper", {"kappa": axes["kappa"][::100], "v": axes["v"][::100]}, n_jobs=2, rtol=args.rtol)  # warm
    before = peak_rss()
    start = time.perf_counter()
    result = atlas(params, "paper", axes, n_jobs=2, rtol=args.rtol)
    wall = time.perf_counter() - start
    after = peak_rss()
    fixed, ragged = array_bytes(result)
    n_sticks = len(result.stick_t)
    outcomes, counts = np.unique(result.outcome_names(), return_counts=True)
    grown = after - before
    rows = [(f"{args.side} x {args.side}", f"{wall:.4g}", f"{n / wall:.4g}", f"{wall / n * 1e6:.3g}",
             f"{before / 1e6:.0f}", f"{after / 1e6:.0f}", f"{grown / n:.0f}", f"{fixed / n:.0f}",
             f"{n_sticks} ({ragged / n:.0f} B/point)", int(np.sum(result.failed)),
             ", ".join(f"{o} {c}" for o, c in zip(outcomes, counts, strict=True)))]
    del result
    with tempfile.TemporaryDirectory() as tmp:
        command = [str(VENV_BIN / "phaseimpact"), "atlas", "--law", "paper",
                   "--axis", f"kappa=1e10:1e15:{args.side}:log", "--axis", f"v=0.3:13:{args.side}:log",
                   "--rtol", f"{args.rtol:g}", "--jobs", "2", "--out", str(Path(tmp) / "atlas.h5"), "--no-progress"]
        start = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True)
        cli_wall = time.perf_counter() - start
        cli_bytes = (Path(tmp) / "atlas.h5").stat().st_size
    cli_rss = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024  # the largest child: this one
    cli_text = table(("command", "wall [s]", "peak RSS of the process [MB]", "archive [MB]"),
                     [(f"`phaseimpact atlas --law paper --axis kappa=1e10:1e15:{args.side}:log --axis "
                       f"v=0.3:13:{args.side}:log --jobs 2 --out X.h5 --no-progress`", f"{cli_wall:.3g}",
                       f"{cli_rss / 1e6:.0f}", f"{cli_bytes / 1e6:.0f}")])
    end_load = load()
    header = ("grid (kappa x v)", "time [s]", "points/s", "µs per point (2 threads)", "peak RSS before [MB]",
              "peak RSS after [MB]", "peak growth per point [B]", "fixed columns per point [B]",
              "stick points (ragged bytes)", "failed", "outcomes")
    text = table(header, rows) + "\n\nThe same grid on the command line (archive included):\n\n" + cli_text
    emit(text)
    emit(f"\nat the end: {end_load}")
    save_section("atlas", f"## Atlas of paper (kappa, v)\n\n{machine()}\n\n{start_load} at the start, {end_load} at "
                          f"the end.\n\n`atlas(seed_parameters(), 'paper', {{'kappa': geomspace(1e10, 1e15, "
                          f"{args.side}), 'v': geomspace(0.3, 13, {args.side})}}, n_jobs=2, "
                          f"rtol={args.rtol:g})`, each run until settled; "
                          "memory from `resource.getrusage` (peak RSS) around the call. "
                          "`python benchmarks/atlas.py`\n\n" + text)
    save_targets("atlas", [target(f"{n:.0e}-point atlas holds only its columns", "about 200 B/point plus stick points",
                                  f"peak growth {grown / n:.0f} B/point; columns {fixed / n:.0f} B/point + "
                                  f"{ragged / n:.0f} B/point of stick points; {wall:.0f} s",
                                  bool(fixed / n <= 250 and grown <= 1.5 * (fixed + ragged) + 10e6),
                                  "python benchmarks/atlas.py"),
                           target(f"{n:.0e}-point (kappa, v) atlas of paper on 2 cores (issue 13), rtol {args.rtol:g}",
                                  "<= 60 s", f"{wall:.0f} s", bool(wall <= 60), "python benchmarks/atlas.py"),
                           target("the same through `phaseimpact atlas` (issue 13), archive included",
                                  "<= 60 s and <= 500 MB", f"{cli_wall:.0f} s, peak RSS {cli_rss / 1e6:.0f} MB",
                                  bool(cli_wall <= 60 and cli_rss <= 500e6), "python benchmarks/atlas.py")])
    return 0


if __name__ == "__main__":
    sys.exit(main())
