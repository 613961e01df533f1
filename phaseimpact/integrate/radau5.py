"""Radau IIA steps (order 5) for the stiff stretches of a phase, compiled.

Above the critical damping ``paper`` creeps: the inward slip is damped at the rate
``kappa |delta|^alpha / m`` (up to ~1e7 /s in the atlas) while the motion itself changes on the
plate's period (~1e-3 s). An explicit step is then held at its stability limit (DOP853:
``h lambda`` about 6, every other attempt rejected), whatever the tolerance. The driver watches
``h lambda`` (:func:`watch`) and, once it stays large, finishes the phase with this method:
Hairer & Wanner's RADAU5 (Solving ODEs II, IV.8) as scipy's ``Radau`` implements it (simplified
Newton on the transformed collocation system, Gustafsson's step predictor, the error estimate
filtered by the real factor), with RADAU5's own mapping of the user's tolerance onto the
method's internal one (:func:`enter`): its embedded estimate is of order 3, so it is asked for
``INNER_SCALE rtol^(2/3)`` (Hairer's factor 0.1 lowered to :data:`INNER_SCALE`) and delivers about
``rtol``.

The Jacobian is a forward difference over the four components that feed back (the work ``W`` and
the time ``t`` are quadratures); the collocation polynomial gives the dense output, written into
the driver's interpolant array so that events are located on it like on DOP853's.

All state travels in one tuple ``stiff`` of views of one buffer (:func:`carve`), read by the
positions ``WS`` ... ``F_START`` (constants: numba indexes the tuple's differently typed members
statically).

The small kernels (LU, solves, the Newton iteration) are ordinary compiled functions that LLVM
inlines or calls as it sees fit, not inlined by numba (``inline="always"``): numba types an inlined
function again inside each caller, which cost about 3 s more of a first compile in one process, and
stiff runs take the same time either way (their cost is in the right-hand sides).
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import allocating, kernel
from ..model.rhs import rhs_integration
from .dop853 import N_STATE
from .spacing import ulp_above

S6 = math.sqrt(6.0)
C1, C2 = (4.0 - S6) / 10.0, (4.0 + S6) / 10.0  # collocation points (the third is 1)
E1, E2, E3 = (-13.0 - 7.0 * S6) / 3.0, (-13.0 + 7.0 * S6) / 3.0, -1.0 / 3.0  # error estimate
# A = T diag(MU_REAL, MU_COMPLEX, conj) T^-1: one real and one complex system per Newton iteration.
MU_REAL = 3.0 + 3.0 ** (2.0 / 3.0) - 3.0 ** (1.0 / 3.0)
MU_RE = 3.0 + 0.5 * (3.0 ** (1.0 / 3.0) - 3.0 ** (2.0 / 3.0))
MU_IM = -0.5 * (3.0 ** (5.0 / 6.0) + 3.0 ** (7.0 / 6.0))
T = np.array([[0.09443876248897524, -0.14125529502095421, 0.03002919410514742],
              [0.25021312296533332, 0.20412935229379994, -0.38294211275726192],
              [1.0, 1.0, 0.0]])
TI = np.array([[4.17871859155190428, 0.32768282076106237, 0.52337644549944951],
               [-4.17871859155190428, -0.32768282076106237, 0.47662355450055044],
               [0.50287263494578682, -2.57192694985560522, 0.59603920482822492]])
P = np.array([[13.0 / 3.0 + 7.0 * S6 / 3.0, -23.0 / 3.0 - 22.0 * S6 / 3.0, 10.0 / 3.0 + 5.0 * S6],
              [13.0 / 3.0 - 7.0 * S6 / 3.0, -23.0 / 3.0 + 22.0 * S6 / 3.0, 10.0 / 3.0 - 5.0 * S6],
              [1.0 / 3.0, -8.0 / 3.0, 10.0 / 3.0]])  # collocation polynomial in x, x^2, x^3
NEWTON_MAXITER = 6
MIN_FACTOR, MAX_FACTOR = 0.2, 10.0
N_FEEDBACK = 4  # components the right-hand side reads: (x1 or w, x2, v1, v2)
_EPS = np.finfo(np.float64).eps
_SQRT_EPS = math.sqrt(_EPS)

#: The switch: DOP853's step is stability-bound when ``h lambda`` (lambda the damping rate of the
#: relative motion, :func:`phaseimpact.model.rhs.damping_rate`) nears its stability limit, about 6
#: on the negative real axis (Hairer's stiffness test uses 6.1). After ``STIFF_STEPS`` accepted steps
#: in a row above ``STIFF_H_LAMBDA`` the phase goes on with Radau (the driver's ``stiff_after``
#: argument; 0 keeps DOP853 throughout, for comparisons). A lower threshold (3) also switched
#: moderately stiff creeps (the seed at v = 1 m/s, kappa 1e12-1e13), where Radau took more steps
#: than DOP853 and the 20,000-kappa sweep 10 % longer (benchmarks/stiff.py has the atlas side).
STIFF_H_LAMBDA = 5.5
STIFF_STEPS = 5
#: Radau is asked for ``INNER_SCALE rtol^(2/3)``: RADAU5's mapping (its estimate is of order 3, the
#: solution of order 5) with Hairer's 0.1 lowered to 0.01, which brings the stick depths and
#: forces of stiff creeps to the accuracy DOP853 reaches at the same ``rtol`` (measured against
#: the oracle at rtol 1e-13 over 3000 atlas points: benchmarks/stiff.py).
INNER_SCALE = 0.01

# Rows of the float workspace ws (rows of N_STATE); the Jacobian's columns are the N_FEEDBACK
# components that feed back (the quadratures W and t make the systems block-triangular: only a
# 4x4 block is factorised, the last two rows follow by substitution).
J_, Z_, F_, W_, DW_, Q_, ERR_, SCALE_, ATOL_ = 0, 6, 9, 12, 15, 18, 21, 22, 23
WS_ROWS = 24
# Controller state ctl.
(ON, COUNT, SWITCH_AFTER, RTOL, H_OLD, ERR_OLD, JAC_CURRENT, LU_H, Q_BASE, Q_S, Q_H, HAVE_Q, FAILED) = range(13)
N_CTL = 13
# Members of the ``stiff`` tuple (:func:`carve`).
(WS, LU_REAL, LU_COMPLEX, ZC, PIV, CTL, TMP, FTMP, START, F_START) = range(10)
# Rows of the pivots ``stiff[PIV]``: those of the real and of the complex factors.
PIV_REAL, PIV_COMPLEX = 0, 1


#: The ``stiff`` tuple's numbers in one float64 buffer (:func:`carve`): the complex members first, at
#: even offsets (16-byte aligned where the buffer is, as a complex array of their own would be).
WORKSPACE_SIZE = 3 * N_FEEDBACK * N_FEEDBACK + 2 * N_STATE + 2 * N_FEEDBACK + WS_ROWS * N_STATE + N_CTL + 4 * N_STATE


@kernel(inline="always")  # typed in each caller: its views are the caller's own (counted where it counts)
def carve(buf):
    """The ``stiff`` tuple as views of ``buf`` (:data:`WORKSPACE_SIZE` float64 numbers): members at
    ``WS`` (the float rows ``J_`` ... ``ATOL_``), ``LU_REAL``, ``LU_COMPLEX`` (the factors), ``ZC`` (a
    complex vector), ``PIV`` (pivots), ``CTL`` (the controller, indices ``ON`` ... ``FAILED``), then
    four scratch states: ``TMP``, ``FTMP`` for the right-hand side and ``START``, ``F_START`` for
    :func:`fixed_step` (the kernels allocate nothing). Zeros in ``buf`` are :func:`clear`'s state."""
    nf2 = N_FEEDBACK * N_FEEDBACK
    lu_complex = buf[:2 * nf2].view(np.complex128).reshape((N_FEEDBACK, N_FEEDBACK))
    o = 2 * nf2
    zc = buf[o:o + 2 * N_STATE].view(np.complex128)
    o += 2 * N_STATE
    piv = buf[o:o + 2 * N_FEEDBACK].view(np.int64).reshape((2, N_FEEDBACK))
    o += 2 * N_FEEDBACK
    lu_real = buf[o:o + nf2].reshape((N_FEEDBACK, N_FEEDBACK))
    o += nf2
    ws = buf[o:o + WS_ROWS * N_STATE].reshape((WS_ROWS, N_STATE))
    o += WS_ROWS * N_STATE
    ctl = buf[o:o + N_CTL]
    o += N_CTL
    return (ws, lu_real, lu_complex, zc, piv, ctl, buf[o:o + N_STATE], buf[o + N_STATE:o + 2 * N_STATE],
            buf[o + 2 * N_STATE:o + 3 * N_STATE], buf[o + 3 * N_STATE:o + 4 * N_STATE])


