"""Peer comparison: phaseimpact's exact integrator against heyoka (Taylor method, LLVM-compiled).

What it measures
----------------
The first contact of the seed case under the smooth Hunt-Crossley law (``seed_parameters(v=1,
kappa=3e9)``), from ``t = 0`` (``delta = 0``, ``x1dot = v``) to separation (``delta`` back to 0)::

    P = (K + kappa (v1 - v2)) delta^1.5,   M1 x1'' = -P,   M2 x2'' = -Kb x2 - Km x2^3 + P.

For every tolerance and integrator: the separation time, the maximum contact force, the state at
separation, their errors against a reference (separation time and max force relative; positions
relative to the Hertz indentation ``L = (5 M1 v^2 / (4 K))^(2/5)``, velocities relative to ``v``),
and the wall time of one solve (median of 5 after a warm-up). For heyoka also the one-off JIT cost
of building ``taylor_adaptive`` (LLVM in-memory cache cleared first).

- ours: ``phaseimpact.simulate(..., stop_on=("separation",))`` over rtol 1e-4..1e-12, and
  ``simulate_batch([p], ...)`` (it has no ``stop_on``: it runs on to ``t_end = 2e-4`` s, before
  the next contact, and the separation is read from its event).
- heyoka: the same equations made dimensionless (``x / L``, ``v / v0``, ``t v0 / L``, since its
  single tolerance is absolute for O(1) states), a terminal event on ``delta`` (direction
  negative) and a non-terminal event on ``dP/dt = 0`` (direction negative) for the force peak,
  over tol 1e-6..1e-15. ``delta^1.5`` is singular at ``delta = 0`` for a Taylor method (its
  derivatives there are infinite), so heyoka starts at ``t0 = 1e-6 L / v0``, from the leading
  term of the series of the solution at ``t = 0`` (whose error there is ~1e-20 of the scales).
- references: ours at rtol 1e-13, heyoka at tol 1e-16, and heyoka in extended precision
  (``long double``, tol 1e-19); errors are taken against heyoka at 1e-16.

heyoka is a comparison only, never a dependency: the script installs it (with numpy, scipy and
phaseimpact in editable mode) into its own venv ``.venv-peers`` at the project root and re-runs
itself there. If that fails, it writes a "not available" section and exits 0.

Output: a printed table and ``benchmarks/results/peers.md``.

Run: ``python benchmarks/peers.py [--quick]``.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
VENV = ROOT / ".venv-peers"
VENV_PYTHON = VENV / "bin" / "python"
LAW = "hunt-crossley"
T_END = 2e-4
TAU0 = 1e-6  # heyoka's start, in units of L / v0
OURS_RTOLS = [10.0**-k for k in range(4, 13)]
HEYOKA_TOLS = [10.0**-k for k in range(6, 16)]
REPEATS = 5


# --------------------------------------------------------------------------------------------
# Bootstrap: a separate venv, then re-exec
# --------------------------------------------------------------------------------------------

def _not_available(reason: str) -> int:
    text = (f"# Peers: heyoka vs phaseimpact\n\nheyoka not available: {reason}\n\n"
            "Nothing was measured. `python benchmarks/peers.py` installs heyoka into `.venv-peers`; "
            "it needs the package registry.")
    print(text)
    (HERE / "results").mkdir(exist_ok=True)
    (HERE / "results" / "peers.md").write_text(text + "\n")
    return 0


def bootstrap(argv) -> int:
    """Create or reuse ``.venv-peers`` with heyoka, then run this script inside it."""
    probe = [str(VENV_PYTHON), "-c", "import heyoka, numpy, scipy, phaseimpact"]
    if not (VENV_PYTHON.exists() and subprocess.call(probe, stderr=subprocess.DEVNULL) == 0):
        print(f"setting up {VENV} (heyoka, numpy, scipy, phaseimpact -e) ...", flush=True)
        steps = [[sys.executable, "-m", "venv", str(VENV)],
                 [str(VENV_PYTHON), "-m", "pip", "install", "-q", "heyoka", "numpy", "scipy"],
                 [str(VENV_PYTHON), "-m", "pip", "install", "-q", "-e", str(ROOT)]]
        for step in steps:
            try:
                rc = subprocess.call(step)
            except OSError as exc:
                rc = str(exc)
            if rc != 0:
                return _not_available(f"`{' '.join(step)}` failed ({rc})")
    env = {**os.environ, "PHASEIMPACT_PEERS": "1"}
    return subprocess.call([str(VENV_PYTHON), __file__, *argv], env=env)


# --------------------------------------------------------------------------------------------
# The problem in heyoka
# --------------------------------------------------------------------------------------------

def scales(p):
    """Hertz indentation ``L`` (m), time ``L / v`` (s) and force ``M1 v^2 / L`` (N)."""
    L = (5 * p.M1 * p.v**2 / (4 * p.K)) ** 0.4
    return L, L / p.v, p.M1 * p.v**2 / L


class HeyokaRun:
    """A compiled heyoka integrator of the first contact, reusable across solves.

    Dimensionless state ``(X1, X2, V1, V2) = (x1 / L, x2 / L, v1 / v, v2 / v)`` in time
    ``tau = t v / L``; contact force ``p = P / F`` with ``F = M1 v^2 / L``.
    """

    def __init__(self, p, tol, fp_type=None):
        import heyoka as hy
        import numpy as np

        self.np, self.fp = np, fp_type or np.float64
        self.L, self.T, self.F = scales(p)
        X1, X2, V1, V2 = hy.make_vars("X1", "X2", "V1", "V2")
        a = p.K * self.L**1.5 / self.F  # = 5/4 by the choice of L
        b = p.kappa * p.v * self.L**1.5 / self.F
        kb, km, mu = p.Kb * self.T**2 / p.M2, p.Km * self.L**2 * self.T**2 / p.M2, p.M1 / p.M2
        self.a, self.b, self.kb, self.km, self.mu = a, b, kb, km, mu
        D, DD = X1 - X2, V1 - V2
        force = (a + b * DD) * D * hy.sqrt(D)
        A1, A2 = -force, -kb * X2 - km * X2**3 + mu * force
        # dp/dtau / sqrt(D): zero at the force peak, falling through it
        peak = b * (A1 - A2) * D + 1.5 * (a + b * DD) * DD
        long = self.fp is not np.float64
        t_event, nt_event = (hy.t_event_ldbl, hy.nt_event_ldbl) if long else (hy.t_event, hy.nt_event)
        kw = {"fp_type": self.fp} if long else {}
        self.y0 = self.initial_state(TAU0)
        sys_ = [(X1, V1), (X2, V2), (V1, A1), (V2, A2)]
        t_events = [t_event(D, direction=hy.event_direction.negative)]
        nt_events = [nt_event(peak, PeakRecorder(a, b), direction=hy.event_direction.negative)]

        def build():
            hy.llvm_state.clear_memcache()
            start = time.perf_counter()
            ta = hy.taylor_adaptive(sys_, self.y0.copy(), time=self.fp(TAU0), tol=self.fp(tol),
                                    t_events=t_events, nt_events=nt_events, **kw)
            return ta, time.perf_counter() - start

        # cold JIT: neither the in-memory nor heyoka's on-disk (~/.cache/heyoka) code cache used
        disk = hy.llvm_state.get_diskcache_enabled()
        hy.llvm_state.set_diskcache_enabled(False)
        self.ta, self.compile_time = build()
        # warm: the compiled code found in the on-disk cache (a later process, same tol and parameters)
        hy.llvm_state.set_diskcache_enabled(True)
        build()
        self.cached_build_time = build()[1]
        hy.llvm_state.set_diskcache_enabled(disk)
        self.hy = hy
        self.peaks = self.ta.nt_events[0].callback  # heyoka keeps a deep copy of the callback

    def initial_state(self, tau):
        """Leading term of the solution's series at ``tau = 0`` (next terms are ~tau^2.5 smaller)."""
        c = (self.a + self.b) * tau**2.5
        return self.np.array([tau - c * tau / 8.75, self.mu * c * tau / 8.75, 1 - c / 2.5, self.mu * c / 2.5],
                             dtype=self.fp)

    def force(self, y):
        return self.peaks.force(y)

    def solve(self):
        """Separation time (s), max force (N), dimensionless state at separation, steps."""
        ta = self.ta
        ta.time = self.fp(TAU0)
        ta.state[:] = self.y0
        ta.reset_cooldowns()
        self.peaks.found.clear()
        outcome = ta.propagate_until(self.fp(1e3))
        if outcome[0] != self.hy.taylor_outcome(-1):
            raise RuntimeError(f"heyoka stopped without separation: {outcome[0]}")
        y = ta.state.copy()
        p_max = max([self.force(y), *(f for _, f in self.peaks.found)])
        return float(ta.time) * self.T, float(p_max) * self.F, y.astype(float), int(outcome[3])


