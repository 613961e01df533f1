"""Results: one run is a :class:`Trajectory`; many runs are :class:`Columns` (arrays)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..model.laws import ContactLaw
from ..model.rhs import V1, V2, X1, X2
from ..parameters import Parameters
from . import driver as d
from .events import EVENT_KINDS

__all__ = ["Event", "Trajectory", "Columns", "STATUSES", "OUTCOMES", "EVENT_KINDS", "run_message"]

STATUSES = d.STATUSES
OUTCOMES = d.OUTCOMES


@dataclass(frozen=True)
class Event:
    """Something that happened along a trajectory.

    Attributes
    ----------
    kind : str
        One of :data:`EVENT_KINDS`: ``contact``, ``separation``, ``reversal`` (an extreme of the
        indentation, or a slip reversal of ``paper``), ``stick``, ``slip``, ``force-peak``,
        ``settled`` (out of reach) or ``runaway``.
    t : float
        Time, s.
    state : ndarray, shape (5,)
        ``(x1, x2, x1dot, x2dot, W)`` at ``t``, after the event's correction.
    force : float
        Contact force at ``t``, N.
    mode : int
        Mode after the event (``paper``: +-1 slipping, 0 stuck).
    """

    kind: str
    t: float
    state: np.ndarray
    force: float
    mode: int

    @property
    def delta(self) -> float:
        return float(self.state[X1] - self.state[X2])

    @property
    def deltadot(self) -> float:
        return float(self.state[V1] - self.state[V2])


def _optional(x) -> float | None:
    return None if math.isnan(x) else float(x)


def run_message(status: str, reason: str, t_stop: float, outcome: str) -> str:
    """A sentence on how a run ended."""
    if status == "step-size-collapse":
        return f"the step size collapsed at t = {t_stop:.6g} s (stiffness or a discontinuity the events miss)"
    if status == "too-many-steps":
        return f"stopped at t = {t_stop:.6g} s: the step or event limit was reached"
    if status == "non-finite":
        return f"the state became non-finite after t = {t_stop:.6g} s"
    if status == "interrupted":  # Ctrl-C or SIGTERM; simulate raises, this is for runs read directly
        return f"interrupted at t = {t_stop:.6g} s (Ctrl-C or SIGTERM)"
    if reason == "runaway":
        return f"the energy doubled at t = {t_stop:.6g} s: the contact force feeds the motion ({outcome})"
    if reason == "settled":
        return f"outcome settled at t = {t_stop:.6g} s ({outcome})"
    if reason == "asked":
        return f"stopped at t = {t_stop:.6g} s at the event asked for"
    return f"the horizon t_end = {t_stop:.6g} s ended the run before the outcome settled"


@dataclass(eq=False)  # not frozen: a frozen dataclass's __init__ costs a microsecond per run
class Trajectory:
    """One trajectory of the impact model.

    Attributes
    ----------
    t, y, force, mode : ndarray
        Samples (empty for a summary run): times (s), states ``(n, 5)``
        ``(x1, x2, x1dot, x2dot, W)`` with ``W`` the contact work (J), contact force (N), mode.
    event_t, event_kind, event_mode, event_y, event_force : ndarray
        The event log as arrays (``event_kind`` indexes :data:`EVENT_KINDS`).
    samples, event_log : ndarray
        Both as the driver returns them, one row per sample or event (columns ``SMP_*`` and
        ``EV_*`` of :mod:`.driver`); the arrays above are views of them (kinds and modes as integers).
    params, law : Parameters, ContactLaw
        What was integrated.
    initial_state, final_state : ndarray, shape (5,)
        The run's own start and end; energies are taken from these (docs/physics.md §4).
    t_end, t_stop : float
        Requested horizon and where the run stopped, s.
    status : str
        Numerical health, one of :data:`STATUSES` (``success`` or a failure).
    stop_reason : str
        ``horizon``, ``settled`` (nothing can change any more), ``runaway``, ``asked`` or ``failed``.
    outcome : str
        One of :data:`OUTCOMES` (docs/physics.md §5).
    message : str
    summary : ndarray
        The summary vector (see :mod:`.driver`, ``S_*``); read it through the properties.
    integrator : str
    """

    samples: np.ndarray = field(repr=False)
    event_log: np.ndarray = field(repr=False)
    params: Parameters
    law: ContactLaw
    initial_state: np.ndarray
    final_state: np.ndarray
    t_end: float
    status: str
    stop_reason: str
    outcome: str
    summary: np.ndarray = field(repr=False)
    integrator: str = "exact"

    @property
    def t(self) -> np.ndarray:
        return self.samples[:, d.SMP_T]

    @property
    def y(self) -> np.ndarray:
        return self.samples[:, d.SMP_Y:d.SMP_Y + 5]

    @property
    def force(self) -> np.ndarray:
        return self.samples[:, d.SMP_FORCE]

    @cached_property
    def mode(self) -> np.ndarray:
        return self.samples[:, d.SMP_MODE].astype(np.int64)

    @property
    def event_t(self) -> np.ndarray:
        return self.event_log[:, d.EV_T]

    @cached_property
    def event_kind(self) -> np.ndarray:
        return self.event_log[:, d.EV_KIND].astype(np.int64)

    @cached_property
    def event_mode(self) -> np.ndarray:
        return self.event_log[:, d.EV_MODE].astype(np.int64)

    @property
    def event_y(self) -> np.ndarray:
        return self.event_log[:, d.EV_Y:d.EV_Y + 5]

    @property
    def event_force(self) -> np.ndarray:
        return self.event_log[:, d.EV_FORCE]

    @property
    def message(self) -> str:
        """A sentence on how the run ended."""
        return run_message(self.status, self.stop_reason, self.t_stop, self.outcome)

    @property
    def ok(self) -> bool:
        return self.status == "success"

    @property
    def t_stop(self) -> float:
        return float(self.summary[d.S_T_STOP])

    @property
    def final_mode(self) -> int:
        return int(self.summary[d.S_MODE])

    @property
    def settled(self) -> bool:
        """The run stopped because nothing can change any more."""
        return self.stop_reason == "settled" or self.stop_reason == "runaway"

    @property
    def cut(self) -> bool:
        """The horizon ended the run before its outcome settled (counts are lower bounds)."""
        return self.stop_reason == "horizon"

    @property
    def max_force(self) -> float:
        return float(self.summary[d.S_MAX_FORCE])

    @property
    def max_indentation(self) -> float:
        return float(self.summary[d.S_MAX_INDENTATION])

    @property
    def restitution(self) -> float | None:
        """``-deltadot`` at the first separation over ``deltadot`` at the first contact."""
        return _optional(self.summary[d.S_RESTITUTION])

    @property
    def contact_duration(self) -> float | None:
        """First contact to first separation, s."""
        return _optional(self.summary[d.S_CONTACT_DURATION])

    @property
    def dissipated_energy(self) -> float:
        """Initial minus final mechanical energy of this run (docs/physics.md §4), J."""
        return float(self.summary[d.S_DISSIPATED])

    @property
    def loop_area(self) -> float:
        """Work of the contact force on the relative motion, ``integral P d(delta)``, J."""
        return float(self.summary[d.S_LOOP_AREA])

    @property
    def n_stick(self) -> int:
        """Number of stick phases (a lower bound if :attr:`cut`)."""
        return int(self.summary[d.S_N_STICK])

    @property
    def n_contacts(self) -> int:
        return int(self.summary[d.S_N_CONTACTS])

    @property
    def t_run(self) -> float | None:
        """Time of the escape: the first separation after the first stick, s."""
        return _optional(self.summary[d.S_T_RUN])

    @property
    def first_stick_margin(self) -> float | None:
        """``1 - M1/M S(A) / (K delta*^alpha)`` of the first stick (>= 0: permanent)."""
        return _optional(self.summary[d.S_FIRST_STICK_MARGIN])

    @property
    def nfev(self) -> int:
        return int(self.summary[d.S_NFEV])

    @property
    def nsteps(self) -> int:
        return int(self.summary[d.S_NSTEPS])

    @property
    def x1(self):
        return self.y[:, X1]

    @property
    def x2(self):
        return self.y[:, X2]

    @property
    def delta(self):
        """Indentation ``x1 - x2`` at the samples, m."""
        return self.y[:, X1] - self.y[:, X2]

    @property
    def deltadot(self):
        """Relative velocity at the samples, m/s."""
        return self.y[:, V1] - self.y[:, V2]

    @cached_property
    def events(self) -> tuple:
        """The event log as :class:`Event` objects."""
        return tuple(Event(EVENT_KINDS[k], float(t), s, float(f), int(m)) for k, t, s, f, m in
                     zip(self.event_kind, self.event_t, self.event_y, self.event_force, self.event_mode,
                         strict=True))

    def events_of(self, *kinds) -> list[Event]:
        codes = [EVENT_KINDS.index(k) for k in kinds]
        return [e for e, k in zip(self.events, self.event_kind, strict=True) if k in codes]

    def stick_points(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stick phases: times (s), ``delta*`` (m) and dwell (s; inf for a permanent stick)."""
        n = int(np.count_nonzero(self.event_kind == EVENT_KINDS.index("stick")))
        out = np.empty((3, n))
        d.stick_points(self.event_log, self.t_stop, self.outcome == "permanent-stick", out[0], out[1], out[2])
        return out[0], out[1], out[2]


