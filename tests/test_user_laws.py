"""A law of one's own from Python (phaseimpact.define_law, --law-file, check-law)."""

import json
import math
import textwrap

import numpy as np
import pytest
from _registry import restored_registry

import phaseimpact
from phaseimpact import ContactLaw, check_law, define_law, seed_parameters, simulate
from phaseimpact._oracle import oracle
from phaseimpact.cli import main
from phaseimpact.continuation import critical_damping
from phaseimpact.model import REGISTRY
from phaseimpact.model.userlaw import UserLawError

LAW_FILE = textwrap.dedent('''\
    """Kuwabara-Kono written by hand, no adhesion."""
    import math

    import phaseimpact


    def force(delta, deltadot, K, gamma, alpha):
        return max((K * delta + gamma * deltadot) * math.sqrt(delta), 0.0)


    def potential(delta, K, alpha):
        return K * delta**2.5 / 2.5


    phaseimpact.define_law("file-kk", force, potential=potential, damping=("gamma", None), damping_power=1.5)
    ''')


class _Settings:
    scale = 1.0


_SETTINGS = _Settings()  # a Python object: numba cannot read it


def kk_force(delta, deltadot, K, gamma, alpha):
    return max((K * delta + gamma * deltadot) * math.sqrt(delta), 0.0)


def kk_partials(delta, deltadot, K, gamma, alpha):
    root = math.sqrt(delta)
    if K * delta + gamma * deltadot <= 0:
        return 0.0, 0.0
    return K * 1.5 * root + gamma * deltadot * 0.5 * root / delta, gamma * root


def kk_potential(delta, K, alpha):
    return K * delta * (delta * math.sqrt(delta)) / 2.5


@pytest.fixture(scope="module", autouse=True)
def _registry_restored():
    with restored_registry():
        yield


@pytest.fixture(scope="module")
def user_kk():
    return define_law("user-kk", kk_force, partials=kk_partials, potential=kk_potential,
                      damping=("gamma", None), damping_power=1.5)


def test_a_user_law_runs_like_the_shipped_one(user_kk):
    assert user_kk.damping_unit(1.5) == "N s/m^1.5"
    for target in ("rigid", "plate"):
        p = seed_parameters(v=1.0, kappa=2e4, target=target)
        mine = simulate(p, "user-kk", 4e-3, rtol=1e-12)
        shipped = simulate(p, ContactLaw("kuwabara-kono", clamp=True), 4e-3, rtol=1e-12)
        assert [e.kind for e in mine.events] == [e.kind for e in shipped.events]
        np.testing.assert_allclose(mine.event_t, shipped.event_t, rtol=1e-12, atol=1e-18)
        assert mine.max_force == pytest.approx(shipped.max_force, rel=1e-12)
        assert mine.dissipated_energy == pytest.approx(shipped.dissipated_energy, rel=1e-9)


def test_a_user_law_passes_the_conformance_suite(user_kk):
    report = check_law("user-kk")
    assert report.passed, str(report)
    assert {v.check for v in report.verdicts} >= {"force", "partials", "energy ledger", "momentum", "scipy"}


def test_wrong_partials_and_potential_fail_with_readable_verdicts():
    define_law("wrong-kk", kk_force, partials=lambda d, dd, K, g, a: (1.4 * K * math.sqrt(d), g * math.sqrt(d)),
               potential=lambda d, K, a: K * d**2.5, damping=("gamma", None), damping_power=1.5)
    report = check_law("wrong-kk", oracle=False)
    verdicts = {v.check: v for v in report.verdicts}
    assert not report.passed
    assert verdicts["partials"].passed is False and "central differences" in verdicts["partials"].detail
    assert verdicts["energy ledger"].passed is False and "potential" in verdicts["energy ledger"].detail
    assert verdicts["momentum"].passed
    assert "FAIL  partials" in str(report)


