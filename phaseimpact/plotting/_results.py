"""Figures of archives and trajectories (the command line's ``plot`` and ``portrait``):
:func:`plot_atlas` (two axes: outcome classes as a categorical colour map), :func:`plot_sweep` (one
axis: counts and max force), :func:`plot_curve` (a continued ``kappa_c``, ``kappa_2`` or grazing value
against its parameter), :func:`plot_orbit_diagram` and :func:`plot_portraits` (one phase portrait per
trajectory, events marked). Imported from :mod:`phaseimpact.plotting`.
"""

from __future__ import annotations

import textwrap

import matplotlib.pyplot as plt
import numpy as np

from ._style import COLUMN_WIDTH, MIN_TEXT_PT, PAGE_WIDTH, UM, figure, style

__all__ = ["OUTCOME_COLOURS", "EVENT_MARKERS", "axis_label", "plot_atlas", "plot_sweep", "plot_curve",
           "plot_orbit_diagram", "plot_portraits"]

#: One colour per outcome class, the same in every figure (docs/physics.md §5's classes).
OUTCOME_COLOURS = {
    "permanent-stick": "#4477aa",
    "ratchet-escape": "#ee7733",
    "rebound": "#228833",
    "runaway": "#cc3311",
    "bounded": "#aa3377",
    "unsettled": "#ccbb44",
    "failed": "#000000",
    "not computed": "#dddddd",
}

_UNITS = {"kappa": "N s/m$^{2.5}$", "v": "m/s", "M1": "kg", "M2": "kg", "K": "N/m$^{1.5}$", "Kb": "N/m",
          "Km": "N/m$^3$", "alpha": "", "R": "m"}
_SYMBOLS = {"kappa": r"$\kappa$", "v": "impact speed $v$", "alpha": r"$\alpha$"}


def _damping_unit(law, base) -> str:
    """The damping coefficient's unit from the law's entry, in mathtext (``N s/m$^{1.5}$``)."""
    unit = law.damping_unit(getattr(base, "alpha", None) or getattr(getattr(base, "params", None), "alpha", 1.5))
    head, _, power = unit.partition("^")
    return f"{head}$^{{{power}}}$" if power else unit


def axis_label(name: str, law=None, base=None) -> str:
    """``name (unit)`` for a parameter of an axis or a curve (SI units); ``kappa`` is named and
    united by ``law``'s entry when given (``base``: the case, for its exponent alpha).

    Parameters
    ----------
    name : str
        A parameter (``kappa``, ``v``, ``M1``...) or a case quantity (``plate.E``, ``R1``...).
    law : ContactLaw, optional
        Whose entry names the damping coefficient and gives its unit.
    base : Parameters or Case, optional
        The case (its ``alpha`` sets the damping's unit).

    Returns
    -------
    str
        The label, in matplotlib mathtext.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.model import as_law
    >>> from phaseimpact.plotting import axis_label
    >>> axis_label("v"), axis_label("plate.E")
    ('impact speed $v$ (m/s)', 'plate.E (Pa)')
    >>> print(axis_label("kappa", as_law("kuwabara-kono"), seed_parameters()))
    $\\gamma$ (N s/m$^{1.5}$)
    """
    from ..settings import SETTABLE

    if name == "kappa" and law is not None:
        symbol = law.entry.damping_name
        return f"{_SYMBOLS.get(symbol, '$' + chr(92) + symbol + '$')} ({_damping_unit(law, base)})"
    unit = _UNITS.get(name, SETTABLE.get(name, ("",))[0])
    unit = "" if unit in ("", "-", "1") else unit.replace("^3", "$^3$")
    text = _SYMBOLS.get(name, name)
    return f"{text} ({unit})" if unit else text


def _case_name(base) -> str:
    return getattr(base, "name", "parameters")


