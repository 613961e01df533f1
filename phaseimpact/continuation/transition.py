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
from dataclasses import asdict, dataclass, field

import numpy as np

from ..integrate import scales, simulate
from ..integrate.events import EVENT_KINDS
from ..model.laws import ContactLaw, as_law
from ..parameters import Parameters

__all__ = [
    "closed_form_kappa_c", "first_stick_margin", "critical_damping", "CriticalDamping", "locate_kappa_2",
    "stick_count", "adding_sliding_exponents", "delta_extremum", "extrema", "grazing_transitions", "transitions",
    "Transition", "check_kappa_range", "RunFailed",
]

_REVERSAL = EVENT_KINDS.index("reversal")
#: Horizon of an extremum search, in plate periods: every contact of an impact happens within a
#: few periods; an extremum beyond that is not a grazing candidate.
EXTREMA_PERIODS = 50
#: Default search range of the damping number ``a = kappa v / K``.
A_RANGE = (1e-8, 1e8)


def check_kappa_range(kappa_min, kappa_max) -> tuple[float, float]:
    for name, value in (("kappa_min", kappa_min), ("kappa_max", kappa_max)):
        if not (isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)
                and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value!r} is out of range; allowed: a finite number > 0")
    if not kappa_min < kappa_max:
        raise ValueError(f"kappa_min = {kappa_min!r}, kappa_max = {kappa_max!r} are out of range; "
                         "allowed: kappa_min < kappa_max")
    return float(kappa_min), float(kappa_max)


def _default_range(params: Parameters) -> tuple[float, float]:
    scale = params.K / params.v
    return A_RANGE[0] * scale, A_RANGE[1] * scale


def closed_form_kappa_c(params: Parameters) -> float | None:
    """``kappa_c`` of docs/physics.md §5's closed form (two-body Hunt-Crossley approach, momentum
    conserved during the contact, stuck pair on the springs); None without a plate."""
    from scipy.optimize import brentq  # imported where used: 0.5 s at start-up
    if params.target != "plate" or params.Kb <= 0:
        return None
    M = params.M1 + params.M2
    m, K, alpha, v = params.reduced_mass, params.K, params.alpha, params.v
    V = params.M1 * v / M
    E = 0.5 * M * V * V
    X2 = 2 * E / params.Kb if params.Km == 0 else (-params.Kb + math.sqrt(params.Kb**2 + 4 * params.Km * E)) / params.Km
    X = math.sqrt(X2)
    required = params.M1 / M * (params.Kb * X + params.Km * X**3)

    def gap(log_a):
        a = math.exp(log_a)
        # a - ln(1+a) without cancellation for small a
        core = a - math.log1p(a) if a > 1e-4 else a * a * (0.5 - a / 3 + a * a / 4)
        delta = ((alpha + 1) * m * v * v * core / (K * a * a)) ** (1 / (alpha + 1))
        return math.log(K * delta**alpha / required)

    lo, hi = math.log(A_RANGE[0]), math.log(A_RANGE[1])
    if gap(lo) * gap(hi) > 0:
        return None
    return math.exp(brentq(gap, lo, hi, xtol=1e-14, rtol=1e-14)) * K / v


class RunFailed(RuntimeError):
    """A run needed by a search ended in a numerical failure (its status and message)."""


def first_stick_margin(params: Parameters, law: ContactLaw | str = "paper", *, rtol: float = 1e-10) -> float:
    """Margin of the first stick (``>= 0``: it never breaks); -inf if the run never sticks.

    Raises :class:`RunFailed` if the run fails numerically (a search must not take that as a value).
    """
    trajectory = simulate(params, law, None, rtol=rtol, stop_on="stick")
    if not trajectory.ok:
        raise RunFailed(f"kappa = {params.kappa:.6g}: {trajectory.status}: {trajectory.message}")
    margin = trajectory.first_stick_margin
    return -math.inf if margin is None else margin


