"""integrate/elliptic.py (sn, cn, dn, am, F(phi|m), K(m) in plain arithmetic for numba's CPU and
CUDA targets) against scipy's ``ellipj``, ``ellipkinc`` and ``ellipk`` (Cephes, the independent
oracle), their identities, and the same source as CUDA device functions: compiled to PTX where
NVVM is installed, and run under numba's CUDA simulator."""

from __future__ import annotations

import os
import platform
import shutil
import subprocess
import sys
import textwrap
import types
from pathlib import Path

import numpy as np
import pytest
import scipy.special

from phaseimpact import _jit
from phaseimpact.integrate import elliptic

ROOT = Path(__file__).resolve().parents[1]
EPS = np.finfo(float).eps
RNG = np.random.default_rng(20261127)

#: Parameters: both ends, the series' branch points (1e-9, 1 - 1e-10), flight.py's range [0, 1/2].
M_JACOBI = np.array([0.0, 1e-15, 1e-12, 0.999e-9, 1e-9, 1.001e-9, 1e-6, 0.01, 0.1, 0.25, 0.3, 0.4, 0.5, 0.6,
                     0.9, 0.99, 0.999, 1 - 1e-6, 1 - 1e-9, 1 - 1e-10, 0.9999999999, 1 - 1e-12, 1.0])
#: Arguments: a dense band around 0 (both signs), many periods, up to 1e6.
U = np.concatenate([np.linspace(-25.0, 25.0, 2001), RNG.uniform(-1e3, 1e3, 300), RNG.uniform(-1e6, 1e6, 100),
                    [0.0, -0.0, 1e-300, 1.5, -1.5]])


def ours_jacobi(u, m):
    out = np.empty((len(u), 4))
    for i, (u_, m_) in enumerate(zip(u, m, strict=True)):
        elliptic.jacobi(u_, m_, out[i])
    return out


def grid_jacobi():
    u, m = np.meshgrid(U, M_JACOBI)
    return u.ravel(), m.ravel()


def test_jacobi_matches_scipy_on_a_dense_grid():
    """Every |u| up to 1e6 and m in [0, 1]: sn, cn, phi within 4 ulp of their size times |u| (the
    amplitude is 2^N a u before its halvings); dn within scipy's own error (its quotient
    cn / cos(phi_1 - phi_0): ~3e-14 at |u| <= 25, growing with |u|; see the Fourier test)."""
    u, m = grid_jacobi()
    ours = ours_jacobi(u, m)
    expected = np.column_stack(scipy.special.ellipj(u, m))
    finite = np.isfinite(expected).all(axis=1)
    # the m -> 1 series (m >= 1 - 1e-10) overflows cosh beyond |u| ~ 710: NaN in both
    assert np.array_equal(np.isfinite(ours).all(axis=1), finite)
    assert finite.mean() > 0.9
    scale = np.maximum(1.0, np.abs(u))[:, None] * np.maximum(1.0, np.abs(expected))
    with np.errstate(invalid="ignore"):  # NaN - NaN where both overflow
        error = np.where(finite[:, None], np.abs(ours - expected) / scale, 0.0)
    assert error[:, [0, 1, 3]].max() <= 4 * EPS
    assert error[:, 2].max() <= 2e-15
    assert error[np.abs(u) <= 25.0, 2].max() <= 400 * EPS


@pytest.mark.skipif(not (sys.platform == "linux" and platform.machine() == "x86_64"),
                    reason="bit-identity needs the libm scipy's wheel calls (measured on Linux x86_64)")
def test_sn_cn_phi_are_bit_identical_to_scipy():
    """The same algorithm and order of operations as scipy's Cephes ``ellpj`` (and the same libm):
    sn, cn and phi bit-identical, NaNs in the same places; dn too where both take the quotient."""
    u, m = grid_jacobi()
    ours = ours_jacobi(u, m)
    expected = np.column_stack(scipy.special.ellipj(u, m))
    np.testing.assert_array_equal(ours[:, [0, 1, 3]], expected[:, [0, 1, 3]])
    quotient = ours[:, 2] ** 2 < 0.25 - 1e-12
    np.testing.assert_array_equal(ours[quotient, 2], expected[quotient, 2])
    assert quotient.sum() > 1000


def fourier_sn_dn(u, m, terms=40):
    """sn and dn by their nome series (DLMF 22.11.1, 22.11.3) with scipy's K and K': a third
    method, accurate to a few ulp within one period (the cosines' arguments stay below 2 pi n)."""
    K, K1 = scipy.special.ellipk(m), scipy.special.ellipk(1.0 - m)
    q = np.exp(-np.pi * K1 / K)
    n = np.arange(1, terms + 1)[:, None]
    dn = np.pi / (2 * K) + 2 * np.pi / K * np.sum(q**n / (1 + q ** (2 * n)) * np.cos(n * np.pi * u / K), axis=0)
    k = n - 1
    sn = (2 * np.pi / (np.sqrt(m) * K)
          * np.sum(q ** (k + 0.5) / (1 - q ** (2 * k + 1)) * np.sin((2 * k + 1) * np.pi * u / (2 * K)), axis=0))
    return sn, dn


