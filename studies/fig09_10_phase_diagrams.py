"""Seed Figs. 9-10: phase diagrams of the relative motion (delta, deltadot) across the critical damping.

Claim (seed conclusion 7, REFERENCE §5), eq. 8 as printed ("paper"), v = 1 m/s, stick and slip
resolved as events, every run until its outcome settles (no horizon cut): below kappa_c the
relative motion sticks at its first maximum compression for good, one asymptotic point (delta*, 0).
Above kappa_c (an adding-sliding bifurcation of the stuck pair's sliding orbit) the stick breaks
at the plate's turning points and re-sticks a few nm deeper, N(kappa) times (42 at
kappa_c (1 + 1e-4)), then escapes after T_run; exactly two stick phases from kappa_2 on. After the
escape the printed reading runs away (the force acts in tension, energy doubles), the unilateral
reading separates and the projectile rebounds (apparent restitution up to above 1). The seed's
fixed-step RK4 chatters across deltadot = 0 instead of sticking (bottom, third panel).
"""

from pathlib import Path

import numpy as np
from _plots import COUNT_ATOL, COUNT_RTOL, READINGS, claim, outcome_of

from phaseimpact import seed_parameters, simulate
from phaseimpact.archive import save_h5
from phaseimpact.continuation import critical_damping
from phaseimpact.plotting import MS, UM, figure, mark_points, save, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "fig09_10_phase_diagrams"
KAPPAS = (1e9, 1e11, 1.6e12, 3e12)
#: Fig. 10's pair around kappa_c (relative offsets): below, and above in the staircase.
BELOW, ABOVE = -1e-4, 1e-4


def run(params, law, **kw):
    return simulate(params, law, None, save="steps", rtol=COUNT_RTOL, atol=COUNT_ATOL, **kw)


def phase(ax, tr, **kw):
    ax.plot(tr.delta * UM, tr.deltadot, **kw)
    ax.set_xlabel(r"$\delta = x_1 - x_2$ (µm)")
    ax.set_ylabel(r"$\dot\delta$ (m/s)")


def short(tr) -> str:
    if tr.outcome == "permanent-stick":
        return "permanent stick"
    if tr.stop_reason == "runaway":
        return "runaway"
    return f"separation, e = {tr.restitution:.3g}"