def _edges(values, log: bool) -> np.ndarray:
    """Cell edges around grid values (geometric midpoints on a log axis)."""
    v = np.asarray(values, dtype=float)
    if v.size == 1:
        return v * np.array([0.9, 1.1]) if log else v + np.array([-0.5, 0.5]) * max(abs(v[0]), 1.0) * 0.1
    if log:
        mid = np.sqrt(v[:-1] * v[1:])
        return np.concatenate([[v[0] ** 2 / mid[0]], mid, [v[-1] ** 2 / mid[-1]]])
    mid = 0.5 * (v[:-1] + v[1:])
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _outcome_legend(ax, present, extra=()):
    """The outcome classes in ``present`` (and ``extra`` handles) in a legend right of ``ax``."""
    from matplotlib.patches import Patch

    handles = [Patch(facecolor=OUTCOME_COLOURS[name], edgecolor="0.3", label=name)
               for name in OUTCOME_COLOURS if name in present]
    ax.legend(handles=handles + list(extra), title="outcome", loc="upper left", bbox_to_anchor=(1.01, 1.0),
              borderaxespad=0, frameon=True, facecolor="0.82", edgecolor="none")


def _count_name(result) -> str:
    return "n_stick" if result.law.is_filippov else "n_contacts"


def plot_atlas(result, *, contours: str | None = None, curves=()):
    """An atlas of two axes: the outcome class of every point as a categorical colour map.

    Parameters
    ----------
    result : SweepResult
        With two axes; the first is drawn along x, the second along y, each on a log scale
        where the axis is log (``Axis.log``).
    contours : {"n_stick", "n_contacts"}, optional
        Overlay the lines where this count changes (labelled ``n|n+1``; at most ten levels).
    curves : sequence of CriticalCurve
        Continued curves to overlay: ``kappa`` against the parameter of the atlas's other axis.

    Returns
    -------
    matplotlib.figure.Figure
        For :func:`save`. Refined boundaries in ``result.extras["boundaries"]`` are marked.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import atlas
    >>> from phaseimpact.plotting import plot_atlas
    >>> a = atlas(seed_parameters(), "paper", {"kappa": [1e11, 1e12, 1e13], "v": [0.5, 2.0]})
    >>> fig = plot_atlas(a, contours="n_stick")
    >>> fig.axes[0].get_title()
    'paper contact=printed, case parameters: 3 x 2 points'
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap

    from ..continuation.sweep import OUTCOME_LABELS

    ax0, ax1 = result.grid.axes
    names = list(OUTCOME_COLOURS)
    colour_of = np.array([names.index(n) for n in OUTCOME_LABELS])
    codes = colour_of[result.outcome_indices()].reshape(result.shape)
    with style():
        fig, axes = figure(1, 1, width=PAGE_WIDTH, height=4.2)
        ax = axes[0, 0]
        cmap = ListedColormap([OUTCOME_COLOURS[n] for n in names])
        norm = BoundaryNorm(np.arange(len(names) + 1) - 0.5, len(names))
        ax.pcolormesh(_edges(ax0.values, ax0.log), _edges(ax1.values, ax1.log), codes.T, cmap=cmap, norm=norm,
                      shading="flat", rasterized=True)
        if ax0.log:
            ax.set_xscale("log")
        if ax1.log:
            ax.set_yscale("log")
        ax.set_xlabel(axis_label(ax0.name, result.grid.law, result.grid.base))
        ax.set_ylabel(axis_label(ax1.name, result.grid.law, result.grid.base))
        ax.grid(False)
        present = {names[i] for i in np.unique(codes)}
        if contours:
            _draw_count_contours(ax, result, contours)
        for i, curve in enumerate(curves):
            _draw_curve(ax, curve, i, kappa_across=ax0.name == "kappa")
        boundaries = result.extras.get("boundaries")
        if boundaries is not None and len(boundaries["points"]):
            points = np.asarray(boundaries["points"], dtype=float)
            ax.plot(points[:, 0], points[:, 1], "o", ms=3.5, mfc="k", mec="w", mew=0.6, ls="none",
                    label=f"boundary refined along {boundaries['axis']} ({float(boundaries['rtol']):g})")
        ax.set_xlim(_edges(ax0.values, ax0.log)[[0, -1]])
        ax.set_ylim(_edges(ax1.values, ax1.log)[[0, -1]])
        _outcome_legend(ax, present, ax.get_legend_handles_labels()[0])
        computed = int(np.count_nonzero(result.status >= 0))
        partial = f" ({computed} computed)" if computed < result.grid.size else ""
        ax.set_title(f"{result.law.label()}, case {_case_name(result.grid.base)}: "
                     f"{result.shape[0]} x {result.shape[1]} points{partial}")
    return fig



def _draw_count_contours(ax, result, contours: str) -> None:
    """Contours between successive counts ``n|n+1`` of the column ``contours`` (failed points left
    out; at most ten levels from the lowest count), and their legend entry."""
    ax0, ax1 = result.grid.axes
    count = np.asarray(result.values[contours], dtype=float).reshape(result.shape)
    count[result.status.reshape(result.shape) != 0] = np.nan
    finite = count[np.isfinite(count)]
    if finite.size and finite.max() > finite.min() and min(result.shape) >= 2:
        low = int(finite.min())
        levels = np.arange(low, min(int(finite.max()), low + 10)) + 0.5
        lines = ax.contour(ax0.values, ax1.values, count.T, levels=levels, colors="k", linewidths=0.8)
        ax.clabel(lines, fmt=lambda x: f"{int(x - 0.5)}|{int(x + 0.5)}", fontsize=MIN_TEXT_PT)
    label = "stick phases" if contours == "n_stick" else "contacts"
    ax.plot([], [], "k-", lw=0.8, label=f"{label}: n|n+1")


def _draw_curve(ax, curve, i: int, kappa_across: bool) -> None:
    """A continued curve over an atlas (the ``i``-th: black, then the colour cycle), with its closed
    form where it has one; ``kappa_across``: kappa is the atlas's first (horizontal) axis."""
    keep = np.isfinite(curve.kappa)
    x, y = (curve.kappa[keep], curve.values[keep]) if kappa_across else (curve.values[keep], curve.kappa[keep])
    ax.plot(x, y, color="k" if i == 0 else f"C{i}", lw=1.6, label=f"{_what_label(curve)} (continued)")
    closed = np.isfinite(curve.closed_form)
    if np.any(closed):
        cx, cy = ((curve.closed_form[closed], curve.values[closed]) if kappa_across
                  else (curve.values[closed], curve.closed_form[closed]))
        ax.plot(cx, cy, color="w", ls="--", lw=1.0, label=r"closed-form $\kappa_c$")

