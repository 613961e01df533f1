"""Many trajectories at once: an explicit DOP853 vectorised across parameter sets (sweeps).

The physics and the event logic are those of :func:`~phaseimpact.integrate._exact.integrate_exact`
(summary outputs only); what changes is the stepper. Every member of the batch carries its own
time, step size, mode and accept/reject decision, and one pass of the main loop makes one step
attempt for every member still running, with numpy arrays of shape ``(n, 5)``. The step-size
control is that of scipy's ``DOP853`` (``scipy/integrate/_ivp/rk.py``), with its tableau.

A member's trajectory is bit-identical whatever the batch it runs in (alone, or anywhere in a
batch of any size): every operation is elementwise, with no reduction across members, and the
sums over stages and over state components are written out in a fixed order instead of using
``np.dot`` (whose summation order depends on the array shape through BLAS). Fractional powers
of the step control are taken with square roots, which are correctly rounded.

Event zeros are located on the step itself: a first estimate of the crossing time from cubic
Hermite interpolation of the step, refined by re-taking the Runge-Kutta step from its start with
shortened sizes (a secant iteration on the step fraction, safeguarded by a bracket) until the
bracket is a few ulps of ``t`` wide or the event function is down to rounding noise; the state
at the zero is thus an 8th-order step, not an interpolant.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.integrate

from ..model import (
    Coefficients,
    ContactLaw,
    as_law,
    coefficients,
    contact_force,
    energy,
    initial_state,
    rhs,
    stack_coefficients,
)
from ..parameters import Parameters
from ._events import (
    DELTA,
    DELTADOT,
    FORCE_RATE,
    RUNAWAY_ENERGY_FACTOR,
    Event,
    crossed,
    departure_sign,
    event_values,
    initial_mode,
    transition,
)
from ._trajectory import Recorder, Save, Trajectory, state_scale

__all__ = ["simulate_batch"]

SAFETY = 0.9  # as scipy's RungeKutta
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
_EPS = np.finfo(float).eps
_EXTREMUM_TOL = 1e-8  # step fraction to which extremum events are located
_TINY = np.finfo(float).tiny
_N_STAGES = scipy.integrate.DOP853.n_stages
_STAGE_EVALS = _N_STAGES  # n_stages - 1 inner stages and f at the new point


def _weights(row):
    """Nonzero ``(stage, weight)`` pairs of a tableau row, as Python floats."""
    return [(j, float(w)) for j, w in enumerate(row) if w != 0]


_A = [_weights(scipy.integrate.DOP853.A[s, :s]) for s in range(_N_STAGES)]
_B = _weights(scipy.integrate.DOP853.B)
_E3 = _weights(scipy.integrate.DOP853.E3)
_E5 = _weights(scipy.integrate.DOP853.E5)
_ARRAY_FIELDS = Coefficients._fields[:6]  # M1 ... kappa; alpha and target are shared


def simulate_batch(params_list, law: ContactLaw | str = "paper", t_end: float = 0.01, *,
                   rtol: float = 1e-10, atol: float | None = None, stop_when_settled: bool = True,
                   max_steps: int = 1_000_000, max_events: int = 10_000) -> list[Trajectory]:
    """Integrate the impact of seed eq. 6 for many parameter sets at once (summary outputs).

    Parameters
    ----------
    params_list : sequence of Parameters
        One parameter set per trajectory. Sets with different ``alpha`` or ``target`` are
        integrated in separate groups.
    law : ContactLaw or str
        Contact law, shared by the whole batch.
    t_end : float
        Horizon, s (> 0).
    rtol : float
        Relative tolerance (1e-14 <= rtol < 1).
    atol : float, optional
        Absolute tolerance relative to the state scales of each member; defaults to ``rtol``.
    stop_when_settled : bool
        Stop a member once nothing can change any more (permanent stick, out of reach).
    max_steps, max_events : int
        Per-member limits; beyond them the member ends with status ``too-many-steps``.

    Returns
    -------
    list of Trajectory
        In the order of ``params_list``, with the fields of a summary run of
        :func:`phaseimpact.simulate` (no samples). ``nfev`` counts every right-hand-side
        evaluation made for the member, event location included.

    Notes
    -----
    A member's result does not depend on the other members: it is the same, bit for bit,
    alone or in any batch. Members finish independently; a failing member (runaway, step-size
    collapse, non-finite state, limits) gets a status and its last finite state, never NaN.
    """
    law = as_law(law)
    params_list = list(params_list)
    if not all(isinstance(p, Parameters) for p in params_list):
        raise TypeError("params_list must hold Parameters")
    if not (isinstance(t_end, (int, float)) and math.isfinite(t_end) and t_end > 0):
        raise ValueError(f"t_end = {t_end!r} is out of range; allowed: a finite number > 0")
    if not (isinstance(rtol, (int, float)) and 1e-14 <= rtol < 1):
        raise ValueError(f"rtol = {rtol!r} is out of range; allowed: 1e-14 <= rtol < 1")
    groups: dict = {}
    for i, p in enumerate(params_list):
        groups.setdefault((p.alpha, p.target), []).append(i)
    out: list = [None] * len(params_list)
    # Overflowing trial steps of a runaway are rejected by the error test, and the energy event
    # or the finiteness check ends the member with a status: the warnings carry no information.
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for members in groups.values():
            results = _integrate([params_list[i] for i in members], law, float(t_end), rtol, atol,
                                 stop_when_settled, max_steps, max_events)
            for i, trajectory in zip(members, results, strict=True):
                out[i] = trajectory
    return out


def _take(c: Coefficients, index) -> Coefficients:
    """Members ``index`` of batched coefficients (``alpha`` and ``target`` are shared)."""
    return c._replace(**{name: getattr(c, name)[index] for name in _ARRAY_FIELDS})


def _combine(weights, K):
    """``sum_j w_j K[j]`` accumulated in a fixed order (no BLAS, see the module docstring)."""
    (j, w), *rest = weights
    acc = w * K[j]
    for j, w in rest:
        acc = acc + w * K[j]
    return acc


def _rms(x):
    """RMS norm of each row of ``x`` (shape (m, 5)), summed in a fixed order."""
    acc = x[:, 0] * x[:, 0]
    for k in range(1, x.shape[1]):
        acc = acc + x[:, k] * x[:, k]
    return np.sqrt(acc / x.shape[1])


def _root8(x):
    """``x ** (1/8)``, by correctly rounded square roots."""
    return np.sqrt(np.sqrt(np.sqrt(x)))


def _dop853_step(y, f, h, c, law, mode):
    """One DOP853 step of size ``h`` (shape (m,)) per member; returns ``y_new, f_new, K``."""
    hh = h[:, None]
    K = [f]
    for s in range(1, _N_STAGES):
        K.append(rhs(y + hh * _combine(_A[s], K), c, law, mode))
    y_new = y + hh * _combine(_B, K)
    f_new = rhs(y_new, c, law, mode)
    K.append(f_new)
    return y_new, f_new, K


def _error_norm(K, h, scale):
    """scipy's DOP853 error norm (the 5th-order estimate, damped by the 3rd-order one)."""
    err5 = _rms(_combine(_E5, K) / scale)
    err3 = _rms(_combine(_E3, K) / scale)
    err5, err3 = err5 * err5, err3 * err3
    denom = err5 + 0.01 * err3
    zero = denom == 0  # nan (an overflowing trial step) must stay nan: it is rejected
    return np.where(zero, 0.0, np.abs(h) * err5 / np.sqrt(np.where(zero, 1.0, denom)))


