"""The documentation site (mkdocs.yml, docs/): every page with code runs as written, and the site builds
with ``mkdocs build --strict``, its generated command-line reference and gallery complete.

A page runs top to bottom in an empty folder, in a process of its own (so the laws it defines stay
there): a block with a title (```toml title="case.toml") is written to that file, the ```python
blocks run as one script, and the lines of the ```sh blocks that start with ``phaseimpact`` go
through the command line's ``main`` (as tests/test_readme.py does for README.md).
By hand, in a scratch folder: ``python PATH/TO/tests/test_docs.py PATH/TO/docs/tutorials/atlas.md``.
"""

import contextlib
import html
import io
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
TUTORIALS = sorted((DOCS / "tutorials").glob("*.md"))
RUNNABLE = ("python", "sh", "bash")


def fenced(page):
    """``(language, title, code)`` of every fenced block of ``page``, in order (title: "" if none)."""
    found = re.findall(r"^```(\w*)([^\n]*)\n(.*?)^```", Path(page).read_text(encoding="utf-8"), flags=re.S | re.M)
    return [(lang, "".join(re.findall(r'title="([^"]+)"', attrs)), code) for lang, attrs, code in found]


def blocks(page):
    """``(language, code)`` of every block of ``page`` that runs (not those written to a file)."""
    return [(lang, code) for lang, title, code in fenced(page) if not title]


def commands(code):
    """The ``phaseimpact`` command lines of a shell block, as argument lists (comments dropped)."""
    for line in code.splitlines():
        words = shlex.split(line, comments=True)
        if words and words[0] == "phaseimpact":
            yield words[1:]


def runnable(page) -> bool:
    return any(lang == "python" or (lang in RUNNABLE and list(commands(code))) for lang, code in blocks(page))


PAGES = [p for p in (DOCS / "index.md", DOCS / "getting-started.md", DOCS / "archive.md", *TUTORIALS) if runnable(p)]


def run_page(page) -> int:
    """Run ``page``'s blocks in order in the current folder; the number of blocks run."""
    from phaseimpact.cli import main

    namespace = {"__name__": "__docs__"}
    ran = 0
    for number, (lang, title, code) in enumerate(fenced(page), 1):
        if title:
            Path(title).write_text(code, encoding="utf-8")
        elif lang == "python":
            exec(compile(code, f"{Path(page).name}, block {number}", "exec"), namespace)
            ran += 1
        elif lang in RUNNABLE:
            for argv in commands(code):
                print(f"$ phaseimpact {shlex.join(argv)}", flush=True)
                status = main(argv)
                if status != 0:
                    raise SystemExit(f"{Path(page).name}, block {number}: phaseimpact {shlex.join(argv)} "
                                     f"exited {status}")
                ran += 1
    return ran


def test_every_tutorial_is_runnable():
    assert len(TUTORIALS) >= 6 and all(runnable(page) for page in TUTORIALS if page.name != "index.md")


def test_every_documented_command_parses(tmp_path, monkeypatch):
    """Fast: no placeholder or unknown option in any command of the pages (with the files the page
    writes first; commands of a user law's file are checked by running the page)."""
    from phaseimpact.cli import build_parser

    parser = build_parser()
    for page in PAGES:
        folder = tmp_path / page.relative_to(DOCS).with_suffix("")
        folder.mkdir(parents=True)
        monkeypatch.chdir(folder)
        for lang, title, code in fenced(page):
            if title:
                Path(title).write_text(code, encoding="utf-8")
            elif lang in RUNNABLE:
                for argv in commands(code):
                    if "--law-file" in argv:
                        continue
                    with contextlib.redirect_stderr(io.StringIO()) as err:
                        try:
                            parser.parse_args(argv)
                        except SystemExit:
                            pytest.fail(f"{page.name}: phaseimpact {shlex.join(argv)}: {err.getvalue()}")


@pytest.mark.slow
@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(DOCS).as_posix())
def test_page_runs_as_written(page, tmp_path):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.run([sys.executable, __file__, str(page)], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, f"{page.name}:\n{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}"
    if page.parent.name == "tutorials":
        written = [p.name for p in tmp_path.iterdir()]
        for name in re.findall(r"\"([\w.-]+\.(?:png|h5|toml|py))\"", page.read_text(encoding="utf-8")):
            assert name in written, f"{page.name} does not write {name}"


# ------------------------------------------------------------------------------------------------
# The site
# ------------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(ROOT / "mkdocs.yml"),
                           "-d", str(out)], cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"mkdocs build --strict failed:\n{proc.stdout[-4000:]}\n{proc.stderr[-6000:]}"
    return out


def _page(site, name):
    """The text of a built page: its HTML, without tags (so code highlighting does not split words)."""
    return html.unescape(re.sub(r"<[^>]+>", "", (site / name / "index.html").read_text(encoding="utf-8")))


def _html(site, name):
    return (site / name / "index.html").read_text(encoding="utf-8")


@pytest.mark.slow
def test_cli_page_lists_every_subcommand_and_option(site):
    import argparse

    from phaseimpact.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    assert len(sub.choices) >= 10
    # the page's sections, by heading id: "phaseimpact", then one per subcommand
    sections = dict(re.findall(r'<h2 id="([\w-]+)">(.*?)(?=<h2 id=|</article>)', _html(site, "cli"), flags=re.S))
    assert list(sections) == ["phaseimpact", *sub.choices]
    for name, command in sub.choices.items():
        text = html.unescape(re.sub(r"<[^>]+>", " ", sections[name]))
        assert f"usage: phaseimpact {name}" in text, f"no usage of {name}"
        for action in command._actions:
            if action.help == argparse.SUPPRESS:
                continue  # hidden: a removed option, refused with its replacement
            for option in action.option_strings:
                assert re.search(rf"(?<![\w-]){re.escape(option)}(?![\w-])", text), f"{name} {option} is missing"
            if action.help:
                assert action.help.split("%(")[0][:40] in text, f"{name}: the help of {action.dest} is missing"


@pytest.mark.slow
def test_gallery_shows_every_figure(site):
    page, source = _page(site, "gallery"), _html(site, "gallery")
    figures = sorted((ROOT / "figures").glob("*.png"))
    assert figures
    for png in figures:
        assert f'src="../figures/{png.name}"' in source, f"{png.name} is not in the gallery"
        assert (site / "figures" / png.name).read_bytes() == png.read_bytes()
        folder = "studies" if (ROOT / "studies" / f"{png.stem}.py").exists() else "benchmarks"
        assert f"python {folder}/{png.stem}.py" in page, f"no command for {png.name}"


@pytest.mark.slow
def test_api_reference_covers_the_public_modules(site):
    import phaseimpact

    top = _html(site, "reference/phaseimpact")
    for name in phaseimpact.__all__:
        assert name.startswith("__") or f"<code>{name}</code>" in top, f"phaseimpact.{name} is not listed"
    for page, module in (("integrate", "integrate"), ("continuation", "continuation"), ("archive", "archive"),
                         ("analysis", "analysis"), ("case", "case"), ("parameters", "parameters"),
                         ("model-laws", "model.laws"), ("model-userlaw", "model.userlaw"), ("checks", "checks"),
                         ("plotting", "plotting")):
        assert f'id="phaseimpact.{module}.' in _html(site, f"reference/{page}"), module
    assert ":func:`" not in _html(site, "reference/continuation")  # Sphinx roles are rewritten


if __name__ == "__main__":
    sys.exit(0 if run_page(sys.argv[1]) else "no code block ran")
