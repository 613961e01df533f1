"""The result of an integration, and the bookkeeping every integrator shares."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model import V1, V2, X1, X2, Coefficients, ContactLaw, contact_force
from ..parameters import Parameters
from ._events import Event

__all__ = ["Trajectory", "Save", "STATUSES"]

#: ``success``: reached ``t_end`` or stopped once the outcome was settled; the others are failures.
STATUSES = ("success", "runaway", "step-size-collapse", "too-many-steps", "non-finite")


@dataclass(frozen=True)
class Save:
    """Which outputs a scene needs.

    Attributes
    ----------
    kind : {"summary", "steps", "times"}
        ``summary``: events, extremes and the final state only (no per-step arrays);
        ``steps``: every accepted step and event; ``times``: the state at ``times``.
    times : ndarray or None
        Output times (s) for ``kind="times"``, increasing.
    """

    kind: str = "summary"
    times: np.ndarray | None = None

    @classmethod
    def parse(cls, save) -> Save:
        if isinstance(save, Save):
            return save
        if isinstance(save, str):
            if save not in ("summary", "steps"):
                raise ValueError(f"save = {save!r} is out of range; "
                                 "allowed: 'summary', 'steps' or an array of times")
            return cls(save)
        times = np.asarray(save, dtype=float)
        if times.ndim != 1 or not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
            raise ValueError("save: output times must be a finite, strictly increasing 1-d array")
        return cls("times", times)

    @property
    def keeps_samples(self) -> bool:
        return self.kind != "summary"


@dataclass(frozen=True)
class Trajectory:
    """A trajectory of the impact model (times, states, events, counters, status).

    Attributes
    ----------
    t : ndarray, shape (n,)
        Sample times, s (empty for a summary run).
    y : ndarray, shape (n, 5)
        States ``(x1, x2, x1dot, x2dot, W)`` at ``t``; ``W`` is the contact work, J.
    force : ndarray, shape (n,)
        Contact force at ``t``, N.
    mode : ndarray of int, shape (n,)
        Mode at ``t`` (``paper``: +-1 slipping, 0 stuck).
    events : tuple of Event
        Events in time order (``contact`` at t = 0 included).
    params, law
        What was integrated.
    t_end : float
        Requested horizon, s.
    t_stop : float
        Where integration stopped (``< t_end`` when the outcome was settled early or it failed).
    final_state, final_mode
        State and mode at ``t_stop``.
    settled : bool
        The run stopped early because nothing can change any more (permanent stick, a
        projectile out of reach): states at ``t > t_stop`` follow without further events.
    status : str
        One of :data:`STATUSES`; ``message`` says why.
    max_force, max_indentation : float
        Extremes over the whole run (exact: taken at located events), N and m.
    nfev, nsteps : int
        Right-hand-side evaluations and accepted steps.
    integrator : str
        Name of the integrator and its settings.
    """

    t: np.ndarray
    y: np.ndarray
    force: np.ndarray
    mode: np.ndarray
    events: tuple
    params: Parameters
    law: ContactLaw
    t_end: float
    t_stop: float
    final_state: np.ndarray
    final_mode: int
    settled: bool
    status: str
    message: str
    max_force: float
    max_indentation: float
    nfev: int
    nsteps: int
    integrator: str

    @property
    def ok(self) -> bool:
        return self.status == "success"

    @property
    def x1(self):
        return self.y[:, X1]

    @property
    def x2(self):
        return self.y[:, X2]

    @property
    def delta(self):
        """Indentation ``x1 - x2``, m."""
        return self.y[:, X1] - self.y[:, X2]

    @property
    def deltadot(self):
        """Relative velocity, m/s."""
        return self.y[:, V1] - self.y[:, V2]

    def events_of(self, *kinds) -> list[Event]:
        return [e for e in self.events if e.kind in kinds]


@dataclass
class Recorder:
    """Collects samples, events and running extremes while an integrator runs."""

    c: Coefficients
    law: ContactLaw
    save: Save
    plain: bool = False  # eq. 8 read literally (fixed-step methods): no modes
    t: list = field(default_factory=list)
    y: list = field(default_factory=list)
    mode: list = field(default_factory=list)
    events: list = field(default_factory=list)
    max_force: float = -np.inf
    max_indentation: float = -np.inf

    def extremes(self, y, mode) -> None:
        """Fold states ``y`` (shape (5,) or (n, 5)) into the running extremes."""
        force = contact_force(y, self.c, self.law, None if self.plain else mode)
        self.max_force = max(self.max_force, float(np.max(force)))
        self.max_indentation = max(self.max_indentation, float(np.max(y[..., X1] - y[..., X2])))

    def sample(self, t, y, mode) -> None:
        self.t.append(t)
        self.y.append(np.array(y, dtype=float))
        self.mode.append(mode)

    def events_of(self, kind: str) -> list:
        return [e for e in self.events if e.kind == kind]

    def event(self, event: Event) -> None:
        self.events.append(event)
        self.extremes(event.state, event.mode)
        if self.save.kind == "steps":
            self.sample(event.t, event.state, event.mode)

    def finish(self, *, params, t_end, t_stop, y, mode, settled, status, message, nfev, nsteps,
               integrator) -> Trajectory:
        self.extremes(y, mode)
        if self.t:
            t = np.asarray(self.t, dtype=float)
            ys = np.asarray(self.y, dtype=float).reshape(len(t), 5)
            modes = np.asarray(self.mode, dtype=int)
        else:
            t, ys, modes = np.empty(0), np.empty((0, 5)), np.empty(0, dtype=int)
        force = contact_force(ys, self.c, self.law, None if self.plain else modes)
        return Trajectory(
            t=t, y=ys, force=np.asarray(force, dtype=float), mode=modes, events=tuple(self.events),
            params=params, law=self.law, t_end=t_end, t_stop=t_stop, final_state=np.array(y, dtype=float),
            final_mode=int(mode), settled=settled, status=status, message=message,
            max_force=self.max_force, max_indentation=self.max_indentation,
            nfev=int(nfev), nsteps=int(nsteps), integrator=integrator,
        )


def state_scale(params: Parameters, c: Coefficients) -> np.ndarray:
    """Characteristic size of each state component (for absolute tolerances).

    Positions scale with the Hertz indentation on a rigid wall (REFERENCE §4), velocities with
    the impact speed and the work with the initial energy.
    """
    indentation = params.hertz_indentation
    work = 0.5 * params.M1 * params.v**2
    return np.array([indentation, indentation, params.v, params.v, work])
