r"""Equations of motion and contact laws (seed eq. 1, 2, 8; REFERENCE §1, §3).

State ``y = (x1, x2, x1dot, x2dot, W)`` with ``W = \int P d(delta)``, the work of the contact
force on the relative motion (its closed-loop value is the area of the force-indentation loop).
All functions are vectorised over leading axes: ``y`` has shape ``(..., 5)`` and any field of
:class:`Coefficients` may be an array broadcasting against ``y[..., 0]``.

Equations (seed eq. 1 and 8, with REFERENCE §3's corrections)::

    M1 x1'' = -P
    M2 x2'' = -Kb x2 - Km x2^3 + P            (plate target)

    delta = x1 - x2,  deltadot = x1dot - x2dot

Contact laws ``P(delta, deltadot)``:

==========================  ==========================================================
``abrate``                  ``K delta^alpha`` for ``delta > 0``, else 0 (eq. 2);
                            ``bilateral=True``: ``K |delta|^alpha sgn(delta)``
``hunt-crossley``           ``(K + kappa deltadot) delta^alpha`` for ``delta > 0``;
                            ``clamp=True`` keeps ``P >= 0``
``lankarani-nikravesh``,    Hunt-Crossley form with ``kappa = chi(e) K / v`` from a
``flores``, ``gonthier``    coefficient of restitution ``e``
``paper``                   ``(K + kappa deltadot) |delta|^alpha sgn(deltadot)`` (eq. 8 as
                            printed): a Filippov system, see below
==========================  ==========================================================

For ``paper`` the sign factor is carried by a *mode*: ``+1`` or ``-1`` while slipping with that
sign of ``deltadot``, ``0`` while stuck (``deltadot = 0``). While stuck the two bodies move as one
of mass ``M1 + M2`` on the target springs and the contact force is whatever keeps them together,
``F_req = M1 / (M1 + M2) * S(x2)`` with ``S(x2) = Kb x2 + Km x2^3``; the stick holds while
``|F_req| <= K |delta|^alpha``.

Symbols: ``M1, M2, K, Kb, Km, kappa, alpha`` as in the seed; ``v`` is the impact speed of eq. 6.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq
from scipy.special import lambertw

from .parameters import Parameters, require, require_choice

__all__ = [
    "LAWS",
    "RESTITUTION_LAWS",
    "ContactLaw",
    "Coefficients",
    "coefficients",
    "contact_force",
    "stick_force",
    "target_spring_force",
    "rhs",
    "jacobian",
    "energy",
    "initial_state",
    "hunt_crossley_restitution",
    "kappa_for_restitution",
    "damping_factor",
]

#: Restitution-based laws and their damping factor ``chi(e)`` in ``P = K delta^a (1 + chi deltadot / v)``.
RESTITUTION_LAWS = {
    "hunt-crossley-approx": lambda e: 1.5 * (1 - e),
    "lankarani-nikravesh": lambda e: 0.75 * (1 - e * e),
    "flores": lambda e: 1.6 * (1 - e) / e,
    "gonthier": lambda e: (1 - e * e) / e,
}
LAWS = ("abrate", "paper", "hunt-crossley", *RESTITUTION_LAWS)

X1, X2, V1, V2, WORK = range(5)


@dataclass(frozen=True)
class ContactLaw:
    """A contact law by name, with its options.

    Attributes
    ----------
    name : str
        One of :data:`LAWS`.
    restitution : float or None
        Coefficient of restitution ``e`` in (0, 1]. Required by the restitution laws; for
        ``hunt-crossley`` and ``paper`` it replaces ``kappa`` by the exact inverse
        (:func:`kappa_for_restitution`).
    bilateral : bool
        ``abrate`` only: the contact also pulls (``K |delta|^alpha sgn(delta)``, seed Fig. 3).
    clamp : bool
        Hunt-Crossley family only: clamp ``P >= 0`` (no adhesion at the end of contact).
    """

    name: str = "paper"
    restitution: float | None = None
    bilateral: bool = False
    clamp: bool = False

    def __post_init__(self):
        require_choice("law", self.name, LAWS)
        if self.restitution is not None:
            e = self.restitution
            require("restitution", e, "0 < e <= 1",
                    isinstance(e, (int, float)) and math.isfinite(e) and 0 < e <= 1)
        elif self.name in RESTITUTION_LAWS:
            raise ValueError(f"law {self.name!r} needs a restitution coefficient "
                             "(restitution in (0, 1])")
        if self.bilateral and self.name != "abrate":
            raise ValueError(f"bilateral = True is only allowed for law 'abrate', not {self.name!r}")
        if self.clamp and not self.is_hunt_crossley_form:
            raise ValueError(f"clamp = True is only allowed for the Hunt-Crossley laws, not {self.name!r}")

    @property
    def is_hunt_crossley_form(self) -> bool:
        return self.name == "hunt-crossley" or self.name in RESTITUTION_LAWS

    @property
    def is_filippov(self) -> bool:
        """True for eq. 8 as printed, whose sign factor needs stick/slip modes."""
        return self.name == "paper"

    @property
    def is_unilateral(self) -> bool:
        return self.name != "paper" and not self.bilateral

    def kappa(self, params: Parameters) -> float:
        """Effective damping ``kappa`` (N s/m^(1+alpha)) of this law for ``params``."""
        if self.name == "abrate":
            return 0.0
        if self.restitution is None:
            return params.kappa
        if self.name in RESTITUTION_LAWS:
            return damping_factor(self.name, self.restitution) * params.K / params.v
        return kappa_for_restitution(self.restitution, params)


def as_law(law) -> ContactLaw:
    """Accept a :class:`ContactLaw` or a law name."""
    return law if isinstance(law, ContactLaw) else ContactLaw(law)


class Coefficients(NamedTuple):
    """Numbers of the right-hand side, floats or arrays (batched runs)."""

    M1: np.ndarray
    M2: np.ndarray
    K: np.ndarray
    Kb: np.ndarray
    Km: np.ndarray
    kappa: np.ndarray
    alpha: float
    target: str


def coefficients(params: Parameters, law: ContactLaw) -> Coefficients:
    """The right-hand side's numbers for ``params`` under ``law`` (springs off unless plate)."""
    springs = params.target == "plate"
    return Coefficients(
        M1=params.M1, M2=params.M2, K=params.K,
        Kb=params.Kb if springs else 0.0, Km=params.Km if springs else 0.0,
        kappa=law.kappa(params), alpha=params.alpha, target=params.target,
    )


