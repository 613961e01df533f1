"""What every command shares: exit codes and limits, the parser class, the argument types (each names
the parameter, its value and the allowed range), and the output (``--json``, notes, numbers)."""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shlex
import sys

from .._atomic import check_target
from ..parameters import KAPPA_MAX, V_RANGE

EXIT_OK, EXIT_FAILURE, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130
#: A reader that went away (``| head``): what a POSIX tool killed by SIGPIPE reports (128 + 13), not a failure.
EXIT_BROKEN_PIPE = 141

#: Relative width of kappa_c's bracket (critical, critical-curve), or of a transition's location.
KAPPA_RTOL_RANGE = (1e-14, 1e-2)
#: Coefficient of restitution.
RESTITUTION_RANGE = (1e-6, 1.0)
#: Points of one sweep or atlas: its columns (about 200 bytes a point) stay in memory.
MAX_SWEEP_POINTS = 10_000_000
#: Values of one critical curve (each is a root search).
MAX_CURVE_POINTS = 1000
#: Impacts of one train (phaseimpact.train.impact_train's limit).
MAX_TRAIN_IMPACTS = 100_000
#: Largest initial plate state of ``basins``, in the grid's natural scales (the plate's swing at speed v, 1.5 v).
MAX_BASIN_SCALES = 1e6
#: The range syntax every command that computes over values takes (``--axis``).
RANGE_METAVAR = "NAME=START:STOP:NUM[:log]"
#: kappa samples of a transition search (each is one run), and the default.
SAMPLES_RANGE = (8, 10_000)
DEFAULT_SAMPLES = 96
#: Panels of one phase portrait.
MAX_PANELS = 12
MAX_JOBS = 4 * (os.cpu_count() or 1)
#: Tasks in flight on a Dask cluster (phaseimpact.continuation._parallel.MAX_DASK_TASKS).
MAX_DASK_TASKS = 100_000
#: --backend's choices, phaseimpact.continuation._parallel.BACKENDS (the parser imports no NumPy).
BACKENDS = ("threads", "loky", "dask", "cuda")
#: Statuses of critical_damping that are answers (anything else is a failure: exit 1).
CRITICAL_ANSWERS = ("success", "not-found", "unconfirmed")
#: What a critical curve continues.
CURVE_WHATS = ("kappa_c", "kappa_2", "grazing")
#: Parameters a critical curve can run over (besides the settable names of a case).
CURVE_PARAMETERS = ("v", "M1", "M2", "K", "Kb", "Km", "alpha")
PLANES = ("delta,deltadot", "x1,x1dot", "x2,x2dot")
#: Figure formats ``plot`` and ``portrait`` write, with the first bytes of such a file.
FIGURE_FORMATS = {".png": (b"\x89PNG",), ".pdf": (b"%PDF",), ".svg": (b"<?xml", b"<svg")}
#: kappa's unit where a message is written before the law is known: each law's entry names its own
#: (``LawEntry.damping_unit``, e.g. N s/m^2.5 for a Hunt-Crossley-type law on Hertz contact).
KAPPA_UNIT = "in the law's damping unit"
#: Version of the ``--json`` contract (``phaseimpact/schemas/cli-<version>.json``): raised when a key
#: is removed or changes meaning; new keys do not raise it.
JSON_SCHEMA_VERSION = 1


