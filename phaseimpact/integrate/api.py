"""One run: :func:`simulate` (a :class:`Trajectory`) and :func:`summary_run` (a summary and a
final state, in this thread's held workspace), with the checks and scales every run shares:
each argument is checked before any work, horizons and tolerances come from the case's own
scales, and the run goes on the one compiled driver. Many runs at once are :mod:`.batch`'s."""

from __future__ import annotations

import functools
import math
import numbers
import threading
from dataclasses import dataclass

import numpy as np

from .. import _signals
from .._jit import cache_info, stiff_run_met
from ..model.laws import ContactLaw, as_law
from ..model.rhs import N_COEF, initial_state, pack
from ..parameters import Parameters, is_number
from . import driver as d
from . import radau5
from .events import EVENT_KINDS
from .record import W_SUMMARY, W_Y, Y_STATE, workspace
from .result import Trajectory
from .rk4 import run_rk4

__all__ = ["simulate", "Scales", "scales", "INTEGRATORS", "RTOL_RANGE"]

#: The integrators :func:`simulate` accepts: ``exact`` (event-driven DOP853, Radau IIA for stiff
#: phases) and ``rk4`` (the seed's fixed-step RK4 on eq. 8 read literally).
INTEGRATORS = ("exact", "rk4")
#: Allowed integrator tolerances: tighter than 1e-13 is below rounding; looser than 1e-3 can
#: change an outcome class (a stick missed), which no allowed setting may do.
RTOL_RANGE = (1e-13, 1e-3)
#: Horizon when none is given, in units of the case's slowest time scale (plate period, or
#: contact time without a plate): near the critical damping the escape takes thousands of periods.
HORIZON_CAP_PERIODS = 1e4
MAX_STEPS = 50_000_000
MAX_EVENTS = 5_000_000
#: Shortest horizon, in contact times: below it not even the time tolerance (``rtol`` times the
#: contact time, rtol >= 1e-13) fits, and the step size underflows.
MIN_HORIZON_CONTACT_TIMES = 1e-13


def is_real(value) -> bool:
    return is_number(value)


def check_params(params, name: str = "params") -> Parameters:
    """``params`` if it is :class:`Parameters`; else ``TypeError`` naming the argument."""
    if not isinstance(params, Parameters):
        raise TypeError(f"{name} = {params!r} has the wrong type ({type(params).__name__}); allowed: Parameters "
                        "(e.g. seed_parameters(), or Case.parameters())")
    return params


def check_t_end(t_end, contact_time: float, name: str = "t_end") -> float:
    """A horizon (s): a finite number no shorter than :data:`MIN_HORIZON_CONTACT_TIMES` contact times."""
    shortest = MIN_HORIZON_CONTACT_TIMES * contact_time
    if type(t_end) is float and shortest <= t_end < math.inf:  # the common case, without formatting the range
        return t_end
    return check_real(name, t_end, f"a finite number >= {shortest:.3g} s ({MIN_HORIZON_CONTACT_TIMES:g} of the "
                                      f"contact time {contact_time:.3g} s: nothing shorter can be resolved)",
                      lambda x: x >= shortest)


def check_bool(name: str, value) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise ValueError(f"{name} = {value!r} is out of range; allowed: True or False")
    return bool(value)


def check_real(name: str, value, allowed: str, ok) -> float:
    """``value`` as a float if it is a real number and ``ok(value)``; else ``ValueError``."""
    if type(value) is float and math.isfinite(value) and ok(value):  # the common case, without the ABC check
        return value
    if not is_real(value) or not math.isfinite(value) or not ok(float(value)):
        raise ValueError(f"{name} = {value!r} is out of range; allowed: {allowed}")
    return float(value)


def check_rtol(rtol) -> float:
    lo, hi = RTOL_RANGE
    if type(rtol) is float and lo <= rtol <= hi:  # the common case, without formatting the range
        return rtol
    return check_real("rtol", rtol, f"{lo:g} <= rtol <= {hi:g}", lambda x: lo <= x <= hi)


