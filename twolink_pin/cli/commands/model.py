"""``info``, ``robots``, ``controllers``, ``fk``, ``ik``, ``trajectory``: the robot, its laws and
its reference, without a simulation."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.cli.commands.common import robot_from_args, trajectory_from_args
from twolink_pin.cli.output import emit, fmt, limits_check_lines, limits_payload, pose_lines
from twolink_pin.errors import InvalidParameterError, TwolinkPinError

if TYPE_CHECKING:
    from twolink_pin.limits import JointLimits
    from twolink_pin.model import RobotModel


def cmd_info(args: argparse.Namespace) -> int:
    from twolink_pin.limits import joint_limits
    from twolink_pin.model.base_parameters import BaseParameterMap

    robot = robot_from_args(args)
    limits = joint_limits(robot)
    base = (
        robot.parameter_map
        if isinstance(robot.parameter_map, BaseParameterMap)
        else BaseParameterMap(robot.model)
    )
    home_pose, home_lines = _pose_payload(robot, robot.home)
    payload: dict[str, Any] = {
        "robot": robot.name,
        "urdf": str(robot.urdf_path),
        "nq": robot.nq,
        "nv": robot.nv,
        "gravity": robot.model.gravity.linear.tolist(),
        "link_lengths": robot.link_lengths.tolist(),
        "torque_limits": robot.torque_limits.tolist(),
        "joint_names": list(limits.joint_names),
        "limits": limits.as_dict(),
        "home": robot.home.tolist(),
        "home_source": robot.profile.home_source or "the robot's profile",
        "home_pose": home_pose,
        "profile": None if robot.profile.file is None else str(robot.profile.file),
        "notes": list(robot.notes),
        "repaired_inertias": [change._asdict() for change in robot.repairs],
        "parameter_names": list(robot.parameter_map.names),
        "p": robot.p.tolist(),
        "base_parameters": {
            "count": base.size,
            "names": list(base.names),
            "units": list(base.units),
            "values": base.values(robot.model).tolist(),
        },
    }
    if args.friction:
        payload["friction_parameters"] = {
            "names": [f"V{j + 1}" for j in range(robot.nv)] + [f"C{j + 1}" for j in range(robot.nv)],
            "units": ["N·m·s/rad"] * robot.nv + ["N·m"] * robot.nv,
        }
    names = robot.parameter_map.names
    p_text = (
        ", ".join(f"{n} = {v:.6g}" for n, v in zip(names, robot.p))
        if len(names) <= 6
        else f"{len(names)} values"
    )
    text = "\n".join(
        [
            f"robot      {robot.name}: {robot.model.name} ({robot.urdf_path})",
            f"joints     nq = {robot.nq}, nv = {robot.nv}; end effector '{robot.ee_frame}'",
            f"gravity    {fmt(robot.model.gravity.linear, 3)} m/s²",
            f"links      {fmt(robot.link_lengths, 3)} m",
            *limits_table(limits),
            f"home       q = [{', '.join(_exact(x) for x in robot.home)}] rad, end effector at",
            *home_lines,
            f"  how      {robot.profile.home_source or 'given by the robot profile'}",
            f"payload    {robot.payload:g} kg",
            f"parameters {p_text}",
            f"base       {base.size} identifiable base parameters (twolink-pin info --json lists them)"
            + (f", plus {2 * robot.nv} friction (viscous V, Coulomb C per joint)" if args.friction else ""),
        ]
    )
    if args.write_urdf:
        payload["urdf_written"] = str(_write_payload_variant(robot, args.write_urdf))
        written = payload["urdf_written"]
        text += (
            f"\nwrote      {written}: the arm with its {robot.payload:g}-kg payload, as the plant with "
            f"--robot {written}, or as the model a law believes with --model {written}"
        )
    emit(args, payload, text)
    return 0


def _exact(x: float) -> str:
    """``x`` as the shortest text that reads back to it (``1.5707963267948966``, ``0``): the
    home is printed as the profile defines it, not rounded to a number of digits."""
    text = repr(float(x))
    return text[:-2] if text.endswith(".0") else text


def limits_table(limits: JointLimits) -> list[str]:
    """``info``'s table of each joint's limits: position range, velocity, acceleration, effort
    ("none" where the URDF or the profile gives none)."""

    def value(x: float) -> str:
        return f"{x:.6g}" if np.isfinite(x) else "none"

    names = limits.joint_names
    width = max(5, *(len(n) for n in names))
    lines = [
        "limits     position and velocity from the URDF, acceleration from the robot's profile, effort from the URDF",
        f"  {'joint':{width}s}  {'position [rad]':>26s}  {'velocity [rad/s]':>16s}  "
        f"{'acceleration [rad/s²]':>21s}  {'effort [N·m]':>12s}",
    ]
    for j, name in enumerate(names):
        lo, hi = float(limits.position_lower[j]), float(limits.position_upper[j])
        span = f"[{value(lo)}, {value(hi)}]" if np.isfinite(lo) or np.isfinite(hi) else "none"
        lines.append(
            f"  {name:{width}s}  {span:>26s}  {value(limits.velocity[j]):>16s}  "
            f"{value(limits.acceleration[j]):>21s}  {value(limits.effort[j]):>12s}"
        )
    return lines


def _write_payload_variant(robot: RobotModel, target_name: str) -> Path:
    """``info --write-urdf``: the robot with its payload as a URDF that ``--urdf`` loads back with
    the catalog robot's profile (:func:`~twolink_pin.model.payload.write_payload_urdf`)."""
    from twolink_pin.model.catalog import catalog_profile_name
    from twolink_pin.model.payload import write_payload_urdf

    if robot.payload <= 0:
        raise InvalidParameterError("--payload", robot.payload, "a mass > 0 kg to write a payload variant")
    target = Path(target_name)
    if target.exists() and target.resolve() == Path(robot.urdf_path).resolve():
        raise InvalidParameterError(
            "--write-urdf", target_name, "a file other than the robot's own URDF (it would be replaced)"
        )
    return write_payload_urdf(
        robot.urdf_path, robot.payload, target_name, robot.ee_frame, catalog_profile_name(robot.profile)
    )


