"""Grids over a case's parameters (``sweep``: one axis, ``atlas``: several): one runner with checkpoints,
the lock, resume, failures and Ctrl-C."""

from __future__ import annotations

import os
import sys

from .._atomic import exclusive
from ..parameters import KAPPA_MAX, V_RANGE
from . import _options as options
from ._case import Setup, _check_in_range, _given, _law_fields, _setting_names, _setup
from ._common import (
    EXIT_FAILURE,
    EXIT_INTERRUPTED,
    EXIT_OK,
    KAPPA_UNIT,
    MAX_JOBS,
    MAX_SWEEP_POINTS,
    _note,
    _one_axis,
    _print_json,
    _progress,
    _real,
    _resume_command,
    _stopped,
)


def _add_grid(p, axis_help: str) -> None:
    options.case_options(p)
    options.law_options(p)
    options.speed(p)
    options.damping(p)
    options.target(p)
    options.axis_option(p, axis_help, repeat=True)
    for removed in ("--kappa-min", "--kappa-max", "--num", "--range"):
        p.add_argument(removed, action=options.Removed)
    p.add_argument("--refine", default=None, metavar="AXIS",
                   help="after the grid, locate every class boundary between neighbours along AXIS (one of the "
                        "--axis names) by bisection, to --refine-rtol, and store the boundary points in the "
                        "archive (plot draws them); default: no refinement")
    p.add_argument("--refine-rtol", type=_real("refine-rtol", 1e-12, 1e-2), default=1e-8,
                   help="relative width of each refined boundary bracket (1e-12..1e-2; default %(default)g)")
    options.horizon(p)
    options.tolerance(p)
    options.parallel(p)
    options.out_options(p, resume=True)
    options.json_option(p)


def add_sweep(p) -> None:
    _add_grid(p, "the sweep's values")


def add_atlas(p) -> None:
    _add_grid(p, "one axis of the grid (repeat for each)")


def run_sweep(args) -> int:
    """An atlas of one axis."""
    _one_axis(args, " (atlas takes a grid)")
    return run_atlas(args)


def _check_grid_options(args) -> None:
    if args.backend != "dask" and args.jobs > MAX_JOBS:  # the parser allows a Dask cluster's task count
        raise ValueError(f"jobs = {args.jobs!r} is out of range for --backend {args.backend}; allowed: an integer "
                         f"1 <= jobs <= {MAX_JOBS} (4 per core), or -1 for all cores (more with --backend dask)")
    if args.scheduler is not None and args.backend != "dask":
        raise ValueError(f"scheduler = {args.scheduler!r} is not read by backend {args.backend!r}; allowed: "
                         "--scheduler together with --backend dask")
    if args.resume and args.force:
        raise ValueError("--resume and --force contradict each other: --resume completes the archive, "
                         "--force replaces it; give one")