@dataclass(frozen=True)
class Scales:
    """A case's own scales (DESIGN principle 5; docs/physics.md §4).

    Made by :func:`scales`; horizons, tolerances and step caps of every run derive from them.

    Attributes
    ----------
    indentation : float
        Largest indentation of the undamped impact of the reduced mass, m.
    contact_time : float
        Its duration, ``2 tau delta_max / v``, s.
    plate_period : float
        Small-amplitude period of the target, s (inf without springs).
    horizon : float
        Default cap on a run that goes until its outcome settles, s.
    max_step : float
        Largest step the driver takes: an eighth of the target's small-amplitude period
        (:attr:`plate_period`), inf without springs, s.

    Examples
    --------
    >>> from phaseimpact import scales, seed_parameters
    >>> s = scales(seed_parameters(v=1.0))
    >>> print(f"{s.indentation:.4g} m, {s.contact_time:.4g} s, {s.plate_period:.4g} s")
    3.669e-05 m, 0.000108 s, 0.001004 s
    >>> s.horizon == 1e4 * s.plate_period
    True
    """

    indentation: float
    contact_time: float
    plate_period: float
    horizon: float
    max_step: float


def hertz_contact_time(alpha, indentation, v):
    """Duration of the undamped impact, ``2 tau delta_max / v`` (s; scalars or arrays, ``alpha`` too)."""
    if type(alpha) is float or np.ndim(alpha) == 0:  # (the first test spares a case np.ndim's cost)
        tau = _hertz_tau(alpha)
    else:  # a batch has few distinct exponents
        exponents, which = np.unique(alpha, return_inverse=True)
        tau = np.array([_hertz_tau(a) for a in exponents.tolist()])[which]
    return 2 * tau * indentation / v


@functools.lru_cache(maxsize=64)
def _hertz_tau(alpha: float) -> float:
    # cached: a batch has few distinct exponents
    return math.sqrt(math.pi) * math.gamma(1 + 1 / (alpha + 1)) / math.gamma(0.5 + 1 / (alpha + 1))  # 1.4716: Hertz


def scales(params: Parameters) -> Scales:
    """The time and length scales of ``params`` (docs/physics.md §4).

    The Hertz indentation and contact time of the undamped impact of the reduced mass, the
    target's small-amplitude period, the default horizon (:data:`HORIZON_CAP_PERIODS` of the
    slowest of these periods) and the driver's largest step. Cached per case.

    Parameters
    ----------
    params : Parameters
        The case (e.g. :func:`~phaseimpact.seed_parameters`).

    Returns
    -------
    Scales
        Lengths in m, times in s; ``plate_period`` and ``max_step`` are inf without springs.

    Raises
    ------
    TypeError
        If ``params`` is not :class:`~phaseimpact.Parameters`.

    Examples
    --------
    >>> from phaseimpact import scales, seed_parameters
    >>> print(f"{scales(seed_parameters(v=1.0)).contact_time:.4g} s")
    0.000108 s
    >>> scales(seed_parameters(target="rigid")).plate_period
    inf
    """
    if type(params) is not Parameters:  # the common case without the check's formatting
        check_params(params)
    return _scales(params)


@functools.lru_cache(maxsize=1024)
def _scales(params: Parameters) -> Scales:
    # cached: a sweep asks for the same case often
    indentation = params.hertz_indentation
    contact_time = hertz_contact_time(params.alpha, indentation, params.v)
    period = params.target_period
    slow = period if math.isfinite(period) else contact_time
    max_step = period / 8 if math.isfinite(period) else math.inf
    return Scales(indentation, contact_time, period, HORIZON_CAP_PERIODS * slow, max_step)


