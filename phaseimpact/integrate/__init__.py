"""Trajectory generators: one entry point, :func:`simulate`, over swappable integrators.

==================  ======================================================================
``exact``           event-driven; scipy's ``DOP853`` between events (LSODA for stiff damping, or
                    ``method=``); stick and slip of ``paper`` resolved exactly
``rk4``             the seed's classic fixed-step RK4 on the plain right-hand side (``step=``)
``simulate_batch``  many parameter sets at once (vectorised DOP853, same events), summary only
==================  ======================================================================
"""

from __future__ import annotations

import math

from ..model import ContactLaw, as_law
from ..parameters import Parameters
from ._batch import simulate_batch
from ._events import Event
from ._exact import SCIPY_METHODS, integrate_exact
from ._rk4 import integrate_rk4
from ._trajectory import STATUSES, Save, Trajectory

__all__ = ["simulate", "simulate_batch", "Trajectory", "Event", "Save", "STATUSES", "INTEGRATORS",
           "SCIPY_METHODS"]

INTEGRATORS = ("exact", "rk4")


def simulate(params: Parameters, law: ContactLaw | str = "paper", t_end: float = 0.01, *,
             integrator: str = "exact", save="summary", stop_when_settled: bool | None = None,
             **options) -> Trajectory:
    """Integrate the impact of seed eq. 6 (``x1dot = v`` at ``x1 = x2 = 0``) up to ``t_end``.

    Parameters
    ----------
    params : Parameters
        Masses, stiffnesses, ``kappa``, impact speed ``v`` and target.
    law : ContactLaw or str
        Contact law (:data:`phaseimpact.model.LAWS`).
    t_end : float
        Horizon, s (> 0).
    integrator : {"exact", "rk4"}
        See the module docstring.
    save : "summary", "steps" or array of times
        What to keep (:class:`Save`): a sweep point needs only the summary; a figure the steps
        or a time grid.
    stop_when_settled : bool, optional
        Stop once nothing can change any more (permanent stick, projectile out of reach).
        Defaults to True for a summary, False otherwise.
    **options
        ``exact``: ``rtol`` (1e-10), ``atol`` (relative to the state scales), ``method``,
        ``max_steps``, ``max_events``, ``initial`` (a state ``(x1, x2, x1dot, x2dot)`` to start
        from instead of seed eq. 6); ``rk4``: ``step`` (s), ``every``.
    """
    law = as_law(law)
    if not (isinstance(t_end, (int, float)) and math.isfinite(t_end) and t_end > 0):
        raise ValueError(f"t_end = {t_end!r} is out of range; allowed: a finite number > 0")
    save = Save.parse(save)
    if integrator == "exact":
        method = options.get("method", "auto")
        if method not in ("auto", *SCIPY_METHODS):
            raise ValueError(f"method = {method!r} is out of range; "
                             f"allowed: auto or one of {', '.join(SCIPY_METHODS)}")
        rtol = options.get("rtol", 1e-10)
        if not (isinstance(rtol, (int, float)) and 1e-13 <= rtol < 1):
            raise ValueError(f"rtol = {rtol!r} is out of range; allowed: 1e-13 <= rtol < 1")
        settle = (save.kind == "summary") if stop_when_settled is None else stop_when_settled
        return integrate_exact(params, law, float(t_end), save=save, stop_when_settled=settle, **options)
    if integrator == "rk4":
        return integrate_rk4(params, law, float(t_end), save=save, **options)
    raise ValueError(f"integrator = {integrator!r} is out of range; allowed: one of {', '.join(INTEGRATORS)}")
