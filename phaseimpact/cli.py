"""Command line: ``phaseimpact {params, simulate, critical, sweep, critical-curve}``.

A contract other tools rely on: SI units; ``--json`` prints one JSON object whose numbers are
finite or ``null``. Bad input prints one line naming the parameter, its value and the allowed
range, and exits with code 2.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys

import numpy as np

from . import __version__
from .analysis import classify_outcome, find_asymptotic_points
from .integrate import simulate
from .model import LAWS, ContactLaw
from .parameters import TARGETS, seed_parameters
from .quantities import impact_quantities

EXIT_USAGE = 2


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def _finite(value):
    """JSON-safe: non-finite numbers become null."""
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


def _print_json(obj) -> None:
    print(json.dumps(_finite(obj), allow_nan=False, indent=2))


def _law(args) -> ContactLaw:
    return ContactLaw(args.law, restitution=args.restitution)


def _params(args):
    return seed_parameters(v=args.v, kappa=args.kappa, target=getattr(args, "target", "plate"))


def cmd_params(args) -> None:
    p = _params(args)
    out = {k: getattr(p, k) for k in ("M1", "M2", "K", "Kb", "Km", "alpha", "kappa", "v")}
    if args.json:
        _print_json(out)
    else:
        for k, value in out.items():
            print(f"{k:>6} = {value:.6g}")


def cmd_simulate(args) -> None:
    law = _law(args)
    p = _params(args)
    trajectory = simulate(p, law, args.t_end, rtol=args.rtol)
    q = impact_quantities(trajectory)
    points = find_asymptotic_points(trajectory)
    outcome = classify_outcome(trajectory, points)
    out = {"law": law.name, "v": p.v, "kappa": law.kappa(p), "target": p.target,
           "status": trajectory.status, "message": trajectory.message, **q.as_dict(),
           "asymptotic_points": [{"delta": float(a), "deltadot": float(b), "dwell": float(d)}
                                 for (a, b), d in zip(points.points, points.dwell, strict=True)],
           "outcome": outcome.kind}
    if args.json:
        _print_json(out)
        return
    print(f"{law.name} on a {p.target} target, v = {p.v:g} m/s, kappa = {out['kappa']:.4g} N s/m^2.5")
    print(f"  status: {trajectory.status} ({trajectory.message})")
    units = {"max_force": "N", "max_indentation": "m", "contact_duration": "s", "restitution": "",
             "time_equal_displacement": "s", "dissipated_energy": "J", "loop_area": "J"}
    for k, u in units.items():
        value = out[k]
        print(f"  {k:<24} {'undefined' if value is None else f'{value:.6g} {u}'}")
    print(f"  outcome: {outcome.kind}; {outcome.message}")
    for (a, b), d in zip(points.points, points.dwell, strict=True):
        print(f"  asymptotic point delta = {a:.6g} m, deltadot = {b:.3g} m/s, dwell {d:.4g} s")


def cmd_critical(args) -> None:
    from .continuation import critical_damping

    law = _law(args)
    result = critical_damping(seed_parameters(v=args.v), law, rtol=args.rtol, kappa_min=args.kappa_min,
                              kappa_max=args.kappa_max, t_end=args.t_end, n_jobs=args.jobs)
    out = result.as_dict()
    if args.json:
        _print_json({k: out[k] for k in ("law", "v", "kappa_c", "bracket", "rtol", "n_below", "n_above",
                                         "status", "message")})
        return
    kc = "not found" if result.kappa_c is None else f"{result.kappa_c:.9g} N s/m^2.5"
    print(f"critical damping of {law.name} at v = {args.v:g} m/s: {kc}")
    print(f"  bracket {result.bracket[0]:.9g} .. {result.bracket[1]:.9g} (counts {result.n_below} / {result.n_above})")
    print(f"  {result.status}: {result.message}")


def cmd_sweep(args) -> None:
    from . import archive
    from .continuation import sweep

    if not args.kappa_min < args.kappa_max:
        raise ValueError(f"kappa-min = {args.kappa_min!r}, kappa-max = {args.kappa_max!r} are out of range; "
                         "allowed: 0 < kappa-min < kappa-max")
    kappas = np.geomspace(args.kappa_min, args.kappa_max, args.num)
    law = _law(args)
    params = seed_parameters(v=args.v)
    previous = None
    if args.resume and os.path.exists(args.out):
        previous = archive.load(args.out)
        if previous.law != law or previous.params != params.replace(kappa=previous.params.kappa):
            raise ValueError(f"resume: {args.out} holds a different law or parameters; remove it or drop --resume")
    elif os.path.exists(args.out) and not args.resume:
        pass  # overwritten atomically at the first checkpoint

    def checkpoint(result):
        archive.save(result, args.out)

    result = sweep(params, law, kappas, t_end=args.t_end, n_jobs=args.jobs, backend=args.backend,
                   scheduler=args.scheduler, rtol=args.rtol, progress=not args.no_progress,
                   previous=previous, on_chunk=checkpoint)
    archive.save(result, args.out)
    counts = np.unique(result.n_asymptotic, return_counts=True)
    summary = {"out": args.out, "points": len(kappas),
               "n_asymptotic": {int(k): int(n) for k, n in zip(*counts, strict=True)},
               "first_split": None if result.first_split() is None else
               [float(kappas[result.first_split()]), float(kappas[result.first_split() + 1])]}
    if args.json:
        _print_json(summary)
    else:
        print(f"wrote {args.out}: {summary}")


def cmd_critical_curve(args) -> None:
    from . import archive
    from .continuation import critical_curve

    if not 0 < args.v_min < args.v_max:
        raise ValueError(f"v-min = {args.v_min!r}, v-max = {args.v_max!r} are out of range; "
                         "allowed: 0 < v-min < v-max")
    law = _law(args)
    params = seed_parameters()
    speeds = np.geomspace(args.v_min, args.v_max, args.num)
    curve = critical_curve(params, law, speeds, rtol=args.rtol, t_end=args.t_end, progress=not args.no_progress)
    archive.save(curve, args.out, law=law, params=params, settings={"rtol": args.rtol, "t_end": args.t_end})
    if args.json:
        _print_json({"out": args.out, "v": speeds.tolist(), "kappa_c": curve.kappa_c.tolist()})
    else:
        for v, kc in zip(speeds, curve.kappa_c, strict=True):
            print(f"v = {v:8.4g} m/s   kappa_c = {kc:.9g}")
        print(f"wrote {args.out}")


def _number(name, *, positive=True):
    """argparse type: a finite number > 0 (or >= 0), the error naming ``name`` and the range."""
    allowed = "a finite number > 0" if positive else "a finite number >= 0"

    def parse(text):
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and (value > 0 if positive else value >= 0)):
            raise argparse.ArgumentTypeError(f"{name} = {text!r} is out of range; allowed: {allowed}")
        return value
    return parse


def _positive(name):
    return _number(name)


def _nonnegative(name):
    return _number(name, positive=False)


def _count(name, low=1):
    def parse(text):
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or value < low:
            raise argparse.ArgumentTypeError(f"{name} = {text!r} is out of range; allowed: an integer >= {low}")
        return value
    return parse


def _jobs(text):
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1 and value != -1:
        raise argparse.ArgumentTypeError(f"jobs = {text!r} is out of range; allowed: an integer >= 1, or -1")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="phaseimpact", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"phaseimpact {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    def common(p, kappa=True, speed=True):
        p.add_argument("--law", choices=LAWS, default="paper", help="contact law (default: paper)")
        p.add_argument("--restitution", type=_positive("restitution"), default=None,
                       help="coefficient of restitution in (0, 1] (restitution laws; exact inverse otherwise)")
        if speed:
            p.add_argument("--v", type=_positive("v"), default=1.0, help="impact speed, m/s (default 1)")
        if kappa:
            p.add_argument("--kappa", type=_nonnegative("kappa"), default=0.0, help="damping, N s/m^2.5")
        p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("params", help="the seed's derived parameters")
    p.add_argument("--v", type=_positive("v"), default=1.0)
    p.add_argument("--kappa", type=_nonnegative("kappa"), default=0.0)
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_params)

    p = sub.add_parser("simulate", help="one impact: summary quantities, asymptotic points, outcome")
    common(p)
    p.add_argument("--target", choices=TARGETS, default="plate")
    p.add_argument("--t-end", type=_positive("t-end"), default=0.01, help="horizon, s (default 0.01)")
    p.add_argument("--rtol", type=_positive("rtol"), default=1e-10)
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("critical", help="the critical damping kappa_c at one speed")
    common(p, kappa=False)
    p.add_argument("--rtol", type=_positive("rtol"), default=1e-6, help="relative width of kappa_c's bracket")
    p.add_argument("--kappa-min", type=_positive("kappa-min"), default=1e8)
    p.add_argument("--kappa-max", type=_positive("kappa-max"), default=1e15)
    p.add_argument("--t-end", type=_positive("t-end"), default=0.01)
    p.add_argument("--jobs", type=_jobs, default=1)
    p.set_defaults(func=cmd_critical)

    p = sub.add_parser("sweep", help="a kappa sweep archived to HDF5")
    common(p, kappa=False)
    p.add_argument("--kappa-min", type=_positive("kappa-min"), required=True)
    p.add_argument("--kappa-max", type=_positive("kappa-max"), required=True)
    p.add_argument("--num", type=_count("num", 2), default=50)
    p.add_argument("--t-end", type=_positive("t-end"), default=0.01)
    p.add_argument("--rtol", type=_positive("rtol"), default=1e-10)
    p.add_argument("--jobs", type=_jobs, default=1)
    p.add_argument("--backend", choices=("loky", "dask"), default="loky")
    p.add_argument("--scheduler", default=None, help="Dask scheduler address, e.g. tcp://host:8786")
    p.add_argument("--out", required=True, help="archive file (.h5)")
    p.add_argument("--resume", action="store_true", help="complete a partial archive without recomputing")
    p.add_argument("--no-progress", action="store_true")
    p.set_defaults(func=cmd_sweep)

    p = sub.add_parser("critical-curve", help="kappa_c against the impact speed, archived to HDF5")
    common(p, kappa=False, speed=False)
    p.add_argument("--v-min", type=_positive("v-min"), required=True)
    p.add_argument("--v-max", type=_positive("v-max"), required=True)
    p.add_argument("--num", type=_count("num", 1), default=5)
    p.add_argument("--rtol", type=_positive("rtol"), default=1e-6)
    p.add_argument("--t-end", type=_positive("t-end"), default=0.01)
    p.add_argument("--out", required=True)
    p.add_argument("--no-progress", action="store_true")
    p.set_defaults(func=cmd_critical_curve)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        args.func(args)
    except ValueError as error:
        print(f"phaseimpact: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("phaseimpact: interrupted", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
