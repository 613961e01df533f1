"""Run every study: regenerate all figures, data archives and the claims table (``make reproduce``).

Full runs write into ``figures/``; ``--quick`` previews into ``figures/preview/`` (git-ignored). A
regenerated file replaces the one there only when it differs beyond the tolerance of ``_settle.py``
(stated in README.md): each study's line, and the last, name the files that did.
"""

import importlib.util
import sys
import time
from pathlib import Path

from tqdm import tqdm

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import _cli  # noqa: E402

STUDIES = (
    "fig02_03_abrate_displacements",
    "fig04_force_indentation",
    "fig06_08_damped",
    "fig09_10_phase_diagrams",
    "bifurcation",
    "staircase",
    "critical_curve",
    "atlas_paper",
    "critical_surface",
    "grazing",
    "erosion",
    "plastic",
    "impact_regime",
    "zener_restitution",
    "train",
    "train_bifurcations",
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
    _cli.on_numpy_baseline()
    args = _cli.parser(__doc__.splitlines()[0], default_jobs=2).parse_args()
    _cli.set_source_date_epoch()
    folder = _cli.output_folder(args.quick)
    print(f"writing {'previews' if args.quick else 'figures'} to {folder.relative_to(HERE.parent)}/", flush=True)
    start = time.perf_counter()
    replaced = []
    bar = tqdm(STUDIES, desc="studies", unit="study", disable=not sys.stderr.isatty())  # no bar in a log
    for name in bar:
        bar.set_postfix_str(name)
        t0 = time.perf_counter()
        module = load(name)
        out, changed = _cli.run_study(module.main, vars(module), args.quick, args.jobs)
        replaced.extend(changed)
        tqdm.write(f"{name:32s} {time.perf_counter() - t0:6.1f} s  -> {out.relative_to(HERE.parent)}: "
                   f"{_cli.report(changed)}")
    print(f"all studies done in {time.perf_counter() - start:.1f} s; {_cli.report(replaced)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