def _run_grid(args, setup: Setup, axes: list):
    """Evaluate the grid ``axes`` over the case into ``args.out``, checkpointed after every chunk.

    Every check (the grid, the archive at ``--out``, the scheduler) comes before any work. Returns
    the result, or None when interrupted (the resume command is printed).
    """
    import numpy as np

    from .. import archive
    from ..continuation import Grid, atlas
    from ..continuation._parallel import check_scheduler

    Grid(setup.case, setup.law, tuple(axes))  # every check of the grid, before any work
    if args.backend == "cuda":
        from .. import cuda

        cuda.check(setup.law)  # a user law, or no GPU: one line and exit 2, nothing computed
    out = args.out
    archive.created_timestamp()  # a bad SOURCE_DATE_EPOCH is refused now, not at the first checkpoint
    if args.backend == "dask" and args.scheduler is not None:
        check_scheduler(args.scheduler)  # before any work: a dead address fails within seconds
    named = {axis.name: axis.values for axis in axes}
    size = int(np.prod([len(axis.values) for axis in axes]))
    grid_kinds = [k for k in archive.KINDS if k != "critical-curve"]  # "sweep" (and "atlas": several axes)
    kind = "atlas" if len(axes) > 1 and "atlas" in grid_kinds else "sweep"
    with exclusive(out, "out"):
        previous, checkpoint = archive.open_for_resume(out, kind, setup.law, setup.params, named, args.t_end,
                                                       args.rtol, resume=args.resume, force=args.force)
        if previous is not None:
            _note(f"resuming {out}: {int(np.count_nonzero(previous.done))} of {size} points done")

        try:
            result = atlas(setup.case, setup.law, axes, t_end=args.t_end, n_jobs=args.jobs, backend=args.backend,
                           scheduler=args.scheduler, rtol=args.rtol, progress=_progress(args),
                           previous=previous, on_chunk=checkpoint)
        except KeyboardInterrupt as stop:  # Ctrl-C or SIGTERM: one line, the checkpoint stays
            saved, done = "", checkpoint.saved  # an interrupted checkpoint write leaves the previous one
            if done is None and os.path.exists(out):  # none written yet: a resumed archive's own points
                try:
                    done = int(np.count_nonzero(archive.load(out).done))
                except ValueError:
                    done = None
            if done is not None:
                saved = f"; {done} of {size} points are saved in {out}"
            print(f"phaseimpact: {_stopped(stop)}{saved}; resume with: {_resume_command(args.argv)}", file=sys.stderr)
            stop.reported = True
            raise
        del checkpoint  # its record of the file (per-point arrays) is not needed for the final write
        archive.save(result, out, force=args.force)
    return result


def _histogram(values, computed) -> dict:
    import numpy as np

    counts = np.unique(np.asarray(values)[computed], return_counts=True)
    return {int(k): int(n) for k, n in zip(*counts, strict=True)}


def _outcome_name(code) -> str:
    from ..integrate import OUTCOMES

    return OUTCOMES[int(code)]


def _grid_summary(result, out_path, setup: Setup) -> dict:
    import numpy as np

    computed = result.status >= 0
    failed = result.failed
    failures = {}
    for code in result.status[failed]:
        from ..integrate import STATUSES

        name = STATUSES[int(code)]
        failures[name] = failures.get(name, 0) + 1
    axes = [{"name": a.name, "num": len(a.values), "start": float(a.values[0]), "stop": float(a.values[-1]),
             "log": bool(a.log)} for a in result.grid.axes]
    summary = {"out": out_path, **_law_fields(setup), "kappa_unit": setup.law.damping_unit(setup.params.alpha),
               "points": int(result.grid.size),
               "computed": int(np.count_nonzero(computed)), "failed": int(np.count_nonzero(failed)),
               "failures": failures, "cut_by_horizon": int(np.count_nonzero(result.cut)),
               "outcomes": result.summary()["outcomes"], "axes": axes,
               "n_stick": _histogram(result.values["n_stick"], computed),
               "n_contacts": _histogram(result.values["n_contacts"], computed)}
    if result.grid.names == ("kappa",) and result.law.is_filippov:
        n_stick = np.asarray(result.values["n_stick"])
        kappas = result.kappa
        split = np.flatnonzero(computed[:-1] & computed[1:] & (n_stick[:-1] == 1) & (n_stick[1:] >= 2))
        summary["first_split"] = (None if not split.size
                                  else [float(kappas[split[0]]), float(kappas[split[0] + 1])])
    boundaries = result.extras.get("boundaries")
    if boundaries is not None:
        summary["boundaries"] = {"axis": boundaries["axis"], "rtol": float(boundaries["rtol"]),
                                 "points": np.asarray(boundaries["points"]).tolist(),
                                 "below": [_outcome_name(c) for c in boundaries["below"]],
                                 "above": [_outcome_name(c) for c in boundaries["above"]]}
    summary["case"] = setup.case.as_dict()
    return summary


