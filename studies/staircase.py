"""The adding-sliding at kappa_c: the staircase N(kappa), the escape time T_run and the local exponents.

Claim (REFERENCE §5), eq. 8 ("paper"), v = 1 m/s, every run until its outcome settles: just above
kappa_c the number of stick phases before the escape, N(kappa), is finite, grows without bound as
kappa -> kappa_c+ (10396 at kappa_c (1 + 5e-6)) and falls in a staircase of even steps to exactly
2 at kappa_2 (kappa_2 / kappa_c - 1 = 2.5e-4). T_run, the time to the escape, diverges like a power
of kappa - kappa_c: the fitted exponent is -1.81 for 5e-6 <= kappa/kappa_c - 1 <= 1e-4, and the
local slope still drifts (-1.65 below 2e-5), so the asymptotic exponent is not reached within the
horizon cap (1e4 plate periods). At the bifurcation the first slip's largest speed grows like
(kappa - kappa_c)^(3/2), the offset between the first two stick depths like (kappa - kappa_c)^2 and
the slip's duration like (kappa - kappa_c)^(1/2): the local slopes are 1.48, 1.98 and 0.50 at
offsets 1e-7 to 6e-7 and bend away at larger offsets, where the damping of the slip matters. The
unilateral reading gives the same N and T_run (the escape is where the two readings part).
"""

from pathlib import Path

import numpy as np
from _plots import COUNT_ATOL, COUNT_RTOL, READINGS, claim, loglog_fit, missed_restick

from phaseimpact import seed_parameters, simulate
from phaseimpact.archive import save_h5
from phaseimpact.continuation import critical_damping
from phaseimpact.plotting import figure, save, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "staircase"
#: Smallest offset kappa/kappa_c - 1 whose escape comes before the horizon cap (1e4 plate periods).
EPS_MIN = 5e-6
EPS_MAX = 6e-4
#: Offsets for the local exponents (the first slip's speed is then 2e-11 to 2e-6 m/s).
EXPONENT_EPS = np.geomspace(1e-7, 3e-4, 10)
#: Fit range of T_run (the asymptotic regime, well below kappa_2).
FIT_MAX = 1e-4


