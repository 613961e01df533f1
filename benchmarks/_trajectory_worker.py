"""A worker process of ``trajectory.py --against``, run with another checkout first on ``PYTHONPATH``.

It imports that checkout's package and its own ``benchmarks/trajectory.py`` (its cases, tolerance,
driver arguments and compiled loop: the driver's signature changes between commits, older ones
took two dozen positional arguments), prints its tree and the results' bits, then for each line
``go`` on stdin the CPU time of one call of ``simulate``, of the compiled loop and of ``simulate`` on a
new case each call (``params.replace``) in each case (each the mean of a batch of calls lasting
about 20 ms). Only the public ``seed_parameters``, ``Parameters.replace`` and ``simulate`` are used
from the package itself, so any commit with the benchmark can be timed.
"""

from __future__ import annotations

import importlib.util
import itertools
import json
import sys
import time
from pathlib import Path

import numpy as np


def _tree_benchmark(root: Path):
    path = root / "benchmarks" / "trajectory.py"
    spec = importlib.util.spec_from_file_location("tree_trajectory_benchmark", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _batch(fn):
    def many(n):
        for _ in range(n):
            fn()
    return many


def main() -> int:
    import phaseimpact
    from phaseimpact import seed_parameters, simulate

    root = Path(phaseimpact.__file__).resolve().parent.parent
    bench = _tree_benchmark(root)
    timers, bits = [], []
    for case in bench.CASES:
        _label, kappa, law, t_end, stop_on = case[:5]
        params = seed_parameters(v=1.0, kappa=kappa)
        args_ = bench.driver_args(params, law, t_end, bench.RTOL, stop_on)

        def call(params=params, law=law, t_end=t_end, stop_on=stop_on):
            return simulate(params, law, t_end, rtol=bench.RTOL, stop_on=stop_on)

        tr = call()
        # quantities every version has (the summary's columns changed between commits)
        bits.append([float(x).hex() for x in np.concatenate([[tr.max_force, tr.t_stop], tr.final_state])])
        kappas = itertools.cycle(params.kappa * (1 + 1e-12 * np.arange(4096)))

        def new_case(params=params, law=law, t_end=t_end, stop_on=stop_on, kappas=kappas):
            # a new case per call, as a loop over kappa makes them: nothing of the case is cached
            return simulate(params.replace(kappa=float(next(kappas))), law, t_end, rtol=bench.RTOL, stop_on=stop_on)

        for fn in (_batch(call), lambda n, a=args_: bench._loop(n, *a), _batch(new_case)):
            fn(10)
            start = time.perf_counter()
            fn(10)
            timers.append((fn, max(10, int(0.02 / max((time.perf_counter() - start) / 10, 1e-7)))))
    print(json.dumps({"tree": str(root), "cases": [c[0] for c in bench.CASES], "bits": bits}), flush=True)
    for line in sys.stdin:
        if line.strip() != "go":
            break
        times = []
        for fn, n in timers:
            # the thread's CPU time: on a loaded machine the wall time also counts the turns of other
            # processes, which the alternation evens out only on average
            start = time.thread_time()
            fn(n)
            times.append((time.thread_time() - start) / n)
        print(json.dumps(times), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
