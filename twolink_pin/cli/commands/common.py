"""What the commands share: the robot, the reference, the simulation settings and one run
from the arguments."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from twolink_pin.errors import InvalidParameterError

if TYPE_CHECKING:
    from twolink_pin.identification import IdentifiedParameters
    from twolink_pin.model import RobotModel
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.simulation import SimulationConfig, SimulationResult
    from twolink_pin.trajectory import Trajectory


def robot_from_args(args: argparse.Namespace) -> RobotModel:
    """The robot of ``--robot``, ``--payload`` and ``--repair-inertias``; what the loader accepted
    with a note, and each inertia it repaired, said once on stderr."""
    from twolink_pin.controllers.loading import check_profile_gains
    from twolink_pin.model import load_robot

    repair = getattr(args, "repair_inertias", False) or None  # None: the profile's choice
    robot = load_robot(args.robot, payload=getattr(args, "payload", 0.0), repair_inertias=repair)
    check_profile_gains(robot)
    said = getattr(args, "notes_said", None)
    if said is None or robot.name not in said:
        for note in robot.notes:
            print(f"twolink-pin: note: {note}", file=sys.stderr, flush=True)
        for change in robot.repairs:
            print(f"twolink-pin: note: repaired inertia of {change.describe()}", file=sys.stderr, flush=True)
        if said is not None:
            said.add(robot.name)
    return robot


def trajectory_from_args(args: argparse.Namespace, robot: RobotModel) -> Trajectory:
    """The reference of ``--trajectory FILE``, else the robot's default."""
    from twolink_pin.trajectory import default_trajectory, read_trajectory_file

    path = getattr(args, "trajectory", None)
    return read_trajectory_file(path, robot) if path else default_trajectory(robot)


def _config(args: argparse.Namespace) -> SimulationConfig:
    from twolink_pin.simulation import SimulationConfig

    offset = args.q0_offset
    return SimulationConfig(
        duration=args.duration,
        dt=args.dt,
        method=args.method,
        q0_offset=None if offset is None else (offset[0] if len(offset) == 1 else tuple(offset)),
        control_period=args.control_period,
        check_step=getattr(args, "check_step", True),
    )


def gain_values(texts: list[str], law: str = "") -> dict[str, Any]:
    """``["kp=200", "kd=30,40"]`` → ``{"kp": 200.0, "kd": (30.0, 40.0)}`` (each value read by
    :func:`~twolink_pin.law_variant.gain_value`); a gain given twice is refused, naming it
    (as ``LAW.NAME`` with the ``law`` of ``--gain LAW.NAME=VALUE``)."""
    from twolink_pin.law_variant import gain_value

    gains: dict[str, Any] = {}
    given: dict[str, str] = {}
    for text in texts:
        name, sep, value = text.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise InvalidParameterError("--gain", law + text, "NAME=VALUE, e.g. kp=200 or kd=30,40")
        name = name.strip()
        if name in given:
            raise InvalidParameterError(
                f"--gain {law}{name}",
                value,
                f"each gain once ({law}{name} is given twice: {law + given[name]!r} and {law + text!r})",
            )
        given[name] = text
        gains[name] = gain_value(law + name, value)
    return gains


def _law_gains(texts: list[str]) -> tuple[tuple[str, tuple[tuple[str, Any], ...]], ...]:
    """compare/report ``--gain LAW.NAME=VALUE`` → per-law gains; a text without ``LAW.`` is
    refused, and so is a law's gain given twice."""
    per_law: dict[str, list[str]] = {}
    for text in texts:
        name, sep, value = text.partition("=")
        law, dot, gain = name.strip().rpartition(".")
        if not (sep and dot and law and gain):
            raise InvalidParameterError("--gain", text, "LAW.NAME=VALUE with several laws, e.g. pd.kp=200")
        per_law.setdefault(law, []).append(f"{gain}={value}")
    return tuple((law, tuple(gain_values(own, f"{law}.").items())) for law, own in per_law.items())


def run_spec(args: argparse.Namespace, law: str | None = None, fixed_gains: bool = True) -> RunSpec:
    """The run the arguments describe, built once per command (``law`` None: the common part
    of several laws' runs, as ``compare`` and ``report`` give them; ``fixed_gains`` False: the
    command's ``--gain`` is not a fixed gain, as the sweep's ranges)."""
    from twolink_pin.cli.disturbance_options import plant_events
    from twolink_pin.cli.plant_options import plant_effects
    from twolink_pin.run_spec import PlantOptions, RunSpec

    several = law is None
    texts = (getattr(args, "gain", []) or []) if fixed_gains else []
    mode = "p0" if getattr(args, "p0", None) else "model" if getattr(args, "model", None) else ""
    return RunSpec(
        law=law,
        gains=() if several else tuple(gain_values(texts).items()),
        law_gains=_law_gains(texts) if several else (),
        lam=args.lam,
        plant=PlantOptions(
            friction=getattr(args, "plant_friction", None) or "law",
            saturate=args.saturate,
            friction_smoothing=args.friction_smoothing,
            position_stops=args.joint_stops,
            **plant_events(args),
            **plant_effects(args),
        ),
        parameters=getattr(args, mode) if mode else None,
        parameters_use=mode,
        simulation=_config(args),
        shared=several,
        believed_effects=bool(getattr(args, "believe_effects", False)),
    )


def identified_parameters(spec: RunSpec, robot: RobotModel) -> IdentifiedParameters | None:
    """The parameter file of ``--p0`` or ``--model``, read once per command (its notes on stderr)."""
    identified = spec.read_parameters(robot)
    if identified is not None:
        for note in identified.notes:
            print(f"twolink-pin: note: {identified.source}: {note}", file=sys.stderr)
    return identified


def _run_one(
    spec: RunSpec,
    robot: RobotModel,
    reference: Trajectory,
    identified: IdentifiedParameters | None = None,
) -> SimulationResult:
    """One law's run (``spec`` of one law: :meth:`RunSpec.for_law` of a shared one)."""
    from twolink_pin.simulation import simulate

    controller, plant = spec.build(robot, identified)
    return simulate(controller, plant, reference, spec.simulation)


def gains_echo(controller: Any) -> tuple[dict[str, Any], str]:
    """The gains a law ran with, for ``--json`` (:func:`~twolink_pin.run_spec.gains_used`) and
    for the text (``kp = (350, 300) N·m/rad, …``): what every command that runs a law echoes."""
    from twolink_pin.run_spec import gains_used

    return gains_used(controller), controller.gains.describe()
