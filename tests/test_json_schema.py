"""The --json contract: every command's output validates against phaseimpact/schemas/cli-1.json
(written by hand from the documented keys: a key a command drops, renames, retypes or adds
undeclared fails here, since every object of the schema has ``additionalProperties: false``)."""

import json
import re
from importlib import resources

import jsonschema
import pytest
from _cli import run

from phaseimpact.cli import CURVE_PARAMETERS, CURVE_WHATS, JSON_SCHEMA_VERSION, build_parser
from phaseimpact.settings import QUANTITIES

SCHEMA = json.loads(resources.files("phaseimpact").joinpath(f"schemas/cli-{JSON_SCHEMA_VERSION}.json").read_text())
VALIDATOR = jsonschema.Draft202012Validator(SCHEMA)


def _json_commands() -> set:
    parser = build_parser()
    commands = next(a for a in parser._actions if a.dest == "command").choices
    return {name for name, sub in commands.items() if any("--json" in a.option_strings for a in sub._actions)}


def test_the_schema_is_a_valid_schema_and_covers_every_json_command():
    jsonschema.Draft202012Validator.check_schema(SCHEMA)
    assert set(SCHEMA["properties"]["command"]["enum"]) == _json_commands()


@pytest.fixture(scope="module")
def outputs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("json")
    hc = ["--law", "hunt-crossley", "--t-end", "1e-3"]
    # name or name:variant -> argv; the variants print the keys only some inputs give
    argvs = {
        "cases": ["cases"],
        "params": ["params", "--case", "sand-gelcoat"],
        "params:thornton": ["params", "--case", "sand-gelcoat", "--law", "thornton"],
        "params:laminate": ["params", "--case", "hail-laminate"],
        "simulate": ["simulate", "--kappa", "2e12"],
        "simulate:thornton": ["simulate", "--case", "sand-gelcoat", "--law", "thornton", "--t-end", "1e-5"],
        "simulate:out": ["simulate", "--kappa", "2e12", "--out", tmp / "run.nc"],
        "fixed-points": ["fixed-points"],
        "critical": ["critical", "--v", "2", "--exponents"],
        "critical:not-found": ["critical", "--case", "sand-gelcoat"],
        "transitions": ["transitions", "--law", "hunt-crossley", "--kappa-min", "1e8", "--kappa-max", "1e12"],
        "sweep": ["sweep", *hc, "--axis", "kappa=1e9:1e10:3:log", "--out", tmp / "s.h5"],
        "sweep:paper": ["sweep", "--t-end", "1e-3", "--axis", "kappa=1e11:1e13:3:log", "--refine", "kappa",
                        "--refine-rtol", "1e-3", "--out", tmp / "p.h5"],
        "atlas": ["atlas", *hc, "--axis", "kappa=1e9:1e10:2:log", "--axis", "v=1:2:2", "--out", tmp / "a.h5"],
        "critical-curve": ["critical-curve", "--axis", "v=1:2:2",
                           "--out", tmp / "c.h5"],
        "check-law": ["check-law", "abrate"],
        "warmup": ["warmup"],
        "plot": ["plot", tmp / "s.h5", "--out", tmp / "s.png"],
        "portrait": ["portrait", "--kappa", "3e9", "--out", tmp / "p.png"],
        "train": ["train", "--law", "hunt-crossley", "--kappa", "3e9", "--period", "3e-3", "--impacts", "3",
                  "--fixed-point"],
        "orbit-diagram": ["orbit-diagram", "--law", "hunt-crossley", "--axis", "T=2e-3:3e-3:2", "--transients", "3",
                          "--samples", "2"],
        "map-continuation": ["map-continuation", "--law", "hunt-crossley", "--kappa", "3e9", "--axis",
                             "T=0.99e-3:0.975e-3:6"],
        "basins": ["basins", "--law", "hunt-crossley", "--kappa", "3e9", "--period", "1.0036e-3", "--grid", "2",
                   "--iterations", "50", "--out", tmp / "b.png"],
    }
    out = {}
    for name, argv in argvs.items():  # in order: plot reads the sweep's archive
        code, stdout, stderr = run([*argv, "--json"])
        assert code == 0, (name, stderr)
        out[name] = json.loads(stdout)
    return out


def test_every_command_is_tried(outputs):
    assert {name.partition(":")[0] for name in outputs} == _json_commands()


