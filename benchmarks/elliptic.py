"""The flight's elliptic functions: ``phaseimpact/integrate/elliptic.py`` (plain arithmetic, CPU and
CUDA from one source) beside scipy's Cephes C code called as ``flight.py`` calls it (its
``cython_special`` entry points registered with llvmlite), on the flight's inputs.

For each of ``sn, cn, dn, phi`` (one call), ``F(phi | m)`` and ``K(m)``: the largest difference
from scipy's Python functions (relative to ``max(1, |value|)``), the share of results
bit-identical to them, and the time of one call from compiled code (a compiled loop over ``N``
random inputs; median over repeats, divided by ``N``), both implementations taking turns. The
table goes to ``benchmarks/results/elliptic.md``.
Inputs as a flight sees them: ``m`` uniform in ``(0, 1/2]`` (the Duffing plate's range),
``u`` uniform in ``[-50, 50]`` (a few periods from the flight's start), ``phi`` in ``(-pi, pi]``.

    python benchmarks/elliptic.py [--n 200000] [--repeats 7]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numba
import numpy as np
import scipy.special

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import emit, load, machine, save_section, table  # noqa: E402

from phaseimpact.integrate import elliptic, flight  # noqa: E402


def _loops(jacobi, first_kind, complete):
    """Compiled loops calling one implementation: each returns a sum, so nothing is optimised away."""

    @numba.njit
    def jacobi_loop(u, m, out):
        total = 0.0
        for i in range(u.size):
            jacobi(u[i], m[i], out)
            total += out[0] + out[1] + out[2] + out[3]
        return total

    @numba.njit
    def first_kind_loop(phi, m, _):
        total = 0.0
        for i in range(phi.size):
            total += first_kind(phi[i], m[i])
        return total

    @numba.njit
    def complete_loop(_, m, __):
        total = 0.0
        for i in range(m.size):
            total += complete(m[i])
        return total

    return {"sn, cn, dn, phi": jacobi_loop, "F(phi | m)": first_kind_loop, "K(m)": complete_loop}


def _values(jacobi, first_kind, complete, u, m, phi):
    """Each implementation's results, called from compiled code one input at a time."""

    @numba.njit
    def evaluate(u, m, phi, out):
        scratch = np.empty(4)
        for i in range(u.size):
            jacobi(u[i], m[i], scratch)
            out[i, :4] = scratch
            out[i, 4] = first_kind(phi[i], m[i])
            out[i, 5] = complete(m[i])

    out = np.empty((u.size, 6))
    evaluate(u, m, phi, out)
    return out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=200_000, help="inputs per timed loop")
    parser.add_argument("--repeats", type=int, default=7, help="timed repeats (median)")
    args = parser.parse_args(argv)
    for name in ("n", "repeats"):
        if getattr(args, name) < 1:
            parser.error(f"--{name} = {getattr(args, name)} is out of range; allowed: 1 or more")

    emit(machine())
    emit(load())
    rng = np.random.default_rng(7)
    n = args.n
    m = rng.uniform(0.0, 0.5, n)
    m[m == 0.0] = 0.25
    u = rng.uniform(-50.0, 50.0, n)
    phi = rng.uniform(-np.pi, np.pi, n)

    new = (elliptic.jacobi, elliptic.first_kind, elliptic.complete)
    cephes = (flight._jacobi, flight._first_kind, flight._complete)
    implementations = {"elliptic.py": new, "scipy (Cephes, as flight.py)": cephes}

    reference = np.column_stack([*scipy.special.ellipj(u, m), scipy.special.ellipkinc(phi, m),
                                 scipy.special.ellipk(m)])
    columns = {"sn, cn, dn, phi": slice(0, 4), "F(phi | m)": slice(4, 5), "K(m)": slice(5, 6)}
    accuracy = {}
    for label, functions in implementations.items():
        values = _values(*functions, u, m, phi)
        difference = np.abs(values - reference) / np.maximum(1.0, np.abs(reference))
        identical = values == reference
        for what, where in columns.items():
            accuracy[label, what] = (difference[:, where].max(axis=0), identical[:, where].mean(axis=0))

    loops = {label: _loops(*functions) for label, functions in implementations.items()}
    arguments = {"sn, cn, dn, phi": u, "F(phi | m)": phi, "K(m)": u}
    out = np.empty(4)
    times = {key: [] for key in accuracy}
    for label in loops:  # compile and warm up
        for what, loop in loops[label].items():
            loop(arguments[what], m, out)
    for _ in range(args.repeats):
        for what in columns:
            for label in loops:  # the two take turns: the shared machine's load hits both alike
                start = time.perf_counter()
                loops[label][what](arguments[what], m, out)
                times[label, what].append((time.perf_counter() - start) / n)

    rows = []
    for what in columns:
        base = statistics.median(times["scipy (Cephes, as flight.py)", what])
        for label in loops:
            largest, identical = accuracy[label, what]
            per_call = statistics.median(times[label, what])
            rows.append([what, label, f"{per_call * 1e9:.1f}", f"{per_call / base:.2f}",
                         " / ".join(f"{x:.1e}" for x in largest), " / ".join(f"{x:.3f}" for x in identical)])
    text = "\n".join([
        "## The flight's elliptic functions: elliptic.py and scipy's Cephes (`benchmarks/elliptic.py`)", "",
        machine(), "", f"{n} inputs: m in (0, 1/2], u in [-50, 50], phi in (-pi, pi]; median of {args.repeats} "
        f"repeats; {load()} at the end", "",
        table(["function", "implementation", "ns per call", "time / scipy's",
               "largest difference from scipy (relative to max(1, abs(value)))", "bit-identical share"], rows)])
    emit()
    emit(text)
    save_section("elliptic", text)


if __name__ == "__main__":
    main()
