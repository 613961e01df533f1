"""The case, the law and the parameters a command computes with, resolved from the options and checked
before any work."""

from __future__ import annotations

import dataclasses
import math

from ..parameters import KAPPA_MAX, V_RANGE
from ..settings import setting_name
from ._common import KAPPA_UNIT, RESTITUTION_RANGE


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
    from ..model import REGISTRY, ContactLaw

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
        from ..model.restitution import check_attainable

        check_attainable(law)
    return law


def _setup(args, *, law=True) -> Setup:
    """Resolve the case (``--case``, ``--set``), the explicit options and the law; check every value.

    Raises ``ValueError`` (exit 2) naming the parameter, its value and the allowed range.
    """
    from ..case import load_case

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
        from ..integrate.api import check_t_end, scales

        check_t_end(args.t_end, scales(params).contact_time, name="t-end")
    return Setup(case, contact_law, params)




def _check_reads_kappa(law, what: str) -> None:
    if not law.reads("kappa"):
        source = (f"its damping comes from restitution = {law.restitution:g}" if law.damping_source == "restitution"
                  else "it has no damping")
        raise ValueError(f"law {law.label()!r} does not read kappa ({source}): every {what} would be the same "
                         "run; allowed: a law that reads kappa (paper, hunt-crossley) without --restitution")



def _check_kappa_range(args) -> None:
    if args.kappa_min is not None and args.kappa_max is not None and not args.kappa_min < args.kappa_max:
        raise ValueError(f"kappa-min = {args.kappa_min!r}, kappa-max = {args.kappa_max!r} are out of range; "
                         "allowed: kappa-min < kappa-max")



def _law_fields(setup: Setup) -> dict:
    law = setup.law
    return {"law": law.name, "law_label": law.label(), "contact": law.contact if law.is_filippov else None,
            "restitution": law.restitution}


def _case_fields(setup: Setup) -> dict:
    """The law and the case's speed, damping and target: the head of a single-case command's JSON."""
    law, p = setup.law, setup.params
    return {**_law_fields(setup), "v": p.v, "kappa": law.kappa(p), "kappa_unit": law.damping_unit(p.alpha),
            "target": p.target}
