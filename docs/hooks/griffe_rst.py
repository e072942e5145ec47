"""Griffe extension: the reStructuredText habits of our docstrings, turned into Markdown.

The package's docstrings are Google style (``Args:``, ``Returns:``, ``Raises:``, parsed
by griffe) with a few reStructuredText constructs that ``help()`` shows well and Markdown
does not know. Before mkdocstrings renders a docstring, this extension rewrites:

* roles, ``:func:`write_html``` and ``:class:`~pathlib.Path``` (also ``:meth:``,
  ``:attr:``, ``:data:``, ``:mod:``, ``:exc:``): a cross-reference
  ``[`write_html`][twolink_pin.visualization.html.write_html]`` when the name resolves,
  from the docstring's scope, to a public object of the package, else plain code
  (``~`` keeps the last component, as in Sphinx);
* literal blocks, a paragraph ending in ``::`` followed by an indented block: a fenced
  code block (``python`` when the block parses as Python, else ``text``), the ``::``
  becoming ``:``;
* simple tables (``====  ====`` borders, two columns, no header): a bullet list
  ``- first column: second column``;
* an ``Args:`` entry for several names at once (``q, v, a: …``, numpydoc's habit): one
  entry per name, each with the text.

The source files are not changed. Loaded by mkdocstrings (``extensions:`` in mkdocs.yml).
"""

from __future__ import annotations

import ast
import re
import textwrap
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?(?P<role>func|class|meth|attr|data|mod|exc|obj|const):`(?P<target>[^`]+)`")
BORDER = re.compile(r"^(?P<indent> *)=+(?: +=+)+ *$")


def _is_public(path: str) -> bool:
    return not any(part.startswith("_") and not part.startswith("__") for part in path.split("."))


def _resolve(obj: griffe.Object, name: str, collection: griffe.ModulesCollection) -> str | None:
    """The full path of ``name`` as written in ``obj``'s docstring, if it is a public object
    of a loaded package; else ``None``."""
    first, _, rest = name.partition(".")
    scopes: list[griffe.Object] = [obj]
    while scopes[-1].parent is not None:
        scopes.append(scopes[-1].parent)
    base = None
    for scope in scopes:
        if first in scope.members:
            base = scope.members[first].path
            break
    if base is None:
        try:
            base = obj.resolve(first)
        except (griffe.NameResolutionError, Exception):  # griffe raises a few kinds here
            base = first
    path = f"{base}.{rest}" if rest else base
    try:
        target = collection[path]
    except (KeyError, ValueError, griffe.AliasResolutionError, griffe.CyclicAliasError):
        return None
    try:
        final = target.final_target.path if target.is_alias else target.path
    except (griffe.AliasResolutionError, griffe.CyclicAliasError):
        return None
    return path if _is_public(final) and _is_public(path) else None


def convert_roles(text: str, obj: griffe.Object, collection: griffe.ModulesCollection) -> str:
    """Sphinx roles in ``text`` as Markdown cross-references or code."""

    def replace(match: re.Match[str]) -> str:
        target = match["target"].strip()
        shown = None
        if target.endswith(">") and "<" in target:  # :func:`text <target>`
            shown, target = target[:-1].split("<", 1)
            shown, target = shown.strip(), target.strip()
        short = target.startswith("~")
        target = target.lstrip("~.")
        if shown is None:
            shown = target.rsplit(".", 1)[-1] if short else target
        path = _resolve(obj, target, collection)
        return f"[`{shown}`][{path}]" if path else f"`{shown}`"

    return ROLE.sub(replace, text)


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip(" "))


def convert_literal_blocks(text: str) -> str:
    """``paragraph::`` + blank line + indented block → ``paragraph:`` + a fenced block."""
    lines = text.split("\n")
    out: list[str] = []
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.rstrip().endswith("::") and i + 1 < len(lines) and not lines[i + 1].strip():
            base = _indent(line)
            j = i + 1
            while j < len(lines) and not lines[j].strip():
                j += 1
            k = j
            while k < len(lines) and (not lines[k].strip() or _indent(lines[k]) > base):
                k += 1
            while k > j and not lines[k - 1].strip():
                k -= 1
            if k > j:
                head = line.rstrip()[:-2].rstrip()
                out.append(" " * base + head + ":" if head.strip() else "")
                block = textwrap.dedent("\n".join(lines[j:k]))
                try:
                    ast.parse(block)
                    language = "python"
                except SyntaxError:
                    language = "text"
                pad = " " * base
                out += [
                    "",
                    f"{pad}```{language}",
                    *(pad + b if b else "" for b in block.split("\n")),
                    f"{pad}```",
                ]
                i = k
                continue
        out.append(line)
        i += 1
    return "\n".join(out)


