"""Dormand-Prince 8(5,3) steps and their 7th-order dense output, compiled.

A port of scipy's ``DOP853`` (``scipy/integrate/_ivp/rk.py``): the same tableau, error estimate,
step-size rule and interpolant, on the packed right-hand side of :mod:`phaseimpact.model.rhs`.
The driver owns the loop; these functions own one step. The step, its error measure and the
interpolant's extra stages are scipy's tableau unrolled into straight-line code
(:mod:`._dop853_stages`, written by :mod:`._dop853_codegen`, which alone reads scipy; a test checks
the committed file against it). Stiff stretches of a phase go on with :mod:`.radau5`.
"""

from __future__ import annotations

import math

from .._jit import kernel
from ..model.rhs import rhs_integration
from ._dop853_stages import dense_coefficients, error_norm, step  # noqa: F401  (the step's API)

N_STATE = 6  # the integration state (see model.rhs.rhs_integration)
N_STAGES = 16  # rows of the stages array K: the step's 13 and the interpolant's 3 more
N_DENSE = 7  # rows of the interpolant F (dense_eval)
ORDER = 8
ERROR_EXPONENT = -1.0 / 8.0  # error estimator of order 7
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0


@kernel(forceinline=True)
def dense_eval(F, y, t_old, h, t, out):
    """State at ``t`` on the interpolant ``F`` of the step ``[t_old, t_old + h]`` from ``y``."""
    x = (t - t_old) / h if h != 0 else 0.0
    for j in range(N_STATE):
        acc = 0.0
        for i in range(N_DENSE - 1, -1, -1):
            acc += F[i, j]
            acc *= x if (N_DENSE - 1 - i) % 2 == 0 else 1.0 - x
        out[j] = y[j] + acc


@kernel
def initial_step(code, c, mode, side, y, f, tolerances, bounds, scratch):
    """scipy's ``select_initial_step`` (Hairer, Norsett & Wanner, II.4), one extra evaluation:
    ``tolerances = (rtol, atol)``, at most ``bounds = (interval, max_step)``, two scratch rows
    ``scratch = (tmp, f1)``."""
    rtol, atol = tolerances
    interval, max_step = bounds
    tmp, f1 = scratch
    d0 = 0.0
    d1 = 0.0
    for j in range(N_STATE):
        scale = atol[j] + abs(y[j]) * rtol
        d0 += (y[j] / scale) ** 2
        d1 += (f[j] / scale) ** 2
    d0 = math.sqrt(d0 / N_STATE)
    d1 = math.sqrt(d1 / N_STATE)
    h0 = 1e-6 * interval if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, interval)
    for j in range(N_STATE):
        tmp[j] = y[j] + h0 * f[j]
    rhs_integration(code, c, tmp, mode, side, f1)
    d2 = 0.0
    for j in range(N_STATE):
        scale = atol[j] + abs(y[j]) * rtol
        d2 += ((f1[j] - f[j]) / scale) ** 2
    d2 = math.sqrt(d2 / N_STATE) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6 * interval, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / ORDER)
    return min(100.0 * h0, h1, interval, max_step)
