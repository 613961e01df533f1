"""HDF5 archives of sweeps and ``kappa_c(v)`` curves, readable with plain h5py.

Schema (``schema_version`` 1; the README has the full table)::

    /                      attrs: schema_version, package_version, kind ("sweep" | "critical-curve"),
                                  law (JSON), parameters (JSON, SI), integrator, rtol, min_dwell,
                                  t_end (s), created (ISO 8601, UTC)
    /sweep/kappa           (n,)   float64  N s/m^(1+alpha)
    /sweep/n_asymptotic    (n,)   int64    -1: not computed yet
    /sweep/outcome         (n,)   str      "" if not computed
    /sweep/status          (n,)   str
    /sweep/max_force       (n,)   float64  N    (NaN: not computed)
    /sweep/max_indentation (n,)   float64  m
    /sweep/restitution     (n,)   float64  -    (NaN: no separation)
    /sweep/dissipated_energy (n,) float64  J
    /sweep/points/offsets  (n+1,) int64    point i's rows are offsets[i]:offsets[i+1]
    /sweep/points/delta    (m,)   float64  m
    /sweep/points/deltadot (m,)   float64  m/s
    /sweep/points/dwell    (m,)   float64  s
    /critical              attrs: kappa_c, bracket (2,), n_below, n_above, rtol, shift, status, message
    /curve/v               (k,)   float64  m/s
    /curve/kappa_c         (k,)   float64  N s/m^(1+alpha) (NaN: not found)
    /curve/bracket         (k, 2) float64
    /curve/status          (k,)   str

Files are written to a temporary file in the same folder and renamed over the target, so a
reader (or a crash) only ever sees the previous file or the complete new one.
"""

from __future__ import annotations

import dataclasses
import datetime
import json
import os

import h5py
import numpy as np

from . import __version__
from ._atomic import atomic_path
from .continuation import CriticalCurve, CriticalDamping, SweepResult
from .model import ContactLaw
from .parameters import Parameters

__all__ = ["SCHEMA_VERSION", "save", "load"]

SCHEMA_VERSION = 1
_STR = h5py.string_dtype()
_SWEEP_FLOATS = {"max_force": "N", "max_indentation": "m", "restitution": "1", "dissipated_energy": "J"}


def save(result: SweepResult | CriticalCurve, path, *, law: ContactLaw | None = None,
         params: Parameters | None = None, settings: dict | None = None) -> None:
    """Write ``result`` to ``path`` atomically (temporary file, then rename)."""
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
        if isinstance(result, SweepResult):
            _write_header(f, "sweep", result.law, result.params, result.t_end, result.settings)
            _write_sweep(f.create_group("sweep"), result)
            if result.critical is not None:
                _write_critical(f.create_group("critical"), result.critical)
        elif isinstance(result, CriticalCurve):
            if law is None or params is None:
                raise ValueError("saving a critical curve needs law= and params=")
            _write_header(f, "critical-curve", law, params, (settings or {}).get("t_end", np.nan), settings or {})
            _write_curve(f.create_group("curve"), result)
        else:
            raise TypeError(f"cannot archive a {type(result).__name__}")


def _write_header(f, kind, law, params, t_end, settings):
    f.attrs["schema_version"] = SCHEMA_VERSION
    f.attrs["package_version"] = __version__
    f.attrs["kind"] = kind
    f.attrs["law"] = json.dumps(dataclasses.asdict(law))
    f.attrs["parameters"] = json.dumps(params.as_dict())
    f.attrs["integrator"] = str(settings.get("integrator", "exact"))
    f.attrs["rtol"] = float(settings.get("rtol", np.nan))
    f.attrs["min_dwell"] = float(settings.get("min_dwell", -1.0))
    f.attrs["t_end"] = float(t_end)
    f.attrs["created"] = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


def _dataset(group, name, data, units, dtype=None):
    d = group.create_dataset(name, data=data, dtype=dtype)
    d.attrs["units"] = units
    return d


def _write_sweep(g, r: SweepResult):
    _dataset(g, "kappa", r.kappa, "N s/m^(1+alpha)")
    _dataset(g, "n_asymptotic", r.n_asymptotic.astype(np.int64), "1")
    _dataset(g, "outcome", np.array(r.outcome, dtype=object), "", dtype=_STR)
    _dataset(g, "status", np.array(r.status, dtype=object), "", dtype=_STR)
    for name, units in _SWEEP_FLOATS.items():
        _dataset(g, name, getattr(r, name).astype(float), units)
    counts = np.array([len(d) for d in r.dwell], dtype=np.int64)
    points = np.concatenate([p.reshape(-1, 2) for p in r.points]) if counts.sum() else np.empty((0, 2))
    p = g.create_group("points")
    p.attrs["layout"] = "ragged: rows offsets[i]:offsets[i+1] belong to sweep point i"
    _dataset(p, "offsets", np.concatenate([[0], np.cumsum(counts)]).astype(np.int64), "1")
    _dataset(p, "delta", points[:, 0], "m")
    _dataset(p, "deltadot", points[:, 1], "m/s")
    _dataset(p, "dwell", np.concatenate(r.dwell) if counts.sum() else np.empty(0), "s")


