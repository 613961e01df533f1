"""Bifurcations of the impact map of the seed plate just below one plate period, and its basins.

Claim (docs/physics.md §7), the seed case with Hunt-Crossley contact (kappa = 3e9, 1 m/s), T from 0.9
to 1.01 plate periods (studies/train.py's period-doubling sequence just below the first multiple),
period-1 and period-2 orbits followed by pseudo-arclength continuation and their bifurcations located
by bisection (phaseimpact map-continuation):

* the small-amplitude period-1 orbit (two contacts per impact, about 15 µm) is stable from the plate
  period down to a period-doubling at T = 0.9830 plate periods (a multiplier through -1); the stable
  period-2 orbit born there doubles again near 0.96 plate periods (period 4): the sequence of the
  orbit diagram from rest, located;
* a large-amplitude period-1 orbit (one contact per impact, about 0.4 to 1.5 mm), which the train
  from rest does not reach, is stable up to a fold (saddle-node) at T = 0.9695 plate periods, where
  it turns back unstable; at about 0.95 plate periods that unstable orbit grazes: its projectile's
  contact reaches the next arrival (a second contact and an overlap), where the map of this model
  ends;
* followed in kappa (2e9 to 4e9), the period-doubling moves from T = 0.988 down to 0.978 plate
  periods as the damping grows, the fold moves up by less than 0.005 of a period;
* at T equal to the plate period three periodic attractors coexist: the small period-1 orbit (12%
  of the initial plate states of a 41 x 41 grid within 1.5 v/omega and 1.5 v) and two period-2
  orbits (57% and 31%), their basins finely interleaved (on a 21 x 21 grid: 15%, 54% and 32%).
"""

from pathlib import Path

import numpy as np
from _plots import claim, known

from phaseimpact import seed_parameters
from phaseimpact.archive import save_h5
from phaseimpact.integrate import scales
from phaseimpact.plotting import (
    BIFURCATION_MARKERS,
    figure,
    plot_basins,
    plot_bifurcation_curves,
    plot_map_branch,
    save,
    style,
)
from phaseimpact.train import basins, continue_map_bifurcation, continue_map_orbit, impact_train, orbit_diagram

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "train_bifurcations"
LAW = "hunt-crossley"
KAPPA = 3e9
#: The second parameter's grid, each half beginning at the case's own value (warm starts).
KAPPAS = (np.array([3e9, 2.5e9, 2e9]), np.array([3e9, 3.5e9, 4e9]))


def two_parameter(params, branch, kind):
    """The ``kind`` point of ``branch`` followed over :data:`KAPPAS` (both halves joined, kappa rising)."""
    point = next(p for p in branch.points if p.kind == kind)
    return [continue_map_bifurcation(params, LAW, branch, point, "kappa", k) for k in KAPPAS]


