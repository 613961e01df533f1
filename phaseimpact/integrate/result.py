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
from . import logs
from .events import EVENT_KINDS

__all__ = ["Event", "Trajectory", "Columns", "STATUSES", "OUTCOMES", "EVENT_KINDS", "run_message"]

#: Numerical health of a run: ``success`` or how it failed (``step-size-collapse``, ``too-many-steps``,
#: ``non-finite``, ``interrupted``).
STATUSES = d.STATUSES
#: Outcome classes of a run (docs/physics.md §5): ``failed``, ``permanent-stick``, ``ratchet-escape``,
#: ``rebound``, ``runaway``, ``bounded``, ``unsettled``.
OUTCOMES = d.OUTCOMES


@dataclass(frozen=True)
class Event:
    """Something that happened along a trajectory.

    The driver locates each event on the step's dense output; :attr:`Trajectory.events` gives
    them in time order.

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

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate
    >>> tr = simulate(seed_parameters(v=1.0, kappa=3e9), "paper")
    >>> [e.kind for e in tr.events]
    ['contact', 'force-peak', 'stick']
    >>> stick = tr.events[-1]
    >>> print(f"t = {stick.t:.4g} s, delta = {stick.delta:.4g} m, mode {stick.mode}")
    t = 5.299e-05 s, delta = 3.547e-05 m, mode 0
    """

    kind: str
    t: float
    state: np.ndarray
    force: float
    mode: int

    @property
    def delta(self) -> float:
        """Indentation ``x1 - x2`` at the event, m."""
        return float(self.state[X1] - self.state[X2])

    @property
    def deltadot(self) -> float:
        """Relative velocity ``x1dot - x2dot`` at the event, m/s."""
        return float(self.state[V1] - self.state[V2])


def _optional(x) -> float | None:
    return None if math.isnan(x) else float(x)


