"""Commands over one case: one impact (``simulate``), the equilibria (``fixed-points``), the critical
damping (``critical``) and every transition in a kappa range (``transitions``)."""

from __future__ import annotations

import contextlib
import math
import sys

from .._atomic import exclusive
from ..parameters import KAPPA_MAX
from . import _options as options
from ._case import Setup, _case_fields, _check_kappa_range, _check_reads_kappa, _law_fields, _setup
from ._common import CRITICAL_ANSWERS, DEFAULT_SAMPLES, EXIT_FAILURE, EXIT_OK, _fmt, _note, _print_json


@contextlib.contextmanager
def _out_archive(args, setup: Setup, kind: str, t_end, settings: dict):
    """``--out`` of simulate and transitions: the overwrite rule of every archive
    (:func:`phaseimpact.archive.check_overwrite`) before any work, and one writer (the path's lock,
    held from the check to the write). Yields the function that writes the result; None without ``--out``."""
    if args.out is None:
        yield None
        return
    from .. import archive

    archive.created_timestamp()  # a bad SOURCE_DATE_EPOCH is refused before any work
    with exclusive(args.out, "out"):
        archive.check_overwrite(args.out, kind, setup.law, setup.params, {}, t_end, args.rtol, force=args.force,
                                settings=settings)

        def write(result) -> None:  # a trajectory carries its law
            archive.save(result, args.out, force=args.force, params=setup.case,
                         law=None if kind == "trajectory" else setup.law, settings=settings)

        yield write


def _check_critical_law(law) -> None:
    if not law.is_filippov:
        from ..model import REGISTRY

        allowed = ", ".join(n for n, entry in REGISTRY.items() if entry.filippov)
        raise ValueError(f"law = {law.name!r} is out of range for the critical damping; allowed: a Filippov law "
                         f"({allowed}; the others have no stick phases to split: see 'phaseimpact transitions')")


def _check_grazing_target(law, params) -> None:
    """Grazing needs the plate to swing back: without it a unilateral impact has one contact."""
    if not law.is_filippov and params.target != "plate":
        raise ValueError(f"target = {params.target!r} is out of range for the grazing transitions of law "
                         f"{law.label()!r} (without the plate's springs nothing swings back: one contact); "
                         "allowed: target plate")


def add_simulate(p) -> None:
    options.case_options(p)
    options.law_options(p)
    options.speed(p)
    options.damping(p)
    options.target(p)
    options.horizon(p, "horizon")
    options.tolerance(p)
    options.run_out(p, "the trajectory (its steps, event log and summary)")
    options.json_option(p)


def _contact_reading(trajectory, setup: Setup) -> dict:
    """Hertz contact radius and peak pressure at the run's largest force, and whether elastic Hertz
    contact holds there (null when the run has no finite force)."""
    from ..model.contact import hertz_contact, plastic_contact, plastic_validity, validity_for_force

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


def run_simulate(args) -> int:
    from ..integrate import scales, simulate
    from ..quantities import impact_quantities

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
        article = "an" if p.target == "infinite" else "a"
        print(f"{law.label()} on {article} {p.target} target ({setup.case.name}), v = {p.v:g} m/s, "
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


def add_fixed_points(p) -> None:
    options.case_options(p)
    options.law_options(p)
    options.speed(p)
    options.damping(p, "moves no equilibrium")
    options.target(p)
    options.json_option(p)


def _eigenvalue_text(z) -> str:
    re_, im = float(z.real) + 0.0, float(z.imag) + 0.0  # + 0.0: no "-0"
    return f"{re_:.6g}" if im == 0 else (f"{im:+.6g}i" if re_ == 0 else f"{re_:.6g}{im:+.6g}i")


def run_fixed_points(args) -> int:
    from ..analysis import fixed_points

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


def add_critical(p) -> None:
    options.case_options(p)
    options.law_options(p, restitution=False)
    options.speed(p)
    options.target(p)
    options.kappa_tolerance(p)
    options.tolerance(p)
    options.kappa_range(p, False, " (default: 1e-8 K/v, the damping number below which the approach is undamped)",
                        f" (default: {KAPPA_MAX:g}; the search widens from the closed form until the margin changes "
                        "sign)")
    p.add_argument("--exponents", action="store_true",
                   help="also measure the adding-sliding exponents (slip speed ~ eps^1.5, stick offset ~ eps^2; "
                        "about 1 s)")
    options.json_option(p)


def run_critical(args) -> int:
    from ..continuation import critical_damping

    setup = _setup(args)
    law, params = setup.law, setup.params
    _check_critical_law(law)
    _check_kappa_range(args)
    from ..continuation.transition import default_kappa_range

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


def add_transitions(p) -> None:
    options.case_options(p)
    options.law_options(p, restitution=False)
    options.speed(p)
    options.target(p)
    options.kappa_range(p, True)
    options.samples(p, DEFAULT_SAMPLES)
    options.kappa_tolerance(p, "width of each transition's final bracket")
    options.tolerance(p)
    options.run_out(p, "the transitions")
    options.json_option(p)


def run_transitions(args) -> int:
    import warnings

    from ..continuation import transitions
    from ..continuation.transition import RunFailed, SamplingWarning, check_samples

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
