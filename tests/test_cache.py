"""Where the compiled engine is kept (phaseimpact/_jit.py): keyed on its sources, so an edit is
never run stale; never a crash where nothing can be written; and the commands that integrate
nothing never import numba."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from phaseimpact import _jit

ROOT = Path(__file__).resolve().parents[1]

# A contact force through rhs's cached machine code (the stale path of issue 22: numba checked only
# the caller's own file, while the force is compiled into it from model/forms.py); rhs and what it
# calls compile in seconds, the whole driver in minutes.
RUN = r"""
import json, sys
import numpy as np
import phaseimpact
from phaseimpact import seed_parameters
from phaseimpact._jit import cache_info
from phaseimpact.model.laws import as_law
from phaseimpact.model.rhs import pack, rhs
p, law = seed_parameters(v=1.0, kappa=3e9), as_law("hunt-crossley")
# in contact at rest (delta = 1e-5 m, no damping force): rhs (model/rhs.py) calls contact_force (model/forms.py)
force = rhs(law.code, pack(p, law), np.array([1e-5, 0.0, 0.0, 0.0, 0.0]), np.int64(1), np.empty(5))
print(json.dumps({"file": phaseimpact.__file__, "cache": str(cache_info().path), "force": force, "K": p.K}))
"""


def _copy_package(destination: Path) -> Path:
    # copy2 keeps the times, and nothing compiled comes along
    shutil.copytree(ROOT / "phaseimpact", destination / "phaseimpact", copy_function=shutil.copy2,
                    ignore=shutil.ignore_patterns("__pycache__"))
    return destination / "phaseimpact"


def _run(code: str, pythonpath: Path, **env) -> subprocess.CompletedProcess:
    environment = {**os.environ, "PYTHONPATH": str(pythonpath), **env}
    environment.pop("NUMBA_DISABLE_JIT", None)
    # run from the copy's parent: the checkout in the working directory must not shadow it
    return subprocess.run([sys.executable, "-c", code], cwd=pythonpath, env=environment, capture_output=True,
                          text=True, timeout=900)


def _edit(path: Path, text: str = "\n# an edit\n") -> None:
    path.write_text(path.read_text() + text)


def test_an_edit_of_python_that_is_not_compiled_keeps_the_cache(tmp_path):
    """The run's Python around the engine (the API, results, laminates, regimes, the command line)
    is compiled into nothing: an edit of it keeps the digest, and so the compiled cache."""
    package = _copy_package(tmp_path)
    before = _jit.engine_digest(package)
    assert before == _jit.engine_digest(ROOT / "phaseimpact")
    for name in ("integrate/api.py", "integrate/batch.py", "integrate/result.py", "integrate/__init__.py",
                 "model/regime.py", "model/laminate.py", "model/__init__.py", "cli/__init__.py", "cuda.py",
                 "__init__.py"):
        _edit(package / name)
        assert _jit.engine_digest(package) == before, name


@pytest.mark.parametrize("name", [
    "model/rhs.py",  # compiles
    "integrate/record.py",  # the workspace's row indices, read by the driver's kernels
    "model/laws.py",  # no compiled function: imported by integrate/events.py (law flags)
    "model/restitution.py",  # imported only inside a function of model/laws.py
    "parameters.py",  # imported by model/rhs.py
    "_signals.py",
])
def test_an_edit_of_what_the_engine_compiles_or_imports_changes_the_digest(tmp_path, name):
    package = _copy_package(tmp_path)
    before = _jit.engine_digest(package)
    _edit(package / name)
    assert _jit.engine_digest(package) != before


def test_new_modules_join_the_digest_when_they_compile_or_a_kernel_module_imports_them(tmp_path):
    package = _copy_package(tmp_path)
    (package / "model" / "tables.py").write_text("LIMIT = 3.0\n")
    (package / "maps" / "fast.py").write_text("from .._jit import kernel\n\n\n@kernel\ndef twice(x):\n"
                                               "    return 2 * x\n")
    (package / "maps" / "aside.py").write_text('"""Not compiled.\n\nfrom phaseimpact import simulate\n"""\n')
    sources = _jit.engine_sources(package)
    assert "maps/fast.py" in sources and "model/tables.py" not in sources and "maps/aside.py" not in sources
    # imported inside a function of a module that compiles
    _edit(package / "model" / "rhs.py", "\n\ndef _limit():\n    from .tables import LIMIT\n    return LIMIT\n")
    assert "model/tables.py" in _jit.engine_sources(package)


# A compiled function in the source text: a decorator of this package's or numba's, or a call of one.
_COMPILED = re.compile(r"^\s*@(?:_jit\.|numba\.)?(?:kernel|allocating|njit|jit|intrinsic|cfunc)\b"
                       r"|\b(?:kernel|allocating|numba\.njit|numba\.cfunc)\(", re.MULTILINE)


def test_every_module_with_a_compiled_function_is_in_the_digest():
    """An independent reading: the text of every file of the package, searched for a decorator."""
    package = ROOT / "phaseimpact"
    found = {path.relative_to(package).as_posix() for path in package.rglob("*.py")
             if path.name != "_dop853_codegen.py" and _COMPILED.search(path.read_text())}
    # the code generator writes "@kernel" into the stages' source, and compiles nothing itself
    assert {"model/rhs.py", "model/forms.py", "integrate/driver.py", "integrate/record.py",
            "model/userlaw.py", "model/native.py"} <= found
    assert found <= set(_jit.engine_sources())
    assert "integrate/_dop853_codegen.py" not in _jit.engine_sources()


def test_numba_overloads_are_for_the_gpu_or_in_the_digest():
    """The digest leaves numba's ``overload`` out of what compiles: the package's are for the CUDA
    target, which is not cached, or in a module of the digest. A CPU overload changes the engine's
    code from where it is registered (record.py's chooses the workspace's ``W_RADAU``)."""
    package = ROOT / "phaseimpact"
    overloads = {path.relative_to(package).as_posix(): re.findall(r"@overload\((.*)\)", path.read_text())
                 for path in package.rglob("*.py") if "@overload(" in path.read_text()}
    assert sorted(overloads) == ["cuda.py", "integrate/record.py"]
    assert all('target="cuda"' in call for call in overloads["cuda.py"])
    cpu = {name for name, calls in overloads.items() if any('target="cuda"' not in call for call in calls)}
    assert cpu == {"integrate/record.py"} and cpu <= set(_jit.engine_sources())


def test_the_import_reader_finds_what_ast_finds_in_every_file():
    """engine_sources reads imports from the text (fast); tests/test_imports.py reads them with ast."""
    from test_imports import _imports

    package = ROOT / "phaseimpact"
    files = {path.relative_to(package).as_posix(): path.read_bytes() for path in package.rglob("*.py")}

    def file_of(module: str) -> str:
        parts = module.split(".")[1:]
        plain = "/".join(parts) + ".py"
        return plain if plain in files else "/".join([*parts, "__init__.py"])

    for name, source in files.items():
        expected = {file_of(module) for module, _, _ in _imports(package, package / name)}
        assert _jit._imports(source, name, files)[0] == expected, name


@pytest.mark.slow
def test_editing_a_kernel_in_a_copy_changes_the_next_run(tmp_path):
    """Copy the package, compute a contact force through ``model/rhs.py``'s ``rhs``, double the Hertz
    power in model/forms.py (a kernel ``rhs`` calls from another file: numba itself checks only the
    cached function's own file), compute again in a fresh process on the same cache root: the new
    force, not the cached one. (Two first compiles, of ``rhs`` and what it calls: numba keys its files
    on each source folder's absolute path, so the copy cannot start from the checkout's cache.)"""
    package = _copy_package(tmp_path / "copy")
    root = tmp_path / "cache"
    first = _run(RUN, package.parent, NUMBA_CACHE_DIR=str(root))
    assert first.returncode == 0, first.stderr[-3000:]
    first = json.loads(first.stdout.strip().splitlines()[-1])
    assert first["file"] == str(package / "__init__.py")
    assert first["cache"] == str(root / _jit.cache_name())
    hertz = first["K"] * 1e-5**1.5  # P = K delta^(3/2), Hertz's law at rest
    assert abs(first["force"] - hertz) <= 1e-12 * hertz

    forms = package / "model" / "forms.py"
    text = forms.read_text()
    edited = re.sub(r"(def _hertz_power\(ad, alpha, root\):\n(?:    .*\n)*?)(    )(if alpha == 1\.5:)",
                    r"\1\2return 2.0 * ad**alpha\n\2\3", text, count=1)
    assert edited != text, "_hertz_power's body was not found: update this test's edit"
    forms.write_text(edited)
    second = _run(RUN, package.parent, NUMBA_CACHE_DIR=str(root))
    assert second.returncode == 0, second.stderr[-3000:]
    second = json.loads(second.stdout.strip().splitlines()[-1])
    assert second["cache"] != first["cache"]
    assert abs(second["force"] - 2 * hertz) <= 1e-12 * hertz  # the edited power, not the cached one


def _info(monkeypatch, roots):
    monkeypatch.setattr(_jit, "_roots", lambda: roots)
    return _jit._choose()


def test_the_first_writable_root_holds_the_cache_and_old_directories_are_pruned(tmp_path, monkeypatch):
    root = tmp_path / "root"
    for i in range(_jit.KEEP + 2):  # older directories of ours, and one that is not ours
        old = root / f"phaseimpact-0.1-{i:016d}"
        old.mkdir(parents=True)
        (old / _jit._MARKER).touch()
        os.utime(old / _jit._MARKER, (1e9 + i, 1e9 + i))
    (root / "someone-elses").mkdir()
    info = _info(monkeypatch, [(root, "test")])
    assert info.path.parent == root
    assert info.path.name == _jit.cache_name()
    left = sorted(p.name for p in root.iterdir())
    kept = [f"phaseimpact-0.1-{i:016d}" for i in range(2, _jit.KEEP + 2)]  # the KEEP most recent
    assert left == sorted([*kept, "someone-elses", info.path.name])


def test_an_unwritable_root_falls_back_then_caches_nothing(tmp_path, monkeypatch):
    if os.geteuid() == 0:
        pytest.skip("root writes anywhere: the unwritable case is run in test_a_read_only_install_...")
    locked = tmp_path / "locked"
    locked.mkdir()
    user = tmp_path / "user"
    locked.chmod(0o555)
    try:
        info = _info(monkeypatch, [(locked, "install"), (user, "per user")])
        assert info.path.parent == user and info.source == "per user"
        info = _info(monkeypatch, [(locked, "install")])
        assert info.path is None and "is writable" in info.reason
    finally:
        locked.chmod(0o755)


def _without_root_privileges() -> list[str] | None:
    """A command prefix running as root without the right to ignore file permissions (a stand-in
    for another user: this one can still read the interpreter under /root)."""
    if os.geteuid() != 0 or shutil.which("setpriv") is None:
        return None
    caps = "-dac_override,-dac_read_search"
    prefix = ["setpriv", f"--bounding-set={caps}", f"--inh-caps={caps}"]
    if subprocess.run([*prefix, "true"], capture_output=True).returncode != 0:
        return None
    return prefix


def test_a_read_only_install_with_no_home_never_crashes(tmp_path):
    """Issue 22: installed by root, run by a user who can write neither the install nor a HOME."""
    prefix = _without_root_privileges()
    if prefix is None:
        pytest.skip("needs root and setpriv to drop the right to write anywhere")
    base = Path(tempfile.mkdtemp(prefix="phaseimpact-readonly-"))
    try:
        package = _copy_package(base)
        for path in [base, *base.rglob("*")]:
            path.chmod(0o555 if path.is_dir() else 0o444)
        env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "NUMBA_DISABLE_JIT")}
        env.update(HOME=str(base / "home"), PYTHONPATH=str(base), PYTHONDONTWRITEBYTECODE="1")
        env.pop("XDG_CACHE_HOME", None)

        def run(*argv):
            return subprocess.run([*prefix, sys.executable, *argv], cwd=base, env=env, capture_output=True,
                                  text=True, timeout=600)
        cases = run("-m", "phaseimpact.cli", "cases")
        assert cases.returncode == 0 and "seed" in cases.stdout and cases.stderr == "", cases.stderr
        # every compiled module imports (before: "cannot cache function ...: no locator available"),
        # and a kernel compiles, for this process only
        kernel = run("-c", "import json, phaseimpact.integrate.api; from phaseimpact.model import forms; "
                           "from phaseimpact._jit import cache_info; "
                           "print(json.dumps([forms.__file__, str(cache_info().path), "
                           "forms.contact_force(2, 1e-5, 0.1, 1, 1e10, 3e9, 1.5)]))")
        assert kernel.returncode == 0, kernel.stderr[-3000:]
        file, cache, force = json.loads(kernel.stdout)
        assert file == str(package / "model" / "forms.py") and cache == "None" and force > 0
    finally:
        for path in [base, *base.rglob("*")]:
            path.chmod(0o755)
        shutil.rmtree(base)


@pytest.mark.parametrize("argv", [["cases"], ["params"], ["--version"], ["--help"], ["cases", "--json"],
                                  ["completion", "bash"]])
def test_commands_that_integrate_nothing_import_no_numba(argv):
    """Their start-up is Python's and phaseimpact's own (NumPy alone is 0.1-0.2 s of it)."""
    code = ("import sys\nfrom phaseimpact.cli import main\ntry:\n    main(sys.argv[1:])\nexcept SystemExit:\n"
            "    pass\nsys.stdout.flush()\nprint(*(('' if name in sys.modules else 'NO-') + name.upper() "
            "for name in ('numpy', 'numba', 'scipy')), file=sys.stderr)")
    out = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    assert out.stderr.strip().splitlines()[-1] == "NO-NUMPY NO-NUMBA NO-SCIPY"


# A kernel and an entry that calls it, in their own module (numba caches by source file).
LINKED = r"""
from phaseimpact._jit import kernel


@kernel
def twice(x):
    return 2.0 * x


@kernel(python=True)
def entry(x):
    return twice(x) + 1.0
"""
# First process: the kernel alone; second: the entry, which reads the kernel from the cache and
# links it. ``hooks`` (the first argument) "lacking" pretends this numba lacks one hooked name.
LINKED_RUN = r"""
import json, os, sys, warnings
warnings.simplefilter("always")
from numba import config, float64
from phaseimpact import _jit
if sys.argv[2] == "lacking":
    _jit._HOOKED += (("numba.core.codegen", "JITCodeLibrary", ("_a_step_this_numba_lacks",)),)
with warnings.catch_warnings(record=True) as caught:
    import linked
    out = {"cache_dir_restored": config.CACHE_DIR == os.environ["NUMBA_CACHE_DIR"],
           "cache": _jit.cache_info().path.name}
    if sys.argv[1] == "kernel":
        linked.twice.compile((float64,))
        library = linked.twice.overloads[(float64,)].library
        out.update(linked_only=isinstance(library, _jit._linked_only_library()),
                   kind=library.serialize_using_object_code()[1],
                   machine_code=any(library.codegen._engine.is_symbol_defined(f.name)
                                    for f in library.get_defined_functions()))
    else:
        kernel = linked.twice.overloads  # filled by the entry's compile or from the cache
        out.update(value=linked.entry(3.0) + linked.entry(4.0),
                   kernel_from_cache=linked.twice.stats.cache_hits.get((float64,), 0),
                   linked_only=isinstance(kernel[(float64,)].library, _jit._linked_only_library()),
                   entry_linked_only=isinstance(linked.entry.overloads[(float64,)].library,
                                                _jit._linked_only_library()))
out["warnings"] = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
print(json.dumps(out))
"""


def _linked(tmp_path, step, hooks="present", **env):
    module = tmp_path / "linked.py"
    if not module.exists():  # rewritten, its new time would make numba's cache of it stale
        module.write_text(LINKED)
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "cache"), "PYTHONPATH": os.pathsep.join((str(tmp_path), str(ROOT))),
           **env}
    out = subprocess.run([sys.executable, "-c", LINKED_RUN, step, hooks], cwd=tmp_path, capture_output=True,
                         text=True, timeout=600, env={**{k: v for k, v in os.environ.items()
                                                         if k not in ("NUMBA_DISABLE_JIT", LINKED_SWITCH)}, **env})
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


LINKED_SWITCH = "PHASEIMPACT_LINKED_ONLY"


def test_a_kernel_is_compiled_for_linking_only_and_read_back_from_the_cache_by_its_callers(tmp_path):
    """A kernel's library keeps its IR for the entries that link it and makes no machine code of
    its own (the compile-time saving of phaseimpact/_jit.py); cached, it is read back as such and
    an entry compiled in another process links it and computes the right value. The cache is
    numba's own (``numba.config.CACHE_DIR``), set to the digest's directory only while the engine's
    functions are declared."""
    name = f"phaseimpact-{_jit._version()}-{_jit.engine_digest()}"
    assert _linked(tmp_path, "kernel") == {"cache_dir_restored": True, "cache": name, "linked_only": True,
                                           "kind": _jit._LINKED_ONLY_KIND, "machine_code": False, "warnings": []}
    assert list((tmp_path / "cache" / name).rglob("linked.twice-*.nbi")), "numba cached nothing in the digest's dir"
    assert _linked(tmp_path, "entry") == {"cache_dir_restored": True, "cache": name, "value": 16.0,
                                          "kernel_from_cache": 1, "linked_only": True, "entry_linked_only": False,
                                          "warnings": []}


def test_the_switch_off_compiles_whole_libraries_in_their_own_cache(tmp_path):
    """``PHASEIMPACT_LINKED_ONLY=0``: numba's own libraries (machine code for each kernel), cached
    apart (a linked-only cache cannot be read without the hooks)."""
    name = f"phaseimpact-{_jit._version()}-{_jit.engine_digest()}-whole"
    kernel = _linked(tmp_path, "kernel", **{LINKED_SWITCH: "0"})
    assert kernel["cache"] == name and kernel["linked_only"] is False and kernel["machine_code"] is True
    assert kernel["kind"] != _jit._LINKED_ONLY_KIND and kernel["warnings"] == []
    entry = _linked(tmp_path, "entry", **{LINKED_SWITCH: "0"})
    assert entry["value"] == 16.0 and entry["kernel_from_cache"] == 1 and entry["linked_only"] is False


def test_a_numba_lacking_a_hooked_name_warns_once_and_still_computes(tmp_path):
    """A numba without one of the names the hooks need: one warning naming it, nothing hooked,
    kernels compiled numba's own way (however many compile), the right value."""
    out = _linked(tmp_path, "entry", hooks="lacking")
    assert len(out["warnings"]) == 1, out["warnings"]
    assert "lacks numba.core.codegen.JITCodeLibrary._a_step_this_numba_lacks" in out["warnings"][0]
    assert out["value"] == 16.0 and out["linked_only"] is False
    assert out["cache"].endswith("-whole")


@pytest.mark.parametrize("value", ["2", "yes", "off"])
def test_the_switch_refuses_other_values(monkeypatch, value):
    monkeypatch.setenv(LINKED_SWITCH, value)
    with pytest.raises(ValueError, match=f"{LINKED_SWITCH} = '{value}' is out of range; allowed: 0 or 1"):
        _jit.linked_only_requested()
