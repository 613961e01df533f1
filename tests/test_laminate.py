"""Laminates and impact regimes (docs/physics.md §8): classical lamination theory against a CLT
written out here (Jones' explicit Q-bar, not the module's matrix rotation) and against published
ply stiffnesses; the isotropic limit against eq. 5a/5b (closed forms here, and
derive_parameters as an independent oracle); Zener's lambda against the dimensional impact."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from phaseimpact.model import laminate as lam
from phaseimpact.model import plate_stiffness as stiff
from phaseimpact.model import regime
from phaseimpact.model.laminate import Laminate, Ply
from phaseimpact.parameters import Geometry, Material, derive_parameters

#: T300/5208 graphite/epoxy (Kaw, *Mechanics of Composite Materials*, 2nd ed., 2006, ch. 2's worked example of [Q]).
T300 = dict(E1=181e9, E2=10.3e9, G12=7.17e9, nu12=0.28, rho=1600.0, thickness=0.125e-3)


def layup(angles, ply=T300, **extra):
    return Laminate(tuple(Ply(angle=a, **ply, **extra) for a in angles))


def hand_q(E1, E2, G12, nu12, **_):
    nu21 = nu12 * E2 / E1
    d = 1 - nu12 * nu21
    return E1 / d, E2 / d, nu12 * E2 / d, G12


def hand_qbar(ply, angle):
    """Jones (1999, ch. 2), Q-bar term by term."""
    Q11, Q22, Q12, Q66 = hand_q(**ply)
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    q11 = Q11 * c**4 + 2 * (Q12 + 2 * Q66) * s**2 * c**2 + Q22 * s**4
    q12 = (Q11 + Q22 - 4 * Q66) * s**2 * c**2 + Q12 * (s**4 + c**4)
    q22 = Q11 * s**4 + 2 * (Q12 + 2 * Q66) * s**2 * c**2 + Q22 * c**4
    q16 = (Q11 - Q12 - 2 * Q66) * s * c**3 + (Q12 - Q22 + 2 * Q66) * s**3 * c
    q26 = (Q11 - Q12 - 2 * Q66) * s**3 * c + (Q12 - Q22 + 2 * Q66) * s * c**3
    q66 = (Q11 + Q22 - 2 * Q12 - 2 * Q66) * s**2 * c**2 + Q66 * (s**4 + c**4)
    return np.array([[q11, q12, q16], [q12, q22, q26], [q16, q26, q66]])


def hand_abd(angles, ply=T300):
    t = ply["thickness"]
    n = len(angles)
    z = [-n * t / 2 + k * t for k in range(n + 1)]
    A, B, D = np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3))
    for k, angle in enumerate(angles):
        q = hand_qbar(ply, angle)
        A += q * (z[k + 1] - z[k])
        B += q * (z[k + 1] ** 2 - z[k] ** 2) / 2
        D += q * (z[k + 1] ** 3 - z[k] ** 3) / 3
    return A, B, D


def close(x, y, rtol):
    """Matrices equal to ``rtol`` of the largest entry (zeros in one are rounding-level in the other)."""
    return np.allclose(x, y, rtol=0, atol=rtol * np.abs(y).max())


CROSS_PLY = (0, 90, 90, 0)
QUASI_ISOTROPIC = (0, 45, -45, 90, 90, -45, 45, 0)


def test_reduced_stiffness_matches_the_published_example():
    """Kaw (2006): Q11 = 181.8, Q12 = 2.897, Q22 = 10.35, Q66 = 7.17 GPa."""
    Q = Ply(angle=0, **T300).reduced_stiffness() / 1e9
    assert np.allclose([Q[0, 0], Q[0, 1], Q[1, 1], Q[2, 2]], [181.8, 2.897, 10.35, 7.17], rtol=1e-3)
    assert Q[0, 2] == Q[1, 2] == 0


@pytest.mark.parametrize("angle", [0, 15, 30, 45, -45, 60, 90, 137.5, -300])
def test_rotation_matches_jones_term_by_term(angle):
    assert close(lam.transformed_stiffness(Ply(angle=angle, **T300)), hand_qbar(T300, angle), 1e-13)


@pytest.mark.parametrize("angles", [CROSS_PLY, QUASI_ISOTROPIC, (0, 90), (30, -30, 10), (45, 0, -45, 90)])
def test_abd_matches_a_hand_written_clt(angles):
    (A, B, D), (A_hand, B_hand, D_hand) = layup(angles).abd(), hand_abd(angles)
    assert close(A, A_hand, 1e-12) and close(D, D_hand, 1e-12)
    # B's scale is A h (a symmetric layup's B is rounding in both)
    assert np.allclose(B, B_hand, rtol=0, atol=1e-12 * np.abs(A_hand).max() * layup(angles).thickness)


@pytest.mark.parametrize("angles", [CROSS_PLY, QUASI_ISOTROPIC, (30, -60, -60, 30)])
def test_symmetric_layups_have_no_coupling(angles):
    A, B, D = layup(angles).abd()
    assert np.abs(B).max() < 1e-12 * np.abs(A).max() * layup(angles).thickness


def test_cross_ply_is_specially_orthotropic():
    A, _, D = layup(CROSS_PLY).abd()
    for M in (A, D):
        assert abs(M[0, 2]) < 1e-14 * M[0, 0] and abs(M[1, 2]) < 1e-14 * M[0, 0]
    assert D[0, 0] > D[1, 1]  # the 0-degree plies are outside


def test_quasi_isotropic_a_is_isotropic_and_d16_equals_d26():
    """[0/+-45/90]s: A isotropic (A11 = A22, A66 = (A11 - A12)/2, A16 = A26 = 0); the +-45 pair
    at different depths leaves D16 = D26 = (Q11 - Q22)/4 times its z-moment, not zero."""
    A, _, D = layup(QUASI_ISOTROPIC).abd()
    assert math.isclose(A[0, 0], A[1, 1], rel_tol=1e-13)
    assert math.isclose(A[2, 2], (A[0, 0] - A[0, 1]) / 2, rel_tol=1e-13)
    assert abs(A[0, 2]) < 1e-13 * A[0, 0] and abs(A[1, 2]) < 1e-13 * A[0, 0]
    Q11, Q22, _, _ = hand_q(**T300)
    t = T300["thickness"]
    # +45 from -3t to -2t, -45 from -2t to -t (and mirrored): the +45 pair weighs (27 - 8) t^3 / 3
    # twice, the -45 pair (8 - 1) t^3 / 3 twice, with Q16(+-45) = +-(Q11 - Q22)/4
    expected = (Q11 - Q22) / 4 * 2 * ((27 - 8) - (8 - 1)) * t**3 / 3
    assert math.isclose(D[0, 2], expected, rel_tol=1e-12) and math.isclose(D[1, 2], expected, rel_tol=1e-12)


def test_unsymmetric_cross_ply_coupling():
    """[0/90] with the 0-degree ply on the impacted face (z < 0): B11 = -B22 = (Q22 - Q11) h^2 / 8,
    and the reduced bending stiffness is below D."""
    laminate = layup((0, 90))
    _, B, D = laminate.abd()
    Q11, Q22, _, _ = hand_q(**T300)
    h = laminate.thickness
    assert math.isclose(B[0, 0], (Q22 - Q11) * h**2 / 8, rel_tol=1e-12)
    assert math.isclose(B[1, 1], -B[0, 0], rel_tol=1e-12)
    reduced = laminate.reduced_bending_stiffness()
    assert reduced[0, 0] < D[0, 0] and reduced[1, 1] < D[1, 1]
    assert stiff.bending_stiffness(laminate, 0.1) < 16 * math.pi * stiff.lekhnitskii_rigidity(D) / 0.1**2


# ----------------------------------------------------------------------------------- isotropic limit

STEEL = dict(E=2.1e11, nu=0.3, rho=7850.0)
SEED_A, SEED_H = 0.1, 0.005


def isotropic_stacks():
    yield Laminate((Ply.isotropic(thickness=SEED_H, **STEEL),))
    yield Laminate(tuple(Ply.isotropic(thickness=SEED_H / 4, angle=a, **STEEL) for a in (0, 33, -71, 90)))
    yield Laminate(tuple(Ply.isotropic(thickness=t, angle=a, **STEEL) for t, a in ((0.001, 12), (0.003, 45),
                                                                                     (0.001, -5))))


@pytest.mark.parametrize("stack", list(isotropic_stacks()))
def test_isotropic_plies_reproduce_eq_5a_5b(stack):
    """Eq. 5a (with h^3) and 5b, printed and Shivakumar's, to 1e-12: written here and from
    derive_parameters (independent code)."""
    E, nu, h, a = STEEL["E"], STEEL["nu"], stack.thickness, SEED_A
    assert math.isclose(h, SEED_H, rel_tol=1e-15)
    kb = 4 * math.pi * E * h**3 / (3 * (1 - nu**2) * a**2)
    km = {"printed": (353 - 191 * nu) * math.pi * E * h / (648 * (1 - nu**2) * a**2),
          "shivakumar": (353 - 191 * nu) * math.pi * E * h / (648 * (1 - nu) * a**2)}
    assert math.isclose(stiff.bending_stiffness(stack, a), kb, rel_tol=1e-12)
    steel = Material(**STEEL)
    for form, expected in km.items():
        oracle = derive_parameters(steel, steel, Geometry(a=a, h=h), membrane=form)
        assert math.isclose(stiff.membrane_stiffness(stack, a, form), expected, rel_tol=1e-12)
        assert math.isclose(stiff.membrane_stiffness(stack, a, form), oracle.Km, rel_tol=1e-12)
        assert math.isclose(stiff.bending_stiffness(stack, a), oracle.Kb, rel_tol=1e-12)
    A, B, D = stack.abd()
    assert np.abs(B).max() < 1e-12 * A[0, 0] * h
    assert math.isclose(D[0, 0], E * h**3 / (12 * (1 - nu**2)), rel_tol=1e-12)
    assert math.isclose(stiff.olsson_rigidity(D), D[0, 0], rel_tol=1e-12)


def test_seed_plate_numbers():
    """docs/physics.md §2: Kb = 1.20830e7 N/m, Km = 1.65415e11 N/m^3 for the seed plate."""
    seed = next(isotropic_stacks())
    assert round(stiff.bending_stiffness(seed, SEED_A), -2) == 1.20830e7
    assert round(stiff.membrane_stiffness(seed, SEED_A) / 1e6) == 1.65415e5


def test_orthotropic_kb_and_km_closed_forms():
    """Cross-ply: Kb = 16 pi (3 D11 + 2 D12 + 4 D66 + 3 D22) / (8 a^2) from the hand D; the
    quasi-isotropic Km from its (isotropic) A: E h / (1 - nu^2) = A11 and nu = A12 / A11."""
    a = 0.15
    _, _, D = hand_abd(CROSS_PLY)
    d_star = (3 * D[0, 0] + 2 * D[0, 1] + 4 * D[2, 2] + 3 * D[1, 1]) / 8
    assert math.isclose(stiff.bending_stiffness(layup(CROSS_PLY), a), 16 * math.pi * d_star / a**2, rel_tol=1e-12)
    A, _, _ = hand_abd(QUASI_ISOTROPIC)
    nu = A[0, 1] / A[0, 0]
    expected = (353 - 191 * nu) * math.pi * A[0, 0] / (648 * a**2)
    assert math.isclose(stiff.membrane_stiffness(layup(QUASI_ISOTROPIC), a), expected, rel_tol=1e-12)


def test_isotropic_part_is_rotation_invariant():
    """U1, U4 of A do not change when every ply turns by the same angle (they are invariants)."""
    base = stiff.isotropic_part(layup((0, 30, -60)).abd()[0])
    turned = stiff.isotropic_part(layup((25, 55, -35)).abd()[0])
    assert np.allclose(base, turned, rtol=1e-12)


# ----------------------------------------------------------------------------------------- shear

def test_shear_stiffness_isotropic_closed_form_and_kbs():
    """Ks = 2 pi (5/6) G h / (1/2 + ln(a/c)) for an isotropic plate; 1/Kbs = 1/Kb + 1/Ks."""
    E, nu, h, a, c = 7e10, 0.33, 0.002, 0.1, 0.001
    stack = Laminate((Ply.isotropic(E, nu, 2700.0, h, shear=True),))
    G = E / (2 * (1 + nu))
    ks = 2 * math.pi * (5 / 6) * G * h / (0.5 + math.log(a / c))
    assert math.isclose(stiff.shear_stiffness(stack, a, c), ks, rel_tol=1e-12)
    kb = 4 * math.pi * E * h**3 / (3 * (1 - nu**2) * a**2)
    kbs = stiff.bending_shear_stiffness(stiff.bending_stiffness(stack, a), ks)
    assert math.isclose(1 / kbs, 1 / kb + 1 / ks, rel_tol=1e-12)


def test_shear_stiffness_does_not_depend_on_the_ply_angle():
    """sqrt(det) of the transverse shear stiffness: the same Ks for one ply at any angle, and
    k_s sqrt(G13 G23) h for it."""
    ply = dict(T300, G13=7.17e9, G23=3.5e9)
    values = [stiff.shear_stiffness(Laminate((Ply(angle=t, **ply),)), 0.05, 5e-4) for t in (0, 20, 45, 90)]
    expected = 2 * math.pi * (5 / 6) * math.sqrt(7.17e9 * 3.5e9) * T300["thickness"] / (0.5 + math.log(100))
    assert np.allclose(values, expected, rtol=1e-12)


def test_shear_needs_moduli_and_a_load_radius_inside_the_plate():
    with pytest.raises(ValueError, match=r"G13 = None is out of range"):
        stiff.shear_stiffness(layup(CROSS_PLY), 0.1, 0.001)
    stack = Laminate((Ply.isotropic(7e10, 0.33, 2700.0, 0.002, shear=True),))
    with pytest.raises(ValueError, match=r"load_radius = 0.2 is out of range; allowed: 0 < load_radius < a = 0.1"):
        stiff.shear_stiffness(stack, 0.1, 0.2)
    with pytest.raises(ValueError, match=r"Ks = -1.0 is out of range"):
        stiff.bending_shear_stiffness(1.0, -1.0)


# --------------------------------------------------------------------------------------- contact

def test_contact_compliances():
    """Yang and Sun: 1/E2 of the top ply. The exact transversely isotropic term gives (1 - nu^2)/E
    for an isotropic solid, so Yang-Sun overstates an isotropic face's compliance by 1/(1 - nu^2)."""
    assert stiff.yang_sun_compliance(Ply(angle=30, **T300)) == 1 / T300["E2"]
    for E, nu in ((2.1e11, 0.3), (3e9, 0.38), (7e10, 0.0)):
        exact = stiff.transversely_isotropic_compliance(E, nu, E, nu, E / (2 * (1 + nu)))
        assert math.isclose(exact, (1 - nu**2) / E, rel_tol=1e-12)
        ply = Ply.isotropic(E, nu, 1000.0, 1e-3)
        assert math.isclose(stiff.yang_sun_compliance(ply) / exact, 1 / (1 - nu**2), rel_tol=1e-12)


