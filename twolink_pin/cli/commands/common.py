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
    from twolink_pin.simulation import SimulationConfig, SimulationResult
    from twolink_pin.trajectory import Trajectory


def _robot(args: argparse.Namespace) -> RobotModel:
    from twolink_pin.model import load_robot

    return load_robot(args.robot, payload=getattr(args, "payload", 0.0))


def _trajectory(args: argparse.Namespace, robot: RobotModel) -> Trajectory:
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
    )


def _smoothing(args: argparse.Namespace) -> float:
    smoothing = args.friction_smoothing
    if smoothing is None:
        smoothing = 1e-3 if args.method == "adaptive" else 0.0
    return float(smoothing)


def _gain_values(texts: list[str]) -> dict[str, Any]:
    """``["kp=200", "kd=30,40"]`` → ``{"kp": 200.0, "kd": (30.0, 40.0)}``."""
    from twolink_pin.cli.arguments import finite

    gains: dict[str, Any] = {}
    for text in texts:
        name, sep, value = text.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise InvalidParameterError("--gain", text, "NAME=VALUE, e.g. kp=200 or kd=30,40")
        try:
            numbers = tuple(finite(x) for x in value.split(","))
        except argparse.ArgumentTypeError as exc:
            raise InvalidParameterError(
                f"--gain {name.strip()}", value, str(exc).removeprefix("expected ")
            ) from None
        gains[name.strip()] = numbers[0] if len(numbers) == 1 else numbers
    return gains


def _identified(args: argparse.Namespace, robot: RobotModel) -> tuple[IdentifiedParameters | None, str]:
    """The parameter file of ``--p0`` or ``--model`` (read once per command) and which it was."""
    mode = "p0" if getattr(args, "p0", None) else "model" if getattr(args, "model", None) else ""
    if not mode:
        return None, ""
    cached = getattr(args, "identified_parameters", None)
    if cached is None:
        from twolink_pin.identification import read_parameter_file

        cached = read_parameter_file(getattr(args, mode), robot)
        args.identified_parameters = cached
        for note in cached.notes:
            print(f"twolink-pin: note: {cached.source}: {note}", file=sys.stderr)
    return cached, mode


def _run_one(
    args: argparse.Namespace, spec: str, robot: RobotModel, trajectory: Trajectory | None = None
) -> SimulationResult:
    from twolink_pin.scenario import law_class, make_scenario
    from twolink_pin.simulation import simulate

    cls = law_class(spec)
    lam = args.lam
    if lam is not None and not cls.takes("lam") and getattr(args, "lambda_optional", False):
        lam = None  # compare/report: λ applies to the laws that have one
    identified, mode = _identified(args, robot)
    several = getattr(args, "lambda_optional", False)  # compare: --p0 seeds the laws that estimate
    if identified is not None and (mode == "model" or cls.estimates or not several):
        from twolink_pin.identification import seeded_scenario

        controller, plant = seeded_scenario(
            cls,
            robot,
            identified,
            mode,
            lam=lam,
            gains=_gain_values(getattr(args, "gain", []) or []),
            saturate=args.saturate,
            friction_smoothing=_smoothing(args),
        )
    else:
        controller, plant = make_scenario(
            cls,
            robot,
            lam=lam,
            gains=_gain_values(getattr(args, "gain", []) or []),
            saturate=args.saturate,
            friction_smoothing=_smoothing(args),
        )
    reference = trajectory if trajectory is not None else _trajectory(args, robot)
    return simulate(controller, plant, reference, _config(args))