#: Columns of :class:`Columns` taken straight from the summary vector (name, index, dtype, unit).
SUMMARY_COLUMNS = (
    ("t_stop", d.S_T_STOP, float, "s"),
    ("max_force", d.S_MAX_FORCE, float, "N"),
    ("max_indentation", d.S_MAX_INDENTATION, float, "m"),
    ("restitution", d.S_RESTITUTION, float, "1"),
    ("contact_duration", d.S_CONTACT_DURATION, float, "s"),
    ("dissipated_energy", d.S_DISSIPATED, float, "J"),
    ("loop_area", d.S_LOOP_AREA, float, "J"),
    ("n_stick", d.S_N_STICK, np.int64, "1"),
    ("n_contacts", d.S_N_CONTACTS, np.int64, "1"),
    ("t_run", d.S_T_RUN, float, "s"),
    ("first_stick_delta", d.S_FIRST_STICK_DELTA, float, "m"),
    ("first_stick_margin", d.S_FIRST_STICK_MARGIN, float, "1"),
    ("nsteps", d.S_NSTEPS, np.int64, "1"),
    ("nfev", d.S_NFEV, np.int64, "1"),
)


class ColumnAccess:
    """Summary columns read as attributes (``result.max_force``) from a ``values`` dict."""

    def __getattr__(self, name):
        values = self.__dict__.get("values")
        if values is not None and name in values:
            return values[name]
        raise AttributeError(name)


