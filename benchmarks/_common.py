"""Shared helpers for the benchmark scripts: machine and load, timing (medians), tables, targets.

The machine is shared and noisy (several processes may run tests at the same time): every
timing is a median of repeats, each script prints the load average when it starts and ends,
and no script asserts a timing. Each script keeps its markdown in ``results/<name>.md`` and its
measured numbers against issue 9's targets in ``results/<name>.json`` (collected by run_all).
"""

from __future__ import annotations

import json
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FIGURES = ROOT / "figures"
RESULTS = Path(__file__).resolve().parent / "results"
VENV_BIN = ROOT / ".venv" / "bin"


def machine() -> str:
    """One line describing the machine and the software."""
    import numba
    import numpy
    import scipy

    return (f"machine: {platform.platform()}, {platform.processor() or platform.machine()}, "
            f"os.cpu_count() = {os.cpu_count()}, Python {platform.python_version()}, "
            f"numpy {numpy.__version__}, scipy {scipy.__version__}, numba {numba.__version__}")


def load() -> str:
    """The load average (1, 5, 15 min): how busy the shared machine was."""
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} / {five:.2f} / {fifteen:.2f} (1 / 5 / 15 min)"


def timed(fn, repeats: int = 3, slow: float = 5.0):
    """Run ``fn`` up to ``repeats`` times; return (median wall time, last result).

    A run slower than ``slow`` seconds is not repeated.
    """
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
        if times[-1] > slow:
            break
    return statistics.median(times), result


def per_call(fn, repeats: int = 7, min_time: float = 0.05, max_number: int = 100_000) -> float:
    """Median over ``repeats`` of the mean time of one call (timeit-like), s.

    Each repeat calls ``fn`` ``number`` times, ``number`` chosen so one repeat lasts about
    ``min_time``; a warm-up call comes first.
    """
    start = time.perf_counter()
    fn()
    once = max(time.perf_counter() - start, 1e-7)
    number = int(min(max_number, max(1, min_time / once)))
    means = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(number):
            fn()
        means.append((time.perf_counter() - start) / number)
    return statistics.median(means)


def table(header, rows) -> str:
    """A markdown table."""
    out = ["| " + " | ".join(str(h) for h in header) + " |", "|" + "---|" * len(header)]
    for row in rows:
        out.append("| " + " | ".join(_fmt(x) for x in row) + " |")
    return "\n".join(out)


def _fmt(x) -> str:
    if isinstance(x, float):
        return f"{x:.3g}" if x == x else "nan"
    return str(x).replace("|", "\\|").replace("\n", "<br>")


def us(seconds: float) -> str:
    """Seconds as microseconds, 3 significant digits."""
    return f"{seconds * 1e6:.3g}"


def commit_of(tree) -> str:
    """The short commit of a checkout (``--against`` reports), and whether its package or benchmark
    scripts have changes not committed (what was timed is then not that commit)."""
    done = subprocess.run(["git", "-C", str(tree), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    changed = subprocess.run(["git", "-C", str(tree), "status", "--porcelain", "--", "phaseimpact",
                              ":(glob)benchmarks/*.py"], capture_output=True, text=True).stdout.strip()
    commit = done.stdout.strip() or "no git"
    return f"{commit} with changes not committed" if changed and done.stdout.strip() else commit


def save_section(name: str, text: str) -> None:
    """Keep a script's markdown output in ``benchmarks/results/<name>.md`` (collected by run_all)."""
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / f"{name}.md").write_text(text + "\n")


def target(what: str, limit: str, measured: str, met: bool | None, command: str) -> dict:
    """One line of the targets table: issue 9's number, what was measured, and how."""
    return {"what": what, "target": limit, "measured": measured, "met": met, "command": command}


def save_targets(name: str, rows: list[dict]) -> None:
    """Keep a script's measurements against the targets in ``results/<name>.json``."""
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / f"{name}.json").write_text(json.dumps({"load": load(), "targets": rows}, indent=1) + "\n")


def emit(text: str = "") -> None:
    print(text)
    sys.stdout.flush()
