"""One frozen description of a run: :class:`RunSpec`, and the one place that builds it.

A run is a law (its reference and gains), the plant it drives (:class:`PlantOptions`),
what its model believes (an identified-parameter file and its use) and the simulation
settings (:class:`~twolink_pin.simulation.SimulationConfig`, the initial offset among
them). Every command builds one from its arguments, once; ``compare`` and ``report`` give
one spec for several laws and take each law's own with :meth:`RunSpec.for_law`; the sweep
and the report hold one beside their own options; a saved result records it
(:meth:`RunSpec.as_dict`), so a run can be replayed from its file alone.

:meth:`RunSpec.build` is the only function that turns a description into a controller and
its plant (it calls :func:`~twolink_pin.scenario.make_scenario` or, with identified
parameters, :func:`~twolink_pin.identification.seeded_scenario`).

Adding a run option: one field here (of :class:`RunSpec` or, for the plant,
:class:`PlantOptions`, with its check in ``__post_init__`` and its use in :meth:`build`), one
line in ``cli/parser.py`` and one in :func:`twolink_pin.cli.commands.common.run_spec`, and a
test that the option reaches the built plant or law (``tests/test_run_spec.py`` shows the
pattern).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from twolink_pin.controllers import Controller
from twolink_pin.disturbances import PayloadStep, SensorNoise, Wrench, check_delay
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.plant import Plant
from twolink_pin.scenario import Scenario, law_class, make_scenario
from twolink_pin.simulation import SimulationConfig

if TYPE_CHECKING:
    from twolink_pin.identification import IdentifiedParameters

FRICTION_CHOICES = ("law", "on", "off")
"""``PlantOptions.friction``: the profile's friction in the plant of a law that estimates
friction only (``law``, the report's experiments), in every plant (``on``), in none (``off``)."""
PARAMETER_USES = ("p0", "model")
"""How identified parameters are used: the estimates start there (``p0``), or the law's
model believes them (``model``)."""
ADAPTIVE_SMOOTHING = 1e-3
"""ε [rad/s] of the friction sign with the adaptive integrator when none is given (the
exact sign stalls its step-size control); RK4 uses the exact sign (0)."""

Gains = tuple[tuple[str, Any], ...]
"""Gains by field name, as ``((name, value), ...)`` (a value: a number or a tuple)."""


def _frozen_gains(gains: Mapping[str, Any] | Gains) -> Gains:
    items = gains.items() if isinstance(gains, Mapping) else gains
    return tuple((str(k), tuple(v) if isinstance(v, (list, tuple)) else v) for k, v in items)


@dataclass(frozen=True)
class PlantOptions:
    """The simulated arm's options (every law of a command runs on the same ones).

    Attributes:
        friction: ``law`` (default: the profile's friction for a law that estimates friction,
            none otherwise), ``on`` (every plant) or ``off`` (no plant).
        saturate: Clip torques at the URDF effort limits.
        friction_smoothing: ε [rad/s] of ``tanh(q̇/ε)`` for Coulomb friction; None: 0 with
            RK4, :data:`ADAPTIVE_SMOOTHING` with the adaptive integrator.
        wrench: An external wrench on a frame over a time window (world axes, N and N·m).
        payload_step: A payload picked up at a time (the law is not told).
        sensor_noise: Seeded Gaussian noise on the q [rad] and q̇ [rad/s] the law measures.
        delay: Steps between a measurement and the torque it produces.

    The last four are the plant's events (:mod:`twolink_pin.disturbances`: what each does,
    and when, on the engine's grid); all off by default, as in the course report.
    """

    friction: str = "law"
    saturate: bool = False
    friction_smoothing: float | None = None
    wrench: Wrench | None = None
    payload_step: PayloadStep | None = None
    sensor_noise: SensorNoise | None = None
    delay: int = 0

    def __post_init__(self) -> None:
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

    def for_law(self, law: str) -> RunSpec:
        """The spec of ``law`` among several: its own gains (``law_gains``), λ if it has one,
        the identified parameters if it uses them (``model``: every law; ``p0``: the laws that
        estimate)."""
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
        """The identified parameters of ``parameters`` for ``robot`` (None without a file)."""
        if self.parameters is None:
            return None
        from twolink_pin.identification import read_parameter_file

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
        gains = dict(self.gains)
        smoothing = self.friction_smoothing
        if self.parameters is not None:
            from twolink_pin.identification import seeded_scenario

            if identified is None:
                identified = self.read_parameters(robot)
            assert identified is not None
            scenario: Scenario = seeded_scenario(
                cls,
                robot,
                identified,
                self.parameters_use,
                lam=self.lam,
                gains=gains,
                saturate=self.plant.saturate,
                friction_smoothing=smoothing,
            )
        else:
            scenario = make_scenario(
                cls,
                robot,
                lam=self.lam,
                gains=gains,
                saturate=self.plant.saturate,
                friction_smoothing=smoothing,
            )
        return _with_events(_with_plant(scenario, robot, self.plant, smoothing), self.plant)

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
        )


def _with_plant(scenario: Scenario, robot: RobotModel, options: PlantOptions, smoothing: float) -> Scenario:
    """``scenario`` with the plant friction ``options.friction`` asks for (the law's belief unchanged)."""
    if options.friction == "law":
        return scenario
    from twolink_pin.dynamics import Friction

    friction = None
    if options.friction == "on":
        friction = scenario.plant.friction
        if friction is None and robot.profile.friction is not None:
            viscous, coulomb = robot.profile.friction
            friction = Friction(viscous, coulomb, smoothing=smoothing)
    return scenario._replace(plant=Plant(robot, friction=friction, saturate=options.saturate))


def _with_events(scenario: Scenario, options: PlantOptions) -> Scenario:
    """``scenario`` whose plant carries the events ``options`` asks for (the same when none)."""
    if (
        options.wrench is None
        and options.payload_step is None
        and options.sensor_noise is None
        and not options.delay
    ):
        return scenario
    plant = scenario.plant
    return scenario._replace(
        plant=Plant(
            plant.robot,
            plant.friction,
            plant.saturate,
            wrench=options.wrench,
            payload_step=options.payload_step,
            sensor_noise=options.sensor_noise,
            delay=options.delay,
        )
    )


def gains_used(controller: Controller) -> dict[str, Any]:
    """The gains a law ran with (the robot's presets and derived values resolved), JSON-ready:
    a number, a list per joint or per parameter, a matrix as its rows, or None
    (:func:`~twolink_pin.controllers.gains.gain_as_json`)."""
    from twolink_pin.controllers.gains import gain_as_json

    return {name: gain_as_json(value) for name, value in controller.gains.values().items()}


def plant_description(scenario: Scenario) -> str:
    """Which plant a law ran on, in a few words (the comparison table's column)."""
    plant = scenario.plant
    parts = ["friction" if plant.friction is not None else "no friction"]
    if plant.saturate:
        parts.append("saturated")
    if plant.wrench is not None:
        parts.append("wrench")
    if plant.payload_step is not None:
        parts.append(f"payload {plant.payload_step.mass:g} kg at {plant.payload_step.time:g} s")
    if plant.sensor_noise is not None:
        parts.append("sensor noise")
    if plant.delay:
        parts.append(f"delay {plant.delay} steps")
    return ", ".join(parts)


__all__ = ["FRICTION_CHOICES", "PARAMETER_USES", "PlantOptions", "RunSpec", "gains_used", "plant_description"]
