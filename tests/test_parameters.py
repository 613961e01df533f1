"""Verification of the derived model parameters (REFERENCE §2; seed eq. 3-5, 7).

Expected values come from REFERENCE §2 (its printed seed values and its formulas, re-coded
here independently of :mod:`phaseimpact.parameters`) or from scaling laws of those formulas.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from phaseimpact import Geometry, Material, Parameters, derive_parameters, seed_parameters
from phaseimpact.parameters import STEEL, dotted_overrides

# ---------------------------------------------------------------------------------------------
# Seed values (REFERENCE §2 table, "seed value (check)" column)
# ---------------------------------------------------------------------------------------------


def test_seed_values_to_printed_digits():
    """REFERENCE §2: M1 0.263056 kg, M2 0.308269 kg, K 2.17570e10, Kb 1.20830e7, Km 1.65415e11."""
    p = seed_parameters()
    assert f"{p.M1:.6f}" == "0.263056"
    assert f"{p.M2:.6f}" == "0.308269"
    assert f"{p.K:.5e}" == "2.17570e+10"
    assert f"{p.Kb:.5e}" == "1.20830e+07"
    assert f"{p.Km:.5e}" == "1.65415e+11"


def test_seed_defaults():
    """REFERENCE §1-3: v = 1 m/s by default, alpha = 3/2, undamped, plate target (eq. 1)."""
    p = seed_parameters()
    assert (p.v, p.alpha, p.kappa, p.target) == (1.0, 1.5, 0.0, "plate")
    assert seed_parameters(13.0).v == 13.0


def test_seed_overrides_apply_and_leave_the_rest():
    """seed_parameters(..., M1=..., kappa=..., target=...) changes exactly the named fields."""
    base = seed_parameters()
    p = seed_parameters(5.0, M1=1.5, M2=0.25, kappa=1e9, target="free")
    assert (p.M1, p.M2, p.kappa, p.target, p.v) == (1.5, 0.25, 1e9, "free", 5.0)
    assert (p.K, p.Kb, p.Km, p.alpha) == (base.K, base.Kb, base.Km, base.alpha)


def test_shivakumar_membrane_changes_only_km():
    """REFERENCE §2 note: Shivakumar's (1-nu) instead of (1-nu^2) multiplies Km by (1-nu^2)/(1-nu)."""
    printed = seed_parameters()
    shiva = seed_parameters(membrane="shivakumar")
    nu = 0.3
    assert shiva.Km / printed.Km == pytest.approx((1 - nu**2) / (1 - nu), rel=1e-14)
    for name in ("M1", "M2", "K", "Kb", "alpha", "kappa", "v", "target"):
        assert getattr(shiva, name) == getattr(printed, name), name


def test_unknown_membrane_formula_is_rejected():
    with pytest.raises(ValueError, match="membrane") as info:
        seed_parameters(membrane="abrate")
    assert "printed" in str(info.value) and "shivakumar" in str(info.value)


# ---------------------------------------------------------------------------------------------
# Bad input: each field, each kind of bad value; the message names the field and its range
# ---------------------------------------------------------------------------------------------

MATERIAL = dict(E=2.1e11, nu=0.3, rho=7850.0)
GEOMETRY = dict(a=0.1, h=0.005, R1=0.02, R2=2e3)
PARAMETERS = dict(M1=0.26, M2=0.31, K=2.2e10, Kb=1.2e7, Km=1.7e11, alpha=1.5, kappa=1e9, v=1.0,
                  target="plate")

NAN, INF = float("nan"), float("inf")
POSITIVE_BAD = (-1.0, 0.0, NAN, INF, -INF)
NONNEGATIVE_BAD = (-1.0, -1e-300, NAN, INF, -INF)


