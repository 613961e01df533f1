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
"""

from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import asdict, dataclass, field

import numpy as np

from ..integrate import scales, simulate
from ..integrate.api import check_rtol
from ..integrate.events import EVENT_KINDS
from ..model.laws import REGISTRY, ContactLaw, as_law
from ..parameters import KAPPA_MAX, Parameters, is_number
from ._renamed import renamed_tolerances
from .confirm import confirmed_count, stick_sequence_violation, tighter

__all__ = [
    "closed_form_kappa_c", "first_stick_margin", "critical_damping", "CriticalDamping", "Kappa2", "locate_kappa_2",
    "adding_sliding_exponents", "delta_extremum", "extrema", "grazing_transitions", "transitions",
    "Transition", "check_kappa_range", "check_samples", "RunFailed", "SamplingWarning", "SAMPLES_RANGE",
]

_REVERSAL = EVENT_KINDS.index("reversal")
#: Horizon of an extremum search, in plate periods: every contact of an impact happens within a
#: few periods; an extremum beyond that is not a grazing candidate.
EXTREMA_PERIODS = 50
#: Lower end of the default search range, as a damping number ``a = kappa v / K``: below it the
#: approach phase is undamped to 1e-8 (``delta*`` moves by ``O(a)``), so the margin cannot change
#: sign there. The upper end is the inputs' own limit :data:`~phaseimpact.parameters.KAPPA_MAX`.
A_MIN = 1e-8
#: kappa samples of a grazing search (each is one run).
SAMPLES_RANGE = (8, 10_000)
#: A grazing search samples the extrema of delta on a log grid of kappa: a window between two grazing
#: values narrower than the grid can be missed. Fewer samples per decade than the first are refused,
#: fewer than the second are warned about (the default, 96 over 1e9..1e13, is 24 per decade).
MIN_SAMPLES_PER_DECADE, WARN_SAMPLES_PER_DECADE = 4, 16
#: Extrema of delta followed per run: an overdamped run creeps through thousands inside one contact,
#: and following each of them across kappa would take hours (a warning says when some are left out).
MAX_EXTREMA = 64


class SamplingWarning(UserWarning):
    """A grazing search sampled more coarsely than the transitions it can resolve: some may be missed.

    Issued by :func:`grazing_transitions` for fewer than :data:`WARN_SAMPLES_PER_DECADE` samples
    per decade of kappa, for runs with more than :data:`MAX_EXTREMA` extrema of ``delta``, and
    for two grazing values closer than two samples.

    Examples
    --------
    24 samples over five decades miss a narrow window that 80 resolve:

    >>> import warnings
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation.transition import grazing_transitions
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     coarse = grazing_transitions(seed_parameters(), "hunt-crossley", 1e8, 1e13, num=24)
    >>> [w.category.__name__ for w in caught], len(coarse)
    (['SamplingWarning'], 3)
    >>> len(grazing_transitions(seed_parameters(), "hunt-crossley", 1e8, 1e13, num=80))
    4
    """


def check_params(params) -> Parameters:
    if not isinstance(params, Parameters):
        raise TypeError(f"params = {params!r} has the wrong type ({type(params).__name__}); allowed: Parameters "
                        "(e.g. seed_parameters(), or Case.parameters())")
    return params


def check_kappa_range(kappa_min, kappa_max, names=("kappa_min", "kappa_max")) -> tuple[float, float]:
    """``(kappa_min, kappa_max)`` as floats with ``0 < kappa_min < kappa_max <= KAPPA_MAX``.

    Parameters
    ----------
    kappa_min, kappa_max : float
        Ends of a search range of ``kappa``, N s/m^(1+alpha).
    names : pair of str, default ("kappa_min", "kappa_max")
        How the message names them (the command line's option names).

    Returns
    -------
    tuple of float
        ``(kappa_min, kappa_max)``.

    Raises
    ------
    ValueError
        For an end that is not a finite number in ``(0, KAPPA_MAX]`` (1e18), or ends in the
        wrong order.

    Examples
    --------
    >>> from phaseimpact.continuation.transition import check_kappa_range
    >>> check_kappa_range(1e9, 1e13)
    (1000000000.0, 10000000000000.0)
    >>> check_kappa_range(1e9, 1e8)
    Traceback (most recent call last):
    ...
    ValueError: kappa_min = 1000000000.0, kappa_max = 100000000.0 are out of range; allowed: kappa_min < kappa_max
    """
    for name, value in zip(names, (kappa_min, kappa_max), strict=True):
        if not (is_number(value) and math.isfinite(value) and 0 < value <= KAPPA_MAX):
            raise ValueError(f"{name} = {value!r} is out of range; allowed: 0 < {name} <= {KAPPA_MAX:g} "
                             "(N s/m^(1+alpha))")
    if not kappa_min < kappa_max:
        raise ValueError(f"{names[0]} = {kappa_min!r}, {names[1]} = {kappa_max!r} are out of range; "
                         f"allowed: {names[0]} < {names[1]}")
    return float(kappa_min), float(kappa_max)


def check_samples(num, kappa_min: float, kappa_max: float, names=("kappa_min", "kappa_max", "num")) -> int:
    """The sample count of a grazing search over ``[kappa_min, kappa_max]``: an integer in
    :data:`SAMPLES_RANGE`, at least :data:`MIN_SAMPLES_PER_DECADE` per decade of kappa.

    Parameters
    ----------
    num : int
        Samples of the log grid of kappa (8 to 10000).
    kappa_min, kappa_max : float
        The search range, N s/m^(1+alpha) (checked by :func:`check_kappa_range`).
    names : triple of str, default ("kappa_min", "kappa_max", "num")
        How the message names the three.

    Returns
    -------
    int
        ``num``.

    Raises
    ------
    ValueError
        For ``num`` not an integer in :data:`SAMPLES_RANGE`, or too few per decade (the message
        gives the count or the span that would do).

    Examples
    --------
    >>> from phaseimpact.continuation.transition import check_samples
    >>> check_samples(96, 1e9, 1e13)
    96
    >>> check_samples(8, 1e8, 1e13)
    Traceback (most recent call last):
    ...
    ValueError: kappa_min = 1e+08, kappa_max = 1e+13 span 5 decades: 8 samples are 1.6 per decade, ...
    """
    lo, hi = SAMPLES_RANGE
    if not (isinstance(num, numbers.Integral) and not isinstance(num, bool) and lo <= num <= hi):
        raise ValueError(f"{names[2]} = {num!r} is out of range; allowed: an integer {lo} <= {names[2]} <= {hi}")
    decades = math.log10(kappa_max) - math.log10(kappa_min)  # the ratio can overflow
    if num < MIN_SAMPLES_PER_DECADE * decades:
        raise ValueError(f"{names[0]} = {kappa_min:g}, {names[1]} = {kappa_max:g} span {decades:.3g} decades: "
                         f"{num} samples are {num / decades:.2g} per decade, too few to find the grazing values; "
                         f"allowed: at least {MIN_SAMPLES_PER_DECADE} per decade, i.e. a span of at most "
                         f"{num / MIN_SAMPLES_PER_DECADE:.3g} decades with {names[2]} = {num}, or "
                         f"{names[2]} >= {math.ceil(MIN_SAMPLES_PER_DECADE * decades)} (at most {hi})")
    return int(num)


def _default_range(params: Parameters) -> tuple[float, float]:
    """The default search range: from the damping number :data:`A_MIN` up to ``KAPPA_MAX``."""
    return min(A_MIN * params.K / params.v, KAPPA_MAX / 10), KAPPA_MAX


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


class RunFailed(RuntimeError):
    """A run needed by a search ended in a numerical failure (its status and message).

    A search never reads a failed run as a value: :func:`first_stick_margin`,
    :func:`delta_extremum`, :func:`grazing_transitions`, :func:`transitions` and
    :func:`~phaseimpact.continuation.critical_curve` raise it, naming the run's ``kappa``;
    :func:`critical_damping` reports it as status ``failed`` instead.

    Examples
    --------
    >>> from phaseimpact.continuation.transition import RunFailed
    >>> try:
    ...     raise RunFailed("kappa = 1e+12: step-size-collapse: ...")
    ... except RuntimeError as error:
    ...     print(type(error).__name__, error)
    RunFailed kappa = 1e+12: step-size-collapse: ...
    """


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
    trajectory = simulate(params, law, None, rtol=rtol, stop_on="stick")
    if not trajectory.ok:
        raise RunFailed(f"kappa = {params.kappa:.6g}: {trajectory.status}: {trajectory.message}")
    margin = trajectory.first_stick_margin
    return -math.inf if margin is None else margin


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


def check_rtol_of_kappa(value) -> float:
    """``kappa_rtol`` as a float, or ValueError naming it and its range, 1e-14 to 1e-2."""
    if not (is_number(value) and 1e-14 <= value <= 1e-2):
        raise ValueError(f"kappa_rtol = {value!r} is out of range; allowed: 1e-14 <= kappa_rtol <= 1e-2")
    return float(value)


def default_kappa_range(params: Parameters, kappa_min=None, kappa_max=None,
                        names=("kappa_min", "kappa_max")) -> tuple[float, float]:
    """The search range of :func:`critical_damping`: the ends given, the others the defaults (the
    damping number :data:`A_MIN` and ``KAPPA_MAX``; a default end on the wrong side of a given one
    is named as a default)."""
    lo_default, hi_default = _default_range(params)
    lo = lo_default if kappa_min is None else kappa_min
    hi = hi_default if kappa_max is None else kappa_max
    for given, default, name, other in ((kappa_max, lo_default, names[0], names[1]),
                                        (kappa_min, hi_default, names[1], names[0])):
        if (kappa_min is None) != (kappa_max is None) and given is not None and is_number(given) and (
                (name == names[0] and not default < given) or (name == names[1] and not given < default)):
            origin = f"damping number kappa v/K = {A_MIN:g}" if name == names[0] else "the largest kappa"
            raise ValueError(f"{other} = {given!r} is out of range with the default {name} = {default:.4g} "
                             f"({origin}); allowed: "
                             f"{other} {'>' if name == names[0] else '<'} {default:.4g}, or {name} given too")
    return check_kappa_range(lo, hi, names)


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


#: Doublings of kappa_2's bracket, at most, until the tighter tolerance confirms both its ends.
WIDENINGS = 12
#: Offset of the two counts that confirm kappa_c (one permanent stick below, a break above).
SIDE_OFFSET = 1e-3
#: Relative width of kappa_2's final bracket, by default and wherever kappa_2 rides on kappa_c.
KAPPA_2_RTOL = 1e-10


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


@dataclass(frozen=True)
class Kappa2:
    """What :func:`locate_kappa_2` found.

    Attributes
    ----------
    kappa_2 : float or None
        Smallest ``kappa`` from which the run makes exactly 2 stick phases, N s/m^(1+alpha); None
        when no bracket was found.
    accuracy : float or None
        Relative width of the final bracket, when both its ends are confirmed.
    n_below : int or None
        The confirmed count at the bracket's lower end (just below ``kappa_2``).
    staircase : list of dict
        ``{"kappa", "relative", "n_stick", "t_run", "cut", "confirmed", "reason"}`` in increasing
        ``kappa`` (as :attr:`CriticalDamping.n_staircase`).
    evaluations : int
        Runs made.
    reason : str
        Why the bracket is not confirmed ("" when it is).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import critical_damping, locate_kappa_2
    >>> p = seed_parameters(v=1.0)
    >>> k2 = locate_kappa_2(p, "paper", critical_damping(p, "paper").kappa_c, samples=0)
    >>> print(f"{k2.kappa_2:.6g}", k2.n_below, k2.staircase, repr(k2.reason))
    1.4998e+12 4 [] ''
    """

    kappa_2: float | None
    accuracy: float | None
    n_below: int | None
    staircase: list
    evaluations: int
    reason: str


@renamed_tolerances("kappa_rtol")
def locate_kappa_2(params: Parameters, law: ContactLaw | str, kappa_c: float, *, kappa_rtol: float = KAPPA_2_RTOL,
                   rtol: float = 1e-10, samples: int = 24):
    """``kappa_2``: the smallest ``kappa`` from which ``N = 2``, by bisection on ``N`` in
    ``log(kappa/kappa_c - 1)`` to a bracket of relative width ``kappa_rtol``, whose ends are then
    confirmed (:func:`.confirm.confirmed_count`); and the staircase of ``N`` sampled from
    ``1.5 (kappa_2/kappa_c - 1)`` down to ``min(1e-5, (kappa_2/kappa_c - 1)/10)``, each count
    confirmed, stopping at the first run the horizon cuts (closer to ``kappa_c`` the escape only
    takes longer).

    Parameters
    ----------
    params : Parameters
        The case (its own ``kappa`` is not read).
    law : ContactLaw or str
        ``paper`` or another Filippov law.
    kappa_c : float
        The critical damping (:func:`critical_damping`), N s/m^(1+alpha).
    kappa_rtol : float, default 1e-10
        Relative width of the final bracket of ``kappa_2`` (not checked here; ``rtol`` up to 0.2.0).
    rtol : float, default 1e-10
        The integrator's tolerance of every run, within :data:`~phaseimpact.integrate.RTOL_RANGE`
        (``integrator_rtol`` up to 0.2.0).
    samples : int, default 24
        Points of the staircase (0: none).

    Returns
    -------
    Kappa2
        ``kappa_2`` None with a ``reason`` when no ``kappa`` up to ``kappa_c (1 + 1e3)`` gives
        ``N = 2``, or ``N = 2`` holds down to ``kappa_c (1 + 1e-12)``.

    Raises
    ------
    ValueError
        For an argument :func:`~phaseimpact.simulate` refuses.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import critical_damping, locate_kappa_2
    >>> p = seed_parameters(v=1.0)
    >>> k2 = locate_kappa_2(p, "paper", critical_damping(p, "paper").kappa_c, samples=3)
    >>> print(f"kappa_2 = {k2.kappa_2:.6g} N s/m^2.5, {k2.n_below} stick phases just below")
    kappa_2 = 1.4998e+12 N s/m^2.5, 4 stick phases just below
    >>> [step["n_stick"] for step in k2.staircase]
    [3358, 126, 2]
    """
    law = as_law(law)
    evaluations = 0

    def count(eps):
        nonlocal evaluations
        evaluations += 1
        run = simulate(params.replace(kappa=kappa_c * (1 + eps)), law, None, rtol=rtol)
        violation = stick_sequence_violation(run, rtol) if run.status == "success" else run.message
        return run.n_stick, violation

    def confirmed(eps):
        nonlocal evaluations
        evaluations += 2
        return confirmed_count(params.replace(kappa=kappa_c * (1 + eps)), law, rtol)

    eps_hi = 1e-3
    while count(eps_hi)[0] != 2:
        eps_hi *= 2
        if eps_hi > 1e3:
            return Kappa2(None, None, None, [], evaluations, "no kappa up to kappa_c (1 + 1e3) gives N = 2")
    eps_lo = eps_hi / 2
    while count(eps_lo)[0] == 2:
        eps_hi, eps_lo = eps_lo, eps_lo / 2
        if eps_lo < 1e-12:
            return Kappa2(None, None, None, [], evaluations, "N = 2 down to kappa_c (1 + 1e-12)")
    while (eps_hi - eps_lo) / (1 + eps_hi) > kappa_rtol:
        mid = math.sqrt(eps_lo * eps_hi)
        if mid in (eps_lo, eps_hi):
            break
        if count(mid)[0] == 2:
            eps_hi = mid
        else:
            eps_lo = mid
    # the ends confirmed; an end the tighter tolerance moves across kappa_2 lies within the
    # integrator's uncertainty of it: the bracket widens, in doubling steps, until both ends hold
    def holds(count, two):
        if two:
            return count.confirmed and not count.cut and count.n_stick == 2
        # a lower bound above 2 (a run cut by the horizon) proves N != 2 as well as a count does
        return count.n_stick_tight is not None and min(count.n_stick, count.n_stick_tight) > 2

    def widens(count):  # a count the tolerance decides, or N on the wrong side: not a broken run
        return not count.cut and (count.confirmed or count.disagree)

    step = eps_hi - eps_lo
    upper = confirmed(eps_hi)
    for _ in range(WIDENINGS):
        if holds(upper, True) or not widens(upper):
            break
        eps_hi, step = eps_hi + step, 2 * step
        upper = confirmed(eps_hi)
    step = eps_hi - eps_lo
    lower = confirmed(eps_lo)
    for _ in range(WIDENINGS):
        if holds(lower, False) or not widens(lower) or eps_lo <= step:
            break
        eps_lo, step = eps_lo - step, 2 * step
        lower = confirmed(eps_lo)
    kappa_2 = kappa_c * (1 + eps_hi)
    reason = ""
    if not holds(upper, True):
        reason = f"at its upper end {upper.reason or ('cut by the horizon' if upper.cut else f'N = {upper.n_stick}')}"
    elif not holds(lower, False):
        reason = f"at its lower end {lower.reason or 'N = 2'}"
    accuracy = None if reason else (eps_hi - eps_lo) / (1 + eps_hi)
    staircase = []
    for eps in np.geomspace(eps_hi * 1.5, min(1e-5, eps_hi / 10), samples):
        n = confirmed(float(eps))
        staircase.append({"kappa": kappa_c * (1 + float(eps)), "relative": float(eps),
                          "n_stick": n.n_stick if n.confirmed else None, "t_run": n.t_run, "cut": n.cut,
                          "confirmed": n.confirmed, "reason": n.reason})
        if n.cut:
            break
    n_below = lower.n_stick if lower.confirmed and not lower.cut else None
    return Kappa2(kappa_2, accuracy, n_below, staircase[::-1], evaluations, reason)


@renamed_tolerances(None)
def adding_sliding_exponents(params: Parameters, law: ContactLaw | str, kappa_c: float, *,
                             eps=(1e-7, 3e-7, 1e-6, 3e-6, 1e-5), rtol: float = 1e-12) -> dict:
    """Local exponents of the adding-sliding at ``kappa_c``: the first slip's largest speed
    ``~ eps^(3/2)`` and the offset between the first two stick depths ``~ eps^2``
    (``eps = kappa/kappa_c - 1``), fitted on log-log over ``eps``.

    Parameters
    ----------
    params : Parameters
        The case (its own ``kappa`` is not read).
    law : ContactLaw or str
        ``paper`` or another Filippov law.
    kappa_c : float
        The critical damping (:func:`critical_damping`), N s/m^(1+alpha).
    eps : sequence of float, default (1e-7, 3e-7, 1e-6, 3e-6, 1e-5)
        Relative offsets above ``kappa_c`` (> 0).
    rtol : float, default 1e-12
        The integrator's tolerance of the runs, within :data:`~phaseimpact.integrate.RTOL_RANGE`
        (``integrator_rtol`` up to 0.2.0).

    Returns
    -------
    dict
        ``eps``; ``slip_speed`` (m/s) and ``stick_offset`` (m) per ``eps`` (NaN where the run made
        fewer than two stick phases); ``slip_speed_exponent`` and ``stick_offset_exponent`` (the
        fitted slopes, None with fewer than two usable points) with their ``..._expected`` (1.5,
        2.0); ``fit_range``.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import adding_sliding_exponents, critical_damping
    >>> p = seed_parameters(v=1.0)
    >>> e = adding_sliding_exponents(p, "paper", critical_damping(p, "paper").kappa_c)
    >>> print(f"{e['slip_speed_exponent']:.1f} {e['stick_offset_exponent']:.1f}")
    1.5 2.0
    """
    law = as_law(law)
    speeds, offsets = [], []
    for e in eps:
        p = params.replace(kappa=kappa_c * (1 + e))
        first = simulate(p, law, None, rtol=rtol, stop_on=("stick", 2))
        sticks = first.events_of("stick")
        slips = first.events_of("slip")
        if len(sticks) < 2 or not slips:
            speeds.append(math.nan)
            offsets.append(math.nan)
            continue
        t0, t1 = slips[0].t, next(ev.t for ev in first.events if ev.t > slips[0].t and ev.kind in ("stick", "reversal"))
        grid = np.linspace(t0, t1, 401)[1:-1]
        fine = simulate(p, law, t1, rtol=rtol, save=grid)
        speeds.append(float(np.max(np.abs(fine.deltadot))))
        offsets.append(abs(sticks[1].delta - sticks[0].delta))
    eps = np.asarray(eps)
    out = {"eps": eps.tolist(), "slip_speed": speeds, "stick_offset": offsets}
    for name, values, expected in (("slip_speed", speeds, 1.5), ("stick_offset", offsets, 2.0)):
        values = np.asarray(values)
        ok = np.isfinite(values) & (values > 0)
        slope = float(np.polyfit(np.log(eps[ok]), np.log(values[ok]), 1)[0]) if ok.sum() >= 2 else None
        out[f"{name}_exponent"] = slope
        out[f"{name}_expected"] = expected
    out["fit_range"] = [float(eps.min()), float(eps.max())]
    return out


# ---------------------------------------------------------------------------------------------
# Grazing of unilateral laws
# ---------------------------------------------------------------------------------------------

def delta_extremum(params: Parameters, law: ContactLaw | str, j: int, *, rtol: float = 1e-10) -> float:
    """``delta`` at the ``j``-th extremum (``deltadot = 0``) of the trajectory, m; ``-inf`` if the
    outcome settles first.

    The contact force of a unilateral law is ``~ delta^alpha`` near ``delta = 0`` (``C^1`` for
    ``alpha > 1``), so each extremum is a smooth function of ``kappa`` across zero: a maximum
    crossing zero from below is a new contact just touching, a minimum crossing zero from above a
    flight phase just vanishing. Its roots are the grazing values (docs/physics.md §5).

    Parameters
    ----------
    params : Parameters
        The case, with its ``kappa`` (N s/m^(1+alpha)).
    law : ContactLaw or str
        A unilateral law.
    j : int
        Which extremum, from 1 (the first is the first contact's deepest indentation).
    rtol : float, default 1e-10
        Integrator tolerance, within :data:`~phaseimpact.integrate.RTOL_RANGE`.

    Returns
    -------
    float
        ``delta`` (m) at the extremum; ``-inf`` when the run (50 of the case's slowest periods)
        ends first.

    Raises
    ------
    RunFailed
        If the run fails numerically.
    ValueError
        For an argument :func:`~phaseimpact.simulate` refuses (``j`` < 1 among them).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import delta_extremum
    >>> p = seed_parameters(v=1.0, kappa=1e9)
    >>> print(f"{delta_extremum(p, 'hunt-crossley', 1):.4g} {delta_extremum(p, 'hunt-crossley', 2):.4g}")
    3.629e-05 -0.0001097
    """
    # no stop when out of reach: the extrema go on (below zero), so each stays defined across
    # the kappa where the projectile stops getting out of reach
    trajectory = simulate(params, law, _extrema_horizon(params), rtol=rtol, stop_on=("reversal", j),
                          stop_when_settled=False)
    _check_ok(trajectory)
    if trajectory.stop_reason != "asked":
        return -math.inf
    y = trajectory.final_state
    return float(y[0] - y[1])


def _check_ok(trajectory):
    """The trajectory, or :class:`RunFailed` naming its kappa: a search must not read a failed run."""
    if not trajectory.ok:
        raise RunFailed(f"kappa = {trajectory.params.kappa:.6g}: {trajectory.status}: {trajectory.message}")
    return trajectory


def _extrema_horizon(params: Parameters) -> float:
    """Horizon of an extremum search: a few tens of the case's slowest periods."""
    s = scales(params)
    return EXTREMA_PERIODS * (s.plate_period if math.isfinite(s.plate_period) else s.contact_time)


def extrema(params: Parameters, law: ContactLaw | str, *, rtol: float = 1e-10) -> np.ndarray:
    """``delta`` at every extremum of the trajectory until its outcome settles, and the next two
    after the projectile is out of reach (so that a grazing return is seen from both sides), m.

    Parameters
    ----------
    params : Parameters
        The case, with its ``kappa`` (N s/m^(1+alpha)).
    law : ContactLaw or str
        A unilateral law.
    rtol : float, default 1e-10
        Integrator tolerance, within :data:`~phaseimpact.integrate.RTOL_RANGE`.

    Returns
    -------
    ndarray of float
        ``delta`` at each extremum in time order, m (positive: in contact).

    Raises
    ------
    RunFailed
        If a run fails numerically.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation.transition import extrema
    >>> [f"{x:.3g}" for x in extrema(seed_parameters(v=1.0, kappa=1e9), "hunt-crossley")]
    ['3.63e-05', '-0.00011', '3.12e-05']
    """
    trajectory = _check_ok(simulate(params, law, None, rtol=rtol))
    y = trajectory.event_y[trajectory.event_kind == _REVERSAL]
    values = list(y[:, 0] - y[:, 1])
    if trajectory.stop_reason == "settled" and trajectory.final_mode != 0:
        after = _check_ok(simulate(params, law, _extrema_horizon(params), rtol=rtol,
                                   initial=trajectory.final_state[:4], stop_when_settled=False,
                                   stop_on=("reversal", 2)))
        y = after.event_y[after.event_kind == _REVERSAL]
        values += list(y[:, 0] - y[:, 1])
    return np.asarray(values)


def contact_count(params: Parameters, law: ContactLaw | str, *, rtol: float = 1e-10) -> int:
    return simulate(params, law, None, rtol=rtol).n_contacts


@dataclass(frozen=True)
class Transition:
    """A change of the long-time count at ``kappa``: stick phases (``paper``) or contacts.

    Attributes
    ----------
    kind : {"adding-sliding", "staircase-end", "grazing"}
        ``adding-sliding`` at ``kappa_c`` and ``staircase-end`` at ``kappa_2`` (``paper``);
        ``grazing`` for a unilateral law.
    kappa : float
        Where, N s/m^(1+alpha).
    count_below, count_above : int or None
        The count just below and just above (None: not confirmed, or unbounded above
        ``kappa_c``).
    extremum : int or None
        Grazing: which extremum of ``delta`` touches zero.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import transitions
    >>> first = transitions(seed_parameters(), "hunt-crossley", 1e8, 1e13, num=80)[0]
    >>> print(first.kind, f"{first.kappa:.4g}", first.count_below, first.count_above, first.extremum)
    grazing 3.577e+10 2 3 5
    """

    kind: str
    kappa: float
    count_below: int | None
    count_above: int | None
    extremum: int | None = None  # grazing: which extremum of delta touches zero

    def as_dict(self) -> dict:
        """The fields as a plain dict (for JSON).

        Returns
        -------
        dict
            ``{"kind", "kappa", "count_below", "count_above", "extremum"}``.

        Examples
        --------
        >>> from phaseimpact.continuation import Transition
        >>> Transition("adding-sliding", 1.5e12, 1, None).as_dict()
        {'kind': 'adding-sliding', 'kappa': 1500000000000.0, 'count_below': 1, 'count_above': None, 'extremum': None}
        """
        return asdict(self)


@renamed_tolerances("kappa_rtol")
def grazing_transitions(params: Parameters, law: ContactLaw | str, kappa_min: float, kappa_max: float, *,
                        num: int = 96, kappa_rtol: float = 1e-9, rtol: float = 1e-10,
                        progress: bool = False) -> list[Transition]:
    """Every grazing value of a unilateral law in ``[kappa_min, kappa_max]``, in order.

    The extrema of ``delta`` are sampled on a log grid of ``num`` values of ``kappa`` (at least
    :data:`MIN_SAMPLES_PER_DECADE` per decade); wherever the ``j``-th changes sign between
    neighbours, or comes close to zero at a local extreme in ``kappa`` without crossing on the grid
    (a window narrower than the grid), its root is located by Brent's method to ``kappa_rtol``
    (relative): :func:`delta_extremum` is the smooth defining function. A :class:`SamplingWarning`
    says when the grid is coarser than what it can resolve; :class:`RunFailed` (naming the kappa)
    when a run fails or the defining function does not bracket a root the samples showed.

    Parameters
    ----------
    params : Parameters
        The case (its own ``kappa`` is not read).
    law : ContactLaw or str
        A unilateral law (``abrate`` does not read ``kappa``: every sample is the same; the
        Hunt-Crossley family, or ``paper`` with ``contact="unilateral"``).
    kappa_min, kappa_max : float
        The search range, N s/m^(1+alpha), ``0 < kappa_min < kappa_max <= 1e18``.
    num : int, default 96
        Samples of the log grid of kappa: 8 to 10000, at least 4 per decade (16 per decade or
        more give no warning).
    kappa_rtol : float, default 1e-9
        Relative tolerance of each grazing value, ``1e-14 <= kappa_rtol <= 1e-2`` (``rtol`` up to
        0.2.0).
    rtol : float, default 1e-10
        The integrator's tolerance of every run, within :data:`~phaseimpact.integrate.RTOL_RANGE`
        (``integrator_rtol`` up to 0.2.0).
    progress : bool, default False
        Draw a progress bar on stderr while sampling.

    Returns
    -------
    list of Transition
        In increasing ``kappa``, each with the contact counts just below and above and the
        extremum that grazes.

    Raises
    ------
    TypeError
        If ``params`` is not :class:`~phaseimpact.Parameters`.
    ValueError
        For ``paper`` in its printed reading (no flight phase), or the range, ``num``,
        ``kappa_rtol`` or ``rtol`` out of range.
    RunFailed
        When a run fails numerically, or a root the samples showed cannot be bracketed.

    Warns
    -----
    SamplingWarning
        When the grid is coarser than the transitions it can resolve.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import grazing_transitions
    >>> for t in grazing_transitions(seed_parameters(v=1.0), "hunt-crossley", 1e8, 1e13, num=80):
    ...     print(f"{t.kappa:.4g}: {t.count_below} -> {t.count_above} contacts")
    3.577e+10: 2 -> 3 contacts
    4.478e+10: 3 -> 2 contacts
    9.125e+10: 2 -> 1 contacts
    5.955e+12: 1 -> 2 contacts
    """
    from scipy.optimize import minimize_scalar  # imported where used: 0.5 s at start-up
    from tqdm.auto import tqdm

    check_params(params)
    law = as_law(law)
    if law.is_filippov and law.contact == "printed":
        raise ValueError("grazing needs a unilateral law (abrate, the Hunt-Crossley family, or paper with "
                         "contact='unilateral')")
    kappa_min, kappa_max = check_kappa_range(kappa_min, kappa_max)
    num = check_samples(num, kappa_min, kappa_max)
    check_rtol_of_kappa(kappa_rtol)
    rtol = check_rtol(rtol)
    density = num / (math.log10(kappa_max) - math.log10(kappa_min))
    if density < WARN_SAMPLES_PER_DECADE:
        warnings.warn(f"{num} samples over kappa {kappa_min:g}..{kappa_max:g} are {density:.2g} per decade: a window "
                      f"between two grazing values narrower than a factor {10 ** (1 / density):.3g} in kappa can be "
                      f"missed ({WARN_SAMPLES_PER_DECADE} per decade resolve a factor "
                      f"{10 ** (1 / WARN_SAMPLES_PER_DECADE):.3g})", SamplingWarning, stacklevel=2)
    logk = np.linspace(math.log(kappa_min), math.log(kappa_max), num)
    samples = [extrema(params.replace(kappa=math.exp(x)), law, rtol=rtol)
               for x in tqdm(logk, desc=f"grazing {law.name}", unit="kappa", disable=not progress)]
    deepest = max(len(e) for e in samples)
    if deepest > MAX_EXTREMA:
        where = math.exp(logk[int(np.argmax([len(e) for e in samples]))])
        warnings.warn(f"runs make up to {deepest} extrema of delta (at kappa = {where:.4g}): the first {MAX_EXTREMA} "
                      "are followed, a grazing of a later one is missed", SamplingWarning, stacklevel=2)
    depth = min(deepest, MAX_EXTREMA)
    table = np.full((num, depth), -np.inf)
    for i, e in enumerate(samples):
        table[i, :min(len(e), depth)] = e[:depth]
    scale = params.hertz_indentation

    def g(x, j):
        return delta_extremum(params.replace(kappa=math.exp(x)), law, j, rtol=rtol)

    def root(lo, hi, j):
        return _grazing_root(g, lo, hi, j, kappa_rtol)

    found = []
    for j in range(1, depth + 1):
        column = table[:, j - 1]
        for i in range(num - 1):
            a, b = column[i], column[i + 1]
            if (a > 0) == (b > 0) or not (np.isfinite(a) or np.isfinite(b)):
                continue
            lo, hi, g_lo, g_hi = logk[i], logk[i + 1], a, b
            for _ in range(40):  # an extremum born (or gone) in between: move to where both exist
                if np.isfinite(g_lo) and np.isfinite(g_hi):
                    break
                mid = 0.5 * (lo + hi)
                g_mid = g(mid, j)
                if np.isfinite(g_mid) == np.isfinite(g_lo) and (g_mid > 0) == (g_lo > 0):
                    lo, g_lo = mid, g_mid
                else:
                    hi, g_hi = mid, g_mid
            if np.isfinite(g_lo) and np.isfinite(g_hi) and (g_lo > 0) != (g_hi > 0):
                found.append((root(lo, hi, j), j))
        # windows narrower than the grid: an extreme in kappa of this extremum close to zero
        for i in range(1, num - 1):
            a, m, b = column[i - 1], column[i], column[i + 1]
            if not (np.isfinite(a) and np.isfinite(m) and np.isfinite(b)) or abs(m) > 0.05 * scale:
                continue
            sign = 1.0 if m < 0 else -1.0  # look for a maximum of a negative run, a minimum of a positive one
            if not (sign * m >= sign * a and sign * m >= sign * b) or (a > 0) != (m > 0) or (b > 0) != (m > 0):
                continue
            best = minimize_scalar(lambda x, j=j, s=sign: -s * g(x, j), bounds=(logk[i - 1], logk[i + 1]),
                                   method="bounded", options={"xatol": 1e-12})
            if (-sign * best.fun > 0) != (m > 0):
                for lo, hi in ((logk[i - 1], best.x), (best.x, logk[i + 1])):
                    found.append((root(lo, hi, j), j))
    found.sort()
    step = logk[1] - logk[0]
    close = [(a, b) for (a, _), (b, _) in zip(found, found[1:], strict=False) if 10 * kappa_rtol * b < b - a
             and math.log(b / a) < step]
    if close:
        a, b = close[0]
        warnings.warn(f"grazing values at kappa = {a:.4g} and {b:.4g} lie closer than two samples: a window that "
                      "narrow between two samples can be missed elsewhere; more samples resolve it", SamplingWarning,
                      stacklevel=2)
    transitions = []
    for kappa, j in found:
        if transitions and abs(kappa - transitions[-1].kappa) <= 10 * kappa_rtol * kappa:
            continue  # the same grazing seen by two extrema (a pair created or removed at it)
        below = contact_count(params.replace(kappa=kappa * (1 - 1e-6)), law, rtol=rtol)
        above = contact_count(params.replace(kappa=kappa * (1 + 1e-6)), law, rtol=rtol)
        transitions.append(Transition("grazing", kappa, below, above, j))
    return transitions


def _grazing_root(g, lo: float, hi: float, j: int, kappa_rtol: float) -> float:
    """The root of ``g(., j)`` in ``[lo, hi]`` (log kappa), ``kappa`` to ``rtol``; :class:`RunFailed`
    naming the bracket when the defining function does not change sign there."""
    from scipy.optimize import brentq  # imported where used: 0.5 s at start-up

    g_lo, g_hi = g(lo, j), g(hi, j)
    if not (np.isfinite(g_lo) and np.isfinite(g_hi)) or (g_lo > 0) == (g_hi > 0):
        raise RunFailed(f"kappa = {math.exp(lo):.6g} to {math.exp(hi):.6g}: extremum {j} of delta changes sign between "
                        f"the samples but not in single runs (delta = {g_lo:.3g} and {g_hi:.3g} m at the ends): no "
                        "grazing can be located there")
    return math.exp(brentq(g, lo, hi, args=(j,), xtol=kappa_rtol / 4, rtol=4 * np.finfo(float).eps))


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