def stick_count(params: Parameters, law: ContactLaw | str = "paper", *, rtol: float = 1e-10):
    """``(N, T_run, cut)``: stick phases until the outcome settles, escape time, and whether the
    horizon cap cut the run (then N is a lower bound)."""
    trajectory = simulate(params, law, None, rtol=rtol)
    return trajectory.n_stick, trajectory.t_run, trajectory.cut


@dataclass(frozen=True)
class CriticalDamping:
    """The critical damping of ``paper`` at one case (docs/physics.md §5).

    Attributes
    ----------
    kappa_c : float or None
        Root of the first stick's margin, N s/m^(1+alpha); None when not found.
    closed_form : float or None
        docs/physics.md §5's closed-form estimate.
    margins : tuple
        Margin at the search range's ends (or at the final bracket).
    kappa_2 : float or None
        Smallest ``kappa`` from which the trajectory makes exactly 2 stick phases.
    n_staircase : list of dict
        ``{"kappa", "n_stick", "t_run", "cut"}`` sampled between ``kappa_c`` and ``kappa_2``.
    classification : str or None
        ``adding-sliding`` with :attr:`exponents` when measured.
    status : {"success", "not-found", "unconfirmed", "failed"}
        ``failed``: a run of the search failed numerically (the message says which).
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
    kappa_2: float | None = None
    n_staircase: list = field(default_factory=list)
    classification: str | None = None
    exponents: dict | None = None

    def as_dict(self) -> dict:
        return asdict(self)


def critical_damping(params: Parameters, law: ContactLaw | str = "paper", *, kappa_min: float | None = None,
                     kappa_max: float | None = None, rtol: float = 1e-10, integrator_rtol: float = 1e-10,
                     with_kappa_2: bool = False, with_exponents: bool = False) -> CriticalDamping:
    """Locate ``kappa_c``, the root of the first stick's margin, for any case.

    The bracket is seeded by the closed form (docs/physics.md §5) and widened geometrically within
    ``[kappa_min, kappa_max]`` (default: damping numbers ``kappa v / K`` in 1e-8..1e8); Brent's
    method narrows it to ``rtol`` (relative). Counts either side confirm it: one permanent
    stick just below, two or more stick phases just above. No root in the range gives status
    ``not-found``, ``kappa_c`` None and the margins at both ends in the message.
    """
    law = as_law(law)
    if not law.is_filippov:
        raise ValueError(f"law = {law.name!r} is out of range for the critical damping; allowed: paper "
                         "(unilateral laws have grazing transitions: use transitions())")
    if not (isinstance(rtol, (int, float)) and 1e-14 <= rtol <= 1e-2):
        raise ValueError(f"kappa_rtol = {rtol!r} is out of range; allowed: 1e-14 <= kappa_rtol <= 1e-2")
    lo_default, hi_default = _default_range(params)
    kappa_min, kappa_max = check_kappa_range(kappa_min or lo_default, kappa_max or hi_default)
    closed = closed_form_kappa_c(params)
    try:
        return _critical_damping(params, law, kappa_min, kappa_max, rtol, integrator_rtol, with_kappa_2,
                                 with_exponents, closed)
    except RunFailed as error:
        return CriticalDamping(law.name, law.contact, params.v, None, rtol, closed, (kappa_min, kappa_max),
                               (math.nan, math.nan), "failed", f"a run of the search failed: {error}", 0)


def _critical_damping(params, law, kappa_min, kappa_max, rtol, integrator_rtol, with_kappa_2, with_exponents,
                      closed) -> CriticalDamping:
    from scipy.optimize import brentq  # imported where used: 0.5 s at start-up
    evaluations = 0

    def margin(log_kappa):
        nonlocal evaluations
        evaluations += 1
        return first_stick_margin(params.replace(kappa=math.exp(log_kappa)), law, rtol=integrator_rtol)

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
        return CriticalDamping(law.name, law.contact, params.v, None, rtol, closed, (kappa_min, kappa_max),
                               (m_min, m_max), "not-found",
                               f"no root of the first stick's margin for kappa in [{kappa_min:.4g}, {kappa_max:.4g}]"
                               f" N s/m^(1+alpha): margin {m_min:.4g} at the low end, {m_max:.4g} at the high end"
                               + (" (the stick never breaks)" if m_max >= 0 else ""), evaluations)
    root = brentq(margin, min(a, b), max(a, b), xtol=rtol / 4, rtol=4 * np.finfo(float).eps, maxiter=200)
    kappa_c = math.exp(root)
    # confirm with the counts either side (cheap: far enough from kappa_c for a short run)
    below = simulate(params.replace(kappa=kappa_c * (1 - 1e-3)), law, None, rtol=integrator_rtol)
    above = simulate(params.replace(kappa=kappa_c * (1 + 1e-3)), law, None, rtol=integrator_rtol)
    evaluations += 2
    ok = below.outcome == "permanent-stick" and below.n_stick == 1 and above.n_stick >= 2
    message = (f"kappa_c = {kappa_c:.10g} N s/m^(1+alpha) (root of the first stick's margin, relative width "
               f"{rtol:g}); just below: {below.n_stick} stick phase ({below.outcome}), just above: "
               f"{above.n_stick} ({above.outcome})")
    result = CriticalDamping(law.name, law.contact, params.v, kappa_c, rtol, closed, (kappa_lo, kappa_hi),
                             (float(m_a), float(m_b)), "success" if ok else "unconfirmed", message, evaluations)
    if with_kappa_2 and ok:
        kappa_2, staircase, extra = locate_kappa_2(params, law, kappa_c, integrator_rtol=integrator_rtol)
        result = _replace(result, kappa_2=kappa_2, n_staircase=staircase,
                          evaluations=result.evaluations + extra)
    if with_exponents and ok:
        result = _replace(result, classification="adding-sliding",
                          exponents=adding_sliding_exponents(params, law, kappa_c, integrator_rtol=integrator_rtol))
    elif ok:
        result = _replace(result, classification="adding-sliding")
    return result


def _replace(result: CriticalDamping, **changes) -> CriticalDamping:
    return CriticalDamping(**{**asdict(result), **changes})


def locate_kappa_2(params: Parameters, law: ContactLaw | str, kappa_c: float, *, rtol: float = 1e-8,
                   integrator_rtol: float = 1e-10, samples: int = 24):
    """``kappa_2``: the smallest ``kappa`` from which ``N = 2``, by bisection on ``N`` in
    ``log(kappa/kappa_c - 1)``; and the staircase of ``N`` sampled between ``kappa_c`` and it.

    Returns ``(kappa_2 or None, staircase, evaluations)``.
    """
    law = as_law(law)
    evaluations = 0

    def count(eps):
        nonlocal evaluations
        evaluations += 1
        return stick_count(params.replace(kappa=kappa_c * (1 + eps)), law, rtol=integrator_rtol)

    eps_hi = 1e-3
    while count(eps_hi)[0] != 2:
        eps_hi *= 2
        if eps_hi > 1e3:
            return None, [], evaluations
    eps_lo = eps_hi / 2
    while count(eps_lo)[0] == 2:
        eps_hi, eps_lo = eps_lo, eps_lo / 2
        if eps_lo < 1e-12:
            return None, [], evaluations
    while (eps_hi - eps_lo) / (1 + eps_hi) > rtol:
        mid = math.sqrt(eps_lo * eps_hi)
        if mid in (eps_lo, eps_hi):
            break
        if count(mid)[0] == 2:
            eps_hi = mid
        else:
            eps_lo = mid
    kappa_2 = kappa_c * (1 + eps_hi)
    staircase = []
    # from eps = 1e-5 up: closer to kappa_c the escape takes thousands of plate periods (N > 3000)
    for eps in np.geomspace(min(1e-5, eps_hi / 10), eps_hi * 1.5, samples):
        n, t_run, cut = count(float(eps))
        staircase.append({"kappa": kappa_c * (1 + float(eps)), "relative": float(eps), "n_stick": int(n),
                          "t_run": t_run, "cut": bool(cut)})
    return kappa_2, staircase, evaluations


def adding_sliding_exponents(params: Parameters, law: ContactLaw | str, kappa_c: float, *,
                             eps=(1e-7, 3e-7, 1e-6, 3e-6, 1e-5), integrator_rtol: float = 1e-12) -> dict:
    """Local exponents of the adding-sliding at ``kappa_c``: the first slip's largest speed
    ``~ eps^(3/2)`` and the offset between the first two stick depths ``~ eps^2``
    (``eps = kappa/kappa_c - 1``), fitted on log-log over ``eps``."""
    law = as_law(law)
    speeds, offsets = [], []
    for e in eps:
        p = params.replace(kappa=kappa_c * (1 + e))
        first = simulate(p, law, None, rtol=integrator_rtol, stop_on=("stick", 2))
        sticks = first.events_of("stick")
        slips = first.events_of("slip")
        if len(sticks) < 2 or not slips:
            speeds.append(math.nan)
            offsets.append(math.nan)
            continue
        t0, t1 = slips[0].t, next(ev.t for ev in first.events if ev.t > slips[0].t and ev.kind in ("stick", "reversal"))
        grid = np.linspace(t0, t1, 401)[1:-1]
        fine = simulate(p, law, t1, rtol=integrator_rtol, save=grid)
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
    """
    # no stop when out of reach: the extrema go on (below zero), so each stays defined across
    # the kappa where the projectile stops getting out of reach
    trajectory = simulate(params, law, _extrema_horizon(params), rtol=rtol, stop_on=("reversal", j),
                          stop_when_settled=False)
    if trajectory.stop_reason != "asked":
        return -math.inf
    y = trajectory.final_state
    return float(y[0] - y[1])