def _bad_cases():
    cases = []  # (class, valid base fields, field, bad value, allowed range as printed)
    # physical ranges: beyond them a derived quantity over- or underflows (issue 24)
    for name, allowed, beyond in (("E", "1000 <= E <= 1e+13 (Pa)", (1e-308, 1e308, 999.0, 1.1e13)),
                                  ("rho", "0.1 <= rho <= 100000 (kg/m^3)", (1e-300, 1e308, 0.09))):
        cases += [(Material, MATERIAL, name, bad, allowed) for bad in POSITIVE_BAD + beyond]
    cases += [(Material, MATERIAL, "nu", bad, "0 <= nu < 0.5") for bad in (-0.1, 0.5, 0.7, NAN, INF)]
    for name in GEOMETRY:
        high = "1e+12" if name == "R2" else "1000"
        cases += [(Geometry, GEOMETRY, name, bad, f"1e-09 <= {name} <= {high} (m)")
                  for bad in POSITIVE_BAD + (1e-308, 1e308)]
    for name in ("M1", "M2", "K", "alpha"):
        cases += [(Parameters, PARAMETERS, name, bad, "> 0") for bad in POSITIVE_BAD]
    cases += [(Parameters, PARAMETERS, "v", bad, "1e-06 <= v <= 10000 (m/s)") for bad in POSITIVE_BAD + (1e300, 1e-7)]
    for name in ("Kb", "Km", "kappa"):
        cases += [(Parameters, PARAMETERS, name, bad, ">= 0") for bad in NONNEGATIVE_BAD]
    cases += [(Parameters, PARAMETERS, "target", bad, "plate, rigid, free")
              for bad in ("membrane", "", None, "Plate")]
    return [pytest.param(*case, id=f"{case[0].__name__}-{case[2]}-{case[3]!r}") for case in cases]


@pytest.mark.parametrize(("cls", "base", "name", "bad", "allowed"), _bad_cases())
def test_bad_field_raises_naming_parameter_and_range(cls, base, name, bad, allowed):
    """Every field is validated; the ValueError names the field and the allowed range."""
    with pytest.raises(ValueError) as info:
        cls(**{**base, name: bad})
    message = str(info.value)
    assert f"{name} =" in message
    assert allowed in message


@pytest.mark.parametrize(("cls", "base", "name"),
                         [(Material, MATERIAL, "nu"), (Parameters, PARAMETERS, "Kb"),
                          (Parameters, PARAMETERS, "Km"), (Parameters, PARAMETERS, "kappa")])
def test_zero_is_allowed_where_the_range_includes_it(cls, base, name):
    """nu = 0 (0 <= nu < 0.5) and zero stiffness/damping (>= 0) are valid."""
    assert getattr(cls(**{**base, name: 0.0}), name) == 0.0


@pytest.mark.parametrize("target", ["plate", "rigid", "free"])
def test_every_target_is_accepted(target):
    assert Parameters(**{**PARAMETERS, "target": target}).target == target


# ---------------------------------------------------------------------------------------------
# Replacing values re-validates
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize(("obj", "name", "bad"), [
    (seed_parameters(), "M1", -1.0), (seed_parameters(), "kappa", -1.0), (seed_parameters(), "v", 0.0),
    (seed_parameters(), "K", NAN), (seed_parameters(), "target", "wall"),
    (STEEL, "nu", 0.6), (STEEL, "E", 0.0), (Geometry(), "h", 0.0), (Geometry(), "R2", INF),
])
def test_dataclasses_replace_revalidates(obj, name, bad):
    """dataclasses.replace runs __post_init__ again: an invalid replacement raises ValueError."""
    with pytest.raises(ValueError, match=f"{name} ="):
        dataclasses.replace(obj, **{name: bad})
    if isinstance(obj, Parameters):
        with pytest.raises(ValueError, match=f"{name} ="):
            obj.replace(**{name: bad})


@pytest.mark.parametrize("name", [f.name for f in dataclasses.fields(Parameters)])
def test_replace_is_dataclasses_replace(name):
    """Parameters.replace (a copy of the fields, validated by __post_init__) gives what
    dataclasses.replace gives for a change of any field: every value and its type (ints and NumPy
    floats stored as floats), and nothing more in the instance."""
    p = seed_parameters()
    value = {"target": "rigid", "alpha": 2, "kappa": np.float64(3e9), "v": 13, "R": 0.01,
             "limiting_pressure": 3e8, "impedance": 1e3}.get(name)
    value = getattr(p, name) * 2 if value is None else value
    got, expected = p.replace(**{name: value}), dataclasses.replace(p, **{name: value})
    assert type(got) is Parameters and got.__dict__.keys() == expected.__dict__.keys()
    assert [(v, type(v)) for v in got.__dict__.values()] == [(expected.__dict__[k], type(expected.__dict__[k]))
                                                              for k in got.__dict__]
    assert getattr(got, name) == value


