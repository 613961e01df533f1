"""Trains of impacts on the seed plate: the impact map's attractor and the plate's build-up against the
period between impacts.

Claim (docs/physics.md §7), the seed case with Hunt-Crossley contact (kappa = 3e9, 1 m/s), one
projectile every T seconds on the plate as the previous impacts left it, T from 0.3 to 4 plate
periods (the plate's small-amplitude period), 200 impacts dropped and 40 kept at each of 400 values,
each value's attractor classified by converging to it (phaseimpact.train.attracting_orbit: Newton's
method on the map's k-th power from the last sample, k up to 8, and a stable orbit that the samples
approach): the attractor's pattern repeats with the plate period. Stable period-1 orbits fill most of
each period, from about 0.15 to 0.72 of a period past each multiple, without a break at the half
multiple: there the orbit's slowest multiplier is about -0.96, so that after 200 impacts its samples
are still distinct (a count of distinct samples calls them irregular). The plate's steady amplitude
is largest (about 0.18 mm) near their start. Just below each multiple lies a narrow window of
period-1 orbits of small amplitude (about 15 µm), reached as T rises through period 2 and period 4:
a period-doubling sequence, which this grid resolves only to period 4. From about 0.72 of a period
to about 0.15 past each multiple, stable orbits of period 2 to 8 (and a few of period 1) alternate
with values where no stable orbit of period up to 8 is approached (irregular, a longer period, or a
transient still far from its orbit). At exactly one plate period the train from rest settles on a
period-2 orbit (bottom panel). The counts of each kind are those of the data file's orbit_period.

Some values lie where the 200 dropped impacts pass close to a basin's edge, or on an irregular
attractor, so that last-bit differences (another machine, a one-ulp change of M2) move where the
train settles or its samples, and with them the value's class. The data file marks them
(near_basin_edge): the values where the trains at T (1 - 1e-12) and T (1 + 1e-12) part by more
than 1e-6 of the state's scales at some impact of the 240 (their linear response to the nudge is
mostly about 1e-10; the values that a one-ulp change of M2 moved beyond make reproduce's tolerance
parted by far more, tests/test_train_study.py). Make reproduce compares these values' samples and
classes only where neither archive marks them.
"""

from pathlib import Path

import numpy as np
from _plots import claim, known

from phaseimpact import seed_parameters
from phaseimpact.archive import save_h5
from phaseimpact.continuation._parallel import map_in_threads
from phaseimpact.integrate import scales
from phaseimpact.maps import ModelImpactMap
from phaseimpact.plotting import figure, save, style
from phaseimpact.train import attracting_orbit, impact_train, orbit_diagram

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "train"
LAW = "hunt-crossley"
KAPPA = 3e9
#: Longest period of a stable orbit looked for from each value's last sample.
MAX_PERIOD = 8
#: Relative change of T to either side of each value for the two trains that mark it near a basin's edge.
NUDGE = 1e-12
#: Parting of the two trains (in the state's scales) at some impact that marks a value near a basin's edge:
#: far above their usual linear response to the nudge (about 1e-10), far below that of the values whose
#: samples or class a one-ulp change of M2 moved (tests/test_train_study.py).
PARTED = 1e-6


