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


def _limit_lines(check: LimitsCheck, scale: float = 1.0) -> list[str]:
    """Each kind's peak against its limit, per joint: the limit the URDF gives (with
    ``--limit-scale F`` < 1, also against the fraction ``F`` of it that was used)."""
    lines = []
    for kind in check.kinds:
        if kind.kind.name == "position" or not np.isfinite(kind.limit).any():
            continue
        used = [p / lim if np.isfinite(lim) else None for p, lim in zip(kind.peak, kind.limit)]
        true = ", ".join("—" if r is None else f"{r * scale:.3f}" for r in used)
        line = f"  peak |{kind.kind.symbol}| / limit: {true} ({kind.kind.name}"
        if scale != 1.0:
            line += f"; of the {100 * scale:g} % used: " + ", ".join(
                "—" if r is None else f"{r:.3f}" for r in used
            )
        lines.append(line + ")")
    return lines


def _verdict(check: LimitsCheck, scale: float) -> str:
    """The first verdict of ``trajectory --time-optimal`` and ``optimize``: every kind of limit
    (the JSON's ``within_limits``), on the one check grid (:func:`~twolink_pin.limits.check_limits`)."""
    t = check.motion.t
    grid = f"on the check grid ({t.size} instants, at most {1e3 * float(np.diff(t).max()):.3g} ms apart)"
    if scale != 1.0:
        grid = f"(the {100 * scale:g} % used) " + grid
    if check.within_limits:
        return f"  within every limit {grid}"
    names = check.limits.joint_names
    beyond = [
        f"{kind.kind.name} of joint {j + 1} ({names[j]}) by {-kind.margin[j]:.3g} {kind.kind.unit}"
        for kind in check.kinds
        for j in np.flatnonzero(kind.margin < 0)
    ]
    return f"  BEYOND A LIMIT {grid}: {', '.join(beyond)}"


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
        "within_limits": result.check.within_limits,
        "within_effort_limits": result.check.of("effort").within_limits,
        "limits_check": result.check.summary(),
        "limits_check_grid": _grid(result.check),
        "figures": figures,
        "saved": saved,
    }
    lines = [
        f"time-optimal retiming (TOPP-RA, {result.gridpoints} grid intervals) of {robot.name}'s reference path, within "
        f"{100 * scale:g} % of its limits" + ("" if friction is None else f", friction from {source}") + ":",
        _verdict(result.check, scale),
        f"  duration {result.duration:.6g} s (the reference: {result.original_duration:g} s of motion, period "
        f"{reference.period:g} s): {result.original_duration / result.duration:.3g}× faster; rest to rest, "
        "repeating every duration",
        f"  via points at t = {fmt(result.trajectory.via_times, 4)} s",
        "  active limits (within 1 %):",
        *[f"    {a.describe()}" for a in result.active],
        *_limit_lines(result.check, scale),
        f"  ({result.seconds * 1e3:.0f} ms)",
    ]
    lines += [f"figure {f}" for f in figures]
    emit(args, payload, "\n".join(lines))
    return 0


def _grid(check: LimitsCheck) -> dict[str, Any]:
    """The check grid, JSON-ready (as ``trajectory --json`` gives it)."""
    from twolink_pin.cli.output import limits_payload

    return limits_payload(check)["limits_check_grid"]


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
        robot, reference, args.cost, limit_scale=scale, friction=friction, max_iterations=args.max_iterations,
        ends=args.ends, regulariser=args.regulariser, regulariser_weight=args.regulariser_weight,
    )  # fmt: skip
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


def _hull_payload(result: Any) -> dict[str, Any]:
    """How far the end effector leaves the via points' hull, JSON-ready."""
    return {
        "distance_m": result.hull.distance,
        "time_s": result.hull.time,
        "position_m": result.hull.position.tolist(),
        "reference_distance_m": result.reference_hull.distance,
    }