def test_transversely_isotropic_compliance_scales_and_checks():
    base = stiff.transversely_isotropic_compliance(10e9, 0.3, 5e9, 0.2, 3e9)
    assert math.isclose(stiff.transversely_isotropic_compliance(20e9, 0.3, 10e9, 0.2, 6e9), base / 2, rel_tol=1e-12)
    assert base > stiff.transversely_isotropic_compliance(10e9, 0.3, 5e9, 0.2, 6e9)  # stiffer in shear
    with pytest.raises(ValueError, match=r"nu_p = 1.2, nu_tp = 0.2 are out of range"):
        stiff.transversely_isotropic_compliance(10e9, 1.2, 5e9, 0.2, 3e9)


# ------------------------------------------------------------------------------------ validation

@pytest.mark.parametrize(("change", "message"), [
    (dict(E1=-1.0), r"E1 = -1.0 is out of range; allowed: 1000 <= E1 <= 1e\+13 \(Pa\)"),
    (dict(E2=2.1e14), r"E2 = 210000000000000.0 is out of range"),
    (dict(nu12=5.0), r"nu12 = 5.0 is out of range; allowed: \|nu12\| < sqrt\(E1/E2\) = 4.19"),
    (dict(rho=0.0), r"rho = 0.0 is out of range; allowed: 0.1 <= rho <= 100000 \(kg/m\^3\)"),
    (dict(angle=float("nan")), r"angle = nan is out of range; allowed: -360 <= angle <= 360 \(degrees\)"),
    (dict(thickness=0.0), r"thickness = 0.0 is out of range"),
    (dict(G13=1e9), r"G13 = 1000000000.0 is out of range; allowed: both G13 and G23"),
    (dict(G13=1e9, G23=-2.0), r"G23 = -2.0 is out of range"),
    (dict(E1="1e11"), r"E1 = '1e11' is out of range"),
])
def test_ply_refuses_bad_values_naming_them(change, message):
    with pytest.raises(ValueError, match=message):
        Ply(**{**T300, "angle": 0, **change})