#: argparse takes "-inf" or "-1e-300" for an option (its own pattern knows "-1" and "-.5" only): every
#: negative number float() reads is a value here, so that its range can be named.
_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)(e[-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


def _check_environment() -> None:
    """The environment this process runs in, checked before any work (``ValueError`` names it)."""
    from .._environment import gpu_calls_kept, numba_num_threads, source_date_epoch
    from .._jit import linked_only_requested

    if sys.stdout is None:  # started with stdout closed (cmd >&-): nothing could be reported
        raise ValueError("stdout is closed; allowed: an open standard output (redirect it to a file or /dev/null)")
    source_date_epoch()
    numba_num_threads()
    linked_only_requested()  # PHASEIMPACT_LINKED_ONLY: read only by a first compile, checked every time
    gpu_calls_kept()  # PHASEIMPACT_GPU_CALLS: read only by the GPU kernel's first compile, checked every time


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER

    def parse_args(self, args=None, namespace=None):
        try:
            _check_environment()
        except ValueError as error:
            self.error(str(error))
        return super().parse_args(args, namespace)

    def parse_known_args(self, args=None, namespace=None):
        self._given = list(sys.argv[1:] if args is None else args)  # a subcommand's parser gets its own words
        return super().parse_known_args(args, namespace)

    def error(self, message):
        choice = re.fullmatch(r"(argument (\S+)): invalid choice: (.*) \(choose from (.*)\)", message)
        if choice:  # the same wording as every other range message
            label, option, value, allowed = choice.groups()
            message = f"{label}: {option.lstrip('-')} = {value} is out of range; allowed: one of {allowed}"
        missing = re.fullmatch(r"argument (--[\w.-]+): expected one argument", message)
        given = getattr(self, "_given", [])
        if missing:  # argparse takes a value starting with '-' for an option
            for option, value in zip(given, given[1:], strict=False):
                if option == missing.group(1) and value.startswith("-"):
                    message += f" (a value that starts with '-' is written {option}={value})"
                    break
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
    if not (math.isfinite(value) and value == int(value) and (value == -1 or 1 <= value <= MAX_DASK_TASKS)):
        raise _out_of_range("jobs", text, f"an integer 1 <= jobs <= {MAX_JOBS} (4 per core; with --backend dask, "
                                          f"tasks in flight, up to {MAX_DASK_TASKS}), or -1 for all cores")
    return int(value)


def _path(name):
    def parse(text):
        try:
            return check_target(text, name)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None
    parse.__name__ = name
    return parse


def _figure_path(text):
    """A figure to write: a writable path ending in .png, .pdf or .svg."""
    suffix = os.path.splitext(text)[1].lower()
    if suffix not in FIGURE_FORMATS:
        raise _out_of_range("out", text, "a figure path ending in " + ", ".join(FIGURE_FORMATS) + " (e.g. fig.png)")
    return _path("out")(text)


def _case(text):
    """argparse type: a shipped case name or a case file, loaded and validated now."""
    from ..case import list_cases, load_case

    try:
        return load_case(text)
    except ValueError as error:
        if "unknown case" in str(error):
            names = ", ".join(c["name"] for c in list_cases())
            raise _out_of_range("case", text, f"a shipped case ({names}; see 'phaseimpact cases') or a .toml "
                                              "case file") from None
        raise argparse.ArgumentTypeError(f"case = {text!r}: {error}") from None
    except (OSError, UnicodeError) as error:  # a path the system refuses outright (NUL bytes...)
        raise _out_of_range("case", text, f"a shipped case name or a readable .toml file ({error})") from None


_case.__name__ = "case"


def _setting(text):
    """argparse type: ``NAME=VALUE`` with a settable name and a number (its range is checked with the case)."""
    from ..settings import parse_setting

    try:
        parse_setting(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(f"set: {error}") from None
    return text


_setting.__name__ = "set"


def _axis(text):
    """argparse type: ``NAME=START:STOP:NUM[:log]`` or ``NAME=V1,V2,...``."""
    from ..continuation import parse_axis

    try:
        return parse_axis(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


_axis.__name__ = "axis"


def _kappa_list(text):
    """argparse type: ``K1,K2,...``, 1 to :data:`MAX_PANELS` values in [0, KAPPA_MAX]."""
    allowed = f"1 to {MAX_PANELS} comma-separated numbers 0 <= kappa <= {KAPPA_MAX:g} ({KAPPA_UNIT})"
    parts = [p.strip() for p in str(text).split(",")]
    if not 1 <= len(parts) <= MAX_PANELS:
        raise _out_of_range("kappa", text, allowed)
    values = []
    for part in parts:
        try:
            value = float(part)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and 0 <= value <= KAPPA_MAX):
            raise _out_of_range("kappa", text, allowed)
        values.append(value)
    return values


_kappa_list.__name__ = "kappa"

_V = _real("v", *V_RANGE, unit="m/s")
_KAPPA = _real("kappa", 0.0, KAPPA_MAX, unit=KAPPA_UNIT)
_T_END = _real("t-end", 0.0, low_open=True, unit="s")


class _Rtol:
    """argparse type of --rtol, reading the engine's range only when --rtol is given or its help is
    shown (importing the engine costs 0.3 s, which the commands that integrate nothing do not pay).
    No ``__name__``: argparse would show that for %(type)s."""

    def __call__(self, text):
        from ..integrate import RTOL_RANGE

        return _real("rtol", *RTOL_RANGE)(text)

    def __str__(self):  # the help's %(type)s
        from ..integrate import RTOL_RANGE

        return f"{RTOL_RANGE[0]:g} <= RTOL <= {RTOL_RANGE[1]:g}"


_RTOL = _Rtol()
_KAPPA_RTOL = _real("kappa-rtol", *KAPPA_RTOL_RANGE)
_RESTITUTION = _real("restitution", *RESTITUTION_RANGE)



# ------------------------------------------------------------------------------------------------
# Output
# ------------------------------------------------------------------------------------------------

def _finite(value):
    """JSON-safe: non-finite numbers become null, NumPy scalars plain numbers."""
    if isinstance(value, dict):
        return {str(k): _finite(v) for k, v in value.items()}
    np = sys.modules.get("numpy")  # a NumPy value means NumPy is imported: asking costs no import
    if isinstance(value, (list, tuple)) or (np is not None and isinstance(value, np.ndarray)):
        return [_finite(v) for v in value]
    if isinstance(value, bool) or (np is not None and isinstance(value, np.bool_)):
        return bool(value)
    if isinstance(value, float) or (np is not None and isinstance(value, np.floating)):
        return float(value) if math.isfinite(value) else None
    if np is not None and isinstance(value, np.integer):
        return int(value)
    return value


def _print_json(args, obj: dict) -> None:
    """The one JSON object of ``--json``: ``schema_version`` and ``command`` first, then ``obj``
    (``phaseimpact/schemas/cli-1.json`` describes every command's keys)."""
    header = {"schema_version": JSON_SCHEMA_VERSION, "command": args.command}
    print(json.dumps(_finite({**header, **obj}), allow_nan=False, indent=2))


def _progress(args) -> bool:
    """Whether to draw a progress bar: for people (stderr a terminal), never into a log file."""
    return sys.stderr.isatty() and not args.no_progress


def _note(text: str) -> None:
    """A progress note for people: only when stderr is a terminal."""
    if sys.stderr.isatty():
        print(f"phaseimpact: {text}", file=sys.stderr, flush=True)


def _fmt(value, unit="", spec=".6g"):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "undefined"
    return f"{value:{spec}}{' ' + unit if unit else ''}"


#: The unit of each quantity ``params`` prints (and of the parameter a critical curve runs over).
PARAM_UNITS = {"M1": "kg", "M2": "kg", "K": "N/m^1.5", "Kb": "N/m", "Km": "N/m^3", "alpha": "",
               "v": "m/s", "R": "m", "contact_time": "s", "plate_period": "s", "indentation": "m", "peak_force": "N",
               "contact_radius": "m", "peak_pressure": "Pa", "first_yield_pressure": "Pa",
               "pressure_to_first_yield": "", "hertz_mass": "kg", "limiting_pressure": "Pa",
               "yield_velocity": "m/s", "plate_impedance": "N s/m", "zener_lambda": "", "plate_mass": "kg",
               "mass_ratio": ""}


def _check_figure_target(path: str, force: bool) -> None:
    """Refuse a format the plotting layer does not write, and to replace an existing file that is not a
    figure of the format asked for, unless ``force``: before any work."""
    from ..plotting import figure_format

    figure_format(path)
    if force or not os.path.isfile(path):
        return
    magic = FIGURE_FORMATS[os.path.splitext(path)[1].lower()]
    try:
        with open(path, "rb") as handle:
            head = handle.read(64).lstrip()
    except OSError:
        head = b""
    if not head.startswith(magic):
        raise ValueError(f"out = {path!r} exists and is not a {os.path.splitext(path)[1]} figure; refusing to "
                         "overwrite it (choose another path, or add --force to replace it)")


def _one_axis(args, note=""):
    """The one ``--axis`` of a command that runs over one parameter."""
    if len(args.axis) != 1:
        raise ValueError(f"axis is given {len(args.axis)} times; allowed: once for {args.command}{note}")
    return args.axis[0]


def _resume_command(argv) -> str:
    words = ["phaseimpact", *argv]
    if "--resume" not in words:
        words.append("--resume")
    return shlex.join(words)


def _stopped(stop: KeyboardInterrupt) -> str:
    from .. import _signals

    return "terminated (SIGTERM)" if isinstance(stop, _signals.Terminated) else "interrupted"