def run_message(status: str, reason: str, t_stop: float, outcome: str) -> str:
    """A sentence on how a run ended (:attr:`Trajectory.message`).

    A numerical failure is named first; else why the run stopped.

    Parameters
    ----------
    status : str
        One of :data:`STATUSES`.
    reason : str
        The stop reason: ``horizon``, ``settled``, ``runaway``, ``asked`` or ``failed``.
    t_stop : float
        Where the run stopped, s.
    outcome : str
        One of :data:`OUTCOMES`.

    Returns
    -------
    str
        One sentence, without a final full stop.

    Examples
    --------
    >>> from phaseimpact.integrate.result import run_message
    >>> run_message("success", "settled", 5.3e-5, "permanent-stick")
    'outcome settled at t = 5.3e-05 s (permanent-stick)'
    >>> run_message("success", "horizon", 2e-3, "bounded")
    'the horizon t_end = 0.002 s ended the run before the outcome settled'
    """
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
    """One trajectory of the impact model, as :func:`~phaseimpact.simulate` returns it.

    The samples (if kept), the event log and the summary vector of one run; the summary
    quantities are read through properties (``max_force``, ``n_stick``, ``t_run``...), undefined
    ones as None.

    Attributes
    ----------
    t, y, force, mode : ndarray
        Samples (empty for a summary run): times (s), states ``(n, 5)``
        ``(x1, x2, x1dot, x2dot, W)`` with ``W`` the contact work (J), contact force (N), mode.
    event_t, event_kind, event_mode, event_y, event_force : ndarray
        The event log as arrays (``event_kind`` indexes :data:`EVENT_KINDS`).
    samples, event_log : ndarray
        Both as the driver returns them, one row per sample or event (columns ``SMP_*`` and
        ``EV_*`` of :mod:`.logs`); the arrays above are views of them (kinds and modes as integers).
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
        A sentence on how the run ended (:func:`run_message`).
    summary : ndarray
        The summary vector (see :mod:`.driver`, ``S_*``); read it through the properties.
    integrator : str
        The integrator and its settings, e.g. ``exact[DOP853+Radau5, rtol=1e-10]``.
    law_fault : str
        Of a run that a user law ended (status ``non-finite``): what its function raised or
        returned, and at which ``delta`` (the :attr:`message`); else empty.

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate
    >>> tr = simulate(seed_parameters(v=1.0, kappa=2e12), "paper")
    >>> tr.ok, tr.outcome, tr.n_stick, tr.n_contacts
    (True, 'ratchet-escape', 2, 1)
    >>> print(f"escape at t_run = {tr.t_run:.3g} s")
    escape at t_run = 0.000965 s
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
    law_fault: str = ""

    @property
    def t(self) -> np.ndarray:
        """Sample times, s (empty for a summary run)."""
        return self.samples[:, logs.SMP_T]

    @property
    def y(self) -> np.ndarray:
        """Sampled states ``(x1, x2, x1dot, x2dot, W)``, shape ``(n, 5)``: m, m, m/s, m/s, J."""
        return self.samples[:, logs.SMP_Y:logs.SMP_Y + 5]

    @property
    def force(self) -> np.ndarray:
        """Contact force at the samples, N."""
        return self.samples[:, logs.SMP_FORCE]

    @cached_property
    def mode(self) -> np.ndarray:
        """Mode at the samples (``paper``: +-1 slipping, 0 stuck)."""
        return self.samples[:, logs.SMP_MODE].astype(np.int64)

    @property
    def event_t(self) -> np.ndarray:
        """Event times, s."""
        return self.event_log[:, logs.EV_T]

    @cached_property
    def event_kind(self) -> np.ndarray:
        """Event kinds as indices into :data:`EVENT_KINDS`."""
        return self.event_log[:, logs.EV_KIND].astype(np.int64)

    @cached_property
    def event_mode(self) -> np.ndarray:
        """Mode after each event."""
        return self.event_log[:, logs.EV_MODE].astype(np.int64)

    @property
    def event_y(self) -> np.ndarray:
        """States ``(x1, x2, x1dot, x2dot, W)`` at the events, shape ``(n_events, 5)``."""
        return self.event_log[:, logs.EV_Y:logs.EV_Y + 5]

    @property
    def event_force(self) -> np.ndarray:
        """Contact force at the events, N."""
        return self.event_log[:, logs.EV_FORCE]

    @property
    def message(self) -> str:
        """A sentence on how the run ended."""
        if self.law_fault:
            return f"{self.law_fault}: the run stopped at t = {self.t_stop:.6g} s"
        return run_message(self.status, self.stop_reason, self.t_stop, self.outcome)

    @property
    def ok(self) -> bool:
        """The run ended without a numerical failure (status ``success``)."""
        return self.status == "success"

    @property
    def t_stop(self) -> float:
        """Where the run stopped, s."""
        return float(self.summary[d.S_T_STOP])

    @property
    def final_mode(self) -> int:
        """Mode at the end of the run (``paper``: +-1 slipping, 0 stuck)."""
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
        """Largest contact force of the run, N."""
        return float(self.summary[d.S_MAX_FORCE])

    @property
    def max_indentation(self) -> float:
        """Largest indentation ``delta = x1 - x2`` of the run, m."""
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
        """Number of contacts (a lower bound if :attr:`cut`)."""
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
        """Right-hand side evaluations."""
        return int(self.summary[d.S_NFEV])

    @property
    def nsteps(self) -> int:
        """Integrator steps."""
        return int(self.summary[d.S_NSTEPS])

    @property
    def x1(self):
        """Projectile displacement at the samples, m."""
        return self.y[:, X1]

    @property
    def x2(self):
        """Target displacement at the samples, m."""
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
        """The events of the given kinds, in time order.

        Parameters
        ----------
        *kinds : str
            Kinds of :data:`EVENT_KINDS` (``"contact"``, ``"stick"``...).

        Returns
        -------
        list of Event

        Raises
        ------
        ValueError
            For a kind not in :data:`EVENT_KINDS`.

        Examples
        --------
        >>> from phaseimpact import seed_parameters, simulate
        >>> tr = simulate(seed_parameters(v=1.0, kappa=1e9), "abrate")
        >>> len(tr.events_of("contact")), len(tr.events_of("contact", "separation"))
        (2, 4)
        """
        codes = [EVENT_KINDS.index(k) for k in kinds]
        return [e for e, k in zip(self.events, self.event_kind, strict=True) if k in codes]

    def stick_points(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stick phases: times (s), ``delta*`` (m) and dwell (s; inf for a permanent stick).

        Read from the event log, so a summary run has them too; the last phase of a run the
        horizon cut dwells until :attr:`t_stop`.

        Returns
        -------
        t, delta, dwell : ndarray, shape (n_stick,)
            When each stick phase began (s), the indentation it holds (m) and how long it lasted
            (s; inf for a permanent stick).

        Examples
        --------
        >>> from phaseimpact import seed_parameters, simulate
        >>> t, delta, dwell = simulate(seed_parameters(v=1.0, kappa=3e9), "paper").stick_points()
        >>> print(f"{t[0]:.4g} s, {delta[0]:.4g} m, {dwell[0]}")
        5.299e-05 s, 3.547e-05 m, inf
        """
        n = int(np.count_nonzero(self.event_kind == EVENT_KINDS.index("stick")))
        out = np.empty((3, n))
        logs.stick_points(self.event_log, self.t_stop, self.outcome == "permanent-stick", out[0], out[1], out[2])
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

    Made by :func:`~phaseimpact.simulate_many`; the summary columns are read as attributes
    (``columns.max_force``) from :attr:`values`.

    Attributes
    ----------
    status, outcome, stop_reason : ndarray of int8
        Codes into :data:`STATUSES`, :data:`OUTCOMES`, ``STOP_REASONS``.
    values : dict of ndarray
        The summary columns by name.
    t_stop, max_force, ... : ndarray
        See :data:`SUMMARY_COLUMNS` for names and units.
    stick_count : ndarray of int64
        Stick phases per run; their times, depths and dwells are the ragged arrays
        ``stick_t``, ``stick_delta``, ``stick_dwell`` in run order (CF contiguous ragged array).
    cut, failed : ndarray of bool
        Runs ended by the horizon before their outcome settled; runs with a numerical failure.

    Examples
    --------
    >>> from phaseimpact import seed_parameters, simulate_many
    >>> c = simulate_many([seed_parameters(kappa=k) for k in (1e9, 1e13)], "paper")
    >>> len(c), c.stick_count.tolist(), int(c.failed.sum())
    (2, [1, 2], 0)
    >>> print(f"{c.max_force[0]:.4g} N")
    4760 N
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
        """Runs whose status is not ``success``."""
        return self.status != d.SUCCESS

    def status_names(self) -> np.ndarray:
        """Each run's status as its name in :data:`STATUSES`.

        Returns
        -------
        ndarray of str (object), shape (n,)

        Examples
        --------
        >>> from phaseimpact import seed_parameters, simulate_many
        >>> simulate_many([seed_parameters(kappa=1e9)], "paper").status_names().tolist()
        ['success']
        """
        return np.array(STATUSES, dtype=object)[self.status]

    def outcome_names(self) -> np.ndarray:
        """Each run's outcome as its name in :data:`OUTCOMES`.

        Returns
        -------
        ndarray of str (object), shape (n,)

        Examples
        --------
        >>> from phaseimpact import seed_parameters, simulate_many
        >>> simulate_many([seed_parameters(kappa=k) for k in (1e9, 1e13)], "paper").outcome_names().tolist()
        ['permanent-stick', 'ratchet-escape']
        """
        return np.array(OUTCOMES, dtype=object)[self.outcome]

    def sticks_of(self, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stick times, depths and dwells of run ``i``.

        Parameters
        ----------
        i : int
            Index of the run, ``0 <= i < len(self)``.

        Returns
        -------
        t, delta, dwell : ndarray
            When each stick phase of the run began (s), its indentation (m) and its dwell (s; inf
            for a permanent stick), in time order.

        Examples
        --------
        >>> from phaseimpact import seed_parameters, simulate_many
        >>> c = simulate_many([seed_parameters(kappa=k) for k in (1e9, 1e13)], "paper")
        >>> t, delta, dwell = c.sticks_of(1)
        >>> len(t), bool(dwell[-1] == float("inf"))
        (2, False)
        """
        start = int(self.stick_count[:i].sum())
        stop = start + int(self.stick_count[i])
        return self.stick_t[start:stop], self.stick_delta[start:stop], self.stick_dwell[start:stop]

    @classmethod
    def from_summary(cls, summary: np.ndarray, stick_count, stick_t, stick_delta, stick_dwell) -> Columns:
        """Columns from the driver's summary vectors and the stick phases of each run.

        Parameters
        ----------
        summary : ndarray, shape (n, N_SUMMARY)
            One summary vector per run (:mod:`.driver`, ``S_*``).
        stick_count : array of int, shape (n,)
            Stick phases per run.
        stick_t, stick_delta, stick_dwell : ndarray, shape (stick_count.sum(),)
            Their times (s), depths (m) and dwells (s), in run order.

        Returns
        -------
        Columns

        Examples
        --------
        >>> import numpy as np
        >>> from phaseimpact import Columns, seed_parameters, simulate
        >>> tr = simulate(seed_parameters(kappa=3e9), "paper")
        >>> t, delta, dwell = tr.stick_points()
        >>> c = Columns.from_summary(tr.summary[None, :], [len(t)], t, delta, dwell)
        >>> c.outcome_names().tolist(), c.n_stick.tolist()
        (['permanent-stick'], [1])
        """
        values = {name: summary[:, index].astype(dtype) for name, index, dtype, _ in SUMMARY_COLUMNS}
        return cls(summary[:, d.S_STATUS].astype(np.int8), summary[:, d.S_OUTCOME].astype(np.int8),
                   summary[:, d.S_REASON].astype(np.int8), values, np.asarray(stick_count, dtype=np.int64),
                   stick_t, stick_delta, stick_dwell)