def _initial_step(t, y, f, t_end, c, law, mode, rtol, atol):
    """scipy's ``select_initial_step`` (Hairer, Norsett & Wanner II.4), per member."""
    interval = t_end - t
    scale = atol + np.abs(y) * rtol
    d0, d1 = _rms(y / scale), _rms(f / scale)
    h0 = np.minimum(np.where((d0 < 1e-5) | (d1 < 1e-5), 1e-6, 0.01 * d0 / d1), interval)
    f1 = rhs(y + h0[:, None] * f, c, law, mode)
    d2 = _rms((f1 - f) / scale) / h0
    flat = (d1 <= 1e-15) & (d2 <= 1e-15)
    h1 = np.where(flat, np.maximum(1e-6, h0 * 1e-3), 1 / _root8(np.maximum(d1, d2) / 0.01))
    return np.minimum(np.minimum(100 * h0, h1), interval)


class _Active:
    """Arrays of the members still running; row ``r`` belongs to member ``ids[r]``."""

    _ROWS = ("ids", "t", "y", "f", "mode", "g_old", "h_abs", "rejected", "overflowed", "atol",
             "energy_limit")

    def __init__(self, **arrays):
        self.__dict__.update(arrays)

    def keep(self, rows) -> None:
        for name in self._ROWS:
            setattr(self, name, getattr(self, name)[rows])
        self.c = _take(self.c, rows)


