"""Run every study: regenerate all figures, data archives and the claims table (``make reproduce``)."""

import argparse
import importlib.util
import sys
import time
from pathlib import Path

from tqdm import tqdm

HERE = Path(__file__).resolve().parent
STUDIES = (
    "fig02_03_abrate_displacements",
    "fig04_force_indentation",
    "fig06_08_damped",
    "fig09_10_phase_diagrams",
    "bifurcation",
    "critical_curve",
    "max_force_vs_kappa",
    "rk4_critical",
    "claims",
)


def load(name):
    spec = importlib.util.spec_from_file_location(name, HERE / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="fewer points, for a fast preview")
    parser.add_argument("--jobs", type=int, default=2, help="joblib workers for sweeps")
    args = parser.parse_args()
    sys.path.insert(0, str(HERE))
    start = time.perf_counter()
    bar = tqdm(STUDIES, desc="studies", unit="study")
    for name in bar:
        bar.set_postfix_str(name)
        t0 = time.perf_counter()
        out = load(name).main(quick=args.quick, jobs=args.jobs)
        tqdm.write(f"{name:32s} {time.perf_counter() - t0:6.1f} s  -> {Path(out).relative_to(HERE.parent)}")
    print(f"all studies done in {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
