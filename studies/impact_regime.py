"""Which plate model a blade impact calls for: Olsson's regime over projectile radius and speed.

Claim (docs/physics.md §8; Olsson 2000, Composites A 31:879), the blade panels of the shipped cases
(the IEA 15 MW gelcoat of "sand-gelcoat", the polyurethane LEP coating of "sand-lep", the glass/epoxy
laminate of "sand-laminate"; each 50 mm in radius and 5 mm thick), quartz grains (dust, sand) and ice
(hail) from 3 µm to 40 mm in radius at 10-120 m/s: the impactor/plate mass ratio M1/M_p, and with it
the regime, does not depend on the speed. Every dust and sand grain, every shipped blade case and
hail up to 14-17 mm in radius (attribute "boundaries") is wave-controlled (M1/M_p < 0.23): the
infinite plate is the model there, not the spring-mass plate of eq. 1. The seed's dust (13 m/s; the
seed gives no size) lies 7.5 to 10.1 orders of magnitude below that bound, and its Zener parameter
lambda (which grows like R1^2 v^0.2) is at most 4.1e-5, near the rigid-wall limit lambda -> 0; the
15 mm hailstone of "hail-laminate" has lambda = 0.44. Larger hail is boundary-controlled; the
quasi-static regime starts beyond the hail sizes. Rain drops are marked, not mapped: a water drop is
a liquid, not the elastic (Hertz) solid the contact models assume. Zener's restitution against
lambda is drawn by studies/zener_restitution.py; his equation gives e = 0.99993 at the dust's
largest lambda and e = 0.480 for the hailstone of "hail-laminate" (each case's e is in the
attribute "cases"; an elastic Hertz ball, which the hail case is not: it crushes, see erosion).

Size classes (diameters; the radius axis shows half): dust 10-62.5 µm (silt-sized, below sand on
Wentworth's scale; the lower end is typical, not a definition), sand 62.5 µm-2 mm (Wentworth 1922,
J. Geol. 30:377), rain drops 0.5-4 mm (over 0.5 mm: AMS Glossary of Meteorology, "Rain"; seldom
over 4 mm: Encyclopaedia Britannica, "rain"), hail 5-50 mm (WMO International Cloud Atlas, "Hail":
generally 5-50 mm in diameter). The projectile is quartz below hail sizes and ice from them.
"""

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
from _plots import V_LABEL, claim, known, log_ticks
from zener_restitution import zener_restitution

from phaseimpact.archive import save_h5
from phaseimpact.case import load_case
from phaseimpact.model.laminate import as_laminate
from phaseimpact.model.plate_stiffness import olsson_rigidity
from phaseimpact.model.regime import (
    LARGE_MASS_RATIO,
    REGIMES,
    SMALL_MASS_RATIO,
    impact_regime,
    infinite_plate_impedance,
    mass_ratio,
    model_for_regime,
    plate_mass,
    regime_report,
    zener_lambda,
)
from phaseimpact.plotting import figure, save, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "impact_regime"
#: The blade panels: (label, the shipped case whose plate and geometry the panel is).
PANELS = (("gelcoat", "sand-gelcoat"), ("LEP coating", "sand-lep"), ("laminate", "sand-laminate"))
#: The projectile materials: quartz (the sand cases' grain) below hail sizes, ice (the hail case's) from them.
QUARTZ, ICE = "sand-gelcoat", "hail-laminate"
#: Diameters, m: (low, high); see the docstring for the sources. Rain is marked, not mapped.
SIZE_CLASSES = {"dust": (10e-6, 62.5e-6), "sand": (62.5e-6, 2e-3), "rain": (0.5e-3, 4e-3), "hail": (5e-3, 50e-3)}
#: Radius from which the projectile is ice (hail's smallest diameter, 5 mm).
ICE_FROM = SIZE_CLASSES["hail"][0] / 2
RADII = (3e-6, 40e-3)  # m
SPEEDS = (10.0, 120.0)  # m/s
SEED_DUST_SPEED = 13.0  # m/s: the seed's wind speed of the dust (its [14]); the seed gives no size
TIP_SPEED = 95.9  # m/s: IEA-15-240-RWT's tip speed, from the blade cases' source
#: The shipped blade cases and the panel each hits.
BLADE_CASES = {"dust-gelcoat": "gelcoat", "sand-gelcoat": "gelcoat", "sand-lep": "LEP coating",
               "sand-laminate": "laminate", "hail-laminate": "laminate"}
