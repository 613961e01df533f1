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
#: archives and captions, which the gallery, test_figures, test_studies and test_statements read).
NEEDED = ("tests", "studies", "docs", "benchmarks", "figures")
#: The quick tests run from the unpacked sdist: those that read what the sdist must carry besides the
#: package (the figures and their data, the studies, the docs pages), not marked slow; the whole
#: suite there would take as long as ``make test``.
FROM_SDIST = ("tests/test_figures.py", "tests/test_studies.py", "tests/test_statements.py", "tests/test_docs.py",
              "tests/test_parameters.py")
#: An sdist larger than this is carrying something by mistake (it is about 9.9 MB: the figures' PNGs,
#: PDFs and HDF5 archives are most of it).
MAX_SDIST_BYTES = 15_000_000

pytestmark = pytest.mark.slow


def _build(kind: str, out: Path) -> Path:
    code = f"from setuptools import build_meta as b; print(b.build_{kind}({str(out)!r}))"
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    return out / done.stdout.strip().splitlines()[-1]


def _source_files() -> set[str]:
    """The tracked files under :data:`NEEDED` (the working tree's files where git is missing)."""
    try:
        listed = subprocess.run(["git", "ls-files", *NEEDED], cwd=ROOT, capture_output=True, text=True, check=True)
        return set(listed.stdout.split())
    except (OSError, subprocess.CalledProcessError):
        return {str(p.relative_to(ROOT)) for d in NEEDED for p in (ROOT / d).rglob("*")
                if p.is_file() and "__pycache__" not in p.parts and "results" not in p.parts}


def test_sdist_has_every_test_input_and_its_tests_run(tmp_path):
    sdist = _build("sdist", tmp_path)
    with tarfile.open(sdist) as tar:
        top = tar.getnames()[0].split("/")[0]
        names = {n.removeprefix(top + "/") for n in tar.getnames()}
        tar.extractall(tmp_path / "unpacked", filter="data")
    missing = sorted(_source_files() - names)
    assert not missing, f"files the tests need are not in the sdist: {missing[:10]}"
    assert sdist.stat().st_size < MAX_SDIST_BYTES and not any(n.startswith("figures/preview") for n in names)
    assert {"phaseimpact/_oracle.py", "Makefile", "mkdocs.yml", "phaseimpact/docs/physics.md"} <= names
    # Collecting every test imports each test module from the unpacked sdist.
    tree = tmp_path / "unpacked" / top
    collected = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider",
                                "tests"], cwd=tree, capture_output=True, text=True)
    assert collected.returncode == 0, collected.stdout[-2000:] + collected.stderr[-2000:]
    assert " tests collected" in collected.stdout
    env = {**os.environ, "PYTHONPATH": str(tree)}  # the sdist's own package, not this checkout's
    ran = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-m", "not slow",
                          *FROM_SDIST], cwd=tree, env=env, capture_output=True, text=True)
    assert ran.returncode == 0, ran.stdout[-3000:]
    assert re.search(r"\b\d{3,} passed", ran.stdout) and " skipped" not in ran.stdout, ran.stdout[-500:]
    site = tmp_path / "site"
    built = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)], cwd=tree,
                           env=env, capture_output=True, text=True)
    assert built.returncode == 0, built.stderr[-3000:]
    assert (site / "gallery" / "index.html").is_file() and (site / "changelog" / "index.html").is_file()


def test_wheel_carries_the_physics_notes_archives_cite(tmp_path):
    wheel = _build("wheel", tmp_path)
    with zipfile.ZipFile(wheel) as whl:
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


def test_mypy_sees_the_types_of_the_installed_package(tmp_path):
    """py.typed ships, and the lazily imported top-level names have their types for a type checker."""
    wheel = _build("wheel", tmp_path)
    target = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--target", str(target),
                    str(wheel)], check=True, capture_output=True)
    (tmp_path / "user.py").write_text(USER_SCRIPT)
    # mypy reads the package from the target (on the interpreter's path), as an installed package: its
    # types are used only because of py.typed
    env = {"PATH": "/usr/bin:/bin", "PYTHONPATH": str(target)}
    done = subprocess.run([sys.executable, "-m", "mypy", "--no-incremental", "user.py"], cwd=tmp_path, env=env,
                          capture_output=True, text=True)
    assert 'Revealed type is "phaseimpact.integrate.result.Trajectory"' in done.stdout, done.stdout
    assert 'expression has type "float", variable has type "str"' in done.stdout, done.stdout
