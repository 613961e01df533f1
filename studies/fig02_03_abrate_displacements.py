"""Seed Figs. 2-3: Abrate's undamped model (unilateral and bilateral contact).

Claim supported: without damping the displacements x1, x2 and x1 - x2 oscillate without decay; with the
unilateral law the projectile separates after one contact, with the bilateral law (seed Fig. 3) the
relative motion keeps oscillating for the whole 10 ms.
"""

from pathlib import Path

import numpy as np

from phaseimpact import ContactLaw, seed_parameters, simulate
from phaseimpact.archive import save_h5
from phaseimpact.plotting import MS, UM, figure, plot_displacements, save, style

ROOT = Path(__file__).resolve().parents[1] / "figures"
NAME = "fig02_03_abrate_displacements"


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    t_end = 0.01
    times = np.linspace(0.0, t_end, 5001 if quick else 20001)
    laws = {"unilateral": ContactLaw("abrate"), "bilateral": ContactLaw("abrate", bilateral=True)}
    runs = {k: simulate(p, law, t_end, save=times) for k, law in laws.items()}
    data = {"t": (times, "s")}
    with style():
        fig, axes = figure(2, 2, height=5.0)
        for row, (name, tr) in enumerate(runs.items()):
            for col, window in enumerate((0.3e-3, t_end)):
                ax = axes[row, col]
                plot_displacements(ax, tr)
                ax.set_xlim(0, window * MS)
                shown = tr.t <= window  # scale the axis to what the window shows
                values = np.concatenate([tr.x1[shown], tr.x2[shown], tr.delta[shown]]) * UM
                pad = 0.05 * np.ptp(values)
                ax.set_ylim(values.min() - pad, values.max() + pad)
                ax.set_title(f"Abrate, {name} contact, {window * MS:g} ms")
            data[f"{name}/x1"] = (tr.x1, "m")
            data[f"{name}/x2"] = (tr.x2, "m")
            data[f"{name}/force"] = (tr.force, "N")
        axes[0, 0].legend(loc="lower left")
        fig.suptitle("v = 1 m/s")
        out = save(fig, ROOT / f"{NAME}.png")
    save_h5(ROOT / "data" / f"{NAME}.h5", data, {"v": 1.0, "law": "abrate", "claim": __doc__.strip()})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