def main(quick=False, jobs=1):
    params = seed_parameters(v=1.0, kappa=KAPPA)
    Tp = scales(params).plate_period
    omega = np.sqrt(params.Kb / params.M2)
    jobs = max(1, jobs)
    ratios = np.linspace(0.9, 1.01, 45 if quick else 111)
    transients, samples = (80, 16) if quick else (150, 32)
    diagram = orbit_diagram(params, LAW, "T", ratios * Tp, transients=transients, samples=samples, n_jobs=jobs)
    # the large-amplitude period-1 orbit (one contact an impact) followed up in T, the small one (two
    # contacts) down from just below the plate period, and the period-2 orbit born at its doubling
    large = continue_map_orbit(params, LAW, "T", 0.9 * Tp, 0.98 * Tp, step=0.005 * Tp)
    small = continue_map_orbit(params, LAW, "T", 0.995 * Tp, 0.95 * Tp, step=0.003 * Tp)
    pd = next(p for p in small.points if p.kind == "period-doubling")
    start = impact_train(params, LAW, 0.98 * Tp, 300, plate=pd.plate + np.array([0.0, 0.03])).plate[-1]
    double = continue_map_orbit(params, LAW, "T", 0.98 * Tp, 0.95 * Tp, k=2, guess=start, step=0.002 * Tp)
    curves = [*two_parameter(params, small, "period-doubling"), *two_parameter(params, large, "fold")]
    grid = 9 if quick else 41
    xs, vs = np.linspace(-1.5, 1.5, grid) * params.v / omega, np.linspace(-1.5, 1.5, grid) * params.v
    basin = basins(params, LAW, Tp, xs, vs, n_jobs=jobs)

    with style():
        fig, axes = figure(2, 2, width=7.2, height=6.4)
        ax = axes[0, 0]
        amplitude = np.hypot(diagram.plate[:, :, 0], diagram.plate[:, :, 1] / omega) * 1e6
        ax.plot(np.repeat(ratios, samples), amplitude.ravel(), ".", color="0.55", ms=1.5, mew=0, rasterized=True,
                label="attractor from rest")
        plot_map_branch(ax, large, x_scale=Tp, label="period-1 orbits", colour="k", omega=omega)
        plot_map_branch(ax, small, x_scale=Tp, colour="k", omega=omega)
        plot_map_branch(ax, double, x_scale=Tp, label="period-2 orbit", colour="#aa3377", omega=omega)
        ax.set_yscale("log")
        ax.set_xlim(ratios[0], ratios[-1])
        ax.set_xlabel("T / T_plate")
        ax.set_ylabel("plate amplitude before impact (µm)")
        ax.set_title("orbits (solid stable, dashed unstable)")
        # the orbits and the located points (marked in both top panels), above the panels, off the data
        fig.legend(*ax.get_legend_handles_labels(), loc="outside upper center", ncols=3)
        ax = axes[0, 1]
        for branch, colour, name in ((large, "k", "large period-1"), (small, "0.4", "small period-1"),
                                     (double, "#aa3377", "period-2")):
            for i, ls in ((0, "-"), (1, ":")):
                ax.plot(branch.values / Tp, branch.multipliers[:, i].real, color=colour, ls=ls, lw=1.0,
                        label=name if i == 0 else None)
        for y in (-1, 1):
            ax.axhline(y, color="0.5", lw=0.7)
        for branch in (large, small, double):
            for p in branch.points:
                marker, colour, _ = BIFURCATION_MARKERS[p.kind]
                ax.plot(p.value / Tp, np.clip(p.multipliers.real[np.argmin(np.abs(np.abs(p.multipliers) - 1))], -2, 2),
                        ls="none", marker=marker, color=colour, mec="k", mew=0.6, ms=6.5, zorder=5)
        ax.plot([], [], color="k", ls=":", lw=1.0, label="2nd multiplier")
        ax.set_ylim(-2, 2.6)  # room above +1, where no multiplier goes, for the legend
        ax.set_xlim(ratios[0], ratios[-1])
        ax.legend(loc="upper left", ncols=2)
        ax.set_xlabel("T / T_plate")
        ax.set_ylabel("Floquet multipliers (real part)")
        ax.set_title("a crossing of ±1 is a bifurcation")
        ax = axes[1, 0]
        plot_bifurcation_curves(ax, curves, x_scale=Tp, y_scale=1e9)
        ax.legend(loc="lower center")
        ax.set_xlabel("T / T_plate at the bifurcation")
        ax.set_ylabel("damping κ (1e9 N s/m$^{2.5}$)")
        ax.set_title("followed in κ")
        plot_basins(basin, ax=axes[1, 1], title="basins at T = T_plate")
        out = save(fig, FIGURES / f"{NAME}.png")

    points = [p for b in (large, small, double) for p in b.points]
    save_h5(FIGURES / "data" / f"{NAME}.h5",
            {"T_over_plate_period": (ratios, "1"), "x2": (diagram.plate[:, :, 0], "m"),
             "distinct": (diagram.distinct, "1"),
             "point_T_over_plate_period": (np.array([known(p.value / Tp) for p in points]), "1"),
             "basin_labels": (basin.labels, "1"), "basin_x2": (xs, "m"), "basin_x2dot": (vs, "m/s")},
            {"law": LAW, "kappa": KAPPA, "v": 1.0, "plate_period": known(Tp),
             "point_kinds": ",".join(p.kind for p in points),
             "basin_periods": ",".join(str(a.period) for a in basin.attractors),
             "basin_counts": ",".join(str(a.count) for a in basin.attractors), "claim": claim(__doc__)})
    for b in (large, small, double):
        print(b.period_k, b.message, [(p.kind, round(p.value / Tp, 6), p.contacts) for p in b.points])
    for c in curves:
        print(c.kind, c.message, np.round(c.values / Tp, 5), c.second_values)
    print([(a.period, a.count, a.plate[0]) for a in basin.attractors], basin.not_converged, basin.no_map)
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
