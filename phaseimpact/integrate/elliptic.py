r"""Jacobi's elliptic functions and the elliptic integral of the first kind, in plain arithmetic that
numba compiles for the CPU and as CUDA device functions alike: scalars in, scalars (or four slots
of the caller's array) out, no allocation, no call into C or Python, only ``math``.

* :func:`jacobi` ``(u, m, out)``: ``sn, cn, dn`` of ``(u | m)`` and the amplitude ``phi`` into
  ``out[:4]``. The arithmetic-geometric mean's descending Landen transformation and its backward
  recurrence for the amplitude (DLMF 22.20(ii); Abramowitz & Stegun 16.4), with the series near
  ``m = 0`` and ``m = 1`` (A&S 16.13, 16.15): the algorithm, branch points and order of operations
  of Cephes' ``ellpj`` (S. L. Moshier), which scipy's ``ellipj`` calls, so that ``sn``, ``cn`` and
  ``phi`` round alike (bit-identical on the test grid). ``dn`` is ``sqrt(1 - m sn^2)`` wherever
  that is at least 1/2 (every ``u`` for ``m <= 3/4``), and Cephes' ``cn / cos(phi_1 - phi_0)``
  (DLMF 22.20.5) elsewhere: the one deliberate difference from scipy, whose quotient is off by
  7 to 9.5 ulp within a period where the square root is within 1.5 (their nome series), and
  differs from it by up to 6.9e-14 for ``|u| <= 50`` (``benchmarks/elliptic.py``).
  ``0 <= m <= 1``; any other ``m`` gives NaN (scipy's too), and so does ``|u| > 709`` for
  ``m >= 1 - 1e-10``, where the series overflows (a series that holds within a quarter period).
* :func:`first_kind` ``(phi, m)``: ``F(phi | m)``, by Carlson's symmetric integral
  ``F = sin(phi) R_F(cos^2 phi, 1 - m sin^2 phi, 1)`` (DLMF 19.25.5) for the amplitude reduced to
  ``[-pi/2, pi/2]`` (``F(phi + n pi) = F(phi) + 2 n K``, DLMF 19.2.10), ``R_F`` by duplication
  (B. C. Carlson, "Numerical computation of real or complex elliptic integrals", Numer. Algorithms
  10 (1995) 13-26, algorithm of §2 with its fifth-order series). Any ``m <= 1``; ``m > 1`` or NaN
  gives NaN; at ``m = 1``, ``asinh(tan phi)`` below ``|phi| = pi/2`` and ``+inf`` from there on, for
  either sign of ``phi`` (as scipy's ``ellipkinc``).
* :func:`complete` ``(m)``: ``K(m) = pi / (2 AGM(1, sqrt(1 - m)))`` (DLMF 19.8.5). Any ``m < 1``;
  infinity at ``m = 1``, NaN above it.

``tests/test_elliptic.py`` checks them against scipy on a dense grid, compiles them to PTX and runs
them under numba's CUDA simulator; ``benchmarks/elliptic.py`` measures their errors and times beside scipy's C entry
points as ``flight.py`` calls them.
"""

from __future__ import annotations

import math

from .._jit import kernel

__all__ = ["jacobi", "first_kind", "complete"]

#: Cephes' MACHEP (2^-53): where the AGM's ``c / a`` counts as converged in :func:`jacobi`.
_MACHEP = 1.11022302462515654042e-16
#: Carlson's ``r`` for ``R_F``: the relative truncation error of its series is below it.
_CARLSON_R = 1.11022302462515654042e-16
#: ``(3 r)^(-1/6)``: the duplication stops once ``4^-n`` times the spread of ``x, y, z`` about their
#: mean, scaled by it, is below that mean.
_CARLSON_SPREAD = (3.0 * _CARLSON_R) ** (-1.0 / 6.0)
#: In :func:`complete` the AGM stops once ``|a - b| <= 1e-8 a``: the next mean is then exact to
#: ``(a - b)^2 / (16 a) <= 1e-17 a``, below rounding.
_AGM_GAP = 1e-8
#: 2^52: every double from there on is a whole number, and no amplitude is reduced by pi.
_WHOLE = 4503599627370496.0


