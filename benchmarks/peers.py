"""Peer comparison: our compiled driver against heyoka (Taylor method, LLVM-compiled), in heyoka's
own venv.

What it measures
----------------
The work-precision problem of ``work_precision.py`` for Hunt-Crossley: seed case
(``seed_parameters(v=1, kappa=3e9)``), ``t_end = 2e-3`` s, no stop when settled (two contacts
and the flights after them), errors (a) of the max force (relative) and (b) of the state at
``t_end`` (positions over the Hertz indentation ``L``, velocities over ``v``), both against the
scipy oracle (``phaseimpact/_oracle.py``) at rtol 1e-13, the same reference as ``work_precision.py``.

- ours: ``simulate(params, "hunt-crossley", 2e-3, rtol=r, stop_when_settled=False)``, rtol
  1e-4..1e-13.
- heyoka, tol 1e-6..1e-15: dimensionless (``x / L``, ``v / v0``, ``tau = t v0 / L``, since its
  one tolerance is absolute for O(1) states) and with **runtime parameters** (``hy.par``: the
  damping ``b = kappa v0 L^1.5 / F`` and the plate's constants), so one compile serves every
  ``kappa``. Two integrators, switched at the events: the contact phase in the time
  transformation ``delta = w^2``, ``dt = w ds`` (``delta^1.5`` is singular at ``delta = 0`` for a
  Taylor method; in ``w`` the equations are polynomial, and a contact starts regularly at
  ``w = 0``), with a terminal event at ``w = 0`` (separation), one at ``tau = tau_end`` and a
  non-terminal one at ``dP/ds = 0`` (force peak, read on the dense output); the flight phase
  in ``tau`` with a terminal event at ``delta = 0`` (contact). Its one-off JIT build of both
  integrators is reported (cold: heyoka's in-memory and on-disk code caches off).

heyoka is a comparison only, never a dependency: the script installs it (with numpy, scipy and
phaseimpact in editable mode) into its own venv ``.venv-peers`` at the project root and re-runs
itself there (with its own ``NUMBA_CACHE_DIR``, so it never touches the project's numba cache).
If that fails or takes more than 10 minutes, it writes a "not available" section and exits 0.

Output: a printed table, ``benchmarks/results/peers.md`` and ``results/peers_points.json`` (the points
``work_precision.py`` draws in ``figures/work_precision.png``).

Run: ``python benchmarks/peers.py [--quick]``.
"""

from __future__ import annotations

import argparse
import json
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
T_END = 2e-3
KAPPA = 3e9
OURS_RTOLS = [10.0**-k for k in range(4, 14)]
HEYOKA_TOLS = [10.0**-k for k in range(6, 16)]
INSTALL_LIMIT = 600  # s
METHOD = "heyoka (Taylor, runtime parameters)"


# --------------------------------------------------------------------------------------------
# Bootstrap: a separate venv, then re-exec
# --------------------------------------------------------------------------------------------

