"""How the engine is compiled (numba): the two decorators every compiled function uses, and where
the compiled machine code is kept.

``kernel`` is for the helpers that never allocate: the law, the right-hand sides, the steppers,
the event functions, the driver's inner loop. They only read and write arrays their caller owns,
so they are compiled without numba's reference counting (NRT). With it, every array argument is
incref'd and decref'd at every call, each a call into the runtime with an atomic update: that was
30 of the 38 ns of one right-hand side and more than half the time of a trajectory (a
Hunt-Crossley run 97 -> 41 us, a stiff atlas point 174 -> 65 us, results unchanged). Numba refuses
to compile an allocation in such a function (and in every function it calls that does not say
otherwise), so the flag cannot hide a leak. It does let a kernel return an array it was given, and
that must never happen: the reference-counted caller would release a reference the kernel never
took and free the array under its owner. Kernels return scalars and tuples of scalars only
(``tests/test_integrate.py`` checks every compiled overload).

``allocating`` is for the few functions that create arrays (the run loops and their growing
buffers, the Radau workspace): reference counted, as numba does by default.

Both compile a function for calls from compiled code only, unless it says ``python=True``: numba
otherwise wraps every compiled function for calls from Python too (unboxing each argument, boxing
the result), and generating and optimising a wrapper for each of the engine's ~80 compiled
functions took about 1.5 s of the first-ever compile (one process: 26.6 -> 25.2 s, medians of 3
cold runs; numba's C-callable wrappers, never used here, are off for all). A function without the
wrapper must never be called from Python: numba does not check, the call crashes. So every
function Python code calls (the entries ``run``, ``run_block`` and ``run_rk4``, what a module lists in
``__all__``, what the oracle and the tests call) says ``python=True``, and
``tests/test_integrate.py`` finds every call from Python in the package, tests, benchmarks and
studies and checks that its target has the wrapper.

A small kernel the hot loops call says ``forceinline=True``: numba gives its LLVM function the
``alwaysinline`` attribute, and LLVM inlines it into every caller after optimising it once. Numba's
own inlining (``inline="always"``) types and lowers the function again inside each caller: for the
same machine code (the run loop's assembly is identical either way), a first compile took about
1.2x as long. It is left to :func:`.integrate.record.carve` and :func:`.integrate.radau5.carve`,
the two kernels that return views: typed in each caller, their views are the caller's own.

A kernel that takes a run's workspace and runs once per step or event (the root finders, the
event handling: :mod:`.integrate.step`, :mod:`.integrate.rootfind`, the driver's step kernels)
says ``forceinline=True`` too, and so do the event function, the interpolant and the physical
state the root finders call. The workspace is a tuple of arrays passed by value (13, and the stiff
solver's ten where the engine has that solver: :func:`.integrate.record.carve`), some seven LLVM
parameters an array: with 22 arrays, the functions that took it had 174 to 202 parameters. Numba
gives its functions ``linkonce_odr`` linkage, so LLVM may not drop the arguments a callee never
reads, and each call copied them all.
What runs a few times per run stays a call: the entries, the loop (``_loop``), its start and end,
and :func:`.integrate.step.advance` (which keeps its steps in a loop of its own);
``tests/test_integrate.py`` holds the list.

Every function is compiled with numba's ``error_model="numpy"``: a float division by zero gives
IEEE's inf or NaN, as on the GPU (numba's CUDA target has no other model), which the run's
steps and checks turn into a status, not a traceback. numba's default (``"python"``) tests every divisor
and raises ZeroDivisionError, and every call of a function that can raise is followed by a test
of its exception status (the same bits without them, and a Hunt-Crossley trajectory's time the
same within the machine's spread: ``benchmarks/results/trajectory_against.md``).

Numba is imported only when something is compiled. Until then (``phaseimpact cases``, ``params``,
building a case: they import the laws but integrate nothing) a decorated function is a
:class:`_Deferred` placeholder; the first use of one, or the first decoration once numba is
imported (the integrator modules import it), hands every placeholder to numba and puts the
compiled function in its place in every module that imported it.

The cache
---------
Compiled machine code is kept on disk (numba's ``cache=True`` files) in one directory per
version of the engine's sources, ``phaseimpact-<version>-<digest>`` (:func:`cache_info`), where
the digest is the SHA-256 of every file that can change the compiled code
(:func:`engine_sources`). numba itself checks only the cached function's own file, while a
cached function holds the machine code of every function it calls: after an edit of
``model/rhs.py`` the driver ran the old right-hand side. And numba freezes the module globals a
compiled function reads (the constants, the workspace's row indices of ``integrate/record.py``)
into its code. So the sources are every module that compiles (imports ``kernel`` or
``allocating``, or one of numba's CPU compilers: ``njit``, ``intrinsic``, ``cfunc``...), this
module and ``_signals.py``, and every module of the package these import, at module level or
inside a function, transitively; read from the import statements, not by importing anything. A
new digest is a new, empty directory, so an edit of any of them recompiles everything; an edit of
the Python around the engine (``integrate/api.py``, ``integrate/result.py``, ``model/regime.py``,
the command line...) keeps the cache.
The directory is handed to numba through its public setting, ``numba.config.CACHE_DIR``
(what ``NUMBA_CACHE_DIR`` sets), for the engine's functions only: it is set while each is
declared to numba and restored at once, so other numba code in the process caches as it would.
The directory lies in the first of these roots that this user can write:

1. ``$NUMBA_CACHE_DIR`` when set;
2. ``__pycache__/`` of the installed package (``phaseimpact warmup`` run by whoever installed it
   fills it for that user);
3. ``$XDG_CACHE_HOME/phaseimpact`` (default ``~/.cache/phaseimpact``), per user;
4. none: every process compiles for itself, and says so on stderr when it does.

Of the directories this module created in a root, the :data:`KEEP` most recently used stay (a few
checkouts or versions side by side); older ones are removed when a new one is made. A cache made
with the kernels compiled as whole libraries (``PHASEIMPACT_LINKED_ONLY=0``, or a numba without
the hooks below) gets its own directory, ``...-whole``: the other kind's files cannot be read back
without the hooks.
"""

