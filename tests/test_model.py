"""Verification of the contact laws, the right-hand side and the restitution maps.

Sources: REFERENCE §3 (contact laws, eq. 1 and 8 with corrections, restitution laws' chi),
REFERENCE §4 (energy invariant, Hunt-Crossley restitution), Newton's third law (momentum).
Reference values are re-coded here from those formulas; the exact Hunt-Crossley restitution
is computed by a 60-digit bisection of its implicit equation (``decimal``), independent of
the package's Lambert-W evaluation.
"""

from __future__ import annotations

import math
from decimal import Decimal, localcontext

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from phaseimpact import ContactLaw, kappa_for_restitution, seed_parameters
from phaseimpact.model import (
    RESTITUTION_LAWS,
    Coefficients,
    coefficients,
    contact_force,
    damping_factor,
    hunt_crossley_restitution,
    rhs,
)

M1, M2, K, KB, KM = 0.263056, 0.308269, 2.17570e10, 1.20830e7, 1.65415e11
ALPHA = 1.5

PROPERTY = settings(max_examples=300, deadline=None)
deltas = st.floats(-1e-3, 1e-3, allow_nan=False)
deltadots = st.floats(-20.0, 20.0, allow_nan=False)
kappas = st.floats(0.0, 1e11, allow_nan=False)
positions = st.floats(-1e-3, 1e-3, allow_nan=False)


def coeffs(kappa=0.0, target="plate") -> Coefficients:
    """Seed-like coefficients; the target springs act only on the plate (REFERENCE §3, §4)."""
    springs = target == "plate"
    return Coefficients(M1=M1, M2=M2, K=K, Kb=KB if springs else 0.0, Km=KM if springs else 0.0,
                        kappa=kappa, alpha=ALPHA, target=target)


def state(delta, deltadot, x2=0.0, v2=0.0):
    """A state with the given relative motion (x2 = v2 = 0 keeps delta, deltadot exact)."""
    return np.array([x2 + delta, x2, v2 + deltadot, v2, 0.0])


def hertz(d):
    return abs(d) ** ALPHA


def close(a, b, rel=1e-12, scale=0.0):
    return math.isclose(float(a), float(b), rel_tol=rel, abs_tol=max(1e-300, rel * scale))


# ---------------------------------------------------------------------------------------------
# Contact laws (REFERENCE §3)
# ---------------------------------------------------------------------------------------------

UNILATERAL = [ContactLaw("abrate"), ContactLaw("hunt-crossley"), ContactLaw("hunt-crossley", clamp=True),
              *(ContactLaw(name, restitution=0.5) for name in RESTITUTION_LAWS)]


@PROPERTY
@given(st.floats(-1e-3, 0.0), deltadots, kappas, st.sampled_from(UNILATERAL))
def test_unilateral_laws_do_not_act_out_of_contact(delta, deltadot, kappa, law):
    """REFERENCE §3: abrate and the Hunt-Crossley family give P = 0 for delta <= 0."""
    assert contact_force(state(delta, deltadot), coeffs(kappa), law) == 0.0


@PROPERTY
@given(deltas, deltadots)
def test_abrate_is_hertz(delta, deltadot):
    """Seed eq. 2: P = K delta^(3/2) for delta > 0, independent of deltadot."""
    P = contact_force(state(delta, deltadot), coeffs(), ContactLaw("abrate"))
    assert close(P, K * hertz(delta) if delta > 0 else 0.0)


@PROPERTY
@given(deltas, deltadots, kappas)
def test_hunt_crossley_and_its_clamp(delta, deltadot, kappa):
    """REFERENCE §3: P = (K + kappa deltadot) delta^(3/2) for delta > 0; clamp=True gives max(P, 0)."""
    c = coeffs(kappa)
    expected = (K + kappa * deltadot) * hertz(delta) if delta > 0 else 0.0
    scale = (K + kappa * abs(deltadot)) * hertz(delta)
    assert close(contact_force(state(delta, deltadot), c, ContactLaw("hunt-crossley")), expected, scale=scale)
    clamped = contact_force(state(delta, deltadot), c, ContactLaw("hunt-crossley", clamp=True))
    assert clamped >= 0.0
    assert close(clamped, max(expected, 0.0), scale=scale)


