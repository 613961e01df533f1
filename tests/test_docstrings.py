"""Docstrings of the public API: every example runs (doctest) and shows what the code prints, and
every public function, class and method documents itself in the numpy style (numpydoc's section
headers: ``Parameters``, ``Returns``, ``Raises``, ``Examples``)."""

import ast
import doctest
import importlib
import inspect
import re
import tempfile
import textwrap
from functools import cached_property

import pytest

MODULES = (
    "phaseimpact.integrate.api",
    "phaseimpact.integrate.batch",
    "phaseimpact.integrate.result",
    "phaseimpact.continuation",
    "phaseimpact.continuation.sweep",
    "phaseimpact.continuation.grid",
    "phaseimpact.continuation.transition",
    "phaseimpact.continuation.kappa_2",
    "phaseimpact.continuation.grazing",
    "phaseimpact.continuation._kappa_search",
    "phaseimpact.continuation.curve",
    "phaseimpact.continuation.boundary",
    "phaseimpact.continuation.confirm",
    "phaseimpact.archive",
    "phaseimpact.analysis",
    "phaseimpact.plotting._style",
    "phaseimpact.plotting._results",
    "phaseimpact.plotting._impact_map",
    "phaseimpact.quantities",
    "phaseimpact.train",
    "phaseimpact.maps",
    "phaseimpact.maps.base",
    "phaseimpact.maps.impact",
    "phaseimpact.maps.impact_analyses",
    "phaseimpact.maps.orbit_diagram",
    "phaseimpact.maps.basins",
    "phaseimpact.maps.continuation",
    "phaseimpact",
    "phaseimpact.parameters",
    "phaseimpact.case",
    "phaseimpact.settings",
    "phaseimpact.model",
    "phaseimpact.model.contact",
    "phaseimpact.model.laws",
    "phaseimpact.model.forms",
    "phaseimpact.model.userlaw",
    "phaseimpact.model.restitution",
    "phaseimpact.model.rhs",
    "phaseimpact.model.laminate",
    "phaseimpact.model.plate_stiffness",
    "phaseimpact.model.regime",
    "phaseimpact.checks",
    "phaseimpact.integrate",
)
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def _module(name: str):
    # importlib, not attribute access: phaseimpact.continuation.sweep is also the name of a function
    return importlib.import_module(name)


@pytest.mark.parametrize("name", MODULES)
def test_examples_run(name, tmp_path, monkeypatch):
    """Each module's examples give exactly the output shown (files they write go to tmp_path)."""
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))  # tempfile.mkdtemp() in examples: below tmp_path
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)  # an example sets and deletes it: restored after
    module = _module(name)
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    report = []
    for test in doctest.DocTestFinder(exclude_empty=True).find(module, name):
        runner.run(test, out=report.append)
    failed, attempted = runner.summarize(verbose=False)
    assert attempted > 0, f"{name}: no examples"
    assert failed == 0, f"{name}: {failed} of {attempted} examples fail:\n" + "".join(report)


def _section(doc: str, title: str) -> bool:
    """Whether ``doc`` has a numpydoc section ``title`` (the title, then a line of dashes)."""
    return re.search(rf"^\s*{title}\s*\n\s*-{{3,}}\s*$", doc, re.MULTILINE) is not None


def _own_nodes(function: ast.AST):
    """The AST nodes of ``function``'s own body, without those of functions and classes inside it."""
    todo = list(ast.iter_child_nodes(function))
    while todo:
        node = todo.pop()
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda | ast.ClassDef):
            continue
        yield node
        todo.extend(ast.iter_child_nodes(node))


def _behaviour(function) -> set:
    """What ``function``'s own code does: ``returns`` (a value), ``yields``, ``raises`` (an exception of
    its own; a bare re-raise does not count)."""
    source = textwrap.dedent(inspect.getsource(inspect.unwrap(function)))
    tree = ast.parse(source)
    node = next(n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef))
    found = set()
    for n in _own_nodes(node):
        if isinstance(n, ast.Return) and n.value is not None and not (
                isinstance(n.value, ast.Constant) and n.value.value is None):
            found.add("returns")
        elif isinstance(n, ast.Yield | ast.YieldFrom):
            found.add("yields")
        elif isinstance(n, ast.Raise) and n.exc is not None:
            found.add("raises")
    return found


