"""Readers of the archives of schemas 1 (phaseimpact 0.1) and 2 (groups ``/sweep`` and ``/curve``,
codes as strings): sweeps and critical curves, in today's terms."""

from __future__ import annotations

import json

import numpy as np

from ..continuation import CriticalCurve, SweepResult
from ..continuation.grid import Axis, Grid
from ..integrate import OUTCOMES, STATUSES
from ..integrate.result import SUMMARY_COLUMNS
from ..parameters import Parameters
from ._common import STOP_REASONS, _attr_str, _base, _law, _strings, _t_end

# -- schema 2 (groups /sweep and /curve, codes as strings) ------------------------------------------

def _codes(strings: np.ndarray, names) -> np.ndarray:
    lookup = {name: i for i, name in enumerate(names)}
    lookup[""] = -1
    try:
        return np.array([lookup[s] for s in strings.ravel()], dtype=np.int8).reshape(strings.shape)
    except KeyError as error:
        raise ValueError(f"unknown code {error.args[0]!r}; allowed: one of {', '.join(names)}") from None


def _read_sweep_v2(f) -> SweepResult:
    g = f["sweep"]
    names = json.loads(_attr_str(g, "axes"))
    axes = tuple(Axis(name, g[name][()], bool(g[name].attrs.get("log", False))) for name in names)
    grid = Grid(_base(f), _law(f), axes)
    settings = {"rtol": float(f.attrs["rtol"]), "engine": _attr_str(f, "engine"),
                "version": _attr_str(f, "package_version")}
    values = {}
    for name, _, dtype, _ in SUMMARY_COLUMNS:
        if name in g:
            values[name] = g[name][()].reshape(-1).astype(dtype)
    result = SweepResult(grid, _t_end(f), settings,
                         status=_codes(_strings(g["status"]).reshape(-1), STATUSES),
                         outcome=_codes(_strings(g["outcome"]).reshape(-1), OUTCOMES),
                         stop_reason=_codes(_strings(g["stop_reason"]).reshape(-1), STOP_REASONS),
                         stick_point=g["sticks/point"][()], stick_t=g["sticks/t"][()],
                         stick_delta=g["sticks/delta"][()], stick_dwell=g["sticks/dwell"][()])
    result.values.update(values)
    return result


def _read_curve_v2(f) -> CriticalCurve:
    g = f["curve"]
    param = _attr_str(g, "param")
    return CriticalCurve(param, g[param][()], g["kappa"][()], g["requested"][()].astype(bool), g["closed_form"][()],
                         g["predicted"][()], _attr_str(g, "what"), _law(f), _base(f), float(g.attrs["rtol"]),
                         int(g.attrs["contact_index"]), _attr_str(g, "message"))


# -- schema 1 (phaseimpact 0.1) ----------------------------------------------------------------------

#: Schema 1 outcome names in today's terms.
_V1_OUTCOMES = {"stick": "permanent-stick", "rest": "permanent-stick", "rebound": "rebound", "runaway": "runaway",
                "bounded-oscillation": "bounded", "failed": "failed", "": ""}


def _v1_parameters(f) -> Parameters:
    return Parameters(**json.loads(_attr_str(f, "parameters")))


def _read_sweep_v1(f) -> SweepResult:
    g = f["sweep"]
    kappa = g["kappa"][()]
    grid = Grid(_v1_parameters(f), _law(f), (Axis.make("kappa", kappa),))
    settings = {"rtol": float(f.attrs["rtol"]), "engine": _attr_str(f, "integrator"),
                "version": _attr_str(f, "package_version")}
    n_asymptotic = g["n_asymptotic"][()]
    old_status = _strings(g["status"])
    status = np.where(np.isin(old_status, ("success", "runaway")), "success", old_status)
    status = np.where(n_asymptotic < 0, "", np.where(status == "error", "non-finite", status))
    outcome = np.array([_V1_OUTCOMES.get(s, "failed") for s in _strings(g["outcome"])], dtype=object)
    reason = np.where(n_asymptotic < 0, "", np.where(outcome == "runaway", "runaway", "horizon"))
    offsets = g["points/offsets"][()]
    result = SweepResult(grid, float(f.attrs["t_end"]), settings,
                         status=_codes(np.asarray(status, dtype=object), STATUSES),
                         outcome=_codes(outcome, OUTCOMES), stop_reason=_codes(np.asarray(reason, dtype=object),
                                                                                 STOP_REASONS),
                         stick_point=np.repeat(np.arange(len(kappa)), np.diff(offsets)),
                         stick_t=np.full(int(offsets[-1]), np.nan), stick_delta=g["points/delta"][()],
                         stick_dwell=g["points/dwell"][()])
    for name in ("max_force", "max_indentation", "restitution", "dissipated_energy"):
        result.values[name] = g[name][()].astype(float)
    result.values["n_stick"] = n_asymptotic.astype(np.int64)
    return result


def _read_curve_v1(f) -> CriticalCurve:
    g = f["curve"]
    v = g["v"][()]
    message = "; ".join(str(m) for m in _strings(g["message"])) if "message" in g else ""
    return CriticalCurve("v", v, g["kappa_c"][()], np.ones(len(v), dtype=bool), np.full(len(v), np.nan),
                         np.full(len(v), np.nan), "kappa_c", _law(f), _v1_parameters(f), float(f.attrs["rtol"]),
                         1, message)
