"""Where a user's first compile goes: the engine's first ``simulate`` on an empty cache, broken down
by numba's event API (``numba.core.event``: one ``numba:compile`` event per compiled function, one
``numba:llvm_lock`` event per call into LLVM, one ``numba:run_pass`` event per compiler pass),
beside numba's own work for one small function compiled alone.

A fresh process with ``NUMBA_CACHE_DIR`` pointing to an empty temporary directory imports numba,
compiles five small stand-alone functions with plain ``numba.njit`` (a 6-line loop each, after one
to warm numba up), then makes the call a user's first ``phaseimpact simulate`` makes
(Hunt-Crossley, summary) under the listeners. A function's own time is its compile event's time
less the events nested in it (the functions it calls, compiled on first sight, and its LLVM calls);
the LLVM time is the sum of the LLVM events; a pass's own time likewise excludes the compiles and
LLVM calls nested in it. What this shows: how much of the first command is numba's own work (typing
and lowering) and how much LLVM's, which of numba's compiler passes take it, whether numba's work is
in the many small functions or the few large ones, and which functions and modules cost the most.

``--against TREE`` times the same first call in this checkout and another one (e.g. ``git worktree
add /tmp/old <commit>``), side by side: each pair is two cold processes started together, one per
tree (one per core on a 2-core machine, so that the machine's speed of the moment hits both alike),
each on an empty cache and compiling in its own process (``PHASEIMPACT_COMPILE_PROCESSES=1`` for
older trees that split the compile over a helper process); it prints each pair's times, the median
ratio, and saves ``results/compile_against.md``.

    python benchmarks/compile_profile.py [--against TREE [--pairs N]]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import VENV_BIN, commit_of, emit, load, machine, save_section, table  # noqa: E402

SMALL = 0.3  # s: a function "small" in the breakdown
PASSES = 8  # compiler passes named in the breakdown

PROBE = r"""
import json, math, time
import numba
import numpy as np
from numba.core import event

class Clock(event.Listener):
    # one stack for every kind it listens to: an event's own time excludes what nests in it (a
    # callee compiled while its caller is typed, the LLVM calls of lowering, a compile's passes)
    def __init__(self):
        self.stack, self.rows = [], []

    def on_start(self, ev):
        if ev.kind == "numba:run_pass":
            label = ev.data["name"].split(" [")[0]
        else:
            name = getattr(ev.data.get("dispatcher"), "py_func", None) if ev.data else None
            label = f"{name.__module__}.{name.__qualname__}" if name is not None else ""
        self.stack.append([ev.kind, label, time.perf_counter(), 0.0])

    def on_end(self, ev):
        kind, label, start, nested = self.stack.pop()
        spent = time.perf_counter() - start
        if self.stack:
            self.stack[-1][3] += spent
        self.rows.append((kind, label, spent - nested))


t = time.perf_counter()
numba.njit(lambda x: x + 1.0)(1.0)
warm_numba = time.perf_counter() - t
alone = []  # (numba's own seconds, LLVM's seconds) of each small function
for i in range(5):  # distinct functions: numba compiles each anew
    ns = {"math": math}
    exec(f'''
def small_{i}(k, h, y, y_new, rtol, atol):
    acc = 0.0
    for j in range(6):
        scale = atol[j] + max(abs(y[j]), abs(y_new[j])) * rtol
        acc += (k[0, j] * h / scale) ** 2
    return math.sqrt(acc / 6)
''', ns)
    f = numba.njit(ns[f"small_{i}"])
    a, y = np.ones((16, 6)), np.ones(6)
    small = Clock()
    with event.install_listener("numba:compile", small), event.install_listener("numba:llvm_lock", small):
        f(a, 0.1, y, y, 1e-10, y)
    alone.append([sum(own for kind, _, own in small.rows if kind == kind_) for kind_ in
                  ("numba:compile", "numba:llvm_lock")])


from phaseimpact import seed_parameters, simulate
p = seed_parameters(v=1.0, kappa=3e9)
clock, passes = Clock(), Clock()  # compiles less what nests in them; passes less what nests in them
t = time.perf_counter()
with event.install_listener("numba:compile", clock), event.install_listener("numba:llvm_lock", clock), \
        event.install_listener("numba:compile", passes), event.install_listener("numba:llvm_lock", passes), \
        event.install_listener("numba:run_pass", passes):
    simulate(p, "hunt-crossley", 2e-3)
total = time.perf_counter() - t
print(json.dumps({"warm_numba": warm_numba, "alone": alone, "total": total, "rows": clock.rows,
                  "passes": [(label, own) for kind, label, own in passes.rows if kind == "numba:run_pass"]}))
