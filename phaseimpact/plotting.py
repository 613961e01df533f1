"""Small matplotlib helpers with one consistent style for the study figures.

Uses the non-interactive ``Agg`` backend. Lengths are drawn in µm, times in ms, velocities in
m/s and forces in N. The only I/O is :func:`save` (PNG) and :func:`save_h5` (HDF5 data).
"""

from __future__ import annotations

import contextlib
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ._atomic import atomic_path  # noqa: E402

__all__ = ["STYLE", "style", "figure", "plot_displacements", "plot_force", "plot_phase", "plot_hysteresis",
           "mark_points", "save", "save_h5", "UM", "MS"]

UM = 1e6  #: m -> µm
MS = 1e3  #: s -> ms

STYLE = {
    "figure.dpi": 110,
    "savefig.dpi": 110,
    "font.size": 8,
    "axes.titlesize": 9,
    "axes.labelsize": 8,
    "legend.fontsize": 7,
    "xtick.labelsize": 7,
    "ytick.labelsize": 7,
    "lines.linewidth": 1.1,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "legend.frameon": False,
    "figure.constrained_layout.use": True,
}


@contextlib.contextmanager
def style():
    """Context in which figures use :data:`STYLE`."""
    with plt.rc_context(STYLE):
        yield


def figure(nrows=1, ncols=1, *, width=7.0, height=None, **kwargs):
    """``plt.subplots`` in the study style (call inside :func:`style`)."""
    height = height if height is not None else 2.4 * nrows
    return plt.subplots(nrows, ncols, figsize=(width, height), squeeze=False, **kwargs)


def plot_displacements(ax, trajectory, *, label="", relative=True, linestyle="-"):
    """x1, x2 (and x1 - x2) against time, µm vs ms."""
    t = trajectory.t * MS
    suffix = f" {label}" if label else ""
    ax.plot(t, trajectory.x1 * UM, "C0", ls=linestyle, label=f"$x_1$ projectile{suffix}")
    ax.plot(t, trajectory.x2 * UM, "C1", ls=linestyle, label=f"$x_2$ target{suffix}")
    if relative:
        ax.plot(t, trajectory.delta * UM, "C2", ls=linestyle, label=f"$x_1-x_2${suffix}")
    ax.set_xlabel("time t (ms)")
    ax.set_ylabel("displacement (µm)")


def plot_force(ax, trajectory, *, label=None, **kwargs):
    """Contact force (N) against time (ms)."""
    ax.plot(trajectory.t * MS, trajectory.force, label=label, **kwargs)
    ax.set_xlabel("time t (ms)")
    ax.set_ylabel("contact force P (N)")


def plot_hysteresis(ax, trajectory, *, label=None, **kwargs):
    """Contact force (N) against indentation delta = x1 - x2 (µm)."""
    ax.plot(trajectory.delta * UM, trajectory.force, label=label, **kwargs)
    ax.set_xlabel(r"indentation $\delta = x_1 - x_2$ (µm)")
    ax.set_ylabel("contact force P (N)")


def mark_points(ax, points, *, label="stick point", color="k", marker="o", scale=(UM, 1.0)):
    """Mark asymptotic points (array (k, 2), SI units) in a phase plane."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(points):
        ax.plot(points[:, 0] * scale[0], points[:, 1] * scale[1], ls="none", marker=marker, mfc="none",
                mec=color, ms=6, mew=1.2, label=f"{label} ({len(points)})")


def plot_phase(ax, trajectory, plane=("delta", "deltadot"), *, mark_events=True, label=None, **kwargs):
    """Phase path in ``plane`` (lengths in µm, velocities in m/s); stick points marked."""
    from .analysis import find_asymptotic_points, plane_coordinates

    a, b = plane_coordinates(trajectory.y, plane)
    ax.plot(np.asarray(a) * UM, b, label=label, **kwargs)
    names = {"delta": r"$\delta = x_1 - x_2$ (µm)", "deltadot": r"$\dot\delta$ (m/s)",
             "x1": "$x_1$ (µm)", "x2": "$x_2$ (µm)", "x1dot": r"$\dot x_1$ (m/s)", "x2dot": r"$\dot x_2$ (m/s)"}
    ax.set_xlabel(names.get(plane[0], plane[0]))
    ax.set_ylabel(names.get(plane[1], plane[1]))
    points = None
    if mark_events and tuple(plane) == ("delta", "deltadot"):
        points = find_asymptotic_points(trajectory, plane)
        mark_points(ax, points.points, color=kwargs.get("color", "k"))
    return points


def save(fig, path, dpi=110):
    """Write ``fig`` to ``path`` (PNG unless the suffix says otherwise; directories created) and close it.

    Written atomically (temporary file, then rename) and without the matplotlib version or a
    creation date in its metadata, so the same figure gives the same bytes on every run.
    """
    path = os.fspath(path)
    fmt = os.path.splitext(path)[1].lstrip(".").lower() or "png"
    metadata = {"Software": None}
    if fmt in ("pdf", "svg", "eps", "ps"):
        metadata["CreationDate"] = None
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=dpi, format=fmt, metadata=metadata)
    finally:
        plt.close(fig)
    return path


def save_h5(path, datasets: dict, attrs: dict | None = None):
    """Write ``{name: (array, units)}`` to HDF5 ``path`` atomically (temp file, then ``os.replace``).

    Names may contain ``/`` for groups; ``attrs`` go on the root (strings or numbers).
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