@PROPERTY
@given(deltas, deltadots, kappas, st.sampled_from([1, -1]))
def test_paper_law_with_a_slip_mode(delta, deltadot, kappa, mode):
    """Seed eq. 8 (REFERENCE §3): P = (K + kappa deltadot) |delta|^(3/2) * mode while slipping."""
    P = contact_force(state(delta, deltadot), coeffs(kappa), ContactLaw("paper"), mode=mode)
    expected = (K + kappa * deltadot) * hertz(delta) * mode
    assert close(P, expected, scale=(K + kappa * abs(deltadot)) * hertz(delta))


@PROPERTY
@given(deltas, deltadots, kappas)
def test_paper_law_without_mode_reads_sign_of_deltadot(delta, deltadot, kappa):
    """Seed eq. 8 read literally (mode=None): the factor is sgn(deltadot), 0 at deltadot = 0."""
    P = contact_force(state(delta, deltadot), coeffs(kappa), ContactLaw("paper"))
    sign = (deltadot > 0) - (deltadot < 0)
    expected = (K + kappa * deltadot) * hertz(delta) * sign
    assert close(P, expected, scale=(K + kappa * abs(deltadot)) * hertz(delta))


@PROPERTY
@given(deltas, positions, kappas)
def test_paper_law_stuck_force_is_the_required_force(delta, x2, kappa):
    """REFERENCE §3: while stuck (mode 0) P = F_req = M1/(M1+M2) (Kb x2 + Km x2^3)."""
    P = contact_force(state(delta, 0.0, x2=x2, v2=0.3), coeffs(kappa), ContactLaw("paper"), mode=0)
    expected = M1 / (M1 + M2) * (KB * x2 + KM * x2**3)
    assert close(P, expected, scale=M1 / (M1 + M2) * (KB * abs(x2) + KM * abs(x2) ** 3))


@PROPERTY
@given(deltas, deltadots)
def test_bilateral_abrate_is_odd(delta, deltadot):
    """REFERENCE §3: bilateral P = K |delta|^(3/2) sgn(delta), an odd function of delta."""
    law, c = ContactLaw("abrate", bilateral=True), coeffs()
    P = contact_force(state(delta, deltadot), c, law)
    assert P == -contact_force(state(-delta, deltadot), c, law)
    assert close(P, math.copysign(K * hertz(delta), delta) if delta else 0.0)


@PROPERTY
@given(deltas, deltas, deltadots, st.booleans())
def test_abrate_increases_with_indentation(d1, d2, deltadot, bilateral):
    """P = K delta^(3/2) is non-decreasing in delta, strictly while in contact."""
    lo, hi = sorted((d1, d2))
    law, c = ContactLaw("abrate", bilateral=bilateral), coeffs()
    P_lo, P_hi = (float(contact_force(state(d, deltadot), c, law)) for d in (lo, hi))
    assert P_lo <= P_hi
    if hi > 1e-200 and hi - lo > 1e-9 * abs(hi):  # (delta^1.5 underflows below ~1e-205)
        assert P_lo < P_hi


@PROPERTY
@given(st.floats(1e-9, 1e-3), deltadots, deltadots, st.floats(1e3, 1e11))
def test_hunt_crossley_increases_with_deltadot(delta, v1, v2, kappa):
    """P = (K + kappa deltadot) delta^(3/2): slope kappa delta^(3/2) > 0 in deltadot for delta > 0."""
    lo, hi = sorted((v1, v2))
    assume(hi - lo > 1e-6)
    law, c = ContactLaw("hunt-crossley"), coeffs(kappa)
    P_lo, P_hi = (float(contact_force(state(delta, v), c, law)) for v in (lo, hi))
    assert P_lo < P_hi