def cmd_robots(args: argparse.Namespace) -> int:
    from twolink_pin.limits import joint_limits
    from twolink_pin.model import catalog, load_robot

    rows = []
    mine = {name: file for name, file in catalog.user_profiles().items() if name not in catalog.CATALOG}
    broken: dict[str, str] = {}
    for name in (*catalog.names(), *mine):
        try:
            robot = load_robot(name if name not in mine else mine[name])
        except TwolinkPinError as exc:  # a profile of the user's that does not load: said, not fatal
            broken[name] = str(exc)
            continue
        model = robot.model
        rows.append(
            {
                "name": name,
                "nq": robot.nq,
                "nv": robot.nv,
                "gravity": model.gravity.linear.tolist(),
                "torque_limits": robot.torque_limits.tolist(),
                "limits": joint_limits(robot).as_dict(),
                "end_effector": robot.ee_frame,
                "unlimited_joints": [
                    str(model.names[int(j) + 1]) for j in np.flatnonzero(np.isinf(model.lowerPositionLimit))
                ],
                "locked_joints": list(robot.profile.locked_joints),
                "home": robot.home.tolist(),
                "base_parameters": robot.parameter_map.size if name != "twolink" else 4,
                "description": robot.profile.description,
                "source": robot.profile.source,
                "profile": None if robot.profile.file is None else str(robot.profile.file),
            }
        )
    lines = []
    for row in rows:
        limits = ", ".join("none" if not np.isfinite(x) else f"{x:g}" for x in row["torque_limits"])
        notes = []
        if row["unlimited_joints"]:
            notes.append(f"no position limit on {', '.join(row['unlimited_joints'])}")
        if row["locked_joints"]:
            notes.append(f"locked {', '.join(row['locked_joints'])}")
        lines.append(
            f"{row['name']:16s} nq = {row['nq']}, nv = {row['nv']}, gravity {fmt(row['gravity'], 2)} m/s², "
            f"effort limits ({limits}) N·m — {row['description']}"
            + (f"\n{'':16s} {'; '.join(notes)}" if notes else "")
        )
    lines.append(
        "effort limit 'none': the URDF gives none (or 0); no torque check or saturation on that joint"
    )
    lines += [f"{name:16s} does not load: {why}" for name, why in broken.items()]
    lines.append(
        f"your profiles: {catalog.user_folder()} ({len(mine)} found; $TWOLINK_PIN_ROBOTS names another folder), "
        "or --robot FILE.toml"
    )
    emit(
        args, {"robots": rows, "broken": broken, "user_folder": str(catalog.user_folder())}, "\n".join(lines)
    )
    return 0


MATRIX_SIZE = {"axis": "3 × 3", "joint": "nv × nv", "estimate": "estimates × estimates"}
"""What ``controllers`` says of a matrix gain's size, by its ``per``."""


