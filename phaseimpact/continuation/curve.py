"""Two-parameter continuation: ``kappa_c``, ``kappa_2`` or a grazing value against a second
parameter (``v``, or any quantity of either body or the geometry).

Natural-parameter continuation of the defining function with step control: each point is
predicted from the previous ones (secant in log-log), corrected by Brent's method on a
bracket around the prediction, and where the prediction is poor the step is halved (the
intermediate points are computed and kept, flagged as not asked for).

The walk is sequential (each bracket comes from the roots before it); what a backend changes
is the corrector. ``threads``: Brent's method, one run at a time. ``cuda``: the defining
function at :data:`GPU_KAPPAS` kappas across the bracket in one GPU launch (one thread per
kappa), the sub-bracket of its sign change, again, until the bracket is as narrow as Brent's
final one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from tqdm.auto import tqdm

from ..case import Case
from ..integrate.api import check_rtol
from ..integrate.batch import summary_runs
from ..integrate.driver import S_STATUS, STATUSES, SUCCESS
from ..model.laws import ContactLaw, as_law
from ..parameters import Parameters
from ._kappa_search import checked_summary
from ._renamed import renamed_tolerances
from .grazing import extremum_of, extremum_run
from .transition import (
    KAPPA_2_RTOL,
    RunFailed,
    check_rtol_of_kappa,
    closed_form_kappa_c,
    critical_damping,
    delta_extremum,
    first_stick_margin,
    locate_kappa_2,
    margin_of,
    margin_run,
)

__all__ = ["CriticalCurve", "critical_curve", "CURVE_QUANTITIES"]

#: What :func:`critical_curve` continues.
CURVE_QUANTITIES = ("kappa_c", "kappa_2", "grazing")
#: Where :func:`critical_curve`'s corrector runs.
CURVE_BACKENDS = ("threads", "cuda")
#: Kappas of one GPU launch of the ``cuda`` corrector (one thread each): each launch narrows the
#: bracket ``GPU_KAPPAS + 1``-fold, so a 2 % bracket reaches ``kappa_rtol = 1e-10`` in 5 launches.
GPU_KAPPAS = 128


@dataclass(frozen=True)
class CriticalCurve:
    """A continued curve: ``values`` of ``param`` and the located ``kappa`` at each.

    Attributes
    ----------
    param : str
        The second parameter's name (``v``, ``R1``, ``plate.E``...).
    values : ndarray
        Its values (asked for and intermediate ones), increasing along the walk.
    kappa : ndarray
        The continued quantity (``what``), NaN where it could not be continued.
    requested : ndarray of bool
        Which values were asked for.
    closed_form : ndarray
        docs/physics.md §5's closed-form ``kappa_c`` (``paper``), NaN otherwise.
    predicted : ndarray
        The predictor's value at each point (how good the continuation's steps were).
    what : str
        ``kappa_c``, ``kappa_2`` or ``grazing`` (with ``contact_index``).
    law : ContactLaw
        The law.
    base : Parameters or Case
        The case whose ``param`` was varied.
    rtol : float
        Relative tolerance of each located value: the call's ``kappa_rtol`` (the archive's ``rtol``
        attribute of a curve).
    contact_index : int
        ``grazing``: which extremum of ``delta`` touches zero.
    message : str
        Where the curve was lost, or which ``kappa_2`` values are unconfirmed ("" when neither).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import critical_curve
    >>> c = critical_curve(seed_parameters(), "paper", "v", [1.0, 2.0])
    >>> c.param, c.what, c.requested.tolist(), repr(c.message)
    ('v', 'kappa_c', [True, False, False, True], "''")
    >>> c.kappa_c is c.kappa, c.v is c.values
    (True, True)
    """

    param: str
    values: np.ndarray
    kappa: np.ndarray
    requested: np.ndarray
    closed_form: np.ndarray
    predicted: np.ndarray
    what: str
    law: ContactLaw
    base: Parameters | Case
    rtol: float
    contact_index: int = 1
    message: str = ""

    @property
    def kappa_c(self) -> np.ndarray:
        """:attr:`kappa` under its older name."""
        return self.kappa

    @property
    def v(self) -> np.ndarray:
        """:attr:`values` under its older name (the impact speed, when ``param`` is ``v``)."""
        return self.values


def _parameters(base, param, value) -> Parameters:
    if isinstance(base, Case):
        return base.parameters(**{param: float(value)})
    return base.replace(**{param: float(value)})


@renamed_tolerances("kappa_rtol")
def critical_curve(base: Parameters | Case, law: ContactLaw | str, param: str, values, *,
                   what: str = "kappa_c", kappa_rtol: float = 1e-10, rtol: float = 1e-10,
                   contact_index: int = 1, kappa_start: float | None = None, max_halvings: int = 6,
                   progress: bool = False, backend: str = "threads") -> CriticalCurve:
    """Continue ``what`` over ``values`` of ``param`` (see the module docstring).

    Raises ``ValueError`` for bad arguments (before any work) and
    :class:`~phaseimpact.continuation.transition.RunFailed` when no start point is found; a curve
    lost on the way ends there, with :attr:`CriticalCurve.message` saying where.

    The first point is found independently (:func:`~phaseimpact.continuation.critical_damping`,
    or the root of :func:`~phaseimpact.continuation.delta_extremum` near ``kappa_start``); each
    next one is predicted by a secant in log-log and corrected by Brent's method within 2 %, then
    20 %, of the prediction; where both fail the step is halved (at most ``max_halvings`` times
    per value). ``kappa_2`` rides on the continued ``kappa_c`` (:func:`locate_kappa_2` at each
    point); an unconfirmed ``kappa_2`` is NaN, named in the message.

    ``backend="cuda"`` keeps this walk and replaces Brent's method in the corrector: the defining
    function (the first stick's margin, or ``delta`` at the extremum) at :data:`GPU_KAPPAS`
    kappas evenly spaced in ``log(kappa)`` across the bracket, in one GPU launch; the bracket
    is refused as Brent's is (ends not finite or of one sign) and also when the samples change
    sign more than once (Brent would take one of the roots); else the interval of the sign change
    is sampled again, until it is as narrow as Brent's final bracket (``kappa_rtol / 4`` in
    ``log(kappa)``): both backends meet ``kappa_rtol`` (``tests/test_cuda.py``). The first
    point's search (:func:`critical_damping`; ``grazing``: the corrector, on the GPU) and
    ``kappa_2``'s confirmation stay on the CPU.

    Parameters
    ----------
    base : Parameters or Case
        The case; a :class:`~phaseimpact.case.Case` allows material and geometry parameters.
    law : ContactLaw or str
        A Filippov law (``paper``) for ``kappa_c`` and ``kappa_2``; a unilateral law for ``grazing``.
    param : str
        The second parameter (``v``, ``R1``, ``plate.E``...; not ``kappa``).
    values : sequence of float
        Its values, SI units: non-empty, 1-d, finite, distinct, in the order to walk.
    what : {"kappa_c", "kappa_2", "grazing"}, default "kappa_c"
        The quantity to continue (:data:`CURVE_QUANTITIES`).
    kappa_rtol : float, default 1e-10
        Relative tolerance of each located value, ``1e-14 <= kappa_rtol <= 1e-2`` (``rtol`` up to
        0.2.0).
    rtol : float, default 1e-10
        The integrator's tolerance of every run, within :data:`~phaseimpact.integrate.RTOL_RANGE`
        (``integrator_rtol`` up to 0.2.0; ``rtol=`` alone is refused for one release).
    contact_index : int, default 1
        ``grazing``: which extremum of ``delta`` touches zero (the ``extremum`` of a
        :class:`~phaseimpact.continuation.Transition`).
    kappa_start : float, optional
        ``grazing`` (required): the grazing value at the first point, N s/m^(1+alpha), e.g. from
        :func:`~phaseimpact.continuation.transitions`; refined there if a root lies within 0.1 %.
    max_halvings : int, default 6
        Step halvings allowed before a value counts as lost.
    progress : bool, default False
        Draw a progress bar on stderr.
    backend : {"threads", "cuda"}, default "threads"
        Where the corrector runs (above): this thread, or a GPU; ``cuda`` is refused before any
        work for a user law or without a usable GPU.

    Returns
    -------
    CriticalCurve
        The values walked (asked for and intermediate), ``kappa`` at each (N s/m^(1+alpha)), the
        closed form (``kappa_c``, ``kappa_2``) and the predictions.

    Raises
    ------
    ValueError
        For ``what`` not in :data:`CURVE_QUANTITIES`, a law that does not fit ``what``,
        ``param = "kappa"``, bad ``values`` (or a case invalid at either end), ``kappa_rtol`` or
        ``rtol`` out of range, ``grazing`` without ``kappa_start``, or ``backend`` out of range
        (``cuda``: without a usable GPU, or for a user law).
    TypeError
        For the spellings of 0.2.0 (``integrator_rtol=``; ``rtol=`` without ``kappa_rtol=``).
    RunFailed
        When no start point is found, or a run of the walk fails numerically.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import critical_curve
    >>> c = critical_curve(seed_parameters(), "paper", "v", [1.0, 2.0, 4.0])
    >>> for v, kappa, asked in zip(c.values, c.kappa, c.requested):
    ...     print(f"v = {v:.3g} m/s: kappa_c = {kappa:.4g} N s/m^2.5{'' if asked else ' (step)'}")
    v = 1 m/s: kappa_c = 1.499e+12 N s/m^2.5
    v = 1.19 m/s: kappa_c = 1.34e+12 N s/m^2.5 (step)
    v = 1.41 m/s: kappa_c = 1.197e+12 N s/m^2.5 (step)
    v = 2 m/s: kappa_c = 9.542e+11 N s/m^2.5
    v = 4 m/s: kappa_c = 6.052e+11 N s/m^2.5

    A material parameter needs a case:

    >>> from phaseimpact.case import load_case
    >>> c = critical_curve(load_case("seed"), "paper", "plate.E", [1e11, 2.1e11])
    >>> [f"{k:.4g}" for k in c.kappa]
    ['1.36e+12', '1.499e+12']
    """
    law = as_law(law)
    values, rtol = _checked(base, law, param, values, what, kappa_rtol, rtol)
    if backend not in CURVE_BACKENDS:
        raise ValueError(f"backend = {backend!r} is out of range; allowed: one of {', '.join(CURVE_BACKENDS)}")
    if backend == "cuda":
        from .. import cuda

        cuda.check(law)
        correct = _gpu_corrector(law, what, contact_index, kappa_rtol, rtol)
    else:
        correct = _corrector(law, what, contact_index, kappa_rtol, rtol)
    first = _first_point(base, law, param, values, what, kappa_start, correct, kappa_rtol, rtol)
    walk_x, walk_k, walk_req, walk_pred, message = _walk(base, param, values, first, correct, max_halvings,
                                                         f"{what}({param})", progress)
    walk_k = np.asarray(walk_k, dtype=float)
    if what == "kappa_2":
        walk_k, message = _kappa_2_along(base, law, param, walk_x, walk_k, rtol, message)
    walk_x = np.asarray(walk_x)
    closed = np.array([(closed_form_kappa_c(_parameters(base, param, x)) or math.nan) if what != "grazing"
                       else math.nan for x in walk_x])
    return CriticalCurve(param, walk_x, walk_k, np.asarray(walk_req), closed, np.asarray(walk_pred),
                         what, law, base, kappa_rtol, contact_index, message)


def _checked(base, law, param, values, what, kappa_rtol, rtol):
    """:func:`critical_curve`'s arguments checked before any work: ``values`` as an array and the
    integrator's ``rtol``."""
    if what not in CURVE_QUANTITIES:
        raise ValueError(f"what = {what!r} is out of range; allowed: one of {', '.join(CURVE_QUANTITIES)}")
    if what in ("kappa_c", "kappa_2") and not law.is_filippov:
        raise ValueError(f"what = {what!r} needs a Filippov law (a stick to lose); law {law.name!r} is not: unilateral "
                         "laws continue 'grazing'")
    if what == "grazing" and law.is_filippov and law.contact == "printed":
        raise ValueError("what = 'grazing' needs a unilateral law")
    if param == "kappa":
        raise ValueError("param = 'kappa' is out of range; allowed: any other parameter (kappa is continued)")
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)) or np.any(np.diff(values) == 0):
        raise ValueError("values are out of range; allowed: a non-empty 1-d array of distinct finite numbers")
    check_rtol_of_kappa(kappa_rtol)
    rtol = check_rtol(rtol)
    _parameters(base, param, values[0]), _parameters(base, param, values[-1])  # both ends valid: check first
    return values, rtol