@kernel(python=True)
def jacobi(u, m, out):
    """``sn, cn, dn`` of ``(u | m)`` into ``out[:3]`` and the amplitude ``phi`` into ``out[3]``
    (``0 <= m <= 1``; NaN in all four otherwise)."""
    if not 0.0 <= m <= 1.0:
        out[0] = out[1] = out[2] = out[3] = math.nan
        return
    if m < 1e-9:
        _jacobi_near_zero(u, m, out)
    elif m >= 0.9999999999:
        _jacobi_near_one(u, m, out)
    else:
        _jacobi_landen(u, m, out)


@kernel(forceinline=True)
def _jacobi_near_zero(u, m, out):
    """:func:`jacobi` for ``0 <= m < 1e-9``: A&S 16.13, first order in ``m``."""
    t = math.sin(u)
    b = math.cos(u)
    ai = 0.25 * m * (u - t * b)
    out[0] = t - ai * b
    out[1] = b + ai * t
    out[2] = 1.0 - 0.5 * m * t * t
    out[3] = u - ai


@kernel(forceinline=True)
def _jacobi_near_one(u, m, out):
    """:func:`jacobi` for ``1 - 1e-10 <= m <= 1``: A&S 16.15, first order in ``1 - m``."""
    if abs(u) > 709.0:  # cosh, sinh, exp overflow (Python's math raises): NaN, as scipy's mostly is
        out[0] = out[1] = out[2] = out[3] = math.nan
        return
    ai = 0.25 * (1.0 - m)
    b = math.cosh(u)
    t = math.tanh(u)
    phi = 1.0 / b
    twon = b * math.sinh(u)
    out[0] = t + ai * (twon - u) / (b * b)
    out[3] = 2.0 * math.atan(math.exp(u)) - 0.5 * math.pi + ai * (twon - u) / b
    ai *= t * phi
    out[1] = phi - ai * (twon - u)
    out[2] = phi + ai * (twon + u)


@kernel(forceinline=True)
def _jacobi_landen(u, m, out):
    """:func:`jacobi` for ``1e-9 <= m < 1 - 1e-10``: the AGM's descending Landen transformation and
    the backward recurrence for the amplitude."""
    # The AGM's levels 1 to 8 (a_i, c_i), in scalars: a kernel holds no array of its own. Eight
    # levels reach c / a <= 2^-53 for every m below 1 - 1e-10.
    a1 = a2 = a3 = a4 = a5 = a6 = a7 = a8 = 1.0
    c1 = c2 = c3 = c4 = c5 = c6 = c7 = c8 = 0.0
    a = 1.0
    b = math.sqrt(1.0 - m)
    c = math.sqrt(m)
    twon = 1.0
    level = 0
    while abs(c / a) > _MACHEP and level < 8:
        ai = a
        level += 1
        c = (ai - b) / 2.0
        t = math.sqrt(ai * b)
        a = (ai + b) / 2.0
        b = t
        twon *= 2.0
        if level == 1:
            a1, c1 = a, c
        elif level == 2:
            a2, c2 = a, c
        elif level == 3:
            a3, c3 = a, c
        elif level == 4:
            a4, c4 = a, c
        elif level == 5:
            a5, c5 = a, c
        elif level == 6:
            a6, c6 = a, c
        elif level == 7:
            a7, c7 = a, c
        else:
            a8, c8 = a, c
    # backward recurrence for the amplitude, from the last level down to the first
    phi = twon * a * u
    previous = phi
    for i in range(level, 0, -1):
        if i == 1:
            a, c = a1, c1
        elif i == 2:
            a, c = a2, c2
        elif i == 3:
            a, c = a3, c3
        elif i == 4:
            a, c = a4, c4
        elif i == 5:
            a, c = a5, c5
        elif i == 6:
            a, c = a6, c6
        elif i == 7:
            a, c = a7, c7
        else:
            a, c = a8, c8
        t = c * math.sin(phi) / a
        previous = phi
        phi = (math.asin(t) + phi) / 2.0
    sn = math.sin(phi)
    cn = math.cos(phi)
    out[0] = sn
    out[1] = cn
    out[2] = _delta_amplitude(m, sn, cn, phi, previous)
    out[3] = phi


