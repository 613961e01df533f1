"""Command-line wrapper shared by the study scripts (``--quick``, ``--jobs``, timing).

Full runs write into ``figures/`` (committed); ``--quick`` previews go to ``figures/preview/``
(git-ignored), so a preview never replaces a committed figure, archive or table. Each figure is
written for print (PNG and a PDF beside it, checked for legibility: ``phaseimpact.plotting.for_print``).
Time stamps in the files come from ``SOURCE_DATE_EPOCH`` (the last commit's time when unset and in
a git checkout), so regenerating unchanged results leaves ``git status`` clean.
"""

import argparse
import os
import subprocess
import time
from pathlib import Path

from phaseimpact.plotting import for_print

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "figures"
PREVIEW = FIGURES / "preview"
#: Module globals through which the study scripts name their output folder.
OUTPUT_NAMES = ("FIGURES", "ROOT")


def output_folder(quick: bool) -> Path:
    return PREVIEW if quick else FIGURES


def redirect(namespace: dict, quick: bool) -> None:
    """Point a study's output folder (its ``FIGURES`` or ``ROOT`` global) at the preview folder."""
    if not quick:
        return
    for name in OUTPUT_NAMES:
        if name in namespace:
            namespace[name] = PREVIEW


def set_source_date_epoch() -> None:
    """Use the last commit's time for time stamps in archives unless ``SOURCE_DATE_EPOCH`` is set."""
    if os.environ.get("SOURCE_DATE_EPOCH"):
        return
    try:
        stamp = subprocess.run(["git", "log", "-1", "--format=%ct"], cwd=ROOT, capture_output=True, text=True,
                               timeout=30).stdout.strip()
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


def run(main, doc: str) -> None:
    args = parser(doc).parse_args()
    set_source_date_epoch()
    redirect(main.__globals__, args.quick)
    start = time.perf_counter()
    with for_print():
        out = main(quick=args.quick, jobs=args.jobs)
    print(out, f"({time.perf_counter() - start:.1f} s)")
