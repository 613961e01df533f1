"""The conformance suite of a contact law: :func:`check_law` (``phaseimpact check-law``).

The shipped laws pass it (``tests/test_laws.py`` runs the same checks with pytest); a user law
(:func:`phaseimpact.define_law`) is held to it before it is trusted. Each check gives a verdict, a
Python bool (or None: skipped) that :class:`Verdict` refuses to take in any other type:

==================  ==========================================================================
``force``           the force is finite in contact; a unilateral law's is 0 at ``delta <= 0``;
                    a law not declared Filippov does not jump up across ``deltadot = 0`` (the
                    bodies could stick there, which only a Filippov law resolves)
``repulsive``       on loading (``delta > 0``, ``deltadot >= 0``) the force pushes the bodies
                    apart: ``P >= 0``, and ``P > 0`` somewhere
``partials``        ``force_partials`` against central differences of the force, in contact
``energy ledger``   the mechanical energy lost equals the contact work less the change of the
                    contact potential (docs/physics.md §4), and the engine's own energy agrees
``momentum``        a free target: total momentum conserved through the impact
``scipy``           against scipy ``solve_ivp`` (DOP853, rtol 1e-12) on a rigid target: the
                    largest force and the rebound speed
``oracle``          against the independent oracle (:mod:`phaseimpact._oracle`, scipy with its
                    own events) on the plate: events, largest force, stop and final state
==================  ==========================================================================

Every run has a budget, so that a law whose integration grinds (a force that jumps, sticks
without being declared Filippov, or is not finite beyond the points sampled) gets a failing line
within seconds: an engine run at most :data:`MAX_STEPS` steps, a scipy run at most
:data:`SCIPY_MAX_NFEV` right-hand side calls and :data:`SCIPY_SECONDS` seconds.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

__all__ = ["check_law", "Verdict", "LawReport", "damping_number", "with_damping_number", "PLASTIC_CHECK_PRESSURE"]

#: Limiting pressure of the default case of a plastic law's checks (Pa): the seed's plate at 1 m/s
#: is then well in the elastic-plastic regime.
PLASTIC_CHECK_PRESSURE = 2e9
#: Step budget of each engine run of the checks (the shipped laws' longest takes 1265 steps:
#: ``abrate`` bilateral on the plate).
MAX_STEPS = 50_000
#: Budget of each scipy run (the ``scipy`` check, the oracle): right-hand side calls (the shipped
#: laws' longest, the oracle's run of ``abrate`` bilateral, takes 31 174), and wall time (s) as a
#: backstop only: that run takes 5 s on a 2-core machine under a load of 12.
SCIPY_MAX_NFEV = 100_000
SCIPY_SECONDS = 20.0
#: Where to read how to declare a law that sticks.
_FILIPPOV_HINT = "declare it Filippov (define_law(..., filippov=True), docs/commands.md)"


@dataclass(frozen=True)
class Verdict:
    """The outcome of one check of :func:`check_law`.

    Attributes
    ----------
    check : str
        The check's name (``"force"``, ``"repulsive"``, ``"partials"``, ``"energy ledger"``,
        ``"momentum"``, ``"scipy"``, ``"oracle"``).
    passed : bool or None
        Whether the law passed; None when the check was skipped (it does not apply). Anything
        but a Python bool or None (a ``numpy.bool_``) is refused with a TypeError.
    detail : str
        What was measured, against what tolerance, or why the check failed or was skipped.

    Examples
    --------
    >>> from phaseimpact.checks import Verdict
    >>> v = Verdict("momentum", True, "relative change 2e-16 (allowed 1e-10)")
    >>> print(v.line())
      PASS  momentum       relative change 2e-16 (allowed 1e-10)
    """

    check: str
    passed: bool | None  # None: skipped
    detail: str

    def __post_init__(self):
        if self.passed is not None and type(self.passed) is not bool:  # np.False_ is not False: it could never fail
            raise TypeError(f"verdict {self.check!r}: passed must be a bool or None, not {type(self.passed).__name__}")

    def line(self) -> str:
        """The verdict as one line of a report.

        Returns
        -------
        str
            ``PASS``, ``FAIL`` or ``skip``, the check's name (padded to 14 characters) and the
            detail, indented by two spaces.

        Examples
        --------
        >>> from phaseimpact.checks import Verdict
        >>> print(Verdict("scipy", None, "a Filippov law: the oracle below").line())
          skip  scipy          a Filippov law: the oracle below
        """
        mark = "PASS" if self.passed else ("skip" if self.passed is None else "FAIL")
        return f"  {mark}  {self.check:<14} {self.detail}"


@dataclass
class LawReport:
    """The verdicts of :func:`check_law` on one law; ``str(report)`` is what ``phaseimpact
    check-law`` prints.

    Attributes
    ----------
    law : str
        The law's label (:meth:`~phaseimpact.model.ContactLaw.label`: name and options).
    verdicts : list of Verdict
        One per check, in the order they ran.
    passed : bool
        (Property.) Every verdict passed or was skipped.

    Examples
    --------
    >>> from phaseimpact.checks import LawReport, Verdict
    >>> report = LawReport("my-law", [Verdict("force", True, "finite in contact"),
    ...                               Verdict("momentum", False, "relative change 1e-3")])
    >>> report.passed
    False
    >>> print(report)
    check-law my-law: FAILED
      PASS  force          finite in contact
      FAIL  momentum       relative change 1e-3
    """

    law: str
    verdicts: list = field(default_factory=list)

    @property
    def passed(self) -> bool:
        return all(v.passed is True or v.passed is None for v in self.verdicts)

    def __str__(self) -> str:
        head = f"check-law {self.law}: {'passed' if self.passed else 'FAILED'}"
        return "\n".join([head] + [v.line() for v in self.verdicts])


def damping_number(params, law) -> float:
    """The law's dimensionless damping at ``params``: its damping force over its elastic force at
    the impact speed and the undamped Hertz indentation on a rigid target (``kappa v / K`` for
    ``(K + kappa deltadot) delta^alpha``). None-damped laws: 0.

    Parameters
    ----------
    params : Parameters
        The model's parameters: ``kappa`` (N s/m^damping_power), ``K`` (N/m^alpha), ``alpha``,
        the impact speed ``v`` (m/s) and the projectile's mass ``M1`` (kg) are read.
    law : ContactLaw or str
        The law, or a registered law's name.

    Returns
    -------
    float
        The dimensionless damping (proportional to ``kappa``); 0.0 for a law whose damping does
        not come from ``kappa`` (undamped, or set by a restitution).

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.checks import damping_number
    >>> p = seed_parameters(v=1.0, kappa=1e9)
    >>> print(f"{damping_number(p, 'hunt-crossley'):.4g} = kappa v / K = {p.kappa * p.v / p.K:.4g}")
    0.04596 = kappa v / K = 0.04596
    >>> damping_number(p, "abrate")
    0.0
    """
    from .model.forms import contact_force
    from .model.laws import as_law
    from .model.rhs import pack

    law = as_law(law)
    if not law.reads("kappa"):
        return 0.0
    c = pack(params.replace(kappa=1.0), law)
    K, alpha, v = c[2], c[6], float(params.v)
    depth = (0.5 * (alpha + 1.0) * params.M1 * v * v / K) ** (1.0 / (alpha + 1.0))
    term = contact_force(law.code, depth, v, 1, K, 1.0, alpha) - contact_force(law.code, depth, 0.0, 1, K, 1.0, alpha)
    elastic = contact_force(law.code, depth, 0.0, 1, K, 0.0, alpha)
    return float(params.kappa) * term / elastic if elastic > 0 else 0.0


def with_damping_number(params, law, a: float):
    """``params`` with ``kappa`` set so that ``law``'s :func:`damping_number` is ``a`` (unchanged
    for a law whose damping does not come from ``kappa``).

    Parameters
    ----------
    params : Parameters
        The model's parameters (its ``kappa`` is replaced).
    law : ContactLaw or str
        The law, or a registered law's name.
    a : float
        The dimensionless damping wanted (:func:`damping_number`), e.g. 0.05: a damping force
        5 % of the elastic one.

    Returns
    -------
    Parameters
        ``params`` with the new ``kappa`` (N s/m^damping_power), or ``params`` itself for a law
        that does not read ``kappa``.

    Examples
    --------
    >>> from phaseimpact import seed_parameters
    >>> from phaseimpact.checks import damping_number, with_damping_number
    >>> p = seed_parameters(v=1.0)
    >>> q = with_damping_number(p, "hunt-crossley", 0.05)
    >>> print(f"kappa = {q.kappa:.4g} N s/m^2.5, a = {damping_number(q, 'hunt-crossley'):.4g}")
    kappa = 1.088e+09 N s/m^2.5, a = 0.05
    >>> with_damping_number(p, "abrate", 0.05) is p
    True
    """
    unit = damping_number(params.replace(kappa=1.0), law)
    if unit <= 0 or not math.isfinite(unit):
        return params
    return params.replace(kappa=a / unit)


def _case(params, law):
    """The check's case: ``params`` with a moderate damping for the law (damping force 5 % of the
    elastic one at the impact speed and the Hertz indentation)."""
    return with_damping_number(params, law, 0.05)


def _one_line(text: str) -> str:
    """A message (scipy's, an exception's) as one line of the report."""
    return " ".join(text.split())


def _check(name, function):
    from ._oracle import BudgetExceeded

    try:
        # a law that overflows or returns NaN makes numpy and scipy warn at every step: the verdict says it once
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            passed, detail = function()
    except BudgetExceeded as exc:
        return Verdict(name, False, f"scipy: {exc}: its integration grinds (a force that jumps, or is not finite "
                                    f"beyond the points sampled; a law that sticks: {_FILIPPOV_HINT})")
    except Exception as exc:  # noqa: BLE001 (a verdict, whatever went wrong)
        return Verdict(name, False, _one_line(f"{type(exc).__name__}: {exc}"))
    return Verdict(name, passed, detail)


def _simulate(params, law, t_end=None, **options):
    """An engine run of a check within :data:`MAX_STEPS`; ``(trajectory, None)``, or ``(None,
    why it failed)``."""
    from .integrate import simulate

    tr = simulate(params, law, t_end, rtol=1e-12, max_steps=MAX_STEPS, **options)
    if tr.status == "success":
        return tr, None
    if tr.status == "too-many-steps":
        return None, (f"the engine's run took more than {MAX_STEPS} steps (to t = {tr.t_stop:.3g} s): it grinds "
                      f"(a force that jumps or is not finite beyond the points sampled; a law that sticks: "
                      f"{_FILIPPOV_HINT})")
    return None, _one_line(f"the engine's run failed: {tr.status} ({tr.message})")


def _force(law, params):
    from .model.forms import force_of
    from .model.rhs import pack

    c = pack(params, law)
    K, damping, alpha = c[2], c[5], c[6]
    modes = (1, -1) if law.is_filippov else (1,)
    for delta in (1e-7, 1e-6, 1e-5, 4e-5):
        for deltadot in (-0.5, 0.0, 0.5):
            for mode in modes:
                f = force_of(law.code, c, delta, deltadot, mode)
                if not math.isfinite(f):
                    return False, f"P({delta:g}, {deltadot:g}) = {f!r}: not finite"
        if not law.is_filippov:
            # a force that jumps up across deltadot = 0 holds the bodies together for a range of loads
            # (a sliding set): only a Filippov law resolves it, any other grinds there
            h = 1e-9 * params.v
            below, above = force_of(law.code, c, delta, -h, 1), force_of(law.code, c, delta, h, 1)
            if above - below > 1e-6 * max(abs(above), abs(below)):
                return False, (f"sticks: the force jumps up across deltadot = 0 (P({delta:g}, -0) = {below:.6g} N, "
                               f"P({delta:g}, +0) = {above:.6g} N): {_FILIPPOV_HINT}")
    if law.is_unilateral:
        native = law.entry.native
        for delta in (0.0, -1e-6):
            f = (force_of(law.code, c, delta, -0.5, 1) if native is None
                 else float(native.functions["force"](delta, -0.5, K, damping, alpha)) if delta == 0.0 else 0.0)
            if f != 0.0:
                return False, f"P({delta:g}, -0.5) = {f!r}: a unilateral law's force must be 0 at the separation"
        return True, "finite in contact, 0 at delta <= 0"
    return True, "finite in contact and in tension"


def _repulsive(law, params):
    """On loading (``delta > 0``, ``deltadot >= 0``) the force pushes the bodies apart: ``P >= 0``,
    and ``P > 0`` somewhere (at depths up to twice the Hertz indentation, speeds up to ``v``)."""
    from .model.forms import force_of
    from .model.rhs import pack

    c = pack(params, law)
    depth, v = params.hertz_indentation, float(params.v)
    largest = 0.0
    for delta in depth * np.array([1e-3, 0.1, 0.5, 1.0, 2.0]):
        for deltadot in (0.0, 0.1 * v, 0.5 * v, v):
            f = force_of(law.code, c, float(delta), deltadot, 1)
            if math.isnan(f):
                return False, f"P({delta:.3g} m, {deltadot:.3g} m/s) = nan on loading: no force at all"
            if not f >= 0.0:
                return False, (f"P({delta:.3g} m, {deltadot:.3g} m/s) = {f:.6g} N on loading: the force must push the "
                               "bodies apart (P >= 0 for delta > 0, deltadot >= 0)")
            largest = max(largest, f)
    if not largest > 0.0:
        return False, "P = 0 everywhere on loading (delta > 0, deltadot >= 0): the force never pushes the bodies apart"
    return True, f"P >= 0 on loading up to twice the Hertz indentation ({2 * depth:.3g} m), largest {largest:.4g} N"


def _partials(law, params):
    from .model.forms import force_of, partials_of
    from .model.rhs import pack

    c = pack(params, law)
    K, alpha = c[2], c[6]
    worst = 0.0
    for delta, deltadot in ((3e-5, 0.4), (2e-5, -0.3), (1e-5, 0.05)):
        for mode in (1, -1) if law.is_filippov else (1,):
            if law.is_filippov and np.sign(deltadot) != mode:
                continue
            exact = partials_of(law.code, c, delta, deltadot, mode)
            hd, hr = 1e-6 * abs(delta), 1e-6 * abs(deltadot)
            code = law.code
            fd = ((force_of(code, c, delta + hd, deltadot, mode) - force_of(code, c, delta - hd, deltadot, mode))
                  / (2 * hd),
                  (force_of(code, c, delta, deltadot + hr, mode) - force_of(code, c, delta, deltadot - hr, mode))
                  / (2 * hr))
            scale = K * abs(delta) ** alpha / abs(delta) + 1.0
            for a, b, what in ((exact[0], fd[0], "dP/ddelta"), (exact[1], fd[1], "dP/ddeltadot")):
                err = abs(a - b) / (abs(b) + 1e-3 * scale)
                if not err <= 1e-5:  # NaN fails too
                    return False, (f"{what} at ({delta:g}, {deltadot:g}) = {a:.6g}, central differences "
                                   f"{b:.6g} (relative error {err:.2g} > 1e-5)")
                worst = max(worst, err)
    return True, f"largest relative error {worst:.2g} (<= 1e-5)"


def _energy(law, params):
    from .model.forms import potential_of
    from .model.rhs import energy, pack

    tr, failed = _simulate(params, law, 4e-3)
    if failed:
        return False, failed
    c = pack(params, law)
    y0, y1 = tr.initial_state, tr.final_state
    du = potential_of(law.code, c, y1[0] - y1[1]) - potential_of(law.code, c, y0[0] - y0[1])
    scale = 0.5 * params.M1 * params.v**2
    gap = abs(tr.dissipated_energy - (tr.loop_area - du)) / scale
    own = abs(tr.dissipated_energy - (energy(law.code, c, y0) - energy(law.code, c, y1))) / scale
    if not (gap <= 1e-8 and own <= 1e-12):
        return False, (f"energy lost {tr.dissipated_energy:.9g} J, contact work less potential change "
                       f"{tr.loop_area - du:.9g} J (gap {gap:.2g} of the impact energy; allowed 1e-8): is the "
                       "potential the elastic term's?")
    if not law.is_conservative:
        return True, f"gap {gap:.2g} of the impact energy (<= 1e-8); no potential (not conservative)"
    # without damping the elastic term alone acts: the energy with its potential is constant through
    # the contact (a wrong potential shows here, not at the ends, where it is 0)
    elastic = params.replace(kappa=0.0) if law.reads("kappa") else params
    steps, failed = _simulate(elastic, law, 4e-3, save="steps")
    if failed:
        return False, f"undamped: {failed}"
    ce = pack(elastic, law)
    values = np.array([energy(law.code, ce, y) for y in steps.y])
    drift = float(np.max(np.abs(values - values[0]))) / scale
    if law.reads("kappa") and not drift <= 1e-8:
        return False, (f"undamped, the energy with the law's potential varies by {drift:.2g} of the impact energy "
                       "through the contact (allowed 1e-8): the potential is not the elastic term's")
    return True, (f"gap {gap:.2g} of the impact energy (<= 1e-8); undamped energy constant to {drift:.2g}")


def _momentum(law, params):
    p = params.replace(target="free")
    tr, failed = _simulate(p, law, 1e-3)
    if failed:
        return False, failed
    momentum = p.M1 * tr.final_state[2] + p.M2 * tr.final_state[3]
    err = abs(momentum - p.M1 * p.v) / (p.M1 * p.v)
    return bool(err <= 1e-10), f"relative change {err:.2g} (allowed 1e-10)"


def _scipy(law, params):
    """A rigid target, integrated by scipy from the force alone until the separation; a law with
    memory (Thornton) is given its largest indentation at the turning point, where scipy restarts."""
    from scipy.integrate import solve_ivp

    from ._oracle import Budget
    from .model.forms import force_of, remember
    from .model.rhs import pack

    if law.is_filippov:
        return None, "a Filippov law: the oracle below resolves its stick and slip"
    p = params.replace(target="rigid")
    c = pack(p, law)
    K, M1 = c[2], p.M1
    budget = Budget(SCIPY_MAX_NFEV, SCIPY_SECONDS)

    def rates(t, z):
        budget.spend()
        return [z[1], -force_of(law.code, c, z[0], z[1], 1) / M1]

    def separation(t, z):
        return z[0] if t > 0 else 1.0

    def turning(t, z):
        return z[1]
    separation.terminal, separation.direction = True, -1
    turning.terminal, turning.direction = True, -1
    contact_time = 3.2 * (M1 / K) ** 0.4 / p.v ** 0.2
    options = dict(method="DOP853", rtol=1e-12, atol=[1e-18, 1e-13], dense_output=True)
    loading = solve_ivp(rates, (0, 20 * contact_time), [0.0, p.v], events=turning, **options)
    if loading.status == -1:
        return False, _one_line(f"scipy could not integrate the loading: {loading.message}")
    if loading.status != 1:
        return False, f"scipy found no turning point in {20 * contact_time:.3g} s: the force does not stop the bodies"
    t_max, z_max = loading.t_events[0][0], loading.y_events[0][0]
    remember(law.code, c, z_max[0])
    sol = solve_ivp(rates, (t_max, 20 * contact_time), z_max, events=separation, **options)
    if sol.status == -1:
        return False, _one_line(f"scipy could not integrate the unloading: {sol.message}")
    if sol.status != 1:
        return None, "scipy found no separation (a sticking or adhesive law): compared nothing"
    t_sep, v_out = sol.t_events[0][0], sol.y_events[0][0][1]
    z = np.hstack([loading.sol(np.linspace(0, t_max, 2001)), sol.sol(np.linspace(t_max, t_sep, 2001))])
    peak = max(force_of(law.code, c, a, b, 1) for a, b in zip(z[0], z[1], strict=True))
    tr, failed = _simulate(p, law, stop_on="separation")  # what scipy integrated (a bilateral law goes on)
    if failed:
        return False, failed
    separations = [e for e in tr.events if e.kind == "separation"]
    if not separations:
        return False, "the engine found no separation where scipy did"
    ours = separations[0].state[2] - separations[0].state[3]
    err_v = abs(ours - v_out) / p.v
    err_f = abs(tr.max_force - peak) / peak
    return bool(err_v <= 1e-8 and err_f <= 1e-5), (
        f"rebound speed {-ours:.10g} m/s vs scipy {-v_out:.10g} (relative {err_v:.2g}, allowed 1e-8); "
        f"max force relative {err_f:.2g} (scipy's sampled, allowed 1e-5)")


def _oracle(law, params):
    from ._oracle import compare, oracle

    if law.entry.memory:
        return None, "the oracle has no law memory: the scipy check above restarts at the turning point"
    tr, failed = _simulate(params, law, 4e-3)
    if failed:
        return False, failed
    ref = oracle(params, law, 4e-3, rtol=1e-12, max_nfev=SCIPY_MAX_NFEV, seconds=SCIPY_SECONDS)
    if ref.reason == "failed":
        return False, f"scipy could not integrate the law at t = {ref.t_stop:.3g} s (a force that is not finite?)"
    agreement = compare(tr, ref, 4e-3)
    return agreement.agrees, agreement.detail()


def check_law(law, params=None, *, oracle: bool = True) -> LawReport:
    """Run the conformance suite on ``law`` (a :class:`~phaseimpact.model.ContactLaw`, a
    registered name, or a user law's name) and return a report with a verdict per check.

    ``params`` defaults to the seed plate at ``v = 1`` m/s; the damping (``kappa``) is chosen for
    the law so that its damping force is about 5 % of the elastic one.

    Parameters
    ----------
    law : ContactLaw or str
        The law with its options, or a registered law's name (shipped or user law).
    params : Parameters, optional
        The case; default: the seed at ``v = 1`` m/s (a plastic law: with a limiting pressure of
        :data:`PLASTIC_CHECK_PRESSURE`, Pa). Its ``kappa`` is replaced (:func:`with_damping_number`
        with 0.05).
    oracle : bool
        Also compare with the independent oracle (:mod:`phaseimpact._oracle`).

    Returns
    -------
    LawReport
        One :class:`Verdict` per check (``force``, ``repulsive``, ``partials``, ``energy
        ledger``, ``momentum``, ``scipy`` and, with ``oracle``, ``oracle``); a check that raised,
        or whose run went past its budget (:data:`MAX_STEPS`, :data:`SCIPY_MAX_NFEV`,
        :data:`SCIPY_SECONDS`), is a failed verdict that says so. ``report.passed`` when none
        failed.

    Raises
    ------
    ValueError
        For a name that is not a registered law's (:func:`~phaseimpact.model.as_law`).

    Examples
    --------
    >>> from phaseimpact.checks import check_law
    >>> report = check_law("hunt-crossley", oracle=False)
    >>> report.passed
    True
    >>> print(report)
    check-law hunt-crossley: passed
      PASS  force          finite in contact, 0 at delta <= 0
      PASS  repulsive      P >= 0 on loading up to twice the Hertz indentation (...), largest ... N
      PASS  partials       largest relative error ... (<= 1e-5)
      PASS  energy ledger  gap ... of the impact energy (<= 1e-8); undamped energy constant to ...
      PASS  momentum       relative change ... (allowed 1e-10)
      PASS  scipy          rebound speed 0.96773... m/s vs scipy 0.96773... (relative ..., allowed 1e-8); ...
    """
    from .model.laws import as_law
    from .parameters import seed_parameters

    law = as_law(law)
    if params is None:  # a plastic law needs a limiting pressure: the seed's steel then yields below 1 m/s
        params = seed_parameters(v=1.0, limiting_pressure=PLASTIC_CHECK_PRESSURE if law.entry.plastic else None)
    params = _case(params, law)
    report = LawReport(law.label())
    report.verdicts.append(_check("force", lambda: _force(law, params)))
    report.verdicts.append(_check("repulsive", lambda: _repulsive(law, params)))
    report.verdicts.append(_check("partials", lambda: _partials(law, params)))
    report.verdicts.append(_check("energy ledger", lambda: _energy(law, params)))
    report.verdicts.append(_check("momentum", lambda: _momentum(law, params)))
    report.verdicts.append(_check("scipy", lambda: _scipy(law, params)))
    if oracle:
        report.verdicts.append(_check("oracle", lambda: _oracle(law, params)))
    return report
