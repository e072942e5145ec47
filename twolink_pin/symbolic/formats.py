"""The equations written out: terminal text, a LaTeX document, JSON strings.

All three show what a person reads: ``M``, ``C``, ``g`` and ``Y`` of
:class:`~twolink_pin.symbolic.equations.Equations` with this arm's zero base parameters left
out (:meth:`~twolink_pin.symbolic.equations.Equations.shown`, said in a line), the base
parameters' definitions and values, the lengths and gravity.

* text: SymPy's one-line form with ``β1``, ``q̇1``, ``q̈1`` for ``beta1``, ``dq1``, ``ddq1``;
* LaTeX: a standalone ``amsmath`` document (long entries broken over lines at their terms),
  and :func:`latex_entry` for one formula (the report draws it as MathML);
* JSON: every expression as SymPy text with the ASCII names (``sympy.sympify`` reads it back),
  beside its LaTeX.
"""

from __future__ import annotations

import re
from typing import Any

from twolink_pin.symbolic.equations import Equations

LINE = 96
"""Longest LaTeX line of one formula [characters of source] before it is broken at a term."""


def _display_names(eq: Equations, latex: bool) -> dict[Any, Any]:
    """The symbols to show in place of the ASCII ones."""
    import sympy as sp

    out: dict[Any, Any] = {}
    for j, (dq, ddq, w) in enumerate(zip(eq.dq, eq.ddq, eq.w), start=1):
        out[dq] = rf"\dot{{q}}_{{{j}}}" if latex else f"q̇{j}"
        out[ddq] = rf"\ddot{{q}}_{{{j}}}" if latex else f"q̈{j}"
        out[w] = rf"\dot{{q}}_{{r,{j}}}" if latex else f"q̇r{j}"
    for k, b in enumerate(eq.beta, start=1):
        out[b] = rf"\beta_{{{k}}}" if latex else f"β{k}"
    if latex:
        for j, q in enumerate(eq.q, start=1):
            out[q] = f"q_{{{j}}}"
        for name in eq.lengths:
            out[sp.Symbol(name, real=True)] = f"l_{{{name[1:]}}}"
        for symbol in eq.standard:
            out[symbol] = _standard_latex(symbol.name)
    return out


def _standard_latex(name: str) -> str:
    """``mcx2`` → ``(m c_{x})_{2}``, ``Izz1`` → ``I_{zz,1}``, ``m3`` → ``m_{3}``."""
    body = name.rstrip("0123456789")
    index = name[len(body) :]
    if body == "m":
        return f"m_{{{index}}}"
    if body.startswith("mc"):
        return f"(m c_{{{body[2:]}}})_{{{index}}}"
    return f"I_{{{body[1:]},{index}}}"


_TEXT_NAMES = (
    (re.compile(r"\bbeta(\d+)"), "β\\1"),
    (re.compile(r"\bddq(\d+)"), "q̈\\1"),
    (re.compile(r"\bdq(\d+)"), "q̇\\1"),
    (re.compile(r"\bw(\d+)"), "q̇r\\1"),
)


def text_form(eq: Equations, expr: Any) -> str:
    """``expr`` as one line of text with the display names (the terms in SymPy's own order of
    the expression: parameters first, as a person writes them)."""
    import sympy as sp

    text = sp.sstr(expr, order="none")
    for pattern, name in _TEXT_NAMES:
        text = pattern.sub(name, text)
    return text


def latex_entry(eq: Equations, expr: Any) -> str:
    """``expr`` in LaTeX with the display names (one formula, no line breaks)."""
    import sympy as sp

    return sp.latex(expr, symbol_names=_display_names(eq, latex=True), order="none")


def _parameters_lines(eq: Equations) -> list[str]:
    zero = set(eq.zero_parameters)
    width = max((len(text_form(eq, d)) for d in eq.beta_definitions), default=0)
    lines = []
    for k, (definition, value, unit) in enumerate(zip(eq.beta_definitions, eq.beta_values, eq.beta_units)):
        note = "   (0 in this arm: its terms are not shown)" if k in zero else ""
        lines.append(f"  β{k + 1} = {text_form(eq, definition):<{width}} = {value:.6g} {unit}{note}")
    return lines


def _legend(eq: Equations) -> list[str]:
    bodies = ", ".join(f"{j} = {name.rsplit('.', 1)[0]}" for j, name in enumerate(eq.standard_names[::10], 1))
    lines = [
        "  with, for body j (the link joint j moves and the links fixed to it): mj [kg]; mcxj, mcyj, mczj [kg·m]",
        f"  (mass × centre of mass); Ixxj .. Izzj [kg·m²] (inertia about joint j's origin); bodies {bodies}",
    ]
    for name, value in eq.lengths.items():
        lines.append(f"  {name} = {value:.6g} m: {eq.length_meanings[name]}")
    lines.append(f"  g = {eq.gravity:.6g} m/s²")
    return lines