def cmd_controllers(args: argparse.Namespace) -> int:
    from dataclasses import fields

    from twolink_pin.controllers import available_controllers
    from twolink_pin.controllers.gains import default_as_json, gain_spec
    from twolink_pin.controllers.loading import broken_plugins

    rows: list[dict[str, Any]] = []
    for name, cls in available_controllers().items():
        gains: list[dict[str, Any]] = [
            {
                "name": f.name,
                "per": gain_spec(f).per,
                "matrix": gain_spec(f).matrix,
                "unit": gain_spec(f).unit,
                "default": default_as_json(cls.Gains, f.name),
                "doc": gain_spec(f).doc,
                **({"choices": list(gain_spec(f).choices)} if gain_spec(f).choices else {}),
            }
            for f in fields(cls.Gains)
        ]
        rows.append(
            {
                "name": name,
                "title": cls.title,
                "class": f"{cls.__module__}:{cls.__qualname__}",
                "estimates": list(cls.estimates),
                "gains": gains,
            }
        )
    lines = []
    for row in rows:
        listed = ", ".join(
            f"{g['name']}"
            + (f" [{g['unit']}]" if g["unit"] else "")
            + (f" ({MATRIX_SIZE[g['per']]} matrix)" if g["matrix"] else "")
            + (f" ({' | '.join(g['choices'])})" if g.get("choices") else "")
            for g in row["gains"]
        )
        lines.append(f"{row['name']:18s} {row['title']}\n{'':18s} gains: {listed}")
    broken = broken_plugins()
    for problem in broken.values():  # a plug-in that failed to load is not silently missing
        print(f"twolink-pin: warning: {problem}", file=sys.stderr, flush=True)
    emit(args, {"controllers": rows, "broken_plugins": broken}, "\n".join(lines))
    return 0


def _pose_payload(robot: RobotModel, q: np.ndarray) -> tuple[dict[str, Any], list[str]]:
    """The end effector's pose at ``q`` [rad] as JSON fields and as text lines."""
    from twolink_pin.kinematics import end_effector_pose

    position, rotation, rpy = end_effector_pose(robot, q)
    fields = {"position": position.tolist(), "rotation": rotation.tolist(), "rpy": rpy.tolist()}
    return fields, pose_lines(position, rotation, rpy, "  ")


def cmd_fk(args: argparse.Namespace) -> int:
    from twolink_pin.kinematics import joint_positions

    robot = robot_from_args(args)
    q = np.array(args.q, dtype=float)
    if q.shape != (robot.nq,):
        raise InvalidParameterError(
            "Q", args.q, f"{robot.nq} joint angles [rad] for {robot.name} (nq = {robot.nq})"
        )
    position = joint_positions(robot, q)[-1]
    pose, lines = _pose_payload(robot, q)
    emit(
        args,
        {
            "position": position.tolist(),
            "xy": position[:2].tolist(),
            "rotation": pose["rotation"],
            "rpy": pose["rpy"],
        },
        "\n".join([f"end effector at {fmt(position)} m for q = {fmt(q)} rad", *lines]),
    )
    return 0


def cmd_ik(args: argparse.Namespace) -> int:
    from twolink_pin.kinematics import inverse_kinematics, is_planar_2r, solve_position
    from twolink_pin.trajectory import home_configuration

    robot = robot_from_args(args)
    if args.z is None and args.seed is None and is_planar_2r(robot):
        sols = inverse_kinematics(robot, (args.x, args.y))
        text = "\n".join(
            f"{label}: q = {fmt(s)} rad" for label, s in zip(("elbow q2 >= 0", "elbow q2 <= 0"), sols)
        )
        emit(args, {"solutions": sols.tolist()}, text)
        return 0
    target = (args.x, args.y) if args.z is None else (args.x, args.y, args.z)
    seed = home_configuration(robot) if args.seed is None else np.array(args.seed, dtype=float)
    if seed.shape != (robot.nv,):
        raise InvalidParameterError("--seed", args.seed, f"{robot.nv} joint angles [rad] for {robot.name}")
    q = solve_position(robot, target, seed)
    emit(
        args,
        {"solutions": [q.tolist()], "seed": seed.tolist()},
        f"q = {fmt(q)} rad (damped least squares from {'home' if args.seed is None else 'the seed'})",
    )
    return 0


