"""Trains of impacts and the impact map (docs/physics.md §7): a train (``train``), the map's attractor over a
parameter (``orbit-diagram``), a branch of its periodic orbits (``map-continuation``) and its basins
(``basins``)."""

from __future__ import annotations

import dataclasses
import math
import sys

from .._atomic import exclusive
from ..parameters import KAPPA_MAX, V_RANGE
from . import _options as options
from ._case import Setup, _case_fields, _check_in_range, _check_reads_kappa, _law_fields, _setup
from ._common import (
    _RTOL,
    EXIT_FAILURE,
    EXIT_OK,
    KAPPA_UNIT,
    MAX_BASIN_SCALES,
    MAX_CURVE_POINTS,
    MAX_JOBS,
    MAX_TRAIN_IMPACTS,
    _check_figure_target,
    _figure_path,
    _integer,
    _note,
    _one_axis,
    _print_json,
    _real,
)


def _period_option(p, *, required: bool) -> None:
    """``--period``: required by a train and basins; orbit-diagram and map-continuation take it unless the
    axis is ``T``."""
    help_ = ("time between arrivals, s, T > 0" if required
             else "time between arrivals (s) when the axis is not T (default: none)")
    p.add_argument("--period", type=_real("period", 0.0, None, low_open=True, unit="s"), required=required,
                   default=None, metavar="T", help=help_)


def _threads_option(p, what: str) -> None:
    p.add_argument("--jobs", type=_integer("jobs", 1, MAX_JOBS), default=1,
                   help=f"{what} computed side by side in threads (default: %(default)s)")


def _figure_option(p, what: str) -> None:
    p.add_argument("--out", type=_figure_path, default=None, metavar="FIG.png",
                   help=f"also draw {what} into this figure, .png, .pdf or .svg (default: none)")
    p.add_argument("--force", action="store_true", help="replace --out even if it is not a figure (default: refuse)")


def add_train(p) -> None:
    options.case_options(p)
    options.law_options(p)
    options.speed(p)
    options.damping(p)
    options.target(p)
    _period_option(p, required=True)
    p.add_argument("--impacts", type=_integer("impacts", 1, 100_000), default=20,
                   help="number of impacts, 1 to 100000 (default: %(default)s)")
    p.add_argument("--fixed-point", action="store_true", help="also find the period-1 orbit and its multipliers")
    options.tolerance(p)
    options.json_option(p)
    options.train_archive_option(p)


def add_orbit_diagram(p) -> None:
    options.case_options(p)
    options.law_options(p)
    options.speed(p)
    options.damping(p)
    options.target(p)
    options.axis_option(p, "the parameter varied and its values (s, N s/m^(1+alpha) or m/s; e.g. T=2e-3:8e-3:400)",
                        names="T, kappa, v", limit=MAX_CURVE_POINTS)
    _period_option(p, required=False)
    p.add_argument("--transients", type=_integer("transients", 0, 100_000), default=200,
                   help="impacts dropped at each value (default: %(default)s)")
    p.add_argument("--samples", type=_integer("samples", 1, 100_000), default=50,
                   help="impacts kept at each value (default: %(default)s)")
    _threads_option(p, "values")
    p.add_argument("--backend", choices=("threads", "cuda"), default="threads",
                   help="threads of this process (--jobs), or a GPU (cuda: each impact of every value in one launch, "
                        "one thread per value; phaseimpact backends says whether it works here) (default: %(default)s)")
    _figure_option(p, "the diagram")
    options.tolerance(p)
    options.json_option(p)
    options.train_archive_option(p, force=False)


def add_map_continuation(p) -> None:
    options.case_options(p)
    options.law_options(p)
    options.speed(p)
    options.damping(p)
    options.target(p)
    options.axis_option(p, "the parameter varied, from START to STOP, the largest step along the branch the axis's "
                        "spacing (s, N s/m^(1+alpha) or m/s; e.g. T=0.99e-3:0.975e-3:6)", names="T, kappa, v",
                        limit=MAX_CURVE_POINTS)
    _period_option(p, required=False)
    p.add_argument("--k", type=_integer("k", 1, 64), default=1,
                   help="the orbit's period in impacts, 1 to 64 (default: %(default)s)")
    p.add_argument("--max-points", type=_integer("max-points", 3, 100_000), default=500,
                   help="points of the branch at most, 3 to 100000 (default: %(default)s)")
    p.add_argument("--xtol", type=_real("xtol", 1e-14, 1e-3), default=1e-9,
                   help="length of each bisection's final segment in the scaled (state, parameter) space, "
                        "1e-14 <= XTOL <= 1e-3 (default: %(default)g)")
    p.add_argument("--rtol", type=_RTOL, default=1e-12,
                   help="integrator tolerance (relative), %(type)s; the multipliers come from finite differences "
                        "of the map, so tighter than elsewhere (default: %(default)s)")
    options.json_option(p)
    options.train_archive_option(p)