def state_tolerances(rtol: float, indentation, v, M1, contact_time) -> np.ndarray:
    """Absolute tolerances of ``(x1, x2, x1dot, x2dot, W, t, w)`` from the state scales (scalars
    or arrays): positions by the Hertz indentation, velocities by the impact speed, the work by
    the impact energy, the time by the contact time and ``w = sqrt(|delta|)`` (the position of a
    regularised contact phase) by the square root of the indentation."""
    if type(indentation) is float:  # one case (simulate's): seven numbers, without broadcasting arrays
        energy = 0.5 * M1 * (v * v)  # numpy's v ** 2 below is v * v: the same bits in either path
        return np.array([rtol * indentation, rtol * indentation, rtol * v, rtol * v, rtol * energy,
                         rtol * contact_time, rtol * math.sqrt(indentation)])
    columns = np.broadcast_arrays(indentation, indentation, v, v, 0.5 * np.asarray(M1) * np.asarray(v) ** 2,
                                  contact_time, np.sqrt(indentation))
    return rtol * np.stack(columns, axis=-1)


def _atol(params: Parameters, rtol: float, atol) -> np.ndarray:
    """The driver's absolute tolerances: ``atol`` for every component, or from the case's scales."""
    if atol is not None:
        return np.full(7, check_real("atol", atol, "a number > 0", lambda x: x > 0))
    return state_tolerances(rtol, params.hertz_indentation, params.v, params.M1, scales(params).contact_time)


@functools.lru_cache(maxsize=1024)
def _packed(params: Parameters, law: ContactLaw, rtol: float) -> tuple:
    """The driver's coefficient array and default absolute tolerances, seed eq. 6's initial state
    and the case's scales (cached: one lookup per run; the driver never writes to the arrays and
    only copies of the initial state are handed out)."""
    return pack(params, law), _atol(params, rtol, None), initial_state(params.v), scales(params)


def _initial(params: Parameters, initial) -> np.ndarray:
    y = initial_state(params.v)
    if initial is not None:
        y[:4] = _checked_initial(initial)
    return y


def _checked_initial(initial) -> np.ndarray:
    """``initial`` as 4 finite floats; ``ValueError`` naming it otherwise."""
    try:
        state = np.asarray(initial, dtype=float)
    except (TypeError, ValueError):
        state = np.full(0, np.nan)
    if isinstance(initial, str) or state.shape != (4,) or not np.all(np.isfinite(state)):
        raise ValueError(f"initial = {initial!r} is out of range; allowed: 4 finite numbers "
                         "(x1, x2, x1dot, x2dot)")
    return state


def _stop_on(stop_on) -> tuple[int, int]:
    """``stop_on`` as (event kind code, count): stop at the n-th event of that kind."""
    if stop_on is None:
        return -1, 0
    if isinstance(stop_on, str):
        kind, n = stop_on, 1
    elif isinstance(stop_on, tuple | list) and len(stop_on) == 2:
        kind, n = stop_on
    else:
        kind, n = None, None
    if not isinstance(kind, str) or kind not in EVENT_KINDS:
        raise ValueError(f"stop_on = {stop_on!r} is out of range; allowed: an event kind "
                         f"({', '.join(EVENT_KINDS)}) or (kind, n)")
    if not (isinstance(n, numbers.Integral) and not isinstance(n, bool) and n >= 1):
        raise ValueError(f"stop_on count = {n!r} is out of range; allowed: an integer >= 1")
    return EVENT_KINDS.index(kind), int(n)


_NO_TIMES = np.empty(0)  # the driver only reads it