def test_validate_ply_names_the_case_file_field():
    """A case file's [[plate.ply]] table is checked with its place in the message."""
    table = {**T300, "angle": 0}
    lam.validate_ply(table)
    with pytest.raises(ValueError, match=r"plate.ply\[2\].nu12 = 5.0 is out of range; allowed: \|nu12\| < sqrt"):
        lam.validate_ply({**table, "nu12": 5.0}, prefix="plate.ply[2].")
    with pytest.raises(ValueError, match=r"plate.ply\[0\]: missing thickness, unknown E3; allowed: E1, E2"):
        lam.validate_ply({**{k: v for k, v in table.items() if k != "thickness"}, "E3": 1e10}, prefix="plate.ply[0].")


def test_laminate_refuses_empty_and_mixed_shear():
    with pytest.raises(ValueError, match=r"plies = \(\) is out of range; allowed: a non-empty sequence of Ply"):
        Laminate(())
    with pytest.raises(ValueError, match=r"plies = .* allowed: a non-empty sequence of Ply"):
        Laminate((Ply(angle=0, **T300), "ply"))
    with pytest.raises(ValueError, match=r"G13 = \[None, 7000000000.0\] is out of range; allowed: given for every ply"):
        Laminate((Ply(angle=0, **T300), Ply(angle=90, G13=7e9, G23=3e9, **T300)))
    with pytest.raises(ValueError, match=r"a = 0.0 is out of range"):
        stiff.bending_stiffness(layup(CROSS_PLY), 0.0)
    with pytest.raises(ValueError, match=r"membrane = 'shivakumr' is out of range"):
        stiff.membrane_stiffness(layup(CROSS_PLY), 0.1, "shivakumr")


