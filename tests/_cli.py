"""The command line run in-process, for the CLI tests."""

import contextlib
import functools
import importlib
import io
import pkgutil

import phaseimpact
from phaseimpact.cli import main


def run(argv):
    """``main(argv)`` in-process: (exit code, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main([str(a) for a in argv])
        except SystemExit as exit_:
            code = exit_.code if isinstance(exit_.code, int) else (0 if exit_.code is None else 2)
    return code, out.getvalue(), err.getvalue()


@functools.cache
def import_every_module() -> None:
    """Import every module of the package, once. A test that patches an engine entry (``simulate``)
    calls this first: a module the command imports lazily would otherwise bind the stand-in by
    ``from ... import`` and keep it for every later test of the session."""
    for module in pkgutil.walk_packages(phaseimpact.__path__, "phaseimpact."):
        importlib.import_module(module.name)
