"""The first compile (phaseimpact/_jit.py): one process, announced once on stderr; and the
kernels compiled as numba's whole libraries (``PHASEIMPACT_LINKED_ONLY=0``) give bit for bit the
results of the linked-only kernels (the default, this process's cache) on a fingerprint of every
law variant, the stiff path, a batch and the seed's RK4.

A cold session costs a whole first compile (30-60 s on two cores). What it checks depends only on
the engine's sources (the digest that also names the cache), this file's session and the versions
of Python, numba and llvmlite: its output is kept in pytest's cache under that key, and a test run
on unchanged sources reuses it (``PHASEIMPACT_COLD_TESTS=1`` runs it anyway; ``pytest
--cache-clear`` forgets it).
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import subprocess
import sys

import numpy as np
import pytest

from phaseimpact import _jit

# The fingerprint: every law variant on a soft and a stiff case, a batch, the seed's RK4.
FINGERPRINT = r"""
import numpy as np
from phaseimpact import seed_parameters, simulate, simulate_many
from phaseimpact.model import law_variants

def fingerprint():
    p = seed_parameters(v=1.0, kappa=3e9, limiting_pressure=2e9)
    stiff = p.replace(kappa=1e14, v=5.0)
    rows = []
    for law in law_variants():
        for case in (p, stiff):
            r = simulate(case, law, 2e-3)
            rows.append([float(x) for x in np.concatenate([r.summary, r.final_state])])
        cols = simulate_many([p, p.replace(kappa=1e12), stiff], law, 2e-3, n_threads=2)
        rows.append([float(x) for x in np.concatenate([cols.max_force, cols.t_run])])
    r = simulate(p, "paper", 2e-4, integrator="rk4")
    rows.append([float(x) for x in np.concatenate([r.summary, r.final_state])])
    return rows
"""
COLD_SESSION = FINGERPRINT + r"""
import json, multiprocessing
print(json.dumps({"rows": fingerprint(), "children": len(multiprocessing.active_children())}))
"""


def _session_key() -> str:
    import llvmlite
    import numba

    parts = (_jit.engine_digest(), COLD_SESSION, sys.version, numba.__version__, llvmlite.__version__,
             platform.machine(), platform.processor())
    return hashlib.sha256(repr(parts).encode()).hexdigest()[:24]


@pytest.fixture(scope="module")
def whole_libraries_session(tmp_path_factory, request):
    """A cold session with the kernels compiled as whole libraries, on an empty cache."""
    key = f"phaseimpact/cold-session-whole/{_session_key()}"
    kept = request.config.cache.get(key, None)
    if kept is not None and not os.environ.get("PHASEIMPACT_COLD_TESTS"):
        return kept
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path_factory.mktemp("numba-cache")), PHASEIMPACT_LINKED_ONLY="0")
    env.pop("NUMBA_DISABLE_JIT", None)
    out = subprocess.run([sys.executable, "-c", COLD_SESSION], env=env, capture_output=True, text=True, timeout=1200)
    assert out.returncode == 0, out.stderr[-3000:]
    session = json.loads(out.stdout.strip().splitlines()[-1])
    session["stderr"] = out.stderr
    request.config.cache.set(key, session)
    return session


def test_a_cold_cache_compiles_in_this_process_and_says_so_once(whole_libraries_session):
    stderr = whole_libraries_session["stderr"]
    assert stderr.count("phaseimpact: compiling") == 1, stderr[-3000:]
    assert f"compiling the engine once for this machine, {_jit.FIRST_COMPILE} on 2 cores (cache: " in stderr
    assert "RuntimeWarning" not in stderr, stderr[-3000:]
    assert whole_libraries_session["children"] == 0


def test_whole_libraries_give_the_linked_only_kernels_numbers_bit_for_bit(whole_libraries_session):
    namespace: dict = {}
    exec(FINGERPRINT, namespace)
    here = namespace["fingerprint"]()  # this process: the default, kernels linked only where numba allows
    assert _jit.linked_only(), "this numba lacks the hooks: both sides would be whole libraries"
    assert len(here) == len(whole_libraries_session["rows"]) > 10
    for cold, warm in zip(whole_libraries_session["rows"], here, strict=True):
        np.testing.assert_array_equal(cold, warm)


def test_the_announcement_says_when_nothing_is_cached(monkeypatch):
    monkeypatch.setattr(_jit, "cache_info", lambda: _jit.CacheInfo(None, "", "NUMBA_DISABLE_JIT is set", ()))
    assert _jit.announce() == (f"phaseimpact: compiling the engine for this process, {_jit.FIRST_COMPILE} on 2 cores "
                               "(nothing is cached: NUMBA_DISABLE_JIT is set; set NUMBA_CACHE_DIR to a writable "
                               "directory to compile once)")


def test_the_compile_after_a_stiff_run_says_what_it_compiles(monkeypatch, capsys):
    """An entry's compile is announced once; after a run turned stiff in this process, the engine's
    next compile (the one with Radau, about as long again) says so once more, instead of a long
    silence or the first compile's words again. Other functions' compiles say nothing."""
    from types import SimpleNamespace

    monkeypatch.setattr(_jit._Announced, "lines", set())
    monkeypatch.setattr(_jit._Announced, "stiff_run", False)
    monkeypatch.setattr(_jit, "cache_info", lambda: _jit.CacheInfo(None, "", "a test", ()))

    def compile_of(module, wrapper=True):
        _jit._on_compile(SimpleNamespace(py_func=SimpleNamespace(__module__=module),
                                         targetoptions={} if wrapper else {"no_cpython_wrapper": True}))
        return capsys.readouterr().err.splitlines()

    assert compile_of("phaseimpact.model.rhs") == []
    assert compile_of("phaseimpact.integrate.driver", wrapper=False) == []  # a kernel the driver calls
    assert compile_of("phaseimpact.integrate.driver") == [_jit.announce()]
    assert compile_of("phaseimpact.integrate.rk4") == []
    _jit.stiff_run_met()
    assert compile_of("phaseimpact.integrate.driver") == [_jit.announce(stiff=True)]
    assert compile_of("phaseimpact.integrate.driver") == []
    assert "a run turned stiff: compiling the engine again" in _jit.announce(stiff=True)
    assert "a run turned stiff" not in _jit.announce()


def test_a_stiff_run_in_a_process_whose_first_compile_it_causes_says_so(monkeypatch, capsys):
    """A process that loaded the engine without Radau from the cache and meets a stiff run compiles
    only the engine with Radau: its one line is the stiff one (through api.again_with_radau)."""
    from types import SimpleNamespace

    from phaseimpact.integrate import api
    from phaseimpact.integrate import driver as d

    monkeypatch.setattr(_jit._Announced, "lines", set())
    monkeypatch.setattr(_jit._Announced, "stiff_run", False)
    monkeypatch.setattr(api, "cache_info", lambda: SimpleNamespace(path=None))
    monkeypatch.setattr(api._Radau, "met", False)
    assert api.again_with_radau(d.NEEDS_RADAU) and api._Radau.met is True
    _jit._on_compile(SimpleNamespace(py_func=d.run.py_func, targetoptions={}))
    assert capsys.readouterr().err.splitlines() == [_jit.announce(stiff=True)]
