"""Audit of the seed's seven conclusions (REFERENCE §6) for both readings of the damped model.

Each conclusion is tested on the seed's case (v = 1 m/s, plate target, kappa = 1e9 and 3e9) with the
exact integrator, for eq. 8 as printed ("paper") and for the Hunt-Crossley reading, and the numbers
that decide it are written to figures/claims.md (one numbered row per conclusion).
"""

from pathlib import Path

import numpy as np

from phaseimpact import seed_parameters, simulate
from phaseimpact.analysis import find_asymptotic_points
from phaseimpact.continuation import critical_damping, sweep
from phaseimpact.model import WORK, ContactLaw, coefficients, energy, initial_state
from phaseimpact.quantities import impact_quantities

FIGURES = Path(__file__).resolve().parents[1] / "figures"
LAWS = ("paper", "hunt-crossley")
KAPPAS = (1e9, 3e9)
T_END = 0.01
CLAIMS = (
    "The damped model's force-indentation loop closes at the origin.",
    "Damping work is larger in the approach phase than in the detaching phase.",
    "More damping slightly delays the instant when projectile and target displacements are equal.",
    "The loop area grows significantly with damping.",
    "Maximum force and extreme relative displacement are not in phase (the force peaks first).",
    "Excessive damping can raise the maximum impact force; an optimum damping minimises it.",
    "The phase path self-intersects; for higher damping two asymptotic points exist (bifurcation).",
)


def first_contact(tr):
    """Samples of the first contact, from t = 0 to its end, and the event that ends it
    (the first separation, or the first stick of eq. 8)."""
    end = next(e for e in tr.events if e.kind in ("separation", "stick"))
    keep = tr.t <= end.t
    return tr.t[keep], tr.delta[keep], tr.deltadot[keep], tr.force[keep], end


def damping_work(tr, kappa, alpha=1.5):
    """Work of the damping part kappa |delta|^alpha deltadot (times sgn for paper) in the approach
    (deltadot > 0) and detaching (deltadot < 0) phases of the first contact, J."""
    t, delta, deltadot, _, _ = first_contact(tr)
    damping = kappa * np.abs(delta) ** alpha * np.abs(deltadot)  # magnitude; it always opposes the motion
    power = damping * np.abs(deltadot)
    approach = np.trapezoid(np.where(deltadot > 0, power, 0.0), t)
    detach = np.trapezoid(np.where(deltadot < 0, power, 0.0), t)
    return approach, detach


def self_intersects(x, y, n=1500):
    """Whether the polyline (x, y) crosses itself (non-adjacent segments), on n resampled points."""
    idx = np.unique(np.linspace(0, len(x) - 1, n).astype(int))
    px, py = x[idx] / (np.ptp(x) or 1), y[idx] / (np.ptp(y) or 1)
    ax, ay, bx, by = px[:-1], py[:-1], px[1:], py[1:]
    for i in range(len(ax) - 2):
        cx, cy, dx, dy = ax[i + 2:], ay[i + 2:], bx[i + 2:], by[i + 2:]
        d1 = (bx[i] - ax[i]) * (cy - ay[i]) - (by[i] - ay[i]) * (cx - ax[i])
        d2 = (bx[i] - ax[i]) * (dy - ay[i]) - (by[i] - ay[i]) * (dx - ax[i])
        d3 = (dx - cx) * (ay[i] - cy) - (dy - cy) * (ax[i] - cx)
        d4 = (dx - cx) * (by[i] - cy) - (dy - cy) * (bx[i] - cx)
        if np.any((d1 * d2 < 0) & (d3 * d4 < 0)):
            return True
    return False


def verdict(ok, partly=False):
    return "partly" if partly else ("confirmed" if ok else "not confirmed")


