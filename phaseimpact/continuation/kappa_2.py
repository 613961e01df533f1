"""``kappa_2`` of a Filippov law, where the staircase of stick phases above ``kappa_c`` ends
(``N = 2`` from there on), the staircase itself, and the local exponents of the adding-sliding at
``kappa_c`` (docs/physics.md §5).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..integrate import simulate
from ..model.laws import ContactLaw, as_law
from ..parameters import Parameters
from ._renamed import renamed_tolerances
from .confirm import confirmed_count, stick_sequence_violation

__all__ = ["Kappa2", "locate_kappa_2", "adding_sliding_exponents", "KAPPA_2_RTOL"]

#: Doublings of kappa_2's bracket, at most, until the tighter tolerance confirms both its ends.
WIDENINGS = 12
#: Relative width of kappa_2's final bracket, by default and wherever kappa_2 rides on kappa_c.
KAPPA_2_RTOL = 1e-10


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
    runs = _Runs(params, law, kappa_c, rtol)
    eps_lo, eps_hi, missing = _bisect_kappa_2(runs, kappa_rtol)
    if missing:
        return Kappa2(None, None, None, [], runs.evaluations, missing)
    (eps_lo, lower), (eps_hi, upper) = _confirmed_ends(runs, eps_lo, eps_hi)
    kappa_2 = kappa_c * (1 + eps_hi)
    reason = ""
    if not _holds(upper, True):
        reason = f"at its upper end {upper.reason or ('cut by the horizon' if upper.cut else f'N = {upper.n_stick}')}"
    elif not _holds(lower, False):
        reason = f"at its lower end {lower.reason or 'N = 2'}"
    accuracy = None if reason else (eps_hi - eps_lo) / (1 + eps_hi)
    staircase = _staircase(runs, eps_hi, samples)
    n_below = lower.n_stick if lower.confirmed and not lower.cut else None
    return Kappa2(kappa_2, accuracy, n_below, staircase, runs.evaluations, reason)


class _Runs:
    """The runs of a ``kappa_2`` search at ``kappa = kappa_c (1 + eps)``, counted."""

    def __init__(self, params, law, kappa_c, rtol):
        self.params, self.law, self.kappa_c, self.rtol = params, law, kappa_c, rtol
        self.evaluations = 0

    def count(self, eps):
        """``(N, violation)`` of one run (the violation: why its stick sequence cannot be read)."""
        self.evaluations += 1
        run = simulate(self.params.replace(kappa=self.kappa_c * (1 + eps)), self.law, None, rtol=self.rtol)
        violation = stick_sequence_violation(run, self.rtol) if run.status == "success" else run.message
        return run.n_stick, violation

    def confirmed(self, eps):
        """The count, confirmed at a tighter tolerance (:func:`.confirm.confirmed_count`: two runs)."""
        self.evaluations += 2
        return confirmed_count(self.params.replace(kappa=self.kappa_c * (1 + eps)), self.law, self.rtol)


def _bisect_kappa_2(runs: _Runs, kappa_rtol: float) -> tuple[float, float, str]:
    """``(eps_lo, eps_hi, "")``: a bracket of ``kappa_2`` of relative width ``kappa_rtol`` (``N = 2`` at
    ``eps_hi``, not at ``eps_lo``), by doubling then bisection in ``log eps``; or why there is none."""
    eps_hi = 1e-3
    while runs.count(eps_hi)[0] != 2:
        eps_hi *= 2
        if eps_hi > 1e3:
            return math.nan, math.nan, "no kappa up to kappa_c (1 + 1e3) gives N = 2"
    eps_lo = eps_hi / 2
    while runs.count(eps_lo)[0] == 2:
        eps_hi, eps_lo = eps_lo, eps_lo / 2
        if eps_lo < 1e-12:
            return math.nan, math.nan, "N = 2 down to kappa_c (1 + 1e-12)"
    while (eps_hi - eps_lo) / (1 + eps_hi) > kappa_rtol:
        mid = math.sqrt(eps_lo * eps_hi)
        if mid in (eps_lo, eps_hi):
            break
        if runs.count(mid)[0] == 2:
            eps_hi = mid
        else:
            eps_lo = mid
    return eps_lo, eps_hi, ""


def _holds(count, two: bool) -> bool:
    """Whether a confirmed count proves its end of the bracket: ``N = 2`` above, ``N != 2`` below."""
    if two:
        return count.confirmed and not count.cut and count.n_stick == 2
    # a lower bound above 2 (a run cut by the horizon) proves N != 2 as well as a count does
    return count.n_stick_tight is not None and min(count.n_stick, count.n_stick_tight) > 2


def _widens(count) -> bool:
    """A count the tolerance decides, or N on the wrong side: not a broken run, so the bracket may widen."""
    return not count.cut and (count.confirmed or count.disagree)


def _confirmed_ends(runs: _Runs, eps_lo: float, eps_hi: float):
    """The bracket's ends confirmed, ``((eps_lo, count), (eps_hi, count))``: an end the tighter
    tolerance moves across kappa_2 lies within the integrator's uncertainty of it, so the bracket
    widens, in doubling steps (at most :data:`WIDENINGS`), until both ends hold."""
    step = eps_hi - eps_lo
    upper = runs.confirmed(eps_hi)
    for _ in range(WIDENINGS):
        if _holds(upper, True) or not _widens(upper):
            break
        eps_hi, step = eps_hi + step, 2 * step
        upper = runs.confirmed(eps_hi)
    step = eps_hi - eps_lo
    lower = runs.confirmed(eps_lo)
    for _ in range(WIDENINGS):
        if _holds(lower, False) or not _widens(lower) or eps_lo <= step:
            break
        eps_lo, step = eps_lo - step, 2 * step
        lower = runs.confirmed(eps_lo)
    return (eps_lo, lower), (eps_hi, upper)


def _staircase(runs: _Runs, eps_hi: float, samples: int) -> list[dict]:
    """Confirmed counts from ``1.5 eps_hi`` down towards ``kappa_c``, in increasing ``kappa``; the
    sampling stops at the first run the horizon cuts (closer to ``kappa_c`` the escape only takes longer)."""
    staircase = []
    for eps in np.geomspace(eps_hi * 1.5, min(1e-5, eps_hi / 10), samples):
        n = runs.confirmed(float(eps))
        staircase.append({"kappa": runs.kappa_c * (1 + float(eps)), "relative": float(eps),
                          "n_stick": n.n_stick if n.confirmed else None, "t_run": n.t_run, "cut": n.cut,
                          "confirmed": n.confirmed, "reason": n.reason})
        if n.cut:
            break
    return staircase[::-1]


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
