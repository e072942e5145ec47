"""A home for an arm whose profile gives none: near the middle of the ranges, far from a singularity.

The middle of every joint's range is often the arm stretched out — the UR3's zero pose, a
singular configuration where the task laws' inertia is damped and robot-derived gains are
scaled at a pose no run should sit at. :func:`choose_home` picks, deterministically, the most
dexterous of :data:`CANDIDATES` configurations spread (a Halton sequence, unscrambled) over the
middle half of each joint's range (a margin of a quarter of the range to each limit; ±π/2 about
0 for a joint without limits), plus the middle itself:

    score(q) = σ_min(J̃(q)) / σ_max(J̃(q)) − :data:`CENTRE_WEIGHT` × mean_j ((q_j − m_j) / h_j)²

with ``J̃`` the end-effector Jacobian (world-aligned) on the rows the arm can move — all six
when it can, the orientation rows scaled by the arm's reach so that they weigh as positions,
else its position rows — ``m`` the middle and ``h`` the half-range of each joint. The ratio is
the inverse condition number of ``J̃`` (1: isotropic, 0: singular); the second term keeps the
home near the middle when the arm is as dexterous elsewhere. Candidates whose end effector is
below the base (along gravity) are left out when any is above it (an arm on a table), and each
joint of the best one is then moved back to (or halfway to) its middle where that costs less
than 2 % of the dexterity (a base's yaw, on which no dexterity depends, sits at its middle).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin

CANDIDATES = 256
"""Configurations tried besides the middle."""
CENTRE_WEIGHT = 0.5
"""Weight of the (normalised, squared) distance from the middle in the score."""
UNLIMITED_HALF_RANGE = np.pi
"""Half-range [rad] taken for a joint without position limits (its candidates: ±π/2 about 0)."""


class Home(NamedTuple):
    """A chosen home and how it was chosen."""

    q: np.ndarray
    """The configuration [rad or m], shape (nv,)."""
    dexterity: float
    """``σ_min/σ_max`` of the scaled Jacobian there (1 isotropic, 0 singular)."""
    middle_dexterity: float
    """The same at the middle of the ranges."""

    def describe(self) -> str:
        """How it was chosen, in one line (``info`` shows it)."""
        return (
            f"chosen: the most dexterous of {CANDIDATES + 1} configurations in the middle half of each joint's "
            f"range (σ_min/σ_max of the end-effector Jacobian {self.dexterity:.3g}; at the middle of the ranges "
            f"{self.middle_dexterity:.3g})"
        )


def _middle(model: pin.Model) -> tuple[np.ndarray, np.ndarray]:
    """The middle and half-range of each joint (0 and π without limits)."""
    lower, upper = np.array(model.lowerPositionLimit), np.array(model.upperPositionLimit)
    finite = np.isfinite(lower) & np.isfinite(upper)
    middle = np.where(finite, 0.5 * (np.where(finite, lower, 0.0) + np.where(finite, upper, 0.0)), 0.0)
    half = np.where(
        finite, 0.5 * (np.where(finite, upper, 0.0) - np.where(finite, lower, 0.0)), UNLIMITED_HALF_RANGE
    )
    return middle, half


def _reach(model: pin.Model, frame: int) -> float:
    """A length scale [m]: the sum of the joint offsets and the frame's, at least 0.1 m."""
    lengths = [float(np.linalg.norm(model.jointPlacements[j].translation)) for j in range(1, model.njoints)]
    lengths.append(float(np.linalg.norm(model.frames[frame].placement.translation)))
    return max(sum(lengths), 0.1)


def _singular_values(model: pin.Model, data: pin.Data, frame: int, q: np.ndarray, reach: float) -> np.ndarray:
    """Singular values of the end-effector Jacobian at ``q``: all six rows (orientation × reach)
    first, then the position rows alone, (6 + 3,) descending each."""
    J = np.array(pin.computeFrameJacobian(model, data, q, frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED))
    J = J.reshape(6, model.nv)  # one joint: Pinocchio gives a vector
    J[3:] *= reach
    full = np.zeros(6)
    full[: min(6, model.nv)] = np.linalg.svd(J, compute_uv=False)[:6]
    position = np.zeros(3)
    position[: min(3, model.nv)] = np.linalg.svd(J[:3], compute_uv=False)[:3]
    return np.concatenate([full, position])


def _rank(values: np.ndarray) -> tuple[int, int]:
    """Which singular value of :func:`_singular_values` the dexterity divides (its column) and
    the arm's generic rank there: six when some candidate moves all six rows, else the rank of
    its position rows (a planar arm's two)."""

    def rank(s: np.ndarray) -> int:
        return int(np.max(np.sum(s > 1e-9 * np.maximum(s[:, :1], 1e-300), axis=1)))

    if rank(values[:, :6]) == 6:
        return 5, 0
    r = rank(values[:, 6:])
    return (6 + r - 1, 6) if r else (-1, 6)


def _dexterity(values: np.ndarray, column: int, first: int) -> np.ndarray:
    """``σ_r/σ_1`` per row of :func:`_singular_values` (``column``, ``first``: from :func:`_rank`)."""
    if column < 0:
        return np.zeros(len(values))
    return values[:, column] / np.maximum(values[:, first], 1e-300)


def _height(model: pin.Model, data: pin.Data, frame: int, q: np.ndarray) -> float:
    """The end effector's height above the base [m], along the gravity's upward direction (z when
    the model has no gravity)."""
    pin.framesForwardKinematics(model, data, q)
    g = np.array(model.gravity.linear)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    return float(up @ data.oMf[frame].translation)


def choose_home(model: pin.Model, frame: int) -> Home:
    """The home of an arm whose profile gives none (module docstring)."""
    from scipy.stats import qmc  # here: importing the CLI stays light (tests/test_startup.py)

    data = model.createData()
    middle, half = _middle(model)
    reach = _reach(model, frame)
    sampler = qmc.Halton(d=model.nv, scramble=False)
    unit = sampler.random(CANDIDATES + 1)[1:]  # the sequence's first point is the origin
    candidates = np.vstack([middle, middle + (unit - 0.5) * half])
    values = np.array([_singular_values(model, data, frame, q, reach) for q in candidates])
    column, first = _rank(values)
    dexterity = _dexterity(values, column, first)
    score = dexterity - CENTRE_WEIGHT * np.mean(((candidates - middle) / half) ** 2, axis=1)
    above = np.array([_height(model, data, frame, q) >= 0.0 for q in candidates])
    if above.any():  # an arm on a table: its end effector above its base where it can be
        score = np.where(above, score, -np.inf)
    best = int(np.argmax(score))
    q, dex = np.array(candidates[best], dtype=float), float(dexterity[best])
    for j in range(model.nv):  # each joint back to its middle where that costs (almost) nothing
        for fraction in (1.0, 0.5):
            trial = q.copy()
            trial[j] += fraction * (middle[j] - q[j])
            value = float(
                _dexterity(_singular_values(model, data, frame, trial, reach)[None], column, first)[0]
            )
            if value >= KEEP * dex and (not above.any() or _height(model, data, frame, trial) >= 0.0):
                q, dex = trial, value
                break
    return Home(q, dex, float(dexterity[0]))


KEEP = 0.98
"""A joint of the best candidate goes back to (or halfway to) its middle if the dexterity stays
above this fraction (a base's yaw, which no dexterity depends on, sits at its middle)."""