class PeakRecorder:
    """Callback of the force-peak event: keeps ``(tau, p)`` at each peak (dense output of the step)."""

    def __init__(self, a, b):
        self.a, self.b, self.found = a, b, []

    def force(self, y):
        D, DD = y[0] - y[1], y[2] - y[3]
        return (self.a + self.b * DD) * D * max(D, 0) ** 0.5

    def __call__(self, ta, tau, d_sgn):
        ta.update_d_output(tau)
        self.found.append((tau, self.force(ta.d_output.copy())))


# --------------------------------------------------------------------------------------------
# Ours
# --------------------------------------------------------------------------------------------

def ours(p, rtol, batch=False):
    """Same outputs as :meth:`HeyokaRun.solve` from phaseimpact (``simulate`` or ``simulate_batch``)."""
    import numpy as np

    from phaseimpact import simulate
    from phaseimpact.integrate import simulate_batch

    if batch:
        tr = simulate_batch([p], LAW, T_END, rtol=rtol)[0]
    else:
        tr = simulate(p, LAW, t_end=T_END, rtol=rtol, stop_on=("separation",))
    seps = tr.events_of("separation")
    if not tr.ok or not seps:
        raise RuntimeError(f"{tr.status}: {tr.message}")
    if not batch and tr.t_stop != seps[0].t:
        raise RuntimeError("simulate did not stop at the first separation")
    L, _, _ = scales(p)
    return seps[0].t, tr.max_force, seps[0].state[:4] / np.array([L, L, p.v, p.v]), tr.nfev


