"""Seed Figs. 9-10: phase diagrams of the relative motion (delta, deltadot) across the critical damping.

Claim (seed conclusion 7, REFERENCE §5): for lower damping there is one asymptotic point, for higher
damping two, split at a critical damping. Resolved exactly (stick and slip as events), eq. 8 as printed
sticks at its first maximum compression below kappa_c; above kappa_c the first stick breaks at the
plate's turning point and the relative motion sticks again, deeper: two (or more) stick points, which
separate continuously from kappa_c (Fig. 10: just below and just above kappa_c). The seed's RK4
chatters across deltadot = 0 instead of sticking (right panel).
"""

from pathlib import Path

import numpy as np

from phaseimpact import seed_parameters, simulate
from phaseimpact.continuation import critical_damping, sweep
from phaseimpact.plotting import MS, UM, figure, plot_phase, save, save_h5, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "fig09_10_phase_diagrams"
T_END = 0.004


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    crit = critical_damping(p, "paper", bracket=(1e12, 2e12))
    kc = crit.kappa_c
    kappas = [1e9, 1e11, 1.6e12, 3e12]
    grid = np.linspace(0.0, T_END, 8001 if quick else 40001)
    data = {"kappa_c": (np.array([kc]), "N s/m^2.5")}
    with style():
        fig, axes = figure(2, 4, width=11, height=5.2)
        for ax, kappa in zip(axes[0], kappas, strict=True):
            tr = simulate(p.replace(kappa=kappa), "paper", T_END, save=grid)
            points = plot_phase(ax, tr, color="C0", lw=0.9)
            ax.set_title(f"κ = {kappa:.2g} ({'below' if kappa < kc else 'above'} κc): {len(points)} point(s)")
            ax.legend(loc="upper right")
            data[f"kappa_{kappa:.2g}/delta"] = (tr.delta, "m")
            data[f"kappa_{kappa:.2g}/deltadot"] = (tr.deltadot, "m/s")
            data[f"kappa_{kappa:.2g}/points"] = (points.points, "m, m/s")
        for ax, factor, color in ((axes[1, 0], 1 - 1e-4, "C2"), (axes[1, 1], 1 + 1e-4, "C3")):
            tr = simulate(p.replace(kappa=kc * factor), "paper", T_END, save=grid)
            points = plot_phase(ax, tr, color=color, lw=0.9)
            ax.set_title(f"Fig. 10: κ = κc·(1 {'-' if factor < 1 else '+'} 1e-4): {len(points)} point(s)")
            ax.legend(loc="upper right")
            sticks = points.points[:, 0]
            if len(sticks) > 1:  # zoom on the split: the stick points, relative to the first
                inset = ax.inset_axes([0.42, 0.3, 0.55, 0.3])
                inset.plot((sticks - sticks[0]) * 1e9, np.arange(len(sticks)), "o", mfc="none", color=color, ms=4)
                inset.set_xlabel("δ* − δ*₁ (nm)", fontsize=6)
                inset.set_ylabel("stick #", fontsize=6)
                inset.tick_params(labelsize=6)
            data[f"kappa_c_{factor:+.4f}/points"] = (points.points, "m, m/s")
        # The seed's RK4 against the exact stick, seen in deltadot(t) after the first maximum compression.
        kappa = 1e9
        exact = simulate(p.replace(kappa=kappa), "paper", 2e-4, save=np.linspace(0, 2e-4, 2001))
        ax = axes[1, 2]
        ax.plot(exact.t * MS, exact.deltadot, "k", lw=1.2, label="exact (events)")
        for step, color in ((4e-7, "C1"), (1e-7, "C4")):
            rk4 = simulate(p.replace(kappa=kappa), "paper", 2e-4, integrator="rk4", step=step, save="steps")
            ax.plot(rk4.t * MS, rk4.deltadot, color=color, lw=0.6, label=f"seed RK4, h = {step:g} s")
        ax.set_xlim(0.04, 0.12)
        ax.set_ylim(-0.02, 0.05)
        ax.set_xlabel("time t (ms)")
        ax.set_ylabel(r"$\dot\delta$ (m/s)")
        ax.set_title("κ = 1e9: RK4 chatters at the stick")
        ax.legend(loc="upper right")
        ax = axes[1, 3]  # the split, zoomed: every stick point against kappa near kappa_c
        near = sweep(p, "paper", np.linspace(0.99 * kc, 1.02 * kc, 16 if quick else 61), t_end=T_END, n_jobs=jobs)
        for kappa, pts in zip(near.kappa, near.points, strict=True):
            ax.plot(np.full(len(pts), kappa / kc), pts[:, 0] * UM, ".", color="C0", ms=3)
        ax.axvline(1.0, color="C3", ls="--", label=f"κc = {kc:.6g}")
        ax.set_xlabel("κ / κc")
        ax.set_ylabel("stick points δ* (µm)")
        ax.set_title("the split near κc")
        ax.legend(loc="upper left")
        out = save(fig, FIGURES / f"{NAME}.png")
    save_h5(FIGURES / "data" / f"{NAME}.h5", data, {"v": 1.0, "law": "paper", "claim": __doc__.strip()})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
