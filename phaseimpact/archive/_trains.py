"""Trains of impacts (:mod:`phaseimpact.train`): the archive kinds ``impact-train``, ``orbit-diagram``,
``map-branch`` and ``basins``. These results do not carry their case and law: ``save`` is given them."""

from __future__ import annotations

import math

import numpy as np

from ..integrate import STATUSES
from ..train import (
    BIFURCATION_KINDS,
    NO_MAP,
    NOT_CONVERGED,
    Attractor,
    Basins,
    ImpactTrain,
    MapBifurcation,
    MapBranch,
    OrbitDiagram,
)
from ._cf import _by, _codes_of, _coordinate, _grid_axes, _header, _parameter_units, _variable, netcdf_name
from ._common import (
    _LONG_NAMES,
    _YES_NO,
    _attr_str,
    _axis_values,
    _checked_axis,
    _checked_codes,
    _Context,
    _data,
    _float,
    _int_attr,
    _out_of_range,
    _real_attr,
    _shaped,
)
from ._digests import _verified
from ._registry import ArchiveKind, register_kind


def _period_of(result, context: _Context) -> float:
    """The time between arrivals (s) when one holds for the whole result; NaN when it varies (over T) or
    was not given."""
    if isinstance(result, (ImpactTrain, Basins)):
        return float(result.period)
    if getattr(result, "param", None) == "T":
        return math.nan
    return _float((context.settings or {}).get("period"))


def _train_header(f, kind: str, context: _Context, period: float, created: str, title: str) -> None:
    settings = context.settings or {}
    _header(f, kind, context.law, context.base, period, settings.get("rtol"), str(settings.get("engine", "")),
            created, title, context.settings)
    if not math.isnan(period):
        f.attrs["period"] = period


def _write_impact_train(f, r: ImpactTrain, created: str, context: _Context) -> None:
    n = len(r.peak_force)
    _train_header(f, "impact-train", context, float(r.period), created,
                  f"phaseimpact impact train: {n} impacts every {r.period:g} s{_by(context)}")
    _coordinate(f, "arrival", np.arange(n + 1, dtype=np.int64), None,
                "arrival n, at n period (the last: after the last impact)")
    _coordinate(f, "impact", np.arange(n, dtype=np.int64), None, "impact n, at n period")
    plate = np.asarray(r.plate, dtype=float)
    _variable(f, "x2", plate[:, 0], ("arrival",), long_name="plate displacement just before the arrival", units="m")
    _variable(f, "x2dot", plate[:, 1], ("arrival",), long_name="plate velocity just before the arrival",
              units="m s-1")
    _variable(f, "amplitude", r.amplitude, ("arrival",), long_name="plate amplitude before the arrival", units="m",
              dtype=float)
    for name, units, long_name in (("peak_force", "N", "largest contact force of the impact"),
                                   ("dissipated_energy", "J", "energy the impact's contact dissipated"),
                                   ("restitution", "1", "coefficient of restitution (NaN: no separation)"),
                                   ("energy_in", "J", "kinetic energy the projectile left in the plate and contact")):
        _variable(f, name, getattr(r, name), ("impact",), long_name=long_name, units=units, dtype=float, fill=True)
    _variable(f, "n_contacts", r.n_contacts, ("impact",), long_name="contacts of the impact", units="1",
              dtype=np.int64)
    _variable(f, "overlap", r.overlap, ("impact",), long_name="projectile still in contact at the next arrival",
              flags=_YES_NO, dtype=np.int8)
    _variable(f, "status", _codes_of(r.status, STATUSES, "status"), ("impact",), long_name=_LONG_NAMES["status"],
              flags=STATUSES)


