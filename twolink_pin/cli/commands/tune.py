"""``tune``: tune a law live in the browser (:mod:`twolink_pin.tuning`)."""

from __future__ import annotations

import argparse
import sys
import threading
from typing import TYPE_CHECKING, Any

from twolink_pin.cli.commands.common import (
    identified_parameters,
    robot_from_args,
    run_spec,
    trajectory_from_args,
)
from twolink_pin.cli.output import emit

if TYPE_CHECKING:
    from twolink_pin.model import RobotModel
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.trajectory import Trajectory


def _duration(args: argparse.Namespace) -> None:
    """No ``--duration``: one period of the reference (a tuning run is short)."""
    if args.duration is None:
        robot = robot_from_args(args)
        args.duration = float(trajectory_from_args(args, robot).period)


def cmd_tune(args: argparse.Namespace) -> int:
    from twolink_pin.cli.commands.run import run_record
    from twolink_pin.cli.simulate_line import command_line, simulate_argv
    from twolink_pin.tuning import Tuner

    _duration(args)
    spec = run_spec(args, args.controller)
    identified_parameters(spec, robot_from_args(args))  # the parameter file's notes, once

    def arm(payload: float) -> tuple[RobotModel, Trajectory]:
        at = argparse.Namespace(**(vars(args) | {"payload": payload}))
        robot = robot_from_args(at)
        return robot, trajectory_from_args(at, robot)

    def command_of(run: RunSpec, payload: float) -> str:
        return command_line(simulate_argv(run, args.robot, payload, args.trajectory))

    def record_of(run: RunSpec, payload: float) -> dict[str, Any]:
        return run_record(argparse.Namespace(**(vars(args) | {"payload": payload})), run)

    lock = threading.Lock()

    def report(line: dict[str, Any]) -> None:
        if args.json:
            with lock:
                emit(args, line, "")

    tuner = Tuner(
        spec,
        args.payload,
        arm,
        command_of,
        record_of,
        report,
        host=args.host,
        port=args.port or 0,
        watch=args.watch,
    )
    try:
        emit(args, {"url": tuner.url}, f"tuning {args.controller} at {tuner.url}")
        if not args.no_browser:
            import webbrowser

            webbrowser.open(tuner.url)
        print("press Ctrl-C to stop", file=sys.stderr, flush=True)
        threading.Event().wait()
    except KeyboardInterrupt:
        print("stopping the tuner", file=sys.stderr, flush=True)
    finally:
        tuner.close()
    return 0
