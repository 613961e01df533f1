"""The command line's commands and their JSON contracts (issues 11, 12, 13).

Each test states a known answer or an agreement between two routes: REFERENCE §4's Hertz closed
forms against the engine's peak force, REFERENCE §5's closed-form ``kappa_c`` against the located
root, grazing values located from a smooth defining function against contact counts of single
runs on either side, continuation against independent searches, and atlas points against single
``simulate`` runs. JSON numbers must be finite or null.
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import re
import shlex
from pathlib import Path

import h5py
import numpy as np
import pytest
from _cli import import_every_module, run

import phaseimpact.analysis as analysis
import phaseimpact.continuation as continuation
import phaseimpact.integrate as integrate
from phaseimpact import archive
from phaseimpact.plotting import OUTCOME_COLOURS
from phaseimpact.settings import SETTABLE

CASES_DIR = Path(__file__).resolve().parents[1] / "phaseimpact" / "cases"
SHIPPED = sorted(p.stem for p in CASES_DIR.glob("*.toml"))
KAPPA_C_V1 = 1.4994e12  # REFERENCE §5 / README: kappa_c of the seed case at 1 m/s




def _no_constant(name):
    raise AssertionError(f"JSON holds {name}: numbers must be finite or null")


def run_json(argv, expect=0):
    """Run with ``--json``; the exit code must be ``expect`` and every number finite or null."""
    code, out, err = run([*argv, "--json"])
    assert code == expect, (argv, code, err)
    return json.loads(out, parse_constant=_no_constant)


def numbers(obj):
    """Every number in a JSON object (for finiteness checks)."""
    if isinstance(obj, dict):
        for value in obj.values():
            yield from numbers(value)
    elif isinstance(obj, list):
        for value in obj:
            yield from numbers(value)
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool):
        yield obj


def assert_finite(obj):
    assert all(math.isfinite(x) for x in numbers(obj))


def png_pixels(path):
    """The RGB pixels of a PNG (n, 3) as 0..255 integers; the file must be a PNG."""
    import matplotlib.image

    assert Path(path).read_bytes()[:4] == b"\x89PNG"
    image = matplotlib.image.imread(path)
    return np.round(image[..., :3].reshape(-1, 3) * 255).astype(int)


def has_colour(pixels, hex_colour, tol=6, min_count=50):
    rgb = np.array([int(hex_colour[i:i + 2], 16) for i in (1, 3, 5)])
    return np.count_nonzero(np.all(np.abs(pixels - rgb) <= tol, axis=1)) >= min_count


# ------------------------------------------------------------------------------------------------
# cases, params, --case/--set
# ------------------------------------------------------------------------------------------------

def test_cases_json_lists_the_shipped_cases():
    out = run_json(["cases"])
    names = [c["name"] for c in out["cases"]]
    assert sorted(names) == SHIPPED and names[0] == "seed"
    assert all(c["description"] and len(c["source"]) > 40 for c in out["cases"])
    code, text, _ = run(["cases"])
    assert code == 0 and all(name in text for name in SHIPPED)


def test_params_json_has_hertz_scales_and_validity():
    out = run_json(["params", "--target", "rigid"])
    for key in ("M1", "M2", "K", "Kb", "Km", "contact_time", "plate_period", "indentation", "peak_force",
                "peak_pressure", "contact_radius", "validity", "case"):
        assert key in out, key
    assert_finite(out)
    assert out["plate_period"] is None  # infinite without the plate's springs
    assert out["validity"] == "ok"  # steel on steel at 1 m/s: no yield strength, a << R
    # REFERENCE §4: T = 2 tau delta_max / v with tau = sqrt(pi) Gamma(7/5) / Gamma(9/10) = 1.4716376...
    assert out["contact_time"] == pytest.approx(2 * 1.4716376 * out["indentation"] / out["v"], rel=1e-6)
    # Hertz: p0 = 3 F / (2 pi a^2) (Johnson eq. 4.24)
    assert out["peak_pressure"] == pytest.approx(3 * out["peak_force"] / (2 * math.pi * out["contact_radius"] ** 2),
                                                 rel=1e-12)
    plate = run_json(["params"])
    assert plate["plate_period"] == pytest.approx(2 * math.pi * math.sqrt(plate["M2"] / plate["Kb"]), rel=1e-12)


def test_params_takes_law_like_every_other_command():
    """Issue 42 item 5: params --law (it needed --set law=...); the law is named, checked and used."""
    by_option = run_json(["params", "--case", "sand-gelcoat", "--law", "thornton"])
    by_setting = run_json(["params", "--case", "sand-gelcoat", "--set", "law=thornton"])
    assert by_option["law"] == by_setting["law"] == "thornton"
    assert by_option["yield_velocity"] == by_setting["yield_velocity"] > 0
    assert by_option["kappa_unit"] == by_setting["kappa_unit"]
    code, text, _ = run(["params", "--case", "sand-gelcoat", "--law", "thornton"])
    assert code == 0 and re.search(r"law = thornton\n", text) and "yield_velocity" in text
    code, _, err = run(["params", "--law", "abrate", "--kappa", "3"])
    assert code == 2 and "kappa = 3.0 is not read by law 'abrate'" in err


def test_set_changes_the_derived_parameters_and_is_recorded_in_the_case():
    base = run_json(["params"])
    small = run_json(["params", "--set", "R1=0.005"])
    assert small["M1"] / base["M1"] == pytest.approx((0.005 / 0.02) ** 3, rel=1e-12)
    assert small["M2"] == base["M2"]  # the plate is untouched
    assert small["case"]["geometry"]["R1"] == 0.005
    later = run_json(["params", "--set", "R1=0.001", "--set", "R1=0.005"])  # later settings win
    assert later["M1"] == small["M1"]
    soft = run_json(["params", "--set", "plate.E=2.1e10"])
    assert soft["Kb"] / base["Kb"] == pytest.approx(0.1, rel=1e-12)  # eq. 5a: Kb is linear in E


def test_override_order_defaults_case_set_options(tmp_path):
    case = tmp_path / "mine.toml"
    text = (CASES_DIR / "seed.toml").read_text(encoding="utf-8").replace('name = "seed"', 'name = "mine"')
    case.write_text(text.replace("v = 1.0 ", 'v = 2.0\nkappa = 3e9\nlaw = "hunt-crossley"\n'), encoding="utf-8")
    from_case = run_json(["simulate", "--case", case])
    assert (from_case["v"], from_case["kappa"], from_case["law"]) == (2.0, 3e9, "hunt-crossley")
    assert from_case["contact"] is None  # only paper has a reading
    assert from_case["case"]["name"] == "mine" and from_case["case"]["impact"]["v"] == 2.0
    from_set = run_json(["simulate", "--case", case, "--set", "v=4"])
    assert from_set["v"] == 4.0 and from_set["case"]["impact"]["v"] == 4.0
    explicit = run_json(["simulate", "--case", case, "--v", "3", "--kappa", "1e9", "--law", "paper",
                         "--contact", "unilateral"])
    assert (explicit["v"], explicit["kappa"], explicit["law"], explicit["contact"]) == (3.0, 1e9, "paper",
                                                                                       "unilateral")
    assert explicit["case"]["impact"] == {"v": 3.0, "kappa": 1e9, "target": "plate", "law": "paper",
                                          "contact": "unilateral"}
    code, _, err = run(["simulate", "--case", case, "--set", "v=4", "--v", "3"])
    assert code == 2 and "v is given twice" in err
    default = run_json(["simulate"])
    assert (default["v"], default["law"], default["case"]["name"]) == (1.0, "paper", "seed")


def test_help_lists_the_settable_names_with_units():
    for command in ("params", "simulate", "critical", "transitions", "sweep", "atlas", "critical-curve",
                    "portrait"):
        code, text, _ = run([command, "--help"])
        assert code == 0 and "--case" in text and "--set" in text
        flat = " ".join(text.split())
        for name, (unit, _) in SETTABLE.items():
            assert (f"{name} ({unit})" if unit else f"{name}:") in flat, (command, name)
        assert "()" not in flat, command  # no empty unit


# ------------------------------------------------------------------------------------------------
# simulate
# ------------------------------------------------------------------------------------------------

def test_simulate_json_contract_and_hertz_reading():
    out = run_json(["simulate", "--law", "paper", "--kappa", "3e12"])
    for key in ("stick_points", "n_stick", "t_run", "cut", "outcome", "stop_reason", "peak_pressure",
                "contact_radius", "validity", "contact", "case", "n_contacts"):
        assert key in out, key
    assert_finite(out)
    assert out["contact"] == "printed" and out["outcome"] == "ratchet-escape"
    assert out["n_stick"] == len(out["stick_points"]) >= 2 and out["t_run"] > 0
    assert out["cut"] is False and out["stop_reason"] in ("settled", "runaway")  # no --t-end: until settled
    # the engine's peak force of an undamped impact on a rigid target is Hertz's (REFERENCE §4), so the
    # pressure read from it equals the closed-form scale
    run_ = run_json(["simulate", "--law", "abrate", "--target", "rigid"])
    scale = run_json(["params", "--target", "rigid"])
    assert run_["peak_pressure"] == pytest.approx(scale["peak_pressure"], rel=1e-8)
    assert run_["contact_radius"] == pytest.approx(scale["contact_radius"], rel=1e-8)
    assert run_["validity"] == "ok"


def test_simulate_reports_an_out_of_range_contact_for_sand_on_gelcoat():
    out = run_json(["simulate", "--case", "sand-gelcoat"])
    assert out["peak_pressure"] > 1.6 * 8.7e7  # issue 12: about ten times the gelcoat's strength
    assert "out of its range" in out["validity"] and "yield strength" in out["validity"]


def test_simulate_with_a_horizon_says_when_it_cut_the_run():
    out = run_json(["simulate", "--law", "paper", "--kappa", "1.5e12", "--t-end", "1e-4"])
    assert out["cut"] is True and out["stop_reason"] == "horizon"
    full = run_json(["simulate", "--law", "paper", "--kappa", "1.5e12"])
    assert full["cut"] is False and full["n_stick"] >= out["n_stick"]


# ------------------------------------------------------------------------------------------------
# critical, transitions
# ------------------------------------------------------------------------------------------------

@pytest.mark.slow  # the kappa_2 search: several seconds
def test_critical_json_kappa_c_against_the_closed_form_and_kappa_2_above():
    out = run_json(["critical", "--law", "paper", "--v", "1"])
    assert_finite(out)
    assert out["status"] == "success" and out["classification"] == "adding-sliding"
    assert out["kappa_c"] == pytest.approx(out["closed_form"], rel=2.5e-3)  # REFERENCE §5: a fraction of a %
    assert out["kappa_c"] == pytest.approx(KAPPA_C_V1, rel=1e-4)
    assert out["kappa_2"] > out["kappa_c"]
    assert out["n_staircase"] and all({"kappa", "n_stick", "t_run", "cut"} <= set(s) for s in out["n_staircase"])
    assert out["case"]["name"] == "seed"


def test_critical_not_found_is_an_answer_with_null_kappa_c():
    out = run_json(["critical", "--case", "sand-gelcoat"])
    assert out["status"] == "not-found" and out["kappa_c"] is None and out["kappa_2"] is None
    assert "margin" in out["message"]


def test_transitions_hunt_crossley_are_grazings_and_agree_with_contact_counts():
    out = run_json(["transitions", "--law", "hunt-crossley", "--v", "1", "--kappa-min", "1e8", "--kappa-max",
                    "1e13"])
    assert_finite(out)
    found = out["transitions"]
    assert found and out["count"] == "contacts" and out["case"]["name"] == "seed"
    assert all(t["kind"] == "grazing" and t["count_below"] != t["count_above"] for t in found)
    kappas = [t["kappa"] for t in found]
    assert kappas == sorted(kappas) and 1e8 <= kappas[0] and kappas[-1] <= 1e13
    for t in found:  # the located root against the counts of single runs on either side
        for factor, key in ((1 - 1e-4, "count_below"), (1 + 1e-4, "count_above")):
            single = run_json(["simulate", "--law", "hunt-crossley", "--v", "1", "--kappa", t["kappa"] * factor])
            assert single["n_contacts"] == t[key], (t, factor)


@pytest.mark.slow  # the kappa_2 search: several seconds
def test_transitions_paper_starts_at_kappa_c():
    out = run_json(["transitions", "--law", "paper", "--v", "1", "--kappa-min", "1e11", "--kappa-max", "1e13"])
    kinds = [t["kind"] for t in out["transitions"]]
    assert kinds[0] == "adding-sliding" and out["count"] == "stick phases"
    assert out["transitions"][0]["kappa"] == pytest.approx(KAPPA_C_V1, rel=1e-4)
    assert out["transitions"][1]["kind"] == "staircase-end" and out["transitions"][1]["count_above"] == 2
    assert out["transitions"][0]["count_above"] is None  # unbounded just above kappa_c


# ------------------------------------------------------------------------------------------------
# critical-curve
# ------------------------------------------------------------------------------------------------

def test_critical_curve_over_v_archive_round_trip_and_independent_searches(tmp_path):
    path = tmp_path / "curve.h5"
    out = run_json(["critical-curve", "--law", "paper", "--axis", "v=1:3:3",
                    "--no-progress", "--out", path])
    assert_finite(out)
    assert out["param"] == "v" and out["what"] == "kappa_c" and out["values"] == [1.0, 2.0, 3.0]  # linear
    curve = archive.load(path)
    asked = np.asarray(curve.requested, dtype=bool)
    assert curve.param == "v" and curve.what == "kappa_c"
    assert np.array_equal(curve.values[asked], [1.0, 2.0, 3.0])
    assert np.allclose(curve.kappa[asked], out["kappa"], rtol=0, atol=0)
    with h5py.File(path) as f:
        assert json.loads(f.attrs["case"])["name"] == "seed"
    # the last point, reached by continuation from the first, against an independent search there
    single = continuation.critical_damping(curve.base.parameters(v=3.0), "paper")
    assert out["kappa"][-1] == pytest.approx(single.kappa_c, rel=1e-8)
    closed = np.asarray(out["closed_form"])
    assert np.allclose(out["kappa"], closed, rtol=2.5e-3)  # REFERENCE §5 at every speed
    # log-spaced speeds
    short = run_json(["critical-curve", "--axis", "v=1:4:3:log", "--no-progress",
                      "--out", tmp_path / "short.h5"])
    assert np.allclose(short["v"], [1.0, 2.0, 4.0]) and short["kappa_c"][0] == pytest.approx(out["kappa"][0])


def test_critical_curve_kappa_2_over_a_material_and_grazing_over_v(tmp_path):
    k2 = run_json(["critical-curve", "--axis", "plate.E=1e11:2e11:2",
                   "--what", "kappa_2", "--no-progress", "--out", tmp_path / "k2.h5"])
    kc = run_json(["critical-curve", "--axis", "plate.E=1e11:2e11:2",
                   "--no-progress", "--out", tmp_path / "kc.h5"])
    assert all(b > a for a, b in zip(kc["kappa"], k2["kappa"], strict=True))
    assert archive.load(tmp_path / "k2.h5").what == "kappa_2"
    graz = run_json(["critical-curve", "--law", "hunt-crossley", "--axis", "v=1:2:2", "--what", "grazing",
                     "--kappa-min", "1e8", "--kappa-max", "1e13", "--no-progress", "--out", tmp_path / "g.h5"])
    first = run_json(["transitions", "--law", "hunt-crossley", "--v", "1", "--kappa-min", "1e8", "--kappa-max",
                      "1e13"])["transitions"][0]
    assert graz["kappa"][0] == pytest.approx(first["kappa"], rel=1e-8)
    assert graz["contact_index"] == first["extremum"]
    at_2 = run_json(["transitions", "--law", "hunt-crossley", "--v", "2", "--kappa-min", "1e8", "--kappa-max",
                     "1e13"])["transitions"]
    assert any(t["kappa"] == pytest.approx(graz["kappa"][1], rel=1e-7) for t in at_2)  # the same grazing, continued


def test_critical_curve_refuses_to_replace_another_curve(tmp_path):
    path = tmp_path / "c.h5"
    base = ["critical-curve", "--axis", "v=1:2:2", "--no-progress", "--out", path]
    assert run(base)[0] == 0
    assert run(base)[0] == 0  # the same work: replaced (intermediate steps do not count as other work)
    code, _, err = run([*base, "--what", "kappa_2"])
    assert code == 2 and "holds other work" in err and "what" in err
    assert run([*base, "--what", "kappa_2", "--force"])[0] == 0


# ------------------------------------------------------------------------------------------------
# atlas
# ------------------------------------------------------------------------------------------------

ATLAS = ["atlas", "--law", "paper", "--axis", "kappa=1e10:1e14:3:log", "--axis", "v=0.5:13:3", "--no-progress"]


def test_atlas_round_trip_and_points_agree_with_single_runs(tmp_path):
    path = tmp_path / "atlas.h5"
    out = run_json([*ATLAS, "--out", path])
    assert_finite(out)
    assert out["points"] == 9 and out["computed"] == 9 and out["failed"] == 0
    assert [a["name"] for a in out["axes"]] == ["kappa", "v"] and out["axes"][0]["log"] is True
    result = archive.load(path)
    assert result.grid.names == ("kappa", "v") and result.shape == (3, 3)
    assert np.allclose(result.axis("kappa"), [1e10, 1e12, 1e14]) and np.allclose(result.axis("v"), [0.5, 6.75, 13])
    assert [a.log for a in result.grid.axes] == [True, False]
    outcomes = result.outcome_names().reshape(3, 3)
    n_stick = result.values["n_stick"].reshape(3, 3)
    for i, kappa in enumerate(result.axis("kappa")):
        for j, v in enumerate(result.axis("v")):
            single = run_json(["simulate", "--law", "paper", "--kappa", kappa, "--v", v])
            assert (single["outcome"], single["n_stick"]) == (outcomes[i, j], n_stick[i, j])
    assert set(outcomes[0]) == {"permanent-stick"} and set(outcomes[-1]) == {"ratchet-escape"}
    with h5py.File(path) as f:
        assert json.loads(f.attrs["case"])["name"] == "seed"


def test_atlas_over_a_geometry_axis_of_the_case(tmp_path):
    out = run_json(["atlas", "--law", "hunt-crossley", "--axis", "kappa=1e9,1e11", "--axis", "R1=0.01:0.02:2",
                    "--no-progress", "--out", tmp_path / "r.h5"])
    assert out["points"] == 4 and out["outcomes"] == {"rebound": 4}
    result = archive.load(tmp_path / "r.h5")
    assert result.grid.names == ("kappa", "R1")
    single = run_json(["simulate", "--law", "hunt-crossley", "--kappa", "1e9", "--set", "R1=0.02"])
    assert result.values["max_force"].reshape(2, 2)[0, 1] == pytest.approx(single["max_force"], rel=1e-12)


def test_atlas_ctrl_c_prints_the_resume_command_that_completes_it(tmp_path, monkeypatch):
    sweep_module = importlib.import_module("phaseimpact.continuation.sweep")
    monkeypatch.setattr(sweep_module, "CHUNK_THREADS", 4)
    save, saves = archive.Checkpoint.__call__, []

    def save_then_interrupt(*args, **kwargs):
        save(*args, **kwargs)
        saves.append(1)
        if len(saves) == 1:
            raise KeyboardInterrupt

    monkeypatch.setattr(archive.Checkpoint, "__call__", save_then_interrupt)
    path = tmp_path / "a.h5"
    code, _, err = run([*ATLAS, "--out", path])
    assert code == 130 and "4 of 9 points are saved" in err and len(err.strip().splitlines()) == 1
    words = shlex.split(err.strip().split("resume with: ", 1)[1])
    assert words[0] == "phaseimpact" and words[-1] == "--resume"
    monkeypatch.setattr(archive.Checkpoint, "__call__", save)
    assert run(words[1:])[0] == 0
    assert archive.load(path).done.all()


# ------------------------------------------------------------------------------------------------
# plot, portrait
# ------------------------------------------------------------------------------------------------

def test_plot_draws_an_atlas_a_sweep_and_a_curve(tmp_path):
    atlas_h5, sweep_h5, curve_h5 = tmp_path / "a.h5", tmp_path / "s.h5", tmp_path / "c.h5"
    assert run(["atlas", "--law", "paper", "--axis", "kappa=1e11:1e13:12:log", "--axis", "v=1:3:4",
                "--no-progress", "--out", atlas_h5])[0] == 0
    assert run(["sweep", "--axis", "kappa=1e11:1e13:12:log", "--no-progress",
                "--out", sweep_h5])[0] == 0
    assert run(["critical-curve", "--axis", "v=1:3:3", "--no-progress",
                "--out", curve_h5])[0] == 0
    for archive_path, kind, extra in ((atlas_h5, "atlas", ["--contours", "n_stick", "--curve", curve_h5]),
                                      (sweep_h5, "sweep", []), (curve_h5, "curve", [])):
        png = tmp_path / f"{kind}.png"
        out = run_json(["plot", archive_path, "--out", png, *extra])
        assert out["kind"] == kind
        pixels = png_pixels(png)
        if kind != "curve":  # both classes of the range, drawn in their colours
            assert has_colour(pixels, OUTCOME_COLOURS["permanent-stick"])
            assert has_colour(pixels, OUTCOME_COLOURS["ratchet-escape"])
    assert not [p for p in tmp_path.iterdir() if p.suffix in (".tmp", ".lock")]


def test_plot_refuses_what_it_cannot_draw_or_would_destroy(tmp_path):
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes")
    code, _, err = run(["plot", notes, "--out", tmp_path / "x.png"])
    assert code == 2 and "not a readable HDF5 file" in err
    curve_h5 = tmp_path / "c.h5"
    assert run(["critical-curve", "--axis", "v=1:2:2", "--no-progress",
                "--out", curve_h5])[0] == 0
    before = curve_h5.read_bytes()
    code, _, err = run(["plot", curve_h5, "--out", curve_h5])
    assert code == 2 and "out" in err.splitlines()[-1]
    fake = tmp_path / "fig.png"
    fake.write_text("not a png")
    code, _, err = run(["plot", curve_h5, "--out", fake])
    assert code == 2 and "is not a .png figure" in err and fake.read_text() == "not a png"
    assert run(["plot", curve_h5, "--out", fake, "--force"])[0] == 0
    assert curve_h5.read_bytes() == before
    code, _, err = run(["plot", curve_h5, "--out", tmp_path / "y.png", "--contours", "n_stick"])
    assert code == 2 and "contours" in err


def test_portrait_marks_each_kappa_with_its_outcome(tmp_path):
    png = tmp_path / "p.png"
    out = run_json(["portrait", "--law", "paper", "--kappa", "1e9,3e12", "--out", png])
    assert_finite(out)
    assert [p["outcome"] for p in out["panels"]] == ["permanent-stick", "ratchet-escape"]
    for panel in out["panels"]:
        single = run_json(["simulate", "--law", "paper", "--kappa", panel["kappa"]])
        assert (single["outcome"], single["n_stick"]) == (panel["outcome"], panel["n_stick"])
    pixels = png_pixels(png)
    assert has_colour(pixels, "#4477aa", min_count=20)  # the stick markers
    other = tmp_path / "q.png"
    assert run(["portrait", "--law", "hunt-crossley", "--kappa", "3e9", "--plane", "x2,x2dot", "--out", other])[0] == 0
    png_pixels(other)


# ------------------------------------------------------------------------------------------------
# Bad input: exit 2, one line naming the parameter, before any work
# ------------------------------------------------------------------------------------------------

@pytest.fixture
def no_work(monkeypatch):
    import_every_module()  # before the patch: no lazy import keeps the stand-in
    def forbidden(*args, **kwargs):
        raise AssertionError("work started before the input was refused")

    for module, name in ((continuation, "sweep"), (continuation, "atlas"), (continuation, "critical_damping"),
                         (continuation, "critical_curve"), (continuation, "transitions"), (integrate, "simulate"),
                         (analysis, "phase_portrait")):
        monkeypatch.setattr(module, name, forbidden)


CURVE = ["critical-curve", "--out", "a.h5"]
OVER_V = [*CURVE, "--axis", "v=1:2:2"]
BAD = [
    (["atlas", "--axis", "kappa=1:0:x", "--out", "a.h5"], "kappa"),
    (["atlas", "--axis", "foo=1:2:3", "--out", "a.h5"], "foo"),
    (["atlas", "--axis", "kappa=1e9:1e12:3:log", "--law", "abrate", "--out", "a.h5"], "kappa"),
    (["atlas", "--axis", "v=-1:2:3", "--out", "a.h5"], "v"),
    (["atlas", "--axis", "v=1:2:3", "--v", "2", "--out", "a.h5"], "v"),
    (["atlas", "--axis", "kappa=1e9:1e12:4000:log", "--axis", "v=1:2:4000", "--out", "a.h5"], "axis"),
    (["atlas", "--axis", "R1=0.01:0.02:2", "--set", "R1=0.01", "--out", "a.h5"], "R1"),
    (["simulate", "--set", "nope=1"], "nope"),
    (["simulate", "--set", "R1=abc"], "R1"),
    (["simulate", "--set", "R1=-1"], "R1"),
    (["simulate", "--set", "plate.nu=0.7"], "plate.nu"),
    (["simulate", "--set", "v=1e308"], "v"),
    (["params", "--set", "R1"], "set"),
    (["simulate", "--case", "missing"], "case"),
    (["critical", "--case", "missing.toml"], "case"),
    (["sweep", "--case", "missing", "--axis", "kappa=1e9:1e12:3:log", "--out", "a.h5"], "case"),
    ([*CURVE, "--axis", "kappa=1:2:2"], "kappa"),
    ([*CURVE, "--axis", "nope=1:2:2"], "nope"),
    ([*CURVE, "--axis", "v=2:1:2"], "axis"),
    ([*CURVE, "--axis", "v=0:1:2:log"], "axis"),
    ([*CURVE, "--axis", "R1=-0.01:0.02:2"], "R1"),
    ([*CURVE, "--axis", "v=1:2"], "axis"),
    ([*OVER_V, "--v", "3"], "v"),
    ([*OVER_V, "--axis", "v=1:2:5:log"], "axis"),
    ([*OVER_V, "--what", "grazing", "--law", "paper", "--kappa-min",
      "1e8", "--kappa-max", "1e13"], "grazing"),
    ([*OVER_V, "--what", "grazing", "--law", "hunt-crossley"],
     "kappa-min"),
    ([*OVER_V, "--what", "kappa_c", "--law", "hunt-crossley"], "what"),
    ([*OVER_V, "--kappa-min", "1e8"], "kappa-min"),
    ([*OVER_V, "--what", "nonsense"], "what"),
    (["transitions", "--kappa-min", "1e12", "--kappa-max", "1e8"], "kappa-min"),
    (["transitions", "--law", "abrate", "--kappa-min", "1e8", "--kappa-max", "1e12"], "kappa"),
    (["transitions", "--kappa-min", "1e8", "--kappa-max", "1e12", "--samples", "3"], "samples"),
    (["transitions", "--law", "hunt-crossley", "--target", "free", "--kappa-min", "1e8", "--kappa-max", "1e12"],
     "target"),
    ([*OVER_V, "--what", "grazing", "--law", "abrate", "--kappa-min",
      "1e8", "--kappa-max", "1e13"], "kappa"),
    ([*OVER_V, "--what", "grazing", "--law", "hunt-crossley",
      "--target", "rigid", "--kappa-min", "1e8", "--kappa-max", "1e13"], "target"),
    (["critical", "--law", "hunt-crossley"], "law"),
    (["portrait", "--kappa", "1e9,abc", "--out", "p.png"], "kappa"),
    (["portrait", "--kappa", ",".join(["1e9"] * 13), "--out", "p.png"], "kappa"),
    (["portrait", "--kappa", "1e9", "--plane", "x1,x2", "--out", "p.png"], "plane"),
    (["portrait", "--kappa", "1e9", "--out", "p.h5"], "out"),
    (["portrait", "--kappa", "1e9", "--law", "abrate", "--out", "p.png"], "kappa"),
    (["plot", "missing.h5", "--out", "p.png"], "missing.h5"),
    (["plot", "afile.txt", "--out", "p.png"], "afile.txt"),
    (["plot", "missing.h5", "--out", "p.txt"], "out"),
]


@pytest.mark.parametrize("args, name", BAD, ids=[" ".join(a[:1] + a[-4:]) for a, _ in BAD])
def test_bad_input_refused_before_any_work(args, name, tmp_path, monkeypatch, no_work):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile.txt").write_text("x")
    code, _, err = run(args)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    assert name in lines[0]
    assert not (tmp_path / "a.h5").exists() and not (tmp_path / "p.png").exists()
    assert not list(tmp_path.glob("*.lock"))


def test_atlas_refine_stores_boundaries_that_match_the_continued_curve(tmp_path):
    """issue 13.2: the refined kappa_c boundary of a (kappa, v) atlas agrees with kappa_c(v) continued
    independently, to the refinement's tolerance; the points survive the archive."""
    out = run_json(["atlas", "--law", "paper", "--axis", "kappa=1e11:1e13:9:log", "--axis", "v=0.5:13:3",
                    "--refine", "kappa", "--refine-rtol", "1e-9", "--no-progress", "--out", tmp_path / "a.h5"])
    b = out["boundaries"]
    assert b["axis"] == "kappa" and len(b["points"]) == 3
    assert set(b["below"]) == {"permanent-stick"} and set(b["above"]) == {"ratchet-escape"}
    points = np.asarray(b["points"])
    curve = continuation.critical_curve(archive.load(tmp_path / "a.h5").grid.base, "paper", "v", points[:, 1])
    np.testing.assert_allclose(points[:, 0], curve.kappa[curve.requested], rtol=2e-9)
    stored = archive.load(tmp_path / "a.h5").extras["boundaries"]
    np.testing.assert_array_equal(np.asarray(stored["points"]), points)


