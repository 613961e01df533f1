"""How ``make test`` runs the suite on two cores: the engine compiled once before pytest-xdist's workers
start, whole files on each worker, the long poles first (tests/conftest.py)."""

import re
from pathlib import Path

import conftest

ROOT = Path(__file__).resolve().parents[1]


def test_make_test_compiles_once_then_runs_whole_files_on_workers():
    """Two workers compiling the same kernels cold side by side would double the first compile; a file
    split over both workers would make its module fixtures (a cold session, the CUDA simulator's grids) twice."""
    recipe = re.search(r"^test: .*\n((?:\t.*\n)+)", (ROOT / "Makefile").read_text(), re.M).group(1).splitlines()
    commands = [line.strip() for line in recipe]
    warmup = commands.index("$(BIN)/phaseimpact warmup")
    run = next(i for i, line in enumerate(commands) if " -m pytest " in line)
    assert warmup < run and "-n $(TEST_JOBS) --dist loadfile --no-loadscope-reorder" in commands[run], commands
    assert all((ROOT / path).is_file() for path in conftest.LONG_POLES), conftest.LONG_POLES


class _Item:
    def __init__(self, nodeid: str, slow: bool = False):
        self.nodeid, self.slow = nodeid, slow

    def get_closest_marker(self, name: str):
        return object() if name == "slow" and self.slow else None


def test_the_long_poles_start_first_and_each_file_stays_in_its_order():
    items = [_Item("tests/test_a.py::x"), _Item("tests/test_a.py::y"), _Item("tests/test_b.py::quick"),
             _Item("tests/test_b.py::slow", slow=True), _Item("tests/test_cuda.py::c"),
             _Item("tests/test_packaging.py::p", slow=True), _Item("tests/test_precompile.py::cold")]
    conftest.pytest_collection_modifyitems(items)
    assert [item.nodeid for item in items] == [
        "tests/test_packaging.py::p", "tests/test_precompile.py::cold", "tests/test_cuda.py::c",
        "tests/test_b.py::quick", "tests/test_b.py::slow", "tests/test_a.py::x", "tests/test_a.py::y"]