def _corrector(law, what, contact_index, kappa_rtol, rtol):
    """The corrector ``correct(p, guess, width)``: the root of the defining function within
    ``guess * exp(+-width)``, None when it has none there."""
    from scipy.optimize import brentq  # imported where used: 0.5 s at start-up

    def defining(p: Parameters, quantity: str):
        """The smooth function whose root in log(kappa) is the quantity (kappa_2 rides on kappa_c)."""
        if quantity == "grazing":
            return lambda x: delta_extremum(p.replace(kappa=math.exp(x)), law, contact_index, rtol=rtol)
        return lambda x: first_stick_margin(p.replace(kappa=math.exp(x)), law, rtol=rtol)

    def correct(p: Parameters, guess: float, width: float) -> float | None:
        f = defining(p, "grazing" if what == "grazing" else "kappa_c")
        lo, hi = math.log(guess) - width, math.log(guess) + width
        f_lo, f_hi = f(lo), f(hi)
        if not (math.isfinite(f_lo) and math.isfinite(f_hi)) or (f_lo > 0) == (f_hi > 0):
            return None
        return math.exp(brentq(f, lo, hi, xtol=kappa_rtol / 4, rtol=BRENT_RTOL))
    return correct


#: Brent's ``rtol`` in the ``threads`` corrector (its ``xtol`` is ``kappa_rtol / 4``): it stops at a
#: bracket narrower than ``xtol + rtol |log(kappa)|``, the ``cuda`` corrector's stop too.
BRENT_RTOL = 4 * np.finfo(float).eps


