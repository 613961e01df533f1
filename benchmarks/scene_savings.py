"""What a summary run saves: save="summary" (stops once settled) vs save="steps" (full horizon).

Paper and hunt-crossley at kappa = 1e9, seed case, t_end = 0.01 and 0.1 s: wall time and
tracemalloc peak of one ``simulate`` call each way.

    python benchmarks/scene_savings.py [--quick]
"""

from __future__ import annotations

import argparse
import sys
import time
import tracemalloc
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import emit, machine, save_section, table  # noqa: E402

from phaseimpact.integrate import simulate  # noqa: E402
from phaseimpact.parameters import seed_parameters  # noqa: E402


def measure(params, law, t_end, **kw):
    start = time.perf_counter()
    tr = simulate(params, law, t_end, **kw)
    wall = time.perf_counter() - start
    tracemalloc.start()
    simulate(params, law, t_end, **kw)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return wall, peak, tr


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="t_end = 0.01 only")
    args = ap.parse_args(argv)
    emit("# Scene savings: summary vs steps\n")
    emit(machine() + "\n")
    params = seed_parameters(kappa=1e9)
    rows = []
    for law in ("paper", "hunt-crossley"):
        for t_end in ((0.01,) if args.quick else (0.01, 0.1)):
            ws, ps, ts = measure(params, law, t_end, save="summary")
            wf, pf, tf = measure(params, law, t_end, save="steps", stop_when_settled=False)
            rows.append((law, t_end, ws, wf, wf / ws, ps / 1e6, pf / 1e6, pf / max(ps, 1), f"{ts.t_stop:.3g}",
                         len(tf.t), ts.nfev, tf.nfev, f"{ts.status}/{tf.status}"))
            emit(f"{law} t_end={t_end}: summary {ws:.3f} s {ps / 1e6:.2f} MB, steps {wf:.3f} s {pf / 1e6:.2f} MB")
    header = ("law", "t_end [s]", "summary time [s]", "steps time [s]", "time ratio", "summary peak [MB]",
              "steps peak [MB]", "memory ratio", "summary t_stop [s]", "steps samples", "summary nfev",
              "steps nfev", "status")
    text = table(header, rows)
    emit()
    emit(text)
    save_section("scene_savings" + args.quick * "_quick",
                 f"## Scene savings (seed case, kappa = 1e9)\n\n{machine()}\n\n"
                 "summary: save='summary' (stops once settled); steps: save='steps', stop_when_settled=False; "
                 "peak = tracemalloc peak of a second identical call.\n\n" + text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
