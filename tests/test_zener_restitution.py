"""studies/zener_restitution.py: the infinite-plate target reproduces Zener's restitution curve.

The study's curve integrates Zener's dimensionless equation with scipy; here it is checked first against
what is known without it (the rigid-wall Hertz contact time, and the dimensional ball-on-dashpot
problem integrated in tests/test_infinite_plate.py), then the engine against it.
"""

import importlib.util
import math
from pathlib import Path

import pytest
from test_infinite_plate import hertz_on_dashpot

from phaseimpact import seed_parameters

STUDIES = Path(__file__).resolve().parents[1] / "studies"


@pytest.fixture(scope="module")
def study():
    import sys

    sys.path.insert(0, str(STUDIES))  # the study imports its siblings (_plots)
    try:
        spec = importlib.util.spec_from_file_location("study_zener_restitution", STUDIES / "zener_restitution.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(STUDIES))
    return module


def test_zeners_equation_has_the_rigid_wall_limit(study):
    """``lambda -> 0``: e -> 1 and the Hertz contact time ``2 sqrt(pi) Gamma(7/5)/Gamma(9/10) (5/4)^(2/5)``
    delta*/v (3.2181 delta*/v)."""
    e, contact = study.zener_restitution(1e-9)
    assert e == pytest.approx(1.0, abs=1e-8)
    assert contact == pytest.approx(2 * math.sqrt(math.pi) * math.gamma(1.4) / math.gamma(0.9) * 1.25**0.4, rel=1e-8)
    assert contact == pytest.approx(3.2181, abs=1e-4)


@pytest.mark.parametrize("R1, v", [(0.02, 1.0), (0.002, 13.0)])
def test_zeners_equation_is_the_dimensional_ball_on_a_dashpot(study, R1, v):
    """The dimensionless equation and its lambda against ``M1 x1'' = -K delta^(3/2)``, ``c x2' = K delta^(3/2)``
    integrated in SI units (another formulation, another integration)."""
    p = seed_parameters(v=v, R1=R1, target="infinite")
    lam = p.M1**0.6 * v**0.2 * p.K**0.4 / p.impedance
    e_dimensional = hertz_on_dashpot(p.M1, p.K, p.impedance, v)[0]
    assert study.zener_restitution(lam)[0] == pytest.approx(e_dimensional, abs=1e-9)


@pytest.mark.parametrize("R1, v, lam", [(0.02, 1.0, 0.01), (0.02, 1.0, 0.5), (0.002, 13.0, 1.2), (0.002, 13.0, 3.0)])
def test_the_engine_reproduces_zeners_curve(study, R1, v, lam):
    """Engine at rtol 1e-10 (default), curve at 1e-12: e to 1e-8 absolute and the contact time to 1e-8
    relative leave a hundredfold margin over the engine's tolerance (the study measures 6e-11 at most)."""
    lam_run, e, contact = study.engine_point(R1, v, lam)
    assert lam_run == pytest.approx(lam, rel=1e-12)  # lambda is proportional to h^-2: the plate sets it exactly
    e_zener, contact_zener = study.zener_restitution(lam_run)
    assert e == pytest.approx(e_zener, abs=1e-8)
    assert contact == pytest.approx(contact_zener, rel=1e-8)
    assert 0.0 < e < 1.0


def test_the_committed_curve_stays_positive():
    """What docs/physics.md §8 and docs/findings.md say of figures/data/zener_restitution.h5: e > 0 at every
    point of the curve and of both engine series, and e falls along each series as lambda grows."""
    import h5py
    import numpy as np

    with h5py.File(STUDIES.parent / "figures" / "data" / "zener_restitution.h5", "r") as f:
        assert bool(f.attrs["curve_positive"]) is True
        assert (f["curve/restitution"][()] > 0).all() and f["curve/lambda"][-1] == f.attrs["curve_lambda_max"]
        for key in ("R1_20mm", "R1_2mm"):
            order = np.argsort(f[f"{key}/lambda"][()])
            e = f[f"{key}/restitution"][()][order]
            assert (e > 0).all() and (np.diff(e) < 0).all()
