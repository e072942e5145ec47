"""The course report's equations as formulas, and the derived ones written in its parameters.

The report writes the planar 2R arm's dynamics by hand in three lumped parameters::

    M = [[p1 + 2 p3 cos θ2, p2 + p3 cos θ2], [p2 + p3 cos θ2, p2]]
    C = [[−p3 θ̇2 sin θ2, −p3 (θ̇1 + θ̇2) sin θ2], [p3 θ̇1 sin θ2, 0]]
    Y p = M θ̈r + C θ̇r,   Y = [Y1 Y2 Y3]  (Y3's lower-left entry with the sign corrected)

with, for link i of mass m_i, centre of mass at c_i along the link and inertia Izz_i about
it (``docs/model.md``, the URDF's comment)::

    p2 = Izz2 + m2 c2²,   p3 = m2 L1 c2,   p1 = Izz1 + m1 c1² + m2 L1² + p2.

:func:`course_parameters` **finds** p from the derivation (:mod:`twolink_pin.symbolic`): it
solves ``M_derived(β) = M_course(p)`` for p, coefficient by coefficient of 1, cos q2 and
sin q2, giving p as combinations of the base parameters (``p1 = β1 + β4``, ``p2 = β4``,
``p3 = l2x β2``). :func:`course_check` then compares, symbolically, M, C and Y so written with
the report's, and p so found, in masses and lengths, with the report's expressions.
:mod:`~twolink_pin.twolink.closed_form` stays the independent numerical check it is.
"""

from __future__ import annotations

from typing import Any

COURSE_SYMBOLS = "p1 p2 p3 m1 m2 c1 c2 Izz1c Izz2c L1"
"""The report's symbols: the lumped parameters, the masses [kg], the centres of mass along
the links [m], the inertias about the centres of mass [kg·m²] and the first link's length [m]."""


def course_matrices(q: Any, dq: Any, ddq: Any, w: Any) -> dict[str, Any]:
    """The report's M, C and Y (columns Y1, Y2, Y3, of ``M ddq + C(q, dq) w``) in p1, p2, p3."""
    import sympy as sp

    p1, p2, p3 = sp.symbols("p1 p2 p3", real=True)
    c2, s2 = sp.cos(q[1]), sp.sin(q[1])
    M = sp.Matrix([[p1 + 2 * p3 * c2, p2 + p3 * c2], [p2 + p3 * c2, p2]])
    C = sp.Matrix([[-p3 * dq[1] * s2, -p3 * (dq[0] + dq[1]) * s2], [p3 * dq[0] * s2, 0]])
    Y = sp.Matrix(
        [
            [ddq[0], ddq[1], 2 * c2 * ddq[0] + c2 * ddq[1] - s2 * dq[1] * w[0] - s2 * (dq[0] + dq[1]) * w[1]],
            [0, ddq[0] + ddq[1], c2 * ddq[0] + s2 * dq[0] * w[0]],
        ]
    )
    return {"p": (p1, p2, p3), "M": M, "C": C, "Y": Y}


def course_p_expressions() -> dict[Any, Any]:
    """The report's p1, p2, p3 in masses and lengths (module docstring)."""
    import sympy as sp

    m1, m2, c1, c2, izz1, izz2, length = sp.symbols("m1 m2 c1 c2 Izz1c Izz2c L1", real=True)
    p2 = izz2 + m2 * c2**2
    return {"p1": izz1 + m1 * c1**2 + m2 * length**2 + p2, "p2": p2, "p3": m2 * length * c2}


def course_parameters(eq: Any) -> dict[str, Any] | None:
    """p1, p2, p3 as combinations of the derived base parameters, found by matching the shown
    derived M(q) (zero base parameters left out) with the report's; None when no p gives it
    (an arm whose M has terms three parameters cannot express)."""
    import sympy as sp

    course = course_matrices(eq.q, eq.dq, eq.ddq, eq.w)
    difference = sp.expand(eq.shown(eq.M) - course["M"])
    cos_q2, sin_q2 = sp.Dummy("cos_q2"), sp.Dummy("sin_q2")
    equations = []
    for entry in difference:
        entry = entry.xreplace({sp.cos(eq.q[1]): cos_q2, sp.sin(eq.q[1]): sin_q2})
        equations += sp.Poly(entry, cos_q2, sin_q2).coeffs()
    solution = sp.solve(equations, course["p"], dict=True)
    if len(solution) != 1 or set(solution[0]) != set(course["p"]):
        return None
    if any(sp.simplify(e.xreplace(solution[0])) != 0 for e in equations):
        return None  # an equation free of p (a sin q2 term) that p cannot satisfy
    return {str(p): sp.factor(solution[0][p]) for p in course["p"]}