def _integrate(params_list, law, t_end, rtol, atol, settle, max_steps, max_events) -> list[Trajectory]:
    """One group of members sharing ``alpha`` and ``target``."""
    n = len(params_list)
    cs = [coefficients(p, law) for p in params_list]
    c = stack_coefficients(cs)
    y0 = initial_state(np.array([p.v for p in params_list]))
    modes = np.array([initial_mode(law, y0[i], cs[i]) for i in range(n)], dtype=int)
    recorders = [Recorder(ci, law, Save("summary")) for ci in cs]
    for i, rec in enumerate(recorders):
        rec.event(Event("contact", 0.0, y0[i].copy(), float(contact_force(y0[i], cs[i], law, modes[i])),
                        int(modes[i])))
    step_rtol = max(rtol, 100 * _EPS)  # scipy raises smaller ones to this
    b = _Active(ids=np.arange(n), t=np.zeros(n), y=y0, f=np.empty((n, 5)), mode=modes,
                g_old=np.empty((n, 6)), h_abs=np.empty(n), rejected=np.zeros(n, dtype=bool),
                overflowed=np.zeros(n, dtype=bool),
                atol=np.array([(rtol if atol is None else atol) * state_scale(p, ci)
                               for p, ci in zip(params_list, cs, strict=True)]),
                energy_limit=RUNAWAY_ENERGY_FACTOR * energy(y0, c, law), c=c)
    nfev, nsteps = np.zeros(n, dtype=int), np.zeros(n, dtype=int)
    n_events = np.array([len(rec.events) for rec in recorders])
    max_force, max_delta = np.full(n, -np.inf), np.full(n, -np.inf)
    out: list = [None] * n

    def start_phase(rows, quiet):
        """What a new scipy solver does at a restart, plus the quiet start of the event columns."""
        cr, y, mode = _take(b.c, rows), b.y[rows], b.mode[rows]
        b.f[rows] = f = rhs(y, cr, law, mode)
        g = event_values(y, cr, law, mode, b.energy_limit[rows], f=f)
        # The run starts on this zero (and maybe others): give them the sign they depart with,
        # so that only a return to zero fires, as in the exact integrator.
        for j, q in enumerate(quiet):
            for col in {q, *np.flatnonzero(g[j] == 0)}:
                g[j, col] = departure_sign(col, y[j], mode[j]) * _TINY
        b.g_old[rows] = g
        b.h_abs[rows] = _initial_step(b.t[rows], y, f, t_end, cr, law, mode, step_rtol, b.atol[rows])
        b.rejected[rows] = False
        nfev[b.ids[rows]] += 2

    def finish(r, status, message, settled=False):
        i = b.ids[r]
        rec = recorders[i]
        rec.max_force = max(rec.max_force, float(max_force[i]))
        rec.max_indentation = max(rec.max_indentation, float(max_delta[i]))
        out[i] = rec.finish(params=params_list[i], t_end=t_end, t_stop=float(b.t[r]), y=b.y[r],
                            mode=int(b.mode[r]), settled=settled, status=status, message=message,
                            nfev=nfev[i], nsteps=nsteps[i], integrator=f"batch[DOP853, rtol={rtol:g}]")
        done[r] = True

    start_phase(np.arange(n), np.full(n, DELTA))
    while b.ids.size:
        done = np.zeros(b.ids.size, dtype=bool)
        # One attempt of scipy's RungeKutta._step_impl for every member.
        min_step = 10 * np.abs(np.nextafter(b.t, np.inf) - b.t)
        h_abs = np.where(b.rejected | (b.h_abs >= min_step), b.h_abs, min_step)
        collapsed = h_abs < min_step  # only after a rejection, as in scipy
        t_new = np.minimum(b.t + h_abs, t_end)
        h = t_new - b.t
        y_new, f_new, K = _dop853_step(b.y, b.f, h, b.c, law, b.mode)
        nfev[b.ids] += _STAGE_EVALS
        error = _error_norm(K, h, b.atol + np.maximum(np.abs(b.y), np.abs(y_new)) * step_rtol)
        # Unlike scipy, never accept a non-finite state: an overflow makes the scale infinite and
        # can zero the error estimate, while a shorter step would meet the runaway event. A state
        # that is non-finite down to the shortest step ends the member as "non-finite".
        finite = np.isfinite(y_new).all(axis=1)
        accepted = (error < 1) & ~collapsed & finite
        shrink = SAFETY / _root8(error)  # SAFETY * error ** (-1/8); nan -> MIN_FACTOR below
        grow = np.where(error == 0, MAX_FACTOR, np.minimum(MAX_FACTOR, shrink))
        grow = np.where(b.rejected, np.minimum(1.0, grow), grow)
        b.h_abs = np.abs(h) * np.where(accepted, grow, np.fmax(MIN_FACTOR, shrink))
        b.rejected = ~accepted
        nsteps[b.ids[accepted | collapsed]] += 1
        for r in np.flatnonzero(collapsed):
            if b.overflowed[r]:  # the last trial step, of the shortest size, was not finite
                finish(r, "non-finite", f"the state became non-finite at t = {b.t[r]:.6g} s")
            else:
                finish(r, "step-size-collapse",
                       f"t = {b.t[r]:.6g} s: Required step size is less than spacing between numbers.")
        b.overflowed = ~finite

        rows = np.flatnonzero(accepted)
        over = (nsteps[b.ids[rows]] >= max_steps) | (n_events[b.ids[rows]] >= max_events)
        for r in rows[over]:
            i = b.ids[r]
            finish(r, "too-many-steps", f"stopped at t = {t_new[r]:.6g} s after {nsteps[i]} steps and "
                                        f"{n_events[i]} events (limits {max_steps}, {max_events})")
        rows = rows[~over]

        cr = _take(b.c, rows)
        g_new = event_values(y_new[rows], cr, law, b.mode[rows], b.energy_limit[rows], f=f_new[rows])
        fired = crossed(b.g_old[rows], g_new)
        restarted = np.zeros(len(rows), dtype=bool)
        hit = np.flatnonzero(fired.any(axis=1))
        if hit.size:
            pair, cols = np.nonzero(fired[hit])
            pr = rows[hit[pair]]
            t_root, y_root, evals = _locate(
                b.t[pr], b.y[pr], b.f[pr], h[pr], t_new[pr], y_new[pr], f_new[pr],
                b.g_old[pr, cols], g_new[hit[pair], cols], cols, _take(b.c, pr), law, b.mode[pr],
                b.energy_limit[pr])
            np.add.at(nfev, b.ids[pr], evals)
            quiet = []
            for k in hit:
                r, i = rows[k], b.ids[rows[k]]
                mine = np.flatnonzero(pr == r)
                for j in sorted(mine, key=lambda j: (t_root[j], cols[j])):
                    change = transition(int(cols[j]), float(t_root[j]), y_root[j], int(b.mode[r]), cs[i],
                                        law, settle)
                    recorders[i].event(change.event)
                    n_events[i] += 1
                    if change.restart:
                        restarted[k] = True
                        b.t[r], b.y[r], b.mode[r] = t_root[j], change.state, change.mode
                        if change.stop == "runaway":
                            finish(r, "runaway", f"energy exceeded {RUNAWAY_ENERGY_FACTOR:g} x the impact "
                                                 f"energy at t = {b.t[r]:.6g} s: the contact force feeds "
                                                 "the motion")
                        elif change.stop == "settled":
                            finish(r, "success", f"outcome settled at t = {b.t[r]:.6g} s "
                                                 f"({change.event.kind})", settled=True)
                        elif b.t[r] >= t_end:
                            finish(r, "success", f"reached t_end = {t_end:g} s")
                        else:
                            quiet.append((r, cols[j]))
                        break
            if quiet:
                start_phase(*map(np.array, zip(*quiet, strict=True)))

        # Members whose step stands: advance them and fold the step end into the extremes,
        # which is all Recorder.extremes would do per step in the exact integrator.
        keep = ~restarted
        go, cr = rows[keep], _take(cr, keep)
        b.t[go], b.y[go], b.f[go], b.g_old[go] = t_new[go], y_new[go], f_new[go], g_new[keep]
        ids = b.ids[go]
        max_force[ids] = np.maximum(max_force[ids], contact_force(y_new[go], cr, law, b.mode[go]))
        max_delta[ids] = np.maximum(max_delta[ids], y_new[go, 0] - y_new[go, 1])
        for r in go[t_new[go] >= t_end]:
            finish(r, "success", f"reached t_end = {t_end:g} s")
        b.keep(~done)
    return out