def _extrema_horizon(params: Parameters) -> float:
    """Horizon of an extremum search: a few tens of the case's slowest periods."""
    s = scales(params)
    return EXTREMA_PERIODS * (s.plate_period if math.isfinite(s.plate_period) else s.contact_time)


def extrema(params: Parameters, law: ContactLaw | str, *, rtol: float = 1e-10) -> np.ndarray:
    """``delta`` at every extremum of the trajectory until its outcome settles, and the next two
    after the projectile is out of reach (so that a grazing return is seen from both sides), m."""
    trajectory = simulate(params, law, None, rtol=rtol)
    y = trajectory.event_y[trajectory.event_kind == _REVERSAL]
    values = list(y[:, 0] - y[:, 1])
    if trajectory.stop_reason == "settled" and trajectory.final_mode != 0:
        after = simulate(params, law, _extrema_horizon(params), rtol=rtol,
                         initial=trajectory.final_state[:4], stop_when_settled=False, stop_on=("reversal", 2))
        y = after.event_y[after.event_kind == _REVERSAL]
        values += list(y[:, 0] - y[:, 1])
    return np.asarray(values)


def contact_count(params: Parameters, law: ContactLaw | str, *, rtol: float = 1e-10) -> int:
    return simulate(params, law, None, rtol=rtol).n_contacts


