"""Work-precision: error against time for our compiled driver and scipy's ``solve_ivp`` methods.

Seed case (``kappa = 3e9``, v = 1 m/s), laws ``hunt-crossley`` and ``paper``, ``t_end = 2e-3`` s,
no stop when settled (the state at ``t_end`` is then defined for everyone). Errors:

(a) max force, relative;
(b) the state at ``t_end``: max over components, positions over the Hertz indentation, velocities
    over v.

Contenders:

- ours: ``simulate(params, law, 2e-3, rtol=r, stop_when_settled=False)``, rtol 1e-4..1e-13;
- scipy with the same events: the oracle (``phaseimpact/_oracle.py``: ``solve_ivp`` on the same law
  entries, the same event table, phase by phase) with ``method`` DOP853, RK45, Radau, BDF, LSODA;
  its max force is located on the force-peak event;
- plain scipy: ``solve_ivp`` on the same right-hand side without events (``paper``: eq. 8 read
  literally), max force the largest over its steps;
- heyoka (``benchmarks/peers.py``, its own venv), drawn when ``results/peers_points.json`` exists.

Reference: the oracle (DOP853) at rtol 1e-13; the floor row says how far ours at 1e-13 is from
it. Times: median of repeats; a run slower than the budget ends that method's sweep.

    python benchmarks/work_precision.py [--quick] [--plot-only]
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import FIGURES, RESULTS, emit, load, machine, save_section, save_targets, table, target  # noqa: E402

from phaseimpact import _oracle as oracle_module  # noqa: E402
from phaseimpact import seed_parameters, simulate  # noqa: E402
from phaseimpact.integrate import api  # noqa: E402
from phaseimpact.model import as_law, pack  # noqa: E402
from phaseimpact.model.forms import PLAIN  # noqa: E402
from phaseimpact.model.rhs import rhs  # noqa: E402

T_END = 2e-3
KAPPA = 3e9
LAWS = ("hunt-crossley", "paper")
RTOLS = [10.0**-k for k in range(4, 14)]
METHODS = ("DOP853", "RK45", "Radau", "BDF", "LSODA")
ERRORS = ("max force", "state at t_end")
OURS = "ours (compiled driver)"


def scale_of(params):
    s = params.hertz_indentation
    return np.array([s, s, params.v, params.v])


def run_ours(params, law, rtol, seconds=None):  # the compiled run has no deadline (it is the fast one)
    tr = simulate(params, law, T_END, rtol=rtol, stop_when_settled=False)
    return tr.max_force, tr.final_state[:4], tr.nfev, tr.status


def run_oracle(params, law, rtol, method, seconds=None):
    run = oracle_module.oracle(params, law, T_END, rtol=rtol, method=method, settle=False, seconds=seconds)
    status = "success" if run.t_stop >= T_END * (1 - 1e-12) else f"stopped at {run.t_stop:.3g} s ({run.reason})"
    return run.max_force, run.final_state[:4], run.nfev, status


def run_plain(params, law, rtol, method, seconds=None):
    law = as_law(law)
    c = pack(params, law)
    mode = PLAIN if law.is_filippov else 1
    budget = oracle_module.Budget(seconds=seconds)

    def fun(_t, y):
        budget.spend()
        out = np.empty(5)
        rhs(law.code, c, y, mode, out)
        return out

    with warnings.catch_warnings(), np.errstate(all="ignore"):  # the chattering runs overflow their Jacobians
        warnings.simplefilter("ignore", RuntimeWarning)
        sol = solve_ivp(fun, (0.0, T_END), api._initial(params, None), method=method, rtol=rtol,
                        atol=api._atol(params, rtol, None)[:5])
    out = np.empty(5)
    force = max(rhs(law.code, c, sol.y[:, i], mode, out) for i in range(sol.y.shape[1]))
    return force, sol.y[:4, -1], sol.nfev, "success" if sol.success else sol.message


def measure(fn, repeats, budget):
    """(median time, result) of ``fn(seconds)``; one run only if it is slow; None if over ``budget``
    seconds (the scipy runs raise :class:`~phaseimpact._oracle.BudgetExceeded` past it)."""
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        try:
            result = fn(budget)
        except oracle_module.BudgetExceeded:
            return None
        times.append(time.perf_counter() - start)
        if times[-1] > 0.5:
            break
    if times[0] < 1e-3:  # fast: the mean of many calls per repeat
        number = int(0.02 / times[0]) + 1
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            for _ in range(number):
                fn(None)
            times.append((time.perf_counter() - start) / number)
    return statistics.median(times), result


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="every other rtol, 3 repeats, 2 s budget")
    ap.add_argument("--plot-only", action="store_true",
                    help="redraw the figure from results/work_precision_points.json")
    args = ap.parse_args(argv)
    name = "work_precision" + args.quick * "_quick"
    if args.plot_only:
        plot(json.loads((RESULTS / f"{name}_points.json").read_text())["points"], args.quick)
        return 0
    rtols = RTOLS[::2] + [RTOLS[-1]] if args.quick else RTOLS
    repeats, budget = (3, 2.0) if args.quick else (5, 10.0)
    start_load = load()
    emit(f"# Work-precision (seed case, kappa = {KAPPA:g}, v = 1 m/s, t_end = {T_END:g} s)\n")
    emit(machine())
    emit(start_load + "\n")
    params = seed_parameters(v=1.0, kappa=KAPPA)
    scale = scale_of(params)
    rows, points, floors = [], [], {}
    for law in LAWS:
        ref_force, ref_state, _, _ = run_oracle(params, law, 1e-13, "DOP853")
        f13, s13, _, _ = run_ours(params, law, 1e-13)
        floors[law] = (abs(f13 / ref_force - 1), float(np.max(np.abs(s13 - ref_state) / scale)))
        emit(f"{law}: reference max force {ref_force!r} N; ours at 1e-13 differs by {floors[law][0]:.1e} (force), "
             f"{floors[law][1]:.1e} (state)")
        contenders = [(OURS, lambda r, s, law=law: run_ours(params, law, r, s))]
        contenders += [(f"scipy {m} + events", lambda r, s, m=m, law=law: run_oracle(params, law, r, m, s))
                       for m in METHODS]
        contenders += [(f"scipy {m}, no events", lambda r, s, m=m, law=law: run_plain(params, law, r, m, s))
                       for m in METHODS]
        for label, fn in contenders:
            for r in rtols:
                got = measure(lambda s, fn=fn, r=r: fn(r, s), repeats, budget)
                if got is None:
                    rows.append((law, label, f"{r:.0e}", f"> {budget:g} s", "", "", "", "abandoned (budget)"))
                    emit(f"{law:14s} {label:26s} rtol={r:.0e} abandoned after {budget:g} s")
                    break
                seconds, (force, state, nfev, status) = got
                e_force = abs(force / ref_force - 1)
                e_state = float(np.max(np.abs(np.asarray(state) - ref_state) / scale))
                rows.append((law, label, f"{r:.0e}", f"{seconds * 1e3:.3g}", nfev, e_force, e_state, status))
                if label == "scipy DOP853 + events" and r == 1e-13:
                    rows[-1] = rows[-1][:-1] + ("the reference",)
                elif status == "success":
                    points.append({"law": law, "method": label, "rtol": r, "time": seconds,
                                   "errors": [e_force, e_state]})
                emit(f"{law:14s} {label:26s} rtol={r:.0e} {seconds * 1e3:9.3f} ms  force {e_force:.1e}  "
                     f"state {e_state:.1e}  nfev {nfev}  {status}")
    for peers in (RESULTS / "peers_points.json", RESULTS / "peers_quick_points.json"):  # heyoka (peers.py)
        if peers.exists():
            points += json.loads(peers.read_text())["points"]
            break
    end_load = load()
    eq_rows, targets = equal_accuracy(points)
    header = ("law", "method", "rtol", "time [ms]", "nfev", "err max force", "err state(t_end)", "status")
    eq_header = ("law", "error", "target", "ours [ms]", "fastest scipy (or heyoka) reaching it [ms]",
                 "ours / fastest other", "every other's time [ms]")
    floor_text = "; ".join(f"{law}: {f:.1e} (max force), {s:.1e} (state)" for law, (f, s) in floors.items())
    text = (f"Reference: the oracle (DOP853 with events) at rtol 1e-13. Ours at rtol 1e-13 against it: {floor_text}; "
            "errors near that level are the reference's own.\n\n"
            "At equal accuracy: the fastest run of each method whose error meets the target.\n\n"
            + table(eq_header, eq_rows) + "\n\nEvery run:\n\n" + table(header, rows))
    emit()
    emit(text)
    emit(f"\nat the end: {end_load}")
    save_section(name, f"## Work-precision\n\n{machine()}\n\n{start_load} at the start, {end_load} at the end.\n\n"
                       f"Seed case, kappa = {KAPPA:g}, v = 1 m/s, t_end = {T_END:g} s (no stop when settled); time = "
                       f"median of {repeats}; figure `figures/work_precision.png`. "
                       "`python benchmarks/work_precision.py`\n\n" + text)
    (RESULTS / f"{name}_points.json").write_text(json.dumps({"load": end_load, "points": points}, indent=0) + "\n")
    save_targets(name, targets)
    plot(points, args.quick)
    return 0


def equal_accuracy(points):
    """Rows of the equal-accuracy table, and the targets: ours at or below every other method."""
    rows, worst = [], {}
    for law in LAWS:
        for k, err in enumerate(ERRORS):
            for goal in (1e-6, 1e-8, 1e-10):
                best = {}
                for p in points:
                    if p["law"] == law and p["errors"][k] <= goal:
                        if p["method"] not in best or p["time"] < best[p["method"]]:
                            best[p["method"]] = p["time"]
                ours = best.pop(OURS, None)
                if not best:
                    continue
                other = min(best, key=best.get)
                ratio = ours / best[other] if ours else math.inf
                rows.append((law, err, f"{goal:.0e}", f"{ours * 1e3:.3g}" if ours else "not reached",
                             f"{best[other] * 1e3:.3g} ({other})", f"{ratio:.2f}",
                             "; ".join(f"{m.replace('scipy ', '')} {t * 1e3:.3g}"
                                       for m, t in sorted(best.items(), key=lambda x: x[1]))))
                key = (law, err)
                if key not in worst or ratio > worst[key][0]:
                    worst[key] = (ratio, goal, other)
    targets = [target(f"work-precision, {law}, {err}", "at or below every scipy method and heyoka",
                      f"worst ours/fastest other {ratio:.2f} (at {goal:.0e}, vs {other})", bool(ratio <= 1.0),
                      "python benchmarks/work_precision.py") for (law, err), (ratio, goal, other) in worst.items()]
    return rows, targets


#: Each method's marker (shape and colour): with events a filled marker on a solid line, without a
#: hollow one on a dotted line, so the series read apart in grayscale too.
MARKERS = {"DOP853": ("s", "C0"), "RK45": ("D", "C1"), "Radau": ("^", "C2"), "BDF": ("v", "C3"), "LSODA": ("P", "C4")}


def plot(points, quick: bool = False) -> None:
    """The figure: ``figures/work_precision.png`` (and ``.pdf``), or a preview in ``figures/preview/`` (quick)."""
    from phaseimpact.plotting import figure, for_print, save, style

    floor = 1e-16
    methods = list(dict.fromkeys(p["method"] for p in points))
    with style():
        fig, axes = figure(len(LAWS), len(ERRORS), height=6.8)
        for i, law in enumerate(LAWS):
            for k, err in enumerate(ERRORS):
                ax = axes[i][k]
                for method in methods:
                    pts = sorted((p for p in points if p["law"] == law and p["method"] == method),
                                 key=lambda p: p["rtol"])
                    if not pts:
                        continue
                    x = [max(p["errors"][k], floor) for p in pts]
                    y = [p["time"] * 1e3 for p in pts]
                    if method == OURS:
                        ax.loglog(x, y, "o-", color="k", lw=2.0, ms=4.5, label=method, zorder=5)
                    elif method.startswith("heyoka"):
                        ax.loglog(x, y, "*-", color="m", lw=1.4, ms=7, label=method, zorder=4)
                    else:
                        marker, color = MARKERS.get(method.split()[1].rstrip(","), ("x", "gray"))
                        events = "events" in method and "no events" not in method
                        ax.loglog(x, y, marker=marker, ls="-" if events else ":", color=color,
                                  mfc=color if events else "none", lw=1.0 if events else 0.9, ms=3.5, label=method)
                ax.set_xlabel(f"relative error of the {err}")
                ax.set_ylabel("time per run (ms)")
                no_peer = any(p["method"].startswith("heyoka") for p in points) and not any(
                    p["method"].startswith("heyoka") and p["law"] == law for p in points)
                ax.set_title(f"{law}: {err}" + ("\n(heyoka: not set up for its stick)" if no_peer else ""))
                ax.grid(True, which="major", alpha=0.3)
        handles, labels = [], []
        for ax in axes.flat:
            for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
                if lab not in labels:
                    handles.append(h)
                    labels.append(lab)
        fig.legend(handles, labels, loc="outside lower center", ncol=3)
        fig.suptitle(f"Work-precision, seed case κ = {KAPPA:g}, v = 1 m/s, t_end = {T_END:g} s\n"
                     "(lower left is better; errors below 1e-16 drawn at 1e-16)")
        path = (FIGURES / "preview" if quick else FIGURES) / "work_precision.png"
        with for_print():
            save(fig, path)
    emit(f"\nwrote {path} (and .pdf)")


if __name__ == "__main__":
    sys.exit(main())
