"""The CUDA backend (phaseimpact/cuda.py) without a GPU: the same per-point kernel run by numba's
CUDA simulator (one Python thread per point, the engine uncompiled) against the threads backend;
the refusals (no GPU, a user law); the device kernel compiled to PTX for an H100 by the real CUDA
target where NVVM is installed; and the portable ulp that replaced ``np.nextafter``."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from _registry import restored_registry

from phaseimpact import _jit, seed_parameters, simulate_many
from phaseimpact.continuation import atlas
from phaseimpact.integrate.spacing import ulp_above

ROOT = Path(__file__).resolve().parents[1]

#: Each law kind on a small grid: elastic (abrate), Filippov (paper), with memory (thornton).
LAWS = {"abrate": {}, "paper": {}, "thornton": {"limiting_pressure": 2e9}}
KAPPAS = np.geomspace(1e9, 1e14, 6)
SPEEDS = (0.5, 2.0)


def cases(law):
    base = seed_parameters(**LAWS[law])
    return [base.replace(kappa=k, v=v) for v in SPEEDS for k in KAPPAS]


SIMULATED = textwrap.dedent("""
    import sys

    import numba
    import numpy as np

    assert numba.config.ENABLE_CUDASIM and numba.config.DISABLE_JIT
    from phaseimpact import seed_parameters, simulate_many
    from phaseimpact.continuation import atlas

    sys.path.insert(0, sys.argv[2])
    from test_cuda import KAPPAS, cases

    out = {}
    for law in ("abrate", "paper", "thornton"):
        for backend in ("cuda", "threads"):
            c = simulate_many(cases(law), law, backend=backend)
            out[f"{law}/{backend}/codes"] = np.stack([c.status, c.outcome, c.stop_reason]).astype(np.int64)
            out[f"{law}/{backend}/stick_count"] = c.stick_count
            out[f"{law}/{backend}/sticks"] = np.stack([c.stick_t, c.stick_delta, c.stick_dwell])
            for name, column in c.values.items():
                out[f"{law}/{backend}/values/{name}"] = column
    a = atlas(seed_parameters(), "paper", {"kappa": KAPPAS[:3], "v": [0.5, 2.0]}, backend="cuda")
    out["atlas/outcome"] = a.outcome
    out["atlas/max_force"] = a.max_force
    np.savez(sys.argv[1], **out)