def test_contact_force_is_vectorised():
    """All functions broadcast over leading axes (model docstring): a batch equals the scalars."""
    rng = np.random.default_rng(1)
    y = np.column_stack([rng.uniform(-1e-4, 1e-4, 50), np.zeros(50), rng.uniform(-2, 2, 50),
                         np.zeros(50), np.zeros(50)])
    c, law = coeffs(1e9), ContactLaw("hunt-crossley")
    batch = contact_force(y, c, law)
    assert batch.shape == (50,)
    assert np.array_equal(batch, [contact_force(row, c, law) for row in y])


# ---------------------------------------------------------------------------------------------
# Right-hand side: momentum, contact work, energy balance (REFERENCE §3, §4)
# ---------------------------------------------------------------------------------------------

ALL_LAWS = [ContactLaw("abrate"), ContactLaw("abrate", bilateral=True), ContactLaw("hunt-crossley"),
            ContactLaw("hunt-crossley", clamp=True), ContactLaw("lankarani-nikravesh", restitution=0.7),
            ContactLaw("paper")]
SLIP_MODES = [None, 1, -1]


def law_force(law: ContactLaw, delta, deltadot, kappa, mode):
    """P of REFERENCE §3, re-coded, for a slipping/plain state."""
    delta, deltadot = float(delta), float(deltadot)
    if law.name == "paper":
        sign = ((deltadot > 0) - (deltadot < 0)) if mode is None else mode
        return (K + kappa * deltadot) * hertz(delta) * sign
    if law.bilateral:
        return math.copysign(K * hertz(delta), delta) if delta else 0.0
    if delta <= 0:
        return 0.0
    if law.name == "abrate":
        return K * hertz(delta)
    P = (K + kappa * deltadot) * hertz(delta)
    return max(P, 0.0) if law.clamp else P


def elastic_force(law: ContactLaw, delta):
    """d/d(delta) of the Hertz potential K |delta|^(5/2)/(5/2) (only delta > 0 if unilateral)."""
    delta = float(delta)
    if law.is_unilateral:
        return K * hertz(delta) if delta > 0 else 0.0
    return math.copysign(K * hertz(delta), delta) if delta else 0.0


def spring(x2, c):
    return c.Kb * x2 + c.Km * x2**3


@PROPERTY
@given(deltas, deltadots, positions, deltadots, kappas, st.sampled_from(ALL_LAWS),
       st.sampled_from(SLIP_MODES), st.sampled_from(["plate", "free"]))
def test_rhs_momentum_changes_only_by_the_spring_force(delta, deltadot, x2, v2, kappa, law, mode, target):
    """Eq. 1/8: M1 x1'' + M2 x2'' = -(Kb x2 + Km x2^3); free target (no springs): conserved."""
    assume(law.name == "paper" or mode is None)
    c = coeffs(kappa, target)
    y = state(delta, deltadot, x2, v2)
    f = rhs(y, c, law, mode)
    total = M1 * f[2] + M2 * f[3]
    scale = abs(M1 * f[2]) + abs(M2 * f[3])
    assert close(total, -spring(x2, c), scale=scale)
    if target == "free":
        assert abs(total) <= 1e-12 * scale


@PROPERTY
@given(deltas, positions, deltadots, kappas, st.sampled_from(["plate", "free", "rigid"]))
def test_rhs_stuck_pair_moves_as_one_body(delta, x2, v, kappa, target):
    """REFERENCE §3: stuck (mode 0), both bodies share the acceleration -S(x2)/(M1+M2) (0 on a wall)."""
    c = coeffs(kappa, target)
    f = rhs(state(delta, 0.0, x2, v), c, ContactLaw("paper"), 0)
    expected = 0.0 if target == "rigid" else -spring(x2, c) / (M1 + M2)
    assert f[2] == f[3]
    assert close(f[2], expected, scale=abs(expected))


