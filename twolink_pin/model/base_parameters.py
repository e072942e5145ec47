"""The identifiable base parameters of a model, found numerically from Pinocchio's regressor.

The joint torques are linear in the ten inertial parameters of every body,
``τ = Y_π(q, q̇, q̈) π``, but not every column of ``Y_π`` is independent: some parameters
never act (a body's inertia about an axis it cannot turn about), some only in fixed linear
combinations (a link's mass with the next link's first moment). The **base parameters**
``β`` are a minimal set of such combinations: ``Y_π π = Y_β β`` for every state, with ``Y_β``
of full column rank — the parameters an identification (or an adaptive law) can recover.

Following Gautier (1990, "Numerical calculation of the base inertial parameters of
robots"): stack ``Y_π`` at random states into ``W`` (``m × n_π``, m ≫ n_π), take a QR
decomposition with column pivoting ``W Π = Q R``; the rank r is the number of diagonal
entries of R above a tolerance. Which r standard parameters to keep is a choice: the
first r independent columns in a fixed order of preference (:data:`PREFERENCE`: first
moments, inertias, masses last, as the classic symbolic regrouping does), and the
others are ``W_d = W_b K`` (least squares, exact to rounding). Then

    β = π_b + K π_d,       Y_β = Y_π P   (P selects the kept columns),

and each β is named after its terms, in the links' names, e.g.
``upper_arm_link.mcz + 0.425 forearm_link.m`` (the parameters of the body a joint moves:
its link and any links fixed to it).
The kept parameters are listed in Pinocchio's order; coefficients below 1e-10 (relative)
are set to 0 and the rest rounded to 12 significant digits, so that names are stable.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from twolink_pin.model.parameters import (
    BODY_PARAMETER_NAMES,
    BODY_PARAMETER_UNITS,
    N_BODY_PARAMETERS,
    ParameterMap,
    inertial_parameters,
)

RANK_TOLERANCE = 1e-9
"""A pivot of R below this fraction of the largest one counts as zero (relative to the
column scales, which are of order one here: unit states, SI parameters)."""
COEFFICIENT_TOLERANCE = 1e-10
"""Entries of K below this (absolute) are exact zeros of the combination."""


def body_name(model: pin.Model, joint: int) -> str:
    """The name of the link joint ``joint`` moves (its first body frame), else the joint's."""
    for frame in model.frames:
        if frame.parentJoint == joint and frame.type == pin.FrameType.BODY:
            return str(frame.name)
    return str(model.names[joint])


def _stacked_regressor(model: pin.Model, samples: int, seed: int) -> np.ndarray:
    """``Y_π`` at ``samples`` random states (q within the limits, q̇, q̈ uniform in ±2), stacked."""
    data = model.createData()
    lower = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -np.pi)
    upper = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, np.pi)
    lower, upper = np.maximum(lower, -np.pi), np.minimum(upper, np.pi)
    upper = np.where(upper > lower, upper, lower + 1e-3)
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(samples):
        q = rng.uniform(lower, upper)
        v, a = rng.uniform(-2.0, 2.0, (2, model.nv))
        rows.append(pin.computeJointTorqueRegressor(model, data, q, v, a).copy())
    return np.vstack(rows)


PREFERENCE = ("mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz", "m")
"""Which of a body's parameters to keep when several are interchangeable: its first moments,
then its inertia, its mass last (a link's mass acts only through the links before it, so
it is folded into their parameters, as in the classic regrouping ``ZZ₁ + l₁² m₂``)."""