from __future__ import annotations

import bisect
import functools
import hashlib
import os
import re
import shutil
import sys
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

__all__ = ["kernel", "allocating", "cache_info", "CacheInfo", "engine_sources", "linked_only",
           "LINKED_ONLY_VARIABLE", "announce"]

#: The package's root directory.
PACKAGE = Path(__file__).resolve().parent
#: The package's name (absolute imports of it are its own).
PACKAGE_NAME = PACKAGE.name
#: Engine sources whatever imports them: the compiler's hooks and the signals' intrinsics.
ALWAYS_ENGINE = ("_jit.py", "_signals.py")
#: Directories of older engine sources kept in a cache root besides the one in use.
KEEP = 4
#: Marks a cache directory this module made (only those are ever removed).
_MARKER = "phaseimpact-cache"

#: Environment variable: ``0`` compiles every kernel as a whole library (numba's own way, no hooks).
LINKED_ONLY_VARIABLE = "PHASEIMPACT_LINKED_ONLY"
#: The first compile of an entry on a cold cache, on two cores (``benchmarks/startup.py``): the
#: announcement quotes it.
FIRST_COMPILE = "about a minute"


def linked_only_requested() -> bool:
    """``PHASEIMPACT_LINKED_ONLY``: ``1`` or unset (the default) hooks the kernels' libraries into
    numba where it can; ``0`` leaves numba as it is."""
    value = os.environ.get(LINKED_ONLY_VARIABLE, "")
    if value not in ("", "0", "1"):
        raise ValueError(f"{LINKED_ONLY_VARIABLE} = {value!r} is out of range; allowed: 0 or 1")
    return value != "0"


# ------------------------------------------------------------------------------------------------
# Where the cache lives
# ------------------------------------------------------------------------------------------------

def _version() -> str:
    from ._version import __version__

    return __version__


