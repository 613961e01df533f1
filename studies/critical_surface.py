"""The critical damping over (v, R1) and (v, h): two-parameter continuation of kappa_c.

Claim (REFERENCE §5), "paper" (either reading; kappa_c does not depend on it), the seed's steel
ball and plate: the adding-sliding exists over the whole range of speeds, ball sizes and plate
thicknesses tried, and kappa_c is set by the ball size far more than by anything else. Continued
over v at fixed R1 (5-40 mm) and h (2.5-20 mm), and over R1 at fixed v (0.3, 1, 13 m/s), kappa_c
falls close to v^(-2/3) at every size and thickness (log-log slopes -0.59 to -0.80) and rises
steeply as the ball shrinks: at 1 m/s from 4.2e10 at R1 = 50 mm to 7.6e16 N s/m^2.5 at 3 mm
(slope -5.8 below 20 mm) and reaches 9.295e17 at R1 = 2 mm, just inside the largest kappa of the
inputs (1e18). Smaller or faster projectiles have their root beyond that limit: the search then
reports how far it looked ("no root ... up to kappa = 1e+18") and the closed form names the root
(3.096e18 at R1 = 1 mm and 100 m/s, 4.1e22 for the sand-gelcoat grain): it is not a stick that
never breaks. REFERENCE §5's closed form is exact in the limit of a slow plate: its error grows with
the contact time over the plate period, from below 1e-4 for balls of 10 mm or less to 0.3 % for
the seed's geometry and 7 % for a 20 mm plate or a 50 mm ball at 0.3 m/s.
"""

from pathlib import Path

import numpy as np
from _plots import KAPPA_LABEL, V_LABEL, claim, known, loglog_fit, save_archive
from matplotlib.ticker import NullFormatter

from phaseimpact import scales
from phaseimpact.archive import save_h5
from phaseimpact.case import load_case
from phaseimpact.continuation import critical_curve, critical_damping
from phaseimpact.plotting import figure, save, style
from phaseimpact.settings import apply_settings

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "critical_surface"
RADII = (0.005, 0.01, 0.02, 0.04)          # m
THICKNESSES = (0.0025, 0.005, 0.01, 0.02)  # m
SPEEDS_AT = (0.3, 1.0, 13.0)               # m/s

#: One marker per curve of a panel, so the curves read apart in grayscale too.
MARKERS = "os^v"

