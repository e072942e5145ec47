"""The decision variables of a trajectory problem: a joint trajectory in segments, each a
B-spline in its own normalised time, and the segments' durations.

The trajectory has ``S`` segments (one between two via points; one for a receding horizon).
On segment ``k``, of duration ``h_k`` [s] starting at ``T_k = h_0 + .. + h_{k−1}``, the joint
positions are ``q(t) = Q_k(σ)``, ``σ = (t − T_k)/h_k ∈ [0, 1]``, with ``Q_k(σ) = Σ_i C_{k,i}
N_i(σ)`` on one B-spline basis (:class:`~twolink_pin.optimal.spline.BSplineBasis`, degree 5 by
default) shared by the segments, so that::

    q^{(r)}(t) = Q_k^{(r)}(σ) / h_k^r = (B_r(σ) C_k) / h_k^r

is linear in the coefficients ``C`` for given durations. The durations are data (the via times
of a file, a receding horizon) or variables (the minimum-time problem: the via times free).

The variable vector ``x`` holds ``C`` (shape (S, n, nv), C order: segment, coefficient,
joint) and then, when they are free, the ``S`` durations. :class:`Points` are evaluation points
``(segment, σ)`` with their basis rows; :meth:`SplineLayout.derivative` gives a derivative of
``q`` at them and its Jacobian with respect to ``x``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from twolink_pin.arrays import readonly
from twolink_pin.errors import InvalidParameterError
from twolink_pin.optimal.spline import BSplineBasis


class Points(NamedTuple):
    """Evaluation points of a :class:`SplineLayout`, with the basis rows they need."""

    segment: np.ndarray
    """Segment of each point, shape (K,), integers."""
    sigma: np.ndarray
    """Normalised time within its segment, shape (K,), in [0, 1]."""
    rows: tuple[np.ndarray, ...]
    """``B_r(σ)`` for r = 0 .. 4, each shape (K, n)."""
    weight: np.ndarray
    """Quadrature weight of each point in normalised time (times ``h`` gives seconds); ones
    where the points are not a quadrature."""

    @property
    def size(self) -> int:
        """K."""
        return int(self.segment.size)


@dataclass(frozen=True)
class SplineLayout:
    """How ``x`` describes a joint trajectory (module docstring).

    Attributes:
        basis: The B-spline basis of every segment, on ``[0, 1]``.
        segments: ``S``, at least 1.
        nv: Number of joints.
        durations: The segments' durations [s], shape (S,), when they are data; None when
            they are variables (the last S entries of ``x``).
    """

    basis: BSplineBasis
    segments: int
    nv: int
    durations: np.ndarray | None = field(default=None)

    def __post_init__(self) -> None:
        if not (isinstance(self.segments, int) and self.segments >= 1):
            raise InvalidParameterError("segments", self.segments, "an integer >= 1")
        if self.basis.start != 0.0 or self.basis.end != 1.0:
            raise InvalidParameterError(
                "basis", (self.basis.start, self.basis.end), "a basis on [0, 1] (normalised time)"
            )
        if self.durations is not None:
            h = np.asarray(self.durations, dtype=float)
            if h.shape != (self.segments,) or not np.all(np.isfinite(h)) or np.any(h <= 0):
                raise InvalidParameterError(
                    "durations", h.tolist(), f"{self.segments} finite durations > 0 s, one per segment"
                )
            object.__setattr__(self, "durations", readonly(h))

    @property
    def n(self) -> int:
        """Coefficients per segment and joint."""
        return self.basis.size

    @property
    def free_durations(self) -> bool:
        """Whether the durations are variables."""
        return self.durations is None

    @property
    def block(self) -> int:
        """Variables of one segment's coefficients (``n · nv``)."""
        return self.n * self.nv

    @property
    def size(self) -> int:
        """Length of ``x``."""
        return self.segments * self.block + (self.segments if self.free_durations else 0)

    def coefficients(self, x: np.ndarray) -> np.ndarray:
        """``C``, shape (S, n, nv)."""
        return x[: self.segments * self.block].reshape(self.segments, self.n, self.nv)

    def durations_of(self, x: np.ndarray) -> np.ndarray:
        """``h`` [s], shape (S,)."""
        if self.durations is None:
            return x[self.segments * self.block :]
        return self.durations

    def pack(self, coefficients: np.ndarray, durations: np.ndarray | None = None) -> np.ndarray:
        """``x`` from ``C`` (S, n, nv) and, when free, the durations [s]."""
        parts = [np.asarray(coefficients, dtype=float).ravel()]
        if self.free_durations:
            if durations is None:
                raise InvalidParameterError(
                    "durations", None, f"{self.segments} durations [s]: they are variables"
                )
            parts.append(np.asarray(durations, dtype=float))
        return np.concatenate(parts)

    def starts(self, x: np.ndarray) -> np.ndarray:
        """``T_k``, each segment's start time [s] (the first at 0), shape (S + 1,): the last
        entry is the total duration."""
        return np.concatenate([[0.0], np.cumsum(self.durations_of(x))])

    def points(self, segment: np.ndarray, sigma: np.ndarray, weight: np.ndarray | None = None) -> Points:
        """Points at ``(segment, σ)`` with their basis rows."""
        segment = np.asarray(segment, dtype=int)
        sigma = np.clip(np.asarray(sigma, dtype=float), 0.0, 1.0)
        rows = tuple(self.basis.matrix(sigma, r) for r in range(min(self.basis.degree, 4) + 1))
        w = np.ones(sigma.size) if weight is None else np.asarray(weight, dtype=float)
        return Points(segment, sigma, rows, w)

    def grid(self, per_piece: int) -> Points:
        """``per_piece`` evenly spaced points per knot interval of every segment, each
        segment's ends included (a join appears once, at the start of the later segment, and
        the trajectory's end once)."""
        local = self.basis.grid(per_piece)
        segment = np.repeat(np.arange(self.segments), local.size - 1)
        sigma = np.tile(local[:-1], self.segments)
        return self.points(np.append(segment, self.segments - 1), np.append(sigma, 1.0))

    def quadrature(self, points: int | None = None) -> Points:
        """Gauss–Legendre points on every knot interval of every segment (weights in
        normalised time)."""
        nodes, weights = self.basis.quadrature(points)
        return self.points(
            np.repeat(np.arange(self.segments), nodes.size),
            np.tile(nodes, self.segments),
            np.tile(weights, self.segments),
        )

    def times(self, x: np.ndarray, points: Points) -> np.ndarray:
        """The time [s] of each point."""
        h = self.durations_of(x)
        return self.starts(x)[points.segment] + h[points.segment] * points.sigma

    def locate(self, x: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(segment, σ)`` of times ``t`` [s] within ``[0, total]`` (clipped)."""
        starts = self.starts(x)
        t = np.clip(np.asarray(t, dtype=float), 0.0, starts[-1])
        segment = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, self.segments - 1)
        h = self.durations_of(x)
        return segment, (t - starts[segment]) / h[segment]

    def derivative(self, x: np.ndarray, points: Points, order: int) -> np.ndarray:
        """``q^{(order)}`` at ``points`` [rad/s^order], shape (K, nv)."""
        C = self.coefficients(x)
        h = self.durations_of(x)[points.segment]
        return np.einsum("kn,knj->kj", points.rows[order], C[points.segment]) / h[:, None] ** order

    def columns(self, points: Points) -> np.ndarray:
        """The column in ``x`` of coefficient ``i`` of joint 0 for each point's segment:
        ``segment · n · nv + i · nv``, shape (K, n) (joint ``j``: add ``j``)."""
        return points.segment[:, None] * self.block + np.arange(self.n)[None, :] * self.nv

    def duration_column(self, points: Points) -> np.ndarray:
        """The column in ``x`` of each point's segment's duration (free durations), shape (K,)."""
        return self.segments * self.block + points.segment

    def jacobian(
        self, x: np.ndarray, points: Points, order: int, value: np.ndarray | None = None
    ) -> np.ndarray:
        """``∂q^{(order)}/∂x`` at ``points``, shape (K, nv, size) (``value``: the derivative
        itself, when known, for the durations' columns)."""
        K, nv = points.size, self.nv
        h = self.durations_of(x)[points.segment]
        J = np.zeros((K, nv, self.size))
        k = np.arange(K)[:, None, None]
        j = np.arange(nv)[None, :, None]
        J[k, j, self.columns(points)[:, None, :] + j] = (points.rows[order] / h[:, None] ** order)[:, None, :]
        if self.free_durations and order > 0:
            if value is None:
                value = self.derivative(x, points, order)
            J[np.arange(K), :, self.duration_column(points)] = -order * value / h[:, None]
        return J


__all__ = ["Points", "SplineLayout"]