"""


#: A user's first call, timed from the import (``--against``), then a run that turns stiff (a tree
#: that compiles Radau only when a run needs it compiles it there): any tree with ``simulate``.
FIRST_CALL = r"""
import time
start = time.perf_counter()
from phaseimpact import seed_parameters, simulate
simulate(seed_parameters(v=1.0, kappa=3e9), "hunt-crossley", 2e-3)
first = time.perf_counter() - start
simulate(seed_parameters(v=6.35, kappa=1.6e14), "paper")
print(first, time.perf_counter() - start - first)
"""


def _cold_pair(trees: list[Path]) -> list[tuple[float, float, float]]:
    """The first call in each tree, cold, all started together, then the stiff run: (wall of the
    first call, wall of the stiff run, CPU time of the process) per tree."""
    with tempfile.TemporaryDirectory(prefix="numba-cold-") as cache:
        procs = []
        for i, root in enumerate(trees):
            env = {**os.environ, "PYTHONPATH": str(root), "NUMBA_CACHE_DIR": f"{cache}/{i}",
                   "PHASEIMPACT_COMPILE_PROCESSES": "1"}
            procs.append(subprocess.Popen([str(VENV_BIN / "python"), "-c", FIRST_CALL], env=env, cwd=root,
                                          text=True, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL))
        times = []
        for proc in procs:
            _, status, usage = os.wait4(proc.pid, 0)
            assert os.waitstatus_to_exitcode(status) == 0, f"the first call failed in {trees[len(times)]}"
            first, stiff = map(float, proc.stdout.read().split()[-2:])
            times.append((first, stiff, usage.ru_utime + usage.ru_stime))
            proc.stdout.close()
        return times


def against(tree: Path, pairs: int) -> int:
    """This checkout's first compile against ``tree``'s, ``pairs`` cold pairs side by side (which
    tree starts first alternates)."""
    here = Path(__file__).resolve().parent.parent
    start_load = load()
    rows, ratios, both = [], [], []
    for k in range(pairs):
        order = [tree, here] if k % 2 == 0 else [here, tree]
        measured = dict(zip(order, _cold_pair(order), strict=True))
        (before, before_stiff, before_cpu), (after, after_stiff, after_cpu) = measured[tree], measured[here]
        ratios.append(after / before)
        both.append((after + after_stiff) / (before + before_stiff))
        rows.append((k + 1, f"{before:.1f}", f"{after:.1f}", f"{after / before:.2f}", f"{before_stiff:.1f}",
                     f"{after_stiff:.1f}", f"{both[-1]:.2f}", f"{before_cpu:.1f}", f"{after_cpu:.1f}"))
        emit(f"pair {k + 1}: {before:.1f} s against {after:.1f} s; then a stiff run {before_stiff:.1f} s against "
             f"{after_stiff:.1f} s")
    end_load = load()
    text = (f"`{tree}` ({commit_of(tree)}, before) against this checkout ({commit_of(here)}, after): a user's first "
            "call (`simulate`, Hunt-Crossley, from the import) on an empty cache, compiled in one process, the two "
            f"trees' processes started together, {pairs} pairs; then, in the same process, a run that turns stiff "
            "(`paper`, v = 6.35 m/s, kappa = 1.6e14: what a tree that compiles Radau only when a run needs it "
            f"compiles there). Median after / before: **{statistics.median(ratios):.2f}** for the first call, "
            f"**{statistics.median(both):.2f}** for both.\n\n"
            + table(("pair", "first call before, wall [s]", "after [s]", "after / before", "then the stiff run, "
                     "before [s]", "after [s]", "both, after / before", "process before, CPU [s]",
                     "after, CPU [s]"), rows)
            + f"\n\n{start_load} at the start, {end_load} at the end. "
              "`python benchmarks/compile_profile.py --against TREE`")
    emit(text)
    save_section("compile_against", f"## The first compile, before and after\n\n{machine()}\n\n{text}")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="the same one cold process (for run_all)")
    ap.add_argument("--against", type=Path, help="another checkout to time the first compile against")
    ap.add_argument("--pairs", type=int, default=3, help="--against: cold pairs (default 3)")
    args = ap.parse_args(argv)
    if args.against is not None:
        return against(args.against.resolve(), args.pairs)
    start_load = load()
    emit("# Where the first compile goes\n")
    emit(machine())
    with tempfile.TemporaryDirectory(prefix="numba-cold-") as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        res = subprocess.run([str(VENV_BIN / "python"), "-c", PROBE], env=env, capture_output=True, text=True,
                             check=True)
    out = json.loads(res.stdout.strip().splitlines()[-1])
    compiles = [(label, own) for kind, label, own in out["rows"] if kind == "numba:compile"]
    llvm = sum(own for kind, _, own in out["rows"] if kind == "numba:llvm_lock")
    llvm_calls = sum(1 for kind, *_ in out["rows"] if kind == "numba:llvm_lock")
    numba_own = sum(own for _, own in compiles)
    alone_numba = statistics.median(numba_s for numba_s, _ in out["alone"])
    alone_llvm = statistics.median(llvm_s for _, llvm_s in out["alone"])
    by_function: dict[str, list[float]] = {}  # a function's own time of each of its compiles
    for label, own in compiles:
        by_function.setdefault(label.removeprefix("phaseimpact."), []).append(own)
    own_of = {name: sum(owns) for name, owns in by_function.items()}
    top = sorted(own_of, key=own_of.get, reverse=True)[:12]
    top_own = sum(own_of[name] for name in top)
    small = [own for own in own_of.values() if own < SMALL]
    modules: dict[str, list] = {}
    for name, owns in by_function.items():
        module = modules.setdefault(name.split(".<locals>")[0].rsplit(".", 1)[0], [0.0, 0])
        module[0] += own_of[name]
        module[1] += len(owns)
    by_module = sorted(modules.items(), key=lambda kv: -kv[1][0])
    end_load = load()
    rows = [("the call (simulate, Hunt-Crossley, on an empty cache)", f"{out['total']:.3g}", ""),
            ("numba's own work: typing and lowering, summed over the functions", f"{numba_own:.3g}",
             f"{len(compiles)} compiles of {len(by_function)} functions"),
            ("LLVM: optimisation and machine code", f"{llvm:.3g}", f"{llvm_calls} calls into LLVM"),
            (f"the {len(top)} functions with the most own work (below)", f"{top_own:.3g}",
             f"{top_own / numba_own:.0%} of numba's own work"),
            (f"the {len(small)} functions under {SMALL} s each", f"{sum(small):.3g}",
             f"{sum(small) / numba_own:.0%} of numba's own work"),
            ("a 6-line function compiled alone (plain numba.njit, with its wrapper for calls from Python): "
             "numba's own work, median of 5", f"{alone_numba:.3g}",
             "runs: " + ", ".join(f"{x:.3f}" for x, _ in out["alone"])
             + f"; LLVM for it (a whole library, optimised and emitted alone) {alone_llvm:.3g} s"),
            ("numba's own warm-up (its first compile in a process)", f"{out['warm_numba']:.3g}", "")]
    repeated = sorted((name, len(owns)) for name, owns in by_function.items() if len(owns) > 1)
    pass_own: dict[str, float] = {}
    for name, own in out["passes"]:
        pass_own[name] = pass_own.get(name, 0.0) + own
    passes = sorted(pass_own.items(), key=lambda kv: -kv[1])
    in_passes = sum(own for _, own in passes)
    pass_rows = [(f"`{name}`", f"{own:.2f}", f"{own / numba_own:.0%}") for name, own in passes[:PASSES]]
    others = in_passes - sum(own for _, own in passes[:PASSES])
    pass_rows.append((f"the other {len(passes) - PASSES} passes", f"{others:.2f}", f"{others / numba_own:.0%}"))
    pass_rows.append(("outside the passes (the dispatcher, caching the compiled code)",
                      f"{numba_own - in_passes:.2f}", f"{(numba_own - in_passes) / numba_own:.0%}"))
    text = (table(("what", "seconds", "note"), rows)
            + "\n\nCompiled more than once (once per set of argument types): "
            + (", ".join(f"`{name}` x{n}" for name, n in repeated) or "none") + "."
            + "\n\nThe functions with the most own compile time (typing and lowering, without what nests in "
              "them; LLVM's time is in its own row):\n\n"
            + table(("function", "own [s]", "compiles"),
                    [(f"`{name}`", f"{own_of[name]:.2f}", len(by_function[name])) for name in top])
            + "\n\nBy compiler pass (numba's `numba:run_pass` events; a pass's own time, without the compiles "
              "and the LLVM calls nested in it; shares of numba's own work):\n\n"
            + table(("pass", "own [s]", "share"), pass_rows)
            + "\n\nBy module (numba's own work; the stiff solver's steps, `integrate.radau5`, are compiled only once "
              "a run turns stiff, `integrate.api.radau_marker`: this call's never does):\n\n"
            + table(("module", "own [s]", "compiles"),
                    [(f"`{name}`", f"{own:.2f}", n) for name, (own, n) in by_module]))
    emit(f"\n{start_load} at the start, {end_load} at the end.\n")
    emit(text)
    save_section("compile_profile",
                 f"## Where the first compile goes\n\n{machine()}\n\n{start_load} at the start, {end_load} at the "
                 "end. `python benchmarks/compile_profile.py`\n\n" + text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
