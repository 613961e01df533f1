"""What a summary run saves: save="summary" (stops once settled) vs save="steps" (full horizon).

Paper and hunt-crossley at kappa = 1e9, seed case, t_end = 0.01 and 0.1 s: time (median of
repeats) and tracemalloc peak of one ``simulate`` call each way, and the same for
``save="steps"`` stopped when settled (the steps alone, without the extra horizon).

    python benchmarks/scene_savings.py [--quick]
"""

from __future__ import annotations

import argparse
import sys
import tracemalloc
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import emit, load, machine, per_call, save_section, table  # noqa: E402

from phaseimpact import seed_parameters, simulate  # noqa: E402


def measure(params, law, t_end, **kw):
    tr = simulate(params, law, t_end, **kw)
    wall = per_call(lambda: simulate(params, law, t_end, **kw), repeats=5, min_time=0.02)
    tracemalloc.start()
    simulate(params, law, t_end, **kw)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return wall, peak, tr


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="t_end = 0.01 only")
    args = ap.parse_args(argv)
    start_load = load()
    emit("# Scene savings: summary vs steps\n")
    emit(machine())
    emit(start_load + "\n")
    params = seed_parameters(kappa=1e9)
    rows = []
    for law in ("paper", "hunt-crossley"):
        for t_end in ((0.01,) if args.quick else (0.01, 0.1)):
            ws, ps, ts = measure(params, law, t_end, save="summary")
            wu, pu, tu = measure(params, law, t_end, save="steps", stop_when_settled=True)
            wf, pf, tf = measure(params, law, t_end, save="steps", stop_when_settled=False)
            rows.append((law, t_end, f"{ws * 1e3:.3g}", f"{wu * 1e3:.3g}", f"{wf * 1e3:.3g}", f"{wf / ws:.3g}",
                         f"{ps / 1e3:.3g}", f"{pu / 1e3:.3g}", f"{pf / 1e3:.3g}", f"{pf / max(ps, 1):.3g}",
                         f"{ts.t_stop:.3g}", len(tu.t), len(tf.t), ts.nfev, tf.nfev,
                         f"{ts.status}/{tu.status}/{tf.status}"))
            emit(f"{law} t_end={t_end}: summary {ws * 1e3:.3g} ms {ps / 1e3:.3g} kB, steps until settled "
                 f"{wu * 1e3:.3g} ms {pu / 1e3:.3g} kB, steps to t_end {wf * 1e3:.3g} ms {pf / 1e3:.3g} kB")
    header = ("law", "t_end [s]", "summary [ms]", "steps, until settled [ms]", "steps, to t_end [ms]",
              "time ratio (to t_end / summary)", "summary peak [kB]", "steps until settled peak [kB]",
              "steps to t_end peak [kB]", "memory ratio", "summary t_stop [s]", "samples until settled",
              "samples to t_end", "summary nfev", "to t_end nfev", "status")
    text = table(header, rows)
    end_load = load()
    emit()
    emit(text)
    emit(f"\nat the end: {end_load}")
    save_section("scene_savings" + args.quick * "_quick",
                 f"## Scene savings (seed case, kappa = 1e9)\n\n{machine()}\n\n{start_load} at the start, {end_load} "
                 "at the end.\n\nsummary: save='summary' (stops once settled); steps: save='steps', until settled or "
                 "to t_end (stop_when_settled=False); time = median of 5; peak = tracemalloc peak of one more "
                 "identical call. `python benchmarks/scene_savings.py`\n\n" + text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