# A module "compiles" when it imports one of these: its functions are machine code in the cache.
# numba's ``overload`` and ``register_jitable`` are left out: the package uses them for the CUDA
# target (cuda.py), whose code is not cached here, and in integrate/record.py, which compiles
# kernels and is in the digest anyway (``tests/test_cache.py`` checks both).
_OUR_COMPILERS = frozenset({"kernel", "allocating"})
_NUMBA_COMPILERS = frozenset({"njit", "jit", "cfunc", "intrinsic", "generated_jit", "vectorize", "guvectorize"})
# The imports are read from the text, not with ``ast``: parsing the candidate files took 0.34 s on
# this (loaded, 2-core) machine, this whole digest takes 10 ms (the former one, of every file in
# model/ and integrate/: 1.7 ms), once per process. ``tests/test_cache.py`` checks that it finds
# what ``ast`` finds, in every file of the package. A statement is ``from X import names`` (a
# parenthesised list may span lines, with comments) or ``import names``, from the start of the
# line where the word ``import`` is found outside docstrings.
_IMPORT_WORD = re.compile(rb"import[ \t(]")
_IMPORT = re.compile(rb"[ \t]*(?:from[ \t]+(\.*[\w.]*)[ \t]+import[ \t]*(\((?:[^)#]|#[^\n]*\n)*\)|[^\n]*)"
                     rb"|import[ \t]+([^\n]*))")
# ``numba.njit(f)``, ``_jit.kernel(f)``: a compiler used through its module (two patterns: each
# starts with a literal, which the search skips to)
_COMPILER_ATTRIBUTES = tuple(re.compile(rb"%s\.(?:%s)\b" % (module, b"|".join(n.encode() for n in sorted(names))))
                             for module, names in ((b"numba", _NUMBA_COMPILERS), (b"_jit", _OUR_COMPILERS)))
_COMMENT = re.compile(rb"#[^\n]*")
#: A file that compiles names one of these (``_jit`` or ``numba``).
_COMPILER_WORDS = (b"jit", b"numba")


def _names(listed: bytes) -> list[str]:
    """The names of an import's list (``a as b, c``, parenthesised or not), without comments."""
    text = _COMMENT.sub(b"", listed).strip(b"()\\ \t\n")
    return [item.split()[0].decode() for item in text.split(b",") if item.split()]


def _long_strings(source: bytes) -> list[int]:
    """Where the triple-quoted strings of ``source`` begin and end, in order (an example in a
    docstring is no import)."""
    quotes = []
    for quote in (b'"""', b"'''"):
        at = source.find(quote)
        while at >= 0:
            quotes.append((at, quote))
            at = source.find(quote, at + 3)
    bounds, opened = [], None
    for at, quote in sorted(quotes):
        if opened is None or quote == opened:
            bounds.append(at)
            opened = quote if opened is None else None
    return bounds


def _code_matches(pattern: re.Pattern, source: bytes, bounds: list[int]):
    """The matches of ``pattern`` in ``source`` outside its triple-quoted strings (``bounds``)."""
    return [match for match in pattern.finditer(source) if bisect.bisect(bounds, match.start()) % 2 == 0]


def _imports(source: bytes, where: str, files: dict[str, bytes]) -> tuple[set[str], bool]:
    """The package's files that ``source`` (the file ``where``, relative to the package) imports,
    anywhere in it (inside functions too), and whether it compiles with numba. ``from X import y``
    counts as the file of the module ``X.y`` where that is one, else as ``X``'s."""
    def file_of(parts: list[str]) -> str | None:
        for candidate in ("/".join(parts) + ".py", "/".join([*parts, "__init__.py"])):
            if candidate in files:
                return candidate
        return None

    package = where.split("/")[:-1]
    bounds = _long_strings(source)
    imported = set()
    compiles = any(_code_matches(pattern, source, bounds) for pattern in _COMPILER_ATTRIBUTES)
    for word in _code_matches(_IMPORT_WORD, source, bounds):
        statement = _IMPORT.match(source, source.rfind(b"\n", 0, word.start()) + 1)
        if statement is None or statement.end() <= word.start():
            continue  # "import" in a line that is no import statement
        origin, listed, plain = statement.groups()
        if plain is not None:  # import phaseimpact.x.y
            for name in _names(plain):
                parts = name.split(".")
                if parts[0] == PACKAGE_NAME and (found := file_of(parts[1:])):
                    imported.add(found)
            continue
        origin = origin.decode()
        names = _names(listed)
        level = len(origin) - len(origin.lstrip("."))
        dotted = [part for part in origin[level:].split(".") if part]
        if level == 0:
            if dotted and dotted[0] == "numba" and _NUMBA_COMPILERS.intersection(names):
                compiles = True
            if not dotted or dotted[0] != PACKAGE_NAME:
                continue
            parts = dotted[1:]
        elif level - 1 > len(package):
            continue  # above the package
        else:
            parts = package[:len(package) - level + 1] + dotted
        module = file_of(parts)
        if module == "_jit.py" and _OUR_COMPILERS.intersection(names):
            compiles = True
        for name in names:
            found = file_of([*parts, name]) or module
            if found is not None:
                imported.add(found)
    return imported, compiles


