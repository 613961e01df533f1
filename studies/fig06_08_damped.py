"""Seed Figs. 6-8: the damped model read as eq. 8 ("paper") and as Hunt-Crossley, kappa = 0, 1e9, 3e9.

Claim checked: damping produces a force-indentation hysteresis loop. With the Hunt-Crossley reading the
loop closes at the origin and the projectile rebounds; with eq. 8 the relative motion sticks at the
first maximum compression, so the path does not return to the origin (the force drops from ~4800 N to
the ~45 N that holds the stuck pair together, then follows the plate). The printed and unilateral
readings of eq. 8 coincide here: below kappa_c nothing happens in tension. Even kappa = 0 sticks: the
sign factor of eq. 8 turns the elastic term into friction.
"""

from pathlib import Path

import numpy as np

from phaseimpact import seed_parameters, simulate
from phaseimpact.archive import save_h5
from phaseimpact.plotting import MS, UM, figure, plot_force, plot_hysteresis, save, style

ROOT = Path(__file__).resolve().parents[1] / "figures"
NAME = "fig06_08_damped"
KAPPAS = (0.0, 1e9, 3e9)
LAWS = ("paper", "hunt-crossley")


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    t_end = 0.3e-3
    times = np.linspace(0.0, t_end, 1501 if quick else 6001)
    data = {"t": (times, "s"), "kappa": (np.array(KAPPAS), "N s/m^2.5")}
    with style():
        fig, axes = figure(3, 2, height=7.6)
        for col, law in enumerate(LAWS):
            name = "paper" if law == "paper" else law
            for i, kappa in enumerate(KAPPAS):
                tr = simulate(p.replace(kappa=kappa), law, t_end, save=times)
                ls = ("-", "--", ":")[i]
                lab = f"κ = {kappa:.0e}" if kappa else "κ = 0"
                ax = axes[0, col]
                ax.plot(tr.t * MS, tr.x1 * UM, "C0", ls=ls)
                ax.plot(tr.t * MS, tr.x2 * UM, "C1", ls=ls)
                ax.plot(tr.t * MS, tr.delta * UM, "C2", ls=ls, label=lab)
                plot_force(axes[1, col], tr, label=lab, color=f"C{i}", ls=ls)
                plot_hysteresis(axes[2, col], tr, label=lab, color=f"C{i}", ls=ls)
                for key, val, unit in (("x1", tr.x1, "m"), ("x2", tr.x2, "m"), ("force", tr.force, "N")):
                    data[f"{law}/kappa_{kappa:.0e}/{key}"] = (val, unit)
            ax = axes[0, col]
            ax.set_xlabel("time t (ms)")
            ax.set_ylabel("displacement (µm)")
            ax.set_title(f"{name}: displacements")
            # each quantity named at its line's end: the colours need not be told apart (grayscale)
            for key, values in (("$x_1$", tr.x1), ("$x_2$", tr.x2), (r"$x_1 - x_2$", tr.delta)):
                ax.annotate(key, (tr.t[-1] * MS, values[-1] * UM), xytext=(3, 0), textcoords="offset points",
                            va="center", ha="left")
            ax.set_xlim(0, 0.38)
            axes[1, col].set_title(f"{name}: contact force")
            axes[2, col].set_title(f"{name}: hysteresis loop")
            if law == "hunt-crossley":  # the flight after the separation (P = 0) is not part of the loop
                axes[2, col].set_xlim(-3, 40)
            for r in range(3):
                axes[r, col].legend(loc="best")
        fig.suptitle("v = 1 m/s; the printed and unilateral readings of paper coincide here")
        out = save(fig, ROOT / f"{NAME}.png")
    save_h5(ROOT / "data" / f"{NAME}.h5", data, {"v": 1.0, "claim": " ".join(__doc__.split())})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