@allocating(python=True)
def workspace(switch_after):
    """A fresh ``stiff`` tuple for one run (:func:`carve` of a buffer of its own), for the tests;
    the driver's runs carve theirs from their workspace (:func:`.record.carve`)."""
    stiff = carve(np.zeros(WORKSPACE_SIZE))
    stiff[CTL][SWITCH_AFTER] = switch_after  # 0: never (DOP853 throughout)
    return stiff


@kernel
def clear(ctl, switch_after):
    """The controller ``ctl`` (``stiff[CTL]``, the workspace's ``W_STIFF``) as :func:`workspace` makes
    it, for the next run in it: zeros, and the switch (nothing allocated)."""
    for k in range(N_CTL):
        ctl[k] = 0.0
    ctl[SWITCH_AFTER] = switch_after  # 0: never (DOP853 throughout)


@kernel
def clear_arrays(stiff):
    """Zeros in the arrays of the ``stiff`` tuple (``W_RADAU``) but its controller (:func:`clear`),
    for the next run in it: the Newton iterations start from what a fresh workspace holds, so a run's
    numbers do not depend on the runs before it in the same thread. Nothing where the engine has no
    stiff solver (``stiff`` None)."""
    if stiff is None:
        return
    ws, lu_real, lu_complex, zc, piv = stiff[WS], stiff[LU_REAL], stiff[LU_COMPLEX], stiff[ZC], stiff[PIV]
    for i in range(ws.shape[0]):
        for j in range(ws.shape[1]):
            ws[i, j] = 0.0
    for i in range(N_FEEDBACK):
        for j in range(N_FEEDBACK):
            lu_real[i, j] = 0.0
            lu_complex[i, j] = 0.0
        piv[PIV_REAL, i] = 0
        piv[PIV_COMPLEX, i] = 0
    for j in range(N_STATE):
        zc[j] = 0.0
        stiff[TMP][j] = 0.0
        stiff[FTMP][j] = 0.0
        stiff[START][j] = 0.0
        stiff[F_START][j] = 0.0


