"""Figures: an archive drawn (``plot``) and phase portraits (``portrait``)."""

from __future__ import annotations

import math
import os
import sys

from .._atomic import exclusive
from ..parameters import KAPPA_MAX
from . import _options as options
from ._case import Setup, _check_reads_kappa, _law_fields, _setup
from ._common import (
    EXIT_FAILURE,
    EXIT_OK,
    KAPPA_UNIT,
    MAX_PANELS,
    PLANES,
    _check_figure_target,
    _kappa_list,
    _note,
    _print_json,
)


def add_plot(p) -> None:
    p.add_argument("archive", metavar="FILE.nc", help="archive written by sweep, atlas or critical-curve")
    options.figure_out(p)
    p.add_argument("--contours", choices=("none", "n_stick", "n_contacts"), default="none",
                   help="atlas only: overlay the level lines of this count (default: %(default)s)")
    p.add_argument("--curve", action="append", default=None, metavar="CURVE.nc",
                   help="atlas only: overlay a critical curve over the atlas's second axis; repeatable "
                        "(default: none)")
    options.json_option(p)


def run_plot(args) -> int:
    from .. import archive

    _check_figure_target(args.out, args.force)
    if os.path.abspath(args.out) == os.path.abspath(args.archive):
        raise ValueError(f"out = {args.out!r} is the archive itself; allowed: another path")
    result = archive.load(args.archive)
    curves = [archive.load(path) for path in (args.curve or [])]
    from .. import plotting
    from ..continuation import CriticalCurve
    from ..train import Basins, OrbitDiagram

    if archive.kind_of(result) in archive.RUN_KINDS:
        portrait = "; its phase portrait: phaseimpact portrait" if archive.kind_of(result) == "trajectory" else ""
        raise ValueError(f"archive = {args.archive!r} is a {archive.kind_of(result)} archive, which plot does not "
                         "draw; allowed: a sweep, an atlas, a critical curve, an orbit diagram, basins or a map branch "
                         f"(its contents: phaseimpact.archive.load or to_xarray{portrait})")
    if archive.kind_of(result) in archive.TRAIN_KINDS:
        kind = archive.kind_of(result)
        if kind == "impact-train":
            raise ValueError(f"archive = {args.archive!r} is an impact train, which plot does not draw; allowed: a "
                             "sweep, an atlas, a critical curve, an orbit diagram, basins or a map branch (a train's "
                             "columns: phaseimpact.archive.to_xarray)")
        if args.contours != "none" or curves:
            raise ValueError(f"archive = {args.archive!r} is a {kind} archive: --contours and --curve are read only "
                             "for an atlas; allowed: an atlas archive with them")
        if isinstance(result, OrbitDiagram):
            fig = plotting.plot_orbit_diagram(result)
        elif isinstance(result, Basins):
            fig = plotting.plot_basins(result)
        else:
            with plotting.style():
                fig, axes = plotting.figure(width=plotting.COLUMN_WIDTH)
                ax = axes.flat[0]
                scale, label = {"T": (1e-3, "period T (ms)"), "v": (1.0, "impact speed v (m/s)")}.get(
                    result.param, (1.0, "damping κ"))
                plotting.plot_map_branch(ax, result, x_scale=scale)
                ax.set_xlabel(label)
                ax.set_ylabel("x2 before impact (µm)")
                ax.legend(loc="best")
    elif isinstance(result, CriticalCurve):
        if args.contours != "none" or curves:
            raise ValueError(f"archive = {args.archive!r} is a critical curve: --contours and --curve are read only "
                             "for an atlas; allowed: an atlas archive with them")
        fig = plotting.plot_curve(result)
        kind = "curve"
    else:
        ndim = len(result.grid.axes)
        for curve in curves:
            if not isinstance(curve, CriticalCurve):
                raise ValueError("curve: allowed: a critical-curve archive (phaseimpact critical-curve --out ...)")
        if ndim == 1:
            if args.contours != "none" or curves:
                raise ValueError(f"archive = {args.archive!r} is a sweep (one axis): --contours and --curve are read "
                                 "only for an atlas; allowed: an atlas archive with them")
            fig = plotting.plot_sweep(result)
            kind = "sweep"
        elif ndim == 2:
            names = result.grid.names
            for curve in curves:
                if set(names) != {"kappa", curve.param}:
                    raise ValueError(f"curve over {curve.param!r} cannot be drawn on an atlas over "
                                     f"{', '.join(names)}; allowed: an atlas with axes kappa and {curve.param}")
            fig = plotting.plot_atlas(result, contours=None if args.contours == "none" else args.contours,
                                      curves=curves)
            kind = "atlas"
        else:
            raise ValueError(f"archive = {args.archive!r} has {ndim} axes ({', '.join(result.grid.names)}); "
                             "allowed: 1 (a sweep) or 2 (an atlas)")
    with exclusive(args.out, "out"):
        plotting.save(fig, args.out)
    if args.json:
        _print_json(args, {"out": args.out, "archive": args.archive, "kind": kind})
    else:
        print(f"wrote {args.out} ({kind} of {args.archive})")
    return EXIT_OK



