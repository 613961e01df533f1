"""Grazing bifurcations of Hunt-Crossley: the number of contacts against kappa and over (kappa, v).

Claim (REFERENCE §5): a unilateral law has no stick, so no adding-sliding; its long-time count is
the number of contacts before the projectile is out of the plate's reach, and that count changes
at grazing values of kappa, where an extremum of delta in a flight phase just touches zero. At the
seed's case (v = 1 m/s) the count goes 2 -> 3 -> 2 -> 1 -> 2 over kappa in 1e8-1e13 N s/m^2.5, at
four grazing values located to 1e-9 as roots of the smooth extremum function (the 3-contact window
is 25 % wide, narrow enough for a coarse grid to step over it). Continued in v, the grazing values
are curves that bound the regions of the (kappa, v) atlas of contacts; more windows (up to 7
contacts) open at other speeds, each bounded by its own continued grazing curve; a curve that
ends inside the range ends where the window it bounds closes (above about 5.7 m/s a 3-contact window
near kappa = 1e10 narrows to nothing between its two grazing curves as v falls).
"""

import math
from collections import namedtuple
from pathlib import Path

import matplotlib.colors as mcolors
import matplotlib.pyplot as plt
import numpy as np
from _plots import KAPPA_LABEL, V_LABEL, kappa_axis, save_archive
from scipy.optimize import brentq

from phaseimpact import seed_parameters
from phaseimpact.archive import save_h5
from phaseimpact.continuation import atlas, critical_curve, delta_extremum, sweep, transitions
from phaseimpact.plotting import PAGE_WIDTH, UM, save, style

FIGURES = Path(__file__).resolve().parents[1] / "figures"
NAME = "grazing"
LAW = "hunt-crossley"
KAPPA_RANGE = (1e8, 1e13)
V_RANGE = (0.3, 13.0)
#: Speeds at which the grazing values are searched for, as seeds of the continued curves: a window of
#: contacts that opens and closes between 0.3 and 13 m/s is found from a speed inside it.
SEED_SPEEDS = (1.0, *np.geomspace(*V_RANGE, 9))
#: Halvings of the speed step before a curve counts as ended (located to 2^-6 of a step of the walk).
HALVINGS = 6


def edges(values):
    logv = np.log(values)
    mid = 0.5 * (logv[1:] + logv[:-1])
    return np.exp(np.concatenate([[2 * logv[0] - mid[0]], mid, [2 * logv[-1] - mid[-1]]]))


#: A grazing value to continue: ``kappa`` (N s/m^2.5) and the extremum of delta that touches zero there.
Grazing = namedtuple("Grazing", "kappa extremum")


def roots_near(p, j, guess, width=0.03, num=13):
    """Grazing values of extremum ``j`` (N s/m^2.5) within ``guess * exp(+-width)``: sign changes of
    delta at the extremum. Where the extremum does not occur (delta_extremum is -inf: the projectile
    leaves for good before it), the search starts from where it first occurs: a new minimum and
    maximum of delta are born together there, possibly on either side of zero."""
    def f(x):
        return delta_extremum(p.replace(kappa=math.exp(x)), LAW, j)

    def first_occurrence(absent, present):
        for _ in range(40):  # bisection to 2^-40 of a sample step
            mid = 0.5 * (absent + present)
            absent, present = (absent, mid) if math.isfinite(f(mid)) else (mid, present)
        return present, f(present)

    x = np.linspace(math.log(guess) - width, math.log(guess) + width, num)
    values = [f(t) for t in x]
    roots = []
    for a, b, fa, fb in zip(x, x[1:], values, values[1:], strict=False):
        if math.isfinite(fa) != math.isfinite(fb):
            a, fa = first_occurrence(a, b) if math.isfinite(fb) else (a, fa)
            b, fb = first_occurrence(b, a) if not math.isfinite(fb) else (b, fb)
        if math.isfinite(fa) and math.isfinite(fb) and (fa > 0) != (fb > 0):
            roots.append(math.exp(brentq(f, a, b, xtol=1e-10)))
    return roots


def step(p, j, v, k, target):
    """The grazing value at speed ``target`` next to the walked points ``(v, k)``, or None: searched
    around the secant prediction, then (near where a window closes the curve turns, and the secant
    overshoots) around the last value, each in a narrow and a wider window."""
    guesses = [k[-1]]
    if len(v) >= 2:
        slope = math.log(k[-1] / k[-2]) / math.log(v[-1] / v[-2])
        guesses.insert(0, k[-1] * (target / v[-1]) ** slope)
    for guess in guesses:
        for width in (0.03, 0.1):
            roots = roots_near(p.replace(v=float(target)), j, guess, width)
            if roots:
                return min(roots, key=lambda r: abs(math.log(r / guess)))
    return None


