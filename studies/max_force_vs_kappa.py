"""Maximum impact force and restitution against the damping, for each reading of the model.

Claims checked: seed conclusion 6 (excessive damping raises the maximum impact force; an optimum
damping minimises it) and how well each restitution-based damping law delivers the coefficient of
restitution it is built from. Left: max force against kappa on the seed's plate at 1 m/s for eq. 8
("paper", printed and unilateral readings) and Hunt-Crossley; all three share the approach phase,
so the optimum is the same, 4372 N at kappa ≈ 1.5e10 N s/m^2.5, against 4843 N undamped. Above
kappa_c the escape of "paper" ends in a runaway (printed, masked: its largest force is wherever the
run was stopped) or in a rebound (unilateral, shown up to where the energy doubles first).
Middle: restitution of Hunt-Crossley against kappa on the free target, with the exact Lambert-W
formula (REFERENCE §4). Right: restitution measured on the free target against the e requested,
for the Hunt-Crossley approximation, Lankarani-Nikravesh, Flores, Gonthier and the exact inverse.
"""

from pathlib import Path

import numpy as np
from _plots import READINGS, claim, log_ticks

from phaseimpact import ContactLaw, seed_parameters, simulate
from phaseimpact.archive import save_h5
from phaseimpact.continuation import critical_damping, sweep
from phaseimpact.model import hunt_crossley_restitution
from phaseimpact.plotting import COLUMN_WIDTH, figure, save, style

RUNAWAY = 2  # index of "runaway" in the stop reasons

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "max_force_vs_kappa"
RESTITUTION_LAWS = ("hunt-crossley-approx", "lankarani-nikravesh", "flores", "gonthier", "hunt-crossley")


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    kappas = np.geomspace(1e8, 1e13, 25 if quick else 81)
    data = {"kappa": (kappas, "N s/m^2.5")}
    with style():
        fig, axes = figure(3, 1, width=COLUMN_WIDTH, height=8.4)
        axes = axes.reshape(1, 3)
        ax = axes[0, 0]
        for (name, law), color, ls in zip((("paper, printed", READINGS["printed"]),
                                            ("paper, unilateral", READINGS["unilateral"]),
                                            ("hunt-crossley", "hunt-crossley")), ("C0", "C2", "C1"), ("-", "--", ":"),
                                           strict=True):
            result = sweep(p, law, kappas, n_jobs=jobs)
            # A runaway's largest force is wherever the run was stopped: not an impact force.
            force = np.where(result.stop_reason == RUNAWAY, np.nan, result.max_force)
            best = int(np.nanargmin(force))
            ax.loglog(kappas, force, color=color, ls=ls,
                      label=f"{name}: {force[best]:.4g} N at {kappas[best]:.3g}")
            ax.plot(kappas[best], result.max_force[best], "o", color=color, mfc="none")
            data[f"{name.replace(', ', '_')}/max_force"] = (result.max_force, "N")
            data[f"{name.replace(', ', '_')}/runaway"] = (result.stop_reason == RUNAWAY, "1")
        ax.axvline(critical_damping(p, "paper").kappa_c, color="k", ls=":", lw=0.8, label="κc (paper)")
        ax.set_xlabel("damping κ (N s/m$^{2.5}$)")
        log_ticks(ax.yaxis, [4000, 6000, 10000, 20000, 40000])
        ax.set_ylabel("maximum contact force (N)")
        ax.set_title("plate, v = 1 m/s: optimum damping\n(runs stopped as runaways omitted)")
        ax.legend(loc="upper left", title="minimum force at κ")

        ax = axes[0, 1]
        free = p.replace(target="free")
        result = sweep(free, "hunt-crossley", kappas, n_jobs=jobs)
        a = kappas * free.v / free.K
        ax.semilogx(kappas, result.restitution, "o", ms=3, color="C1", label="measured (sweep)")
        ax.semilogx(kappas, hunt_crossley_restitution(a), "k-", lw=0.8, label="Lambert-W formula")
        ax.set_xlabel("damping κ (N s/m$^{2.5}$)")
        ax.set_ylabel("coefficient of restitution e")
        ax.set_title("Hunt-Crossley, free target")
        ax.legend(loc="lower left")
        data["hunt-crossley/free/restitution"] = (result.restitution, "1")

        ax = axes[0, 2]
        requested = np.linspace(0.1, 0.95, 8 if quick else 18)
        for name, color in zip(RESTITUTION_LAWS, ("C2", "C3", "C4", "C5", "k"), strict=True):
            measured = [simulate(free, ContactLaw(name, restitution=float(e))).restitution for e in requested]
            label = "exact inverse (hunt-crossley)" if name == "hunt-crossley" else name
            line = "os^vD"[RESTITUTION_LAWS.index(name)] + "-" if name != "hunt-crossley" else "-"
            ax.plot(requested, measured, line, ms=3, color=color, label=label)
            data[f"restitution_laws/{name}"] = (np.array(measured, dtype=float), "1")
        ax.plot([0, 1], [0, 1], ":", color="grey", lw=0.8)
        ax.set_xlabel("requested restitution e")
        ax.set_ylabel("measured restitution")
        ax.set_title("restitution laws, free target, v = 1 m/s")
        ax.legend(loc="lower right")
        data["restitution_laws/requested"] = (requested, "1")
        out = save(fig, FIGURES / f"{NAME}.png")
    save_h5(FIGURES / "data" / f"{NAME}.h5", data, {"v": 1.0, "claim": claim(__doc__)})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
