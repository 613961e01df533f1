"""The commands of ``phaseimpact``: one table, :data:`COMMANDS`, from which :func:`build_parser` builds the
parser (and with it ``--help``, shell completion and the docs' command-line reference, docs/cli.md).

How to add a command
--------------------
1. Write its two functions in the module of its family (``runs``, ``grids``, ``trains``...) or in a new
   module ``phaseimpact/cli/NAME.py``:

   - ``add_NAME(p)`` adds its options to ``p``, its ``argparse`` parser: the shared ones from
     :mod:`._options` (``options.case_options(p)``, ``options.json_option(p)``...), its own with a
     ``type`` from :mod:`._common` that names the parameter, its value and the allowed range
     (``_real``, ``_integer``, ``_path``...).
   - ``run_NAME(args) -> int`` checks what the parser cannot (raise ``ValueError`` naming the
     parameter, its value and the allowed range: :func:`main` prints it in one line and exits 2),
     then does the work and returns an exit code (``EXIT_OK``, or ``EXIT_FAILURE`` after a line on
     stderr for a numerical failure). ``--json`` prints through ``_print_json(args, {...})``; add the
     command's keys to ``phaseimpact/schemas/cli-1.json`` (tests/test_json_schema.py checks each
     command that takes ``--json``).
   - The module imports NumPy, the engine or the archive inside ``run_NAME``, not at its top: the
     parser is built by every command, and those that integrate nothing start without them
     (tests/test_cache.py).

2. Add one :class:`Command` to :data:`COMMANDS` (and a new module to the imports below), where the
   command is to show in ``--help``:
   its name, the two functions, a one-line ``help`` and a ``description``; ``integrates=False`` for a
   command that compiles and integrates nothing (it then starts without numba or SciPy).

A command that takes ``--set`` gets the case's settable quantities as its help's epilog. Example, the
one tests/test_cli_registry.py adds and runs::

    # phaseimpact/cli/greeting.py
    from . import _options as options
    from ._common import EXIT_OK, _print_json

    def add_greet(p) -> None:
        p.add_argument("--name", default="world", help="whom to greet (default: %(default)s)")
        options.json_option(p)

    def run_greet(args) -> int:
        if args.json:
            _print_json(args, {"greeting": f"hello, {args.name}"})
        else:
            print(f"hello, {args.name}")
        return EXIT_OK

    # in COMMANDS
    Command("greet", greeting.add_greet, greeting.run_greet, integrates=False,
            help="print a greeting", description="Print a greeting."),
"""

from __future__ import annotations

import argparse
import dataclasses
from collections.abc import Callable

from .._version import __version__
from . import backends, curves, environment, figures, grids, inputs, runs, trains
from ._common import _Parser
from ._options import settable_epilog


@dataclasses.dataclass(frozen=True)
class Command:
    """One command: ``add(parser)`` adds its options, ``run(args)`` does its work and returns the exit code."""

    name: str
    add: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]
    help: str
    description: str
    #: False for a command that compiles and integrates nothing: it starts without the engine (numba, SciPy),
    #: whose Ctrl-C handling :func:`main` then does not install.
    integrates: bool = True


