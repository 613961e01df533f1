"""One meaning per name (issue 41 item 5): ``rtol`` is the integrator's tolerance in every function
and command, a bracket's tolerance has its own name, the old spellings are refused with the new
ones; archives are ``.nc`` in every help and page; ``basins --grid`` and the ``status`` codes say
what the code does; shell completion offers cases, settings and files."""

import argparse
import contextlib
import inspect
import io
import re
import shutil
import subprocess
from pathlib import Path

import pytest

import phaseimpact
from phaseimpact import continuation, seed_parameters
from phaseimpact.case import list_cases
from phaseimpact.cli import build_parser, main
from phaseimpact.continuation import (
    adding_sliding_exponents,
    atlas,
    critical_curve,
    critical_damping,
    grazing_transitions,
    locate_kappa_2,
    refine_boundaries,
    transitions,
)
from phaseimpact.continuation import transition as transition_module
from phaseimpact.integrate import STATUSES

ROOT = Path(__file__).resolve().parents[1]
P = seed_parameters(v=1.0)

#: (function, its positional arguments, the new name of its bracket's tolerance)
RENAMED = [
    (critical_damping, (P, "paper"), "kappa_rtol"),
    (transitions, (P, "paper", 1e9, 1e14), "kappa_rtol"),
    (grazing_transitions, (P, "hunt-crossley", 1e8, 1e13), "kappa_rtol"),
    (locate_kappa_2, (P, "paper", 1.5e12), "kappa_rtol"),
    (critical_curve, (P, "paper", "v", [1.0, 2.0]), "kappa_rtol"),
    (refine_boundaries, (None, "kappa"), "refine_rtol"),
]


@pytest.mark.parametrize("function, args, bracket", RENAMED, ids=lambda x: getattr(x, "__name__", ""))
def test_a_bare_rtol_of_the_old_meaning_is_refused_with_both_names(function, args, bracket):
    with pytest.raises(TypeError, match=rf"rtol= now means the integrator's tolerance .*now {bracket}="):
        function(*args, rtol=1e-6)


@pytest.mark.parametrize("function, args, bracket", [*RENAMED, (adding_sliding_exponents, (P, "paper", 1.5e12), None)],
                         ids=lambda x: getattr(x, "__name__", ""))
def test_integrator_rtol_is_refused_with_its_new_name(function, args, bracket):
    with pytest.raises(TypeError, match=r"integrator_rtol= is renamed rtol="):
        function(*args, integrator_rtol=1e-10)


def test_no_public_function_keeps_the_old_names():
    """Every public function of the package: ``integrator_rtol`` nowhere, and ``rtol`` beside a
    bracket's own tolerance wherever a function has one."""
    checked = 0
    for module in (phaseimpact, continuation, transition_module):
        for name in dir(module):
            function = getattr(module, name)
            if name.startswith("_") or not inspect.isfunction(function):
                continue
            parameters = inspect.signature(function).parameters
            assert "integrator_rtol" not in parameters, f"{name} still takes integrator_rtol"
            if {"kappa_rtol", "refine_rtol"} & set(parameters):
                assert "rtol" in parameters, f"{name}: its bracket has a name, its integrator none"
                checked += 1
    assert checked >= 6


def test_rtol_reaches_the_integrator_and_kappa_rtol_the_bracket(monkeypatch):
    seen = []
    margin = transition_module.first_stick_margin

    def recorded(params, law, *, rtol):
        seen.append(rtol)
        return margin(params, law, rtol=rtol)

    monkeypatch.setattr(transition_module, "first_stick_margin", recorded)
    found = critical_damping(P, "paper", kappa_rtol=1e-4, rtol=1e-9)
    assert found.status == "success"
    assert found.rtol == 1e-4  # the bracket it was narrowed to
    # the margins of the search at rtol, those of the accuracy estimate at rtol / 100
    assert all(r == pytest.approx(1e-9) or r == pytest.approx(1e-11) for r in seen) and seen.count(1e-9) >= 3
    assert abs(found.kappa_c / found.closed_form - 1) < 0.01  # docs/physics.md §5: within 0.2 %


@pytest.mark.parametrize("keywords, named", [({"kappa_rtol": 1e-10, "rtol": 1.0}, "rtol"),
                                             ({"kappa_rtol": 1.0}, "kappa_rtol")])
