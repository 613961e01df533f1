"""Cases, case files and --set settings (issue 12; REFERENCE §2); contact mechanics: test_contact.py.

Expected values come from REFERENCE §2 and §4 (printed digits), from the closed forms of Hertz
impact re-derived here or checked against a numerical integration of ``m delta'' = -K delta^1.5``,
and from the issue's own estimates for sand on a gelcoat (contact about 0.3 µs, peak pressure
near 1 GPa, about ten times the gelcoat's compressive strength).
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from phaseimpact import seed_parameters
from phaseimpact.case import Case, case_from_dict, list_cases, load_case, seed_case
from phaseimpact.model.contact import hertz_scales, validity
from phaseimpact.parameters import Geometry, Material
from phaseimpact.settings import SETTABLE, apply_settings, parse_setting

CASES_DIR = Path(__file__).resolve().parents[1] / "phaseimpact" / "cases"
SHIPPED = sorted(p.stem for p in CASES_DIR.glob("*.toml"))

# ---------------------------------------------------------------------------------------------
# Shipped cases
# ---------------------------------------------------------------------------------------------


def test_the_issue_s_cases_are_shipped():
    """Issue 12 §3: the seed, sand/dust on gelcoat, LEP coating and laminate, and hail."""
    assert {"seed", "sand-gelcoat", "sand-lep", "sand-laminate", "hail-laminate"} <= set(SHIPPED)
    listed = list_cases()
    assert [c["name"] for c in listed][0] == "seed"
    assert sorted(c["name"] for c in listed) == SHIPPED
    assert all(set(c) == {"name", "description", "source"} for c in listed)


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_case_loads_with_sources_and_finite_parameters(name):
    case = load_case(name)
    assert case.name == name  # the name in the file is the name load_case takes
    assert case.description and len(case.source) > 40  # every case cites where its numbers come from
    p = case.parameters()
    for key in ("M1", "M2", "K", "Kb", "Km", "v", "R"):
        value = getattr(p, key)
        assert math.isfinite(value) and value > 0, key
    scales = hertz_scales(p, case.plate)
    assert all(math.isfinite(scales[k]) and scales[k] > 0 for k in
               ("contact_time", "indentation", "peak_force", "contact_radius", "peak_pressure"))
    assert isinstance(validity(p, case.plate, case.projectile), str)


@pytest.mark.parametrize("name", [n for n in SHIPPED if n != "seed"])
def test_assumed_values_are_marked_in_the_source(name):
    """Issue 12 §3: 'mark assumed values' (in the source text as well as in comments)."""
    assert "assumed" in load_case(name).source.lower()


def test_seed_case_is_reference_section_2():
    """REFERENCE §2: the seed file, the programmatic seed case and seed_parameters() agree."""
    case = load_case("seed")
    assert case == seed_case()
    assert case.parameters() == seed_parameters()
    p = case.parameters()
    assert f"{p.M1:.6f}" == "0.263056" and f"{p.K:.5e}" == "2.17570e+10"
    assert case.impact == {"v": 1.0, "kappa": 0.0, "target": "plate", "law": "paper", "contact": "printed",
                           "restitution": None, "law_file": None}


def test_case_parameters_overrides():
    """Case.parameters(**overrides): v, kappa, target, geometry and dotted material names win."""
    case = load_case("seed")
    p = case.parameters(v=5.0, kappa=1e9, target="rigid", R1=0.01, **{"plate.E": 7e10})
    q = seed_parameters(5.0, kappa=1e9, target="rigid", R1=0.01, plate_E=7e10)
    assert p == q
    assert p.M1 == pytest.approx(case.parameters().M1 / 8, rel=1e-14)  # M1 ∝ R1^3
    with pytest.raises(ValueError, match="unknown parameter 'G'"):
        case.parameters(G=1.0)


# ---------------------------------------------------------------------------------------------
# TOML round trip and bad files
# ---------------------------------------------------------------------------------------------

def _custom_case(**impact) -> Case:
    return Case(name="custom \"quoted\" ünïcode", description="tab\there", source="line1\nline2 \\ backslash",
                projectile=Material(E=np.float32(7e10), nu=np.int64(0), rho=2700),
                plate=Material(E=3e9, nu=0.35, rho=1200.0, yield_strength=8e7),
                geometry=Geometry(a=0.2, h=0.002, R1=1e-4, R2=0.5),
                impact={"v": 42, "kappa": 1e6, "target": "free", "law": "paper", "contact": "unilateral", **impact})


@pytest.mark.parametrize("case", [load_case(n) for n in SHIPPED] + [
    _custom_case(), _custom_case(law="hunt-crossley", kappa=0.0, contact="printed", restitution=0.5)],
    ids=SHIPPED + ["custom", "custom-restitution"])
def test_toml_round_trip(case, tmp_path):
    """as_dict -> TOML -> load_case gives an equal case; as_dict is plain JSON."""
    path = case.save(tmp_path / "case.toml")
    assert load_case(path) == case
    assert load_case(str(path)) == case
    data = json.loads(json.dumps(case.as_dict()))
    assert case_from_dict(data) == case


def test_numbers_are_stored_as_plain_floats():
    case = _custom_case()
    assert type(case.projectile.E) is float and type(case.projectile.nu) is float
    assert type(case.impact["v"]) is float and case.impact["v"] == 42.0


def test_defaults_of_optional_keys_and_name_from_the_file(tmp_path):
    path = tmp_path / "my-case.toml"
    path.write_text(_seed_text().replace('name = "seed"\n', ""), encoding="utf-8")
    case = load_case(path)
    assert case.name == "my-case"
    assert case.impact["kappa"] == 0.0 and case.impact["contact"] == "printed" and case.impact["restitution"] is None


def _seed_text() -> str:
    return (CASES_DIR / "seed.toml").read_text(encoding="utf-8")


def _replace_line(text: str, table: str, key: str, new: str | None) -> str:
    """Replace (or, with ``new=None``, delete) line ``key = ...`` inside ``[table]``."""
    lines, current = text.splitlines(), ""
    for i, line in enumerate(lines):
        if line.startswith("["):
            current = line.split("]")[0][1:]
        elif current == table and line.split("=")[0].strip() == key:
            lines[i:i + 1] = [] if new is None else [new]
            return "\n".join(lines) + "\n"
    raise AssertionError(f"{table}.{key} not in the seed file")


def _drop_table(text: str, table: str) -> str:
    out, skip = [], False
    for line in text.splitlines():
        if line.startswith("["):
            skip = line.startswith(f"[{table}]")
        if not skip:
            out.append(line)
    return "\n".join(out) + "\n"


BAD_FILES = {
    "unknown key": (lambda t: t.replace("[plate]", "[plate]\nG = 8e10", 1), ["'plate.G'", "E, nu, rho"]),
    "unknown top-level key": (lambda t: "speed = 3.0\n" + t, ["'speed'"]),
    "unknown table": (lambda t: t + "\n[damping]\nkappa = 1.0\n", ["'damping'"]),
    "missing [plate]": (lambda t: _drop_table(t, "plate"), ["[plate]"]),
    "missing plate.E": (lambda t: _replace_line(t, "plate", "E", None), ["'plate.E'"]),
    "missing geometry.h": (lambda t: _replace_line(t, "geometry", "h", None), ["'geometry.h'", "> 0"]),
    # physical ranges (issue 24): the input is named, never a derived quantity ("Kb = inf", "M1 = 0.0")
    "E huge": (lambda t: _replace_line(t, "plate", "E", "E = 1e308"), ["plate.E = 1e+308", "1000 <= plate.E <= 1e+13"]),
    "E tiny": (lambda t: _replace_line(t, "plate", "E", "E = 1e-308"), ["plate.E = 1e-308", "(Pa)"]),
    "rho tiny": (lambda t: _replace_line(t, "plate", "rho", "rho = 1e-300"), ["plate.rho = 1e-300", "kg/m^3"]),
    "R1 huge": (lambda t: _replace_line(t, "geometry", "R1", "R1 = 1e308"), ["geometry.R1 = 1e+308", "<= 1000 (m)"]),
    "v huge": (lambda t: _replace_line(t, "impact", "v", "v = 1e300"), ["impact.v = 1e+300", "<= 10000 (m/s)"]),
    "kappa huge": (lambda t: t + "kappa = 1e30\n", ["impact.kappa = 1e+30", "<= 1e+18"]),
    # values the case's law never reads (issue 24): refused, not silently ignored
    "abrate with kappa": (lambda t: t + 'law = "abrate"\nkappa = 1e9\n', ["impact.kappa = 1000000000.0",
                                                                        "not read by law 'abrate'", "undamped"]),
    "flores with kappa": (lambda t: t + 'law = "flores"\nrestitution = 0.5\nkappa = 1e9\n',
                          ["impact.kappa", "not read by law 'flores'", "restitution"]),
    "paper with restitution": (lambda t: t + "restitution = 0.5\n", ["impact.restitution = 0.5",
                                                                     "not read by law 'paper'", "gonthier"]),
    "hunt-crossley with contact": (lambda t: t + 'law = "hunt-crossley"\ncontact = "unilateral"\n',
                                   ["impact.contact = 'unilateral'", "not read by law 'hunt-crossley'"]),
    "multiline description": (lambda t: re.sub(r"^description = .*$", 'description = """two\nlines"""', t,
                                               flags=re.M),
                              ["description = 'two\\nlines'", "one line"]),
    "missing impact.v": (lambda t: _replace_line(t, "impact", "v", None), ["'impact.v'"]),
    "nu = 0.7": (lambda t: _replace_line(t, "plate", "nu", "nu = 0.7"), ["plate.nu = 0.7", "0 <= nu < 0.5"]),
    "E = -1": (lambda t: _replace_line(t, "projectile", "E", "E = -1"), ["projectile.E = -1", "<= projectile.E <="]),
    "E a string": (lambda t: _replace_line(t, "plate", "E", 'E = "2e11"'), ["plate.E = '2e11'", "wrong type"]),
    "E a boolean": (lambda t: _replace_line(t, "plate", "E", "E = true"), ["plate.E = True", "wrong type"]),
    "R1 = 0": (lambda t: _replace_line(t, "geometry", "R1", "R1 = 0.0"), ["geometry.R1 = 0.0", "1e-09 <= geometry.R1"]),
    "yield_strength = 0": (lambda t: t.replace("[plate]", "[plate]\nyield_strength = 0.0", 1),
                           ["plate.yield_strength = 0.0", "1000 <= plate.yield_strength"]),
    "v = nan": (lambda t: _replace_line(t, "impact", "v", "v = nan"), ["impact.v = nan", "1e-06 <= impact.v"]),
    "target": (lambda t: t + 'target = "wall"\n', ["impact.target = 'wall'", "plate, rigid, free"]),
    "contact": (lambda t: t + 'contact = "both"\n', ["impact.contact = 'both'", "printed, unilateral"]),
    "law": (lambda t: t + 'law = "newton"\n', ["impact.law = 'newton'", "paper"]),
    "restitution": (lambda t: t + "restitution = 1.5\n", ["impact.restitution = 1.5", "<= impact.restitution <= 1"]),
    "kappa < 0": (lambda t: t + "kappa = -1.0\n", ["impact.kappa = -1.0", "0 <= impact.kappa"]),
    "name not a string": (lambda t: t.replace('name = "seed"', "name = 3"), ["name = 3", "wrong type"]),
    "table not a table": (lambda t: "geometry = 1.0\n" + _drop_table(t, "geometry"), ["geometry = 1.0"]),
    "syntax error": (lambda t: t.replace("E = 2.1e11", "E = 2.1e11 Pa", 1), ["TOML syntax error", "line"]),
}


@pytest.mark.parametrize("label", list(BAD_FILES))
def test_bad_case_file_raises_naming_file_key_value_and_range(label, tmp_path):
    edit, expected = BAD_FILES[label]
    path = tmp_path / "bad.toml"
    path.write_text(edit(_seed_text()), encoding="utf-8")
    with pytest.raises(ValueError) as info:
        load_case(path)
    message = str(info.value)
    assert message.startswith(str(path) + ":")
    for part in expected:
        assert part in message, (part, message)


def test_unknown_name_and_missing_file():
    with pytest.raises(ValueError, match="unknown case 'granite'.*sand-gelcoat"):
        load_case("granite")
    with pytest.raises(ValueError, match="nowhere.toml: cannot read"):
        load_case("nowhere.toml")


# ---------------------------------------------------------------------------------------------
# --set NAME=VALUE
# ---------------------------------------------------------------------------------------------

def test_settable_names_are_every_key_of_the_case_schema():
    """Issue 24: --set takes every key of the schema but the text ones (name, description, source)."""
    schema = [f"{body}.{key}" for body in ("projectile", "plate") for key in ("E", "nu", "rho", "yield_strength")]
    schema += ["a", "h", "R1", "R2", "v", "kappa", "restitution", "target", "law", "contact"]
    assert sorted(SETTABLE) == sorted(schema)
    assert SETTABLE["plate.E"][0] == "Pa" and SETTABLE["R1"][0] == "m" and SETTABLE["v"][0] == "m/s"


def test_impact_settings_and_the_schema_s_own_spellings():
    case = seed_case().with_settings(["impact.law=flores", "restitution=0.5", "geometry.R1=0.01",
                                      "projectile.yield_strength=1e9", "impact.target=rigid"])
    assert (case.impact["law"], case.impact["restitution"], case.impact["target"]) == ("flores", 0.5, "rigid")
    assert case.geometry.R1 == 0.01 and case.projectile.yield_strength == 1e9
    assert parse_setting("impact.kappa=1e9") == ("kappa", 1e9)
    with pytest.raises(ValueError, match="impact.target = 'wall'"):
        seed_case().with_settings(["target=wall"])


def test_settings_apply_and_leave_the_rest():
    case = seed_case()
    new = case.with_settings(["plate.E=1e9", "R1 = 0.001", "v=13", "plate.yield_strength=2.5e8", "R1=0.002"])
    assert new.plate.E == 1e9 and new.plate.yield_strength == 2.5e8 and new.plate.nu == case.plate.nu
    assert new.geometry.R1 == 0.002  # the later setting wins
    assert new.impact["v"] == 13.0 and new.impact["law"] == case.impact["law"]
    assert (new.projectile, new.geometry.a, new.geometry.h, new.geometry.R2) == (
        case.projectile, case.geometry.a, case.geometry.h, case.geometry.R2)
    assert apply_settings(case, {"plate.E": "1e9", "a": 0.2}) == dataclasses.replace(
        case, plate=dataclasses.replace(case.plate, E=1e9), geometry=dataclasses.replace(case.geometry, a=0.2))
    assert parse_setting("projectile.rho=2650") == ("projectile.rho", 2650.0)


@pytest.mark.parametrize(("setting", "expected"), [
    ("plate.G=1e9", ["unknown setting 'plate.G'", "projectile.E (Pa)", "R2 (m)"]),
    ("impact.damping=1e9", ["unknown setting 'impact.damping'"]),
    ("R1=abc", ["R1 = 'abc' is not a number", "m"]),
    ("plate.E", ["NAME=VALUE", "plate.nu"]),
    ("plate.nu=0.7", ["plate.nu = 0.7", "0 <= nu < 0.5"]),
    ("plate.E=-1", ["plate.E = -1.0", "1000 <= plate.E"]),
    ("h=0", ["h = 0.0", "1e-09 <= h"]),
    ("v=inf", ["v = inf", "1e-06 <= v <= 10000"]),
    ("plate.yield_strength=0", ["plate.yield_strength = 0.0", "1000 <= plate.yield_strength"]),
    ("R1=1e308", ["R1 = 1e+308", "R1 <= 1000 (m)"]),
    ("a=1e-308", ["a = 1e-308", "1e-09 <= a"]),
    ("projectile.rho=1e-300", ["projectile.rho = 1e-300", "0.1 <= projectile.rho"]),
    ("plate.E=1e308", ["plate.E = 1e+308", "plate.E <= 1e+13"]),
])
def test_bad_settings_raise_naming_the_setting(setting, expected):
    with pytest.raises(ValueError) as info:
        seed_case().with_settings([setting])
    for part in expected:
        assert part in str(info.value), (part, str(info.value))


# ---------------------------------------------------------------------------------------------
# Laminate plates: [[plate.ply]] (issue 40 item 1)
# ---------------------------------------------------------------------------------------------

STEEL_PLY = {"E1": 2.1e11, "E2": 2.1e11, "G12": 2.1e11 / 2.6, "nu12": 0.3, "rho": 7850.0}


def _laminate_toml(plies, geometry="a = 0.1\nR1 = 0.02\nR2 = 2000.0", plate_extra="") -> str:
    text = "[projectile]\nE = 2.1e11\nnu = 0.3\nrho = 7850.0\n\n[plate]\n" + plate_extra + "\n"
    for ply in plies:
        text += "\n[[plate.ply]]\n" + "\n".join(f"{k} = {v!r}" for k, v in ply.items()) + "\n"
    return text + f"\n[geometry]\n{geometry}\n\n[impact]\nv = 1.0\n"


def _load_text(tmp_path, text):
    path = tmp_path / "lam.toml"
    path.write_text(text, encoding="utf-8")
    return load_case(path)


@pytest.mark.parametrize("angles", [(0.0,), (0.0, 30.0), (0.0, 45.0, -45.0, 90.0)])
def test_isotropic_plies_in_a_case_file_give_the_seed_numbers(tmp_path, angles):
    """A steel plate given as plies (any number, any angles) keeps eq. 3-5's numbers to 1e-12."""
    plies = [{**STEEL_PLY, "angle": t, "thickness": 0.005 / len(angles)} for t in angles]
    case = _load_text(tmp_path, _laminate_toml(plies))
    assert case.geometry.h == pytest.approx(0.005, rel=1e-15)
    seed, laminate = seed_parameters(v=1.0), case.parameters()
    for name in ("M1", "M2", "K", "Kb", "Km", "R"):
        assert math.isclose(getattr(laminate, name), getattr(seed, name), rel_tol=1e-12), name
    shivakumar = case.parameters(membrane="shivakumar").Km
    assert math.isclose(shivakumar, seed_parameters(v=1.0, membrane="shivakumar").Km, rel_tol=1e-12)


