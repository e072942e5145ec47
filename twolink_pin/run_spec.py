"""One frozen description of a run: :class:`RunSpec`, and the one place that builds it.

A run is a law (its reference and gains), the plant it drives (:class:`PlantOptions`),
what its model believes (an identified-parameter file and its use) and the simulation
settings (:class:`~twolink_pin.simulation.SimulationConfig`, the initial offset among
them). Every command builds one from its arguments, once; ``compare`` and ``report`` give
one spec for several laws and take each law's own with :meth:`RunSpec.for_law`; the sweep
and the report hold one beside their own options; a saved result records it
(:meth:`RunSpec.as_dict`), so a run can be replayed from its file alone.

:meth:`RunSpec.build` is the only function that turns a description into a controller and
its plant: the law once (:func:`~twolink_pin.scenario.make_controller`, believing identified
parameters from :func:`~twolink_pin.identification.believed` when it is given some), the
plant once (:meth:`PlantOptions.plant <twolink_pin.plant_options.PlantOptions.plant>`);
:func:`make_scenario` is a :class:`RunSpec` built at once. Before building, it refuses an
option that would do nothing for this law on this robot (:meth:`RunSpec.check_effective`).

Adding a run option: one field (of :class:`RunSpec` here or, for the plant,
:class:`~twolink_pin.plant_options.PlantOptions` in ``plant_options.py``, with its check in ``__post_init__``
and its use in :meth:`build` or :meth:`PlantOptions.plant`), one ``add_argument`` in
``cli/parser.py``'s run-option group and one line in
:func:`twolink_pin.cli.commands.common.run_spec`, and a test that the option reaches the
built plant or law (``tests/test_run_spec.py`` shows the pattern; it also checks that the
parser's run options and the fields here agree).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.arm_effects import believe_effects, refuse_idle
from twolink_pin.contact_checks import check_contact
from twolink_pin.controllers import Controller
from twolink_pin.errors import InvalidParameterError
from twolink_pin.law_variant import Variant
from twolink_pin.model import RobotModel
from twolink_pin.plant import ADAPTIVE_SMOOTHING, FRICTION_CHOICES, robot_friction
from twolink_pin.plant_options import PlantOptions
from twolink_pin.scenario import Scenario, law_class, make_controller
from twolink_pin.simulation import SimulationConfig

if TYPE_CHECKING:
    from twolink_pin.dynamics import Friction
    from twolink_pin.identification import IdentifiedParameters
    from twolink_pin.trajectory import Trajectory

PARAMETER_USES = ("p0", "model")
"""How identified parameters are used: the estimates start there (``p0``), or the law's
model believes them (``model``)."""
Gains = tuple[tuple[str, Any], ...]
"""Gains by field name, as ``((name, value), ...)`` (a value: a number or a tuple)."""


def _frozen_gains(gains: Mapping[str, Any] | Gains) -> Gains:
    items = gains.items() if isinstance(gains, Mapping) else gains
    return tuple((str(k), tuple(v) if isinstance(v, (list, tuple)) else v) for k, v in items)


@dataclass(frozen=True)
class RunSpec:
    """One run, or the common part of several laws' runs (``law`` None).

    Attributes:
        law: A registered name, ``file.py:Class`` or ``module:Class``; None in a spec shared
            by several laws (:meth:`for_law` gives each law's).
        gains: Gains of ``law`` by field name, over the robot's presets.
        law_gains: Per-law gains of a shared spec: ``((law name, gains), ...)``.
        lam: ``λ`` [1/s]; refused by a law without one, except in a shared spec, where it
            goes to the laws that have one.
        plant: The plant's options.
        parameters: An identified-parameter file (``twolink-pin identify --save``).
        parameters_use: ``p0`` or ``model`` (see :data:`PARAMETER_USES`); in a shared spec
            ``p0`` seeds the laws that estimate, the others run as usual.
        simulation: Duration, step, integrator, initial offset, control period.
        shared: Whether this spec is the common part of several laws' runs.
        believed_effects: The law's model includes the plant's armature (in its ``M(q)``) and
            joint damping (in the viscous friction a friction-estimating law believes)
            (``--believe-effects``; :mod:`twolink_pin.arm_effects`).
    """

    law: str | type[Controller] | None = None
    gains: Gains = ()
    law_gains: tuple[tuple[str, Gains], ...] = ()
    lam: float | None = None
    plant: PlantOptions = field(default_factory=PlantOptions)
    parameters: str | None = None
    parameters_use: str = ""
    simulation: SimulationConfig = field(default_factory=SimulationConfig)
    shared: bool = False
    believed_effects: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "gains", _frozen_gains(self.gains))
        object.__setattr__(
            self, "law_gains", tuple((str(name), _frozen_gains(g)) for name, g in self.law_gains)
        )
        if self.lam is not None and not (math.isfinite(self.lam) and self.lam > 0):
            raise InvalidParameterError("lambda", self.lam, "a finite λ > 0 1/s")
        if (self.parameters is None) != (self.parameters_use == ""):
            raise InvalidParameterError(
                "parameters_use", self.parameters_use, "'p0' or 'model' with a parameter file, '' without"
            )
        if self.parameters is not None and self.parameters_use not in PARAMETER_USES:
            raise InvalidParameterError("parameters_use", self.parameters_use, "'p0' or 'model'")
        if not isinstance(self.simulation, SimulationConfig):
            raise InvalidParameterError("simulation", type(self.simulation).__name__, "a SimulationConfig")

    @property
    def friction_smoothing(self) -> float:
        """ε [rad/s] of the friction sign for this spec's integrator."""
        return self.plant.smoothing(self.simulation.method)

    def law_class(self) -> type[Controller]:
        """The law's class (loaded once per process and reference)."""
        if self.law is None:
            raise InvalidParameterError("law", None, "a law (for_law gives a shared spec's law)")
        return law_class(self.law)

    def for_law(self, law: str | Variant) -> RunSpec:
        """The spec of ``law`` among several: its own gains (``law_gains``), λ if it has one,
        the identified parameters if it uses them (``model``: every law; ``p0``: the laws that
        estimate). A :class:`~twolink_pin.law_variant.Variant`'s own settings then replace
        these for its run (its gains over the law's, ``lam`` over ``--lambda``, its parameter
        file over the shared one)."""
        if isinstance(law, Variant):
            return law_spec(self.for_law(law.law), law)
        cls = law_class(law)
        gains = dict(self.gains)
        for name, own in self.law_gains:
            if name in (cls.name, law):
                gains.update(own)
        lam = self.lam if (self.lam is None or cls.takes("lam") or not self.shared) else None
        parameters, use = self.parameters, self.parameters_use
        if self.shared and use == "p0" and not cls.estimates:
            parameters, use = None, ""
        return dataclasses.replace(
            self,
            law=law,
            gains=tuple(gains.items()),
            law_gains=(),
            lam=lam,
            parameters=parameters,
            parameters_use=use,
            shared=False,
        )

    def check_law_gains(self, laws: Sequence[str]) -> None:
        """Refuse per-law gains of a law that is not among ``laws`` (references as given).

        Raises:
            InvalidParameterError: the first such law, with the laws that run.
        """
        names = {law_class(law).name for law in laws} | set(laws)
        for name, _ in self.law_gains:
            if name not in names:
                raise InvalidParameterError(
                    "--gain", name, f"a law that runs here: {', '.join(law_class(law).name for law in laws)}"
                )

    def read_parameters(self, robot: RobotModel) -> IdentifiedParameters | None:
        """The parameters of ``parameters`` for ``robot`` (None without a file): an identified
        parameter file (``identify --save``), or a URDF whose inertias the law believes."""
        if self.parameters is None:
            return None
        from twolink_pin.identification import read_parameter_file, urdf_parameters

        if str(self.parameters).lower().endswith(".urdf"):
            return urdf_parameters(self.parameters, robot)
        return read_parameter_file(self.parameters, robot)

    def build(self, robot: RobotModel, identified: IdentifiedParameters | None = None) -> Scenario:
        """The law and its plant on ``robot``: the one place a run is assembled.

        Args:
            robot: The arm (plant and the law's nominal model).
            identified: The parameters of ``parameters``, if already read
                (:meth:`read_parameters`: read once for several laws); read here otherwise.

        Raises:
            InvalidParameterError: a gain or λ the law does not have, ``p0`` for a law that
                estimates nothing, parameters the robot's map cannot express.
            ControllerSpecError: no such law, or it could not be built.
        """
        cls = self.law_class()
        gains: dict[str, Any] = dict(self.gains)
        plant = self.plant.plant(
            robot, estimates_friction="friction" in cls.estimates, method=self.simulation.method
        )
        friction = self.law_friction(cls, robot)
        parameters = None
        if self.parameters is not None:
            from twolink_pin.identification import believed

            if identified is None:
                identified = self.read_parameters(robot)
            assert identified is not None
            belief = believed(cls, robot, identified, self.parameters_use, gains)
            parameters, gains = belief.parameters, belief.gains
            if belief.friction is not None:  # with the ε of the friction it replaces
                smoothing = friction.smoothing if friction is not None else 0.0
                friction = (
                    dataclasses.replace(belief.friction, smoothing=smoothing)
                    if smoothing
                    else belief.friction
                )
        law_robot = robot
        if self.believed_effects:
            law_robot, friction = believe_effects(robot, plant, friction)
        controller = make_controller(
            cls, law_robot, lam=self.lam, gains=gains, friction=friction, model_parameters=parameters
        )
        return Scenario(controller, plant)

    def law_friction(self, cls: type[Controller], robot: RobotModel) -> Friction | None:
        """The friction a friction-estimating law believes without identified parameters: its
        robot's profile friction (None for the other laws, or without one)."""
        if "friction" in cls.estimates and robot.profile.friction is not None:
            return robot_friction(robot, self.friction_smoothing)[0]
        return None

    def check_effective(
        self,
        robot: RobotModel,
        laws: Sequence[str | type[Controller]] = (),
        trajectory: Trajectory | None = None,
    ) -> None:
        """Refuse an option that would do nothing on ``robot`` for this spec's law, or for every
        one of ``laws`` (a shared spec): a silent no-op is a wrong answer. The commands call it
        once, before their runs (λ and gains a law lacks are refused when it is built), with the
        ``trajectory`` the runs follow (its force reference checked against the scene and the
        laws: :func:`~twolink_pin.contact_checks.check_contact`).

        Raises:
            InvalidParameterError: the option, its value and why it would do nothing.
        """
        classes = [law_class(law) for law in laws] if laws else [self.law_class()]
        names = ", ".join(f"'{cls.name}'" for cls in classes)
        plant, sim = self.plant, self.simulation
        if plant.saturate and not np.isfinite(robot.torque_limits).any():
            raise InvalidParameterError(
                "--saturate",
                True,
                f"a robot with effort limits ({robot.name}'s URDF gives none: nothing to clip)",
            )
        if plant.position_stops:
            self._check_stops(robot)
        refuse_idle(plant, robot, sim.method)  # the arm's effects (twolink_pin.arm_effects)
        if self.believed_effects and plant.armature is None and plant.joint_damping is None:
            raise InvalidParameterError(
                "--believe-effects",
                True,
                "a plant with armature or joint damping to believe (--armature, --joint-damping)",
            )
        built = [
            plant.plant(robot, estimates_friction="friction" in cls.estimates, method=sim.method).friction
            for cls in classes
        ]
        if (
            plant.friction == "off"
            and all(f is None for f in built)
            and all(
                self.law_friction(cls, robot) is None and "friction" not in cls.estimates for cls in classes
            )
        ):
            raise InvalidParameterError(
                "--plant-friction",
                "off",
                f"a law whose plant has friction ({names} runs without it already)",
            )
        if plant.friction_smoothing is not None and all(
            f is None and "friction" not in cls.estimates for f, cls in zip(built, classes, strict=True)
        ):
            raise InvalidParameterError(
                "--friction-smoothing",
                plant.friction_smoothing,
                f"a run with friction (the plant of {names} has none here and the law models none: "
                "add --plant-friction on)",
            )
        if self.lam is not None and laws and not any(cls.takes("lam") for cls in classes):
            raise InvalidParameterError(
                "--lambda", self.lam, f"a law with a λ gain among those that run ({names})"
            )
        if self.parameters_use == "p0" and laws and not any(cls.estimates for cls in classes):
            raise InvalidParameterError(
                "--p0", self.parameters, f"a law that estimates parameters among those that run ({names})"
            )
        self._check_events(sim)
        check_contact(plant, sim, classes, trajectory)

    def _check_events(self, sim: SimulationConfig) -> None:
        """Refuse a plant event that acts on no step of the run (steps ``t_k = k dt``,
        ``k < steps``), or that adds nothing."""
        plant, steps = self.plant, sim.steps
        dt = sim.duration / steps

        def first_step(t: float) -> int:  # the first k with t_k >= t
            return math.ceil(t / dt - 1e-9)

        wrench = plant.wrench
        if wrench is not None:
            k = first_step(wrench.start)
            if k >= steps or k * dt >= wrench.stop:
                raise InvalidParameterError(
                    "--wrench",
                    f"@{wrench.start:g}:{wrench.stop:g} s",
                    f"a window that holds a step of the run (steps at k·{dt:g} s up to {(steps - 1) * dt:g} s;"
                    f" --duration {sim.duration:g} s)",
                )
        if plant.payload_step is not None and first_step(plant.payload_step.time) >= steps:
            raise InvalidParameterError(
                "--payload-step",
                f"at {plant.payload_step.time:g} s",
                f"a time within the run (before its last step at {(steps - 1) * dt:g} s; --duration {sim.duration:g} s)",
            )
        noise = plant.sensor_noise
        if noise is not None and noise.sigma_q == 0 and noise.sigma_v == 0 and noise.sigma_f == 0:
            raise InvalidParameterError(
                "--sensor-noise", "0,0,0", "a standard deviation > 0 on q, q̇ or the force (0 adds no noise)"
            )

    def _check_stops(self, robot: RobotModel) -> None:
        """``--joint-stops`` needs a position range on some joint and the RK4 engine."""
        from twolink_pin.limits import POSITION, joint_limits

        limits = joint_limits(robot)
        if not limits.given(POSITION).any():
            raise InvalidParameterError(
                "--joint-stops",
                True,
                f"a robot with a position range on some joint ({robot.name}'s joints "
                f"{', '.join(limits.joint_names)} have none: nothing to stop at)",
            )
        if self.simulation.method != "rk4":
            raise InvalidParameterError(
                "--joint-stops",
                True,
                f"--method rk4 (the stops act between its steps), not {self.simulation.method}",
            )

    def as_dict(self) -> dict[str, Any]:
        """The spec as JSON-ready data (:meth:`from_dict` reads it back)."""
        sim = dataclasses.asdict(self.simulation)
        law = self.law
        return {
            "law": law if law is None or isinstance(law, str) else f"{law.__module__}:{law.__qualname__}",
            "gains": {k: list(v) if isinstance(v, tuple) else v for k, v in self.gains},
            "law_gains": {
                name: {k: list(v) if isinstance(v, tuple) else v for k, v in g} for name, g in self.law_gains
            },
            "lam": self.lam,
            "plant": dataclasses.asdict(self.plant),
            "parameters": self.parameters,
            "parameters_use": self.parameters_use,
            "simulation": {k: list(v) if isinstance(v, tuple) else v for k, v in sim.items()},
            "shared": self.shared,
            "believed_effects": self.believed_effects,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RunSpec:
        """The spec :meth:`as_dict` wrote."""
        sim = dict(data.get("simulation") or {})
        if isinstance(sim.get("q0_offset"), list):
            sim["q0_offset"] = tuple(sim["q0_offset"])
        return cls(
            law=data.get("law"),
            gains=_frozen_gains(dict(data.get("gains") or {})),
            law_gains=tuple((n, _frozen_gains(g)) for n, g in (data.get("law_gains") or {}).items()),
            lam=data.get("lam"),
            plant=PlantOptions(**dict(data.get("plant") or {})),
            parameters=data.get("parameters"),
            parameters_use=data.get("parameters_use", ""),
            simulation=SimulationConfig(**sim),
            shared=bool(data.get("shared", False)),
            believed_effects=bool(data.get("believed_effects", False)),
        )


def law_spec(spec: RunSpec, variant: Variant) -> RunSpec:
    """``spec`` (one law's, :meth:`RunSpec.for_law`) with ``variant``'s settings over it."""
    gains = dict(spec.gains) | dict(variant.gains)
    lam = None if "lam" in dict(variant.gains) else spec.lam  # the variant's λ over --lambda
    parameters, use = spec.parameters, spec.parameters_use
    if variant.parameters is not None:
        parameters, use = variant.parameters, variant.parameters_use
    plant = spec.plant
    if variant.plant:  # its plant keys over the command's plant options
        try:
            plant = dataclasses.replace(plant, **dict(variant.plant))
        except InvalidParameterError as exc:
            raise InvalidParameterError(f"{variant.key}: {exc.name}", exc.value, exc.expected) from None
    return dataclasses.replace(
        spec, gains=tuple(gains.items()), lam=lam, parameters=parameters, parameters_use=use, plant=plant
    )


def gains_used(controller: Controller) -> dict[str, Any]:
    """The gains a law ran with (the robot's presets and derived values resolved), JSON-ready:
    a number, a list per joint or per parameter, a matrix as its rows, or None
    (:func:`~twolink_pin.controllers.gains.gain_as_json`)."""
    from twolink_pin.controllers.gains import gain_as_json

    return {name: gain_as_json(value) for name, value in controller.gains.values().items()}


def plant_description(scenario: Scenario) -> str:
    """Which plant a law ran on, in a few words (the comparison table's column)."""
    return scenario.plant.describe()


def make_scenario(
    law: str | type[Controller],
    robot: RobotModel,
    *,
    lam: float | None = None,
    gains: Mapping[str, Any] | None = None,
    saturate: bool = False,
    friction_smoothing: float = 0.0,
) -> Scenario:
    """The law on ``robot`` with its default gains (the robot's presets), and its plant: the
    :class:`RunSpec` of these options, built (:meth:`RunSpec.build`).

    Args:
        law: The law (class, registered name, ``file.py:Class`` or ``module:Class``).
        robot: The arm (plant and law model).
        lam: ``λ`` [1/s] for a law whose gains have ``lam``; refused for one without.
        gains: Other gains by field name (one value, one per joint, ...), over the defaults.
        saturate: Clip torques at the URDF limits in the plant.
        friction_smoothing: ε [rad/s] of ``tanh(q̇/ε)`` for Coulomb friction (0: exact sgn).

    Raises:
        InvalidParameterError: ``lam`` or a gain the law does not have.
        ControllerSpecError: no such law.
    """
    cls = law_class(law)
    smoothing = (friction_smoothing or None) if "friction" in cls.estimates else None
    spec = RunSpec(
        law=cls,
        gains=tuple((gains or {}).items()),
        lam=lam,
        plant=PlantOptions(saturate=saturate, friction_smoothing=smoothing),
    )
    return spec.build(robot)


__all__ = [
    "ADAPTIVE_SMOOTHING",
    "FRICTION_CHOICES",
    "PARAMETER_USES",
    "PlantOptions",
    "RunSpec",
    "gains_used",
    "law_spec",
    "make_scenario",
    "plant_description",
]