def ending(tr) -> str:
    return "cut by the horizon" if tr.cut else f"settled at {tr.t_stop * MS:.3g} ms"


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    crit = critical_damping(p, "paper", with_kappa_2=True)
    kc, k2 = crit.kappa_c, crit.kappa_2
    printed, unilateral = READINGS["printed"], READINGS["unilateral"]
    data = {"kappa_c": (np.array([kc]), "N s/m^2.5"), "kappa_2": (np.array([k2]), "N s/m^2.5")}
    with style():
        fig, grid = figure(4, 2, height=9.4)
        axes = grid.reshape(2, 4)
        for ax, kappa in zip(axes[0], KAPPAS, strict=True):
            tr = run(p.replace(kappa=kappa), printed)
            phase(ax, tr, color="C0", lw=0.9, label="printed: " + short(tr))
            _, delta, _ = tr.stick_points()
            mark_points(ax, np.column_stack([delta, np.zeros_like(delta)]), label="stick point")
            key = f"kappa_{kappa:.2g}"
            data[f"{key}/printed/delta"] = (tr.delta, "m")
            data[f"{key}/printed/deltadot"] = (tr.deltadot, "m/s")
            data[f"{key}/stick_delta"] = (delta, "m")
            side = "< κc" if kappa < kc else "> κ2"
            title = f"κ = {kappa:.2g} ({side}): {tr.n_stick} stick point{'s' if tr.n_stick > 1 else ''}"
            if kappa > kc:
                un = run(p.replace(kappa=kappa), unilateral)
                phase(ax, un, color="C1", lw=0.9, ls="--", label="unilateral: " + short(un))
                data[f"{key}/unilateral/delta"] = (un.delta, "m")
                data[f"{key}/unilateral/deltadot"] = (un.deltadot, "m/s")
                title += ",\nthen escape; " + ending(tr)
            else:
                title += f",\npermanent; {ending(tr)}"
            ax.set_title(title)
            ax.legend(loc="center left" if kappa > kc else "lower left")

        # Fig. 10: just below and just above kappa_c.
        below = run(p.replace(kappa=kc * (1 + BELOW)), printed)
        above = run(p.replace(kappa=kc * (1 + ABOVE)), printed)
        ax = axes[1, 0]
        phase(ax, below, color="C2", lw=0.9)
        _, d_below, _ = below.stick_points()
        mark_points(ax, np.column_stack([d_below, np.zeros_like(d_below)]), label="stick point (permanent)")
        ax.set_title(f"Fig. 10: κ = κc (1 − 1e-4)\n{below.n_stick} stick point, {outcome_of(below)}")
        ax.legend(loc="lower left")
        ax = axes[1, 1]
        phase(ax, above, color="C3", lw=0.6)
        t_st, d_st, _ = above.stick_points()
        mark_points(ax, np.column_stack([d_st, np.zeros_like(d_st)]), label="stick points")
        ax.set_title(f"Fig. 10: κ = κc (1 + 1e-4), printed\n{above.n_stick} stick points, escape at "
                     f"{above.t_run * MS:.3g} ms, runaway")
        ax.legend(loc="lower right")
        data["fig10_below/delta"] = (below.delta, "m")
        data["fig10_below/deltadot"] = (below.deltadot, "m/s")
        data["fig10_above/delta"] = (above.delta, "m")
        data["fig10_above/deltadot"] = (above.deltadot, "m/s")
        data["fig10_above/stick_t"] = (t_st, "s")
        data["fig10_above/stick_delta"] = (d_st, "m")

        # The seed's RK4 against the exact stick, seen in deltadot(t) around the first maximum compression.
        kappa = 1e9
        exact = simulate(p.replace(kappa=kappa), "paper", 2e-4, save=np.linspace(0, 2e-4, 2001))
        ax = axes[1, 2]
        ax.plot(exact.t * MS, exact.deltadot, "k", lw=1.2, label="exact (events)")
        for step, color, line in ((4e-7, "C1", "-"), (1e-7, "C4", "--")):
            rk4 = simulate(p.replace(kappa=kappa), "paper", 2e-4, integrator="rk4", step=step, save="steps")
            ax.plot(rk4.t * MS, rk4.deltadot, color=color, ls=line, lw=0.8, label=f"seed RK4, h = {step:g} s")
        ax.set_xlim(0.04, 0.12)
        ax.set_ylim(-0.02, 0.05)
        ax.set_xlabel("time t (ms)")
        ax.set_ylabel(r"$\dot\delta$ (m/s)")
        ax.set_title("κ = 1e9: the seed's RK4 chatters\nwhere the exact solution sticks")
        ax.legend(loc="upper right")

        # The ratchet and the escape of the run above kappa_c, over its whole length.
        ax = axes[1, 3]
        after = above.t >= t_st[0]
        ax.plot(above.t[after] * MS, (above.delta[after] - d_st[0]) * 1e9, color="C3", lw=0.8, label="δ(t) − δ*₁")
        ax.plot(t_st * MS, (d_st - d_st[0]) * 1e9, "k.", ms=3, label="stick phases")
        ax.axvline(above.t_run * MS, color="k", ls=":", lw=0.8, label=f"escape, T_run = {above.t_run * MS:.3g} ms")
        ax.set_ylim(-2, 1.3 * max(1.0, (d_st[-1] - d_st[0]) * 1e9))
        ax.set_xlabel("time t (ms)")
        ax.set_ylabel("δ − δ*₁ (nm)")
        ax.set_title("κ = κc (1 + 1e-4): δ* ratchets\noutwards, then escapes (off the axis)")
        ax.legend(loc="upper left")
        data["fig10_above/t"] = (above.t, "s")
        out = save(fig, FIGURES / f"{NAME}.png")
    save_h5(FIGURES / "data" / f"{NAME}.h5", data,
            {"v": 1.0, "law": "paper (printed; unilateral where named)", "rtol": COUNT_RTOL,
             "atol": "the case's own (None)", "n_stick_above": above.n_stick, "t_run_above": above.t_run,
             "claim": claim(__doc__)})
    return out


if __name__ == "__main__":
    from _cli import run as run_study

    run_study(main, __doc__)