@PROPERTY
@given(deltas, deltadots, positions, deltadots, kappas, st.sampled_from(ALL_LAWS),
       st.sampled_from(SLIP_MODES), st.sampled_from(["plate", "free", "rigid"]))
def test_rhs_kinematics_and_contact_work(delta, deltadot, x2, v2, kappa, law, mode, target):
    """x' = v, and W' = P deltadot (model docstring) with P = -M1 x1'' (eq. 1) and P of REFERENCE §3."""
    assume(law.name == "paper" or mode is None)
    if target == "rigid":
        v2 = 0.0
    y = state(delta, deltadot, x2, v2)
    d, dd = y[0] - y[1], y[2] - y[3]
    f = rhs(y, coeffs(kappa, target), law, mode)
    assert (f[0], f[1]) == (y[2], y[3])
    P = law_force(law, d, dd, kappa, mode)
    scale = (K + kappa * abs(dd)) * hertz(d)
    assert close(-M1 * f[2], P, scale=scale)
    assert close(f[4], P * dd, scale=scale * abs(dd))
    if target == "rigid":
        assert f[3] == 0.0


@PROPERTY
@given(deltas, deltadots, positions, deltadots, kappas, st.sampled_from(ALL_LAWS),
       st.sampled_from(SLIP_MODES), st.sampled_from(["plate", "free", "rigid"]))
def test_energy_balance_from_rhs(delta, deltadot, x2, v2, kappa, law, mode, target):
    """REFERENCE §4 invariant: with E = M1 v1^2/2 + M2 v2^2/2 + Kb x2^2/2 + Km x2^4/4 + K d^(5/2)/(5/2),
    dE/dt = grad E . rhs (chain rule) = -(P - F_elastic) deltadot, F_elastic = dPotential/d(delta)."""
    assume(law.name == "paper" or mode is None)
    if target == "rigid":
        v2 = 0.0  # the target is held fixed
    c = coeffs(kappa, target)
    y = state(delta, deltadot, x2, v2)
    d, dd = y[0] - y[1], y[2] - y[3]
    f = rhs(y, c, law, mode)
    Fe = elastic_force(law, d)
    terms = [M1 * y[2] * f[2], M2 * y[3] * f[3], spring(y[1], c) * f[1], Fe * (f[0] - f[1])]
    dEdt = math.fsum(terms)
    expected = -(law_force(law, d, dd, kappa, mode) - Fe) * dd
    assert close(dEdt, expected, scale=sum(abs(t) for t in terms))


@PROPERTY
@given(deltas, positions, deltadots, kappas, st.sampled_from(["plate", "free", "rigid"]))
def test_energy_is_constant_while_stuck(delta, x2, v, kappa, target):
    """REFERENCE §3-4: a stuck pair oscillates on the springs with conserved energy (dE/dt = 0)."""
    if target == "rigid":
        v = 0.0
    c = coeffs(kappa, target)
    y = state(delta, 0.0, x2, v)
    f = rhs(y, c, ContactLaw("paper"), 0)
    terms = [M1 * y[2] * f[2], M2 * y[3] * f[3], spring(y[1], c) * f[1]]
    assert abs(math.fsum(terms)) <= 1e-12 * sum(abs(t) for t in terms) + 1e-300
    assert f[4] == 0.0


@pytest.mark.parametrize("target", ["rigid", "free"])
def test_coefficients_switch_springs_off_without_plate(target):
    """REFERENCE §4: rigid and free targets have no target springs; the plate keeps Kb, Km."""
    p = seed_parameters(target=target)
    c = coefficients(p, ContactLaw("abrate"))
    assert (c.Kb, c.Km) == (0.0, 0.0)
    plate = coefficients(seed_parameters(), ContactLaw("abrate"))
    assert (plate.Kb, plate.Km) == (p.Kb, p.Km)


# ---------------------------------------------------------------------------------------------
# Hunt-Crossley restitution (REFERENCE §4) and restitution laws (REFERENCE §3)
# ---------------------------------------------------------------------------------------------

