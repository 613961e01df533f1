"""A transition continued over a second parameter (``critical-curve``)."""

from __future__ import annotations

import sys

from .._atomic import exclusive
from ..parameters import V_RANGE
from ..settings import QUANTITIES, SETTABLE
from . import _options as options
from ._case import (
    Setup,
    _check_in_range,
    _check_kappa_range,
    _check_reads_kappa,
    _given,
    _law_fields,
    _setting_names,
    _setup,
)
from ._common import (
    CURVE_PARAMETERS,
    CURVE_WHATS,
    DEFAULT_SAMPLES,
    EXIT_FAILURE,
    EXIT_OK,
    MAX_CURVE_POINTS,
    PARAM_UNITS,
    _fmt,
    _note,
    _one_axis,
    _print_json,
    _progress,
)


def add_critical_curve(p) -> None:
    options.case_options(p)
    options.law_options(p, restitution=False)
    options.speed(p)
    options.target(p)
    curve_params = ", ".join([*CURVE_PARAMETERS, *(n for n in QUANTITIES if n not in CURVE_PARAMETERS)])
    options.axis_option(p, "the parameter the curve runs over and its values, increasing, in its SI unit (e.g. "
                        "v=0.5:10:20:log)", names=curve_params, limit=MAX_CURVE_POINTS)
    for removed in ("--param", "--values"):
        p.add_argument(removed, action=options.Removed, example="v=0.5:10:20:log")
    p.add_argument("--what", choices=CURVE_WHATS, default="kappa_c",
                   help="what is continued: kappa_c or kappa_2 (law paper), or grazing (a unilateral law: the first "
                        "grazing value in [KAPPA_MIN, KAPPA_MAX] at the first value) (default: %(default)s)")
    options.kappa_range(p, False, " (--what grazing only; default: none)", " (--what grazing only; default: none)")
    options.samples(p, None)
    options.kappa_tolerance(p, "width of kappa_c's (kappa_2's, the grazing value's) final bracket at each point")
    options.tolerance(p)
    p.add_argument("--backend", choices=("threads", "cuda"), default="threads",
                   help="where each point's correction runs: this process (Brent's method), or a GPU (cuda: the "
                        "defining function at many kappas of the bracket in each launch, one thread each; the first "
                        "point and kappa_2's confirmation stay on the CPU; phaseimpact backends says whether it works "
                        "here) (default: %(default)s)")
    options.out_options(p, resume=False)
    options.json_option(p)


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


def _check_what(args, setup: Setup) -> None:
    """The options ``--what`` reads and refuses: kappa_c and kappa_2 are a Filippov law's, a grazing value a
    unilateral law's on a plate, in a kappa range."""
    law, what = setup.law, args.what
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


def run_critical_curve(args) -> int:
    import numpy as np

    from .. import archive
    from ..continuation import critical_curve, transitions
    from ..continuation.transition import RunFailed

    setup = _setup(args)
    law = setup.law
    what = args.what
    _check_what(args, setup)
    param, values = _curve_values(args, setup)
    if args.backend == "cuda":
        from .. import cuda

        cuda.check(law)  # a user law, or no GPU: one line and exit 2, nothing computed
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
                                   progress=_progress(args), backend=args.backend)
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
