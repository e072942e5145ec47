"""The plant's accelerations for N runs: ``pin.aba`` for one, ``abaInParallel`` for many, or the
plant's own engine's (:meth:`~twolink_pin.plant.Plant.dynamics`: MuJoCo's)."""

from __future__ import annotations

from functools import partial
from typing import Any

import numpy as np
import pinocchio as pin

from twolink_pin.dynamics import ABA_CONVENTION, smooth_sign
from twolink_pin.plant import Plant
from twolink_pin.simulation.terms import check_parallel, threads_for


class SingleRunDynamics:
    """``q̈`` [rad/s²] of one run, shape (1, nv), from ``(1, nv)`` state and torque."""

    def __init__(self, plant: Plant) -> None:
        self._plant = plant
        self._model = plant.model
        self._data = plant.model.createData()
        self._nv = plant.model.nv
        friction = plant.friction
        # (1, nv) rows: numpy's fast path against the (1, nv) state
        self._friction = (
            None if friction is None else (np.array([friction.viscous]), np.array([friction.coulomb]))
        )
        smoothing = 0.0 if friction is None else friction.smoothing
        self._sign = np.sign if smoothing == 0 else partial(smooth_sign, smoothing=smoothing)
        self._damping = plant.joint_damping[None] if plant.joint_damping.any() else None
        # plant.applied_torque's clip as maximum then minimum against (1, nv) rows: the same
        # values (clip is min(max(τ, −limit), limit), NaN passed through) at a third of
        # np.clip's cost
        self._saturate = (-plant.limits[None], plant.limits[None]) if plant.saturate else None

    def __call__(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, external: np.ndarray | None = None
    ) -> np.ndarray:
        """``external``: a joint torque [N·m] the world adds (a wrench's or a contact's ``Jᵀ f``), never
        saturated, (1, nv) or None."""
        # plant.motor_torque, spelled out with the rows above: this runs four times per step.
        saturate = self._saturate
        u = tau if saturate is None else np.minimum(np.maximum(tau, saturate[0]), saturate[1])
        if self._friction is not None:
            viscous, coulomb = self._friction
            u = u - (viscous * v + coulomb * self._sign(v))
        if self._damping is not None:
            u = u - self._damping * v
        if external is not None:
            u = u + external
        return pin.aba(self._model, self._data, q[0], v[0], u[0], ABA_CONVENTION)[None]


class BatchDynamics:
    """``q̈`` [rad/s²] of N runs, shape (N, nv), one ``abaInParallel`` call."""

    def __init__(self, plant: Plant, runs: int, threads: int | None) -> None:
        check_parallel()
        self._plant = plant
        self._threads = threads_for(runs, threads)
        self._pool = pin.ModelPool(plant.model, self._threads)
        # RK4 keeps the four stages' accelerations alive at once: four output buffers in turn.
        self._outs = [np.empty((runs, plant.model.nv)) for _ in range(4)]
        self._next = 0
        self._plain = plant.friction is None and not plant.saturate and not plant.joint_damping.any()

    def __call__(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, external: np.ndarray | None = None
    ) -> np.ndarray:
        """The result is valid until the fourth call after this one; ``external`` as in
        :meth:`SingleRunDynamics.__call__`, (N, nv)."""
        u = tau if self._plain else self._plant.motor_torque(v, tau)
        if external is not None:
            u = u + external
        out = self._outs[self._next]
        self._next = (self._next + 1) % 4
        pin.abaInParallel(
            self._threads,
            self._pool,
            np.ascontiguousarray(q).T,
            np.ascontiguousarray(v).T,
            np.ascontiguousarray(u).T,
            out.T,
        )
        return out


def dynamics_for(plant: Plant, runs: int, threads: int | None = None) -> Any:
    """The plant's acceleration function for ``runs`` runs advanced together: the plant's own
    engine's (MuJoCo's), else Pinocchio's ABA."""
    own = plant.dynamics(runs, threads_for(runs, threads) if runs > 1 else 1)
    if own is not None:
        return own
    return SingleRunDynamics(plant) if runs == 1 else BatchDynamics(plant, runs, threads)
