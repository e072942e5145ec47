"""The options every family of commands shares: the robot (``--robot``/``--urdf``,
``--payload``, ``--json``) and the reference (``--trajectory``); used by
:mod:`~twolink_pin.cli.parser` and :mod:`~twolink_pin.cli.identify_parser`."""

from __future__ import annotations

import argparse

from twolink_pin.cli.arguments import bounded

ROBOT_HELP = (
    "robot: a catalog name (twolink-pin robots lists them) or a path to a .urdf file (default twolink)"
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
    if json_flag:
        p.add_argument("--json", action="store_true", help="print JSON instead of text")


TRAJECTORY_HELP = (
    "the reference: a TOML or JSON file of via points, joint (times, joints [rad]) or end-effector "
    "(times, positions [m]), or a Fourier series (a fourier table: twolink-pin excite writes one); "
    "default: the robot's own"
)


def add_trajectory_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--trajectory", "--via", dest="trajectory", metavar="FILE", help=TRAJECTORY_HELP)


__all__ = ["MAX_PAYLOAD", "ROBOT_HELP", "TRAJECTORY_HELP", "add_robot_options", "add_trajectory_option"]
