"""B-spline bases: the matrices that turn a spline's coefficients into its values and
derivatives at given points.

A clamped B-spline of degree ``p`` on the knots ``k_0 = .. = k_p < k_{p+1} <= .. < k_{n} = ..
= k_{n+p}`` is ``y(s) = Σ_i c_i N_{i,p}(s)``: a piecewise polynomial of degree ``p``, ``C^{p-1}``
across a simple knot, through ``c_0`` at the first knot and ``c_{n-1}`` at the last. For a
set of points ``s_1..s_K`` the basis matrix ``B_r`` (shape (K, n)) holds ``N^{(r)}_{i,p}(s_k)``,
so that ``y^{(r)}(s_k) = (B_r c)_k``: every value and derivative of the spline is linear in
its coefficients, which is what makes via points, position, velocity and acceleration
limits *linear* constraints of the trajectory optimiser (:mod:`twolink_pin.optimal.transcription`).

The values come from the Cox–de Boor recursion, evaluated for all points at once with NumPy
(no SciPy: ``scipy.interpolate`` costs 0.8 s to import); a derivative from the rule that the
derivative of a degree-``p`` spline is a degree-``p − 1`` spline on the inner knots with
coefficients ``p (c_{i+1} − c_i) / (k_{i+p+1} − k_{i+1})`` (de Boor, *A Practical Guide to
Splines*, ch. X), i.e. ``B_r = N_{p−r} D_r ⋯ D_1`` with the difference matrices ``D``.
"""

from __future__ import annotations

import math

import numpy as np

from twolink_pin.arrays import readonly
from twolink_pin.errors import InvalidParameterError


