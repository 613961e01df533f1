"""Continuation over parameters: sweeps and atlases (:mod:`.sweep`), the transitions of the
long-time behaviour (:mod:`.transition`: ``kappa_c``, ``kappa_2``, grazing) and their
two-parameter continuation (:mod:`.curve`). Only :mod:`._parallel` knows about joblib/Dask.

Every name below is documented where it is defined: :mod:`.sweep` (:func:`sweep`, :func:`atlas`,
:class:`SweepResult`), :mod:`.grid` (:class:`Axis`, :class:`Grid`, :func:`parse_axis`),
:mod:`.boundary` (:func:`refine_boundaries`), :mod:`.transition` (:func:`critical_damping`,
:func:`transitions`...), :mod:`.kappa_2` (:func:`locate_kappa_2`, :func:`adding_sliding_exponents`),
:mod:`.grazing` (:func:`grazing_transitions`, :func:`delta_extremum`), :mod:`.curve`
(:func:`critical_curve`) and :mod:`.confirm` (:func:`confirmed_count`).

Examples
--------
>>> import numpy as np
>>> from phaseimpact import seed_parameters
>>> from phaseimpact.continuation import critical_damping, sweep
>>> p = seed_parameters(v=1.0)
>>> sweep(p, "paper", np.geomspace(1e9, 1e14, 5)).summary()["outcomes"]
{'permanent-stick': 3, 'ratchet-escape': 2}
>>> print(f"{critical_damping(p, 'paper').kappa_c:.4g} N s/m^2.5")
1.499e+12 N s/m^2.5
"""

from ._parallel import BACKENDS
from .boundary import Boundaries, refine_boundaries
from .confirm import ConfirmedCount, confirmed_count, stick_sequence_violation
from .curve import CURVE_QUANTITIES, CriticalCurve, critical_curve
from .grid import Axis, Grid, parse_axis
from .sweep import SweepResult, atlas, sweep
from .transition import (
    CriticalDamping,
    Transition,
    adding_sliding_exponents,
    closed_form_kappa_c,
    critical_damping,
    delta_extremum,
    first_stick_margin,
    grazing_transitions,
    locate_kappa_2,
    transitions,
)

__all__ = [
    "BACKENDS", "CURVE_QUANTITIES", "Axis", "Boundaries", "refine_boundaries", "CriticalCurve", "CriticalDamping",
    "Grid", "SweepResult",
    "Transition", "adding_sliding_exponents", "atlas", "closed_form_kappa_c", "critical_curve",
    "critical_damping", "first_stick_margin", "delta_extremum", "grazing_transitions", "locate_kappa_2",
    "parse_axis", "sweep", "transitions", "ConfirmedCount", "confirmed_count", "stick_sequence_violation",
]