def test_shear_moduli_switch_on_abrates_bending_shear_stiffness(tmp_path):
    """With G13, G23: 1/Kbs = 1/Kb + 1/Ks, Ks = 2 pi k G h / (1/2 + ln(a/c)) at the Hertz contact
    radius c = sqrt(R delta), delta = (5 m v^2 / (4 K))^(2/5) (closed forms here)."""
    G = STEEL_PLY["G12"]
    case = _load_text(tmp_path, _laminate_toml([{**STEEL_PLY, "G13": G, "G23": G, "angle": 0.0, "thickness": 0.005}]))
    p, seed = case.parameters(v=3.0), seed_parameters(v=3.0)
    mass = seed.M1 * seed.M2 / (seed.M1 + seed.M2)
    c = math.sqrt(seed.R * (5 * mass * 3.0**2 / (4 * seed.K)) ** 0.4)
    Ks = 2 * math.pi * (5 / 6) * G * 0.005 / (0.5 + math.log(0.1 / c))
    assert math.isclose(p.Kb, 1 / (1 / seed.Kb + 1 / Ks), rel_tol=1e-12)
    assert p.Kb < seed.Kb and case.parameters(v=30.0).Kb > p.Kb  # a wider contact: less shear deflection


def test_laminate_case_file_errors_name_the_key(tmp_path):
    ply = {**STEEL_PLY, "angle": 0.0, "thickness": 0.0025}
    cases = [
        (_laminate_toml([ply, ply], geometry="a = 0.1\nh = 0.006\nR1 = 0.02\nR2 = 2000.0"),
         "geometry.h = 0.006 is out of range; allowed: the plies' total thickness 0.005 m"),
        (_laminate_toml([ply], plate_extra="E = 2.1e11"), "plate.E = 210000000000.0 does not go with"),
        (_laminate_toml([ply, {k: v for k, v in ply.items() if k != "E1"}]), r"plate.ply\[1\]: missing E1"),
        (_laminate_toml([ply, {**ply, "angle": 400.0}]), r"plate.ply\[1\].angle = 400.0 is out of range"),
        (_laminate_toml([ply, {**ply, "angle": "up"}]), r"plate.ply\[1\].angle = 'up' has the wrong type"),
        (_laminate_toml([{**ply, "G13": 8e10, "G23": 8e10}, ply]),
         "plate.ply: G13 = .* given for every ply or for none"),
        (_laminate_toml([ply], plate_extra="yield_strength = -1.0"), "plate.yield_strength = -1.0 is out of range"),
    ]
    for text, message in cases:
        with pytest.raises(ValueError, match=message):
            _load_text(tmp_path, text)
    case = _load_text(tmp_path, _laminate_toml([ply, ply], geometry="a = 0.1\nh = 0.005\nR1 = 0.02\nR2 = 2000.0"))
    assert case.geometry.h == 0.005  # the same h, given: accepted