def cmd_trajectory(args: argparse.Namespace) -> int:
    from twolink_pin.feasibility import TorqueCheck
    from twolink_pin.limits import check_limits
    from twolink_pin.trajectory import (
        FourierTrajectory,
        JointTrajectory,
        PoseTrajectory,
        SampledTrajectory,
        default_via_points,
    )

    robot = robot_from_args(args)
    traj = trajectory_from_args(args, robot)
    if args.time_optimal:
        from twolink_pin.cli.commands.optimal import time_optimal_command

        return time_optimal_command(args, robot, traj)
    for flag, given in (("--limit-scale", args.limit_scale is not None), ("--friction", args.friction)):
        if given:
            raise InvalidParameterError(
                flag, "given", "--time-optimal beside it (it sets the retiming's limits)"
            )
    via = default_via_points(robot) if not args.trajectory else None
    check = TorqueCheck(check_limits(robot, traj))  # every limit; the figures show its effort kind
    if args.save:
        from twolink_pin.trajectory.file import write_trajectory_file

        if Path(args.save).suffix.lower() not in (".json", ".toml"):
            raise InvalidParameterError(
                "--save", args.save, "a trajectory file name ending in .json or .toml"
            )
        write_trajectory_file(args.save, traj)  # type: ignore[arg-type]
        print(f"reference saved to {args.save} (read by --trajectory and --reference)", file=sys.stderr)
    if isinstance(traj, FourierTrajectory):  # an excitation: no via points, no polynomial
        return _fourier_trajectory(args, robot, traj, check)
    if isinstance(traj, PoseTrajectory):  # via poses on SE(3): no polynomial
        from twolink_pin.cli.task_space import pose_trajectory_command

        return pose_trajectory_command(args, robot, traj, check)
    if isinstance(traj, SampledTrajectory):  # samples (a retimed or optimised reference)
        from twolink_pin.cli.commands.optimal import sampled_trajectory_command

        return sampled_trajectory_command(args, robot, traj, check)
    assert isinstance(traj, JointTrajectory)  # the only other kind a file or a profile gives
    figures: list[str] = []
    if args.plot:
        from twolink_pin.files import removed_on_failure
        from twolink_pin.plotting import save_trajectory_figures

        with removed_on_failure(args.plot) as folder:
            figures = [str(p) for p in save_trajectory_figures(robot, traj, check, folder)]
    payload = {
        "times": traj.times.tolist(),
        "via_xy": None if via is None else [list(p) for p in via.xy],
        "via_q": traj.via_q.tolist(),
        "coefficients": traj.coefficients.tolist(),
        **check.summary(),
        **limits_payload(check),
        "figures": figures,
    }
    lines = ["via points (t [s], q [rad]" + (", end effector (x, y) [m])" if via is not None else ")") + ":"]
    for k, (t, q) in enumerate(zip(traj.times, traj.via_q)):
        lines.append(f"  {t:5.2f}  {fmt(q)}" + (f"  {fmt(via.xy[k], 3)}" if via is not None else ""))
    for j, c in enumerate(traj.coefficients):
        terms = " ".join(f"{x:+.5g}" for x in c)
        lines.append(f"q{j + 1}(t) coefficients, ascending powers of t: {terms}")
    lines.append(f"peak |tau| {fmt(check.peak, 2)} N·m at t = {fmt(check.peak_time, 3)} s")
    lines.append(check.verdict())
    lines += limits_check_lines(check.limits_check)
    lines += [f"figure {f}" for f in figures]
    emit(args, payload, "\n".join(lines))
    return 0


def _fourier_trajectory(args: argparse.Namespace, robot: RobotModel, traj: Any, check: Any) -> int:
    """``trajectory`` for a Fourier-series file: its coefficients, bounds and torque check."""
    from twolink_pin.identification.measures import excitation_measures

    measures = excitation_measures(robot, traj)
    figures: list[str] = []
    if args.plot:
        from twolink_pin.files import removed_on_failure
        from twolink_pin.plotting.identification import save_excitation_figures

        with removed_on_failure(args.plot) as folder:
            figures = [str(p) for p in save_excitation_figures(robot, traj, folder, check=check)]
    q_bound, v_bound, a_bound = traj.bounds
    payload = {
        "fourier": traj.as_dict(),
        "bandwidth_hz": traj.bandwidth,
        "bounds": {"q_minus_offset": q_bound.tolist(), "v": v_bound.tolist(), "a": a_bound.tolist()},
        "condition_number": measures.condition_number,
        "gram_min_eigenvalue_per_s": measures.gram_min_eigenvalue_per_s,
        **check.summary(),
        **limits_payload(check),
        "figures": figures,
    }
    lines = [
        f"Fourier series: period {traj.period:g} s, {traj.harmonics} harmonics (up to {traj.bandwidth:.3g} Hz)",
        f"offsets q0 {fmt(traj.offset)} rad; bounds |q − q0| <= {fmt(q_bound, 3)} rad, |q̇| <= {fmt(v_bound, 3)} rad/s, "
        f"|q̈| <= {fmt(a_bound, 3)} rad/s²",
        f"cond(W) of the base parameters and friction over a period: {measures.condition_number:.4g}",
        f"peak |tau| {fmt(check.peak, 2)} N·m at t = {fmt(check.peak_time, 3)} s",
        check.verdict(),
        *limits_check_lines(check.limits_check),
    ]
    lines += [f"figure {f}" for f in figures]
    emit(args, payload, "\n".join(lines))
    return 0
