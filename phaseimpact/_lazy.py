"""Names a package exports but imports on first use (PEP 562), so that importing the package
costs only what is used: the commands that integrate nothing never import NumPy, SciPy or numba."""

from __future__ import annotations

import importlib


def attach(package: str, namespace: dict, exports: dict[str, str]):
    """``(__getattr__, __dir__)`` for ``package``: ``exports`` maps a name to the submodule (relative
    to ``package``) that defines it; the first access imports it and keeps the value in
    ``namespace`` (the package's globals), so later accesses cost nothing."""

    def __getattr__(name):
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f".{module}", package), name)
        namespace[name] = value
        return value

    def __dir__():
        return sorted(set(namespace) | set(exports))

    return __getattr__, __dir__


class NumPyOnFirstUse:
    """NumPy, imported when a module first reads an attribute of it: ``np = NumPyOnFirstUse(globals())``
    (the commands that integrate nothing import such a module but never NumPy). The first access
    replaces ``np`` in ``namespace`` by NumPy itself, so later accesses cost nothing."""

    def __init__(self, namespace: dict):
        self._namespace = namespace

    def __getattr__(self, name):
        import numpy

        self._namespace["np"] = numpy
        return getattr(numpy, name)
