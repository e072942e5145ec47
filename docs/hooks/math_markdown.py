"""MkDocs hook: ``$…$`` and ``$$…$$`` in the pages and in the docstrings become MathML.

The conversion is :func:`twolink_pin.mathml.latex_to_mathml` (``latex2mathml``, in Python,
at build time): the site carries no MathJax or KaTeX and the browser fetches nothing to
draw a formula. The Markdown extension below is added to the site's extensions before
mkdocstrings reads them (``on_config`` at high priority), so the API reference's
docstrings go through it too. Math inside code spans and code blocks is left alone (the
code-span pattern runs first, and code blocks are never inline-processed). A formula that
does not convert fails the build with the page and the formula.
"""

from __future__ import annotations

from typing import Any

from mkdocs.config.defaults import MkDocsConfig
from mkdocs.exceptions import PluginError
from mkdocs.plugins import event_priority

from twolink_pin.mathml import markdown_extension


def MathExtension() -> Any:
    """The package's Markdown math extension, failing the build on a bad formula."""
    return markdown_extension(error=PluginError)


@event_priority(100)  # before mkdocstrings copies the extension list for its docstrings
def on_config(config: MkDocsConfig) -> MkDocsConfig:
    config.markdown_extensions.append(MathExtension())  # Markdown takes instances beside names
    return config
