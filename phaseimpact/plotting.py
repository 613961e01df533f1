"""Small matplotlib helpers with one consistent style for the study figures, and the figures of
the command line (``phaseimpact plot``, ``phaseimpact portrait``).

Uses the non-interactive ``Agg`` backend. Lengths are drawn in µm, times in ms, velocities in
m/s and forces in N. The only I/O is :func:`save` (PNG, PDF or SVG) and :func:`save_h5` (HDF5 data).

Figures are made for print: at most :data:`PAGE_WIDTH` wide (a journal's two columns;
:data:`COLUMN_WIDTH` for one), every text at least :data:`MIN_TEXT_PT` at that size
(:func:`print_problems` says which are not), PNG at 300 dpi and, inside :func:`for_print`, a vector
PDF beside each PNG.

Archives and trajectories: :func:`plot_atlas` (two axes: outcome classes as a categorical colour
map), :func:`plot_sweep` (one axis: counts and max force), :func:`plot_curve` (a continued
``kappa_c``, ``kappa_2`` or grazing value against its parameter) and :func:`plot_portraits` (one
phase portrait per trajectory, events marked). Each returns a figure for :func:`save`.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import textwrap
import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ._atomic import atomic_path  # noqa: E402

__all__ = ["STYLE", "style", "figure", "plot_displacements", "plot_force", "plot_hysteresis",
           "mark_points", "save", "save_h5", "figure_format", "FIGURE_FORMATS", "UM", "MS", "OUTCOME_COLOURS",
           "axis_label", "plot_atlas", "plot_sweep", "plot_curve", "plot_portraits", "plot_orbit_diagram",
           "MIN_TEXT_PT", "COLUMN_WIDTH", "PAGE_WIDTH", "print_problems", "for_print"]

UM = 1e6  #: m -> µm
MS = 1e3  #: s -> ms

#: Smallest text of a printed figure, points (journals ask for 7-8 pt at the printed size).
MIN_TEXT_PT = 8
#: Width of one journal column and of a full page (two columns), inches.
COLUMN_WIDTH = 3.5
PAGE_WIDTH = 7.2

#: matplotlib rcParams of the study figures (:func:`style`): every text :data:`MIN_TEXT_PT`, figures
#: drawn at the size they are printed at.
STYLE = {
    "figure.dpi": 100,
    "savefig.dpi": 300,
    "font.size": MIN_TEXT_PT,
    "axes.titlesize": MIN_TEXT_PT,
    "axes.labelsize": MIN_TEXT_PT,
    "legend.fontsize": MIN_TEXT_PT,
    "legend.title_fontsize": MIN_TEXT_PT,
    "figure.titlesize": MIN_TEXT_PT + 1,
    "xtick.labelsize": MIN_TEXT_PT,
    "ytick.labelsize": MIN_TEXT_PT,
    "axes.titlepad": 4.0,
    "axes.labelpad": 2.0,
    "legend.handlelength": 1.6,
    "legend.handletextpad": 0.4,
    "legend.labelspacing": 0.3,
    "legend.borderaxespad": 0.3,
    "legend.columnspacing": 1.0,
    "lines.linewidth": 1.0,
    "lines.markersize": 4.0,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "legend.frameon": False,
    "figure.constrained_layout.use": True,
    "figure.constrained_layout.h_pad": 0.03,
    "figure.constrained_layout.w_pad": 0.03,
    "pdf.fonttype": 42,  # TrueType, not Type 3: journals' PDF checks reject Type 3 fonts
}


@contextlib.contextmanager
def style():
    """Context in which figures use :data:`STYLE`.

    Yields
    ------
    None
        Inside the ``with`` block, matplotlib's rcParams are :data:`STYLE`; they are restored after.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from phaseimpact.plotting import STYLE, style
    >>> with style():
    ...     print(plt.rcParams["font.size"] == STYLE["font.size"])
    True
    """
    with plt.rc_context(STYLE):
        yield


def figure(nrows=1, ncols=1, *, width=PAGE_WIDTH, height=None, **kwargs):
    """``plt.subplots`` in the study style (call inside :func:`style`).

    Parameters
    ----------
    nrows, ncols : int, default 1
        The grid of axes.
    width : float, default :data:`PAGE_WIDTH`
        Figure width, inches: the printed width (text sizes are the printed sizes).
    height : float, optional
        Figure height, inches; default 2.4 per row.
    **kwargs
        Passed to :func:`matplotlib.pyplot.subplots` (``sharex``...).

    Returns
    -------
    fig : matplotlib.figure.Figure
    axes : ndarray of Axes, shape (nrows, ncols)
        Always 2-d (``squeeze=False``).

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from phaseimpact.plotting import figure, style
    >>> with style():
    ...     fig, axes = figure(1, 3)
    >>> axes.shape, fig.get_size_inches().tolist()
    ((1, 3), [7.2, 2.4])
    >>> plt.close(fig)
    """
    height = height if height is not None else 2.4 * nrows
    return plt.subplots(nrows, ncols, figsize=(width, height), squeeze=False, **kwargs)


def plot_displacements(ax, trajectory, *, label="", relative=True, linestyle=None):
    """x1, x2 (and x1 - x2) against time, µm vs ms.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    trajectory : Trajectory
        A run with samples (``save="steps"`` or a time grid).
    label : str, default ""
        Appended to each line's label.
    relative : bool, default True
        Also draw the indentation ``x1 - x2``.
    linestyle : str, optional
        Line style of the three lines; default: solid, dashed and dash-dotted, so they read apart
        in grayscale too.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from phaseimpact import seed_parameters, simulate
    >>> from phaseimpact.plotting import figure, plot_displacements, style
    >>> tr = simulate(seed_parameters(kappa=3e9), "paper", 2e-4, save="steps")
    >>> with style():
    ...     fig, axes = figure()
    ...     plot_displacements(axes[0, 0], tr, label="paper")
    >>> [line.get_label() for line in axes[0, 0].lines]
    ['$x_1$ projectile paper', '$x_2$ target paper', '$x_1-x_2$ paper']
    >>> plt.close(fig)
    """
    t = trajectory.t * MS
    suffix = f" {label}" if label else ""
    styles = (linestyle,) * 3 if linestyle is not None else ("-", "--", "-.")
    ax.plot(t, trajectory.x1 * UM, "C0", ls=styles[0], label=f"$x_1$ projectile{suffix}")
    ax.plot(t, trajectory.x2 * UM, "C1", ls=styles[1], label=f"$x_2$ target{suffix}")
    if relative:
        ax.plot(t, trajectory.delta * UM, "C2", ls=styles[2], label=f"$x_1-x_2${suffix}")
    ax.set_xlabel("time t (ms)")
    ax.set_ylabel("displacement (µm)")


def plot_force(ax, trajectory, *, label=None, **kwargs):
    """Contact force (N) against time (ms).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    trajectory : Trajectory
        A run with samples (``save="steps"`` or a time grid).
    label : str, optional
        The line's label.
    **kwargs
        Passed to :meth:`matplotlib.axes.Axes.plot`.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from phaseimpact import seed_parameters, simulate
    >>> from phaseimpact.plotting import figure, plot_force, style
    >>> tr = simulate(seed_parameters(kappa=3e9), "paper", 2e-4, save="steps")
    >>> with style():
    ...     fig, axes = figure()
    ...     plot_force(axes[0, 0], tr, color="k")
    >>> axes[0, 0].get_xlabel(), axes[0, 0].get_ylabel()
    ('time t (ms)', 'contact force P (N)')
    >>> plt.close(fig)
    """
    ax.plot(trajectory.t * MS, trajectory.force, label=label, **kwargs)
    ax.set_xlabel("time t (ms)")
    ax.set_ylabel("contact force P (N)")


def plot_hysteresis(ax, trajectory, *, label=None, **kwargs):
    """Contact force (N) against indentation delta = x1 - x2 (µm).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    trajectory : Trajectory
        A run with samples (``save="steps"`` or a time grid).
    label : str, optional
        The line's label.
    **kwargs
        Passed to :meth:`matplotlib.axes.Axes.plot`.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from phaseimpact import seed_parameters, simulate
    >>> from phaseimpact.plotting import figure, plot_hysteresis, style
    >>> tr = simulate(seed_parameters(kappa=1e9), "hunt-crossley", save="steps")
    >>> with style():
    ...     fig, axes = figure()
    ...     plot_hysteresis(axes[0, 0], tr, label="hunt-crossley")
    >>> len(axes[0, 0].lines), axes[0, 0].get_ylabel()
    (1, 'contact force P (N)')
    >>> plt.close(fig)
    """
    ax.plot(trajectory.delta * UM, trajectory.force, label=label, **kwargs)
    ax.set_xlabel(r"indentation $\delta = x_1 - x_2$ (µm)")
    ax.set_ylabel("contact force P (N)")


def mark_points(ax, points, *, label="stick point", color="k", marker="o", scale=(UM, 1.0)):
    """Mark asymptotic points (array (k, 2), SI units) in a phase plane.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    points : array of shape (k, 2)
        Points in SI units (e.g. :attr:`phaseimpact.analysis.AsymptoticPoints.points`); none: nothing
        is drawn.
    label : str, default "stick point"
        The legend label (the count is appended).
    color : str, default "k"
        Edge colour of the hollow markers.
    marker : str, default "o"
        Marker.
    scale : pair of float, default (UM, 1.0)
        Factors of the two coordinates (µm and m/s for the ``(delta, deltadot)`` plane).

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from phaseimpact import seed_parameters, simulate
    >>> from phaseimpact.analysis import find_asymptotic_points
    >>> from phaseimpact.plotting import figure, mark_points, style
    >>> points = find_asymptotic_points(simulate(seed_parameters(kappa=2e12), "paper")).points
    >>> with style():
    ...     fig, axes = figure()
    ...     mark_points(axes[0, 0], points)
    >>> axes[0, 0].get_legend_handles_labels()[1]
    ['stick point (2)']
    >>> plt.close(fig)
    """
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(points):
        ax.plot(points[:, 0] * scale[0], points[:, 1] * scale[1], ls="none", marker=marker, mfc="none",
                mec=color, ms=6, mew=1.2, label=f"{label} ({len(points)})")


#: The formats :func:`save` writes, each with the metadata that keeps its bytes the same from run to
#: run (no matplotlib version, no creation date; each backend names these keys its own way).
FIGURE_FORMATS = {
    "png": {"Software": None},
    "pdf": {"Creator": None, "Producer": None, "CreationDate": None},
    "svg": {"Creator": None, "Date": None},
}


def figure_format(path) -> str:
    """The format of a figure ``path`` from its suffix (``png`` when it has none); ``ValueError`` for a
    format :func:`save` does not write (call it before the work that makes the figure).

    Parameters
    ----------
    path : str or path-like
        The figure's file.

    Returns
    -------
    str
        A key of :data:`FIGURE_FORMATS`.

    Raises
    ------
    ValueError
        For a suffix other than ``.png``, ``.pdf`` or ``.svg`` (any case).

    Examples
    --------
    >>> from phaseimpact.plotting import figure_format
    >>> figure_format("atlas.SVG"), figure_format("atlas")
    ('svg', 'png')
    >>> figure_format("atlas.jpg")
    Traceback (most recent call last):
    ...
    ValueError: figure 'atlas.jpg' has format 'jpg'; allowed: .png, .pdf, .svg
    """
    suffix = os.path.splitext(os.fspath(path))[1].lstrip(".").lower()
    fmt = suffix or "png"
    if fmt not in FIGURE_FORMATS:
        raise ValueError(f"figure {os.fspath(path)!r} has format {suffix!r}; allowed: "
                         + ", ".join(f".{name}" for name in FIGURE_FORMATS))
    return fmt


#: What :func:`for_print` asks of :func:`save`: formats written beside each figure, and whether a
#: figure that would not print legibly is an error (else a warning).
_PRINT: contextvars.ContextVar[tuple[tuple[str, ...], bool] | None] = contextvars.ContextVar("print", default=None)


def print_problems(fig, minimum: float = MIN_TEXT_PT, width: float = PAGE_WIDTH) -> list[str]:
    """What keeps ``fig`` from printing legibly at its own size: wider than ``width``, or a visible
    text (tick label, axis label, title, legend entry, annotation, contour label...) smaller than
    ``minimum``.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure, at the size it is printed at (its size in inches).
    minimum : float, default :data:`MIN_TEXT_PT`
        Smallest text size, points.
    width : float, default :data:`PAGE_WIDTH`
        Widest figure, inches.

    Returns
    -------
    list of str
        One line per problem; empty when the figure prints legibly.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from phaseimpact.plotting import figure, print_problems, style
    >>> with style():
    ...     fig, axes = figure(width=8.0)
    ...     _ = axes[0, 0].set_title("fine")
    ...     _ = axes[0, 0].annotate("tiny", (0.5, 0.5), fontsize=6)
    >>> for problem in print_problems(fig):
    ...     print(problem)
    8 in wide (at most 7.2 in)
    6 pt text (at least 8 pt): 'tiny'
    >>> plt.close(fig)
    """
    problems = []
    wide = float(fig.get_size_inches()[0])
    if wide > width + 1e-9:
        problems.append(f"{wide:g} in wide (at most {width:g} in)")
    fig.canvas.draw()  # tick labels exist only once drawn
    for text in fig.findobj(matplotlib.text.Text):
        if text.get_text().strip() and _shown(text) and text.get_fontsize() < minimum - 1e-9:
            problems.append(f"{text.get_fontsize():g} pt text (at least {minimum:g} pt): {text.get_text()!r}")
    return problems


def _shown(text) -> bool:
    """Whether ``text`` is drawn: it and its axes are visible (a hidden panel's texts are not printed)."""
    return text.get_visible() and (text.axes is None or text.axes.get_visible())


@contextlib.contextmanager
def for_print(beside=("pdf",), strict: bool = False):
    """Context in which :func:`save` writes each figure for print: also in the formats ``beside`` (same
    name, their suffix), and checked by :func:`print_problems` (a warning, or ``ValueError`` if ``strict``).

    Parameters
    ----------
    beside : sequence of str, default ("pdf",)
        Formats (keys of :data:`FIGURE_FORMATS`) written beside the one a path names.
    strict : bool, default False
        Raise, rather than warn, for a figure that does not print legibly (nothing is written then).

    Yields
    ------
    None

    Raises
    ------
    ValueError
        For a format not in :data:`FIGURE_FORMATS`.

    Examples
    --------
    >>> import os, tempfile
    >>> from phaseimpact.plotting import figure, for_print, save, style
    >>> folder = tempfile.mkdtemp()
    >>> with style(), for_print():
    ...     fig, axes = figure(width=3.5)
    ...     _ = axes[0, 0].plot([0, 1], [0, 1])
    ...     _ = save(fig, os.path.join(folder, "line.png"))
    >>> sorted(os.listdir(folder))
    ['line.pdf', 'line.png']
    """
    beside = tuple(figure_format(f"figure.{fmt}") for fmt in beside)
    token = _PRINT.set((beside, strict))
    try:
        yield
    finally:
        _PRINT.reset(token)


def save(fig, path, dpi=300):
    """Write ``fig`` to ``path`` (.png, .pdf or .svg; PNG without a suffix; directories created) and close it.

    Written atomically (temporary file, then rename) and without the matplotlib version or a
    creation date in its metadata, so the same figure gives the same bytes on every run (SVG: its
    element ids are hashed with a fixed salt, not a random one). Inside :func:`for_print`, also
    written in its formats beside ``path``, and checked for print.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure; closed afterwards, also when the write fails.
    path : str or path-like
        Where to write; the suffix gives the format (:func:`figure_format`).
    dpi : float, default 300
        Resolution of PNG (and of rasterised parts of PDF and SVG), dots per inch.

    Returns
    -------
    str
        ``path``.

    Raises
    ------
    ValueError
        For a format not in :data:`FIGURE_FORMATS`, a path that cannot be written, or another
        process writing it; inside ``for_print(strict=True)``, for a figure :func:`print_problems`
        finds fault with.

    Examples
    --------
    >>> import os, tempfile
    >>> from phaseimpact.plotting import figure, save, style
    >>> with style():
    ...     fig, axes = figure()
    ...     _ = axes[0, 0].plot([0, 1], [0, 1])
    >>> path = save(fig, os.path.join(tempfile.mkdtemp(), "figs", "line.svg"))
    >>> os.path.basename(path), os.path.getsize(path) > 0
    ('line.svg', True)
    """
    path = os.fspath(path)
    try:
        fmt = figure_format(path)
        paths = {fmt: path}
        printing = _PRINT.get()
        if printing is not None:
            beside, strict = printing
            problems = print_problems(fig)
            if problems:
                message = f"figure {path!r} does not print legibly: " + "; ".join(problems)
                if strict:
                    raise ValueError(message)
                warnings.warn(message, stacklevel=2)
            stem = os.path.splitext(path)[0]
            paths.update({other: f"{stem}.{other}" for other in beside if other != fmt})
        # deterministic PDF and SVG: no random ids (svg.hashsalt); PDF ids come from the content
        with plt.rc_context({"svg.hashsalt": "phaseimpact"}):
            for kind, target in paths.items():
                with atomic_path(target) as tmp:
                    fig.savefig(tmp, dpi=dpi, format=kind, metadata=FIGURE_FORMATS[kind])
    finally:
        plt.close(fig)
    return path


def save_h5(path, datasets: dict, attrs: dict | None = None):
    """Write ``{name: (array, units)}`` to HDF5 ``path`` atomically (temp file, then ``os.replace``).

    Names may contain ``/`` for groups; ``attrs`` go on the root (strings or numbers).

    Parameters
    ----------
    path : str or path-like
        The file to write.
    datasets : dict
        ``{name: (array, units)}``; strings are stored as bytes, arrays of more than 64 elements
        gzip-compressed; ``units`` becomes each dataset's attribute.
    attrs : dict, optional
        Root attributes.

    Returns
    -------
    str or path-like
        ``path``.

    Raises
    ------
    ValueError
        For a path that cannot be written or another process writing it.

    Examples
    --------
    >>> import os, tempfile
    >>> import h5py, numpy as np
    >>> from phaseimpact.plotting import save_h5
    >>> path = save_h5(os.path.join(tempfile.mkdtemp(), "data.h5"),
    ...                {"t": (np.linspace(0, 1e-3, 5), "s"), "runs/law": (["paper", "abrate"], "1")},
    ...                {"case": "seed"})
    >>> with h5py.File(path) as f:
    ...     print(sorted(f), f["t"].attrs["units"], f["runs/law"][()].tolist(), f.attrs["case"])
    ['runs', 't'] s [b'paper', b'abrate'] seed
    """
    import h5py

    with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
        for key, value in (attrs or {}).items():
            f.attrs[key] = value
        for name, (data, units) in datasets.items():
            arr = np.asarray(data)
            if arr.dtype == object or arr.dtype.kind == "U":
                arr = arr.astype("S")
            ds = f.create_dataset(name, data=arr, compression="gzip" if arr.size > 64 else None)
            ds.attrs["units"] = units
    return path


# ------------------------------------------------------------------------------------------------
# Figures of archives and portraits (the command line's plot and portrait)
# ------------------------------------------------------------------------------------------------

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
    from .case import SETTABLE

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

    from .continuation.sweep import OUTCOME_LABELS

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
        for i, curve in enumerate(curves):
            keep = np.isfinite(curve.kappa)
            x, y = (curve.kappa[keep], curve.values[keep]) if ax0.name == "kappa" else (curve.values[keep],
                                                                                       curve.kappa[keep])
            ax.plot(x, y, color="k" if i == 0 else f"C{i}", lw=1.6, label=f"{_what_label(curve)} (continued)")
            closed = np.isfinite(curve.closed_form)
            if np.any(closed):
                cx, cy = ((curve.closed_form[closed], curve.values[closed]) if ax0.name == "kappa"
                          else (curve.values[closed], curve.closed_form[closed]))
                ax.plot(cx, cy, color="w", ls="--", lw=1.0, label=r"closed-form $\kappa_c$")
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
    from .analysis import plane_coordinates

    plane = tuple(plane)
    summaries = trajectories if summaries is None else summaries
    n = len(trajectories)
    ncols = min(n, 2)  # two panels a row: each wide enough for its legend at the printed size
    nrows = -(-n // ncols)
    names = {"delta": r"$\delta = x_1 - x_2$ (µm)", "deltadot": r"$\dot\delta$ (m/s)", "x1": "$x_1$ (µm)",
             "x2": "$x_2$ (µm)", "x1dot": r"$\dot x_1$ (m/s)", "x2dot": r"$\dot x_2$ (m/s)"}
    with style():
        fig = plt.figure(figsize=(COLUMN_WIDTH if n == 1 else PAGE_WIDTH, 3.0 * nrows + 0.3 * bool(title)))
        # each panel spans two grid columns, so an odd last panel is centred rather than beside an empty slot
        grid = fig.add_gridspec(nrows, 2 * ncols)
        for k, (tr, summary) in enumerate(zip(trajectories, summaries, strict=True)):
            row, col = divmod(k, ncols)
            first = 2 * col + (ncols - (n - row * ncols) if row == nrows - 1 else 0)
            ax = fig.add_subplot(grid[row, first:first + 2])
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
            _, delta, dwell = summary.stick_points()
            if len(delta):
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
            ax.set_xlabel(names[plane[0]])
            ax.set_ylabel(names[plane[1]])
            kappa = summary.law.kappa(summary.params)
            counts = (f"{summary.n_stick} stick phase{'s' if summary.n_stick != 1 else ''}, "
                      f"{summary.n_contacts} contact{'s' if summary.n_contacts != 1 else ''}")
            if summary.cut:
                counts += " (at least: cut)"
            if not summary.ok:
                counts += f"; {summary.status}"
            ax.set_title(rf"$\kappa$ = {kappa:.6g}: {summary.outcome}" + f"\n{counts}")
            ax.legend(loc="best", frameon=True, framealpha=0.8, edgecolor="none")
        if title:
            fig.suptitle(title)
    return fig


# ------------------------------------------------------------------------------------------------
# The impact map: branches of periodic orbits, their bifurcations, basins of attraction
# ------------------------------------------------------------------------------------------------

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
