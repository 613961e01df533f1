"""Work-precision: error vs wall time for our integrators, scipy's solve_ivp and the seed's RK4.

Seed case (kappa = 3e9, v = 1 m/s), laws ``hunt-crossley`` and ``paper``, t_end = 2 ms.
Reference: our exact integrator at rtol = 1e-13. Errors: relative error of the max force;
state at t_end (positions / Hertz indentation scale, velocities / v, max over components);
``paper`` only: relative error of the stick indentation (delta at the first ``stick`` event;
methods without events: delta at t_end, stuck by then).

    python benchmarks/work_precision.py [--quick]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import FIGURES, RESULTS, emit, machine, save_section, table, timed  # noqa: E402

import phaseimpact.integrate as integrate  # noqa: E402
from phaseimpact.integrate import simulate  # noqa: E402
from phaseimpact.integrate._trajectory import state_scale  # noqa: E402
from phaseimpact.model import X1, X2, as_law, coefficients, contact_force, initial_state, rhs  # noqa: E402
from phaseimpact.parameters import seed_parameters  # noqa: E402

T_END = 2e-3
KAPPA = 3e9
LAWS = ("hunt-crossley", "paper")
RTOLS = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12]
RK4_STEPS = [1e-6, 3e-7, 1e-7, 3e-8, 1e-8]
RK4_BUDGET = 20.0  # s: skip RK4 steps predicted slower than this
SCIPY_BUDGET = 20.0  # s: a solve_ivp run is abandoned after this (paper's plain RHS chatters)


class _Timeout(Exception):
    pass


ERRORS = ("max force", "state at t_end", "stick indentation")


def _stick_delta(events, final_state):
    for e in events:
        if e.kind == "stick":
            return e.delta
    return float(final_state[X1] - final_state[X2])


def summary_of(max_force, final_state, stick_delta):
    return {"max_force": float(max_force), "final": np.asarray(final_state, float)[:4],
            "stick": float(stick_delta)}


def run_exact(params, law, rtol, method):
    tr = simulate(params, law, T_END, rtol=rtol, method=method, stop_when_settled=False)
    return tr, summary_of(tr.max_force, tr.final_state, _stick_delta(tr.events, tr.final_state))


def run_rk4(params, law, step):
    tr = simulate(params, law, T_END, integrator="rk4", step=step)
    return tr, summary_of(tr.max_force, tr.final_state, _stick_delta((), tr.final_state))


def run_scipy(params, law, rtol, method):
    c = coefficients(params, as_law(law))
    law_ = as_law(law)
    y0 = initial_state(params.v)
    scale = state_scale(params, c)
    deadline = time.perf_counter() + SCIPY_BUDGET

    def f(t, y):
        if time.perf_counter() > deadline:
            raise _Timeout
        return rhs(y, c, law_)

    sol = solve_ivp(f, (0.0, T_END), y0, method=method, rtol=rtol, atol=rtol * scale)
    force = contact_force(sol.y.T, c, law_)
    final = sol.y[:, -1]
    out = summary_of(np.max(force), final, final[X1] - final[X2])
    out["nfev"] = sol.nfev
    out["status"] = "success" if sol.success else sol.message
    return sol, out


def run_batch(params, law, rtol):
    tr = integrate.simulate_batch([params], law, T_END, rtol=rtol, stop_when_settled=False)[0]
    return tr, summary_of(tr.max_force, tr.final_state, _stick_delta(tr.events, tr.final_state))


def errors(res, ref, scale):
    e_force = abs(res["max_force"] - ref["max_force"]) / abs(ref["max_force"])
    e_state = float(np.max(np.abs(res["final"] - ref["final"]) / scale[:4]))
    e_stick = abs(res["stick"] - ref["stick"]) / abs(ref["stick"])
    return e_force, e_state, e_stick


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="fewer tolerances, one repeat")
    ap.add_argument("--plot-only", action="store_true", help="redraw the figure from results/work_precision.md")
    args = ap.parse_args(argv)
    if args.plot_only:
        plot(curves_from_table(RESULTS / "work_precision.md"))
        return 0
    rtols = RTOLS[::2] if args.quick else RTOLS
    repeats = 1 if args.quick else 3
    emit(f"# Work-precision (seed case, kappa = {KAPPA:g}, v = 1 m/s, t_end = {T_END:g} s)\n")
    emit(machine() + "\n")
    has_batch = hasattr(integrate, "simulate_batch")
    if not has_batch:
        emit("**simulate_batch not available: batch integrator not benchmarked (placeholder).**\n")
    rows, curves = [], {}
    params = seed_parameters(kappa=KAPPA)
    for law in LAWS:
        c = coefficients(params, as_law(law))
        scale = state_scale(params, c)
        t0 = time.perf_counter()
        _, ref = run_exact(params, law, 1e-13, "DOP853")
        emit(f"reference {law}: max force {ref['max_force']:.10g} N, stick delta {ref['stick']:.10g} m "
             f"({time.perf_counter() - t0:.2f} s)")
        runs = []
        for method in ("DOP853", "RK45"):
            runs += [(f"exact {method}", f"rtol={r:g}", lambda r=r, m=method, lw=law: run_exact(params, lw, r, m))
                     for r in rtols]
        if has_batch:
            runs += [("batch DOP853", f"rtol={r:g}", lambda r=r, lw=law: run_batch(params, lw, r)) for r in rtols]
        for method in ("RK45", "DOP853", "LSODA", "Radau"):
            runs += [(f"solve_ivp {method}", f"rtol={r:g}", lambda r=r, m=method, lw=law: run_scipy(params, lw, r, m))
                     for r in rtols]
        rk4_cost = None  # s per step
        for step in RK4_STEPS:
            n = math.ceil(T_END / step)
            if rk4_cost is not None and rk4_cost * n > RK4_BUDGET:
                rows.append((law, "seed RK4", f"step={step:g}", "skipped", "", "", "", "",
                             f"predicted {rk4_cost * n:.0f} s > {RK4_BUDGET:g} s"))
                continue
            runs.append(("seed RK4", f"step={step:g}", lambda s=step, lw=law: run_rk4(params, lw, s)))
            wall, (tr, res) = timed(runs.pop()[2], repeats=repeats)
            rk4_cost = wall / n
            _record(rows, curves, law, "seed RK4", f"step={step:g}", wall, tr, res, ref, scale)
        timed_out = set()
        for name, setting, fn in runs:
            if name in timed_out:
                rows.append((law, name, setting, "skipped", "", "", "", "", "a looser rtol exceeded the budget"))
                continue
            try:
                wall, (tr, res) = timed(fn, repeats=repeats)
            except _Timeout:
                timed_out.add(name)
                rows.append((law, name, setting, f"> {SCIPY_BUDGET:g}", "", "", "", "",
                             f"abandoned after {SCIPY_BUDGET:g} s"))
                emit(f"{law:14s} {name:18s} {setting:14s} abandoned after {SCIPY_BUDGET:g} s")
                continue
            _record(rows, curves, law, name, setting, wall, tr, res, ref, scale)
    header = ("law", "method", "setting", "time [s]", "nfev", "err max force", "err state(t_end)",
              "err stick delta", "status")
    text = table(header, rows)
    emit()
    emit(text)
    save_section("work_precision" + args.quick * "_quick",
                 f"## Work-precision\n\n{machine()}\n\nSeed case, kappa = {KAPPA:g}, "
                 f"v = 1 m/s, t_end = {T_END:g} s; reference: exact DOP853 at rtol = 1e-13; "
                 f"time = median of {repeats} runs.\n\n" + text)
    plot(curves)
    return 0


def _record(rows, curves, law, name, setting, wall, tr, res, ref, scale):
    e = errors(res, ref, scale)
    nfev = res.get("nfev", getattr(tr, "nfev", ""))
    status = res.get("status", getattr(tr, "status", ""))
    rows.append((law, name, setting, wall, nfev, e[0], e[1], e[2] if law == "paper" else "", status))
    if status == "success":  # a failed run's numbers are not a point of the trade-off
        curves.setdefault((law, name), []).append((wall, *e))
    emit(f"{law:14s} {name:18s} {setting:14s} {wall:9.4f} s  force {e[0]:.2e}  state {e[1]:.2e}  "
         f"stick {e[2]:.2e}  {status}")


def curves_from_table(path) -> dict:
    """The plotted points, read back from a results table (``--plot-only``)."""
    curves = {}
    for line in Path(path).read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 9 or cells[-1] != "success":
            continue
        law, name, _, wall, _, force, state, stick, _ = cells
        try:
            point = (float(wall), float(force), float(state), float(stick) if stick else float("nan"))
        except ValueError:
            continue
        curves.setdefault((law, name), []).append(point)
    return curves


def plot(curves) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    kinds = [(law, k) for law in LAWS for k in range(3) if not (law != "paper" and k == 2)]
    fig, axes = plt.subplots(1, len(kinds), figsize=(5 * len(kinds), 4.5), squeeze=False)
    styles = {"exact DOP853": ("C0", "o-"), "exact RK45": ("C1", "o-"), "batch DOP853": ("C2", "D--"),
              "solve_ivp RK45": ("C3", "s:"), "solve_ivp DOP853": ("C4", "s:"), "solve_ivp LSODA": ("C5", "s:"),
              "solve_ivp Radau": ("C6", "s:"), "seed RK4": ("k", "^-")}
    floor = 1e-16
    for ax, (law, k) in zip(axes[0], kinds, strict=True):
        for (lw, name), pts in curves.items():
            if lw != law:
                continue
            color, style = styles.get(name, ("gray", "x-"))
            ax.loglog([p[1 + k] if p[1 + k] > floor else floor for p in pts], [p[0] for p in pts], style,
                      color=color, label=name, ms=4)
        ax.set_xlabel(f"relative error: {ERRORS[k]}")
        ax.set_ylabel("wall time [s]")
        ax.set_title(f"{law}: {ERRORS[k]}")
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.suptitle(f"Work-precision, seed case kappa = {KAPPA:g}, t_end = {T_END:g} s (errors < 1e-16 drawn at 1e-16)")
    fig.tight_layout()
    FIGURES.mkdir(exist_ok=True)
    fig.savefig(FIGURES / "work_precision.png", dpi=120)
    emit(f"\nwrote {FIGURES / 'work_precision.png'}")


if __name__ == "__main__":
    sys.exit(main())
