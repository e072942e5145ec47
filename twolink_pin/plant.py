"""The simulated arm: Pinocchio's forward dynamics plus friction and motor saturation.

``q̈ = ABA(q, q̇, sat(τ) − f(q̇))`` where ``f`` is the optional joint friction
(:class:`twolink_pin.dynamics.Friction`; Pinocchio's ABA ignores URDF friction) and ``sat``
clips to the URDF torque limits when ``saturate`` is on (off by default, as in the report).
A plant may also push back (:mod:`twolink_pin.disturbances`: a wrench, a payload step,
sensor noise, a delay; none by default), and may make each joint's position range a hard
stop (``position_stops``: :mod:`twolink_pin.simulation.stops`, off by default: a joint then
passes its range and the run records the crossing); the engine then runs
:mod:`twolink_pin.simulation.events`.

:class:`Plant` is one frozen value; a variant is :func:`dataclasses.replace` of it.
:class:`PlantOptions` is what a run asks of its plant (the friction as a choice, the events);
:meth:`PlantOptions.plant` builds the plant from them, once.
:meth:`Plant.applied_torque` and :meth:`Plant.motor_torque` work on one state ``(nv,)`` or
on N runs ``(N, nv)``; the engine evaluates ABA itself for all runs at once
(:mod:`twolink_pin.simulation.forward`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.disturbances import PayloadStep, SensorNoise, Wrench, check_delay
from twolink_pin.dynamics import ABA_CONVENTION, Friction
from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import JointLimits, joint_limits
from twolink_pin.model import RobotModel

DEFAULT_FRICTION = (0.4, 0.2)
"""``(viscous [N·m·s/rad], coulomb [N·m])`` on every joint of a plant asked for friction
(``--plant-friction on``) whose robot has neither a profile friction nor a URDF
``<dynamics damping friction>``: the twolink's first joint's, as the identification runs use."""
FRICTION_CHOICES = ("law", "on", "off")
"""``PlantOptions.friction``: the profile's friction in the plant of a law that estimates
friction only (``law``, the report's experiments), in every plant (``on``), in none (``off``)."""
ADAPTIVE_SMOOTHING = 1e-3
"""ε [rad/s] of the friction sign with the adaptive integrator when none is given (the
exact sign stalls its step-size control); RK4 uses the exact sign (0)."""


def robot_friction(robot: RobotModel, smoothing: float = 0.0) -> tuple[Friction, str]:
    """The joint friction of ``robot`` and where it comes from: its profile's (the twolink:
    the report's), else its URDF's ``<dynamics damping friction>`` where any is non-zero,
    else :data:`DEFAULT_FRICTION` on every joint."""
    if robot.profile.friction is not None:
        viscous, coulomb = robot.profile.friction
        return Friction(viscous, coulomb, smoothing=smoothing), "the robot's profile"
    urdf = robot.urdf_friction
    if urdf is not None:
        return Friction(*urdf, smoothing=smoothing), "the URDF's <dynamics damping friction>"
    v, c = DEFAULT_FRICTION
    return (
        Friction((v,) * robot.nv, (c,) * robot.nv, smoothing=smoothing),
        "the default (no friction in the URDF)",
    )


class LinearTerms(NamedTuple):
    """The plant's joint-wise linear terms beyond the rigid bodies of ``plant.model``: what the
    step check (:mod:`twolink_pin.simulation.step_check`) adds to the arm's inertia, damping and
    stiffness when it finds the fastest mode of a run's start. A plant with effects of its own (a
    second engine's armature and joint damping, a contact's stiffness) gives them here."""

    armature: np.ndarray
    """Inertia added to each joint [kg·m² or kg], shape (nv,): what ``M(q)`` of ``plant.model``
    (Pinocchio's CRBA, its own ``armature`` included) does not hold."""
    damping: np.ndarray
    """``∂f/∂q̇`` of each joint's loss [N·m·s/rad], shape (nv,): the viscous friction (a URDF's
    ``<dynamics damping>``); Coulomb friction is not linear (its smoothed sign is bounded)."""
    stiffness: np.ndarray
    """``∂f/∂q`` of each joint [N·m/rad], shape (nv,): zeros here (a contact's, once surfaces exist)."""


@dataclass(frozen=True, eq=False)
class Plant:
    """Forward dynamics of ``robot`` with optional friction and torque saturation.

    Attributes:
        robot: The arm.
        friction: Joint friction; None for none.
        saturate: Clip commanded torques at the URDF effort limits (joints without a
            limit are never clipped).
        wrench: External wrench on a frame over a time window.
        payload_step: Payload picked up at a time (the law not told).
        sensor_noise: Noise on the q, q̇ the law measures.
        delay: Steps between a measurement and the torque it produces.
        position_stops: Make each joint's position range a hard, perfectly inelastic stop
            (:mod:`twolink_pin.simulation.stops`); joints without a range have none.
        model: The Pinocchio model integrated (default ``robot.model``; the model after a
            payload step in :func:`~twolink_pin.simulation.events.payload_plant`).
        friction_source: Where ``friction`` comes from, in words (the summaries show it).
    """

    robot: RobotModel
    friction: Friction | None = None
    saturate: bool = False
    _: dataclasses.KW_ONLY
    wrench: Wrench | None = None
    payload_step: PayloadStep | None = None
    sensor_noise: SensorNoise | None = None
    delay: int = 0
    position_stops: bool = False
    model: pin.Model = field(default=None, repr=False)
    friction_source: str = ""
    limits: np.ndarray = field(init=False, repr=False)
    """Effort limits [N·m], shape (nv,), read-only."""
    joint_limits: JointLimits = field(init=False, repr=False)
    """Every limit of every joint (:func:`~twolink_pin.limits.joint_limits` of the robot): what
    the run's crossings are counted against and where the stops are."""

    def __post_init__(self) -> None:
        robot, friction = self.robot, self.friction
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
        for name in ("saturate", "position_stops"):
            if not isinstance(getattr(self, name), bool):
                raise InvalidParameterError(name, getattr(self, name), "True or False")
        for name, kind in (("wrench", Wrench), ("payload_step", PayloadStep), ("sensor_noise", SensorNoise)):
            value = getattr(self, name)
            if value is not None and not isinstance(value, kind):
                raise InvalidParameterError(
                    name, value, f"a twolink_pin.disturbances.{kind.__name__} or None"
                )
        wrench = self.wrench
        if wrench is not None and wrench.frame is not None and not robot.model.existFrame(wrench.frame):
            raise InvalidParameterError(
                "wrench.frame",
                wrench.frame,
                f"a frame of {robot.name}: {[f.name for f in robot.model.frames]}",
            )
        check_delay(self.delay)
        if self.model is None:
            object.__setattr__(self, "model", robot.model)
        limits = np.array(robot.torque_limits, dtype=float)
        limits.setflags(write=False)
        object.__setattr__(self, "limits", limits)
        object.__setattr__(self, "joint_limits", joint_limits(robot))

    @property
    def has_events(self) -> bool:
        """Whether the plant pushes back: a wrench, a payload step, sensor noise, a delay or
        joint stops."""
        return (
            any(x is not None for x in (self.wrench, self.payload_step, self.sensor_noise))
            or self.delay > 0
            or self.position_stops
        )

    def applied_torque(self, tau: np.ndarray) -> np.ndarray:
        """Motor torque actually applied [N·m]: ``tau`` clipped to the limits if saturating."""
        return np.clip(tau, -self.limits, self.limits) if self.saturate else tau

    def linear_terms(self) -> LinearTerms:
        """The plant's linear terms beyond ``model``'s rigid bodies (:class:`LinearTerms`)."""
        nv = self.robot.nv
        damping = np.zeros(nv) if self.friction is None else np.array(self.friction.viscous, dtype=float)
        return LinearTerms(np.zeros(nv), damping, np.zeros(nv))

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

    def describe(self, values: bool = False) -> str:
        """Which plant this is, in a few words (the comparison table's column); ``values``:
        with the friction's values and where they come from (``simulate``'s summary)."""
        friction = self.friction
        if friction is None:
            parts = ["no friction"]
        elif not values:
            parts = ["friction"]
        else:
            parts = [
                f"friction V = ({', '.join(f'{x:g}' for x in friction.viscous)}) N·m·s/rad, "
                f"C = ({', '.join(f'{x:g}' for x in friction.coulomb)}) N·m"
                + (f" from {self.friction_source}" if self.friction_source else "")
            ]
        if self.saturate:
            parts.append("saturated")
        if self.wrench is not None:
            parts.append("wrench")
        if self.payload_step is not None:
            parts.append(f"payload {self.payload_step.mass:g} kg at {self.payload_step.time:g} s")
        if self.sensor_noise is not None:
            parts.append("sensor noise")
        if self.delay:
            parts.append(f"delay {self.delay} steps")
        if self.position_stops:
            parts.append("joint stops")
        return ", ".join(parts)

    def friction_dict(self) -> dict[str, Any] | None:
        """The plant's friction as JSON-ready data (None without): ``viscous`` [N·m·s/rad],
        ``coulomb`` [N·m], ``smoothing`` [rad/s] and ``source``."""
        friction = self.friction
        if friction is None:
            return None
        return {
            "viscous": list(friction.viscous),
            "coulomb": list(friction.coulomb),
            "smoothing": friction.smoothing,
            "source": self.friction_source,
        }


@dataclass(frozen=True)
class PlantOptions:
    """The simulated arm's options (every law of a command runs on the same ones).

    Attributes:
        friction: ``law`` (default: the profile's friction for a law that estimates friction,
            none otherwise), ``on`` (every plant: :func:`robot_friction`) or ``off`` (no plant).
        saturate: Clip torques at the URDF effort limits.
        friction_smoothing: ε [rad/s] of ``tanh(q̇/ε)`` for Coulomb friction; None: 0 with
            RK4, :data:`ADAPTIVE_SMOOTHING` with the adaptive integrator.
        wrench: An external wrench on a frame over a time window (world axes, N and N·m).
        payload_step: A payload picked up at a time (the law is not told).
        sensor_noise: Seeded Gaussian noise on the q [rad] and q̇ [rad/s] the law measures.
        delay: Steps between a measurement and the torque it produces.
        position_stops: Each joint's position range a hard stop (``--joint-stops``;
            :mod:`twolink_pin.simulation.stops`): off, a joint may pass its range, and the run
            says so.

    The wrench, payload step, sensor noise and delay are the plant's events (:mod:`twolink_pin.disturbances`: what each does,
    and when, on the engine's grid); all off by default, as in the course report.
    """

    friction: str = "law"
    saturate: bool = False
    friction_smoothing: float | None = None
    wrench: Wrench | None = None
    payload_step: PayloadStep | None = None
    sensor_noise: SensorNoise | None = None
    delay: int = 0
    position_stops: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.position_stops, bool):
            raise InvalidParameterError("position_stops", self.position_stops, "True or False")
        # as_dict / from_dict: the events come back from JSON as mappings
        for name, kind in (("wrench", Wrench), ("payload_step", PayloadStep), ("sensor_noise", SensorNoise)):
            value = getattr(self, name)
            if isinstance(value, Mapping):
                object.__setattr__(self, name, kind(**value))
            elif value is not None and not isinstance(value, kind):
                raise InvalidParameterError(
                    name, value, f"a twolink_pin.disturbances.{kind.__name__} or None"
                )
        check_delay(self.delay)
        if self.friction not in FRICTION_CHOICES:
            raise InvalidParameterError(
                "plant friction", self.friction, f"one of {', '.join(FRICTION_CHOICES)}"
            )
        eps = self.friction_smoothing
        if eps is not None and not (isinstance(eps, (int, float)) and math.isfinite(eps) and eps >= 0):
            raise InvalidParameterError("friction_smoothing", eps, "a finite ε >= 0 rad/s or None")

    def smoothing(self, method: str) -> float:
        """ε [rad/s] for the integrator ``method``."""
        if self.friction_smoothing is not None:
            return float(self.friction_smoothing)
        return ADAPTIVE_SMOOTHING if method == "adaptive" else 0.0

    def plant(self, robot: RobotModel, *, estimates_friction: bool, method: str = "rk4") -> Plant:
        """The plant these options describe on ``robot`` (built once per run).

        Args:
            robot: The arm.
            estimates_friction: Whether the law estimates friction (``law``: its plant has
                the profile's friction, as in the report's experiments).
            method: The integrator (``friction_smoothing`` None: ε from it).
        """
        eps = self.smoothing(method)
        friction: Friction | None = None
        source = ""
        if self.friction == "on":
            friction, source = robot_friction(robot, eps)
        elif self.friction == "law" and estimates_friction and robot.profile.friction is not None:
            friction, source = robot_friction(robot, eps)
        return Plant(
            robot,
            friction,
            self.saturate,
            wrench=self.wrench,
            payload_step=self.payload_step,
            sensor_noise=self.sensor_noise,
            delay=self.delay,
            position_stops=self.position_stops,
            friction_source=source,
        )

    def extras(self) -> dict[str, Any]:
        """The options that are not their defaults, by field name."""
        default = PlantOptions()
        return {
            f.name: getattr(self, f.name)
            for f in dataclasses.fields(self)
            if getattr(self, f.name) != getattr(default, f.name)
        }


__all__ = [
    "ADAPTIVE_SMOOTHING",
    "DEFAULT_FRICTION",
    "FRICTION_CHOICES",
    "LinearTerms",
    "Plant",
    "PlantOptions",
    "robot_friction",
]
