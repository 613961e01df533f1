"""Grazing transitions of unilateral laws (docs/physics.md §5): the number of contacts before the
projectile is out of reach changes where a flight phase's largest ``delta`` just reaches zero, located
as the root of that extremum (:func:`delta_extremum`, a smooth function of ``kappa``), not by counting.
:func:`grazing_transitions` samples the extrema on a log grid of ``kappa`` and locates each root.
"""

from __future__ import annotations

import math
import numbers
import warnings

import numpy as np

from ..integrate import scales, simulate
from ..integrate.api import check_rtol, summary_run
from ..integrate.driver import ASKED_STOP, S_N_CONTACTS, S_REASON
from ..integrate.events import EVENT_KINDS
from ..model.laws import ContactLaw, as_law
from ..parameters import Parameters
from ._kappa_search import RunFailed, Transition, check_kappa_range, check_params, check_rtol_of_kappa, checked_summary
from ._renamed import renamed_tolerances

__all__ = ["SamplingWarning", "SAMPLES_RANGE", "check_samples", "delta_extremum", "extrema", "grazing_transitions"]

_REVERSAL = EVENT_KINDS.index("reversal")
#: Horizon of an extremum search, in plate periods: every contact of an impact happens within a
#: few periods; an extremum beyond that is not a grazing candidate.
EXTREMA_PERIODS = 50
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
    t_end, options = extremum_run(params, j)
    return extremum_of(*checked_summary(params, law, t_end, rtol=rtol, **options))


def extremum_run(params: Parameters, j: int) -> tuple[float, dict]:
    """The horizon and options of :func:`delta_extremum`'s run."""
    # no stop when out of reach: the extrema go on (below zero), so each stays defined across
    # the kappa where the projectile stops getting out of reach
    return _extrema_horizon(params), {"stop_on": ("reversal", j), "stop_when_settled": False}


def extremum_of(summary, y) -> float:
    """:func:`delta_extremum` read from its run's summary and final state."""
    return float(y[0] - y[1]) if summary[S_REASON] == ASKED_STOP else -math.inf


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
    return int(summary_run(params, law, None, rtol=rtol)[0][S_N_CONTACTS])


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
    law, kappa_min, kappa_max, num, rtol = _checked(params, law, kappa_min, kappa_max, num, kappa_rtol, rtol)
    logk = np.linspace(math.log(kappa_min), math.log(kappa_max), num)
    table = _extrema_table(params, law, logk, rtol, progress)

    def g(x, j):
        return delta_extremum(params.replace(kappa=math.exp(x)), law, j, rtol=rtol)

    found = []
    for j in range(1, table.shape[1] + 1):
        found += _sign_changes(g, table[:, j - 1], logk, j, kappa_rtol)
        found += _narrow_windows(g, table[:, j - 1], logk, j, kappa_rtol, params.hertz_indentation)
    found.sort()
    _warn_close(found, logk[1] - logk[0], kappa_rtol)
    return _counted(found, params, law, kappa_rtol, rtol)


def _checked(params, law, kappa_min, kappa_max, num, kappa_rtol, rtol):
    """The inputs of :func:`grazing_transitions`, checked before any work: ``(law, kappa_min,
    kappa_max, num, rtol)``; a :class:`SamplingWarning` for fewer than
    :data:`WARN_SAMPLES_PER_DECADE` samples per decade."""
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
                      f"{10 ** (1 / WARN_SAMPLES_PER_DECADE):.3g})", SamplingWarning, stacklevel=3)
    return law, kappa_min, kappa_max, num, rtol


def _counted(found: list[tuple[float, int]], params: Parameters, law: ContactLaw, kappa_rtol: float,
             rtol: float) -> list[Transition]:
    """A :class:`Transition` per grazing value (sorted), with the contact counts just below and above."""
    transitions = []
    for kappa, j in found:
        if transitions and abs(kappa - transitions[-1].kappa) <= 10 * kappa_rtol * kappa:
            continue  # the same grazing seen by two extrema (a pair created or removed at it)
        below = contact_count(params.replace(kappa=kappa * (1 - 1e-6)), law, rtol=rtol)
        above = contact_count(params.replace(kappa=kappa * (1 + 1e-6)), law, rtol=rtol)
        transitions.append(Transition("grazing", kappa, below, above, j))
    return transitions


def _extrema_table(params: Parameters, law: ContactLaw, logk: np.ndarray, rtol: float, progress: bool) -> np.ndarray:
    """``delta`` at the extrema of each sample (rows: ``log kappa``; columns: the first
    :data:`MAX_EXTREMA` extrema, ``-inf`` where a run has fewer), m; a :class:`SamplingWarning` when
    a run has more."""
    from tqdm.auto import tqdm

    samples = [extrema(params.replace(kappa=math.exp(x)), law, rtol=rtol)
               for x in tqdm(logk, desc=f"grazing {law.name}", unit="kappa", disable=not progress)]
    deepest = max(len(e) for e in samples)
    if deepest > MAX_EXTREMA:
        where = math.exp(logk[int(np.argmax([len(e) for e in samples]))])
        warnings.warn(f"runs make up to {deepest} extrema of delta (at kappa = {where:.4g}): the first {MAX_EXTREMA} "
                      "are followed, a grazing of a later one is missed", SamplingWarning, stacklevel=3)
    depth = min(deepest, MAX_EXTREMA)
    table = np.full((len(logk), depth), -np.inf)
    for i, e in enumerate(samples):
        table[i, :min(len(e), depth)] = e[:depth]
    return table


def _sign_changes(g, column: np.ndarray, logk: np.ndarray, j: int, kappa_rtol: float) -> list[tuple[float, int]]:
    """``(kappa, j)`` of each root of extremum ``j`` between neighbouring samples whose signs differ."""
    found = []
    for i in range(len(logk) - 1):
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
            found.append((_grazing_root(g, lo, hi, j, kappa_rtol), j))
    return found


def _narrow_windows(g, column: np.ndarray, logk: np.ndarray, j: int, kappa_rtol: float,
                    scale: float) -> list[tuple[float, int]]:
    """``(kappa, j)`` of the two roots of each window narrower than the grid: an extreme in kappa of
    extremum ``j`` within ``0.05 scale`` (m) of zero that crosses it between two samples."""
    from scipy.optimize import minimize_scalar  # imported where used: 0.5 s at start-up

    found = []
    for i in range(1, len(logk) - 1):
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
                found.append((_grazing_root(g, lo, hi, j, kappa_rtol), j))
    return found


def _warn_close(found: list[tuple[float, int]], step: float, kappa_rtol: float) -> None:
    """A :class:`SamplingWarning` when two grazing values (sorted) lie closer than two samples."""
    close = [(a, b) for (a, _), (b, _) in zip(found, found[1:], strict=False) if 10 * kappa_rtol * b < b - a
             and math.log(b / a) < step]
    if close:
        a, b = close[0]
        warnings.warn(f"grazing values at kappa = {a:.4g} and {b:.4g} lie closer than two samples: a window that "
                      "narrow between two samples can be missed elsewhere; more samples resolve it", SamplingWarning,
                      stacklevel=3)


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