def stack_coefficients(items: list[Coefficients]) -> Coefficients:
    """Stack per-run coefficients into arrays; ``alpha`` and ``target`` must agree."""
    first = items[0]
    if any(c.alpha != first.alpha or c.target != first.target for c in items):
        raise ValueError("a batch must share alpha and target")
    arrays = [np.array([getattr(c, f) for c in items], dtype=float) for f in Coefficients._fields[:6]]
    return Coefficients(*arrays, alpha=first.alpha, target=first.target)


def _power(x, alpha):
    """``x**alpha`` for ``x >= 0``; the Hertz exponent 3/2 takes the cheap ``x*sqrt(x)``."""
    return x * np.sqrt(x) if alpha == 1.5 else x**alpha


def target_spring_force(x2, c: Coefficients):
    """``S(x2) = Kb x2 + Km x2^3``, N."""
    return (c.Kb + c.Km * x2 * x2) * x2


def contact_force(y, c: Coefficients, law: ContactLaw, mode=None):
    """Contact force ``P`` (N, positive pushing the bodies apart) for states ``y``.

    ``mode`` (``paper`` only) is the sign of ``deltadot`` while slipping, 0 while stuck; ``None``
    reads eq. 8 literally, with ``sgn(deltadot)`` and no stick (what a fixed-step method sees).
    """
    delta = y[..., X1] - y[..., X2]
    deltadot = y[..., V1] - y[..., V2]
    if law.is_filippov:
        sign = np.sign(deltadot) if mode is None else mode
        slip = (c.K + c.kappa * deltadot) * _power(np.abs(delta), c.alpha) * sign
        return slip if mode is None else np.where(mode == 0, stick_force(y, c), slip)
    if law.bilateral:
        return c.K * _power(np.abs(delta), c.alpha) * np.sign(delta)
    hertz = _power(np.maximum(delta, 0.0), c.alpha)
    if law.name == "abrate":
        return c.K * hertz
    force = (c.K + c.kappa * deltadot) * hertz
    return np.maximum(force, 0.0) if law.clamp else force


def stick_force(y, c: Coefficients):
    """Force that keeps the projectile with the target while stuck, ``F_req``, N."""
    return c.M1 / (c.M1 + c.M2) * target_spring_force(y[..., X2], c)


def rhs(y, c: Coefficients, law: ContactLaw, mode=None):
    """Time derivative of ``y`` (shape ``(..., 5)``); ``mode`` as in :func:`contact_force`."""
    P = contact_force(y, c, law, mode)
    a1 = -P / c.M1
    if c.target == "rigid":
        a2 = np.zeros_like(a1)
    else:
        a2 = (P - target_spring_force(y[..., X2], c)) / c.M2
    if law.is_filippov and mode is not None:
        common = -target_spring_force(y[..., X2], c) / (c.M1 + c.M2)
        if c.target == "rigid":
            common = np.zeros_like(common)
        stuck = mode == 0
        a1 = np.where(stuck, common, a1)
        a2 = np.where(stuck, common, a2)
    out = np.empty(np.broadcast_shapes(np.shape(y), np.shape(P) + (5,)))  # cheaper than np.stack
    out[..., X1], out[..., X2] = y[..., V1], y[..., V2]
    out[..., V1], out[..., V2] = a1, a2
    out[..., WORK] = P * (y[..., V1] - y[..., V2])
    return out