def _not_available(reason: str) -> int:
    text = (f"## Peers: heyoka vs phaseimpact\n\nheyoka not available: {reason}\n\n"
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
        deadline = time.monotonic() + INSTALL_LIMIT
        for step in steps:
            try:
                rc = subprocess.call(step, timeout=max(1.0, deadline - time.monotonic()))
            except (OSError, subprocess.TimeoutExpired) as exc:
                rc = str(exc)
            if rc != 0:
                return _not_available(f"`{' '.join(step)}` failed ({rc})")
    env = {**os.environ, "PHASEIMPACT_PEERS": "1", "NUMBA_CACHE_DIR": str(VENV / "numba-cache")}
    return subprocess.call([str(VENV_PYTHON), __file__, *argv], env=env)


# --------------------------------------------------------------------------------------------
# The problem in heyoka
# --------------------------------------------------------------------------------------------

def scales(p):
    """Length ``L`` (the Hertz indentation, m), time ``L / v`` (s) and force ``M1 v^2 / L`` (N)."""
    L = p.hertz_indentation
    return L, L / p.v, p.M1 * p.v**2 / L


def runtime_parameters(p):
    """``[a, b, kb, km, mu, tau_end]`` of a case (``hy.par[0..5]``)."""
    L, T, F = scales(p)
    return [p.K * L**1.5 / F, p.kappa * p.v * L**1.5 / F, p.Kb * T**2 / p.M2, p.Km * L**2 * T**2 / p.M2, p.M1 / p.M2,
            T_END / T]


class PeakRecorder:
    """Callback of the force-peak event: keeps the dimensionless force at each peak (dense output)."""

    def __init__(self):
        self.found = []

    def __call__(self, ta, s, d_sgn):
        ta.update_d_output(s)
        w, _, v1, v2, _ = ta.d_output
        a, b = ta.pars[0], ta.pars[1]
        self.found.append((a + b * (v1 - v2)) * w**3)


class Heyoka:
    """The contact and flight integrators, compiled once for every case (runtime parameters)."""

    def __init__(self, tol):
        import heyoka as hy
        import numpy as np

        self.hy, self.np = hy, np
        a, b, kb, km, mu, tau_end = (hy.par[i] for i in range(6))
        w, X2, V1, V2, tau = hy.make_vars("w", "X2", "V1", "V2", "tau")
        DD = V1 - V2
        # products, not powers: heyoka's pow recurrence divides by the value, zero at a contact's start
        force = (a + b * DD) * (w * w * w)  # P / F with delta = w^2
        dV1 = -w * force
        dV2 = w * (mu * force - kb * X2 - km * (X2 * X2 * X2))
        contact = [(w, DD / 2), (X2, w * V2), (V1, dV1), (V2, dV2), (tau, w)]
        peak = b * w * (dV1 - dV2) + 1.5 * (a + b * DD) * DD  # dP/ds / (F w^2)
        X1, Y2, U1, U2 = hy.make_vars("X1", "Y2", "U1", "U2")
        flight = [(X1, U1), (Y2, U2), (U1, 0.0 * U1), (U2, -kb * Y2 - km * (Y2 * Y2 * Y2))]
        pars = [1.0] * 6

        def build():
            hy.llvm_state.clear_memcache()
            start = time.perf_counter()
            c = hy.taylor_adaptive(contact, [0.0] * 5, tol=tol, pars=pars,
                                   t_events=[hy.t_event(w, direction=hy.event_direction.negative),
                                             hy.t_event(tau - tau_end, direction=hy.event_direction.positive)],
                                   nt_events=[hy.nt_event(peak, PeakRecorder(),
                                                          direction=hy.event_direction.negative)])
            f = hy.taylor_adaptive(flight, [0.0] * 4, tol=tol, pars=pars[:4],  # it reads kb, km only
                                   t_events=[hy.t_event(X1 - Y2, direction=hy.event_direction.positive)])
            return c, f, time.perf_counter() - start

        disk = hy.llvm_state.get_diskcache_enabled()
        hy.llvm_state.set_diskcache_enabled(False)
        try:
            self.contact, self.flight, self.compile_time = build()
        finally:
            hy.llvm_state.set_diskcache_enabled(disk)
        self.peaks = self.contact.nt_events[0].callback
        self.order = self.contact.order

    def solve(self, p):
        """(max force N, state at t_end (x1, x2, v1, v2) in SI, steps) of case ``p`` from eq. 6."""
        np = self.np
        L, T, F = scales(p)
        pars = runtime_parameters(p)
        tau_end = pars[5]
        c, f = self.contact, self.flight
        c.pars[:] = pars
        f.pars[:] = pars[:4]
        self.peaks.found.clear()
        state = ("contact", 0.0, 1.0, 0.0, 0.0, 0.0)  # phase, X2 (w = 0 at a contact), V1, V2, tau, X1
        steps = 0
        for _ in range(1000):
            phase, X2, V1, V2, tau, X1 = state
            if phase == "contact":
                c.time = 0.0
                c.state[:] = [0.0, X2, V1, V2, tau]
                c.reset_cooldowns()
                out = c.propagate_until(1e30)
                steps += out[3]
                w, X2, V1, V2, tau = c.state
                if out[0] == self.hy.taylor_outcome(-1):  # separation
                    state = ("flight", X2, V1, V2, tau, X2)
                    continue
                final = np.array([X2 + w * w, X2, V1, V2])  # tau_end inside the contact
                break
            f.time = tau
            f.state[:] = [X1, X2, V1, V2]
            f.reset_cooldowns()
            out = f.propagate_until(tau_end)
            steps += out[3]
            X1, X2, V1, V2 = f.state
            if out[0] == self.hy.taylor_outcome(-1):  # a new contact
                state = ("contact", X2, V1, V2, float(f.time), X2)
                continue
            final = np.array([X1, X2, V1, V2])
            break
        else:
            raise RuntimeError("more than 1000 phases")
        max_force = max(self.peaks.found, default=0.0) * F
        return max_force, final * np.array([L, L, p.v, p.v]), steps


# --------------------------------------------------------------------------------------------
# Benchmark
# --------------------------------------------------------------------------------------------

def timed(fn, repeats):
    fn()  # warm-up
    times = []
    for _ in range(repeats):
        number, start = 0, time.perf_counter()
        while number == 0 or time.perf_counter() - start < 0.02:
            fn()
            number += 1
        times.append((time.perf_counter() - start) / number)
    return statistics.median(times)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="every other tolerance, 3 repeats")
    args = parser.parse_args(argv)
    if not os.environ.get("PHASEIMPACT_PEERS"):
        return bootstrap(sys.argv[1:])

    import heyoka as hy
    import numpy as np

    sys.path.insert(0, str(HERE))
    from _common import emit, load, machine, save_section, table

    from phaseimpact import seed_parameters, simulate
    from phaseimpact._oracle import oracle

    rtols, tols, repeats = OURS_RTOLS, HEYOKA_TOLS, 5
    if args.quick:
        rtols, tols, repeats = rtols[::2], tols[::2], 3
    start_load = load()
    p = seed_parameters(v=1.0, kappa=KAPPA)
    scale = np.array([p.hertz_indentation, p.hertz_indentation, p.v, p.v])
    emit(f"# Peers: phaseimpact vs heyoka {hy.__version__} ({LAW}, seed case, kappa = {KAPPA:g}, t_end = {T_END:g} s)")
    emit(machine())
    emit(start_load)

    def reference(q):
        ref = oracle(q, LAW, T_END, rtol=1e-13, settle=False)
        return ref.max_force, np.asarray(ref.final_state[:4])

    ref_force, ref_state = reference(p)

    def errors(force, state, rf=ref_force, rs=ref_state):
        return abs(force / rf - 1), float(np.max(np.abs(np.asarray(state) - rs) / scale))

    rows, points = [], []
    for r in rtols:
        def ours(r=r):
            tr = simulate(p, LAW, T_END, rtol=r, stop_when_settled=False)
            return tr.max_force, tr.final_state[:4], tr.nfev
        seconds = timed(ours, repeats)
        force, state, nfev = ours()
        err = errors(force, state)
        rows.append(["ours (compiled driver)", f"rtol={r:.0e}", f"{seconds * 1e3:.3g}", "-", f"nfev {nfev}", *err])
        points.append({"law": LAW, "method": "ours (compiled driver, peers venv)", "rtol": r, "time": seconds,
                       "errors": list(err)})
        emit(f"ours   rtol={r:.0e} {seconds * 1e3:8.3f} ms  errors {err[0]:.1e} {err[1]:.1e}")
    other = seed_parameters(v=1.0, kappa=1e11)
    other_ref = reference(other)
    for tol in tols:
        run = Heyoka(tol)
        seconds = timed(lambda run=run: run.solve(p), repeats)
        force, state, steps = run.solve(p)
        err = errors(force, state)
        f2, s2, _ = run.solve(other)  # the same compiled integrators, another kappa
        err2 = errors(f2, s2, *other_ref)
        rows.append(["heyoka", f"tol={tol:.0e}", f"{seconds * 1e3:.3g}", f"{run.compile_time * 1e3:.0f}",
                     f"order {run.order}, steps {steps}", *err])
        points.append({"law": LAW, "method": METHOD, "rtol": tol, "time": seconds, "errors": list(err),
                       "compile": run.compile_time, "kappa_1e11_errors": list(err2)})
        emit(f"heyoka tol={tol:.0e}  {seconds * 1e3:8.3f} ms  JIT {run.compile_time * 1e3:7.0f} ms  errors "
             f"{err[0]:.1e} {err[1]:.1e}; same build at kappa 1e11: {err2[0]:.1e} {err2[1]:.1e}")
    end_load = load()

    eq_rows = []
    for k, what in enumerate(("max force", "state at t_end")):
        for goal in (1e-6, 1e-8, 1e-10, 1e-12):
            best = {}
            for pt in points:
                if pt["errors"][k] <= goal and (pt["method"] not in best or pt["time"] < best[pt["method"]][0]):
                    best[pt["method"]] = (pt["time"], pt["rtol"])
            o, h = best.get("ours (compiled driver, peers venv)"), best.get(METHOD)
            eq_rows.append([what, f"{goal:.0e}", f"{o[0] * 1e3:.3g} (rtol {o[1]:.0e})" if o else "not reached",
                            f"{h[0] * 1e3:.3g} (tol {h[1]:.0e})" if h else "not reached",
                            f"{o[0] / h[0]:.2f}" if o and h else "-"])
    hy_points = [pt for pt in points if pt["method"] == METHOD]
    jit = [pt["compile"] for pt in hy_points]
    header = ["solver", "setting", "solve [ms]", "JIT build, cold [ms]", "work", "err max force", "err state(t_end)"]
    text = "\n".join([
        "## Peers: phaseimpact vs heyoka", "", machine() + f", heyoka {hy.__version__}", "",
        f"{start_load} at the start, {end_load} at the end. `python benchmarks/peers.py` (own venv `.venv-peers`)",
        "", f"{LAW}, seed case, kappa = {KAPPA:g}, v = 1 m/s, t_end = {T_END:g} s, no stop when settled. "
        "Reference: the scipy oracle at rtol 1e-13 (as in work_precision). heyoka takes the case as runtime "
        "parameters: one JIT build per tolerance serves every kappa (the same build at kappa = 1e11 is checked "
        "against the oracle there: "
        f"errors {hy_points[-1]['kappa_1e11_errors'][0]:.1e} (max force), {hy_points[-1]['kappa_1e11_errors'][1]:.1e} "
        f"(state) at tol {hy_points[-1]['rtol']:.0e}). Times: median "
        f"of {repeats}, each the mean of calls over 20 ms.", "",
        "At equal accuracy (fastest run reaching the target):", "",
        table(["error", "target", "ours [ms]", "heyoka [ms]", "ours / heyoka"], eq_rows), "",
        f"heyoka's cold JIT build of the two integrators: {min(jit) * 1e3:.0f}..{max(jit) * 1e3:.0f} ms per tolerance.",
        "", "Every run:", "", table(header, rows)])
    emit()
    emit(text)
    name = "peers" + args.quick * "_quick"
    save_section(name, text)
    (HERE / "results" / f"{name}_points.json").write_text(json.dumps(
        {"load": end_load, "points": hy_points}, indent=0) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
