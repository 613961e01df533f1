"""Griffe extension for the API reference (mkdocs.yml, mkdocstrings ``extensions``).

The package's docstrings are numpy style with reStructuredText inside, which Markdown does not know:

* Sphinx roles (``:func:`~phaseimpact.simulate```, ``:class:`Trajectory```, ``:mod:`.sweep```) become
  a link to the object's reference where the name resolves in the docstring's scope and the object
  is documented, and code otherwise (an optional cross-reference: never a warning, so ``--strict``
  does not depend on it);
* simple tables (columns under ``====  ====`` rules) are shown as preformatted text;
* a paragraph ending in ``::`` (before a literal block) ends in ``:``.

Only the rendering changes: the docstrings in phaseimpact/ are left as they are.
"""

from __future__ import annotations

import ast
import html
import re

import griffe

ROLE = re.compile(r":(?:py:)?(?P<role>func|meth|class|mod|data|attr|exc|obj|const):`(?P<target>[^`]+)`")
RULE = re.compile(r"^\s*=+(\s+=+)+\s*$")  # a rule of a reST simple table


def _walk(obj):
    yield obj
    for member in obj.members.values():
        if not member.is_alias:
            yield from _walk(member)


def _resolve(obj, name: str) -> str | None:
    """The full path of ``name`` as written in ``obj``'s docstring, or None."""
    if name.startswith("."):  # relative to the docstring's package: .sweep, ..model
        module = obj.module
        package = module.path if module.is_init_module else module.parent.path
        dots = len(name) - len(name.lstrip("."))
        parts = package.split(".")
        if dots - 1 >= len(parts):
            return None
        return ".".join(parts[:len(parts) - (dots - 1)] + [name.lstrip(".")])
    head, _, rest = name.partition(".")
    if head == obj.module.package.name:
        return _unlazy(obj.module.package, name)
    try:
        path = obj.resolve(head)
    except (griffe.NameResolutionError, AttributeError):
        return None
    return _unlazy(obj.module.package, f"{path}.{rest}" if rest else path)


def _lookup(package, path: str):
    if path == package.path:
        return package
    if not path.startswith(package.path + "."):
        return None
    try:
        return package[path[len(package.path) + 1:]]
    except (KeyError, ValueError, griffe.AliasResolutionError):
        return None


def _unlazy(package, path: str) -> str:
    """``path`` with a name a module imports on first use (``phaseimpact.simulate``: its ``_EXPORTS``
    or ``_LAZY`` table, which static analysis does not follow) replaced by where it is defined."""
    parts = path.split(".")
    for i in range(1, len(parts)):
        if _lookup(package, ".".join(parts[:i + 1])) is not None:
            continue
        module = _lookup(package, ".".join(parts[:i]))
        for table in ("_EXPORTS", "_LAZY"):
            attribute = module.members.get(table) if module is not None and module.is_module else None
            try:
                mapping = ast.literal_eval(str(attribute.value)) if attribute is not None else {}
            except (ValueError, SyntaxError):
                mapping = {}
            if isinstance(mapping, dict) and parts[i] in mapping:
                return ".".join([*parts[:i], mapping[parts[i]], *parts[i:]])
        break
    return path


def _replace(obj, match: re.Match) -> str:
    target = match["target"].strip()
    name = target.lstrip("~!")
    label = name.lstrip(".").rsplit(".", 1)[-1] if target.startswith("~") else name.lstrip(".")
    if match["role"] in ("func", "meth"):
        label += "()"
    path = _resolve(obj, name)
    if path is None:
        return f"`{label}`"
    return f'<autoref identifier="{html.escape(path)}" optional><code>{html.escape(label)}</code></autoref>'


def _plain(text: str) -> str:
    """Roles as plain names, padded to the role's width (columns of a preformatted table stay aligned)."""
    def name(match):
        target = match["target"]
        label = target.lstrip("~!.").rsplit(".", 1)[-1] if target.startswith("~") else target.lstrip("!")
        return label.ljust(len(match[0]))

    return ROLE.sub(name, text)


def markdown(obj, text: str) -> str:
    """``text``, a docstring of ``obj``, with its reST rewritten for Markdown."""
    lines, out, table = text.split("\n"), [], None
    for number, line in enumerate(lines):
        if table is not None:
            table.append(_plain(line))
            ends = number + 1 == len(lines) or not lines[number + 1].strip()
            if RULE.match(line) and ends and len([t for t in table if RULE.match(t)]) >= 2:
                indent = re.match(r"\s*", table[0]).group()
                out += ["", f"{indent}```text", *table, f"{indent}```", ""]
                table = None
            continue
        if RULE.match(line):
            table = [line]
            continue
        line = ROLE.sub(lambda m: _replace(obj, m), line)
        if line.rstrip().endswith("::") and not line.strip() == "::":
            line = line.rstrip()[:-1]
        out.append(line)
    if table is not None:  # not a table after all
        out += [ROLE.sub(lambda m: _replace(obj, m), line) for line in table]
    return "\n".join(out)


class SphinxRoles(griffe.Extension):
    """Rewrite the reST of every docstring of a package once it is loaded."""

    def on_package(self, *, pkg, **kwargs) -> None:
        for obj in _walk(pkg):
            if obj.docstring is not None:
                obj.docstring.value = markdown(obj, obj.docstring.value)