@dataclass(frozen=True)
class Transition:
    """A change of the long-time count at ``kappa``: stick phases (``paper``) or contacts."""

    kind: str
    kappa: float
    count_below: int | None
    count_above: int | None
    extremum: int | None = None  # grazing: which extremum of delta touches zero

    def as_dict(self) -> dict:
        return asdict(self)


def grazing_transitions(params: Parameters, law: ContactLaw | str, kappa_min: float, kappa_max: float, *,
                        num: int = 96, rtol: float = 1e-9, integrator_rtol: float = 1e-10) -> list[Transition]:
    """Every grazing value of a unilateral law in ``[kappa_min, kappa_max]``, in order.

    The extrema of ``delta`` are sampled on a log grid of ``kappa``; wherever the ``j``-th changes
    sign between neighbours, or comes close to zero at a local extreme in ``kappa`` without
    crossing on the grid (a window narrower than the grid), its root is located by Brent's
    method to ``rtol`` (relative): :func:`delta_extremum` is the smooth defining function.
    """
    from scipy.optimize import brentq, minimize_scalar  # imported where used: 0.5 s at start-up
    law = as_law(law)
    if law.is_filippov and law.contact == "printed":
        raise ValueError("grazing needs a unilateral law (abrate, the Hunt-Crossley family, or paper with "
                         "contact='unilateral')")
    kappa_min, kappa_max = check_kappa_range(kappa_min, kappa_max)
    logk = np.linspace(math.log(kappa_min), math.log(kappa_max), num)
    samples = [extrema(params.replace(kappa=math.exp(x)), law, rtol=integrator_rtol) for x in logk]
    depth = max(len(e) for e in samples)
    table = np.full((num, depth), -np.inf)
    for i, e in enumerate(samples):
        table[i, :len(e)] = e
    scale = params.hertz_indentation
    eps = 4 * np.finfo(float).eps

    def g(x, j):
        return delta_extremum(params.replace(kappa=math.exp(x)), law, j, rtol=integrator_rtol)

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
                found.append((math.exp(brentq(g, lo, hi, args=(j,), xtol=rtol / 4, rtol=eps)), j))
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
                    found.append((math.exp(brentq(g, lo, hi, args=(j,), xtol=rtol / 4, rtol=eps)), j))
    found.sort()
    transitions = []
    for kappa, j in found:
        if transitions and abs(kappa - transitions[-1].kappa) <= 10 * rtol * kappa:
            continue  # the same grazing seen by two extrema (a pair created or removed at it)
        below = contact_count(params.replace(kappa=kappa * (1 - 1e-6)), law, rtol=integrator_rtol)
        above = contact_count(params.replace(kappa=kappa * (1 + 1e-6)), law, rtol=integrator_rtol)
        transitions.append(Transition("grazing", kappa, below, above, j))
    return transitions


