"""The (kappa, v) atlas of eq. 8, printed and unilateral readings, with the continued kappa_c(v), kappa_2(v).

Claim (REFERENCE §5): over damping 1e10-1e15 N s/m^2.5 and speeds 0.3-13 m/s every run of "paper"
ends in one of few ways, and the boundary between the permanent stick and the escape is the
continued adding-sliding curve kappa_c(v) (the closed form of REFERENCE §5 lies on it to 0.3 %;
kappa_2(v) is within 6e-4 of it, indistinguishable at this scale). Below it: one permanent stick
(both readings). Above it: two stick phases (more only in the thin staircase next to kappa_c,
which this grid does not sample), then the escape; every count is checked against a run at a
tighter integrator tolerance (points where it differs would be marked). Printed reading: every
escape becomes a runaway (the law acts in tension). Unilateral reading: the projectile separates
and rebounds with an apparent restitution that passes 1 a little above kappa_c, or, at higher
damping, gains energy faster than it separates (stopped when the energy has doubled). Atlases
archived in figures/data/atlas_paper_*.h5 (phaseimpact archives; archive.load reads them).
"""

from pathlib import Path

import matplotlib.colors as mcolors
import numpy as np
from _plots import COUNT_RTOL, KAPPA_LABEL, READINGS, V_LABEL, save_archive

from phaseimpact import seed_parameters
from phaseimpact.continuation import atlas, critical_curve
from phaseimpact.plotting import figure, save, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "atlas_paper"
RUNAWAY = 2  # index of "runaway" in STOP_REASONS


def edges(values):
    """Cell edges of a log-spaced axis."""
    logv = np.log(values)
    mid = 0.5 * (logv[1:] + logv[:-1])
    return np.exp(np.concatenate([[2 * logv[0] - mid[0]], mid, [2 * logv[-1] - mid[-1]]]))


def classes(result):
    """0 permanent stick, 1 two stick phases then escape, 2 three or more then escape, 3 energy
    doubled before the projectile separated (unilateral reading only; the printed reading always
    runs away after its escape), 4 an escape after a single stick (a re-stick missed by the engine)."""
    n = result.n_stick
    permanent = result.outcome_names() == "permanent-stick"
    unilateral = result.law.contact == "unilateral"
    gained = unilateral & (result.stop_reason == RUNAWAY)
    return np.where(permanent, 0, np.where(n == 1, 4, np.where(gained, 3, np.where(n == 2, 1, 2))))


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    kappas = np.geomspace(1e10, 1e15, 24 if quick else 70)
    speeds = np.geomspace(0.3, 13.0, 12 if quick else 36)
    axes_ = {"v": speeds, "kappa": kappas}
    results, sensitive = {}, {}
    for name, law in READINGS.items():
        r = atlas(p, law, axes_, n_jobs=jobs, rtol=COUNT_RTOL)
        check = atlas(p, law, axes_, n_jobs=jobs, rtol=1e-13)
        results[name] = r
        sensitive[name] = (r.n_stick != check.n_stick) | (r.outcome != check.outcome)
        save_archive(r, FIGURES / "data" / f"{NAME}_{name}.h5")
    curve_v = np.geomspace(0.3, 13.0, 8 if quick else 30)
    kc = critical_curve(p, "paper", "v", curve_v)
    k2 = critical_curve(p, "paper", "v", curve_v, what="kappa_2")
    shape = (len(speeds), len(kappas))
    xe, ye = edges(kappas), edges(speeds)

    def overlay(ax):
        ax.plot(kc.kappa, kc.values, "w-", lw=2.2)
        ax.plot(kc.kappa, kc.values, "k-", lw=1.0, label="κc(v), continued")
        ax.plot(k2.kappa, k2.values, "--", color="C3", lw=1.0, label="κ2(v)")
        ax.plot(kc.closed_form, kc.values, ":", color="yellow", lw=1.2, label="closed form of κc")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xticks([1e11, 1e13])  # every other decade, none at an edge: room for the labels of narrow panels
        ax.set_xlabel(KAPPA_LABEL)
        ax.grid(False)

    with style():
        fig, axes = figure(1, 3, height=3.7, sharey=True)
        labels = ["permanent stick (N = 1)", "N = 2, escape (printed: runaway; unilateral: rebound)",
                  "N ≥ 3, escape (printed: runaway; unilateral: rebound)",
                  "unilateral: escape, stopped by the energy guard", "escape after N = 1 (missed re-stick)"]
        present = set()
        colors = ["#4c72b0", "#dd8452", "#c44e52", "#8172b3", "#999999"]
        cmap = mcolors.ListedColormap(colors)
        for ax, name in zip(axes[0, :2], READINGS, strict=True):
            r = results[name]
            cls = classes(r)
            ax.pcolormesh(xe, ye, cls.reshape(shape).astype(float), cmap=cmap, vmin=-0.5, vmax=4.5, shading="flat",
                          rasterized=True)
            K, V = np.meshgrid(kappas, speeds)
            bad = sensitive[name].reshape(shape)
            if bad.any():
                ax.plot(K[bad], V[bad], "o", mfc="white", mec="k", mew=0.3, ms=2.5,
                        label=f"N or outcome changes with rtol 1e-12 → 1e-13 ({bad.sum()} of {bad.size})")
            present |= set(np.unique(cls).tolist())
            overlay(ax)
            ax.set_title(f"paper, {name} reading:\nhow each run ends")
        axes[0, 0].set_ylabel(V_LABEL)
        for c, text in enumerate(labels):
            if c in present:
                axes[0, 0].plot([], [], "s", color=colors[c], ms=6, label=text)
        ax = axes[0, 2]
        un = results["unilateral"]
        e = np.where((un.outcome_names() == "ratchet-escape") & (un.stop_reason != RUNAWAY), un.restitution, np.nan)
        mesh = ax.pcolormesh(xe, ye, e.reshape(shape), cmap="viridis", shading="flat", rasterized=True)
        ax.contour(kappas, speeds, e.reshape(shape), levels=[1.0], colors="w", linewidths=1.0)
        fig.colorbar(mesh, ax=ax, label="apparent restitution e (white line: e = 1)")
        overlay(ax)
        ax.set_title("unilateral: restitution e\n(blank: permanent stick)")
        handles, texts = axes[0, 0].get_legend_handles_labels()
        order = [texts.index(t) for t in texts if not t.startswith("κ") and not t.startswith("closed")]
        order += [texts.index(t) for t in texts if t.startswith("κ") or t.startswith("closed")]
        fig.legend([handles[i] for i in order], [texts[i] for i in order], loc="outside lower center", ncol=2)
        out = save(fig, FIGURES / f"{NAME}.png")
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
