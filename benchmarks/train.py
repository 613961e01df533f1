"""Trains of impacts: one evaluation of the impact map, and an orbit diagram (issue 26's numbers).

The seed plate, Hunt-Crossley contact (kappa = 3e9, 1 m/s), one projectile every 3 ms (three plate
periods): the median time of one map evaluation (a 200-impact train divided by 200: the engine's
run over the period plus its Python layer) next to the same map integrated by the scipy oracle
(``phaseimpact/_oracle.py``, ``solve_ivp`` DOP853 with the same events), with the two maps' difference
after one impact; then an orbit diagram over T (values x impacts, threads), timed at a size this
machine runs in seconds and extrapolated linearly in values x impacts to issue 26's 1000 x 500;
with ``--full``, the 1000 x 500 diagram itself on 2 threads (about a minute).

    python benchmarks/train.py [--quick | --full]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import emit, load, machine, save_section, save_targets, table, target  # noqa: E402

from phaseimpact import seed_parameters  # noqa: E402
from phaseimpact._oracle import oracle  # noqa: E402
from phaseimpact.train import impact_map, impact_train, orbit_diagram  # noqa: E402

PERIOD = 3e-3


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="3 repeats and a smaller diagram")
    ap.add_argument("--full", action="store_true", help="also the whole 1000 x 500 diagram on 2 threads")
    args = ap.parse_args(argv)
    repeats = 3 if args.quick else 7
    p = seed_parameters(v=1.0, kappa=3e9)
    emit(machine())
    emit(load())
    impact_train(p, "hunt-crossley", PERIOD, 5)  # compile or load the engine
    per_map = []
    for _ in range(repeats):
        start = time.perf_counter()
        impact_train(p, "hunt-crossley", PERIOD, 200)
        per_map.append((time.perf_counter() - start) / 200)
    ours = statistics.median(per_map)
    plate = impact_train(p, "hunt-crossley", PERIOD, 20).plate[-1]
    start = time.perf_counter()
    ref = oracle(p, "hunt-crossley", PERIOD, rtol=1e-12, settle=False,
                 initial=(plate[0], plate[0], p.v, plate[1]))
    scipy_time = time.perf_counter() - start
    mine, _ = impact_map(p, "hunt-crossley", PERIOD, plate, rtol=1e-10)
    scale = np.array([p.hertz_indentation, p.v])
    difference = float(np.max(np.abs(mine - ref.final_state[[1, 3]]) / scale))

    values, impacts = (40, 60) if args.quick else (100, 100)
    rows = []
    for jobs in (1, 2):
        start = time.perf_counter()
        orbit_diagram(p, "hunt-crossley", "T", np.linspace(5e-4, 4e-3, values), transients=impacts // 2,
                      samples=impacts - impacts // 2, n_jobs=jobs)
        seconds = time.perf_counter() - start
        rows.append((jobs, values, impacts, seconds, seconds * (1000 * 500) / (values * impacts)))
    full = None
    if args.full:
        start = time.perf_counter()
        orbit_diagram(p, "hunt-crossley", "T", np.linspace(5e-4, 4e-3, 1000), transients=250, samples=250, n_jobs=2)
        full = time.perf_counter() - start
        rows.append((2, 1000, 500, full, full))
    text = "\n".join([
        "## Trains of impacts (impact map)", "", machine(), "", load(), "",
        table(["what", "ours", "scipy oracle (same events)", "ratio"],
              [("one map evaluation (µs)", ours * 1e6, scipy_time * 1e6, scipy_time / ours)]),
        "", f"difference of the two maps after one impact: {difference:.2g} of the state's scales "
            "(ours at rtol 1e-10, the oracle at 1e-12)", "",
        table(["threads", "values", "impacts each", "time (s)", "extrapolated to 1000 x 500 (s)"], rows),
    ])
    emit(text)
    save_section("train" + args.quick * "_quick", text)
    command = "python benchmarks/train.py" + args.full * " --full"
    best = full if full is not None else min(r[4] for r in rows)
    how = "measured" if full is not None else "extrapolated"
    save_targets("train" + args.quick * "_quick", [
        target("impact-map evaluation, one core", "<= 100 µs", f"{ours * 1e6:.3g} µs", ours <= 1e-4, command),
        target("orbit diagram 1000 x 500, 2 cores", "<= 60 s", f"{best:.3g} s ({how})", best <= 60, command),
    ])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