#: Every command, in the order of ``phaseimpact --help``.
COMMANDS: list[Command] = [
    Command("cases", inputs.add_cases, inputs.run_cases, integrates=False,
            help="the shipped cases (name, description, sources)",
            description="The named cases shipped with phaseimpact, for --case NAME."),
    Command("completion", environment.add_completion, environment.run_completion, integrates=False,
            help="the shell completion script (bash or zsh)",
            description="Print the completion script of phaseimpact's commands and options for a shell, generated "
                        "from this parser (shtab); e.g. in ~/.bashrc: eval \"$(phaseimpact completion bash)\"."),
    Command("warmup", environment.add_warmup, environment.run_warmup,
            help="compile the engine ahead, and say where its cache is",
            description="Compile every entry of the engine into its cache now (the first command that integrates "
                        "would otherwise do it, about a minute on 2 cores), and say where the cache is: for "
                        "containers, cluster workers and a fresh install (each user who cannot write the install "
                        "compiles once into ~/.cache/phaseimpact). On a warm cache it only loads."),
    Command("backends", backends.add_backends, backends.run_backends,
            help="which --backend choices work on this machine, and why not",
            description="Lists each backend of sweep and atlas (--backend) with whether it can run here: threads, "
                        "joblib processes (loky), a Dask cluster (dask), and a GPU (cuda, with what is missing "
                        "when there is none: the CUDA driver, NVVM or a device). orbit-diagram and "
                        "critical-curve take threads or cuda."),
    Command("check-law", inputs.add_check_law, inputs.run_check_law,
            help="run the law conformance suite on a law or a law file",
            description="The checks every shipped law passes (force, repulsive on loading, partials against finite "
                        "differences, energy ledger, momentum, scipy and the independent oracle), on a registered "
                        "law with each of its options, or on the laws a Python file defines with "
                        "phaseimpact.define_law. Every run has a step and time budget (a law whose integration "
                        "grinds fails within seconds). Exit code 1 when a check fails, 2 when the law file cannot be "
                        "loaded."),
    Command("params", inputs.add_params, inputs.run_params, integrates=False,
            help="a case's derived parameters, Hertz scales and validity",
            description="The derived parameters (seed eq. 3-5) of a case, its Hertz scales (contact time, plate "
                        "period, indentation, peak force, contact radius, peak pressure) and whether elastic Hertz "
                        "contact holds."),
    Command("simulate", runs.add_simulate, runs.run_simulate,
            help="one impact: summary quantities, stick points, outcome",
            description="One impact from seed eq. 6, integrated exactly (event-driven)."),
    Command("fixed-points", runs.add_fixed_points, runs.run_fixed_points,
            help="the equilibria (points or sets) with eigenvalues and stability",
            description="The equilibria of eq. 1 under the law, from its equations: isolated points or sets (the "
                        "separated set of a unilateral law, the stuck set of paper), each with the eigenvalues of "
                        "its linearisation and a stability label (docs/physics.md §5)."),
    Command("critical", runs.add_critical, runs.run_critical,
            help="the critical damping kappa_c and kappa_2 at one speed (law paper, or a Filippov user law)",
            description="The critical damping kappa_c of eq. 8 (law paper, or a Filippov user law): where the first "
                        "stick stops being permanent (an adding-sliding bifurcation), and kappa_2, from which the "
                        "run makes exactly two stick phases."),
    Command("transitions", runs.add_transitions, runs.run_transitions,
            help="every change of the long-time count in a kappa range",
            description="Every kappa in [KAPPA_MIN, KAPPA_MAX] where the long-time count changes, in order: the "
                        "adding-sliding at kappa_c and the end of the staircase at kappa_2 for paper (counts: stick "
                        "phases), grazing values for unilateral laws (counts: contacts before the projectile is out "
                        "of reach)."),
    Command("sweep", grids.add_sweep, grids.run_sweep,
            help="one axis: a sweep of kappa (or any parameter), archived to netCDF-4 (.nc)",
            description="Every value of one axis (usually kappa: --axis kappa=1e9:1e12:50:log), each run until its "
                        "outcome settles (or to --t-end): outcome class, stick phases, contacts, T_run, max force... "
                        "Archived to netCDF-4 (.nc) and checkpointed after every chunk. The same as atlas with one "
                        "axis."),
    Command("atlas", grids.add_atlas, grids.run_atlas,
            help="outcomes over a grid of any parameters, archived to netCDF-4 (.nc)",
            description="Every point of a grid over named parameters (kappa, v, M1, ..., and every settable quantity "
                        "of the case), each run until its outcome settles (or to --t-end): outcome class, stick "
                        "phases, contacts, T_run, max force... Archived to netCDF-4 (.nc) and checkpointed after "
                        "every chunk."),
    Command("critical-curve", curves.add_critical_curve, curves.run_critical_curve,
            help="kappa_c, kappa_2 or a grazing value against a parameter, archived to netCDF-4 (.nc)",
            description="A transition continued over a second parameter (v, a material or a geometry quantity): "
                        "kappa_c or kappa_2 of law paper, or a grazing value of a unilateral law; each point "
                        "predicted from the previous ones and corrected, with step control."),
    Command("plot", figures.add_plot, figures.run_plot,
            help="draw an archive: an atlas, a sweep or a curve",
            description="Draw an archive: an atlas (two axes: outcome classes as a colour map, log axes where the "
                        "axis is log), a sweep (one axis: counts and max force), or a critical curve (kappa against "
                        "the parameter, the closed form dashed)."),
    Command("portrait", figures.add_portrait, figures.run_portrait,
            help="phase portraits, one panel per kappa, events marked",
            description="Phase portraits: one panel per kappa, the trajectory in a phase plane with its events "
                        "marked (contacts, separations, slips, stick phases; permanent sticks as asymptotic points) "
                        "and its outcome in the panel's title."),
    Command("train", trains.add_train, trains.run_train,
            help="a train of impacts: one projectile every T seconds on the plate as the last left it",
            description="A projectile of the case arrives every --period seconds on the plate as the previous "
                        "impacts left it (the impact map, docs/physics.md §7): per impact the plate's state before "
                        "it, its amplitude, the peak force, the energy dissipated and the restitution; --fixed-point "
                        "adds the period-1 orbit of the map with its Floquet multipliers."),
    Command("orbit-diagram", trains.add_orbit_diagram, trains.run_orbit_diagram,
            help="the impact map's attractor over T, kappa or v",
            description="The impact map iterated at each value of --axis (the period T, kappa or v) from a plate at "
                        "rest: --transients impacts dropped, then --samples plate states kept (one point each); the "
                        "number of distinct points tells a fixed point (1), a period-k orbit (k) or irregular motion."),
    Command("map-continuation", trains.add_map_continuation, trains.run_map_continuation,
            help="a branch of periodic orbits of the impact map over T, kappa or v, with its bifurcations",
            description="The period-K orbit of the impact map followed over the --axis parameter from START to STOP "
                        "(pseudo-arclength continuation, docs/physics.md §7), its Floquet multipliers along the way, "
                        "and its period-doubling (a multiplier through -1), fold (through +1), Neimark-Sacker (a "
                        "complex pair through the unit circle) and grazing points (the contacts per period change) "
                        "located by bisection."),
    Command("basins", trains.add_basins, trains.run_basins,
            help="basins of attraction of the impact map over the plate's initial state",
            description="From each initial plate state (x2, x2dot) of an N x N grid (--grid N: evenly spaced "
                        "positions from -X to X by velocities from -V to V, --x2-max X, --x2dot-max V) the impact "
                        "map is iterated until a period up to --max-period repeats (docs/physics.md §7); each state "
                        "is labelled by the attractor it reaches (attractors told apart by their points and period), "
                        "or as reaching none."),
]


def find(name: str) -> Command:
    """The command called ``name`` (a name the parser accepted)."""
    return next(command for command in COMMANDS if command.name == name)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="phaseimpact", description="Impact models analysed as dynamical systems: one impact, "
                                                     "the critical damping and the other transitions, sweeps, "
                                                     "atlases and continued curves over a case's parameters, and "
                                                     "their figures.",
                     epilog="SI units throughout. Exit codes: 0 done, 1 numerical failure (reported), "
                            "2 bad input (nothing computed), 130 interrupted.")
    parser.add_argument("--version", action="version", version=f"phaseimpact {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    epilog = settable_epilog()
    for command in COMMANDS:
        p = sub.add_parser(command.name, help=command.help, description=command.description)
        command.add(p)
        if any(action.dest == "set" for action in p._actions):
            p.epilog = epilog
        p.set_defaults(func=command.run)
    return parser
