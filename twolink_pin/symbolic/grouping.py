"""The base parameters as exact combinations of masses, first moments, inertias and lengths.

:mod:`twolink_pin.model.base_parameters` finds them numerically (Gautier's QR of the
regressor stacked at random states); here the same choice is made exactly. Each standard
parameter's column of the regressor is determined by its ``M^{(π)}`` and ``g^{(π)}``
(:func:`~twolink_pin.symbolic.lagrange.standard_terms`; its Coriolis part follows from M),
and those are polynomials in the state whose coefficients are polynomials in the lengths.
Writing every coefficient of every state monomial as a row gives a matrix A (rows: an entry
of M or g and a monomial of the state; columns: the parameters) over the field of rational
functions of the lengths, whose column dependencies are exactly those of the regressor.

Ordered as :data:`~twolink_pin.model.base_parameters.PREFERENCE` orders them (bodies
1..n, each body's first moments, inertias, mass last), the pivot columns of A's reduced
row echelon form are the first independent columns in that order — the parameters kept,
as the numerical map keeps them — and each other column d is ``Σ_p R[p, d] col_p``, so

    β_p = π_p + Σ_d R[p, d] π_d,

e.g. ``β1 = Izz1 + l2x² m2`` for the twolink (the course's p1 is β1 + Izz2). A parameter
whose column is zero (never acts) belongs to no β. The rows are few (an arm of 3 joints:
about 160), the reduction exact (:class:`sympy.polys.matrices.DomainMatrix`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin.model.base_parameters import PREFERENCE
from twolink_pin.model.parameters import BODY_PARAMETER_NAMES, N_BODY_PARAMETERS
from twolink_pin.symbolic.kinematics import Matrix, Vector
from twolink_pin.symbolic.trig_ring import TrigRing


@dataclass(frozen=True)
class Grouping:
    """Which standard parameters are kept and what each base parameter adds to its own."""

    kept: tuple[int, ...]
    """Indices into π (10 per body, Pinocchio's order) of the parameters kept, in that order."""
    combination: tuple[dict[int, tuple[Any, Any]], ...]
    """For each kept parameter, ``{index d into π: (numerator, denominator)}`` of the
    coefficient of ``π_d`` in its β (polynomials in the lengths, of the ring's polynomials;
    the kept parameter itself is absent: its coefficient is 1)."""


def preference_order(bodies: int) -> list[int]:
    """Indices into π in :data:`PREFERENCE` order, body by body."""
    return [
        N_BODY_PARAMETERS * b + BODY_PARAMETER_NAMES.index(name) for b in range(bodies) for name in PREFERENCE
    ]


def _rows(ring: TrigRing, masses: list[Matrix], gravities: list[Vector], order: list[int]) -> dict[Any, Any]:
    """``{(row key, column position): polynomial in the lengths}`` of the matrix A."""
    n = ring.n
    entries: dict[Any, Any] = {}
    for position, index in enumerate(order):
        polys = [masses[index][r][c] for r in range(n) for c in range(r, n)] + list(gravities[index])
        for which, poly in enumerate(polys):
            for monom, coeff in ring.state_split(poly).items():
                entries[((which, monom), position)] = coeff
    return entries


def group(ring: TrigRing, masses: list[Matrix], gravities: list[Vector]) -> Grouping:
    """The exact base parameters (module docstring) of the standard terms ``masses``, ``gravities``."""
    from sympy import QQ, symbols
    from sympy.polys.matrices import DomainMatrix

    order = preference_order(len(masses) // N_BODY_PARAMETERS)
    entries = _rows(ring, masses, gravities, order)
    length_symbols = symbols(list(ring.length_names)) if ring.length_names else []
    field = QQ.frac_field(*length_symbols) if ring.length_names else QQ
    row_index: dict[Any, int] = {}
    table: dict[int, dict[int, Any]] = {}
    for (key, position), poly in entries.items():
        row = row_index.setdefault(key, len(row_index))
        table.setdefault(row, {})[position] = field.from_sympy(poly.as_expr())
    A = DomainMatrix(table, (len(row_index), len(order)), field)
    reduced, pivots = A.rref()
    reduced_rows = reduced.to_dok()
    combination = []
    for row, pivot in enumerate(pivots):
        terms = {}
        for position in range(len(order)):
            value = reduced_rows.get((row, position))
            if position in pivots or value is None or value == field.zero:
                continue
            terms[order[position]] = _ring_fraction(ring, field, value)
        combination.append((order[pivot], terms))
    combination.sort(key=lambda item: item[0])
    return Grouping(
        kept=tuple(index for index, _ in combination),
        combination=tuple(terms for _, terms in combination),
    )


def _ring_fraction(ring: TrigRing, field: Any, value: Any) -> tuple[Any, Any]:
    """A field element as (numerator, denominator) polynomials of ``ring``."""
    expr = field.to_sympy(value)
    numerator, denominator = expr.as_numer_denom()
    gens = [ring.gen(name) for name in ring.length_names]
    names = dict(zip(ring.length_names, gens))
    num, den = _to_ring(ring, numerator, names), _to_ring(ring, denominator, names)
    if den.is_ground:  # a polynomial: cleaned of inexact constants' residues (tilted arms)
        return ring.clean(num * ring.ring(1 / den.LC)), ring.one
    return ring.clean(num), ring.clean(den)


def _to_ring(ring: TrigRing, expr: Any, names: dict[str, Any]) -> Any:
    from sympy import Poly, Symbol

    if not names:
        return ring.ring(expr)
    poly = Poly(expr, *[Symbol(name) for name in names])
    out = ring.zero
    gens = list(names.values())
    for monom, coeff in poly.terms():
        term = ring.ring(coeff)
        for gen, e in zip(gens, monom):
            term *= gen**e
        out += term
    return out
