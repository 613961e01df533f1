"""Helpers shared by the study scripts: labels, the two readings of eq. 8, fits and archiving.

General figure style and the PNG/HDF5 writers live in :mod:`phaseimpact.plotting`; what is only
needed by the studies lives here.
"""

from __future__ import annotations

import contextlib
import math
import os
import subprocess
from pathlib import Path

import numpy as np

from phaseimpact import ContactLaw, archive
from phaseimpact.continuation import stick_sequence_violation

ROOT = Path(__file__).resolve().parents[1]

KAPPA_LABEL = "damping κ (N s/m$^{2.5}$)"
V_LABEL = "impact speed v (m/s)"
#: The two readings of eq. 8 (REFERENCE §3): printed |delta| (acts in tension too) and unilateral.
READINGS = {"printed": ContactLaw("paper"), "unilateral": ContactLaw("paper", contact="unilateral")}
READING_TEXT = {"printed": "paper, printed reading (acts in tension)",
                "unilateral": "paper, unilateral reading (P = 0 for δ ≤ 0)"}
#: Tolerances for counting stick phases near kappa_c: tighter than the default rtol (1e-10), which
#: counts right too (tests/test_counts.py), and the case's own absolute tolerances (None): a slip's
#: relative speed has a tolerance of its own (docs/physics.md §3), and an absurdly small atol only
#: brings rounding into it (an atol of 1e-22 moved the first slip's stick offset at kappa_c (1 + 1e-7)
#: by a factor 3).
COUNT_RTOL = 1e-12
COUNT_ATOL = None


def claim(doc: str) -> str:
    """The study's docstring as one attribute string."""
    return " ".join(doc.split())


#: Significant digits fitted and derived quantities are kept to: far more than a fit over measured
#: points knows, and few enough that a last-bit difference of ``log`` or a sum (another CPU, another
#: BLAS) does not change what is stored, so ``make reproduce`` leaves the committed files alone.
FIT_DIGITS = 10


def known(value: float, digits: int = FIT_DIGITS) -> float:
    """``value`` rounded to ``digits`` significant digits (NaN and infinities as they are)."""
    value = float(value)
    return float(f"{value:.{digits - 1}e}") if math.isfinite(value) else value


def loglog_fit(x, y) -> tuple[float, float]:
    """Slope and intercept of ``log y`` against ``log x`` (finite, positive points only), least squares,
    each to :data:`FIT_DIGITS` significant digits.

    The sums are exact (``math.fsum``) rather than BLAS's, whose last bits depend on the CPU and the
    number of threads; the rounding absorbs what ``log`` may still differ by.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    if ok.sum() < 2:  # e.g. a quick preview without points in the fit range
        return float("nan"), float("nan")
    lx, ly = np.log(x[ok]), np.log(y[ok])
    n = len(lx)
    dx, dy = lx - math.fsum(lx) / n, ly - math.fsum(ly) / n
    slope = math.fsum(dx * dy) / math.fsum(dx * dx)
    intercept = math.fsum(ly) / n - slope * (math.fsum(lx) / n)
    return known(slope), known(intercept)


def code_epoch() -> str | None:
    """Commit time of the last change to ``studies/`` (the scripts that define the figures).

    Archives written by :func:`save_archive` carry it as their ``created`` time, so neither
    committing regenerated figures nor a library commit that leaves the results alone changes
    what the next ``make reproduce`` writes (the archives also record the package version).
    """
    try:
        out = subprocess.run(["git", "log", "-1", "--format=%ct", "--", "studies"],
                             cwd=ROOT, capture_output=True, text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return out if out.isdigit() else None


@contextlib.contextmanager
def _epoch(value: str | None):
    old = os.environ.get("SOURCE_DATE_EPOCH")
    if value is not None:
        os.environ["SOURCE_DATE_EPOCH"] = value
    try:
        yield
    finally:
        if old is None:
            os.environ.pop("SOURCE_DATE_EPOCH", None)
        else:
            os.environ["SOURCE_DATE_EPOCH"] = old


def save_archive(result, path) -> str:
    """:func:`phaseimpact.archive.save` (schema 2, ``archive.load`` reads it back) with a stable time stamp."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with _epoch(code_epoch()):
        return archive.save(result, path, force=True)


def kappa_axis(ax, which="x"):
    """Label a damping axis (log scale)."""
    if which == "x":
        ax.set_xscale("log")
        ax.set_xlabel(KAPPA_LABEL)
    else:
        ax.set_yscale("log")
        ax.set_ylabel(KAPPA_LABEL)


def outcome_of(trajectory) -> str:
    """How a run of ``paper`` ended, in words for a legend or title."""
    if trajectory.outcome == "permanent-stick":
        return "permanent stick"
    if trajectory.stop_reason == "runaway":
        return "escape, then runaway (energy doubled)"
    if trajectory.outcome == "ratchet-escape":
        e = trajectory.restitution
        return f"escape, then separation (e = {e:.3g})" if e is not None else "escape, then separation"
    return trajectory.outcome


def missed_restick(trajectory, rtol: float = COUNT_RTOL) -> bool:
    """Whether the engine visibly missed a re-stick of ``paper`` (a library defect): the run, made at
    ``rtol``, breaks an invariant of eq. 8 beyond what it resolves
    (:func:`phaseimpact.continuation.stick_sequence_violation`)."""
    return stick_sequence_violation(trajectory, rtol) is not None


def log_ticks(axis, ticks) -> None:
    """Plain-number major ticks on a log axis (``ax.xaxis`` or ``ax.yaxis``), no minor labels."""
    from matplotlib.ticker import FixedLocator, NullFormatter, ScalarFormatter

    axis.set_major_locator(FixedLocator(ticks))
    formatter = ScalarFormatter()
    formatter.set_scientific(False)
    axis.set_major_formatter(formatter)
    axis.set_minor_formatter(NullFormatter())
