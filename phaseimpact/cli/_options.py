"""The options more than one command takes, each defined once: a command's ``add_*`` calls these."""

from __future__ import annotations

import argparse

from ..parameters import KAPPA_MAX, TARGETS, V_RANGE
from ..settings import SETTABLE
from ._common import (
    _KAPPA,
    _KAPPA_RTOL,
    _RESTITUTION,
    _RTOL,
    _T_END,
    _V,
    BACKENDS,
    DEFAULT_SAMPLES,
    KAPPA_RTOL_RANGE,
    KAPPA_UNIT,
    MAX_DASK_TASKS,
    MAX_JOBS,
    MAX_SWEEP_POINTS,
    RANGE_METAVAR,
    RESTITUTION_RANGE,
    SAMPLES_RANGE,
    _axis,
    _case,
    _figure_path,
    _integer,
    _jobs,
    _path,
    _real,
    _setting,
)


def _settable_help() -> str:
    return ", ".join(f"{name} ({unit})" if unit else name for name, (unit, _) in SETTABLE.items())


class Removed(argparse.Action):
    """An option of an earlier version: refused with the ``--axis`` that replaces it (hidden from the help)."""

    def __init__(self, option_strings, dest, example="kappa=1e9:1e14:50:log", **kwargs):
        self.example = example
        super().__init__(option_strings, dest, nargs="?", help=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        example = f"{values}" if option_string == "--range" and values and "=" in values else self.example
        parser.error(f"{option_string} was removed; allowed: --axis {RANGE_METAVAR} (NUM values from START to "
                     f"STOP, log spaced with :log) or --axis NAME=V1,V2,..., e.g. --axis {example}")


def case_options(p):
    p.add_argument("--case", type=_case, default=None, metavar="NAME|FILE.toml",
                   help="a shipped case (see 'phaseimpact cases') or a TOML case file; its [impact] values "
                        "are used unless an option overrides them (default: seed)")
    p.add_argument("--set", type=_setting, action="append", default=None, metavar="NAME=VALUE",
                   help="change one quantity of the case, SI units; repeatable, later ones win; names: "
                        f"{_settable_help()} (default: none)")


def law_options(p, *, restitution=True, contact=True):
    from ..model import REGISTRY  # the shipped laws and those of --law-file (loaded before parsing)

    p.add_argument("--law", choices=tuple(REGISTRY), default=None,
                   help="contact law (default: the case's, else paper)")
    p.add_argument("--law-file", default=None, metavar="FILE.py",
                   help="a Python file that defines laws with phaseimpact.define_law (then --law NAME); see "
                        "'phaseimpact check-law FILE.py' (default: none)")
    if contact:
        p.add_argument("--contact", choices=("printed", "unilateral"), default=None,
                       help="Filippov laws (paper) only: read |delta|^alpha as printed (also in tension) or "
                            "unilaterally (P = 0 for delta <= 0) (default: the case's, else printed)")
    if restitution:
        lo, hi = RESTITUTION_RANGE
        p.add_argument("--restitution", type=_RESTITUTION, default=None, metavar="E",
                       help=f"coefficient of restitution, {lo:g} <= E <= {hi:g}: required by the restitution "
                            "laws; replaces --kappa for hunt-crossley (exact inverse) (default: the case's, "
                            "else none)")


def speed(p):
    v_lo, v_hi = V_RANGE
    p.add_argument("--v", type=_V, default=None, metavar="V",
                   help=f"impact speed, m/s, {v_lo:g} <= V <= {v_hi:g} (default: the case's, 1 for seed)")


def damping(p, read_by=None):
    from ..model import REGISTRY

    readers = [n for n, x in REGISTRY.items() if x.damping == "kappa"]
    units = {}
    for n in readers:
        units.setdefault(REGISTRY[n].damping_unit(1.5), []).append(n)
    unit = "; ".join(f"{u} for {', '.join(names)}" for u, names in units.items())
    read_by = read_by or f"read by {', '.join(readers)} only"
    p.add_argument("--kappa", type=_KAPPA, default=None,
                   help=f"damping coefficient in the law's unit (alpha = 3/2: {unit}), 0 <= KAPPA <= "
                        f"{KAPPA_MAX:g}; {read_by} (default: the case's, else 0)")


def target(p):
    p.add_argument("--target", choices=TARGETS, default=None,
                   help="what is hit (default: the case's, else plate)")


def tolerance(p):
    p.add_argument("--rtol", type=_RTOL, default=1e-10,
                   help="integrator tolerance (relative), %(type)s (default: %(default)s)")


def kappa_tolerance(p, what="width of kappa_c's final bracket"):
    lo, hi = KAPPA_RTOL_RANGE
    p.add_argument("--kappa-rtol", type=_KAPPA_RTOL, default=1e-10,
                   help=f"relative {what}, {lo:g} <= KAPPA_RTOL <= {hi:g} (default: %(default)s)")


def horizon(p, what="horizon of every run"):
    p.add_argument("--t-end", type=_T_END, default=None,
                   help=f"{what}, s, a finite number > 0 (default: each run until its outcome settles, "
                        "capped by the case's own time scales)")


def axis_option(p, what, *, repeat=False, names="kappa, v, M1, M2, K, Kb, Km, alpha and the --set names",
                limit=MAX_SWEEP_POINTS):
    """The one range syntax of every command that computes over a list of values."""
    p.add_argument("--axis", type=_axis, action="append", required=True, metavar=RANGE_METAVAR,
                   help=f"{what}: NAME=START:STOP:NUM (NUM values, linear; with :log, log spaced) or "
                        f"NAME=V1,V2,...; names: {names}; at most {limit} values in all"
                        + ("" if repeat else "; once"))


def kappa_range(p, required, default_min="", default_max=""):
    kmin = _real("kappa-min", 0.0, KAPPA_MAX, low_open=True, unit=KAPPA_UNIT)
    kmax = _real("kappa-max", 0.0, KAPPA_MAX, low_open=True, unit=KAPPA_UNIT)
    p.add_argument("--kappa-min", type=kmin, default=None, required=required,
                   help=f"lower end of kappa ({KAPPA_UNIT}), 0 < KAPPA_MIN <= {KAPPA_MAX:g}{default_min}")
    p.add_argument("--kappa-max", type=kmax, default=None, required=required,
                   help=f"upper end of kappa ({KAPPA_UNIT}), KAPPA_MIN < KAPPA_MAX <= {KAPPA_MAX:g}{default_max}")


def samples(p, default):
    lo, hi = SAMPLES_RANGE
    p.add_argument("--samples", type=_integer("samples", lo, hi), default=default,
                   help=f"log-spaced kappa values sampled to find where a count changes (a window narrower "
                        f"than the sampling can be missed), {lo} <= SAMPLES <= {hi} (default: {DEFAULT_SAMPLES})")


def parallel(p):
    p.add_argument("--jobs", type=_jobs, default=1,
                   help=f"parallel workers, 1..{MAX_JOBS}, or -1 for all cores; with --backend dask the tasks "
                        f"in flight, up to {MAX_DASK_TASKS}, -1 for every thread of the cluster's workers "
                        "(default: %(default)s)")
    p.add_argument("--backend", choices=BACKENDS, default="threads",
                   help="threads of this process, joblib processes (loky), a Dask cluster, or a GPU (cuda: one "
                        "thread per point; phaseimpact backends says whether it works here) (default: %(default)s)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="Dask scheduler address, e.g. tcp://host:8786 (only with --backend dask; default: a "
                        "local in-process cluster)")


def out_options(p, resume):
    p.add_argument("--out", type=_path("out"), required=True, metavar="FILE.nc",
                   help="netCDF-4/CF archive to write, .nc (docs/archive.md; written atomically; refused if it "
                        "exists and is not an archive of the same work, unless --force)")
    p.add_argument("--force", action="store_true",
                   help="replace --out even if it holds something else (default: refuse)")
    if resume:
        p.add_argument("--resume", action="store_true",
                       help="complete the partial archive --out (same options) without recomputing its "
                            "finished points; failed points are recomputed")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bar (there is one only when stderr is a terminal)")


def run_out(p, what):
    p.add_argument("--out", type=_path("out"), default=None, metavar="FILE.nc",
                   help=f"also write {what} as a netCDF-4/CF archive, .nc (docs/archive.md; written atomically; "
                        "phaseimpact.archive.load reads it back; refused if it exists and is not an archive of "
                        "the same work, unless --force) (default: none)")
    p.add_argument("--force", action="store_true",
                   help="replace --out even if it holds something else (default: refuse)")


def figure_out(p):
    p.add_argument("--out", type=_figure_path, required=True, metavar="FIG.png",
                   help="figure to write, .png, .pdf or .svg (written atomically; an existing file that is "
                        "not such a figure is refused unless --force)")
    p.add_argument("--force", action="store_true",
                   help="replace --out even if it is not a figure (default: refuse)")


def json_option(p):
    p.add_argument("--json", action="store_true", help="print one JSON object (numbers finite or null)")


def train_archive_option(p, force=True):
    p.add_argument("--archive", type=_path("archive"), default=None, metavar="FILE.nc",
                   help="also write the result as a netCDF-4/CF archive (docs/archive.md; phaseimpact.archive.load "
                        "reads it back); an existing archive is replaced, another file only with --force "
                        "(default: none)")
    if force:
        p.add_argument("--force", action="store_true",
                       help="replace --archive even if it is not an archive (default: refuse)")


def settable_epilog() -> str:
    """The epilog of every command that takes ``--set``: the quantities it sets, with their units."""
    return "Settable with --set NAME=VALUE (SI units): " + "; ".join(
        f"{name} ({unit}): {text}" if unit else f"{name}: {text}" for name, (unit, text) in SETTABLE.items()) + "."
