"""Zener's restitution against lambda: the infinite-plate target against Zener's equation, integrated here.

Claim (docs/physics.md §8; Zener 1941, Phys. Rev. 59:669): an elastic Hertz sphere (law "abrate") on
the infinite plate (target "infinite", the load point moving with P / c, c = 8 sqrt(D rho h)) has a
coefficient of restitution that is a function of Zener's lambda = M1^(3/5) v^(1/5) K^(2/5) / c alone,
and the engine reproduces Zener's curve. The curve is integrated here, not by phaseimpact's engine:
with the indentation in units of delta* = (M1 v^2 / K)^(2/5) and time in delta* / v, ball
(M1 x1'' = -P), Hertz contact (P = K delta^(3/2)) and plate (c w' = P) give
s'' = -s^(3/2) - lambda (s^(3/2))', integrated once as s' = u - lambda s^(3/2), u' = -s^(3/2)
(u = x1' / v, the ball's velocity; lambda s^(3/2) = w' / v, the load point's), from s = 0, u = 1,
to the return to s = 0, where the load point is at rest and e = -u (scipy's DOP853, rtol 1e-12).
Two series of engine runs, a 20 mm steel ball (the seed's) at 1 m/s and a 2 mm steel ball at
13 m/s, each on steel plates whose thickness sets lambda from 0.01 to 3, lie on the one curve: the
largest difference in e is stored as "max_abs_difference_e" (the engine runs at rtol 1e-10), in the
contact time as "max_rel_difference_contact_time". e -> 1 and the rigid-wall Hertz contact time as
lambda -> 0; e falls steeply but stays positive over the range (0.0028 at lambda = 3): this
integration gives no lambda at which the ball stops rebounding. A literature value for where e
vanishes is not quoted here (none could be checked against Zener's paper).
"""

import math
from pathlib import Path

import numpy as np
from _plots import claim, known, log_ticks
from scipy.integrate import solve_ivp

from phaseimpact import seed_parameters, simulate
from phaseimpact.archive import save_h5
from phaseimpact.model.regime import zener_lambda
from phaseimpact.plotting import COLUMN_WIDTH, figure, save, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "zener_restitution"
LAMBDAS = (0.01, 3.0)
#: The engine's series: (label, ball radius R1 in m, impact speed in m/s, marker), steel on steel.
SERIES = (("20 mm ball, 1 m/s", 0.02, 1.0, "o"), ("2 mm ball, 13 m/s", 0.002, 13.0, "s"))
#: The independent integration's tolerance (the engine runs at its default 1e-10).
ZENER_RTOL = 1e-12
#: Rigid-wall Hertz contact time in units of delta*/v: 2 sqrt(pi) Gamma(7/5) / Gamma(9/10) (5/4)^(2/5).
RIGID_WALL_CONTACT = 2 * math.sqrt(math.pi) * math.gamma(1.4) / math.gamma(0.9) * 1.25**0.4


def zener_restitution(lam: float) -> tuple[float, float]:
    """Zener's equation for one ``lambda``, by scipy: (restitution, contact time in units of ``delta*/v``)."""
    def rates(t, z):
        s, u = z
        force = max(s, 0.0) ** 1.5
        return [u - lam * force, -force]

    def separation(t, z):
        return z[0]

    separation.terminal, separation.direction = True, -1
    sol = solve_ivp(rates, [0.0, 1e4], [0.0, 1.0], method="DOP853", rtol=ZENER_RTOL, atol=1e-16,
                    events=separation)
    if sol.t_events[0].size != 1:
        raise RuntimeError(f"Zener's equation at lambda = {lam}: no separation up to t = 1e4 delta*/v")
    return float(-sol.y_events[0][0][1]), float(sol.t_events[0][0])


def engine_point(R1: float, v: float, lam: float):
    """The engine's elastic Hertz impact on the infinite steel plate whose thickness gives ``lam``
    (``lambda`` is proportional to ``h^-2``): (lambda of the run's parameters, restitution, contact time
    in units of ``delta*/v``)."""
    reference = seed_parameters(v=v, R1=R1, target="infinite")
    h = 0.005 * math.sqrt(zener_lambda(reference.M1, v, reference.K, reference.impedance) / lam)
    p = seed_parameters(v=v, R1=R1, h=h, target="infinite")
    run = simulate(p, "abrate")
    if run.status != "success" or run.restitution is None:
        raise RuntimeError(f"R1 = {R1}, v = {v}, h = {h}: {run.status}, {run.message}")
    delta_star = (p.M1 * v * v / p.K) ** 0.4
    return zener_lambda(p.M1, v, p.K, p.impedance), run.restitution, run.contact_duration * v / delta_star


