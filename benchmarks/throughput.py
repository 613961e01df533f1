"""Sweep throughput: ``sweep`` (n_jobs = 1, 2) vs a user's loop of ``solve_ivp``.

Paper law, seed case, N kappa values log-spaced in [1e9, 1e14], t_end = 0.01 s. The user's loop:
``solve_ivp(DOP853)`` on the plain right-hand side ``rhs(y, c, law)``, rtol = 1e-10 (atol scaled
like ours), max force from the accepted steps refined on the dense output around the largest
one (so it can agree with ours to ~1e-6). The loop is timed on a random subset of points
(``--subset``) and its full time extrapolated; each solve_ivp run is abandoned after
``--cap`` seconds (the plain RHS of ``paper`` chatters across deltadot = 0 once stuck), which
makes the extrapolated loop time a lower bound.

    python benchmarks/throughput.py [--quick] [--n 2000] [--subset 50] [--cap 10]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import emit, machine, save_section, table  # noqa: E402

import phaseimpact.integrate as integrate  # noqa: E402
from phaseimpact.continuation import sweep  # noqa: E402
from phaseimpact.integrate._trajectory import state_scale  # noqa: E402
from phaseimpact.model import as_law, coefficients, contact_force, initial_state, rhs  # noqa: E402
from phaseimpact.parameters import seed_parameters  # noqa: E402

T_END = 0.01
LAW = "paper"


class _Timeout(Exception):
    pass


def user_point(params, law, rtol, cap):
    """One point of the user's loop: (max force, finished?)."""
    law = as_law(law)
    c = coefficients(params, law)
    deadline = time.perf_counter() + cap
    best = [0.0]

    def f(t, y):
        if time.perf_counter() > deadline:
            raise _Timeout
        return rhs(y, c, law)

    try:
        sol = solve_ivp(f, (0.0, T_END), initial_state(params.v), method="DOP853", rtol=rtol,
                        atol=rtol * state_scale(params, c), dense_output=True)
    except _Timeout:
        return best[0], False
    force = contact_force(sol.y.T, c, law)
    i = int(np.argmax(force))
    lo, hi = sol.t[max(i - 1, 0)], sol.t[min(i + 1, len(sol.t) - 1)]
    if hi > lo:
        res = minimize_scalar(lambda t: -float(contact_force(sol.sol(t), c, law)), bounds=(lo, hi),
                              method="bounded", options={"xatol": 1e-14 * max(hi, 1e-9)})
        return max(float(force[i]), -res.fun), True
    return float(force[i]), True


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="N = 100, subset 10, cap 3 s")
    ap.add_argument("--n", type=int, default=None)
    ap.add_argument("--subset", type=int, default=None)
    ap.add_argument("--cap", type=float, default=None)
    ap.add_argument("--rtol", type=float, default=1e-10, help="rtol of the user's solve_ivp loop")
    ap.add_argument("--law", default=LAW, help="contact law (default paper)")
    args = ap.parse_args(argv)
    n = args.n or (100 if args.quick else 2000)
    subset = args.subset or (10 if args.quick else 50)
    cap = args.cap or (3.0 if args.quick else 10.0)
    law = args.law
    emit(f"# Sweep throughput ({law}, N = {n}, kappa in [1e9, 1e14], t_end = {T_END:g} s)\n")
    emit(machine() + "\n")
    params = seed_parameters()
    kappas = np.logspace(9, 14, n)
    rows, results = [], {}
    for jobs in (1, 2):
        start = time.perf_counter()
        res = sweep(params, law, kappas, t_end=T_END, n_jobs=jobs)
        wall = time.perf_counter() - start
        results[jobs] = (wall, res)
        kinds, counts = np.unique(res.status, return_counts=True)
        emit(f"sweep n_jobs={jobs}: {wall:.2f} s, statuses {dict(zip(kinds, counts.tolist(), strict=True))}")
    if hasattr(integrate, "simulate_batch"):
        start = time.perf_counter()
        batch = integrate.simulate_batch([params.replace(kappa=float(k)) for k in kappas], law, T_END, rtol=1e-10)
        results["batch"] = (time.perf_counter() - start, np.array([tr.max_force for tr in batch]))
        emit(f"simulate_batch: {results['batch'][0]:.2f} s")
    else:
        emit("simulate_batch not available (placeholder row)")
    rng = np.random.default_rng(0)
    pick = np.sort(rng.choice(n, size=min(subset, n), replace=False))
    times, forces, finished = [], [], []
    for idx in pick:
        start = time.perf_counter()
        fmax, ok = user_point(params.replace(kappa=float(kappas[idx])), law, args.rtol, cap)
        times.append(time.perf_counter() - start)
        forces.append(fmax)
        finished.append(ok)
    times, forces, finished = np.array(times), np.array(forces), np.array(finished)
    loop_time = float(np.mean(times) * n)
    # A runaway's largest force is wherever its run stopped, not an impact force: left out.
    ref = np.where(results[1][1].outcome == "runaway", np.nan, results[1][1].max_force)
    finished &= np.isfinite(ref[pick])
    disagree = np.abs(forces[finished] - ref[pick][finished]) / np.abs(ref[pick][finished])
    worst = float(np.max(disagree)) if disagree.size else float("nan")
    bound = "" if finished.all() else ">= "
    emit(f"solve_ivp loop: {len(pick)} of {n} points timed, {int((~finished).sum())} abandoned after {cap:g} s; "
         f"mean {np.mean(times):.3f} s/point; estimated full loop {bound}{loop_time:.1f} s")
    for jobs in (1, 2):
        wall, res = results[jobs]
        dis = np.abs(res.max_force - ref) / np.abs(ref)  # NaN (runaways) ignored by nanmax
        rows.append((f"sweep n_jobs={jobs}", n, wall, n / wall, f"{bound}{loop_time / wall:.1f}",
                     float(np.nanmax(dis)) if jobs != 1 else "(reference)", "measured, all points"))
    if "batch" in results:
        wall, mf = results["batch"]
        rows.append(("simulate_batch (rtol 1e-10)", n, wall, n / wall, f"{bound}{loop_time / wall:.1f}",
                     float(np.nanmax(np.abs(mf - ref) / np.abs(ref))), "measured, all points"))
    else:
        rows.append(("simulate_batch", "-", "-", "-", "-", "-", "NOT AVAILABLE (placeholder)"))
    rows.append((f"solve_ivp DOP853 loop (rtol {args.rtol:g}, plain RHS)", n, f"{bound}{loop_time:.1f}",
                 f"<= {n / loop_time:.3g}" if bound else n / loop_time, "1",
                 worst, f"estimated from {len(pick)} random points; {int((~finished).sum())} capped at {cap:g} s"))
    header = ("method", "N", "time [s]", "points/s", "speedup vs loop", "max rel. max-force disagreement",
              "note")
    text = table(header, rows)
    emit()
    emit(text)
    save_section(f"throughput_{law}" + args.quick * "_quick",
                 f"## Sweep throughput ({law})\n\n{machine()}\n\n{law}, N = {n} kappa log-spaced in "
                 f"[1e9, 1e14], t_end = {T_END:g} s; disagreement relative to sweep n_jobs=1 "
                 f"(loop: over its finished points; runaways, whose largest force is where the run stopped, "
                 f"left out).\n\n" + text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