def fmt(x, unit=""):
    return "undefined" if x is None else f"{x:.4g}{unit}"


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    grid = np.linspace(0, T_END, 20001 if quick else 100001)
    runs = {(law, k): simulate(p.replace(kappa=k), law, T_END, save=grid) for law in LAWS for k in (0.0, *KAPPAS)}
    q = {key: impact_quantities(tr) for key, tr in runs.items()}
    rows = []

    # 1. loop closes at the origin: state of the force-indentation path at the end of the first contact.
    cells = []
    for law in LAWS:
        tr = runs[(law, 3e9)]
        _, delta, _, force, end = first_contact(tr)
        closes = abs(end.delta) <= 1e-12 * np.max(delta) and abs(end.force) <= 1e-9 * np.max(force)
        cells.append((verdict(closes), f"first contact ends ({end.kind}, t = {end.t * 1e3:.4g} ms) at "
                                       f"δ = {end.delta * 1e6:.3g} µm, P = {end.force:.4g} N"))
    rows.append(cells)

    # 2. damping work, approach vs detaching.
    cells = []
    for law in LAWS:
        approach, detach = damping_work(runs[(law, 3e9)], 3e9)
        note = " (no detaching phase: the relative motion sticks)" if detach == 0 else ""
        cells.append((verdict(approach > detach, partly=detach == 0),
                      f"κ = 3e9: approach {approach * 1e3:.4g} mJ, detaching {detach * 1e3:.4g} mJ{note}"))
    rows.append(cells)

    # 3. time of x1 = x2 after contact begins, increasing slightly with damping.
    cells = []
    for law in LAWS:
        times = [q[(law, k)].time_equal_displacement for k in (0.0, *KAPPAS)]
        ok = all(t is not None for t in times) and times[0] < times[1] < times[2] and times[2] < 1.1 * times[0]
        cells.append((verdict(ok), "t(x1 = x2) for κ = 0, 1e9, 3e9: "
                      + ", ".join(fmt(t and t * 1e3, " ms") for t in times)
                      + ("" if ok else " (x1 never equals x2 again: stuck)")))
    rows.append(cells)

    # 4. loop area grows significantly with damping: the work of P over the first contact (the area of
    #    the closed loop for Hunt-Crossley; for paper the open path up to the stick).
    #    paper's path never closes, so its energy lost up to the stick stands in for the area.
    cells = []
    for law in LAWS:
        ends = [first_contact(runs[(law, k)])[4] for k in KAPPAS]
        if law == "paper":
            c = coefficients(p, ContactLaw(law))
            areas = [float(energy(initial_state(p.v), c, ContactLaw(law)) - energy(e.state, c, ContactLaw(law)))
                     for e in ends]
            what = "no closed loop (it sticks); energy lost up to the stick"
        else:
            areas = [e.state[WORK] for e in ends]
            what = "area of the first contact's loop"
        ratio = areas[1] / areas[0]
        cells.append((verdict(ratio > 1.5, partly=law == "paper" and ratio > 1.5),
                      f"{what}, κ = 1e9: {areas[0] * 1e3:.4g} mJ, 3e9: {areas[1] * 1e3:.4g} mJ (x{ratio:.3g})"))
    rows.append(cells)

    # 5. force peaks before the extreme indentation.
    cells = []
    for law in LAWS:
        tr = runs[(law, 3e9)]
        peak = max((e for e in tr.events if e.kind == "force-peak"), key=lambda e: e.force)
        extreme = next(e for e in tr.events if e.kind in ("reversal", "stick"))
        cells.append((verdict(peak.t < extreme.t),
                      f"max force at {peak.t * 1e6:.4g} µs, extreme δ at {extreme.t * 1e6:.4g} µs"))
    rows.append(cells)

    # 6. an optimum damping minimises the maximum force.
    cells = []
    kappas = np.geomspace(1e8, 1e12, 12 if quick else 41)
    for law in LAWS:
        result = sweep(p, law, kappas, n_jobs=jobs)
        force = np.where(result.outcome == "runaway", np.nan, result.max_force)
        best = int(np.nanargmin(force))
        interior = 0 < best < len(kappas) - 1 and np.isfinite(force[-1])
        cells.append((verdict(interior), f"min max-force {force[best]:.4g} N at κ ≈ {kappas[best]:.3g}; "
                                f"{force[0]:.4g} N at κ = 1e8, {np.nanmax(force):.4g} N at the top"))
    rows.append(cells)

    # 7. self-intersection and two asymptotic points for higher damping.
    cells = []
    for law in LAWS:
        crit = critical_damping(p, law, bracket=(1e11, 1e14)) if law == "paper" else None
        above = simulate(p.replace(kappa=3e12), law, 0.004, save=np.linspace(0, 0.004, 20001))
        crosses = self_intersects(above.delta, above.deltadot)
        n_above = len(find_asymptotic_points(above)) if law == "paper" else 0
        if crit is not None and crit.kappa_c is not None:
            text = (f"κc = {crit.kappa_c:.6g}: {crit.n_below} point below, {crit.n_above} above; "
                    f"path at κ = 3e12 self-intersects: {crosses}")
            cells.append((verdict(crosses and crit.n_above >= 2, partly=crit.n_above >= 2 and not crosses), text))
        else:
            cells.append((verdict(False, partly=crosses),
                          f"no asymptotic point (the projectile rebounds); path at κ = 3e12 self-intersects: "
                          f"{crosses}; asymptotic points: {n_above}"))
    rows.append(cells)

    lines = ["# The seed's conclusions, audited", "",
             "Seed case, v = 1 m/s, plate target, exact event-driven integrator; `paper` is eq. 8 as printed "
             "(Filippov reading, stick and slip), `hunt-crossley` the standard reading. Regenerate with "
             "`python studies/claims.py`.", "",
             "| # | conclusion | paper | hunt-crossley | numbers (paper; hunt-crossley) |", "|---|---|---|---|---|"]
    for i, (claim, cells) in enumerate(zip(CLAIMS, rows, strict=True), start=1):
        verdicts = [v for v, _ in cells]
        numbers = "; ".join(text for _, text in cells)
        lines.append(f"| {i} | {claim} | {verdicts[0]} | {verdicts[1]} | {numbers} |")
    out = FIGURES / "claims.md"
    out.write_text("\n".join(lines) + "\n")
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
