"""What every search in ``kappa`` shares: the checks of its inputs (before any work), its default
range, :class:`RunFailed` for a run it cannot read as a value, and the :class:`Transition` it reports.
Imported from :mod:`phaseimpact.continuation.transition`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from ..integrate import simulate
from ..integrate.api import summary_run
from ..integrate.driver import S_STATUS, SUCCESS
from ..parameters import KAPPA_MAX, Parameters, is_number

# check_params, check_rtol_of_kappa and default_kappa_range serve the searches and the command line,
# not users: outside __all__, as they were in transition.py.
__all__ = ["RunFailed", "Transition", "check_kappa_range", "A_MIN"]

#: Lower end of the default search range, as a damping number ``a = kappa v / K``: below it the
#: approach phase is undamped to 1e-8 (``delta*`` moves by ``O(a)``), so the margin cannot change
#: sign there. The upper end is the inputs' own limit :data:`~phaseimpact.parameters.KAPPA_MAX`.
A_MIN = 1e-8


class RunFailed(RuntimeError):
    """A run needed by a search ended in a numerical failure (its status and message).

    A search never reads a failed run as a value: :func:`first_stick_margin`,
    :func:`delta_extremum`, :func:`grazing_transitions`, :func:`transitions` and
    :func:`~phaseimpact.continuation.critical_curve` raise it, naming the run's ``kappa``;
    :func:`critical_damping` reports it as status ``failed`` instead.

    Examples
    --------
    >>> from phaseimpact.continuation.transition import RunFailed
    >>> try:
    ...     raise RunFailed("kappa = 1e+12: step-size-collapse: ...")
    ... except RuntimeError as error:
    ...     print(type(error).__name__, error)
    RunFailed kappa = 1e+12: step-size-collapse: ...
    """


def checked_summary(params: Parameters, law, t_end, **options):
    """A search's run on the per-point path (:func:`~phaseimpact.integrate.api.summary_run`: its
    summary vector and final state), or :class:`RunFailed` naming its ``kappa``, status and
    message: a search must not read a failed run. The message of that (rare) failure comes from
    the same run with its event log, which names a user law's fault."""
    run = summary_run(params, law, t_end, **options)
    if run[0][S_STATUS] != SUCCESS:
        trajectory = simulate(params, law, t_end, **options)
        raise RunFailed(f"kappa = {params.kappa:.6g}: {trajectory.status}: {trajectory.message}")
    return run


def check_params(params) -> Parameters:
    if not isinstance(params, Parameters):
        raise TypeError(f"params = {params!r} has the wrong type ({type(params).__name__}); allowed: Parameters "
                        "(e.g. seed_parameters(), or Case.parameters())")
    return params


def check_kappa_range(kappa_min, kappa_max, names=("kappa_min", "kappa_max")) -> tuple[float, float]:
    """``(kappa_min, kappa_max)`` as floats with ``0 < kappa_min < kappa_max <= KAPPA_MAX``.

    Parameters
    ----------
    kappa_min, kappa_max : float
        Ends of a search range of ``kappa``, N s/m^(1+alpha).
    names : pair of str, default ("kappa_min", "kappa_max")
        How the message names them (the command line's option names).

    Returns
    -------
    tuple of float
        ``(kappa_min, kappa_max)``.

    Raises
    ------
    ValueError
        For an end that is not a finite number in ``(0, KAPPA_MAX]`` (1e18), or ends in the
        wrong order.

    Examples
    --------
    >>> from phaseimpact.continuation.transition import check_kappa_range
    >>> check_kappa_range(1e9, 1e13)
    (1000000000.0, 10000000000000.0)
    >>> check_kappa_range(1e9, 1e8)
    Traceback (most recent call last):
    ...
    ValueError: kappa_min = 1000000000.0, kappa_max = 100000000.0 are out of range; allowed: kappa_min < kappa_max
    """
    for name, value in zip(names, (kappa_min, kappa_max), strict=True):
        if not (is_number(value) and math.isfinite(value) and 0 < value <= KAPPA_MAX):
            raise ValueError(f"{name} = {value!r} is out of range; allowed: 0 < {name} <= {KAPPA_MAX:g} "
                             "(N s/m^(1+alpha))")
    if not kappa_min < kappa_max:
        raise ValueError(f"{names[0]} = {kappa_min!r}, {names[1]} = {kappa_max!r} are out of range; "
                         f"allowed: {names[0]} < {names[1]}")
    return float(kappa_min), float(kappa_max)


