"""``equations``: an arm's equations of motion in closed form (:mod:`twolink_pin.symbolic`)."""

from __future__ import annotations

import argparse
from typing import Any

from twolink_pin.cli.commands.common import robot_from_args
from twolink_pin.cli.output import emit


def _timed_out(robot: str, joints: int) -> Any:
    from twolink_pin.errors import EquationsError

    def error(timeout: Any) -> EquationsError:  # a deadline.RunTimeout
        return EquationsError(
            robot,
            f"the derivation of its {joints} joints did not finish within --timeout {timeout.seconds:g} s of wall-clock "
            "time; give a larger --timeout, or fewer joints with --joints N (docs/equations.md: time per "
            "number of joints)",
        )

    return error


def cmd_equations(args: argparse.Namespace) -> int:
    from twolink_pin.files import atomic_write
    from twolink_pin.model.catalog import resolve
    from twolink_pin.simulation.deadline import bounded
    from twolink_pin.symbolic import check_urdf, derive_equations
    from twolink_pin.symbolic.formats import equations_json, equations_latex, equations_text
    from twolink_pin.symbolic.numpy_module import numpy_module

    path, _ = resolve(args.robot)
    check_urdf(path)  # a floating, planar or unknown joint, a closed chain: said in these terms
    robot = robot_from_args(args)
    source = str(robot.urdf_path)
    joints = args.joints or robot.nv
    with bounded(_timed_out(robot.name, joints)):
        eq = derive_equations(robot, joints=args.joints, use_cache=not args.no_cache)
        latex = equations_latex(eq, source) if args.latex else None
        module = numpy_module(eq, source) if args.python else None
        payload = equations_json(eq, source) if args.json else {}
        text = "" if args.json else equations_text(eq, source)
    written = []
    for target, content in ((args.latex, latex), (args.python, module)):
        if target and content is not None:
            with atomic_write(target) as f:
                f.write(content)
            written.append(target)
    if args.json:
        payload["written"] = written
    else:
        text += "".join(f"wrote {target}\n" for target in written)
    emit(args, payload, text.rstrip("\n"))
    return 0