@pytest.mark.parametrize("m", [1e-6, 0.01, 0.1, 0.3, 0.5, 0.75])
def test_sn_dn_against_their_fourier_series(m):
    """Within one period (|u| <= 2K) dn within 4 ulp of its nome series (measured: <= 1.5 ulp for
    m <= 1/2, 3.5 at 3/4; scipy's quotient: 7 to 9.5 ulp); sn within 16 ulp (the series' own
    rounding, 5 to 9 ulp; its 1/sqrt(m) q^(1/2) cancels for small m, so not there)."""
    K = scipy.special.ellipk(m)
    u = np.linspace(-2 * K, 2 * K, 4001)
    sn, _, dn, _ = ours_jacobi(u, np.full_like(u, m)).T
    sn_series, dn_series = fourier_sn_dn(u, m)
    if m >= 0.01:
        assert np.max(np.abs(sn - sn_series)) <= 16 * EPS
    assert np.max(np.abs(dn - dn_series)) <= 4 * EPS


def test_jacobi_identities():
    """sn^2 + cn^2 = 1 and dn^2 + m sn^2 = 1 to rounding where |u| <= 25 (dn = cn / cos(phi_1 -
    phi_0) loses digits with |u|, as scipy's does), and F(am(u) | m) = u. Not for m >= 1 - 1e-10,
    whose series (Cephes', scipy's) holds only within a quarter period."""
    u, m = grid_jacobi()
    keep = (np.abs(u) <= 25.0) & (m < 0.9999999999)
    u, m = u[keep], m[keep]
    sn, cn, dn, phi = ours_jacobi(u, m).T
    assert np.max(np.abs(sn * sn + cn * cn - 1.0)) <= 2 * EPS
    dn_residual = np.abs(dn * dn + m * sn * sn - 1.0)
    assert dn_residual.max() <= 64 * EPS  # m = 0.9, where dn < 1/2 comes from cn / cos(...): 29 ulp
    assert dn_residual[m <= 0.75].max() <= 2 * EPS
    back = np.array([elliptic.first_kind(p, m_) for p, m_ in zip(phi, m, strict=True)])
    # F is ill-conditioned near odd multiples of pi/2 as m -> 1 (dF/dphi = 1/dn), and there the
    # amplitude's own error (Cephes' backward recurrence, asin near +-1) grows: 21 of these units
    # at m = 1 - 1e-9, below 3 up to m = 0.999
    bound = EPS * (np.maximum(np.abs(u), 1.0) + np.abs(phi) / np.abs(dn)) * np.where(m <= 0.999, 4.0, 32.0)
    assert np.all(np.abs(back - u) <= bound)
    flight_range = m <= 0.5
    assert np.max(np.abs(back - u)[flight_range] / np.maximum(np.abs(u), 1.0)[flight_range]) <= 4 * EPS


def test_first_kind_matches_scipy_within_4_ulp():
    """F(phi | m) for phi in [-pi, pi] (flight.py's, from atan2) and beyond (up to 60), m from -5
    through 0 and 1/2 to 1 - 1e-12: within 4 ulp of scipy's (both are within ~2 of the truth)."""
    phi = np.concatenate([np.linspace(-np.pi, np.pi, 2001), RNG.uniform(-60.0, 60.0, 400),
                          [np.pi / 2, -np.pi / 2, np.pi, -np.pi, 0.0, 1e-300]])
    for m in (-5.0, -0.5, 0.0, 1e-15, 1e-9, 0.1, 0.3, 0.5, 0.9, 0.999, 1 - 1e-9, 1 - 1e-12):
        ours = np.array([elliptic.first_kind(p, m) for p in phi])
        expected = scipy.special.ellipkinc(phi, m)
        np.testing.assert_allclose(ours, expected, rtol=4 * EPS, atol=0, err_msg=f"m = {m}")


def test_complete_matches_scipy_within_4_ulp():
    m = np.concatenate([-np.logspace(-15, 3, 200), [0.0], np.linspace(0, 1, 1001)[1:-1], 1 - np.logspace(-15, -1, 200)])
    ours = np.array([elliptic.complete(m_) for m_ in m])
    np.testing.assert_allclose(ours, scipy.special.ellipk(m), rtol=4 * EPS, atol=0)


def test_outside_the_domain_as_scipy():
    """jacobi: NaN for m outside [0, 1] or NaN; first_kind: NaN above m = 1, asinh(tan phi) at m = 1
    and infinite from |phi| = pi/2, 2 K phi / pi for |phi| beyond 2^52 (infinite phi included), 0 at
    m = -inf; complete: infinite at 1, NaN above."""
    out = np.empty(4)
    for m in (-0.5, 1.5, np.nan):
        elliptic.jacobi(0.7, m, out)
        assert np.isnan(out).all() and np.isnan(scipy.special.ellipj(0.7, m)).all()
    for phi, m in [(0.3, 1.0), (-1.2, 1.0), (np.pi / 2, 1.0), (-2.0, 1.0), (0.3, 1.5), (np.nan, 0.3), (0.3, np.nan),
                   (np.inf, 0.3), (-np.inf, 0.3), (1e20, 0.5), (-1e300, -1.0), (2.0**52, 0.3), (1.0, -np.inf)]:
        np.testing.assert_allclose(elliptic.first_kind(phi, m), scipy.special.ellipkinc(phi, m), rtol=4 * EPS)
    for m in (1.0, 1.5, np.nan):
        np.testing.assert_equal(elliptic.complete(m), scipy.special.ellipk(m))