# The light controller below takes ``ctl`` alone (the workspace's ``W_STIFF``): the stiffness watch
# runs in every run, also in an engine compiled without the stiff solver's arrays.
@kernel
def reset(ctl):
    """A new phase starts explicit."""
    ctl[ON] = 0.0
    ctl[COUNT] = 0.0


@kernel
def active(ctl):
    return ctl[ON] != 0.0


@kernel(python=True)
def failed(ctl):
    """True once a step to a root could not be taken (the run must end with a failure status)."""
    return ctl[FAILED] != 0.0


@kernel
def watch(ctl, h_lambda):
    """Count accepted explicit steps with a large ``h lambda``."""
    ctl[COUNT] = ctl[COUNT] + 1.0 if h_lambda > STIFF_H_LAMBDA else 0.0


@kernel
def due(ctl):
    """True when the phase has turned stiff and the next step should be Radau's."""
    return ctl[ON] == 0.0 and ctl[SWITCH_AFTER] > 0.0 and ctl[COUNT] >= ctl[SWITCH_AFTER]


@kernel(python=True)
def enter(code, c, mode, side, u, fu, rtol, atol, stiff):
    """Switch the phase to Radau at ``(u, fu)``; returns the evaluations spent (the Jacobian)."""
    if stiff is None:  # an engine compiled without the stiff solver (record.carve): pruned, never run
        return 0
    ws, ctl = stiff[WS], stiff[CTL]
    inner = INNER_SCALE * rtol ** (2.0 / 3.0)
    ctl[ON] = 1.0
    ctl[RTOL] = inner
    for j in range(N_STATE):
        ws[ATOL_, j] = atol[j] * (inner / rtol)
    ctl[H_OLD] = 0.0
    ctl[ERR_OLD] = 0.0
    ctl[LU_H] = 0.0
    ctl[HAVE_Q] = 0.0
    ctl[JAC_CURRENT] = 1.0
    return jacobian(code, c, mode, side, u, fu, stiff)


