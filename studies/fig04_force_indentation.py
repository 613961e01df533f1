"""Seed Fig. 4: force against relative displacement for Abrate's undamped model.

Claim supported: without damping the loading and unloading branches coincide with the Hertz curve
P = K delta^1.5: no hysteresis, no dissipated energy.
"""

from pathlib import Path

import numpy as np

from phaseimpact import ContactLaw, seed_parameters, simulate
from phaseimpact.archive import save_h5
from phaseimpact.plotting import COLUMN_WIDTH, UM, figure, plot_hysteresis, save, style
from phaseimpact.quantities import impact_quantities

ROOT = Path(__file__).resolve().parents[1] / "figures"
NAME = "fig04_force_indentation"


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    t_end = 0.3e-3
    times = np.linspace(0.0, t_end, 3001 if quick else 12001)
    tr = simulate(p, ContactLaw("abrate"), t_end, save=times)
    q = impact_quantities(tr)
    d = np.linspace(0, tr.delta.max(), 200)
    with style():
        fig, axes = figure(1, 1, width=COLUMN_WIDTH, height=2.8)
        ax = axes[0, 0]
        plot_hysteresis(ax, tr, label="Abrate, undamped, v = 1 m/s", color="C0", lw=2.5, alpha=0.6)
        ax.plot(d * UM, p.K * d**p.alpha, "k--", lw=0.9, label=r"Hertz $K\delta^{1.5}$")
        ax.set_title(f"Undamped contact: loop area {q.loop_area:.2e} J")
        ax.legend()
        out = save(fig, ROOT / f"{NAME}.png")
    save_h5(ROOT / "data" / f"{NAME}.h5", {"t": (times, "s"), "delta": (tr.delta, "m"), "force": (tr.force, "N")},
            {"loop_area_J": q.loop_area, "claim": __doc__.strip()})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