def convert_simple_tables(text: str) -> str:
    """Two-column, headerless RST simple tables → ``- first: second`` bullet lists."""
    lines = text.split("\n")
    out: list[str] = []
    i = 0
    while i < len(lines):
        border = BORDER.match(lines[i])
        end = next((j for j in range(i + 1, len(lines)) if BORDER.match(lines[j])), None) if border else None
        if border is None or end is None:
            out.append(lines[i])
            i += 1
            continue
        indent = len(border["indent"])
        split = lines[i].index(" ", indent)
        while lines[i][split] == " ":
            split += 1
        items: list[list[str]] = []
        for row in lines[i + 1 : end]:
            first, second = row[:split].strip(), row[split:].strip()
            if first:
                items.append([first, second])
            elif items and second:
                items[-1][1] += " " + second
        out += [f"{' ' * indent}- {a}: {b}" if b else f"{' ' * indent}- {a}" for a, b in items]
        i = end + 1
    return "\n".join(out)


SECTION = re.compile(r"^(?P<indent> *)(?:Args|Arguments|Parameters|Attributes):\s*$")
GROUPED = re.compile(r"^(?P<names>[A-Za-z_]\w*(?: *, *[A-Za-z_]\w*)+)(?P<rest>(?: *\([^)]*\))?:.*)$")


def split_grouped_parameters(text: str) -> str:
    """``q, v, a: text`` in an ``Args:`` section → one entry per name, each with the text
    (Google style documents one name per entry; griffe would see a parameter ``'q, v, a'``)."""
    lines = text.split("\n")
    out: list[str] = []
    i = 0
    section_indent: int | None = None
    item_indent: int | None = None
    while i < len(lines):
        line = lines[i]
        header = SECTION.match(line)
        if header:
            section_indent, item_indent = len(header["indent"]), None
            out.append(line)
            i += 1
            continue
        if section_indent is not None and line.strip():
            indent = _indent(line)
            if indent <= section_indent:
                section_indent = None
            elif item_indent is None:
                item_indent = indent
        grouped = (
            GROUPED.match(line.strip())
            if section_indent is not None and _indent(line) == item_indent
            else None
        )
        if grouped is None:
            out.append(line)
            i += 1
            continue
        j = i + 1
        while j < len(lines) and (not lines[j].strip() or _indent(lines[j]) > (item_indent or 0)):
            j += 1
        while j > i + 1 and not lines[j - 1].strip():
            j -= 1
        for name in (n.strip() for n in grouped["names"].split(",")):
            out.append(" " * (item_indent or 0) + name + grouped["rest"])
            out += lines[i + 1 : j]
        i = j
    return "\n".join(out)


class RstToMarkdown(griffe.Extension):
    """Rewrite every docstring of the loaded package once all its modules are loaded."""

    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader, **kwargs: Any) -> None:
        seen: set[int] = set()

        def visit(obj: griffe.Object) -> None:
            if id(obj) in seen:
                return
            seen.add(id(obj))
            if obj.docstring is not None:
                value = split_grouped_parameters(obj.docstring.value)
                value = convert_simple_tables(value)
                value = convert_literal_blocks(value)
                obj.docstring.value = convert_roles(value, obj, loader.modules_collection)
            for member in obj.members.values():
                if not member.is_alias:
                    visit(member)  # type: ignore[arg-type]

        visit(pkg)