def test_laminate_case_round_trips_and_takes_settings(tmp_path):
    case = load_case("hail-laminate")
    assert load_case(case.save(tmp_path / "again.toml")) == case
    assert case_from_dict(json.loads(json.dumps(case.as_dict()))) == case
    stronger = case.with_settings(["plate.yield_strength=2e8", "v=50"])
    assert stronger.plate.yield_strength == 2e8 and stronger.plate.plies == case.plate.plies
    with pytest.raises(ValueError, match=r"plate.E = 10000000000.0 does not apply to a laminate plate; allowed: "
                                         "plate.yield_strength"):
        case.with_settings(["plate.E=1e10"])
    with pytest.raises(ValueError, match="geometry.h = 0.006 is out of range"):
        case.with_settings(["h=0.006"])
    with pytest.raises(ValueError, match="h = 0.006 is out of range; allowed: the plies' total thickness"):
        case.parameters(h=0.006)
    with pytest.raises(ValueError, match="plate_E = 10000000000.0 does not apply to a laminate plate"):
        case.parameters(plate_E=1e10)


@pytest.mark.parametrize("name", ["sand-laminate", "hail-laminate"])
def test_laminate_cases_state_the_isotropic_approximations_error(name):
    """The numbers each laminate case's source quotes: the isotropic approximation it used before
    (E = E3 = 16.7 GPa, nu = 0.17, derived here through the isotropic path) against its plies."""
    from phaseimpact.model.plate_stiffness import bending_stiffness
    from phaseimpact.parameters import derive_parameters

    case = load_case(name)
    assert isinstance(case.plate.plies, tuple) and len(case.plate.plies) == 5 and case.geometry.h == 0.005
    old = derive_parameters(case.projectile, Material(E=1.67e10, nu=0.17, rho=1940.0), case.geometry, v=90.0)
    new = case.parameters()
    bending = bending_stiffness(case.plate, case.geometry.a)
    quoted = [f"Kb = {old.Kb:.3e} N/m", f"K = {old.K:.3e} N/m^1.5", f"Km = {old.Km:.3e} N/m^3",
              f"Kb = {bending:.3e} N/m ({bending / old.Kb:.2f} times)",
              f"Kbs = {new.Kb:.3e} N/m ({new.Kb / old.Kb:.2f} times",
              f"K = {new.K:.3e} N/m^1.5 ({new.K / old.K:.3f} times",
              f"Km = {new.Km:.3e} N/m^3 ({new.Km / old.Km:.2f} times"]
    source = case.source.replace("e+0", "e").replace("e+1", "e1")
    for text in quoted:
        assert text.replace("e+0", "e").replace("e+1", "e1") in source, text
    assert math.isclose(new.M2, old.M2, rel_tol=1e-12)  # same areal density
    if name == "sand-laminate":
        c = hertz_scales(new)["contact_radius"]
        assert f"{c * 1e6:.0f} µm contact radius" in source
