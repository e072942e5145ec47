"""The simulated arm: Pinocchio's forward dynamics plus friction and motor saturation.

``q̈ = ABA(q, q̇, sat(τ) − f(q̇))`` where ``f`` is the optional joint friction
(:class:`twolink_pin.dynamics.Friction`; Pinocchio ignores URDF friction) and ``sat``
clips to the URDF torque limits when ``saturate`` is on (off by default, as in the report).
A plant may also push back (:mod:`twolink_pin.disturbances`: a wrench, a payload step,
sensor noise, a delay; none by default); the engine then runs
:mod:`twolink_pin.simulation.events`.
:meth:`Plant.applied_torque` and :meth:`Plant.motor_torque` work on one state ``(nv,)`` or
on N runs ``(N, nv)``; the engine evaluates ABA itself for all runs at once
(:mod:`twolink_pin.simulation.forward`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from twolink_pin.disturbances import PayloadStep, SensorNoise, Wrench, check_delay
from twolink_pin.dynamics import ABA_CONVENTION, Friction
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel


class Plant:
    """Forward dynamics of ``robot`` with optional friction and torque saturation.

    Args:
        robot: The arm.
        friction: Joint friction; None for none.
        saturate: Clip commanded torques at the URDF effort limits (joints without a
            limit are never clipped).
    """

    def __init__(
        self,
        robot: RobotModel,
        friction: Friction | None = None,
        saturate: bool = False,
        *,
        wrench: Wrench | None = None,
        payload_step: PayloadStep | None = None,
        sensor_noise: SensorNoise | None = None,
        delay: int = 0,
    ) -> None:
        if not isinstance(robot, RobotModel):
            raise InvalidParameterError(
                "robot", type(robot).__name__, "a RobotModel (twolink_pin.load_robot)"
            )
        if friction is not None and not isinstance(friction, Friction):
            raise InvalidParameterError("friction", type(friction).__name__, "a twolink_pin Friction or None")
        if friction is not None and len(friction.viscous) != robot.nv:
            raise InvalidParameterError(
                "friction", friction, f"viscous and coulomb of length nv = {robot.nv}"
            )
        if not isinstance(saturate, bool):
            raise InvalidParameterError("saturate", saturate, "True or False")
        self.robot = robot
        self.model = robot.model
        self.friction = friction
        self.saturate = saturate
        self.limits = np.array(robot.torque_limits, dtype=float)
        self.limits.setflags(write=False)
        for name, value, kind in (
            ("wrench", wrench, Wrench),
            ("payload_step", payload_step, PayloadStep),
            ("sensor_noise", sensor_noise, SensorNoise),
        ):
            if value is not None and not isinstance(value, kind):
                raise InvalidParameterError(
                    name, value, f"a twolink_pin.disturbances.{kind.__name__} or None"
                )
        if wrench is not None and wrench.frame is not None and not robot.model.existFrame(wrench.frame):
            raise InvalidParameterError(
                "wrench.frame",
                wrench.frame,
                f"a frame of {robot.name}: {[f.name for f in robot.model.frames]}",
            )
        self.wrench = wrench
        """External wrench on a frame over a time window (:mod:`twolink_pin.disturbances`)."""
        self.payload_step = payload_step
        """Payload picked up at a time (the law not told)."""
        self.sensor_noise = sensor_noise
        """Noise on the q, q̇ the law measures."""
        self.delay = check_delay(delay)
        """Steps between a measurement and the torque it produces."""

    @property
    def has_events(self) -> bool:
        """Whether the plant pushes back: a wrench, a payload step, sensor noise or a delay."""
        return (
            any(x is not None for x in (self.wrench, self.payload_step, self.sensor_noise)) or self.delay > 0
        )

    def applied_torque(self, tau: np.ndarray) -> np.ndarray:
        """Motor torque actually applied [N·m]: ``tau`` clipped to the limits if saturating."""
        return np.clip(tau, -self.limits, self.limits) if self.saturate else tau

    def motor_torque(self, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """What drives the rigid bodies [N·m]: ``sat(τ) − f(q̇)``."""
        u = self.applied_torque(tau)
        return u if self.friction is None else u - self.friction.torque(v)

    def acceleration(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Joint acceleration [rad/s²] of one state under commanded torque ``tau`` [N·m]."""
        data = self.model.createData()
        return pin.aba(self.model, data, q, v, self.motor_torque(v, tau), ABA_CONVENTION).copy()

    def energy(self, q: np.ndarray, v: np.ndarray) -> float:
        """Mechanical energy ``½ q̇ᵀ M q̇ + U(q)`` [J] of one state."""
        data = self.model.createData()
        return float(pin.computeKineticEnergy(self.model, data, q, v)) + float(
            pin.computePotentialEnergy(self.model, data, q)
        )