def _gpu_corrector(law, what, contact_index, kappa_rtol, rtol):
    """:func:`_corrector` on a GPU: the defining function at :data:`GPU_KAPPAS` points of the bracket
    in one launch, the interval of its one sign change sampled again until narrower than Brent's final
    bracket; None where Brent's corrector refuses the bracket, or where the samples change sign more
    than once."""
    if what == "grazing":  # delta_extremum's and first_stick_margin's runs and readings
        def run(q):
            return extremum_run(q, contact_index)
        read = extremum_of
    else:
        run, read = margin_run, lambda summary, _final: margin_of(summary)

    def defining(p: Parameters, log_kappas: np.ndarray) -> np.ndarray:
        points = [p.replace(kappa=math.exp(x)) for x in log_kappas]
        t_ends, options = [run(q)[0] for q in points], run(p)[1]
        summaries, finals = summary_runs(law, points, t_ends, rtol=rtol, **options)
        for point, t_end, summary in zip(points, t_ends, summaries, strict=True):
            if summary[S_STATUS] != SUCCESS:  # a search must not read a failed run: the CPU's message
                checked_summary(point, law, t_end, rtol=rtol, **options)
                raise RunFailed(f"kappa = {point.kappa:.6g}: {STATUSES[int(summary[S_STATUS])]} on the GPU")
        return np.array([read(summary, final) for summary, final in zip(summaries, finals, strict=True)])

    def correct(p: Parameters, guess: float, width: float) -> float | None:
        x = np.linspace(math.log(guess) - width, math.log(guess) + width, GPU_KAPPAS)
        f = defining(p, x)
        if not (math.isfinite(f[0]) and math.isfinite(f[-1])) or (f[0] > 0) == (f[-1] > 0):
            return None
        while True:
            changes = np.flatnonzero((f[:-1] > 0) != (f[1:] > 0))
            if changes.size != 1:
                return None
            i = changes[0]
            lo, hi = x[i], x[i + 1]
            # the width falls GPU_KAPPAS + 1-fold a launch; at the stop, it spans several ulps of log(kappa)
            if hi - lo < kappa_rtol / 4 + BRENT_RTOL * max(abs(lo), abs(hi)):
                return math.exp(0.5 * (lo + hi))
            inner = np.linspace(lo, hi, GPU_KAPPAS + 2)[1:-1]
            x = np.concatenate(([lo], inner, [hi]))
            f = np.concatenate(([f[i]], defining(p, inner), [f[i + 1]]))
    return correct