def test_replace_with_valid_values_keeps_the_rest():
    p = seed_parameters()
    q = p.replace(kappa=3e9, v=13.0)
    assert (q.kappa, q.v) == (3e9, 13.0)
    assert (q.M1, q.M2, q.K, q.Kb, q.Km, q.target) == (p.M1, p.M2, p.K, p.Kb, p.Km, p.target)


# ---------------------------------------------------------------------------------------------
# Property tests on the derivation (REFERENCE §2 formulas and their scaling laws)
# ---------------------------------------------------------------------------------------------

materials = st.builds(Material, E=st.floats(1e8, 1e12), nu=st.floats(0.0, 0.49), rho=st.floats(500.0, 2e4))
geometries = st.builds(Geometry, a=st.floats(0.01, 1.0), h=st.floats(1e-4, 0.05),
                       R1=st.floats(1e-4, 0.1), R2=st.floats(1e-3, 1e4))
scales = st.floats(0.1, 10.0)
PROPERTY = settings(max_examples=150, deadline=None)


def _reference_formulas(m1: Material, m2: Material, g: Geometry, membrane="printed"):
    """REFERENCE §2 table, re-coded: M1, M2, K (with eta restored), Kb (h^3), Km (eq. 5b)."""
    eta = (1 - m1.nu**2) / m1.E + (1 - m2.nu**2) / m2.E
    R = g.R1 * g.R2 / (g.R1 + g.R2)
    km_den = (1 - m2.nu**2) if membrane == "printed" else (1 - m2.nu)
    return dict(
        M1=m1.rho * 4 / 3 * math.pi * g.R1**3,
        M2=0.25 * m2.rho * math.pi * g.a**2 * g.h,
        K=4 * math.sqrt(R) / (3 * eta),
        Kb=4 * math.pi * m2.E * g.h**3 / (3 * (1 - m2.nu**2) * g.a**2),
        Km=(353 - 191 * m2.nu) * math.pi * m2.E * g.h / (648 * km_den * g.a**2),
    )


@PROPERTY
@given(materials, materials, geometries, st.sampled_from(["printed", "shivakumar"]))
def test_derivation_matches_reference_formulas(m1, m2, g, membrane):
    """REFERENCE §2 formulas, evaluated independently, to 1e-12 relative; all positive, finite."""
    p = derive_parameters(m1, m2, g, membrane=membrane)
    for name, expected in _reference_formulas(m1, m2, g, membrane).items():
        value = getattr(p, name)
        assert math.isfinite(value) and value > 0, name
        assert value == pytest.approx(expected, rel=1e-12), name


@PROPERTY
@given(materials, materials, geometries, scales)
def test_hertz_stiffness_scales_as_sqrt_of_effective_radius(m1, m2, g, s):
    """K = 4 sqrt(R)/(3 eta): scaling both radii by s scales R = R1 R2/(R1+R2) by s, K by sqrt(s)."""
    base = derive_parameters(m1, m2, g)
    scaled = derive_parameters(m1, m2, dataclasses.replace(g, R1=g.R1 * s, R2=g.R2 * s))
    assert scaled.K / base.K == pytest.approx(math.sqrt(s), rel=1e-12)


@PROPERTY
@given(materials, materials, geometries, scales)
def test_hertz_stiffness_scales_as_inverse_compliance(m1, m2, g, s):
    """K ∝ 1/eta: multiplying both Young's moduli by s divides eta (eq. 4) by s, multiplies K by s."""
    base = derive_parameters(m1, m2, g)
    scaled = derive_parameters(dataclasses.replace(m1, E=m1.E * s), dataclasses.replace(m2, E=m2.E * s), g)
    assert scaled.K / base.K == pytest.approx(s, rel=1e-12)