def first_slip(params, law):
    """Largest speed and duration of the first slip, and the offset between the first two stick depths."""
    run = simulate(params, law, None, rtol=1e-13, stop_on=("stick", 2))
    sticks, slips = run.events_of("stick"), run.events_of("slip")
    if len(sticks) < 2 or not slips:
        return np.nan, np.nan, np.nan
    t0 = slips[0].t
    t1 = next(e.t for e in run.events if e.t > t0 and e.kind in ("stick", "reversal"))
    fine = simulate(params, law, t1, rtol=1e-13, save=np.linspace(t0, t1, 401)[1:-1])
    return float(np.max(np.abs(fine.deltadot))), abs(sticks[1].delta - sticks[0].delta), t1 - t0


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    crit = critical_damping(p, "paper", with_kappa_2=True)
    kc, k2 = crit.kappa_c, crit.kappa_2
    eps = np.geomspace(3e-5 if quick else EPS_MIN, EPS_MAX, 25 if quick else 110)
    runs = {name: [] for name in READINGS}
    for i, e in enumerate(eps):
        for name, law in READINGS.items():
            if name == "unilateral" and i % 5:
                continue  # the unilateral reading on every fifth point: it gives the same N and T_run
            runs[name].append(simulate(p.replace(kappa=kc * (1 + e)), law, None, rtol=COUNT_RTOL, atol=COUNT_ATOL))
    pr, un = runs["printed"], runs["unilateral"]
    n = np.array([tr.n_stick for tr in pr])
    t_run = np.array([np.nan if tr.t_run is None else tr.t_run for tr in pr])
    cut = np.array([tr.cut for tr in pr])
    missed = np.array([missed_restick(tr) for tr in pr])
    eps_un = eps[::5]
    n_un = np.array([tr.n_stick for tr in un])
    t_un = np.array([np.nan if tr.t_run is None else tr.t_run for tr in un])
    ok_un = ~np.array([missed_restick(tr) for tr in un])
    good = ~missed
    fit = (eps <= FIT_MAX) & ~cut & ~missed & np.isfinite(t_run)
    slope, intercept = loglog_fit(eps[fit], t_run[fit])
    smallest = fit & (eps <= 2e-5)
    slope_small = loglog_fit(eps[smallest], t_run[smallest])[0]
    period = p.target_period

    local = np.array([first_slip(p.replace(kappa=kc * (1 + e)), "paper") for e in EXPONENT_EPS])
    names = ("slip speed", "stick offset", "slip duration")
    expected = (1.5, 2.0, 0.5)
    slopes = [loglog_fit(EXPONENT_EPS[:3], local[:3, j])[0] for j in range(3)]

    with style():
        fig, grid = figure(2, 2, height=5.8)
        axes = grid.reshape(1, 4)
        ax = axes[0, 0]
        ax.loglog(eps[good], n[good], "-", drawstyle="steps-mid", color="C0", lw=1, label="printed")
        if np.any(missed):
            ax.loglog(eps[missed], n[missed], "x", color="0.5", ms=4,
                      label=f"engine missed a re-stick ({missed.sum()}, not used)")
        ax.loglog(eps_un[ok_un], n_un[ok_un], "x", color="C1", ms=4, label="unilateral (every 5th κ)")
        if np.any(cut):
            ax.loglog(eps[cut], n[cut], "v", color="C3", label="cut by the horizon (lower bound)")
        ax.axvline(k2 / kc - 1, color="k", ls=":", lw=0.8, label=f"κ2: κ2/κc − 1 = {k2 / kc - 1:.3g}")
        ax.set_xlabel("κ/κc − 1")
        ax.set_ylabel("stick phases before the escape N")
        ax.set_title(f"N(κ) above κc = {kc:.6g}")
        ax.legend(loc="upper right")

        ax = axes[0, 1]
        near = eps >= 6e-5
        ax.plot(eps[near] * 1e4, n[near], "o-", drawstyle="steps-mid", ms=2.5, color="C0", lw=0.8)
        ax.axvline((k2 / kc - 1) * 1e4, color="k", ls=":", lw=0.8, label="κ2 (N = 2 from here on)")
        ax.set_yscale("log", base=2)
        ax.set_yticks([2, 4, 8, 16, 32, 64, 128])
        ax.set_yticklabels(["2", "4", "8", "16", "32", "64", "128"])
        ax.set_xlabel("(κ/κc − 1) × 1e4")
        ax.set_ylabel("N")
        ax.set_title("the staircase ends at κ2")
        ax.legend(loc="upper right")

        ax = axes[0, 2]
        ax.loglog(eps[good], t_run[good] * 1e3, ".", ms=3, color="C0", label="printed")
        ax.loglog(eps_un[ok_un], t_un[ok_un] * 1e3, "x", ms=4, color="C1", label="unilateral")
        ax.loglog(eps[fit], np.exp(intercept) * eps[fit] ** slope * 1e3, "k-", lw=0.8,
                  label=f"fit, κ/κc − 1 ≤ {FIT_MAX:g}: slope {slope:.3f}")
        ax.axvline(k2 / kc - 1, color="k", ls=":", lw=0.8)
        ax.set_xlabel("κ/κc − 1")
        ax.set_ylabel("time to the escape T_run (ms)")
        ax.set_title(f"T_run diverges at κc\n(plate period {period * 1e3:.3g} ms)")
        ax.legend(loc="upper right")

        ax = axes[0, 3]
        for j, (name, ex, color, marker) in enumerate(zip(names, expected, ("C0", "C2", "C4"), "os^", strict=True)):
            y = local[:, j] / local[0, j]
            ax.loglog(EXPONENT_EPS, y, marker + "-", ms=3, color=color,
                      label=f"{name}: slope {slopes[j]:.3f} (→ {ex:g})")
            ax.loglog(EXPONENT_EPS, (EXPONENT_EPS / EXPONENT_EPS[0]) ** ex, ":", color=color, lw=0.8)
        ax.set_xlabel("κ/κc − 1")
        ax.set_ylabel("relative to the smallest offset's")
        ax.plot([], [], "k:", lw=0.8, label="ε^(3/2), ε², ε^(1/2); ε = κ/κc − 1")
        ax.set_title("adding-sliding: the first slip")
        ax.legend(loc="upper left")
        out = save(fig, FIGURES / f"{NAME}.png")
    save_h5(FIGURES / "data" / f"{NAME}.h5", {
        "eps": (eps, "1"), "kappa": (kc * (1 + eps), "N s/m^2.5"), "n_stick": (n, "1"), "t_run": (t_run, "s"),
        "cut": (cut, "1"), "engine_missed_restick": (missed, "1"), "outcome": (np.array([tr.outcome for tr in pr]), ""),
        "unilateral/eps": (eps_un, "1"), "unilateral/n_stick": (n_un, "1"), "unilateral/t_run": (t_un, "s"),
        "exponents/eps": (EXPONENT_EPS, "1"), "exponents/slip_speed": (local[:, 0], "m/s"),
        "exponents/stick_offset": (local[:, 1], "m"), "exponents/slip_duration": (local[:, 2], "s"),
    }, {"v": 1.0, "law": "paper (printed; unilateral on every fifth point)", "kappa_c": kc, "kappa_2": k2,
        "t_run_exponent": slope, "t_run_fit_max_eps": FIT_MAX, "t_run_exponent_below_2e-5": slope_small,
        "n_missed_restick": int(missed.sum()), "slip_speed_exponent": slopes[0],
        "stick_offset_exponent": slopes[1], "slip_duration_exponent": slopes[2], "rtol": COUNT_RTOL,
        "atol": "the case's own (None)", "claim": claim(__doc__)})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