def add_basins(p) -> None:
    options.case_options(p)
    options.law_options(p)
    options.speed(p)
    options.damping(p)
    options.target(p)
    _period_option(p, required=True)
    p.add_argument("--x2-max", type=_real("x2-max", 0.0, None, low_open=True, unit="m"), default=None,
                   metavar="X", help="initial positions from -X to X, m, X > 0 (default: 1.5 v / omega, omega = "
                                     "sqrt(Kb/M2): the plate's swing at speed v)")
    p.add_argument("--x2dot-max", type=_real("x2dot-max", 0.0, None, low_open=True, unit="m/s"), default=None,
                   metavar="V", help="initial velocities from -V to V, m/s, V > 0 (default: 1.5 v)")
    p.add_argument("--grid", type=_integer("grid", 1, 400), default=21, metavar="N",
                   help="initial states per axis, 1 <= N <= 400: N x N states in all (default: %(default)s)")
    p.add_argument("--iterations", type=_integer("iterations", 1, 100_000), default=500,
                   help="impacts at most from each state, 1 to 100000 (default: %(default)s)")
    p.add_argument("--max-period", type=_integer("max-period", 1, 64), default=16,
                   help="longest period recognised, 1 to 64 (default: %(default)s)")
    _threads_option(p, "initial states")
    _figure_option(p, "the basins")
    options.tolerance(p)
    options.json_option(p)
    options.train_archive_option(p, force=False)


@dataclasses.dataclass(frozen=True)
class _TrainWork:
    """What a train command's ``--archive`` holds: its kind, axes (an orbit diagram's), horizon (the period,
    NaN over ``T``) and settings, as :func:`phaseimpact.archive.save` stores them."""

    kind: str
    axes: dict
    t_end: float
    settings: dict


def _train_work(args, kind: str, axes: dict | None = None, **settings) -> _TrainWork:
    over_t = "T" in (axes or {}) or settings.get("param") == "T"
    return _TrainWork(kind, axes or {}, math.nan if over_t else args.period, {"rtol": args.rtol, **settings})


def _cell(value, width: int, spec: str = ".6g") -> str:
    """A number of a text table, right-aligned; NaN or inf (no separation, a failed run) as 'undefined'."""
    return f"{value:{width}{spec}}" if math.isfinite(value) else f"{'undefined':>{width}}"


def _plate_period_text(params) -> str:
    period = params.target_period
    return f"plate period {period:.6g} s" if math.isfinite(period) else f"no plate period: a {params.target} target"


def _check_train_period(name: str, period: float, params) -> None:
    """A period between arrivals (``--period``, or an end of ``--axis T``), checked before any work: one the
    map can resolve, and a warning when projectiles would arrive while the last is still in contact."""
    from ..integrate import scales
    from ..train import _check_period

    _check_period(period, params, name)
    contact_time = scales(params).contact_time
    if period < contact_time:
        print(f"phaseimpact: warning: {name} = {period:g} s is shorter than the contact time {contact_time:.3g} s "
              "(Hertz): each projectile arrives while the last is still in contact, whose restitution is then "
              "undefined", file=sys.stderr)


def _check_archive_target(args, setup: Setup, work: _TrainWork) -> None:
    """``--archive`` follows ``--out``'s rule (:func:`phaseimpact.archive.check_overwrite`): a file holding
    other work is replaced only with ``--force``. Checked before any work, and again under the lock."""
    if args.archive is None:
        return
    from .. import archive

    archive.check_overwrite(args.archive, work.kind, setup.law, setup.params, work.axes, work.t_end, args.rtol,
                            force=args.force, name="archive", settings=work.settings)


def _save_train_archive(args, setup: Setup, result, work: _TrainWork) -> None:
    if args.archive is None:
        return
    from .. import archive

    with exclusive(args.archive, "archive"):
        _check_archive_target(args, setup, work)  # another process may have written it meanwhile
        archive.save(result, args.archive, force=args.force, params=setup.case, law=setup.law,
                     settings=work.settings)


