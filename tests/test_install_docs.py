"""Install and first run as documented (issue 41, item 4): no install command that cannot work (the
package is not on PyPI), the extras the docs and messages name exist, the troubleshooting page and
the changelog are in the site, and CITATION.cff cites this version."""

import re
import sys
from pathlib import Path

import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
#: Every page a user reads: the README and the docs site's sources.
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def _nav(items) -> list[str]:
    pages = []
    for item in items:
        if isinstance(item, str):
            pages.append(item)
        else:
            for value in item.values():
                pages += _nav(value) if isinstance(value, list) else [value]
    return pages


def _mkdocs() -> dict:
    yaml = pytest.importorskip("yaml")
    return yaml.safe_load((ROOT / "mkdocs.yml").read_text())


def test_no_page_installs_from_an_index_that_does_not_have_the_package():
    """``pip install phaseimpact`` or ``pip install "phaseimpact[dask]"`` finds nothing: the package is
    installed from a clone (``-e .``) or a built wheel (``dist/...whl``)."""
    from_index = re.compile(r"pip install (?:-[-\w]+ )*[\"']?phaseimpact(?:\[[^\]]*\])?[\"']?(?=[\s`]|$)")
    found = [(page.relative_to(ROOT), m.group(0)) for page in PAGES for m in from_index.finditer(page.read_text())]
    assert not found, found
    start = (ROOT / "docs" / "getting-started.md").read_text()
    assert "pip install -e ." in start and "pip wheel --no-deps -w dist ." in start and "not published" in start


def test_the_extras_the_docs_name_exist():
    extras = PYPROJECT["project"]["optional-dependencies"]
    named = set()
    for page in PAGES:
        named |= set(re.findall(r"\.\[(\w+)\]", page.read_text()))
    assert named and named <= set(extras), named - set(extras)
    assert {re.split(r"[<>=\[]", d)[0] for d in extras["xarray"]} == {"xarray", "h5netcdf"}


def test_troubleshooting_and_changelog_are_in_the_site():
    config = _mkdocs()
    nav = _nav(config["nav"])
    assert {"troubleshooting.md", "changelog.md"} <= set(nav)
    # the changelog page is the repository's CHANGELOG.md itself (a snippet), never a copy to keep in step
    assert (ROOT / "docs" / "changelog.md").read_text().strip() == '--8<-- "CHANGELOG.md"'
    snippets = next(e["pymdownx.snippets"] for e in config["markdown_extensions"]
                    if isinstance(e, dict) and "pymdownx.snippets" in e)
    assert snippets["check_paths"] is True  # a missing CHANGELOG.md fails the build
    page = (ROOT / "docs" / "troubleshooting.md").read_text()
    for needed in ("NUMBA_CACHE_DIR", "phaseimpact warmup", "read-only", "XDG_CACHE_HOME"):
        assert needed in page, needed


def test_the_first_compile_time_quoted_is_the_benchmarks():
    """The troubleshooting page quotes the first command's compile time from figures/benchmarks.md."""
    table = (ROOT / "figures" / "benchmarks.md").read_text()
    row = re.search(r"\| first command on an empty cache \(phaseimpact simulate\)[^|]* \| [^|]+ \| ([\d.]+) s[ |]",
                    table)
    assert row, "figures/benchmarks.md has no row for the first command's compile"
    measured = row.group(1)
    page = (ROOT / "docs" / "troubleshooting.md").read_text()
    assert f"on an empty cache took {measured} s" in " ".join(page.split())


def test_citation_cites_this_version():
    cff = _yaml_file("CITATION.cff")
    assert str(cff["version"]) == PYPROJECT["project"]["version"]
    assert cff["authors"] and all(a.get("name") or a.get("family-names") for a in cff["authors"])
    assert re.fullmatch(r"\d{4}-\d{2}-\d{2}", str(cff["date-released"]))
    assert cff["cff-version"] == "1.2.0" and cff["license"] == PYPROJECT["project"]["license"]


def _yaml_file(name: str) -> dict:
    yaml = pytest.importorskip("yaml")
    return yaml.safe_load((ROOT / name).read_text())