@PROPERTY
@given(materials, materials, geometries, scales, scales, scales)
def test_bending_stiffness_scales_as_E_h3_over_a2(m1, m2, g, sE, sh, sa):
    """Kb = 4 pi E h^3 / (3 (1-nu^2) a^2) (REFERENCE §2, eq. 5a with h^3): Kb ∝ E h^3 / a^2."""
    base = derive_parameters(m1, m2, g)
    scaled = derive_parameters(m1, dataclasses.replace(m2, E=m2.E * sE),
                               dataclasses.replace(g, h=g.h * sh, a=g.a * sa))
    assert scaled.Kb / base.Kb == pytest.approx(sE * sh**3 / sa**2, rel=1e-12)


@PROPERTY
@given(materials, materials, geometries, scales)
def test_projectile_mass_scales_as_radius_cubed(m1, m2, g, s):
    """M1 = rho 4/3 pi R1^3: M1 ∝ R1^3, and it does not depend on the plate."""
    base = derive_parameters(m1, m2, g)
    scaled = derive_parameters(m1, STEEL, dataclasses.replace(g, R1=g.R1 * s, a=g.a * 2, h=g.h / 2))
    assert scaled.M1 / base.M1 == pytest.approx(s**3, rel=1e-12)


@PROPERTY
@given(materials, materials, geometries, st.sampled_from(["M1", "M2", "K", "alpha", "v"]),
       st.sampled_from([-1.0, 0.0, NAN, INF]))
def test_replacing_derived_parameters_revalidates(m1, m2, g, name, bad):
    """A derived Parameters object re-validates on dataclasses.replace (positive fields)."""
    p = derive_parameters(m1, m2, g)
    with pytest.raises(ValueError, match=f"{name} ="):
        dataclasses.replace(p, **{name: bad})


# ---------------------------------------------------------------------------------------------
# Issue 12: every quantity settable by name; any real number type; yield strength; R
# ---------------------------------------------------------------------------------------------

def test_seed_parameters_accepts_geometry_and_material_names():
    """seed_parameters(v, R1=..., plate_E=...) equals derive_parameters with the changed inputs."""
    p = seed_parameters(13.0, a=0.2, h=0.002, R1=0.005, R2=1.0, projectile_E=7e10, projectile_nu=0.33,
                        projectile_rho=2700.0, plate_E=3.4e9, plate_nu=0.35, plate_rho=1200.0, kappa=1e9)
    expected = derive_parameters(Material(E=7e10, nu=0.33, rho=2700.0), Material(E=3.4e9, nu=0.35, rho=1200.0),
                                 Geometry(a=0.2, h=0.002, R1=0.005, R2=1.0), v=13.0, kappa=1e9)
    assert p == expected
    for name, value in _reference_formulas(Material(E=7e10, nu=0.33, rho=2700.0),
                                           Material(E=3.4e9, nu=0.35, rho=1200.0),
                                           Geometry(a=0.2, h=0.002, R1=0.005, R2=1.0)).items():
        assert getattr(p, name) == pytest.approx(value, rel=1e-12), name


def test_explicit_parameter_fields_win_over_the_derivation():
    p = seed_parameters(R1=0.005, M1=1.0, target="rigid", alpha=1.4)
    assert (p.M1, p.target, p.alpha) == (1.0, "rigid", 1.4)
    assert p.K == seed_parameters(R1=0.005).K


@pytest.mark.parametrize("name", ["G", "radius", "plate_G", "plate.E", "r1"])
def test_unknown_names_raise_value_error_listing_the_allowed(name):
    """Issue 12: seed_parameters(v, R1=...) used to raise a bare TypeError; unknown names must
    raise ValueError naming the parameter and listing the allowed names."""
    with pytest.raises(ValueError) as info:
        seed_parameters(**{name: 1.0})
    message = str(info.value)
    assert repr(name) in message
    for allowed in ("R1", "plate_E", "projectile_nu", "kappa", "target", "membrane"):
        assert allowed in message


def test_parameters_replace_rejects_unknown_names_with_value_error():
    with pytest.raises(ValueError, match="unknown parameter 'R1'"):
        seed_parameters().replace(R1=0.01)