def _engine_files(package: Path) -> dict[str, bytes]:
    """The engine's source files under ``package`` (relative paths, ``/``-separated) and their
    bytes: every module that compiles, and every module of the package those import, transitively."""
    files = {}
    for folder, subfolders, names in os.walk(package):
        subfolders[:] = [name for name in subfolders if name != "__pycache__"]
        prefix = os.path.relpath(folder, package).replace(os.sep, "/")
        for name in names:
            if name.endswith(".py"):
                with open(os.path.join(folder, name), "rb") as file:
                    files[name if prefix == "." else f"{prefix}/{name}"] = file.read()
    graph = {}
    for where, source in files.items():
        if any(word in source for word in _COMPILER_WORDS):  # only these can compile
            imported, compiles = _imports(source, where, files)
            if compiles:
                graph[where] = imported
    todo = [*graph, *ALWAYS_ENGINE]
    engine = {}
    while todo:
        where = todo.pop()
        if where in engine:
            continue
        engine[where] = files[where]
        if where not in graph:
            graph[where] = _imports(files[where], where, files)[0]
        todo.extend(graph[where])
    return engine


def engine_sources(package: Path = PACKAGE) -> tuple[str, ...]:
    """The files whose code can change the compiled engine, relative to ``package`` (sorted): the
    modules that compile (see the module's docstring) and every module of the package they import,
    at module level or inside a function, transitively."""
    return tuple(sorted(_engine_files(package)))


def engine_digest(package: Path = PACKAGE) -> str:
    """SHA-256 (hex, 16 digits) of the engine's sources under ``package`` (:func:`engine_sources`):
    names and contents."""
    digest = hashlib.sha256()
    for name, source in sorted(_engine_files(package).items()):
        digest.update(name.encode() + b"\0")
        digest.update(source + b"\0")
    return digest.hexdigest()[:16]


def cache_name() -> str:
    """The cache directory's name: the engine's version and digest, and how kernels are compiled."""
    return f"phaseimpact-{_version()}-{engine_digest()}{'' if linked_only() else '-whole'}"


@dataclass(frozen=True)
class CacheInfo:
    """Where this process keeps the compiled engine.

    ``path`` is None when nothing is cached (``reason`` says why); ``tried`` lists the roots tried,
    in order."""

    path: Path | None
    source: str
    reason: str
    tried: tuple[str, ...]

    def describe(self) -> str:
        if self.path is None:
            return f"no cache ({self.reason})"
        return f"{self.path} ({self.source})"


def _user_root() -> Path | None:
    base = os.environ.get("XDG_CACHE_HOME") or (os.path.join(os.path.expanduser("~"), ".cache"))
    if not os.path.isabs(base):  # no usable HOME ("~" left as is)
        return None
    return Path(base) / "phaseimpact"


def _roots() -> list[tuple[Path, str]]:
    roots = []
    if os.environ.get("NUMBA_CACHE_DIR"):
        roots.append((Path(os.environ["NUMBA_CACHE_DIR"]), "NUMBA_CACHE_DIR"))
    roots.append((PACKAGE / "__pycache__", "the install's"))
    user = _user_root()
    if user is not None:
        roots.append((user, "per user"))
    return roots


