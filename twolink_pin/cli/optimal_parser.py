"""The options of trajectories within limits (split from :mod:`.parser`): ``trajectory
--time-optimal`` and the ``optimize`` command (issue 36)."""

from __future__ import annotations

import argparse
from typing import Any

from twolink_pin.cli.arguments import bounded, whole
from twolink_pin.cli.common_options import add_robot_options, add_trajectory_option


def add_within_limits_options(p: argparse.ArgumentParser, retime: bool) -> None:
    """``--limit-scale`` and ``--friction`` (and, with ``retime``, ``--time-optimal``)."""
    if retime:
        p.add_argument(
            "--time-optimal",
            action="store_true",
            help="retime the reference's path to its shortest duration within the velocity, acceleration and "
            "effort limits (TOPP-RA); --save writes the retimed reference",
        )
    p.add_argument(
        "--limit-scale",
        type=bounded(0.0, 1.0, low_open=True, unit=""),
        default=None,
        metavar="F",
        help="use a fraction 0 < F <= 1 of each velocity, acceleration and effort limit (headroom for feedback; "
        "default 1)",
    )
    p.add_argument(
        "--friction",
        action="store_true",
        help="add the plant's joint friction (the robot's profile's, else its URDF's) to the torque the limits bound",
    )


def add_optimize_command(sub: Any, c: Any) -> None:
    """``optimize``: an optimal trajectory through the reference's via points."""
    from twolink_pin.trajectory.optimal import (
        COSTS,
        DEFAULT_REGULARISER,
        ENDS,
        MAX_ITERATIONS,
        REGULARISER_WEIGHT,
        REGULARISERS,
    )

    p = sub.add_parser(
        "optimize",
        help="the trajectory through the reference's via points with the least effort (its via times) or the "
        "shortest duration (via times free), within every limit of the arm",
    )
    p.add_argument(
        "--cost",
        choices=COSTS,
        default="effort",
        help="∫τᵀτ dt with the via times (effort, default) or the duration (time)",
    )
    p.add_argument(
        "--ends",
        choices=tuple(ENDS),
        default="smooth",
        help="effort: at rest with zero acceleration and jerk at both ends (smooth, default: the course "
        "polynomial's) or at rest only (rest: crocoddyl's; the torque may step at the start)",
    )
    p.add_argument(
        "--regulariser",
        choices=REGULARISERS,
        default=DEFAULT_REGULARISER,
        help="effort: add w ∫‖q − q_ref(t)‖² dt (path, default: near the reference's path, for via poses its "
        "straight SE(3) path), w ∫‖q̇‖² dt (velocity: the least motion) or minimise the effort alone (none: "
        "joints that cost little torque may swing far and fast)",
    )
    p.add_argument(
        "--regulariser-weight",
        type=bounded(0.0, 1e6, unit=""),
        default=REGULARISER_WEIGHT,
        metavar="K",
        help="the regulariser's weight as a fraction of the reference's ∫τᵀτ dt: path, one joint 0.1 rad off the "
        "path for the whole motion costs K times it; velocity, the reference's own motion costs K times it "
        f"(default {REGULARISER_WEIGHT:g})",
    )
    add_trajectory_option(p)
    add_within_limits_options(p, retime=False)
    p.add_argument(
        "--max-iterations",
        type=whole(1, 10_000),
        default=MAX_ITERATIONS,
        metavar="N",
        help=f"most SQP iterations of a solve (default {MAX_ITERATIONS})",
    )
    p.add_argument(
        "--plot", metavar="DIR", help="write the velocity, acceleration and torque figures into DIR"
    )
    p.add_argument(
        "--save",
        metavar="FILE",
        help="write the optimal trajectory (.json or .toml, with its torque) that --trajectory reads",
    )
    add_robot_options(p)
    p.set_defaults(func=c.cmd_optimize)


__all__ = ["add_optimize_command", "add_within_limits_options"]
