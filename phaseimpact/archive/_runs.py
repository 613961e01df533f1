"""One run and a transition search: the archive kinds ``trajectory`` (a
:class:`~phaseimpact.integrate.result.Trajectory`) and ``transitions`` (a list of
:class:`~phaseimpact.continuation.Transition`)."""

from __future__ import annotations

import re

import numpy as np

from ..continuation import Transition
from ..integrate import OUTCOMES, STATUSES
from ..integrate import driver as _driver
from ..integrate import logs as _logs
from ..integrate.events import EVENT_KINDS
from ..integrate.result import SUMMARY_COLUMNS, Trajectory
from ..parameters import Parameters
from ._cf import _by, _codes_of, _coordinate, _grid_axes, _header, _parameter_units, _variable
from ._common import (
    _LONG_NAMES,
    _STATE,
    STOP_REASONS,
    TRANSITION_KINDS,
    _attr_str,
    _checked_codes,
    _Context,
    _Damaged,
    _data,
    _json,
    _json_attr,
    _law,
    _out_of_range,
    _real_attr,
    _shaped,
    _short,
)
from ._digests import _verified
from ._registry import ArchiveKind, register_kind


def _transitions_of(result) -> bool:
    """``result`` is what :func:`~phaseimpact.continuation.transitions` returns: a list of Transition."""
    return isinstance(result, (list, tuple)) and all(isinstance(item, Transition) for item in result)


def _write_trajectory(f, tr: Trajectory, created: str, context: _Context) -> None:
    settings = context.settings or {}
    found = re.search(r"rtol=([^,\]]+)", tr.integrator)  # the integrator's name rounds it: settings' is exact
    rtol = settings.get("rtol", float(found.group(1)) if found else None)
    _header(f, "trajectory", tr.law, tr.params if context.base is None else context.base, tr.t_end, rtol,
            tr.integrator, created, f"phaseimpact trajectory: {tr.law.name} law, {tr.outcome} ({tr.status})",
            context.settings)
    f.attrs["message"] = tr.message
    if tr.law_fault:  # the message of a run a user law ended is made from it
        f.attrs["law_fault"] = tr.law_fault
    # t, not time: CF's time coordinate (the name time, standard_name time or axis T) needs units "s since
    # <a date>", which xarray decodes to datetime64 (whole nanoseconds; the run's clock starts at 0)
    _coordinate(f, "t", tr.t, "s", "time since the start of the run").attrs["cartesian_axis"] = "T"
    for i, (name, units, long_name) in enumerate(_STATE):
        _variable(f, name, tr.y[:, i], ("t",), long_name=long_name, units=units)
    _variable(f, "delta", tr.delta, ("t",), long_name="indentation x1 - x2", units="m")
    _variable(f, "deltadot", tr.deltadot, ("t",), long_name="relative velocity x1dot - x2dot", units="m s-1")
    _variable(f, "force", tr.force, ("t",), long_name="contact force", units="N")
    _variable(f, "mode", tr.mode, ("t",), long_name="mode (paper: +-1 slipping, 0 stuck)")

    _variable(f, "event_time", tr.event_t, ("event",), long_name="time of the event", units="s")
    _variable(f, "event_kind", tr.event_kind, ("event",), long_name="kind of the event", flags=EVENT_KINDS,
              dtype=np.int8)
    for i, (name, units, long_name) in enumerate(_STATE):
        _variable(f, f"event_{name}", tr.event_y[:, i], ("event",), long_name=f"{long_name} at the event",
                  units=units)
    _variable(f, "event_force", tr.event_force, ("event",), long_name="contact force at the event", units="N")
    _variable(f, "event_mode", tr.event_mode, ("event",), long_name="mode after the event")

    for name, codes, table in (("status", tr.status, STATUSES), ("outcome", tr.outcome, OUTCOMES),
                               ("stop_reason", tr.stop_reason, STOP_REASONS)):
        _variable(f, name, _codes_of([codes], table, name)[0], long_name=_LONG_NAMES[name], flags=table)
    for name, index, dtype, units in SUMMARY_COLUMNS:
        value = np.asarray(tr.summary[index]).astype(dtype)
        _variable(f, name, value, long_name=_LONG_NAMES[name], units=units, fill=value.dtype.kind == "f")
    _variable(f, "first_stick_t", np.float64(tr.summary[_driver.S_FIRST_STICK_T]),
              long_name="time the first stick phase began", units="s", fill=True)
    _variable(f, "final_mode", np.int64(tr.final_mode), long_name="mode at the end of the run")
    components = {"components": " ".join(name for name, _, _ in _STATE),
                  "component_units": _json([units for _, units, _ in _STATE]),
                  "comment": "no units attribute: the components differ in unit (component_units)"}
    _variable(f, "initial_state", tr.initial_state, ("component",), long_name="state at the start", **components)
    _variable(f, "final_state", tr.final_state, ("component",), long_name="state at the end", **components)