def _takes_arguments(function) -> bool:
    """Whether a function written in Python takes an argument besides ``self`` or ``cls``."""
    function = inspect.unwrap(function)
    if not inspect.isfunction(function):  # an __init__ inherited from a builtin (an exception class)
        return False
    names = list(inspect.signature(function).parameters)
    if names and names[0] in ("self", "cls"):
        names = names[1:]
    return bool(names)


def _missing_in_function(function) -> list[str]:
    doc = inspect.getdoc(function) or ""
    if not doc.strip():
        return ["a docstring"]
    does = _behaviour(function)
    missing = []
    if _takes_arguments(function) and not _section(doc, "Parameters"):
        missing.append("Parameters")
    if "returns" in does and not _section(doc, "Returns"):
        missing.append("Returns")
    if "yields" in does and not (_section(doc, "Yields") or _section(doc, "Returns")):
        missing.append("Yields")
    if "raises" in does and not _section(doc, "Raises"):
        missing.append("Raises")
    if not _section(doc, "Examples"):
        missing.append("Examples")
    return missing


def _missing_in_class(cls) -> list[str]:
    doc = inspect.cleandoc(vars(cls).get("__doc__") or "")  # its own, not a base class's
    if not doc:
        return ["a docstring"]
    missing = []
    if _takes_arguments(cls.__init__) and not (_section(doc, "Attributes") or _section(doc, "Parameters")):
        missing.append("Attributes or Parameters")
    if not _section(doc, "Examples"):
        missing.append("Examples")
    return missing


def _methods(cls):
    """The public methods a user calls, defined by ``cls`` itself (properties and dunders are exempt)."""
    for name, member in vars(cls).items():
        if name.startswith("_") or isinstance(member, property | cached_property):
            continue
        if isinstance(member, classmethod | staticmethod):
            member = member.__func__
        if inspect.isfunction(member):
            yield name, member


def _public_objects():
    """Every public function and class of :data:`MODULES` (their ``__all__``), each once."""
    seen = {}
    for name in MODULES:
        module = _module(name)
        for attr in module.__all__:
            obj = getattr(module, attr)
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and id(obj) not in seen:
                seen[id(obj)] = (f"{obj.__module__}.{obj.__qualname__}", obj)
    return list(seen.values())


def test_public_objects_are_found():
    """The check below sees the API (not an empty list that passes whatever the docstrings say)."""
    names = {name for name, _ in _public_objects()}
    for expected in ("phaseimpact.integrate.api.simulate", "phaseimpact.integrate.result.Trajectory",
                     "phaseimpact.continuation.sweep.atlas", "phaseimpact.archive.Checkpoint",
                     "phaseimpact.plotting._style.style", "phaseimpact.quantities.impact_quantities"):
        assert expected in names
    assert len(names) > 60


def test_numpy_sections():
    """Every public function, class and method documents what it takes, returns and raises, with examples."""
    problems = []
    for name, obj in _public_objects():
        if inspect.isclass(obj):
            missing = _missing_in_class(obj)
            problems += [f"{name}: missing {', '.join(missing)}"] if missing else []
            for method_name, method in _methods(obj):
                missing = _missing_in_function(method)
                problems += [f"{name}.{method_name}: missing {', '.join(missing)}"] if missing else []
        else:
            missing = _missing_in_function(obj)
            problems += [f"{name}: missing {', '.join(missing)}"] if missing else []
    assert not problems, "docstrings incomplete:\n" + "\n".join(problems)


def test_section_check_can_fail():
    """The checks above tell a complete docstring from an incomplete one."""

    def complete(x):
        """Twice ``x``.

        Parameters
        ----------
        x : float

        Returns
        -------
        float

        Raises
        ------
        ValueError
            For a negative ``x``.

        Examples
        --------
        >>> complete(1.0)
        2.0
        """
        if x < 0:
            raise ValueError(x)
        return 2 * x

    def incomplete(x):
        """Twice ``x``; Parameters, Returns and Examples named but not as sections."""
        if x < 0:
            raise ValueError(x)
        return 2 * x

    assert _missing_in_function(complete) == []
    assert _missing_in_function(incomplete) == ["Parameters", "Returns", "Raises", "Examples"]