def test_a_bilateral_user_law_acts_in_tension():
    def linear(delta, deltadot, K, damping, alpha):
        return 1e6 * delta

    define_law("spring", linear, unilateral=False, potential=lambda d, K, a: 0.5e6 * d * d)
    law = ContactLaw("spring")
    assert not law.is_unilateral
    from phaseimpact.model.forms import contact_force

    assert contact_force(law.code, -1e-3, 0.0, 1, 1.0, 0.0, 1.5) == pytest.approx(-1e3)
    p = seed_parameters(v=1.0, target="free")
    tr = simulate(p, "spring", 1e-3, rtol=1e-12)
    assert p.M1 * tr.final_state[2] + p.M2 * tr.final_state[3] == pytest.approx(p.M1 * p.v, rel=1e-10)


@pytest.mark.parametrize("force, message", [
    (lambda d, dd, K, g, a: float("nan"), "must be finite"),
    (lambda d, dd: 0.0, "wrong signature"),
    (lambda d, dd, K, g, a: K * abs(d) ** 1.5 + 1.0, "must vanish at the separation"),
    (lambda d, dd, K, g, a: _SETTINGS.scale * d, "numba cannot compile"),
    ("not a function", "not a function"),
])
def test_a_bad_law_gets_a_clear_error(force, message):
    with pytest.raises(UserLawError, match=message) as info:
        define_law("bad", force)
    assert "Traceback" not in str(info.value) and len(str(info.value)) < 400
    assert "bad" not in REGISTRY


def test_names_and_options_are_checked():
    with pytest.raises(UserLawError, match="shipped"):
        define_law("paper", kk_force)
    with pytest.raises(UserLawError, match="name"):
        define_law("two words", kk_force)
    define_law("plain-kk", kk_force)
    with pytest.raises(ValueError, match="clamp"):
        ContactLaw("plain-kk", clamp=True)


