"""What a run asks of its plant: :class:`PlantOptions` (the friction as a choice, saturation, the
events that push back, joint stops, the scene, the engine and the arm's effects), validated once;
:meth:`PlantOptions.plant` builds the frozen :class:`~twolink_pin.plant.Plant` from them."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from twolink_pin.arm_effects import (
    INTEGRATORS,
    MUJOCO_ONLY,
    OPTION,
    PER_JOINT,
    check_effect,
    check_solver,
    resolve_effect,
)
from twolink_pin.contact.scene import Scene
from twolink_pin.disturbances import PayloadStep, SensorNoise, Wrench, check_delay
from twolink_pin.dynamics import Friction
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.plant import (
    ADAPTIVE_SMOOTHING,
    DEFAULT_ENGINE,
    ENGINES,
    FRICTION_CHOICES,
    Plant,
    robot_friction,
)


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
        scene: The surfaces the arm may touch and their contact properties (``--scene FILE``,
            ``--wall …``; :mod:`twolink_pin.contact`), or None (free space).
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
    scene: Scene | None = None
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
        if isinstance(self.scene, Mapping):  # from_dict: the scene comes back from JSON as a mapping
            object.__setattr__(self, "scene", Scene(**self.scene))
        elif self.scene is not None and not isinstance(self.scene, Scene):
            raise InvalidParameterError("scene", self.scene, "a twolink_pin.contact.Scene or None")
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
            scene=self.scene,
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
