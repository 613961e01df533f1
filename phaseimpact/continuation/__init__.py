"""Continuation over parameters: sweeps and atlases (:mod:`.sweep`), the transitions of the
long-time behaviour (:mod:`.transition`: ``kappa_c``, ``kappa_2``, grazing) and their
two-parameter continuation (:mod:`.curve`). Only :mod:`._parallel` knows about joblib/Dask."""

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