def _preferred_columns(W: np.ndarray, rank: int, bodies: int) -> np.ndarray | None:
    """The first ``rank`` independent columns of ``W`` in the order bodies 1..n, each body's
    parameters in :data:`PREFERENCE` order (an unpivoted QR in that order: a column is
    independent of those before it when the part of it they do not explain is more than
    ``RANK_TOLERANCE`` of its norm). None if that does not give ``rank`` columns."""
    order = np.array(
        [
            N_BODY_PARAMETERS * b + BODY_PARAMETER_NAMES.index(name)
            for b in range(bodies)
            for name in PREFERENCE
        ]
    )
    norms = np.linalg.norm(W[:, order], axis=0)
    live = norms > RANK_TOLERANCE * max(float(norms.max()), 1e-300)
    candidates = order[live]
    import scipy.linalg  # 0.4 s to import: only for robots without a profile's parameter map

    R = scipy.linalg.qr(W[:, candidates], mode="r")[0]
    diagonal = np.abs(np.diag(R))[: len(candidates)]
    independent = diagonal > np.sqrt(RANK_TOLERANCE) * norms[live][: diagonal.size]
    kept = np.sort(candidates[: diagonal.size][independent])
    return kept if kept.size == rank else None


class BaseParameterMap(ParameterMap):
    """``β = B π``, ``Y_β = Y_π P``: the base parameters of ``model`` (see the module docstring).

    Args:
        model: The Pinocchio model (its kinematics and gravity; the inertias do not matter).
        samples: Random states stacked (default ``max(40, 3 n_π / nv)``).
        seed: Seed of the states.

    Attributes:
        kept: Indices (into π) of the standard parameters kept, in Pinocchio's order.
        combination: ``B``, shape (n_β, n_π).
    """

    def __init__(self, model: pin.Model, samples: int | None = None, seed: int = 0) -> None:
        n_pi = N_BODY_PARAMETERS * (model.njoints - 1)
        count = samples if samples is not None else max(40, (3 * n_pi) // max(1, model.nv))
        W = _stacked_regressor(model, count, seed)
        import scipy.linalg  # 0.4 s to import: only for robots without a profile's parameter map

        _, R, pivots = scipy.linalg.qr(W, mode="economic", pivoting=True)
        diagonal = np.abs(np.diag(R))
        rank = (
            int(np.sum(diagonal > RANK_TOLERANCE * diagonal[0])) if diagonal.size and diagonal[0] > 0 else 0
        )
        kept = _preferred_columns(W, rank, model.njoints - 1)
        if kept is None:
            kept = np.sort(pivots[:rank])
        others = np.array([j for j in range(n_pi) if j not in set(kept.tolist())], dtype=int)
        W_b = W[:, kept]
        K = np.linalg.lstsq(W_b, W[:, others], rcond=None)[0] if others.size else np.zeros((rank, 0))
        K[np.abs(K) < COEFFICIENT_TOLERANCE] = 0.0
        K = np.array([[float(f"{x:.12g}") for x in row] for row in K]).reshape(rank, others.size)
        B = np.zeros((rank, n_pi))
        B[np.arange(rank), kept] = 1.0
        B[:, others] = K
        P = np.zeros((n_pi, rank))
        P[kept, np.arange(rank)] = 1.0
        standard = [
            f"{body_name(model, j)}.{name}" for j in range(1, model.njoints) for name in BODY_PARAMETER_NAMES
        ]
        units = BODY_PARAMETER_UNITS * (model.njoints - 1)
        names = []
        for i, k in enumerate(kept):
            terms = [standard[k]]
            for j, d in enumerate(others):
                c = K[i, j]
                if c != 0.0:
                    terms.append(f"{'+' if c > 0 else '-'} {abs(c):.4g} {standard[d]}")
            names.append(" ".join(terms))
        self.names = tuple(names)
        self.units = tuple(units[k] for k in kept)
        self.kept = kept
        self.combination = B
        self.combination.setflags(write=False)
        P.setflags(write=False)
        self._matrix = P

    @property
    def matrix(self) -> np.ndarray:
        return self._matrix

    def values(self, model: pin.Model) -> np.ndarray:
        """``β = B π`` of ``model``."""
        return np.asarray(self.combination @ inertial_parameters(model), dtype=float)
