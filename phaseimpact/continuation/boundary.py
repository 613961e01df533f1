"""Class boundaries of an atlas, refined along one axis (issue: atlases).

Where two neighbouring grid points along ``axis`` end in different outcome classes, the
boundary between them is located by bisection on the class (in log space on a log axis) to a
stated relative tolerance, all other coordinates held. For ``paper``'s edge between a
permanent stick and the rest, the class is read from the sign of the first stick's margin, a
smooth function whose root is ``kappa_c`` (docs/physics.md §5): no run needs to reach the (near
``kappa_c`` unbounded) escape time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..integrate import driver as drv
from ..integrate.api import check_rtol, summary_run
from ._renamed import renamed_tolerances
from .sweep import SweepResult
from .transition import first_stick_margin

__all__ = ["Boundaries", "refine_boundaries"]


@dataclass(frozen=True)
class Boundaries:
    """Refined boundary points of an atlas, as :func:`refine_boundaries` returns them.

    Attributes
    ----------
    axis : str
        The axis along which each boundary was refined.
    points : ndarray, shape (n, ndim)
        Coordinates of each boundary point (the grid's axes, in order).
    below, above : ndarray of int8, shape (n,)
        Outcome class codes on the low and high side along ``axis``.
    rtol : float
        Relative width of each refined bracket: the call's ``refine_rtol``.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import atlas, refine_boundaries
    >>> a = atlas(seed_parameters(), "paper", {"kappa": [1e11, 1e12, 1e13], "v": [1.0, 2.0]})
    >>> b = refine_boundaries(a, "kappa", refine_rtol=1e-4)
    >>> len(b), b.axis, b.points.shape
    (2, 'kappa', (2, 2))
    """

    axis: str
    points: np.ndarray
    below: np.ndarray
    above: np.ndarray
    rtol: float

    def __len__(self) -> int:
        return len(self.below)


@renamed_tolerances("refine_rtol")
def refine_boundaries(result: SweepResult, axis: str = "kappa", *, refine_rtol: float = 1e-8,
                      rtol: float | None = None) -> Boundaries:
    """Locate every class change along ``axis`` between neighbouring points of ``result``.

    Where two neighbouring grid points along ``axis`` end in different outcome classes (both
    computed, neither failed), the boundary between them is located by bisection on the class
    (geometric midpoints on a log axis), all other coordinates held, until the bracket's
    relative width is below ``refine_rtol``. For a Filippov law's edge between a permanent stick and the
    rest, the class is read from the sign of the first stick's margin (its root is ``kappa_c``,
    docs/physics.md §5), so no run has to reach the escape.

    Parameters
    ----------
    result : SweepResult
        A sweep or atlas (:func:`~phaseimpact.continuation.atlas`).
    axis : str, default "kappa"
        The axis to refine along; one of ``result.grid.names``.
    refine_rtol : float, default 1e-8
        Relative width of each final bracket, ``1e-14 <= refine_rtol <= 0.1`` (``rtol`` up to
        0.2.0, as the command line's ``--refine-rtol``).
    rtol : float, optional
        The integrator's tolerance of the runs, within :data:`~phaseimpact.integrate.RTOL_RANGE`;
        default the result's own (``result.settings["rtol"]``; ``integrator_rtol`` up to 0.2.0,
        ``rtol=`` alone is refused for one release).

    Returns
    -------
    Boundaries
        One point per class change, in the order of the grid lines, each at its bracket's
        (geometric) midpoint.

    Raises
    ------
    ValueError
        If ``axis`` is not an axis of ``result``, or ``refine_rtol`` or ``rtol`` is out of range.
    TypeError
        For the spellings of 0.2.0 (``integrator_rtol=``; ``rtol=`` without ``refine_rtol=``).
    RunFailed
        When a run of a Filippov law's margin fails numerically (naming its kappa).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import atlas, refine_boundaries
    >>> a = atlas(seed_parameters(), "paper", {"kappa": [1e11, 1e12, 1e13], "v": [1.0, 2.0]})
    >>> b = refine_boundaries(a, "kappa", refine_rtol=1e-4)
    >>> for (kappa, v), lo, hi in zip(b.points, b.below, b.above):
    ...     print(f"v = {v} m/s: kappa_c = {kappa:.4g} N s/m^2.5, outcome {lo} -> {hi}")
    v = 1.0 m/s: kappa_c = 1.499e+12 N s/m^2.5, outcome 1 -> 2
    v = 2.0 m/s: kappa_c = 9.542e+11 N s/m^2.5, outcome 1 -> 2
    """
    grid = result.grid
    names = grid.names
    if axis not in names:
        raise ValueError(f"axis = {axis!r} is out of range; allowed: one of {', '.join(names)}")
    if not (isinstance(refine_rtol, float | int) and 1e-14 <= refine_rtol <= 0.1):
        raise ValueError(f"refine_rtol = {refine_rtol!r} is out of range; allowed: 1e-14 <= refine_rtol <= 0.1")
    rtol = check_rtol(result.settings.get("rtol", 1e-10) if rtol is None else rtol)
    k = names.index(axis)
    values = grid.axes[k].values
    log = grid.axes[k].log and np.all(values > 0)
    outcome = result.outcome.reshape(grid.shape)
    law = grid.law
    stuck = drv.PERMANENT_STICK

    def classify(point: dict) -> int:
        params = grid.parameters_at(point)
        if law.is_filippov and stuck in pair:
            return stuck if first_stick_margin(params, law, rtol=rtol) >= 0 else -2
        summary = summary_run(params, law, result.t_end, rtol=rtol)[0]
        return int(summary[drv.S_OUTCOME]) if summary[drv.S_STATUS] == drv.SUCCESS else drv.FAILED

    points, below, above = [], [], []
    moved = np.moveaxis(outcome, k, -1)
    for index in np.ndindex(*moved.shape[:-1]):
        line = moved[index]
        for i in range(len(line) - 1):
            a, b = int(line[i]), int(line[i + 1])
            if a == b or a < 0 or b < 0 or drv.FAILED in (a, b):
                continue
            pair = (a, b)
            others = {grid.axes[j].name: grid.axes[j].values[index[j - (j > k)]] for j in range(len(names)) if j != k}
            lo, hi = values[i], values[i + 1]
            side_lo = classify({**others, axis: lo})
            while abs(hi - lo) > refine_rtol * max(abs(lo), abs(hi)):
                mid = math.sqrt(lo * hi) if log else 0.5 * (lo + hi)
                if mid in (lo, hi):
                    break
                if classify({**others, axis: mid}) == side_lo:
                    lo = mid
                else:
                    hi = mid
            where = math.sqrt(lo * hi) if log else 0.5 * (lo + hi)
            coordinates = [others[n] if n != axis else where for n in names]
            points.append(coordinates)
            below.append(a)
            above.append(b)
    return Boundaries(axis, np.asarray(points, dtype=float).reshape(-1, len(names)),
                      np.asarray(below, dtype=np.int8), np.asarray(above, dtype=np.int8), float(refine_rtol))