def _writable(path: Path) -> bool:
    # what numba's own locator checks before it uses a directory
    try:
        path.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
    except OSError:
        return False
    return True


def _prune(root: Path, keep: Path) -> None:
    """Remove all but the :data:`KEEP` most recently used cache directories this module made."""
    try:
        ours = [d for d in root.iterdir() if d != keep and (d / _MARKER).is_file()]
        ours.sort(key=lambda d: (d / _MARKER).stat().st_mtime, reverse=True)
    except OSError:
        return
    for old in ours[KEEP:]:
        shutil.rmtree(old, ignore_errors=True)


def _choose() -> CacheInfo:
    name = cache_name()
    tried = []
    for root, source in _roots():
        path = root / name
        tried.append(str(path))
        fresh = not path.exists()
        if _writable(path):
            try:
                (path / _MARKER).touch()  # its time is this directory's last use (pruning keeps the recent ones)
            except OSError:
                pass
            if fresh:
                _prune(root, path)
            return CacheInfo(path, source, "", tuple(tried))
    return CacheInfo(None, "", "none of " + ", ".join(tried) + " is writable", tuple(tried))


@functools.cache
def cache_info() -> CacheInfo:
    """Where this process keeps the compiled engine (chosen once, on first need)."""
    if os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0"):
        return CacheInfo(None, "", "NUMBA_DISABLE_JIT is set", ())
    return _choose()


# ------------------------------------------------------------------------------------------------
# The first compile says so
# ------------------------------------------------------------------------------------------------

def announce(stiff: bool = False) -> str:
    """The line a compile of the engine writes on stderr (it depends on where the cache is); ``stiff``:
    the compile of the engine with its stiff solver, after a run turned stiff (:func:`stiff_run_met`)."""
    info = cache_info()
    what = ("a run turned stiff: compiling the engine again with its stiff solver (Radau IIA)," if stiff
            else "compiling the engine")
    if info.path is None:
        return (f"phaseimpact: {what} for this process, {FIRST_COMPILE} on 2 cores (nothing is cached: "
                f"{info.reason}; set NUMBA_CACHE_DIR to a writable directory to compile once)")
    return f"phaseimpact: {what} once for this machine, {FIRST_COMPILE} on 2 cores (cache: {info.path})"


class _Announced:
    """What this process has said on stderr: the first compile of the engine; and whether a run has
    turned stiff here (the engine's next compile is then the one with Radau, said once more: it
    takes about as long, and without a line the command would seem to hang)."""

    stiff_run = False
    lines: set[bool] = set()


def stiff_run_met() -> None:
    """A run turned stiff in this process (:func:`phaseimpact.integrate.api.turned_stiff`): a compile
    of an entry from now on is the engine with its stiff solver, and says so."""
    _Announced.stiff_run = True


#: The modules of the run loops called from Python, whose compile is the engine's (a kernel called
#: from Python, as the tests do, compiles in a second).
_ENTRIES_MODULES = ("phaseimpact.integrate.driver", "phaseimpact.integrate.rk4")


def _on_compile(dispatcher) -> None:
    """Print :func:`announce` when numba compiles an entry (once; once more for the engine with its
    stiff solver after a run turned stiff)."""
    if (getattr(dispatcher.py_func, "__module__", "") in _ENTRIES_MODULES
            and not dispatcher.targetoptions.get("no_cpython_wrapper", False)):
        stiff = _Announced.stiff_run
        if stiff not in _Announced.lines:
            _Announced.lines.add(stiff)
            print(announce(stiff), file=sys.stderr, flush=True)


@functools.cache
def _listen_for_first_compile() -> None:
    """Call :func:`_on_compile` when numba compiles a function (a cache miss: numba's
    ``numba:compile`` event fires on nothing else)."""
    from numba.core import event

    class Compile(event.Listener):
        def on_start(self, ev):
            _on_compile(ev.data["dispatcher"])

        def on_end(self, ev):
            pass

    event.register("numba:compile", Compile())