def _save(save, horizon: float, t_end):
    if isinstance(save, str):
        if save not in ("summary", "steps"):
            raise ValueError(f"save = {save!r} is out of range; allowed: 'summary', 'steps' or an array of times")
        return (d.SAVE_SUMMARY if save == "summary" else d.SAVE_STEPS), _NO_TIMES
    try:
        times = np.asarray(save, dtype=float)
    except (TypeError, ValueError):
        times = np.full((0, 0), np.nan)
    if times.ndim != 1 or not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
        raise ValueError(f"save = {save!r} is out of range; allowed: 'summary', 'steps' or output times as a "
                         "finite, strictly increasing 1-d array")
    # the run starts at t = 0 and ends at the horizon: a time outside would be a sample invented or dropped
    if times.size and (times[0] < 0 or times[-1] > horizon):
        where = "t_end" if t_end is not None else "the horizon cap"
        raise ValueError(f"save: output times {times[0]:.6g} .. {times[-1]:.6g} s are out of range; allowed: times "
                         f"in [0, {horizon:.6g}] s ({where})")
    return d.SAVE_TIMES, times


_STIFF_ON = np.int64(radau5.STIFF_STEPS)


#: In the engine's cache directory (:func:`phaseimpact._jit.cache_info`): a run on this machine has
#: turned stiff, so the engine with Radau is (being) compiled there (:func:`radau_marker`).
RADAU_MET_FILE = "radau-met"


class _Radau:
    """Whether a run has turned stiff, in this process or (its cache's ``RADAU_MET_FILE``) on this
    machine; None until :func:`radau_marker` first looks."""

    met = None


def radau_marker(stiff_after) -> bool | None:
    """The driver entries' ``radau`` argument (:func:`.record.carve`): None, the engine compiled and
    run without its stiff solver, until a run turns stiff (in this process, or on this machine with
    the same cache); True from then on.

    A first command whose runs never turn stiff compiles in about 0.8 of the time. A run that does
    stops there with the status ``NEEDS_RADAU`` and its caller runs it again with True: the same
    kernels up to the switch, so the same numbers (:func:`again_with_radau`). That first stiff run
    compiles the driver a second time, with Radau (nearly as long again): once per machine,
    since from then on every process that shares the cache runs only the engine with Radau
    (``benchmarks/compile_profile.py --against``)."""
    if not stiff_after:
        return None
    if _Radau.met is None:
        path = cache_info().path
        _Radau.met = path is not None and (path / RADAU_MET_FILE).exists()
    return True if _Radau.met else None


def radau_needed() -> None:
    """A run turned stiff: :func:`radau_marker` gives True from now on, here and (where the cache can
    be written) in every later process that shares this cache."""
    _Radau.met = True
    path = cache_info().path
    if path is not None:
        try:
            (path / RADAU_MET_FILE).touch()  # an empty file: nothing to leave half-written
        except OSError:
            pass  # a cache no longer writable: this process alone knows


def turned_stiff() -> None:
    """A run with ``radau`` None stopped where it turned stiff: :func:`radau_needed`, and the compile
    of the engine with Radau that follows says so on stderr (:func:`.._jit.stiff_run_met`)."""
    stiff_run_met()
    radau_needed()


def again_with_radau(status) -> bool:
    """Whether a run with ``radau`` None stopped where it turned stiff (its caller runs it again with
    :func:`radau_marker`, which now gives True)."""
    if status == d.NEEDS_RADAU:
        turned_stiff()
        return True
    return False


def _stiff_after(stiff) -> np.int64:
    """The driver's switch: DOP853 steps at the stability limit before Radau takes over (0: never)."""
    if stiff is True:  # the common case, without the isinstance of a union
        return _STIFF_ON
    if not isinstance(stiff, bool | np.bool_):
        raise ValueError(f"stiff = {stiff!r} is out of range; allowed: True or False")
    return np.int64(radau5.STIFF_STEPS if stiff else 0)


