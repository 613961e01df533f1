"""``phaseimpact warmup``: the engine compiled ahead of time.

The first call of an entry on an empty cache compiles the engine in that process (and says so on
stderr once: :func:`phaseimpact._jit.announce`); :func:`warmup` makes every entry the commands use,
so that no later command, cluster worker or user of the same cache compiles anything.
"""

from __future__ import annotations

import time
from pathlib import Path

from .._jit import cache_info
from . import driver, rk4

__all__ = ["warmup"]


def _cache_files(path: Path | None) -> tuple[int, int]:
    if path is None or not path.is_dir():
        return 0, 0
    files = [f for f in path.rglob("*") if f.suffix in (".nbi", ".nbc")]
    return len(files), sum(f.stat().st_size for f in files)


def warmup() -> dict:
    """Compile (or load) every entry the commands use, each law, integrator and output.

    Returns where the cache is (``cache``: a path or None, ``writable``: whether there is one,
    ``reason`` when there is none), ``compiled`` (whether anything was compiled here), ``seconds``,
    and the cache's ``files`` and ``bytes``."""
    from ..model import law_variants
    from ..parameters import seed_parameters
    from . import api
    from .api import simulate, summary_run
    from .batch import simulate_many

    info = cache_info()
    start = time.perf_counter()
    entries = (driver.run, driver.run_block, driver.run_held, rk4.run_rk4)
    before = [entry.stats.cache_misses.copy() for entry in entries]
    p = seed_parameters(v=1.0, kappa=3e9, limiting_pressure=2e9)  # p_y: read by the plastic law only
    stiff = p.replace(kappa=1e14, v=5.0)  # the stiff (Radau) path
    # the engine with Radau, which every later process that shares the cache then runs (api.radau_marker)
    api.radau_needed()
    for law in law_variants():
        simulate(p, law, 2e-3)
        simulate_many([p, stiff], law, 2e-3)
        summary_run(p, law, 2e-3)  # critical searches, impact maps
    simulate(p, "paper", None, stop_on="slip")
    simulate(stiff, "paper", 2e-3)
    simulate(p, "paper", 2e-4, integrator="rk4")
    simulate(p, "hunt-crossley", 2e-3, save="steps")
    simulate_many([p, p.replace(kappa=1e12)], "paper", n_threads=2)
    compiled = [entry.stats.cache_misses for entry in entries] != before
    files, size = _cache_files(info.path)
    return {"cache": None if info.path is None else str(info.path), "writable": info.path is not None,
            "source": info.source, "reason": info.reason or None, "compiled": compiled,
            "seconds": time.perf_counter() - start, "files": files, "bytes": size}
