"""The archive package: one record per kind in its registry (the guide's example, run as written, adds
a kind that saves, loads, converts and describes like the shipped ones), one ``open_for_resume`` for
the resumable commands, and the package's shape (no import cycle, no module or function too long)."""

import ast
import re
from pathlib import Path

import numpy as np
import pytest
from _registry import restored_archive_kinds
from test_imports import _cycles, _imports

from phaseimpact import archive, seed_parameters
from phaseimpact.archive import _registry
from phaseimpact.cli import main
from phaseimpact.continuation import critical_curve, sweep
from phaseimpact.model import ContactLaw

PACKAGE = Path(archive.__file__).parent


def _guide_example() -> str:
    """The code block of the registry's guide (after ``For example``), dedented."""
    doc = _registry.__doc__
    block = doc[doc.index("For example"):].split("::\n\n", 1)[1]
    lines = []
    for line in block.split("\n"):
        if line and not line.startswith("    "):
            break
        lines.append(line[4:])
    return "\n".join(lines)


def test_the_guides_example_adds_a_kind_that_round_trips(tmp_path):
    """Write, load, describe and to_xarray of a kind that is one record (the guide's code, run as written)."""
    with restored_archive_kinds():
        space = {}
        exec(compile(_guide_example(), "guide", "exec"), space)  # noqa: S102  (the docstring's own example)
        forces = np.array([1.5, -0.0, 2e3]).view(space["Forces"])
        assert archive.kind_of(forces) == "forces"
        params, law = seed_parameters(kappa=3e9), ContactLaw("hunt-crossley")
        path = archive.save(forces, tmp_path / "forces.nc", params=params, law=law)
        back = archive.load(path)
        assert type(back) is space["Forces"] and back.tobytes() == forces.tobytes()  # bit for bit, -0.0 too
        held = archive.describe(path)
        assert held["kind"] == "forces" and held["law"] == law.as_dict() and held["axes"] == {}
        ds = archive.to_xarray(forces, params=params, law=law)
        assert ds.attrs["kind"] == "forces" and ds.force.attrs["units"] == "N"
        assert np.array_equal(ds.force.values, forces)
        with pytest.raises(TypeError, match="needs params= and law="):  # a result without its case, as a train's
            archive.save(forces, tmp_path / "other.nc")
        archive.unregister_kind("forces")
        with pytest.raises(archive.DamagedArchiveError, match="kind = 'forces' is out of range"):
            archive.load(path)  # removed: its files are no archive this process reads
    assert "forces" not in archive.REGISTRY


def test_the_registry_holds_each_shipped_kind_once_in_order():
    assert tuple(archive.REGISTRY) == archive.KINDS + archive.RUN_KINDS + archive.TRAIN_KINDS
    assert [r.name for r in archive.REGISTRY.values() if r.resumable] == ["sweep", "atlas"]
    with pytest.raises(ValueError, match="already registered"):
        archive.register_kind(archive.REGISTRY["basins"])
    with pytest.raises(TypeError, match="ArchiveKind"):
        archive.register_kind("basins")


# -- open_for_resume -----------------------------------------------------------------------------

def _sweep_work(kappa, rtol=1e-10):
    return ("sweep", ContactLaw("paper"), seed_parameters(), {"kappa": np.asarray(kappa)}, None, rtol)


def test_open_for_resume_gives_the_archive_to_complete_and_a_checkpoint(tmp_path):
    path = tmp_path / "s.nc"
    previous, checkpoint = archive.open_for_resume(path, *_sweep_work([1e9, 1e13]), resume=True)
    assert previous is None and checkpoint.path == str(path) and not path.exists()  # nothing to complete yet
    done = sweep(seed_parameters(), "paper", [1e9, 1e13])
    archive.save(done, path)
    previous, checkpoint = archive.open_for_resume(path, *_sweep_work([1e9, 1e13]), resume=True)
    assert np.array_equal(previous.max_force, done.max_force) and previous.done.all()
    assert checkpoint.force is False
    before = path.read_bytes()
    with pytest.raises(ValueError, match=r"resume: out = .* holds other work \(rtol 1e-10 \(asked 1e-09\)\)"):
        archive.open_for_resume(path, *_sweep_work([1e9, 1e13], rtol=1e-9), resume=True)
    with pytest.raises(ValueError, match="refusing to overwrite it"):  # no resume: the overwrite rule
        archive.open_for_resume(path, *_sweep_work([1e9, 1e12]), resume=False)
    previous, checkpoint = archive.open_for_resume(path, *_sweep_work([1e9, 1e12]), resume=False, force=True)
    assert previous is None and checkpoint.force is True
    assert path.read_bytes() == before  # refusals and a forced open write nothing


def test_open_for_resume_refuses_a_kind_resume_cannot_complete_as_the_command_line_does(tmp_path, capsys):
    """The same message as ``sweep --resume`` onto a critical curve (two paths to one refusal)."""
    curve = tmp_path / "curve.nc"
    archive.save(critical_curve(seed_parameters(), "paper", "v", [1.0]), curve)
    with pytest.raises(ValueError) as refused:
        archive.open_for_resume(curve, *_sweep_work(np.geomspace(1e9, 1e14, 3)), resume=True)
    assert "is a critical-curve archive, not a sweep or atlas" in str(refused.value)
    assert main(["sweep", "--law", "paper", "--v", "1", "--axis", "kappa=1e9:1e14:3:log", "--no-progress",
                 "--out", str(curve), "--resume"]) == 2
    assert str(refused.value) in capsys.readouterr().err


# -- the package's shape -------------------------------------------------------------------------

def test_the_archive_package_has_no_import_cycle_and_never_imports_its_face():
    graph = {}
    for path in sorted(PACKAGE.glob("*.py")):
        name = "phaseimpact.archive" + ("" if path.name == "__init__.py" else f".{path.stem}")
        targets = {target for target, _, at_top in _imports(PACKAGE.parent, path) if at_top}
        graph[name] = {t for t in targets if t.startswith("phaseimpact.archive")}
        if name != "phaseimpact.archive":
            assert "phaseimpact.archive" not in graph[name], f"{path.name} imports the package face"
    assert len(graph) > 10 and _cycles(graph) == []


def test_no_archive_module_over_800_lines_and_no_function_over_80():
    for path in sorted(PACKAGE.glob("*.py")):
        text = path.read_text()
        assert text.count("\n") <= 800, f"{path.name}: {text.count(chr(10))} lines"
        long = [(node.name, node.end_lineno - node.lineno + 1) for node in ast.walk(ast.parse(text))
                if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and node.end_lineno - node.lineno >= 80]
        assert long == [], f"{path.name}: {long}"


def test_the_shape_checks_can_fail():
    """The cycle finder sees a cycle (the test above asserts its absence with it)."""
    assert _cycles({"a": {"b"}, "b": {"a"}}) == [["a", "b"]]
    assert re.search(r"\bregister_kind\(ArchiveKind\(", _guide_example())
