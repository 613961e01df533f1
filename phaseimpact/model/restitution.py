"""Coefficient of restitution of Hunt-Crossley contact and its exact inverse (docs/physics.md §4)."""

from __future__ import annotations

import functools
import math

import numpy as np

from ..parameters import Parameters, is_number, require

__all__ = ["hunt_crossley_restitution", "kappa_for_restitution", "attainable_restitution", "check_attainable"]

#: Coefficients of restitution a law may be asked for.
RESTITUTION_RANGE = (1e-6, 1.0)

#: Taylor coefficients of e(a) at a = 0 (from the implicit equation of docs/physics.md §4).
_RESTITUTION_SERIES = (1.0, -2 / 3, 4 / 9, -44 / 135, 104 / 405, -40 / 189, 7648 / 42525, -2848 / 18225)
_SERIES_BELOW = 0.02  # the series' truncation error there is ~1e-15; W0's rounding error is ~eps/a^2


def hunt_crossley_restitution(a):
    """Exact restitution of Hunt-Crossley contact, ``a = kappa v0 / K`` (docs/physics.md §4).

    ``e = (1 + W0(-(1+a) exp(-(1+a)))) / a``. Next to ``a = 0`` the argument of ``W0`` sits on
    its branch point and rounding costs ``eps/a^2``; there the Taylor series is used instead.
    """
    from scipy.special import lambertw  # here, not at import: scipy.special costs 0.3 s of start-up

    a = np.asarray(a, dtype=float)
    safe = np.where(a >= _SERIES_BELOW, a, 1.0)
    w = lambertw(-(1 + safe) * np.exp(-(1 + safe)), 0).real
    series = np.polynomial.polynomial.polyval(a, _RESTITUTION_SERIES)
    return np.where(a >= _SERIES_BELOW, (1 + w) / safe, series)


def kappa_for_restitution(e: float, params: Parameters) -> float:
    """The ``kappa`` whose Hunt-Crossley contact restitutes exactly ``e`` at speed ``params.v``.

    Inverts :func:`hunt_crossley_restitution` (valid for a rigid or free target), for
    ``1e-6 <= e <= 1`` (below that ``a`` exceeds 1e6 and ``e ~ 1/a`` is all that is left).
    """
    if not is_number(e):
        raise TypeError(f"e = {e!r} has the wrong type ({type(e).__name__}); allowed: a number with 1e-6 <= e <= 1 "
                        "(the call is kappa_for_restitution(e, params))")
    if not isinstance(params, Parameters):
        raise TypeError(f"params = {params!r} has the wrong type ({type(params).__name__}); allowed: Parameters "
                        "(the call is kappa_for_restitution(e, params))")
    require("restitution", e, "a number with 1e-6 <= e <= 1", math.isfinite(e) and 1e-6 <= e <= 1)
    e = float(e)
    if e == 1:
        return 0.0
    from scipy.optimize import brentq  # here, not at import (start-up)

    a = brentq(lambda a: float(hunt_crossley_restitution(a)) - e, 1e-12, 1e12,
               xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)
    return a * params.K / params.v


@functools.cache
def attainable_restitution(name: str) -> tuple[float, float]:
    """The restitution a restitution law (:data:`~phaseimpact.model.laws.REGISTRY` name) delivers
    over the allowed ``e`` (:data:`RESTITUTION_RANGE`), as ``(lowest, 1)``.

    Its damping ``kappa = chi(e) K / v`` is Hunt-Crossley's with ``a = chi(e)``, whose exact
    restitution (rigid or free target) is :func:`hunt_crossley_restitution` of ``chi(e)``; ``chi``
    falls with ``e``, so the smallest ``e`` gives the lowest restitution. A bounded ``chi``
    (``3(1-e^2)/4``: at most 0.75) cannot restitute less than its bound does.
    """
    from .laws import REGISTRY

    chi = REGISTRY[name].chi
    return float(hunt_crossley_restitution(chi(RESTITUTION_RANGE[0]))), 1.0


def check_attainable(law) -> None:
    """Refuse a restitution law asked for a restitution it cannot deliver (``ValueError`` with the
    attainable range); any other law passes."""
    if law.restitution is None or law.entry.chi is None:
        return
    lowest, _ = attainable_restitution(law.name)
    if law.restitution < lowest:
        raise ValueError(f"restitution = {law.restitution!r} is out of range for law {law.name!r}: its damping "
                         f"{law.entry.description.split(', ')[-1]} restitutes at least e = {lowest:.3g} on a rigid "
                         f"target (the exact Hunt-Crossley restitution of chi); allowed: {lowest:.3g} <= restitution "
                         "<= 1 with this law, or any 1e-6 <= restitution <= 1 with hunt-crossley (exact inverse)")
