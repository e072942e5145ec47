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
from twolink_pin.errors import InvalidParameterError
from twolink_pin.interrupts import Terminated
from twolink_pin.readiness import ready

if TYPE_CHECKING:
    from twolink_pin.model import RobotModel
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.trajectory import Trajectory


PERIODS = 3
"""Periods of the reference a run holds when ``--duration`` is not given: more than one, so
that the last period's error tells what the first period's transient hides."""


def _duration(args: argparse.Namespace) -> None:
    """No ``--duration``: :data:`PERIODS` periods of the reference."""
    if args.duration is None:
        robot = robot_from_args(args)
        args.duration = PERIODS * float(trajectory_from_args(args, robot).period)


def _check_watch(args: argparse.Namespace) -> None:
    """``--watch`` watches a law's file: refused for a registered law (nothing to watch)."""
    law = str(args.controller)
    if args.watch and not law.partition(":")[0].endswith(".py"):
        raise InvalidParameterError(
            "--watch",
            law,
            "a law given as a file (path/to/law.py:Class) to reload when it is saved; "
            f"{law!r} is no file (leave --watch out)",
        )


def cmd_tune(args: argparse.Namespace) -> int:
    from twolink_pin.cli.commands.run import run_record
    from twolink_pin.cli.simulate_line import command_line, simulate_argv
    from twolink_pin.contact_checks import check_contact
    from twolink_pin.tuning import Tuner

    _check_watch(args)
    _duration(args)
    spec = run_spec(args, args.controller)
    robot = robot_from_args(args)
    identified_parameters(spec, robot)  # the parameter file's notes, once
    check_contact(spec.plant, spec.simulation, [spec.law_class()], trajectory_from_args(args, robot))

    def arm(payload: float) -> tuple[RobotModel, Trajectory]:
        at = argparse.Namespace(**(vars(args) | {"payload": payload}))
        robot = robot_from_args(at)
        return robot, trajectory_from_args(at, robot)

    def command_of(run: RunSpec, payload: float) -> str:
        return command_line(
            simulate_argv(
                run,
                args.robot,
                payload,
                args.trajectory,
                scene=args.scene,
                repair_inertias=args.repair_inertias,
            )
        )

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
        limit=args.timeout or None,
    )
    try:
        emit(args, {"url": tuner.url}, f"tuning {args.controller} at {tuner.url} (Ctrl-C stops it)")
        if not tuner.address.loopback:
            from twolink_pin.tuning.address import exposure_note

            print(exposure_note(tuner.address, tuner.server.get_port()), file=sys.stderr, flush=True)
        ready("serving")
        if not args.no_browser:
            import webbrowser

            webbrowser.open(tuner.url)
        threading.Event().wait()
    except Terminated:  # SIGTERM: exit 143 "terminated", as every command
        raise
    except KeyboardInterrupt:  # Ctrl-C: the way to stop the tuner (exit 0)
        pass
    finally:
        tuner.close()
    return 0
