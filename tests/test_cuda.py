"""The CUDA backend (phaseimpact/cuda.py) without a GPU: the same per-point kernel run by numba's
CUDA simulator (one Python thread per point, the engine uncompiled) against the threads backend, for
simulate_many, atlas, orbit diagrams and critical curves; the refusals (no GPU, a user law);
the device kernel compiled to PTX for an H100 by the real CUDA target where NVVM is installed; and
the portable ulp that replaced ``np.nextafter``."""

from __future__ import annotations

import hashlib
import math
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
    from test_cuda import ORBITS, orbit_diagram_of

    for name in ORBITS:
        for backend in ("cuda", "threads"):
            d = orbit_diagram_of(name, backend)
            out[f"orbits/{name}/{backend}/plate"] = d.plate
            out[f"orbits/{name}/{backend}/peak_force"] = d.peak_force
            out[f"orbits/{name}/{backend}/distinct"] = d.distinct
    from phaseimpact.continuation import curve
    from test_cuda import CURVES, SIMULATED_GPU_KAPPAS, critical_curve_of

    curve.GPU_KAPPAS = SIMULATED_GPU_KAPPAS
    for name in CURVES:
        c = critical_curve_of(name, "cuda")
        for column in ("values", "kappa", "requested", "predicted"):
            out[f"curves/{name}/{column}"] = getattr(c, column)
    np.savez(sys.argv[1], **out)