def exact_restitution(a: float) -> float:
    """Root e in (0, 1] of 1 - e a = (1 + a) exp(-a (1 + e)) by 60-digit bisection (REFERENCE §4).

    f(0) = 1 - (1+a) e^-a > 0 and f(1) = 1 - a - (1+a) e^(-2a) < 0 for every a > 0, and the only
    other root is e = -1, so [0, 1] brackets the physical root.
    """
    with localcontext() as ctx:
        ctx.prec = 60
        A = Decimal(a)

        def f(e):
            return 1 - e * A - (1 + A) * (-(A * (1 + e))).exp()

        lo, hi = Decimal(0), Decimal(1)
        for _ in range(190):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if f(mid) > 0 else (lo, mid)
        return float((lo + hi) / 2)


A_RANGE = np.logspace(-3, 2, 26)


@pytest.mark.parametrize("a", A_RANGE)
def test_hunt_crossley_restitution_solves_the_implicit_equation(a):
    """REFERENCE §4: 1 - e a = (1 + a) exp(-a (1 + e)) to 1e-12, e in (0, 1)."""
    e = float(hunt_crossley_restitution(a))
    assert 0 < e < 1
    assert abs(1 - e * a - (1 + a) * math.exp(-a * (1 + e))) < 1e-12


@pytest.mark.parametrize("a", A_RANGE)
def test_hunt_crossley_restitution_matches_high_precision_root(a):
    """The residual test is weak for small a (its slope in e is -e a^2); compare e itself with the
    60-digit root. 1e-9 absolute over a in [1e-3, 100] (the package loses ~eps/a^2, see below)."""
    assert abs(float(hunt_crossley_restitution(a)) - exact_restitution(a)) < 1e-9


def test_hunt_crossley_restitution_limits_and_monotonicity():
    """REFERENCE §4: e -> 1 as a -> 0 (e = 1 - 2a/3 + O(a^2)), e ~ 1/a for large a, e decreasing."""
    a = np.logspace(-3, 2, 400)
    e = hunt_crossley_restitution(a)
    assert e.shape == a.shape
    assert np.all(np.diff(e) < 0)
    assert float(hunt_crossley_restitution(0.0)) == 1.0
    assert abs(float(hunt_crossley_restitution(1e-3)) - (1 - 2e-3 / 3)) < 1e-6
    assert float(hunt_crossley_restitution(100.0)) == pytest.approx(0.01, rel=1e-12)


@pytest.mark.parametrize("a", [1e-5, 1e-6, 1e-8, 1e-9])
def test_hunt_crossley_restitution_small_damping(a):
    """REFERENCE §4 / model docstring 'e -> 1 as a -> 0': e finite, in (0, 1], to 1e-10."""
    e = float(hunt_crossley_restitution(a))
    assert math.isfinite(e) and 0 < e <= 1
    assert abs(e - exact_restitution(a)) < 1e-10


@pytest.mark.parametrize("v", [0.5, 1.0, 13.0])
@pytest.mark.parametrize("e", np.linspace(0.05, 0.99, 9))
def test_kappa_for_restitution_round_trips(e, v):
    """e -> kappa -> e(kappa v / K) == e to 1e-10, with the package's map and the 60-digit root."""
    p = seed_parameters(v)
    kappa = kappa_for_restitution(e, p)
    assert kappa > 0
    assert abs(float(hunt_crossley_restitution(kappa * v / p.K)) - e) < 1e-10
    assert abs(exact_restitution(kappa * v / p.K) - e) < 1e-10


def test_kappa_for_restitution_elastic_and_monotone():
    """e = 1 needs no damping; kappa decreases as e increases (e decreasing in a)."""
    p = seed_parameters()
    assert kappa_for_restitution(1.0, p) == 0.0
    ks = [kappa_for_restitution(e, p) for e in np.linspace(0.05, 0.99, 30)]
    assert np.all(np.diff(ks) < 0)