def simulate(params: Parameters, law: ContactLaw | str = "paper", t_end: float | None = None, *,
             integrator: str = "exact", save="summary", stop_when_settled: bool | None = None,
             rtol: float = 1e-10, atol: float | None = None, step: float | None = None, every: int = 1,
             initial=None, stop_on=None, max_steps: int = MAX_STEPS, stiff: bool = True) -> Trajectory:
    """Integrate one impact from seed eq. 6 (``x1dot = v`` at ``x1 = x2 = 0``) or ``initial``.

    Every argument is checked before any work. The run goes on the one compiled driver:
    contact, separation, stick and slip are located on the step's dense output and the
    integration restarts at the root; the outcome class is read from the run (docs/physics.md §5).

    Parameters
    ----------
    params : Parameters
        The case: masses, stiffnesses, ``kappa`` (N s/m^(1+alpha), N s/m^2.5 for alpha = 3/2) and
        the impact speed ``v`` (m/s).
    law : ContactLaw or str, default "paper"
        A law of :data:`phaseimpact.model.LAWS` with its options, or its name.
    t_end : float, optional
        Horizon, s: a finite number of at least ``1e-13`` contact times. Default: run until the
        outcome settles (permanent stick, escape, projectile out of reach), capped at
        :attr:`Scales.horizon`; :attr:`Trajectory.cut` says when the cap ended it.
    integrator : {"exact", "rk4"}, default "exact"
        ``exact``: event-driven DOP853, stick and slip resolved exactly. ``rk4``: the seed's
        classic fixed-step RK4 on eq. 8 read literally (``step`` s, default a thousandth of the
        contact time), keeping every ``every``-th step.
    save : "summary", "steps" or array of times, default "summary"
        What to keep: a sweep point needs only the summary; a figure the steps or a time grid
        (s, finite, strictly increasing, within ``[0, t_end]``).
    stop_when_settled : bool, optional
        Stop once nothing can change any more; default True when ``t_end`` is None or for a
        summary.
    rtol : float, default 1e-10
        Relative tolerance, within :data:`RTOL_RANGE` (1e-13 to 1e-3).
    atol : float, optional
        Absolute tolerance (> 0) of every state component; default ``rtol`` times the state
        scales (Hertz indentation, impact speed, impact energy, contact time).
    step : float, optional
        ``rk4`` only: the fixed step, s (> 0).
    every : int, default 1
        ``rk4`` only: keep every ``every``-th step (>= 1).
    initial : 4 numbers, optional
        ``(x1, x2, x1dot, x2dot)`` (m, m, m/s, m/s) to start from instead of eq. 6.
    stop_on : str or (str, int), optional
        Stop at the n-th event of a kind of :data:`~phaseimpact.integrate.EVENT_KINDS`
        (``"stick"``, ``("stick", 2)``).
    max_steps : int, default 50_000_000
        Step limit (>= 1); a run that reaches it ends with status ``too-many-steps``.
    stiff : bool, default True
        ``exact`` only: a phase whose DOP853 steps stay at their stability limit (a creep held by
        a strong damper) goes on with Radau IIA (order 5, :mod:`.radau5`); False keeps DOP853
        throughout (for comparisons).

    Returns
    -------
    Trajectory
        Samples (per ``save``), the event log, the summary, ``status`` (numerical health),
        ``stop_reason`` and ``outcome``. A numerical failure is reported in ``status``, not raised.

    Raises
    ------
    TypeError
        If ``params`` is not :class:`~phaseimpact.Parameters`.
    ValueError
        For an unknown law or integrator, or any of ``t_end``, ``save``, ``rtol``, ``atol``,
        ``step``, ``every``, ``initial``, ``stop_on``, ``stop_when_settled``, ``max_steps`` or
        ``stiff`` out of range (``rk4``: also a ``step`` that needs more than ``max_steps`` steps,
        or a law that keeps a memory of the contact); the message names the argument, its value
        and the allowed range.
    KeyboardInterrupt
        Ctrl-C or SIGTERM during the run (the compiled driver stops within a second).

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate
    >>> tr = simulate(seed_parameters(v=1.0, kappa=3e9), "paper")
    >>> tr.status, tr.outcome, tr.n_stick
    ('success', 'permanent-stick', 1)
    >>> print(f"{tr.max_force:.4g} N")
    4629 N

    A fixed horizon with the steps kept (for a figure), and the seed's RK4:

    >>> tr = simulate(seed_parameters(v=1.0, kappa=3e9), "paper", 2e-3, save="steps")
    >>> tr.y.shape[1], tr.stop_reason, tr.cut
    (5, 'horizon', True)
    >>> simulate(seed_parameters(), "abrate", 2e-4, integrator="rk4").integrator
    'rk4[step=1.08e-07]'
    """
    law = as_law(law)
    check_params(params)
    if not isinstance(integrator, str) or integrator not in INTEGRATORS:
        raise ValueError(f"integrator = {integrator!r} is out of range; allowed: one of {', '.join(INTEGRATORS)}")
    stiff_after = _stiff_after(stiff)
    rtol = check_rtol(rtol)
    c, default_atol, seed_state, s = _packed(params, law, rtol)
    horizon = s.horizon if t_end is None else check_t_end(t_end, s.contact_time)
    save_kind, times = _save(save, horizon, t_end)
    settle = ((t_end is None or save_kind == d.SAVE_SUMMARY) if stop_when_settled is None
              else check_bool("stop_when_settled", stop_when_settled))
    stop_kind, stop_count = _stop_on(stop_on)
    if not (type(max_steps) is int and max_steps >= 1) and not (  # the common case, without the ABC checks
            isinstance(max_steps, numbers.Integral) and not isinstance(max_steps, bool) and max_steps >= 1):
        raise ValueError(f"max_steps = {max_steps!r} is out of range; allowed: an integer >= 1")
    y0 = seed_state.copy() if initial is None else _initial(params, initial)
    rk4_step = 0.0
    if integrator == "rk4":
        if law.entry.memory:  # its memory is updated at located events, which the fixed-step run has not
            raise ValueError(f"integrator = 'rk4' is out of range for law {law.name!r} (it keeps a memory of the "
                             "contact); allowed: 'exact'")
        rk4_step = s.contact_time / 1000 if step is None else check_real("step", step, "a number > 0", lambda x: x > 0)
        if not (isinstance(every, numbers.Integral) and every >= 1):
            raise ValueError(f"every = {every!r} is out of range; allowed: an integer >= 1")
        if horizon / rk4_step > max_steps:
            raise ValueError(f"step = {rk4_step!r} needs {horizon / rk4_step:.3g} steps; allowed: at most "
                             f"max_steps = {max_steps}")
    if not _signals.installed:
        _signals.install()
    native = law.entry.native
    while True:
        if native is not None:
            native.reset()
        if rk4_step:
            out = run_rk4(law.code, c, y0, horizon, save_kind, times, int(max_steps), rk4_step, int(every))
        else:
            out = d.run(law.code, c, y0, default_atol if atol is None else _atol(params, rtol, atol), horizon,
                        s.max_step, (rtol, settle, stop_kind, stop_count, int(max_steps), MAX_EVENTS, stiff_after),
                        save_kind, times, radau_marker(stiff_after))
        codes = out[0].tolist()  # the summary's numbers: cheaper than reading entries of the array one by one
        if again_with_radau(codes[d.S_STATUS]):
            continue
        woken = _woken(codes[d.S_STATUS], native)
        if not (woken or _signals.deferred):
            break
        _signals.check(woken)  # raises for Ctrl-C or SIGTERM; after an old wake-up, runs again
    summary, event_log, samples, y_final = out
    law_fault = ""
    if native is not None and native.faulted and codes[d.S_STATUS] != d.SUCCESS:
        # the law's NaN failed the run, whatever the steps made of it
        summary[d.S_STATUS] = codes[d.S_STATUS] = d.NON_FINITE
        law_fault = native.fault(law.name)
    status = d.STATUSES[int(codes[d.S_STATUS])]
    reason = d.STOP_REASONS[int(codes[d.S_REASON])]
    outcome = d.OUTCOMES[int(codes[d.S_OUTCOME])]
    return Trajectory(
        samples=samples, event_log=event_log, params=params, law=law, initial_state=y0, final_state=y_final,
        t_end=horizon, status=status, stop_reason=reason, outcome=outcome, summary=summary,
        integrator=_integrator_name(rk4_step, rtol, stiff_after > 0), law_fault=law_fault)


