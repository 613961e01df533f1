"""Small matplotlib helpers with one consistent style for the study figures, and the figures of
the command line (``phaseimpact plot``, ``phaseimpact portrait``).

Uses the non-interactive ``Agg`` backend. Lengths are drawn in µm, times in ms, velocities in
m/s and forces in N. The only I/O is :func:`save` (PNG, PDF or SVG); a figure's data goes to HDF5
through :func:`phaseimpact.archive.save_h5`.

Figures are made for print: at most :data:`PAGE_WIDTH` wide (a journal's two columns;
:data:`COLUMN_WIDTH` for one), every text at least :data:`MIN_TEXT_PT` at that size
(:func:`print_problems` says which are not), PNG at 300 dpi and, inside :func:`for_print`, a vector
PDF beside each PNG.

One module per concern, this package their face: :mod:`._style` (style, :func:`figure`,
:func:`save`, print checks, one trajectory's panels), :mod:`._results` (archives and trajectories:
:func:`plot_atlas` (two axes: outcome classes as a categorical colour map), :func:`plot_sweep` (one
axis: counts and max force), :func:`plot_curve` (a continued ``kappa_c``, ``kappa_2`` or grazing
value against its parameter), :func:`plot_orbit_diagram`, :func:`plot_portraits` (one phase
portrait per trajectory, events marked)), :mod:`._impact_map` (branches of periodic orbits, their
bifurcations, basins of attraction). Each figure function returns a figure for :func:`save`.
"""

import matplotlib

matplotlib.use("Agg")  # before pyplot is first imported (by the modules below)

# The impact map's figures are importable from here but, as before the split, not in __all__.
from ._impact_map import (  # noqa: E402, F401
    ATTRACTOR_MARKERS,
    BASIN_COLOURS,
    BIFURCATION_MARKERS,
    mark_bifurcations,
    plot_basins,
    plot_bifurcation_curves,
    plot_map_branch,
    plot_variable,
)
from ._results import (  # noqa: E402
    EVENT_MARKERS,  # noqa: F401
    OUTCOME_COLOURS,
    axis_label,
    plot_atlas,
    plot_curve,
    plot_orbit_diagram,
    plot_portraits,
    plot_sweep,
)
from ._style import (  # noqa: E402
    COLUMN_WIDTH,
    FIGURE_FORMATS,
    MIN_TEXT_PT,
    MS,
    PAGE_WIDTH,
    STYLE,
    UM,
    figure,
    figure_format,
    for_print,
    mark_points,
    plot_displacements,
    plot_force,
    plot_hysteresis,
    print_problems,
    save,
    style,
)

__all__ = ["STYLE", "style", "figure", "plot_displacements", "plot_force", "plot_hysteresis",
           "mark_points", "save", "figure_format", "FIGURE_FORMATS", "UM", "MS", "OUTCOME_COLOURS",
           "axis_label", "plot_atlas", "plot_sweep", "plot_curve", "plot_portraits", "plot_orbit_diagram",
           "MIN_TEXT_PT", "COLUMN_WIDTH", "PAGE_WIDTH", "print_problems", "for_print"]