def test_every_json_output_validates_against_the_schema(outputs):
    for name, doc in outputs.items():
        command = name.partition(":")[0]
        assert doc["schema_version"] == JSON_SCHEMA_VERSION and doc["command"] == command
        errors = sorted(VALIDATOR.iter_errors(doc), key=lambda e: list(e.path))
        assert not errors, name + ": " + "\n".join(f"{'/'.join(map(str, e.path))}: {e.message}" for e in errors[:5])


def test_the_variants_print_their_conditional_keys(outputs):
    """The variants are there for keys only some inputs give: they must still give them."""
    assert outputs["params:thornton"]["law"] == "thornton" and outputs["params:thornton"]["yield_velocity"] > 0
    assert outputs["params"]["laminate"] is None and set(outputs["params:laminate"]["laminate"]) == {"A", "B", "D",
                                                                                                    "D_star"}
    assert "ply" in outputs["params:laminate"]["case"]["plate"] and outputs["params:laminate"]["regime_warning"]
    assert "yield_velocity" in outputs["simulate:thornton"] and "exponents" in outputs["critical"]
    assert outputs["critical:not-found"]["kappa_c_status"] == "not-found"
    assert {"first_split", "boundaries"} <= set(outputs["sweep:paper"])
    assert outputs["simulate:out"]["out"].endswith("run.nc") and outputs["simulate"]["out"] is None


def test_a_dropped_key_fails_validation(outputs):
    """The schema catches the drift the contract had (critical --json without n_below)."""
    doc = {k: v for k, v in outputs["critical"].items() if k != "n_below"}
    assert any("n_below" in e.message for e in VALIDATOR.iter_errors(doc))


@pytest.mark.parametrize("where", ["top", "nested"])
def test_an_undeclared_key_fails_validation(outputs, where):
    """Issue 42 item 5: a key the schema does not declare is refused, at the top and deep inside."""
    doc = json.loads(json.dumps(outputs["simulate"]))
    (doc if where == "top" else doc["stick_points"][0])["undeclared"] = 1.0
    assert any("undeclared" in e.message for e in VALIDATOR.iter_errors(doc))
    doc = json.loads(json.dumps(outputs["critical"]))
    (doc if where == "top" else doc["case"]["impact"])["n_below_2"] = 2
    assert any("n_below_2" in e.message for e in VALIDATOR.iter_errors(doc))


def _objects(node, path="$"):
    """Every object schema below ``$defs`` (the ``if`` clauses only select a command)."""
    if isinstance(node, dict):
        if "properties" in node or node.get("type") == "object":
            yield path, node
        for key, value in node.items():
            if key != "if":
                yield from _objects(value, f"{path}/{key}")
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from _objects(value, f"{path}/{i}")


def test_every_object_of_the_schema_is_closed():
    objects = list(_objects(SCHEMA["$defs"]))
    assert len(objects) > 50
    open_ = [path for path, node in objects if node.get("additionalProperties") is not False]
    assert not open_, open_


def _numbers(node, path="$"):
    """Every property whose values are numbers (or arrays of them), with its schema."""
    if isinstance(node, dict):
        for key, value in node.get("properties", {}).items():
            item = value
            while isinstance(item, dict) and item.get("type") in ("array", ["array", "null"]):
                item = item.get("items", {})
            types = item.get("type") if isinstance(item, dict) else None
            types = types if isinstance(types, list) else [types]
            if {"number", "integer"} & set(types):
                yield f"{path}/{key}", value
        for key, value in node.items():
            yield from _numbers(value, f"{path}/{key}")
    elif isinstance(node, list):
        for value in node:
            yield from _numbers(value, path)


def test_every_number_of_the_schema_states_its_unit():
    """Each number's description ends with its unit in brackets ("[m]", "[1]": dimensionless)."""
    numbers = list(_numbers(SCHEMA["$defs"]))
    assert len(numbers) > 100
    missing = [path for path, node in numbers if not re.search(r"\[[^\]]+\]$", node.get("description", ""))]
    assert not missing, missing


def test_critical_curve_declares_the_keys_named_after_its_parameter_and_quantity():
    """critical-curve --json repeats the values under the parameter's own name and kappa under
    --what's: every name a curve can run over and continue is declared."""
    declared = SCHEMA["$defs"]["critical-curve"]["properties"]
    assert {*CURVE_PARAMETERS, *QUANTITIES, *CURVE_WHATS} <= set(declared)
