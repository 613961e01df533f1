"""The documentation site (mkdocs.yml, docs/) and the README: every code block runs as written, and
the site builds with ``mkdocs build --strict``, its generated command-line reference and gallery
complete.

A page runs top to bottom in an empty folder, in a process of its own (so the laws it defines stay
there): a block with a title (```toml title="case.toml") is written to that file, each ```python
block runs in the page's one namespace, and each line of a ```sh block runs: ``phaseimpact ...``
through the command line's ``main`` (exit 0 required), any other command in bash. A block that
cannot run here (``make``, ``pip install`` from the internet, a cluster's address, output) says so
where the reader sees it, on the line before its fence: ``<!-- no-run: why -->``; the test honours
the marker, counts it, and still checks that its ``phaseimpact`` commands parse.
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
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
TUTORIALS = sorted((DOCS / "tutorials").glob("*.md"))
#: Every page with code: the README and the site's pages.
PAGES = [ROOT / "README.md", *sorted(DOCS.rglob("*.md"))]
#: The languages of the blocks that run; a block of another language is data (toml, json, text).
PYTHON, SHELL = ("python",), ("sh", "bash", "shell", "console")
#: The marker of a block that does not run, on the line before its fence, with the reason.
NO_RUN = re.compile(r"^\s*<!--\s*no-run:\s*(?P<why>\S.*?)\s*-->\s*$")
FENCE = re.compile(r"^(?P<indent>[ \t]*)```(?P<lang>[\w-]*)(?P<attrs>[^\n]*)\n(?P<code>.*?)^(?P=indent)```[ \t]*$",
                   flags=re.S | re.M)


@dataclass(frozen=True)
class Block:
    """A fenced block: its language, the file it is written to ("" if none), its code (dedented),
    the line of its fence and the reason it does not run (None: it runs)."""

    lang: str
    title: str
    code: str
    line: int
    no_run: str | None

    @property
    def runs(self) -> bool:
        return self.no_run is None and not self.title and self.lang in PYTHON + SHELL


def fenced(page) -> list[Block]:
    """Every fenced block of ``page``, in order (blocks inside list items too)."""
    text = Path(page).read_text(encoding="utf-8")
    found = []
    for m in FENCE.finditer(text):
        before = text[:m.start()].rstrip("\n").rsplit("\n", 1)[-1]
        marker = NO_RUN.match(before)
        code = textwrap.dedent(m["code"])
        found.append(Block(m["lang"], "".join(re.findall(r'title="([^"]+)"', m["attrs"])), code,
                           text.count("\n", 0, m.start()) + 1, marker["why"] if marker else None))
    return found


def command_lines(code):
    """``(line, words)`` of each command of a shell block (continued lines joined; comments and blank
    lines dropped)."""
    for line in code.replace("\\\n", " ").splitlines():
        words = shlex.split(line, comments=True)
        if words:
            yield line, words


def commands(code):
    """The ``phaseimpact`` command lines of a shell block, as argument lists."""
    for _, words in command_lines(code):
        if words[0] == "phaseimpact":
            yield words[1:]


def counts(page) -> tuple[int, int]:
    """``(blocks that run, blocks marked no-run)`` of ``page``."""
    found = fenced(page)
    return sum(b.runs for b in found), sum(b.no_run is not None for b in found)


RUN_PAGES = [p for p in PAGES if counts(p)[0]]


def run_page(page) -> int:
    """Run ``page``'s blocks in order in the current folder; the number of blocks run."""
    from phaseimpact.cli import main

    namespace = {"__name__": "__docs__"}
    ran = 0
    for block in fenced(page):
        where = f"{Path(page).name}, line {block.line}"
        if block.title and block.no_run is None:
            Path(block.title).write_text(block.code, encoding="utf-8")
        if not block.runs:
            continue
        if block.lang in PYTHON:
            exec(compile(block.code, where, "exec"), namespace)
        for line, words in command_lines(block.code) if block.lang in SHELL else ():
            print(f"$ {line}", flush=True)
            if words[0] == "phaseimpact":
                status = main(words[1:])
            else:  # verbatim, as a reader's shell runs it, with this Python first on the PATH
                path = os.pathsep.join((str(Path(sys.executable).parent), os.environ.get("PATH", "")))
                status = subprocess.run(["bash", "-c", line], env={**os.environ, "PATH": path}).returncode
            if status != 0:
                raise SystemExit(f"{where}: {line.strip()} exited {status}")
        ran += 1
    return ran