def _woken(status, native) -> bool:
    """Whether a signal stopped the run: the driver saw it (status ``interrupted``), or a user law
    did (it then returns NaN, and the run fails at once: :mod:`phaseimpact.model.userlaw`)."""
    return status == d.INTERRUPTED or (native is not None and native.stopped)


@functools.lru_cache(maxsize=64)
def _integrator_name(rk4_step: float, rtol: float, stiff: bool) -> str:
    if rk4_step:
        return f"rk4[step={rk4_step:.3g}]"
    return f"exact[{'DOP853+Radau5' if stiff else 'DOP853'}, rtol={rtol:g}]"


_held = threading.local()  # each thread's workspaces for summary_run: made once, reused run after run


def _held_workspace(radau):
    """This thread's workspace for :func:`summary_run`, one for each ``radau`` (:func:`radau_marker`)."""
    held = getattr(_held, "workspaces", None)
    if held is None:
        held = _held.workspaces = {}
    ws = held.get(radau)
    if ws is None:
        ws = held[radau] = workspace(N_COEF, 0, radau)  # no stick points kept: their count is in the summary
    return ws


def summary_run(params: Parameters, law: ContactLaw | str = "paper", t_end: float | None = None, *,
                rtol: float = 1e-10, stop_when_settled: bool = True, stop_on=None,
                initial=None) -> tuple[np.ndarray, np.ndarray]:
    """One run's summary and final state on the per-point path (:func:`.driver.run_point`, no
    event log), for callers that run points one at a time and read only summaries (critical
    searches, the impact map). The run goes in this thread's workspace, made at its first call:
    nothing compiled allocates per run. Arguments as for :func:`simulate`; the numbers are
    :func:`simulate`'s (the same inputs and kernels).

    Returns ``(summary, final_state)``: the driver's summary vector (``driver.S_*``, the status
    ``non-finite`` when a user law failed the run, as in :func:`simulate`) and the state
    ``(x1, x2, x1dot, x2dot, W)`` at the end."""
    law = as_law(law)
    rtol = check_rtol(rtol)
    settle = check_bool("stop_when_settled", stop_when_settled)
    stop_kind, stop_count = _stop_on(stop_on)
    c, default_atol, seed_state, s = _packed(check_params(params), law, rtol)  # simulate's inputs, cached
    horizon = s.horizon if t_end is None else check_t_end(t_end, s.contact_time)
    y0 = seed_state if initial is None else _initial(params, initial)
    batch = (c[None], y0[None], np.array([horizon]), default_atol[None], np.array([s.max_step]))
    stiff_after = _stiff_after(True)
    options = (rtol, settle, stop_kind, stop_count, MAX_STEPS, MAX_EVENTS, stiff_after)
    if not _signals.installed:
        _signals.install()
    native = law.entry.native
    while True:
        if native is not None:
            native.reset()
        ws = _held_workspace(radau_marker(stiff_after))
        d.run_held(law.code, ws, batch, options, 0)
        if again_with_radau(ws[W_SUMMARY][d.S_STATUS]):
            continue
        woken = _woken(ws[W_SUMMARY][d.S_STATUS], native)
        if not (woken or _signals.deferred):
            break
        _signals.check(woken)  # raises for Ctrl-C or SIGTERM; after an old wake-up, runs again
    summary = ws[W_SUMMARY].copy()
    if native is not None and native.faulted and summary[d.S_STATUS] != d.SUCCESS:
        summary[d.S_STATUS] = d.NON_FINITE  # the law's NaN failed the run, as in simulate
    return summary, ws[W_Y][Y_STATE].copy()
