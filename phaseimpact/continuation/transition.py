"""Where the long-time behaviour changes with ``kappa`` (docs/physics.md §5).

``paper`` (a Filippov system): below the critical damping ``kappa_c`` the first stick is
permanent (one asymptotic point); at ``kappa_c`` the stuck pair's sliding orbit touches the
boundary of the sliding region at its turning points, an **adding-sliding** bifurcation; above
it the trajectory makes ``N(kappa)`` stick phases, ratchets and escapes after ``T_run``, and
``N = 2`` from ``kappa_2`` on. ``kappa_c`` is the root of the first stick's margin
``1 - M1/M S(A) / (K delta*^alpha)``, found without any horizon.

Unilateral laws: the number of contacts before the projectile is out of reach changes where a
flight phase's largest ``delta`` just reaches zero, a **grazing** bifurcation, located as the
root of that extremum (a smooth function of ``kappa``), not by counting.

This module locates ``kappa_c`` and is the face of the searches in ``kappa``: :mod:`.kappa_2`
(``kappa_2``, the staircase, the adding-sliding's exponents), :mod:`.grazing` (grazing values) and
:mod:`._kappa_search` (their inputs' checks, :class:`RunFailed`, :class:`Transition`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from ..integrate.api import check_rtol
from ..integrate.driver import S_FIRST_STICK_MARGIN
from ..model.laws import REGISTRY, ContactLaw, as_law
from ..parameters import KAPPA_MAX, Parameters
from ._kappa_search import (
    A_MIN,
    RunFailed,
    Transition,
    check_kappa_range,
    check_params,
    check_rtol_of_kappa,
    checked_summary,
    default_kappa_range,
)
from ._renamed import renamed_tolerances
from .confirm import confirmed_count, tighter
from .grazing import SAMPLES_RANGE, SamplingWarning, check_samples, delta_extremum, extrema, grazing_transitions
from .kappa_2 import KAPPA_2_RTOL, Kappa2, adding_sliding_exponents, locate_kappa_2

__all__ = [
    "closed_form_kappa_c", "first_stick_margin", "critical_damping", "CriticalDamping", "Kappa2", "locate_kappa_2",
    "adding_sliding_exponents", "delta_extremum", "extrema", "grazing_transitions", "transitions",
    "Transition", "check_kappa_range", "check_samples", "RunFailed", "SamplingWarning", "SAMPLES_RANGE",
]


def closed_form_kappa_c(params: Parameters) -> float | None:
    """``kappa_c`` of docs/physics.md §5's closed form (two-body Hunt-Crossley approach, momentum
    conserved during the contact, stuck pair on the springs); None without a plate.

    An estimate (within a few tenths of a percent for the seed's case) that seeds the bracket of
    :func:`critical_damping`.

    Parameters
    ----------
    params : Parameters
        The case (its ``kappa`` is not read).

    Returns
    -------
    float or None
        N s/m^(1+alpha), possibly beyond ``KAPPA_MAX`` (an estimate, not an input); None for a
        rigid or free target, a plate without bending stiffness, or a stick that breaks already
        at the damping number ``kappa v / K`` = :data:`A_MIN` (no root above it).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import closed_form_kappa_c
    >>> print(f"{closed_form_kappa_c(seed_parameters(v=1.0)):.4g} N s/m^2.5")
    1.497e+12 N s/m^2.5
    >>> print(closed_form_kappa_c(seed_parameters(target="rigid")))
    None
    """
    from scipy.optimize import brentq  # imported where used: 0.5 s at start-up
    if params.target != "plate" or params.Kb <= 0:
        return None
    M = params.M1 + params.M2
    m, K, alpha, v = params.reduced_mass, params.K, params.alpha, params.v
    V = params.M1 * v / M
    E = 0.5 * M * V * V
    # the turning point of Kb X^2/2 + Km X^4/4 = E, written without the cancellation of
    # (-Kb + sqrt(Kb^2 + 4 Km E)) / Km, which gave X = 0 for a grain's tiny energy (and a division by 0)
    X2 = 4 * E / (params.Kb + math.sqrt(params.Kb**2 + 4 * params.Km * E))
    X = math.sqrt(X2)
    required = params.M1 / M * (params.Kb * X + params.Km * X**3)
    if required <= 0:
        return None

    def gap(log_a):
        a = math.exp(log_a)
        # a - ln(1+a) without cancellation for small a
        core = a - math.log1p(a) if a > 1e-4 else a * a * (0.5 - a / 3 + a * a / 4)
        delta = ((alpha + 1) * m * v * v * core / (K * a * a)) ** (1 / (alpha + 1))
        return math.log(K * delta**alpha / required)

    # delta* falls monotonically with a (like a^(-1/(alpha+1)) for large a), so the gap has at most
    # one root, and one exactly when it is positive at A_MIN: widen the upper end until it is negative
    lo = math.log(A_MIN)
    if gap(lo) <= 0:
        return None
    hi = math.log(1e8)
    while gap(hi) > 0:
        hi += math.log(1e8)
        if hi > math.log(1e100):  # a * a would overflow: no estimate
            return None
    return math.exp(brentq(gap, lo, hi, xtol=1e-14, rtol=1e-14)) * K / v


def first_stick_margin(params: Parameters, law: ContactLaw | str = "paper", *, rtol: float = 1e-10) -> float:
    """Margin of the first stick (``>= 0``: it never breaks); -inf if the run never sticks.

    ``1 - M1/M S(A) / (K delta*^alpha)`` of the first stick phase (docs/physics.md §5), from a run
    that stops there: a smooth function of ``kappa`` whose root is ``kappa_c``, found without any
    horizon.

    Parameters
    ----------
    params : Parameters
        The case, with its ``kappa`` (N s/m^(1+alpha)).
    law : ContactLaw or str, default "paper"
        ``paper`` or another Filippov law.
    rtol : float, default 1e-10
        Integrator tolerance, within :data:`~phaseimpact.integrate.RTOL_RANGE`.

    Returns
    -------
    float
        Dimensionless margin; -inf when the run never sticks.

    Raises
    ------
    RunFailed
        If the run fails numerically (a search must not take that as a value).
    ValueError
        For an argument :func:`~phaseimpact.simulate` refuses.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import first_stick_margin
    >>> p = seed_parameters(v=1.0)
    >>> print(f"{first_stick_margin(p.replace(kappa=1e12)):.4f} {first_stick_margin(p.replace(kappa=2e12)):.4f}")
    0.2046 -0.1795
    """
    t_end, options = margin_run(params)
    return margin_of(checked_summary(params, law, t_end, rtol=rtol, **options)[0])


def margin_run(params: Parameters) -> tuple[None, dict]:
    """The horizon (the case's own) and options of :func:`first_stick_margin`'s run."""
    return None, {"stop_on": "stick"}


def margin_of(summary) -> float:
    """:func:`first_stick_margin` read from its run's summary."""
    margin = summary[S_FIRST_STICK_MARGIN]
    return -math.inf if math.isnan(margin) else float(margin)


@dataclass(frozen=True)
class CriticalDamping:
    """The critical damping of ``paper`` at one case (docs/physics.md §5).

    What :func:`critical_damping` found.

    Attributes
    ----------
    law, contact : str
        The law's name and its reading of ``|delta|^alpha``.
    v : float
        Impact speed of the case, m/s.
    kappa_c : float or None
        Root of the first stick's margin, N s/m^(1+alpha); None when not found.
    rtol : float
        Relative tolerance asked of ``kappa_c``: the call's ``kappa_rtol``.
    closed_form : float or None
        docs/physics.md §5's closed-form estimate.
    bracket : tuple of float
        The final bracket of the root (or the search range when none was found), N s/m^(1+alpha).
    search_range : tuple of float
        The range searched, N s/m^(1+alpha) (no root found: none lies in it).
    margins : tuple
        Margin at the search range's ends (or at the final bracket).
    message : str
        The result in words (counts either side, accuracy, why unconfirmed or not found).
    evaluations : int
        Runs the search made.
    kappa_c_accuracy : float or None
        Estimated relative error of ``kappa_c``: the final bracket's width plus its change when the
        root is solved again at a tighter integrator tolerance (:func:`.confirm.tighter`).
    kappa_2 : float or None
        Smallest ``kappa`` from which the trajectory makes exactly 2 stick phases.
    kappa_2_accuracy : float or None
        Relative width of ``kappa_2``'s final bracket, whose ends are confirmed (N = 2 above, N != 2
        below) at the tighter tolerance; None when they are not.
    n_below, n_above : int or None
        Stick phases just below ``kappa_c`` (1: the permanent stick) and just above it, at
        ``kappa_c (1 -+ SIDE_OFFSET)``; None where the count is not confirmed.
    n_below_kappa_2, n_above_kappa_2 : int or None
        Stick phases just below ``kappa_2`` (at its bracket's lower end, confirmed) and above it (2).
    n_staircase : list of dict
        ``{"kappa", "relative", "n_stick", "t_run", "cut", "confirmed", "reason"}`` sampled from
        above ``kappa_2`` down towards ``kappa_c`` until a run is cut by the horizon; ``n_stick`` is
        None where the count is not confirmed (:func:`.confirm.confirmed_count`, ``reason`` says why).
    classification : str or None
        ``adding-sliding`` with :attr:`exponents` when measured.
    exponents : dict or None
        :func:`adding_sliding_exponents`, when asked for.
    status : {"success", "not-found", "unconfirmed", "failed"}
        The whole result: ``success`` only when every quantity below is confirmed; ``failed``: a
        run of the search failed numerically (the message says which).
    kappa_c_status : {"confirmed", "unconfirmed", "not-found", "failed"}
        ``kappa_c`` alone: confirmed by the counts either side (1 permanent stick below, a break
        above), each confirmed (:func:`.confirm.confirmed_count`).
    kappa_2_status : {"confirmed", "unconfirmed", "not-found"} or None
        ``kappa_2`` alone: both ends of its bracket confirmed; None when not located (not asked
        for, or ``kappa_c`` unconfirmed).
    staircase_status : {"confirmed", "unconfirmed"} or None
        Every count of :attr:`n_staircase` confirmed, or some not (their ``reason`` says why);
        None without a staircase. An unconfirmed count leaves ``kappa_c`` and ``kappa_2``
        confirmed where they are.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import critical_damping
    >>> c = critical_damping(seed_parameters(v=1.0), "paper")
    >>> c.status, c.classification, c.kappa_2
    ('success', 'adding-sliding', None)
    """

    law: str
    contact: str
    v: float
    kappa_c: float | None
    rtol: float
    closed_form: float | None
    bracket: tuple
    margins: tuple
    status: str
    message: str
    evaluations: int
    kappa_c_accuracy: float | None = None
    kappa_2: float | None = None
    kappa_2_accuracy: float | None = None
    n_below: int | None = None
    n_above: int | None = None
    n_below_kappa_2: int | None = None
    n_above_kappa_2: int | None = None
    n_staircase: list = field(default_factory=list)
    classification: str | None = None
    exponents: dict | None = None
    search_range: tuple = ()
    kappa_c_status: str | None = None
    kappa_2_status: str | None = None
    staircase_status: str | None = None

    def as_dict(self) -> dict:
        """The fields as a plain dict (for JSON).

        Returns
        -------
        dict
            ``{field: value}`` in the order of the fields.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.continuation import critical_damping
        >>> list(critical_damping(seed_parameters(), "paper").as_dict())[:4]
        ['law', 'contact', 'v', 'kappa_c']
        """
        return asdict(self)


@renamed_tolerances("kappa_rtol")
def critical_damping(params: Parameters, law: ContactLaw | str = "paper", *, kappa_min: float | None = None,
                     kappa_max: float | None = None, kappa_rtol: float = 1e-10, rtol: float = 1e-10,
                     with_kappa_2: bool = False, with_exponents: bool = False) -> CriticalDamping:
    """Locate ``kappa_c``, the root of the first stick's margin, for any case.

    The bracket is seeded by the closed form (docs/physics.md §5) and widened geometrically within
    ``[kappa_min, kappa_max]`` (default: from the damping number ``kappa v / K`` = 1e-8, below
    which the approach is undamped, up to the inputs' limit ``KAPPA_MAX`` = 1e18) until the margin
    changes sign; Brent's method narrows it to ``kappa_rtol`` (relative). Counts either side confirm it:
    one permanent stick just below, two or more stick phases just above. No root in the range
    gives status ``not-found``, ``kappa_c`` None and a message saying what was searched ("no
    root ... up to kappa = ...", the margins at both ends), never that the stick cannot break
    unless the equations say so (a target without springs).

    Parameters
    ----------
    params : Parameters
        The case (its own ``kappa`` is not read).
    law : ContactLaw or str, default "paper"
        ``paper`` or another Filippov law.
    kappa_min, kappa_max : float, optional
        Search range, N s/m^(1+alpha), ``0 < kappa_min < kappa_max <= 1e18``; an end not given
        is the default above.
    kappa_rtol : float, default 1e-10
        Relative tolerance of ``kappa_c``, ``1e-14 <= kappa_rtol <= 1e-2`` (called ``rtol`` up to
        0.2.0).
    rtol : float, default 1e-10
        The integrator's tolerance of every run, within :data:`~phaseimpact.integrate.RTOL_RANGE`
        (called ``integrator_rtol`` up to 0.2.0; ``rtol=`` alone is refused for one release).
    with_kappa_2 : bool, default False
        Also locate ``kappa_2`` and sample the staircase (:func:`locate_kappa_2`).
    with_exponents : bool, default False
        Also measure the local exponents of the adding-sliding (:func:`adding_sliding_exponents`).

    Returns
    -------
    CriticalDamping
        ``status`` ``success`` only when the counts either side (and, with ``kappa_2``, every
        count) are confirmed; ``failed`` when a run of the search failed numerically.

    Raises
    ------
    TypeError
        If ``params`` is not :class:`~phaseimpact.Parameters`.
    ValueError
        For a law that is not a Filippov law (unilateral laws have grazing transitions:
        :func:`transitions`), ``kappa_rtol``, ``rtol`` or the search range out of range.
    TypeError
        For the spellings of 0.2.0 (``integrator_rtol=``; ``rtol=`` without ``kappa_rtol=``).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import critical_damping
    >>> c = critical_damping(seed_parameters(v=1.0), "paper")
    >>> print(f"{c.kappa_c:.6g} N s/m^2.5 ({c.status}), closed form {c.closed_form:.4g}")
    1.49942e+12 N s/m^2.5 (success), closed form 1.497e+12
    >>> critical_damping(seed_parameters(v=1.0), "paper", kappa_min=1e8, kappa_max=1e10).status
    'not-found'
    """
    check_params(params)
    law = as_law(law)
    if not law.is_filippov:
        allowed = ", ".join(name for name, entry in REGISTRY.items() if entry.filippov)
        raise ValueError(f"law = {law.name!r} is out of range for the critical damping; allowed: a Filippov law "
                         f"({allowed}; unilateral laws have grazing transitions: use transitions())")
    check_rtol_of_kappa(kappa_rtol)
    rtol = check_rtol(rtol)
    kappa_min, kappa_max = default_kappa_range(params, kappa_min, kappa_max)
    closed = closed_form_kappa_c(params)
    try:
        result = _critical_damping(params, law, kappa_min, kappa_max, kappa_rtol, rtol, with_kappa_2,
                                   with_exponents, closed)
    except RunFailed as error:
        result = CriticalDamping(law.name, law.contact, params.v, None, kappa_rtol, closed, (kappa_min, kappa_max),
                                 (math.nan, math.nan), "failed", f"a run of the search failed: {error}", 0,
                                 kappa_c_status="failed")
    return _replace(result, search_range=(kappa_min, kappa_max))


def _critical_damping(params, law, kappa_min, kappa_max, kappa_rtol, rtol, with_kappa_2, with_exponents,
                      closed) -> CriticalDamping:
    from scipy.optimize import brentq  # imported where used: 0.5 s at start-up
    evaluations = 0

    def margin(log_kappa):
        nonlocal evaluations
        evaluations += 1
        return first_stick_margin(params.replace(kappa=math.exp(log_kappa)), law, rtol=rtol)

    lo, hi = math.log(kappa_min), math.log(kappa_max)
    start = min(max(math.log(closed), lo), hi) if closed else 0.5 * (lo + hi)
    m_start = margin(start)
    # widen geometrically (factor 2, then 4, 8...) towards the sign change
    a, m_a, step = start, m_start, math.log(2.0)
    going_up = m_start >= 0  # permanent stick: the root lies above
    b, m_b = a, m_a
    while True:
        b = min(a + step, hi) if going_up else max(a - step, lo)
        m_b = margin(b)
        if (m_b < 0) == going_up or b in (lo, hi):
            break
        a, m_a, step = b, m_b, 2 * step
    kappa_lo, kappa_hi = sorted((math.exp(a), math.exp(b)))
    if (m_a >= 0) == (m_b >= 0):
        m_min, m_max = (margin(lo), margin(hi))
        return CriticalDamping(law.name, law.contact, params.v, None, kappa_rtol, closed, (kappa_min, kappa_max),
                               (m_min, m_max), "not-found",
                               _not_found_message(params, kappa_min, kappa_max, m_min, m_max, closed), evaluations,
                               kappa_c_status="not-found")
    root = brentq(margin, min(a, b), max(a, b), xtol=kappa_rtol / 4, rtol=4 * np.finfo(float).eps, maxiter=200)
    kappa_c = math.exp(root)
    accuracy, spent = _kappa_c_accuracy(params, law, root, kappa_rtol, rtol)
    evaluations += spent
    # confirm with the counts either side, far enough from kappa_c for short runs
    below = confirmed_count(params.replace(kappa=kappa_c * (1 - SIDE_OFFSET)), law, rtol)
    above = confirmed_count(params.replace(kappa=kappa_c * (1 + SIDE_OFFSET)), law, rtol)
    evaluations += 4
    ok = below.confirmed and above.confirmed and below.n_stick == 1 and not below.cut and above.n_stick >= 2
    message = (f"kappa_c = {kappa_c:.10g} N s/m^(1+alpha), estimated relative error {_fmt_accuracy(accuracy)} "
               f"(root of the first stick's margin); at kappa_c (1 - {SIDE_OFFSET:g}): {below.n_stick} stick phase"
               f" (permanent), at kappa_c (1 + {SIDE_OFFSET:g}): {above.n_stick}")
    if not ok:
        message += "; " + "; ".join(r for r in (below.reason, above.reason) if r) if (below.reason or above.reason) \
            else "; the counts either side do not show a permanent stick below and a break above"
    result = CriticalDamping(law.name, law.contact, params.v, kappa_c, kappa_rtol, closed, (kappa_lo, kappa_hi),
                             (float(m_a), float(m_b)), "success" if ok else "unconfirmed", message, evaluations,
                             kappa_c_accuracy=accuracy, n_below=below.n_stick if below.confirmed else None,
                             n_above=above.n_stick if above.confirmed else None,
                             kappa_c_status="confirmed" if ok else "unconfirmed")
    if with_kappa_2 and ok:
        result = _with_kappa_2(result, params, law, rtol)
    if with_exponents and ok:
        result = _replace(result, classification="adding-sliding",
                          exponents=adding_sliding_exponents(params, law, kappa_c, rtol=rtol))
    elif ok:
        result = _replace(result, classification="adding-sliding")
    return result


def _not_found_message(params, kappa_min, kappa_max, m_min, m_max, closed) -> str:
    """What a search without a root did: its range and the margins at its ends; a physical reading
    only where the equations prove it (no target springs: the margin is 1 at every kappa)."""
    limit = " (the largest kappa of the inputs)" if kappa_max == KAPPA_MAX else ""
    text = (f"no root of the first stick's margin up to kappa = {kappa_max:.4g} N s/m^(1+alpha){limit}, searched "
            f"from {kappa_min:.4g}: margin {m_min:.4g} at the low end, {m_max:.4g} at the high end")
    if params.target != "plate" or (params.Kb == 0 and params.Km == 0):
        return text + (f" (target {params.target} without springs: nothing pulls the stuck pair apart, the margin "
                       "is 1 at every kappa)")
    if closed is not None and closed > kappa_max:
        return text + f"; the closed form (docs/physics.md §5) puts kappa_c at {closed:.5g}, beyond the range"
    return text


#: Offset of the two counts that confirm kappa_c (one permanent stick below, a break above).
SIDE_OFFSET = 1e-3


def _fmt_accuracy(accuracy) -> str:
    return "unknown" if accuracy is None else f"{accuracy:.1e}"


def _kappa_c_accuracy(params, law, log_root, kappa_rtol, rtol):
    """Relative error estimate of kappa_c: the bracket width plus the root's move at a tighter
    integrator tolerance (Brent again, in a narrow bracket around the first root)."""
    from scipy.optimize import brentq
    tight = tighter(rtol)
    spent = 0

    def margin(log_kappa):
        nonlocal spent
        spent += 1
        return first_stick_margin(params.replace(kappa=math.exp(log_kappa)), law, rtol=tight)

    for width in (1e-7, 1e-5, 1e-3):
        lo, hi = log_root - width, log_root + width
        m_lo, m_hi = margin(lo), margin(hi)
        if (m_lo >= 0) != (m_hi >= 0):
            root = brentq(margin, lo, hi, xtol=kappa_rtol / 4, rtol=4 * np.finfo(float).eps, maxiter=200)
            return kappa_rtol + abs(math.expm1(root - log_root)), spent
    return None, spent


def _with_kappa_2(result: CriticalDamping, params, law, rtol) -> CriticalDamping:
    """``result`` with kappa_2, its accuracy and the staircase, and the status they allow."""
    found = locate_kappa_2(params, law, result.kappa_c, kappa_rtol=KAPPA_2_RTOL, rtol=rtol)
    kappa_2, accuracy, staircase, reason = found.kappa_2, found.accuracy, found.staircase, found.reason
    message = result.message + (f"; kappa_2 = {kappa_2:.10g}, estimated relative error {_fmt_accuracy(accuracy)}"
                                if kappa_2 is not None else "")
    unconfirmed = [s for s in staircase if not s["confirmed"]]
    kappa_2_status = "not-found" if kappa_2 is None else ("unconfirmed" if reason else "confirmed")
    staircase_status = None if not staircase else ("unconfirmed" if unconfirmed else "confirmed")
    if reason:
        message = f"{message}; kappa_2 {kappa_2_status}: {reason}"
    if unconfirmed:
        message += (f"; {len(unconfirmed)} of {len(staircase)} staircase counts unconfirmed (first: "
                    f"{unconfirmed[0]['reason']})")
    status = result.status if kappa_2_status == "confirmed" and staircase_status != "unconfirmed" else "unconfirmed"
    return _replace(result, kappa_2=kappa_2, kappa_2_accuracy=accuracy, n_below_kappa_2=found.n_below,
                    n_above_kappa_2=2 if kappa_2 is not None else None, n_staircase=staircase,
                    evaluations=result.evaluations + found.evaluations, status=status, message=message,
                    kappa_2_status=kappa_2_status, staircase_status=staircase_status)


def _replace(result: CriticalDamping, **changes) -> CriticalDamping:
    return CriticalDamping(**{**asdict(result), **changes})


@renamed_tolerances("kappa_rtol")
def transitions(params: Parameters, law: ContactLaw | str, kappa_min: float, kappa_max: float, *,
                kappa_rtol: float = 1e-9, rtol: float = 1e-10, num: int = 96,
                progress: bool = False) -> list[Transition]:
    """Every transition of the long-time count in ``[kappa_min, kappa_max]``, in order.

    ``paper`` (either reading): the adding-sliding at ``kappa_c`` (one stick phase below,
    unboundedly many just above) and the end of the staircase at ``kappa_2`` (``N = 2`` above);
    unilateral laws: every grazing value (contacts before the projectile is out of reach), by
    :func:`grazing_transitions` with ``num`` samples (``progress``: a bar on stderr).

    Parameters
    ----------
    params : Parameters
        The case (its own ``kappa`` is not read).
    law : ContactLaw or str
        A law that reads ``kappa``.
    kappa_min, kappa_max : float
        The range, N s/m^(1+alpha), ``0 < kappa_min < kappa_max <= 1e18``.
    kappa_rtol : float, default 1e-9
        Relative tolerance of each located value, ``1e-14 <= kappa_rtol <= 1e-2`` (``rtol`` up to
        0.2.0).
    rtol : float, default 1e-10
        The integrator's tolerance of every run, within :data:`~phaseimpact.integrate.RTOL_RANGE`
        (``integrator_rtol`` up to 0.2.0; ``rtol=`` alone is refused for one release).
    num : int, default 96
        Samples of a grazing search (unilateral laws; see :func:`grazing_transitions`).
    progress : bool, default False
        Draw a progress bar on stderr (grazing search).

    Returns
    -------
    list of Transition
        In increasing ``kappa``. ``paper``: ``adding-sliding`` (``count_above`` None) and, if
        ``kappa_2 <= kappa_max``, ``staircase-end`` (``count_below`` None when not confirmed).

    Raises
    ------
    TypeError
        If ``params`` is not :class:`~phaseimpact.Parameters`.
    ValueError
        For a law that does not read ``kappa`` or any argument out of range.
    RunFailed
        When a run of the search fails numerically, naming the kappa.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import transitions
    >>> for t in transitions(seed_parameters(v=1.0), "paper", 1e9, 1e14):
    ...     print(t.kind, f"{t.kappa:.6g}", t.count_below, t.count_above)
    adding-sliding 1.49942e+12 1 None
    staircase-end 1.4998e+12 4 2
    """
    check_params(params)
    law = as_law(law)
    if not law.reads("kappa"):
        raise ValueError(f"law {law.label()!r} does not read kappa (its damping comes from "
                         f"{law.damping_source or 'nowhere: it is undamped'}): no transition in kappa; allowed: a law "
                         "that reads kappa (paper, hunt-crossley) without restitution")
    kappa_min, kappa_max = check_kappa_range(kappa_min, kappa_max)
    if not law.is_filippov:
        return grazing_transitions(params, law, kappa_min, kappa_max, num=num, kappa_rtol=kappa_rtol,
                                   rtol=rtol, progress=progress)
    critical = critical_damping(params, law, kappa_min=kappa_min, kappa_max=kappa_max, kappa_rtol=kappa_rtol,
                                rtol=rtol, with_kappa_2=True)
    if critical.status == "failed":
        raise RunFailed(critical.message)
    out = []
    if critical.kappa_c is not None:
        out.append(Transition("adding-sliding", critical.kappa_c, 1, None))
    if critical.kappa_2 is not None and critical.kappa_2 <= kappa_max:
        out.append(Transition("staircase-end", critical.kappa_2, critical.n_below_kappa_2, 2))
    return out
