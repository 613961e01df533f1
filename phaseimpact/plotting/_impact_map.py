"""Figures of the impact map: branches of periodic orbits (:func:`plot_map_branch`), their
bifurcations (:func:`mark_bifurcations`, :func:`plot_bifurcation_curves`), basins of attraction
(:func:`plot_basins`) and any archived variable (:func:`plot_variable`). Imported from
:mod:`phaseimpact.plotting`.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ._results import _edges
from ._style import COLUMN_WIDTH, UM, figure, style

__all__ = ["BIFURCATION_MARKERS", "BASIN_COLOURS", "ATTRACTOR_MARKERS", "plot_map_branch", "mark_bifurcations",
           "plot_bifurcation_curves", "plot_basins", "plot_variable"]

#: Marker, colour and label of each kind of located bifurcation of the impact map (shapes differ, not
#: only colours).
BIFURCATION_MARKERS = {
    "period-doubling": ("s", "#cc3311", "period-doubling"),
    "fold": ("^", "#0077bb", "fold (saddle-node)"),
    "neimark-sacker": ("D", "#ee7733", "Neimark–Sacker"),
    "grazing": ("X", "#009988", "grazing"),
}
#: Colours of basins (cycled), of states that reach no periodic attractor and of failed runs.
BASIN_COLOURS = ("#88ccee", "#ddcc77", "#cc6677", "#44aa99", "#aa4499", "#999933", "#882255", "#117733")
NOT_CONVERGED_COLOUR, NO_MAP_COLOUR = "#dddddd", "#000000"
#: Markers of the attractors in a basin picture, in turn.
ATTRACTOR_MARKERS = ("o", "s", "^", "D", "v", "P", "*", "h")


def _branch_y(plate, omega):
    plate = np.asarray(plate, dtype=float).reshape(-1, 2)
    return (plate[:, 0] if omega is None else np.hypot(plate[:, 0], plate[:, 1] / omega)) * UM


def plot_map_branch(ax, branch, *, x_scale: float = 1.0, label: str | None = None, colour: str = "k",
                    points: bool = True, omega: float | None = None):
    """Draw a branch of periodic orbits of the impact map onto ``ax``: the plate's position before
    the orbit's first impact (µm) against the parameter, stable parts solid, unstable parts dashed,
    and its located bifurcations marked (:data:`BIFURCATION_MARKERS`).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    branch : MapBranch
        From :func:`phaseimpact.train.continue_map_orbit`.
    x_scale : float, default 1
        The parameter is drawn divided by it (e.g. the plate period, to draw T / T_plate).
    label : str, optional
        Legend label of the stable part.
    colour : str, default "k"
    points : bool, default True
        Mark the located points (each kind labelled once per axes).
    omega : float, optional
        With the plate's angular frequency (rad/s), draw its amplitude before the impact,
        ``sqrt(x2^2 + (x2dot / omega)^2)`` (µm), instead of ``x2``.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``.

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact.plotting import figure, plot_map_branch, style
    >>> from phaseimpact.train import MapBifurcation, MapBranch
    >>> pd = MapBifurcation("period-doubling", "T", 1.5, np.zeros(2), np.array([-1.0, 0.5]), 1e-9, 0.0,
    ...                     ((1, 0, 0),) * 2)
    >>> branch = MapBranch("T", 1, np.array([1.0, 2.0]), np.zeros((2, 2)), np.array([[0.5, -0.9], [0.5, -1.1]]),
    ...                    np.array([True, False]), np.ones((2, 3), int), [pd], "reached the end of the range")
    >>> with style():
    ...     fig, axes = figure()
    ...     _ = plot_map_branch(axes[0, 0], branch)
    >>> len(axes[0, 0].lines)
    3
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    x = np.asarray(branch.values, dtype=float) / x_scale
    y = _branch_y(branch.plate, omega)
    stable = np.asarray(branch.stable, dtype=bool)
    # one line per stretch of equal stability, each joined to the next point so the branch is unbroken
    cuts = [0, *(np.flatnonzero(np.diff(stable.astype(int))) + 1), len(x)]
    labelled = False
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        end = min(b + 1, len(x))
        ax.plot(x[a:end], y[a:end], color=colour, lw=1.2 if stable[a] else 0.9, ls="-" if stable[a] else "--",
                label=(label if stable[a] and not labelled else None))
        labelled = labelled or bool(stable[a])
    if points:
        mark_bifurcations(ax, branch.points, x_scale=x_scale, omega=omega)
    return ax