def _in_course_terms(eq: Any) -> dict[Any, Any]:
    """The derived standard parameters and lengths in the report's symbols: the joint-frame
    inertia ``Izz_j = Izz_j,c + m_j c_j²`` and first moment ``mcx_j = m_j c_j`` of a link whose
    centre of mass lies on its x axis, and ``l2x = L1``."""
    import sympy as sp

    m1, m2, c1, c2, izz1, izz2, length = sp.symbols("m1 m2 c1 c2 Izz1c Izz2c L1", real=True)
    names = {str(s): s for s in eq.standard}
    return {
        names["m1"]: m1,
        names["m2"]: m2,
        names["mcx1"]: m1 * c1,
        names["mcx2"]: m2 * c2,
        names["mcy1"]: 0,
        names["mcy2"]: 0,
        names["Izz1"]: izz1 + m1 * c1**2,
        names["Izz2"]: izz2 + m2 * c2**2,
        sp.Symbol("l2x", real=True): length,
    }


def course_check(eq: Any) -> dict[str, Any]:
    """The derived equations written in the report's p, compared with the report's formulas
    (all exact: ``sympy.simplify`` of each difference is 0).

    Returns:
        ``found``: p in the base parameters (or None); ``M``, ``C``, ``Y``: whether each
        equals the report's; ``p_expressions``: whether p found, in masses and lengths,
        equals the report's expressions; ``p_values``: p of this arm [kg·m²]; ``latex``: the
        derived M and C written in p beside the report's, entry by entry, and p found.
    """
    import sympy as sp

    from twolink_pin.symbolic.formats import latex_entry

    found = course_parameters(eq)
    if found is None:
        return {
            "found": None,
            "M": False,
            "C": False,
            "Y": False,
            "p_expressions": False,
            "p_values": None,
            "latex": None,
        }
    course = course_matrices(eq.q, eq.dq, eq.ddq, eq.w)
    p = course["p"]
    # β in terms of p: invert the found map on the base parameters it involves
    used = sorted({b for value in found.values() for b in value.free_symbols if b in set(eq.beta)}, key=str)
    beta_of_p = sp.solve([sp.Eq(sym, found[str(sym)]) for sym in p], used, dict=True)[0]

    def same(derived: Any, report: Any) -> bool:
        return bool(sp.simplify(eq.shown(derived).xreplace(beta_of_p) - report) == sp.zeros(*report.shape))

    Y_course_from_derived = eq.shown(eq.Y_reference).xreplace(beta_of_p) * sp.Matrix(
        [[sp.diff(b.xreplace(beta_of_p), pi) for pi in p] for b in eq.beta]
    )
    definitions = dict(zip(eq.beta, eq.beta_definitions))
    terms = _in_course_terms(eq)
    expected = course_p_expressions()
    p_expressions = all(
        sp.simplify(found[name].xreplace(definitions).xreplace(terms) - expected[name]) == 0 for name in found
    )
    values = eq.symbol_values

    def entries(name: str, derived: Any, report: Any) -> list[dict[str, str]]:
        written = sp.simplify(eq.shown(derived).xreplace(beta_of_p))
        return [
            {
                "derived": f"{name}_{{{r + 1}{c + 1}}} = {latex_entry(eq, written[r, c])}",
                "report": f"{name}_{{{r + 1}{c + 1}}} = {latex_entry(eq, report[r, c])}",
            }
            for r in range(2)
            for c in range(2)
            if name == "C" or c >= r
        ]

    latex = {
        "p": [f"{sp.latex(sym)} = {latex_entry(eq, found[str(sym)])}" for sym in p],
        "M": entries("M", eq.M, course["M"]),
        "C": entries("C", eq.C, course["C"]),
    }
    return {
        "latex": latex,
        "found": {name: str(value) for name, value in found.items()},
        "M": same(eq.M, course["M"]),
        "C": same(eq.C, course["C"]),
        "Y": bool(sp.simplify(Y_course_from_derived - course["Y"]) == sp.zeros(2, 3)),
        "p_expressions": p_expressions,
        "p_values": {name: float(value.xreplace(values)) for name, value in found.items()},
    }
