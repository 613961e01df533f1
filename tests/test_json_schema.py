"""The --json contract: every command's output validates against phaseimpact/schemas/cli-1.json
(written by hand from the documented keys: a key a command drops, renames or retypes fails here)."""

import json
from importlib import resources

import jsonschema
import pytest
from _cli import run

from phaseimpact.cli import JSON_SCHEMA_VERSION, build_parser

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
    argvs = {
        "cases": ["cases"],
        "params": ["params", "--case", "sand-gelcoat"],
        "simulate": ["simulate", "--kappa", "2e12"],
        "fixed-points": ["fixed-points"],
        "critical": ["critical", "--v", "2"],
        "transitions": ["transitions", "--law", "hunt-crossley", "--kappa-min", "1e8", "--kappa-max", "1e12"],
        "sweep": ["sweep", *hc, "--axis", "kappa=1e9:1e10:3:log", "--out", tmp / "s.h5"],
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
    assert set(outputs) == _json_commands()


@pytest.mark.parametrize("command", sorted(_json_commands()))
def test_every_json_output_validates_against_the_schema(outputs, command):
    doc = outputs[command]
    assert doc["schema_version"] == JSON_SCHEMA_VERSION and doc["command"] == command
    errors = sorted(VALIDATOR.iter_errors(doc), key=lambda e: list(e.path))
    assert not errors, "\n".join(f"{'/'.join(map(str, e.path))}: {e.message}" for e in errors[:5])


def test_a_dropped_key_fails_validation(outputs):
    """The schema catches the drift the contract had (critical --json without n_below)."""
    doc = {k: v for k, v in outputs["critical"].items() if k != "n_below"}
    assert any("n_below" in e.message for e in VALIDATOR.iter_errors(doc))
