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

    Parameters
    ----------
    a : float or array_like
        The dimensionless damping ``kappa v0 / K`` (``kappa`` in N s/m^(alpha+1), ``v0`` the
        impact speed in m/s, ``K`` in N/m^alpha), ``a >= 0``.

    Returns
    -------
    numpy.ndarray
        The coefficient of restitution, of the shape of ``a`` (a 0-d array for a scalar); 1 at
        ``a = 0``, falling towards ``1/a`` for large ``a``.

    Examples
    --------
    >>> from phaseimpact.model import hunt_crossley_restitution
    >>> print(f"{float(hunt_crossley_restitution(0.1)):.6f}")
    0.937476
    >>> hunt_crossley_restitution([0.0, 0.1, 1.0]).round(4)
    array([1.    , 0.9375, 0.5936])
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

    Parameters
    ----------
    e : float
        The coefficient of restitution, ``1e-6 <= e <= 1``.
    params : Parameters
        The model's parameters: the contact stiffness ``K`` (N/m^alpha) and the impact speed
        ``v`` (m/s) are read.

    Returns
    -------
    float
        ``kappa`` (N s/m^(alpha+1), N s/m^2.5 for Hertz) with ``kappa v / K`` the root of
        ``hunt_crossley_restitution(a) = e`` (to a few ulps); 0.0 for ``e = 1``.

    Raises
    ------
    TypeError
        If ``e`` is not a number or ``params`` not :class:`~phaseimpact.Parameters`.
    ValueError
        If ``e`` is not finite or outside ``[1e-6, 1]``.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.model import hunt_crossley_restitution, kappa_for_restitution
    >>> p = seed_parameters(v=1.0)
    >>> kappa = kappa_for_restitution(0.8, p)
    >>> print(f"{kappa:.4g} N s/m^2.5, a = {kappa * p.v / p.K:.4g}")
    8.119e+09 N s/m^2.5, a = 0.3731
    >>> print(f"{float(hunt_crossley_restitution(kappa * p.v / p.K)):.12f}")
    0.800000000000
    >>> kappa_for_restitution(1.5, p)
    Traceback (most recent call last):
        ...
    ValueError: restitution = 1.5 is out of range; allowed: a number with 1e-6 <= e <= 1
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
def attainable_restitution(chi) -> tuple[float, float]:
    """The restitution a restitution law with damping factor ``chi`` (its entry's ``chi``, a
    function of ``e``) delivers over the allowed ``e`` (:data:`RESTITUTION_RANGE`), as ``(lowest, 1)``.

    Its damping ``kappa = chi(e) K / v`` is Hunt-Crossley's with ``a = chi(e)``, whose exact
    restitution (rigid or free target) is :func:`hunt_crossley_restitution` of ``chi(e)``; ``chi``
    falls with ``e``, so the smallest ``e`` gives the lowest restitution. A bounded ``chi``
    (``3(1-e^2)/4``: at most 0.75) cannot restitute less than its bound does.
    """
    return float(hunt_crossley_restitution(chi(RESTITUTION_RANGE[0]))), 1.0


def check_attainable(law) -> None:
    """Refuse a restitution law asked for a restitution it cannot deliver (``ValueError`` with the
    attainable range); any other law passes.

    Parameters
    ----------
    law : ContactLaw
        The law with its options; only a restitution law (one with a damping factor ``chi``)
        given a ``restitution`` is checked.

    Raises
    ------
    ValueError
        If ``law.restitution`` is below the lowest restitution the law attains
        (:func:`attainable_restitution`; e.g. 0.663 for ``lankarani-nikravesh``); the message
        gives the attainable range and points to ``hunt-crossley``'s exact inverse.

    Examples
    --------
    >>> from phaseimpact.model import ContactLaw
    >>> from phaseimpact.model.restitution import check_attainable
    >>> check_attainable(ContactLaw("lankarani-nikravesh", restitution=0.7))  # passes: returns None
    >>> check_attainable(ContactLaw("lankarani-nikravesh", restitution=0.2))
    Traceback (most recent call last):
        ...
    ValueError: restitution = 0.2 is out of range for law 'lankarani-nikravesh': ...
    allowed: 0.663 <= restitution <= 1 with this law, ...
    """
    if law.restitution is None or law.entry.chi is None:
        return
    lowest, _ = attainable_restitution(law.entry.chi)
    if law.restitution < lowest:
        raise ValueError(f"restitution = {law.restitution!r} is out of range for law {law.name!r}: its damping "
                         f"{law.entry.description.split(', ')[-1]} restitutes at least e = {lowest:.3g} on a rigid "
                         f"target (the exact Hunt-Crossley restitution of chi); allowed: {lowest:.3g} <= restitution "
                         "<= 1 with this law, or any 1e-6 <= restitution <= 1 with hunt-crossley (exact inverse)")
