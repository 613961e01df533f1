"""check-law's verdicts can fail: Python bools by construction, a failing law for each check, a
budget for every run (a grinding law gets a line, not a wait), law files that exit or are not
files, and the oracle in the package (an installed wheel runs it)."""

import ast
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from _registry import restored_registry

import phaseimpact
from phaseimpact import checks
from phaseimpact._oracle import BudgetExceeded, oracle
from phaseimpact.checks import LawReport, Verdict, check_law
from phaseimpact.cli import main
from phaseimpact.parameters import seed_parameters

ROOT = Path(__file__).resolve().parents[1]

HEAD = "import math\nimport phaseimpact\n\n\n"
#: The audit's laws (../shared/audits/inputs-2026-11b.md), written from their descriptions, and the
#: checks each must fail (together: every check). define_law samples delta up to 2e-5; "deep" is
#: beyond, where check-law looks.
LAWS = {
    "nan-deep": ("def force(delta, deltadot, K, kappa, alpha):\n"
                 "    return math.nan if delta > 3e-5 else K * delta**alpha\n",
                 ("force", "repulsive", "partials", "energy ledger", "momentum", "scipy", "oracle")),
    "inf-deep": ("def force(delta, deltadot, K, kappa, alpha):\n"
                 "    return math.inf if delta > 3e-5 else K * delta**alpha\n", ("force", "partials", "momentum")),
    "huge": ("def force(delta, deltadot, K, kappa, alpha):\n"
             "    return 1e300 * delta if delta > 0 else 0.0\n", ("energy ledger", "momentum", "scipy", "oracle")),
    "intret": ("def force(delta, deltadot, K, kappa, alpha):\n"
               "    return float(int(K * delta**alpha)) if delta > 0 else 0.0\n",
               ("energy ledger", "momentum", "scipy", "oracle")),
    "negative": ("def force(delta, deltadot, K, kappa, alpha):\n"
                 "    return -K * delta**alpha if delta > 0 else 0.0\n", ("repulsive", "scipy", "oracle")),
    # eq. 8's sign factor on the elastic term, not declared Filippov: the bodies stick at deltadot = 0
    "sticky": ("def force(delta, deltadot, K, kappa, alpha):\n"
               "    s = 1.0 if deltadot >= 0 else -1.0\n"
               "    return (K * s + kappa * deltadot) * delta**alpha if delta > 0 else 0.0\n",
               ("force", "energy ledger", "momentum", "scipy", "oracle")),
    "wrong-partials": ("def force(delta, deltadot, K, kappa, alpha):\n"
                       "    return (K + kappa * deltadot) * delta**alpha if delta > 0 else 0.0\n"
                       "def partials(delta, deltadot, K, kappa, alpha):\n"
                       "    return 1.4 * K * delta**0.5, kappa * delta**alpha\n", ("partials",)),
    "wrong-potential": ("def force(delta, deltadot, K, kappa, alpha):\n"
                        "    return (K + kappa * deltadot) * delta**alpha if delta > 0 else 0.0\n"
                        "def potential(delta, K, alpha):\n"
                        "    return K * delta**(alpha + 1)\n", ("energy ledger",)),
}


def _law_file(tmp_path, name):
    source = LAWS[name][0]
    options = ", ".join(f"{o}={o}" for o in ("partials", "potential") if f"def {o}(" in source)
    path = tmp_path / f"{name}.py"
    path.write_text(HEAD + source + f"\n\nphaseimpact.define_law({name!r}, force{', ' + options if options else ''})\n")
    return path


@pytest.fixture(autouse=True)
def _registry_restored():
    with restored_registry():
        yield