def test_atlas_refine_axis_must_be_an_axis():
    code, _, err = run(["atlas", "--law", "paper", "--axis", "kappa=1e11:1e13:3:log", "--refine", "v",
                        "--out", "/tmp/never.h5"])
    assert code == 2 and "refine" in err


def test_no_progress_bar_goes_into_a_log(tmp_path):
    """stderr redirected (a log file, a pipe): notes and errors only, never a bar's redraws."""
    code, _, err = run(["sweep", "--law", "hunt-crossley", "--axis", "kappa=1e9:1e10:4:log",
                        "--t-end", "1e-3", "--out", tmp_path / "s.h5"])
    assert code == 0
    assert "pt/s" not in err and "%|" not in err and "\r" not in err, err


@pytest.mark.parametrize("shell", ["bash", "zsh"])
def test_shell_completion_knows_every_command_and_option(shell):
    from phaseimpact.cli import build_parser

    code, out, _ = run(["completion", shell])
    assert code == 0
    commands = next(a for a in build_parser()._actions if a.dest == "command").choices
    for name, sub in commands.items():
        assert name in out, name
        for action in sub._actions:
            if action.help == argparse.SUPPRESS:  # removed spellings, kept only to point at their successors
                continue
            for option in action.option_strings:
                if option.startswith("--"):
                    assert option in out, (name, option)


