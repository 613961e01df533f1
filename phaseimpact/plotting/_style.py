"""The study figures' style and the figures of one trajectory: :func:`style`, :func:`figure`,
:func:`save` (PNG, PDF or SVG), print checks (:func:`print_problems`, :func:`for_print`) and the
trajectory panels (:func:`plot_displacements`, :func:`plot_force`, :func:`plot_hysteresis`,
:func:`mark_points`). Imported from :mod:`phaseimpact.plotting`.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import warnings

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from .._atomic import atomic_path

__all__ = ["STYLE", "style", "figure", "plot_displacements", "plot_force", "plot_hysteresis", "mark_points", "save",
           "figure_format", "FIGURE_FORMATS", "UM", "MS", "MIN_TEXT_PT", "COLUMN_WIDTH", "PAGE_WIDTH",
           "print_problems", "for_print"]

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
