"""Entry points: :func:`simulate` (one run, a :class:`Trajectory`) and :func:`simulate_many`
(many runs in parallel threads, :class:`Columns`). Both check every argument before any work,
derive horizons and tolerances from the case's own scales, and call the one compiled driver."""

from __future__ import annotations

import functools
import math
import numbers
import operator
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .. import _signals
from ..model.forms import ALPHA_, DAMP_, GUARD_, IMPEDANCE_, K_, KB_, KM_, LAW_, M1_, M2_, RIGID_, SPRINGS_
from ..model.laws import ContactLaw, as_law
from ..model.rhs import N_COEF, initial_state, pack
from ..parameters import Parameters, is_number
from . import driver as d
from . import logs, radau5
from .events import EVENT_KINDS
from .record import W_SUMMARY, W_Y, Y_STATE, workspace, workspace_size
from .result import Columns, Trajectory
from .rk4 import run_rk4

__all__ = ["simulate", "simulate_many", "Scales", "scales", "INTEGRATORS", "RTOL_RANGE"]

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
    tau = _hertz_tau(alpha) if np.ndim(alpha) == 0 else np.array([_hertz_tau(a) for a in np.asarray(alpha).tolist()])
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
                        save_kind, times)
        codes = out[0].tolist()  # the summary's numbers: cheaper than reading entries of the array one by one
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


@dataclass(frozen=True)
class Batch:
    """Packed inputs of many runs of one law: coefficients (n, N_COEF), initial states (n, 5),
    horizons, absolute tolerances (n, 7, see :func:`state_tolerances`) and step caps (n,)."""

    law: ContactLaw
    C: np.ndarray
    Y0: np.ndarray
    t_end: np.ndarray
    atol: np.ndarray
    max_step: np.ndarray

    def __len__(self) -> int:
        return len(self.C)


#: Where :func:`simulate_many` runs: threads of this process, or a GPU (:mod:`phaseimpact.cuda`).
SIMULATE_MANY_BACKENDS = ("threads", "cuda")
#: Runs packed at a time by :func:`simulate_many` (any size gives the same numbers: runs are independent).
PACK_CHUNK = 2048


def pack_batch(params_seq, law: ContactLaw, t_end, rtol: float, initial=None) -> Batch:
    """Pack a sequence of :class:`Parameters` (one law) for :func:`run_batch`."""
    law = as_law(law)
    return _pack(_checked_sequence(params_seq), law, t_end, rtol, initial)


def _checked_sequence(params_seq) -> list:
    if isinstance(params_seq, Parameters) or not hasattr(params_seq, "__iter__"):
        raise TypeError(f"params_seq = {params_seq!r} has the wrong type ({type(params_seq).__name__}); allowed: a "
                        "sequence of Parameters")
    params_seq = list(params_seq)
    if not params_seq:
        raise ValueError("params_seq = [] is out of range; allowed: a non-empty sequence of Parameters")
    for i, p in enumerate(params_seq):
        if type(p) is not Parameters:  # the common case without formatting the name
            check_params(p, f"params_seq[{i}]")
    return params_seq


_NUMBER_FIELDS = operator.attrgetter("M1", "M2", "K", "Kb", "Km", "alpha", "kappa", "v")