def test_the_law_file_runs_everywhere_from_the_command_line(tmp_path, capsys):
    path = tmp_path / "mylaw.py"
    path.write_text(LAW_FILE)
    assert len(LAW_FILE.splitlines()) <= 15
    law = ["--law-file", str(path), "--law", "file-kk"]
    assert main(["simulate", *law, "--kappa", "1e4", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["law"] == "file-kk" and out["kappa_unit"] == "N s/m^1.5" and out["outcome"]
    assert main(["sweep", *law, "--axis", "kappa=1e3:1e5:3:log", "--out",
                 str(tmp_path / "s.h5"), "--no-progress"]) == 0
    assert main(["atlas", *law, "--axis", "kappa=1e3:1e5:2:log", "--axis", "v=0.5:1:2", "--out",
                 str(tmp_path / "a.h5"), "--no-progress"]) == 0
    assert main(["transitions", *law, "--kappa-min", "1e3", "--kappa-max", "1e7", "--json"]) == 0
    assert main(["plot", str(tmp_path / "s.h5"), "--out", str(tmp_path / "s.png"), "--law-file", str(path)]) == 0
    capsys.readouterr()
    assert main(["check-law", str(path)]) == 0
    assert "check-law file-kk: passed" in capsys.readouterr().out


def test_check_law_fails_a_wrong_file(tmp_path, capsys):
    path = tmp_path / "bad.py"
    path.write_text(LAW_FILE.replace("/ 2.5", "/ 2.0").replace("file-kk", "file-bad"))
    assert main(["check-law", str(path)]) == 1
    out = capsys.readouterr().out
    assert "FAIL  energy ledger" in out and "PASS  partials" in out


def test_a_broken_law_file_is_a_usage_error(tmp_path, capsys):
    path = tmp_path / "broken.py"
    path.write_text("import phaseimpact\nphaseimpact.define_law('x', lambda d: d)\n")
    assert main(["simulate", "--law-file", str(path), "--law", "x"]) == 2
    err = capsys.readouterr().err
    assert "wrong signature" in err and "Traceback" not in err
    assert main(["simulate", "--law-file", str(tmp_path / "none.py")]) == 2


def test_check_law_of_a_shipped_law_passes(capsys):
    assert main(["check-law", "kuwabara-kono"]) == 0
    out = capsys.readouterr().out
    assert "kuwabara-kono: passed" in out and "kuwabara-kono clamp: passed" in out
    assert phaseimpact.check_law("hunt-crossley").passed


def paper_magnitude(delta, deltadot, K, kappa, alpha):
    return (K + kappa * deltadot) * abs(delta) ** alpha


def stiffening_magnitude(delta, deltadot, K, kappa, alpha):
    """eq. 8 with an elastic term that stiffens with depth: its stick bound is not K |delta|^alpha."""
    return (K * (1.0 + abs(delta) / 2e-5) + kappa * deltadot) * abs(delta) ** alpha


@pytest.mark.parametrize("unilateral", [False, True], ids=["printed", "unilateral"])
def test_a_filippov_user_law_runs_like_paper(unilateral):
    define_law("user-paper", paper_magnitude, filippov=True, unilateral=unilateral)
    shipped = ContactLaw("paper", contact="unilateral" if unilateral else "printed")
    for kappa in (3e9, 2e12):  # below kappa_c (a permanent stick) and above (breaks)
        p = seed_parameters(v=1.0, kappa=kappa)
        mine, ref = simulate(p, "user-paper", 2e-3, rtol=1e-12), simulate(p, shipped, 2e-3, rtol=1e-12)
        assert [e.kind for e in mine.events] == [e.kind for e in ref.events]
        np.testing.assert_allclose(mine.event_t, ref.event_t, rtol=1e-9, atol=1e-15)
        assert (mine.n_stick, mine.outcome) == (ref.n_stick, ref.outcome)
    p = seed_parameters(v=1.0)
    assert critical_damping(p, "user-paper").kappa_c == pytest.approx(critical_damping(p, shipped).kappa_c, rel=1e-9)


def test_a_filippov_user_law_sticks_within_its_own_bound():
    """The stick holds while the force that keeps the bodies together is within |P(delta, 0)|, the
    law's own (here not paper's K |delta|^alpha): the engine's kappa_c separates a permanent stick
    from a break in the scipy oracle, which reads the bound from the force function alone."""
    define_law("stiffening", stiffening_magnitude, filippov=True, unilateral=False)
    p = seed_parameters(v=1.0)
    kc = critical_damping(p, "stiffening").kappa_c
    assert abs(kc / critical_damping(p, "paper").kappa_c - 1) > 0.01
    for factor, breaks in ((1 - 1e-4, False), (1 + 1e-4, True)):
        ref = oracle(p.replace(kappa=kc * factor), "stiffening", 2e-3, rtol=1e-12)
        assert ("slip" in ref.kinds) == breaks, ref.kinds
        mine = simulate(p.replace(kappa=kc * factor), "stiffening", 2e-3, rtol=1e-12)
        assert [e.kind for e in mine.events] == ref.kinds
    report = check_law("stiffening")
    assert report.passed, str(report)


def test_a_filippov_law_has_no_potential():
    with pytest.raises(UserLawError, match="potential is not allowed with filippov = True"):
        define_law("bad-filippov", paper_magnitude, filippov=True, potential=lambda d, K, a: 0.0)


def test_a_case_file_names_its_law_file(tmp_path, capsys):
    """``impact.law_file`` (relative to the case file) is run when the case is read: the case alone
    runs the law, and the case as recorded names the file by its absolute path."""
    from phaseimpact.case import load_case

    (tmp_path / "laws").mkdir()
    (tmp_path / "laws" / "mylaw.py").write_text(LAW_FILE.replace("file-kk", "case-kk"))
    case_file = tmp_path / "case.toml"
    case_file.write_text(load_case("seed").to_toml().replace('law = "paper"', 'law = "case-kk"\nlaw_file = '
                                                             '"laws/mylaw.py"').replace("kappa = 0.0", "kappa = 1e4"))
    case = load_case(case_file)
    assert case.impact["law"] == "case-kk"
    assert case.impact["law_file"] == str((tmp_path / "laws" / "mylaw.py").resolve())
    assert main(["simulate", "--case", str(case_file), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["law"] == "case-kk" and out["kappa_unit"] == "N s/m^1.5"
    assert out["case"]["impact"]["law_file"] == case.impact["law_file"]
    missing = tmp_path / "missing.toml"
    missing.write_text(case_file.read_text().replace("laws/mylaw.py", "laws/none.py"))
    with pytest.raises(SystemExit) as stop:  # --case is read while the arguments are parsed
        main(["simulate", "--case", str(missing)])
    assert stop.value.code == 2 and "impact.law_file: law file" in capsys.readouterr().err