@pytest.mark.parametrize("e", [0.99999, 0.999999, 1 - 1e-7, 1 - 1e-8])
def test_kappa_for_restitution_near_elastic(e):
    p = seed_parameters()
    kappa = kappa_for_restitution(e, p)
    assert abs(exact_restitution(kappa * p.v / p.K) - e) < 1e-10


CHI = {  # REFERENCE §3
    "hunt-crossley-approx": lambda e: 3 * (1 - e) / 2,
    "lankarani-nikravesh": lambda e: 3 * (1 - e**2) / 4,
    "flores": lambda e: 8 * (1 - e) / (5 * e),
    "gonthier": lambda e: (1 - e**2) / e,
}


def test_every_restitution_law_has_a_reference_formula():
    assert set(CHI) == set(RESTITUTION_LAWS)


@pytest.mark.parametrize("name", sorted(CHI))
@pytest.mark.parametrize("e", [0.05, 0.3, 0.5, 0.9, 1.0])
@pytest.mark.parametrize("v", [0.5, 13.0])
def test_restitution_laws_chi(name, e, v):
    """REFERENCE §3: P = K delta^a (1 + chi deltadot / v0), i.e. kappa = chi(e) K / v0."""
    p = seed_parameters(v, kappa=123.0)
    assert damping_factor(name, e) == pytest.approx(CHI[name](e), rel=1e-14, abs=1e-300)
    law = ContactLaw(name, restitution=e)
    assert law.kappa(p) == pytest.approx(CHI[name](e) * p.K / v, rel=1e-14, abs=1e-300)


def test_law_kappa_sources():
    """abrate is undamped; hunt-crossley/paper take params.kappa, or the exact inverse of e."""
    p = seed_parameters(kappa=3e9)
    assert ContactLaw("abrate").kappa(p) == 0.0
    assert ContactLaw("hunt-crossley").kappa(p) == 3e9
    assert ContactLaw("paper").kappa(p) == 3e9
    for name in ("hunt-crossley", "paper"):
        kappa = ContactLaw(name, restitution=0.6).kappa(p)
        assert exact_restitution(kappa * p.v / p.K) == pytest.approx(0.6, abs=1e-10)


@pytest.mark.parametrize(("kwargs", "named"), [
    (dict(name="hertz"), "law"),
    (dict(name=""), "law"),
    (dict(name="hunt-crossley", restitution=0.0), "restitution"),
    (dict(name="hunt-crossley", restitution=1.5), "restitution"),
    (dict(name="hunt-crossley", restitution=-0.2), "restitution"),
    (dict(name="hunt-crossley", restitution=float("nan")), "restitution"),
    (dict(name="hunt-crossley", restitution=float("inf")), "restitution"),
    (dict(name="lankarani-nikravesh", restitution=0.0), "restitution"),
    (dict(name="hunt-crossley", bilateral=True), "bilateral"),
    (dict(name="paper", bilateral=True), "bilateral"),
    (dict(name="flores", restitution=0.5, bilateral=True), "bilateral"),
    (dict(name="lankarani-nikravesh"), "restitution"),
    (dict(name="flores"), "restitution"),
    (dict(name="gonthier"), "restitution"),
    (dict(name="hunt-crossley-approx"), "restitution"),
    (dict(name="abrate", clamp=True), "clamp"),
    (dict(name="paper", clamp=True), "clamp"),
])
def test_contact_law_bad_input(kwargs, named):
    """ContactLaw validates its name and options; the ValueError names the offending parameter."""
    with pytest.raises(ValueError, match=named):
        ContactLaw(**kwargs)


def test_restitution_range_is_stated():
    with pytest.raises(ValueError, match=r"0 < e <= 1"):
        ContactLaw("hunt-crossley", restitution=1.5)
    with pytest.raises(ValueError, match="restitution"):
        kappa_for_restitution(0.0, seed_parameters())
    with pytest.raises(ValueError, match="law"):
        damping_factor("abrate", 0.5)
