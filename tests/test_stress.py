"""Regression tests from the stress matrix (benchmarks/stress.py): each failure it found is a test."""

import numpy as np
import pytest

from phaseimpact import seed_parameters, simulate
from phaseimpact.integrate._exact import choose_method
from phaseimpact.model import ContactLaw
from phaseimpact.quantities import impact_quantities


def test_stiff_hunt_crossley_damping_finishes():
    """Found: Hunt-Crossley at kappa = 1e15, v = 300 m/s hit 200,000 DOP853 steps (217 s) without
    finishing. The damping rate there exceeds the contact frequency by orders of magnitude; the
    automatic method choice takes LSODA and finishes within a small step budget."""
    p = seed_parameters(v=300.0, kappa=1e15)
    assert choose_method(p, ContactLaw("hunt-crossley")) == "LSODA"
    tr = simulate(p, "hunt-crossley", 0.01, max_steps=50_000)
    assert tr.status == "success", tr.message
    q = impact_quantities(tr)
    assert np.all(np.isfinite(tr.final_state)) and np.isfinite(q.max_force)
    assert 0 <= q.dissipated_energy <= 0.5 * p.M1 * p.v**2 * (1 + 1e-6)  # passive: no energy created


def test_stiff_damping_lsoda_agrees_with_dop853():
    """The cheaper stiff method gives the same maximum force as DOP853 (to the tolerance)."""
    p = seed_parameters(v=1.0, kappa=1e15)
    stiff = simulate(p, "hunt-crossley", 0.01, rtol=1e-8)
    explicit = simulate(p, "hunt-crossley", 0.01, rtol=1e-8, method="DOP853")
    assert stiff.integrator.startswith("exact[LSODA") and explicit.integrator.startswith("exact[DOP853")
    assert stiff.max_force == pytest.approx(explicit.max_force, rel=1e-6)


@pytest.mark.parametrize("kappa, v", [(1e15, 0.001), (1e12, 300.0)])
def test_paper_runaway_corners_end_with_a_status(kappa, v):
    """Found in the matrix: eq. 8's negative-damping branch at extreme kappa and v; it must end as a
    classified runaway with finite numbers, never NaN."""
    tr = simulate(seed_parameters(v=v, kappa=kappa), "paper", 0.01, max_steps=200_000)
    assert tr.status == "runaway"
    assert np.all(np.isfinite(tr.final_state)) and np.isfinite(tr.max_force)