def main(quick=False, jobs=1):
    n = 3 if quick else 20  # per series
    curve_lambda = np.geomspace(LAMBDAS[0] / 2, LAMBDAS[1] * 1.2, 40 if quick else 240)
    curve = np.array([zener_restitution(float(x)) for x in curve_lambda])
    data = {"curve/lambda": (curve_lambda, "1"), "curve/restitution": (curve[:, 0], "1"),
            "curve/contact_time": (curve[:, 1], "1")}
    largest_e, largest_t = 0.0, 0.0
    runs = {}
    for k, (label, R1, v, _) in enumerate(SERIES):
        # the series interleave: each covers the range, neither repeats the other's lambdas
        targets = np.geomspace(*LAMBDAS, 2 * n)[k::2]
        engine = np.array([engine_point(R1, v, float(x)) for x in targets])
        zener = np.array([zener_restitution(float(x)) for x in engine[:, 0]])
        largest_e = max(largest_e, float(np.max(np.abs(engine[:, 1] - zener[:, 0]))))
        largest_t = max(largest_t, float(np.max(np.abs(engine[:, 2] / zener[:, 1] - 1))))
        runs[label] = (engine, zener)
        key = f"R1_{R1 * 1e3:g}mm"
        data[f"{key}/lambda"] = (engine[:, 0], "1")
        data[f"{key}/restitution"] = (engine[:, 1], "1")
        data[f"{key}/contact_time"] = (engine[:, 2], "1")
        data[f"{key}/zener_restitution"] = (zener[:, 0], "1")
        data[f"{key}/zener_contact_time"] = (zener[:, 1], "1")

    with style():
        fig, axes = figure(2, 1, width=COLUMN_WIDTH, height=5.4, sharex=True)
        ax = axes[0, 0]
        ax.semilogx(curve_lambda, curve[:, 0], "k-", lw=1.0, label="Zener's equation (scipy)")
        for label, _, _, marker in SERIES:
            engine, _ = runs[label]
            ax.plot(engine[:, 0], engine[:, 1], marker, ms=4, mfc="white", mec="k", mew=0.9,
                    label=f"engine: {label}")
        ax.set_ylabel("coefficient of restitution e")
        ax.set_ylim(0, 1.02)
        ax.set_title(f"elastic Hertz ball on the infinite plate\nlargest |Δe| = {largest_e:.1g}")
        ax.legend(loc="lower left")
        ax = axes[1, 0]
        ax.loglog(curve_lambda, curve[:, 1], "k-", lw=1.0)
        for label, _, _, marker in SERIES:
            engine, _ = runs[label]
            ax.plot(engine[:, 0], engine[:, 2], marker, ms=4, mfc="white", mec="k", mew=0.9)
        ax.axhline(RIGID_WALL_CONTACT, color="0.4", ls="--", lw=0.8, label="rigid wall (λ → 0)")
        ax.set_xlabel("Zener's λ = M1$^{3/5}$ v$^{1/5}$ K$^{2/5}$ / c")
        log_ticks(ax.yaxis, [3, 5, 10, 20])
        ax.set_ylabel("contact time (units of δ*/v)")
        ax.set_xlim(curve_lambda[0], curve_lambda[-1])
        ax.set_title(f"contact time: largest relative difference {largest_t:.1g}")
        ax.legend(loc="upper left")
        out = save(fig, FIGURES / f"{NAME}.png")

    save_h5(FIGURES / "data" / f"{NAME}.h5", data,
            {"max_abs_difference_e": known(largest_e, 2), "max_rel_difference_contact_time": known(largest_t, 2),
             "zener_rtol": ZENER_RTOL, "engine_rtol": 1e-10, "rigid_wall_contact_time": RIGID_WALL_CONTACT,
             "restitution_at_lambda_3": known(zener_restitution(3.0)[0], 4),
             "restitution_at_lambda_1e-4": known(zener_restitution(1e-4)[0], 6),
             "curve_lambda_max": float(curve_lambda[-1]), "curve_positive": bool(np.all(curve[:, 0] > 0)),
             "series": str([label for label, *_ in SERIES]), "claim": claim(__doc__)})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
