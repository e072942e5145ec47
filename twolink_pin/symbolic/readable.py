"""The derived polynomials as expressions a person reads: sums of cos and sin of joint angles.

A polynomial in ``c_j = cos q_j``, ``s_j = sin q_j`` is rewritten, with the product-to-sum
identities, as a **trigonometric polynomial**: a sum of ``a_f cos(f·q) + b_f sin(f·q)`` over
integer frequency vectors f — ``c2 c3 − s2 s3`` becomes ``cos(q2 + q3)``,
``c2²`` becomes ``cos(2 q2)/2 + 1/2`` — whose coefficients are polynomials in the lengths, the
rates and g. This form is unique (the functions ``cos(f·q)``, ``sin(f·q)`` of distinct f
with first nonzero component positive are independent), so it is a normal form as well as
a short one: no heuristic simplifier is run, and it costs milliseconds for a 6-joint arm.
Then each coefficient is factored when short, its common factors pulled out otherwise.

``M``, ``C``, ``g`` are written **by parameter**: ``Σ_k β_k (…)``.
"""

from __future__ import annotations

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


def trig_series(ring: TrigRing, p: Any) -> dict[Frequency, tuple[Any, Any]]:
    """``p`` as ``{f: (a_f, b_f)}`` with ``p = Σ a_f cos(f·q) + b_f sin(f·q)``; ``a_f``, ``b_f``
    polynomials of ``ring`` free of the cosines and sines."""
    n = ring.n
    trig = {ring.index[f"c{j}"]: (j - 1, "c") for j in ring.revolute_joints}
    trig.update({ring.index[f"s{j}"]: (j - 1, "s") for j in ring.revolute_joints})
    out: dict[Frequency, list[Any]] = {}
    for monom, coeff in p.iterterms():
        rest = list(monom)
        series: Series = {tuple(0 for _ in range(n)): (Fraction(1), Fraction(0))}
        powers: dict[int, list[int]] = {}
        for i, (joint, which) in trig.items():
            if monom[i]:
                powers.setdefault(joint, [0, 0])[0 if which == "c" else 1] = monom[i]
                rest[i] = 0
        for joint, (cos_power, sin_power) in powers.items():
            series = _multiply(series, _monomial_series(n, joint, cos_power, sin_power))
        term = ring.ring({tuple(rest): coeff})
        for freq, (a, b) in series.items():
            slot = out.setdefault(freq, [ring.zero, ring.zero])
            if a:
                slot[0] += term * ring.constant(a)
            if b:
                slot[1] += term * ring.constant(b)
    return {f: (a, b) for f, (a, b) in out.items() if a != ring.zero or b != ring.zero}


def _angle(freq: Frequency, q: Sequence[Any]) -> Any:
    return sum((f * qj for f, qj in zip(freq, q) if f), 0)


def to_expr(ring: TrigRing, p: Any, names: dict[str, Any], q: Sequence[Any]) -> Any:
    """``p`` as a SymPy expression in cos and sin of the angles ``q`` (module docstring);
    ``names`` maps the ring's other generator names to SymPy symbols."""
    import sympy as sp

    gens = [names.get(name) for name in ring.names]
    out = []
    for freq, (a, b) in sorted(trig_series(ring, p).items()):
        angle = _angle(freq, q)
        for coeff, fn in ((a, sp.cos), (b, sp.sin)):
            if coeff == ring.zero:
                continue
            expr = _tidy(poly_expr(coeff, gens), len(coeff))
            out.append(expr if angle == 0 else expr * fn(angle))
    return sp.Add(*out)


FACTOR_TERMS = 8
"""A coefficient of at most this many terms is factored (``dq2 l2y + dq2 l3y + dq3 l2y + dq3 l3y``
→ ``(dq2 + dq3)(l2y + l3y)``); a longer one only has its common factors pulled out."""


def _tidy(expr: Any, terms: int) -> Any:
    import sympy as sp

    if expr.has(sp.Float):  # factoring decimals writes 1.0*x and splits them into products
        return expr
    return sp.factor(expr) if 1 < terms <= FACTOR_TERMS else sp.factor_terms(expr)


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


def _common(expr: Any) -> Any:
    """``expr`` with its terms' common factors pulled out (not with decimals: see :func:`_tidy`)."""
    import sympy as sp

    return expr if expr.has(sp.Float) else sp.factor_terms(expr)


def by_parameter(
    ring: TrigRing, parts: Sequence[Any], beta: Sequence[Any], names: dict[str, Any], q: Sequence[Any]
) -> Any:
    """``Σ_k β_k parts[k]`` with each part readable (:func:`to_expr`)."""
    import sympy as sp

    return sp.Add(
        *[b * _common(to_expr(ring, part, names, q)) for b, part in zip(beta, parts) if part != ring.zero]
    )
