r"""LaTeX math in text, turned into MathML that a browser draws with no script and no network.

The documentation site (its Markdown pages and the docstrings of the API reference) and
any HTML page the package writes share one notation: ``$…$`` for inline math and
``$$…$$`` for a displayed formula, in LaTeX, as in the control laws' docstrings::

    $$\tau = M(q)\,\ddot q_d + C(q, \dot q)\,\dot q_d + g(q) - K_p e - K_d \dot e$$

:func:`render_math` replaces each of them by a ``<math>`` element (MathML Core, drawn
natively by Chromium ≥ 109, Firefox and Safari), converted here in Python by
``latex2mathml``: the page carries no MathJax or KaTeX and fetches nothing. A ``$`` that
opens inline math is followed by a non-space and the closing one is preceded by a
non-space and not followed by a digit (so "costs $5 and $6" stays text); ``\$`` is a
literal dollar sign.

Imports nothing from the rest of the package but its exceptions (any layer may use it);
``latex2mathml`` is imported when the first formula is converted.
"""

from __future__ import annotations

import functools
import html
import re
from typing import Any

from twolink_pin.errors import InvalidParameterError

DISPLAY_MATH = re.compile(r"\$\$(?P<tex>.+?)\$\$", re.DOTALL)
"""``$$…$$``: a displayed formula (may span lines)."""

INLINE_MATH = re.compile(r"(?<![\\$])\$(?![\s$])(?P<tex>(?:\\.|[^$\\\n])+?)(?<![\s\\])\$(?![\d$])")
"""``$…$`` on one line: no space just inside the dollars, no digit just after the closing one."""

ESCAPED_DOLLAR = re.compile(r"\\\$")
r"""``\$``: a literal dollar sign."""


@functools.lru_cache(maxsize=4096)
def latex_to_mathml(latex: str, *, display: bool = False) -> str:
    r"""One LaTeX formula as a ``<math>`` element.

    Args:
        latex: The formula without its dollar signs, e.g. ``r"\dot s = -K s"``.
        display: ``True`` for a displayed (block) formula, ``False`` for inline math.

    Returns:
        The MathML markup, one line, with the LaTeX source kept in an
        ``<annotation encoding="application/x-tex">`` (what a screen reader or a copy
        offers) and ``alttext``.

    Raises:
        InvalidParameterError: ``latex`` is empty or not a formula ``latex2mathml``
            understands (the error keeps it as ``value``).
    """
    from latex2mathml.converter import convert

    source = latex.strip()
    if not source:
        raise InvalidParameterError("latex", latex, "a non-empty LaTeX formula")
    try:
        markup = convert(source, display="block" if display else "inline")
    except Exception as error:  # latex2mathml raises its own exception types and bare IndexErrors
        reason = f"{type(error).__name__}: {error}"
        raise InvalidParameterError(
            "latex", latex, f"a formula latex2mathml can convert ({reason})"
        ) from None
    tex = html.escape(source, quote=True)
    body = markup.removesuffix("</math>")
    start = body.index(">") + 1
    head = body[:start].replace("<math ", f'<math alttext="{tex}" ', 1)
    inner = body[start:]
    return (
        f"{head}<semantics><mrow>{inner}</mrow>"
        f'<annotation encoding="application/x-tex">{tex}</annotation></semantics></math>'
    )


def render_math(text: str) -> str:
    r"""Replace every ``$$…$$`` and ``$…$`` in ``text`` by its MathML; ``\$`` becomes ``$``.

    ``text`` is HTML or plain text; it is not otherwise changed (the caller escapes it
    first if it is plain text with ``<`` or ``&``). A Markdown page is converted by the
    site's Markdown extension instead, which leaves code spans and code blocks alone.

    Args:
        text: Text with LaTeX formulas between dollar signs.

    Returns:
        The text with ``<math>`` elements in place of the formulas.

    Raises:
        InvalidParameterError: a formula cannot be converted (the error keeps its LaTeX).
    """
    text = DISPLAY_MATH.sub(lambda m: latex_to_mathml(m["tex"], display=True), text)
    text = INLINE_MATH.sub(lambda m: latex_to_mathml(m["tex"]), text)
    return ESCAPED_DOLLAR.sub("$", text)


MATH = re.compile(
    f"{ESCAPED_DOLLAR.pattern}|{DISPLAY_MATH.pattern}|{INLINE_MATH.pattern.replace('(?P<tex>', '(?P<itex>')}",
    re.DOTALL,
)
r"""Any of ``\$``, ``$$…$$`` (group ``tex``) and ``$…$`` (group ``itex``)."""


def markdown_extension(error: type[Exception] = InvalidParameterError) -> Any:
    """A Python-Markdown extension that turns ``$…$`` and ``$$…$$`` into MathML (code spans
    and code blocks left alone: its pattern runs just after code spans). A formula that
    does not convert raises ``error`` with the formula (the site's build passes its own
    error type, so that the build fails with the page named)."""
    from markdown import Extension
    from markdown.inlinepatterns import InlineProcessor

    class _MathProcessor(InlineProcessor):
        def handleMatch(self, m: re.Match[str], data: str) -> tuple[Any, int, int]:
            if m.group(0) == "\\$":
                return "$", m.start(0), m.end(0)
            display = m.group("tex") is not None
            latex = m.group("tex") if display else m.group("itex")
            try:
                markup = latex_to_mathml(latex, display=display)
            except InvalidParameterError as problem:
                raise error(f"math: {problem}") from None
            return self.md.htmlStash.store(markup), m.start(0), m.end(0)

    class MathExtension(Extension):
        def extendMarkdown(self, md: Any) -> None:
            md.inlinePatterns.register(_MathProcessor(MATH.pattern, md), "twolink_math", 185)

    return MathExtension()


ROLE = re.compile(r":(?:py:)?(?:class|func|meth|attr|mod|data|exc|obj):`~?(?:[\w.]+\.)?(?P<name>[\w]+)`")
"""A Sphinx role such as ``:class:`~twolink_pin.controllers.ComputedTorque```."""


def docstring_html(text: str) -> str:
    """A docstring as HTML, as the site shows it: Markdown (the package's docstrings are
    Markdown-compatible: ``code``, *emphasis*, lists), its math as MathML, Sphinx roles as
    code (``:class:`X``` → ``X``). Raw HTML in the docstring is shown as text (escaped
    outside the formulas), so a law's docstring cannot inject markup into a page."""
    import markdown

    text = ROLE.sub(lambda m: f"``{m['name']}``", text)
    text = text.replace("::\n", ":\n")  # an RST literal-block marker: the indented block follows
    parts, last = [], 0
    for m in MATH.finditer(text):
        parts.append(html.escape(text[last : m.start()], quote=False))
        parts.append(m.group(0))
        last = m.end()
    parts.append(html.escape(text[last:], quote=False))
    return markdown.markdown("".join(parts), extensions=[markdown_extension()])


__all__ = [
    "DISPLAY_MATH",
    "ESCAPED_DOLLAR",
    "INLINE_MATH",
    "MATH",
    "docstring_html",
    "latex_to_mathml",
    "markdown_extension",
    "render_math",
]
