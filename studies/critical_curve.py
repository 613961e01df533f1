"""The critical damping against the impact speed: kappa_c(v) and kappa_2(v) by continuation.

Claim (REFERENCE §5), "paper" (both readings share kappa_c and kappa_2: the first stick and the
staircase come before any tension): the adding-sliding exists at every speed from 0.3 to 13 m/s
(the seed's dust speed). kappa_c falls with v, close to v^(-2/3) with a logarithmic correction
(fitted log-log slope -0.657); REFERENCE §5's closed form (a two-body Hunt-Crossley approach and
momentum conservation) is 0.04 % to 0.3 % below it; the staircase window kappa_2 / kappa_c - 1
narrows from 6e-4 at 0.3 m/s to 5e-5 at 13 m/s. Each kappa_c is the root of the first stick's
margin (to 1e-10 relative), continued in v with a secant predictor; each kappa_2 is located by
bisection on N from the continued kappa_c. Archived as figures/data/critical_curve*.h5.
"""

from pathlib import Path

import numpy as np
from _plots import KAPPA_LABEL, V_LABEL, loglog_fit, save_archive

from phaseimpact import seed_parameters
from phaseimpact.continuation import critical_curve
from phaseimpact.plotting import figure, save, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "critical_curve"


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    speeds = np.geomspace(0.3, 13.0, 8 if quick else 40)
    kc = critical_curve(p, "paper", "v", speeds)
    k2 = critical_curve(p, "paper", "v", speeds, what="kappa_2")
    save_archive(kc, FIGURES / "data" / f"{NAME}.h5")
    save_archive(k2, FIGURES / "data" / f"{NAME}_kappa_2.h5")
    slope, _ = loglog_fit(kc.values, kc.kappa)
    closed_error = kc.closed_form / kc.kappa - 1
    window = np.interp(k2.values, kc.values, kc.kappa)
    with style():
        fig, axes = figure(1, 2, height=3.3)
        ax = axes[0, 0]
        ax.loglog(kc.values, kc.kappa, "o-", ms=3, color="C0", label=f"κc, continued (slope {slope:.3f})")
        ax.loglog(k2.values, k2.kappa, "s", ms=3, mfc="none", color="C3", label="κ2 (N = 2 from here on)")
        ax.loglog(kc.values, kc.closed_form, "k--", lw=0.9, label="closed form")
        ax.loglog(kc.values, kc.kappa[0] * (kc.values / kc.values[0]) ** (-2 / 3), ":", color="0.5", lw=0.9,
                  label="∝ v^(−2/3)")
        ax.axvline(13.0, color="C1", ls=":", lw=0.8, label="seed's dust speed 13 m/s")
        ax.set_xlabel(V_LABEL)
        ax.set_ylabel(KAPPA_LABEL)
        ax.set_title("paper: adding-sliding at κc(v),\nstaircase ends at κ2(v)")
        ax.legend(loc="lower left")
        ax = axes[0, 1]
        ax.loglog(kc.values, -closed_error, "k--", lw=0.9, label="1 − closed form / κc")
        ax.loglog(k2.values, k2.kappa / window - 1, "s-", ms=3, mfc="none", color="C3",
                  label="κ2/κc − 1 (staircase width)")
        ax.set_xlabel(V_LABEL)
        ax.set_ylabel("relative difference")
        ax.set_title("closed form's error and\nthe staircase's width")
        ax.legend(loc="upper right")
        out = save(fig, FIGURES / f"{NAME}.png")
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
