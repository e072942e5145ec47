"""The derived polynomials as expressions a person reads: sums of cos and sin of joint angles.

A polynomial in ``c_j = cos q_j``, ``s_j = sin q_j`` is rewritten, with the product-to-sum
identities, as a **trigonometric polynomial**: a sum of ``a_f cos(f·q) + b_f sin(f·q)`` over
integer frequency vectors f — ``c2 c3 − s2 s3`` becomes ``cos(q2 + q3)``,
``c2²`` becomes ``cos(2 q2)/2 + 1/2`` — whose coefficients are polynomials in the lengths, the
rates and g. This form is unique (the functions ``cos(f·q)``, ``sin(f·q)`` of distinct f
with first nonzero component positive are independent), so it is a normal form as well as
a short one: no heuristic simplifier is run, and it costs milliseconds for a 6-joint arm.
Then the factor common to all terms is pulled out, and each coefficient is factored when
short (and the arm small), and ``1 ± cos 2u`` is written as ``2 cos² u`` or ``2 sin² u``.

``M``, ``C``, ``g`` are written **by parameter**: ``Σ_k β_k (…)``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction
from functools import lru_cache
from typing import Any

from twolink_pin.symbolic.trig_ring import TrigRing

Frequency = tuple[int, ...]
Series = dict[Frequency, tuple[Fraction, Fraction]]


def _canonical(freq: Frequency, cos: Fraction, sin: Fraction) -> tuple[Frequency, Fraction, Fraction]:
    """``cos(-x) = cos x``, ``sin(-x) = −sin x``: the first nonzero component made positive."""
    for f in freq:
        if f != 0:
            if f < 0:
                return tuple(-x for x in freq), cos, -sin
            break
    else:
        return freq, cos, Fraction(0)  # sin 0 = 0
    return freq, cos, sin


def _add(out: Series, freq: Frequency, cos: Fraction, sin: Fraction) -> None:
    freq, cos, sin = _canonical(freq, cos, sin)
    a, b = out.get(freq, (Fraction(0), Fraction(0)))
    out[freq] = (a + cos, b + sin)


def _multiply(x: Series, y: Series) -> Series:
    """Product of two trigonometric polynomials (product-to-sum identities)."""
    out: Series = {}
    half = Fraction(1, 2)
    for fx, (ax, bx) in x.items():
        for fy, (ay, by) in y.items():
            plus = tuple(i + j for i, j in zip(fx, fy))
            minus = tuple(i - j for i, j in zip(fx, fy))
            # cos X cos Y, cos X sin Y, sin X cos Y, sin X sin Y
            _add(out, plus, half * (ax * ay - bx * by), half * (ax * by + bx * ay))
            _add(out, minus, half * (ax * ay + bx * by), half * (bx * ay - ax * by))
    return {f: ab for f, ab in out.items() if ab != (0, 0)}


@lru_cache(maxsize=4096)
def _monomial_series(n: int, joint: int, cos_power: int, sin_power: int) -> Series:
    """``cos^a q_j sin^b q_j`` as a trigonometric polynomial (frequency vectors of length n)."""
    unit = tuple(1 if i == joint else 0 for i in range(n))
    zero = tuple(0 for _ in range(n))
    out: Series = {zero: (Fraction(1), Fraction(0))}
    for _ in range(cos_power):
        out = _multiply(out, {unit: (Fraction(1), Fraction(0))})
    for _ in range(sin_power):
        out = _multiply(out, {unit: (Fraction(0), Fraction(1))})
    return out


@lru_cache(maxsize=65536)
def _signature_series(
    n: int, signature: tuple[tuple[int, int, int], ...]
) -> tuple[tuple[Frequency, Any, Any], ...]:
    """The trigonometric polynomial of ``Π_j cos^a q_j sin^b q_j`` (``signature``: the
    ``(j, a, b)`` of the joints it involves), its coefficients as SymPy rationals."""
    from sympy import QQ

    series: Series = {tuple(0 for _ in range(n)): (Fraction(1), Fraction(0))}
    for joint, cos_power, sin_power in signature:
        series = _multiply(series, _monomial_series(n, joint, cos_power, sin_power))
    return tuple(
        (freq, QQ(a.numerator, a.denominator), QQ(b.numerator, b.denominator))
        for freq, (a, b) in series.items()
    )


def trig_series(ring: TrigRing, p: Any) -> dict[Frequency, tuple[Any, Any]]:
    """``p`` as ``{f: (a_f, b_f)}`` with ``p = Σ a_f cos(f·q) + b_f sin(f·q)``; ``a_f``, ``b_f``
    polynomials of ``ring`` free of the cosines and sines."""
    n = ring.n
    pairs = [(j - 1, ring.index[f"c{j}"], ring.index[f"s{j}"]) for j in ring.revolute_joints]
    trig_indices = [i for _, c, s in pairs for i in (c, s)]
    out: dict[Frequency, tuple[dict[Any, Any], dict[Any, Any]]] = {}
    for monom, coeff in p.iterterms():
        signature = tuple((joint, monom[c], monom[s]) for joint, c, s in pairs if monom[c] or monom[s])
        rest = list(monom)
        for i in trig_indices:
            rest[i] = 0
        key = tuple(rest)
        for freq, a, b in _signature_series(n, signature):
            cos_terms, sin_terms = out.setdefault(freq, ({}, {}))
            if a:
                cos_terms[key] = cos_terms.get(key, 0) + coeff * a
            if b:
                sin_terms[key] = sin_terms.get(key, 0) + coeff * b
    series = {}
    for freq, (cos_terms, sin_terms) in out.items():
        a = ring.ring({k: v for k, v in cos_terms.items() if v})
        b = ring.ring({k: v for k, v in sin_terms.items() if v})
        if a or b:
            series[freq] = (a, b)
    return series


def _angle(freq: Frequency, q: Sequence[Any]) -> Any:
    """``f·q``, a common factor pulled out (``2 q2 + 2 q3`` → ``2 (q2 + q3)``)."""
    import sympy as sp

    common = math.gcd(*freq)
    inner = sp.Add(*[(f // common) * qj for f, qj in zip(freq, q) if f])
    return _product(sp.Integer(common), [inner])


def to_expr(ring: TrigRing, p: Any, names: dict[str, Any], q: Sequence[Any]) -> Any:
    """``p`` as a SymPy expression in cos and sin of the angles ``q`` (module docstring), the
    factor common to all its terms (a number and a monomial) pulled out in front; ``names``
    maps the ring's other generator names to SymPy symbols."""
    import sympy as sp

    gens = [names.get(name) for name in ring.names]
    series = sorted(trig_series(ring, p).items())
    content, monom = _common_factor(ring, [x for _, ab in series for x in ab if x])
    out = []
    for freq, (a, b) in series:
        angle = _angle(freq, q)
        for coeff, fn in ((a, sp.cos), (b, sp.sin)):
            if coeff == ring.zero:
                continue
            expr = _tidy(ring, _divided(ring, coeff, content, monom), gens)
            out.append(expr if angle == 0 else expr * fn(angle))
    return _product(poly_expr(ring.ring({monom: content}), gens), [sp.Add(*out)])


