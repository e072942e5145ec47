"""The geometric path a time-optimal retiming times (:mod:`~twolink_pin.trajectory.retiming`):
a reference's joint path ``q(s)`` as pieces retimed from rest to rest, its resting ends
stretched so that TOPP-RA keeps its digits there."""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from twolink_pin.trajectory.base import Trajectory
from twolink_pin.trajectory.se3 import PoseTrajectory

END_ZONE = 0.05
"""The fraction of a resting path's parameter at each end that is stretched (:class:`_EndsStretched`)."""


class PathPiece(NamedTuple):
    """A stretch of geometric path retimed from rest to rest."""

    path: Callable[[np.ndarray, int], np.ndarray]
    """``(s, order) -> q^{(order)}(s)``, shape (len(s), nv)."""
    start: float
    end: float


def path_pieces(trajectory: Trajectory) -> list[PathPiece]:
    """The geometric path of ``trajectory`` (module docstring): one piece, or one per SE(3)
    segment."""
    if isinstance(trajectory, PoseTrajectory):
        return [
            PathPiece(functools.partial(trajectory.segment_path, k), 0.0, 1.0)
            for k in range(len(trajectory.times) - 1)
        ]
    span = float(getattr(trajectory, "span", trajectory.period))
    orders = _rest_orders(trajectory, trajectory.t0, span)
    return [PathPiece(EndsStretched(trajectory, trajectory.t0, span, *orders), 0.0, 1.0)]


def _rest_orders(trajectory: Trajectory, start: float, span: float) -> tuple[int, int]:
    """How the trajectory leaves rest at its start and reaches it at its end: ``m`` with
    ``q − q_end ~ (t − t_end)^m`` (the first of q̇, q̈, jerk that is not zero, 4 if none is;
    1: it does not rest there)."""
    ends = trajectory.sample(np.array([start, start + span]))
    scale = max(float(np.abs(trajectory.sample(np.linspace(start, start + span, 65)).v).max()), 1e-300)
    orders = []
    for index in (0, 1):
        sizes = [float(np.abs(x[index]).max()) for x in (ends.v, ends.a, ends.jerk)]
        zero = [size <= 1e-9 * scale * span ** (-r) for r, size in enumerate(sizes)]
        orders.append(zero.index(False) + 1 if False in zero else 4)
    return orders[0], orders[1]


def _end_map(m: int) -> tuple[float, float, float]:
    """``(α, β, γ)`` of ``ψ(x) = x^{1/m} (α + β x + γ x²)``: ``ψ(1) = 1``, ``ψ'(1) = 1``,
    ``ψ''(1) = 0`` (a C² join with the identity), monotone for m = 1 .. 4."""
    p = 1.0 / m
    A = np.array([[1.0, 1.0, 1.0], [p, p + 1, p + 2], [p * (p - 1), (p + 1) * p, (p + 2) * (p + 1)]])
    a, b, c = np.linalg.solve(A, [1.0, 1.0, 0.0])
    return float(a), float(b), float(c)


class EndsStretched:
    """A trajectory's path in a parameter ``σ ∈ [0, 1]``: ``s = start + span φ(σ)``, ``φ(σ) = σ``
    but within :data:`END_ZONE` of an end where the trajectory rests, there ``δ ψ(σ/δ)`` with
    ``ψ(x) ~ x^{1/m}`` (:func:`_end_map`). In ``s`` the tangent of a polynomial that leaves rest
    with zero velocity, acceleration and jerk vanishes like ``s³``: TOPP-RA's constraints lose
    their scale and its steps their digits near the ends (it declared such paths not
    controllable on a finer grid there). In ``σ`` the tangent stays finite and ``ṡ²`` grows
    linearly from rest, what TOPP-RA's constant path acceleration per interval represents."""

    def __init__(self, trajectory: Trajectory, start: float, span: float, m0: int, m1: int) -> None:
        self.trajectory, self.start, self.span = trajectory, start, span
        self.ends = ((m0, _end_map(m0)), (m1, _end_map(m1)))
        self._last: tuple[np.ndarray, tuple[np.ndarray, ...]] | None = None  # q, q', q'' at the last σ

    def phi(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``φ, φ', φ''`` at ``σ`` (inside [1e-9, 1 − 1e-9]: the ends are singular)."""
        x = np.clip(np.asarray(sigma, dtype=float), 1e-9, 1.0 - 1e-9)
        phi, d1, d2 = x.copy(), np.ones_like(x), np.zeros_like(x)
        delta = END_ZONE
        for side, (m, (a, b, c)) in enumerate(self.ends):
            if m == 1:
                continue
            y = x / delta if side == 0 else (1.0 - x) / delta
            zone = y < 1.0
            p, yy = 1.0 / m, y[zone]
            psi = yy**p * (a + b * yy + c * yy**2)
            dpsi = yy ** (p - 1) * (p * a + (p + 1) * b * yy + (p + 2) * c * yy**2)
            ddpsi = yy ** (p - 2) * (p * (p - 1) * a + (p + 1) * p * b * yy + (p + 2) * (p + 1) * c * yy**2)
            sign = 1.0 if side == 0 else -1.0
            phi[zone] = delta * psi if side == 0 else 1.0 - delta * psi
            d1[zone], d2[zone] = dpsi, sign * ddpsi / delta
        return phi, d1, d2

    def sigma_of(self, t: np.ndarray) -> np.ndarray:
        """The parameter ``σ`` at which the path is the trajectory's at time ``t`` [s]."""
        sigma = np.linspace(0.0, 1.0, 20001)
        phi = self.phi(sigma)[0]
        phi[0], phi[-1] = 0.0, 1.0
        return np.interp((np.asarray(t, dtype=float) - self.start) / self.span, phi, sigma)

    def __call__(self, sigma: np.ndarray, order: int) -> np.ndarray:
        sigma = np.asarray(sigma, dtype=float)
        if self._last is None or not np.array_equal(self._last[0], sigma):  # q, q', q'' asked in turn
            phi, d1, d2 = self.phi(sigma)
            sample = self.trajectory.sample(self.start + self.span * phi)
            v, a = np.atleast_2d(sample.v), np.atleast_2d(sample.a)
            values = (
                np.atleast_2d(sample.q),
                v * (self.span * d1)[:, None],
                a * (self.span * d1)[:, None] ** 2 + v * (self.span * d2)[:, None],
            )
            self._last = (sigma.copy(), values)
        return self._last[1][order]


def path_lengths(pieces: list[PathPiece]) -> np.ndarray:
    """Each piece's joint-space length [rad] (50 chords)."""
    out = []
    for piece in pieces:
        q = piece.path(np.linspace(piece.start, piece.end, 51), 0)
        out.append(float(np.linalg.norm(np.diff(q, axis=0), axis=1).sum()))
    return np.array(out)


__all__ = ["END_ZONE", "EndsStretched", "PathPiece", "path_lengths", "path_pieces"]