def jacobian(y, c: Coefficients, law: ContactLaw, mode=None) -> np.ndarray:
    """Exact Jacobian of the mechanical right-hand side ``(x1, x2, x1dot, x2dot)``, shape (4, 4).

    At ``delta = 0`` the Hertz stiffness ``alpha K |delta|^(alpha-1)`` is exactly zero (for
    ``alpha > 1``), which a finite difference would blur.
    """
    y = np.asarray(y, dtype=float)
    delta, deltadot = y[X1] - y[X2], y[V1] - y[V2]
    ad = abs(delta)
    spring_rate = c.Kb + 3.0 * c.Km * y[X2] ** 2
    J = np.zeros((4, 4))
    J[0, 2] = J[1, 3] = 1.0
    if law.is_filippov and mode == 0:
        M = c.M1 + c.M2
        if c.target != "rigid":
            J[2, 1] = J[3, 1] = -spring_rate / M
        return J
    stiffness = c.alpha * ad ** (c.alpha - 1) if ad > 0 else 0.0
    if law.is_filippov:
        sign = np.sign(deltadot) if mode is None else mode
        P_delta = sign * (c.K + c.kappa * deltadot) * stiffness * np.sign(delta)
        P_rate = sign * c.kappa * ad**c.alpha
    elif law.bilateral:
        P_delta, P_rate = c.K * stiffness, 0.0
    elif delta > 0 and not (law.clamp and contact_force(y, c, law) <= 0):
        P_delta, P_rate = (c.K + c.kappa * deltadot) * stiffness, c.kappa * ad**c.alpha
    else:
        P_delta = P_rate = 0.0
    dP = np.array([P_delta, -P_delta, P_rate, -P_rate])
    J[2] = -dP / c.M1
    if c.target != "rigid":
        J[3] = dP / c.M2
        J[3, 1] -= spring_rate / c.M2
    return J


def contact_potential(delta, c: Coefficients, law: ContactLaw):
    """Hertz potential ``K |delta|^(alpha+1) / (alpha+1)`` (only ``delta > 0`` if unilateral), J."""
    d = np.maximum(delta, 0.0) if law.is_unilateral else np.abs(delta)
    return c.K * d * _power(d, c.alpha) / (c.alpha + 1)


def energy(y, c: Coefficients, law: ContactLaw):
    """Mechanical energy (REFERENCE §4): kinetic + target springs + Hertz potential, J."""
    x2 = y[..., X2]
    kinetic = 0.5 * c.M1 * y[..., V1] ** 2 + 0.5 * c.M2 * y[..., V2] ** 2
    x2sq = x2 * x2  # products, not pow: elementwise results must not depend on the array shape
    springs = (0.5 * c.Kb + 0.25 * c.Km * x2sq) * x2sq
    return kinetic + springs + contact_potential(y[..., X1] - x2, c, law)


def initial_state(v, shape=()):
    """Seed eq. 6: ``x1 = x2 = 0``, ``x1dot = v``, ``x2dot = 0``, no work done."""
    y = np.zeros(np.broadcast_shapes(shape, np.shape(v)) + (5,))
    y[..., V1] = v
    return y


def damping_factor(name: str, e: float) -> float:
    """``chi(e)`` of a restitution law (REFERENCE §3)."""
    require_choice("law", name, tuple(RESTITUTION_LAWS))
    return RESTITUTION_LAWS[name](e)


#: Taylor coefficients of e(a) at a = 0 (from the implicit equation of REFERENCE §4).
_RESTITUTION_SERIES = (1.0, -2 / 3, 4 / 9, -44 / 135, 104 / 405, -40 / 189, 7648 / 42525, -2848 / 18225)
_SERIES_BELOW = 0.02  # the series' truncation error there is ~1e-15; W0's rounding error is ~eps/a^2


def hunt_crossley_restitution(a):
    """Exact restitution of Hunt-Crossley contact, ``a = kappa v0 / K`` (REFERENCE §4).

    ``e = (1 + W0(-(1+a) exp(-(1+a)))) / a``. Next to ``a = 0`` the argument of ``W0`` sits on
    its branch point and rounding costs ``eps/a^2``; there the Taylor series is used instead.
    """
    a = np.asarray(a, dtype=float)
    safe = np.where(a >= _SERIES_BELOW, a, 1.0)
    w = lambertw(-(1 + safe) * np.exp(-(1 + safe)), 0).real
    series = np.polynomial.polynomial.polyval(a, _RESTITUTION_SERIES)
    return np.where(a >= _SERIES_BELOW, (1 + w) / safe, series)


def kappa_for_restitution(e: float, params: Parameters) -> float:
    """The ``kappa`` whose Hunt-Crossley contact restitutes exactly ``e`` at speed ``params.v``.

    Inverts :func:`hunt_crossley_restitution` (valid for a rigid or free target).
    """
    require("restitution", e, "0 < e <= 1", math.isfinite(e) and 0 < e <= 1)
    if e == 1:
        return 0.0
    a = brentq(lambda a: float(hunt_crossley_restitution(a)) - e, 1e-9, 1e9,
               xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)
    return a * params.K / params.v