def plot_sweep(result):
    """A sweep (one axis): the long-time count (stick phases for ``paper``, contacts otherwise) and the
    largest force against the axis, each point coloured by its outcome class; points whose horizon cut
    the run (the count is a lower bound) drawn as upward triangles.

    Parameters
    ----------
    result : SweepResult
        With one axis (:func:`~phaseimpact.continuation.sweep`).

    Returns
    -------
    matplotlib.figure.Figure
        Two panels sharing the axis, for :func:`save`.

    Examples
    --------
    >>> import numpy as np
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import sweep
    >>> from phaseimpact.plotting import plot_sweep
    >>> fig = plot_sweep(sweep(seed_parameters(), "paper", np.geomspace(1e9, 1e14, 5)))
    >>> len(fig.axes), fig.axes[0].get_title()
    (2, 'paper contact=printed, case parameters: 5 values of kappa')
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    axis = result.grid.axes[0]
    x = np.asarray(axis.values)
    outcomes = result.outcome_names()
    count_name = _count_name(result)
    count = np.asarray(result.values[count_name], dtype=float)
    force = np.asarray(result.values["max_force"], dtype=float)
    computed = result.status >= 0
    cut = np.asarray(result.cut, dtype=bool)
    with style():
        fig, axes = figure(2, 1, width=PAGE_WIDTH, height=5.0, sharex=True)
        top, bottom = axes[0, 0], axes[1, 0]
        for ax, y in ((top, count), (bottom, force)):
            for name in OUTCOME_COLOURS:
                for marker, pick in (("o", ~cut), ("^", cut)):
                    keep = (outcomes == name) & pick & np.isfinite(y)
                    if np.any(keep):
                        ax.scatter(x[keep], y[keep], s=12, marker=marker, color=OUTCOME_COLOURS[name], zorder=2,
                                   edgecolors="none")
        if axis.log:
            bottom.set_xscale("log")
        finite = count[computed & np.isfinite(count) & (count > 0)]
        if finite.size and finite.max() > 30:
            top.set_yscale("log")
        else:
            top.yaxis.get_major_locator().set_params(integer=True)
        positive = force[computed & np.isfinite(force) & (force > 0)]
        if positive.size and positive.max() > 100 * positive.min():
            bottom.set_yscale("log")
        top.set_ylabel("stick phases $N$" if count_name == "n_stick" else "contacts")
        bottom.set_ylabel("max contact force (N)")
        bottom.set_xlabel(axis_label(axis.name, result.grid.law, result.grid.base))
        present = set(outcomes[computed]) | ({"not computed"} if not computed.all() else set())
        extra = []
        if np.any(cut):
            extra = [top.scatter([], [], marker="^", color="0.4", s=12, label="cut by the horizon (lower bound)")]
        _outcome_legend(top, present, extra)
        top.set_title(f"{result.law.label()}, case {_case_name(result.grid.base)}: {len(x)} values of {axis.name}")
    return fig


def _what_label(curve) -> str:
    return {"kappa_c": r"$\kappa_c$", "kappa_2": r"$\kappa_2$",
            "grazing": rf"grazing $\kappa$ (extremum {curve.contact_index})"}.get(curve.what, curve.what)


def _geometric(values) -> bool:
    v = np.asarray(values, dtype=float)
    return bool(v.size > 2 and np.all(v > 0) and v.max() / v.min() > 20)


def plot_curve(curve):
    """A continued curve: ``kappa`` (``kappa_c``, ``kappa_2`` or a grazing value) against its parameter,
    the values asked for as dots (intermediate continuation steps as small dots), the closed
    form dashed where it exists.

    Parameters
    ----------
    curve : CriticalCurve
        From :func:`~phaseimpact.continuation.critical_curve` (values lost are marked with crosses).

    Returns
    -------
    matplotlib.figure.Figure
        For :func:`save`.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.continuation import critical_curve
    >>> from phaseimpact.plotting import plot_curve
    >>> fig = plot_curve(critical_curve(seed_parameters(), "paper", "v", [1.0, 2.0]))
    >>> print(fig.axes[0].get_ylabel())
    $\\kappa_c$ (N s/m$^{2.5}$)
    >>> fig.axes[0].get_legend_handles_labels()[1][1:]
    ['values asked for', 'intermediate steps', 'closed-form $\\\\kappa_c$']
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    x = np.asarray(curve.values, dtype=float)
    y = np.asarray(curve.kappa, dtype=float)
    asked = np.asarray(curve.requested, dtype=bool)
    finite = np.isfinite(y)
    what = _what_label(curve)
    with style():
        fig, axes = figure(1, 1, width=COLUMN_WIDTH + 1.0, height=3.4)
        ax = axes[0, 0]
        ax.plot(x[finite], y[finite], "C0-", lw=1.2, label=f"{what} (continued)")
        ax.plot(x[finite & asked], y[finite & asked], "C0o", ms=4, label="values asked for")
        if np.any(finite & ~asked):
            ax.plot(x[finite & ~asked], y[finite & ~asked], "C0.", ms=3, label="intermediate steps")
        closed = np.isfinite(curve.closed_form)
        if np.any(closed):
            ax.plot(x[closed], curve.closed_form[closed], "k--", lw=1.0, label=r"closed-form $\kappa_c$")
        if np.any(~finite):
            ax.plot(x[~finite], np.full(np.count_nonzero(~finite), np.nanmin(y) if np.any(finite) else 1.0), "rx",
                    label="lost")
        ax.set_yscale("log")
        if _geometric(x):
            ax.set_xscale("log")
        ax.set_xlabel(axis_label(curve.param, curve.law, curve.base))
        ax.set_ylabel(f"{what} ({_damping_unit(curve.law, curve.base)})")
        ax.legend()
        title = f"{curve.law.label()}, case {_case_name(curve.base)}"
        ax.set_title("\n".join([title, *textwrap.wrap(curve.message, 60)]))
    return fig


