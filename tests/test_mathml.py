"""Tests of twolink_pin.mathml: LaTeX between dollar signs becomes MathML the browser draws,
the LaTeX kept as an annotation; text that only looks like math is left alone; a formula
that cannot be converted is an InvalidParameterError naming it."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import pytest

from twolink_pin.errors import InvalidParameterError
from twolink_pin.mathml import latex_to_mathml, render_math

MATHML = "{http://www.w3.org/1998/Math/MathML}"


def test_formula_is_wellformed_mathml_keeping_its_latex() -> None:
    """One ``<math>`` element (well-formed XML) with ``display``, ``alttext`` and the LaTeX
    source as its ``application/x-tex`` annotation."""
    latex = r"\tau = M(q)\,\ddot q_d - K_p e"
    for display, mode in ((True, "block"), (False, "inline")):
        root = ET.fromstring(latex_to_mathml(latex, display=display))
        assert root.tag == f"{MATHML}math" and root.get("display") == mode
        assert root.get("alttext") == latex
        annotation = root.find(f"{MATHML}semantics/{MATHML}annotation")
        assert annotation is not None and annotation.text == latex
        assert annotation.get("encoding") == "application/x-tex"


def test_render_math_replaces_display_then_inline_formulas() -> None:
    """``$$…$$`` (across lines) becomes a block formula, ``$…$`` an inline one; the text
    around them is unchanged."""
    out = render_math("Law:\n$$\n\\tau = -K s\n$$\nwith $s = \\dot e + \\lambda e$ here.")
    assert out.startswith("Law:\n<math ") and out.endswith(" here.")
    assert [m for m in re.findall(r'display="(\w+)"', out)] == ["block", "inline"]
    assert "$" not in out


@pytest.mark.parametrize(
    "text",
    ["costs $5 and $6", "a $ b $ c", "price: $ 3", "no math here", "a lone $$ pair opener"],
)
def test_text_that_only_looks_like_math_is_kept(text: str) -> None:
    """A ``$`` before a digit or a space, or after a space when closing, opens no formula;
    an unpaired ``$$`` is text."""
    assert render_math(text) == text


def test_escaped_dollar_is_a_dollar_sign() -> None:
    assert render_math(r"\$5, and $x$ costs \$3") == "$5, and " + latex_to_mathml("x") + " costs $3"


@pytest.mark.parametrize(
    ("latex", "message"),
    [
        ("  ", r"latex = '  ' is invalid: expected a non-empty LaTeX formula"),
        (r"\frac{", r"latex = '\\\\frac\{' is invalid: expected a formula latex2mathml can convert \("),
    ],
)
def test_bad_formula_is_an_invalid_parameter_error(latex: str, message: str) -> None:
    with pytest.raises(InvalidParameterError, match=message) as caught:
        latex_to_mathml(latex)
    assert caught.value.value == latex