def _first_point(base, law, param, values, what, kappa_start, correct, kappa_rtol, rtol) -> float:
    """The curve's first point: an independent search (or the caller's start for a grazing value)."""
    p0 = _parameters(base, param, values[0])
    if what == "grazing":
        if kappa_start is None:
            raise ValueError("what = 'grazing' needs kappa_start (a grazing value at the first point, e.g. "
                             "from transitions())")
        return correct(p0, kappa_start, 1e-3) or kappa_start
    found = critical_damping(p0, law, kappa_rtol=kappa_rtol, rtol=rtol)
    if found.kappa_c is None:
        raise RunFailed(f"no kappa_c at {param} = {values[0]:g} to start from: {found.message}")
    return found.kappa_c


def _walk(base, param, values, first, correct, max_halvings, desc, progress):
    """The walk from ``first`` over ``values`` (kappa_c or the grazing value; kappa_2 is located
    from each kappa_c): the values walked, the roots, whether each was asked for, the predictions
    and where the curve was lost ("" when it was not)."""
    log_x = bool(np.all(values > 0))

    def coordinate(x):
        return math.log(x) if log_x else x

    walk_x, walk_k, walk_req, walk_pred = [float(values[0])], [first], [True], [first]
    bar = tqdm(total=len(values), desc=desc, unit="pt", disable=not progress)
    bar.update(1)
    message = ""
    for target in values[1:]:
        pending = [float(target)]
        halvings = 0
        while pending:
            x = pending[-1]
            p = _parameters(base, param, x)
            if len(walk_k) >= 2:
                slope = ((math.log(walk_k[-1]) - math.log(walk_k[-2]))
                         / (coordinate(walk_x[-1]) - coordinate(walk_x[-2])))
                guess = math.exp(math.log(walk_k[-1]) + slope * (coordinate(x) - coordinate(walk_x[-1])))
            else:
                guess = walk_k[-1]
            root = correct(p, guess, 0.02) or correct(p, guess, 0.2)
            if root is None and halvings < max_halvings:
                halvings += 1  # step control: walk there in a smaller step first
                pending.append(math.sqrt(walk_x[-1] * x) if log_x else 0.5 * (walk_x[-1] + x))
                continue
            pending.pop()
            if root is None:
                message = f"lost the curve at {param} = {x:g} (no root near the prediction {guess:.6g})"
                break
            walk_x.append(x)
            walk_k.append(root)
            walk_pred.append(guess)
            walk_req.append(not pending)
        bar.update(1)
        if message:
            break
    bar.close()
    return walk_x, walk_k, walk_req, walk_pred, message


def _kappa_2_along(base, law, param, walk_x, walk_k, rtol, message):
    """``kappa_2`` located from each continued ``kappa_c``, and the message with the unconfirmed ones."""
    found = [locate_kappa_2(_parameters(base, param, x), law, kc, kappa_rtol=KAPPA_2_RTOL, rtol=rtol, samples=0)
             for x, kc in zip(walk_x, walk_k, strict=True)]
    # an unconfirmed kappa_2 (its bracket's counts move at a tighter tolerance) is left out, never guessed
    kappa_2 = np.array([f.kappa_2 if f.kappa_2 is not None and not f.reason else math.nan for f in found])
    unconfirmed = [f"{param} = {x:g} ({f.reason})" for x, f in zip(walk_x, found, strict=True) if f.reason]
    if unconfirmed:
        note = f"kappa_2 unconfirmed (left NaN) at {', '.join(unconfirmed)}"
        message = f"{message}; {note}" if message else note
    return kappa_2, message
