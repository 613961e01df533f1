"""Locating kappa_c(paper, v = 1): ``critical_damping`` vs a user's brute-force grid.

Ours: ``critical_damping(seed_parameters(), "paper", bracket=(1e12, 2e12))`` (Brent on the first
stick's margin, rtol = 1e-6, confirmed at 1e-12). Brute force: a grid of N kappa values in
[1e12, 2e12], each integrated with the seed's RK4 (step 1e-7, every 10th step kept) and its
asymptotic points counted with ``find_asymptotic_points(tr, method="distance", tol=--tol)``
(default 1e-2: at 1e-3 the RK4 chatter makes 4-18 "points" and no 1 -> 2 change is found);
the bracket is the grid cell where the count first goes from 1 to 2.

    python benchmarks/critical.py [--quick] [--t-end 0.002]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import emit, machine, save_section, table  # noqa: E402

from phaseimpact.analysis import find_asymptotic_points  # noqa: E402
from phaseimpact.continuation import critical_damping  # noqa: E402
from phaseimpact.integrate import simulate  # noqa: E402
from phaseimpact.parameters import seed_parameters  # noqa: E402

LO, HI = 1e12, 2e12


def brute_force(n: int, t_end: float, step: float, tol: float):
    params = seed_parameters()
    kappas = np.linspace(LO, HI, n)
    counts = []
    start = time.perf_counter()
    for k in kappas:
        tr = simulate(params.replace(kappa=float(k)), "paper", t_end, integrator="rk4", step=step,
                      save="steps", every=10)
        counts.append(len(find_asymptotic_points(tr, method="distance", tol=tol)))
    wall = time.perf_counter() - start
    counts = np.array(counts)
    hits = np.flatnonzero((counts[:-1] == 1) & (counts[1:] >= 2))
    bracket = (float(kappas[hits[0]]), float(kappas[hits[0] + 1])) if hits.size else None
    return wall, bracket, counts


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="brute force with N = 20 only")
    ap.add_argument("--t-end", type=float, default=2e-3, help="horizon of the brute-force runs, s")
    ap.add_argument("--step", type=float, default=1e-7, help="RK4 step of the brute-force runs, s")
    ap.add_argument("--tol", type=float, default=1e-2,
                    help="distance tolerance (1e-3 counts RK4 chatter as many points: 4-18 on this grid)")
    args = ap.parse_args(argv)
    emit("# Critical damping kappa_c(paper, v = 1 m/s)\n")
    emit(machine() + "\n")
    start = time.perf_counter()
    cd = critical_damping(seed_parameters(), "paper", bracket=(LO, HI))
    wall = time.perf_counter() - start
    emit(f"critical_damping: kappa_c = {cd.kappa_c!r}, bracket = {cd.bracket}, status = {cd.status}, "
         f"shift = {cd.shift}, evaluations = {cd.evaluations}, {wall:.3f} s ({cd.message})")
    width = (cd.bracket[1] - cd.bracket[0]) / cd.kappa_c if cd.kappa_c else float("nan")
    kc = f"{cd.kappa_c:.9g}" if cd.kappa_c else "none"
    rows = [("critical_damping (exact, Brent)", "-", cd.evaluations, wall, kc,
             f"[{cd.bracket[0]:.9g}, {cd.bracket[1]:.9g}]", width, cd.status)]
    label = f"brute force RK4 step={args.step:g}, t_end={args.t_end:g}, distance tol={args.tol:g}"
    for n in ((20,) if args.quick else (20, 100)):
        bw, bracket, counts = brute_force(n, args.t_end, args.step, args.tol)
        emit(f"brute force N = {n}: {bw:.2f} s, counts = {counts.tolist()}")
        if bracket:
            mid = 0.5 * (bracket[0] + bracket[1])
            rows.append((label, n, n, bw,
                         f"{mid:.6g}", f"[{bracket[0]:.6g}, {bracket[1]:.6g}]", (bracket[1] - bracket[0]) / mid,
                         "found"))
        else:
            rows.append((label, n, n, bw, "none", "-", "-",
                         "no 1->2 change on the grid"))
    header = ("method", "grid N", "trajectories", "time [s]", "kappa_c", "bracket", "relative width", "status")
    text = table(header, rows)
    emit()
    emit(text)
    save_section("critical" + args.quick * "_quick",
                 f"## Critical damping kappa_c(paper, v = 1)\n\n{machine()}\n\n" + text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
