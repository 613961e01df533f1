"""The engine's layering: ``phaseimpact/integrate`` and ``phaseimpact/model`` import nothing above
them (the analyses, the archive, the command line, plotting, the package's face) and no module of
theirs is part of an import cycle. Read from the sources (``ast``), not by importing them."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: The layers below everything else.
ENGINE = ("integrate", "model")
#: What they may not import, at any depth ("" is the package face, ``phaseimpact/__init__.py``).
ABOVE = ("", "continuation", "analysis", "maps", "archive", "cli", "plotting", "train")


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


def layering_errors(package_root: Path) -> list[str]:
    """Upward imports from the engine's layers (any depth) and import cycles through them (imports
    at module level: a function-level import runs after every module is loaded)."""
    name = package_root.name
    engine = tuple(f"{name}.{layer}" for layer in ENGINE)
    above = tuple(f"{name}.{layer}".rstrip(".") for layer in ABOVE)
    graph: dict[str, set[str]] = {}
    errors = []
    for path in sorted(package_root.rglob("*.py")):
        module = _module(package_root, path)
        graph[module] = set()
        for target, line, at_top in _imports(package_root, path):
            if at_top:
                graph[module].add(target)
            in_engine = any(module == e or module.startswith(e + ".") for e in engine)
            upward = any(target == a if a == name else target == a or target.startswith(a + ".") for a in above)
            if in_engine and upward:
                errors.append(f"{path.relative_to(package_root.parent)}:{line}: {module} imports {target}, above it")
    for cycle in _cycles(graph):
        if any(m == e or m.startswith(e + ".") for m in cycle for e in engine):
            errors.append("import cycle: " + " -> ".join([*cycle, cycle[0]]))
    return errors


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """One cycle through each strongly connected component with more than one module (or a module
    importing itself)."""
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


def test_the_engine_imports_nothing_above_it_and_is_in_no_cycle():
    assert layering_errors(ROOT / "phaseimpact") == []


def _package(tmp_path: Path, files: dict[str, str]) -> Path:
    root = tmp_path / "pkg"
    for name, text in {"__init__.py": "", "integrate/__init__.py": "", "model/__init__.py": "", **files}.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)
    return root


@pytest.mark.parametrize(("files", "expected"), [
    ({"cli.py": "", "integrate/api.py": "def f():\n    from ..cli import main\n"},
     ["pkg/integrate/api.py:2: pkg.integrate.api imports pkg.cli, above it"]),
    ({"integrate/api.py": "from .. import __version__\n"},
     ["pkg/integrate/api.py:1: pkg.integrate.api imports pkg, above it"]),
    ({"continuation/__init__.py": "", "model/laws.py": "import pkg.continuation.branch\n"},
     ["pkg/model/laws.py:1: pkg.model.laws imports pkg.continuation.branch, above it"]),
    ({"model/laws.py": "from . import rhs\n", "model/rhs.py": "from .laws import force\n"},
     ["import cycle: pkg.model.laws -> pkg.model.rhs -> pkg.model.laws"]),
    ({"model/laws.py": "def f():\n    from . import rhs\n", "model/rhs.py": "from .laws import force\n",
      "_jit.py": "", "integrate/driver.py": "from .. import _jit\nfrom ..model import rhs\n"}, []),
], ids=["nested-upward", "package-face", "absolute-upward", "cycle", "allowed"])
def test_the_check_finds_upward_imports_and_cycles(tmp_path, files, expected):
    assert layering_errors(_package(tmp_path, files)) == expected
