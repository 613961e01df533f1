"""Shared helpers for the benchmark scripts (machine info, timing, markdown tables)."""

from __future__ import annotations

import os
import platform
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FIGURES = ROOT / "figures"
RESULTS = Path(__file__).resolve().parent / "results"


def machine() -> str:
    """One line describing the machine and the software."""
    import numpy
    import scipy

    return (f"machine: {platform.platform()}, {platform.processor() or platform.machine()}, "
            f"os.cpu_count() = {os.cpu_count()}, Python {platform.python_version()}, "
            f"numpy {numpy.__version__}, scipy {scipy.__version__}")


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


def save_section(name: str, text: str) -> None:
    """Keep a script's markdown output in ``benchmarks/results/<name>.md`` (collected by run_all)."""
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / f"{name}.md").write_text(text + "\n")


def emit(text: str = "") -> None:
    print(text)
    sys.stdout.flush()