""")


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """The small grids run in a subprocess under numba's CUDA simulator (chosen at import)."""
    path = tmp_path_factory.mktemp("cuda") / "simulated.npz"
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1", NUMBA_DISABLE_JIT="1",
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    out = subprocess.run([sys.executable, "-c", SIMULATED, str(path), str(ROOT / "tests")], env=env,
                         capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert out.returncode == 0, out.stderr[-3000:]
    with np.load(path) as data:
        return dict(data)


def _columns(data, prefix):
    return {key[len(prefix):]: value for key, value in data.items() if key.startswith(prefix)}


@pytest.mark.parametrize("law", list(LAWS))
def test_simulated_gpu_is_bit_identical_to_threads_in_the_same_arithmetic(simulated, law):
    """The GPU path (one thread per point, its own workspace rows) against run_block's threads, both
    uncompiled in the simulator's process: the same arithmetic in the same order, so every column
    bit-identical, NaNs in the same places."""
    gpu, threads = _columns(simulated, f"{law}/cuda/"), _columns(simulated, f"{law}/threads/")
    assert gpu.keys() == threads.keys() and len(gpu) > 10
    for name in gpu:
        np.testing.assert_array_equal(gpu[name], threads[name], err_msg=name)
    assert gpu["stick_count"].shape == (len(KAPPAS) * len(SPEEDS),)


@pytest.mark.parametrize("law", list(LAWS))
def test_simulated_gpu_matches_the_compiled_threads_backend(simulated, law):
    """The simulated GPU against the compiled engine on two threads: counts, codes and outcomes
    equal, every float within 1e-9 relative (compiled and uncompiled arithmetic may differ in the
    last bits of a libm call)."""
    compiled = simulate_many(cases(law), law, n_threads=2)
    gpu = _columns(simulated, f"{law}/cuda/")
    np.testing.assert_array_equal(gpu["codes"], np.stack([compiled.status, compiled.outcome, compiled.stop_reason]))
    np.testing.assert_array_equal(gpu["stick_count"], compiled.stick_count)
    floats = {"sticks": np.stack([compiled.stick_t, compiled.stick_delta, compiled.stick_dwell])}
    floats.update({f"values/{name}": column for name, column in compiled.values.items()})
    for name, expected in floats.items():
        np.testing.assert_allclose(gpu[name], expected, rtol=1e-9, atol=0, equal_nan=True, err_msg=name)
    outcomes = set(compiled.outcome.tolist())
    assert len(outcomes) >= 1 and not compiled.failed.any()


def test_simulated_gpu_atlas_matches_threads(simulated):
    """atlas(backend="cuda") fills the same result object as the threads backend."""
    threads = atlas(seed_parameters(), "paper", {"kappa": KAPPAS[:3], "v": [0.5, 2.0]})
    np.testing.assert_array_equal(simulated["atlas/outcome"], threads.outcome)
    np.testing.assert_allclose(simulated["atlas/max_force"], threads.max_force, rtol=1e-9, atol=0)


def _cuda_usable() -> bool:
    from phaseimpact import cuda

    return cuda.unavailable() is None


@pytest.mark.skipif(_cuda_usable(), reason="this machine has a usable GPU: nothing to refuse")
def test_without_a_gpu_the_cli_refuses_in_one_line(tmp_path):
    """No GPU here: --backend cuda exits 2 with one line naming CUDA, before any work (no archive)."""
    out_file = tmp_path / "a.nc"
    out = subprocess.run([sys.executable, "-m", "phaseimpact.cli", "sweep", "--axis", "kappa=1e9:1e12:3:log",
                          "--out", str(out_file), "--backend", "cuda"], capture_output=True, text=True,
                         timeout=300, cwd=ROOT, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "CUDA is not usable" in lines[0], out.stderr
    assert not out_file.exists()


@pytest.mark.skipif(_cuda_usable(), reason="this machine has a usable GPU: nothing to refuse")
def test_without_a_gpu_python_refuses_before_any_work():
    with pytest.raises(ValueError, match="backend = 'cuda': CUDA is not usable"):
        simulate_many([seed_parameters()], "paper", backend="cuda")
    with pytest.raises(ValueError, match="CUDA is not usable"):
        atlas(seed_parameters(), "paper", {"kappa": [1e9, 1e10]}, backend="cuda")


def test_the_cli_offers_every_backend_of_the_library():
    from phaseimpact.cli._common import BACKENDS
    from phaseimpact.continuation._parallel import BACKENDS as LIBRARY

    assert BACKENDS == LIBRARY and "cuda" in BACKENDS


def test_backends_command_lists_each_backend():
    out = subprocess.run([sys.executable, "-m", "phaseimpact.cli", "backends"], capture_output=True, text=True,
                         timeout=300, cwd=ROOT, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert out.returncode == 0, out.stderr
    rows = {line.split()[0]: line.split()[1] for line in out.stdout.splitlines()}
    assert list(rows) == ["threads", "loky", "dask", "cuda"] and rows["threads"] == "yes"
    assert rows["cuda"] == ("yes" if _cuda_usable() else "no")


def test_a_user_law_is_refused_on_the_gpu():
    """A user law is a Python function: refused with backend cuda (before any run), whether or not
    a GPU exists, in simulate_many and atlas alike."""
    import phaseimpact

    with restored_registry():  # later tests enumerate the registry (test_precompile's fingerprint)
        phaseimpact.define_law("cuda-test-kk", lambda d, dd, K, gamma, a: (K * d + gamma * dd) * d ** 0.5,
                               damping=("gamma", "N s m-1.5"), damping_power=1.5)
        with pytest.raises(ValueError, match="cannot run the user law 'cuda-test-kk'"):
            simulate_many([seed_parameters(kappa=1e5)], "cuda-test-kk", backend="cuda")
        with pytest.raises(ValueError, match="cannot run the user law 'cuda-test-kk'"):
            atlas(seed_parameters(kappa=1e5), "cuda-test-kk", {"kappa": [1e5, 1e6]}, backend="cuda")


def test_ulp_above_is_nextafter_bit_for_bit():
    """The portable gap to the next float (the device has no nextafter) equals numpy's for zero,
    subnormals, powers of two of both signs and random magnitudes."""
    rng = np.random.default_rng(39)
    values = np.concatenate([[0.0, 5e-324, 1e-320, 2.2250738585072014e-308, 1.0, 0.5, 2.0, -1.0, -0.5, -2.0,
                              1e300, -1e-300, 1.7976931348623157e308 / 2],
                             2.0 ** np.arange(-1074, 1023, 7), -(2.0 ** np.arange(-1070, 1023, 11)),
                             rng.uniform(0, 1, 200) * 10.0 ** rng.integers(-300, 300, 200),
                             -rng.uniform(0, 1, 50) * 10.0 ** rng.integers(-300, 300, 50)])
    ours = np.array([ulp_above(float(s)) for s in values])
    np.testing.assert_array_equal(ours, np.nextafter(values, np.inf) - values)


def _nvvm_available() -> bool:
    try:
        from numba.cuda.cudadrv import nvvm

        return nvvm.is_available()
    except Exception:  # no numba.cuda, or no CUDA toolkit
        return False


PTX = textwrap.dedent("""
    import sys
    import types

    import numba
    import numpy as np
    import numba.cuda.dispatcher
    from numba import cuda

    from phaseimpact import cuda as gpu, seed_parameters
    from phaseimpact.integrate import api, driver as d

    # The engine's @njit functions become device functions when the kernel calls them; numba asks the
    # current device for its compute capability there, and there is none: the H100's (9.0) instead.
    numba.cuda.dispatcher.get_current_device = lambda: types.SimpleNamespace(compute_capability=(9, 0))
    batch = api.pack_batch([seed_parameters()], "paper", None, 1e-10)
    work = gpu.workspaces(1, batch.C.shape[1], 32)
    outputs = (np.empty((1, d.N_SUMMARY)), np.empty((1, 32)), np.empty((1, 32)), np.empty((1, 32)),
               np.empty(1, np.int64))
    options = (1e-10, True, np.int64(-1), np.int64(0), api.MAX_STEPS, api.MAX_EVENTS, api._stiff_after(True))
    args = (np.int64(batch.law.code), (batch.C, batch.Y0, batch.t_end, batch.atol, batch.max_step), options,
            outputs, work)
    ptx, _ = cuda.compile_ptx(gpu._kernel().py_func, tuple(numba.typeof(a) for a in args), cc=(9, 0))
    print(len(ptx), ".entry" in ptx, ".target sm_90" in ptx, "phaseimpact_poll" in ptx)
""")


@pytest.mark.slow
@pytest.mark.skipif(os.environ.get("PHASEIMPACT_PTX") != "1",
                    reason="the PTX compile takes ~10 min on 2 cores: make test-ptx (PHASEIMPACT_PTX=1) runs it")
@pytest.mark.skipif(not _nvvm_available(), reason="no NVVM (CUDA toolkit) to compile PTX with")
def test_the_device_kernel_compiles_to_ptx_for_an_h100(request):
    """The real CUDA target (not the simulator) accepts the whole per-point path: law, right-hand
    sides, DOP853, Radau, events, root finders, the flight's elliptic functions, for sm_90 (about 8
    minutes on 2 loaded cores: kept per engine digest in pytest's cache, as the cold sessions of
    tests/test_precompile.py)."""
    key = f"phaseimpact/cuda-ptx/{_jit.engine_digest()}/{hashlib.sha256(PTX.encode()).hexdigest()[:16]}"
    kept = request.config.cache.get(key, None)
    if kept is None:
        out = subprocess.run([sys.executable, "-c", PTX], capture_output=True, text=True, timeout=1500, cwd=ROOT,
                             env=dict(os.environ, PYTHONPATH=str(ROOT)))
        assert out.returncode == 0, out.stderr[-3000:]
        kept = out.stdout.split()
        request.config.cache.set(key, kept)
    size, entry, target, polls = kept
    assert int(size) > 100_000 and (entry, target, polls) == ("True", "True", "False")


def test_the_gpu_benchmark_runs_under_the_simulator(tmp_path):
    """benchmarks/gpu.py --simulator: the three parts on a 3 x 3 grid (CI keeps the script from rotting);
    the simulated GPU and the CPU agree in codes and counts."""
    results = tmp_path / "gpu_simulator.md"
    script = ROOT / "benchmarks" / "gpu.py"
    out = subprocess.run([sys.executable, str(script), "--simulator", "--results", str(results)], capture_output=True,
                         text=True, timeout=600, cwd=ROOT, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert out.returncode == 0, out.stderr[-3000:]
    text = results.read_text()
    assert "GPU vs CPU equal in codes and counts" in text
    assert text.count("| (a) paper atlas | 9 |") == 3 and "| (b) hunt-crossley" in text