def transitions(params: Parameters, law: ContactLaw | str, kappa_min: float, kappa_max: float, *,
                rtol: float = 1e-9, integrator_rtol: float = 1e-10, num: int = 96) -> list[Transition]:
    """Every transition of the long-time count in ``[kappa_min, kappa_max]``, in order.

    ``paper`` (either reading): the adding-sliding at ``kappa_c`` (one stick phase below,
    unboundedly many just above) and the end of the staircase at ``kappa_2`` (``N = 2`` above);
    unilateral laws: every grazing value (contacts before the projectile is out of reach).
    """
    law = as_law(law)
    kappa_min, kappa_max = check_kappa_range(kappa_min, kappa_max)
    if not law.is_filippov:
        return grazing_transitions(params, law, kappa_min, kappa_max, num=num, rtol=rtol,
                                   integrator_rtol=integrator_rtol)
    critical = critical_damping(params, law, kappa_min=kappa_min, kappa_max=kappa_max, rtol=rtol,
                                integrator_rtol=integrator_rtol, with_kappa_2=True)
    out = []
    if critical.kappa_c is not None:
        out.append(Transition("adding-sliding", critical.kappa_c, 1, None))
    if critical.kappa_2 is not None and critical.kappa_2 <= kappa_max:
        n_below = stick_count(params.replace(kappa=critical.kappa_2 * (1 - 1e-7)), law, rtol=integrator_rtol)[0]
        out.append(Transition("staircase-end", critical.kappa_2, int(n_below), 2))
    return out