def _pack(params_seq: list, law: ContactLaw, t_end, rtol: float, initial) -> Batch:
    """The rows of :func:`pack`, :func:`scales` and the initial states, on columns: per case only the
    fields are read (and what the law computes per case). The same IEEE operations in the same order
    as the per-case code (``hertz_indentation``'s powers stay per case), hence the same bits."""
    y0 = initial_state(0.0) if initial is None else np.concatenate([_checked_initial(initial), [0.0]])
    M1, M2, K, Kb, Km, alpha, kappa, v = np.array([_NUMBER_FIELDS(p) for p in params_seq]).reshape(-1, 8).T
    targets = [p.target for p in params_seq]
    springs = np.array([t == "plate" for t in targets])
    C = np.zeros((len(v), N_COEF))
    C[:, M1_], C[:, M2_], C[:, K_], C[:, ALPHA_] = M1, M2, K, alpha
    C[:, KB_], C[:, KM_] = np.where(springs, Kb, 0.0), np.where(springs, Km, 0.0)
    C[:, DAMP_] = _damping_column(law, params_seq, K, v, kappa)
    C[:, SPRINGS_], C[:, RIGID_], C[:, GUARD_] = springs, [t == "rigid" for t in targets], law.runaway_factor
    if law.entry.coefficients is not None:
        for i, p in enumerate(params_seq):
            own = law.coefficients(p)
            C[i, LAW_:LAW_ + len(own)] = own
    C[:, IMPEDANCE_] = [p.impedance if t == "infinite" else 0.0 for p, t in zip(params_seq, targets, strict=True)]
    indentation = np.array([p.hertz_indentation for p in params_seq])
    contact_time = hertz_contact_time(alpha, indentation, v)
    with np.errstate(divide="ignore"):  # Kb = 0: no period (Parameters.target_period)
        period = np.where(springs & (Kb != 0), 2 * math.pi * np.sqrt(M2 / Kb), math.inf)
    finite = np.isfinite(period)
    Y0 = np.tile(y0, (len(v), 1))
    if initial is None:
        Y0[:, 2] = v
    horizon = HORIZON_CAP_PERIODS * np.where(finite, period, contact_time)
    return Batch(law, C, Y0, _horizons(t_end, horizon, contact_time),
                 state_tolerances(rtol, indentation, v, M1, contact_time), np.where(finite, period / 8, math.inf))


def _damping_column(law: ContactLaw, params_seq: list, K: np.ndarray, v: np.ndarray, kappa: np.ndarray):
    """:meth:`ContactLaw.kappa` of every case (the same operations on columns)."""
    if law.damping_source in (None, "kappa"):
        return 0.0 if law.damping_source is None else kappa
    if law.entry.chi is not None:
        return law.entry.chi(law.restitution) * K / v
    return [law.kappa(p) for p in params_seq]  # the exact inverse: a root per case


def _horizons(t_end, default: np.ndarray, contact_time: np.ndarray) -> np.ndarray:
    """Each case's horizon: ``default``, or ``t_end`` checked against each case's contact time (the
    first case it is too short for is named, as :func:`check_t_end` per case would)."""
    if t_end is None:
        return default
    checked = check_t_end(t_end, contact_time[0])
    too_short = np.flatnonzero(~(MIN_HORIZON_CONTACT_TIMES * contact_time <= checked))
    if too_short.size:
        check_t_end(t_end, contact_time[too_short[0]])
    return np.full(len(contact_time), checked)


