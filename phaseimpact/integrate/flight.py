r"""Free flight in closed form: the driver's stepper for phases without a contact force.

Apart, the projectile moves uniformly and the target is a conservative oscillator of one degree
of freedom (docs/physics.md §3)::

    x1 = x1(0) + x1dot t,        M2 x2'' = -(Kb x2 + Km x2^3)

The oscillator is Duffing's without damping, solved by Jacobi's elliptic cosine: with
``a = Kb/M2``, ``b = Km/M2`` and the turning point ``A`` of its energy,
``x2 = A cn(omega t + psi | m)``, ``x2dot = -A omega sn dn``, ``omega^2 = a + b A^2``,
``m = b A^2 / (2 omega^2)`` (``0 <= m <= 1/2``); the harmonic case ``Km = 0`` is ``cos``/``sin``, a
free target moves uniformly and a rigid one stays at 0. The state at any time of the phase is then
exact to rounding, so a flight costs no right-hand sides, has no truncation error and needs no
error control: steps are only the brackets in which events are looked for, and they end where
the target passes its centre (:func:`next_centre`). Between two such passes ``x2dot`` is monotone
(``x2dot' = -S(x2)/M2`` keeps its sign), so ``deltadot = x1dot - x2dot`` has at most one zero and
``delta`` at most one extremum in a step: no pair of events can hide inside one. Once no event
can happen any more the phase goes to its end in one step (:func:`unreachable`).

``sn, cn, dn`` and the integrals ``F(phi | m)``, ``K(m)`` are :mod:`.elliptic`'s, plain arithmetic
that numba compiles for the CPU and the GPU alike (scipy's Cephes routines, which they match to
a few ulps, have no device version).

The orbit's invariants (kind, ``A``, ``omega``, ``m``, ``psi`` at a reference ``s``, and the
quarter period ``K(m)`` of the elliptic argument) are computed once per flight, at its start
(:func:`coefficients`, into rows 0 and 2 of an array of the driver's, row 1 being scratch for the
elliptic functions' outputs): a step then costs one evaluation of ``sn, cn, dn``.
"""

from __future__ import annotations

import math

from .._jit import kernel
from ..model.rhs import KB_, KM_, M2_, RIGID_, SPRINGS_, V1, V2, WORK, X1, X2, target_reach
from .elliptic import complete as _complete
from .elliptic import first_kind as _first_kind
from .elliptic import jacobi as _jacobi

__all__ = ["coefficients", "state_at", "next_centre", "unreachable"]


TIME = 5
# Kinds of target motion.
RIGID, FREE, HARMONIC, DUFFING = range(4)
# Layout of F[0] and F[2].
_KIND, _AMPLITUDE, _OMEGA, _M, _PSI, _S_REF = range(6)
_QUARTER = 0  # in F[2]


@kernel(python=True)
def coefficients(c, u, s, F):
    """The invariants of the flight through the integration state ``u`` at ``s`` into ``F[0]``
    (and the quarter period into ``F[2]``)."""
    x2, v2 = u[X2], u[V2]
    F[0, _S_REF] = s
    if c[RIGID_] > 0:
        F[0, _KIND] = RIGID
        return
    if c[SPRINGS_] == 0 or (c[KB_] == 0 and c[KM_] == 0):
        F[0, _KIND] = FREE
        return
    a = c[KB_] / c[M2_]
    b = c[KM_] / c[M2_]
    F[0, _KIND] = HARMONIC if b == 0 else DUFFING
    amplitude = target_reach(c, u)  # the turning point of the target's energy
    omega = math.sqrt(a + b * amplitude * amplitude)
    if amplitude == 0:  # at rest in the centre
        F[0, _AMPLITUDE] = 0.0
        F[0, _OMEGA] = omega
        F[0, _M] = 0.0
        F[0, _PSI] = 0.0
        F[2, _QUARTER] = 0.5 * math.pi
        return
    m = 0.5 * b * amplitude * amplitude / (omega * omega)
    # the amplitude phi of psi: cos(phi) = cn = x2 / A; sin(phi) = sn from sn dn = -v2 / (A omega),
    # the root of m s^4 - s^2 + q^2 = 0 below 1 (atan2 of both: accurate at the turning points and
    # at the centre alike)
    q = v2 / (amplitude * omega)
    s2 = 2.0 * q * q / (1.0 + math.sqrt(max(0.0, 1.0 - 4.0 * m * q * q)))
    phi = math.atan2(-math.copysign(math.sqrt(min(s2, 1.0)), v2), min(1.0, max(-1.0, x2 / amplitude)))
    F[0, _AMPLITUDE] = amplitude
    F[0, _OMEGA] = omega
    F[0, _M] = m
    F[0, _PSI] = phi if m == 0 else _first_kind(phi, m)
    F[2, _QUARTER] = 0.5 * math.pi if m == 0 else _complete(m)