def run_train(args) -> int:
    from ..integrate import scales
    from ..train import impact_train, map_fixed_point

    setup = _setup(args)
    work = _train_work(args, "impact-train", period=args.period, impacts=args.impacts)
    _check_archive_target(args, setup, work)
    p, law = setup.params, setup.law
    _check_train_period("period", args.period, p)
    _note(f"{args.impacts} impacts of {law.label()}, one every {args.period:g} s")
    train = impact_train(p, law, args.period, args.impacts, rtol=args.rtol)
    _save_train_archive(args, setup, train, work)
    orbit = map_fixed_point(p, law, args.period) if args.fixed_point else None
    out = {**_case_fields(setup), "plate_period": scales(p).plate_period, **train.as_dict(),
           "fixed_point": None if orbit is None else orbit.as_dict(), "case": setup.case.as_dict()}
    failed = [s for s in train.status if s != "success"]
    if args.json:
        _print_json(args, out)
    else:
        print(f"{law.label()} on a {p.target} target ({setup.case.name}), v = {p.v:g} m/s, one impact every "
              f"{args.period:g} s ({_plate_period_text(p)})")
        print(f"  {'n':>5} {'x2 before (m)':>14} {'x2dot (m/s)':>12} {'amplitude (m)':>14} {'peak force (N)':>14} "
              f"{'dissipated (J)':>14} {'restitution':>11}")
        for n in range(args.impacts):
            print(f"  {n:5d} {_cell(train.plate[n, 0], 14)} {_cell(train.plate[n, 1], 12)} "
                  f"{_cell(train.amplitude[n], 14)} {_cell(train.peak_force[n], 14)} "
                  f"{_cell(train.dissipated_energy[n], 14)} {_cell(train.restitution[n], 11)}")
        if train.overlap.any():
            print(f"  note: {int(train.overlap.sum())} projectile(s) still in contact when the next one arrived")
        if orbit is not None:
            if orbit.converged:
                print(f"  period-1 orbit: x2 = {orbit.plate[0]:.9g} m, x2dot = {orbit.plate[1]:.9g} m/s before each "
                      f"impact; multipliers {_multiplier_text(orbit.multipliers)} "
                      f"({'stable' if orbit.stable else 'unstable'})")
            else:
                print(f"  period-1 orbit: not found; {' '.join(orbit.message.split())}")  # SciPy wraps its lines
    if failed:
        print(f"phaseimpact: {len(failed)} run(s) of the train failed ({failed[0]})", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def run_orbit_diagram(args) -> int:
    import numpy as np

    from .. import plotting
    from ..train import orbit_diagram

    if args.out is not None:
        _check_figure_target(args.out, args.force)
    if args.transients + args.samples > MAX_TRAIN_IMPACTS:
        raise ValueError(f"transients + samples = {args.transients} + {args.samples} is out of range; allowed: "
                         f"--transients + --samples <= {MAX_TRAIN_IMPACTS} (the impacts of each value's train)")
    setup = _setup(args)
    param, values = _train_axis(args, setup)
    work = _train_work(args, "orbit-diagram", {param: values}, period=args.period, transients=args.transients,
                       samples=args.samples)
    _check_archive_target(args, setup, work)
    if args.backend == "cuda":
        from .. import cuda

        cuda.check(setup.law)  # a user law, or no GPU: one line and exit 2, nothing computed
    _note(f"orbit diagram of {setup.law.label()} over {param}: {len(values)} values x "
          f"{args.transients + args.samples} impacts")
    diagram = orbit_diagram(setup.params, setup.law, param, values, period=args.period,
                            transients=args.transients, samples=args.samples, rtol=args.rtol, n_jobs=args.jobs,
                            backend=args.backend)
    _save_train_archive(args, setup, diagram, work)
    if args.out is not None:
        with exclusive(args.out, "out"):
            title = f"{setup.law.label()}, {setup.case.name}, v = {setup.params.v:g} m/s"
            plotting.save(plotting.plot_orbit_diagram(diagram, title=title), args.out)
    out = {"out": args.out, **_law_fields(setup), "v": setup.params.v, "param": param,
           "period": args.period, "values": diagram.values.tolist(), "transients": args.transients,
           "samples": args.samples, "distinct": diagram.distinct.tolist(),
           "x2": diagram.plate[:, :, 0].tolist(), "x2dot": diagram.plate[:, :, 1].tolist(),
           "case": setup.case.as_dict()}
    if args.json:
        _print_json(args, out)
    else:
        counts = {int(k): int(n) for k, n in zip(*np.unique(diagram.distinct, return_counts=True), strict=True)}
        print(f"orbit diagram over {param}: {len(values)} values; distinct points after {args.transients} "
              f"impacts (1: fixed point, k: period k, {args.samples}: irregular): {counts}"
              + (f"; wrote {args.out}" if args.out else ""))
    return EXIT_OK


def _train_axis(args, setup: Setup):
    """``(param, values)`` of the one --axis of orbit-diagram or map-continuation, checked before any work."""
    import numpy as np

    from ..train import TRAIN_PARAMETERS

    axis = _one_axis(args)
    param, values = axis.name, axis.values
    if param not in TRAIN_PARAMETERS:
        raise ValueError(f"axis {param!r} is out of range; allowed: one of {', '.join(TRAIN_PARAMETERS)}")
    if len(values) > MAX_CURVE_POINTS:
        raise ValueError(f"axis {param!r} has {len(values)} values; allowed: at most {MAX_CURVE_POINTS}")
    if param != "T" and args.period is None:
        raise ValueError(f"period = None is out of range for axis {param}; allowed: --period T (s) > 0")
    if param == "T" and args.period is not None:
        raise ValueError(f"period = {args.period:g} s contradicts --axis T, which gives the period of each value; "
                         "allowed: --period with an axis kappa or v only")
    if param == "kappa":
        _check_reads_kappa(setup.law, f"{args.command} value")
    low, high = float(np.min(values)), float(np.max(values))
    for x in (low, high):
        if param == "v":
            _check_in_range("v", x, *V_RANGE, "m/s", "axis v")
        elif param == "kappa":
            _check_in_range("kappa", x, 0.0, KAPPA_MAX, KAPPA_UNIT, "axis kappa")
        elif x <= 0:
            raise ValueError(f"T = {x!r} is out of range; allowed: T > 0 (s)")
    if param == "kappa":
        _check_train_period("period", args.period, setup.params)
    elif param == "v":  # the contact time is v's: the longest at the lowest v (the one warning)
        from ..train import _check_period

        _check_period(args.period, setup.params.replace(v=high), "period")
        _check_train_period("period", args.period, setup.params.replace(v=low))
    elif param == "T":
        for x in sorted({low, high}):
            _check_train_period("T", x, setup.params)
    return param, values


def _multiplier_text(multipliers) -> str:
    return ", ".join(f"{m.real:.6g}{m.imag:+.3g}i" for m in multipliers)


def _located(point, branch_values) -> bool:
    """False for a bifurcation whose bracket is still the whole step between two points of the branch
    (the corrector failed at the first bisection): where it lies in that step is unknown."""
    import numpy as np

    steps = np.abs(np.diff(np.asarray(branch_values, dtype=float)))
    at = np.flatnonzero(np.asarray(branch_values[:-1], dtype=float) == point.value)
    return not any(point.bracket >= steps[i] * (1 - 1e-9) for i in at)


def run_map_continuation(args) -> int:
    import numpy as np

    from ..integrate import scales
    from ..train import continue_map_orbit

    setup = _setup(args)
    param, values = _train_axis(args, setup)
    if len(values) < 2:
        raise ValueError(f"axis {param!r} has {len(values)} value; allowed: START:STOP:NUM with NUM >= 2 (the "
                         "branch runs from START to STOP, its largest step the axis's spacing)")
    start, stop = float(values[0]), float(values[-1])
    step = float(np.max(np.abs(np.diff(values))))
    work = _train_work(args, "map-branch", period=args.period, k=args.k, xtol=args.xtol, param=param, start=start,
                       stop=stop, step=step, max_points=args.max_points)
    _check_archive_target(args, setup, work)
    p, law = setup.params, setup.law
    _note(f"period-{args.k} orbits of {law.label()} over {param} from {start:g} to {stop:g}")
    branch = continue_map_orbit(p, law, param, start, stop, period=args.period, k=args.k,
                                step=step, max_points=args.max_points,
                                xtol=args.xtol, rtol=args.rtol)
    _save_train_archive(args, setup, branch, work)
    located = [_located(point, branch.values) for point in branch.points]
    out = {**_case_fields(setup), "plate_period": scales(p).plate_period, "period": args.period, "param": param,
           "from": start, "to": stop, "num": len(values), **branch.as_dict(), "case": setup.case.as_dict()}
    for point, is_located in zip(out["points"], located, strict=True):
        point["located"] = is_located
    if args.json:
        _print_json(args, out)
    else:
        print(f"period-{args.k} orbits of {law.label()} ({setup.case.name}), v = {p.v:g} m/s, over {param} "
              f"from {start:g} to {stop:g}: {len(branch.values)} points, "
              f"{int(branch.stable.sum())} stable; {branch.message}")
        if not branch.points:
            print("  no bifurcation located")
        for point, is_located in zip(branch.points, located, strict=True):
            if not is_located:
                print(f"  {point.kind:16s} not located: between {param} = {point.value:.12g} and the next point of "
                      f"the branch (bracket {point.bracket:.2g}, the whole step: the bisection did not narrow it; "
                      "a smaller step (a larger NUM) may locate it)")
                continue
            print(f"  {point.kind:16s} {param} = {point.value:.12g} (bracket {point.bracket:.2g}); "
                  f"x2 = {point.plate[0]:.6g} m, x2dot = {point.plate[1]:.6g} m/s; multipliers "
                  f"{_multiplier_text(point.multipliers)}"
                  + (f"; contacts per period {point.contacts[0][0]} -> {point.contacts[1][0]}"
                     if point.kind == "grazing" else "") + ("; the branch turns" if point.turning else ""))
    if len(branch.values) == 0:
        print(f"phaseimpact: {branch.message}", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def run_basins(args) -> int:
    import numpy as np

    from .. import plotting
    from ..integrate import scales
    from ..train import basins

    if args.out is not None:
        _check_figure_target(args.out, args.force)
    setup = _setup(args)
    p, law = setup.params, setup.law
    _check_train_period("period", args.period, p)
    omega = math.sqrt(p.Kb / p.M2) if p.target == "plate" and p.Kb > 0 else None
    if args.x2_max is None and omega is None:
        raise ValueError(f"x2-max = None is out of range for a {p.target} target without springs; allowed: "
                         "--x2-max X (m) > 0")
    # the grid's scales: the plate's swing at speed v (the indentation without springs) and v; far
    # beyond them the states overflow the integrator (1e308 made NaN of the grid itself)
    swing = 1.5 * p.v / omega if omega is not None else p.hertz_indentation
    for name, given, scale, unit, what in (("x2-max", args.x2_max, swing, "m", "the plate's swing at speed v"
                                            if omega is not None else "the Hertz indentation"),
                                           ("x2dot-max", args.x2dot_max, 1.5 * p.v, "m/s", "1.5 v")):
        if given is not None and given > MAX_BASIN_SCALES * scale:
            raise ValueError(f"{name} = {given:g} {unit} is out of range; allowed: 0 < {name} <= "
                             f"{MAX_BASIN_SCALES * scale:.3g} {unit} ({MAX_BASIN_SCALES:g} times {what}, "
                             f"{scale:.3g} {unit})")
    x2_max = args.x2_max if args.x2_max is not None else swing
    x2dot_max = args.x2dot_max if args.x2dot_max is not None else 1.5 * p.v
    xs, vs = np.linspace(-x2_max, x2_max, args.grid), np.linspace(-x2dot_max, x2dot_max, args.grid)
    work = _train_work(args, "basins", period=args.period, iterations=args.iterations, max_period=args.max_period,
                       grid=args.grid, x2_max=x2_max, x2dot_max=x2dot_max)
    _check_archive_target(args, setup, work)
    _note(f"basins of {law.label()} at T = {args.period:g} s: {args.grid} x {args.grid} initial states")
    result = basins(p, law, args.period, xs, vs, iterations=args.iterations, max_period=args.max_period,
                    rtol=args.rtol, n_jobs=args.jobs)
    _save_train_archive(args, setup, result, work)
    if args.out is not None:
        with exclusive(args.out, "out"):
            title = f"{law.label()}, {setup.case.name}, v = {p.v:g} m/s, T = {args.period:g} s"
            plotting.save(plotting.plot_basins(result, title=title), args.out)
    out = {"out": args.out, **_case_fields(setup), "plate_period": scales(p).plate_period,
           "iterations": args.iterations, "max_period": args.max_period, **result.as_dict(),
           "case": setup.case.as_dict()}
    if args.json:
        _print_json(args, out)
    else:
        total = result.labels.size
        print(f"basins of {law.label()} ({setup.case.name}), v = {p.v:g} m/s, T = {args.period:g} s: {total} initial "
              f"states, {len(result.attractors)} periodic attractor(s)" + (f"; wrote {args.out}" if args.out else ""))
        for i, a in enumerate(result.attractors):
            print(f"  {i}: period {a.period}, basin {a.count} ({100 * a.count / total:.1f}%), "
                  f"x2 = {a.plate[0, 0]:.6g} m, x2dot = {a.plate[0, 1]:.6g} m/s before its first impact")
        print(f"  no period within {args.iterations} impacts: {result.not_converged}; runs failed: {result.no_map}")
    return EXIT_FAILURE if result.no_map else EXIT_OK
