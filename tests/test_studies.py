"""The study scripts: one per figure or table, each stating its claim and reachable from run_all.

Imports only (running the studies is ``make reproduce``'s job): every script is listed in
``studies/run_all.py``, has a docstring that states its claim, a ``main(quick, jobs)`` and an output
folder global that ``--quick`` can redirect to ``figures/preview/``.
"""

import ast
import importlib.util
from pathlib import Path

import numpy as np
import pytest

STUDIES = Path(__file__).resolve().parents[1] / "studies"
SCRIPTS = sorted(p for p in STUDIES.glob("*.py") if not p.name.startswith("_") and p.name != "run_all.py")


def listed() -> tuple:
    tree = ast.parse((STUDIES / "run_all.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "STUDIES" for t in node.targets):
            return tuple(ast.literal_eval(node.value))
    raise AssertionError("run_all.py defines no STUDIES")


def test_every_study_is_run_by_run_all():
    assert sorted(listed()) == sorted(p.stem for p in SCRIPTS)


@pytest.mark.parametrize("path", SCRIPTS, ids=lambda p: p.stem)
def test_study_states_its_claim_and_can_be_redirected(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    doc = ast.get_docstring(tree)
    assert doc and "claim" in doc.lower(), f"{path.name}: the docstring must state the claim it supports"
    names = {t.id for node in tree.body if isinstance(node, ast.Assign) for t in node.targets
             if isinstance(t, ast.Name)}
    assert names & {"FIGURES", "ROOT"}, f"{path.name}: no FIGURES/ROOT global for --quick to redirect"
    mains = [node for node in tree.body if isinstance(node, ast.FunctionDef) and node.name == "main"]
    assert mains, f"{path.name}: no main()"
    args = [a.arg for a in mains[0].args.args]
    assert args[:2] == ["quick", "jobs"], f"{path.name}: main(quick, jobs) expected, got {args}"


def test_no_pitchfork_and_no_general_runaway_claim():
    """The transition of eq. 8 is an adding-sliding (docs/physics.md §5), not a pitchfork."""
    for path in [*SCRIPTS, STUDIES / "_plots.py"]:
        text = path.read_text(encoding="utf-8").lower()
        assert "pitchfork" not in text, path.name
        assert "runaway above kappa_c" not in text and "runaway above κc" not in text, path.name


def _study_helpers():
    spec = importlib.util.spec_from_file_location("studies_plots", STUDIES / "_plots.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_fitted_values_are_kept_to_the_digits_they_are_known():
    plots = _study_helpers()
    assert plots.known(1.4836952594860489) == 1.483695259 and plots.known(-0.0) == 0.0
    assert plots.known(plots.known(2 / 3)) == plots.known(2 / 3) and np.isnan(plots.known(np.nan))
    x = np.geomspace(1e-6, 1e-3, 9)
    slope, intercept = plots.loglog_fit(x, 3.0 * x ** -1.75)
    assert abs(slope + 1.75) < 1e-9 and abs(intercept - np.log(3.0)) < 1e-8
    assert slope == plots.known(slope) and intercept == plots.known(intercept)


def test_staircase_fits_regenerate_from_the_archived_data_and_ignore_last_bit_differences():
    """make reproduce on another machine of the kind changed three fitted exponents of staircase.h5 in
    their 16th digit (the data were identical): the fits are stored to the digits they are known, so
    they follow from the archived data whatever the last bits of the inputs."""
    h5py = pytest.importorskip("h5py")
    plots = _study_helpers()
    with h5py.File(STUDIES.parent / "figures" / "data" / "staircase.h5", "r") as f:
        attrs = dict(f.attrs)
        eps, t_run = f["eps"][()], f["t_run"][()]
        usable = ~f["cut"][()].astype(bool) & ~f["engine_missed_restick"][()].astype(bool) & np.isfinite(t_run)
        local = {name: (f["exponents/eps"][()], f[f"exponents/{name}"][()])
                 for name in ("slip_speed", "stick_offset", "slip_duration")}
    fit = usable & (eps <= attrs["t_run_fit_max_eps"])

    def fits(nudge):
        out = {"t_run_exponent": plots.loglog_fit(nudge(eps[fit]), nudge(t_run[fit]))[0],
               "t_run_exponent_below_2e-5": plots.loglog_fit(nudge(eps[fit & (eps <= 2e-5)]),
                                                             nudge(t_run[fit & (eps <= 2e-5)]))[0]}
        for name, (x, y) in local.items():  # the local slopes: the three smallest offsets
            out[f"{name}_exponent"] = plots.loglog_fit(nudge(x[:3]), nudge(y[:3]))[0]
        return out

    regenerated = fits(lambda a: a)
    last_bit = fits(lambda a: np.nextafter(a, np.inf))  # every input one ulp up: what another CPU may give
    for name, value in regenerated.items():
        assert value == plots.known(attrs[name]), name  # the fit of the archived data
        assert last_bit[name] == value, name
        assert attrs[name] == plots.known(attrs[name]), f"{name} = {attrs[name]!r}: stored beyond its digits"


def _load_study(name, monkeypatch):
    monkeypatch.syspath_prepend(str(STUDIES))
    spec = importlib.util.spec_from_file_location(f"study_{name}", STUDIES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
def test_impact_regime_map_agrees_with_the_mass_criterion_and_zeners_closed_form(tmp_path, monkeypatch):
    """A quick run of studies/impact_regime.py, checked against numbers computed here from the case inputs:
    Olsson's ratio M1 / (pi a^2 rho h) with his bounds 0.23 and 2, and, for the isotropic gelcoat panel, Zener's
    closed form of lambda (docs/physics.md §8) with R = R1 R2 / (R1 + R2) in place of R1."""
    import json

    import h5py

    from phaseimpact.case import load_case
    from phaseimpact.plotting import for_print

    study = _load_study("impact_regime", monkeypatch)
    monkeypatch.setattr(study, "FIGURES", tmp_path)
    with for_print():  # as studies/_cli.py runs it: PNG and PDF
        out = Path(study.main(quick=True, jobs=1))
    assert out.is_file() and out.with_suffix(".pdf").is_file()
    quartz, ice = load_case("sand-gelcoat").projectile, load_case("hail-laminate").projectile
    with h5py.File(tmp_path / "data" / "impact_regime.h5") as f:
        R1, v = f["R1"][()], f["v"][()]
        for key, case in (("gelcoat", "sand-gelcoat"), ("LEP", "sand-lep"), ("laminate", "sand-laminate")):
            c = load_case(case)
            plies = getattr(c.plate, "plies", None)
            rho_h = sum(p.rho * p.thickness for p in plies) if plies else c.plate.rho * 0.005
            rho1 = np.where(R1 >= 2.5e-3, ice.rho, quartz.rho)
            ratio = rho1 * 4 / 3 * np.pi * R1**3 / (np.pi * 0.05**2 * rho_h)
            assert np.allclose(f[f"{key}/mass_ratio"][()], ratio, rtol=1e-12)
            expected = np.where(ratio < 0.23, "wave-controlled", np.where(ratio <= 2, "boundary-controlled",
                                                                           "quasi-static"))
            assert [s.decode() for s in f[f"{key}/regime"][()]] == expected.tolist()
            assert {s.decode() for s in f[f"{key}/regime"][()]} == {"wave-controlled", "boundary-controlled",
                                                                     "quasi-static"}
            models = [s.decode() for s in f[f"{key}/model"][()]]
            assert models == ["infinite" if r == "wave-controlled" else "plate" for r in expected]
        # Zener's closed form on the isotropic gelcoat panel, each projectile material
        g = load_case("sand-gelcoat").plate
        c0 = np.sqrt(g.E / (g.rho * (1 - g.nu**2)))
        for material, part in ((quartz, R1 < 2.5e-3), (ice, R1 >= 2.5e-3)):
            R = R1[part] * 1.0 / (R1[part] + 1.0)
            closed = (np.pi**0.6 / np.sqrt(3) * (R1[part] / 0.005) ** 2 * (v[:, None] / c0) ** 0.2
                      * (material.rho / g.rho) ** 0.6 * (R / R1[part]) ** 0.2
                      * (1 + g.E * (1 - material.nu**2) / (material.E * (1 - g.nu**2))) ** -0.4)
            assert np.allclose(f["gelcoat/zener_lambda"][()][:, part], closed, rtol=1e-10)
        cases = {c["name"]: c for c in json.loads(f.attrs["cases"])}
    assert set(cases) == {"dust-gelcoat", "sand-gelcoat", "sand-lep", "sand-laminate", "hail-laminate"}
    assert all(c["regime"] == "wave-controlled" and c["model"] == "infinite" and c["warns"] for c in cases.values())