def _print_grid_summary(s: dict) -> None:
    shape = " x ".join(f"{a['num']} {a['name']}" for a in s["axes"])
    print(f"wrote {s['out']}: {s['points']} points ({shape}) of {s['law_label']}, {s['computed']} computed, "
          f"{s['failed']} failed"
          + (f", {s['cut_by_horizon']} cut by the horizon (counts are lower bounds)" if s["cut_by_horizon"] else ""))
    print("  outcomes:      " + ", ".join(f"{k} {v}" for k, v in s["outcomes"].items()))
    if s["contact"] is not None:  # paper: stick phases
        print("  stick phases:  " + ", ".join(f"{k}: {v} points" for k, v in s["n_stick"].items()))
    print("  contacts:      " + ", ".join(f"{k}: {v} points" for k, v in s["n_contacts"].items()))
    if "boundaries" in s:
        b = s["boundaries"]
        print(f"  boundaries:    {len(b['points'])} points refined along {b['axis']} to {b['rtol']:g} (relative)")
    if "first_split" in s:
        if s["first_split"] is None:
            print("  the count of stick phases never goes from 1 to 2 on this grid")
        else:
            lo, hi = s["first_split"]
            print(f"  first split (1 -> 2 stick phases) between kappa = {lo:.6g} and {hi:.6g} {s['kappa_unit']}")


def _finish_grid(args, result, setup: Setup) -> int:
    if result is None:
        return EXIT_INTERRUPTED
    summary = _grid_summary(result, args.out, setup)
    if args.json:
        _print_json(args, summary)
    else:
        _print_grid_summary(summary)
    if summary["failed"]:
        kinds = ", ".join(f"{k}: {v}" for k, v in summary["failures"].items())
        print(f"phaseimpact: {summary['failed']} of {summary['points']} points failed numerically ({kinds}); "
              f"they are stored with their status in {args.out}, and --resume recomputes them", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def run_atlas(args) -> int:
    import numpy as np

    _check_grid_options(args)
    setup = _setup(args)
    names = [axis.name for axis in args.axis]
    for name in names:
        if name in _setting_names(args) or (name in ("v", "kappa", "target") and _given(args, name)):
            option = f"--{name}" if _given(args, name) else f"--set {name}=..."
            raise ValueError(f"axis {name!r} is also given as {option}, which the axis would override; allowed: "
                             "one of them")
    for axis in args.axis:  # the command line's ranges (the grid checks each corner as a case)
        if axis.name == "v":
            _check_in_range("v", float(np.min(axis.values)), *V_RANGE, "m/s", "axis v")
            _check_in_range("v", float(np.max(axis.values)), *V_RANGE, "m/s", "axis v")
        elif axis.name == "kappa":
            _check_in_range("kappa", float(np.min(axis.values)), 0.0, KAPPA_MAX, KAPPA_UNIT, "axis kappa")
            _check_in_range("kappa", float(np.max(axis.values)), 0.0, KAPPA_MAX, KAPPA_UNIT, "axis kappa")
    size = int(np.prod([len(a.values) for a in args.axis]))
    if size > MAX_SWEEP_POINTS:
        raise ValueError(f"axis: the grid has {size} points; allowed: at most {MAX_SWEEP_POINTS}")
    if args.refine is not None and args.refine not in names:
        raise ValueError(f"refine = {args.refine!r} is out of range; allowed: one of the axes ({', '.join(names)})")
    result = _run_grid(args, setup, list(args.axis))
    if result is not None and args.refine is not None:
        from .. import archive
        from ..continuation import refine_boundaries

        _note(f"refining the class boundaries along {args.refine}")
        try:
            found = refine_boundaries(result, args.refine, refine_rtol=args.refine_rtol, rtol=args.rtol)
        except KeyboardInterrupt as stop:
            print(f"phaseimpact: {_stopped(stop)} while refining; the atlas is saved in {args.out} without its "
                  f"boundaries; resume with: {_resume_command(args.argv)}", file=sys.stderr)
            stop.reported = True
            raise
        result.extras["boundaries"] = {"axis": found.axis, "points": found.points, "below": found.below,
                                       "above": found.above, "rtol": found.rtol}
        with exclusive(args.out, "out"):
            archive.save(result, args.out, force=True)  # the same work, with its boundaries
    return _finish_grid(args, result, setup)
