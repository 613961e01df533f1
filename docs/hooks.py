"""MkDocs hooks (``hooks:`` in mkdocs.yml): the pages that are generated at build time.

* ``cli.md``: the command-line reference, from ``phaseimpact.cli.build_parser()`` (every subcommand's
  usage, description and options with their help text), in place of ``<!-- cli-reference -->``.
* ``gallery.md``: every ``figures/*.png`` with its caption (figures/README.md's table), a link to its
  vector PDF (for print) and the command that regenerates it, in place of ``<!-- gallery -->``. The
  PNGs and PDFs are served from ``figures/`` in the built site (added to the build here; never copied
  into ``docs/``).
* ``reference/phaseimpact.md``: the table of the package's top-level names, in place of
  ``<!-- top-level-names -->``.

A figure without a caption in figures/README.md or without a script that makes it is a warning, so
``mkdocs build --strict`` fails on it.
"""

from __future__ import annotations

import argparse
import html
import importlib
import inspect
import logging
import re
import sys
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "figures"
if str(ROOT) not in sys.path:  # the checkout's package, also without an installed one
    sys.path.insert(0, str(ROOT))

log = logging.getLogger("mkdocs.hooks.phaseimpact")

MARKERS = {
    "cli.md": "<!-- cli-reference -->",
    "gallery.md": "<!-- gallery -->",
    "reference/phaseimpact.md": "<!-- top-level-names -->",
}
# A row of figures/README.md's table: | ![](NAME.png) | caption |
FIGURE_ROW = re.compile(r"^\|\s*!\[[^\]]*\]\((?P<name>[\w.-]+)\.png\)\s*\|\s*(?P<caption>.*?)\s*\|\s*$", re.M)


# The figures of this build, listed once (on_files), so the gallery shows exactly the files served.
_figures: list[Path] = []


def on_files(files, config):
    """Serve ``figures/*.png`` at ``figures/NAME.png`` in the site, and the PDF beside each."""
    _figures[:] = sorted(FIGURES.glob("*.png"))
    for png in _figures:
        for path in (png, png.with_suffix(".pdf")):
            if path.is_file():
                files.append(File.generated(config, f"figures/{path.name}", abs_src_path=str(path)))
    return files


def on_page_markdown(markdown, page, config, files):
    marker = MARKERS.get(page.file.src_uri)
    if marker is None:
        return markdown
    if marker not in markdown:
        log.warning("%s: the marker %s is missing", page.file.src_uri, marker)
        return markdown
    build = {"cli.md": cli_reference, "gallery.md": gallery, "reference/phaseimpact.md": top_level_names}
    return markdown.replace(marker, build[page.file.src_uri]())


# ------------------------------------------------------------------------------------------------
# Command line
# ------------------------------------------------------------------------------------------------

def _subparsers(parser: argparse.ArgumentParser) -> argparse._SubParsersAction:
    return next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))


def _options_table(parser: argparse.ArgumentParser) -> str:
    """The parser's arguments as an HTML table (its help text is plain text: no Markdown in it)."""
    formatter = parser._get_formatter()
    rows = []
    for action in parser._actions:
        if action.help == argparse.SUPPRESS or isinstance(action, argparse._SubParsersAction):
            continue
        invocation = formatter._format_action_invocation(action)
        text = formatter._expand_help(action) if action.help else ""
        rows.append(f"<tr><td><code>{html.escape(invocation)}</code></td><td>{html.escape(text)}</td></tr>")
    return ("<table>\n<thead><tr><th>option</th><th>meaning</th></tr></thead>\n<tbody>\n"
            + "\n".join(rows) + "\n</tbody>\n</table>")


def _usage(parser: argparse.ArgumentParser) -> str:
    return "```text\n" + parser.format_usage().strip() + "\n```"


def cli_reference() -> str:
    from phaseimpact.cli import build_parser

    parser = build_parser()
    sub = _subparsers(parser)
    summaries = {choice.dest: choice.help or "" for choice in sub._choices_actions}
    parts = ["## `phaseimpact`", "", html.escape(parser.description or ""), "", _usage(parser), "",
             _options_table(parser), "", html.escape(parser.epilog or ""), ""]
    for name, command in sub.choices.items():
        parts += [f"## `{name}`", "", f"*{html.escape(summaries.get(name, ''))}*", "",
                  html.escape(command.description or ""), "", _usage(command), "", _options_table(command), ""]
        if command.epilog:
            parts += [html.escape(command.epilog), ""]
    return "\n".join(parts)


# ------------------------------------------------------------------------------------------------
# Gallery
# ------------------------------------------------------------------------------------------------

def captions() -> dict[str, str]:
    """figures/README.md's table: figure name -> caption (Markdown), in the table's order."""
    return {m["name"]: m["caption"] for m in FIGURE_ROW.finditer((FIGURES / "README.md").read_text(encoding="utf-8"))}


def figure_command(name: str) -> str | None:
    """The command that regenerates ``figures/NAME.png``: its study script (``make reproduce`` runs them
    all) or its benchmark script (``make benchmarks``)."""
    if (ROOT / "studies" / f"{name}.py").is_file():
        return f"python studies/{name}.py   # all figures: make reproduce"
    if (ROOT / "benchmarks" / f"{name}.py").is_file():
        return f"python benchmarks/{name}.py   # all benchmarks: make benchmarks"
    return None


def gallery() -> str:
    known = captions()
    present = {png.stem for png in _figures}
    order = [name for name in known if name in present] + sorted(present - set(known))
    parts = []
    for name in order:
        caption = known.get(name)
        if caption is None:
            log.warning("gallery: figures/%s.png has no caption in figures/README.md's table", name)
            caption = ""
        command = figure_command(name)
        if command is None:
            log.warning("gallery: no script in studies/ or benchmarks/ makes figures/%s.png", name)
        parts += [f"## {name}", "", f"![{name}](figures/{name}.png)", "", caption, ""]
        if (FIGURES / f"{name}.pdf").is_file():
            parts += [f"[PDF for print](figures/{name}.pdf)", ""]
        if command:
            parts += ["```sh", command, "```", ""]
    return "\n".join(parts)


# ------------------------------------------------------------------------------------------------
# Top-level names
# ------------------------------------------------------------------------------------------------

def top_level_names() -> str:
    """``phaseimpact.__all__``: each name, where it is defined (a link to its reference) and the first
    paragraph of its docstring."""
    import phaseimpact

    rows = ["| name | defined in | summary |", "|---|---|---|"]
    for name in phaseimpact.__all__:
        if name.startswith("__"):
            continue
        package = f"phaseimpact.{phaseimpact._EXPORTS[name]}"
        value = getattr(importlib.import_module(package), name)
        if inspect.isclass(value) or inspect.isfunction(value):
            home, doc = value.__module__, inspect.getdoc(value)
        else:  # a constant: the deepest module that holds it
            home = max((m for m, mod in list(sys.modules.items())
                        if m.startswith(package) and getattr(mod, name, None) is value), key=len)
            doc = None
        path = f"{home}.{name}"
        summary = (doc or "").split("\n\n")[0].replace("\n", " ").replace("|", "\\|")
        summary = re.sub(r":\w+:`~?([^`]+)`", r"`\1`", summary)  # Sphinx roles as code
        # a constant has no docstring, so maybe no entry in the reference: an optional link
        link = (f"[`{name}`][{path}]" if doc is not None
                else f'<autoref identifier="{path}" optional><code>{name}</code></autoref>')
        rows.append(f"| {link} | `{home}` | {summary} |")
    return "\n".join(rows)