def _default_range(params: Parameters) -> tuple[float, float]:
    """The default search range: from the damping number :data:`A_MIN` up to ``KAPPA_MAX``."""
    return min(A_MIN * params.K / params.v, KAPPA_MAX / 10), KAPPA_MAX


def check_rtol_of_kappa(value) -> float:
    """``kappa_rtol`` as a float, or ValueError naming it and its range, 1e-14 to 1e-2."""
    if not (is_number(value) and 1e-14 <= value <= 1e-2):
        raise ValueError(f"kappa_rtol = {value!r} is out of range; allowed: 1e-14 <= kappa_rtol <= 1e-2")
    return float(value)


def default_kappa_range(params: Parameters, kappa_min=None, kappa_max=None,
                        names=("kappa_min", "kappa_max")) -> tuple[float, float]:
    """The search range of :func:`critical_damping`: the ends given, the others the defaults (the
    damping number :data:`A_MIN` and ``KAPPA_MAX``; a default end on the wrong side of a given one
    is named as a default)."""
    lo_default, hi_default = _default_range(params)
    lo = lo_default if kappa_min is None else kappa_min
    hi = hi_default if kappa_max is None else kappa_max
    for given, default, name, other in ((kappa_max, lo_default, names[0], names[1]),
                                        (kappa_min, hi_default, names[1], names[0])):
        if (kappa_min is None) != (kappa_max is None) and given is not None and is_number(given) and (
                (name == names[0] and not default < given) or (name == names[1] and not given < default)):
            origin = f"damping number kappa v/K = {A_MIN:g}" if name == names[0] else "the largest kappa"
            raise ValueError(f"{other} = {given!r} is out of range with the default {name} = {default:.4g} "
                             f"({origin}); allowed: "
                             f"{other} {'>' if name == names[0] else '<'} {default:.4g}, or {name} given too")
    return check_kappa_range(lo, hi, names)


@dataclass(frozen=True)
class Transition:
    """A change of the long-time count at ``kappa``: stick phases (``paper``) or contacts.

    Attributes
    ----------
    kind : {"adding-sliding", "staircase-end", "grazing"}
        ``adding-sliding`` at ``kappa_c`` and ``staircase-end`` at ``kappa_2`` (``paper``);
        ``grazing`` for a unilateral law.
    kappa : float
        Where, N s/m^(1+alpha).
    count_below, count_above : int or None
        The count just below and just above (None: not confirmed, or unbounded above
        ``kappa_c``).
    extremum : int or None
        Grazing: which extremum of ``delta`` touches zero.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import transitions
    >>> first = transitions(seed_parameters(), "hunt-crossley", 1e8, 1e13, num=80)[0]
    >>> print(first.kind, f"{first.kappa:.4g}", first.count_below, first.count_above, first.extremum)
    grazing 3.577e+10 2 3 5
    """

    kind: str
    kappa: float
    count_below: int | None
    count_above: int | None
    extremum: int | None = None  # grazing: which extremum of delta touches zero

    def as_dict(self) -> dict:
        """The fields as a plain dict (for JSON).

        Returns
        -------
        dict
            ``{"kind", "kappa", "count_below", "count_above", "extremum"}``.

        Examples
        --------
        >>> from phaseimpact.continuation import Transition
        >>> Transition("adding-sliding", 1.5e12, 1, None).as_dict()
        {'kind': 'adding-sliding', 'kappa': 1500000000000.0, 'count_below': 1, 'count_above': None, 'extremum': None}
        """
        return asdict(self)
