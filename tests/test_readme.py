"""The README's commands parse; its blocks run as written in tests/test_docs.py (with every page of
the docs, in order, in a scratch folder)."""

import contextlib
import io
import re
import shlex
from pathlib import Path

import pytest

from phaseimpact.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
#: Pages whose documented commands must parse (the README's also run).
DOCUMENTED = (README, ROOT / "docs" / "commands.md", ROOT / "docs" / "getting-started.md")


def blocks(path=README):
    """``(language, code)`` of every fenced block, in order."""
    return re.findall(r"^```(\w*)\n(.*?)^```", path.read_text(encoding="utf-8"), flags=re.S | re.M)


def commands(code):
    """The ``phaseimpact`` command lines of a shell block, as argument lists (comments dropped)."""
    for line in code.splitlines():
        words = shlex.split(line, comments=True)
        if words and words[0] == "phaseimpact":
            yield words[1:]


def test_readme_has_runnable_blocks():
    found = blocks()
    assert any(lang == "python" for lang, _ in found)
    assert sum(len(list(commands(code))) for lang, code in found if lang in ("sh", "bash")) >= 5


@pytest.mark.parametrize("page", DOCUMENTED, ids=lambda p: p.name)
def test_every_documented_command_parses(page):
    """Fast: no placeholder (``...``) or unknown option in any documented command."""
    parser = build_parser()
    for lang, code in blocks(page):
        if lang in ("sh", "bash"):
            for argv in commands(code):
                with contextlib.redirect_stderr(io.StringIO()) as err:
                    try:
                        parser.parse_args(argv)
                    except SystemExit:
                        pytest.fail(f"phaseimpact {shlex.join(argv)}: {err.getvalue()}")
