"""make reproduce: a clean checkout stays clean on any machine (issue 37, item 6).

Regenerated files replace the committed ones only when they differ beyond the tolerance of
``studies/_settle.py``: a last-bit difference (1e-15) keeps the committed bytes, a real change
(1e-6) replaces them. And the Makefile's recipe works outside a git checkout (``git archive``).
"""

import importlib.util
import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from phaseimpact import archive, seed_parameters
from phaseimpact.archive import save_h5
from phaseimpact.continuation import sweep
from phaseimpact.model import ContactLaw

ROOT = Path(__file__).resolve().parents[1]


def _study_module(name):
    """A module of studies/ by its file (studies/ on sys.path would shadow tests/_cli.py with studies/_cli.py)."""
    spec = importlib.util.spec_from_file_location(f"studies_{name}", ROOT / "studies" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_settle = _study_module("_settle")


def _scaled(path: Path, out: Path, dataset: str, factor: float) -> Path:
    shutil.copy(path, out)
    with h5py.File(out, "r+") as f:
        f[dataset][...] = f[dataset][()] * factor
    return out


def test_study_data_file_kept_for_last_bits_replaced_for_a_real_change(tmp_path):
    x = np.geomspace(1e-6, 1e3, 200)
    old = save_h5(tmp_path / "old.h5", {"x": (x, "m"), "n": (np.arange(200), "1")}, {"kappa": 3e9, "law": "paper"})
    assert _settle.equivalent(old, _scaled(old, tmp_path / "bits.h5", "x", 1 + 1e-15))
    assert not _settle.equivalent(old, _scaled(old, tmp_path / "real.h5", "x", 1 + 1e-6))
    changed_attribute = save_h5(tmp_path / "attr.h5", {"x": (x, "m"), "n": (np.arange(200), "1")},
                                {"kappa": 3e9 * (1 + 1e-6), "law": "paper"})
    assert not _settle.equivalent(old, changed_attribute)
    renamed = save_h5(tmp_path / "renamed.h5", {"y": (x, "m"), "n": (np.arange(200), "1")},
                      {"kappa": 3e9, "law": "paper"})
    assert not _settle.equivalent(old, renamed)


def test_archive_kept_for_last_bits_and_another_created_time(tmp_path, monkeypatch):
    """A phaseimpact archive (dimension scales, references, digests): a regenerated one with a last-bit
    difference in max_force and another `created` time is the same result."""
    result = sweep(seed_parameters(), ContactLaw("paper"), np.geomspace(1e9, 1e14, 6))
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    old = archive.save(result, tmp_path / "old.h5")
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1800000000")
    new = archive.save(result, tmp_path / "new.h5")
    assert Path(old).read_bytes() != Path(new).read_bytes()
    assert _settle.equivalent(old, _scaled(Path(new), tmp_path / "bits.h5", "max_force", 1 + 1e-15))
    assert not _settle.equivalent(old, _scaled(Path(new), tmp_path / "real.h5", "max_force", 1 + 1e-6))


@pytest.mark.parametrize(("old", "new", "same"), [
    ("| kappa_c | 1234567890.123 N s/m^2.5 |", f"| kappa_c | {1234567890.123 * (1 + 1e-15)!r} N s/m^2.5 |", True),
    ("| kappa_c | 1234567890.123 N s/m^2.5 |", f"| kappa_c | {1234567890.123 * (1 + 1e-6):.3f} N s/m^2.5 |", False),
    ("slope 0.1234 (fit)", "slope 0.1235 (fit)", True),  # a rounding flip of the printed digits
    ("slope 0.1234 (fit)", "slope 0.1240 (fit)", False),
    ("slope 0.1234 (fit)", "slope 0.1234000 (fit)", True),
    ("slope 1.0 (fit)", "slope 1.000001 (fit)", False),
    ("slope 0.1234 (fit)", "slope 0.1234 (fitted)", False),
    ("3 points", "4 points", False),
])
def test_tables_compared_to_their_printed_digits(tmp_path, old, new, same):
    (tmp_path / "old.md").write_text(old + "\n")
    (tmp_path / "new.md").write_text(new + "\n")
    assert _settle.equivalent(tmp_path / "old.md", tmp_path / "new.md") is same


def _figure(path, scale):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from phaseimpact.plotting import save

    fig, ax = plt.subplots()
    ax.plot(np.linspace(0, 1, 50), np.sin(np.linspace(0, 6, 50)) * scale)
    ax.set_ylim(-2, 2)
    return Path(save(fig, path))


def test_figure_compared_by_its_pixels(tmp_path):
    old = _figure(tmp_path / "old.png", 1.0)
    assert _settle.equivalent(old, _figure(tmp_path / "bits.png", 1 + 1e-15))
    assert not _settle.equivalent(old, _figure(tmp_path / "real.png", 1.2))


def test_settle_keeps_committed_bytes_within_tolerance_and_reports_the_rest(tmp_path):
    target, staging = tmp_path / "figures", tmp_path / "staging"
    (target / "data").mkdir(parents=True)
    (staging / "data").mkdir(parents=True)
    x = np.linspace(1.0, 2.0, 100)
    for name in ("bits", "real"):
        save_h5(target / "data" / f"{name}.h5", {"x": (x, "m")})
    save_h5(staging / "data" / "bits.h5", {"x": (x * (1 + 1e-15), "m")})
    save_h5(staging / "data" / "real.h5", {"x": (x * (1 + 1e-6), "m")})
    _figure(target / "fig.png", 1.0)
    (target / "fig.pdf").write_bytes(b"%PDF committed")
    _figure(staging / "fig.png", 1 + 1e-15)
    (staging / "fig.pdf").write_bytes(b"%PDF regenerated, other last bits")
    (staging / "claims.md").write_text("new table\n")
    committed = {p: p.read_bytes() for p in target.rglob("*") if p.is_file()}
    regenerated_real = (staging / "data" / "real.h5").read_bytes()

    changed = _settle.settle(staging, target)

    assert changed == ["claims.md", "data/real.h5"]
    assert (target / "data" / "real.h5").read_bytes() == regenerated_real
    for path in (target / "data" / "bits.h5", target / "fig.png", target / "fig.pdf"):
        assert path.read_bytes() == committed[path], path.name  # the PDF follows its PNG
    assert (target / "claims.md").read_text() == "new table\n"
    assert not staging.exists()


def _chatter_counts(path: Path, counts, chatters=None) -> Path:
    """An archive like rk4_critical's: counts whose chattering cells (the mask) are last-bit sensitive."""
    counts = np.asarray(counts)
    chatters = counts > 1 if chatters is None else np.asarray(chatters)
    return save_h5(path, {"exact_count": (np.ones(len(counts), int), "1"), "rk4_count": (counts, "1"),
                          "rk4_chatters": (chatters, "1")},
                   {"last_bit_sensitive": "rk4_count", "last_bit_mask": "rk4_chatters", "drawn_in": "fig.png",
                    "last_bit_reason": "a chattering run's count moves with last bits"})


def test_declared_last_bit_sensitive_values_compared_by_their_mask(tmp_path):
    """rk4_critical's chattering counts differ between machines (4 and 13 against 5 and 14): such
    cells compare as chattering; the others and the mask itself exactly."""
    old = _chatter_counts(tmp_path / "old.h5", [1, 4, 13, 1])
    assert _settle.equivalent(old, _chatter_counts(tmp_path / "other.h5", [1, 5, 14, 1]))
    assert not _settle.equivalent(old, _chatter_counts(tmp_path / "unmasked.h5", [2, 4, 13, 1], [False, True, True,
                                                                                                   False]))
    assert not _settle.equivalent(old, _chatter_counts(tmp_path / "stopped.h5", [1, 1, 13, 1]))  # the mask moved
    undeclared = save_h5(tmp_path / "plain.h5", {"rk4_count": (np.array([1, 4, 13, 1]), "1")})
    assert not _settle.equivalent(undeclared, save_h5(tmp_path / "plain2.h5", {"rk4_count": (np.array([1, 5, 14, 1]),
                                                                                               "1")}))


def _settled_trains(path: Path, period, near_edge) -> Path:
    """An archive like train's: each value's samples and class, and its mask estimated by the run (so
    among the sensitive names: another machine's mask may differ)."""
    period = np.asarray(period)
    return save_h5(path, {"x2": (np.outer(period, [1.0, 2.0]), "m"), "orbit_period": (period, "1"),
                          "near_basin_edge": (np.asarray(near_edge), "1")},
                   {"last_bit_sensitive": "x2 orbit_period near_basin_edge", "last_bit_mask": "near_basin_edge",
                    "last_bit_reason": "where a train settles near a basin's edge moves with last bits"})


def test_several_sensitive_datasets_compared_where_neither_archive_marks_them(tmp_path):
    """train's values near a basin's edge: their samples (a row per value) and classes move together, and
    each machine marks its own; a value either archive marks is not compared, the others are."""
    old = _settled_trains(tmp_path / "old.h5", [1, 2, 0, 1], [False, True, True, False])
    assert _settle.equivalent(old, _settled_trains(tmp_path / "moved.h5", [1, 1, 2, 1], [False, True, True, False]))
    assert _settle.equivalent(old, _settled_trains(tmp_path / "other.h5", [1, 1, 0, 1], [False, False, True, False]))
    assert _settle.equivalent(old, _settled_trains(tmp_path / "more.h5", [1, 2, 3, 8], [False, True, True, True]))
    assert not _settle.equivalent(old, _settled_trains(tmp_path / "unmarked.h5", [2, 2, 0, 1],
                                                       [False, True, True, False]))


def test_a_figure_drawn_from_sensitive_values_follows_its_archive(tmp_path):
    """Only masked values moved: the archive and its figure keep their committed bytes. The same
    values with another figure (a change of style) replace the figure."""
    target, staging = tmp_path / "figures", tmp_path / "staging"
    for folder in (target, staging):
        (folder / "data").mkdir(parents=True)
    _chatter_counts(target / "data" / "c.h5", [1, 4, 13, 1])
    _figure(target / "fig.png", 1.0)
    _chatter_counts(staging / "data" / "c.h5", [1, 5, 14, 1])
    _figure(staging / "fig.png", 1.2)  # drawn from the moved counts
    committed = (target / "fig.png").read_bytes()
    assert _settle.settle(staging, target) == []
    assert (target / "fig.png").read_bytes() == committed
    staging.mkdir()
    (staging / "data").mkdir()
    _chatter_counts(staging / "data" / "c.h5", [1, 4, 13, 1])
    _figure(staging / "fig.png", 1.2)
    assert _settle.settle(staging, target) == ["fig.png"]


def test_rk4_critical_declares_its_sensitive_counts():
    with h5py.File(ROOT / "figures" / "data" / "rk4_critical.h5", "r") as f:
        assert f.attrs["last_bit_sensitive"] == "rk4_count" and f.attrs["last_bit_mask"] == "rk4_chatters"
        counts, exact = f["rk4_count"][()], f["exact_count"][()]
        np.testing.assert_array_equal(f["rk4_chatters"][()], counts > exact[None, :, None])
        assert (ROOT / "figures" / f.attrs["drawn_in"]).exists()


def test_makefile_reproduce_outside_a_git_checkout(tmp_path):
    """From `git archive HEAD | tar x` (no .git) the recipe set SOURCE_DATE_EPOCH to '' (git log printed
    nothing), on which NumPy crashed at import: it must pass a usable value or none."""
    make = shutil.which("make")
    if make is None:
        pytest.skip("make is not installed")
    shutil.copy(ROOT / "Makefile", tmp_path / "Makefile")
    (tmp_path / "pyproject.toml").write_text("")
    bin_ = tmp_path / ".venv" / "bin"
    bin_.mkdir(parents=True)
    fake = bin_ / "python"  # records what the recipe runs, and with which SOURCE_DATE_EPOCH
    fake.write_text('#!/bin/sh\necho "SOURCE_DATE_EPOCH=${SOURCE_DATE_EPOCH-unset} $*" >> "$(dirname "$0")/log"\n')
    fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
    stamp = tmp_path / ".venv" / ".installed"
    stamp.touch()
    os.utime(tmp_path / "pyproject.toml", (1, 1))  # older than the stamp: nothing to install
    env = {k: v for k, v in os.environ.items() if k != "SOURCE_DATE_EPOCH"}
    env["GIT_CEILING_DIRECTORIES"] = str(tmp_path.parent)  # no checkout above tmp_path either
    result = subprocess.run([make, "reproduce", "QUICK=1"], cwd=tmp_path, env=env, capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 0, result.stderr
    runs = (bin_ / "log").read_text().splitlines()
    assert len(runs) == 2 and runs[0].endswith("-m phaseimpact warmup"), runs  # the engine compiled up front
    assert runs[1].endswith("studies/run_all.py --quick --jobs 2"), runs
    epoch = runs[1].split()[0].partition("=")[2]
    assert epoch == "unset" or epoch.isdigit(), runs


@pytest.mark.slow
def test_a_study_runs_from_git_archive_output(tmp_path):
    """`git archive HEAD | tar x` (no .git) then a study, as `make reproduce QUICK=1` runs it, with the empty
    SOURCE_DATE_EPOCH the old Makefile passed: NumPy's f2py raised at import, nothing was produced."""
    git = shutil.which("git")
    if git is None or subprocess.run([git, "rev-parse", "HEAD"], cwd=ROOT, capture_output=True).returncode:
        pytest.skip("not a git checkout")
    tree = tmp_path / "tree"
    tree.mkdir()
    archive_ = subprocess.run([git, "archive", "HEAD"], cwd=ROOT, capture_output=True, check=True, timeout=120)
    subprocess.run(["tar", "x"], input=archive_.stdout, cwd=tree, check=True, timeout=120)
    assert not (tree / ".git").exists()
    # the package of this checkout (the same code, its compiled engine cached), the studies of the archive
    env = {**os.environ, "SOURCE_DATE_EPOCH": "", "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg",
           "GIT_CEILING_DIRECTORIES": str(tmp_path)}
    result = subprocess.run([sys.executable, "studies/fig04_force_indentation.py", "--quick"], cwd=tree, env=env,
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    written = sorted(p.relative_to(tree / "figures" / "preview").as_posix()
                     for p in (tree / "figures" / "preview").rglob("*") if p.is_file())
    assert written == ["data/fig04_force_indentation.h5", "fig04_force_indentation.pdf",
                       "fig04_force_indentation.png"], written
    assert "3 file(s) changed beyond the tolerance" in result.stdout  # new files: nothing to compare with


def test_readme_states_the_tolerance_the_comparison_uses():
    text = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    rtol = f"{_settle.RTOL:.0e}".replace("e-0", "e-")  # as written: 1e-9
    assert float(rtol) == _settle.RTOL
    assert f"within a relative {rtol} (or {rtol} of the dataset's largest magnitude" in text
    assert f"within {_settle.PIXEL_LEVELS} levels of 255 per channel" in text
