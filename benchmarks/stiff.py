"""Stiff creeps: DOP853 throughout against DOP853 with Radau IIA for stiff stretches, run time
against error, over random points of the atlas's (kappa, v) grid.

Far above kappa_c the inward slip of ``paper`` is a creep held by the damper (damping rate of the
relative motion up to ~1e7 /s): DOP853 is held at its stability limit there whatever the
tolerance. Both methods run the same points at several ``rtol``; errors are against DOP853 at rtol
1e-13 (a reference from the other method: Radau's own estimate plays no part in it). Times are
medians of 3 runs of the whole batch in one thread (`_common.timed`).

    python benchmarks/stiff.py [--quick]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import emit, load, machine, save_section, save_targets, table, timed  # noqa: E402

from phaseimpact import seed_parameters  # noqa: E402
from phaseimpact.integrate.batch import pack_batch, run_batch  # noqa: E402

COLUMNS = ("t_run", "max_force", "dissipated_energy", "first_stick_delta")
RTOLS = (1e-8, 1e-9, 1e-10, 1e-11)


def points(n: int):
    """``n`` random points of the atlas benchmark's 1000 x 1000 grid (fixed seed)."""
    rng = np.random.default_rng(1)
    kappa, v = np.geomspace(1e10, 1e15, 1000), np.geomspace(0.3, 13.0, 1000)
    base = seed_parameters()
    return [base.replace(kappa=float(kappa[i]), v=float(v[j]))
            for i, j in zip(rng.integers(0, 1000, n), rng.integers(0, 1000, n), strict=True)]


def errors(result, ref) -> dict:
    """Largest and median relative error of each column and of the stick depths."""
    out = {}
    for name in COLUMNS:
        a, b = result.values[name], ref.values[name]
        ok = np.isfinite(b) & (b != 0)
        e = np.abs(a[ok] / b[ok] - 1)
        out[name] = (float(e.max()), float(np.median(e)))
    if len(result.stick_delta) == len(ref.stick_delta):
        e = np.abs(result.stick_delta / ref.stick_delta - 1)
        out["stick depths"] = (float(e.max()), float(np.median(e)))
    else:
        out["stick depths"] = (float("nan"), float("nan"))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="500 points instead of 3000")
    args = ap.parse_args(argv)
    n = 500 if args.quick else 3000
    start_load = load()
    emit(f"# Stiff creeps: {n} random (kappa, v) points of paper's atlas grid\n")
    emit(machine())
    params = points(n)
    reference = run_batch(pack_batch(params, "paper", None, 1e-13), rtol=1e-13, stiff=False, n_threads=2)
    rows, summary = [], {}
    for rtol in RTOLS:
        batch = pack_batch(params, "paper", None, rtol)
        for stiff in (False, True):
            run_batch(batch, rtol=rtol, stiff=stiff)  # warm
            wall, result = timed(lambda b=batch, r=rtol, st=stiff: run_batch(b, rtol=r, stiff=st), repeats=3, slow=1e9)
            per_point = wall / n
            err = errors(result, reference)
            mismatches = int(np.sum(result.outcome != reference.outcome) + np.sum(result.n_stick != reference.n_stick))
            method = "DOP853 + Radau IIA" if stiff else "DOP853 throughout"
            summary[(rtol, stiff)] = per_point
            rows.append((f"{rtol:.0e}", method, f"{per_point * 1e6:.0f}", f"{result.values['nsteps'].mean():.0f}",
                         f"{result.values['nfev'].mean():.0f}", mismatches,
                         *(f"{err[k][0]:.1e} / {err[k][1]:.0e}" for k in (*COLUMNS, "stick depths"))))
            emit(" | ".join(str(x) for x in rows[-1]))
    header = ("rtol", "method", "µs per point (1 thread)", "steps (mean)", "evaluations (mean)",
              "class or count differs", *(f"{c}: max / median rel. error" for c in COLUMNS),
              "stick depths: max / median")
    text = table(header, rows)
    ratios = ", ".join(f"{summary[(r, False)] / summary[(r, True)]:.2f}x at {r:.0e}" for r in RTOLS)
    end_load = load()
    emit("\n" + text + f"\n\nDOP853 throughout / with Radau: {ratios}")
    name = "stiff" + args.quick * "_quick"
    save_section(name, f"## Stiff creeps (DOP853 against DOP853 + Radau IIA)\n\n{machine()}\n\n{start_load} at the "
                          f"start, {end_load} at the end.\n\n{n} random points of the atlas benchmark's grid "
                          "(kappa 1e10-1e15, v 0.3-13 m/s, log-spaced 1000 x 1000), each run until settled; errors "
                          "against DOP853 at rtol 1e-13; times are medians of 3 runs of the batch in one thread. "
                          f"`python benchmarks/stiff.py`\n\n{text}\n\nTime of DOP853 throughout over DOP853 + Radau "
                          f"IIA: {ratios}.")
    save_targets(name, [])
    return 0


if __name__ == "__main__":
    sys.exit(main())