def _locate(t, y, f, h, t_new, y_new, f_new, g_old, g_new, cols, c, law, mode, energy_limit):
    """Zeros of event columns ``cols`` inside steps ``(t, y) -> (t_new, y_new)``, one per pair.

    Returns the time and state just past each zero (on the side where the event has fired, at
    most a few ulps of ``t`` away) and the number of right-hand-side evaluations per pair.
    """
    m = len(t)
    evals = np.zeros(m, dtype=int)

    def on_interpolant(x, k):
        # Cubic Hermite interpolant of the step: cheap, and good to a small fraction of it.
        s, hk, d = x[:, None], h[k][:, None], y_new[k] - y[k]
        ys = y[k] + s * (hk * f[k] + s * ((3 * d - hk * (2 * f[k] + f_new[k]))
                                          + s * (hk * (f[k] + f_new[k]) - 2 * d)))
        np.add.at(evals, k, 1)
        g = event_values(ys, _take(c, k), law, mode[k], energy_limit[k])
        return g[np.arange(len(k)), cols[k]], ys

    def on_step(x, k):
        ck = _take(c, k)
        ys, fs, _ = _dop853_step(y[k], f[k], x * h[k], ck, law, mode[k])
        evals[k] += _STAGE_EVALS
        g = event_values(ys, ck, law, mode[k], energy_limit[k], f=fs)
        return g[np.arange(len(k)), cols[k]], ys

    every = np.arange(m)
    lo, hi, g_lo, g_hi = np.zeros(m), np.ones(m), g_old.copy(), g_new.copy()
    # A run restarted on this zero (g_old a signed tiny number) may leave it and come back within
    # the step, as in a grazing contact: bracket the return from a sample where g has left zero.
    back = np.flatnonzero(np.sign(on_interpolant(lo, every)[0]) != np.sign(g_old))
    grid = np.linspace(0, 1, 33)[1:]
    signs = np.sign(on_interpolant(np.tile(grid, back.size), np.repeat(back, grid.size))[0])
    away = signs.reshape(back.size, grid.size) == np.sign(g_old[back])[:, None]
    first = np.argmax(away, axis=1)
    returned = np.argmax(~away & (np.arange(grid.size) > first[:, None]), axis=1)  # > first: found
    lo[back] = np.where(returned > first, grid[returned - 1], grid[first])
    hi[back] = np.where(returned > first, grid[returned], 1.0)
    g_lo[back], g_hi[back] = on_interpolant(lo[back], back)[0], on_interpolant(hi[back], back)[0]
    stays = back[~away.any(axis=1)]  # the excursion is below what the step resolves: zero at 0
    g_hi[stays] = 0.0

    _, guess, _ = _find_zero(on_interpolant, lo, hi, g_lo, g_hi, y_new, np.full(m, 1e-10),
                             lo + g_lo / (g_lo - g_hi) * (hi - lo), (g_hi - g_lo) / (hi - lo))
    d = 1e-6  # the interpolant's slope is a good Newton slope for the step
    slope = (on_interpolant(guess + d, every)[0] - on_interpolant(guess - d, every)[0]) / (2 * d)
    tol = 4 * _EPS * np.maximum(np.abs(t_new) / np.abs(h), 1.0)
    # Extremum events (a force peak, the deepest indentation of a non-Filippov law) only record a
    # maximum, whose value is quadratic in the timing error: 1e-8 of the step is plenty and saves
    # most of the re-steps. Events that change the state or the mode keep the ulp-level bracket.
    extremum = (cols == FORCE_RATE) | ((cols == DELTADOT) & (not law.is_filippov))
    tol = np.where(extremum, np.maximum(tol, _EXTREMUM_TOL), tol)
    _, x, y_root = _find_zero(on_step, lo, hi, g_lo, g_hi, y_new, tol, guess, slope)
    x[stays], y_root[stays] = 0.0, y[stays]
    return np.where(x == 1, t_new, t + x * h), y_root, evals