def _write_orbit_diagram(f, r: OrbitDiagram, created: str, context: _Context) -> None:
    dim = netcdf_name(r.param)
    values = np.asarray(r.values, dtype=float)
    _train_header(f, "orbit-diagram", context, _period_of(r, context), created,
                  f"phaseimpact orbit diagram: {r.plate.shape[1]} samples at {len(values)} values of {r.param}"
                  f"{_by(context)}")
    f.attrs["param"] = r.param
    _grid_axes([_coordinate(f, dim, values, _parameter_units(r.param, context), r.param)])
    dims = (dim, "sample")
    _variable(f, "x2", r.plate[..., 0], dims, long_name="plate displacement just before the sampled impact",
              units="m", dtype=float)
    _variable(f, "x2dot", r.plate[..., 1], dims, long_name="plate velocity just before the sampled impact",
              units="m s-1", dtype=float)
    _variable(f, "peak_force", r.peak_force, dims, long_name="largest contact force of the sampled impact",
              units="N", dtype=float, fill=True)
    _variable(f, "distinct", r.distinct, (dim,), long_name="distinct states among the samples", units="1",
              dtype=np.int64)


def _multipliers(f, prefix: str, values, dims) -> None:
    values = np.asarray(values, dtype=complex)
    for part, name in (("real", values.real), ("imag", values.imag)):
        _variable(f, f"{prefix}multiplier_{part}", np.ascontiguousarray(name), dims,
                  long_name=f"Floquet multipliers, {'real' if part == 'real' else 'imaginary'} part", units="1")


_STRUCTURE = {"structure": "contacts stick_phases overlaps",
              "comment": "per period of the orbit: contacts, stick phases, projectiles still in contact at the "
                         "next arrival"}


def _write_map_branch(f, r: MapBranch, created: str, context: _Context) -> None:
    units = _parameter_units(r.param, context)
    name = netcdf_name(r.param)
    _train_header(f, "map-branch", context, _period_of(r, context), created,
                  f"phaseimpact map branch: period-{r.period_k} orbits over {r.param}, {len(r.values)} points, "
                  f"{len(r.points)} bifurcations{_by(context)}")
    f.attrs["param"] = r.param
    f.attrs["period_k"] = np.int64(r.period_k)
    f.attrs["message"] = str(r.message)
    # the parameter is no coordinate variable: it turns back at a fold (CF coordinates are monotonic)
    _variable(f, name, r.values, ("point",), long_name=f"{r.param} along the branch", units=units, dtype=float)
    plate = np.asarray(r.plate, dtype=float).reshape(-1, 2)
    _variable(f, "x2", plate[:, 0], ("point",), long_name="plate displacement before the orbit's first impact",
              units="m")
    _variable(f, "x2dot", plate[:, 1], ("point",), long_name="plate velocity before the orbit's first impact",
              units="m s-1")
    _multipliers(f, "", np.asarray(r.multipliers).reshape(-1, 2), ("point", "multiplier"))
    _variable(f, "stable", r.stable, ("point",), long_name="every multiplier inside the unit circle",
              flags=_YES_NO, dtype=np.int8)
    _variable(f, "contacts", np.asarray(r.contacts).reshape(-1, 3), ("point", "structure"),
              long_name="contact structure of the orbit", units="1", dtype=np.int64, **_STRUCTURE)
    points = r.points
    dims = ("bifurcation",)
    _variable(f, "bifurcation_kind", _codes_of([p.kind for p in points], BIFURCATION_KINDS, "kind"), dims,
              long_name="kind of the bifurcation", flags=BIFURCATION_KINDS)
    _variable(f, "bifurcation_value", [p.value for p in points], dims, long_name=f"{r.param} at the bifurcation",
              units=units, dtype=float)
    plate = np.array([p.plate for p in points], dtype=float).reshape(-1, 2)
    _variable(f, "bifurcation_x2", plate[:, 0], dims, long_name="plate displacement at the bifurcation", units="m")
    _variable(f, "bifurcation_x2dot", plate[:, 1], dims, long_name="plate velocity at the bifurcation",
              units="m s-1")
    _multipliers(f, "bifurcation_", np.array([p.multipliers for p in points], dtype=complex).reshape(-1, 2),
                 ("bifurcation", "multiplier"))
    _variable(f, "bifurcation_bracket", [p.bracket for p in points], dims,
              long_name=f"width of the final bracket in {r.param}", units=units, dtype=float)
    _variable(f, "bifurcation_test_value", [p.test_value for p in points], dims,
              long_name="test function at the bifurcation (0: grazing)", units="1", dtype=float)
    _variable(f, "bifurcation_contacts", np.array([p.contacts for p in points], dtype=np.int64).reshape(-1, 2, 3),
              ("bifurcation", "side", "structure"), long_name="contact structure on either side", units="1",
              **_STRUCTURE)
    _variable(f, "bifurcation_turning", [p.turning for p in points], dims,
              long_name="fold: the branch turns back in the parameter", flags=_YES_NO, dtype=np.int8)


