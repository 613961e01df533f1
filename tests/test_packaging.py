"""What the distributions carry: the sdist is enough to run the tests, the wheel carries the physics
notes that archives cite."""

import os
import re
import subprocess
import sys
import tarfile
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: Everything a test imports or reads from the source tree (figures: the committed figures, their
#: archives and captions, which the gallery, test_figures, test_studies and test_statements read),
#: and the package itself, file for file.
NEEDED = ("phaseimpact", "tests", "studies", "docs", "benchmarks", "figures")
#: What runs from the unpacked sdist, by this rule: every test file that is not all slow runs there.
#: The files that read what the sdist carries besides the package (the figures and their data, the
#: studies, the docs pages: these) run all their quick tests; every other file runs its first quick
#: test (its imports, fixtures and the package from the sdist; INSTEAD_OF_THE_FIRST where that one
#: would compile the engine cold). Their other quick tests exercise the package, which the sdist
#: carries file for file (NEEDED) and ``make test`` runs from the checkout: all of them again would
#: nearly double ``make test`` (1499 of its 1544 tests are quick; this rule picks 248 of them).
READS_THE_TREE = ("tests/test_figures.py", "tests/test_studies.py", "tests/test_statements.py", "tests/test_docs.py",
                  "tests/test_readme.py")
#: ``make test-sdist`` (PHASEIMPACT_SDIST_ALL=1) runs every quick test from the sdist instead: the whole
#: quick subset, as a release check outside ``make test``'s ten minutes.
EVERY_QUICK_TEST = os.environ.get("PHASEIMPACT_SDIST_ALL") == "1"
#: A file whose first quick test compiles a whole cold engine session (minutes) runs this one instead.
INSTEAD_OF_THE_FIRST = {
    "tests/test_precompile.py": "tests/test_precompile.py::test_the_announcement_says_when_nothing_is_cached"}
#: The suite's stated skips (any other skip from the sdist fails the test).
SKIP_REASONS = ("root", "git checkout", "git history", "NVVM", "Linux x86_64")
#: An sdist larger than this is carrying something by mistake (it is about 9.9 MB: the figures' PNGs,
#: PDFs and HDF5 archives are most of it).
MAX_SDIST_BYTES = 15_000_000

pytestmark = pytest.mark.slow


def _source_files() -> set[str]:
    """The tracked files under :data:`NEEDED` (the working tree's files where git is missing)."""
    try:
        listed = subprocess.run(["git", "ls-files", *NEEDED], cwd=ROOT, capture_output=True, text=True, check=True)
        return set(listed.stdout.split())
    except (OSError, subprocess.CalledProcessError):
        return {str(p.relative_to(ROOT)) for d in NEEDED for p in (ROOT / d).rglob("*")
                if p.is_file() and "__pycache__" not in p.parts and "results" not in p.parts}


def test_sdist_has_every_test_input_and_its_tests_run(built_sdist, tmp_path):
    with tarfile.open(built_sdist) as tar:
        top = tar.getnames()[0].split("/")[0]
        names = {n.removeprefix(top + "/") for n in tar.getnames()}
        tar.extractall(tmp_path / "unpacked", filter="data")
    missing = sorted(_source_files() - names)
    assert not missing, f"files the tests need are not in the sdist: {missing[:10]}"
    assert built_sdist.stat().st_size < MAX_SDIST_BYTES and not any(n.startswith("figures/preview") for n in names)
    assert {"phaseimpact/_oracle.py", "Makefile", "mkdocs.yml", "phaseimpact/docs/physics.md"} <= names
    # Collecting every test imports each test module from the unpacked sdist.
    tree = tmp_path / "unpacked" / top
    env = {**os.environ, "PYTHONPATH": str(tree)}  # the sdist's own package, not this checkout's
    collected = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider",
                                "-m", "not slow", "tests"], cwd=tree, env=env, capture_output=True, text=True)
    assert collected.returncode == 0, collected.stdout[-2000:] + collected.stderr[-2000:]
    quick = [line for line in collected.stdout.splitlines() if line.startswith("tests/test_") and "::" in line]
    selected = _sdist_selection(quick)
    every_file = {line.split("::")[0] for line in quick}
    assert {t.split("::")[0] for t in selected} == every_file and len(every_file) >= 30
    # pytest's cache in a scratch folder (test_precompile keeps a cold session's output there)
    ran = subprocess.run([sys.executable, "-m", "pytest", "-q", "-rs", "-o", f"cache_dir={tmp_path / 'cache'}",
                          *selected],
                         cwd=tree, env=env, capture_output=True, text=True)
    assert ran.returncode == 0, ran.stdout[-3000:]
    passed = re.search(r"\b(\d+) passed", ran.stdout)
    skipped = [line for line in ran.stdout.splitlines() if line.startswith("SKIPPED")]
    assert passed and int(passed.group(1)) + len(skipped) >= len(selected), ran.stdout[-500:]
    # a skip is only one of the suite's stated ones (root only, no git checkout or history, no CUDA
    # compiler, another platform), never a file the sdist lacks
    assert all(any(reason in line for reason in SKIP_REASONS) for line in skipped), skipped
    assert "not in the sdist" not in ran.stdout and "No such file" not in ran.stdout, ran.stdout[-2000:]
    site = tmp_path / "site"
    built = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)], cwd=tree,
                           env=env, capture_output=True, text=True)
    assert built.returncode == 0, built.stderr[-3000:]
    assert (site / "gallery" / "index.html").is_file() and (site / "changelog" / "index.html").is_file()