def _find_zero(evaluate, lo, hi, g_lo, g_hi, y_hi, tol, guess, slope, max_iter=60):
    """Zeros of ``evaluate(x, k) -> (g, y)`` in brackets ``[lo, hi]``, vectorised over pairs ``k``.

    ``g_lo`` and ``g_hi`` have opposite signs (``hi`` stays on the side where the event has
    fired; ``g_hi = 0`` means ``hi`` is the zero). ``y_hi`` is the ``y`` at ``hi = 1``.
    Secant iteration safeguarded by the bracket: it starts at ``guess``, takes a Newton step
    with ``slope``, then secant steps on the last two iterates, and bisects when a step leaves
    the bracket. Trial points stay ``tol / 2`` inside the bracket, so it closes to ``tol`` even
    when the iterates approach the zero from one side. It also ends when ``g`` is within
    rounding: ``|g| <= |slope| tol``, or the smallest ``|g|`` has not halved in two iterations
    while ``hi`` is that close to zero too (rounding noise, whose sign means nothing, has been
    reached from both sides).

    Returns ``lo``, ``hi`` and the ``y`` evaluated at ``hi``.
    """
    m = len(g_lo)
    lo, hi, g_hi, y_hi = lo.copy(), hi.copy(), np.array(g_hi, dtype=float), y_hi.copy()
    known = hi == 1  # where y_hi is the y at hi
    sign = np.sign(g_lo)
    x_a, g_a, x_b, g_b = (np.zeros(m) for _ in range(4))  # the last two iterates
    smallest, stale = np.full(m, np.inf), np.zeros(m, dtype=int)
    k = np.flatnonzero(g_hi != 0)
    for it in range(max_iter):
        if k.size == 0:
            break
        a, b, half = lo[k], hi[k], 0.5 * tol[k]
        if it == 0:
            x = guess[k]
        else:
            x = x_b[k] - g_b[k] / (slope[k] if it == 1 else (g_b[k] - g_a[k]) / (x_b[k] - x_a[k]))
            x = np.where((x > a + half) & (x < b - half), x, 0.5 * (a + b))
        x = np.where(np.isfinite(x), np.clip(x, a + half, b - half), 0.5 * (a + b))
        g, ys = evaluate(x, k)
        x_a[k], g_a[k], x_b[k], g_b[k] = x_b[k], g_b[k], x, g
        zero = np.abs(g) <= np.abs(slope[k]) * tol[k]
        fired = (g * sign[k] <= 0) | zero
        up, down = k[fired], k[~fired]
        hi[up], g_hi[up], y_hi[up], known[up] = x[fired], g[fired], ys[fired], True
        lo[down] = x[~fired]
        stale[k] = np.where(np.abs(g) <= 0.5 * smallest[k], 0, stale[k] + 1)
        smallest[k] = np.minimum(smallest[k], np.abs(g))
        noise = (stale[k] >= 2) & (np.abs(g_hi[k]) <= 4 * smallest[k])
        k = k[(hi[k] - lo[k] > tol[k]) & ~zero & ~noise]
    k = np.flatnonzero(~known)
    if k.size:
        y_hi[k] = evaluate(hi[k], k)[1]
    return lo, hi, y_hi
