"""A timing found by TOPP-RA turned into samples (:mod:`~twolink_pin.trajectory.retiming`):
``s(t)`` quadratic on each grid interval, sampled densely enough that the quintic Hermite between
samples is the exact timing, and the times at which the retimed path passes the via points."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from twolink_pin.errors import OptimizationError
from twolink_pin.trajectory.base import Trajectory
from twolink_pin.trajectory.retiming_path import EndsStretched, PathPiece
from twolink_pin.trajectory.sampled import hermite_coefficients
from twolink_pin.trajectory.se3 import PoseTrajectory

MAX_LEVEL = 4
"""Most halvings of a grid interval for the samples (the first and last intervals of a resting
path do not reach :data:`REPRESENTATION`: the motion leaves rest like ``t² + c t^{5/2}`` there,
no polynomial; their error is what :data:`MARGIN` leaves room for)."""


class Timing(NamedTuple):
    """A piece timed by TOPP-RA: ``ṡ`` at its grid points, constant ``s̈`` on each interval."""

    piece: PathPiece
    grid: np.ndarray
    """The grid points [path parameter], shape (N + 1,)."""
    sd: np.ndarray
    """``ṡ`` at the grid points, shape (N + 1,)."""
    u: np.ndarray
    """``s̈`` on each interval, shape (N,)."""
    t: np.ndarray
    """The time of each grid point [s], shape (N + 1,)."""


def timing_of(piece: PathPiece, grid: np.ndarray, sd: np.ndarray, t0: float) -> Timing:
    """``ṡ`` at the ``grid`` points as a timing starting at ``t0`` [s]."""
    ds = np.diff(grid)
    mean = 0.5 * (sd[:-1] + sd[1:])
    if np.any(mean <= 0):
        raise OptimizationError(
            "the time-optimal retiming", "TOPP-RA stopped on the path (ṡ = 0 inside it)", 1
        )
    t = t0 + np.concatenate([[0.0], np.cumsum(ds / mean)])
    return Timing(piece, grid, sd, (sd[1:] ** 2 - sd[:-1] ** 2) / (2.0 * ds), t)


def exact_motion(timing: Timing, interval: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, ...]:
    """The timed path at the fraction ``tau`` of the time of each ``interval``: ``t`` [s],
    ``q``, ``q̇``, ``q̈`` (``s(t)`` quadratic on an interval: ``s̈ = u``)."""
    dt = np.diff(timing.t)[interval] * tau
    sd, u = timing.sd[interval], timing.u[interval]
    grid = timing.grid
    s = np.minimum(grid[interval] + sd * dt + 0.5 * u * dt**2, grid[interval + 1])
    speed = sd + u * dt
    path = timing.piece.path
    d1, d2 = path(s, 1), path(s, 2)
    return (
        timing.t[interval] + dt,
        path(s, 0),
        d1 * speed[:, None],
        d2 * speed[:, None] ** 2 + d1 * u[:, None],
    )


def _fractions(m: np.ndarray, offset: float) -> np.ndarray:
    """``(j + offset)/m_i`` for j = 0..m_i (offset 0: the m_i + 1 ends of m_i equal parts) or
    j = 0..m_i − 1 (offset 0.5: their midpoints), for each i, concatenated."""
    count = m + 1 if offset == 0.0 else m
    start = np.repeat(np.cumsum(count) - count, count)
    j = np.arange(int(count.sum())) - start
    return (j + offset) / np.repeat(m, count)


def _hermite_midpoint_acceleration(
    t: np.ndarray, q: np.ndarray, v: np.ndarray, a: np.ndarray, steps: np.ndarray
) -> np.ndarray:
    """The quintic Hermite's acceleration halfway through the ``steps`` (row ``i`` to ``i + 1``),
    shape (len(steps), nv): ``(2 c₂ + 3 c₃ + 3 c₄ + 2.5 c₅) / h²`` with its coefficients in ``τ``."""
    i, j = steps, steps + 1
    h = t[j] - t[i]
    c = hermite_coefficients(h, q[i], v[i], a[i], q[j], v[j], a[j])
    return (2.0 * c[:, 2] + 3.0 * c[:, 3] + 3.0 * c[:, 4] + 2.5 * c[:, 5]) / h[:, None] ** 2


def _piece_rows(timing: Timing, tolerance: float) -> tuple[np.ndarray, ...]:
    """One timing's samples: each grid interval at ``2^level + 1`` evenly spaced times, both
    ends included (each interior grid point twice: its acceleration before and after), the
    level raised (at most :data:`MAX_LEVEL`) until the quintic Hermite between them is the
    exact timing to ``tolerance`` [rad/s²] of acceleration at every midpoint (near a resting
    path's ends the motion is no polynomial)."""
    n = timing.u.size
    level = np.zeros(n, dtype=int)
    rows: list[tuple[np.ndarray, ...] | None] = [None] * n
    todo = np.arange(n)
    while todo.size:
        m = 2 ** level[todo]
        t, q, v, a = exact_motion(timing, np.repeat(todo, m + 1), _fractions(m, 0.0))
        _, _, _, mid = exact_motion(timing, np.repeat(todo, m), _fractions(m, 0.5))
        inner = np.ones(t.size - 1, dtype=bool)
        inner[np.cumsum(m + 1)[:-1] - 1] = False  # the step from one interval's end to the next's start
        error = np.abs(_hermite_midpoint_acceleration(t, q, v, a, np.flatnonzero(inner)) - mid).max(axis=1)
        worst = np.maximum.reduceat(error, np.concatenate([[0], np.cumsum(m)[:-1]]))
        done = (worst <= tolerance) | (level[todo] >= MAX_LEVEL)
        bounds = np.concatenate([[0], np.cumsum(m + 1)])
        for k in np.flatnonzero(done):
            rows[int(todo[k])] = tuple(x[bounds[k] : bounds[k + 1]] for x in (t, q, v, a))
        todo = todo[~done]
        level[todo] += 1
    return tuple(np.concatenate([r[i] for r in rows if r is not None]) for i in range(4))


def represented(timings: list[Timing], tolerance: float) -> tuple[np.ndarray, ...]:
    """Every timing's samples (:func:`_piece_rows`), one after the other."""
    parts = [_piece_rows(timing, tolerance) for timing in timings]
    return tuple(np.concatenate([p[i] for p in parts]) for i in range(4))


def _time_at(timing: Timing, s: np.ndarray) -> np.ndarray:
    """When the timing reaches the path parameters ``s`` [s]: within an interval
    ``s(τ) = s_i + ṡ_i τ + u_i τ²/2``."""
    grid = timing.grid
    i = np.clip(np.searchsorted(grid, s, side="right") - 1, 0, grid.size - 2)
    d = np.clip(s - grid[i], 0.0, np.diff(grid)[i])
    sd, u = timing.sd[i], timing.u[i]
    root = np.sqrt(np.maximum(sd**2 + 2.0 * u * d, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.where(sd + root > 0, 2.0 * d / (sd + root), 0.0)
    return timing.t[i] + tau


def retimed_via_times(trajectory: Trajectory, timings: list[Timing]) -> np.ndarray:
    """When the retimed path passes the reference's via points [s]."""
    if isinstance(trajectory, PoseTrajectory):
        return np.array([timings[0].t[0]] + [timing.t[-1] for timing in timings])
    path = timings[0].piece.path
    assert isinstance(path, EndsStretched)
    return _time_at(timings[0], path.sigma_of(np.asarray(trajectory.via_times, dtype=float)))


__all__ = ["MAX_LEVEL", "Timing", "exact_motion", "represented", "retimed_via_times", "timing_of"]