def _sdist_selection(quick: list[str]) -> list[str]:
    """The quick tests (node ids, in collection order) that run from the sdist: :data:`READS_THE_TREE`."""
    if EVERY_QUICK_TEST:
        return list(quick)
    first = dict(INSTEAD_OF_THE_FIRST)
    for node in quick:
        first.setdefault(node.split("::")[0], node)
    return [node for node in quick if node.split("::")[0] in READS_THE_TREE or first[node.split("::")[0]] == node]


def test_the_sdist_selection_keeps_every_file():
    quick = ["tests/test_docs.py::a", "tests/test_docs.py::b", "tests/test_laws.py::c[1]", "tests/test_laws.py::c[2]",
             "tests/test_precompile.py::cold", *INSTEAD_OF_THE_FIRST.values()]
    assert _sdist_selection(quick) == ["tests/test_docs.py::a", "tests/test_docs.py::b", "tests/test_laws.py::c[1]",
                                       *INSTEAD_OF_THE_FIRST.values()]


def test_wheel_carries_the_physics_notes_archives_cite(built_wheel):
    with zipfile.ZipFile(built_wheel) as whl:
        notes = whl.read("phaseimpact/docs/physics.md").decode()
        assert "py.typed" in " ".join(whl.namelist())
    assert notes == (ROOT / "docs" / "physics.md").read_text()
    assert "§5" in notes or "## 5" in notes


USER_SCRIPT = """\
import phaseimpact as pi

trajectory = pi.simulate(pi.seed_parameters(v=1.0), "paper")
reveal_type(trajectory)
wrong: str = trajectory.max_force
"""


def test_mypy_sees_the_types_of_the_installed_package(installed_wheel, tmp_path):
    """py.typed ships, and the lazily imported top-level names have their types for a type checker."""
    (tmp_path / "user.py").write_text(USER_SCRIPT)
    # mypy reads the package from the target (on the interpreter's path), as an installed package: its
    # types are used only because of py.typed
    env = {"PATH": "/usr/bin:/bin", "PYTHONPATH": str(installed_wheel)}
    done = subprocess.run([sys.executable, "-m", "mypy", "--no-incremental", "user.py"], cwd=tmp_path, env=env,
                          capture_output=True, text=True)
    assert 'Revealed type is "phaseimpact.integrate.result.Trajectory"' in done.stdout, done.stdout
    assert 'expression has type "float", variable has type "str"' in done.stdout, done.stdout
