"""Command line: ``phaseimpact {cases, warmup, params, simulate, fixed-points, critical, transitions, sweep, atlas,
critical-curve, plot, portrait}``.

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

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import math
import os
import re
import shlex
import signal
import sys
import threading

from ._atomic import check_target, exclusive
from ._version import __version__
from .case import QUANTITIES, SETTABLE, setting_name
from .parameters import KAPPA_MAX, TARGETS, V_RANGE

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
BACKENDS = ("threads", "loky", "dask")
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
    from ._environment import numba_num_threads, source_date_epoch
    from ._jit import linked_only_requested

    if sys.stdout is None:  # started with stdout closed (cmd >&-): nothing could be reported
        raise ValueError("stdout is closed; allowed: an open standard output (redirect it to a file or /dev/null)")
    source_date_epoch()
    numba_num_threads()
    linked_only_requested()  # PHASEIMPACT_LINKED_ONLY: read only by a first compile, checked every time


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
    from .case import list_cases, load_case

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
    from .case import parse_setting

    try:
        parse_setting(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(f"set: {error}") from None
    return text


_setting.__name__ = "set"


def _axis(text):
    """argparse type: ``NAME=START:STOP:NUM[:log]`` or ``NAME=V1,V2,...``."""
    from .continuation import parse_axis

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
        from .integrate import RTOL_RANGE

        return _real("rtol", *RTOL_RANGE)(text)

    def __str__(self):  # the help's %(type)s
        from .integrate import RTOL_RANGE

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


# ------------------------------------------------------------------------------------------------
# The case, the law and the parameters (all checks before any work)
# ------------------------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Setup:
    """What a command computes with: the case as used (its ``[impact]`` table holds the resolved
    speed, damping, target, law, reading and restitution), the law and the parameters."""

    case: object
    law: object
    params: object


def _given(args, name):
    return getattr(args, name, None) is not None


def _setting_names(args) -> list[str]:
    return [setting_name(text.partition("=")[0]) for text in (getattr(args, "set", None) or [])]


def _check_in_range(name, value, low, high, unit, source):
    if not (math.isfinite(value) and low <= value <= high):
        raise ValueError(f"{name} = {value!r} ({source}) is out of range; allowed: {low:g} <= {name} <= {high:g} "
                         f"({unit})")


def _resolve_law(args, impact: dict):
    """The contact law from the options, else from the case; refuse options the law would ignore."""
    from .model import REGISTRY, ContactLaw

    name = args.law if _given(args, "law") else impact["law"]
    restitution_laws = [n for n, entry in REGISTRY.items() if entry.damping == "restitution"]
    settings = _setting_names(args)
    contact_given = _given(args, "contact") or "contact" in settings
    if name not in REGISTRY:
        raise ValueError(f"law = {name!r} is not a registered law; allowed: {', '.join(REGISTRY)} (or a law of "
                         "--law-file FILE.py)")
    entry = REGISTRY[name]
    readers = [n for n, x in REGISTRY.items() if "contact" in x.options]
    if contact_given and "contact" not in entry.options:
        raise ValueError(f"contact = {impact['contact'] if 'contact' in settings else args.contact!r} is not read by "
                         f"law {name!r}; allowed: --contact with law {', '.join(readers)}")
    contact = args.contact if _given(args, "contact") else (impact["contact"] if "contact" in entry.options
                                                            else "printed")
    # a value given by --set is the user's as much as an option's: refused where the law ignores it
    kappa_given = _given(args, "kappa") or "kappa" in settings
    restitution = getattr(args, "restitution", None)
    if restitution is None and "restitution" in settings:
        restitution = impact["restitution"]
    inverse_laws = [n for n, x in REGISTRY.items() if x.inverse]
    if restitution is not None and entry.damping != "restitution" and not entry.inverse:
        raise ValueError(f"restitution = {restitution!r} is not read by law {name!r} ({entry.description}); "
                         f"allowed: --restitution with {', '.join(inverse_laws)} or a restitution law")
    if restitution is None and impact["restitution"] is not None and not kappa_given and (
            name in restitution_laws or entry.inverse):
        restitution = impact["restitution"]  # the case's: its law reads it
    if restitution is None and name in restitution_laws:
        lo, hi = RESTITUTION_RANGE
        raise ValueError(f"restitution = None is out of range for law {name!r} (its only damping); allowed: "
                         f"--restitution E with {lo:g} <= E <= {hi:g}")
    law = ContactLaw(name, restitution=restitution, contact=contact)
    if kappa_given and not law.reads("kappa"):
        source = "its damping comes from the restitution" if law.damping_source == "restitution" else "it is undamped"
        raise ValueError(f"kappa = {impact['kappa']!r} is not read by law {law.label()!r} ({source}); allowed: "
                         + ("--kappa or --restitution, not both" if restitution is not None
                            else "--kappa with " + ", ".join(n for n, x in REGISTRY.items() if x.damping == "kappa")))
    if law.restitution is not None:  # numpy and scipy only where there is a restitution to check
        from .model.restitution import check_attainable

        check_attainable(law)
    return law


def _setup(args, *, law=True) -> Setup:
    """Resolve the case (``--case``, ``--set``), the explicit options and the law; check every value.

    Raises ``ValueError`` (exit 2) naming the parameter, its value and the allowed range.
    """
    from .case import load_case

    case = args.case if getattr(args, "case", None) is not None else load_case("seed")
    settings = getattr(args, "set", None) or []
    names = _setting_names(args)
    for key in ("v", "kappa", "target", "law", "contact", "restitution"):
        if key in names and _given(args, key):
            raise ValueError(f"{key} is given twice (--{key} {getattr(args, key)!r} and --set {key}=...); allowed: "
                             "one of them")
    if settings:
        case = case.with_settings(settings)
    impact = dict(case.impact)
    for key in ("v", "kappa", "target"):
        if _given(args, key):
            impact[key] = getattr(args, key)

    def source(key):
        return f"from --{key}" if _given(args, key) else ("from --set" if key in names else f"from case {case.name!r}")
    _check_in_range("v", impact["v"], *V_RANGE, "m/s", source("v"))
    _check_in_range("kappa", impact["kappa"], 0.0, KAPPA_MAX, KAPPA_UNIT, source("kappa"))
    contact_law = None
    if law:
        contact_law = _resolve_law(args, impact)
        impact.update(law=contact_law.name, contact=contact_law.contact, restitution=contact_law.restitution)
        if not contact_law.reads("kappa"):  # the case's kappa, under a law the options chose that ignores it
            impact["kappa"] = 0.0
    case = dataclasses.replace(case, impact=impact)  # validated again: the case as used
    params = case.parameters()
    if getattr(args, "t_end", None) is not None:  # a horizon shorter than the case can resolve
        from .integrate.api import check_t_end, scales

        check_t_end(args.t_end, scales(params).contact_time, name="t-end")
    return Setup(case, contact_law, params)


def _check_critical_law(law) -> None:
    if not law.is_filippov:
        from .model import REGISTRY

        allowed = ", ".join(n for n, entry in REGISTRY.items() if entry.filippov)
        raise ValueError(f"law = {law.name!r} is out of range for the critical damping; allowed: a Filippov law "
                         f"({allowed}; the others have no stick phases to split: see 'phaseimpact transitions')")


def _check_reads_kappa(law, what: str) -> None:
    if not law.reads("kappa"):
        source = (f"its damping comes from restitution = {law.restitution:g}" if law.damping_source == "restitution"
                  else "it has no damping")
        raise ValueError(f"law {law.label()!r} does not read kappa ({source}): every {what} would be the same "
                         "run; allowed: a law that reads kappa (paper, hunt-crossley) without --restitution")


def _check_grazing_target(law, params) -> None:
    """Grazing needs the plate to swing back: without it a unilateral impact has one contact."""
    if not law.is_filippov and params.target != "plate":
        raise ValueError(f"target = {params.target!r} is out of range for the grazing transitions of law "
                         f"{law.label()!r} (without the plate's springs nothing swings back: one contact); "
                         "allowed: target plate")


def _check_kappa_range(args) -> None:
    if args.kappa_min is not None and args.kappa_max is not None and not args.kappa_min < args.kappa_max:
        raise ValueError(f"kappa-min = {args.kappa_min!r}, kappa-max = {args.kappa_max!r} are out of range; "
                         "allowed: kappa-min < kappa-max")


def _check_figure_target(path: str, force: bool) -> None:
    """Refuse a format the plotting layer does not write, and to replace an existing file that is not a
    figure of the format asked for, unless ``force``: before any work."""
    from .plotting import figure_format

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


def _law_fields(setup: Setup) -> dict:
    law = setup.law
    return {"law": law.name, "law_label": law.label(), "contact": law.contact if law.is_filippov else None,
            "restitution": law.restitution}


def _case_fields(setup: Setup) -> dict:
    """The law and the case's speed, damping and target: the head of a single-case command's JSON."""
    law, p = setup.law, setup.params
    return {**_law_fields(setup), "v": p.v, "kappa": law.kappa(p), "kappa_unit": law.damping_unit(p.alpha),
            "target": p.target}


@contextlib.contextmanager
def _out_archive(args, setup: Setup, kind: str, t_end, settings: dict):
    """``--out`` of simulate and transitions: the overwrite rule of every archive
    (:func:`phaseimpact.archive.check_overwrite`) before any work, and one writer (the path's lock,
    held from the check to the write). Yields the function that writes the result; None without ``--out``."""
    if args.out is None:
        yield None
        return
    from . import archive

    archive.created_timestamp()  # a bad SOURCE_DATE_EPOCH is refused before any work
    with exclusive(args.out, "out"):
        archive.check_overwrite(args.out, kind, setup.law, setup.params, {}, t_end, args.rtol, force=args.force,
                                settings=settings)

        def write(result) -> None:  # a trajectory carries its law
            archive.save(result, args.out, force=args.force, params=setup.case,
                         law=None if kind == "trajectory" else setup.law, settings=settings)

        yield write


# ------------------------------------------------------------------------------------------------
# Commands
# ------------------------------------------------------------------------------------------------

def cmd_cases(args) -> int:
    from .case import list_cases

    cases = list_cases()
    if args.json:
        _print_json(args, {"cases": cases})
    else:
        width = max(len(c["name"]) for c in cases)
        for c in cases:
            print(f"{c['name']:<{width}}  {c['description']}")
        print("(phaseimpact COMMAND --case NAME; 'phaseimpact cases --json' also gives each case's sources)")
    return EXIT_OK


def cmd_completion(args) -> int:
    import shtab

    parser = build_parser()
    preamble = _complete_values(parser)
    script = shtab.complete(parser, shell=args.shell, root_prefix="phaseimpact", preamble=preamble)
    if args.shell == "bash":
        # "--set NAME=" is followed by its value, not by a space: shtab's function runs its helpers in a
        # subshell, where compopt has no effect, so a wrapper says it after them
        script += ("\n_phaseimpact() {\n  _shtab_phaseimpact \"$@\"\n"
                   "  [[ ${#COMPREPLY[@]} -gt 0 && ${COMPREPLY[0]} == *= ]] && compopt -o nospace 2>/dev/null\n"
                   "  return 0\n}\ncomplete -o bashdefault -F _phaseimpact phaseimpact\n")
    print(script)
    return EXIT_OK


def _complete_values(parser) -> dict:
    """Tell shtab what each value completes to (an action's ``complete``): files for paths, the shipped
    cases and ``.toml`` files for ``--case``, the laws and ``.py`` files for ``check-law``, ``.py`` files
    for ``--law-file``, ``NAME=`` for ``--set``. Returns the shell functions this needs, by shell."""
    from .case import list_cases
    from .model import REGISTRY

    cases, laws = " ".join(c["name"] for c in list_cases()), " ".join(REGISTRY)
    names = " ".join(f"{name}=" for name in SETTABLE)
    kinds = {  # dest -> (bash function, zsh action); bash functions named *_file complete as file names
        "case": ("_phaseimpact_compgen_case_file", "_phaseimpact_case"),
        "set": ("_phaseimpact_compgen_setting", "_phaseimpact_setting"),
        "law_file": ("_phaseimpact_compgen_py_file", "_files -g '*.py'"),
        "law": ("_phaseimpact_compgen_law_file", "_phaseimpact_law_or_file"),
        "out": ("_shtab_compgen_files", "_files"), "archive": ("_shtab_compgen_files", "_files"),
        "curve": ("_shtab_compgen_files", "_files"),
    }
    for command in next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices.values():
        for action in command._actions:
            if action.dest in kinds and not (action.dest == "law" and action.option_strings):  # --law: choices
                bash, zsh = kinds[action.dest]
                action.complete = {"bash": bash, "zsh": zsh}
    bash = f"""
_phaseimpact_compgen_case_file() {{
  compgen -W "{cases}" -- "$1"; compgen -d -- "$1"; compgen -f -X '!*.toml' -- "$1"
}}
_phaseimpact_compgen_py_file() {{
  compgen -d -- "$1"; compgen -f -X '!*.py' -- "$1"
}}
_phaseimpact_compgen_law_file() {{
  compgen -W "{laws}" -- "$1"; compgen -d -- "$1"; compgen -f -X '!*.py' -- "$1"
}}
_phaseimpact_compgen_setting() {{
  compgen -W "{names}" -- "$1"
}}
"""
    zsh = f"""
_phaseimpact_case() {{
  _alternative 'cases:shipped case:({cases})' 'files:case file:_files -g "*.toml"'
}}
_phaseimpact_law_or_file() {{
  _alternative 'laws:law:({laws})' 'files:law file:_files -g "*.py"'
}}
_phaseimpact_setting() {{
  compadd -S '' -- {names}
}}
"""
    return {"bash": bash, "zsh": zsh}


def cmd_check_law(args) -> int:
    from .checks import check_law
    from .model import REGISTRY, law_variants
    from .model.userlaw import load_law_file

    if args.law in REGISTRY:
        names = [args.law]
    elif os.path.lexists(args.law) or args.law.endswith(".py"):
        names = load_law_file(args.law)  # whatever the file does besides defining laws is one line
    else:
        raise ValueError(f"law = {args.law!r} is neither a registered law nor a law file; allowed: "
                         f"{', '.join(REGISTRY)} or FILE.py")
    reports = [check_law(law) for law in law_variants(names)]
    if args.json:
        _print_json(args, {"passed": all(r.passed for r in reports),
                           "laws": [{"law": r.law, "passed": r.passed,
                                     "checks": [{"check": v.check, "passed": v.passed, "detail": v.detail}
                                                for v in r.verdicts]} for r in reports]})
    else:
        print("\n".join(str(r) for r in reports))
    return EXIT_OK if all(r.passed for r in reports) else EXIT_FAILURE


def cmd_warmup(args) -> int:
    from .integrate.precompile import warmup

    out = warmup()
    if args.json:
        _print_json(args, out)
    elif out["cache"] is None:
        print(f"compiled in {out['seconds']:.1f} s for this process only: nothing is cached ({out['reason']})")
    else:
        done = "compiled" if out["compiled"] else "already compiled; loaded"
        print(f"{done} in {out['seconds']:.1f} s; cache: {out['cache']} ({out['source']}; {out['files']} files, "
              f"{out['bytes'] / 1e6:.1f} MB)")
    return EXIT_OK


PARAM_UNITS = {"M1": "kg", "M2": "kg", "K": "N/m^1.5", "Kb": "N/m", "Km": "N/m^3", "alpha": "",
               "v": "m/s", "R": "m", "contact_time": "s", "plate_period": "s", "indentation": "m", "peak_force": "N",
               "contact_radius": "m", "peak_pressure": "Pa", "first_yield_pressure": "Pa",
               "pressure_to_first_yield": "", "hertz_mass": "kg", "limiting_pressure": "Pa",
               "yield_velocity": "m/s"}


def cmd_params(args) -> int:
    from .model.contact import hertz_scales, validity

    setup = _setup(args)
    p, case, law = setup.params, setup.case, setup.law
    out = {**_law_fields(setup),
           **{k: getattr(p, k) for k in ("M1", "M2", "K", "Kb", "Km", "alpha", "kappa", "v", "target", "R")}}
    out["kappa_unit"] = law.damping_unit(p.alpha)
    # The Hertz scales are those of the relative motion: the reduced mass M1 M2/(M1+M2) unless the
    # target is rigid (docs/physics.md §4); say which, since a plate's figures differ from a rigid one's.
    out["hertz_mass"] = p.reduced_mass
    out["hertz_mass_is"] = ("M1 (rigid target)" if p.target == "rigid"
                            else f"reduced mass M1 M2/(M1+M2) ({p.target} target)")
    out.update(hertz_scales(p, case.plate))
    out["validity"] = validity(p, case.plate, case.projectile, case.geometry)
    # Thornton's elastic-plastic law (--law thornton) yields at v_y, where the Hertz peak pressure
    # reaches p_y = 1.6 Y of the weaker body (null without a yield strength)
    out["limiting_pressure"] = p.limiting_pressure
    out["yield_velocity"] = p.yield_velocity
    out["case"] = case.as_dict()
    if args.json:
        _print_json(args, out)
    else:
        print(f"case {case.name}: {case.description}" if case.description else f"case {case.name}")
        print(f"  {'law':>23} = {law.label()}")
        for k, value in out.items():
            if k in ("case", "validity", "target", "hertz_mass_is", "kappa_unit", *_law_fields(setup)):
                continue
            unit = out["kappa_unit"] or KAPPA_UNIT if k == "kappa" else PARAM_UNITS.get(k, "")
            print(f"  {k:>23} = {_fmt(value, unit)}".rstrip())
        print(f"  {'target':>23} = {p.target}")
        print(f"  Hertz scales (contact_time ... peak_pressure) use hertz_mass, the {out['hertz_mass_is']}")
        print(f"  validity: {out['validity']}")
    return EXIT_OK


def _contact_reading(trajectory, setup: Setup) -> dict:
    """Hertz contact radius and peak pressure at the run's largest force, and whether elastic Hertz
    contact holds there (null when the run has no finite force)."""
    from .model.contact import hertz_contact, plastic_contact, plastic_validity, validity_for_force

    force = trajectory.max_force
    if not (isinstance(force, float) and math.isfinite(force)) or setup.params.R is None:
        return {"peak_pressure": None, "contact_radius": None, "validity": "unknown: the run has no finite peak force"}
    force = max(force, 0.0)
    case = setup.case
    if setup.law.entry.plastic:  # the pressure is capped at p_y: Hertz's reading does not apply
        return {**plastic_contact(force, setup.params),
                "validity": plastic_validity(force, setup.params, case.geometry, case.plate, case.projectile)}
    return {**hertz_contact(force, setup.params),
            "validity": validity_for_force(force, setup.params, case.plate, case.projectile, case.geometry)}


def cmd_simulate(args) -> int:
    from .integrate import scales, simulate
    from .quantities import impact_quantities

    setup = _setup(args)
    law, p = setup.law, setup.params
    horizon = "until the outcome settles" if args.t_end is None else f"to t = {args.t_end:g} s"
    t_end = scales(p).horizon if args.t_end is None else args.t_end  # what the archive's header holds
    with _out_archive(args, setup, "trajectory", t_end, {"rtol": args.rtol}) as write:
        _note(f"integrating {law.label()} at v = {p.v:g} m/s {horizon} (the first run compiles the engine)")
        # an archive keeps the steps too; the run is the same (it stops where the summary's does)
        trajectory = simulate(p, law, args.t_end, rtol=args.rtol, save="summary" if write is None else "steps",
                              stop_when_settled=True)
        if write is not None:
            write(trajectory)
    q = impact_quantities(trajectory)
    t_stick, delta_stick, dwell = trajectory.stick_points()
    out = {**_case_fields(setup), "status": trajectory.status, "stop_reason": trajectory.stop_reason,
           "message": trajectory.message,
           "t_end": trajectory.t_end, "t_stop": trajectory.t_stop, **q.as_dict(),
           **_contact_reading(trajectory, setup),
           **({"limiting_pressure": p.limiting_pressure, "yield_velocity": p.yield_velocity}
              if law.entry.plastic else {}),
           "n_stick": trajectory.n_stick, "n_contacts": trajectory.n_contacts, "t_run": trajectory.t_run,
           "cut": trajectory.cut, "outcome": trajectory.outcome,
           "stick_points": [{"t": t, "delta": d, "dwell": w}
                            for t, d, w in zip(t_stick, delta_stick, dwell, strict=True)],
           "asymptotic_points": [{"delta": d, "deltadot": 0.0, "dwell": w}
                                 for d, w in zip(delta_stick, dwell, strict=True)],
           "case": setup.case.as_dict(), "out": args.out}
    if args.json:
        _print_json(args, out)
    else:
        print(f"{law.label()} on a {p.target} target ({setup.case.name}), v = {p.v:g} m/s, "
              f"{law.entry.damping_name} = {out['kappa']:.4g} {law.damping_unit(p.alpha)}")
        print(f"  status: {trajectory.status} ({trajectory.message})")
        units = {"max_force": "N", "max_indentation": "m", "contact_duration": "s", "restitution": "",
                 "time_equal_displacement": "s", "dissipated_energy": "J", "loop_area": "J",
                 "peak_pressure": "Pa", "contact_radius": "m"}
        for k, u in units.items():
            print(f"  {k:<24} {_fmt(out[k], u)}")
        print(f"  validity: {out['validity']}")
        lower = " (at least: the horizon cut the run)" if trajectory.cut else ""
        print(f"  outcome: {trajectory.outcome}; {trajectory.n_stick} stick phase(s){lower}, "
              f"{trajectory.n_contacts} contact(s)"
              + ("" if trajectory.t_run is None else f", escape at t = {trajectory.t_run:.6g} s"))
        for t, d, w in zip(t_stick, delta_stick, dwell, strict=True):
            lasting = "permanent" if math.isinf(w) else f"{w:.4g} s"
            print(f"  stick at t = {t:.6g} s: delta = {d:.6g} m, dwell {lasting}")
        if args.out is not None:
            print(f"wrote {args.out} (the trajectory: {len(trajectory.t)} steps, {len(trajectory.event_t)} events)")
    if not trajectory.ok:
        print(f"phaseimpact: numerical failure: {trajectory.status}: {trajectory.message}", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def _eigenvalue_text(z) -> str:
    re_, im = float(z.real) + 0.0, float(z.imag) + 0.0  # + 0.0: no "-0"
    return f"{re_:.6g}" if im == 0 else (f"{im:+.6g}i" if re_ == 0 else f"{re_:.6g}{im:+.6g}i")


def cmd_fixed_points(args) -> int:
    from .analysis import fixed_points

    setup = _setup(args)
    law, p = setup.law, setup.params
    found = fixed_points(p, law)
    out = {**_case_fields(setup), "equilibria": [e.as_dict() for e in found], "case": setup.case.as_dict()}
    if args.json:
        _print_json(args, out)
        return EXIT_OK
    print(f"equilibria of {law.label()} on a {p.target} target ({setup.case.name}), docs/physics.md §5 "
          "(kappa and v move none: the damping acts through deltadot, zero at rest)")
    for e in found:
        conditions = ", ".join(f"{k} {c}" for k, c in e.conditions.items())
        shape = "isolated point" if e.kind == "point" else f"set of dimension {e.dimension}"
        print(f"  {e.name}: {shape}: {conditions}")
        print(f"    {e.description}")
        at = ", ".join(f"{x:.4g}" for x in e.state)
        eig = ", ".join(_eigenvalue_text(z) for z in e.eigenvalues) or "none"
        print(f"    eigenvalues (1/s) in ({', '.join(e.coordinates)}) at (x1, x2, x1dot, x2dot) = ({at}): {eig}")
        print(f"    linearisation: {e.stability}; {e.note}")
    return EXIT_OK


def cmd_critical(args) -> int:
    from .continuation import critical_damping

    setup = _setup(args)
    law, params = setup.law, setup.params
    _check_critical_law(law)
    _check_kappa_range(args)
    from .continuation.transition import default_kappa_range

    # a default end beyond the one given is named as the default it is, with the range it comes from
    default_kappa_range(params, args.kappa_min, args.kappa_max, names=("kappa-min", "kappa-max"))
    _note(f"locating kappa_c and kappa_2 of {law.label()} at v = {params.v:g} m/s"
          + (" and measuring the exponents (about 1 s)" if args.exponents else ""))
    result = critical_damping(params, law, kappa_min=args.kappa_min, kappa_max=args.kappa_max,
                              kappa_rtol=args.kappa_rtol, rtol=args.rtol, with_kappa_2=True,
                              with_exponents=args.exponents)
    out = {**_law_fields(setup), "v": result.v, "kappa_c": result.kappa_c,
           "kappa_c_accuracy": result.kappa_c_accuracy, "kappa_2": result.kappa_2,
           "kappa_2_accuracy": result.kappa_2_accuracy, "n_below": result.n_below, "n_above": result.n_above,
           "n_below_kappa_2": result.n_below_kappa_2, "n_above_kappa_2": result.n_above_kappa_2,
           "closed_form": result.closed_form, "classification": result.classification,
           "status": result.status, "kappa_c_status": result.kappa_c_status,
           "kappa_2_status": result.kappa_2_status, "staircase_status": result.staircase_status,
           "message": result.message, "bracket": list(result.bracket), "search_range": list(result.search_range),
           "margins": list(result.margins), "kappa_rtol": result.rtol, "rtol": args.rtol,
           "n_staircase": result.n_staircase, "evaluations": result.evaluations, "case": setup.case.as_dict()}
    if args.exponents:
        out["exponents"] = result.exponents
    if args.json:
        _print_json(args, out)
    else:
        unit = law.damping_unit(params.alpha)
        kc = (f"not found up to kappa = {result.search_range[1]:g} {unit}" if result.kappa_c is None
              else f"{result.kappa_c:.10g} {unit}")
        print(f"critical damping of {law.label()} ({setup.case.name}) at v = {params.v:g} m/s: {kc}")
        statuses = {"kappa_c": result.kappa_c_status, "kappa_2": result.kappa_2_status,
                    "staircase": result.staircase_status}
        print("  " + ", ".join(f"{name} {status}" for name, status in statuses.items() if status is not None)
              + (f"; counts just below / above kappa_c: {_fmt(result.n_below, '', 'd')} / "
                 f"{_fmt(result.n_above, '', 'd')}" if result.kappa_c is not None else ""))
        print(f"  closed form {_fmt(result.closed_form, unit)}; kappa_2 (N = 2 from here on) "
              f"{_fmt(result.kappa_2, unit, '.10g')}; classification {result.classification or 'none'}")
        if result.n_staircase:
            steps = [("?" if s["n_stick"] is None else f"{s['n_stick']}") + ("+" if s["cut"] else "")
                     for s in result.n_staircase]
            eps = [s["kappa"] / result.kappa_c - 1 for s in result.n_staircase]
            print(f"  stick phases at kappa/kappa_c - 1 = {eps[0]:.3g} .. {eps[-1]:.3g} ('+': a lower bound, "
                  "'?': not confirmed at a tighter tolerance): "
                  + " ".join(steps))
        if args.exponents and result.exponents:
            e = result.exponents
            print(f"  exponents: slip speed {_fmt(e.get('slip_speed_exponent'), '', '.3g')} (expected 1.5), "
                  f"stick offset {_fmt(e.get('stick_offset_exponent'), '', '.3g')} (expected 2), "
                  f"eps in {e['fit_range'][0]:g}..{e['fit_range'][1]:g}")
        print(f"  {result.status}: {result.message}")
    if result.status not in CRITICAL_ANSWERS:
        print(f"phaseimpact: kappa_c search failed: {result.status}: {result.message}", file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def cmd_transitions(args) -> int:
    import warnings

    from .continuation import transitions
    from .continuation.transition import RunFailed, SamplingWarning, check_samples

    setup = _setup(args)
    law, params = setup.law, setup.params
    _check_reads_kappa(law, "kappa")
    _check_grazing_target(law, params)
    _check_kappa_range(args)
    if not law.is_filippov:  # a grazing search samples kappa: enough samples per decade, or refused now
        check_samples(args.samples, args.kappa_min, args.kappa_max, names=("kappa-min", "kappa-max", "samples"))
    settings = {"rtol": args.rtol, "kappa_min": args.kappa_min, "kappa_max": args.kappa_max,
                "kappa_rtol": args.kappa_rtol, "samples": args.samples}
    with _out_archive(args, setup, "transitions", None, settings) as write:
        _note(f"locating the transitions of {law.label()} at v = {params.v:g} m/s for kappa in "
              f"[{args.kappa_min:g}, {args.kappa_max:g}]")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", SamplingWarning)
            try:
                found = transitions(params, law, args.kappa_min, args.kappa_max, kappa_rtol=args.kappa_rtol,
                                    rtol=args.rtol, num=args.samples, progress=sys.stderr.isatty())
            except RunFailed as error:  # every input was checked: this is the search's own failure
                print(f"phaseimpact: the transition search failed: {error}", file=sys.stderr)
                return EXIT_FAILURE
        if write is not None:
            write(found)
    notes = [str(w.message) for w in caught if issubclass(w.category, SamplingWarning)]
    for note in notes:
        print(f"phaseimpact: warning: {note}", file=sys.stderr)
    count = "stick phases" if law.is_filippov else "contacts"
    out = {**_law_fields(setup), "v": params.v, "kappa_min": args.kappa_min, "kappa_max": args.kappa_max,
           "count": count, "transitions": [t.as_dict() for t in found], "kappa_rtol": args.kappa_rtol,
           "rtol": args.rtol, "samples": args.samples, "warnings": notes, "case": setup.case.as_dict(),
           "out": args.out}
    if args.json:
        _print_json(args, out)
    else:
        print(f"transitions of {law.label()} ({setup.case.name}) at v = {params.v:g} m/s, kappa in "
              f"[{args.kappa_min:g}, {args.kappa_max:g}] {law.damping_unit(params.alpha)} (counts: {count})")
        for t in found:
            above = "unbounded" if t.count_above is None else str(t.count_above)
            print(f"  {t.kind:<15} kappa = {t.kappa:.10g}   {t.count_below} -> {above}")
        if not found:
            print("  none in this range")
        if args.out is not None:
            print(f"wrote {args.out} ({len(found)} transitions)")
    return EXIT_OK


# ------------------------------------------------------------------------------------------------
# Grids (sweep, atlas): one runner with checkpoints, the lock, resume, failures and Ctrl-C
# ------------------------------------------------------------------------------------------------

def _resume_command(argv) -> str:
    words = ["phaseimpact", *argv]
    if "--resume" not in words:
        words.append("--resume")
    return shlex.join(words)


def _one_axis(args, note=""):
    """The one ``--axis`` of a command that runs over one parameter."""
    if len(args.axis) != 1:
        raise ValueError(f"axis is given {len(args.axis)} times; allowed: once for {args.command}{note}")
    return args.axis[0]


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

    from . import archive
    from .continuation import Grid, atlas
    from .continuation._parallel import check_scheduler

    Grid(setup.case, setup.law, tuple(axes))  # every check of the grid, before any work
    out = args.out
    archive.created_timestamp()  # a bad SOURCE_DATE_EPOCH is refused now, not at the first checkpoint
    if args.backend == "dask" and args.scheduler is not None:
        check_scheduler(args.scheduler)  # before any work: a dead address fails within seconds
    named = {axis.name: axis.values for axis in axes}
    size = int(np.prod([len(axis.values) for axis in axes]))
    grid_kinds = [k for k in archive.KINDS if k != "critical-curve"]  # "sweep" (and "atlas": several axes)
    kind = "atlas" if len(axes) > 1 and "atlas" in grid_kinds else "sweep"
    with exclusive(out, "out"):
        previous = None
        if os.path.exists(out) and args.resume:
            held = archive.describe(out)
            if held["kind"] not in grid_kinds:
                raise ValueError(f"out = {out!r} is a {held['kind']} archive, not a sweep or atlas: --resume cannot "
                                 "complete it (choose another --out, or drop --resume and add --force)")
            differences = archive.same_work(held, kind, setup.law, setup.params, named, args.t_end, args.rtol)
            if differences:
                raise ValueError(f"resume: out = {out!r} holds other work ({'; '.join(differences)}); "
                                 "give the options it was computed with, or drop --resume")
            previous = archive.load(out)
            _note(f"resuming {out}: {int(np.count_nonzero(previous.done))} of {size} points done")
        elif os.path.exists(out):
            archive.check_overwrite(out, kind, setup.law, setup.params, named, args.t_end, args.rtol,
                                    force=args.force)

        checkpoint = archive.Checkpoint(out, force=args.force)  # writes only the new points, in place

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
    from .integrate import OUTCOMES

    return OUTCOMES[int(code)]


def _grid_summary(result, out_path, setup: Setup) -> dict:
    import numpy as np

    computed = result.status >= 0
    failed = result.failed
    failures = {}
    for code in result.status[failed]:
        from .integrate import STATUSES

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


def cmd_atlas(args) -> int:
    """``atlas`` and ``sweep`` (an atlas of one axis)."""
    import numpy as np

    if args.command == "sweep":
        _one_axis(args, " (atlas takes a grid)")
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
        from . import archive
        from .continuation import refine_boundaries

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


# ------------------------------------------------------------------------------------------------
# Critical curves
# ------------------------------------------------------------------------------------------------

def _curve_values(args, setup: Setup):
    """``(param, values)`` of a critical curve, checked (every value a valid case) before any work."""
    import numpy as np

    axis = _one_axis(args)
    param, values = axis.name, axis.values
    allowed = [*CURVE_PARAMETERS, *(n for n in QUANTITIES if n not in CURVE_PARAMETERS)]
    if param not in allowed:
        raise ValueError(f"axis {param!r} is out of range; allowed: one of {', '.join(allowed)}"
                         + (" (kappa is what the curve continues)" if param == "kappa" else ""))
    if len(values) > MAX_CURVE_POINTS:
        raise ValueError(f"axis {param!r} has {len(values)} values; allowed: at most {MAX_CURVE_POINTS}")
    if param == "v" and _given(args, "v"):
        raise ValueError("axis 'v' and --v contradict each other: the curve runs over v; give one")
    if param in _setting_names(args):
        raise ValueError(f"axis {param!r} is also given as --set {param}=...: the curve runs over it; give one")
    if not np.all(np.diff(values) > 0):
        raise ValueError(f"axis {param!r} = {values.tolist()!r} is out of range; allowed: increasing values")
    for value in (values[0], values[-1]):
        if param == "v":
            _check_in_range("v", float(value), *V_RANGE, "m/s", "axis v")
        try:
            setup.case.parameters(**{param: float(value)})
        except ValueError as error:
            raise ValueError(f"axis {param!r} value {float(value)!r} is out of range: {error}") from None
    return param, values


def cmd_critical_curve(args) -> int:
    import numpy as np

    from . import archive
    from .continuation import critical_curve, transitions
    from .continuation.transition import RunFailed

    setup = _setup(args)
    law = setup.law
    what = args.what
    if what in ("kappa_c", "kappa_2"):
        if not law.is_filippov:
            raise ValueError(f"what = {what!r} is out of range for law {law.name!r}; allowed: what kappa_c or "
                             "kappa_2 with law paper, what grazing with a unilateral law")
        for name in ("kappa_min", "kappa_max"):
            if getattr(args, name) is not None:
                raise ValueError(f"{name.replace('_', '-')} = {getattr(args, name)!r} is not read by what = "
                                 f"{what!r}; allowed: --kappa-min/--kappa-max with --what grazing")
        if args.samples is not None:
            raise ValueError(f"samples = {args.samples!r} is not read by what = {what!r}; allowed: --samples with "
                             "--what grazing")
    else:
        if not law.is_unilateral:
            raise ValueError(f"what = 'grazing' is out of range for law {law.label()!r} (it acts in tension too: no "
                             "grazing); allowed: a unilateral law (abrate, the Hunt-Crossley family, or paper "
                             "with --contact unilateral)")
        _check_reads_kappa(law, "point of a grazing curve")
        if setup.params.target != "plate":
            raise ValueError(f"target = {setup.params.target!r} is out of range for what = 'grazing' (without the "
                             "plate's springs nothing swings back); allowed: target plate")
        if args.kappa_min is None or args.kappa_max is None:
            raise ValueError("kappa-min, kappa-max are required by what = 'grazing' (the range in which the first "
                             "grazing value is looked for); allowed: --kappa-min A --kappa-max B")
        _check_kappa_range(args)
    param, values = _curve_values(args, setup)
    out = args.out
    archive.created_timestamp()
    samples = args.samples or DEFAULT_SAMPLES
    with exclusive(out, "out"):
        archive.check_overwrite(out, "critical-curve", law, setup.params, {param: values}, None, args.kappa_rtol,
                                force=args.force, settings={"what": what})
        start, index = None, 1
        if what == "grazing":
            first = setup.case.parameters(**{param: float(values[0])})
            _note(f"looking for the first grazing of {law.label()} at {param} = {values[0]:g}")
            found = [t for t in transitions(first, law, args.kappa_min, args.kappa_max, kappa_rtol=args.kappa_rtol,
                                            rtol=args.rtol, num=samples) if t.kind == "grazing"]
            if not found:
                print(f"phaseimpact: the curve failed to start: no grazing value of {law.label()} for kappa in "
                      f"[{args.kappa_min:g}, {args.kappa_max:g}] at {param} = {values[0]:g} (with {samples} samples); "
                      "nothing written", file=sys.stderr)
                return EXIT_FAILURE
            start, index = found[0].kappa, int(found[0].extremum)
        _note(f"continuing {what} of {law.label()} over {len(values)} values of {param}")
        try:
            curve = critical_curve(setup.case, law, param, values, what=what, kappa_rtol=args.kappa_rtol,
                                   rtol=args.rtol, contact_index=index, kappa_start=start,
                                   progress=_progress(args))
        except RunFailed as error:  # every input was checked: this is the curve's own failure
            print(f"phaseimpact: the curve failed to start: {error}; nothing written", file=sys.stderr)
            return EXIT_FAILURE
        archive.save(curve, out, force=args.force)
    asked = np.asarray(curve.requested, dtype=bool)
    values_out, kappa_out = curve.values[asked].tolist(), curve.kappa[asked].tolist()
    result = {"out": out, **_law_fields(setup), "param": param, "what": what, "values": values_out,
              "kappa": kappa_out, param: values_out, what: kappa_out,
              "closed_form": curve.closed_form[asked].tolist(), "contact_index": curve.contact_index,
              "steps": int(len(curve.values)), "message": curve.message, "kappa_rtol": args.kappa_rtol,
              "rtol": args.rtol, "case": setup.case.as_dict()}
    if args.json:
        _print_json(args, result)
    else:
        unit = SETTABLE.get(param, (PARAM_UNITS.get(param, ""),))[0]
        for x, k, closed in zip(curve.values[asked], curve.kappa[asked], curve.closed_form[asked], strict=True):
            line = f"{param} = {x:10.6g} {unit}   {what} = {_fmt(k, '', '.10g'):>16}"
            # the closed form (docs/physics.md §5) is of kappa_c, whatever the curve continues: kappa_2 has none
            label = "closed-form kappa_c" if what == "kappa_c" else "kappa_c's closed form (none for kappa_2)"
            print(line + (f"   {label} {_fmt(closed, '', '.6g')}" if np.isfinite(closed) else ""))
        note = f"; {curve.message}" if curve.message else ""
        print(f"wrote {out} ({len(curve.values)} continuation steps{note})")
    if curve.message or not np.all(np.isfinite(curve.kappa[asked])):
        print(f"phaseimpact: the curve is incomplete: {curve.message or what + ' lost at some values'}",
              file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


# ------------------------------------------------------------------------------------------------
# Figures
# ------------------------------------------------------------------------------------------------

def cmd_plot(args) -> int:
    from . import archive

    _check_figure_target(args.out, args.force)
    if os.path.abspath(args.out) == os.path.abspath(args.archive):
        raise ValueError(f"out = {args.out!r} is the archive itself; allowed: another path")
    result = archive.load(args.archive)
    curves = [archive.load(path) for path in (args.curve or [])]
    from . import plotting
    from .continuation import CriticalCurve
    from .train import Basins, OrbitDiagram

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


#: Samples drawn along each portrait's trajectory (at least one per integrator step, up to 16).
PORTRAIT_SAMPLES = 400_000


def _portrait_runs(args, setup: Setup):
    """Each ``--kappa``'s run until its outcome settles (for the events, the counts and the title) and
    the same run sampled for drawing: where the integrator stepped (a few points per step) and the
    first contact finely; a permanent stick is drawn on for two plate periods (the stuck pair's orbit)."""
    import numpy as np

    from .integrate import scales, simulate

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


def cmd_portrait(args) -> int:
    from . import plotting

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


# ------------------------------------------------------------------------------------------------
# Parser
# ------------------------------------------------------------------------------------------------

def _settable_help() -> str:
    return ", ".join(f"{name} ({unit})" if unit else name for name, (unit, _) in SETTABLE.items())


class _Removed(argparse.Action):
    """An option of an earlier version: refused with the ``--axis`` that replaces it (hidden from the help)."""

    def __init__(self, option_strings, dest, example="kappa=1e9:1e14:50:log", **kwargs):
        self.example = example
        super().__init__(option_strings, dest, nargs="?", help=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        example = f"{values}" if option_string == "--range" and values and "=" in values else self.example
        parser.error(f"{option_string} was removed; allowed: --axis {RANGE_METAVAR} (NUM values from START to "
                     f"STOP, log spaced with :log) or --axis NAME=V1,V2,..., e.g. --axis {example}")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="phaseimpact", description="Impact models analysed as dynamical systems: one impact, "
                                                     "the critical damping and the other transitions, sweeps, "
                                                     "atlases and continued curves over a case's parameters, and "
                                                     "their figures.",
                     epilog="SI units throughout. Exit codes: 0 done, 1 numerical failure (reported), "
                            "2 bad input (nothing computed), 130 interrupted.")
    parser.add_argument("--version", action="version", version=f"phaseimpact {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    v_lo, v_hi = V_RANGE

    def case_options(p):
        p.add_argument("--case", type=_case, default=None, metavar="NAME|FILE.toml",
                       help="a shipped case (see 'phaseimpact cases') or a TOML case file; its [impact] values "
                            "are used unless an option overrides them (default: seed)")
        p.add_argument("--set", type=_setting, action="append", default=None, metavar="NAME=VALUE",
                       help="change one quantity of the case, SI units; repeatable, later ones win; names: "
                            f"{_settable_help()} (default: none)")

    def law_options(p, *, restitution=True, contact=True):
        from .model import REGISTRY  # the shipped laws and those of --law-file (loaded before parsing)

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
        p.add_argument("--v", type=_V, default=None, metavar="V",
                       help=f"impact speed, m/s, {v_lo:g} <= V <= {v_hi:g} (default: the case's, 1 for seed)")

    def damping(p, read_by=None):
        from .model import REGISTRY

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
                       help="threads of this process, joblib processes (loky) or a Dask cluster "
                            "(default: %(default)s)")
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

    settable = "Settable with --set NAME=VALUE (SI units): " + "; ".join(
        f"{name} ({unit}): {text}" if unit else f"{name}: {text}" for name, (unit, text) in SETTABLE.items()) + "."

    def add(name, help_, description):
        return sub.add_parser(name, help=help_, description=description, epilog=settable)

    p = sub.add_parser("cases", help="the shipped cases (name, description, sources)",
                       description="The named cases shipped with phaseimpact, for --case NAME.")
    json_option(p)
    p.set_defaults(func=cmd_cases)

    p = sub.add_parser("completion", help="the shell completion script (bash or zsh)",
                       description="Print the completion script of phaseimpact's commands and options for a shell, "
                                   "generated from this parser (shtab); e.g. in ~/.bashrc: "
                                   "eval \"$(phaseimpact completion bash)\".")
    p.add_argument("shell", choices=("bash", "zsh"), help="the shell")
    p.set_defaults(func=cmd_completion)

    p = sub.add_parser("warmup", help="compile the engine ahead, and say where its cache is",
                       description="Compile every entry of the engine into its cache now (the first command that "
                                   "integrates would otherwise do it, about a minute on 2 cores), and say where the "
                                   "cache is: for containers, cluster workers and a fresh install (each user who "
                                   "cannot write the install compiles once into ~/.cache/phaseimpact). On a warm "
                                   "cache it only loads.")
    json_option(p)
    p.set_defaults(func=cmd_warmup)

    p = sub.add_parser("check-law", help="run the law conformance suite on a law or a law file",
                       description="The checks every shipped law passes (force, repulsive on loading, partials "
                                   "against finite differences, energy ledger, momentum, scipy and the independent "
                                   "oracle), on a registered law with each of its options, or on the laws a Python "
                                   "file defines with phaseimpact.define_law. Every run has a step and time budget "
                                   "(a law whose integration grinds fails within seconds). Exit code 1 when a check "
                                   "fails, 2 when the law file cannot be loaded.")
    p.add_argument("law", metavar="LAW|FILE.py", help="a registered law's name, or a Python file defining laws")
    json_option(p)
    p.set_defaults(func=cmd_check_law)

    p = add("params", "a case's derived parameters, Hertz scales and validity",
            "The derived parameters (seed eq. 3-5) of a case, its Hertz scales (contact time, plate period, "
            "indentation, peak force, contact radius, peak pressure) and whether elastic Hertz contact holds.")
    case_options(p)
    law_options(p)
    speed(p)
    damping(p, "not read by the scales")
    target(p)
    json_option(p)
    p.set_defaults(func=cmd_params)

    p = add("simulate", "one impact: summary quantities, stick points, outcome",
            "One impact from seed eq. 6, integrated exactly (event-driven).")
    case_options(p)
    law_options(p)
    speed(p)
    damping(p)
    target(p)
    horizon(p, "horizon")
    tolerance(p)
    run_out(p, "the trajectory (its steps, event log and summary)")
    json_option(p)
    p.set_defaults(func=cmd_simulate)

    p = add("fixed-points", "the equilibria (points or sets) with eigenvalues and stability",
            "The equilibria of eq. 1 under the law, from its equations: isolated points or sets (the separated set "
            "of a unilateral law, the stuck set of paper), each with the eigenvalues of its linearisation and a "
            "stability label (docs/physics.md §5).")
    case_options(p)
    law_options(p)
    speed(p)
    damping(p, "moves no equilibrium")
    target(p)
    json_option(p)
    p.set_defaults(func=cmd_fixed_points)

    p = add("critical", "the critical damping kappa_c and kappa_2 at one speed (law paper, or a Filippov user law)",
            "The critical damping kappa_c of eq. 8 (law paper, or a Filippov user law): where the first stick "
            "stops being permanent (an adding-sliding bifurcation), and kappa_2, from which the run makes exactly "
            "two stick phases.")
    case_options(p)
    law_options(p, restitution=False)
    speed(p)
    target(p)
    kappa_tolerance(p)
    tolerance(p)
    kappa_range(p, False, " (default: 1e-8 K/v, the damping number below which the approach is undamped)",
                f" (default: {KAPPA_MAX:g}; the search widens from the closed form until the margin changes sign)")
    p.add_argument("--exponents", action="store_true",
                   help="also measure the adding-sliding exponents (slip speed ~ eps^1.5, stick offset ~ eps^2; "
                        "about 1 s)")
    json_option(p)
    p.set_defaults(func=cmd_critical)

    p = add("transitions", "every change of the long-time count in a kappa range",
            "Every kappa in [KAPPA_MIN, KAPPA_MAX] where the long-time count changes, in order: the adding-sliding "
            "at kappa_c and the end of the staircase at kappa_2 for paper (counts: stick phases), grazing values "
            "for unilateral laws (counts: contacts before the projectile is out of reach).")
    case_options(p)
    law_options(p, restitution=False)
    speed(p)
    target(p)
    kappa_range(p, True)
    samples(p, DEFAULT_SAMPLES)
    kappa_tolerance(p, "width of each transition's final bracket")
    tolerance(p)
    run_out(p, "the transitions")
    json_option(p)
    p.set_defaults(func=cmd_transitions)

    grid_commands = (
        ("sweep", "one axis: a sweep of kappa (or any parameter), archived to netCDF-4 (.nc)",
         "Every value of one axis (usually kappa: --axis kappa=1e9:1e12:50:log), each run until its outcome settles "
         "(or to --t-end): outcome class, stick phases, contacts, T_run, max force... Archived to netCDF-4 (.nc) and "
         "checkpointed after every chunk. The same as atlas with one axis."),
        ("atlas", "outcomes over a grid of any parameters, archived to netCDF-4 (.nc)",
         "Every point of a grid over named parameters (kappa, v, M1, ..., and every settable quantity of the "
         "case), each run until its outcome settles (or to --t-end): outcome class, stick phases, contacts, "
         "T_run, max force... Archived to netCDF-4 (.nc) and checkpointed after every chunk."),
    )
    for name, summary, description in grid_commands:
        p = add(name, summary, description)
        case_options(p)
        law_options(p)
        speed(p)
        damping(p)
        target(p)
        axis_option(p, "the sweep's values" if name == "sweep" else "one axis of the grid (repeat for each)",
                    repeat=True)
        for removed in ("--kappa-min", "--kappa-max", "--num", "--range"):
            p.add_argument(removed, action=_Removed)
        p.add_argument("--refine", default=None, metavar="AXIS",
                       help="after the grid, locate every class boundary between neighbours along AXIS (one of the "
                            "--axis names) by bisection, to --refine-rtol, and store the boundary points in the "
                            "archive (plot draws them); default: no refinement")
        p.add_argument("--refine-rtol", type=_real("refine-rtol", 1e-12, 1e-2), default=1e-8,
                       help="relative width of each refined boundary bracket (1e-12..1e-2; default %(default)g)")
        horizon(p)
        tolerance(p)
        parallel(p)
        out_options(p, resume=True)
        json_option(p)
        p.set_defaults(func=cmd_atlas)

    p = add("critical-curve", "kappa_c, kappa_2 or a grazing value against a parameter, archived to netCDF-4 (.nc)",
            "A transition continued over a second parameter (v, a material or a geometry quantity): kappa_c or "
            "kappa_2 of law paper, or a grazing value of a unilateral law; each point predicted from the previous "
            "ones and corrected, with step control.")
    case_options(p)
    law_options(p, restitution=False)
    speed(p)
    target(p)
    curve_params = ", ".join([*CURVE_PARAMETERS, *(n for n in QUANTITIES if n not in CURVE_PARAMETERS)])
    axis_option(p, "the parameter the curve runs over and its values, increasing, in its SI unit (e.g. "
                "v=0.5:10:20:log)", names=curve_params, limit=MAX_CURVE_POINTS)
    for removed in ("--param", "--values"):
        p.add_argument(removed, action=_Removed, example="v=0.5:10:20:log")
    p.add_argument("--what", choices=CURVE_WHATS, default="kappa_c",
                   help="what is continued: kappa_c or kappa_2 (law paper), or grazing (a unilateral law: the first "
                        "grazing value in [KAPPA_MIN, KAPPA_MAX] at the first value) (default: %(default)s)")
    kappa_range(p, False, " (--what grazing only; default: none)", " (--what grazing only; default: none)")
    samples(p, None)
    kappa_tolerance(p, "width of kappa_c's (kappa_2's, the grazing value's) final bracket at each point")
    tolerance(p)
    out_options(p, resume=False)
    json_option(p)
    p.set_defaults(func=cmd_critical_curve)

    p = sub.add_parser("plot", help="draw an archive: an atlas, a sweep or a curve",
                       description="Draw an archive: an atlas (two axes: outcome classes as a colour map, log axes "
                                   "where the axis is log), a sweep (one axis: counts and max force), or a critical "
                                   "curve (kappa against the parameter, the closed form dashed).")
    p.add_argument("archive", metavar="FILE.nc", help="archive written by sweep, atlas or critical-curve")
    figure_out(p)
    p.add_argument("--contours", choices=("none", "n_stick", "n_contacts"), default="none",
                   help="atlas only: overlay the level lines of this count (default: %(default)s)")
    p.add_argument("--curve", action="append", default=None, metavar="CURVE.nc",
                   help="atlas only: overlay a critical curve over the atlas's second axis; repeatable "
                        "(default: none)")
    json_option(p)
    p.set_defaults(func=cmd_plot)

    p = add("portrait", "phase portraits, one panel per kappa, events marked",
            "Phase portraits: one panel per kappa, the trajectory in a phase plane with its events marked "
            "(contacts, separations, slips, stick phases; permanent sticks as asymptotic points) and its outcome "
            "in the panel's title.")
    case_options(p)
    law_options(p, restitution=False)
    speed(p)
    target(p)
    p.add_argument("--kappa", dest="kappas", type=_kappa_list, required=True, metavar="K1,K2,...",
                   help=f"damping coefficients ({KAPPA_UNIT}), 1 to {MAX_PANELS} values in [0, {KAPPA_MAX:g}], "
                        "one panel each")
    p.add_argument("--plane", choices=PLANES, default=PLANES[0],
                   help="phase plane: relative motion, projectile or target (default: %(default)s)")
    horizon(p)
    tolerance(p)
    figure_out(p)
    json_option(p)
    p.set_defaults(func=cmd_portrait)

    p = add("train", "a train of impacts: one projectile every T seconds on the plate as the last left it",
            "A projectile of the case arrives every --period seconds on the plate as the previous impacts left it "
            "(the impact map, docs/physics.md §7): per impact the plate's state before it, its amplitude, the peak "
            "force, the energy dissipated and the restitution; --fixed-point adds the period-1 orbit of the map "
            "with its Floquet multipliers.")
    case_options(p)
    law_options(p)
    speed(p)
    damping(p)
    target(p)
    p.add_argument("--period", type=_real("period", 0.0, None, low_open=True, unit="s"), required=True, metavar="T",
                   help="time between arrivals, s, T > 0")
    p.add_argument("--impacts", type=_integer("impacts", 1, 100_000), default=20,
                   help="number of impacts, 1 to 100000 (default: %(default)s)")
    p.add_argument("--fixed-point", action="store_true", help="also find the period-1 orbit and its multipliers")
    tolerance(p)
    json_option(p)
    train_archive_option(p)
    p.set_defaults(func=cmd_train)

    p = add("orbit-diagram", "the impact map's attractor over T, kappa or v",
            "The impact map iterated at each value of --axis (the period T, kappa or v) from a plate at rest: "
            "--transients impacts dropped, then --samples plate states kept (one point each); the number of "
            "distinct points tells a fixed point (1), a period-k orbit (k) or irregular motion.")
    case_options(p)
    law_options(p)
    speed(p)
    damping(p)
    target(p)
    axis_option(p, "the parameter varied and its values (s, N s/m^(1+alpha) or m/s; e.g. T=2e-3:8e-3:400)",
                names="T, kappa, v", limit=MAX_CURVE_POINTS)
    p.add_argument("--period", type=_real("period", 0.0, None, low_open=True, unit="s"), default=None, metavar="T",
                   help="time between arrivals (s) when the axis is not T (default: none)")
    p.add_argument("--transients", type=_integer("transients", 0, 100_000), default=200,
                   help="impacts dropped at each value (default: %(default)s)")
    p.add_argument("--samples", type=_integer("samples", 1, 100_000), default=50,
                   help="impacts kept at each value (default: %(default)s)")
    p.add_argument("--jobs", type=_integer("jobs", 1, MAX_JOBS), default=1,
                   help="values computed side by side in threads (default: %(default)s)")
    p.add_argument("--out", type=_figure_path, default=None, metavar="FIG.png",
                   help="also draw the diagram into this figure, .png, .pdf or .svg (default: none)")
    p.add_argument("--force", action="store_true", help="replace --out even if it is not a figure (default: refuse)")
    tolerance(p)
    json_option(p)
    train_archive_option(p, force=False)
    p.set_defaults(func=cmd_orbit_diagram)

    p = add("map-continuation", "a branch of periodic orbits of the impact map over T, kappa or v, with its "
                                "bifurcations",
            "The period-K orbit of the impact map followed over the --axis parameter from START to STOP "
            "(pseudo-arclength continuation, docs/physics.md §7), its Floquet multipliers along the way, and its "
            "period-doubling (a multiplier through -1), fold (through +1), Neimark-Sacker (a complex pair through "
            "the unit circle) and grazing points (the contacts per period change) located by bisection.")
    case_options(p)
    law_options(p)
    speed(p)
    damping(p)
    target(p)
    axis_option(p, "the parameter varied, from START to STOP, the largest step along the branch the axis's "
                "spacing (s, N s/m^(1+alpha) or m/s; e.g. T=0.99e-3:0.975e-3:6)", names="T, kappa, v",
                limit=MAX_CURVE_POINTS)
    p.add_argument("--period", type=_real("period", 0.0, None, low_open=True, unit="s"), default=None, metavar="T",
                   help="time between arrivals (s) when the axis is not T (default: none)")
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
    json_option(p)
    train_archive_option(p)
    p.set_defaults(func=cmd_map_continuation)

    p = add("basins", "basins of attraction of the impact map over the plate's initial state",
            "From each initial plate state (x2, x2dot) of an N x N grid (--grid N: evenly spaced positions from "
            "-X to X by velocities from -V to V, --x2-max X, --x2dot-max V) the impact map is iterated until a "
            "period up to --max-period repeats (docs/physics.md §7); each state is labelled by the attractor it "
            "reaches (attractors told apart by their points and period), or as reaching none.")
    case_options(p)
    law_options(p)
    speed(p)
    damping(p)
    target(p)
    p.add_argument("--period", type=_real("period", 0.0, None, low_open=True, unit="s"), required=True, metavar="T",
                   help="time between arrivals, s, T > 0")
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
    p.add_argument("--jobs", type=_integer("jobs", 1, MAX_JOBS), default=1,
                   help="initial states computed side by side in threads (default: %(default)s)")
    p.add_argument("--out", type=_figure_path, default=None, metavar="FIG.png",
                   help="also draw the basins into this figure, .png, .pdf or .svg (default: none)")
    p.add_argument("--force", action="store_true", help="replace --out even if it is not a figure (default: refuse)")
    tolerance(p)
    json_option(p)
    train_archive_option(p, force=False)
    p.set_defaults(func=cmd_basins)
    return parser


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
    from .integrate import scales
    from .train import _check_period

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
    from . import archive

    archive.check_overwrite(args.archive, work.kind, setup.law, setup.params, work.axes, work.t_end, args.rtol,
                            force=args.force, name="archive", settings=work.settings)


def _save_train_archive(args, setup: Setup, result, work: _TrainWork) -> None:
    if args.archive is None:
        return
    from . import archive

    with exclusive(args.archive, "archive"):
        _check_archive_target(args, setup, work)  # another process may have written it meanwhile
        archive.save(result, args.archive, force=args.force, params=setup.case, law=setup.law,
                     settings=work.settings)


def cmd_train(args) -> int:
    from .integrate import scales
    from .train import impact_train, map_fixed_point

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


def cmd_orbit_diagram(args) -> int:
    import numpy as np

    from . import plotting
    from .train import orbit_diagram

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
    _note(f"orbit diagram of {setup.law.label()} over {param}: {len(values)} values x "
          f"{args.transients + args.samples} impacts")
    diagram = orbit_diagram(setup.params, setup.law, param, values, period=args.period,
                            transients=args.transients, samples=args.samples, rtol=args.rtol, n_jobs=args.jobs)
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

    from .train import TRAIN_PARAMETERS

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
        from .train import _check_period

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


def cmd_map_continuation(args) -> int:
    import numpy as np

    from .integrate import scales
    from .train import continue_map_orbit

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


def cmd_basins(args) -> int:
    import numpy as np

    from . import plotting
    from .integrate import scales
    from .train import basins

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


#: Commands that compile and integrate nothing: they start without the engine (numba, SciPy).
_INTEGRATE_NOTHING = ("cases", "params", "completion")


def _stopped(stop: KeyboardInterrupt) -> str:
    from . import _signals

    return "terminated (SIGTERM)" if isinstance(stop, _signals.Terminated) else "interrupted"


def _load_law_files(argv) -> tuple[list, dict]:
    """Run the files of ``--law-file FILE.py`` (they register laws with phaseimpact.define_law);
    return ``argv`` without them, so that every command takes them (``plot`` and ``info`` of an
    archive of a user law too), and ``{path: names of the laws it defines}``."""
    rest, i, files = [], 0, {}
    while i < len(argv):
        arg = argv[i]
        if arg == "--":
            rest.extend(argv[i:])
            break
        path = arg.split("=", 1)[1] if arg.startswith("--law-file=") else (
            argv[i + 1] if arg == "--law-file" and i + 1 < len(argv) else None)
        if path is None:
            rest.append(arg)
            i += 1
            continue
        from .model.userlaw import load_law_file

        files[path] = load_law_file(path)
        i += 1 if arg.startswith("--law-file=") else 2
    return rest, files


def _law_of_files(args, files: dict) -> None:
    """``--law-file`` without ``--law``: the file's one law (unless the case names a user law); a
    shipped law of the case, paper by default, would silently ignore the file."""
    from .model import LAWS

    if not files or not hasattr(args, "law") or args.command == "check-law" or args.law is not None \
            or "law" in _setting_names(args):
        return
    defined = [name for names in files.values() for name in names]
    case = getattr(args, "case", None)
    if case is not None and case.impact["law"] not in LAWS:
        return
    from .model.userlaw import single_law

    args.law = single_law(defined, " and ".join(files), "--law NAME")


_ANSI_ESCAPE = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


class _StandardOutput:
    """``sys.stdout`` for a command: a failed write names the standard output (``> /dev/full``: the disk
    is full, but no file of ours); characters its encoding lacks are written as escapes
    (``PYTHONIOENCODING=ascii``), not an error half way through the output."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except UnicodeEncodeError as error:
            return self._stream.write(text.encode(error.encoding, "backslashreplace").decode(error.encoding))
        except BrokenPipeError:
            raise
        except OSError as error:
            raise OSError(error.errno, error.strerror or str(error), "standard output") from None

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            raise
        except OSError as error:
            raise OSError(error.errno, error.strerror or str(error), "standard output") from None

    def __getattr__(self, name):
        return getattr(self._stream, name)


def main(argv=None) -> int:
    # Ctrl-C and SIGTERM, wherever they arrive (compiled runs included): one line, exit 130 or 143
    previous_term = signal.getsignal(signal.SIGTERM)
    try:
        argv = list(sys.argv[1:] if argv is None else argv)
        if any(arg == "--law-file" or arg.startswith("--law-file=") for arg in argv):
            from . import _signals  # a law file compiles (seconds): Ctrl-C and SIGTERM end it with one line

            _signals.install_command_line()
        parsed, law_files = _load_law_files(argv)  # before the parser: its --law choices include the file's laws
        parser = build_parser()
        args = parser.parse_args(parsed)
        args.argv = argv
        _law_of_files(args, law_files)
        if args.command not in _INTEGRATE_NOTHING:  # _signals imports numba (0.2 s): only where runs are stopped
            from . import _signals

            _signals.install_command_line()
        stdout, sys.stdout = sys.stdout, _StandardOutput(sys.stdout)
        try:
            code = args.func(args)
            sys.stdout.flush()  # a full standard output fails here, named, not at the interpreter's exit
        finally:
            sys.stdout = stdout
        return code
    except ValueError as error:  # one line, without the colour escapes numba puts in its messages
        print(f"phaseimpact: error: {_ANSI_ESCAPE.sub('', str(error))}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt as stop:
        if not getattr(stop, "reported", False):
            print(f"phaseimpact: {_stopped(stop)}", file=sys.stderr)
        from . import _signals

        return _signals.exit_code(stop)
    except BrokenPipeError:  # the reader of stdout went away (| head): nothing more to say
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError, AttributeError):
            pass
        return EXIT_BROKEN_PIPE
    except OSError as error:  # the disk, not the input: full, gone, permissions changed under us
        print(f"phaseimpact: error: {error}", file=sys.stderr)
        return EXIT_FAILURE
    finally:
        if previous_term is not None and threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGTERM, previous_term)  # main() called in-process (tests) leaves it as it was


if __name__ == "__main__":
    sys.exit(main())
