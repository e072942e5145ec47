"""``trajectory --time-optimal`` and ``optimize``: references designed within the arm's limits."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.cli.commands.common import robot_from_args, trajectory_from_args
from twolink_pin.cli.output import emit, fmt
from twolink_pin.errors import InvalidParameterError

if TYPE_CHECKING:
    from twolink_pin.dynamics import Friction
    from twolink_pin.limits import JointLimits, LimitsCheck, Motion
    from twolink_pin.limits.active import ActiveLimit
    from twolink_pin.model import RobotModel
    from twolink_pin.trajectory import Trajectory


def _friction(args: argparse.Namespace, robot: RobotModel) -> tuple[Friction | None, str]:
    """The plant's friction when ``--friction`` asks for it, and where it comes from."""
    if not args.friction:
        return None, "none"
    from twolink_pin.plant import robot_friction

    return robot_friction(robot)


def _check_save(path: str | None) -> None:
    """Refuse a ``--save`` name a trajectory file cannot have, before any work."""
    if path and Path(path).suffix.lower() not in (".json", ".toml"):
        raise InvalidParameterError("--save", path, "a trajectory file name ending in .json or .toml")


def _limit_lines(check: LimitsCheck) -> list[str]:
    """Each kind's peak against its limit, per joint."""
    lines = []
    for kind in check.kinds:
        if kind.kind.name == "position" or not np.isfinite(kind.limit).any():
            continue
        ratio = [f"{p / lim:.3f}" if np.isfinite(lim) else "—" for p, lim in zip(kind.peak, kind.limit)]
        lines.append(f"  peak |{kind.kind.symbol}| / limit: {', '.join(ratio)} ({kind.kind.name})")
    return lines


def _figures(
    args: argparse.Namespace,
    motion: Motion,
    limits: JointLimits,
    prefix: str,
    title: str,
    active: tuple[ActiveLimit, ...],
    reference: Motion | None,
) -> list[str]:
    """``--plot DIR``: the velocity, acceleration and torque figures."""
    if not args.plot:
        return []
    from twolink_pin.files import removed_on_failure
    from twolink_pin.plotting.within_limits import save_limit_figures

    with removed_on_failure(args.plot) as folder:
        return [str(p) for p in save_limit_figures(motion, limits, folder, prefix, title, active, reference)]


def _save(args: argparse.Namespace, trajectory: Any) -> str | None:
    """``--save FILE``: the trajectory file, written once the run succeeded."""
    if not args.save:
        return None
    from twolink_pin.trajectory.file import write_trajectory_file

    write_trajectory_file(args.save, trajectory)
    print(f"saved to {args.save} (read by --trajectory)", file=sys.stderr)
    return str(args.save)


def time_optimal_command(args: argparse.Namespace, robot: RobotModel, reference: Trajectory) -> int:
    """``trajectory --time-optimal``: the reference's path retimed within the limits."""
    from twolink_pin.limits import reference_motion
    from twolink_pin.trajectory.retiming import time_optimal, verify_motion

    _check_save(args.save)
    friction, source = _friction(args, robot)
    scale = 1.0 if args.limit_scale is None else args.limit_scale
    result = time_optimal(robot, reference, limit_scale=scale, friction=friction)
    motion = verify_motion(robot, result.trajectory, 4, friction)
    figures = _figures(
        args, motion, result.limits, "time_optimal_", "time-optimal retiming", result.active,
        reference_motion(robot, reference, 2001, friction),
    )  # fmt: skip
    saved = _save(args, result.trajectory)
    payload = {
        "duration": result.duration,
        "original_duration": result.original_duration,
        "original_period": reference.period,
        "limit_scale": scale,
        "friction": source,
        "gridpoints": result.gridpoints,
        "seconds": result.seconds,
        "via_times": result.trajectory.via_times.tolist(),
        "active": [a.summary() for a in result.active],
        "limits_check": result.check.summary(),
        "figures": figures,
        "saved": saved,
    }
    lines = [
        f"time-optimal retiming (TOPP-RA, {result.gridpoints} grid intervals) of {robot.name}'s reference path, within "
        f"{100 * scale:g} % of its limits" + ("" if friction is None else f", friction from {source}") + ":",
        f"  duration {result.duration:.6g} s (the reference: {result.original_duration:g} s of motion, period "
        f"{reference.period:g} s): {result.original_duration / result.duration:.3g}× faster; rest to rest, "
        "repeating every duration",
        f"  via points at t = {fmt(result.trajectory.via_times, 4)} s",
        "  active limits (within 1 %):",
        *[f"    {a.describe()}" for a in result.active],
        *_limit_lines(result.check),
        f"  every limit held on a grid 10× finer than TOPP-RA's ({result.seconds * 1e3:.0f} ms)",
    ]
    lines += [f"figure {f}" for f in figures]
    emit(args, payload, "\n".join(lines))
    return 0