# ------------------------------------------------------------------------------------------------
# Kernels compiled for linking only
# ------------------------------------------------------------------------------------------------
# numba finalises every compiled function as if Python would call it: it links in the LLVM IR of
# everything the function calls, optimises that whole module and generates its machine code. A
# kernel (no Python wrapper) is never called but from compiled code, which links its IR and
# optimises and generates it again in its own module; an entry (``run``) holds the whole engine.
# So each level of the call tree redid the work of the levels below, and most of LLVM's share of a
# first compile went into machine code that nothing would run. A kernel's library here keeps its
# function-level optimisation and its IR for linking, and stops there; the entry that links it
# optimises the whole and makes the only machine code, as before. The machine code of the
# entries, and every result, is bit-identical (``tests/test_precompile.py``); the first compile's
# time with and without is in ``benchmarks/results/startup.md``.
#
# numba has no public switch for this: the library class below overrides three of its library's
# internal steps, and :func:`_linked_only_installed` hooks three more (where a function's library
# is made, where a cached one is read back, and where a function's environment is set). Every
# name is checked first (:data:`_HOOKED`): with a numba that lacks one nothing is changed, the
# compile takes numba's own time, and one warning says so. ``PHASEIMPACT_LINKED_ONLY=0`` turns it
# off.

#: The Python functions compiled as kernels without a Python wrapper (see above).
_LINKED_ONLY: set = set()
#: The kind under which a kernel's library is cached (numba's own are "object" and "bitcode").
_LINKED_ONLY_KIND = "phaseimpact-linked-only"
#: numba's internals the linked-only kernels use or replace: (module, class, names).
_HOOKED = (
    ("numba.core.codegen", "JITCodeLibrary", ("_optimize_final_module", "_finalize_final_module",
                                              "_finalize_dynamic_globals", "_verify_declare_only_symbols",
                                              "_get_module_for_linking", "serialize_using_object_code")),
    ("numba.core.codegen", "JITCPUCodegen", ("unserialize_library", "set_env")),
    ("numba.core.typed_passes", "BaseNativeLowering", ("run_pass",)),
)


@functools.cache
def _linked_only_library():
    from llvmlite import binding
    from numba.core import codegen

    class LinkedOnlyLibrary(codegen.JITCodeLibrary):
        """The library of a kernel: optimised function by function, never made machine code."""

        def _optimize_final_module(self):
            pass  # the entries that link it optimise it with themselves

        def _finalize_final_module(self):
            self._finalize_dynamic_globals()
            self._verify_declare_only_symbols()
            self._finalized = True  # not added to the JIT: no machine code, no symbol

        def serialize_using_object_code(self):
            self._ensure_finalized()
            return self.name, _LINKED_ONLY_KIND, self._get_module_for_linking().as_bitcode()

        @classmethod
        def from_cache(cls, codegen_, name, bitcode):
            library = cls(codegen_, name)
            library._final_module = binding.parse_bitcode(bitcode)
            library._finalize_final_module()
            return library

    return LinkedOnlyLibrary


def _missing_hooks() -> list[str]:
    import importlib

    missing = []
    for module, owner, names in _HOOKED:
        cls = getattr(importlib.import_module(module), owner, None)
        missing.extend(f"{module}.{owner}.{name}" for name in names if not hasattr(cls, name))
    return missing


@functools.cache
def linked_only() -> bool:
    """Whether kernels are compiled for linking only in this process: asked for
    (``PHASEIMPACT_LINKED_ONLY``) and this numba has every hooked name (else one warning says which
    it lacks). Hooks numba on the first call."""
    if not linked_only_requested():
        return False
    missing = _missing_hooks()
    if missing:
        import numba

        warnings.warn(f"phaseimpact: numba {numba.__version__} lacks {', '.join(missing)}; kernels are "
                      f"compiled as whole libraries, and a first compile takes longer (set "
                      f"{LINKED_ONLY_VARIABLE}=0 to choose this without the warning)", RuntimeWarning, stacklevel=2)
        return False
    _install_linked_only()
    return True


