"""Elastic-plastic impacts of the erosion cases: restitution against speed under Thornton's law.

Claim (REFERENCE §7; Thornton 1997, J. Appl. Mech. 64:383), the shipped cases with a yield strength
(sand and dust on a gelcoat, sand and hail on a laminate), each grain or hailstone on a rigid wall
under the law `thornton` (Hertz to the yield indentation, then linear at the limiting pressure
p_y = 1.6 Y of the weaker body, Hertzian unloading with the enlarged radius): below the yield
velocity v_y the impact is elastic (e = 1); above it the simulated restitution follows Thornton's
closed form e(v_y / v), the same curve for every case once the speed is scaled by its own v_y, within
1e-6 at the default tolerance (the largest deviation is in the data file), and falls as v^(-1/4) at
high speed. At their own
speeds every erosion case is far above its yield velocity (the factor is in the data file,
attribute "cases"): elastic Hertz contact never applies to them, and their rebound is that of a
strongly plastic impact.
"""

import json
import math
from pathlib import Path

import numpy as np
from _plots import claim, known, loglog_fit

from phaseimpact import simulate_many
from phaseimpact.archive import save_h5
from phaseimpact.case import list_cases, load_case
from phaseimpact.model.contact import plastic_validity
from phaseimpact.plotting import figure, save, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "plastic"
LAW = "thornton"


def thornton_restitution(r):
    """REFERENCE §7 (Thornton 1997): ``e(r)`` for ``r = v_y / v <= 1``; 1 for ``r >= 1``."""
    r = np.minimum(np.asarray(r, dtype=float), 1.0)
    return (math.sqrt(6 * math.sqrt(3) / 5) * np.sqrt(1 - r * r / 6)
            * (r / (r + 2 * np.sqrt(6 / 5 - r * r / 5))) ** 0.25)


def main(quick=False, jobs=1):
    ratios = np.geomspace(0.5, 1000.0, 12 if quick else 40)  # v / v_y
    cases, runs = [], {}
    for entry in list_cases():
        case = load_case(entry["name"])
        base = case.parameters(target="rigid")
        if base.limiting_pressure is None:
            continue
        v_y = base.yield_velocity
        params = [base.replace(v=float(v_y * r)) for r in ratios]
        cols = simulate_many(params, LAW, n_threads=max(1, jobs))
        e = np.asarray(cols.values["restitution"])
        runs[case.name] = {"v": ratios * v_y, "restitution": e, "closed_form": thornton_restitution(1 / ratios)}
        own = simulate_many([case.parameters(target="rigid")], LAW).values["max_force"][0]
        cases.append({"name": case.name, "v": case.impact["v"], "yield_velocity": known(v_y),
                      "limiting_pressure": base.limiting_pressure, "v_over_v_y": known(case.impact["v"] / v_y),
                      "regime": plastic_validity(float(own), case.parameters(target="rigid"))})
    errors = np.concatenate([np.abs(r["restitution"] / r["closed_form"] - 1) for r in runs.values()])
    high = ratios >= 100
    slope = loglog_fit(ratios[high], next(iter(runs.values()))["restitution"][high])[0]

    with style():
        fig, axes = figure(1, 2, height=3.4)
        ax = axes[0, 0]
        fine = np.geomspace(ratios[0], ratios[-1], 400)
        ax.semilogx(fine, thornton_restitution(1 / fine), "k-", lw=1.0, label="Thornton (1997), closed form")
        tail = fine[fine > 50]
        ax.semilogx(tail, 0.9 * thornton_restitution(1 / 50.0) * (tail / 50.0) ** -0.25, "k:", lw=1.0,
                    label="∝ v^(−1/4) (shifted down)")
        for i, r in enumerate(runs.values()):  # every case on one curve: each shows every n-th speed
            ax.semilogx(ratios[i::len(runs)], r["restitution"][i::len(runs)], "osD^"[i % 4], ms=3.5, mfc="none",
                        color=f"C{i}")
        ax.axvline(1.0, color="0.5", lw=0.8, ls="--")
        ax.annotate("v = v_y", (1.0, 0.62), (1.25, 0.6))
        ax.set_xlabel("impact speed over yield velocity, v / v_y")
        ax.set_ylabel("coefficient of restitution e")
        ax.set_title("rigid wall, law thornton")
        ax.legend(loc="lower left")

        ax = axes[0, 1]
        for i, (name, r) in enumerate(runs.items()):
            err = np.abs(r["restitution"] / r["closed_form"] - 1)
            ax.loglog(ratios, np.maximum(err, 1e-17), "osD^"[i % 4], ms=3.5, mfc="none", color=f"C{i}",
                      label=f"{name} (simulated)")
        ax.axhline(1e-6, color="C3", ls="--", lw=0.9)
        ax.set_ylim(top=1e-5)  # room above the target line for its label
        ax.annotate("target 1e-6", (0.02, 1e-6), (0, 3), xycoords=("axes fraction", "data"),
                    textcoords="offset points", va="bottom", color="C3")
        ax.set_xlabel("impact speed over yield velocity, v / v_y")
        ax.set_ylabel("|e / e_Thornton − 1| (rtol 1e-10)")
        ax.set_title("agreement with the closed form")
        fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncols=len(runs))
        out = save(fig, FIGURES / f"{NAME}.png")

    data = {}
    for name, r in runs.items():
        for key, unit in (("v", "m/s"), ("restitution", "1"), ("closed_form", "1")):
            data[f"{name}/{key}"] = (r[key], unit)
    save_h5(FIGURES / "data" / f"{NAME}.h5", data,
            {"law": LAW, "target": "rigid", "largest_relative_error": known(float(np.max(errors))),
             "high_speed_exponent": slope, "cases": json.dumps(cases), "claim": claim(__doc__)})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