def _check_law_cli(capsys, *args):
    code = main(["check-law", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


def test_a_verdict_is_a_python_bool_or_none():
    assert Verdict("scipy", None, "skipped").passed is None
    for wrong in (np.False_, np.True_, 0, 1, "no"):
        with pytest.raises(TypeError, match="bool or None"):
            Verdict("oracle", wrong, "what the old oracle check returned")
    report = LawReport("x", [Verdict("force", True, ""), Verdict("scipy", None, ""), Verdict("oracle", False, "")])
    assert report.passed is False
    assert LawReport("x", [Verdict("force", True, ""), Verdict("scipy", None, "")]).passed is True


def test_the_failing_laws_cover_every_check():
    names = {v.check for v in check_law("hunt-crossley").verdicts}
    assert names == {"force", "repulsive", "partials", "energy ledger", "momentum", "scipy", "oracle"}
    assert set().union(*(failing for _, failing in LAWS.values())) == names


@pytest.mark.slow
@pytest.mark.parametrize("name", list(LAWS))
def test_a_law_failing_a_check_makes_check_law_fail(tmp_path, capsys, name):
    """Each audit law and each wrong law fails its checks, with exit 1 and passed = false (the
    negative law printed FAIL oracle and exited 0); every line a verdict, no warning or traceback."""
    code, out, err = _check_law_cli(capsys, _law_file(tmp_path, name), "--json")
    assert code == 1, out + err
    report = json.loads(out)
    assert report["passed"] is False and report["laws"][0]["passed"] is False
    verdicts = {c["check"]: c for c in report["laws"][0]["checks"]}
    for check in LAWS[name][1]:
        assert verdicts[check]["passed"] is False, verdicts[check]
    assert "Traceback" not in err and "Warning" not in err


@pytest.mark.slow
def test_an_attractive_law_fails_repulsive_in_one_line(tmp_path, capsys):
    code, out, _ = _check_law_cli(capsys, _law_file(tmp_path, "negative"))
    assert code == 1
    assert out.splitlines()[0] == "check-law negative: FAILED"
    line = next(line for line in out.splitlines() if "repulsive" in line)
    assert line.lstrip().startswith("FAIL") and "push the bodies apart" in line


@pytest.mark.slow
def test_a_law_that_sticks_undeclared_is_told_to_declare_it_filippov(tmp_path, capsys):
    code, out, _ = _check_law_cli(capsys, _law_file(tmp_path, "sticky"))
    assert code == 1
    line = next(line for line in out.splitlines() if " force " in line)
    assert "FAIL" in line and "sticks" in line and "filippov=True" in line


def test_the_oracle_run_has_a_budget():
    p = seed_parameters(v=1.0, kappa=3e9)
    full = oracle(p, "hunt-crossley", 4e-3, rtol=1e-12)
    with pytest.raises(BudgetExceeded, match="100 right-hand side calls"):
        oracle(p, "hunt-crossley", 4e-3, rtol=1e-12, max_nfev=100)
    with pytest.raises(BudgetExceeded, match="no result within 0 s"):
        oracle(p, "hunt-crossley", 4e-3, rtol=1e-12, seconds=0.0)
    assert full.nfev > 100


@pytest.mark.slow
def test_the_oracle_ends_a_run_that_scipy_cannot_integrate():
    """A force that is NaN beyond 3e-5 m: scipy's step fails there, and the oracle stops with the
    reason "failed" (before, it restarted the failed phase up to 100 000 times)."""
    import math

    phaseimpact.define_law("nan-deep-oracle", lambda d, dd, K, k, a: math.nan if d > 3e-5 else K * d**a)
    run = oracle(seed_parameters(v=1.0, kappa=3e9), "nan-deep-oracle", 4e-3, rtol=1e-12, max_nfev=100_000)
    assert run.reason == "failed"
    assert run.t_stop < 4e-3


def test_every_run_of_the_checks_has_a_budget(monkeypatch):
    """Runs past their budget are failed verdicts that say so (before, the scipy runs had none:
    a grinding law ran 480 s without a verdict)."""
    monkeypatch.setattr(checks, "SCIPY_MAX_NFEV", 50)
    report = check_law("hunt-crossley")
    verdicts = {v.check: v for v in report.verdicts}
    assert not report.passed
    for name in ("scipy", "oracle"):
        assert verdicts[name].passed is False and "50 right-hand side calls" in verdicts[name].detail
    assert verdicts["momentum"].passed is True
    monkeypatch.undo()
    monkeypatch.setattr(checks, "MAX_STEPS", 20)
    verdicts = {v.check: v for v in check_law("hunt-crossley").verdicts}
    for name in ("energy ledger", "momentum", "scipy", "oracle"):
        assert verdicts[name].passed is False and "more than 20 steps" in verdicts[name].detail


@pytest.mark.parametrize(("body", "said"), [
    ("import sys\nsys.exit(0)\n", "exited (status 0)"),
    ("import sys\nsys.exit(3)\n", "exited (status 3)"),
    ("raise RuntimeError('broken on purpose')\n", "RuntimeError: broken on purpose"),
])
def test_a_law_file_that_exits_or_raises_is_one_line_and_exit_2(tmp_path, capsys, body, said):
    path = tmp_path / "law.py"
    path.write_text(body)
    code, out, err = _check_law_cli(capsys, path)
    assert code == 2 and out == ""
    assert len(err.splitlines()) == 1 and str(path) in err and said in err


def test_a_law_file_that_calls_os_exit_is_reported(tmp_path):
    """os._exit would end the process at once (the audit: exit 0, no output); in a subprocess, so
    that a regression cannot end the test run."""
    path = tmp_path / "osexit.py"
    path.write_text("import os\nos._exit(0)\n")
    done = subprocess.run([sys.executable, "-m", "phaseimpact", "check-law", str(path)], capture_output=True,
                          text=True, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 2 and done.stdout == ""
    assert str(path) in done.stderr and "exited (status 0)" in done.stderr


def test_a_folder_or_fifo_is_named_as_such(tmp_path, capsys):
    folder = tmp_path / "dir.py"
    folder.mkdir()
    code, _, err = _check_law_cli(capsys, folder)
    assert code == 2 and "is a folder" in err and "does not exist" not in err
    fifo = tmp_path / "fifo.py"
    os.mkfifo(fifo)
    code, _, err = _check_law_cli(capsys, fifo)
    assert code == 2 and "is a FIFO" in err and "does not exist" not in err


def test_numba_colour_escapes_are_not_in_one_line_errors(tmp_path, capsys):
    path = tmp_path / "pyobj.py"
    path.write_text(HEAD + "class Settings:\n    scale = 1.0\n\n\nSETTINGS = Settings()\n\n\n"
                    "def force(delta, deltadot, K, kappa, alpha):\n    return SETTINGS.scale * K * delta**alpha\n\n\n"
                    "phaseimpact.define_law('pyobj', force)\n")
    code, _, err = _check_law_cli(capsys, path)
    assert code == 2 and "pyobj" in err and "\x1b" not in err and len(err.splitlines()) == 1


def test_no_module_of_the_package_imports_tests_or_touches_sys_path():
    package = Path(phaseimpact.__file__).parent
    found = []
    for path in sorted(package.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) and node.level == 0 else [])
            found += [f"{path.name}: import {n}" for n in names if n.split(".")[0] in ("tests", "oracle", "conftest")]
            if isinstance(node, ast.Attribute) and node.attr == "path" and getattr(node.value, "id", None) == "sys":
                found.append(f"{path.name}:{node.lineno}: sys.path")
    assert not found


@pytest.mark.slow
def test_check_law_from_a_built_wheel_runs_the_oracle(built_wheel, installed_wheel, tmp_path):
    """The wheel installed by pip (offline, no checkout on the path) and its own ``phaseimpact``
    command, run from elsewhere: the oracle check is there and passes (before, an installed
    package skipped it: tests/oracle.py not found). The engine runs uncompiled (NUMBA_DISABLE_JIT):
    the install's first compile would be most of this test's minutes and is not what it checks
    (test_packaging's sdist run compiles a distribution's engine cold, test_cache a copy's)."""
    with zipfile.ZipFile(built_wheel) as whl:
        assert "phaseimpact/_oracle.py" in whl.namelist()
    command = installed_wheel / "bin" / "phaseimpact"  # the wheel's console script, run by this interpreter
    env = {**os.environ, "PYTHONPATH": str(installed_wheel), "NUMBA_DISABLE_JIT": "1"}
    where = subprocess.run([sys.executable, "-c", "import phaseimpact; print(phaseimpact.__file__)"], cwd=tmp_path,
                           capture_output=True, text=True, env=env)
    assert where.stdout.strip() == str(installed_wheel / "phaseimpact" / "__init__.py"), where.stdout + where.stderr
    done = subprocess.run([sys.executable, str(command), "check-law", "hunt-crossley", "--json"], cwd=tmp_path,
                          capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    checks_run = {c["check"]: c["passed"] for c in json.loads(done.stdout)["laws"][0]["checks"]}
    assert checks_run["oracle"] is True