@kernel
def jacobian(code, c, mode, side, u, fu, stiff):
    """Forward-difference Jacobian columns of the feedback components into ``ws[J_]``."""
    ws, ctl, tmp, ftmp = stiff[WS], stiff[CTL], stiff[TMP], stiff[FTMP]
    rtol = ctl[RTOL]
    for j in range(N_FEEDBACK):
        for i in range(N_STATE):
            tmp[i] = u[i]
        # the increment on the component's own scale (atol / rtol), not on its possibly tiny value
        tmp[j] = u[j] + _SQRT_EPS * max(abs(u[j]), ws[ATOL_, j] / rtol)
        step = tmp[j] - u[j]
        rhs_integration(code, c, tmp, mode, side, ftmp)
        for i in range(N_STATE):
            ws[J_ + i, j] = (ftmp[i] - fu[i]) / step
    return N_FEEDBACK


@kernel
def _lu(A, piv):
    """In-place LU with partial pivoting (real or complex), the diagonal stored inverted (the
    solves multiply: a complex division costs several multiplications); False when singular."""
    n = A.shape[0]
    for k in range(n):
        p = k
        big = abs(A[k, k].real) + abs(A[k, k].imag)
        for i in range(k + 1, n):
            size = abs(A[i, k].real) + abs(A[i, k].imag)
            if size > big:
                big = size
                p = i
        piv[k] = p
        if big == 0.0:
            return False
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
        inv = 1.0 / A[k, k]
        A[k, k] = inv
        for i in range(k + 1, n):
            A[i, k] *= inv
            m = A[i, k]
            for j in range(k + 1, n):
                A[i, j] -= m * A[k, j]
    return True


@kernel
def _solve(A, piv, b):
    """Solve ``A x = b`` in place with the factors of :func:`_lu` (the first ``len(A)`` entries of ``b``)."""
    for k in range(N_FEEDBACK):
        p = piv[k]
        if p != k:
            b[k], b[p] = b[p], b[k]
    for i in range(1, N_FEEDBACK):
        acc = b[i]
        for k in range(i):
            acc -= A[i, k] * b[k]
        b[i] = acc
    for i in range(N_FEEDBACK - 1, -1, -1):
        acc = b[i]
        for k in range(i + 1, N_FEEDBACK):
            acc -= A[i, k] * b[k]
        b[i] = acc * A[i, i]


@kernel
def _factorize(h, stiff):
    """LU of the feedback blocks of ``MU_REAL/h I - J`` and ``MU_COMPLEX/h I - J``; False when singular."""
    ws, lu_real, lu_complex, piv = stiff[WS], stiff[LU_REAL], stiff[LU_COMPLEX], stiff[PIV]
    for i in range(N_FEEDBACK):
        for j in range(N_FEEDBACK):
            lu_real[i, j] = -ws[J_ + i, j]
            lu_complex[i, j] = -ws[J_ + i, j]
        lu_real[i, i] += MU_REAL / h
        lu_complex[i, i] += complex(MU_RE / h, MU_IM / h)
    return _lu(lu_real, piv[PIV_REAL]) and _lu(lu_complex, piv[PIV_COMPLEX])


@kernel
def _solve_system(lu, piv, ws, h_over_mu, b):
    """Solve ``(mu/h I - J) x = b`` in place: the feedback block by its LU, the quadrature rows
    (whose columns of ``J`` are zero) by substitution."""
    _solve(lu, piv, b)
    for q in range(N_FEEDBACK, N_STATE):
        acc = b[q]
        for j in range(N_FEEDBACK):
            acc += ws[J_ + q, j] * b[j]
        b[q] = acc * h_over_mu


@kernel
def _norm(rows, scale):
    """RMS of ``rows`` (views of the workspace's rows: one signature for every caller, where row
    numbers passed as constants compiled a copy per call site) on ``scale``; inf when not finite."""
    acc = 0.0
    for i in range(rows.shape[0]):
        for j in range(N_STATE):
            acc += (rows[i, j] / scale[j]) ** 2
    return math.sqrt(acc / (rows.shape[0] * N_STATE)) if math.isfinite(acc) else math.inf


