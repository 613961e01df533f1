"""Grazing bifurcations of Hunt-Crossley: the number of contacts against kappa and over (kappa, v).

Claim (REFERENCE §5): a unilateral law has no stick, so no adding-sliding; its long-time count is
the number of contacts before the projectile is out of the plate's reach, and that count changes
at grazing values of kappa, where an extremum of delta in a flight phase just touches zero. At the
seed's case (v = 1 m/s) the count goes 2 -> 3 -> 2 -> 1 -> 2 over kappa in 1e8-1e13 N s/m^2.5, at
four grazing values located to 1e-9 as roots of the smooth extremum function (the 3-contact window
is 25 % wide, narrow enough for a coarse grid to step over it). Continued in v, the grazing values
are curves that bound the regions of the (kappa, v) atlas of contacts; more windows (up to 7
contacts) open at other speeds, each bounded by its own continued grazing curve.
"""

from pathlib import Path

import matplotlib.colors as mcolors
import numpy as np
from _plots import KAPPA_LABEL, V_LABEL, kappa_axis, save_archive

from phaseimpact import seed_parameters
from phaseimpact.continuation import atlas, critical_curve, delta_extremum, sweep, transitions
from phaseimpact.plotting import UM, figure, save, save_h5, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "grazing"
LAW = "hunt-crossley"
KAPPA_RANGE = (1e8, 1e13)
V_RANGE = (0.3, 13.0)


def edges(values):
    logv = np.log(values)
    mid = 0.5 * (logv[1:] + logv[:-1])
    return np.exp(np.concatenate([[2 * logv[0] - mid[0]], mid, [2 * logv[-1] - mid[-1]]]))


def continued(p, start_v, transition, speeds):
    """The grazing curve through ``transition`` (found at ``start_v``), walked to both ends of ``speeds``."""
    base = p.replace(v=start_v)
    parts = []
    for values in (speeds[speeds >= start_v], speeds[speeds <= start_v][::-1]):
        values = np.concatenate([[start_v], values[values != start_v]])
        if len(values) < 2:
            continue
        c = critical_curve(base, LAW, "v", values, what="grazing", kappa_start=transition.kappa,
                           contact_index=transition.extremum)
        parts.append((c.values, c.kappa))
    v = np.concatenate([x for x, _ in parts])
    k = np.concatenate([y for _, y in parts])
    order = np.argsort(v)
    return v[order], k[order]


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    found = transitions(p, LAW, *KAPPA_RANGE)
    kappas = np.geomspace(*KAPPA_RANGE, 150 if quick else 800)
    line = sweep(p, LAW, kappas, n_jobs=jobs)
    save_archive(line, FIGURES / "data" / f"{NAME}_sweep.h5")
    js = sorted({t.extremum for t in found})
    ext = {j: np.array([delta_extremum(p.replace(kappa=float(k)), LAW, j) for k in kappas[::4]]) for j in js}

    speeds = np.geomspace(*V_RANGE, 12 if quick else 40)
    grid = atlas(p, LAW, {"v": speeds, "kappa": np.geomspace(*KAPPA_RANGE, 30 if quick else 80)}, n_jobs=jobs)
    save_archive(grid, FIGURES / "data" / f"{NAME}_atlas.h5")
    curve_v = np.geomspace(*V_RANGE, 10 if quick else 36)
    curves = []
    for v0 in (1.0, V_RANGE[0], V_RANGE[1]):
        for t in (found if v0 == 1.0 else transitions(p.replace(v=v0), LAW, *KAPPA_RANGE)):
            v, k = continued(p, v0, t, curve_v)
            at1 = np.interp(0.0, np.log(v), np.log(k))
            if any(abs(at1 - np.interp(0.0, np.log(cv), np.log(ck))) < 1e-4 for cv, ck, _ in curves):
                continue  # the same curve, found again from another speed
            curves.append((v, k, t.extremum))

    with style():
        fig, axes = figure(1, 3, width=13, height=4.0)
        ax = axes[0, 0]
        ax.plot(kappas, line.n_contacts, "-", drawstyle="steps-mid", color="C0", lw=1.2, label="sweep (800 κ)")
        for i, t in enumerate(found):
            ax.axvline(t.kappa, color="C3", ls=":", lw=0.9,
                       label=f"grazing at {t.kappa:.4g}: {t.count_below} → {t.count_above}")
            ax.annotate(f"{t.count_below}→{t.count_above}", (t.kappa, 3.45 - 0.2 * (i % 2)), fontsize=6,
                        ha="right" if i % 2 == 0 else "left", color="C3")
        kappa_axis(ax)
        ax.set_ylabel("contacts before the projectile is out of reach")
        ax.set_ylim(0.5, 3.6)
        ax.set_yticks([1, 2, 3])
        ax.set_title("Hunt-Crossley, v = 1 m/s: contacts against κ")
        ax.legend(loc="lower left", fontsize=6)

        ax = axes[0, 1]
        for j in js:
            ax.plot(kappas[::4], ext[j] * UM, "-", lw=1, label=f"extremum {j} of δ")
        for t in found:
            ax.plot(t.kappa, 0.0, "o", color="C3", mfc="none", ms=5)
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_yscale("symlog", linthresh=1.0)
        kappa_axis(ax)
        ax.set_ylabel("δ at the extremum (µm, symlog)")
        ax.set_title("defining functions: grazing where an\nextremum of δ crosses 0 (circles)")
        ax.legend(loc="lower right", fontsize=6)

        ax = axes[0, 2]
        n = grid.n_contacts.reshape(len(speeds), -1)
        top = int(n.max())
        cmap = mcolors.ListedColormap([mcolors.to_hex(c) for c in
                                       __import__("matplotlib").colormaps["viridis"](np.linspace(0, 1, top))])
        mesh = ax.pcolormesh(edges(grid.axis("kappa")), edges(speeds), n, cmap=cmap, vmin=0.5, vmax=top + 0.5,
                             shading="flat", rasterized=True)
        fig.colorbar(mesh, ax=ax, ticks=range(1, top + 1), label="contacts")
        for i, (v, k, _) in enumerate(curves):
            ax.plot(k, v, "w-", lw=2.0)
            ax.plot(k, v, "-", color="C3", lw=0.9, label="continued grazing curves" if i == 0 else None)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(*KAPPA_RANGE)
        ax.set_xlabel(KAPPA_LABEL)
        ax.set_ylabel(V_LABEL)
        ax.grid(False)
        ax.set_title(f"(κ, v) atlas of contacts, {len(curves)} grazing curves")
        ax.legend(loc="lower left", fontsize=6, frameon=True, facecolor="white", framealpha=0.8)
        out = save(fig, FIGURES / f"{NAME}.png")
    data = {"transitions/kappa": (np.array([t.kappa for t in found]), "N s/m^2.5"),
            "transitions/count_below": (np.array([t.count_below for t in found]), "1"),
            "transitions/count_above": (np.array([t.count_above for t in found]), "1"),
            "transitions/extremum": (np.array([t.extremum for t in found]), "1"),
            "extrema/kappa": (kappas[::4], "N s/m^2.5")}
    data.update({f"extrema/delta_{j}": (ext[j], "m") for j in js})
    for i, (v, k, j) in enumerate(curves):
        data[f"curves/{i}/v"] = (v, "m/s")
        data[f"curves/{i}/kappa"] = (k, "N s/m^2.5")
        data[f"curves/{i}/extremum"] = (np.array([j]), "1")
    save_h5(FIGURES / "data" / f"{NAME}.h5", data, {"law": LAW, "v": 1.0, "claim": " ".join(__doc__.split())})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