""")

#: Orbit diagrams over each parameter, a law of each kind: (law, case options, param, values, period).
ORBITS = {"hunt-crossley-T": ("hunt-crossley", {"kappa": 3e9}, "T", [0.4e-3, 1e-3, 3e-3], None),
          "paper-v": ("paper", {"kappa": 3e9}, "v", [0.5, 1.0, 2.0], 3e-3),
          "thornton-kappa": ("thornton", {"limiting_pressure": 2e9}, "kappa", [0.0, 1e9], 2e-3)}


def orbit_diagram_of(name, backend):
    from phaseimpact.train import orbit_diagram

    law, case, param, values, period = ORBITS[name]
    return orbit_diagram(seed_parameters(**case), law, param, values, period=period, transients=2, samples=3,
                         backend=backend)

#: Critical curves, each quantity the GPU corrector evaluates: (law, what, values of v, options); the
#: grazing curve starts at the seed case's first grazing value (extremum 5, near 3.577e10 at v = 1).
CURVES = {"kappa_c": ("paper", "kappa_c", [1.0, 2.0], {}),
          "grazing": ("hunt-crossley", "grazing", [1.0, 1.05, 1.1], {"kappa_start": 3.577e10, "contact_index": 5})}
#: Kappas of a launch of the GPU corrector under the simulator (few: each is a Python thread).
SIMULATED_GPU_KAPPAS = 4


def critical_curve_of(name, backend):
    from phaseimpact.continuation import critical_curve

    law, what, speeds, options = CURVES[name]
    return critical_curve(seed_parameters(), law, "v", speeds, what=what, kappa_rtol=1e-10, backend=backend,
                          **options)


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


@pytest.mark.parametrize("name", list(ORBITS))
def test_simulated_gpu_orbit_diagram_is_bit_identical_to_threads(simulated, name):
    """orbit_diagram(backend="cuda"), one launch per impact over all values, against the threads backend
    (each value's impacts in turn through simulate), both uncompiled in the simulator's process: the same
    inputs and arithmetic, so states, peak forces and counts bit-identical."""
    gpu, threads = _columns(simulated, f"orbits/{name}/cuda/"), _columns(simulated, f"orbits/{name}/threads/")
    assert gpu.keys() == threads.keys() == {"plate", "peak_force", "distinct"}
    for column in gpu:
        np.testing.assert_array_equal(gpu[column], threads[column], err_msg=column)
    values = ORBITS[name][3]
    assert gpu["plate"].shape == (len(values), 3, 2) and np.all(np.isfinite(gpu["peak_force"]))
    assert np.all(gpu["peak_force"] > 0)  # every sampled impact touched


@pytest.mark.parametrize("name", list(ORBITS))
def test_simulated_gpu_orbit_diagram_matches_the_compiled_threads_backend(simulated, name):
    """The simulated GPU's orbit diagram against the compiled engine: distinct counts equal, states
    and peak forces within 1e-9 relative (last bits of a libm call, carried over five impacts)."""
    compiled = orbit_diagram_of(name, "threads")
    gpu = _columns(simulated, f"orbits/{name}/cuda/")
    np.testing.assert_array_equal(gpu["distinct"], compiled.distinct)
    np.testing.assert_allclose(gpu["peak_force"], compiled.peak_force, rtol=1e-9, atol=0)
    # the plate's x2 crosses zero: relative to the state's scales (Hertz indentation, v), as distinct counts
    scale = np.array([seed_parameters(**ORBITS[name][1]).hertz_indentation, 1.0])
    np.testing.assert_allclose(gpu["plate"] / scale, compiled.plate / scale, rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", list(CURVES))
def test_simulated_gpu_critical_curve_walks_as_the_threads_backend(simulated, name):
    """critical_curve(backend="cuda"): the same walk with the GPU's corrector (the defining function at
    SIMULATED_GPU_KAPPAS kappas per launch, sign change narrowed to Brent's final bracket) against the
    compiled threads backend (Brent's method): the same values walked, steps and requested flags, every
    kappa within 1e-9 relative (both within kappa_rtol = 1e-10 of the root)."""
    threads = critical_curve_of(name, "threads")
    gpu = _columns(simulated, f"curves/{name}/")
    np.testing.assert_array_equal(gpu["values"], threads.values)
    np.testing.assert_array_equal(gpu["requested"], threads.requested)
    assert len(gpu["values"]) > len(CURVES[name][2]) and not threads.message  # the step was halved on the way
    np.testing.assert_allclose(gpu["kappa"], threads.kappa, rtol=1e-9, atol=0)
    np.testing.assert_allclose(gpu["predicted"], threads.predicted, rtol=1e-9, atol=0)


def _cuda_usable() -> bool:
    from phaseimpact import cuda

    return cuda.unavailable() is None


REFUSED_COMMANDS = {  # a command line with --backend cuda, and the files it must not write
    "sweep": (["sweep", "--axis", "kappa=1e9:1e12:3:log", "--out", "{d}/a.nc"], ["a.nc"]),
    "orbit-diagram": (["orbit-diagram", "--law", "hunt-crossley", "--kappa", "3e9", "--axis", "T=5e-4:4e-3:3",
                       "--transients", "2", "--samples", "2", "--out", "{d}/o.png", "--archive", "{d}/o.nc"],
                      ["o.png", "o.nc"]),
    "critical-curve": (["critical-curve", "--axis", "v=1:2:2", "--out", "{d}/c.nc"], ["c.nc"]),
}


@pytest.mark.skipif(_cuda_usable(), reason="this machine has a usable GPU: nothing to refuse")
@pytest.mark.parametrize("command", sorted(REFUSED_COMMANDS))
def test_without_a_gpu_the_cli_refuses_in_one_line(tmp_path, command):
    """No GPU here: --backend cuda exits 2 with one line naming CUDA, before any work (no figure, no
    archive)."""
    argv, written = REFUSED_COMMANDS[command]
    out = subprocess.run([sys.executable, "-m", "phaseimpact.cli", *(a.format(d=tmp_path) for a in argv),
                          "--backend", "cuda"], capture_output=True, text=True, timeout=300, cwd=ROOT,
                         env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "backend = 'cuda': CUDA is not usable" in lines[0], out.stderr
    assert not any((tmp_path / name).exists() for name in written)


@pytest.mark.skipif(_cuda_usable(), reason="this machine has a usable GPU: nothing to refuse")
def test_without_a_gpu_python_refuses_before_any_work():
    with pytest.raises(ValueError, match="backend = 'cuda': CUDA is not usable"):
        simulate_many([seed_parameters()], "paper", backend="cuda")
    with pytest.raises(ValueError, match="CUDA is not usable"):
        atlas(seed_parameters(), "paper", {"kappa": [1e9, 1e10]}, backend="cuda")
    from phaseimpact.train import orbit_diagram

    with pytest.raises(ValueError, match="backend = 'cuda': CUDA is not usable"):
        orbit_diagram(seed_parameters(kappa=3e9), "hunt-crossley", "T", [1e-3, 2e-3], backend="cuda")
    with pytest.raises(ValueError, match="backend = 'dask' is out of range; allowed: one of threads, cuda"):
        orbit_diagram(seed_parameters(kappa=3e9), "hunt-crossley", "T", [1e-3, 2e-3], backend="dask")
    from phaseimpact.continuation import critical_curve

    with pytest.raises(ValueError, match="backend = 'cuda': CUDA is not usable"):
        critical_curve(seed_parameters(), "paper", "v", [1.0, 2.0], backend="cuda")
    with pytest.raises(ValueError, match="backend = 'mpi' is out of range; allowed: one of threads, cuda"):
        critical_curve(seed_parameters(), "paper", "v", [1.0, 2.0], backend="mpi")


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
    a GPU exists, in simulate_many, atlas, orbit diagrams and critical curves alike."""
    import phaseimpact

    with restored_registry():  # later tests enumerate the registry (test_precompile's fingerprint)
        phaseimpact.define_law("cuda-test-kk", lambda d, dd, K, gamma, a: (K * d + gamma * dd) * d ** 0.5,
                               damping=("gamma", "N s m-1.5"), damping_power=1.5)
        with pytest.raises(ValueError, match="cannot run the user law 'cuda-test-kk'"):
            simulate_many([seed_parameters(kappa=1e5)], "cuda-test-kk", backend="cuda")
        with pytest.raises(ValueError, match="cannot run the user law 'cuda-test-kk'"):
            atlas(seed_parameters(kappa=1e5), "cuda-test-kk", {"kappa": [1e5, 1e6]}, backend="cuda")
        from phaseimpact.train import orbit_diagram

        with pytest.raises(ValueError, match="cannot run the user law 'cuda-test-kk'"):
            orbit_diagram(seed_parameters(kappa=1e5), "cuda-test-kk", "T", [1e-3, 2e-3], backend="cuda")
        from phaseimpact.continuation import critical_curve

        with pytest.raises(ValueError, match="cannot run the user law 'cuda-test-kk'"):
            critical_curve(seed_parameters(), "cuda-test-kk", "v", [1.0, 2.0], what="grazing", kappa_start=1e5,
                           backend="cuda")


def test_orbit_diagram_checks_its_tolerance_before_any_run():
    """The GPU's runs do not pass through simulate, which checked rtol for the threads backend:
    orbit_diagram checks it first, for both backends, GPU or not."""
    from phaseimpact.train import orbit_diagram

    for backend in ("threads", "cuda"):
        with pytest.raises(ValueError, match=r"rtol = 5.0 is out of range; allowed: 1e-13 <= rtol <= 0.001"):
            orbit_diagram(seed_parameters(kappa=3e9), "hunt-crossley", "T", [1e-3], rtol=5.0, backend=backend)


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
    import re
    import sys
    import time
    import types

    import numba
    import numpy as np
    import numba.cuda.dispatcher
    from numba import cuda

    from phaseimpact import cuda as gpu, seed_parameters
    from phaseimpact.integrate import api, driver as d
    from phaseimpact.integrate.batch import pack_batch
    from phaseimpact.integrate.record import workspace_size

    # The engine's @njit functions become device functions when the kernel calls them; numba asks the
    # current device for its compute capability there, and there is none: the H100's (9.0) instead.
    numba.cuda.dispatcher.get_current_device = lambda: types.SimpleNamespace(compute_capability=(9, 0))
    batch = pack_batch([seed_parameters()], "paper", None, 1e-10)
    work = np.zeros((1, workspace_size(batch.C.shape[1], 32)))
    outputs = (np.empty((1, d.N_SUMMARY)), np.empty((1, 32)), np.empty((1, 32)), np.empty((1, 32)),
               np.empty(1, np.int64))
    options = (1e-10, True, np.int64(-1), np.int64(0), api.MAX_STEPS, api.MAX_EVENTS, api._stiff_after(True))
    args = (np.int64(batch.law.code), (batch.C, batch.Y0, batch.t_end, batch.atol, batch.max_step), options,
            outputs, work, np.empty((0, 5)))
    kernel = gpu._kernel()  # installs the call policy (PHASEIMPACT_GPU_CALLS) around NVVM
    from numba.cuda.cudadrv import nvvm

    entry = gpu.nvvm_entry(nvvm)
    nvvm_s, handed, policy_entry = [], [], getattr(nvvm, entry)

    def timed_entry(llvmir, **options):
        handed.extend([llvmir] if isinstance(llvmir, str) else llvmir)  # numba's modules, before the policy
        start = time.perf_counter()
        try:
            return policy_entry(llvmir, **options)
        finally:
            nvvm_s.append(time.perf_counter() - start)

    setattr(nvvm, entry, timed_entry)
    start = time.perf_counter()
    ptx, _ = cuda.compile_ptx(kernel.py_func, tuple(numba.typeof(a) for a in args), cc=(9, 0))
    total = time.perf_counter() - start
    functions = len(re.findall(r"(?m)^[.](?:visible |weak )*[.]func", ptx))
    print(len(ptx), ".entry" in ptx, ".target sm_90" in ptx, "phaseimpact_poll" in ptx, functions, ptx.count("\\n"),
          f"{sum(nvvm_s):.1f}", f"{total:.1f}", len(handed), len(set(handed)), sum(map(len, handed)))
""")


@pytest.mark.slow
@pytest.mark.skipif(not _nvvm_available(), reason="no NVVM (CUDA toolkit) to compile PTX with")
def test_the_device_kernel_compiles_to_ptx_for_an_h100(request):
    """The real CUDA target (not the simulator) accepts the whole per-point path: law, right-hand
    sides, DOP853, Radau, events, root finders, the flight's elliptic functions, for sm_90 (about
    half a minute with the engine's calls kept, ``phaseimpact.cuda``'s call policy; kept per engine
    digest in pytest's cache, as the cold sessions of tests/test_precompile.py). The calls are
    there: with every function inlined (``PHASEIMPACT_GPU_CALLS=0``) the PTX has no function
    besides the kernel, and NVVM took 277 s of a 298 s compile (benchmarks/results/gpu_compile.md)."""
    from phaseimpact._environment import GPU_CALLS_VARIABLE

    policy = hashlib.sha256((PTX + (ROOT / "phaseimpact" / "cuda.py").read_text()).encode()).hexdigest()[:16]
    key = f"phaseimpact/cuda-ptx/{_jit.engine_digest()}/{policy}/{os.environ.get(GPU_CALLS_VARIABLE, '')}"
    kept = request.config.cache.get(key, None)
    if kept is None:
        out = subprocess.run([sys.executable, "-c", PTX], capture_output=True, text=True, timeout=1500, cwd=ROOT,
                             env=dict(os.environ, PYTHONPATH=str(ROOT)))
        assert out.returncode == 0, out.stderr[-3000:]
        kept = out.stdout.split()
        request.config.cache.set(key, kept)
    size, entry, target, polls, functions = kept[:5]
    assert int(size) > 100_000 and (entry, target, polls) == ("True", "True", "False")
    assert int(functions) > 50, f"{functions} PTX functions: the engine's calls were inlined"


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


def _synthetic_margins(monkeypatch, margin):
    """The GPU corrector's launches answered on the CPU with ``margin(kappa)`` as each run's first stick
    margin; returns the list of each launch's kappas."""
    from phaseimpact.continuation import curve
    from phaseimpact.integrate import driver as d

    launches = []

    def summary_runs(law, points, t_ends, *, rtol, **options):
        kappas = np.array([p.kappa for p in points])
        launches.append(kappas)
        summary = np.zeros((len(points), d.N_SUMMARY))
        summary[:, d.S_STATUS] = d.SUCCESS
        summary[:, d.S_FIRST_STICK_MARGIN] = margin(kappas)
        return summary, np.zeros((len(points), 5))

    monkeypatch.setattr(curve, "summary_runs", summary_runs)
    return launches


@pytest.mark.parametrize("kappa_rtol", [1e-10, 1e-14])
def test_gpu_corrector_narrows_to_brents_final_bracket(monkeypatch, kappa_rtol):
    """A margin with one known root: the root within kappa_rtol / 4 (Brent's xtol in log(kappa)), in
    launches of GPU_KAPPAS kappas each, a 2 % bracket narrowed GPU_KAPPAS + 1-fold a launch (5 launches
    at kappa_rtol = 1e-10, as GPU_KAPPAS's docstring says); each launch's kappas in the last's bracket."""
    from phaseimpact.continuation import curve
    from phaseimpact.model import as_law

    root = 1.234567e12
    launches = _synthetic_margins(monkeypatch, lambda k: np.log(root) - np.log(k))
    correct = curve._gpu_corrector(as_law("paper"), "kappa_c", 1, kappa_rtol, 1e-10)
    found = correct(seed_parameters(), root * 1.01, 0.02)
    assert abs(math.log(found / root)) <= kappa_rtol / 4 + curve.BRENT_RTOL * math.log(root)
    assert all(len(kappas) == curve.GPU_KAPPAS for kappas in launches)
    if kappa_rtol == 1e-10:
        assert len(launches) == 5
    for before, after in zip(launches[:-1], launches[1:], strict=True):
        assert before.min() <= after.min() and after.max() <= before.max()


def test_gpu_corrector_refuses_a_bracket_as_brent_does_and_several_sign_changes(monkeypatch):
    """None for ends of one sign or not finite (as the threads corrector), and for a bracket whose samples
    change sign five times, its ends of opposite signs (Brent would take one of the roots: the GPU's
    corrector takes none)."""
    from phaseimpact.continuation import curve
    from phaseimpact.model import as_law

    law, p, guess = as_law("paper"), seed_parameters(), 1e12
    for margin in (lambda k: np.log(k) * 0 + 1.0,  # no root
                   lambda k: np.where(k > guess * 1.01, -np.inf, np.log(guess * 0.99) - np.log(k)),  # end -inf
                   lambda k: np.sin(np.log(k / guess) * 2.5 * np.pi / 0.02)):  # roots at 0, +-0.008, +-0.016
        _synthetic_margins(monkeypatch, margin)
        assert curve._gpu_corrector(law, "kappa_c", 1, 1e-10, 1e-10)(p, guess, 0.02) is None


def test_gpu_corrector_does_not_read_a_failed_run(monkeypatch):
    """A launch whose run failed is not read as a value: RunFailed naming its kappa and status (the run
    again on the CPU, which succeeds here, has no message to add)."""
    from phaseimpact.continuation import curve
    from phaseimpact.continuation.transition import RunFailed
    from phaseimpact.integrate import driver as d
    from phaseimpact.model import as_law

    _synthetic_margins(monkeypatch, lambda k: np.log(1e12) - np.log(k))
    answered = curve.summary_runs

    def failing(*args, **options):
        summary, final = answered(*args, **options)
        summary[1, d.S_STATUS] = d.STATUSES.index("step-size-collapse")
        return summary, final

    monkeypatch.setattr(curve, "summary_runs", failing)
    with pytest.raises(RunFailed, match=r"kappa = 9\.\d+e\+11: step-size-collapse on the GPU"):
        curve._gpu_corrector(as_law("paper"), "kappa_c", 1, 1e-10, 1e-10)(seed_parameters(), 1e12, 0.1)


def test_gpu_summaries_refuse_a_non_finite_arrival_before_any_launch(monkeypatch):
    """batch.summary_runs (the orbit diagram's launches): finite arrivals reach the launch as the runs'
    initial (x1, x2, x1dot, x2dot); one NaN among them is simulate's ValueError, and nothing is launched."""
    from phaseimpact import cuda
    from phaseimpact.integrate.batch import summary_runs
    from phaseimpact.model import as_law

    launched = []
    monkeypatch.setattr(cuda, "run_batch_cuda", lambda code, batch, *rest: launched.append(batch))
    cases = [seed_parameters(), seed_parameters(v=2.0)]
    arrivals = np.array([[1e-6, 1e-6, 1.0, -0.1], [2e-6, 2e-6, 2.0, 0.3]])
    summary_runs(as_law("paper"), cases, [None, None], rtol=1e-10, arrivals=arrivals)
    assert len(launched) == 1 and np.array_equal(launched[0][1][:, :4], arrivals)
    arrivals[1, 3] = np.nan
    with pytest.raises(ValueError, match=r"initial = .* is out of range; allowed: 4 finite numbers"):
        summary_runs(as_law("paper"), cases, [None, None], rtol=1e-10, arrivals=arrivals)
    assert len(launched) == 1


LOOP = "_ZN11phaseimpact9integrate6driver5_loopB4v162B12cw51cXTLSUwvE5ArrayIdLi1E"
FORCED = "_ZN11phaseimpact5model5forms8force_ofB3v25B12cw51cXTLSUwvEdd"
KERNEL = "_ZN6cudapy11phaseimpact4cuda7_kernel12_3clocals_3e6pointsB2v1E5Tuple"


def test_the_call_policy_marks_the_engine_calls_noinline_and_nothing_else():
    """keep_calls: a named function's definition loses ``alwaysinline`` and gains ``noinline`` (its
    body's brace kept, on the line or the next), its declaration elsewhere loses ``alwaysinline``;
    a function not named, and the kernel, are left as they were."""
    from phaseimpact.cuda import keep_calls

    module = "\n".join([
        f'define linkonce_odr i32 @"{LOOP}"(i8* %".1", double %".2") alwaysinline {{',
        "entry:", "  ret i32 0", "}",
        f'declare i32 @"{LOOP}"(i8*, double) alwaysinline',
        f'define linkonce_odr i32 @"{FORCED}"(double %".1") alwaysinline',
        "{", "  ret i32 0", "}",
        f'define void @"{KERNEL}"(i8* %".1")', "{", "  ret void", "}"])
    calls = frozenset({"phaseimpact.integrate.driver._loop"})
    lines = keep_calls(module, calls).split("\n")
    assert lines[0] == f'define linkonce_odr i32 @"{LOOP}"(i8* %".1", double %".2") noinline {{'
    assert lines[4] == f'declare i32 @"{LOOP}"(i8*, double)'
    assert lines[1:4] + lines[5:] == module.split("\n")[1:4] + module.split("\n")[5:]
    everything = frozenset({"phaseimpact.integrate.driver._loop", "phaseimpact.model.forms.force_of"})
    marked = keep_calls(module, everything).split("\n")
    assert marked[5] == f'define linkonce_odr i32 @"{FORCED}"(double %".1") noinline' and marked[6] == "{"
    assert marked[-4:] == module.split("\n")[-4:]  # the kernel: never noinline (NVVM refuses that)


def test_the_call_policy_names_the_cpu_engines_calls():
    """engine_calls: the functions the CPU compiles as calls (the run loop, the step), not those it
    inlines (forceinline: the DOP853 stages, the law's force); the symbols demangle to those names."""
    import phaseimpact.integrate.driver  # noqa: F401 (the engine's modules, as the kernel imports them)
    from phaseimpact.cuda import _demangled, engine_calls

    calls = engine_calls()
    assert {"phaseimpact.integrate.driver._loop", "phaseimpact.integrate.step.advance",
            "phaseimpact.integrate.driver.run_point"} <= calls
    assert not {"phaseimpact.integrate._dop853_stages.step", "phaseimpact.model.forms.force_of",
                "phaseimpact.integrate.step.phase_step"} & calls
    assert _demangled(LOOP) == "phaseimpact.integrate.driver._loop"
    assert _demangled(KERNEL) == "cudapy.phaseimpact.cuda._kernel._3clocals_3e.points"


@pytest.mark.parametrize("value", ["2", "yes", " 1"])
def test_the_call_policy_switch_refuses_other_values(monkeypatch, value):
    """Before any work: the check, and backend="cuda" (refused for the switch before the GPU is looked at)."""
    from phaseimpact._environment import GPU_CALLS_VARIABLE, gpu_calls_kept

    monkeypatch.setenv(GPU_CALLS_VARIABLE, value)
    message = rf"PHASEIMPACT_GPU_CALLS = '{value}' is out of range; allowed: 0 or 1"
    with pytest.raises(ValueError, match=message):
        gpu_calls_kept()
    with pytest.raises(ValueError, match=message):
        atlas(seed_parameters(), "paper", {"kappa": [1e9, 1e10]}, backend="cuda")
    monkeypatch.setenv(GPU_CALLS_VARIABLE, "0")
    assert gpu_calls_kept() is False


def test_the_call_policy_finds_numbas_nvvm_entry_or_warns(monkeypatch):
    """nvvm_entry: compile_ir (numba >= 0.60, numba-cuda), else llvm_to_ptx (numba 0.59), else None;
    with none, installing the policy warns once and leaves numba as it is."""
    import types

    from numba.cuda.cudadrv import nvvm

    from phaseimpact import cuda as gpu

    assert gpu.nvvm_entry(types.SimpleNamespace(compile_ir=print, llvm_to_ptx=print)) == "compile_ir"
    assert gpu.nvvm_entry(types.SimpleNamespace(llvm_to_ptx=print)) == "llvm_to_ptx"
    assert gpu.nvvm_entry(types.SimpleNamespace(compile_ir=None)) is None
    for name in gpu.NVVM_ENTRIES:
        monkeypatch.delattr(nvvm, name, raising=False)
    monkeypatch.delenv("PHASEIMPACT_GPU_CALLS", raising=False)
    with pytest.warns(RuntimeWarning, match=r"has none of nvvm.compile_ir, nvvm.llvm_to_ptx; the GPU kernel is "
                                            r"compiled numba's own way"):
        gpu._install_call_policy.__wrapped__()
    assert gpu.nvvm_entry(nvvm) is None  # nothing put in their place
