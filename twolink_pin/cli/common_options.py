"""The options every family of commands shares: the robot (``--robot``/``--urdf``,
``--payload``, ``--json``) and the reference (``--trajectory``); used by
:mod:`~twolink_pin.cli.parser` and :mod:`~twolink_pin.cli.identify_parser`."""

from __future__ import annotations

import argparse

from twolink_pin.cli.arguments import bounded

ROBOT_HELP = (
    "robot: a catalog name or one of your profiles (twolink-pin robots lists them), a path to a .urdf file, "
    "or a profile file .toml (one arm of a URDF, its home, gains: docs/your_arm.md) (default twolink)"
)

MAX_PAYLOAD = 1e4
"""Largest payload accepted on the command line [kg]."""


def add_robot_options(p: argparse.ArgumentParser, json_flag: bool = True) -> None:
    p.add_argument("--robot", "--urdf", dest="robot", metavar="NAME|PATH", help=ROBOT_HELP)
    p.add_argument(
        "--payload",
        type=bounded(0.0, MAX_PAYLOAD, unit="kg"),
        default=0.0,
        help="point mass at the end effector [kg] (0 to 1e4)",
    )
    p.add_argument(
        "--repair-inertias",
        action="store_true",
        help="replace each URDF link inertia that breaks the triangle inequality by the nearest one that "
        "satisfies it (same principal axes, mass and centre of mass), listing each change on stderr; "
        "default: such a file is refused",
    )
    if json_flag:
        p.add_argument("--json", action="store_true", help="print JSON instead of text")


TRAJECTORY_HELP = (
    "the reference: a TOML or JSON file of via points, joint (times, joints [rad]) or end-effector "
    "(times, positions [m]), or a Fourier series (a fourier table: twolink-pin excite writes one); "
    "default: the robot's own"
)


RUN_GROUP = "run options"
"""The title of the argument group of the options that shape a simulated run (a field of
:class:`~twolink_pin.run_spec.RunSpec`): what ``animate --from`` refuses, what a saved result
records; ``tests/test_run_spec.py`` checks that each reaches the run."""


def run_group(p: argparse.ArgumentParser) -> argparse._ArgumentGroup:
    """The parser's group of run options (:data:`RUN_GROUP`), made at its first use."""
    group = getattr(p, "twolink_run_group", None)
    if group is None:
        group = p.add_argument_group(RUN_GROUP, "what shapes the simulated run (saved results record them)")
        p.twolink_run_group = group  # type: ignore[attr-defined]
    return group


def run_option_strings(p: argparse.ArgumentParser) -> frozenset[str]:
    """Every option string of ``p``'s run options (``--lambda``, ``--delay``, ...)."""
    group = getattr(p, "twolink_run_group", None)
    if group is None:
        return frozenset()
    return frozenset(s for action in group._group_actions for s in action.option_strings)


def add_step_check_option(p: argparse.ArgumentParser) -> None:
    """``--no-step-check``: run even beyond the integrator's stability bound on the start's fastest
    mode (:mod:`twolink_pin.simulation.step_check`), which is refused by default."""
    run_group(p).add_argument(
        "--no-step-check",
        dest="check_step",
        action="store_false",
        help="run even when --dt (or --control-period) is beyond the integrator's stability bound on the "
        "fastest mode of the start (refused by default, exit 2, with the largest stable step)",
    )


def add_trajectory_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--trajectory", "--via", dest="trajectory", metavar="FILE", help=TRAJECTORY_HELP)


__all__ = [
    "MAX_PAYLOAD",
    "ROBOT_HELP",
    "RUN_GROUP",
    "TRAJECTORY_HELP",
    "add_robot_options",
    "add_step_check_option",
    "add_trajectory_option",
    "run_group",
    "run_option_strings",
]