def _write_basins(f, r: Basins, created: str, context: _Context) -> None:
    _train_header(f, "basins", context, float(r.period), created,
                  f"phaseimpact basins: {len(r.x2dot_values)} x {len(r.x2_values)} initial states, "
                  f"{len(r.attractors)} attractors{_by(context)}")
    f.attrs["not_converged"] = np.int64(r.not_converged)
    f.attrs["no_map"] = np.int64(r.no_map)
    _grid_axes([_coordinate(f, "x2dot", np.asarray(r.x2dot_values, dtype=float), "m s-1", "initial plate velocity"),
                _coordinate(f, "x2", np.asarray(r.x2_values, dtype=float), "m", "initial plate displacement")])
    _variable(f, "labels", r.labels, ("x2dot", "x2"), long_name="attractor reached from the initial state",
              dtype=np.int64, comment=f"the attractor's index; {NOT_CONVERGED}: no period repeated, {NO_MAP}: a run "
                                      "failed")
    _variable(f, "impacts", r.impacts, ("x2dot", "x2"), long_name="impacts until the orbit repeated", units="1",
              dtype=np.int64)
    periods = np.array([a.period for a in r.attractors], dtype=np.int64)
    _variable(f, "attractor_period", periods, ("attractor",), long_name="impacts per repetition of the attractor",
              units="1", comment="also its number of rows along orbit_point (the attractors' rows in order)")
    _variable(f, "attractor_count", [a.count for a in r.attractors], ("attractor",),
              long_name="initial states of the grid that go to the attractor", units="1", dtype=np.int64)
    plate = np.concatenate([np.asarray(a.plate, dtype=float).reshape(-1, 2) for a in r.attractors] or
                           [np.empty((0, 2))])
    _variable(f, "attractor_x2", plate[:, 0], ("orbit_point",), long_name="plate displacement on the attractor",
              units="m")
    _variable(f, "attractor_x2dot", plate[:, 1], ("orbit_point",), long_name="plate velocity on the attractor",
              units="m s-1")


def _read_impact_train(f) -> ImpactTrain:
    n = _data(f, "impact", ndim=1, kinds="iu").shape[0]
    plate = np.stack([_shaped(f, "x2", (n + 1,)), _shaped(f, "x2dot", (n + 1,))], axis=1)
    rows = {name: _shaped(f, name, (n,)) for name in ("peak_force", "dissipated_energy", "restitution", "energy_in")}
    return ImpactTrain(_real_attr(f, "period"), plate, rows["peak_force"], rows["dissipated_energy"],
                       rows["restitution"], rows["energy_in"], _shaped(f, "n_contacts", (n,), "iu").astype(np.int64),
                       _shaped(f, "amplitude", (n + 1,)), _checked_codes(f, "overlap", _YES_NO, (n,)).astype(bool),
                       [STATUSES[c] for c in _checked_codes(f, "status", STATUSES, (n,))])


def _read_orbit_diagram(f) -> OrbitDiagram:
    param = _attr_str(f, "param")
    values = _checked_axis(param, _data(f, netcdf_name(param), ndim=1), False).values
    n = len(values)
    samples = _data(f, "x2", ndim=2, kinds="f").shape[1]
    plate = np.stack([_shaped(f, "x2", (n, samples)), _shaped(f, "x2dot", (n, samples))], axis=-1)
    return OrbitDiagram(param, values, plate, _shaped(f, "peak_force", (n, samples)),
                        _shaped(f, "distinct", (n,), "iu").astype(np.int64))


def _complex(f, prefix: str, shape: tuple) -> np.ndarray:
    out = np.empty(shape, dtype=complex)  # parts set, not summed: re + 1j * im loses a -0.0 and mixes in NaN
    out.real = _shaped(f, f"{prefix}multiplier_real", shape)
    out.imag = _shaped(f, f"{prefix}multiplier_imag", shape)
    return out


