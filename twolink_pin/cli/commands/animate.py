"""``animate``: a run in 3-D — the law's run now, or a saved run (``--from FILE.npz``) on the robot,
reference and law it records — written as one HTML file (``--html``) or served in a meshcat
viewer until Ctrl-C or SIGTERM."""

from __future__ import annotations

import argparse
import sys
import threading
from typing import TYPE_CHECKING, Any

from twolink_pin.cli.commands.common import (
    gains_echo,
    identified_parameters,
    robot_from_args,
    run_spec,
    trajectory_from_args,
)
from twolink_pin.cli.output import emit
from twolink_pin.errors import InvalidParameterError

if TYPE_CHECKING:
    from twolink_pin.model import RobotModel
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.simulation import SimulationResult
    from twolink_pin.trajectory import Trajectory


def cmd_animate(args: argparse.Namespace) -> int:
    robot, reference, result, spec, controller = _run_to_animate(args)
    gains, gains_text = gains_echo(controller) if controller is not None else (None, "not recorded")
    from twolink_pin.plant_options import PlantOptions
    from twolink_pin.visualization.overlays import run_overlays

    plant = PlantOptions() if spec is None else spec.plant  # a saved run without its record: none
    overlays = run_overlays(plant.wrench, result.t, plant.scene, result.wrench)
    from twolink_pin.kinematics import joint_positions

    via_q = getattr(reference, "via_q", None)  # a Fourier excitation has no via points
    points = None if via_q is None else joint_positions(robot, via_q)[:, -1, :]  # the end effector's
    if args.html:
        from twolink_pin.visualization import write_html

        path = write_html(
            robot,
            result.t,
            result.q,
            result.q_des,
            path=args.html,
            via_points=points,
            loop=args.loop,
            **overlays,
        )
        emit(
            args,
            {"html": str(path), "controller": result.controller, "gains": gains},
            f"animation written to {path}\n  {result.controller} gains {gains_text}",
        )
        return 0
    _serve_animation(args, robot, result, points, overlays, gains, gains_text)
    return 0


def _run_to_animate(args: argparse.Namespace) -> tuple[Any, Any, Any, Any, Any]:
    """``(robot, reference, result, spec, controller)`` of the run ``animate`` shows: the saved
    run of ``--from`` (with no law and no run option beside it), else the law's run now."""
    if args.from_file:
        typed = {token.split("=")[0] for token in args.argv if token.startswith("--")}
        ignored = sorted(typed & args.run_options)  # the parser's run options (cli.common_options.run_group)
        if args.controller is not None or ignored:
            raise InvalidParameterError(
                "--from",
                args.from_file,
                "no CONTROLLER and no simulation option with it (it replays a saved run as it was); got "
                + ", ".join(([f"CONTROLLER {args.controller}"] if args.controller else []) + ignored),
            )
        robot, reference, result = _saved_run(args)
        spec = _saved_spec(args)
        return robot, reference, result, spec, _saved_controller(spec, robot)
    if args.controller is None:
        raise InvalidParameterError(
            "CONTROLLER", None, "a controller (name, file.py:Class) or --from FILE.npz"
        )
    from twolink_pin.simulation import simulate

    robot = robot_from_args(args)
    reference = trajectory_from_args(args, robot)
    spec = run_spec(args, args.controller)
    spec.check_effective(robot, trajectory=reference)
    scenario = spec.build(robot, identified_parameters(spec, robot))
    result = simulate(*scenario, reference, spec.simulation)
    return robot, reference, result, spec, scenario.controller


def _serve_animation(
    args: argparse.Namespace,
    robot: Any,
    result: Any,
    points: Any,
    overlays: dict[str, Any],
    gains: Any,
    gains_text: str,
) -> None:
    """Serve the run in a meshcat viewer until Ctrl-C or SIGTERM."""
    import signal

    from twolink_pin.visualization import serve

    def _stop(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, _stop)  # a service manager's stop shuts down as cleanly as Ctrl-C
    with serve(
        robot,
        result.t,
        result.q,
        result.q_des,
        via_points=points,
        host=args.host,
        port=args.port,
        loop=args.loop,
        open_browser=not args.no_browser,
        quiet=True,
        **overlays,
    ) as viewer:
        emit(
            args,
            {"url": viewer.url, "host": viewer.host, "port": viewer.port, "gains": gains},
            f"meshcat viewer at {viewer.url}\n  {result.controller} gains {gains_text}"
            + ("" if viewer.wrench_scale is None else f"\n  force arrow {viewer.wrench_scale:g} m per N"),
        )
        print("press Ctrl-C to stop", file=sys.stderr, flush=True)
        try:
            threading.Event().wait()
        except KeyboardInterrupt:
            print("stopping the viewer", file=sys.stderr)


def _saved_run(args: argparse.Namespace) -> tuple[RobotModel, Trajectory, SimulationResult]:
    """``animate --from FILE``: the result, on the robot and reference it records (``--robot``,
    ``--payload``, ``--trajectory`` given: those); a file that records no robot: the catalog
    robot of its name, else ``--robot``."""
    from twolink_pin.model import catalog, load_robot
    from twolink_pin.simulation.storage import load_record, load_result
    from twolink_pin.trajectory import default_trajectory, read_trajectory_file

    result = load_result(args.from_file)
    record = load_record(args.from_file) or {}
    source = args.robot
    payload = args.payload
    if source is None:
        source = record.get("robot") or (result.robot if result.robot in catalog.CATALOG else None)
        if "payload" in record and payload == 0.0:
            payload = float(record["payload"])
    repair = bool(getattr(args, "repair_inertias", False) or record.get("repair_inertias", False))
    robot = load_robot(source, payload=payload, repair_inertias=repair or None)
    if result.q.shape[1] != robot.nq:
        raise InvalidParameterError(
            "--from",
            args.from_file,
            f"a result for {robot.name} (nq = {robot.nq}); it has {result.q.shape[1]} joints",
        )
    path = args.trajectory or record.get("trajectory")
    reference = read_trajectory_file(path, robot) if path else default_trajectory(robot)
    return robot, reference, result


def _saved_spec(args: argparse.Namespace) -> RunSpec | None:
    """``animate --from FILE``: the run the file records, or None (an older file)."""
    from twolink_pin.errors import TwolinkPinError
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.simulation.storage import load_record

    run = (load_record(args.from_file) or {}).get("run")
    try:
        return RunSpec.from_dict(run) if run else None
    except TwolinkPinError:
        return None


def _saved_controller(spec: RunSpec | None, robot: RobotModel) -> Any:
    """The law a saved run used, rebuilt from the run it records (for its gains); None when
    the file records no run or the law cannot be rebuilt here."""
    from twolink_pin.errors import TwolinkPinError

    if spec is None or spec.law is None:
        return None
    try:
        return spec.build(robot).controller
    except TwolinkPinError:
        return None