def main(quick=False, jobs=1):
    params = seed_parameters(v=1.0, kappa=KAPPA)
    plate_period = scales(params).plate_period
    ratios = np.linspace(0.3, 4.0, 60 if quick else 400)
    transients, samples = (60, 20) if quick else (200, 40)
    diagram = orbit_diagram(params, LAW, "T", ratios * plate_period, transients=transients, samples=samples,
                            n_jobs=max(1, jobs))
    omega = np.sqrt(params.Kb / params.M2)
    amplitude = np.hypot(diagram.plate[:, :, 0], diagram.plate[:, :, 1] / omega)
    steady = amplitude.mean(axis=1)
    # classified by converging to an orbit: Newton from the last sample, its multipliers, and the
    # samples approaching it (a count of distinct samples calls a multiplier near -1 irregular)
    orbits = map_in_threads(lambda i: attracting_orbit(params, LAW, ratios[i] * plate_period, diagram.plate[i],
                                                       max_period=MAX_PERIOD), range(len(ratios)), max(1, jobs))
    orbit_period = np.array([0 if o is None else o.period_k for o in orbits])
    largest = np.array([0.0 if o is None else float(np.max(np.abs(o.multipliers))) for o in orbits])
    fixed = orbit_period == 1
    longer = orbit_period > 1
    irregular = orbit_period == 0
    near_edge = near_basin_edge(params, ratios * plate_period, transients + samples, jobs)
    examples = (0.5, 1.0, 2.3)  # T / plate period: one impact per half swing, per swing, in between
    build = {r: impact_train(params, LAW, r * plate_period, 60) for r in examples}

    with style():
        fig, axes = figure(3, 1, height=8.0)
        ax = axes[0, 0]
        ax.plot(np.repeat(ratios, samples), diagram.plate[:, :, 0].ravel() * 1e6, ".", color="k", ms=1.2, mew=0,
                rasterized=True)
        ax.set_xlabel("period between impacts over the plate period, T / T_plate")
        ax.set_ylabel("plate position x2 before impact (µm)")
        ax.set_title(f"orbit diagram ({LAW}, κ = {KAPPA:g}, v = 1 m/s; {samples} impacts after {transients})")
        ax = axes[1, 0]
        ax.plot(ratios, steady * 1e6, "C0-", lw=0.8, label="mean amplitude over the samples")
        ax.plot(ratios[fixed], steady[fixed] * 1e6, "C2o", ms=2.5, label="period-1 orbit")
        ax.plot(ratios[longer], steady[longer] * 1e6, "C1s", ms=2.5, label=f"period 2 to {MAX_PERIOD}")
        ax.plot(ratios[irregular], steady[irregular] * 1e6, "C3x", ms=2.5, label=f"no stable period ≤ {MAX_PERIOD}")
        for k in range(1, 5):
            ax.axvline(k, color="0.6", lw=0.7, ls=":")
        ax.set_xlabel("T / T_plate")
        ax.set_ylabel("plate amplitude before impact (µm)")
        ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.0), ncols=4)  # above the panel, off the data
        ax = axes[2, 0]
        for i, (r, style_) in enumerate(zip(examples, ("o-", "s--", "^:"), strict=True)):
            ax.plot(build[r].amplitude * 1e6, style_, color=f"C{i}", ms=2.5, lw=0.8, label=f"T = {r:g} T_plate")
        ax.set_xlabel("impact n")
        ax.set_ylabel("plate amplitude before impact n (µm)")
        ax.set_title("build-up from rest")
        ax.legend(loc="lower right")
        out = save(fig, FIGURES / f"{NAME}.png")

    counts = {"period-1": int(fixed.sum()), f"period-k (1 < k <= {MAX_PERIOD})": int(longer.sum()),
              f"no stable orbit of period <= {MAX_PERIOD} approached": int(irregular.sum()),
              "near a basin's edge": int(near_edge.sum())}
    half = fixed & (np.abs(ratios - np.round(ratios - 0.5) - 0.5) < 0.03)  # period-1 within 0.03 of a half multiple
    print(counts, "largest multiplier of period-1 orbits near half multiples:",
          known(largest[half].max(), 3) if half.any() else None)
    save_h5(FIGURES / "data" / f"{NAME}.h5",
            {"T_over_plate_period": (ratios, "1"), "x2": (diagram.plate[:, :, 0], "m"),
             "x2dot": (diagram.plate[:, :, 1], "m/s"), "peak_force": (diagram.peak_force, "N"),
             "distinct": (diagram.distinct, "1"), "orbit_period": (orbit_period, "1"),
             "largest_multiplier": (np.array([known(m) for m in largest]), "1"), "steady_amplitude": (steady, "m"),
             "near_basin_edge": (near_edge, "1")},
            {"law": LAW, "kappa": KAPPA, "v": 1.0, "plate_period": known(plate_period), "transients": transients,
             "samples": samples, "max_period": MAX_PERIOD, "nudge": NUDGE, "parted": PARTED, "claim": claim(__doc__),
             # studies/_settle.py: a value near a basin's edge is compared only where neither archive marks it
             "last_bit_sensitive": " ".join(PER_VALUE), "last_bit_mask": "near_basin_edge", "drawn_in": f"{NAME}.png",
             "last_bit_reason": "where a train settles near a basin's edge moves with last-bit differences "
                                "(a one-ulp change of M2 moved the class of a few values)"})
    return out


#: The archive's datasets of each value that move with it when last bits move where its train settles.
PER_VALUE = ("x2", "x2dot", "peak_force", "distinct", "orbit_period", "largest_multiplier", "steady_amplitude",
             "near_basin_edge")


def near_basin_edge(params, periods, impacts, jobs):
    """Whether the trains at ``T (1 - NUDGE)`` and ``T (1 + NUDGE)`` part by more than ``PARTED`` of the
    state's scales at some impact of ``impacts`` from rest, for each period ``T`` of ``periods``."""
    low, high = (orbit_diagram(params, LAW, "T", periods * (1 + side * NUDGE), transients=0, samples=impacts,
                               n_jobs=max(1, jobs)).plate for side in (-1, 1))
    scale = ModelImpactMap(params, LAW, None).scale
    return np.max(np.abs(high - low) / scale, axis=(1, 2)) > PARTED


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