FACTOR_TERMS = 8
"""A coefficient of at most this many terms of an arm of at most :data:`FACTOR_JOINTS` joints
is factored (``dq2 l2y + dq2 l3y + dq3 l2y + dq3 l3y`` → ``(dq2 + dq3)(l2y + l3y)``); other
coefficients only have their common factor pulled out."""
FACTOR_JOINTS = 3
"""Beyond this many joints the coefficients are not factored: SymPy's multivariate factoring
(~20 ms a coefficient) would take most of the time of a larger arm (docs/equations.md)."""


def _common_factor(ring: TrigRing, polys: Sequence[Any]) -> tuple[Any, tuple[int, ...]]:
    """The rational content (negative when every coefficient is) and the monomial common to
    every term of ``polys`` (``(1, 0…0)`` with a decimal coefficient among them, or none)."""
    from sympy import QQ

    monom: tuple[int, ...] | None = None
    numerators, denominators = [], []
    for poly in polys:
        for exps, coeff in poly.iterterms():
            monom = exps if monom is None else tuple(min(a, b) for a, b in zip(monom, exps))
            numerators.append(abs(int(coeff.numerator)))
            denominators.append(int(coeff.denominator))
    zero = tuple(0 for _ in ring.names)
    if monom is None or max(denominators) > SHOWN_DENOMINATOR:
        return QQ(1), zero
    sign = -1 if all(c < 0 for poly in polys for c in poly.itercoeffs()) else 1
    return QQ(sign * math.gcd(*numerators), math.lcm(*denominators)), monom


