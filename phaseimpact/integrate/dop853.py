"""Dormand-Prince 8(5,3) steps and their 7th-order dense output, compiled.

A port of scipy's ``DOP853`` (``scipy/integrate/_ivp/rk.py``): the same tableau (imported from
scipy, not retyped), error estimate, step-size rule and interpolant, on the packed right-hand
side of :mod:`phaseimpact.model.rhs`. The driver owns the loop; these functions own one step.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from scipy.integrate._ivp import dop853_coefficients as _tableau

from ..model.rhs import rhs

N_STAGES = _tableau.N_STAGES  # 12
A = np.ascontiguousarray(_tableau.A, dtype=np.float64)
B = np.ascontiguousarray(_tableau.B, dtype=np.float64)
B2 = B.reshape(1, -1)  # as a one-row table for _combine
C = np.ascontiguousarray(_tableau.C, dtype=np.float64)
E3 = np.ascontiguousarray(_tableau.E3, dtype=np.float64)
E5 = np.ascontiguousarray(_tableau.E5, dtype=np.float64)
D = np.ascontiguousarray(_tableau.D, dtype=np.float64)
ORDER = 8
ERROR_EXPONENT = -1.0 / 8.0  # error estimator of order 7
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0


@numba.njit(cache=True)
def _combine(y, h, K, coef, row, n, out):
    """``out = y + h * sum_r coef[row, r] K[r]`` over the first ``n`` stages (zeros skipped).

    Indices, not row views: a view of a local array costs a reference-count pair in the hot loop.
    """
    a0 = a1 = a2 = a3 = a4 = 0.0
    for r in range(n):
        a = coef[row, r]
        if a != 0.0:
            a0 += a * K[r, 0]
            a1 += a * K[r, 1]
            a2 += a * K[r, 2]
            a3 += a * K[r, 3]
            a4 += a * K[r, 4]
    out[0] = y[0] + h * a0
    out[1] = y[1] + h * a1
    out[2] = y[2] + h * a2
    out[3] = y[3] + h * a3
    out[4] = y[4] + h * a4


@numba.njit(cache=True)
def _stage(code, c, mode, tmp, K, s, fs):
    rhs(code, c, tmp, mode, fs)
    for j in range(5):
        K[s, j] = fs[j]


@numba.njit(cache=True)
def step(code, c, mode, y, f, h, K, y_new, f_new, tmp):
    """One step of size ``h`` from ``(y, f)``: fills stages ``K`` (16, 5), ``y_new``, ``f_new``;
    returns the contact force at ``y_new``."""
    for j in range(5):
        K[0, j] = f[j]
    for s in range(1, N_STAGES):
        _combine(y, h, K, A, s, s, tmp)
        _stage(code, c, mode, tmp, K, s, f_new)
    _combine(y, h, K, B2, 0, N_STAGES, y_new)
    force = rhs(code, c, y_new, mode, f_new)
    for j in range(5):
        K[N_STAGES, j] = f_new[j]
    return force


@numba.njit(cache=True)
def error_norm(K, h, y, y_new, rtol, atol):
    """scipy's DOP853 error measure (< 1: accept); inf for a non-finite step."""
    e5 = 0.0
    e3 = 0.0
    for j in range(5):
        scale = atol[j] + max(abs(y[j]), abs(y_new[j])) * rtol
        a5 = 0.0
        a3 = 0.0
        for r in range(N_STAGES + 1):
            a5 += K[r, j] * E5[r]
            a3 += K[r, j] * E3[r]
        e5 += (a5 / scale) ** 2
        e3 += (a3 / scale) ** 2
    if not (math.isfinite(e5) and math.isfinite(e3)):
        return math.inf
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * 5.0)


@numba.njit(cache=True)
def dense_coefficients(code, c, mode, y, f, y_new, f_new, h, K, F, tmp):
    """The interpolant of the last step (three extra stages): fills ``F`` (7, 5)."""
    for s in range(N_STAGES + 1, 16):
        _combine(y, h, K, A, s, s, tmp)
        _stage(code, c, mode, tmp, K, s, F[0])
    for j in range(5):
        dy = y_new[j] - y[j]
        F[0, j] = dy
        F[1, j] = h * f[j] - dy
        F[2, j] = 2.0 * dy - h * (f_new[j] + f[j])
        for i in range(4):
            acc = 0.0
            for r in range(16):
                acc += D[i, r] * K[r, j]
            F[3 + i, j] = h * acc


@numba.njit(cache=True)
def dense_eval(F, y, t_old, h, t, out):
    """State at ``t`` on the interpolant ``F`` of the step ``[t_old, t_old + h]`` from ``y``."""
    x = (t - t_old) / h if h != 0 else 0.0
    for j in range(5):
        acc = 0.0
        for i in range(6, -1, -1):
            acc += F[i, j]
            acc *= x if (6 - i) % 2 == 0 else 1.0 - x
        out[j] = y[j] + acc


@numba.njit(cache=True)
def initial_step(code, c, mode, y, f, rtol, atol, interval, max_step, tmp, f1):
    """scipy's ``select_initial_step`` (Hairer, Norsett & Wanner, II.4), one extra evaluation."""
    d0 = 0.0
    d1 = 0.0
    for j in range(5):
        scale = atol[j] + abs(y[j]) * rtol
        d0 += (y[j] / scale) ** 2
        d1 += (f[j] / scale) ** 2
    d0 = math.sqrt(d0 / 5.0)
    d1 = math.sqrt(d1 / 5.0)
    h0 = 1e-6 * interval if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, interval)
    for j in range(5):
        tmp[j] = y[j] + h0 * f[j]
    rhs(code, c, tmp, mode, f1)
    d2 = 0.0
    for j in range(5):
        scale = atol[j] + abs(y[j]) * rtol
        d2 += ((f1[j] - f[j]) / scale) ** 2
    d2 = math.sqrt(d2 / 5.0) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6 * interval, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / ORDER)
    return min(100.0 * h0, h1, interval, max_step)