#: Regime fills that print in grey: (face grey, hatch).
FILLS = {"wave-controlled": ("0.96", ""), "boundary-controlled": ("0.78", "///"), "quasi-static": ("0.55", "xxx")}
LAMBDA_LEVELS = (1e-4, 1e-2, 1.0)
LABEL_SPEED = 28.0  # m/s, where the lambda lines are labelled


def marker_of(case_name: str) -> str:
    return "D" if "dust" in case_name else "^" if "hail" in case_name else "o"


def mm_ticks(axis) -> None:
    from matplotlib.ticker import FuncFormatter

    log_ticks(axis, [0.01, 0.1, 1, 10])
    axis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))


def radius_at_ratio(ratio: float, M_p: float, rho1: float) -> float:
    """The projectile radius whose mass is ``ratio M_p`` (closed form: ``M1 = rho1 4/3 pi R1^3``)."""
    return (ratio * M_p / (rho1 * 4 / 3 * math.pi)) ** (1 / 3)


def panel_data(panel_case, projectiles, radii, speeds):
    """Mass ratio, regime, model and Zener's lambda over the radii (and speeds) for one panel."""
    laminate = as_laminate(panel_case.plate, panel_case.geometry.h)
    impedance = infinite_plate_impedance(olsson_rigidity(laminate.reduced_bending_stiffness()),
                                         laminate.areal_density)
    M_p = plate_mass(laminate.areal_density, panel_case.geometry.a)
    M1, K = np.empty(len(radii)), np.empty(len(radii))
    for i, r in enumerate(radii):
        material = projectiles["ice"] if r >= ICE_FROM else projectiles["quartz"]
        p = dataclasses.replace(panel_case, projectile=material).parameters(R1=float(r))
        M1[i], K[i] = p.M1, p.K
    ratio = np.array([mass_ratio(m, M_p) for m in M1])
    regime = [impact_regime(x) for x in ratio]
    lam = np.array([[zener_lambda(m, float(v), k, impedance) for m, k in zip(M1, K, strict=True)] for v in speeds])
    bounds = {}
    for name, material in projectiles.items():
        bounds[name] = [known(radius_at_ratio(x, M_p, material.rho)) for x in (SMALL_MASS_RATIO, LARGE_MASS_RATIO)]
    return {"M1": M1, "K": K, "mass_ratio": ratio, "regime": regime,
            "model": [model_for_regime(g) for g in regime], "zener_lambda": lam,
            "plate_mass": M_p, "impedance": impedance, "bounds": bounds}


def spans(bounds, lo, hi):
    """The radius intervals of each regime: quartz below :data:`ICE_FROM`, ice from it."""
    out = []
    for name, (a, b) in (("quartz", (lo, ICE_FROM)), ("ice", (ICE_FROM, hi))):
        small, large = bounds[name]
        for regime, (x0, x1) in zip(REGIMES, ((a, small), (small, large), (large, b)), strict=True):
            x0, x1 = max(x0, a), min(x1, b)
            if x1 > x0:
                out.append((regime, x0, x1))
    return out


