"""The plant's accelerations for N runs: ``pin.aba`` for one, ``abaInParallel`` for many, or the
plant's own engine's (:meth:`~twolink_pin.plant.Plant.dynamics`: MuJoCo's)."""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
import pinocchio as pin

from twolink_pin.dynamics import ABA_CONVENTION, smooth_sign
from twolink_pin.plant import Plant
from twolink_pin.simulation.terms import check_parallel, threads_for


def single_run_dynamics(plant: Plant) -> Callable[..., np.ndarray]:
    """``accel(q, v, tau, external=None)``: ``q̈`` [rad/s²] of one run, shape (1, nv), from
    ``(1, nv)`` state and torque; ``external`` is a joint torque [N·m] the world adds (a wrench's
    or a contact's ``Jᵀ f``), never saturated, (1, nv) or None.

    ``plant.motor_torque`` spelled out with (1, nv) rows (numpy's fast path against the (1, nv)
    state), then ABA: a closure over the plant's rows with only the effects this plant has (the
    engine calls it four times a step; no attribute lookups)."""
    model, data, aba, convention = plant.model, plant.model.createData(), pin.aba, ABA_CONVENTION
    friction = plant.friction
    viscous, coulomb = (
        (None, None) if friction is None else (np.array([friction.viscous]), np.array([friction.coulomb]))
    )
    smoothing = 0.0 if friction is None else friction.smoothing
    sign = np.sign if smoothing == 0 else partial(smooth_sign, smoothing=smoothing)
    damping = plant.joint_damping[None] if plant.joint_damping.any() else None
    # plant.applied_torque's clip as maximum then minimum against (1, nv) rows: the same values
    # (clip is min(max(τ, −limit), limit), NaN passed through) at a third of np.clip's cost
    saturate, low, high = plant.saturate, -plant.limits[None], plant.limits[None]
    if viscous is None and damping is None and not saturate:  # the plain arm: ABA alone

        def plain(
            q: np.ndarray, v: np.ndarray, tau: np.ndarray, external: np.ndarray | None = None
        ) -> np.ndarray:
            u = tau if external is None else tau + external
            return aba(model, data, q[0], v[0], u[0], convention)[None]

        return plain

    def accel(
        q: np.ndarray, v: np.ndarray, tau: np.ndarray, external: np.ndarray | None = None
    ) -> np.ndarray:
        u = np.minimum(np.maximum(tau, low), high) if saturate else tau
        if viscous is not None:
            u = u - (viscous * v + coulomb * sign(v))
        if damping is not None:
            u = u - damping * v
        if external is not None:
            u = u + external
        return aba(model, data, q[0], v[0], u[0], convention)[None]

    return accel


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
        :func:`single_run_dynamics`, (N, nv)."""
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
    return single_run_dynamics(plant) if runs == 1 else BatchDynamics(plant, runs, threads)
