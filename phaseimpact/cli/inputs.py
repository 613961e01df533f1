"""What a command computes with, shown without a run: the shipped cases (``cases``), a case's derived
parameters and scales (``params``), and the law conformance suite (``check-law``)."""

from __future__ import annotations

import os

from . import _options as options
from ._case import _law_fields, _setup
from ._common import EXIT_FAILURE, EXIT_OK, KAPPA_UNIT, PARAM_UNITS, _fmt, _print_json


def add_cases(p) -> None:
    options.json_option(p)


def run_cases(args) -> int:
    from ..case import list_cases

    cases = list_cases()
    if args.json:
        _print_json(args, {"cases": cases})
    else:
        width = max(len(c["name"]) for c in cases)
        for c in cases:
            print(f"{c['name']:<{width}}  {c['description']}")
        print("(phaseimpact COMMAND --case NAME; 'phaseimpact cases --json' also gives each case's sources)")
    return EXIT_OK


def add_params(p) -> None:
    options.case_options(p)
    options.law_options(p)
    options.speed(p)
    options.damping(p, "not read by the scales")
    options.target(p)
    options.json_option(p)


def run_params(args) -> int:
    from ..model.contact import hertz_scales, validity

    setup = _setup(args)
    p, case, law = setup.params, setup.case, setup.law
    out = {**_law_fields(setup),
           **{k: getattr(p, k) for k in ("M1", "M2", "K", "Kb", "Km", "alpha", "kappa", "v", "target", "R")}}
    out["kappa_unit"] = law.damping_unit(p.alpha)
    # The Hertz scales are those of the relative motion: the reduced mass M1 M2/(M1+M2) unless the
    # target is rigid (docs/physics.md §4); say which, since a plate's figures differ from a rigid one's.
    out["hertz_mass"] = p.reduced_mass
    out["hertz_mass_is"] = ("M1 (rigid target)" if p.target == "rigid" else
                            "M1 (infinite target: the load point has no mass)" if p.target == "infinite"
                            else f"reduced mass M1 M2/(M1+M2) ({p.target} target)")
    out.update(hertz_scales(p, case.plate))
    out["validity"] = validity(p, case.plate, case.projectile, case.geometry)
    # Thornton's elastic-plastic law (--law thornton) yields at v_y, where the Hertz peak pressure
    # reaches p_y = 1.6 Y of the weaker body (null without a yield strength)
    out["limiting_pressure"] = p.limiting_pressure
    out["yield_velocity"] = p.yield_velocity
    out.update(_laminate_and_regime(p, case))
    out["case"] = case.as_dict()
    if args.json:
        _print_json(args, out)
    else:
        print(f"case {case.name}: {case.description}" if case.description else f"case {case.name}")
        print(f"  {'law':>23} = {law.label()}")
        for k, value in out.items():
            if k in ("case", "validity", "target", "hertz_mass_is", "kappa_unit", "laminate", "regime",
                     "regime_warning", *_law_fields(setup)):
                continue
            unit = out["kappa_unit"] or KAPPA_UNIT if k == "kappa" else PARAM_UNITS.get(k, "")
            print(f"  {k:>23} = {_fmt(value, unit)}".rstrip())
        print(f"  {'target':>23} = {p.target}")
        print(f"  Hertz scales (contact_time ... peak_pressure) use hertz_mass, the {out['hertz_mass_is']}")
        print(f"  validity: {out['validity']}")
        if out["laminate"] is not None:
            print(f"  laminate: {len(case.plate.plies)} plies, h = {case.geometry.h:g} m; A (N/m), B (N), D (N m) in "
                  "the plate's axes (x, y, xy):")
            A = out["laminate"]["A"]
            # rounding of the ply sums leaves ~1e-16 of the largest term where the layup gives zero:
            # printed as 0 (B is on the scale of A h); --json keeps the sums as computed
            scale_A = max(abs(x) for row in A for x in row)
            for name, scale in (("A", scale_A), ("B", scale_A * case.geometry.h), ("D", None)):
                matrix = out["laminate"][name]
                scale = scale or max(abs(x) for row in matrix for x in row)
                rows = "; ".join(" ".join(f"{x if abs(x) > 1e-12 * scale else 0.0:.4g}" for x in row)
                                 for row in matrix)
                print(f"  {name:>23} = [{rows}]")
        print(f"  regime: {out['regime']} by Olsson's mass criterion (M1 over the whole plate's mass "
              f"{_fmt(out['plate_mass'], 'kg')}: wave-controlled below 0.23, quasi-static above 2)")
        if out["regime_warning"]:
            print(f"  regime warning: {out['regime_warning']}")
    return EXIT_OK


def _laminate_and_regime(p, case) -> dict:
    """The laminate's stiffness matrices (null for an isotropic plate) and which plate model the
    impact calls for (docs/physics.md §8)."""
    from ..model.laminate import Laminate
    from ..model.regime import regime_report

    report = regime_report(p, case.plate, case.geometry)
    laminate = None
    if isinstance(case.plate, Laminate):
        A, B, D = case.plate.abd()
        laminate = {"A": A.tolist(), "B": B.tolist(), "D": D.tolist(), "D_star": report["D_star"]}
    return {"laminate": laminate, **{k: report[k] for k in ("plate_impedance", "zener_lambda", "plate_mass",
                                                            "mass_ratio", "regime", "regime_warning")}}


def add_check_law(p) -> None:
    p.add_argument("law", metavar="LAW|FILE.py", help="a registered law's name, or a Python file defining laws")
    options.json_option(p)


def run_check_law(args) -> int:
    from ..checks import check_law
    from ..model import REGISTRY, law_variants
    from ..model.userlaw import load_law_file

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
