"""Transitions: ``kappa_c`` (and its pieces), ``kappa_2``, a ``kappa_c(v)`` curve and the grazing
values, each against the brute-force way (a dense grid of runs and the count's changes on it).

- ``critical_damping(seed_parameters(), "paper", kappa_rtol=1e-10)``: kappa_c to 1e-10 relative. Its
  time is split by instrumenting the runs it makes: the margin root (runs to the first stick,
  Brent on the margin) and the two confirming runs at ``kappa_c (1 -+ 1e-3)`` (until settled).
  Brute force: ``simulate_many`` over N kappa in [1e12, 2e12] (2 threads), the bracket where
  the stick count first goes from 1 to 2.
- ``locate_kappa_2`` to 1e-8 (without and with the 24-sample staircase).
- ``critical_curve(..., "paper", "v", geomspace(0.3, 13, 200))`` (continuation: a predicted
  bracket per point) against independent ``critical_damping`` searches at each speed
  (timed on a subset, extrapolated).
- ``grazing_transitions(seed_parameters(v=1, kappa=3e9), "hunt-crossley", 1e8, 1e13)`` against
  the changes of the contact count on a 20,000-point grid (``simulate_many``, 2 threads).

    python benchmarks/critical.py [--quick]
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

import phaseimpact.continuation._kappa_search as kappa_search  # noqa: E402
import phaseimpact.continuation.grazing as grazing  # noqa: E402
import phaseimpact.continuation.kappa_2 as kappa_2  # noqa: E402
import phaseimpact.continuation.transition as transition  # noqa: E402
from phaseimpact import seed_parameters, simulate_many  # noqa: E402
from phaseimpact.continuation import critical_curve, critical_damping, grazing_transitions, locate_kappa_2  # noqa: E402

RTOL = 1e-10


class Split:
    """Wraps the runs the searches in kappa make (``simulate``, and ``summary_run`` on the per-point
    path, in the transition search's modules): time and count per kind of run."""

    WRAPPED = ((kappa_search, "summary_run"), (kappa_search, "simulate"), (kappa_2, "simulate"),
               (grazing, "summary_run"), (grazing, "simulate"))

    def __init__(self):
        self.time = {}
        self.count = {}
        self.inner = {(module, name): getattr(module, name) for module, name in self.WRAPPED}

    def timed(self, inner):
        def run(*args, **kwargs):
            kind = "margin (runs to the first stick)" if kwargs.get("stop_on") == "stick" else "confirming runs"
            start = time.perf_counter()
            try:
                return inner(*args, **kwargs)
            finally:
                self.time[kind] = self.time.get(kind, 0.0) + time.perf_counter() - start
                self.count[kind] = self.count.get(kind, 0) + 1
        return run

    def __enter__(self):
        for (module, name), inner in self.inner.items():
            setattr(module, name, self.timed(inner))
        return self

    def __exit__(self, *exc):
        for (module, name), inner in self.inner.items():
            setattr(module, name, inner)


def median_time(fn, repeats):
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def brute_kappa_c(params, n):
    kappas = np.linspace(1e12, 2e12, n)
    start = time.perf_counter()
    cols = simulate_many([params.replace(kappa=float(k)) for k in kappas], "paper", rtol=RTOL, n_threads=2)
    wall = time.perf_counter() - start
    hits = np.flatnonzero((cols.n_stick[:-1] == 1) & (cols.n_stick[1:] >= 2))
    if not hits.size:
        return wall, None
    return wall, (float(kappas[hits[0]]), float(kappas[hits[0] + 1]))


def brute_grazing(params, n):
    kappas = np.geomspace(1e8, 1e13, n)
    start = time.perf_counter()
    cols = simulate_many([params.replace(kappa=float(k)) for k in kappas], "hunt-crossley", rtol=RTOL, n_threads=2)
    wall = time.perf_counter() - start
    change = np.flatnonzero(np.diff(cols.n_contacts) != 0)
    return wall, [(float(kappas[i]), float(kappas[i + 1]), int(cols.n_contacts[i]), int(cols.n_contacts[i + 1]))
                  for i in change]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="3 repeats, a 20-point curve, smaller grids")
    args = ap.parse_args(argv)
    repeats = 3 if args.quick else 7
    n_curve = 20 if args.quick else 200
    start_load = load()
    emit("# Transitions: kappa_c, kappa_2, kappa_c(v), grazing\n")
    emit(machine())
    emit(start_load + "\n")
    params = seed_parameters()
    rows, targets = [], []

    # kappa_c and its pieces
    critical_damping(params, "paper", kappa_rtol=RTOL)  # warm-up
    splits = []
    times = []
    for _ in range(repeats):
        with Split() as split:
            start = time.perf_counter()
            cd = critical_damping(params, "paper", kappa_rtol=RTOL)
            times.append(time.perf_counter() - start)
        splits.append(split)
    t_kc = statistics.median(times)
    m_lo = transition.first_stick_margin(params.replace(kappa=cd.kappa_c * (1 - RTOL)), "paper")
    m_hi = transition.first_stick_margin(params.replace(kappa=cd.kappa_c * (1 + RTOL)), "paper")
    width = f"{cd.rtol:.0e}; margin {m_lo:+.1e} at (1-1e-10), {m_hi:+.1e} at (1+1e-10)"
    pieces = {k: statistics.median(s.time[k] for s in splits) for k in splits[0].time}
    counts = splits[0].count
    rows.append(("kappa_c: critical_damping(seed, 'paper', kappa_rtol=1e-10)", f"{t_kc * 1e3:.3g}", cd.evaluations,
                 f"{cd.kappa_c:.12g}", width, f"{cd.status}; closed form {cd.closed_form:.6g} "
                 f"({cd.kappa_c / cd.closed_form - 1:+.2%})"))
    for kind, t in pieces.items():
        rows.append((f"  of which {kind}", f"{t * 1e3:.3g}", counts[kind], "", "", "instrumented"))
    targets.append(target("kappa_c to 1e-10 relative (compute)", "<= 50 ms",
                          f"{t_kc * 1e3:.3g} ms (margin root "
                          f"{pieces.get('margin (runs to the first stick)', 0) * 1e3:.3g} ms, confirming runs "
                          f"{pieces.get('confirming runs', 0) * 1e3:.3g} ms)", bool(t_kc <= 0.05),
                          "python benchmarks/critical.py"))
    for n in ((200,) if args.quick else (200, 2000)):
        wall, bracket = brute_kappa_c(params, n)
        if bracket:
            inside = bracket[0] <= cd.kappa_c <= bracket[1]
            rows.append((f"  brute force: simulate_many over {n} kappa in [1e12, 2e12], 2 threads", f"{wall * 1e3:.3g}",
                         n, f"[{bracket[0]:.6g}, {bracket[1]:.6g}]", f"{(bracket[1] - bracket[0]) / cd.kappa_c:.1e}",
                         f"count 1 -> 2; kappa_c {'inside' if inside else 'OUTSIDE'}"))
        else:
            rows.append((f"  brute force over {n} kappa", f"{wall * 1e3:.3g}", n, "none", "", "no 1 -> 2 change"))
    emit(f"kappa_c = {cd.kappa_c!r} in {t_kc * 1e3:.3g} ms ({pieces})")

    # kappa_2
    for samples in (0, 24):
        t2, found = median_time(
            lambda s=samples: locate_kappa_2(params, "paper", cd.kappa_c, kappa_rtol=1e-8, samples=s), repeats)
        kappa_2, ev = found.kappa_2, found.evaluations
        rows.append((f"kappa_2: locate_kappa_2(kappa_rtol=1e-8, samples={samples})", f"{t2 * 1e3:.3g}", ev + samples,
                     f"{kappa_2:.10g}", "1e-08", f"kappa_2 / kappa_c - 1 = {kappa_2 / cd.kappa_c - 1:.4g}"))
        emit(f"kappa_2 = {kappa_2!r} ({samples} staircase samples) in {t2 * 1e3:.3g} ms")

    # kappa_c(v)
    speeds = np.geomspace(0.3, 13.0, n_curve)
    start = time.perf_counter()
    curve = critical_curve(params, "paper", "v", speeds)
    t_curve = time.perf_counter() - start
    sub = speeds[:: max(1, n_curve // 10)]
    start = time.perf_counter()
    independent = [critical_damping(params.replace(v=float(v)), "paper", kappa_rtol=RTOL).kappa_c for v in sub]
    t_indep = (time.perf_counter() - start) / len(sub) * n_curve
    on_curve = np.interp(np.log(sub), np.log(curve.v), np.log(curve.kappa_c))
    dis = float(np.max(np.abs(np.log(np.array(independent, float)) - on_curve)))
    rows.append((f"kappa_c(v): critical_curve over {n_curve} speeds in [0.3, 13] m/s", f"{t_curve * 1e3:.4g}",
                 len(curve.v), f"{len(curve.v)} points", "1e-10",
                 curve.message or f"{t_curve / n_curve * 1e3:.2g} ms per point"))
    rows.append((f"  independent critical_damping at each speed ({len(sub)} timed)", f"{t_indep * 1e3:.4g}",
                 n_curve, "", "1e-10", f"extrapolated; agree with the curve within {dis:.1e} (relative)"))
    emit(f"curve: {t_curve:.3g} s for {n_curve} speeds; independent searches ~{t_indep:.3g} s")

    # grazing
    seed3 = seed_parameters(v=1.0, kappa=3e9)
    t_g, found = median_time(lambda: grazing_transitions(seed3, "hunt-crossley", 1e8, 1e13), repeats)
    values = ", ".join(f"{g.kappa:.10g} ({g.count_below}->{g.count_above})" for g in found)
    rows.append(("grazing: grazing_transitions(seed kappa=3e9, 'hunt-crossley', 1e8, 1e13)", f"{t_g * 1e3:.3g}", "",
                 values, "1e-09", f"{len(found)} values"))
    n_grid = 2000 if args.quick else 20000
    wall, changes = brute_grazing(seed3, n_grid)
    located = sum(any(a <= g.kappa <= b for a, b, _, _ in changes) for g in found)
    rel = np.geomspace(1e8, 1e13, n_grid)
    rows.append((f"  brute force: contact count over {n_grid} kappa (log grid), 2 threads", f"{wall * 1e3:.3g}", n_grid,
                 "; ".join(f"[{a:.5g}, {b:.5g}] {na}->{nb}" for a, b, na, nb in changes),
                 f"{rel[1] / rel[0] - 1:.1e}",
                 f"{len(changes)} changes; {located} of the {len(found)} located values lie in one"))
    emit(f"grazing: {values} in {t_g * 1e3:.3g} ms; grid changes {changes}")

    end_load = load()
    header = ("what", "time [ms]", "runs / evaluations", "result", "relative width", "note")
    text = table(header, rows)
    emit()
    emit(text)
    emit(f"\nat the end: {end_load}")
    save_section("critical" + args.quick * "_quick",
                 f"## Transitions (kappa_c, kappa_2, kappa_c(v), grazing)\n\n{machine()}\n\n{start_load} at the start, "
                 f"{end_load} at the end.\n\nSeed case (paper, v = 1 m/s unless said); times are medians of {repeats} "
                 "(the curve and the grids: one run). `python benchmarks/critical.py`\n\n" + text)
    save_targets("critical" + args.quick * "_quick", targets)
    return 0


if __name__ == "__main__":
    sys.exit(main())
