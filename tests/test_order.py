"""The steppers' orders of convergence, measured: DOP853 (order 8) and Radau IIA (order 5) take
fixed steps on a linear system, the contact of a bilateral linear spring (``abrate`` with
``alpha = 1``) between the projectile and the plate on its linear spring, whose exact solution is
``expm(A t)`` (scipy). Halving the step must divide the error by ``2^order``: a slope of 8 and 5 on
a log-log plot of the error against the step."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from phaseimpact import seed_parameters
from phaseimpact._jit import kernel
from phaseimpact.integrate import dop853, radau5
from phaseimpact.model.forms import PLAIN
from phaseimpact.model.laws import ContactLaw
from phaseimpact.model.rhs import ALPHA_, K_, KB_, KM_, M1_, M2_, PLAIN_PHASE, pack, rhs_integration

#: The system's fastest angular frequency times the horizon: a few radians, so that the largest
#: step resolves the motion and the smallest still has an error far above rounding.
OMEGA_T = 8.0


@kernel(python=True)
def _dop853_run(code, c, mode, side, u, h, n, K, fu, u_new, fu_new):
    """``n`` DOP853 steps of ``h`` from ``u`` (in place)."""
    rhs_integration(code, c, u, mode, side, fu)
    for _ in range(n):
        dop853.step(code, c, mode, side, u, fu, h, K, u_new, fu_new)
        for j in range(u.shape[0]):
            u[j] = u_new[j]
            fu[j] = fu_new[j]
    return 0


def _linear_system():
    """``(code, c, A, u0, T)``: the packed linear contact, its matrix on ``(x1, x2, x1dot, x2dot)``,
    a start inside the contact and the horizon."""
    law = ContactLaw("abrate", bilateral=True)  # P = K |delta|^alpha sign(delta): K delta at alpha = 1
    c = pack(seed_parameters(v=1.0, alpha=1.0), law)
    c[ALPHA_] = 1.0
    c[KM_] = 0.0  # a linear plate spring
    c[K_] = 3.0 * c[KB_]  # both springs matter
    m1, m2, k, kb = c[M1_], c[M2_], c[K_], c[KB_]
    A = np.array([[0.0, 0.0, 1.0, 0.0],
                  [0.0, 0.0, 0.0, 1.0],
                  [-k / m1, k / m1, 0.0, 0.0],
                  [k / m2, -(k + kb) / m2, 0.0, 0.0]])
    omega = np.max(np.abs(np.linalg.eigvals(A)))
    u0 = np.array([0.5 / omega, 0.0, 1.0, -0.3, 0.0, 0.0])  # (x1, x2, x1dot, x2dot, W, t), delta > 0
    return law.code, c, A, u0, OMEGA_T / omega, omega


def _error(u, A, u0, T, omega):
    exact = expm(A * T) @ u0[:4]
    scale = np.array([1.0 / omega, 1.0 / omega, 1.0, 1.0])  # lengths on the motion's own scale
    assert u[5] == pytest.approx(T, rel=1e-13)  # t' = 1: every step integrates the time exactly
    return np.max(np.abs(u[:4] - exact) / scale)


def _slope(steps, errors):
    return np.polyfit(np.log(steps), np.log(errors), 1)[0]


def test_dop853_is_of_order_8():
    code, c, A, u0, T, omega = _linear_system()
    K = np.empty((dop853.N_STAGES, dop853.N_STATE))
    work = np.empty((3, dop853.N_STATE))
    steps, errors = [], []
    for n in (8, 16, 32):
        u = u0.copy()
        _dop853_run(code, c, np.int64(PLAIN), np.int64(PLAIN_PHASE), u, T / n, n, K, work[0], work[1], work[2])
        steps.append(T / n)
        errors.append(_error(u, A, u0, T, omega))
    assert errors[-1] > 1e-12  # still far above rounding
    slope = _slope(steps, errors)
    assert 7.7 < slope < 8.4, (slope, errors)


def test_radau_iia_is_of_order_5():
    code, c, A, u0, T, omega = _linear_system()
    mode, side = np.int64(PLAIN), np.int64(PLAIN_PHASE)
    rtol = 1e-12
    atol = np.array([rtol / omega, rtol / omega, rtol, rtol, np.inf, rtol * T])
    steps, errors = [], []
    for n in (8, 16, 32, 64):
        u, fu = u0.copy(), np.empty(6)
        u_new, fu_new = np.empty(6), np.empty(6)
        rhs_integration(code, c, u, mode, side, fu)
        stiff = radau5.workspace(np.int64(radau5.STIFF_STEPS))
        radau5.enter(code, c, mode, side, u, fu, rtol, atol, stiff)
        h = T / n
        for i in range(n):
            radau5.fixed_step(code, c, mode, side, i * h, h, stiff, (u, fu, u_new, fu_new))
            u, fu = u_new.copy(), fu_new.copy()
        assert not radau5.failed(stiff[radau5.CTL])
        steps.append(h)
        errors.append(_error(u, A, u0, T, omega))
    assert errors[-1] > 1e-13
    slope = _slope(steps, errors)
    assert 4.75 < slope < 5.25, (slope, errors)