def test_every_tutorial_is_runnable():
    assert len(TUTORIALS) >= 6 and all(counts(page)[0] for page in TUTORIALS if page.name != "index.md")


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_block_runs_or_says_why(page):
    """Python and shell blocks run, unless marked no-run with a reason; a block without a language
    is marked (it cannot be told from code); a marker stands before a block."""
    text = page.read_text(encoding="utf-8")
    for block in fenced(page):
        if not block.lang and not block.title:
            assert block.no_run, f"{page.name}, line {block.line}: a block without a language and no no-run marker"
    markers = sum(bool(NO_RUN.match(line)) for line in text.splitlines())
    assert markers == counts(page)[1], f"{page.name}: a no-run marker that is not on the line before a fence"


def test_the_markers_are_counted(tmp_path, monkeypatch):
    """The marker is honoured: a marked block is not run, an unmarked one is, whatever its text."""
    page = tmp_path / "page.md"
    page.write_text("<!-- no-run: needs the internet -->\n```sh\npip install x\n```\n\n```python\nx = 1\n```\n"
                    "\n- item\n\n  <!-- no-run: an output -->\n  ```python\n  1 / 0\n  ```\n"
                    "\n```sh\necho \"$((6 * 7))\" > answer.txt   # verbatim, through bash\n```\n", encoding="utf-8")
    blocks = fenced(page)
    assert [(b.lang, b.no_run, b.runs) for b in blocks] == [
        ("sh", "needs the internet", False), ("python", None, True), ("python", "an output", False),
        ("sh", None, True)]
    assert counts(page) == (2, 2) and blocks[2].code == "1 / 0\n"
    monkeypatch.chdir(tmp_path)
    assert run_page(page) == 2 and (tmp_path / "answer.txt").read_text() == "42\n"


def test_every_documented_command_parses(tmp_path, monkeypatch):
    """Fast: no placeholder or unknown option in any command of the pages, marked no-run or not (with
    the files the page writes first; commands of a user law's file are checked by running the page)."""
    from phaseimpact.cli import build_parser

    parser = build_parser()
    for page in PAGES:
        folder = tmp_path / page.relative_to(ROOT).with_suffix("")
        folder.mkdir(parents=True)
        monkeypatch.chdir(folder)
        for block in fenced(page):
            if block.title:
                Path(block.title).write_text(block.code, encoding="utf-8")
            elif block.lang in SHELL:
                for argv in commands(block.code):
                    if "--law-file" in argv:
                        continue
                    with contextlib.redirect_stderr(io.StringIO()) as err:
                        try:
                            parser.parse_args(argv)
                        except SystemExit:
                            pytest.fail(f"{page.name}: phaseimpact {shlex.join(argv)}: {err.getvalue()}")


@pytest.mark.slow
@pytest.mark.parametrize("page", RUN_PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_page_runs_as_written(page, tmp_path):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.run([sys.executable, __file__, str(page)], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, f"{page.name}:\n{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}"
    assert f"ran {counts(page)[0]} blocks" in proc.stdout  # every block that runs ran, none skipped
    if page.parent.name == "tutorials":
        written = [p.name for p in tmp_path.iterdir()]
        for name in re.findall(r"\"([\w.-]+\.(?:png|nc|toml|py))\"", page.read_text(encoding="utf-8")):
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
    ran = run_page(sys.argv[1])
    print(f"ran {ran} blocks, {counts(sys.argv[1])[1]} marked no-run")
    sys.exit(0 if ran else "no code block ran")
