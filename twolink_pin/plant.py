"""The simulated arm: Pinocchio's forward dynamics plus friction and motor saturation.

``q̈ = ABA(q, q̇, sat(τ) − f(q̇) − D q̇)`` where ``f`` is the optional joint friction
(:class:`twolink_pin.dynamics.Friction`; Pinocchio's ABA ignores URDF friction), ``sat``
clips to the URDF torque limits when ``saturate`` is on (off by default, as in the report),
``D`` the joint damping and ABA's model carries the armature (both none by default:
:mod:`twolink_pin.arm_effects`).
A plant may also push back (:mod:`twolink_pin.disturbances`: a wrench, a payload step,
sensor noise, a delay; none by default), and may make each joint's position range a hard
stop (``position_stops``: :mod:`twolink_pin.simulation.stops`, off by default: a joint then
passes its range and the run records the crossing), and may touch the surfaces of a scene
(``scene``: :mod:`twolink_pin.contact`, none by default; the Pinocchio plant's contact is
:class:`~twolink_pin.contact.CompliantContact`); the engine then runs
:mod:`twolink_pin.simulation.events`.

:class:`Plant` is one frozen value; a variant is :func:`dataclasses.replace` of it.
:class:`~twolink_pin.plant_options.PlantOptions` (:mod:`twolink_pin.plant_options`) is what a run
asks of its plant (the friction as a choice, the events, the engine); its ``plant`` method builds
the plant from them, once.
:meth:`Plant.applied_torque` and :meth:`Plant.motor_torque` work on one state ``(nv,)`` or
on N runs ``(N, nv)``; the engine evaluates ABA itself for all runs at once
(:mod:`twolink_pin.simulation.forward`).

A second engine is another :class:`Plant` class registered by name (:func:`register_engine`;
:mod:`twolink_pin.mujoco_plant` registers ``mujoco``): ``PlantOptions(engine=...)`` picks it, and
it answers the engine's questions through :meth:`Plant.dynamics`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any, ClassVar, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.arm_effects import (
    ARM,
    UNITS,
    per_joint,
)
from twolink_pin.contact.compliant import CompliantContact
from twolink_pin.contact.scene import Scene
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
        scene: The surfaces the arm may touch (:class:`~twolink_pin.contact.Scene`), or None.
        model: The Pinocchio model integrated (default ``robot.model``, with ``armature`` in
            its ``model.armature``; the model after a payload step in :meth:`after_payload`).
        friction_source: Where ``friction`` comes from, in words (the summaries show it).
        armature: Rotor inertia reflected through each joint's gearbox [kg·m²], shape (nv,);
            None: none (:mod:`twolink_pin.arm_effects`).
        joint_damping: Joint damping [N·m·s/rad], shape (nv,); None: none.
        effect_sources: ``((effect, where its values come from), ...)`` for the summaries.
    """

    engine: ClassVar[str] = "pinocchio"
    """The registered name of the engine that integrates this plant (:func:`register_engine`)."""
    takes: ClassVar[tuple[str, ...]] = ()
    """The engine's own options (:data:`~twolink_pin.arm_effects.MUJOCO_ONLY`) this class takes."""

    robot: RobotModel
    friction: Friction | None = None
    saturate: bool = False
    _: dataclasses.KW_ONLY
    wrench: Wrench | None = None
    payload_step: PayloadStep | None = None
    sensor_noise: SensorNoise | None = None
    delay: int = 0
    position_stops: bool = False
    scene: Scene | None = None
    model: pin.Model = field(default=None, repr=False)
    friction_source: str = ""
    armature: np.ndarray = field(default=None, repr=False)  # type: ignore[arg-type]  # None: zeros
    joint_damping: np.ndarray = field(default=None, repr=False)  # type: ignore[arg-type]  # None: zeros
    effect_sources: tuple[tuple[str, str], ...] = ()
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
        if self.scene is not None:
            if not isinstance(self.scene, Scene):
                raise InvalidParameterError("scene", self.scene, "a twolink_pin.contact.Scene or None")
            if self.scene.frame is not None and not robot.model.existFrame(self.scene.frame):
                raise InvalidParameterError(
                    "scene.frame",
                    self.scene.frame,
                    f"a frame of {robot.name}: {[f.name for f in robot.model.frames]}",
                )
        wrench = self.wrench
        if wrench is not None and wrench.frame is not None and not robot.model.existFrame(wrench.frame):
            raise InvalidParameterError(
                "wrench.frame",
                wrench.frame,
                f"a frame of {robot.name}: {[f.name for f in robot.model.frames]}",
            )
        check_delay(self.delay)
        for name in ("armature", "joint_damping"):
            object.__setattr__(self, name, per_joint(name, getattr(self, name), robot.nv))
        model = robot.model if self.model is None else self.model
        if not np.array_equal(model.armature, self.armature):  # ABA and CRBA read model.armature
            model = model.copy()
            model.armature = np.array(self.armature)
        object.__setattr__(self, "model", model)
        limits = np.array(robot.torque_limits, dtype=float)
        limits.setflags(write=False)
        object.__setattr__(self, "limits", limits)
        object.__setattr__(self, "joint_limits", joint_limits(robot))

    @property
    def law_per_stage(self) -> bool:
        """Whether the engine's RK4 integrates this plant, so that the law can be evaluated at
        each of its stages (False: the plant's own integrator steps it, the law held over each
        step)."""
        return True

    def dynamics(self, runs: int, threads: int | None) -> Any:
        """The plant's own ``q̈ = f(q, q̇, τ)`` for ``runs`` runs, or None: the engine's
        (:func:`~twolink_pin.simulation.forward.dynamics_for`, Pinocchio's ABA). Another
        engine's plant returns an object with that call, and may add ``held_step`` (it steps
        the state itself) and ``failure(run)`` (its own cause of a run that failed)."""
        return None

    def after_payload(self) -> Plant:
        """This plant with its payload step's mass carried from the start (the plant after the step)."""
        step = self.payload_step
        assert step is not None
        return dataclasses.replace(self, model=step.model(self.model, self.robot.ee_frame_id))

    @property
    def has_events(self) -> bool:
        """Whether the plant pushes back: a wrench, a payload step, sensor noise, a delay,
        joint stops or a scene to touch."""
        return (
            any(x is not None for x in (self.wrench, self.payload_step, self.sensor_noise, self.scene))
            or self.delay > 0
            or self.position_stops
        )

    def contact_model(self, runs: int, step: float | None = None) -> CompliantContact | None:
        """This plant's contact with its scene for ``runs`` runs advanced together (None without a
        scene): the Pinocchio plant's spring–damper (:class:`~twolink_pin.contact.CompliantContact`),
        checked against the RK4 ``step`` [s]. The engine asks it ``(q, q̇) -> ContactForces`` at
        every stage: the force sensor reads ``wrench``, the plant's ABA adds ``tau``. A plant of
        another engine answers with its own contact (``tau`` zero where its engine applies the
        contact itself)."""
        return None if self.scene is None else CompliantContact(self.robot, self.scene, runs, step)

    def applied_torque(self, tau: np.ndarray) -> np.ndarray:
        """Motor torque actually applied [N·m]: ``tau`` clipped to the limits if saturating."""
        return np.clip(tau, -self.limits, self.limits) if self.saturate else tau

    def linear_terms(self) -> LinearTerms:
        """The plant's linear terms beyond ``model``'s rigid bodies (:class:`LinearTerms`)."""
        nv = self.robot.nv
        damping = np.zeros(nv) if self.friction is None else np.array(self.friction.viscous, dtype=float)
        # the armature is in self.model's own (its CRBA holds it); the joint damping D q̇ is not
        return LinearTerms(np.zeros(nv), damping + self.joint_damping, np.zeros(nv))

    def motor_torque(self, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """What drives the rigid bodies [N·m]: ``sat(τ) − f(q̇) − D q̇``."""
        u = self.applied_torque(tau)
        if self.friction is not None:
            u = u - self.friction.torque(v)
        return u - self.joint_damping * v if self.joint_damping.any() else u

    def acceleration(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Joint acceleration [rad/s²] of one state under commanded torque ``tau`` [N·m]."""
        data = self.model.createData()
        return pin.aba(self.model, data, q, v, self.motor_torque(v, tau), ABA_CONVENTION).copy()

    def energy(self, q: np.ndarray, v: np.ndarray) -> float:
        """Mechanical energy ``½ q̇ᵀ M q̇ + U(q)`` [J] of one state (``M`` with the armature:
        the rotors' ``½ a q̇²`` counted)."""
        data = self.model.createData()
        rotors = 0.5 * float(np.dot(self.armature, np.square(v)))
        return (
            float(pin.computeKineticEnergy(self.model, data, q, v))
            + rotors
            + float(pin.computePotentialEnergy(self.model, data, q))
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
        if self.scene is not None:
            parts.append(self.scene.describe() if values else "contact")
        parts.extend(self.effects_described(values))
        return ", ".join(parts)

    def effects_described(self, values: bool = False) -> list[str]:
        """The arm's effects this plant models, in words (with their values and sources)."""
        sources = dict(self.effect_sources)
        parts = []
        for name in ("armature", "joint_damping"):
            given = getattr(self, name)
            if given.any():
                text = name.replace("_", " ")
                if values:
                    text += f" ({', '.join(f'{x:g}' for x in given)}) {UNITS[name]}"
                    text += f" from {sources[name]}" if sources.get(name) else ""
                parts.append(text)
        return parts

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


ENGINES: dict[str, type[Plant]] = {"pinocchio": Plant}
"""The plants by engine name (``PlantOptions.engine``, ``--plant``): Pinocchio's here, the others
registered by their modules (:func:`register_engine`)."""
DEFAULT_ENGINE = "pinocchio"
"""The engine of a run that names none: every existing result is Pinocchio's."""


def register_engine(name: str, plant: type[Plant]) -> None:
    """Add an engine: ``PlantOptions(engine=name)`` builds ``plant`` (a :class:`Plant` subclass
    taking the options it lists in ``takes``)."""
    ENGINES[name] = plant


__all__ = [
    "ADAPTIVE_SMOOTHING",
    "ARM",
    "DEFAULT_ENGINE",
    "DEFAULT_FRICTION",
    "ENGINES",
    "FRICTION_CHOICES",
    "LinearTerms",
    "Plant",
    "register_engine",
    "robot_friction",
]