def _write_critical(g, c: CriticalDamping):
    g.attrs["kappa_c"] = np.nan if c.kappa_c is None else c.kappa_c
    g.attrs["bracket"] = np.asarray(c.bracket, dtype=float)
    g.attrs["n_below"], g.attrs["n_above"] = c.n_below, c.n_above
    g.attrs["rtol"] = c.rtol
    g.attrs["shift"] = np.nan if c.shift is None else c.shift
    g.attrs["status"], g.attrs["message"] = c.status, c.message
    g.attrs["v"], g.attrs["law"] = c.v, c.law
    g.attrs["evaluations"] = c.evaluations


def _write_curve(g, curve: CriticalCurve):
    _dataset(g, "v", curve.v, "m/s")
    _dataset(g, "kappa_c", curve.kappa_c, "N s/m^(1+alpha)")
    _dataset(g, "bracket", np.array([r.bracket for r in curve.results], dtype=float).reshape(-1, 2),
             "N s/m^(1+alpha)")
    _dataset(g, "n_above", np.array([r.n_above for r in curve.results], dtype=np.int64), "1")
    _dataset(g, "shift", np.array([np.nan if r.shift is None else r.shift for r in curve.results]), "1")
    _dataset(g, "status", np.array([r.status for r in curve.results], dtype=object), "", dtype=_STR)
    _dataset(g, "message", np.array([r.message for r in curve.results], dtype=object), "", dtype=_STR)


def load(path):
    """Read an archive back: a :class:`SweepResult` or a :class:`CriticalCurve`.

    Raises ``ValueError`` for a missing, foreign, truncated or newer-schema file.
    """
    path = os.fspath(path)
    try:
        f = h5py.File(path, "r")
    except FileNotFoundError:
        raise ValueError(f"archive {path!r} does not exist") from None
    except OSError as error:
        raise ValueError(f"{path!r} is not a readable HDF5 file (truncated or foreign): {error}") from None
    with f:
        if "schema_version" not in f.attrs or "kind" not in f.attrs:
            raise ValueError(f"{path!r} is not a phaseimpact archive (no schema_version attribute)")
        version = int(f.attrs["schema_version"])
        if version > SCHEMA_VERSION:
            raise ValueError(f"{path!r} has schema_version {version}; this phaseimpact reads up to "
                             f"{SCHEMA_VERSION}: upgrade phaseimpact")
        try:
            law = ContactLaw(**json.loads(f.attrs["law"]))
            params = Parameters(**json.loads(f.attrs["parameters"]))
            kind = f.attrs["kind"]
            if kind == "sweep":
                return _read_sweep(f, law, params)
            if kind == "critical-curve":
                return _read_curve(f, law, params)
        except (KeyError, OSError, TypeError, json.JSONDecodeError) as error:
            raise ValueError(f"{path!r} is an incomplete or damaged phaseimpact archive: {error}") from None
        raise ValueError(f"{path!r} has unknown kind {kind!r}")


def _strings(dataset):
    return np.array([s.decode() if isinstance(s, bytes) else s for s in dataset[()]], dtype=object)


def _read_sweep(f, law, params) -> SweepResult:
    g = f["sweep"]
    offsets = g["points/offsets"][()]
    delta, deltadot, dwell = g["points/delta"][()], g["points/deltadot"][()], g["points/dwell"][()]
    n = len(g["kappa"])
    settings = {"rtol": float(f.attrs["rtol"]), "min_dwell": float(f.attrs["min_dwell"]),
                "integrator": str(f.attrs["integrator"])}
    result = SweepResult(
        g["kappa"][()], params, law, float(f.attrs["t_end"]), settings,
        n_asymptotic=g["n_asymptotic"][()].astype(int), outcome=_strings(g["outcome"]),
        status=_strings(g["status"]),
        points=[np.column_stack([delta[offsets[i]:offsets[i + 1]], deltadot[offsets[i]:offsets[i + 1]]])
                for i in range(n)],
        dwell=[dwell[offsets[i]:offsets[i + 1]] for i in range(n)],
        **{name: g[name][()] for name in _SWEEP_FLOATS},
    )
    if "critical" in f:
        a = f["critical"].attrs
        kappa_c = float(a["kappa_c"])
        shift = float(a["shift"])
        result.critical = CriticalDamping(
            str(a["law"]), float(a["v"]), None if np.isnan(kappa_c) else kappa_c, tuple(a["bracket"].tolist()),
            int(a["n_below"]), int(a["n_above"]), float(a["rtol"]), None if np.isnan(shift) else shift,
            str(a["status"]), str(a["message"]), int(a["evaluations"]))
    return result


def _read_curve(f, law, params) -> CriticalCurve:
    g = f["curve"]
    v, kappa_c, bracket = g["v"][()], g["kappa_c"][()], g["bracket"][()]
    status, message = _strings(g["status"]), _strings(g["message"])
    n_above, shift = g["n_above"][()], g["shift"][()]
    results = tuple(
        CriticalDamping(law.name, float(v[i]), None if np.isnan(kappa_c[i]) else float(kappa_c[i]),
                        tuple(bracket[i].tolist()), 1 if not np.isnan(kappa_c[i]) else -1, int(n_above[i]),
                        float(f.attrs["rtol"]), None if np.isnan(shift[i]) else float(shift[i]),
                        str(status[i]), str(message[i]), 0)
        for i in range(len(v)))
    return CriticalCurve(v, results)