def _write_transitions(f, items, created: str, context: _Context) -> None:
    settings = context.settings or {}
    _header(f, "transitions", context.law, context.base, None, settings.get("rtol"), "", created,
            f"phaseimpact transitions: {len(items)} changes of the long-time count over kappa{_by(context)}",
            context.settings)
    for key in ("kappa_min", "kappa_max"):
        if key in settings:
            f.attrs[key] = float(settings[key])
    units = _parameter_units("kappa", context)
    items = sorted(items, key=lambda t: t.kappa)  # the coordinate kappa increases (CF; .sel(kappa=...))

    def count(name):  # None (not confirmed, unbounded) is -1, read by xarray as NaN
        return np.array([-1 if getattr(t, name) is None else getattr(t, name) for t in items], dtype=np.int64)

    _grid_axes([_coordinate(f, "kappa", np.array([t.kappa for t in items], dtype=float), units,
                            "kappa at the transition")])
    _variable(f, "kind", _codes_of([t.kind for t in items], TRANSITION_KINDS, "kind"), ("kappa",),
              long_name="kind of the transition", flags=TRANSITION_KINDS)
    for name, long_name in (("count_below", "long-time count just below"),
                            ("count_above", "long-time count just above"),
                            ("extremum", "grazing: the extremum of delta that touches zero")):
        _variable(f, name, count(name), ("kappa",), long_name=long_name, units="1", fill=True)


def _read_trajectory(f) -> Trajectory:
    t = _data(f, "t", ndim=1, kinds="f")
    samples = np.empty((len(t), _logs.N_SMP_COLUMNS))
    samples[:, _logs.SMP_T] = t
    m = _data(f, "event_time", ndim=1, kinds="f").shape[0]
    events = np.empty((m, _logs.N_EV_COLUMNS))
    events[:, _logs.EV_T] = _shaped(f, "event_time", (m,))
    events[:, _logs.EV_KIND] = _checked_codes(f, "event_kind", EVENT_KINDS, (m,))
    events[:, _logs.EV_MODE] = _shaped(f, "event_mode", (m,), "i")
    for i, (name, _, _) in enumerate(_STATE):
        samples[:, _logs.SMP_Y + i] = _shaped(f, name, t.shape)
        events[:, _logs.EV_Y + i] = _shaped(f, f"event_{name}", (m,))
    samples[:, _logs.SMP_FORCE] = _shaped(f, "force", t.shape)
    samples[:, _logs.SMP_MODE] = _shaped(f, "mode", t.shape, "i")
    events[:, _logs.EV_FORCE] = _shaped(f, "event_force", (m,))
    summary = np.empty(_driver.N_SUMMARY)
    names = {}
    for name, index, table in (("status", _driver.S_STATUS, STATUSES), ("outcome", _driver.S_OUTCOME, OUTCOMES),
                               ("stop_reason", _driver.S_REASON, STOP_REASONS)):
        summary[index] = _checked_codes(f, name, table, ())
        names[name] = table[int(summary[index])]
    for name, index, dtype, _ in SUMMARY_COLUMNS:
        summary[index] = _shaped(f, name, (), "f" if dtype is float else "iu")
    summary[_driver.S_FIRST_STICK_T] = _shaped(f, "first_stick_t", ())
    summary[_driver.S_MODE] = _shaped(f, "final_mode", (), "i")
    tr = Trajectory(samples, events, Parameters(**_json_attr(f, "parameters", dict)), _law(f),
                    _shaped(f, "initial_state", (len(_STATE),)), _shaped(f, "final_state", (len(_STATE),)),
                    _real_attr(f, "t_end"), names["status"], names["stop_reason"], names["outcome"], summary,
                    _attr_str(f, "engine"), _attr_str(f, "law_fault") if "law_fault" in f.attrs else "")
    if tr.message != _attr_str(f, "message"):
        raise _Damaged(f"attribute message = {_short(_attr_str(f, 'message'))} is not the run's: "
                       f"{_short(tr.message)}")
    return tr


def _read_transitions(f) -> list[Transition]:
    kappa = _data(f, "kappa", ndim=1, kinds="f")
    n = len(kappa)
    kinds = _checked_codes(f, "kind", TRANSITION_KINDS, (n,))
    counts = {name: _shaped(f, name, (n,), "i") for name in ("count_below", "count_above", "extremum")}
    for name, values in counts.items():
        _out_of_range(name, values, values < -1, "-1 (not known) or a count >= 0")

    def count(name, i):
        return None if counts[name][i] == -1 else int(counts[name][i])

    return [Transition(TRANSITION_KINDS[kinds[i]], float(kappa[i]), count("count_below", i), count("count_above", i),
                       count("extremum", i)) for i in range(n)]


register_kind(ArchiveKind("trajectory", lambda r: isinstance(r, Trajectory), _write_trajectory,
                          _verified(_read_trajectory)))
register_kind(ArchiveKind("transitions", _transitions_of, _write_transitions, _verified(_read_transitions)))
