"""Bifurcation diagram of eq. 8 over six decades of damping: stick points, their number, how runs end.

Claim (seed conclusion 7, REFERENCE §5), "paper", v = 1 m/s, both readings, every run until its
outcome settles: up to kappa_c = 1.49942e12 N s/m^2.5 the relative motion sticks once and for good
(one asymptotic point; the plastic stick dissipates 71.1 mJ, about m v^2/2 with m the reduced
mass, whatever kappa). At kappa_c the stuck pair's sliding orbit touches the boundary of the
sliding region (adding-sliding bifurcation); above it the stick points are transient: N(kappa) of
them (unresolved on this grid: the staircase lies within 2.5e-4 of kappa_c, see staircase.png),
exactly two from kappa_2 on, then an escape. After the escape the printed reading runs away (the
law acts in tension; the energy doubles), the unilateral reading separates with an apparent
restitution that grows from below 1 to above 1, until at higher damping it too gains energy
faster than it separates. Every count is checked against a run at a tighter integrator tolerance
(rtol 1e-13 against 1e-12); points where it differs would be marked.
"""

from pathlib import Path

import numpy as np
from _plots import COUNT_RTOL, KAPPA_LABEL, READINGS, kappa_axis, save_archive

from phaseimpact import seed_parameters
from phaseimpact.continuation import critical_damping, sweep
from phaseimpact.plotting import UM, figure, save, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "bifurcation"


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    kappas = np.geomspace(1e9, 1e15, 40 if quick else 181)
    crit = critical_damping(p, "paper", with_kappa_2=True)
    kc, k2 = crit.kappa_c, crit.kappa_2
    results, check = {}, {}
    for name, law in READINGS.items():
        results[name] = sweep(p, law, kappas, n_jobs=jobs, rtol=COUNT_RTOL)
        check[name] = sweep(p, law, kappas, n_jobs=jobs, rtol=1e-13)
        save_archive(results[name], FIGURES / "data" / f"{NAME}_{name}.h5")
    pr, un = results["printed"], results["unilateral"]
    m = p.reduced_mass
    with style():
        fig, grid = figure(2, 2, height=5.6)
        axes = grid.reshape(1, 4)
        ax = axes[0, 0]
        permanent = pr.outcome_names()[pr.stick_point] == "permanent-stick"
        ax.plot(kappas[pr.stick_point[permanent]], pr.stick_delta[permanent] * UM, "o", ms=2.5, color="C0",
                label="permanent stick point")
        ax.plot(kappas[pr.stick_point[~permanent]], pr.stick_delta[~permanent] * UM, "o", ms=2.5, color="C3",
                mfc="none", label="transient (then escape)")
        for value, text in ((kc, "κc"), (k2, "κ2")):
            ax.axvline(value, color="k", ls=":" if text == "κ2" else "--", lw=0.8)
        ax.set_title(f"stick depths (printed = unilateral)\nκc = {kc:.6g}, κ2 = κc (1 + {k2 / kc - 1:.2g})")
        kappa_axis(ax)
        ax.set_ylabel("stick depth δ* (µm)")
        ax.legend(loc="upper right")

        ax = axes[0, 1]
        for name, color, marker in (("printed", "C0", "o"), ("unilateral", "C1", "x")):
            r = results[name]
            ax.plot(kappas, r.n_stick, marker, ms=3, color=color, mfc="none", label=name)
        differs = (pr.n_stick != check["printed"].n_stick) | (un.n_stick != check["unilateral"].n_stick)
        if np.any(differs):
            ax.plot(kappas[differs], np.maximum(pr.n_stick, un.n_stick)[differs] + 0.4, "v", color="C3", ms=4,
                    label=f"count changes with rtol 1e-12 → 1e-13 ({differs.sum()})")
        ax.axvline(kc, color="k", ls="--", lw=0.8, label="κc")
        kappa_axis(ax)
        ax.set_ylabel("stick phases N")
        ax.set_yticks(range(0, int(max(pr.n_stick.max(), un.n_stick.max())) + 2))
        ax.set_title("number of stick phases\n(staircase near κc not resolved here)")
        ax.legend(loc="upper left")

        ax = axes[0, 2]
        separated = un.outcome_names() == "ratchet-escape"
        runaway_un = un.stop_reason == 2  # STOP_REASONS: horizon, settled, runaway, ...
        ok = separated & ~runaway_un & np.isfinite(un.restitution)
        ax.plot(kappas[ok], un.restitution[ok], "o", ms=3, color="C1", label="unilateral")
        top = np.nanmax(un.restitution[ok]) if ok.any() else 1.5
        stopped = runaway_un & (kappas > kc)
        if stopped.any():  # the numerical guard (100 x the initial energy) stopped a run before it separated
            ax.plot(kappas[stopped], np.full(stopped.sum(), top * 1.05), "x", color="C3", ms=4,
                    label="unilateral: stopped by the energy guard before separation")
        ax.axhline(1.0, color="k", lw=0.6)
        ax.axvline(kc, color="k", ls="--", lw=0.8)
        ax.set_xlim(kappas[0], kappas[-1])
        kappa_axis(ax)
        ax.set_ylabel("restitution e (after the escape)")
        ax.set_title("above κc, unilateral: rebound, e > 1 possible\n(printed: every run above κc runs away)")
        ax.legend(loc="upper left")

        ax = axes[0, 3]
        for name, color, marker in (("printed", "C0", "o"), ("unilateral", "C1", "x")):
            r = results[name]
            ax.plot(kappas, r.dissipated_energy * 1e3, marker, ms=3, color=color, mfc="none", label=name)
        ax.axhline(0.5 * m * p.v**2 * 1e3, color="k", ls=":", lw=0.8, label=f"m v²/2 = {0.5 * m * p.v**2 * 1e3:.4g} mJ")
        ax.axvline(kc, color="k", ls="--", lw=0.8)
        kappa_axis(ax)
        ax.set_ylabel("dissipated energy (mJ)")
        ax.set_title("energy lost (no Hertz potential for paper)\nnegative = gained; floor: stopped at 2 E0")
        ax.legend(loc="lower left")
        ax.set_xlabel(KAPPA_LABEL)
        out = save(fig, FIGURES / f"{NAME}.png")
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
