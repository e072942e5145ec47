"""What a plant that pushes back (:mod:`twolink_pin.disturbances`) does to the engine's step.

:func:`~twolink_pin.simulation.engine.integrate` is the one RK4 loop; for a plant with
events it asks :class:`PlantEvents` (built once per run) at each step k (``t_k = k dt``):

* :meth:`PlantEvents.accel_at` — the plant over step k:
  ``q̈ = ABA_k(q, q̇, sat(τ) − f(q̇) + J(q)ᵀ F_k)`` with ``ABA_k`` on the model with the
  payload from its step on, ``F_k`` the wrench if on during step k (``J`` the wrench
  frame's world-aligned Jacobian at each RK4 stage);
* :meth:`PlantEvents.noise_at` — the law's measurement offset ``(q, q̇) + noise_k`` (one
  noise sample per step and run, from the run's own generator, drawn block by block so that
  a run's noise does not depend on its batch; :meth:`PlantEvents.draw` per block);
* :meth:`PlantEvents.stop` — with ``position_stops``, after step k: each joint beyond its
  range put back at the bound and its velocity into the stop removed by an inelastic impact
  (:mod:`twolink_pin.simulation.stops`, on the model of step k);
* :class:`DelayLine` — with ``delay = d`` the law is sampled (every step, or every control
  period) and step k applies the torque computed at the latest sample ``<= k − d`` (before
  the first such sample: the first torque computed); ``z`` advances by ``dt ż`` with the
  undelayed ż. The recorded command is the torque applied.

This module holds the events' effect on the step only; the loop, the recording and the
divergence checks are the engine's.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from twolink_pin.plant import Plant
from twolink_pin.simulation.forward import dynamics_for
from twolink_pin.simulation.rigid_terms import RigidBodyTerms
from twolink_pin.simulation.stops import JointStops

Accel = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
"""``(q, v, tau) -> q̈`` for N runs."""


def payload_plant(plant: Plant) -> Plant:
    """``plant`` with its payload step's mass carried from the start (the plant after the step:
    :meth:`~twolink_pin.plant.Plant.after_payload`, its engine's)."""
    return plant.after_payload()


class Pushed:
    """``dynamics`` with the wrench's generalized force ``J(q)ᵀ F`` added to the torque: at every
    RK4 stage, or at the start of a step that the plant's own integrator takes (``held_step``:
    MuJoCo's Euler and implicitfast evaluate their forces once per step)."""

    def __init__(self, dynamics: Accel, push: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> None:
        self._dynamics = dynamics
        self._push = push
        if hasattr(dynamics, "held_step"):
            self.held_step = self._held_step

    def __call__(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return self._dynamics(q, v, self._push(q, tau)).copy()

    def _held_step(self, q: np.ndarray, v: np.ndarray, z: np.ndarray, tau: np.ndarray, *rest: Any) -> Any:
        return self._dynamics.held_step(q, v, z, self._push(q, tau), *rest)  # type: ignore[attr-defined]


class PlantEvents:
    """The events of ``plant`` for ``runs`` runs advanced together (see module doc)."""

    def __init__(self, plant: Plant, runs: int, threads: int | None, nv: int) -> None:
        self._plant = plant
        self._before = dynamics_for(plant, runs, threads)
        self._after_plant = payload_plant(plant) if plant.payload_step is not None else None
        self._after = (
            dynamics_for(self._after_plant, runs, threads) if self._after_plant is not None else None
        )
        self._payload_time = plant.payload_step.time if plant.payload_step is not None else np.inf
        self._wrench = plant.wrench
        self._kinematics = RigidBodyTerms(plant.robot, None) if self._wrench is not None else None
        self._force = None if self._wrench is None else self._wrench.forces(runs)
        self.noise = plant.sensor_noise
        self._generators = self.noise.generators(runs) if self.noise is not None else []
        self._block: tuple[np.ndarray, np.ndarray] | None = None
        self._k0 = 0
        self.delay = plant.delay
        self._nv = nv
        self.stops = None
        if plant.position_stops:
            after = self._after_plant.model if self._after_plant is not None else plant.model
            self.stops = (JointStops(plant.joint_limits, plant.model), JointStops(plant.joint_limits, after))

    def stop(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The state after the step that starts at ``t`` [s] with the joint stops applied."""
        assert self.stops is not None
        return self.stops[t >= self._payload_time](q, v)

    def accel_at(self, t: float) -> Accel:
        """The plant's ``q̈`` over the step that starts at ``t`` [s]."""
        dynamics = self._after if self._after is not None and t >= self._payload_time else self._before
        wrench = self._wrench
        if wrench is None or not wrench.active(t):
            if hasattr(dynamics, "held_step"):  # a plant that steps itself: returns fresh arrays
                return dynamics
            return lambda q, v, tau: dynamics(q, v, tau).copy()
        kinematics, force, frame = self._kinematics, self._force, wrench.frame
        assert kinematics is not None and force is not None

        def push(q: np.ndarray, tau: np.ndarray) -> np.ndarray:
            J = kinematics.frame(q, np.zeros_like(q), frame).jacobian
            return tau + np.vecmat(np.broadcast_to(force, (J.shape[0], 6)), J)

        return Pushed(dynamics, push)

    def failure(self, run: int) -> str | None:
        """The plant's own cause of run ``run``'s failure (its engine's), if it knows one."""
        for dynamics in (self._after, self._before):
            reason = getattr(dynamics, "failure", None)
            text = reason(run) if reason is not None else None
            if text:
                return str(text)
        return None

    def draw(self, k0: int, k1: int) -> None:
        """Draw the noise of steps ``k0 … k1 − 1`` (one block; every run its own generator)."""
        noise = self.noise
        if noise is None:
            return
        nv = self._nv
        draws = np.stack([g.standard_normal((k1 - k0, 2 * nv)) for g in self._generators], axis=1)
        self._block = (noise.sigma_q * draws[..., :nv], noise.sigma_v * draws[..., nv:])
        self._k0 = k0

    def noise_at(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The offsets on ``(q, q̇)`` the law measures at step k, each (N, nv)."""
        assert self._block is not None
        return self._block[0][k - self._k0], self._block[1][k - self._k0]


class DelayLine:
    """The law's sampled outputs, applied ``delay`` steps late (see module doc)."""

    def __init__(self, delay: int) -> None:
        self.delay = delay
        self._outputs: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # sample step -> (τ, ż)
        self._first: np.ndarray | None = None

    def push(self, k: int, tau: np.ndarray, dz: np.ndarray) -> None:
        """The law's output sampled at step k."""
        self._outputs[k] = (tau, dz)
        if self._first is None:
            self._first = tau

    def at(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """``(τ applied, ż)`` over step k."""
        outputs = self._outputs
        sample = max((s for s in outputs if s <= k - self.delay), default=None)
        for s in [s for s in outputs if sample is not None and s < sample]:
            del outputs[s]
        dz = outputs[max(s for s in outputs if s <= k)][1]
        assert self._first is not None
        return (self._first if sample is None else outputs[sample][0]), dz


__all__ = ["DelayLine", "PlantEvents", "Pushed", "payload_plant"]