def _divided(ring: TrigRing, p: Any, content: Any, monom: tuple[int, ...]) -> Any:
    """``p / (content · monomial)`` (exact: both divide every term)."""
    return ring.ring({tuple(e - m for e, m in zip(exps, monom)): c / content for exps, c in p.iterterms()})


def _tidy(ring: TrigRing, p: Any, gens: Sequence[Any]) -> Any:
    """A coefficient polynomial as an expression: factored in the ring (no conversion of
    expressions) when short and the arm small (:data:`FACTOR_TERMS`, :data:`FACTOR_JOINTS`),
    else with its common factor pulled out."""

    decimal = any(int(c.denominator) > SHOWN_DENOMINATOR for c in p.itercoeffs())
    if ring.n <= FACTOR_JOINTS and 1 < len(p) <= FACTOR_TERMS and not decimal:
        content, factors = p.factor_list()
        return _product(number(content), [poly_expr(f, gens) ** power for f, power in factors])
    content, monom = _common_factor(ring, [p])
    return _product(
        poly_expr(ring.ring({monom: content}), gens), [poly_expr(_divided(ring, p, content, monom), gens)]
    )


def _product(front: Any, factors: Sequence[Any]) -> Any:
    """``front · Π factors``, a number in front kept there (SymPy distributes ``−1 · (a + b)``
    into ``−a − b`` and ``2 (a + b)`` into ``2a + 2b``)."""
    import sympy as sp

    rest = sp.Mul(*factors)
    if front == 1:
        return rest
    if front.is_Number and rest.is_Add:
        return sp.Mul(front, rest, evaluate=False)
    return front * rest


SHOWN_DENOMINATOR = 10**6
"""A rational coefficient with a larger denominator (an inexact constant of a tilted arm: the
nearest fraction of cos 0.3) is written as a 15-digit decimal number."""


def number(coeff: Any) -> Any:
    """A rational coefficient as SymPy shows it (:data:`SHOWN_DENOMINATOR`)."""
    import sympy as sp

    if int(coeff.denominator) > SHOWN_DENOMINATOR:
        return sp.Float(float(coeff), 15)
    return sp.Rational(int(coeff.numerator), int(coeff.denominator))


def poly_expr(p: Any, gens: Sequence[Any]) -> Any:
    """A polynomial free of cosines and sines as a SymPy expression in ``gens``."""
    import sympy as sp

    terms = []
    for monom, coeff in p.iterterms():
        factors = [number(coeff)]
        factors += [gens[i] ** e for i, e in enumerate(monom) if e]
        terms.append(sp.Mul(*factors))
    return sp.Add(*terms)


def _squares(expr: Any) -> Any:
    """``1 − cos 2u`` → ``2 sin² u`` and ``1 + cos 2u`` → ``2 cos² u`` (a factored coefficient's
    ``β (1 − cos 2(q2 + q3))/2`` reads ``β sin²(q2 + q3)``)."""
    import sympy as sp

    def half_angle(e: Any) -> tuple[int, Any] | None:
        if not (e.is_Add and len(e.args) == 2 and sp.S.One in e.args):
            return None
        other = e.args[0] if e.args[1] == sp.S.One else e.args[1]
        sign, cosine = (-1, -other) if other.could_extract_minus_sign() else (1, other)
        if isinstance(cosine, sp.cos):
            return sign, cosine.args[0] / 2
        return None

    def square(e: Any) -> Any:
        sign, u = half_angle(e)  # type: ignore[misc]
        return 2 * (sp.cos(u) ** 2 if sign > 0 else sp.sin(u) ** 2)

    return expr.replace(lambda e: half_angle(e) is not None, square)


def _common(expr: Any) -> Any:
    """``expr`` with ``1 ± cos 2u`` written as squares (not with decimals)."""
    import sympy as sp

    return expr if expr.has(sp.Float) else _squares(expr)


def by_parameter(
    ring: TrigRing, parts: Sequence[Any], beta: Sequence[Any], names: dict[str, Any], q: Sequence[Any]
) -> Any:
    """``Σ_k β_k parts[k]`` with each part readable (:func:`to_expr`)."""
    import sympy as sp

    return sp.Add(
        *[b * _common(to_expr(ring, part, names, q)) for b, part in zip(beta, parts) if part != ring.zero]
    )