def _install_linked_only() -> None:
    from numba.core import codegen, typed_passes

    library_class = _linked_only_library()
    lower, unserialize, set_env = (typed_passes.BaseNativeLowering.run_pass,
                                   codegen.JITCPUCodegen.unserialize_library, codegen.JITCPUCodegen.set_env)

    def run_pass(self, state):
        if state.library is None and state.func_id.func in _LINKED_ONLY:
            state.library = library_class(state.targetctx.codegen(), state.func_id.func_qualname)
        return lower(self, state)

    def unserialize_library(self, serialized):
        name, kind, data = serialized
        if kind == _LINKED_ONLY_KIND:
            return library_class.from_cache(self, name, data)
        return unserialize(self, serialized)

    def set_env_where_defined(self, env_name, env):
        # numba sets a function's environment (what boxes Python objects; kernels use none) at
        # its symbol's address; a kernel's library defines no symbol
        if self._engine.get_global_value_address(env_name):
            set_env(self, env_name, env)

    typed_passes.BaseNativeLowering.run_pass = run_pass
    codegen.JITCPUCodegen.unserialize_library = unserialize_library
    codegen.JITCPUCodegen.set_env = set_env_where_defined


# ------------------------------------------------------------------------------------------------
# The decorators
# ------------------------------------------------------------------------------------------------

_pending: list[_Deferred] = []


def _compile(function, options):
    import numba

    _listen_for_first_compile()
    if options["no_cpython_wrapper"] and linked_only():
        _LINKED_ONLY.add(function)
    path = cache_info().path
    if path is None:
        return numba.njit(cache=False, **options)(function)
    # numba's locator reads the setting when the function is declared (``cache=True``), and keeps it
    previous = numba.config.CACHE_DIR
    numba.config.CACHE_DIR = str(path)
    try:
        return numba.njit(cache=True, **options)(function)
    finally:
        numba.config.CACHE_DIR = previous


class _Deferred:
    """A function for numba, held as Python until anything needs numba (see the module's docstring).
    Calls and attributes go to the compiled function."""

    def __init__(self, function, options):
        functools.update_wrapper(self, function)
        self.py_func = function
        self._options = options
        self._dispatcher = None

    def __call__(self, *args, **kwargs):
        return _resolve(self)(*args, **kwargs)

    def __getattr__(self, name):
        if name.startswith("__") or name in ("_options", "_dispatcher"):
            raise AttributeError(name)
        return getattr(_resolve(self), name)

    def __repr__(self):
        return f"<phaseimpact._jit._Deferred {self.__qualname__}>"


def _resolve(deferred: _Deferred):
    _compile_pending()
    return deferred._dispatcher


def _compile_pending() -> None:
    """Hand every placeholder to numba and replace it wherever a module holds it."""
    if not _pending:
        return
    done = {}
    while _pending:
        item = _pending.pop(0)
        item._dispatcher = _compile(item.py_func, item._options)
        done[id(item)] = item
    for module in list(sys.modules.values()):
        namespace = getattr(module, "__dict__", None)
        if not isinstance(namespace, dict):
            continue
        for key, value in list(namespace.items()):
            if type(value) is _Deferred and id(value) in done:
                namespace[key] = value._dispatcher


def _compiler(reference_counted: bool):
    def decorate(function=None, *, python: bool = False, forceinline: bool = False, inline: str = "never",
                 nogil: bool = False):
        options = dict(_nrt=reference_counted, forceinline=forceinline, inline=inline, nogil=nogil,
                       no_cpython_wrapper=not python, no_cfunc_wrapper=True, error_model="numpy")

        def compile_(f):
            if "numba" in sys.modules:  # numba's import is paid: compile-ready functions, placeholders too
                _compile_pending()
                return _compile(f, options)
            deferred = _Deferred(f, options)
            _pending.append(deferred)
            return deferred
        return compile_ if function is None else compile_(function)
    return decorate


#: ``@kernel``, ``@kernel(forceinline=True)``, ``@kernel(python=True)``: a compiled helper that
#: allocates nothing.
kernel = _compiler(reference_counted=False)
#: ``@allocating``, ``@allocating(python=True, nogil=True)``: a compiled function that creates arrays.
allocating = _compiler(reference_counted=True)