def test_a_new_engine_file_is_in_the_cache_digest(tmp_path):
    """elliptic.py is compiled into the engine: an edit of it must give a new cache directory."""
    package = tmp_path / "phaseimpact"
    shutil.copytree(ROOT / "phaseimpact", package, ignore=shutil.ignore_patterns("__pycache__"))
    before = _jit.engine_digest(package)
    source = package / "integrate" / "elliptic.py"
    source.write_text(source.read_text() + "\n# an edit\n")
    assert _jit.engine_digest(package) != before


def _nvvm_available() -> bool:
    try:
        from numba.cuda.cudadrv import nvvm

        return nvvm.is_available()
    except Exception:  # no numba.cuda, or no CUDA toolkit
        return False


@pytest.mark.skipif(not _nvvm_available(), reason="no NVVM (CUDA toolkit) to compile PTX with")
def test_the_same_source_compiles_as_cuda_device_functions(monkeypatch):
    """Each function's Python source compiled by numba's CUDA target for an H100 (sm_90), without
    a GPU: the subset is the device's (no call into C or Python, nothing allocated)."""
    import numba.cuda.dispatcher
    from numba import cuda, float64, void

    # the compiled helpers they call become device functions, and numba asks the current device for
    # its compute capability there; there is none: the H100's (9.0) instead (as test_cuda's PTX test)
    monkeypatch.setattr(numba.cuda.dispatcher, "get_current_device",
                        lambda: types.SimpleNamespace(compute_capability=(9, 0)))

    signatures = {"jacobi": void(float64, float64, float64[:]), "first_kind": float64(float64, float64),
                  "complete": float64(float64)}
    for name, signature in signatures.items():
        function = getattr(elliptic, name)
        ptx, _ = cuda.compile_ptx(getattr(function, "py_func", function), signature, device=True, cc=(9, 0))
        assert f"{name}" in ptx and ".visible .func" in ptx


SIMULATED = textwrap.dedent("""
    import sys

    import numba
    import numpy as np
    from numba import cuda

    from phaseimpact.integrate import elliptic

    assert numba.config.ENABLE_CUDASIM and numba.config.DISABLE_JIT
    jacobi, first_kind, complete = (cuda.jit(device=True)(getattr(f, "py_func", f))
                                    for f in (elliptic.jacobi, elliptic.first_kind, elliptic.complete))

    @cuda.jit
    def evaluate(u, m, phi, out):
        i = cuda.grid(1)
        if i < u.size:
            jacobi(u[i], m[i], out[i])
            out[i, 4] = first_kind(phi[i], m[i])
            out[i, 5] = complete(m[i])

    data = np.load(sys.argv[1])
    u, m, phi = data["u"], data["m"], data["phi"]
    out = np.zeros((u.size, 6))
    evaluate[(u.size + 31) // 32, 32](u, m, phi, out)
    np.save(sys.argv[2], out)
""")


def test_the_same_functions_as_cuda_device_functions_in_the_simulator(tmp_path):
    """A cuda.jit kernel calling the three as device functions, one thread per point, under numba's
    CUDA simulator (chosen at import: its own process): the CPU's results, bit for bit. The
    simulator runs device functions as Python, so the helpers they call must be Python too
    (``NUMBA_DISABLE_JIT=1``, as for :mod:`phaseimpact.cuda`'s kernel)."""
    u = np.concatenate([np.linspace(-30.0, 30.0, 61), [1e4, -1e4]])
    m = np.resize(np.array([0.0, 1e-12, 0.1, 0.3, 0.5, 0.9, 1 - 1e-12]), u.size)  # u = -1e4 at 1 - 1e-12: NaN
    phi = np.resize(np.linspace(-np.pi, np.pi, 17), u.size) * np.resize([1.0, 1.0, 7.0], u.size)
    np.savez(tmp_path / "in.npz", u=u, m=m, phi=phi)
    environment = {**os.environ, "NUMBA_ENABLE_CUDASIM": "1", "NUMBA_DISABLE_JIT": "1", "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, "-c", SIMULATED, str(tmp_path / "in.npz"), str(tmp_path / "out.npy")],
                          env=environment, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    simulated = np.load(tmp_path / "out.npy")
    cpu = np.column_stack([ours_jacobi(u, m), [elliptic.first_kind(p, m_) for p, m_ in zip(phi, m, strict=True)],
                           [elliptic.complete(m_) for m_ in m]])
    assert np.isfinite(cpu).all(axis=1).sum() == u.size - 1
    np.testing.assert_array_equal(simulated, cpu)