def mark_bifurcations(ax, points, *, x_scale: float = 1.0, omega: float | None = None):
    """Mark located bifurcations of the impact map at (parameter, plate position before impact, µm).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    points : sequence of MapBifurcation
    x_scale : float, default 1
        The parameter is drawn divided by it.
    omega : float, optional
        As for :func:`plot_map_branch`: mark at the plate's amplitude instead of ``x2``.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``; each kind is labelled once per axes.

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact.plotting import figure, mark_bifurcations, style
    >>> from phaseimpact.train import MapBifurcation
    >>> fold = MapBifurcation("fold", "T", 1.0, np.zeros(2), np.array([1.0, 0.3]), 0.0, 0.0, ((1, 0, 0),) * 2)
    >>> with style():
    ...     fig, axes = figure()
    ...     _ = mark_bifurcations(axes[0, 0], [fold])
    >>> axes[0, 0].lines[0].get_marker()
    '^'
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    present = {line.get_label() for line in ax.lines}
    for p in points:
        marker, colour, text = BIFURCATION_MARKERS[p.kind]
        ax.plot(p.value / x_scale, _branch_y(p.plate, omega)[0], ls="none", marker=marker, color=colour, mec="k",
                mew=0.6, ms=6.5, zorder=5, label=None if text in present else text)
        present.add(text)
    return ax


def plot_bifurcation_curves(ax, curves, *, x_scale: float = 1.0, y_scale: float = 1.0):
    """Draw bifurcations followed in two parameters onto ``ax``: the first parameter (divided by
    ``x_scale``) horizontally, the second (divided by ``y_scale``) vertically, one line per curve,
    its points marked by kind (:data:`BIFURCATION_MARKERS`; each kind labelled once per axes).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    curves : sequence of BifurcationCurve
        From :func:`phaseimpact.train.continue_map_bifurcation`.
    x_scale, y_scale : float, default 1

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``.

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact.plotting import figure, plot_bifurcation_curves, style
    >>> from phaseimpact.train import BifurcationCurve
    >>> c = BifurcationCurve("fold", "T", "kappa", np.array([1e9, 2e9]), np.array([1.0, 1.1]), np.zeros((2, 2)),
    ...                      np.ones((2, 2)), np.zeros(2), "followed over the whole grid")
    >>> with style():
    ...     fig, axes = figure()
    ...     _ = plot_bifurcation_curves(axes[0, 0], [c])
    >>> axes[0, 0].lines[0].get_marker()
    '^'
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    present = {line.get_label() for line in ax.lines}
    for curve in curves:
        marker, colour, text = BIFURCATION_MARKERS[curve.kind]
        ax.plot(np.asarray(curve.values) / x_scale, np.asarray(curve.second_values) / y_scale, marker=marker,
                color=colour, mec="k", mew=0.5, ms=5, lw=1.0, label=None if text in present else text)
        present.add(text)
    return ax