def _matrix_lines(eq: Equations, name: str, matrix: Any, symmetric: bool = False) -> list[str]:
    lines = []
    rows, cols = matrix.shape
    for r in range(rows):
        for c in range(cols):
            if symmetric and c < r:
                continue
            label = f"{name}{r + 1}" if cols == 1 else f"{name}{r + 1}{c + 1}"
            lines.append(f"  {label} = {text_form(eq, matrix[r, c])}")
    return lines


def equations_text(eq: Equations, source: str = "") -> str:
    """The equations as terminal text (module docstring)."""
    kinds = ", ".join(f"{name} ({kind})" for name, kind in zip(eq.joint_names, eq.kinds))
    how = "read from the cache" if eq.from_cache else f"derived in {eq.seconds:.2f} s"
    skew = "checked exactly" if eq.skew_symmetric else "NOT skew-symmetric: a bug, please report it"
    Y = eq.shown(eq.Y)
    lines = [
        f"{eq.robot}: equations of motion{f' of {source}' if source else ''} ({eq.n} joints: {kinds}; {how})",
        "",
        "  M(q) q̈ + C(q, q̇) q̇ + g(q) = Y(q, q̇, q̈) β = τ",
        "",
        f"base parameters β ({len(eq.beta)}):",
        *_parameters_lines(eq),
        *_legend(eq),
        "",
        "M(q), symmetric:",
        *_matrix_lines(eq, "M", eq.shown(eq.M), symmetric=True),
        f"C(q, q̇), from the Christoffel symbols (Ṁ − 2C skew-symmetric: {skew}):",
        *_matrix_lines(eq, "C", eq.shown(eq.C)),
        "g(q):",
        *_matrix_lines(eq, "g", eq.shown(eq.g)),
        f"Y(q, q̇, q̈), column k multiplies βk (entries not listed are 0{', as are the columns of zero β' if eq.zero_parameters else ''}):",
    ]
    for r in range(Y.rows):
        for k in range(Y.cols):
            if Y[r, k] != 0 and k not in eq.zero_parameters:
                lines.append(f"  Y{r + 1},{k + 1} = {text_form(eq, Y[r, k])}")
    return "\n".join(lines) + "\n"


def _signed(text: str) -> str:
    """A term as it continues a sum: ``+ a`` or ``- a``."""
    return f"- {text[1:].lstrip()}" if text.startswith("-") else f"+ {text}"


def _pieces(eq: Equations, expr: Any) -> list[str]:
    """LaTeX pieces of ``expr``, each at most about :data:`LINE` long where it can be split
    (at the terms of a sum, inside a product's one parenthesised sum), that read as ``expr``
    when written one after the other."""
    import sympy as sp

    text = latex_entry(eq, expr)
    if len(text) <= LINE:
        return [text]
    if isinstance(expr, sp.Add):
        out: list[str] = []
        for i, term in enumerate(sp.Add.make_args(expr)):
            pieces = _pieces(eq, term)
            out += [_signed(pieces[0]) if i else pieces[0], *pieces[1:]]
        return out
    sums = [f for f in expr.args if isinstance(f, sp.Add)] if isinstance(expr, sp.Mul) else []
    if len(sums) == 1:
        rest = sp.Mul(*[f for f in expr.args if f is not sums[0]])
        head = {"1": "", "-1": "-"}.get(latex_entry(eq, rest), latex_entry(eq, rest))
        inner = _pieces(eq, sums[0])
        inner[0] = rf"{head} \bigl( {inner[0]}".lstrip()
        inner[-1] += r" \bigr)"
        return inner
    return [text]


def _broken(eq: Equations, label: str, expr: Any) -> str:
    """One ``align*`` row, broken into lines of about :data:`LINE` (:func:`_pieces`)."""
    lines, current = [], ""
    for piece in _pieces(eq, expr):
        if current and len(current) + len(piece) > LINE:
            lines.append(current)
            current = piece
        else:
            current = f"{current} {piece}".strip()
    lines.append(current)
    return f"{label} &= {lines[0]}" + "".join(rf" \\ &\quad {line}" for line in lines[1:])


def equations_latex(eq: Equations, source: str = "") -> str:
    """A standalone LaTeX document of the equations (``pdflatex`` with ``amsmath``)."""
    zero = ", ".join(f"$\\beta_{{{k + 1}}}$" for k in eq.zero_parameters)
    units = [u.replace("·", r"\,").replace("²", "^{2}") for u in eq.beta_units]
    rows = [
        _broken(eq, rf"\beta_{{{k + 1}}}", d) + rf" \quad (= {v:.6g}\ \mathrm{{{u}}})"
        for k, (d, v, u) in enumerate(zip(eq.beta_definitions, eq.beta_values, units))
    ]
    sections = [("Base parameters", rows)]
    for title, name, matrix, sym in (
        ("The inertia matrix $M(q)$ (symmetric)", "M", eq.M, True),
        (r"The Coriolis matrix $C(q, \dot q)$ (Christoffel symbols)", "C", eq.C, False),
        ("Gravity $g(q)$", "g", eq.g, False),
        (r"The regressor $Y(q, \dot q, \ddot q)$", "Y", eq.Y, False),
    ):
        shown = eq.shown(matrix)
        entries = []
        for r in range(shown.rows):
            for c in range(shown.cols):
                if (sym and c < r) or (name == "Y" and (shown[r, c] == 0 or c in eq.zero_parameters)):
                    continue
                label = f"{name}_{{{r + 1}}}" if shown.cols == 1 else f"{name}_{{{r + 1},{c + 1}}}"
                entries.append(_broken(eq, label, shown[r, c]))
        sections.append((title, entries))
    body = []
    for title, entries in sections:
        body.append(rf"\section*{{{title}}}")
        body.append("\\begin{align*}\n" + " \\\\\n".join(entries) + "\n\\end{align*}")
    lengths = ", ".join(rf"$l_{{{n[1:]}}} = {v:.6g}$ m" for n, v in eq.lengths.items())
    return "\n".join(
        [
            r"\documentclass{article}",
            r"\usepackage[margin=2cm,landscape]{geometry}",
            r"\usepackage{amsmath}",
            r"\allowdisplaybreaks",  # a long align* (a 3-joint arm's C) breaks across pages
            r"\begin{document}",
            rf"\title{{Equations of motion of {_escape(eq.robot)}}}\date{{}}\maketitle",
            r"$$M(q)\,\ddot q + C(q, \dot q)\,\dot q + g(q) = Y(q, \dot q, \ddot q)\,\beta = \tau$$",
            _escape(f"Derived from {source or eq.robot} by twolink-pin equations; ")
            + (f"{lengths}; " if lengths else "")
            + rf"$g = {eq.gravity:.6g}$ m/s$^2$."
            + (f" Zero in this arm, not shown: {zero}." if zero else ""),
            *body,
            r"\end{document}",
            "",
        ]
    )


def _escape(text: str) -> str:
    """Plain text safe in LaTeX."""
    for char, escaped in (
        ("\\", r"\textbackslash{}"),
        ("_", r"\_"),
        ("&", r"\&"),
        ("%", r"\%"),
        ("#", r"\#"),
        ("$", r"\$"),
    ):
        text = text.replace(char, escaped)
    return text


def equations_json(eq: Equations, source: str = "") -> dict[str, Any]:
    """The equations as JSON-ready data (module docstring)."""
    import sympy as sp

    def strings(matrix: Any) -> list[list[str]]:
        return [[sp.sstr(matrix[r, c], order="none") for c in range(matrix.cols)] for r in range(matrix.rows)]

    def latexes(matrix: Any) -> list[list[str]]:
        return [[latex_entry(eq, matrix[r, c]) for c in range(matrix.cols)] for r in range(matrix.rows)]

    return {
        "robot": eq.robot,
        "source": source,
        "joints": [{"name": n, "kind": k} for n, k in zip(eq.joint_names, eq.kinds)],
        "symbols": {
            "q": [str(s) for s in eq.q],
            "dq": [str(s) for s in eq.dq],
            "ddq": [str(s) for s in eq.ddq],
            "w": [str(s) for s in eq.w],
        },
        "base_parameters": [
            {
                "symbol": str(b),
                "definition": sp.sstr(d, order="none"),
                "latex": latex_entry(eq, d),
                "value": float(v),
                "unit": u,
            }
            for b, d, v, u in zip(eq.beta, eq.beta_definitions, eq.beta_values, eq.beta_units)
        ],
        "zero_base_parameters": [str(eq.beta[k]) for k in eq.zero_parameters],
        "standard_parameters": [
            {"symbol": str(s), "name": n, "value": float(v)}
            for s, n, v in zip(eq.standard, eq.standard_names, eq.standard_values)
        ],
        "lengths": [
            {"symbol": n, "value": v, "meaning": eq.length_meanings[n]} for n, v in eq.lengths.items()
        ],
        "gravity": eq.gravity,
        "M": strings(eq.M),
        "C": strings(eq.C),
        "g": [row[0] for row in strings(eq.g)],
        "Y": strings(eq.Y),
        "Y_reference": strings(eq.Y_reference),
        "latex": {
            "M": latexes(eq.M),
            "C": latexes(eq.C),
            "g": [row[0] for row in latexes(eq.g)],
            "Y": latexes(eq.Y),
        },
        "skew_symmetric": eq.skew_symmetric,
        "seconds": eq.seconds,
        "from_cache": eq.from_cache,
    }
