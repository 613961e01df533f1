"""Stress matrix: extreme damping, speeds, mass and stiffness scales, long horizons, every law and
both readings of ``paper``.

Every case runs ``simulate`` (exact, summary, ``max_steps`` bounded) in-process and records
status, outcome, stop reason, message, energy ledger (dissipated / initial energy), nfev and
time. A non-success status is reported (with its message), never a NaN: exit code 1 if any case
raised or produced NaN/inf in ``max_force``, ``final_state`` or the dissipated energy.

    python benchmarks/stress.py [--quick] [--max-steps 200000]
"""

from __future__ import annotations

import argparse
import itertools
import sys
import time
import traceback
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import FIGURES, emit, load, machine, save_section, table  # noqa: E402

from phaseimpact import ContactLaw, seed_parameters, simulate  # noqa: E402
from phaseimpact.model import pack  # noqa: E402
from phaseimpact.model.rhs import energy, initial_state  # noqa: E402

#: (label, law); kappa is swept only for the laws that read it
LAWS = (("paper", ContactLaw("paper")), ("paper unilateral", ContactLaw("paper", contact="unilateral")),
        ("hunt-crossley", ContactLaw("hunt-crossley")), ("abrate", ContactLaw("abrate")),
        ("flores e=0.6", ContactLaw("flores", restitution=0.6)))
READS_KAPPA = ("paper", "paper unilateral", "hunt-crossley")
KAPPAS = (0.0, 1e9, 1e12, 1e15)
SPEEDS = (1e-3, 1.0, 300.0)
SCALES = (1e-4, 1e4)


def cases(quick: bool):
    """(law, kappa, v, mass scale, stiffness scale, t_end)."""
    if quick:
        return [(law, k, v, 1.0, 1.0, t) for law, k, v, t in itertools.product(("paper", "hunt-crossley"),
                                                                              (0.0, 1e12), (1.0, 300.0), (0.01, None))]
    out = []
    for law, _ in LAWS:
        kappas = KAPPAS if law in READS_KAPPA else (0.0,)
        some = (0.0, 1e12) if law in READS_KAPPA else (0.0,)
        out += [(law, k, v, 1.0, 1.0, t) for k, v, t in itertools.product(kappas, SPEEDS, (0.01, None))]
        out += [(law, k, 1.0, s, 1.0, 0.01) for k, s in itertools.product(some, SCALES)]
        out += [(law, k, 1.0, 1.0, s, 0.01) for k, s in itertools.product(some, SCALES)]
        out += [(law, k, v, 1.0, 1.0, 1.0) for k, v in ((0.0, 1.0), (1e9, 1.0), (1e12, 300.0))
                if law in READS_KAPPA or k == 0.0]
    return out


def run_case(law, kappa, v, ms, ks, t_end, max_steps):
    law = dict(LAWS)[law]
    base = seed_parameters(v=v)
    start = time.perf_counter()
    try:
        params = base.replace(kappa=kappa, M1=base.M1 * ms, M2=base.M2 * ms, K=base.K * ks, Kb=base.Kb * ks,
                              Km=base.Km * ks)
        tr = simulate(params, law, t_end, max_steps=max_steps)
    except Exception:  # noqa: BLE001 - every failure is reported in the table
        return {"failed": True, "time": time.perf_counter() - start, "status": "EXCEPTION", "outcome": "",
                "message": traceback.format_exc().strip().splitlines()[-1], "balance": float("nan"),
                "nfev": "", "max_force": float("nan"), "t_stop": float("nan")}
    wall = time.perf_counter() - start
    e0 = float(energy(law.code, pack(params, law), initial_state(params.v)))
    balance = tr.dissipated_energy / e0
    finite = np.isfinite(tr.max_force) and np.all(np.isfinite(tr.final_state)) and np.isfinite(balance)
    return {"failed": not finite, "time": wall, "status": tr.status, "outcome": f"{tr.outcome} ({tr.stop_reason})",
            "message": tr.message, "balance": balance, "nfev": tr.nfev, "max_force": tr.max_force,
            "t_stop": tr.t_stop}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="8 cases")
    ap.add_argument("--max-steps", type=int, default=200_000)
    args = ap.parse_args(argv)
    start_load = load()
    emit("# Stress matrix\n")
    emit(machine())
    emit(start_load + "\n")
    rows, failures = [], []
    todo = cases(args.quick)
    for i, (law, kappa, v, ms, ks, t_end) in enumerate(todo):
        r = run_case(law, kappa, v, ms, ks, t_end, args.max_steps)
        flag = "FAIL" if r["failed"] else ("ok" if r["status"] == "success" else "reported")
        rows.append((i, law, kappa, v, ms, ks, "until settled" if t_end is None else t_end, flag, r["status"],
                     r["outcome"], r["max_force"], r["balance"], r["t_stop"], r["nfev"], r["time"], r["message"]))
        if r["failed"]:
            failures.append(rows[-1])
        emit(f"[{i + 1}/{len(todo)}] {law} kappa={kappa:g} v={v:g} mass x{ms:g} stiff x{ks:g} t_end={t_end}: "
             f"{flag} {r['status']} ({r['time']:.2f} s) {r['message'][:150]}")
    header = ("#", "law", "kappa", "v [m/s]", "mass x", "stiffness x", "t_end [s]", "check", "status",
              "outcome (stop)", "max force [N]", "dissipated/E0", "t_stop [s]", "nfev", "time [s]", "message")
    text = table(header, rows)
    n_fail = len(failures)
    n_rep = sum(1 for r in rows if r[7] == "reported")
    summary = (f"{len(rows)} cases, max_steps = {args.max_steps}: {n_fail} FAIL (exception or non-finite), "
               f"{n_rep} with a reported non-success status, {len(rows) - n_fail - n_rep} success.")
    emit()
    emit(text)
    emit()
    emit(summary)
    end_load = load()
    md = (f"## Stress matrix\n\n{machine()}\n\n{start_load} at the start, {end_load} at the end. "
          f"`python benchmarks/stress.py`\n\n{summary}\n\n" + text)
    save_section("stress" + ("_quick" if args.quick else ""), md)
    if not args.quick:
        FIGURES.mkdir(exist_ok=True)
        (FIGURES / "stress.md").write_text(md + "\n")
    return 1 if n_fail else 0


if __name__ == "__main__":
    sys.exit(main())