def test_params_reports_the_laminate_and_the_impact_regime():
    """Issue 40 items 2-3: A/B/D of a laminate case, Zener's lambda, Olsson's mass ratio and regime
    (closed forms here), and the warning when the target model does not fit the regime."""
    seed = run_json(["params"])
    M1, M_p = 7850.0 * 4 / 3 * math.pi * 0.02**3, 7850.0 * math.pi * 0.1**2 * 0.005
    assert seed["mass_ratio"] == pytest.approx(M1 / M_p, rel=1e-12) and seed["plate_mass"] == pytest.approx(M_p)
    assert seed["mass_ratio"] == pytest.approx(0.2133, abs=1e-4) and seed["regime"] == "wave-controlled"
    assert seed["M1"] / seed["M2"] == pytest.approx(0.853, abs=1e-3)  # docs/physics.md §8: against eq. 1's M2
    D = 2.1e11 * 0.005**3 / (12 * (1 - 0.3**2))
    assert seed["plate_impedance"] == pytest.approx(8 * math.sqrt(D * 7850.0 * 0.005), rel=1e-12)
    assert seed["zener_lambda"] == pytest.approx(M1**0.6 * 1.0**0.2 * seed["K"] ** 0.4 / seed["plate_impedance"],
                                                 rel=1e-12)
    assert seed["laminate"] is None and "infinite plate is the model" in seed["regime_warning"]
    assert run_json(["params", "--target", "rigid"])["regime_warning"] is None
    heavy = run_json(["params", "--set", "R1=0.05"])  # 4.11 kg on 1.23 kg: quasi-static, the plate fits
    assert heavy["regime"] == "quasi-static" and heavy["regime_warning"] is None
    middle = run_json(["params", "--set", "R1=0.03"])  # 0.888 kg: boundary-controlled
    assert middle["regime"] == "boundary-controlled" and middle["regime_warning"] is None
    free = run_json(["params", "--set", "R1=0.03", "--target", "free"])  # a free mass where the edge takes part
    assert free["regime_warning"].endswith("target free) is out of its range; the spring-mass plate is the model")
    hail = run_json(["params", "--case", "hail-laminate"])
    A, B, Dm = (np.array(hail["laminate"][k]) for k in ("A", "B", "D"))
    assert A[0, 0] == pytest.approx(4 * 1e-3 * 2.87e10 / (1 - 0.5**2 * 1.66 / 2.87) + 1e-3 * 1.11e10 / (1 - 0.25),
                                    rel=1e-12)  # Q11 t summed: four triax plies, one biax
    assert np.abs(B).max() < 1e-9 * A.max()  # symmetric layup
    olsson = math.sqrt(Dm[0, 0] * Dm[1, 1] * ((Dm[0, 1] + 2 * Dm[2, 2]) / math.sqrt(Dm[0, 0] * Dm[1, 1]) + 1) / 2)
    assert hail["laminate"]["D_star"] == pytest.approx(olsson, rel=1e-12)
    assert hail["regime"] == "wave-controlled" and hail["regime_warning"].startswith("the impact is wave-controlled")
    code, text, _ = run(["params", "--case", "hail-laminate"])
    assert code == 0 and "laminate: 5 plies, h = 0.005 m" in text and "regime warning: the impact is" in text
