"""The simulated arm: Pinocchio's forward dynamics plus friction and motor saturation.

``q̈ = ABA(q, q̇, sat(τ) − f(q̇) − D q̇)`` where ``f`` is the optional joint friction
(:class:`twolink_pin.dynamics.Friction`; Pinocchio's ABA ignores URDF friction), ``sat``
clips to the URDF torque limits when ``saturate`` is on (off by default, as in the report),
``D`` the joint damping and ABA's model carries the armature (both none by default:
:mod:`twolink_pin.arm_effects`).
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

A second engine is another :class:`Plant` class registered by name (:func:`register_engine`;
:mod:`twolink_pin.mujoco_plant` registers ``mujoco``): ``PlantOptions(engine=...)`` picks it, and
it answers the engine's questions through :meth:`Plant.dynamics`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
import pinocchio as pin

from twolink_pin.arm_effects import (
    ARM,
    INTEGRATORS,
    MUJOCO_ONLY,
    OPTION,
    PER_JOINT,
    UNITS,
    check_effect,
    check_solver,
    per_joint,
    resolve_effect,
)
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


@dataclass(frozen=True)
class PlantOptions:
    """The simulated arm's options (every law of a command runs on the same ones).

    Attributes:
        friction: ``law`` (default: the profile's friction for a law that estimates friction,
            none otherwise), ``on`` (every plant: :func:`robot_friction`) or ``off`` (no plant).
        saturate: Clip torques at the URDF effort limits (MuJoCo: the actuators' force range).
        friction_smoothing: ε [rad/s] of ``tanh(q̇/ε)`` for Coulomb friction; None: 0 with
            RK4, :data:`ADAPTIVE_SMOOTHING` with the adaptive integrator.
        wrench: An external wrench on a frame over a time window (world axes, N and N·m).
        payload_step: A payload picked up at a time (the law is not told).
        sensor_noise: Seeded Gaussian noise on the q [rad] and q̇ [rad/s] the law measures.
        delay: Steps between a measurement and the torque it produces.
        position_stops: Each joint's position range a hard stop (``--joint-stops``;
            :mod:`twolink_pin.simulation.stops`): off, a joint may pass its range, and the run
            says so.
        engine: The plant's engine: ``pinocchio`` (default) or ``mujoco``
            (:mod:`twolink_pin.mujoco_plant`: the same URDF compiled by MuJoCo).
        armature: Rotor inertia [kg·m²]: ``arm``, one value or one per joint; None: none.
        joint_damping: Joint damping [N·m·s/rad], the same forms.
        frictionloss: MuJoCo's dry friction [N·m], the same forms (MuJoCo only).
        soft_limits: The position ranges as MuJoCo's soft joint limits; None: on with MuJoCo
            (where the URDF gives a range), off with Pinocchio (MuJoCo only).
        solref: The soft limits' (time constant [s], damping ratio); None: MuJoCo's (0.02, 1).
        solimp: Their impedance (d0, dwidth, width [rad], midpoint, power); None: MuJoCo's.
        integrator: MuJoCo's integrator: ``rk4`` (the engine's, default), ``euler``,
            ``implicitfast`` (MuJoCo only).

    The wrench, payload step, sensor noise and delay are the plant's events (:mod:`twolink_pin.disturbances`: what each does,
    and when, on the engine's grid); all off by default, as in the course report. The arm's
    effects (armature to integrator) are :mod:`twolink_pin.arm_effects`'s.
    """

    friction: str = "law"
    saturate: bool = False
    friction_smoothing: float | None = None
    wrench: Wrench | None = None
    payload_step: PayloadStep | None = None
    sensor_noise: SensorNoise | None = None
    delay: int = 0
    position_stops: bool = False
    engine: str = DEFAULT_ENGINE
    armature: tuple[float, ...] | str | None = None
    joint_damping: tuple[float, ...] | str | None = None
    frictionloss: tuple[float, ...] | str | None = None
    soft_limits: bool | None = None
    solref: tuple[float, ...] | None = None
    solimp: tuple[float, ...] | None = None
    integrator: str = "rk4"

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
        self._check_effects()

    def _check_effects(self) -> None:
        """The arm's effects well formed, and each one the chosen engine has."""
        if self.engine not in ENGINES:
            raise InvalidParameterError("--plant", self.engine, f"one of {', '.join(ENGINES)}")
        for name in PER_JOINT:
            object.__setattr__(self, name, check_effect(name, getattr(self, name)))
        for name in ("solref", "solimp"):
            object.__setattr__(self, name, check_solver(name, getattr(self, name)))
        if self.soft_limits is not None and not isinstance(self.soft_limits, bool):
            raise InvalidParameterError(
                "soft_limits", self.soft_limits, "True, False or None (the engine's default)"
            )
        if self.integrator not in INTEGRATORS:
            raise InvalidParameterError(
                "--mujoco-integrator", self.integrator, f"one of {', '.join(INTEGRATORS)}"
            )
        takes = ENGINES[self.engine].takes
        default = PlantOptions.__dataclass_fields__
        for name in MUJOCO_ONLY:
            value = getattr(self, name)
            if name not in takes and value != default[name].default:
                raise InvalidParameterError(
                    OPTION[name],
                    _shown(value),
                    f"a plant that has it: --plant mujoco (the {self.engine} plant has no {name.replace('_', ' ')})",
                )
        if self.soft_limits is False and (self.solref is not None or self.solimp is not None):
            raise InvalidParameterError(
                "--solref" if self.solref is not None else "--solimp",
                _shown(self.solref or self.solimp),
                "soft limits to shape (--soft-limits off leaves none)",
            )
        if self.position_stops and "soft_limits" in takes:
            raise InvalidParameterError(
                "--joint-stops",
                True,
                f"the Pinocchio plant: the {self.engine} plant's joint ranges are its soft limits "
                "(--soft-limits, --solref, --solimp)",
            )

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

        Raises:
            InvalidParameterError: an effect ``arm`` the robot gives no value of, or a count of
                values that is neither 1 nor nv.
        """
        eps = self.smoothing(method)
        friction: Friction | None = None
        source = ""
        if self.friction == "on":
            friction, source = robot_friction(robot, eps)
        elif self.friction == "law" and estimates_friction and robot.profile.friction is not None:
            friction, source = robot_friction(robot, eps)
        cls = ENGINES[self.engine]
        values: dict[str, Any] = {}
        sources = []
        for name in PER_JOINT:
            if name in ("armature", "joint_damping") or name in cls.takes:
                values[name], where = resolve_effect(robot, name, getattr(self, name))
                if where:
                    sources.append((name, where))
        values.update({name: getattr(self, name) for name in cls.takes if name not in PER_JOINT})
        return cls(
            robot,
            friction,
            self.saturate,
            wrench=self.wrench,
            payload_step=self.payload_step,
            sensor_noise=self.sensor_noise,
            delay=self.delay,
            position_stops=self.position_stops,
            friction_source=source,
            effect_sources=tuple(sources),
            **values,
        )

    def extras(self) -> dict[str, Any]:
        """The options that are not their defaults, by field name."""
        default = PlantOptions()
        return {
            f.name: getattr(self, f.name)
            for f in dataclasses.fields(self)
            if getattr(self, f.name) != getattr(default, f.name)
        }


def _shown(value: Any) -> Any:
    """A tuple of values as the command line writes them (``0.1,0.2``)."""
    if isinstance(value, tuple):
        return ",".join(f"{x:g}" for x in value)
    return value


__all__ = [
    "ADAPTIVE_SMOOTHING",
    "ARM",
    "DEFAULT_ENGINE",
    "DEFAULT_FRICTION",
    "ENGINES",
    "FRICTION_CHOICES",
    "Plant",
    "PlantOptions",
    "register_engine",
    "robot_friction",
]