def _optimize_payload(
    result: Any, scale: float, source: str, figures: list[str], saved: str | None
) -> dict[str, Any]:
    """``optimize --json``."""
    regulariser = result.regulariser
    return {
        "cost": result.cost,
        "within_limits": result.check.within_limits,
        "within_effort_limits": result.check.of("effort").within_limits,
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
        "ends": result.ends,
        "regulariser": None if regulariser is None else regulariser._asdict(),
        "hull_excursion": _hull_payload(result),
        "limit_scale": scale,
        "friction": source,
        "via_times": result.trajectory.via_times.tolist(),
        "limits_check": result.check.summary(),
        "limits_check_grid": _grid(result.check),
        "figures": figures,
        "saved": saved,
    }


def _cost_line(result: Any) -> str:
    """What was minimised, and to what."""
    if result.cost == "time":
        return (
            f"  duration {result.duration:.6g} s; the time-optimal retiming of the reference's path: "
            f"{result.retimed_duration:.6g} s; the reference: {result.reference_duration:g} s"
        )
    change = 100.0 * (result.effort / result.reference_effort - 1.0) if result.reference_effort > 0 else 0.0
    line = (
        f"  ∫τᵀτ dt = {result.effort:.6g} N²·m²·s; the reference: {result.reference_effort:.6g} ({change:+.1f} %), "
        f"both over {result.duration:g} s; ends {result.ends}"
    )
    reg = result.regulariser
    if reg is None or reg.kind == "none" or reg.weight == 0:
        return line + "; no regulariser (the effort alone)"
    if reg.kind == "path":
        return (
            line
            + f"; regulariser {reg.weight:.4g} ∫‖q − q_ref‖² dt (near the reference's path, κ = {reg.kappa:g}), "
            f"∫‖q − q_ref‖² dt = {reg.value:.3g} rad²·s"
        )
    return (
        line + f"; regulariser {reg.weight:.4g} ∫‖q̇‖² dt (κ = {reg.kappa:g} of the reference's effort), "
        f"∫‖q̇‖² dt = {reg.value:.4g} rad²/s"
    )


def _optimize_text(robot: RobotModel, result: Any, scale: float, source: str, figures: list[str]) -> str:
    """``optimize``'s summary: the verdict on every limit first."""
    violation = "no limit" if result.max_violation is None else f"{result.max_violation:.3g} of the limit"
    pose = (
        ""
        if result.pose_error is None
        else f"; via poses to {result.pose_error[0]:.2g} m, {result.pose_error[1]:.2g} rad"
    )
    hull, ref = result.hull, result.reference_hull
    lines = [
        f"minimum-{result.cost} trajectory of {robot.name} through its reference's via points, within "
        f"{100 * scale:g} % of its limits" + ("" if source == "none" else f", friction from {source}") + ":",
        _verdict(result.check, scale),
        _cost_line(result),
        f"  via points at t = {fmt(result.trajectory.via_times, 4)} s, to {result.via_error:.2g} rad{pose}",
        f"  the end effector leaves the via points' convex hull by up to {1e3 * hull.distance:.3g} mm (t = "
        f"{hull.time:.3f} s; the reference: {1e3 * ref.distance:.3g} mm)",
        f"  largest excess over a limit: {violation} (<= 0: every limit held)",
        *_limit_lines(result.check, scale),
        f"  {result.iterations} SQP iterations, {result.seconds:.3g} s",
    ]
    lines += [f"figure {f}" for f in figures]
    return "\n".join(lines)


def sampled_trajectory_command(args: argparse.Namespace, robot: RobotModel, traj: Any, check: Any) -> int:
    """``trajectory`` for a ``samples`` file: its samples, period, via times and every limit."""
    from twolink_pin.cli.output import limits_check_lines, limits_payload

    figures = _figures(  # no via points to draw: its velocity, acceleration, torque against the limits
        args,
        check.limits_check.motion,
        check.limits_check.limits,
        "trajectory_",
        Path(args.trajectory).name,
        (),
        None,
    )
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