def test_laminate_sums_and_interfaces():
    stack = Laminate([Ply(angle=0, **{**T300, "thickness": t, "rho": r}) for t, r in ((1e-3, 1000.0), (3e-3, 2000.0))])
    assert isinstance(stack.plies, tuple)
    assert stack.thickness == 4e-3 and math.isclose(stack.areal_density, 7.0, rel_tol=1e-15)
    assert np.allclose(stack.interfaces(), [-2e-3, -1e-3, 2e-3], rtol=0, atol=1e-18)


# ---------------------------------------------------------------------------------------- regime

def test_impedance_and_plate_mass_of_the_seed_plate():
    """REFERENCE §8: c = 2457.328 N s/m for the seed plate; its mass is four times M2 (0.308269 kg)."""
    D = 2.1e11 * SEED_H**3 / (12 * (1 - 0.3**2))
    assert round(regime.infinite_plate_impedance(D, 7850.0 * SEED_H), 3) == 2457.328
    assert round(regime.plate_mass(7850.0 * SEED_H, SEED_A) / 4, 6) == 0.308269


def test_olsson_rigidity_closed_form():
    _, _, D = hand_abd(CROSS_PLY)
    A = (D[0, 1] + 2 * D[2, 2]) / math.sqrt(D[0, 0] * D[1, 1])
    expected = math.sqrt(D[0, 0] * D[1, 1] * (A + 1) / 2)
    assert math.isclose(stiff.olsson_rigidity(layup(CROSS_PLY).abd()[2]), expected, rel_tol=1e-12)
    assert expected != pytest.approx(math.sqrt(D[0, 0] * D[1, 1]), rel=1e-3)  # A != 1 here: a real test