def run_batch(batch: Batch, *, rtol: float, settle: bool = True, stop_on=None, n_threads: int = 1,
              capacity: int = 32, stiff: bool = True, backend: str = "threads") -> Columns:
    """Run a packed batch in ``n_threads`` threads, or one GPU thread per run (``backend="cuda"``,
    checked by :func:`phaseimpact.cuda.check` first); each run is independent of the others, so the columns
    do not depend on the thread count or on how a sweep was cut into batches."""
    stop_kind, stop_count = _stop_on(stop_on)
    stiff_after = _stiff_after(stiff)
    n = len(batch)
    summary = np.empty((n, d.N_SUMMARY))
    st = np.empty((3, n, capacity))
    count = np.empty(n, np.int64)
    args = (batch.law.code, (batch.C, batch.Y0, batch.t_end, batch.atol, batch.max_step),
            (rtol, settle, stop_kind, stop_count, MAX_STEPS, MAX_EVENTS, stiff_after))
    outputs = (summary, st[0], st[1], st[2], count)
    threads = max(1, min(int(n_threads), n))
    # each thread's workspace, made here once for the chunk (the compiled runs allocate nothing)
    work = np.zeros((threads, workspace_size(batch.C.shape[1], capacity)))
    if not _signals.installed:
        _signals.install()
    native = batch.law.entry.native
    while True:
        if native is not None:
            native.reset()
        if backend == "cuda":
            from .. import cuda

            cuda.run_batch_cuda(*args, outputs)
        elif threads == 1:
            d.run_block(*args, 0, n, 1, outputs, work[0])
        else:  # thread k runs k, k + threads, ...: equal loads (run_block); the driver releases the GIL
            with ThreadPoolExecutor(threads) as pool:
                list(pool.map(lambda k: d.run_block(*args, k, n, threads, outputs, work[k]), range(threads)))
        woken = bool(np.any(summary[:, d.S_STATUS] == d.INTERRUPTED)) or _woken(d.SUCCESS, native)
        if not (woken or _signals.deferred):
            break
        _signals.check(woken)  # raises for Ctrl-C or SIGTERM; after an old wake-up, runs again
    if native is not None and native.faulted:
        _mark_law_faults(batch, summary, native, rtol, settle, stop_kind, stop_count, stiff_after)
    # the stick points of every run in run order: each run's first min(count, capacity) from the
    # buffers (one masked gather: a Python loop over the runs was the serial part of a threaded sweep)
    kept = np.arange(capacity) < np.minimum(count, capacity)[:, None]
    points = [st[j][kept] for j in range(3)]
    for i in np.flatnonzero(count > capacity)[::-1]:  # from the last, so earlier offsets stay valid
        # more stick phases than the buffer holds (near kappa_c): rerun this one for all of them
        out = _run_one(batch, i, rtol, settle, stop_kind, stop_count, stiff_after, native)
        k = int(count[i])
        full = np.empty((3, k))
        s = out[0]
        logs.stick_points(out[1], s[d.S_T_STOP], s[d.S_OUTCOME] == d.PERMANENT_STICK, full[0], full[1], full[2])
        offset = int(np.minimum(count[:i], capacity).sum())
        points = [np.concatenate([p[:offset], full[j], p[offset + capacity:]]) for j, p in enumerate(points)]
    return Columns.from_summary(summary, count, *points)


def _run_one(batch: Batch, i: int, rtol, settle, stop_kind, stop_count, stiff_after, native):
    """Run ``i`` of ``batch`` alone, summary and stick points (again after an old wake-up)."""
    while True:
        if native is not None:
            native.reset()
        out = d.run(batch.law.code, batch.C[i], batch.Y0[i], batch.atol[i], batch.t_end[i], batch.max_step[i],
                    (rtol, settle, stop_kind, stop_count, MAX_STEPS, MAX_EVENTS, stiff_after), d.SAVE_SUMMARY,
                    _NO_TIMES)
        codes = out[0].tolist()  # the summary's numbers: cheaper than reading entries of the array one by one
        woken = _woken(codes[d.S_STATUS], native)
        if not (woken or _signals.deferred):
            return out
        _signals.check(woken)


_held = threading.local()  # each thread's workspace for summary_run: made once, reused run after run


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
    options = (rtol, settle, stop_kind, stop_count, MAX_STEPS, MAX_EVENTS, _stiff_after(True))
    ws = getattr(_held, "workspace", None)
    if ws is None:
        ws = _held.workspace = workspace(N_COEF, 0)  # no stick points kept: their count is in the summary
    if not _signals.installed:
        _signals.install()
    native = law.entry.native
    while True:
        if native is not None:
            native.reset()
        d.run_held(law.code, ws, batch, options, 0)
        woken = _woken(ws[W_SUMMARY][d.S_STATUS], native)
        if not (woken or _signals.deferred):
            break
        _signals.check(woken)  # raises for Ctrl-C or SIGTERM; after an old wake-up, runs again
    summary = ws[W_SUMMARY].copy()
    if native is not None and native.faulted and summary[d.S_STATUS] != d.SUCCESS:
        summary[d.S_STATUS] = d.NON_FINITE  # the law's NaN failed the run, as in simulate
    return summary, ws[W_Y][Y_STATE].copy()