def plot_basins(result, *, ax=None, title: str = ""):
    """The basins of attraction of the impact map: each initial plate state of the grid coloured by
    the attractor it goes to, the attractors' points marked (a marker shape each), states that reach
    no periodic attractor light grey, failed runs black.

    Parameters
    ----------
    result : Basins
        From :func:`phaseimpact.train.basins`.
    ax : matplotlib.axes.Axes, optional
        Where to draw; default a new figure.
    title : str
        The axes' title.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn into (for :func:`save`).

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact.plotting import plot_basins
    >>> from phaseimpact.train import Attractor, Basins
    >>> b = Basins(1e-3, np.array([0.0, 1e-4]), np.array([0.0, 1.0]), np.array([[0, 1], [-1, 0]]),
    ...            np.ones((2, 2), int), [Attractor(np.zeros((1, 2)), 1, 2), Attractor(np.ones((2, 2)), 2, 1)], 1, 0)
    >>> fig = plot_basins(b)
    >>> print(fig.axes[0].get_xlabel())
    initial plate position x2 (µm)
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.lines import Line2D

    n = len(result.attractors)
    colours = [NO_MAP_COLOUR, NOT_CONVERGED_COLOUR, *(BASIN_COLOURS[i % len(BASIN_COLOURS)] for i in range(n))]
    cmap = ListedColormap(colours)
    norm = BoundaryNorm(np.arange(-2.5, n + 0.5), cmap.N)
    xs = np.asarray(result.x2_values, dtype=float) * UM
    vs = np.asarray(result.x2dot_values, dtype=float)
    with style():
        if ax is None:
            fig, axes = figure(1, 1, width=COLUMN_WIDTH + 1.4, height=COLUMN_WIDTH)
            ax = axes[0, 0]
        ax.pcolormesh(_edges(xs, False), _edges(vs, False), result.labels, cmap=cmap, norm=norm, rasterized=True)
        ax.grid(False)
        total = result.labels.size
        legend = []
        periods = [a.period for a in result.attractors]
        seen = {}
        for i, a in enumerate(result.attractors):
            # coexisting attractors of one period are told apart by a letter (period 2a, period 2b)
            seen[a.period] = seen.get(a.period, -1) + 1
            name = f"{a.period}{chr(ord('a') + seen[a.period])}" if periods.count(a.period) > 1 else f"{a.period}"
            style_ = {"ls": "none", "marker": ATTRACTOR_MARKERS[i % len(ATTRACTOR_MARKERS)], "mfc": colours[i + 2],
                      "mec": "k", "mew": 0.9, "ms": 7}
            ax.plot(a.plate[:, 0] * UM, a.plate[:, 1], zorder=5, **style_)
            legend.append(Line2D([], [], label=f"period {name}: basin {100 * a.count / total:.0f}%", **style_))
        for count, colour, text in ((result.not_converged, NOT_CONVERGED_COLOUR, "no period found"),
                                    (result.no_map, NO_MAP_COLOUR, "run failed")):
            if count:
                legend.append(Line2D([], [], ls="none", marker="s", mfc=colour, mec="k", ms=8,
                                     label=f"{text}: {100 * count / total:.0f}%"))
        ax.legend(handles=legend, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
        ax.set_xlabel("initial plate position x2 (µm)")
        ax.set_ylabel("initial plate velocity (m/s)")
        if title:
            ax.set_title(title)
    return ax.figure


__all__ += ["plot_map_branch", "mark_bifurcations", "plot_bifurcation_curves", "plot_basins", "BIFURCATION_MARKERS"]


def plot_variable(da, *, ax=None, **kwargs):
    """Plot a variable of a phaseimpact Dataset (:func:`~phaseimpact.archive.to_xarray`, or an archive
    opened with xarray) as ``da.plot`` does, with what its attributes say and xarray does not read:
    a coordinate marked ``log`` (1: a log-spaced grid axis) goes on a log axis, and a flag variable
    (``flag_values``, ``flag_meanings``: status, outcome, ...) gets one colour per value named in the
    colour bar (2-d), or its values named on the y axis (1-d); -1 (not computed) is left blank.

    Parameters
    ----------
    da : xarray.DataArray
        One variable, 1-d or 2-d.
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new :func:`figure`).
    **kwargs
        Passed on to ``da.plot`` (``x=``, ``y=``, ``xscale=`` ... given here win).

    Returns
    -------
    object
        The artist ``da.plot`` returns (a QuadMesh for 2-d, a list of lines for 1-d).

    Raises
    ------
    ValueError
        For a variable of other than 1 or 2 dimensions.

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.archive import to_xarray
    >>> from phaseimpact.continuation import atlas
    >>> ds = to_xarray(atlas(seed_parameters(), "paper", {"kappa": np.geomspace(1e11, 1e13, 3), "v": [1.0, 2.0]}))
    >>> mesh = plot_variable(ds.outcome, x="kappa")
    >>> mesh.axes.get_xscale(), mesh.axes.get_yscale(), [t.get_text() for t in mesh.colorbar.ax.get_yticklabels()][:2]
    ('log', 'linear', ['failed', 'permanent-stick'])
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap

    if ax is None:
        ax = figure()[1][0, 0]
    if da.ndim not in (1, 2):
        raise ValueError(f"da has {da.ndim} dimensions {da.dims}; allowed: 1 or 2")
    x, y = kwargs.get("x"), kwargs.get("y")
    if da.ndim == 1:
        x = x or da.dims[0]
    else:  # as xarray: the last dimension along x, unless one of them is named
        x = x or next(d for d in reversed(da.dims) if d != y)
        y = y or next(d for d in da.dims if d != x)
    for scale, name in (("xscale", x), ("yscale", y)):
        if name is not None and name in da.coords and int(np.ravel(da[name].attrs.get("log", 0))[0]) == 1:
            kwargs.setdefault(scale, "log")
    if "flag_meanings" not in da.attrs:
        return da.plot(ax=ax, **kwargs)
    names = str(da.attrs["flag_meanings"]).split()
    values = np.ravel(da.attrs["flag_values"]).astype(float)
    shown = da.where(da >= values.min())
    if da.ndim == 1:
        artist = shown.plot(ax=ax, marker="o", linestyle="none", **kwargs)
        ax.set_yticks(values, names)
        return artist
    edges = np.concatenate([[values[0] - 0.5], (values[:-1] + values[1:]) / 2, [values[-1] + 0.5]])
    colours = ListedColormap(plt.get_cmap("tab10")(np.arange(len(names)) % 10))
    artist = shown.plot(ax=ax, cmap=colours, norm=BoundaryNorm(edges, len(names)),
                        cbar_kwargs={"ticks": values, "label": da.attrs.get("long_name", da.name)}, **kwargs)
    artist.colorbar.set_ticklabels(names)
    return artist


__all__ += ["plot_variable"]
