"""Set-up shared by several test files, made once per test session (each costs seconds to minutes)."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: The files that take longest, longest first, as a two-worker run measured them (seconds of test time at
#: load ~2.8): the sdist sample, whose unpacked package compiles cold (358), the whole-library cold session
#: (219), every page's code blocks and the docs build (190), the CUDA simulator's grids (73), then files of
#: 40-71 s. ``make test`` runs the files on pytest-xdist workers, one file per worker at a time
#: (``--dist loadfile``: a module fixture is made once); these start first, so that no worker is left
#: running a long file at the end while the other waits.
LONG_POLES = ("tests/test_packaging.py", "tests/test_precompile.py", "tests/test_docs.py", "tests/test_cuda.py",
              "tests/test_signals.py", "tests/test_user_law_faults.py", "tests/test_check_law.py",
              "tests/test_cache.py", "tests/test_archive_cli.py", "tests/test_cli_inputs.py",
              "tests/test_disk_errors.py")


def pytest_collection_modifyitems(items):
    """The files of :data:`LONG_POLES` first, in its order, then the files with a slow test, then the rest
    (these in collection order); each file's tests together and in their order."""
    rank: dict[str, int] = {}
    for item in items:
        path = item.nodeid.split("::")[0]
        own = LONG_POLES.index(path) if path in LONG_POLES else len(LONG_POLES) + (
            0 if item.get_closest_marker("slow") else 1)
        rank[path] = min(rank.get(path, own), own)
    items.sort(key=lambda item: rank[item.nodeid.split("::")[0]])  # stable


def build_distribution(kind: str, out: Path) -> Path:
    """``kind`` ("wheel" or "sdist") built from this checkout by setuptools' PEP 517 backend into ``out``."""
    code = f"from setuptools import build_meta as b; print(b.build_{kind}({str(out)!r}))"
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    return out / done.stdout.strip().splitlines()[-1]


@pytest.fixture(scope="session")
def built_wheel(tmp_path_factory) -> Path:
    """The wheel of this checkout (test_packaging reads it, test_check_law and mypy use it installed)."""
    return build_distribution("wheel", tmp_path_factory.mktemp("wheel"))


@pytest.fixture(scope="session")
def built_sdist(tmp_path_factory) -> Path:
    """The sdist of this checkout (test_packaging unpacks it and runs tests from it)."""
    return build_distribution("sdist", tmp_path_factory.mktemp("sdist"))


@pytest.fixture(scope="session")
def installed_wheel(built_wheel, tmp_path_factory) -> Path:
    """:func:`built_wheel` installed by pip, offline and without dependencies, into its own folder
    (a ``--target``: put it on ``PYTHONPATH``; its console scripts are in ``bin/``)."""
    target = tmp_path_factory.mktemp("installed")
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--no-index", "--target",
                    str(target), str(built_wheel)], check=True, capture_output=True)
    return target
