"""Bifurcation diagram: the stick points (asymptotic points of (delta, deltadot)) against kappa.

Claim (seed conclusion 7, REFERENCE §5): the count of asymptotic points changes from one to two at a
critical damping kappa_c. For eq. 8 as printed ("paper", v = 1 m/s) a sweep of kappa over five decades
shows one stick point up to kappa_c ≈ 1.4994e12 N s/m^2.5 and two above it (the runs above kappa_c
end in the runaway of the negative-damping branch, marked). The sweep is archived with
phaseimpact.archive (figures/data/bifurcation.h5, readable with plain h5py).
"""

from pathlib import Path

import numpy as np

from phaseimpact import archive, seed_parameters
from phaseimpact.continuation import critical_damping, sweep
from phaseimpact.plotting import UM, figure, save, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "bifurcation"


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    kappas = np.geomspace(1e9, 1e14, 40 if quick else 160)
    result = sweep(p, "paper", kappas, n_jobs=jobs, progress=True)
    i = result.first_split()
    result.critical = critical_damping(p, "paper", bracket=(kappas[i], kappas[i + 1]))
    kc = result.critical.kappa_c
    archive.save(result, FIGURES / "data" / f"{NAME}.h5")
    with style():
        fig, axes = figure(1, 2, width=9, height=3.4)
        ax = axes[0, 0]
        for kappa, pts, outcome in zip(result.kappa, result.points, result.outcome, strict=True):
            color = "C3" if outcome == "runaway" else "C0"
            ax.semilogx(np.full(len(pts), kappa), pts[:, 0] * UM, "o", ms=2.5, color=color)
        ax.semilogx([], [], "o", ms=3, color="C0", label="stick point (run ends stuck)")
        ax.semilogx([], [], "o", ms=3, color="C3", label="stick point (run ends in runaway)")
        ax.axvline(kc, color="k", ls="--", lw=0.8, label=f"κc = {kc:.6g}")
        ax.set_xlabel("damping κ (N s/m$^{2.5}$)")
        ax.set_ylabel("stick indentation δ* (µm)")
        ax.set_title("paper, v = 1 m/s: asymptotic points of (δ, δ̇)")
        ax.legend(loc="upper right")
        ax = axes[0, 1]
        ax.semilogx(result.kappa, result.n_asymptotic, "o-", ms=2.5, color="C0")
        ax.axvline(kc, color="k", ls="--", lw=0.8)
        ax.set_xlabel("damping κ (N s/m$^{2.5}$)")
        ax.set_ylabel("number of asymptotic points")
        ax.set_yticks([0, 1, 2, 3])
        ax.set_title("count: 1 below κc, 2 above")
        return save(fig, FIGURES / f"{NAME}.png")


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
