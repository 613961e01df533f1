"""The package's layering (docs/design.md, "Layers"): every module belongs to a declared layer, imports
nothing from a layer above its own (at module level or inside a function), and no modules import
each other in a cycle. Read from the sources (``ast``), not by importing them.

A layer's unit is the first name under the package (``phaseimpact.integrate.api`` is in
``integrate``), so ``archive`` and ``cli`` are units whether they are modules or packages; ``""`` is
the package's face, ``phaseimpact/__init__.py``. A dotted unit (``integrate.batch``) layers a
package's own modules: it is the unit of the modules under it, and a package's face (its
``__init__.py``) may import any module of its package, as it re-exports them.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: The layers, bottom to top: a unit imports its own layer and those below, never one above.
LAYERS = (
    ("_environment", "_lazy", "_signals", "_atomic", "_version", "cases"),  # no import of the package
    ("_jit",),  # the compiler's hooks and cache (the engine's sources import it)
    ("parameters",),
    ("model",),  # all physics: laws, equations of motion, restitution, contact mechanics
    ("integrate", "_oracle", "cuda"),  # trajectories (the scipy oracle of the checks; the GPU's launches)
    ("integrate.batch", "integrate.precompile"),  # many runs at once, over integrate.api's one; the warm-up
    ("case", "settings"),  # case files (read the laws' names) and their --set settings
    ("analysis", "quantities", "checks"),  # one trajectory or one law at a time
    ("continuation",),  # sweeps, atlases, transitions, curves (the only joblib/Dask importer)
    ("maps", "train"),  # maps of a state to the next (ImpactMap), trains of impacts; train is the face
    ("archive",),  # HDF5 / netCDF-4 (h5py), the studies' figure data included
    ("plotting",),  # matplotlib
    ("cli",),
    ("", "_entry", "__main__"),  # the package's face and the entry points
)

#: Cycles through imports inside functions (a module-level cycle is never allowed) that are known and
#: due to be broken, each with the edit that breaks it. An entry that no longer occurs fails the test.
KNOWN_CYCLES: set = set()


def _module(package_root: Path, path: Path) -> str:
    parts = list(path.relative_to(package_root.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(package_root: Path, path: Path) -> list[tuple[str, int, bool]]:
    """(module imported, line, whether at module level) for each import of ``path`` within the
    package; ``from X import name`` counts as the submodule ``X.name`` where that is a module."""
    tree = ast.parse(path.read_text(), str(path))
    top = {id(node) for node in tree.body}
    here = _module(package_root, path).split(".")
    package = here if path.name == "__init__.py" else here[:-1]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            module = ".".join(base + ([node.module] if node.module else []))
            names = []
            for alias in node.names:
                sub = package_root.parent.joinpath(*f"{module}.{alias.name}".split("."))
                names.append(f"{module}.{alias.name}" if sub.with_suffix(".py").is_file()
                             or (sub / "__init__.py").is_file() else module)
        else:
            continue
        found.extend((name, node.lineno, id(node) in top) for name in names
                     if name.split(".")[0] == package_root.name)
    return found


def _unit(module: str, units=frozenset()) -> str:
    """The layer's unit of a module: the longest of ``units`` it is in (``integrate.batch``), else the
    first name under the package; "" for the package itself."""
    parts = module.split(".")[1:]
    for end in range(len(parts), 1, -1):
        if ".".join(parts[:end]) in units:
            return ".".join(parts[:end])
    return parts[0] if parts else ""


def layering_errors(package_root: Path, layers=LAYERS, known_cycles=frozenset()) -> list[str]:
    """Modules in no layer, imports from a layer above (module level or inside a function), cycles
    through module-level imports, and cycles through any imports but ``known_cycles`` (each a sorted
    tuple of the cycle's modules; one that no longer occurs is reported too)."""
    level = {unit: i for i, names in enumerate(layers) for unit in names}
    top_graph: dict[str, set[str]] = {}
    any_graph: dict[str, set[str]] = {}
    errors = []
    for path in sorted(package_root.rglob("*.py")):
        module = _module(package_root, path)
        top_graph[module], any_graph[module] = set(), set()
        if _unit(module, level) not in level:
            errors.append(f"{path.relative_to(package_root.parent)}: {module} is in no layer")
            continue
        for target, line, at_top in _imports(package_root, path):
            any_graph[module].add(target)
            if at_top:
                top_graph[module].add(target)
            own_module = path.name == "__init__.py" and target.startswith(module + ".")
            if not own_module and level.get(_unit(target, level), -1) > level[_unit(module, level)]:
                errors.append(f"{path.relative_to(package_root.parent)}:{line}: {module} imports {target}, "
                              f"a layer above it")
    for cycle in _cycles(top_graph):
        errors.append("import cycle: " + " -> ".join([*cycle, cycle[0]]))
    cycles = {tuple(cycle) for cycle in _cycles(any_graph)}
    for cycle in sorted(cycles - set(known_cycles) - {tuple(c) for c in _cycles(top_graph)}):
        errors.append("import cycle (inside functions): " + " -> ".join([*cycle, cycle[0]]))
    for cycle in sorted(set(known_cycles) - cycles):
        errors.append("known cycle no longer found (remove it from KNOWN_CYCLES): " + " -> ".join(cycle))
    return errors


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The modules of each strongly connected component with more than one module (or a module
    importing itself), sorted."""
    index, low, stack, on_stack, components = {}, {}, [], set(), []

    def visit(node):
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(graph.get(node, ())):
            if nxt not in graph:
                continue
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1 or node in graph.get(node, ()):
                components.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return components


def test_the_package_imports_downwards_only_and_has_no_cycle():
    assert layering_errors(ROOT / "phaseimpact", LAYERS, KNOWN_CYCLES) == []


def test_every_declared_unit_exists():
    """A layer naming a module that is gone would let its replacement go unchecked."""
    for unit in (u for layer in LAYERS for u in layer if u):
        path = ROOT / "phaseimpact" / unit.replace(".", "/")
        assert path.with_suffix(".py").is_file() or path.is_dir(), unit


LAYERS_OF_TEST = (("_jit",), ("model",), ("integrate",), ("integrate.batch",), ("continuation",), ("cli",), ("",))


def _package(tmp_path: Path, files: dict[str, str]) -> Path:
    root = tmp_path / "pkg"
    for name, text in {"__init__.py": "", "integrate/__init__.py": "", "model/__init__.py": "", **files}.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)
    return root


@pytest.mark.parametrize(("files", "expected"), [
    ({"cli.py": "", "integrate/api.py": "def f():\n    from ..cli import main\n"},
     ["pkg/integrate/api.py:2: pkg.integrate.api imports pkg.cli, a layer above it"]),
    ({"integrate/api.py": "from .. import __version__\n"},
     ["pkg/integrate/api.py:1: pkg.integrate.api imports pkg, a layer above it"]),
    ({"continuation/__init__.py": "", "model/laws.py": "import pkg.continuation.branch\n"},
     ["pkg/model/laws.py:1: pkg.model.laws imports pkg.continuation.branch, a layer above it"]),
    ({"cli/__init__.py": "", "cli/run.py": "from ..continuation import sweep\n", "continuation/__init__.py": "",
      "continuation/sweep.py": "from ..cli import run\n"},
     ["pkg/continuation/sweep.py:1: pkg.continuation.sweep imports pkg.cli.run, a layer above it",
      "import cycle: pkg.cli.run -> pkg.continuation.sweep -> pkg.cli.run"]),
    ({"model/laws.py": "from . import rhs\n", "model/rhs.py": "from .laws import force\n"},
     ["import cycle: pkg.model.laws -> pkg.model.rhs -> pkg.model.laws"]),
    ({"model/laws.py": "def f():\n    from . import rhs\n", "model/rhs.py": "from .laws import force\n"},
     ["import cycle (inside functions): pkg.model.laws -> pkg.model.rhs -> pkg.model.laws"]),
    ({"plotting.py": ""}, ["pkg/plotting.py: pkg.plotting is in no layer"]),
    ({"integrate/batch.py": "", "integrate/api.py": "def f():\n    from .batch import run_batch\n"},
     ["pkg/integrate/api.py:2: pkg.integrate.api imports pkg.integrate.batch, a layer above it"]),
    ({"_jit.py": "", "integrate/driver.py": "from .. import _jit\nfrom ..model import rhs\n", "model/rhs.py": "",
      "cli.py": "from .integrate import driver\n"}, []),
    ({"integrate/api.py": "", "integrate/batch.py": "from .api import check\n",
      "integrate/__init__.py": "from .api import simulate\nfrom .batch import simulate_many\n",
      "continuation/__init__.py": "from ..integrate.batch import run_batch\n"}, []),
], ids=["nested-upward", "package-face", "absolute-upward", "package-to-package", "cycle", "cycle-in-function",
        "undeclared", "within-a-package", "allowed", "within-a-package-allowed"])
def test_the_check_finds_upward_imports_cycles_and_strays(tmp_path, files, expected):
    assert layering_errors(_package(tmp_path, files), LAYERS_OF_TEST) == expected


def test_a_known_cycle_is_allowed_until_it_is_gone(tmp_path):
    files = {"model/laws.py": "def f():\n    from . import rhs\n", "model/rhs.py": "from .laws import force\n"}
    known = {("pkg.model.laws", "pkg.model.rhs")}
    assert layering_errors(_package(tmp_path, files), LAYERS_OF_TEST, known) == []
    files["model/laws.py"] = ""
    assert layering_errors(_package(tmp_path, files), LAYERS_OF_TEST, known) == [
        "known cycle no longer found (remove it from KNOWN_CYCLES): pkg.model.laws -> pkg.model.rhs"]
