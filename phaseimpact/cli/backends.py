"""``phaseimpact backends``: where sweeps and atlases can run on this machine, and why not."""

from __future__ import annotations

import importlib.util
import os

from ._common import EXIT_OK


def add_backends(p) -> None:
    pass  # no options


def backend_table() -> list[tuple[str, bool, str]]:
    """(backend, usable here, why or what) for each of ``--backend``'s choices, in their order."""
    from .. import cuda
    from ..continuation._parallel import BACKENDS

    cores = f"{os.cpu_count() or 1} cores of this machine"
    missing_cuda = cuda.unavailable()
    found = {
        "threads": (True, f"threads of this process, on the {cores}"),
        "loky": (importlib.util.find_spec("joblib") is not None, "joblib processes, on the " + cores),
        "dask": (importlib.util.find_spec("distributed") is not None, "a Dask cluster (dask.distributed)"),
        "cuda": (missing_cuda is None, missing_cuda or "one GPU thread per point (numba's CUDA target)"),
    }
    install = {"loky": "needs joblib: pip install joblib",
               "dask": "needs dask.distributed: pip install 'phaseimpact[dask]'"}
    return [(name, found[name][0], found[name][1] if found[name][0] or name not in install else install[name])
            for name in BACKENDS]


def run_backends(args) -> int:
    for name, usable, what in backend_table():
        print(f"{name:8} {'yes' if usable else 'no ':4} {what}")
    return EXIT_OK
