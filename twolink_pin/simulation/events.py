"""What a plant that pushes back (:mod:`twolink_pin.disturbances`) does to the engine's step.

:func:`~twolink_pin.simulation.engine.integrate` is the one RK4 loop; for a plant with
events it asks :class:`PlantEvents` (built once per run) at each step k (``t_k = k dt``):

* :meth:`PlantEvents.accel_at` — the plant over step k:
  ``q̈ = ABA_k(q, q̇, sat(τ) − f(q̇) + J(q)ᵀ F_k + τ_c(q, q̇))`` with ``ABA_k`` on the model with
  the payload from its step on, ``F_k`` the wrench if on during step k (``J`` the wrench
  frame's world-aligned Jacobian at each RK4 stage), ``τ_c`` the contact's joint torque with a
  scene (:attr:`PlantEvents.contact`, :class:`~twolink_pin.contact.CompliantContact`); neither
  is saturated (the motors' limits clip the motors' torque only). A contact its engine applies
  itself (``pushes`` False: MuJoCo's, :mod:`twolink_pin.mujoco_contact`) adds no ``τ_c`` and
  follows (``follow``) the step's dynamics, whose runs it reads;
* :meth:`PlantEvents.noise_at` — the law's measurement offset ``(q, q̇) + noise_k`` (one
  noise sample per step and run, from the run's own generator, drawn block by block so that
  a run's noise does not depend on its batch; :meth:`PlantEvents.draw` per block), and the
  force sensor's (:meth:`PlantEvents.force_noise`, with ``sigma_f``);
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

from twolink_pin.contact.compliant import check_start
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
    """``dynamics`` with the generalized forces from outside the motors (the wrench's
    ``J(q)ᵀ F``, the contact's ``τ_c``) added after the motors' torque is clipped: at every RK4
    stage, or at the start of a step that the plant's own integrator takes (``held_step``:
    MuJoCo's Euler and implicitfast evaluate their forces once per step). ``external(q, q̇)``
    gives them, (N, nv) [N·m], or None (nothing pushes)."""

    def __init__(
        self, dynamics: Accel, external: Callable[[np.ndarray, np.ndarray], np.ndarray | None]
    ) -> None:
        self._dynamics = dynamics
        self._external = external
        if hasattr(dynamics, "held_step"):
            self.held_step = self._held_step

    def __call__(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return self._dynamics(q, v, tau, self._external(q, v)).copy()  # type: ignore[call-arg]

    def _held_step(self, q: np.ndarray, v: np.ndarray, z: np.ndarray, tau: np.ndarray, *rest: Any) -> Any:
        held = self._dynamics.held_step  # type: ignore[attr-defined]
        return held(q, v, z, tau, *rest, external=self._external(q, v))


class PlantEvents:
    """The events of ``plant`` for ``runs`` runs advanced together (see module doc)."""

    def __init__(
        self, plant: Plant, runs: int, threads: int | None, nv: int, dt: float | None = None
    ) -> None:
        self._plant = plant
        self._before = dynamics_for(plant, runs, threads)
        self._after_plant = payload_plant(plant) if plant.payload_step is not None else None
        self._after = (
            dynamics_for(self._after_plant, runs, threads) if self._after_plant is not None else None
        )
        self._payload_time = plant.payload_step.time if plant.payload_step is not None else np.inf
        self._accels: dict[tuple[bool, bool], Accel] = {}  # (payload on, wrench on) → q̈
        self._wrench = plant.wrench
        self._kinematics = RigidBodyTerms(plant.robot, None) if self._wrench is not None else None
        self._force = None if self._wrench is None else self._wrench.forces(runs)
        self.noise = plant.sensor_noise
        self._generators = self.noise.generators(runs) if self.noise is not None else []
        self._block: tuple[np.ndarray, np.ndarray] | None = None
        self._k0 = 0
        self._k = 0
        self.contact = plant.contact_model(runs, dt)
        """The plant's contact with its scene (:meth:`~twolink_pin.plant.Plant.contact_model`;
        None without one); ``dt`` [s]: the step it is checked against."""
        self._follow = getattr(self.contact, "follow", None)
        self._pushes = getattr(self.contact, "pushes", True)
        self.felt = self.noise is not None and self.noise.sigma_f > 0 and self.contact is not None
        """Whether the force sensor is noisy (:meth:`force_noise`)."""
        self._force_generators = (
            self.noise.force_generators(runs) if self.felt and self.noise is not None else []
        )
        self._force_block: np.ndarray | None = None
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

    def check_start(self, q0: np.ndarray) -> None:
        """Refuse runs that start inside a surface of the scene (``q0`` (N, nv) [rad])."""
        if self.contact is not None:
            check_start(self._plant.robot, self.contact.scene, q0)

    def accel_at(self, t: float) -> Accel:
        """The plant's ``q̈`` over the step that starts at ``t`` [s]."""
        after = self._after is not None and t >= self._payload_time
        wrench, contact = self._wrench, self.contact
        pushing = wrench is not None and wrench.active(t)
        if contact is not None:
            contact.time = t
        key = (after, pushing)
        accel = self._accels.get(key)
        if accel is None or self._follow is not None:
            dynamics = self._after if after and self._after is not None else self._before
            if self._follow is not None:  # a contact its engine computes: read from these runs
                self._follow(dynamics)
            if accel is None:
                accel = self._accels[key] = self._accel(dynamics, pushing)
        return accel

    def _accel(self, dynamics: Accel, pushing: bool) -> Accel:
        """``q̈`` of ``dynamics`` with the wrench (``pushing``) and the contact, if any."""
        contact = self.contact if self._pushes else None  # else its engine applies it itself
        if not pushing and contact is None:
            if hasattr(dynamics, "held_step"):  # a plant that steps itself: returns fresh arrays
                return dynamics
            return lambda q, v, tau: dynamics(q, v, tau).copy()
        kinematics, force = self._kinematics, self._force
        frame = None if self._wrench is None else self._wrench.frame
        free = getattr(contact, "free", None)  # what it answers when no run touches: nothing to add

        def external(q: np.ndarray, v: np.ndarray) -> np.ndarray | None:
            touched = None if contact is None else contact(q, v)
            torque = None if touched is None or touched is free else touched.tau
            if pushing:
                assert kinematics is not None and force is not None
                J = kinematics.frame(q, np.zeros_like(v), frame).jacobian
                pushed = np.vecmat(np.broadcast_to(force, (J.shape[0], 6)), J)
                torque = pushed if torque is None else torque + pushed
            return torque

        return Pushed(dynamics, external)

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
        if self._force_generators:
            forces = np.stack([g.standard_normal((k1 - k0, 3)) for g in self._force_generators], axis=1)
            self._force_block = np.concatenate([noise.sigma_f * forces, np.zeros_like(forces)], axis=2)

    def noise_at(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The offsets on ``(q, q̇)`` the law measures at step k, each (N, nv)."""
        assert self._block is not None
        self._k = k
        return self._block[0][k - self._k0], self._block[1][k - self._k0]

    def force_noise(self) -> np.ndarray | None:
        """The offset on the wrench [N; N·m] the force sensor reads during the step of the last
        :meth:`noise_at`, (N, 6) (moments exact); None without force noise."""
        block = self._force_block
        return None if block is None else block[self._k - self._k0]


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