def add_portrait(p) -> None:
    options.case_options(p)
    options.law_options(p, restitution=False)
    options.speed(p)
    options.target(p)
    p.add_argument("--kappa", dest="kappas", type=_kappa_list, required=True, metavar="K1,K2,...",
                   help=f"damping coefficients ({KAPPA_UNIT}), 1 to {MAX_PANELS} values in [0, {KAPPA_MAX:g}], "
                        "one panel each")
    p.add_argument("--plane", choices=PLANES, default=PLANES[0],
                   help="phase plane: relative motion, projectile or target (default: %(default)s)")
    options.horizon(p)
    options.tolerance(p)
    options.figure_out(p)
    options.json_option(p)


PORTRAIT_SAMPLES = 400_000


def _portrait_runs(args, setup: Setup):
    """Each ``--kappa``'s run until its outcome settles (for the events, the counts and the title) and
    the same run sampled for drawing: where the integrator stepped (a few points per step) and the
    first contact finely; a permanent stick is drawn on for two plate periods (the stuck pair's orbit)."""
    import numpy as np

    from ..integrate import scales, simulate

    summaries, drawn = [], []
    period = scales(setup.params).plate_period
    for kappa in args.kappas:
        p = setup.params.replace(kappa=kappa)
        summary = simulate(p, setup.law, args.t_end, rtol=args.rtol)
        end = summary.t_stop
        if args.t_end is None and summary.outcome == "permanent-stick" and math.isfinite(period):
            end += 2 * period
        if not end > 0:
            end = summary.t_end
        steps = simulate(p, setup.law, end, rtol=args.rtol, save="steps", stop_when_settled=False).t
        per_step = int(np.clip(PORTRAIT_SAMPLES // max(len(steps), 1), 1, 16))
        fine = steps[:-1, None] + np.diff(steps)[:, None] * (np.arange(per_step) / per_step)
        first = np.linspace(0.0, min(end, 3 * scales(p).contact_time), 401)
        times = np.unique(np.concatenate([fine.ravel(), steps, first, np.linspace(0.0, end, 401)]))
        times = times[(times >= 0) & (times <= end)]
        drawn.append(simulate(p, setup.law, end, rtol=args.rtol, save=times, stop_when_settled=False))
        summaries.append(summary)
    return summaries, drawn


def run_portrait(args) -> int:
    from .. import plotting

    _check_figure_target(args.out, args.force)
    setup = _setup(args)
    _check_reads_kappa(setup.law, "panel")
    plane = tuple(args.plane.split(","))
    _note(f"integrating {len(args.kappas)} trajectories of {setup.law.label()}")
    with exclusive(args.out, "out"):  # one writer: a second one is refused now, not after the work
        summaries, drawn = _portrait_runs(args, setup)
        title = f"{setup.law.label()}, {setup.case.name}, v = {setup.params.v:g} m/s, {setup.params.target} target"
        plotting.save(plotting.plot_portraits(drawn, plane, summaries=summaries, title=title), args.out)
    panels = [{"kappa": float(k), "outcome": tr.outcome, "status": tr.status, "stop_reason": tr.stop_reason,
               "n_stick": tr.n_stick, "n_contacts": tr.n_contacts, "cut": tr.cut, "t_stop": tr.t_stop}
              for k, tr in zip(args.kappas, summaries, strict=True)]
    if args.json:
        _print_json(args, {"out": args.out, **_law_fields(setup), "v": setup.params.v, "plane": list(plane),
                     "panels": panels, "case": setup.case.as_dict()})
    else:
        print(f"wrote {args.out}: {len(panels)} panel(s) in the ({', '.join(plane)}) plane")
        for p in panels:
            print(f"  kappa = {p['kappa']:.6g}: {p['outcome']}, {p['n_stick']} stick phase(s), "
                  f"{p['n_contacts']} contact(s)")
    failed = [p for p in panels if p["status"] != "success"]
    if failed:
        print("phaseimpact: numerical failure in " + ", ".join(f"kappa = {p['kappa']:g} ({p['status']})"
                                                               for p in failed)
              + "; drawn up to where it stopped", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK
