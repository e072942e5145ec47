"""The equations as a standalone Python module: numpy only, no twolink-pin.

:func:`numpy_module` writes the source of a module with

* ``M(q, p=None, out=None)``, ``C(q, v, p=None, out=None)``, ``g(q, p=None, out=None)`` and
  ``Y(q, v, a, w=None, out=None)`` — so that ``Y(q, v, a) @ p_base`` is the inverse dynamics
  ``M a + C v + g``, and ``Y(q, v, a, w) @ p`` is ``M a + C(q, v) w + g`` (Slotine–Li);
* ``p_base``, this arm's base parameters, and ``BASE_PARAMETERS``, their definitions; any
  other values (an estimate) can be passed as ``p``;
* the lengths [m] and ``GRAVITY`` [m/s²] as module constants, each with its meaning.

Each function takes one state (``q`` of shape (n,)) or a batch (shape (N, n); then
``(N, n, n)``, ``(N, n)``, ``(N, n, r)`` out). One state runs on Python floats and ``math``
(a twolink ``M(q, out=buffer)`` costs about what ``pin.crba`` does from Python), a batch on
numpy arrays (per state, a small fraction of that: ``scripts/benchmark.py --equations``).
Common subexpressions are computed once (``sympy.cse``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin.symbolic.equations import Equations

_HELPERS = """
def _vector(x, name):
    x = _np.asarray(x, dtype=float)
    if x.ndim == 0 or x.shape[-1] != N_JOINTS:
        raise ValueError(f"{name} must have shape ({N_JOINTS},) or (N, {N_JOINTS}), got {x.shape}")
    return x


def _parameters(p):
    if p is None:
        return _P_BASE
    p = _np.asarray(p, dtype=float)
    if p.shape != p_base.shape:
        raise ValueError(f"p must have shape {p_base.shape} (the base parameters), got {p.shape}")
    return tuple(p.tolist())


def _output(out, shape, clear):
    if out is None:
        return _np.zeros(shape) if clear else _np.empty(shape)
    if not isinstance(out, _np.ndarray) or out.shape != shape or out.dtype != float:
        raise ValueError(f"out must be a float array of shape {shape}, got {getattr(out, 'shape', out)!r}")
    if clear:
        out.fill(0.0)
    return out