@dataclass
class Columns(ColumnAccess):
    """Many runs as a struct of arrays (one entry per run); NaN where a quantity is undefined.

    Attributes
    ----------
    status, outcome, stop_reason : ndarray of int8
        Codes into :data:`STATUSES`, :data:`OUTCOMES`, ``STOP_REASONS``.
    t_stop, max_force, ... : ndarray
        See :data:`SUMMARY_COLUMNS` for names and units.
    stick_count : ndarray of int64
        Stick phases per run; their times, depths and dwells are the ragged arrays
        ``stick_t``, ``stick_delta``, ``stick_dwell`` in run order (CF contiguous ragged array).
    """

    status: np.ndarray
    outcome: np.ndarray
    stop_reason: np.ndarray
    values: dict
    stick_count: np.ndarray
    stick_t: np.ndarray
    stick_delta: np.ndarray
    stick_dwell: np.ndarray

    def __len__(self) -> int:
        return len(self.status)

    @property
    def cut(self) -> np.ndarray:
        """Runs ended by the horizon before their outcome settled."""
        return self.stop_reason == d.HORIZON

    @property
    def failed(self) -> np.ndarray:
        return self.status != d.SUCCESS

    def status_names(self) -> np.ndarray:
        return np.array(STATUSES, dtype=object)[self.status]

    def outcome_names(self) -> np.ndarray:
        return np.array(OUTCOMES, dtype=object)[self.outcome]

    def sticks_of(self, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stick times, depths and dwells of run ``i``."""
        start = int(self.stick_count[:i].sum())
        stop = start + int(self.stick_count[i])
        return self.stick_t[start:stop], self.stick_delta[start:stop], self.stick_dwell[start:stop]

    @classmethod
    def from_summary(cls, summary: np.ndarray, stick_count, stick_t, stick_delta, stick_dwell) -> Columns:
        values = {name: summary[:, index].astype(dtype) for name, index, dtype, _ in SUMMARY_COLUMNS}
        return cls(summary[:, d.S_STATUS].astype(np.int8), summary[:, d.S_OUTCOME].astype(np.int8),
                   summary[:, d.S_REASON].astype(np.int8), values, np.asarray(stick_count, dtype=np.int64),
                   stick_t, stick_delta, stick_dwell)