def timed(fn, repeats=REPEATS):
    fn()  # warm-up
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def errors(result, ref):
    """Relative errors of separation time and max force, scaled error of the separation state."""
    import numpy as np

    t, f, y = result[:3]
    return abs(t / ref[0] - 1), abs(f / ref[1] - 1), float(np.max(np.abs(np.asarray(y) - ref[2])))


# --------------------------------------------------------------------------------------------
# Benchmark
# --------------------------------------------------------------------------------------------

def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer tolerances, one repeat (no waiting)")
    args = parser.parse_args(argv)
    if not os.environ.get("PHASEIMPACT_PEERS"):
        return bootstrap(sys.argv[1:])

    import heyoka as hy
    import numpy as np

    sys.path.insert(0, str(HERE))
    from _common import emit, machine, save_section, table

    from phaseimpact import seed_parameters

    global REPEATS
    rtols, tols = OURS_RTOLS, HEYOKA_TOLS
    if args.quick:
        rtols, tols, REPEATS = rtols[::4], tols[::3], 1
    p = seed_parameters(v=1.0, kappa=3e9)
    L, T, _ = scales(p)
    lines = ["# Peers: phaseimpact vs heyoka (first Hunt-Crossley contact)", "",
             machine() + f", heyoka {hy.__version__}", "",
             f"Seed case, v = {p.v} m/s, kappa = {p.kappa:.3g}; L = {L:.6g} m, L/v = {T:.6g} s. "
             "Errors: separation time and max force relative; state = max over (x1, x2)/L, (v1, v2)/v.", ""]

    # references (no timing)
    ref_ours = ours(p, 1e-13)
    ref_hy = HeyokaRun(p, 1e-16).solve()
    ref_ld = HeyokaRun(p, 1e-19, fp_type=np.longdouble).solve()
    ref_rows = [["ours rtol=1e-13 vs heyoka tol=1e-16", *errors(ref_ours, ref_hy)],
                ["heyoka long double tol=1e-19 vs heyoka tol=1e-16", *errors(ref_ld, ref_hy)],
                ["ours rtol=1e-13 vs heyoka long double", *errors(ref_ours, ref_ld)]]
    lines += ["## References", "",
              f"heyoka tol=1e-16: separation at {ref_hy[0]!r} s, max force {ref_hy[1]!r} N.", "",
              table(["pair", "t_sep", "max force", "state"], ref_rows), ""]
    emit("\n".join(lines))

    note = "run alone on the machine (other jobs disturb the timings)"

    rows, runs = [], []  # runs: (solver, setting, seconds, max error)
    for r in rtols:
        for batch in (False, True):
            name = "ours simulate_batch" if batch else "ours simulate"
            res = ours(p, r, batch)
            seconds = timed(lambda r=r, batch=batch: ours(p, r, batch))
            err = errors(res, ref_hy)
            rows.append([name, f"rtol={r:.0e}", seconds * 1e3, "", f"nfev {res[3]}", *err])
            runs.append((name, f"rtol={r:.0e}", seconds, max(err), 0.0))
            emit(f"{name:20s} rtol={r:.0e}  {seconds * 1e3:8.2f} ms  errors {err[0]:.1e} {err[1]:.1e} {err[2]:.1e}")
    for tol in tols:
        run = HeyokaRun(p, tol)
        res = run.solve()
        seconds = timed(run.solve)
        err = errors(res, ref_hy)
        rows.append(["heyoka", f"tol={tol:.0e}", seconds * 1e3,
                     f"{run.compile_time * 1e3:.0f} ({run.cached_build_time * 1e3:.1f})",
                     f"order {run.ta.order}, steps {res[3]}", *err])
        runs.append(("heyoka", f"tol={tol:.0e}", seconds, max(err), run.compile_time))
        emit(f"{'heyoka':20s} tol={tol:.0e}   {seconds * 1e3:8.2f} ms  JIT {run.compile_time * 1e3:7.1f} ms  "
             f"errors {err[0]:.1e} {err[1]:.1e} {err[2]:.1e}")

    header = ["solver", "setting", "solve, ms", "JIT build, ms (disk-cached)", "work", "err t_sep", "err max force",
              "err state"]
    lines = ["## Work and precision", "", f"Timings: median of {REPEATS} after a warm-up; {note}.", "",
             table(header, rows), ""]

    # equal accuracy: the fastest run of each solver whose worst error meets the target
    floor = max(errors(ref_ld, ref_hy))  # how well the heyoka reference itself is known
    eq_rows = []
    for target in (1e-4, 1e-6, 1e-8, 1e-10, 1e-12):
        best = {}
        for solver, setting, seconds, err, jit in runs:
            if err <= target and (solver not in best or seconds < best[solver][1]):
                best[solver] = (setting, seconds, jit)
        cell = {s: f"{b[1] * 1e3:.3g} ms ({b[0]})" if b else "not reached"
                for s in ("ours simulate", "ours simulate_batch", "heyoka") for b in [best.get(s)]}
        ratio = breakeven = float("nan")
        if "ours simulate" in best and "heyoka" in best:
            (_, t_ours, _), (_, t_hy, t_jit) = best["ours simulate"], best["heyoka"]
            ratio, breakeven = t_ours / t_hy, t_jit / (t_ours - t_hy)
        eq_rows.append([f"{target:.0e}" + (" (below reference spread)" if target < floor else ""),
                        cell["ours simulate"], cell["ours simulate_batch"], cell["heyoka"], ratio, breakeven])
    lines += ["## At equal accuracy", "",
              "Fastest run of each solver whose worst error (of the three columns above) meets the target.", "",
              table(["worst error <=", "ours simulate", "ours simulate_batch", "heyoka", "ours / heyoka",
                     "break-even solves (JIT included)"], eq_rows),
              ""]
    jit = [r[4] * 1e3 for r in runs if r[0] == "heyoka"]
    ratios = [rw[4] for rw in eq_rows if rw[4] == rw[4]]
    breakevens = [rw[5] for rw in eq_rows if rw[5] == rw[5]]
    if ratios:
        faster = "heyoka" if statistics.median(ratios) > 1 else "ours (simulate)"
        lines += [f"**Conclusion.** At equal accuracy {faster} is faster: ours/heyoka time ratio "
                  f"{min(ratios):.3g}..{max(ratios):.3g} over the targets reached by both. "
                  f"heyoka's one-off JIT build of `taylor_adaptive` costs {min(jit):.0f}..{max(jit):.0f} ms "
                  "(cold; it grows with the Taylor order, i.e. with the tolerance, and is paid again for "
                  "every parameter set, as the constants are compiled in; a few ms when heyoka's on-disk code "
                  "cache has it): about "
                  f"{min(breakevens):.1f}..{max(breakevens):.1f} of our solves, so heyoka wins, JIT included, "
                  f"from {math.ceil(max(breakevens))} solves of the same compiled integrator on.", ""]
    text = "\n".join(lines)
    emit(text)
    if not args.quick:
        save_section("peers", "\n".join(["# Peers: phaseimpact vs heyoka (first Hunt-Crossley contact)", "",
                                         machine() + f", heyoka {hy.__version__}", "", note, "",
                                         "## References", "",
                                         f"heyoka tol=1e-16: separation at {ref_hy[0]!r} s, "
                                         f"max force {ref_hy[1]!r} N.", "",
                                         table(["pair", "t_sep", "max force", "state"], ref_rows), "", text]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