"""


@dataclass(frozen=True)
class _Function:
    """One function of the generated module."""

    name: str
    state: tuple[tuple[str, tuple[Any, ...]], ...]
    """Its state arguments and the symbols each unpacks into."""
    matrix: Any
    symmetric: bool
    doc: str
    parameters: bool = True
    """Whether it takes ``p`` (the regressor does not)."""
    reference: bool = False
    """Whether it takes ``w`` (the regressor's reference rate, default ``v``)."""


def _entries(f: _Function) -> list[tuple[tuple[int, ...], Any]]:
    out: list[tuple[tuple[int, ...], Any]] = []
    for r in range(f.matrix.rows):
        for c in range(f.matrix.cols):
            if (f.symmetric and c < r) or f.matrix[r, c] == 0:
                continue
            out.append(((r,) if f.name == "g" else (r, c), f.matrix[r, c]))
    return out


def _statements(
    entries: list[tuple[tuple[int, ...], Any]], symmetric: bool, batch: bool, indent: str
) -> list[str]:
    """The statements computing every entry into ``out`` (common subexpressions first): on
    Python floats with ``math`` for one state, on arrays with numpy for a batch."""
    import sympy as sp
    from sympy.printing.pycode import PythonCodePrinter

    printer = PythonCodePrinter({"fully_qualified_modules": False})
    gravity = {sp.Symbol("g", positive=True): sp.Symbol("GRAVITY")}
    replacements, reduced = sp.cse(
        [e.xreplace(gravity) for _, e in entries], symbols=sp.numbered_symbols("_x")
    )
    functions = ("_np.cos(", "_np.sin(") if batch else ("_cos(", "_sin(")

    def code(expr: Any) -> str:  # the printer writes cos(…) and sin(…); no symbol name has a "("
        text = printer.doprint(expr)
        return text.replace("cos(", functions[0]).replace("sin(", functions[1])

    lines = [f"{indent}{printer.doprint(s)} = {code(e)}" for s, e in replacements]
    at = "..., " if batch else ""
    for (index, _), expr in zip(entries, reduced):
        mirror = f"out[{at}{index[1]}, {index[0]}] = " if symmetric and index[0] != index[1] else ""
        lines.append(f"{indent}out[{at}{', '.join(map(str, index))}] = {mirror}{code(expr)}")
    return lines


def _shape(f: _Function) -> str:
    """The output's trailing shape as Python source: ``2, 2`` or ``2,``."""
    rows, cols = f.matrix.shape
    return f"{rows}," if cols == 1 and f.name == "g" else f"{rows}, {cols}"


def _source(f: _Function, beta: tuple[Any, ...]) -> str:
    """The function's source (see the module docstring). One state given as numpy vectors takes
    the fast path (Python floats); anything else is converted, checked, and either comes back
    to it or is computed as a batch. With ``reference``, the last state argument is ``w``,
    optional (default ``v``)."""
    state = [a for a, _ in f.state]
    required = state[:-1] if f.reference else state
    extra = (["w=None"] if f.reference else []) + (["p=None"] if f.parameters else []) + ["out=None"]
    call = ", ".join(required + [e.split("=")[0] for e in extra])
    entries = _entries(f)
    full = f.matrix.rows * (f.matrix.rows + 1) // 2 if f.symmetric else f.matrix.rows * f.matrix.cols
    clear = len(entries) < full
    vector = "(N_JOINTS,)"
    lines = [f"def {f.name}({', '.join(required + extra)}):", f'    """{f.doc}"""']
    if f.reference:
        lines.append("    if w is None:")
        lines.append("        w = v")
    lines.append(
        f"    if {' and '.join(f'{a}.__class__ is _ndarray and {a}.shape == {vector}' for a in state)}:"
    )
    lines += [f"        {', '.join(str(s) for s in symbols)}, = {a}.tolist()" for a, symbols in f.state]
    if f.parameters:
        lines.append(f"        {', '.join(str(b) for b in beta)}, = _P_BASE if p is None else _parameters(p)")
    lines.append("        if out is None:")
    lines.append(f"            out = {'_zeros' if clear else '_empty'}(({_shape(f)}))")
    lines.append(
        f"        elif out.__class__ is not _ndarray or out.shape != ({_shape(f)}){' or True' if clear else ''}:"
    )
    lines.append(f"            out = _output(out, ({_shape(f)}), {clear})")
    lines += _statements(entries, f.symmetric, batch=False, indent="        ")
    lines.append("        return out")
    lines += [f"    {a} = _vector({a}, {a!r})" for a in state]
    lines.append(f"    if {' and '.join(f'{a}.ndim == 1' for a in state)}:")
    lines.append(f"        return {f.name}({call})")
    if f.parameters:
        lines.append(f"    {', '.join(str(b) for b in beta)}, = _parameters(p)")
    lines += [
        f"    {', '.join(str(s) for s in symbols)}, = _np.moveaxis({a}, -1, 0)" for a, symbols in f.state
    ]
    batch = ", ".join(f"{a}.shape[:-1]" for a in state)
    lines.append(f"    out = _output(out, _np.broadcast_shapes({batch}) + ({_shape(f)}), {clear})")
    lines += _statements(entries, f.symmetric, batch=True, indent="    ")
    lines.append("    return out")
    return "\n".join(lines)


def _header(eq: Equations, source: str) -> list[str]:
    from twolink_pin.version import __version__

    zero = ", ".join(str(eq.beta[k]) for k in eq.zero_parameters)
    definitions = [
        f"    {b} = {d}   [{u}]"
        for b, d, u in zip(eq.beta, (str(x) for x in eq.beta_definitions), eq.beta_units)
    ]
    return [
        f'"""Equations of motion of the {eq.robot} arm in closed form, written by twolink-pin {__version__}',
        f"(``twolink-pin equations --python``) from {source or eq.robot}. Needs numpy only.",
        "",
        "    M(q) a + C(q, v) v + g(q) = Y(q, v, a) @ p_base = tau",
        "",
        "q [rad or m], v = dq/dt, a = d2q/dt2, tau [N·m or N]; one state of shape (n,) or a batch of",
        "shape (N, n). ``p`` (default ``p_base``, this arm's) are the base parameters:",
        "",
        *definitions,
        "",
        "with, for body j: mj the mass, mcxj.. the first moment (mass × centre of mass), Ixxj.. the",
        "inertia about joint j's origin, in joint j's frame; the lengths are the constants below.",
        f"Zero in this arm: {zero}." if zero else "",
        "",
        "``Y(q, v, a, w) @ p`` is ``M(q) a + C(q, v) w + g(q)`` (Slotine–Li: w = the reference rate).",
        "C is built from the Christoffel symbols: dM/dt - 2 C is skew-symmetric.",
        '"""',
        "",
        "from math import cos as _cos",
        "from math import sin as _sin",
        "",
        "import numpy as _np",
        "from numpy import empty as _empty",
        "from numpy import ndarray as _ndarray",
        "from numpy import zeros as _zeros",
        "",
        f"N_JOINTS = {eq.n}",
        f"JOINT_NAMES = {tuple(eq.joint_names)!r}",
        f"GRAVITY = {eq.gravity!r}  # [m/s²]",
        *[f"{name} = {value!r}  # [m] {eq.length_meanings[name]}" for name, value in eq.lengths.items()],
        f"BASE_PARAMETERS = {tuple(str(d) for d in eq.beta_definitions)!r}",
        f"BASE_PARAMETER_UNITS = {tuple(eq.beta_units)!r}",
        f"p_base = _np.array({[float(x) for x in eq.beta_values]!r})",
        "p_base.setflags(write=False)",
        "_P_BASE = tuple(p_base.tolist())",
    ]


def numpy_module(eq: Equations, source: str = "") -> str:
    """The source of the standalone module of ``eq`` (module docstring)."""
    q, v, a = ("q", eq.q), ("v", eq.dq), ("a", eq.ddq)
    functions = [
        _Function("M", (q,), eq.M, True, "The inertia matrix M(q), shape (n, n) or (N, n, n)."),
        _Function("C", (q, v), eq.C, False, "C(q, v) (Christoffel symbols), shape (n, n) or (N, n, n)."),
        _Function("g", (q,), eq.g, False, "Gravity g(q), shape (n,) or (N, n)."),
        _Function(
            "Y",
            (q, v, a, ("w", eq.w)),
            eq.Y_reference,
            False,
            "Y with Y @ p = M(q) a + C(q, v) w + g(q) (w default v), shape (n, r) or (N, n, r).",
            parameters=False,
            reference=True,
        ),
    ]
    parts = ["\n".join(_header(eq, source)), _HELPERS.strip()] + [_source(f, eq.beta) for f in functions]
    return "\n\n\n".join(parts) + "\n"