def test_both_tolerances_are_checked_before_any_work(keywords, named, monkeypatch):
    monkeypatch.setattr(transition_module, "first_stick_margin", lambda *a, **k: pytest.fail("work was done"))
    for function, args in ((critical_damping, (P, "paper")), (transitions, (P, "paper", 1e9, 1e14)),
                           (critical_curve, (P, "paper", "v", [1.0, 2.0]))):
        with pytest.raises(ValueError, match=rf"^{named} = 1\.0 is out of range"):
            function(*args, **keywords)


def test_refine_rtol_is_the_bracket_and_rtol_the_integrator():
    result = atlas(P, "paper", {"kappa": [1e11, 1e13]}, n_jobs=1)
    with pytest.raises(ValueError, match=r"^refine_rtol = 1\.0 is out of range"):
        refine_boundaries(result, "kappa", refine_rtol=1.0)
    with pytest.raises(ValueError, match=r"^rtol = 1\.0 is out of range"):
        refine_boundaries(result, "kappa", refine_rtol=1e-3, rtol=1.0)
    found = refine_boundaries(result, "kappa", refine_rtol=1e-3, rtol=1e-9)
    (kappa,) = found.points[:, 0]
    assert found.rtol == 1e-3 and abs(kappa / transition_module.closed_form_kappa_c(P) - 1) < 0.01


# ------------------------------------------------------------------------------------------------
# The command line and the pages
# ------------------------------------------------------------------------------------------------

def _subcommands():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices


def _help(name) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
        main([name, "--help"])
    return out.getvalue()


def test_archives_are_nc_in_every_help_and_page():
    for name in _subcommands():
        text = _help(name)
        assert not re.search(r"\.h5\b|HDF5 archive|to HDF5", text), f"phaseimpact {name} --help: {text}"
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]:
        assert not re.search(r"[\w-]\.h5\b", page.read_text(encoding="utf-8")), f"{page.name} names a .h5 file"
    metavars = {a.metavar for c in _subcommands().values() for a in c._actions if a.dest in ("out", "archive", "curve")}
    assert {m for m in metavars if not m.startswith("FIG")} == {"FILE.nc", "CURVE.nc"}


def test_basins_says_what_its_grid_is():
    text = " ".join(_help("basins").split())
    assert "NUM" not in text
    assert "--grid N " in text and "an N x N grid" in text and "1 <= N <= 400" in text


def test_archive_page_lists_every_status_code():
    row = next(line for line in (ROOT / "docs" / "archive.md").read_text(encoding="utf-8").splitlines()
               if line.startswith("| `status` | grid"))
    assert f"`flag_values` 0 to {len(STATUSES) - 1}: " + ", ".join(f"`{s}`" for s in STATUSES) in row


@pytest.mark.skipif(shutil.which("bash") is None, reason="no bash")
def test_bash_completion_offers_cases_settings_and_files(tmp_path):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["completion", "bash"]) == 0
    script_file = tmp_path.parent / f"{tmp_path.name}.bash"  # outside the folder whose files are offered
    script_file.write_text(out.getvalue(), encoding="utf-8")
    for name in ("mine.toml", "notes.txt", "mylaw.py"):
        (tmp_path / name).write_text("", encoding="utf-8")
    (tmp_path / "runs").mkdir()

    def offers(*words) -> set:
        line = " ".join(f"'{w}'" for w in ("phaseimpact", *words))
        script = (f"source {script_file}; COMP_WORDS=({line}); COMP_CWORD=$(( ${{#COMP_WORDS[@]}} - 1 )); "
                  "_phaseimpact; printf '%s\\n' \"${COMPREPLY[@]}\"")
        proc = subprocess.run(["bash", "-c", script], cwd=tmp_path, capture_output=True, text=True, timeout=60)
        assert proc.returncode == 0 and not proc.stderr, proc.stderr
        return set(proc.stdout.split())

    cases = {case["name"] for case in list_cases()}
    assert "seed" in cases and offers("simulate", "--case", "") == cases | {"mine.toml", "runs"}
    assert offers("simulate", "--set", "plate.n") == {"plate.nu="}
    assert offers("simulate", "--law-file", "") == {"mylaw.py", "runs"}
    for words in (("sweep", "--out"), ("atlas", "--out"), ("train", "--archive"), ("plot",),
                  ("plot", "x.nc", "--curve"), ("portrait", "--out")):
        assert offers(*words, "") == {"mine.toml", "notes.txt", "mylaw.py", "runs"}, words
    assert {"paper", "abrate", "mylaw.py"} <= offers("check-law", "") and "notes.txt" not in offers("check-law", "")