class BSplineBasis:
    """The clamped B-spline basis of degree ``degree`` on the breakpoints ``breakpoints``
    (strictly increasing, in the spline's own variable ``s``: local time [s] or a
    normalised one). The interior breakpoints are simple knots, so the spline is
    ``C^{degree−1}`` everywhere.

    Attributes:
        degree: Polynomial degree ``p`` (>= 1).
        breakpoints: Where the polynomial pieces meet, shape (m + 1,), the ends included.
        knots: The clamped knot vector, shape (n + p + 1,).
        size: Number of coefficients ``n = m + p``.
    """

    def __init__(self, breakpoints: np.ndarray, degree: int = 5) -> None:
        breaks = np.asarray(breakpoints, dtype=float)
        if not (isinstance(degree, int) and 1 <= degree <= 9):
            raise InvalidParameterError("degree", degree, "an integer from 1 to 9")
        if (
            breaks.ndim != 1
            or breaks.size < 2
            or not np.all(np.isfinite(breaks))
            or np.any(np.diff(breaks) <= 0)
        ):
            raise InvalidParameterError(
                "breakpoints", breaks.tolist(), "at least two finite, strictly increasing values"
            )
        self.degree = degree
        self.breakpoints = readonly(breaks)
        self.knots = readonly(
            np.concatenate([np.full(degree, breaks[0]), breaks, np.full(degree, breaks[-1])])
        )
        self.size = breaks.size - 1 + degree
        self._differences = [self._difference(r) for r in range(1, degree + 1)]

    @classmethod
    def uniform(cls, start: float, end: float, intervals: int, degree: int = 5) -> BSplineBasis:
        """``intervals`` equal pieces between ``start`` and ``end``."""
        if not (isinstance(intervals, int) and intervals >= 1):
            raise InvalidParameterError("intervals", intervals, "an integer >= 1")
        return cls(np.linspace(start, end, intervals + 1), degree)

    @property
    def start(self) -> float:
        """The first breakpoint."""
        return float(self.breakpoints[0])

    @property
    def end(self) -> float:
        """The last breakpoint."""
        return float(self.breakpoints[-1])

    def _difference(self, r: int) -> np.ndarray:
        """``D_r``: coefficients of the ``(r−1)``-th derivative → of the ``r``-th, shape
        (n − r, n − r + 1)."""
        p, k = self.degree - r + 1, self.knots[r - 1 : len(self.knots) - r + 1]
        n = self.size - r + 1
        span = k[p + 1 : p + n] - k[1:n]
        D = np.zeros((n - 1, n))
        i = np.arange(n - 1)
        D[i, i], D[i, i + 1] = -p / span, p / span
        return D

    def matrix(self, s: np.ndarray, order: int = 0) -> np.ndarray:
        """``B_order`` at the points ``s`` (clipped to the spline's interval): shape
        (K, :attr:`size`), ``y^{(order)}(s) = B_order @ c``."""
        if not (isinstance(order, int) and 0 <= order <= self.degree):
            raise InvalidParameterError("order", order, f"a derivative from 0 to {self.degree}")
        s = np.clip(np.atleast_1d(np.asarray(s, dtype=float)), self.start, self.end)
        knots = self.knots[order : len(self.knots) - order]
        B = _values(knots, self.degree - order, s)
        for D in reversed(self._differences[:order]):
            B = B @ D
        return B

    def derivative_coefficients(self, order: int) -> np.ndarray:
        """``D_order ⋯ D_1`` (shape (n − order, n)): the coefficients of the spline's
        ``order``-th derivative, a degree ``p − order`` B-spline on the inner knots. B-spline
        basis functions are non-negative and sum to one, so the derivative lies between the
        smallest and largest of these coefficients everywhere (the convex-hull property): a
        bound on them bounds the derivative between every two knots, with no grid."""
        if not (isinstance(order, int) and 0 <= order <= self.degree):
            raise InvalidParameterError("order", order, f"a derivative from 0 to {self.degree}")
        out = np.eye(self.size)
        for D in self._differences[:order]:
            out = D @ out
        return out

    def matrices(self, s: np.ndarray, orders: int = 3) -> tuple[np.ndarray, ...]:
        """``(B_0, .., B_orders)`` at ``s``."""
        return tuple(self.matrix(s, r) for r in range(orders + 1))

    def quadrature(self, points: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Gauss–Legendre nodes and weights on every piece (``points`` per piece, default
        ``degree + 1``): ``∫ y(s) ds = Σ w_k y(s_k)``, exact for a polynomial of degree
        ``2 points − 1`` on each piece."""
        m = self.degree + 1 if points is None else points
        x, w = np.polynomial.legendre.leggauss(m)
        a, b = self.breakpoints[:-1, None], self.breakpoints[1:, None]
        nodes = 0.5 * (a + b) + 0.5 * (b - a) * x
        weights = 0.5 * (b - a) * w
        return nodes.ravel(), weights.ravel()

    def grid(self, per_piece: int) -> np.ndarray:
        """``per_piece`` evenly spaced points on every piece, the breakpoints included once."""
        if not (isinstance(per_piece, int) and per_piece >= 1):
            raise InvalidParameterError("per_piece", per_piece, "an integer >= 1")
        a, b = self.breakpoints[:-1, None], self.breakpoints[1:, None]
        inner = a + (b - a) * (np.arange(per_piece) / per_piece)
        return np.concatenate([inner.ravel(), self.breakpoints[-1:]])

    def fit(self, s: np.ndarray, values: np.ndarray) -> np.ndarray:
        """Least-squares coefficients (shape (n, …)) of the spline nearest ``values`` at ``s``."""
        B = self.matrix(s)
        coefficients, *_ = np.linalg.lstsq(B, values, rcond=None)
        return coefficients

    def shift(self, delta: float, samples_per_piece: int = 4) -> np.ndarray:
        """The matrix ``S`` (n × n) with ``S c`` the coefficients of the spline nearest
        ``s ↦ y(s + delta)`` (least squares on a grid; beyond the end, ``y`` is continued
        by its last piece): a receding horizon's warm start, its previous plan moved on by
        one replanning period."""
        if not math.isfinite(delta):
            raise InvalidParameterError("delta", delta, "a finite shift")
        s = self.grid(max(samples_per_piece, self.degree + 1))
        target = _values_extrapolated(self, s + delta)
        return np.linalg.lstsq(self.matrix(s), target, rcond=None)[0]


def _values(knots: np.ndarray, degree: int, s: np.ndarray) -> np.ndarray:
    """``N_{i,degree}(s_k)`` for every basis function of ``knots`` (clamped), shape (K, n)."""
    left, right = knots[:-1], knots[1:]
    N = ((left <= s[:, None]) & (s[:, None] < right)).astype(float)
    last = int(np.flatnonzero(left < right)[-1])
    N[s >= knots[-1], :] = 0.0
    N[s >= knots[-1], last] = 1.0  # the right end belongs to the last piece
    for d in range(1, degree + 1):
        a_den = knots[d:-1] - knots[: -d - 1]
        b_den = knots[d + 1 :] - knots[1:-d]
        with np.errstate(divide="ignore", invalid="ignore"):
            a = np.where(a_den > 0, (s[:, None] - knots[: -d - 1]) / a_den, 0.0)
            b = np.where(b_den > 0, (knots[d + 1 :] - s[:, None]) / b_den, 0.0)
        N = a * N[:, :-1] + b * N[:, 1:]
    return N


def _values_extrapolated(basis: BSplineBasis, s: np.ndarray) -> np.ndarray:
    """Basis values at ``s`` where points beyond the end follow the last piece's polynomial
    (its Taylor expansion at the end), shape (K, n)."""
    inside = np.minimum(s, basis.end)
    out = basis.matrix(inside)
    beyond = s > basis.end
    if beyond.any():
        h = (s[beyond] - basis.end)[:, None]
        ends = [basis.matrix(np.array([basis.end]), r)[0] for r in range(basis.degree + 1)]
        out[beyond] = sum(ends[r][None, :] * h**r / math.factorial(r) for r in range(len(ends)))
    return out


__all__ = ["BSplineBasis"]
