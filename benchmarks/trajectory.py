"""One trajectory: ``simulate`` and the compiled loop alone, against scipy, with their errors.

Seed case ``seed_parameters(v=1.0, kappa=3e9)``, rtol 1e-10, summary, stop when settled:

- Hunt-Crossley to ``t_end`` 2e-3 and 1e-2 s (it settles at ~0.64 ms: the projectile is out
  of reach after its second contact, so both horizons do the same work);
- ``paper`` to its first stick break (``stop_on="slip"``, no horizon): at ``kappa = 3e9`` the
  first stick is permanent (``kappa < kappa_c ~ 1.5e12``), so the run settles at it (this is
  what every margin evaluation of ``critical_damping`` costs); at ``kappa = 2e12`` it breaks.

Columns: the median time of one ``simulate`` call; of one ``driver.run`` inside a compiled
(numba) loop, i.e. the engine without any Python; the difference (the Python layer: argument
checks, the Trajectory; the case's packing is cached); ``driver.run`` called from Python; and
``simulate`` on a new case each call (``params.replace(kappa=...)`` included, nothing cached: what
a loop over kappa pays per run). Alternatives: the
scipy oracle (``phaseimpact/_oracle.py``: ``solve_ivp`` DOP853 on the same law entries with the same
events, phase by phase) and a plain ``solve_ivp`` DOP853 run on the same right-hand side
without events (what a user would write; its max force is only the largest over its steps).
Errors: max force, restitution (Hunt-Crossley) or the slip time and stick depth (paper),
relative to the oracle at rtol 1e-13.

``--against TREE`` times this checkout against another one (e.g. ``git worktree add /tmp/old
<commit>``; any commit with this benchmark, whose own driver arguments and compiled loop its worker
uses: ``_trajectory_worker.py``) on the same cases: a worker process per tree, both alive, taking
turns batch by batch, so that the load of a shared machine hits both alike; it prints the median
per-call times, their ratios and the largest relative difference of the results, and saves
``results/trajectory_against.md``.

    python benchmarks/trajectory.py [--quick] [--against TREE [--rounds N]]
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numba
import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import commit_of, emit, load, machine, per_call, save_section, save_targets, table, target, us  # noqa: E402

from phaseimpact import seed_parameters, simulate  # noqa: E402
from phaseimpact._oracle import oracle  # noqa: E402
from phaseimpact.integrate import api  # noqa: E402
from phaseimpact.integrate import driver as d  # noqa: E402
from phaseimpact.model import as_law, pack  # noqa: E402
from phaseimpact.model.forms import PLAIN  # noqa: E402
from phaseimpact.model.rhs import rhs  # noqa: E402

RTOL = 1e-10
REF_RTOL = 1e-13
#: (label, law, t_end, stop_on, target for one trajectory in s)
CASES = (("hunt-crossley, t_end 2e-3", 3e9, "hunt-crossley", 2e-3, None, 60e-6),
         ("hunt-crossley, t_end 1e-2", 3e9, "hunt-crossley", 1e-2, None, 120e-6),
         ("paper, to the first stick (permanent)", 3e9, "paper", None, "slip", 30e-6),
         ("paper kappa 2e12, to the first stick break", 2e12, "paper", None, "slip", 30e-6))


def driver_args(params, law, t_end, rtol, stop_on):
    """The arguments :func:`phaseimpact.simulate` passes to ``driver.run`` (summary, settle)."""
    law = as_law(law)
    s = api.scales(params)
    stop_kind, stop_count = api._stop_on(stop_on)
    horizon = s.horizon if t_end is None else t_end
    stiff_after = api._stiff_after(True)
    return (law.code, pack(params, law), api._initial(params, None), api._atol(params, rtol, None), horizon,
            s.max_step, (rtol, True, stop_kind, stop_count, api.MAX_STEPS, api.MAX_EVENTS, stiff_after),
            d.SAVE_SUMMARY, np.empty(0), api.radau_marker(stiff_after))


@numba.njit
def _loop(n, code, c, y0, atol, t_end, max_step, options, save_kind, times, radau):
    total = 0.0
    for _ in range(n):
        out = d.run(code, c, y0, atol, t_end, max_step, options, save_kind, times, radau)
        total += out[0][d.S_MAX_FORCE]
    return total


def interleaved(fns: dict, repeats: int, min_time: float = 0.03) -> dict:
    """Median time of one call of each ``fns[name](n)`` (which makes ``n`` calls), s.

    The contenders take turns within each repeat, so a burst of load on the shared machine
    hits all of them alike.
    """
    numbers = {}
    for name, fn in fns.items():
        fn(1)
        start = time.perf_counter()
        fn(10)
        numbers[name] = max(10, int(min_time / max((time.perf_counter() - start) / 10, 1e-7)))
    means = {name: [] for name in fns}
    for _ in range(repeats):
        for name, fn in fns.items():
            start = time.perf_counter()
            fn(numbers[name])
            means[name].append((time.perf_counter() - start) / numbers[name])
    return {name: statistics.median(m) for name, m in means.items()}


def repeat(fn):
    def many(n):
        for _ in range(n):
            fn()
    return many


def new_case_each_call(params, law, t_end, stop_on, rtol):
    """``simulate`` on a new case per call, made by ``params.replace`` (included), as a loop over
    kappa makes them: the caches of one case's packing and tolerances never hit (the kappas cycle
    through more values than they hold)."""
    kappas = itertools.cycle(params.kappa * (1 + 1e-12 * np.arange(4096)))

    def call():
        return simulate(params.replace(kappa=float(next(kappas))), law, t_end, rtol=rtol, stop_on=stop_on)
    return call


class _Timeout(Exception):
    pass


def plain_scipy(params, law, t_end, rtol, budget=2.0):
    """``solve_ivp`` DOP853 on the same right-hand side, no events: (time, max force over steps, nfev);
    None if one run takes longer than ``budget`` s (``paper``'s plain right-hand side chatters
    across ``deltadot = 0`` once stuck)."""
    law = as_law(law)
    c = pack(params, law)
    mode = PLAIN if law.is_filippov else 1
    y0 = api._initial(params, None)
    atol = api._atol(params, rtol, None)[:5]  # the physical state
    deadline = [0.0]

    def fun(_t, y):
        if time.perf_counter() > deadline[0]:
            raise _Timeout
        out = np.empty(5)
        rhs(law.code, c, y, mode, out)
        return out

    def solve():
        deadline[0] = time.perf_counter() + budget
        return solve_ivp(fun, (0.0, t_end), y0, method="DOP853", rtol=rtol, atol=atol)

    try:
        seconds = per_call(solve, repeats=3, min_time=0.0)
    except _Timeout:
        return None
    sol = solve()
    out = np.empty(5)
    force = max(rhs(law.code, c, sol.y[:, i], mode, out) for i in range(sol.y.shape[1]))
    return seconds, force, sol.nfev


def first(run, kind):
    found = run.of(kind)
    return found[0] if found else (np.nan, np.full(5, np.nan))


def quantities_oracle(run, v):
    t_sep, y_sep = first(run, "separation")
    t_slip, _ = first(run, "slip")
    _, y_stick = first(run, "stick")
    return {"max force": run.max_force, "restitution": -(y_sep[2] - y_sep[3]) / v, "slip time": t_slip,
            "stick depth": y_stick[0] - y_stick[1]}


def quantities_ours(tr):
    slips, sticks = tr.events_of("slip"), tr.events_of("stick")
    return {"max force": tr.max_force, "restitution": tr.restitution if tr.restitution is not None else np.nan,
            "slip time": slips[0].t if slips else np.nan, "stick depth": sticks[0].delta if sticks else np.nan}


def rel(a, b) -> float:
    return abs(a - b) / abs(b) if b else abs(a - b)


def against(tree: Path, rounds: int, repeats: int) -> int:
    """This checkout against ``tree``: one worker process per tree, both alive, taking turns batch
    by batch (the order swapped every round), so that the load of a shared machine hits both alike."""
    here = Path(__file__).resolve().parent.parent
    start_load = load()
    workers = {}
    for name, root in (("before", tree), ("after", here)):
        env = dict(os.environ, PYTHONPATH=str(root))
        proc = subprocess.Popen([sys.executable, str(Path(__file__).with_name("_trajectory_worker.py"))], env=env,
                                cwd=root, text=True, stdin=subprocess.PIPE, stdout=subprocess.PIPE)
        head = json.loads(proc.stdout.readline())
        assert Path(head["tree"]).resolve() == root.resolve(), (head["tree"], root)
        assert head["cases"] == [c[0] for c in CASES], f"{root} times other cases: {head['cases']}"
        workers[name] = (proc, head["bits"])
    samples = {"before": [], "after": []}
    for r in range(rounds * repeats):
        for name in (("before", "after") if r % 2 == 0 else ("after", "before")):
            proc = workers[name][0]
            proc.stdin.write("go\n")
            proc.stdin.flush()
            samples[name].append(json.loads(proc.stdout.readline()))
    for proc, _ in workers.values():
        proc.stdin.close()
        proc.wait()
    runs = {name: [[{"simulate": t[3 * i], "loop": t[3 * i + 1], "new case": t[3 * i + 2], "bits": workers[name][1][i]}
                    for i in range(len(CASES))] for t in samples[name]] for name in samples}
    end_load = load()
    rows, ratios, worst = [], [], 0.0
    for i, case in enumerate(CASES):
        before = [r[i] for r in runs["before"]]
        after = [r[i] for r in runs["after"]]
        timed = ("simulate", "loop", "new case")
        med = {name: {k: statistics.median(r[k] for r in rs) for k in timed}
               for name, rs in (("before", before), ("after", after))}
        ratio = {k: statistics.median(b[k] / a[k] for b, a in zip(before, after, strict=True)) for k in timed}
        differs = _largest_difference(before[0]["bits"], after[0]["bits"])
        worst = max(worst, differs)
        ratios.append(ratio)
        rows.append((case[0], us(med["before"]["simulate"]), us(med["after"]["simulate"]), f"{ratio['simulate']:.2f}",
                     us(med["before"]["loop"]), us(med["after"]["loop"]), f"{ratio['loop']:.2f}",
                     us(med["before"]["new case"]), us(med["after"]["new case"]), f"{ratio['new case']:.2f}",
                     "0 (bit for bit)" if differs == 0 else f"{differs:.1e}"))
    text = (f"`{tree}` ({commit_of(tree)}, before) against this checkout ({commit_of(here)}, after): a worker process "
            f"per tree, {rounds * repeats} "
            "turns each, alternating batch by batch (each batch the mean of about 20 ms of calls, the thread's CPU "
            "time: on a loaded machine the wall time counts other processes' turns too); each time the "
            "median of the batches, each ratio the median of the ratios of neighbouring batches (the same load on "
            "both sides). Results: the largest difference of max force, t_stop and the final state, relative to "
            "each quantity's own scale (the largest of its two values).\n\n"
            + table(("case", "simulate before [µs]", "after [µs]", "before / after", "compiled loop before [µs]",
                     "after [µs]", "before / after", "simulate, a new case each call, before [µs]", "after [µs]",
                     "before / after", "results: largest relative difference"), rows))
    emit(text)
    emit(f"\n{start_load} at the start, {end_load} at the end")
    save_section("trajectory_against", f"## One trajectory, before and after\n\n{machine()}\n\n{start_load} at the "
                 f"start, {end_load} at the end.\n\n{text}\n\n`python benchmarks/trajectory.py --against TREE`")
    # issue 36 asks 29.6 -> 25 µs, measured on a quieter machine: on a loaded one, the same ratio
    needed = 29.6 / 25
    save_targets("trajectory_against", [target(
        f"one trajectory ({CASES[0][0]}) against the code before, same machine and run (issue 36: 29.6 -> 25 µs)",
        f">= {needed:.2f}x faster, results within 1e-14", f"{ratios[0]['simulate']:.2f}x (simulate), "
        f"{ratios[0]['loop']:.2f}x (compiled loop), results within {worst:.1e}",
        bool(ratios[0]["simulate"] >= needed and worst <= 1e-14), "python benchmarks/trajectory.py --against TREE")])
    return 0 if worst <= 1e-14 else 1


def _largest_difference(bits_a: list, bits_b: list) -> float:
    """Largest relative difference between two lists of numbers (as hex), each relative to the larger of the two."""
    a = np.array([float.fromhex(x) for x in bits_a])
    b = np.array([float.fromhex(x) for x in bits_b])
    scale = np.maximum(np.abs(a), np.abs(b))
    return float(np.max(np.where(a == b, 0.0, np.abs(a - b) / np.where(scale > 0, scale, 1.0))))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="5 repeats instead of 15")
    ap.add_argument("--against", type=Path, help="another checkout of the project to time this one against")
    ap.add_argument("--rounds", type=int, default=4, help="--against: turns per tree, times the repeats (default 4)")
    args = ap.parse_args(argv)
    repeats = 5 if args.quick else 15
    if args.against:
        return against(args.against, args.rounds, repeats)
    start_load = load()
    emit("# One trajectory (seed case, kappa = 3e9, v = 1 m/s, rtol 1e-10, summary, stop when settled)\n")
    emit(machine())
    emit(start_load + "\n")
    rows, err_rows, targets = [], [], []
    for label, kappa, law, t_end, stop_on, limit in CASES:
        params = seed_parameters(v=1.0, kappa=kappa)
        args_ = driver_args(params, law, t_end, RTOL, stop_on)

        def call(params=params, law=law, t_end=t_end, stop_on=stop_on):
            return simulate(params, law, t_end, rtol=RTOL, stop_on=stop_on)

        tr = call()
        check = d.run(*args_)[0]
        assert check[d.S_MAX_FORCE] == tr.max_force, "driver_args must mirror simulate"
        times = interleaved({"simulate": repeat(call), "loop": lambda n, a=args_: _loop(n, *a),
                             "run": repeat(lambda a=args_: d.run(*a)),
                             "new case": repeat(new_case_each_call(params, law, t_end, stop_on, RTOL))}, repeats)
        t_sim, t_loop, t_run, t_new = times["simulate"], times["loop"], times["run"], times["new case"]
        t_oracle = per_call(lambda p=params, law=law, h=t_end, s=stop_on: oracle(p, law, h, rtol=RTOL, stop_on=s),
                            repeats=3, min_time=0.0)
        plain = plain_scipy(params, law, tr.t_stop if t_end is None else t_end, RTOL)
        t_plain, f_plain, nfev_plain = plain or (np.nan, np.nan, 0)
        plain_cell = f"{t_plain * 1e3:.3g} ms ({t_plain / t_sim:.0f}x)" if plain else "abandoned after 2 s (chatters)"
        ref = oracle(params, law, t_end, rtol=REF_RTOL, stop_on=stop_on)
        q_ref = quantities_oracle(ref, params.v)
        q_10 = quantities_ours(tr)
        q_13 = quantities_ours(simulate(params, law, t_end, rtol=REF_RTOL, stop_on=stop_on))
        q_or10 = quantities_oracle(oracle(params, law, t_end, rtol=RTOL, stop_on=stop_on), params.v)
        names = ("max force", "restitution") if law == "hunt-crossley" else ("max force", "stick depth")
        if tr.events_of("slip"):
            names += ("slip time",)
        errors = []
        for name in names:
            e10, e13, eo = rel(q_10[name], q_ref[name]), rel(q_13[name], q_ref[name]), rel(q_or10[name], q_ref[name])
            errors.append(f"{name} {e10:.1e}")
            ep = rel(f_plain, q_ref[name]) if name == "max force" else np.nan
            err_rows.append((label, name, f"{q_ref[name]:.12g}", e10, e13, eo, ep))
            if law == "hunt-crossley" and t_end == 2e-3:  # issue 9's accuracy target (the same run at 1e-2)
                targets.append(target(f"{label}: {name} vs oracle at rtol 1e-13", "<= 1e-9 relative",
                                      f"{e10:.1e} (rtol 1e-10), {e13:.1e} (rtol 1e-13)", bool(max(e10, e13) <= 1e-9),
                                      "python benchmarks/trajectory.py"))
        rows.append((label, f"{tr.t_stop:.4g}", tr.nsteps, tr.nfev, us(t_sim), us(t_loop), us(t_sim - t_loop),
                     us(t_run), us(t_new), ", ".join(errors), us(limit), f"{t_sim / limit:.2f}",
                     f"{t_loop / limit:.2f}", f"{t_oracle * 1e3:.3g} ms ({t_oracle / t_sim:.0f}x)",
                     plain_cell))
        targets.append(target(f"one trajectory: {label}", f"<= {us(limit)} µs",
                              f"simulate {us(t_sim)} µs, compiled loop {us(t_loop)} µs",
                              bool(t_sim <= limit), "python benchmarks/trajectory.py"))
        emit(f"{label}: simulate {us(t_sim)} µs, compiled loop {us(t_loop)} µs, driver.run from Python "
             f"{us(t_run)} µs, simulate on a new case each call {us(t_new)} µs; oracle {t_oracle * 1e3:.3g} ms, "
             f"plain solve_ivp {t_plain * 1e3:.3g} ms "
             f"(nfev {nfev_plain}); t_stop {tr.t_stop:.4g} s, {tr.nsteps} steps, nfev {tr.nfev}")
    end_load = load()
    header = ("case", "t_stop [s]", "steps", "nfev", "simulate [µs]", "compiled loop [µs]", "Python layer [µs]",
              "driver.run from Python [µs]", "simulate, a new case each call [µs]",
              "error vs oracle at rtol 1e-13 (ours, rtol 1e-10)", "target [µs]",
              "simulate / target", "compiled / target",
              "scipy oracle, same events (x simulate)", "plain solve_ivp DOP853, no events (x simulate)")
    err_header = ("case", "quantity", "oracle at rtol 1e-13", "ours rtol 1e-10", "ours rtol 1e-13",
                  "oracle rtol 1e-10", "plain solve_ivp rtol 1e-10")
    text = (table(header, rows) + "\n\nRelative errors against the oracle at rtol 1e-13:\n\n"
            + table(err_header, err_rows))
    emit()
    emit(text)
    emit(f"\nat the end: {end_load}")
    save_section("trajectory" + args.quick * "_quick",
                 f"## One trajectory\n\n{machine()}\n\n{start_load} at the start, {end_load} at the end.\n\n"
                 f"Seed case, kappa = 3e9, v = 1 m/s, rtol {RTOL:g}, summary, stop when settled; times are medians "
                 f"of {repeats} repeats (each the mean of many calls). `python benchmarks/trajectory.py`\n\n" + text)
    save_targets("trajectory" + args.quick * "_quick", targets)
    return 0


if __name__ == "__main__":
    sys.exit(main())
