"""Command-line wrapper shared by the study scripts (``--quick``, ``--jobs``, timing).

Full runs write into ``figures/`` (committed); ``--quick`` previews go to ``figures/preview/``
(git-ignored), so a preview never replaces a committed figure, archive or table. Each figure is
written for print (PNG and a PDF beside it, checked for legibility: ``phaseimpact.plotting.for_print``).
Time stamps in the files come from ``SOURCE_DATE_EPOCH`` (the last commit's time when unset and in
a git checkout), and a regenerated file replaces the one there only when it differs beyond the
tolerance of :mod:`_settle`, so regenerating unchanged results leaves ``git status`` clean, also on
another machine whose libraries change the last bits.
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _settle import settle

from phaseimpact.plotting import for_print

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "figures"
PREVIEW = FIGURES / "preview"
#: Module globals through which the study scripts name their output folder.
OUTPUT_NAMES = ("FIGURES", "ROOT")


def output_folder(quick: bool) -> Path:
    return PREVIEW if quick else FIGURES


def redirect(namespace: dict, folder: Path) -> None:
    """Point a study's output folder (its ``FIGURES`` or ``ROOT`` global) at ``folder``."""
    for name in OUTPUT_NAMES:
        if name in namespace:
            namespace[name] = folder


def run_study(main, namespace: dict, quick: bool, jobs: int) -> tuple[Path, list[str]]:
    """Run a study's ``main`` into a staging folder, then move into the output folder only the files that
    differ from those there beyond the tolerance of :mod:`_settle` (README.md, "Reproducing").

    Returns the file ``main`` names, in the output folder, and the files replaced (relative to it).
    """
    folder = output_folder(quick)
    PREVIEW.mkdir(parents=True, exist_ok=True)  # git-ignored, so an interrupted run leaves git clean
    staging = Path(tempfile.mkdtemp(prefix=".staging-", dir=PREVIEW))
    try:
        redirect(namespace, staging)
        with for_print():
            out = Path(main(quick=quick, jobs=jobs))
        changed = settle(staging, folder)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return (folder / out.relative_to(staging) if out.is_relative_to(staging) else out), changed


def report(changed: list[str]) -> str:
    """What :func:`run_study` replaced, in words."""
    if not changed:
        return "no file changed beyond the tolerance"
    return f"{len(changed)} file(s) changed beyond the tolerance: " + ", ".join(changed)


def set_source_date_epoch() -> None:
    """Use the time of the last commit of the code (``phaseimpact/``, ``studies/``) for time stamps in
    archives unless ``SOURCE_DATE_EPOCH`` is set; outside a git checkout leave it unset (an empty value
    means unset: phaseimpact removes it on import)."""
    if os.environ.get("SOURCE_DATE_EPOCH", "").strip():
        return
    try:
        stamp = subprocess.run(["git", "log", "-1", "--format=%ct", "--", "phaseimpact", "studies"], cwd=ROOT,
                               capture_output=True, text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return
    if stamp.isdigit():
        os.environ["SOURCE_DATE_EPOCH"] = stamp


def jobs(text: str) -> int:
    limit = 4 * (os.cpu_count() or 1)
    try:
        value = int(text)
    except ValueError:
        value = 0
    if not (value == -1 or 1 <= value <= limit):
        raise argparse.ArgumentTypeError(f"jobs = {text!r} is out of range; allowed: an integer 1..{limit}, or -1")
    return value


def parser(doc: str, default_jobs: int = 1) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=doc)
    p.add_argument("--quick", action="store_true",
                   help=f"fewer points, for a fast preview, written to {PREVIEW.relative_to(ROOT)}/ (default: off)")
    p.add_argument("--jobs", type=jobs, default=default_jobs,
                   help="parallel workers for sweeps, or -1 for all cores (default: %(default)s)")
    return p


#: Set in the environment of a study process re-executed on numpy's baseline code (:func:`on_numpy_baseline`).
BASELINE_VARIABLE = "PHASEIMPACT_STUDIES_NUMPY_BASELINE"


def on_numpy_baseline() -> None:
    """Run this study process on numpy's baseline SIMD code, re-executing it once with
    ``NPY_DISABLE_CPU_FEATURES`` naming the dispatched features this CPU has (numpy's documented
    switch; it must be set before numpy is imported, hence the re-execution).

    numpy picks its SIMD code per CPU, and its power and log give different last bits with AVX-512
    than without: on an AVX-512 machine ``np.geomspace(1e10, 1e15, 70)``, atlas_paper's kappa axis,
    differed from the committed archive's by one ulp at 5 of the 70 points, and the step counts and
    stick times computed from them moved beyond the tolerance in four archives. On the baseline
    code they were the committed numbers exactly."""
    if os.environ.get(BASELINE_VARIABLE) == "1":
        return
    import numpy as np

    try:
        found = np.show_config(mode="dicts")["SIMD Extensions"]["found"]
    except (TypeError, KeyError):  # a numpy without the report (before 1.25): run as it is
        return
    if not found:  # the baseline code already
        return
    env = dict(os.environ, **{BASELINE_VARIABLE: "1", "NPY_DISABLE_CPU_FEATURES": " ".join(found)})
    sys.stdout.flush()
    os.execve(sys.executable, [sys.executable, *sys.argv], env)


def run(main, doc: str) -> None:
    on_numpy_baseline()
    args = parser(doc).parse_args()
    set_source_date_epoch()
    start = time.perf_counter()
    out, changed = run_study(main, main.__globals__, args.quick, args.jobs)
    print(out, f"({time.perf_counter() - start:.1f} s): {report(changed)}")
