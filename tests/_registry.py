"""The law registry as it was before a test module defined its own laws."""

import contextlib

from phaseimpact.model import REGISTRY, laws


@contextlib.contextmanager
def restored_registry():
    """The laws defined inside leave the registry with it (later tests enumerate the registry)."""
    before = dict(REGISTRY)
    try:
        yield
    finally:
        REGISTRY.clear()
        REGISTRY.update(before)
        laws._named_law.cache_clear()


@contextlib.contextmanager
def restored_archive_kinds():
    """The archive kinds registered inside leave the archive registry with it."""
    from phaseimpact.archive import REGISTRY as KINDS

    before = dict(KINDS)
    try:
        yield
    finally:
        KINDS.clear()
        KINDS.update(before)