@kernel
def _collocation(code, c, mode, side, u, h, newton_tol, stiff):
    """Simplified Newton on the collocation system from the guess in ``ws[Z_]``; returns
    ``(converged, iterations, rate, evaluations)`` with the solution in ``ws[Z_]``."""
    ws, lu_real, lu_complex, zc, piv = stiff[WS], stiff[LU_REAL], stiff[LU_COMPLEX], stiff[ZC], stiff[PIV]
    ctl, tmp, ftmp = stiff[CTL], stiff[TMP], stiff[FTMP]
    rtol = ctl[RTOL]
    mu_real = MU_REAL / h
    mu_complex = complex(MU_RE / h, MU_IM / h)
    h_over_mu_real = h / MU_REAL
    h_over_mu_complex = h / complex(MU_RE, MU_IM)
    for j in range(N_STATE):
        ws[ERR_, j] = ws[ATOL_, j] + abs(u[j]) * rtol  # the Newton norm's scale
        for i in range(3):
            ws[W_ + i, j] = TI[i, 0] * ws[Z_, j] + TI[i, 1] * ws[Z_ + 1, j] + TI[i, 2] * ws[Z_ + 2, j]
    dw_norm_old = -1.0
    rate = -1.0
    evaluations = 0
    for k in range(NEWTON_MAXITER):
        finite = True
        for i in range(3):
            for j in range(N_STATE):
                tmp[j] = u[j] + ws[Z_ + i, j]
            rhs_integration(code, c, tmp, mode, side, ftmp)
            evaluations += 1
            for j in range(N_STATE):
                ws[F_ + i, j] = ftmp[j]
                finite = finite and math.isfinite(ftmp[j])
        if not finite:
            return False, k + 1, rate, evaluations
        for j in range(N_STATE):
            f0, f1, f2 = ws[F_, j], ws[F_ + 1, j], ws[F_ + 2, j]
            w0, w1, w2 = ws[W_, j], ws[W_ + 1, j], ws[W_ + 2, j]
            ws[DW_, j] = TI[0, 0] * f0 + TI[0, 1] * f1 + TI[0, 2] * f2 - mu_real * w0
            zc[j] = complex(TI[1, 0] * f0 + TI[1, 1] * f1 + TI[1, 2] * f2,
                            TI[2, 0] * f0 + TI[2, 1] * f1 + TI[2, 2] * f2) - mu_complex * complex(w1, w2)
        _solve_system(lu_real, piv[PIV_REAL], ws, h_over_mu_real, ws[DW_])
        _solve_system(lu_complex, piv[PIV_COMPLEX], ws, h_over_mu_complex, zc)
        for j in range(N_STATE):
            ws[DW_ + 1, j] = zc[j].real
            ws[DW_ + 2, j] = zc[j].imag
        dw_norm = _norm(ws[DW_:DW_ + 3], ws[ERR_])
        if dw_norm_old >= 0.0:
            rate = dw_norm / dw_norm_old
        if rate >= 0.0 and (rate >= 1.0 or rate ** (NEWTON_MAXITER - k) / (1.0 - rate) * dw_norm > newton_tol):
            return False, k + 1, rate, evaluations
        for j in range(N_STATE):
            for i in range(3):
                ws[W_ + i, j] += ws[DW_ + i, j]
            for i in range(3):
                ws[Z_ + i, j] = T[i, 0] * ws[W_, j] + T[i, 1] * ws[W_ + 1, j] + T[i, 2] * ws[W_ + 2, j]
        if dw_norm == 0.0 or (rate >= 0.0 and rate / (1.0 - rate) * dw_norm < newton_tol):
            return True, k + 1, rate, evaluations
        dw_norm_old = dw_norm
    return False, NEWTON_MAXITER, rate, evaluations


@kernel
def _guess(s, h, stiff):
    """Starting stages from the last collocation polynomial when this step starts on it (at its
    end: the next step; at its start: a fresh step to a root inside it); zero otherwise."""
    ws, ctl = stiff[WS], stiff[CTL]
    x0 = 1.0 if s == ctl[Q_S] else (0.0 if s == ctl[Q_BASE] else -1.0)
    if ctl[HAVE_Q] == 0.0 or x0 < 0.0:
        for i in range(3):
            for j in range(N_STATE):
                ws[Z_ + i, j] = 0.0
        return
    for i in range(3):
        x = x0 + h * (C1 if i == 0 else (C2 if i == 1 else 1.0)) / ctl[Q_H]
        for j in range(N_STATE):
            ws[Z_ + i, j] = (ws[Q_, j] * (x - x0) + ws[Q_ + 1, j] * (x * x - x0 * x0)
                             + ws[Q_ + 2, j] * (x * x * x - x0 * x0 * x0))


