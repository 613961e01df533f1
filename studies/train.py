"""Trains of impacts on the seed plate: the impact map's attractor and the plate's build-up against the
period between impacts.

Claim (docs/physics.md §7), the seed case with Hunt-Crossley contact (kappa = 3e9, 1 m/s), one
projectile every T seconds on the plate as the previous impacts left it, T from 0.3 to 4 plate
periods (the plate's small-amplitude period), 200 impacts dropped and 40 kept at each of 400 values:
the attractor's pattern repeats with the plate period. Stable period-1 orbits (one point after the
transients) fill most of each period, from about 0.15 to 0.72 of a period past each multiple
(interrupted near the half multiple), the plate's steady amplitude largest (about 0.18 mm) near
their start. Just below each multiple lies a narrow window of period-1 orbits of small amplitude
(about 15 µm), reached as T rises through period 2 and period 4: a period-doubling sequence, which
this grid resolves only to period 4. From about 0.75 of a period to about 0.13 past each multiple
the map shows no period within the 40 samples (irregular, or a long period). At exactly one plate
period the train from rest settles on a period-2 orbit (bottom panel). The counts of each kind are
in the data file (attribute "counts").
"""

from pathlib import Path

import numpy as np
from _plots import claim, known

from phaseimpact import seed_parameters
from phaseimpact.integrate import scales
from phaseimpact.plotting import figure, save, save_h5, style
from phaseimpact.train import impact_train, orbit_diagram

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "train"
LAW = "hunt-crossley"
KAPPA = 3e9


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
    fixed = diagram.distinct == 1
    irregular = diagram.distinct == samples
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
        ax.plot(ratios[irregular], steady[irregular] * 1e6, "C3x", ms=2.5, label=f"no period within {samples}")
        for k in range(1, 5):
            ax.axvline(k, color="0.6", lw=0.7, ls=":")
        ax.set_xlabel("T / T_plate")
        ax.set_ylabel("plate amplitude before impact (µm)")
        ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.0), ncols=3)  # above the panel, off the data
        ax = axes[2, 0]
        for i, (r, style_) in enumerate(zip(examples, ("o-", "s--", "^:"), strict=True)):
            ax.plot(build[r].amplitude * 1e6, style_, color=f"C{i}", ms=2.5, lw=0.8, label=f"T = {r:g} T_plate")
        ax.set_xlabel("impact n")
        ax.set_ylabel("plate amplitude before impact n (µm)")
        ax.set_title("build-up from rest")
        ax.legend(loc="lower right")
        out = save(fig, FIGURES / f"{NAME}.png")

    counts = {"period-1": int(fixed.sum()), "irregular": int(irregular.sum()),
              "period-k (1 < k < samples)": int((~fixed & ~irregular).sum())}
    save_h5(FIGURES / "data" / f"{NAME}.h5",
            {"T_over_plate_period": (ratios, "1"), "x2": (diagram.plate[:, :, 0], "m"),
             "x2dot": (diagram.plate[:, :, 1], "m/s"), "peak_force": (diagram.peak_force, "N"),
             "distinct": (diagram.distinct, "1"), "steady_amplitude": (steady, "m")},
            {"law": LAW, "kappa": KAPPA, "v": 1.0, "plate_period": known(plate_period), "transients": transients,
             "samples": samples, "counts": str(counts), "claim": claim(__doc__)})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