def continued(p, start_v, transition, speeds):
    """The grazing curve through ``transition`` (found at ``start_v``), walked to both ends of ``speeds``.

    Returns ``(v, kappa, ends)``, ``ends`` the speeds inside the range where the curve ends: where
    critical_curve's corrector loses it (its bracket reaches where the extremum no longer occurs), the
    walk goes on with :func:`step`, halving a step that fails; where even the shortest step finds no
    root, the window of contacts the curve bounds has closed."""
    base = p.replace(v=start_v)
    parts, ends = [], []
    for values in (speeds[speeds >= start_v], speeds[speeds <= start_v][::-1]):
        values = np.concatenate([[start_v], values[values != start_v]])
        if len(values) < 2:
            continue
        c = critical_curve(base, LAW, "v", values, what="grazing", kappa_start=transition.kappa,
                           contact_index=transition.extremum)
        v, k = list(c.values), list(c.kappa)
        shortest = abs(math.log(values[1] / values[0])) / 2**HALVINGS
        pending = list(values[np.abs(np.log(values / start_v)) > abs(math.log(v[-1] / start_v)) * (1 + 1e-12)][::-1])
        while pending:  # each target, reached in halved steps where a whole one fails
            x = float(pending[-1])
            root = step(p, transition.extremum, v, k, x)
            if root is not None:
                v.append(x)
                k.append(root)
                pending.pop()
            elif abs(math.log(x / v[-1])) > shortest:
                pending.append(math.sqrt(v[-1] * x))
            else:
                ends.append(v[-1])
                break
        parts.append((np.array(v), np.array(k)))
    v = np.concatenate([x for x, _ in parts])
    k = np.concatenate([y for _, y in parts])
    order = np.argsort(v)
    return v[order], k[order], ends


def same_curve(a, b):
    """Whether two walked curves ``(v, kappa, extremum)`` are one: the same extremum, the same values where
    both were walked."""
    if a[2] != b[2]:
        return False
    shared = np.intersect1d(a[0], b[0])
    return bool(shared.size) and bool(np.allclose(np.interp(shared, a[0], a[1]), np.interp(shared, b[0], b[1]),
                                                  rtol=1e-4))


def walk(p, v0, t, speeds, curves):
    """Add the curve through grazing ``t`` at ``v0`` to ``curves``, unless there; where it ends inside the
    range, also the curve it ends on (the other side of the closing window: the extremum before or after)."""
    v, k, ends = continued(p, v0, t, speeds)
    if any(same_curve((v, k, t.extremum), c) for c in curves):
        return
    curves.append((v, k, t.extremum, ends))
    for end in ends:
        near = np.abs(np.log(v / end))
        inside = v[np.argmin(np.where(near > 0, near, np.inf))]  # the walked point next to the end
        for j in (t.extremum - 1, t.extremum + 1):
            for root in roots_near(p.replace(v=float(inside)), j, float(np.interp(inside, v, k))):
                walk(p, float(inside), Grazing(root, j), speeds, curves)


