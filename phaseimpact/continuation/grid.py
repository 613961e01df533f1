"""Grids of named parameters: any parameter is an axis (DESIGN principle 6).

An axis is a name and a 1-d array of values. Names are :class:`~phaseimpact.Parameters` fields
(``kappa``, ``v``, ``M1``...) and, on a :class:`~phaseimpact.case.Case` base, every quantity of
either body or the geometry (``plate.E``, ``projectile.rho``, ``R1``, ``h``...). An axis the law
does not read (``kappa`` under ``abrate`` or a restitution law) is refused before any work.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ..case import Case
from ..integrate.api import HORIZON_CAP_PERIODS, check_rtol, hertz_contact_time, scales, state_tolerances
from ..integrate.batch import Batch, pack_batch
from ..model.laws import ContactLaw
from ..model.rhs import ALPHA_, DAMP_, K_, M1_, pack
from ..parameters import KAPPA_MAX, PARAMETER_NAMES, V_RANGE, Parameters, indentation_of, is_number
from ..settings import QUANTITIES, SETTABLE

__all__ = ["Axis", "Grid", "parse_axis", "MAX_POINTS"]

#: Largest grid held in memory (about 200 bytes a point, plus stick points).
MAX_POINTS = 10_000_000
_NUMERIC_FIELDS = tuple(n for n in PARAMETER_NAMES if n not in ("target", "R"))


@dataclass(frozen=True)
class Axis:
    """One named axis: ``values`` (1-d, finite) and whether it is meant to be read on a log scale.

    Build one with :meth:`make` (which checks the values) or :func:`parse_axis` (from text); a
    :class:`Grid` checks the name and the range of the values against its base case and law.

    Attributes
    ----------
    name : str
        A parameter name (``kappa``, ``v``, ``M1``...; ``plate.E``, ``R1``... on a Case base).
    values : ndarray of float, shape (n,)
        The parameter's values, in SI units (``kappa`` in N s/m^(1+alpha), ``v`` in m/s).
    log : bool
        Drawn and refined on a log scale.

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact.continuation import Axis
    >>> a = Axis.make("kappa", np.geomspace(1e9, 1e12, 4))
    >>> a.name, len(a.values), a.log
    ('kappa', 4, True)
    """

    name: str
    values: np.ndarray
    log: bool = False

    @classmethod
    def make(cls, name: str, values, log: bool | None = None) -> Axis:
        """An axis from a name and a sequence of numbers, checked.

        Parameters
        ----------
        name : str
            The parameter's name (checked against the case by :class:`Grid`).
        values : sequence or ndarray of numbers
            Non-empty, 1-d, finite; SI units. Strings and generators are refused.
        log : bool, optional
            Default: True for more than two positive values spaced geometrically.

        Returns
        -------
        Axis

        Raises
        ------
        TypeError
            If ``name`` is not a string or ``values`` not a sequence of numbers.
        ValueError
            If ``values`` is empty, not 1-d, or holds a non-finite number.

        Examples
        --------
        >>> from phaseimpact.continuation import Axis
        >>> Axis.make("v", [0.5, 1.0, 1.5]).log, Axis.make("v", [0.5, 1.0, 2.0]).log
        (False, True)
        >>> Axis.make("v", [])
        Traceback (most recent call last):
        ...
        ValueError: axis v = array([], dtype=float64) is out of range; allowed: a non-empty 1-d array of finite numbers
        """
        if not isinstance(name, str):
            raise TypeError(f"axis name = {name!r} has the wrong type ({type(name).__name__}); allowed: a string")
        numeric = (values.dtype.kind in "iuf" if isinstance(values, np.ndarray)
                   else isinstance(values, list | tuple | range) and all(map(is_number, values)))
        if not numeric:  # strings are not read as numbers, a generator is not a sequence
            raise TypeError(f"axis {name} = {values!r} has the wrong type ({type(values).__name__}); allowed: a 1-d "
                            "sequence or array of numbers")
        values = np.asarray(values, dtype=float)
        if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)):
            raise ValueError(f"axis {name} = {values!r} is out of range; allowed: a non-empty 1-d array of "
                             "finite numbers")
        if log is None:
            log = bool(values.size > 2 and np.all(values > 0) and np.allclose(np.diff(np.log(values)),
                                                                                  np.log(values[1] / values[0])))
        return cls(name, values, log)


def parse_axis(text: str) -> Axis:
    """``NAME=START:STOP:NUM[:log]`` (or ``NAME=V1,V2,...``) as an :class:`Axis`.

    The command line's ``--axis``: ``NUM`` values from ``START`` to ``STOP`` (both included),
    spaced geometrically with ``:log`` (linearly without it, or with ``:lin``), or the listed
    values.

    Parameters
    ----------
    text : str
        E.g. ``"kappa=1e9:1e12:50:log"``, ``"v=0.5:13:60"`` or ``"R1=0.005,0.01,0.02"``; SI units.

    Returns
    -------
    Axis
        ``log`` True only for the ``:log`` form.

    Raises
    ------
    TypeError
        If ``text`` is not a string.
    ValueError
        For text not of these forms, non-finite ends, ``NUM`` not an integer in
        ``1..MAX_POINTS``, or ``:log`` with an end <= 0.

    Examples
    --------
    >>> from phaseimpact.continuation import parse_axis
    >>> a = parse_axis("kappa=1e9:1e12:4:log")
    >>> a.name, a.values.tolist(), a.log
    ('kappa', [1000000000.0, 10000000000.0, 100000000000.0, 1000000000000.0], True)
    >>> parse_axis("v=0.5,1,2").values.tolist()
    [0.5, 1.0, 2.0]
    """
    if not isinstance(text, str):
        raise TypeError(f"axis = {text!r} has the wrong type ({type(text).__name__}); allowed: a string "
                        "NAME=START:STOP:NUM[:log] or NAME=V1,V2,...")
    match = re.fullmatch(r"\s*([A-Za-z_][\w.]*)\s*=\s*(.+)", text)
    if not match:
        raise ValueError(f"axis = {text!r} is out of range; allowed: NAME=START:STOP:NUM[:log] or NAME=V1,V2,...")
    name, spec = match.groups()
    try:
        if ":" in spec:
            parts = spec.split(":")
            if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] not in ("log", "lin")):
                raise ValueError
            start, stop, num = float(parts[0]), float(parts[1]), float(parts[2])
            log = len(parts) == 4 and parts[3] == "log"
        else:
            return Axis.make(name, [float(v) for v in spec.split(",")], log=False)
    except ValueError:
        raise ValueError(f"axis {name} = {spec!r} is out of range; allowed: START:STOP:NUM[:log] with numbers, "
                         "or V1,V2,...") from None
    if not (math.isfinite(num) and num == int(num) and 1 <= num <= MAX_POINTS):  # NaN has no int()
        raise ValueError(f"axis {name} = {spec!r}: NUM = {parts[2]!r} is out of range; allowed: an integer "
                         f"1 <= NUM <= {MAX_POINTS}")
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise ValueError(f"axis {name} = {spec!r} is out of range; allowed: finite START and STOP")
    if log and not (start > 0 and stop > 0):
        raise ValueError(f"axis {name} = {spec!r} is out of range; allowed: START > 0 and STOP > 0 with :log")
    values = np.geomspace(start, stop, int(num)) if log else np.linspace(start, stop, int(num))
    return Axis(name, values, log)


def _check_span(name: str, values: np.ndarray, low: float, high: float, unit: str) -> None:
    """Every value of an axis the batch packs as an array (not through Parameters) within its range."""
    bad = values[(values < low) | (values > high)]
    if bad.size:
        raise ValueError(f"axis {name} holds {name} = {float(bad[0])!r}, out of range; allowed: {low:g} <= {name} <= "
                         f"{high:g} ({unit})")


@dataclass(frozen=True)
class Grid:
    """A grid of named axes over a base case (Parameters or Case), for one law.

    Points are numbered in C order over the axes (the last axis varies fastest). Every axis is
    checked when the grid is made, before any work: its name must be a parameter the law reads
    (material and geometry names need a Case base), its values distinct, ``kappa`` within
    ``[0, KAPPA_MAX]`` and ``v`` within ``V_RANGE``, every corner of the grid a valid case, and
    the grid at most :data:`MAX_POINTS` points.

    Parameters
    ----------
    base : Parameters or Case
        The case the axes vary.
    law : ContactLaw
        The law of every point (:func:`~phaseimpact.model.as_law` makes one from a name).
    axes : tuple of Axis
        At least one, with distinct names.

    Attributes
    ----------
    base, law, axes
        As given.
    shape : tuple of int
        Number of values of each axis.
    size : int
        Number of points.
    names : tuple of str
        The axes' names, in order.

    Raises
    ------
    TypeError
        If ``base`` is not Parameters or a Case, or an axis is not an :class:`Axis`.
    ValueError
        For an axis the law does not read, a name that is no parameter, repeated names or values,
        a value out of range, or more than :data:`MAX_POINTS` points.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import Axis, Grid
    >>> from phaseimpact.model import as_law
    >>> axes = (Axis.make("kappa", [1e9, 1e12]), Axis.make("v", [1.0, 2.0, 3.0]))
    >>> g = Grid(seed_parameters(), as_law("paper"), axes)
    >>> g.shape, g.size, g.names
    ((2, 3), 6, ('kappa', 'v'))
    >>> Grid(seed_parameters(), as_law("abrate"), (Axis.make("kappa", [1e9, 1e12]),))
    Traceback (most recent call last):
    ...
    ValueError: axis 'kappa' is not read by law 'abrate' (its damping comes from no damping): ...
    """

    base: Parameters | Case
    law: ContactLaw
    axes: tuple

    def __post_init__(self):
        if not isinstance(self.base, Parameters | Case):
            raise TypeError(f"base = {self.base!r} has the wrong type ({type(self.base).__name__}); allowed: "
                            "Parameters or a Case")
        if not self.axes:
            raise ValueError("axes: allowed: at least one axis")
        for axis in self.axes:
            if not isinstance(axis, Axis):
                raise TypeError(f"axis = {axis!r} has the wrong type ({type(axis).__name__}); allowed: an Axis "
                                "(Axis.make(name, values) or parse_axis('NAME=START:STOP:NUM')), or give the axes as "
                                "a dict name -> values")
        names = [a.name for a in self.axes]
        if len(set(names)) != len(names):
            raise ValueError(f"axes = {names!r} is out of range; allowed: distinct names")
        allowed = self.allowed_names()
        for axis in self.axes:
            if axis.name not in allowed:
                if axis.name in SETTABLE and axis.name not in QUANTITIES:
                    raise ValueError(f"axis {axis.name!r} is not read by the equations of motion (it sets the "
                                     "validity check or the law, not the dynamics): every point would be the same; "
                                     f"allowed: {', '.join(allowed)}")
                if axis.name in QUANTITIES:
                    raise ValueError(f"axis {axis.name!r} needs a Case base (materials and geometry, e.g. "
                                     "phaseimpact.case.seed_case() or load_case(NAME)), not Parameters; allowed on "
                                     f"Parameters: {', '.join(allowed)}")
                raise ValueError(f"axis {axis.name!r} is out of range; allowed: {', '.join(allowed)}")
            if np.unique(axis.values).size != axis.values.size:
                raise ValueError(f"axis {axis.name} = {axis.values!r} is out of range; allowed: distinct values "
                                 "(a repeated value computes the same points twice)")
            if axis.name == "kappa":
                _check_span("kappa", axis.values, 0.0, KAPPA_MAX, "N s/m^(1+alpha)")
            elif axis.name == "v":
                _check_span("v", axis.values, *V_RANGE, "m/s")
            if not self.law.reads(axis.name):
                source = self.law.damping_source or "no damping"
                raise ValueError(f"axis {axis.name!r} is not read by law {self.law.label()!r} (its damping "
                                 f"comes from {source}): every point would be the same; allowed: a parameter "
                                 "the law reads")
        if self.size > MAX_POINTS:
            raise ValueError(f"grid of {self.size} points is out of range; allowed: at most {MAX_POINTS}")
        # every corner must be a valid case, and each axis's smallest and largest value (a range of the
        # inputs is an interval: both ends valid, all between valid), checked before any work
        for corner in np.ndindex(*(2,) * len(self.axes)):
            self.parameters_at({a.name: a.values[-1 if k else 0] for a, k in zip(self.axes, corner, strict=True)})
        for axis in self.axes:
            for value in (axis.values.min(), axis.values.max()):
                self.parameters_at({axis.name: value})

    def allowed_names(self) -> tuple:
        """The names an axis of this grid may take: ``kappa``, ``v``, the other numeric
        :class:`~phaseimpact.Parameters` fields and, on a Case base, every material and geometry
        quantity (``plate.E``, ``R1``...).

        Returns
        -------
        tuple of str

        Examples
        --------
        >>> from phaseimpact.case import load_case
        >>> from phaseimpact.continuation import Axis, Grid
        >>> from phaseimpact.model import as_law
        >>> g = Grid(load_case("seed"), as_law("paper"), (Axis.make("plate.E", [7e10, 2.1e11]),))
        >>> "plate.E" in g.allowed_names(), g.allowed_names()[:2]
        (True, ('kappa', 'v'))
        """
        names = ("kappa", "v", *[n for n in _NUMERIC_FIELDS if n not in ("kappa", "v")])
        if isinstance(self.base, Case):
            names += tuple(n for n in QUANTITIES if n not in names)
            if self.law.entry.plastic:  # its limiting pressure is 1.6 Y of the weaker body
                names += ("projectile.yield_strength", "plate.yield_strength")
        return names

    @property
    def shape(self) -> tuple:
        """Number of values of each axis."""
        return tuple(len(a.values) for a in self.axes)

    @property
    def size(self) -> int:
        """Number of points."""
        return int(np.prod(self.shape))

    @property
    def names(self) -> tuple:
        """The axes' names, in order."""
        return tuple(a.name for a in self.axes)

    def base_parameters(self) -> Parameters:
        """The base case's :class:`~phaseimpact.Parameters` (a Case's, derived from its materials).

        Returns
        -------
        Parameters

        Examples
        --------
        >>> from phaseimpact.case import load_case
        >>> from phaseimpact.continuation import Axis, Grid
        >>> from phaseimpact.model import as_law
        >>> g = Grid(load_case("seed"), as_law("paper"), (Axis.make("v", [1.0, 2.0]),))
        >>> print(f"{g.base_parameters().M1:.4g} kg")
        0.2631 kg
        """
        return self.base.parameters() if isinstance(self.base, Case) else self.base

    def parameters_at(self, values: dict) -> Parameters:
        """Parameters of one point (``values``: axis name -> value).

        Parameters
        ----------
        values : dict
            ``{axis name: value}`` (SI units); names not given keep the base case's value.

        Returns
        -------
        Parameters

        Raises
        ------
        ValueError
            For a value out of its parameter's range.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.continuation import Axis, Grid
        >>> from phaseimpact.model import as_law
        >>> g = Grid(seed_parameters(), as_law("paper"), (Axis.make("kappa", [1e9, 1e12]),))
        >>> g.parameters_at({"kappa": 1e10}).kappa
        10000000000.0
        """
        if isinstance(self.base, Case):
            return self.base.parameters(**{k: float(v) for k, v in values.items()})
        return self.base.replace(**{k: float(v) for k, v in values.items()})

    def point_values(self, index) -> dict:
        """Axis values of flat point ``index``.

        Parameters
        ----------
        index : int
            Flat (C order) index, ``0 <= index < size``.

        Returns
        -------
        dict
            ``{axis name: value}``.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.continuation import Axis, Grid
        >>> from phaseimpact.model import as_law
        >>> axes = (Axis.make("kappa", [1e9, 1e12]), Axis.make("v", [1.0, 2.0, 3.0]))
        >>> g = Grid(seed_parameters(), as_law("paper"), axes)
        >>> g.point_values(4)
        {'kappa': 1000000000000.0, 'v': 2.0}
        """
        multi = np.unravel_index(int(index), self.shape)
        return {a.name: float(a.values[i]) for a, i in zip(self.axes, multi, strict=True)}

    def batch(self, indices: np.ndarray, t_end: float | None, rtol: float) -> Batch:
        """Packed inputs of the points ``indices`` (flat). ``kappa`` and ``v`` axes are packed as
        arrays (no per-point objects); other axes re-derive each point's parameters.

        Parameters
        ----------
        indices : array of int
            Flat (C order) point indices.
        t_end : float or None
            Horizon of every run, s; None: each run's default horizon (until its outcome settles,
            capped by its scales).
        rtol : float
            Integrator tolerance, within :data:`~phaseimpact.integrate.RTOL_RANGE`.

        Returns
        -------
        Batch
            Coefficients, initial states, horizons, tolerances and step caps, one row per point,
            for :func:`phaseimpact.integrate.batch.run_batch`.

        Raises
        ------
        ValueError
            For ``rtol`` out of range.

        Examples
        --------
        >>> from phaseimpact import seed_parameters
        >>> from phaseimpact.continuation import Axis, Grid
        >>> from phaseimpact.model import as_law
        >>> axes = (Axis.make("kappa", [1e9, 1e12]), Axis.make("v", [1.0, 2.0, 3.0]))
        >>> g = Grid(seed_parameters(), as_law("paper"), axes)
        >>> b = g.batch([0, 1, 5], None, 1e-10)
        >>> len(b), b.Y0[:, 2].tolist()
        (3, [1.0, 2.0, 3.0])
        """
        rtol = check_rtol(rtol)
        indices = np.asarray(indices, dtype=np.int64)
        n = len(indices)
        multi = np.unravel_index(indices, self.shape)
        columns = {a.name: a.values[m] for a, m in zip(self.axes, multi, strict=True)}
        if set(columns) <= {"kappa", "v"}:
            base = self.base_parameters()
            C = np.tile(pack(base, self.law), (n, 1))
            v = columns.get("v", np.full(n, base.v))
            if "kappa" in columns:
                C[:, DAMP_] = columns["kappa"]
            elif self.law.damping_source == "restitution" and self.law.entry.chi is not None:
                C[:, DAMP_] = self.law.entry.chi(self.law.restitution) * base.K / v
            elif self.law.damping_source == "restitution":
                C[:, DAMP_] = [self.law.kappa(base.replace(v=float(x))) for x in v]
            Y0 = np.zeros((n, 5))
            Y0[:, 2] = v
            s = scales(base)
            alpha = C[0, ALPHA_]
            # Parameters.hertz_indentation per point (Python's power: numpy's differs in the last bit for
            # ~5 % of the values, and so would a point of the atlas from simulate's run of it); scales()'s
            # other expressions on arrays
            m, K = base.reduced_mass, float(C[0, K_])
            speeds, which = np.unique(v, return_inverse=True)  # one speed for a whole sweep over kappa
            indentation = np.array([indentation_of(float(alpha), m, x, K) for x in speeds.tolist()])[which]
            contact_time = hertz_contact_time(alpha, indentation, v)
            A = state_tolerances(rtol, indentation, v, C[:, M1_], contact_time)
            if t_end is not None:
                T = np.full(n, t_end)
            elif math.isfinite(s.plate_period):
                T = np.full(n, s.horizon)
            else:  # scales()'s horizon of each point: a number of its contact times
                T = HORIZON_CAP_PERIODS * contact_time
            return Batch(self.law, C, Y0, T, A, np.full(n, s.max_step))
        points = (self.parameters_at({k: v[i] for k, v in columns.items()}) for i in range(n))
        return pack_batch(points, self.law, t_end, rtol)