@pytest.mark.parametrize(("name", "bad", "shown"), [
    ("plate_E", -1.0, "plate_E = -1.0"), ("projectile_nu", 0.5, "projectile_nu = 0.5"),
    ("plate_rho", 0.0, "plate_rho = 0.0"), ("R1", "abc", "R1 = 'abc'"), ("a", float("nan"), "a = nan"),
    ("plate_yield_strength", -5.0, "plate_yield_strength = -5.0"),
])
def test_bad_override_values_name_the_override(name, bad, shown):
    with pytest.raises(ValueError) as info:
        seed_parameters(**{name: bad})
    assert shown in str(info.value) and "allowed" in str(info.value)


def test_dotted_overrides():
    assert dotted_overrides({"plate.E": 1e9, "projectile.rho": 2650, "R1": 0.01}) == {
        "plate_E": 1e9, "projectile_rho": 2650, "R1": 0.01}
    assert seed_parameters(**dotted_overrides({"plate.E": 1e9})) == seed_parameters(plate_E=1e9)
    with pytest.raises(ValueError, match="'plate.G'"):
        dotted_overrides({"plate.G": 1.0})


NUMPY_VALUES = [np.float32(0.25), np.float64(0.25), np.int64(1), np.int32(2), 3, 0.5]


@pytest.mark.parametrize("value", NUMPY_VALUES, ids=lambda v: type(v).__name__)
def test_any_real_number_type_is_accepted_and_stored_as_float(value):
    """NumPy scalars and ints are numbers; the dataclasses store plain Python floats."""
    nu = float(value) if float(value) < 0.5 else 0.3
    m = Material(E=value * 1e9, nu=np.float32(nu) if isinstance(value, np.floating) else nu, rho=value * 1000,
                 yield_strength=value * 1e6)
    g = Geometry(a=value, h=value, R1=value, R2=value)
    p = Parameters(M1=value, M2=value, K=value, Kb=value, Km=value, alpha=value, kappa=value, v=value, R=value)
    for obj in (m, g, p):
        for f in dataclasses.fields(obj):
            stored = getattr(obj, f.name)
            assert stored is None or isinstance(stored, str) or type(stored) is float, (obj, f.name)
    assert p.v == float(value) and g.R1 == float(value)
    q = seed_parameters(np.float32(2.0), R1=np.float64(0.01), plate_nu=np.float32(0.25), kappa=np.int64(10))
    assert type(q.v) is float and q.v == 2.0 and type(q.kappa) is float


@pytest.mark.parametrize(("cls", "base", "name"), [(Material, MATERIAL, "E"), (Material, MATERIAL, "nu"),
                                                   (Geometry, GEOMETRY, "R1"), (Parameters, PARAMETERS, "v"),
                                                   (Parameters, PARAMETERS, "kappa")])
@pytest.mark.parametrize("bad", [True, False, np.bool_(True), "1.0", None, [1.0]])
def test_bools_strings_and_none_are_not_numbers(cls, base, name, bad):
    with pytest.raises(ValueError, match=f"{name} ="):
        cls(**{**base, name: bad})


def test_yield_strength_is_optional_and_positive():
    assert STEEL.yield_strength is None
    assert Material(**MATERIAL, yield_strength=2.5e8).yield_strength == 2.5e8
    for bad in (0.0, -1.0, NAN, INF, True, 1e308):
        with pytest.raises(ValueError, match=r"yield_strength =.*1000 <= yield_strength <= 1e\+12"):
            Material(**MATERIAL, yield_strength=bad)


def test_effective_radius_is_filled_and_optional():
    """REFERENCE §2: R = R1 R2/(R1+R2); derived parameters carry it, direct Parameters may omit it."""
    g = Geometry()
    assert seed_parameters().R == pytest.approx(g.R1 * g.R2 / (g.R1 + g.R2), rel=1e-15)
    assert seed_parameters(R1=0.01, R2=0.01).R == pytest.approx(0.005, rel=1e-15)
    assert Parameters(**PARAMETERS).R is None
    for bad in (0.0, -1.0, NAN):
        with pytest.raises(ValueError, match="R ="):
            Parameters(**PARAMETERS, R=bad)
