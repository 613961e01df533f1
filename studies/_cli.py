"""Command-line wrapper shared by the study scripts (``--quick``, ``--jobs``, timing)."""

import argparse
import time


def run(main, doc: str) -> None:
    parser = argparse.ArgumentParser(description=doc)
    parser.add_argument("--quick", action="store_true", help="fewer points, for a fast preview")
    parser.add_argument("--jobs", type=int, default=1, help="joblib workers for sweeps")
    args = parser.parse_args()
    start = time.perf_counter()
    out = main(quick=args.quick, jobs=args.jobs)
    print(out, f"({time.perf_counter() - start:.1f} s)")
