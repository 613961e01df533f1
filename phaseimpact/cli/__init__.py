"""Command line: ``phaseimpact COMMAND``, the commands of :data:`COMMANDS` (``phaseimpact/cli/commands.py``,
whose docstring says how to add one).

A contract other tools rely on: SI units; ``--json`` prints one JSON object whose numbers are
finite or ``null``. Every argument is checked before any work: bad input prints one line naming
the parameter, its value and the allowed range, and exits with code 2 (no traceback). A run that
ends in a numerical failure (a trajectory, a sweep point, a lost curve) is reported and exits with
code 1. Ctrl-C exits with code 130 (a sweep or an atlas says how to resume).

Every computing command takes a case (``--case NAME|FILE.toml``, default ``seed``) and
``--set NAME=VALUE`` settings. What is used, from weakest to strongest: the built-in defaults,
the case's ``[impact]`` table, ``--set``, then the explicit options (``--v``, ``--kappa``,
``--law``, ``--contact``, ``--target``, ``--restitution``). Results and archives record the case
as it was used.
"""

from ._common import (
    CURVE_PARAMETERS,
    CURVE_WHATS,
    EXIT_BROKEN_PIPE,
    EXIT_FAILURE,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_USAGE,
    FIGURE_FORMATS,
    JSON_SCHEMA_VERSION,
    MAX_DASK_TASKS,
    RANGE_METAVAR,
)
from ._main import main
from .commands import COMMANDS, Command, build_parser

__all__ = ["COMMANDS", "CURVE_PARAMETERS", "CURVE_WHATS", "Command", "EXIT_BROKEN_PIPE", "EXIT_FAILURE",
           "EXIT_INTERRUPTED", "EXIT_OK", "EXIT_USAGE", "FIGURE_FORMATS", "JSON_SCHEMA_VERSION", "MAX_DASK_TASKS",
           "RANGE_METAVAR", "build_parser", "main"]