@kernel(forceinline=True)
def _delta_amplitude(m, sn, cn, phi, previous):
    """:func:`jacobi`'s ``dn`` from the Landen branch's ``sn, cn``, its amplitude ``phi`` (``phi_0``)
    and that of the first level, ``previous`` (``phi_1``)."""
    # dn = sqrt(1 - m sn^2) wherever that is well conditioned (dn^2 >= 1/4: always for m <= 3/4);
    # Cephes takes it only where cn / cos(phi_1 - phi_0) (DLMF 22.20.5) divides by less than 0.1,
    # a quotient whose error grows with |u| (the amplitudes' difference loses digits). Where dn is
    # small (m -> 1, sn -> +-1) the quotient is the accurate one.
    square = 1.0 - m * sn * sn
    divisor = math.cos(phi - previous)
    return math.sqrt(square) if square >= 0.25 or abs(divisor) < 0.1 else cn / divisor


@kernel(python=True)
def first_kind(phi, m):
    """``F(phi | m)``, any ``phi`` and ``m <= 1`` (NaN for ``m > 1`` or NaN)."""
    if math.isnan(phi) or not m <= 1.0:
        return math.nan
    if m == 1.0:  # DLMF 19.6.8: the integral diverges at pi/2
        if abs(phi) >= 0.5 * math.pi:
            return math.inf  # of either sign of phi, as scipy's
        return math.asinh(math.tan(phi))
    if m == -math.inf:
        return 0.0
    if not abs(phi) < _WHOLE:  # no reduction left to do: F = 2 K phi / pi to rounding (inf: inf)
        turns = phi / math.pi
        value = 0.0
    else:
        # F(r + n pi) = F(r) + 2 n K with r in [-pi/2, pi/2]
        turns = float(math.floor(phi / math.pi + 0.5))
        reduced = phi - turns * math.pi
        sin_ = math.sin(reduced)
        cos_ = math.cos(reduced)
        x = cos_ * cos_
        y = x + (1.0 - m) * sin_ * sin_  # 1 - m sin^2 without its cancellation near m = 1, phi = pi/2
        z = 1.0
        # Carlson's R_F(x, y, z) by duplication
        mean0 = (x + y + z) / 3.0
        dx0, dy0 = mean0 - x, mean0 - y
        # the largest of |mean0 - x|, |mean0 - y|, |mean0 - z| (no max(): numba's CUDA target compiles
        # it as a device function of its own, which needs a device present)
        spread = abs(dx0) if abs(dx0) > abs(dy0) else abs(dy0)
        spread = _CARLSON_SPREAD * (spread if spread > abs(mean0 - z) else abs(mean0 - z))
        mean = mean0
        scale = 1.0  # 4^-n
        while scale * spread >= abs(mean):
            root_x, root_y, root_z = math.sqrt(x), math.sqrt(y), math.sqrt(z)
            lam = root_x * (root_y + root_z) + root_y * root_z
            x = 0.25 * (x + lam)
            y = 0.25 * (y + lam)
            z = 0.25 * (z + lam)
            mean = 0.25 * (mean + lam)
            scale *= 0.25
        dx = dx0 * scale / mean
        dy = dy0 * scale / mean
        dz = -(dx + dy)
        e2 = dx * dy - dz * dz
        e3 = dx * dy * dz
        series = 1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0
        value = sin_ * series / math.sqrt(mean)
        if turns == 0.0:
            return value
    # K(m) by the AGM, as in complete()
    a = 1.0
    b = math.sqrt(1.0 - m)
    while abs(a - b) > _AGM_GAP * a:
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return value + 2.0 * turns * (math.pi / (a + b))


@kernel(python=True)
def complete(m):
    """``K(m)``, ``m < 1``; infinity at ``m = 1``, NaN above it or for NaN."""
    if not m < 1.0:
        return math.inf if m == 1.0 else math.nan
    a = 1.0
    b = math.sqrt(1.0 - m)
    while abs(a - b) > _AGM_GAP * a:
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (a + b)  # pi / (2 AGM), the last mean taken in the division