def main(quick=False, jobs=1):
    seed = load_case("seed")
    speeds = np.geomspace(0.3, 13.0, 6 if quick else 24)
    radii = np.geomspace(0.05, 0.003, 8 if quick else 30)
    curves = {}
    for r1 in RADII:
        curves[f"R1={r1:g}"] = critical_curve(seed.parameters(R1=r1), "paper", "v", speeds)
    for h in THICKNESSES:
        curves[f"h={h:g}"] = critical_curve(seed.parameters(h=h), "paper", "v", speeds)
    for v in SPEEDS_AT:
        curves[f"v={v:g}"] = critical_curve(apply_settings(seed, {"v": v}), "paper", "R1", radii)
    ratio = {}  # contact time over plate period at each point of each curve
    for key, c in curves.items():
        save_archive(c, FIGURES / "data" / f"{NAME}_{key.replace('=', '_')}.h5")
        name, value = key.split("=")
        case = apply_settings(seed, {"v": float(value)}) if name == "v" else seed
        fixed = {} if name == "v" else {name: float(value)}
        moving = "R1" if name == "v" else "v"
        own = [scales(case.parameters(**fixed, **{moving: x})) for x in c.values]
        ratio[key] = np.array([s.contact_time / s.plate_period for s in own])
    at_1 = curves["v=1"]
    slope_r1, _ = loglog_fit(at_1.values[at_1.values <= 0.02], at_1.kappa[at_1.values <= 0.02])
    # the smallest ball of the study, and two cases whose root lies beyond the inputs' kappa <= 1e18
    small = critical_damping(seed.parameters(R1=0.002), "paper")
    beyond = {"R1_1mm_v100": critical_damping(seed.parameters(R1=0.001, v=100.0), "paper"),
              "sand_gelcoat": critical_damping(load_case("sand-gelcoat").parameters(), "paper")}
    with style():
        fig, grid = figure(2, 2, height=6.0)
        axes = grid.reshape(1, 4)
        for ax, prefix, values, unit, title in ((axes[0, 0], "R1", RADII, "mm", "κc(v) for ball radii R1"),
                                                 (axes[0, 1], "h", THICKNESSES, "mm", "κc(v) for plate thicknesses h")):
            for i, x in enumerate(values):
                c = curves[f"{prefix}={x:g}"]
                slope, _ = loglog_fit(c.values, c.kappa)
                ax.loglog(c.values, c.kappa, MARKERS[i] + "-", ms=2.5, color=f"C{i}",
                          label=f"{prefix} = {x * 1e3:g} {unit} (slope {slope:.2f})")
                ax.loglog(c.values, c.closed_form, "k--", lw=0.7)
            ax.plot([], [], "k--", lw=0.7, label="closed form")
            ax.set_xlabel(V_LABEL)
            ax.set_ylabel(KAPPA_LABEL)
            ax.set_title(title)
            if prefix == "R1":
                ax.set_ylim(top=1e19)  # room for the legend above the curves
            ax.legend(loc="upper right")
        ax = axes[0, 2]
        for i, v in enumerate(SPEEDS_AT):
            c = curves[f"v={v:g}"]
            ax.loglog(c.values * 1e3, c.kappa, MARKERS[i] + "-", ms=2.5, color=f"C{i}", label=f"v = {v:g} m/s")
            ax.loglog(c.values * 1e3, c.closed_form, "k--", lw=0.7)
        ax.plot([], [], "k--", lw=0.7, label="closed form")
        ax.set_xticks([3, 5, 10, 20, 50])
        ax.set_xticklabels(["3", "5", "10", "20", "50"])
        ax.minorticks_off()
        ax.set_xlabel("ball radius R1 (mm)")
        ax.set_ylabel(KAPPA_LABEL)
        ax.set_title(f"κc(R1): slope {slope_r1:.2f} at 1 m/s\n(R1 ≤ 20 mm)")
        ax.legend(loc="upper right")
        ax = axes[0, 3]
        families = {"R1": ("-", RADII, "κc(v) at each R1"), "h": ("--", THICKNESSES, "κc(v) at each h"),
                    "v": (":", SPEEDS_AT, "κc(R1) at each v")}
        for prefix, (line, values, label) in families.items():
            for i, x in enumerate(values):  # the colours of the other panels
                c = curves[f"{prefix}={x:g}"]
                ax.loglog(ratio[f"{prefix}={x:g}"], np.abs(c.closed_form / c.kappa - 1), line, color=f"C{i}", lw=1.1)
            ax.plot([], [], line, color="k", lw=1.1, label=label)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("Hertz contact time / plate period")
        ax.set_ylabel("|closed form / κc − 1|")
        ax.set_title("closed form: exact for a slow plate\n(colours as in the other panels)")
        ax.legend(loc="lower right")
        out = save(fig, FIGURES / f"{NAME}.png")
    summary = {"claim": claim(__doc__), "R1_2mm_v1_status": small.status, "R1_2mm_v1_message": small.message,
               "R1_2mm_v1_kappa_c": known(small.kappa_c), "kappa_c_R1_slope_v1": slope_r1}
    for key, found in beyond.items():
        summary[f"{key}_status"] = found.status
        summary[f"{key}_message"] = found.message
        summary[f"{key}_closed_form"] = known(found.closed_form)
    for key, c in curves.items():
        summary[f"{key}/closed_form_error_max"] = float(np.max(np.abs(c.closed_form / c.kappa - 1)))
        summary[f"{key}/kappa_c_range"] = f"{c.kappa.min():.4g}..{c.kappa.max():.4g}"
        summary[f"{key}/message"] = c.message
    save_h5(FIGURES / "data" / f"{NAME}.h5",
            {f"{key.replace('=', '_')}/ratio": (ratio[key], "1") for key in curves}, summary)
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