@kernel
def _predict(h_abs, h_old, err, err_old):
    """Gustafsson's predictive step factor (scipy's ``predict_factor``) before the safety factor."""
    if err == 0.0:
        return MAX_FACTOR
    multiplier = 1.0 if (h_old == 0.0 or err_old == 0.0) else h_abs / h_old * (err_old / err) ** 0.25
    return min(1.0, multiplier) * err**-0.25


@kernel
def _solve_stages(code, c, mode, side, s, u, fu, h, stiff):
    """Converge the collocation system for a step ``h`` (new factors, a fresh Jacobian once if the
    old one fails); returns ``(converged, iterations, rate, evaluations)``."""
    ctl = stiff[CTL]
    newton_tol = max(10.0 * _EPS / ctl[RTOL], min(0.03, math.sqrt(ctl[RTOL])))
    evaluations = 0
    _guess(s, h, stiff)
    while True:
        ok = True
        if ctl[LU_H] != h:
            ok = _factorize(h, stiff)
            ctl[LU_H] = h if ok else 0.0
        converged, iterations, rate = False, 0, -1.0
        if ok:
            converged, iterations, rate, spent = _collocation(code, c, mode, side, u, h, newton_tol, stiff)
            evaluations += spent
        if converged or ctl[JAC_CURRENT] != 0.0:
            return converged, iterations, rate, evaluations
        evaluations += jacobian(code, c, mode, side, u, fu, stiff)
        ctl[JAC_CURRENT] = 1.0
        ctl[LU_H] = 0.0
        _guess(s, h, stiff)


@kernel
def _finish(code, c, mode, side, span, u, ends, stiff):
    """The step's end ``ends = (u_new, fu_new)`` from the converged stages; the polynomial kept
    for the next guess, on ``span = (s, s_end, h)``. Returns the contact force at ``u_new``."""
    ws, ctl = stiff[WS], stiff[CTL]
    s, s_end, h = span
    u_new, fu_new = ends
    for j in range(N_STATE):
        u_new[j] = u[j] + ws[Z_ + 2, j]
        for k in range(3):
            ws[Q_ + k, j] = ws[Z_, j] * P[0, k] + ws[Z_ + 1, j] * P[1, k] + ws[Z_ + 2, j] * P[2, k]
    ctl[HAVE_Q] = 1.0
    ctl[Q_BASE] = s
    ctl[Q_S] = s_end
    ctl[Q_H] = h
    return rhs_integration(code, c, u_new, mode, side, fu_new)