def cmd_optimize(args: argparse.Namespace) -> int:
    """``optimize``: the least effort or the shortest duration through the via points."""
    from twolink_pin.limits import reference_motion
    from twolink_pin.trajectory.optimal import optimize
    from twolink_pin.trajectory.retiming import verify_motion

    _check_save(args.save)
    robot = robot_from_args(args)
    reference = trajectory_from_args(args, robot)
    friction, source = _friction(args, robot)
    scale = 1.0 if args.limit_scale is None else args.limit_scale
    result = optimize(
        robot, reference, args.cost, limit_scale=scale, friction=friction, max_iterations=args.max_iterations
    )
    motion = verify_motion(robot, result.trajectory, 20, friction)
    figures = _figures(
        args, motion, result.limits, f"optimal_{args.cost}_", f"minimum-{args.cost} trajectory", (),
        reference_motion(robot, reference, 2001, friction),
    )  # fmt: skip
    saved = _save(args, result.trajectory)
    emit(
        args,
        _optimize_payload(result, scale, source, figures, saved),
        _optimize_text(robot, result, scale, source, figures),
    )
    return 0


def _optimize_payload(
    result: Any, scale: float, source: str, figures: list[str], saved: str | None
) -> dict[str, Any]:
    """``optimize --json``."""
    return {
        "cost": result.cost,
        "duration": result.duration,
        "iterations": result.iterations,
        "seconds": result.seconds,
        "via_error": result.via_error,
        "pose_error": None if result.pose_error is None else list(result.pose_error),
        "max_violation": result.max_violation,
        "effort": result.effort,
        "reference_effort": result.reference_effort,
        "reference_duration": result.reference_duration,
        "retimed_duration": result.retimed_duration,
        "limit_scale": scale,
        "friction": source,
        "via_times": result.trajectory.via_times.tolist(),
        "limits_check": result.check.summary(),
        "figures": figures,
        "saved": saved,
    }


def _optimize_text(robot: RobotModel, result: Any, scale: float, source: str, figures: list[str]) -> str:
    """``optimize``'s summary."""
    change = 100.0 * (result.effort / result.reference_effort - 1.0) if result.reference_effort > 0 else 0.0
    if result.cost == "effort":
        cost = (
            f"  ∫τᵀτ dt = {result.effort:.6g} N²·m²·s; the reference's polynomial: {result.reference_effort:.6g} "
            f"({change:+.1f} %), both over {result.duration:g} s"
        )
    else:
        cost = (
            f"  duration {result.duration:.6g} s; the time-optimal retiming of the reference's path: "
            f"{result.retimed_duration:.6g} s; the reference: {result.reference_duration:g} s"
        )
    violation = "no limit" if result.max_violation is None else f"{result.max_violation:.3g} of the limit"
    pose = (
        ""
        if result.pose_error is None
        else f"; via poses to {result.pose_error[0]:.2g} m, {result.pose_error[1]:.2g} rad"
    )
    lines = [
        f"minimum-{result.cost} trajectory of {robot.name} through its reference's via points, within "
        f"{100 * scale:g} % of its limits" + ("" if source == "none" else f", friction from {source}") + ":",
        cost,
        f"  via points at t = {fmt(result.trajectory.via_times, 4)} s, to {result.via_error:.2g} rad{pose}",
        f"  largest excess over a limit on the check grid: {violation} (<= 0: every limit held)",
        *_limit_lines(result.check),
        f"  {result.iterations} SQP iterations, {result.seconds:.3g} s",
    ]
    lines += [f"figure {f}" for f in figures]
    return "\n".join(lines)


def sampled_trajectory_command(args: argparse.Namespace, robot: RobotModel, traj: Any, check: Any) -> int:
    """``trajectory`` for a ``samples`` file: its samples, period, via times and every limit."""
    from twolink_pin.cli.output import limits_check_lines, limits_payload

    figures: list[str] = []
    if args.plot:
        from twolink_pin.files import removed_on_failure
        from twolink_pin.plotting import save_trajectory_figures

        with removed_on_failure(args.plot) as folder:
            figures = [str(p) for p in save_trajectory_figures(robot, traj, check, folder)]
    payload = {
        "samples": int(traj.times.size),
        "period": traj.period,
        "via_times": traj.via_times.tolist(),
        "feedforward": traj.tau is not None,
        **check.summary(),
        **limits_payload(check),
        "figures": figures,
    }
    lines = [
        f"{traj.times.size} samples of q, q̇, q̈{', τ' if traj.tau is not None else ''} (quintic Hermite between), "
        f"period {traj.period:.6g} s",
        f"via points at t = {fmt(traj.via_times, 4)} s" if traj.via_times.size else "no via points marked",
        f"peak |tau| {fmt(check.peak, 2)} N·m at t = {fmt(check.peak_time, 3)} s",
        check.verdict(),
        *limits_check_lines(check.limits_check),
    ]
    lines += [f"figure {f}" for f in figures]
    emit(args, payload, "\n".join(lines))
    return 0


__all__ = ["cmd_optimize", "sampled_trajectory_command", "time_optimal_command"]
