"""The polynomial ring the derivation computes in: cos and sin of each angle as two variables.

Every quantity of a serial arm of revolute and prismatic joints — a rotation, a position,
a Jacobian, ``M(q)``, ``C(q, q̇)``, ``g(q)``, the regressor — is a polynomial in
``c_j = cos q_j``, ``s_j = sin q_j`` (revolute joint j), ``q_j`` (prismatic joint j), the
arm's lengths [m], the rates ``q̇``, ``w`` (the Slotine–Li reference rate), the
accelerations ``q̈`` and the gravity ``g`` [m/s²], with rational coefficients. SymPy's sparse
polynomials (:func:`sympy.polys.rings.ring`) multiply and differentiate these far faster
than general expressions, and a polynomial is **canonical** once every ``s_j²`` is replaced
by ``1 − c_j²`` (:meth:`TrigRing.reduce`): two polynomials are the same function of the
state exactly when their reduced forms are equal, so identities (``Ṁ − 2C`` skew-symmetric,
two columns of the regressor dependent) are checked exactly, with no simplifier's guess.

``∂/∂q_j`` of a revolute joint's polynomial is ``−s_j ∂/∂c_j + c_j ∂/∂s_j`` (:meth:`TrigRing.dq`).

**Tilted arms.** A placement turned by an angle that is not a multiple of a quarter turn
(``rpy="0 0 0.3"``), or a joint axis off the frame's axes, brings numbers such as cos 0.3
that are not rational: they enter as the nearest fractions (:mod:`~twolink_pin.symbolic.skeleton`),
and identities such as ``cos² + sin² = 1`` then hold only to ~1e-17 — a residue that exact
algebra would count as a term (an extra base parameter, a 40-digit fraction). With a
``tolerance`` (the derivation passes :data:`TILTED_TOLERANCE` for such arms) every reduced
polynomial is cleaned: coefficients below ``tolerance`` × its largest are dropped, and one
within ``tolerance`` (relative) of a fraction of denominator ≤ 10⁴ becomes that fraction.
Legitimate coefficients are products of a few rotation entries and rationals, far above it.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cached_property
from typing import Any

TILTED_TOLERANCE = 1e-12
"""The cleaning tolerance of an arm whose constants are not all exact (module docstring)."""
SIMPLE_DENOMINATOR = 10**4
"""A coefficient this close to a fraction with at most this denominator is that fraction."""
REVOLUTE = "revolute"
PRISMATIC = "prismatic"


class TrigRing:
    """Polynomials in the state of an arm (see the module docstring).

    Args:
        kinds: Each joint's kind, :data:`REVOLUTE` or :data:`PRISMATIC`, in joint order.
        lengths: Names of the arm's length symbols [m] (placements' offsets).

    With ``tolerance``, :meth:`reduce` also cleans (module docstring: tilted arms).

    Generator names: ``c1, s1`` (revolute joint 1) or ``q1`` (prismatic joint 1), ...; the
    lengths; ``dq1 ..``, ``w1 ..``, ``ddq1 ..`` (q̇, the reference rate, q̈); ``g``.
    """

    def __init__(self, kinds: Sequence[str], lengths: Sequence[str], tolerance: float | None = None) -> None:
        from sympy import QQ
        from sympy.polys.rings import ring

        self.tolerance = tolerance
        self.kinds = tuple(kinds)
        self.n = len(self.kinds)
        names: list[str] = []
        for j, kind in enumerate(self.kinds, start=1):
            names += [f"c{j}", f"s{j}"] if kind == REVOLUTE else [f"q{j}"]
        self.length_names = tuple(lengths)
        names += list(self.length_names)
        for prefix in ("dq", "w", "ddq"):
            names += [f"{prefix}{j}" for j in range(1, self.n + 1)]
        names.append("g")
        self.names = tuple(names)
        self.ring, *gens = ring(",".join(names), QQ)
        self._gens = dict(zip(names, gens))
        self.index = {name: i for i, name in enumerate(names)}
        self.one = self.ring.one
        self.zero = self.ring.zero
        self._sine_indices = tuple(self.index[f"s{j}"] for j in self.revolute_joints)
        self._cosines = {self.index[f"s{j}"]: self._gens[f"c{j}"] for j in self.revolute_joints}

    @property
    def revolute_joints(self) -> tuple[int, ...]:
        """1-based indices of the revolute joints."""
        return tuple(j for j, kind in enumerate(self.kinds, start=1) if kind == REVOLUTE)

    def gen(self, name: str) -> Any:
        """The generator called ``name``."""
        return self._gens[name]

    def constant(self, value: Any) -> Any:
        """A rational number (``fractions.Fraction`` or int) as a polynomial."""
        from sympy import QQ

        return self.ring(QQ(value.numerator, value.denominator))

    def cos(self, j: int) -> Any:
        """``cos q_j`` (1-based revolute joint)."""
        return self._gens[f"c{j}"]

    def sin(self, j: int) -> Any:
        """``sin q_j`` (1-based revolute joint)."""
        return self._gens[f"s{j}"]

    def rates(self, prefix: str) -> list[Any]:
        """``[dq1, ..]`` (prefix ``dq``), ``[w1, ..]`` or ``[ddq1, ..]``."""
        return [self._gens[f"{prefix}{j}"] for j in range(1, self.n + 1)]

    @cached_property
    def _one_minus_cos_squared(self) -> dict[int, Any]:
        return {i: self.one - c**2 for i, c in self._cosines.items()}

    def reduce(self, p: Any) -> Any:
        """``p`` with every ``s_j^k`` (k ≥ 2) replaced using ``s_j² = 1 − c_j²``: the canonical form
        (cleaned, with a tolerance)."""
        if not any(m[i] >= 2 for m in p.itermonoms() for i in self._sine_indices):
            return p if self.tolerance is None else self.clean(p)
        out = self.zero
        for monom, coeff in p.iterterms():
            factor = self.one
            exps = list(monom)
            for i in self._sine_indices:
                if exps[i] >= 2:
                    factor *= self._one_minus_cos_squared[i] ** (exps[i] // 2)
                    exps[i] %= 2
            out += self.ring({tuple(exps): coeff}) * factor
        return self.reduce(out)

    def clean(self, p: Any) -> Any:
        """``p`` without the residues of inexact constants (module docstring: tilted arms)."""
        from fractions import Fraction

        from sympy import QQ

        if self.tolerance is None or not p:
            return p
        largest = max(abs(float(c)) for c in p.itercoeffs())
        out = {}
        for monom, coeff in p.iterterms():
            value = float(coeff)
            if abs(value) < self.tolerance * largest:
                continue
            if coeff.denominator > SIMPLE_DENOMINATOR:
                simple = Fraction(value).limit_denominator(SIMPLE_DENOMINATOR)
                if abs(float(simple) - value) <= self.tolerance * abs(value):
                    coeff = QQ(simple.numerator, simple.denominator)
            out[monom] = coeff
        return self.ring(out)

    def dq(self, p: Any, j: int) -> Any:
        """``∂p/∂q_j`` (1-based joint), reduced."""
        if self.kinds[j - 1] == REVOLUTE:
            c, s = self._gens[f"c{j}"], self._gens[f"s{j}"]
            return self.reduce(-s * p.diff(c) + c * p.diff(s))
        return p.diff(self._gens[f"q{j}"])

    def time_derivative(self, p: Any) -> Any:
        """``dp/dt = Σ_j ∂p/∂q_j q̇_j`` of a polynomial in the configuration."""
        rates = self.rates("dq")
        out = self.zero
        for j in range(1, self.n + 1):
            out += self.dq(p, j) * rates[j - 1]
        return self.reduce(out)

    def state_split(self, p: Any) -> dict[tuple[int, ...], Any]:
        """``p`` as ``{state monomial: polynomial in the lengths}``: the state monomial is the
        exponent tuple with the lengths' exponents zeroed (so that dependencies between
        columns of the regressor are found over the field of the lengths)."""
        lengths = [self.index[name] for name in self.length_names]
        out: dict[tuple[int, ...], Any] = {}
        for monom, coeff in p.iterterms():
            state = list(monom)
            length_monom = [0] * len(monom)
            for i in lengths:
                length_monom[i], state[i] = monom[i], 0
            key = tuple(state)
            out[key] = out.get(key, self.zero) + self.ring({tuple(length_monom): coeff})
        return out

    def evaluate(self, p: Any, values: dict[str, float]) -> float:
        """``p`` at a point: ``values`` gives a float for each generator ``p`` contains."""
        total = 0.0
        for monom, coeff in p.iterterms():
            term = float(coeff)
            for name, e in zip(self.names, monom):
                if e:
                    term *= values[name] ** e
            total += term
        return total

    def to_dict(self, p: Any) -> list[list[Any]]:
        """``p`` as JSON-ready terms ``[[exponents...], "numerator/denominator"]``."""
        return [[list(m), str(c)] for m, c in sorted(p.iterterms())]

    def from_dict(self, terms: Sequence[Sequence[Any]]) -> Any:
        """The inverse of :meth:`to_dict` (no ``eval``: rationals parsed as text)."""
        from sympy import QQ

        out = {}
        for monom, text in terms:
            if len(monom) != len(self.names):
                raise ValueError(f"a term of {len(monom)} exponents in a ring of {len(self.names)}")
            num, _, den = str(text).partition("/")
            out[tuple(int(e) for e in monom)] = QQ(int(num), int(den or 1))
        return self.ring(out)