def main(quick=False, jobs=1):
    p = seed_parameters(v=1.0)
    found = transitions(p, LAW, *KAPPA_RANGE)
    kappas = np.geomspace(*KAPPA_RANGE, 150 if quick else 800)
    line = sweep(p, LAW, kappas, n_jobs=jobs)
    save_archive(line, FIGURES / "data" / f"{NAME}_sweep.h5")
    js = sorted({t.extremum for t in found})
    ext = {j: np.array([delta_extremum(p.replace(kappa=float(k)), LAW, j) for k in kappas[::4]]) for j in js}

    speeds = np.geomspace(*V_RANGE, 12 if quick else 40)
    grid = atlas(p, LAW, {"v": speeds, "kappa": np.geomspace(*KAPPA_RANGE, 30 if quick else 80)}, n_jobs=jobs)
    save_archive(grid, FIGURES / "data" / f"{NAME}_atlas.h5")
    curve_v = np.geomspace(*V_RANGE, 10 if quick else 36)
    curves = []
    for v0 in SEED_SPEEDS:
        for t in (found if v0 == 1.0 else transitions(p.replace(v=v0), LAW, *KAPPA_RANGE)):
            if any(j == t.extremum and cv[0] <= v0 <= cv[-1] and abs(np.interp(v0, cv, ck) / t.kappa - 1) < 1e-4
                   for cv, ck, j, _ in curves):
                continue  # on a curve already walked from another speed
            walk(p, v0, t, curve_v, curves)
    curves.sort(key=lambda c: (c[1][0], c[2]))  # in a stable order, whatever speed found them

    with style():
        fig, axes = plt.subplot_mosaic([["count", "extrema"], ["atlas", "atlas"]], figsize=(PAGE_WIDTH, 6.6),
                                       height_ratios=(1.0, 1.25))
        ax = axes["count"]
        ax.plot(kappas, line.n_contacts, "-", drawstyle="steps-mid", color="C0", lw=1.2,
                label=f"sweep ({len(kappas)} κ)")
        for t in found:
            ax.axvline(t.kappa, color="C3", ls=":", lw=0.9,
                       label=f"grazing {t.kappa:.4g}: {t.count_below} → {t.count_above}")
        kappa_axis(ax)
        ax.set_ylabel("contacts before the\nprojectile is out of reach")
        ax.set_ylim(0.5, 5.4)  # room above the counts for the legend
        ax.set_yticks([1, 2, 3])
        ax.set_title("Hunt-Crossley, v = 1 m/s: contacts against κ")
        ax.legend(loc="upper left", frameon=True, framealpha=1.0, edgecolor="none")

        ax = axes["extrema"]
        for j, marker in zip(js, "os^v<>", strict=False):
            ax.plot(kappas[::4], ext[j] * UM, "-", marker=marker, markevery=12, ms=3.5, lw=1,
                    label=f"extremum {j} of δ")
        for t in found:
            ax.plot(t.kappa, 0.0, "o", color="C3", mfc="none", ms=5)
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_yscale("symlog", linthresh=1.0)
        kappa_axis(ax)
        ax.set_ylabel("δ at the extremum (µm, symlog)")
        ax.set_title("grazing: an extremum of δ\ncrosses 0 (circles)")
        ax.legend(loc="upper left")

        ax = axes["atlas"]
        n = grid.n_contacts.reshape(len(speeds), -1)
        top = int(n.max())
        cmap = mcolors.ListedColormap([mcolors.to_hex(c) for c in
                                       __import__("matplotlib").colormaps["viridis"](np.linspace(0, 1, top))])
        mesh = ax.pcolormesh(edges(grid.axis("kappa")), edges(speeds), n, cmap=cmap, vmin=0.5, vmax=top + 0.5,
                             shading="flat", rasterized=True)
        fig.colorbar(mesh, ax=ax, ticks=range(1, top + 1), label="contacts")
        for i, (v, k, _, _) in enumerate(curves):
            ax.plot(k, v, "w-", lw=2.0)
            ax.plot(k, v, "-", color="C3", lw=0.9, label="continued grazing curves" if i == 0 else None)
        closed = [(np.interp(e, v, k), e) for v, k, _, ends in curves for e in ends]
        if closed:
            ax.plot(*np.transpose(closed), "o", color="k", mfc="w", ms=4, mew=1.0,
                    label="a curve ends: the window of contacts it bounds closes")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(*KAPPA_RANGE)
        ax.set_xlabel(KAPPA_LABEL)
        ax.set_ylabel(V_LABEL)
        ax.grid(False)
        ax.set_title(f"(κ, v) atlas of contacts, {len(curves)} grazing curves")
        ax.legend(loc="lower left", frameon=True, facecolor="white", framealpha=0.85, edgecolor="none")
        out = save(fig, FIGURES / f"{NAME}.png")
    data = {"transitions/kappa": (np.array([t.kappa for t in found]), "N s/m^2.5"),
            "transitions/count_below": (np.array([t.count_below for t in found]), "1"),
            "transitions/count_above": (np.array([t.count_above for t in found]), "1"),
            "transitions/extremum": (np.array([t.extremum for t in found]), "1"),
            "extrema/kappa": (kappas[::4], "N s/m^2.5")}
    data.update({f"extrema/delta_{j}": (ext[j], "m") for j in js})
    for i, (v, k, j, ends) in enumerate(curves):
        data[f"curves/{i}/v"] = (v, "m/s")
        data[f"curves/{i}/kappa"] = (k, "N s/m^2.5")
        data[f"curves/{i}/extremum"] = (np.array([j]), "1")
        data[f"curves/{i}/ends_at_v"] = (np.array(ends, dtype=float), "m/s")
    save_h5(FIGURES / "data" / f"{NAME}.h5", data, {"law": LAW, "v": 1.0, "claim": " ".join(__doc__.split())})
    return out


if __name__ == "__main__":
    from _cli import run

    run(main, __doc__)