def summary_runs(law: ContactLaw, params_seq, t_ends, *, rtol: float, stop_when_settled: bool = True,
                 stop_on=None, arrivals=None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`summary_run` of every case of ``params_seq`` in one GPU launch, one thread each (the
    ``cuda`` backends of the critical curve and the orbit diagram): the summaries (n x
    ``driver.N_SUMMARY``) and final states (n x 5) it would give, from the same inputs. ``t_ends``:
    each run's horizon (None: the case's own); ``arrivals`` (n x 4, optional): each run's initial
    ``(x1, x2, x1dot, x2dot)`` (``W`` from the seed state, as ``initial`` does). The caller checks
    ``law`` and ``rtol`` and calls :func:`phaseimpact.cuda.check` first."""
    from .. import cuda

    packed = [_packed(p, law, rtol) for p in params_seq]  # summary_run's inputs, cached
    starts = np.stack([y0 for _, _, y0, _ in packed])
    if arrivals is not None:
        unusable = np.flatnonzero(~np.all(np.isfinite(arrivals), axis=1))
        if unusable.size:  # the ValueError summary_run would give
            _initial(params_seq[unusable[0]], arrivals[unusable[0]])
        starts[:, :4] = arrivals
    horizons = np.array([s.horizon if t_end is None else check_t_end(t_end, s.contact_time)
                         for (_, _, _, s), t_end in zip(packed, t_ends, strict=True)])
    batch = (np.stack([c for c, _, _, _ in packed]), starts, horizons,
             np.stack([atol for _, atol, _, _ in packed]), np.array([s.max_step for _, _, _, s in packed]))
    stop_kind, stop_count = _stop_on(stop_on)
    options = (rtol, check_bool("stop_when_settled", stop_when_settled), stop_kind, stop_count, MAX_STEPS,
               MAX_EVENTS, _stiff_after(True))
    n = len(packed)
    summary, final = np.empty((n, d.N_SUMMARY)), np.empty((n, 5))
    no_sticks = np.empty((n, 1))  # the stick points are not read: one slot each
    cuda.run_batch_cuda(law.code, batch, options, (summary, no_sticks, no_sticks.copy(), no_sticks.copy(),
                                                   np.empty(n, np.int64)), final)
    return summary, final


def _mark_law_faults(batch: Batch, summary, native, rtol, settle, stop_kind, stop_count, stiff_after) -> None:
    """Give the status ``non-finite`` to the failed runs whose user law raised or gave NaN or inf.

    The law's fault record is one for the whole batch (its runs share the compiled function, in
    several threads): each failed run is run again alone (the same numbers: runs are independent)
    to see whether its law faulted. Only failed runs can be the law's: a run whose law faulted on
    a rejected trial step and then went on is a success."""
    for i in np.flatnonzero(summary[:, d.S_STATUS] != d.SUCCESS):
        _run_one(batch, i, rtol, settle, stop_kind, stop_count, stiff_after, native)
        if native.faulted:
            summary[i, d.S_STATUS] = d.NON_FINITE


def simulate_many(params_seq, law: ContactLaw | str = "paper", t_end: float | None = None, *,
                  rtol: float = 1e-10, stop_when_settled: bool = True, stop_on=None, initial=None,
                  n_threads: int = 1, stiff: bool = True, backend: str = "threads") -> Columns:
    """Many impacts (one per :class:`Parameters` of ``params_seq``), summaries only, as columns.

    Same driver and arguments as :func:`simulate`; runs go in ``n_threads`` threads inside this
    process and the result is bit-identical for any thread count.

    Parameters
    ----------
    params_seq : sequence of Parameters
        One case per run (non-empty), all integrated with ``law``.
    law : ContactLaw or str, default "paper"
        A law of :data:`phaseimpact.model.LAWS` with its options, or its name.
    t_end : float, optional
        Horizon of every run, s (> 0, and at least ``1e-13`` contact times of each case); default:
        each run until its outcome settles, capped at its :attr:`Scales.horizon`.
    rtol : float, default 1e-10
        Relative tolerance, within :data:`RTOL_RANGE`; absolute tolerances from each case's scales.
    stop_when_settled : bool, default True
        Stop each run once nothing can change any more.
    stop_on : str or (str, int), optional
        Stop each run at the n-th event of a kind, as for :func:`simulate`.
    initial : 4 numbers, optional
        ``(x1, x2, x1dot, x2dot)`` (m, m, m/s, m/s) of every run instead of seed eq. 6.
    n_threads : int, default 1
        Threads of this process (>= 1); the compiled driver releases the GIL.
    stiff : bool, default True
        Radau IIA for stiff phases, as for :func:`simulate`.
    backend : {"threads", "cuda"}, default "threads"
        ``cuda``: one GPU thread per run, the same per-point kernel compiled for the GPU
        (``n_threads`` is then not read); refused before any work for a user law or without a
        usable GPU.

    Returns
    -------
    Columns
        One entry per run, in the order of ``params_seq``: codes of status, outcome and stop
        reason, the summary columns and the stick phases (a ragged array).

    Raises
    ------
    TypeError
        If ``params_seq`` is not a sequence of :class:`~phaseimpact.Parameters`.
    ValueError
        For an empty ``params_seq``, an unknown law, or any argument out of range (named in the
        message).

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate_many
    >>> base = seed_parameters(v=1.0)
    >>> c = simulate_many([base.replace(kappa=k) for k in (1e9, 1e12, 1e13)], "paper")
    >>> len(c), list(c.outcome_names())
    (3, ['permanent-stick', 'permanent-stick', 'ratchet-escape'])
    >>> c.n_stick.tolist()
    [1, 1, 2]
    """
    law = as_law(law)
    rtol = check_rtol(rtol)
    if t_end is not None:
        t_end = check_real("t_end", t_end, "a finite number > 0", lambda x: x > 0)
    if not (isinstance(n_threads, numbers.Integral) and not isinstance(n_threads, bool) and n_threads >= 1):
        raise ValueError(f"n_threads = {n_threads!r} is out of range; allowed: an integer >= 1")
    _stiff_after(stiff)
    check_bool("stop_when_settled", stop_when_settled)
    _stop_on(stop_on)
    if backend not in SIMULATE_MANY_BACKENDS:
        raise ValueError(f"backend = {backend!r} is out of range; allowed: one of {', '.join(SIMULATE_MANY_BACKENDS)}")
    if backend == "cuda":
        from .. import cuda

        cuda.check(law)
    params_seq = _checked_sequence(params_seq)  # every case, before any run
    if t_end is not None:  # long enough for the case of the longest contact
        check_t_end(t_end, max(hertz_contact_time(p.alpha, p.hertz_indentation, p.v) for p in params_seq))
    chunks = [params_seq[i:i + PACK_CHUNK] for i in range(0, len(params_seq), PACK_CHUNK)]
    options = {"rtol": rtol, "settle": stop_when_settled, "stop_on": stop_on, "n_threads": n_threads, "stiff": stiff,
               "backend": backend}
    if n_threads == 1 or len(chunks) == 1 or backend == "cuda":
        return _joined([run_batch(_pack(chunk, law, t_end, rtol, initial), **options) for chunk in chunks])
    # Packing is Python and serial (on columns ~2 us a case, 2-3 % of a run): a second thread packs the
    # next chunks while this one runs the last in the worker threads (whose compiled runs release the
    # GIL), so the packing does not add to the run time. The runs stay in this thread, where signals arrive.
    with ThreadPoolExecutor(1) as packer:
        packed = [packer.submit(_pack, chunk, law, t_end, rtol, initial) for chunk in chunks]
        try:
            return _joined([run_batch(batch.result(), **options) for batch in packed])
        except BaseException:  # Ctrl-C or SIGTERM: the chunks not yet packed are not packed
            packer.shutdown(cancel_futures=True)
            raise


def _joined(parts: list[Columns]) -> Columns:
    """The columns of consecutive chunks as one."""
    if len(parts) == 1:
        return parts[0]

    def cat(name):
        return np.concatenate([getattr(part, name) for part in parts])

    values = {name: np.concatenate([part.values[name] for part in parts]) for name in parts[0].values}
    return Columns(cat("status"), cat("outcome"), cat("stop_reason"), values, cat("stick_count"), cat("stick_t"),
                   cat("stick_delta"), cat("stick_dwell"))
