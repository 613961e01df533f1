"""Command line: ``phaseimpact {params, simulate, critical, sweep, critical-curve}``.

A contract other tools rely on: SI units; ``--json`` prints one JSON object whose numbers are
finite or ``null``. Every argument is checked before any work: bad input prints one line naming
the parameter, its value and the allowed range, and exits with code 2 (no traceback). A run that
ends in a numerical failure (a sweep point, a trajectory) is reported and exits with code 1.
Ctrl-C exits with code 130 (a sweep says how to resume).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import math
import os
import re
import shlex
import sys

import numpy as np

from . import __version__
from ._atomic import check_target, exclusive
from .integrate import RTOL_RANGE
from .model import LAWS
from .parameters import TARGETS

EXIT_OK, EXIT_FAILURE, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130

#: Impact speeds the model is meant for, m/s (quasi-static to far beyond any Hertz contact).
V_RANGE = (1e-6, 1e4)
#: Largest damping coefficient, N s/m^2.5 (the seed's kappa_c is about 1.5e12).
KAPPA_MAX = 1e18
#: Relative width of kappa_c's bracket (critical, critical-curve).
KAPPA_RTOL_RANGE = (1e-14, 1e-2)
#: Coefficient of restitution.
RESTITUTION_RANGE = (1e-6, 1.0)
#: Points of one sweep: its columns (about 200 bytes a point) stay in memory.
MAX_SWEEP_POINTS = 10_000_000
#: Speeds of one critical curve (each is a kappa_c search).
MAX_CURVE_POINTS = 1000
MAX_JOBS = 4 * (os.cpu_count() or 1)
BACKENDS = ("threads", "loky", "dask")
#: Seconds to wait for a Dask scheduler before giving up.
SCHEDULER_TIMEOUT = 5.0
#: Statuses of critical_damping that are answers (anything else is a failure: exit 1).
CRITICAL_ANSWERS = ("success", "not-found", "unconfirmed")


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        choice = re.fullmatch(r"(argument (\S+)): invalid choice: (.*) \(choose from (.*)\)", message)
        if choice:  # the same wording as every other range message
            label, option, value, allowed = choice.groups()
            message = f"{label}: {option.lstrip('-')} = {value} is out of range; allowed: one of {allowed}"
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


# ------------------------------------------------------------------------------------------------
# Argument types: each names the parameter, its value and the allowed range
# ------------------------------------------------------------------------------------------------

def _out_of_range(name, text, allowed):
    return argparse.ArgumentTypeError(f"{name} = {text!r} is out of range; allowed: {allowed}")


def _real(name, low=None, high=None, *, low_open=False, unit=""):
    """argparse type: a finite number within ``[low, high]`` (``(low, high]`` if ``low_open``)."""
    if low is None:
        allowed = "a finite number"
    elif high is None:
        allowed = f"a finite number {'>' if low_open else '>='} {low:g}"
    else:
        allowed = f"{low:g} {'<' if low_open else '<='} {name} <= {high:g}"
    allowed += f" ({unit})" if unit else ""

    def parse(text):
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        ok = math.isfinite(value)
        if ok and low is not None:
            ok = value > low if low_open else value >= low
        if ok and high is not None:
            ok = value <= high
        if not ok:
            raise _out_of_range(name, text, allowed)
        return value
    parse.__name__ = name  # argparse names the type in some messages
    return parse


def _integer(name, low, high):
    allowed = f"an integer {low} <= {name} <= {high}"

    def parse(text):
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and value == int(value) and low <= value <= high):
            raise _out_of_range(name, text, allowed)
        return int(value)
    parse.__name__ = name
    return parse


def _jobs(text):
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value == int(value) and (value == -1 or 1 <= value <= MAX_JOBS)):
        raise _out_of_range("jobs", text, f"an integer 1 <= jobs <= {MAX_JOBS} (4 per core), or -1 for all cores")
    return int(value)


def _path(name):
    def parse(text):
        try:
            return check_target(text, name)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None
    parse.__name__ = name
    return parse


_V = _real("v", *V_RANGE, unit="m/s")
_KAPPA = _real("kappa", 0.0, KAPPA_MAX, unit="N s/m^2.5")
_T_END = _real("t-end", 0.0, low_open=True, unit="s")
_RTOL = _real("rtol", *RTOL_RANGE)
_KAPPA_RTOL = _real("kappa-rtol", *KAPPA_RTOL_RANGE)
_RESTITUTION = _real("restitution", *RESTITUTION_RANGE)


# ------------------------------------------------------------------------------------------------
# Output
# ------------------------------------------------------------------------------------------------

def _finite(value):
    """JSON-safe: non-finite numbers become null, NumPy scalars plain numbers."""
    if isinstance(value, dict):
        return {str(k): _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_finite(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


def _print_json(obj) -> None:
    print(json.dumps(_finite(obj), allow_nan=False, indent=2))


def _note(text: str) -> None:
    """A progress note for people: only when stderr is a terminal."""
    if sys.stderr.isatty():
        print(f"phaseimpact: {text}", file=sys.stderr, flush=True)


def _fmt(value, unit="", spec=".6g"):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "undefined"
    return f"{value:{spec}}{' ' + unit if unit else ''}"


# ------------------------------------------------------------------------------------------------
# Checks shared by the commands (all before any work)
# ------------------------------------------------------------------------------------------------

def _law(args):
    from .model import REGISTRY, ContactLaw

    RESTITUTION_LAWS = [name for name, entry in REGISTRY.items() if entry.damping == "restitution"]

    restitution = getattr(args, "restitution", None)
    if restitution is not None and args.law == "abrate":
        raise ValueError(f"restitution = {restitution!r} is not read by law 'abrate' (undamped Hertz contact); "
                         "allowed: --restitution with hunt-crossley or a restitution law")
    if restitution is None and args.law in RESTITUTION_LAWS:
        lo, hi = RESTITUTION_RANGE
        raise ValueError(f"restitution = None is out of range for law {args.law!r} (its only damping); allowed: "
                         f"--restitution E with {lo:g} <= E <= {hi:g}")
    law = ContactLaw(args.law, restitution=restitution, contact=getattr(args, "contact", None) or "printed")
    kappa = getattr(args, "kappa", None)
    if kappa is not None and not law.reads("kappa"):
        source = "its damping comes from the restitution" if law.damping_source == "restitution" else "it is undamped"
        raise ValueError(f"kappa = {kappa!r} is not read by law {law.label()!r} ({source}); allowed: "
                         + ("--kappa or --restitution, not both" if restitution is not None
                            else "--kappa with paper or hunt-crossley"))
    return law


def _contact_given(args):
    if getattr(args, "contact", None) is not None and args.law != "paper":
        raise ValueError(f"contact = {args.contact!r} is not read by law {args.law!r}; allowed: --contact with "
                         "law paper")


def _params(args, **overrides):
    from .parameters import seed_parameters

    kappa = getattr(args, "kappa", None)
    settings = {"v": getattr(args, "v", 1.0), "kappa": 0.0 if kappa is None else kappa}
    if getattr(args, "target", None) is not None:
        settings["target"] = args.target
    settings.update(overrides)
    return seed_parameters(**settings)


def _check_scheduler(address: str) -> None:
    """Refuse an address where no Dask scheduler answers, within :data:`SCHEDULER_TIMEOUT` s."""
    try:
        from distributed.core import rpc
    except ImportError:
        raise ValueError("backend = 'dask' needs dask.distributed: pip install 'phaseimpact[dask]'") from None

    async def identity():
        remote = rpc(address, timeout=SCHEDULER_TIMEOUT)
        try:
            return await asyncio.wait_for(remote.identity(), SCHEDULER_TIMEOUT)
        finally:
            await remote.close_rpc()

    try:
        answer = asyncio.run(identity())
    except Exception as error:  # any failure to talk to it means: not a usable scheduler
        reason = str(error) or f"no answer within {SCHEDULER_TIMEOUT:g} s"
        raise ValueError(f"scheduler = {address!r} is out of reach ({type(error).__name__}: {reason}); "
                         "allowed: the address of a running Dask scheduler, e.g. tcp://host:8786") from None
    if not (isinstance(answer, dict) and answer.get("type") == "Scheduler"):
        raise ValueError(f"scheduler = {address!r} is out of range: it answers, but is not a Dask scheduler")


# ------------------------------------------------------------------------------------------------
# Commands
# ------------------------------------------------------------------------------------------------

def cmd_params(args) -> int:
    p = _params(args)
    out = {k: getattr(p, k) for k in ("M1", "M2", "K", "Kb", "Km", "alpha", "kappa", "v")}
    if args.json:
        _print_json(out)
    else:
        units = {"M1": "kg", "M2": "kg", "K": "N/m^1.5", "Kb": "N/m", "Km": "N/m^3", "alpha": "",
                 "kappa": "N s/m^2.5", "v": "m/s"}
        for k, value in out.items():
            print(f"{k:>6} = {value:.6g} {units[k]}".rstrip())
    return EXIT_OK


def cmd_simulate(args) -> int:
    from .integrate import simulate
    from .quantities import impact_quantities

    _contact_given(args)
    law = _law(args)
    p = _params(args)
    horizon = "until the outcome settles" if args.t_end is None else f"to t = {args.t_end:g} s"
    _note(f"integrating {law.label()} at v = {p.v:g} m/s {horizon} (the first run compiles the engine)")
    trajectory = simulate(p, law, args.t_end, rtol=args.rtol)
    q = impact_quantities(trajectory)
    t_stick, delta_stick, dwell = trajectory.stick_points()
    out = {"law": law.name, "contact": law.contact, "v": p.v, "kappa": law.kappa(p), "target": p.target,
           "status": trajectory.status, "stop_reason": trajectory.stop_reason, "message": trajectory.message,
           "t_end": trajectory.t_end, "t_stop": trajectory.t_stop, **q.as_dict(),
           "n_stick": trajectory.n_stick, "t_run": trajectory.t_run, "cut": trajectory.cut,
           "stick_points": [{"t": t, "delta": d, "dwell": w}
                            for t, d, w in zip(t_stick, delta_stick, dwell, strict=True)],
           "asymptotic_points": [{"delta": d, "deltadot": 0.0, "dwell": w}
                                 for d, w in zip(delta_stick, dwell, strict=True)],
           "outcome": trajectory.outcome}
    if args.json:
        _print_json(out)
    else:
        print(f"{law.label()} on a {p.target} target, v = {p.v:g} m/s, kappa = {out['kappa']:.4g} N s/m^2.5")
        print(f"  status: {trajectory.status} ({trajectory.message})")
        units = {"max_force": "N", "max_indentation": "m", "contact_duration": "s", "restitution": "",
                 "time_equal_displacement": "s", "dissipated_energy": "J", "loop_area": "J"}
        for k, u in units.items():
            print(f"  {k:<24} {_fmt(out[k], u)}")
        print(f"  outcome: {trajectory.outcome}; {trajectory.n_stick} stick phase(s)"
              + ("" if trajectory.t_run is None else f", escape at t = {trajectory.t_run:.6g} s"))
        for t, d, w in zip(t_stick, delta_stick, dwell, strict=True):
            lasting = "permanent" if math.isinf(w) else f"{w:.4g} s"
            print(f"  stick at t = {t:.6g} s: delta = {d:.6g} m, dwell {lasting}")
    if not trajectory.ok:
        print(f"phaseimpact: numerical failure: {trajectory.status}: {trajectory.message}", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def _check_critical_law(law) -> None:
    if not law.is_filippov:
        raise ValueError(f"law = {law.name!r} is out of range for the critical damping; allowed: paper "
                         "(the other laws have no stick phases to split)")


def cmd_critical(args) -> int:
    from .continuation import critical_damping

    law = _law(args)
    _check_critical_law(law)
    params = _params(args)
    if args.kappa_min is not None and args.kappa_max is not None and not args.kappa_min < args.kappa_max:
        raise ValueError(f"kappa-min = {args.kappa_min!r}, kappa-max = {args.kappa_max!r} are out of range; "
                         "allowed: kappa-min < kappa-max")
    _note(f"locating kappa_c of {law.label()} at v = {params.v:g} m/s (a few seconds)")
    result = critical_damping(params, law, kappa_min=args.kappa_min, kappa_max=args.kappa_max,
                              rtol=args.kappa_rtol, integrator_rtol=args.rtol)
    out = {"law": result.law, "contact": result.contact, "v": result.v, "kappa_c": result.kappa_c,
           "bracket": list(result.bracket), "kappa_rtol": result.rtol, "rtol": args.rtol,
           "closed_form": result.closed_form, "kappa_2": result.kappa_2, "classification": result.classification,
           "status": result.status, "message": result.message, "evaluations": result.evaluations}
    if args.json:
        _print_json(out)
    else:
        kc = "not found" if result.kappa_c is None else f"{result.kappa_c:.10g} N s/m^2.5"
        print(f"critical damping of {law.label()} at v = {params.v:g} m/s: {kc}")
        print(f"  bracket {result.bracket[0]:.10g} .. {result.bracket[1]:.10g} N s/m^2.5; closed form "
              f"{_fmt(result.closed_form, 'N s/m^2.5', '.6g')}")
        print(f"  {result.status}: {result.message}")
    if result.status not in CRITICAL_ANSWERS:
        print(f"phaseimpact: kappa_c search failed: {result.status}: {result.message}", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def _resume_command(argv) -> str:
    words = ["phaseimpact", *argv]
    if "--resume" not in words:
        words.append("--resume")
    return shlex.join(words)


def _sweep_summary(result, out_path) -> dict:
    n_stick = np.asarray(result.values["n_stick"])
    computed = result.status >= 0
    kappas = result.kappa
    split = np.flatnonzero(computed[:-1] & computed[1:] & (n_stick[:-1] == 1) & (n_stick[1:] >= 2))
    counts = np.unique(n_stick[computed], return_counts=True)
    failed = result.failed
    failures = {}
    for name in result.status_names()[failed]:
        failures[str(name)] = failures.get(str(name), 0) + 1
    return {"out": out_path, "law": result.law.label(), "points": int(result.grid.size),
            "computed": int(np.count_nonzero(computed)), "failed": int(np.count_nonzero(failed)),
            "failures": failures, "cut_by_horizon": int(np.count_nonzero(result.cut)),
            "outcomes": result.summary()["outcomes"],
            "n_stick": {int(k): int(n) for k, n in zip(*counts, strict=True)},
            "first_split": None if not split.size else [float(kappas[split[0]]), float(kappas[split[0] + 1])]}


def _print_sweep_summary(s: dict) -> None:
    print(f"wrote {s['out']}: {s['points']} points of {s['law']}, {s['computed']} computed, {s['failed']} failed"
          + (f", {s['cut_by_horizon']} cut by the horizon (counts are lower bounds)" if s["cut_by_horizon"] else ""))
    print("  outcomes:      " + ", ".join(f"{k} {v}" for k, v in s["outcomes"].items()))
    print("  stick phases:  " + ", ".join(f"{k}: {v} points" for k, v in s["n_stick"].items()))
    if s["first_split"] is None:
        print("  the count of stick phases never goes from 1 to 2 on this grid")
    else:
        lo, hi = s["first_split"]
        print(f"  first split (1 -> 2 stick phases) between kappa = {lo:.6g} and {hi:.6g} N s/m^2.5")


def cmd_sweep(args) -> int:
    from . import archive
    from .continuation import Axis, Grid, sweep

    if args.scheduler is not None and args.backend != "dask":
        raise ValueError(f"scheduler = {args.scheduler!r} is not read by backend {args.backend!r}; allowed: "
                         "--scheduler together with --backend dask")
    if args.resume and args.force:
        raise ValueError("--resume and --force contradict each other: --resume completes the archive, "
                         "--force replaces it; give one")
    if not args.kappa_min < args.kappa_max:
        raise ValueError(f"kappa-min = {args.kappa_min!r}, kappa-max = {args.kappa_max!r} are out of range; "
                         "allowed: kappa-min < kappa-max")
    _contact_given(args)
    law = _law(args)
    if not law.reads("kappa"):
        source = (f"its damping comes from restitution = {law.restitution:g}" if law.damping_source == "restitution"
                  else "it has no damping")
        raise ValueError(f"law {law.label()!r} does not read kappa ({source}): every point "
                         "of a kappa sweep would be the same run; allowed: a law that reads kappa (paper, "
                         "hunt-crossley) without --restitution")
    params = _params(args)
    kappas = np.geomspace(args.kappa_min, args.kappa_max, args.num)
    Grid(params, law, (Axis.make("kappa", kappas),))  # every check of the grid, before any work
    out = args.out
    archive.created_timestamp()  # a bad SOURCE_DATE_EPOCH is refused now, not at the first checkpoint
    if args.backend == "dask" and args.scheduler is not None:
        _check_scheduler(args.scheduler)
    axes = {"kappa": kappas}
    with exclusive(out, "out"):
        previous = None
        if os.path.exists(out) and args.resume:
            held = archive.describe(out)
            if held["kind"] != "sweep":
                raise ValueError(f"out = {out!r} is a {held['kind']} archive, not a sweep: --resume cannot "
                                 "complete it (choose another --out, or drop --resume and add --force)")
            differences = archive.same_work(held, "sweep", law, params, axes, args.t_end, args.rtol)
            if differences:
                raise ValueError(f"resume: out = {out!r} holds other work ({'; '.join(differences)}); "
                                 "give the options it was computed with, or drop --resume")
            previous = archive.load(out)
            _note(f"resuming {out}: {int(np.count_nonzero(previous.done))} of {len(kappas)} points done")
        elif os.path.exists(out):
            archive.check_overwrite(out, "sweep", law, params, axes, args.t_end, args.rtol, force=args.force)

        def checkpoint(result):
            archive.save(result, out, force=args.force)

        try:
            result = sweep(params, law, kappas, t_end=args.t_end, n_jobs=args.jobs, backend=args.backend,
                           scheduler=args.scheduler, rtol=args.rtol, progress=not args.no_progress,
                           previous=previous, on_chunk=checkpoint)
        except KeyboardInterrupt:
            saved = ""
            if os.path.exists(out):
                try:
                    done = int(np.count_nonzero(archive.load(out).done))
                    saved = f"; {done} of {len(kappas)} points are saved in {out}"
                except ValueError:
                    saved = ""
            print(f"phaseimpact: interrupted{saved}. Resume with:\n  {_resume_command(args.argv)}", file=sys.stderr)
            return EXIT_INTERRUPTED
        archive.save(result, out, force=args.force)
    summary = _sweep_summary(result, out)
    if args.json:
        _print_json(summary)
    else:
        _print_sweep_summary(summary)
    if summary["failed"]:
        kinds = ", ".join(f"{k}: {v}" for k, v in summary["failures"].items())
        print(f"phaseimpact: {summary['failed']} of {summary['points']} points failed numerically ({kinds}); "
              f"they are stored with their status in {out}, and --resume recomputes them", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def cmd_critical_curve(args) -> int:
    from . import archive
    from .continuation import critical_curve

    if not args.v_min < args.v_max:
        raise ValueError(f"v-min = {args.v_min!r}, v-max = {args.v_max!r} are out of range; "
                         "allowed: v-min < v-max")
    law = _law(args)
    _check_critical_law(law)
    params = _params(args, v=args.v_min)
    _params(args, v=args.v_max)  # both ends valid, checked before any work
    speeds = np.geomspace(args.v_min, args.v_max, args.num)
    out = args.out
    archive.created_timestamp()
    with exclusive(out, "out"):
        if os.path.exists(out):
            archive.check_overwrite(out, "critical-curve", law, params, {"v": speeds}, None, args.kappa_rtol,
                                    force=args.force)
        _note(f"continuing kappa_c of {law.label()} over {args.num} speeds")
        curve = critical_curve(params, law, "v", speeds, rtol=args.kappa_rtol, integrator_rtol=args.rtol,
                               progress=not args.no_progress)
        archive.save(curve, out, force=args.force)
    asked = np.asarray(curve.requested, dtype=bool)
    if args.json:
        _print_json({"out": out, "v": curve.values[asked].tolist(), "kappa_c": curve.kappa[asked].tolist(),
                     "closed_form": curve.closed_form[asked].tolist(), "message": curve.message})
    else:
        for v, kc, closed in zip(curve.values[asked], curve.kappa[asked], curve.closed_form[asked], strict=True):
            print(f"v = {v:8.4g} m/s   kappa_c = {_fmt(kc, '', '.10g'):>16}   closed form {_fmt(closed, '', '.6g')}")
        print(f"wrote {out}" + (f" ({curve.message})" if curve.message else ""))
    if curve.message or not np.all(np.isfinite(curve.kappa[asked])):
        print(f"phaseimpact: the curve is incomplete: {curve.message or 'kappa_c lost at some speeds'}",
              file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


# ------------------------------------------------------------------------------------------------
# Parser
# ------------------------------------------------------------------------------------------------

def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="phaseimpact", description=__doc__.splitlines()[0],
                     epilog="SI units throughout. Exit codes: 0 done, 1 numerical failure (reported), "
                            "2 bad input (nothing computed), 130 interrupted.")
    parser.add_argument("--version", action="version", version=f"phaseimpact {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    v_lo, v_hi = V_RANGE

    def law_options(p, *, restitution=True, contact=True):
        p.add_argument("--law", choices=LAWS, default="paper", help="contact law (default: %(default)s)")
        if contact:
            p.add_argument("--contact", choices=("printed", "unilateral"), default=None,
                           help="law 'paper' only: read |delta|^alpha as printed (also in tension) or "
                                "unilaterally (P = 0 for delta <= 0) (default: printed)")
        if restitution:
            lo, hi = RESTITUTION_RANGE
            p.add_argument("--restitution", type=_RESTITUTION, default=None, metavar="E",
                           help=f"coefficient of restitution, {lo:g} <= E <= {hi:g}: required by the restitution "
                                "laws; replaces --kappa for hunt-crossley (exact inverse) (default: none)")

    def speed(p):
        p.add_argument("--v", type=_V, default=1.0, metavar="V",
                       help=f"impact speed, m/s, {v_lo:g} <= V <= {v_hi:g} (default: %(default)s)")

    def tolerance(p):
        lo, hi = RTOL_RANGE
        p.add_argument("--rtol", type=_RTOL, default=1e-10,
                       help=f"integrator tolerance (relative), {lo:g} <= RTOL <= {hi:g} (default: %(default)s)")

    def kappa_tolerance(p):
        lo, hi = KAPPA_RTOL_RANGE
        p.add_argument("--kappa-rtol", type=_KAPPA_RTOL, default=1e-10,
                       help=f"relative width of kappa_c's final bracket, {lo:g} <= KAPPA_RTOL <= {hi:g} "
                            "(default: %(default)s)")

    def out_options(p, resume):
        p.add_argument("--out", type=_path("out"), required=True, metavar="FILE.h5",
                       help="HDF5 archive to write (written atomically; refused if it exists and is not an "
                            "archive of the same work, unless --force)")
        p.add_argument("--force", action="store_true",
                       help="replace --out even if it holds something else (default: refuse)")
        if resume:
            p.add_argument("--resume", action="store_true",
                           help="complete the partial archive --out (same options) without recomputing its "
                                "finished points; failed points are recomputed")
        p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")

    def json_option(p):
        p.add_argument("--json", action="store_true", help="print one JSON object (numbers finite or null)")

    p = sub.add_parser("params", help="the seed's derived parameters",
                       description="The seed's derived parameters (eq. 3-5, steel) at one speed.")
    speed(p)
    p.add_argument("--kappa", type=_KAPPA, default=None,
                   help=f"damping coefficient, N s/m^2.5, 0 <= KAPPA <= {KAPPA_MAX:g} (default: 0)")
    json_option(p)
    p.set_defaults(func=cmd_params)

    p = sub.add_parser("simulate", help="one impact: summary quantities, stick points, outcome",
                       description="One impact from seed eq. 6, integrated exactly (event-driven).")
    law_options(p)
    speed(p)
    p.add_argument("--kappa", type=_KAPPA, default=None,
                   help=f"damping coefficient, N s/m^2.5, 0 <= KAPPA <= {KAPPA_MAX:g}; read by paper and "
                        "hunt-crossley only (default: 0)")
    p.add_argument("--target", choices=TARGETS, default="plate", help="what is hit (default: %(default)s)")
    p.add_argument("--t-end", type=_T_END, default=None,
                   help="horizon, s, a finite number > 0 (default: run until the outcome settles, capped by "
                        "the case's own time scales)")
    tolerance(p)
    json_option(p)
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("critical", help="the critical damping kappa_c at one speed (law paper)",
                       description="The critical damping kappa_c of eq. 8 (law paper) at one speed: where the "
                                   "first stick stops being permanent.")
    law_options(p, restitution=False)
    speed(p)
    kappa_tolerance(p)
    tolerance(p)
    p.add_argument("--kappa-min", type=_real("kappa-min", 0.0, KAPPA_MAX, low_open=True, unit="N s/m^2.5"),
                   default=None, help="lower end of the search, N s/m^2.5 (default: 1e-8 K/v)")
    p.add_argument("--kappa-max", type=_real("kappa-max", 0.0, KAPPA_MAX, low_open=True, unit="N s/m^2.5"),
                   default=None, help="upper end of the search, N s/m^2.5 (default: 1e8 K/v)")
    json_option(p)
    p.set_defaults(func=cmd_critical)

    p = sub.add_parser("sweep", help="a kappa sweep archived to HDF5",
                       description="Every kappa of a log grid, each run until its outcome settles (or to "
                                   "--t-end), archived to HDF5 and checkpointed after every chunk.")
    law_options(p)
    speed(p)
    p.add_argument("--kappa-min", type=_real("kappa-min", 0.0, KAPPA_MAX, low_open=True, unit="N s/m^2.5"),
                   required=True, help=f"first kappa, N s/m^2.5, 0 < KAPPA_MIN <= {KAPPA_MAX:g}")
    p.add_argument("--kappa-max", type=_real("kappa-max", 0.0, KAPPA_MAX, low_open=True, unit="N s/m^2.5"),
                   required=True, help=f"last kappa, N s/m^2.5, KAPPA_MIN < KAPPA_MAX <= {KAPPA_MAX:g}")
    p.add_argument("--num", type=_integer("num", 2, MAX_SWEEP_POINTS), default=50,
                   help=f"number of kappa values (log spaced), 2 <= NUM <= {MAX_SWEEP_POINTS} (default: %(default)s)")
    p.add_argument("--t-end", type=_T_END, default=None,
                   help="horizon of every run, s (default: each run until its outcome settles, capped)")
    tolerance(p)
    p.add_argument("--jobs", type=_jobs, default=1,
                   help=f"parallel workers, 1..{MAX_JOBS}, or -1 for all cores (default: %(default)s)")
    p.add_argument("--backend", choices=BACKENDS, default="threads",
                   help="threads of this process, joblib processes (loky) or a Dask cluster (default: %(default)s)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="Dask scheduler address, e.g. tcp://host:8786 (only with --backend dask; default: a "
                        "local in-process cluster)")
    out_options(p, resume=True)
    json_option(p)
    p.set_defaults(func=cmd_sweep)

    p = sub.add_parser("critical-curve", help="kappa_c against the impact speed, archived to HDF5",
                       description="kappa_c(v) of law paper over log-spaced speeds, by continuation.")
    law_options(p, restitution=False)
    p.add_argument("--v-min", type=_real("v-min", *V_RANGE, unit="m/s"), required=True,
                   help=f"lowest speed, m/s, {v_lo:g} <= V_MIN <= {v_hi:g}")
    p.add_argument("--v-max", type=_real("v-max", *V_RANGE, unit="m/s"), required=True,
                   help=f"highest speed, m/s, V_MIN < V_MAX <= {v_hi:g}")
    p.add_argument("--num", type=_integer("num", 1, MAX_CURVE_POINTS), default=5,
                   help=f"number of speeds (log spaced), 1 <= NUM <= {MAX_CURVE_POINTS} (default: %(default)s)")
    kappa_tolerance(p)
    tolerance(p)
    out_options(p, resume=False)
    json_option(p)
    p.set_defaults(func=cmd_critical_curve)
    return parser


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    args = parser.parse_args(argv)
    args.argv = argv
    try:
        return args.func(args)
    except ValueError as error:
        print(f"phaseimpact: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("phaseimpact: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except OSError as error:  # the disk, not the input: full, gone, permissions changed under us
        print(f"phaseimpact: error: {error}", file=sys.stderr)
        return EXIT_FAILURE


if __name__ == "__main__":
    sys.exit(main())