def _restitution(m, v, K, c):
    """Ball (m, v) with Hertz contact K delta^1.5 on a dashpot c: integrated in its own units."""
    def rhs(t, y):
        P = K * max(y[0] - y[2], 0.0) ** 1.5
        return [y[1], -P / m, P / c]

    def parted(t, y):
        return y[0] - y[2]
    parted.terminal, parted.direction = True, -1
    T = 3.3 * (m * m / (K * K * v)) ** 0.2
    run = solve_ivp(rhs, (0, 200 * T), [0.0, v, 0.0], method="DOP853", rtol=1e-12, atol=1e-18 * v * T,
                    events=parted, first_step=1e-6 * T)
    return -run.y_events[0][0][1] / v


def test_zener_lambda_alone_sets_the_restitution():
    """Two Hertz impacts on infinite plates with the code's lambda equal (different sizes, masses,
    speeds) rebound alike to 1e-9; a lambda off by a power would not. lambda -> 0: e -> 1."""
    m1, v1, K1, c1 = 2.63056e-4, 1.0, 6.87677e9, 2457.328  # REFERENCE §8's check: e = 0.958
    m2, v2, K2 = 0.05, 7.0, 3e9
    lam1 = regime.zener_lambda(m1, v1, K1, c1)
    c2 = c1 * regime.zener_lambda(m2, v2, K2, c1) / lam1  # lambda is proportional to 1/c
    assert math.isclose(regime.zener_lambda(m2, v2, K2, c2), lam1, rel_tol=1e-14)
    e1, e2 = _restitution(m1, v1, K1, c1), _restitution(m2, v2, K2, c2)
    assert round(e1, 3) == 0.958
    assert abs(e1 - e2) < 1e-9
    assert 1 - _restitution(m1, v1, K1, c1 * 1e4) < 2 * lam1 / 1e4