@kernel(python=True)
def next_centre(F, s):
    """Where after ``s`` the target next passes its centre ``x2 = 0`` (``cn = 0``, the elliptic
    argument an odd multiple of ``K``); inf for a free or rigid target, which has none."""
    kind = F[0, _KIND]
    if kind == RIGID or kind == FREE or F[0, _AMPLITUDE] == 0:
        return math.inf
    omega, quarter = F[0, _OMEGA], F[2, _QUARTER]
    argument = omega * (s - F[0, _S_REF]) + F[0, _PSI]
    n = math.floor((argument - quarter) / (2.0 * quarter)) + 1.0
    centre = F[0, _S_REF] + ((2.0 * n + 1.0) * quarter - F[0, _PSI]) / omega
    if centre - s <= 1e-12 * quarter / omega:  # on a centre (to rounding): the next one
        centre += 2.0 * quarter / omega
    return centre


@kernel(python=True, forceinline=True)
def state_at(c, F, u0, s0, s, out):
    """The integration state at ``s`` of the flight that was at ``u0`` at ``s0`` (its invariants in
    ``F[0]``, from :func:`coefficients`); the time is ``s`` itself (a plain phase). At ``s0`` it
    is ``u0`` exactly, as an interpolant is at its step's start: an event the run restarted on is
    zero there, not a rounding residue that a root finder could take for a crossing."""
    if s == s0:
        for j in range(6):
            out[j] = u0[j]
        return
    tau = s - s0
    out[X1] = u0[X1] + u0[V1] * tau
    out[V1] = u0[V1]
    out[WORK] = u0[WORK]
    out[TIME] = s
    kind = F[0, _KIND]
    if kind == RIGID:
        out[X2] = u0[X2]
        out[V2] = u0[V2]
    elif kind == FREE:
        out[X2] = u0[X2] + u0[V2] * tau
        out[V2] = u0[V2]
    elif kind == HARMONIC:
        omega = F[0, _OMEGA]
        cos_, sin_ = math.cos(omega * tau), math.sin(omega * tau)
        out[X2] = u0[X2] * cos_ + u0[V2] / omega * sin_
        out[V2] = u0[V2] * cos_ - u0[X2] * omega * sin_
    elif F[0, _AMPLITUDE] == 0:
        out[X2] = 0.0
        out[V2] = 0.0
    else:
        amplitude, omega = F[0, _AMPLITUDE], F[0, _OMEGA]
        scratch = F[1]
        _jacobi(omega * (s - F[0, _S_REF]) + F[0, _PSI], F[0, _M], scratch)
        out[X2] = amplitude * scratch[1]
        out[V2] = -amplitude * omega * scratch[0] * scratch[2]


@kernel(python=True)
def unreachable(F, u):
    """Whether no event can happen any more in the flight whose invariants are in ``F``: the
    projectile recedes beyond the target's reach and faster than the target can move (so
    ``delta < 0`` and ``deltadot < 0`` from now on, and the energy is constant)."""
    v1 = u[V1]
    kind = F[0, _KIND]
    if kind == RIGID:
        return v1 <= 0
    if kind == FREE:
        return v1 - u[V2] <= 0
    amplitude = F[0, _AMPLITUDE]
    # |x2dot| = A omega |sn dn| <= A omega; the margins cover the rounding of A and omega
    return (v1 <= 0 and u[X1] + (1.0 + 1e-12) * amplitude < 0
            and -v1 > (1.0 + 1e-12) * amplitude * F[0, _OMEGA])