#: How the events of a trajectory are marked in a portrait: kind -> (marker, colour, label).
EVENT_MARKERS = {
    "contact": (">", "#228833", "contact"),
    "separation": ("<", "#cc3311", "separation"),
    "slip": ("x", "#aa3377", "slip"),
}


def plot_orbit_diagram(diagram, *, title: str = ""):
    """An orbit diagram of the impact map: the plate's position before each sampled impact against
    the parameter (one dot per sample), and the number of distinct points per value.

    Parameters
    ----------
    diagram : OrbitDiagram
        From :func:`phaseimpact.train.orbit_diagram`.
    title : str
        The figure's title.

    Returns
    -------
    matplotlib.figure.Figure
        For :func:`save`.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.train import orbit_diagram
    >>> from phaseimpact.plotting import plot_orbit_diagram
    >>> d = orbit_diagram(seed_parameters(), "hunt-crossley", "T", [2e-3, 3e-3], transients=5, samples=3)
    >>> fig = plot_orbit_diagram(d)
    >>> print(fig.axes[1].get_xlabel())
    period T between impacts (s)
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    labels = {"T": "period T between impacts (s)", "kappa": r"damping $\kappa$ (law's unit)",
              "v": "impact speed v (m/s)"}
    values = np.asarray(diagram.values, dtype=float)
    samples = diagram.plate.shape[1]
    with style():
        fig, axes = figure(2, 1, width=5.6, height=5.0, sharex=True)
        ax = axes[0, 0]
        ax.plot(np.repeat(values, samples), diagram.plate[:, :, 0].ravel() * 1e6, ".", color="k", ms=1.2,
                mew=0, rasterized=True)
        ax.set_ylabel(r"plate position $x_2$ before impact (µm)")
        if title:
            ax.set_title(title)
        ax = axes[1, 0]
        ax.plot(values, diagram.distinct, "C0.-", ms=3, lw=0.6)
        ax.set_yscale("log")
        ax.set_ylabel("distinct points")
        ax.set_xlabel(labels[diagram.param])
        if diagram.param != "T" and values.min() > 0 and values.max() / values.min() > 100:
            ax.set_xscale("log")
    return fig


def plot_portraits(trajectories, plane=("delta", "deltadot"), *, summaries=None, title: str = ""):
    """One phase portrait per trajectory, with its events.

    Parameters
    ----------
    trajectories : sequence of Trajectory
        What to draw: runs with samples (``save="steps"`` or a time grid), e.g. from
        ``analysis.phase_portrait``.
    plane : pair of str
        ``("delta", "deltadot")``, ``("x1", "x1dot")`` or ``("x2", "x2dot")``.
    summaries : sequence of Trajectory, optional
        The same runs as run until their outcome settled: their events, stick phases, outcome and
        counts are marked and titled (default: those of ``trajectories``). A drawn run may go on
        past a permanent stick to show the stuck pair's orbit.
    title : str
        The figure's title.

    Contacts, separations and slips are marked where they happen; each stick phase where it starts,
    and in the ``(delta, deltadot)`` plane as the point ``(delta*, 0)`` it rests at: a filled star
    for a permanent stick (an asymptotic point), hollow circles for transient ones. Each panel's
    title gives ``kappa``, the outcome and the counts.

    Returns
    -------
    matplotlib.figure.Figure
        Up to two panels a row (an odd last one centred), :data:`PAGE_WIDTH` wide, for :func:`save`.

    Raises
    ------
    ValueError
        For a plane not in :data:`phaseimpact.analysis.PLANES`, or ``summaries`` of another
        length than ``trajectories``.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.analysis import phase_portrait
    >>> from phaseimpact.plotting import plot_portraits
    >>> fig = plot_portraits(phase_portrait(seed_parameters(), "paper", [1e9, 2e12], t_end=2e-3))
    >>> [ax.get_title().splitlines()[1] for ax in fig.axes]
    ['1 stick phase, 1 contact (at least: cut)', '2 stick phases, 1 contact']
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    plane = tuple(plane)
    summaries = trajectories if summaries is None else summaries
    n = len(trajectories)
    ncols = min(n, 2)  # two panels a row: each wide enough for its legend at the printed size
    nrows = -(-n // ncols)
    with style():
        fig = plt.figure(figsize=(COLUMN_WIDTH if n == 1 else PAGE_WIDTH, 3.0 * nrows + 0.3 * bool(title)))
        # each panel spans two grid columns, so an odd last panel is centred rather than beside an empty slot
        grid = fig.add_gridspec(nrows, 2 * ncols)
        for k, (tr, summary) in enumerate(zip(trajectories, summaries, strict=True)):
            row, col = divmod(k, ncols)
            first = 2 * col + (ncols - (n - row * ncols) if row == nrows - 1 else 0)
            _draw_portrait(fig.add_subplot(grid[row, first:first + 2]), tr, summary, plane)
        if title:
            fig.suptitle(title)
    return fig


_PLANE_LABELS = {"delta": r"$\delta = x_1 - x_2$ (µm)", "deltadot": r"$\dot\delta$ (m/s)", "x1": "$x_1$ (µm)",
                 "x2": "$x_2$ (µm)", "x1dot": r"$\dot x_1$ (m/s)", "x2dot": r"$\dot x_2$ (m/s)"}


def _draw_portrait(ax, tr, summary, plane) -> None:
    """One panel of :func:`plot_portraits`: the run ``tr`` in ``plane``, the events and stick phases
    of ``summary``, a title with its outcome and counts, a legend."""
    from ..analysis import plane_coordinates

    a, b = plane_coordinates(tr.y, plane)
    ax.plot(np.asarray(a) * UM, b, color="0.25", lw=0.8)
    a0, b0 = plane_coordinates(summary.initial_state, plane)
    ax.plot([a0 * UM], [b0], "ks", ms=3, label="start")
    for kind, (marker, colour, label) in EVENT_MARKERS.items():
        events = summary.events_of(kind)
        if events:
            ea, eb = plane_coordinates(np.array([e.state for e in events]), plane)
            ax.plot(ea * UM, eb, ls="none", marker=marker, color=colour, ms=5, mew=1.0,
                    label=f"{label} ({len(events)})")
    _mark_stick_phases(ax, summary, plane, plane_coordinates)
    ax.set_xlabel(_PLANE_LABELS[plane[0]])
    ax.set_ylabel(_PLANE_LABELS[plane[1]])
    kappa = summary.law.kappa(summary.params)
    counts = (f"{summary.n_stick} stick phase{'s' if summary.n_stick != 1 else ''}, "
              f"{summary.n_contacts} contact{'s' if summary.n_contacts != 1 else ''}")
    if summary.cut:
        counts += " (at least: cut)"
    if not summary.ok:
        counts += f"; {summary.status}"
    ax.set_title(rf"$\kappa$ = {kappa:.6g}: {summary.outcome}" + f"\n{counts}")
    ax.legend(loc="best", frameon=True, framealpha=0.8, edgecolor="none")


def _mark_stick_phases(ax, summary, plane, plane_coordinates) -> None:
    """Each stick phase where it starts, in the ``(delta, deltadot)`` plane at the point
    ``(delta*, 0)`` it rests at: a filled star for a permanent stick, hollow circles for transient ones."""
    _, delta, dwell = summary.stick_points()
    if not len(delta):
        return
    permanent = np.isinf(dwell)
    if plane == ("delta", "deltadot"):
        pa, pb = delta, np.zeros_like(delta)
    else:
        sticks = summary.events_of("stick")
        pa, pb = plane_coordinates(np.array([e.state for e in sticks]), plane)
    if np.any(~permanent):
        ax.plot(pa[~permanent] * UM, pb[~permanent], ls="none", marker="o", mfc="none", mec="#4477aa",
                ms=6, mew=1.1, label=f"stick phase ({np.count_nonzero(~permanent)})")
    if np.any(permanent):
        label = ("asymptotic point (permanent stick)" if plane == ("delta", "deltadot")
                 else "permanent stick begins")
        ax.plot(pa[permanent] * UM, pb[permanent], ls="none", marker="*", color="#4477aa", ms=11,
                mec="k", mew=0.6, label=label)