def test_zener_lambda_isotropic_closed_form():
    """Zener's form for an isotropic ball on an isotropic plate, written out (docs/physics.md §8)."""
    R1, h, v = 0.003, 0.004, 4.0
    E1, nu1, rho1, E2, nu2, rho2 = 2.1e11, 0.3, 7850.0, 7e10, 0.33, 2700.0
    m = rho1 * 4 / 3 * math.pi * R1**3
    K = 4 * math.sqrt(R1) / (3 * ((1 - nu1**2) / E1 + (1 - nu2**2) / E2))
    c = 8 * math.sqrt(E2 * h**3 / (12 * (1 - nu2**2)) * rho2 * h)
    c0 = math.sqrt(E2 / (rho2 * (1 - nu2**2)))
    zener = (math.pi**0.6 / math.sqrt(3) * (R1 / h) ** 2 * (v / c0) ** 0.2 * (rho1 / rho2) ** 0.6
             * (1 + E2 * (1 - nu1**2) / (E1 * (1 - nu2**2))) ** -0.4)
    assert math.isclose(regime.zener_lambda(m, v, K, c), zener, rel_tol=1e-12)


def test_mass_criterion():
    """Olsson (2000): wave-controlled below 0.23, quasi-static above 2; a sand grain on a panel is
    deep in the first."""
    grain = 2650.0 * 4 / 3 * math.pi * 50e-6**3
    assert regime.impact_regime(regime.mass_ratio(grain, 0.1)) == "wave-controlled"
    assert [regime.impact_regime(r) for r in (0.2299, 0.23, 2.0, 2.0001)] == [
        "wave-controlled", "boundary-controlled", "boundary-controlled", "quasi-static"]
    assert [regime.model_for_regime(r) for r in regime.REGIMES] == ["infinite", "plate", "plate"]
    with pytest.raises(ValueError, match=r"regime = 'ballistic' is out of range"):
        regime.model_for_regime("ballistic")
    with pytest.raises(ValueError, match=r"M1 = -1.0 is out of range; allowed: a finite number > 0 \(kg\)"):
        regime.mass_ratio(-1.0, 1.0)
    with pytest.raises(ValueError, match=r"impedance = nan is out of range"):
        regime.zener_lambda(1.0, 1.0, 1.0, float("nan"))
    with pytest.raises(ValueError, match=r"D11 = -1.0 is out of range"):
        stiff.olsson_rigidity(-np.eye(3))