def _read_map_branch(f) -> MapBranch:
    param = _attr_str(f, "param")
    values = _data(f, netcdf_name(param), ndim=1, kinds="f")
    n = len(values)
    m = _data(f, "bifurcation_value", ndim=1, kinds="f").shape[0]
    kinds = _checked_codes(f, "bifurcation_kind", BIFURCATION_KINDS, (m,))
    turning = _checked_codes(f, "bifurcation_turning", _YES_NO, (m,))
    plate = np.stack([_shaped(f, "bifurcation_x2", (m,)), _shaped(f, "bifurcation_x2dot", (m,))], axis=1)
    multipliers = _complex(f, "bifurcation_", (m, 2))
    contacts = _shaped(f, "bifurcation_contacts", (m, 2, 3), "iu").tolist()
    bracket, test = _shaped(f, "bifurcation_bracket", (m,)), _shaped(f, "bifurcation_test_value", (m,))
    points = [MapBifurcation(BIFURCATION_KINDS[kinds[i]], param, float(_shaped(f, "bifurcation_value", (m,))[i]),
                             plate[i], multipliers[i], float(bracket[i]), float(test[i]),
                             tuple(tuple(side) for side in contacts[i]), bool(turning[i])) for i in range(m)]
    return MapBranch(param, _int_attr(f, "period_k"), values,
                     np.stack([_shaped(f, "x2", (n,)), _shaped(f, "x2dot", (n,))], axis=1), _complex(f, "", (n, 2)),
                     _checked_codes(f, "stable", _YES_NO, (n,)).astype(bool),
                     _shaped(f, "contacts", (n, 3), "iu").astype(np.int64), points, _attr_str(f, "message"))


def _read_basins(f) -> Basins:
    xs = _checked_axis("x2", _data(f, "x2", ndim=1), False).values
    vs = _checked_axis("x2dot", _data(f, "x2dot", ndim=1), False).values
    shape = (len(vs), len(xs))
    labels = _shaped(f, "labels", shape, "i").astype(np.int64)
    periods = _data(f, "attractor_period", ndim=1, kinds="iu").astype(np.int64)
    counts = _shaped(f, "attractor_count", periods.shape, "iu").astype(np.int64)
    _out_of_range("labels", labels.reshape(-1), (labels.reshape(-1) < NO_MAP) | (labels.reshape(-1) >= len(periods)),
                  f"{NO_MAP} to {len(periods) - 1}")
    _out_of_range("attractor_period", periods, periods < 1, "a positive integer")
    rows = int(periods.sum())
    plate = np.stack([_shaped(f, "attractor_x2", (rows,)), _shaped(f, "attractor_x2dot", (rows,))], axis=1)
    starts = np.concatenate([[0], np.cumsum(periods)])
    attractors = [Attractor(plate[a:b], int(b - a), int(c)) for a, b, c in zip(starts, starts[1:], counts,
                                                                                 strict=False)]
    return Basins(_real_attr(f, "period"), xs, vs, labels, _shaped(f, "impacts", shape, "iu").astype(np.int64),
                  attractors, _int_attr(f, "not_converged"), _int_attr(f, "no_map"))


def _orbit_diagram_axes(f, version: int) -> dict:
    param = _attr_str(f, "param")
    return {param: _axis_values(f, param, netcdf_name(param))}


register_kind(ArchiveKind("impact-train", lambda r: isinstance(r, ImpactTrain), _write_impact_train,
                          _verified(_read_impact_train)))
register_kind(ArchiveKind("orbit-diagram", lambda r: isinstance(r, OrbitDiagram), _write_orbit_diagram,
                          _verified(_read_orbit_diagram), _orbit_diagram_axes))
register_kind(ArchiveKind("map-branch", lambda r: isinstance(r, MapBranch), _write_map_branch,
                          _verified(_read_map_branch)))
register_kind(ArchiveKind("basins", lambda r: isinstance(r, Basins), _write_basins, _verified(_read_basins)))