def main(quick=False, jobs=1):
    projectiles = {"quartz": load_case(QUARTZ).projectile, "ice": load_case(ICE).projectile}
    radii = np.geomspace(*RADII, 60 if quick else 241)
    speeds = np.geomspace(*SPEEDS, 6 if quick else 23)
    panels = {label: panel_data(load_case(name), projectiles, radii, speeds) for label, name in PANELS}
    dust = np.array(SIZE_CLASSES["dust"]) / 2

    cases = []
    for name in BLADE_CASES:
        c = load_case(name)
        r = regime_report(c.parameters(), c.plate, c.geometry)  # what `params` reports for the case
        cases.append({"name": name, "panel": BLADE_CASES[name], "R1": c.geometry.R1, "v": c.impact["v"],
                      "mass_ratio": known(r["mass_ratio"]),
                      "regime": r["regime"], "model": r["regime_model"], "zener_lambda": known(r["zener_lambda"]),
                      "zener_restitution": known(zener_restitution(r["zener_lambda"])[0], 6),
                      "below_bound": known(SMALL_MASS_RATIO / r["mass_ratio"]),
                      "warns": r["regime_warning"] is not None})
    seed_dust = {}
    for label, name in PANELS:
        c = load_case(name)
        d = panel_data(c, projectiles, dust, [SEED_DUST_SPEED, TIP_SPEED])
        seed_dust[label] = {"mass_ratio": [known(x) for x in d["mass_ratio"]], "regime": sorted(set(d["regime"])),
                            "zener_lambda_13": [known(x) for x in d["zener_lambda"][0]],
                            "zener_lambda_tip": [known(x) for x in d["zener_lambda"][1]],
                            "below_bound_decades": [known(math.log10(SMALL_MASS_RATIO / x), 3)
                                                    for x in d["mass_ratio"]]}
    seed_dust_ratio = [min(s["mass_ratio"][0] for s in seed_dust.values()),
                       max(s["mass_ratio"][1] for s in seed_dust.values())]
    seed_dust_lambda = max(max(s["zener_lambda_13"]) for s in seed_dust.values())
    hail_bound = [min(p["bounds"]["ice"][0] for p in panels.values()),
                  max(p["bounds"]["ice"][0] for p in panels.values())]

    with style():
        fig, axes = figure(2, 2, height=6.6)
        maps = [axes[0, 0], axes[0, 1], axes[1, 0]]
        for ax, (label, name) in zip(maps, PANELS, strict=True):
            d = panels[label]
            for regime, x0, x1 in spans(d["bounds"], *RADII):
                face, hatch = FILLS[regime]
                ax.axvspan(x0 * 1e3, x1 * 1e3, facecolor=face, hatch=hatch, edgecolor="0.35", lw=0, zorder=0)
            ax.axvline(d["bounds"]["ice"][0] * 1e3, color="k", lw=1.6, zorder=2)
            ax.axvline(ICE_FROM * 1e3, color="0.3", lw=0.8, ls="-", zorder=2)
            ax.text(ICE_FROM * 1e3 * 0.9, 117.0, "quartz", ha="right", va="top", zorder=5)
            ax.text(ICE_FROM * 1e3 * 1.1, 117.0, "ice", ha="left", va="top", zorder=5)
            for level in LAMBDA_LEVELS:  # lambda = level: v = (level c / (M1^0.6 K^0.4))^5, per material
                v_line = (level * d["impedance"] / (d["M1"] ** 0.6 * d["K"] ** 0.4)) ** 5
                for part in (radii < ICE_FROM, radii >= ICE_FROM):
                    ax.plot(radii[part] * 1e3, v_line[part], color="0.25", ls=":", lw=1.0, zorder=3)
                    crossing = np.flatnonzero(part[1:] & part[:-1] & (v_line[:-1] >= LABEL_SPEED)
                                              & (v_line[1:] < LABEL_SPEED))
                    if crossing.size:  # label the line where it crosses LABEL_SPEED
                        i = crossing[0]
                        exponent = round(math.log10(level))
                        ax.text(radii[i] * 1e3 / 1.1, LABEL_SPEED, "λ = 1" if exponent == 0 else
                                f"λ = 10$^{{{exponent}}}$", rotation=90, ha="right", va="center", zorder=5)
            ax.axhline(TIP_SPEED, color="k", ls="--", lw=0.8, zorder=3)
            ax.hlines(SEED_DUST_SPEED, dust[0] * 1e3, dust[1] * 1e3, color="k", lw=3.0, zorder=4)
            for c in cases:
                if c["panel"] == label:
                    left = "hail" in c["name"]  # keep clear of the model switch
                    ax.plot(c["R1"] * 1e3, c["v"], marker_of(c["name"]), ms=6, mfc="white", mec="k", mew=1.2,
                            zorder=6)
                    ax.annotate(c["name"], (c["R1"] * 1e3, c["v"]), (-5, -22) if left else (5, -11),
                                textcoords="offset points", ha="right" if left else "left", zorder=6)
            # the size classes, as bars at the bottom (rain only marked: not a Hertz solid)
            for row, classes in ((0, ("dust", "sand", "hail")), (1, ("rain",))):
                y0, y1 = 0.01 + 0.1 * row, 0.09 + 0.1 * row
                for cls in classes:
                    a, b = (x / 2 * 1e3 for x in SIZE_CLASSES[cls])
                    ax.fill_between([a, b], y0, y1, transform=ax.get_xaxis_transform(), facecolor="white",
                                    edgecolor="k", hatch="...." if cls == "rain" else "", lw=0.8, zorder=4)
                    ax.text(math.sqrt(a * b), (y0 + y1) / 2, "rain: not mapped" if cls == "rain" else cls,
                            transform=ax.get_xaxis_transform(), ha="center", va="center", zorder=5,
                            bbox={"facecolor": "white", "edgecolor": "none", "pad": 0.5})
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlim(RADII[0] * 1e3, RADII[1] * 1e3)
            ax.set_ylim(*SPEEDS)
            mm_ticks(ax.xaxis)
            log_ticks(ax.yaxis, [10, 20, 50, 100])
            ax.set_xlabel("projectile radius R1 (mm)")
            ax.set_ylabel(V_LABEL)
            ax.grid(False)
            ax.set_title(f"{label} panel (case {name}), M_p = {d['plate_mass'] * 1e3:.0f} g")

        ax = axes[1, 1]
        styles = {"gelcoat": "-", "LEP coating": "--", "laminate": ":"}
        for regime, y0, y1 in zip(REGIMES, (1e-16, SMALL_MASS_RATIO, LARGE_MASS_RATIO),
                                  (SMALL_MASS_RATIO, LARGE_MASS_RATIO, 1e3), strict=True):
            face, hatch = FILLS[regime]
            ax.axhspan(y0, y1, facecolor=face, hatch=hatch, edgecolor="0.35", lw=0, zorder=0)
        for label, d in panels.items():
            ax.loglog(radii * 1e3, d["mass_ratio"], "k", ls=styles[label], lw=1.2, label=f"{label} panel")
        ax.axvline(ICE_FROM * 1e3, color="0.3", lw=0.8)
        ax.text(ICE_FROM * 1e3 * 0.9, 1e-7, "quartz", ha="right", va="bottom")
        ax.text(ICE_FROM * 1e3 * 1.1, 1e-7, "ice", ha="left", va="bottom")
        for c in cases:
            ax.plot(c["R1"] * 1e3, c["mass_ratio"], marker_of(c["name"]), ms=6, mfc="white", mec="k", mew=1.2, zorder=6)
        ax.fill_between(dust * 1e3, seed_dust_ratio[0], seed_dust_ratio[1], facecolor="k", alpha=0.6, lw=0,
                        label="seed's dust (any speed)")
        ax.annotate(f"{SMALL_MASS_RATIO:g}", (RADII[0] * 1e3 * 1.3, SMALL_MASS_RATIO), (0, -2),
                    textcoords="offset points", va="top")
        ax.annotate(f"{LARGE_MASS_RATIO:g}", (RADII[0] * 1e3 * 1.3, LARGE_MASS_RATIO), (0, 2),
                    textcoords="offset points", va="bottom")
        ax.set_xlim(RADII[0] * 1e3, RADII[1] * 1e3)
        ax.set_ylim(1e-15, 1e2)
        mm_ticks(ax.xaxis)
        ax.set_xlabel("projectile radius R1 (mm)")
        ax.set_ylabel("mass ratio M1 / M_p")
        ax.grid(False)
        ax.set_title("Olsson's mass criterion (no speed dependence)")
        ax.legend(loc="lower right", frameon=True, facecolor="white", framealpha=0.9)

        from matplotlib.lines import Line2D
        from matplotlib.patches import Patch

        handles = [Patch(facecolor=FILLS[g][0], hatch=FILLS[g][1], edgecolor="0.35", label=text) for g, text in (
            ("wave-controlled", "wave-controlled (M1/M_p < 0.23): infinite plate"),
            ("boundary-controlled", "boundary-controlled (0.23-2): spring–mass plate"),
            ("quasi-static", "quasi-static (> 2): spring–mass plate"))]
        handles += [Line2D([], [], color="k", lw=1.6, label="model switch (hail, M1/M_p = 0.23)"),
                    Line2D([], [], color="0.25", ls=":", label="Zener's λ (∝ R1² v^0.2)"),
                    Line2D([], [], color="k", ls="--", lw=0.8, label=f"IEA-15 tip speed {TIP_SPEED:g} m/s"),
                    Line2D([], [], color="k", lw=3.0, label="seed's dust, 13 m/s (size: typical dust)"),
                    *(Line2D([], [], ls="", marker=marker_of(n), mfc="white", mec="k", mew=1.2, label=text)
                      for n, text in (("sand", "shipped sand cases"), ("dust", "dust-gelcoat"),
                                      ("hail", "hail-laminate")))]
        fig.legend(handles=handles, loc="outside lower center", ncols=2)
        out = save(fig, FIGURES / f"{NAME}.png")

    data = {"R1": (radii, "m"), "v": (speeds, "m/s")}
    for label, d in panels.items():
        key = label.split()[0]
        data[f"{key}/M1"] = (d["M1"], "kg")
        data[f"{key}/K"] = (d["K"], "N/m^1.5")
        data[f"{key}/mass_ratio"] = (d["mass_ratio"], "1")
        data[f"{key}/regime"] = (d["regime"], "1")
        data[f"{key}/model"] = (d["model"], "1")
        data[f"{key}/zener_lambda"] = (d["zener_lambda"], "1")
    save_h5(FIGURES / "data" / f"{NAME}.h5", data,
            {"panels": json.dumps({label: {"case": name, "plate_mass": known(panels[label]["plate_mass"]),
                                           "impedance": known(panels[label]["impedance"])} for label, name in PANELS}),
             "projectiles": json.dumps({"quartz": QUARTZ, "ice": ICE, "ice_from_radius": ICE_FROM}),
             "boundaries": json.dumps({label: d["bounds"] for label, d in panels.items()}),
             "size_classes_diameter": json.dumps(SIZE_CLASSES), "cases": json.dumps(cases),
             "seed_dust": json.dumps(seed_dust), "seed_dust_speed": SEED_DUST_SPEED,
             "seed_dust_mass_ratio_min": seed_dust_ratio[0], "seed_dust_mass_ratio_max": seed_dust_ratio[1],
             "seed_dust_zener_lambda_max": seed_dust_lambda,
             "seed_dust_zener_restitution": known(zener_restitution(seed_dust_lambda)[0], 6),
             "hail_wave_bound_min": hail_bound[0], "hail_wave_bound_max": hail_bound[1],
             "small_mass_ratio": SMALL_MASS_RATIO, "large_mass_ratio": LARGE_MASS_RATIO,
             "claim": claim(__doc__)})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