@kernel
def attempt(code, c, mode, side, s, s_bound, h_abs, stiff, rows):
    """One accepted step from ``(s, u)`` (at most to ``s_bound``), first try ``h_abs``, into
    ``u_new``, ``fu_new``; ``rows = (u, fu, u_new, fu_new)``.

    Returns ``(ok, s_new, h_next, force_new, evaluations)``; ``ok`` False when the step size
    collapsed. The step's stages stay in the workspace for :func:`dense_coefficients`.
    """
    if stiff is None:  # an engine compiled without the stiff solver (record.carve): pruned, never run
        return False, s, h_abs, 0.0, 0
    ws, ctl = stiff[WS], stiff[CTL]
    u, fu, u_new, fu_new = rows
    rtol = ctl[RTOL]
    evaluations = 0
    rejected = False
    err = 0.0
    iterations = 0
    rate = -1.0
    s_new = s
    h = 0.0
    while True:
        if not h_abs >= 10.0 * ulp_above(s):  # NaN too, as in DOP853's attempt
            return False, s, h_abs, 0.0, evaluations
        s_new = min(s + h_abs, s_bound)
        h = s_new - s
        converged, iterations, rate, spent = _solve_stages(code, c, mode, side, s, u, fu, h, stiff)
        evaluations += spent
        if not converged:
            h_abs = 0.5 * h
            continue
        for j in range(N_STATE):
            z3 = ws[Z_ + 2, j]
            ws[SCALE_, j] = ws[ATOL_, j] + max(abs(u[j]), abs(u[j] + z3)) * rtol  # the error's scale
            ws[ERR_, j] = fu[j] + (E1 * ws[Z_, j] + E2 * ws[Z_ + 1, j] + E3 * z3) / h
        _solve_system(stiff[LU_REAL], stiff[PIV][PIV_REAL], ws, h / MU_REAL, ws[ERR_])
        err = _norm(ws[ERR_:ERR_ + 1], ws[SCALE_])
        if rejected and err > 1.0:
            # the estimate after a rejection, filtered once more (Hairer's rule for stiff components)
            tmp, ftmp = stiff[TMP], stiff[FTMP]
            for j in range(N_STATE):
                tmp[j] = u[j] + ws[ERR_, j]
            rhs_integration(code, c, tmp, mode, side, ftmp)
            evaluations += 1
            for j in range(N_STATE):
                ws[ERR_, j] = ftmp[j] + (E1 * ws[Z_, j] + E2 * ws[Z_ + 1, j] + E3 * ws[Z_ + 2, j]) / h
            _solve_system(stiff[LU_REAL], stiff[PIV][PIV_REAL], ws, h / MU_REAL, ws[ERR_])
            err = _norm(ws[ERR_:ERR_ + 1], ws[SCALE_])
        if err <= 1.0:
            break
        safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + iterations)
        h_abs = h * max(MIN_FACTOR, safety * _predict(h, ctl[H_OLD], err, ctl[ERR_OLD]))
        rejected = True
    safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + iterations)
    factor = min(MAX_FACTOR, safety * _predict(h, ctl[H_OLD], err, ctl[ERR_OLD]))
    recompute_jacobian = iterations > 2 and rate > 1e-3
    if not recompute_jacobian and factor < 1.2:
        factor = 1.0  # keep the step and with it the factorisation
    ctl[H_OLD] = h
    ctl[ERR_OLD] = max(err, 1e-2)
    force_new = _finish(code, c, mode, side, (s, s_new, h), u, (u_new, fu_new), stiff)
    evaluations += 1
    if recompute_jacobian:
        evaluations += jacobian(code, c, mode, side, u_new, fu_new, stiff)
        ctl[LU_H] = 0.0
    ctl[JAC_CURRENT] = 1.0 if recompute_jacobian else 0.0
    return True, s_new, h * factor, force_new, evaluations


@kernel(python=True)
def fixed_step(code, c, mode, side, s, h, stiff, rows):
    """A step of exactly ``h`` (to an event's root) from ``u`` into ``u_new``, ``fu_new`` (``rows =
    (u, fu, u_new, fu_new)``) without error control, split into equal sub-steps until Newton
    converges. Returns the evaluations spent."""
    if stiff is None:  # an engine compiled without the stiff solver (record.carve): pruned, never run
        return 0
    u, fu, u_new, fu_new = rows
    evaluations = 0
    start, f_start = stiff[START], stiff[F_START]
    for pieces in (1, 2, 4, 8, 16, 32, 64):
        part = h / pieces
        for j in range(N_STATE):
            start[j] = u[j]
            f_start[j] = fu[j]
        converged = True
        for k in range(pieces):
            converged, _, _, spent = _solve_stages(code, c, mode, side, s + k * part, start, f_start, part, stiff)
            evaluations += spent
            if not converged:
                break
            _finish(code, c, mode, side, (s + k * part, s + (k + 1) * part, part), start, (u_new, fu_new), stiff)
            evaluations += 1
            for j in range(N_STATE):
                start[j] = u_new[j]
                f_start[j] = fu_new[j]
        if converged:
            return evaluations
    # Newton never converged, even on 64 pieces: no state at the root; the driver ends the run
    # with a failure status (radau5.failed)
    stiff[CTL][FAILED] = 1.0
    for j in range(N_STATE):
        u_new[j] = u[j]
        fu_new[j] = fu[j]
    return evaluations


@kernel
def dense_coefficients(stiff, F):
    """The step's collocation polynomial in the driver's interpolant form (:func:`.dop853.dense_eval`:
    ``F0 x + F1 x(1-x) + F2 x^2(1-x)`` with the higher rows zero)."""
    if stiff is None:  # an engine compiled without the stiff solver (record.carve): pruned, never run
        return
    ws = stiff[WS]
    for j in range(N_STATE):
        q1, q2, q3 = ws[Q_, j], ws[Q_ + 1, j], ws[Q_ + 2, j]
        F[0, j] = q1 + q2 + q3
        F[1, j] = -q2 - q3
        F[2, j] = -q3
        for i in range(3, F.shape[0]):
            F[i, j] = 0.0
