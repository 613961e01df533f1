"""The study scripts: one per figure or table, each stating its claim and reachable from run_all.

Imports only (running the studies is ``make reproduce``'s job): every script is listed in
``studies/run_all.py``, has a docstring that states its claim, a ``main(quick, jobs)`` and an output
folder global that ``--quick`` can redirect to ``figures/preview/``.
"""

import ast
from pathlib import Path

import pytest

STUDIES = Path(__file__).resolve().parents[1] / "studies"
SCRIPTS = sorted(p for p in STUDIES.glob("*.py") if not p.name.startswith("_") and p.name != "run_all.py")


def listed() -> tuple:
    tree = ast.parse((STUDIES / "run_all.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "STUDIES" for t in node.targets):
            return tuple(ast.literal_eval(node.value))
    raise AssertionError("run_all.py defines no STUDIES")


def test_every_study_is_run_by_run_all():
    assert sorted(listed()) == sorted(p.stem for p in SCRIPTS)


@pytest.mark.parametrize("path", SCRIPTS, ids=lambda p: p.stem)
def test_study_states_its_claim_and_can_be_redirected(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    doc = ast.get_docstring(tree)
    assert doc and "claim" in doc.lower(), f"{path.name}: the docstring must state the claim it supports"
    names = {t.id for node in tree.body if isinstance(node, ast.Assign) for t in node.targets
             if isinstance(t, ast.Name)}
    assert names & {"FIGURES", "ROOT"}, f"{path.name}: no FIGURES/ROOT global for --quick to redirect"
    mains = [node for node in tree.body if isinstance(node, ast.FunctionDef) and node.name == "main"]
    assert mains, f"{path.name}: no main()"
    args = [a.arg for a in mains[0].args.args]
    assert args[:2] == ["quick", "jobs"], f"{path.name}: main(quick, jobs) expected, got {args}"


def test_no_pitchfork_and_no_general_runaway_claim():
    """The transition of eq. 8 is an adding-sliding (docs/physics.md §5), not a pitchfork."""
    for path in [*SCRIPTS, STUDIES / "_plots.py"]:
        text = path.read_text(encoding="utf-8").lower()
        assert "pitchfork" not in text, path.name
        assert "runaway above kappa_c" not in text and "runaway above κc" not in text, path.name
