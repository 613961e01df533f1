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
