"""What ``simulate`` and ``compare`` show of the end effector: the task-space metrics of every
run (position error [mm], orientation error [deg]: RMS, max, last period;
:func:`~twolink_pin.task_metrics.task_metrics`; a joint-space law moves the same end effector)
in the summary and ``--json``, and for a task-space law (one whose class declares
``task_space = True``) the task-error figure beside the joint ones in ``--plot``; and what
``trajectory`` shows for a file of via poses (:func:`pose_trajectory_command`)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from twolink_pin.controllers import Controller
    from twolink_pin.model import RobotModel
    from twolink_pin.simulation import SimulationResult
    from twolink_pin.task_metrics import TaskMetrics
    from twolink_pin.trajectory import PoseTrajectory


def is_task_space(controller: Controller | type) -> bool:
    """Whether the law (an instance or its class) declares ``task_space = True``."""
    return bool(getattr(controller, "task_space", False))


def task_summary(result: SimulationResult, robot: RobotModel) -> TaskMetrics:
    """The run's task-space metrics, whatever the law: a joint-space law moves the same end
    effector (:func:`~twolink_pin.task_metrics.task_metrics`)."""
    from twolink_pin.task_metrics import task_metrics

    return task_metrics(result, robot)


def task_lines(metrics: TaskMetrics | None) -> list[str]:
    """The summary's lines for ``metrics`` (none for None)."""
    if metrics is None:
        return []
    p_rms, p_max, p_last, a_rms, a_max, a_last = metrics.text()
    return [
        f"  task |p − p_d| RMS {p_rms} mm   max {p_max} mm   last period max {p_last} mm",
        f"  task angle     RMS {a_rms} deg  max {a_max} deg  last period max {a_last} deg",
    ]


def save_task_figure(
    robot: RobotModel,
    result: SimulationResult,
    folder: Path,
    prefix: str,
    title: str | None = None,
    spans: Sequence[tuple[float, float]] = (),
) -> Path:
    """``<prefix>_task_error.png`` in ``folder`` (:func:`~twolink_pin.plotting.save_task_error_figure`),
    ``spans`` (a wrench's window [s]) shaded."""
    from twolink_pin.plotting import save_task_error_figure

    name = f"{prefix}_task_error.png" if prefix else "task_error.png"
    return save_task_error_figure(robot, result, Path(folder) / name, title, spans)


def pose_trajectory_command(args: Any, robot: RobotModel, traj: PoseTrajectory, check: Any) -> int:
    """``trajectory`` for a file of via poses: the poses, the joint configurations the IK gave,
    how closely the joint path follows the pose path, the torque check; ``--plot`` as for via
    points."""
    import pinocchio as pin

    from twolink_pin.cli.output import emit, fmt, limits_check_lines, limits_payload

    figures: list[str] = []
    if args.plot:
        from twolink_pin.files import removed_on_failure
        from twolink_pin.plotting import save_trajectory_figures

        with removed_on_failure(args.plot) as folder:
            figures = [str(p) for p in save_trajectory_figures(robot, traj, check, folder)]  # type: ignore[arg-type]
    rpy = [pin.rpy.matrixToRpy(R) for R in traj.rotations]
    payload = {
        "times": traj.times.tolist(),
        "positions": traj.positions.tolist(),
        "rpy": [r.tolist() for r in rpy],
        "via_q": traj.via_q.tolist(),
        "ik_error": {"position_m": traj.ik_error[0], "angle_rad": traj.ik_error[1]},
        **check.summary(),
        **limits_payload(check),
        "figures": figures,
    }
    lines = ["via poses (t [s], position [m], roll-pitch-yaw [rad], q [rad]):"]
    for t, p, r, q in zip(traj.times, traj.positions, rpy, traj.via_q, strict=True):
        lines.append(f"  {t:5.2f}  {fmt(p, 3)}  {fmt(r, 4)}  {fmt(q)}")
    lines.append(
        f"joint path (6-D IK) vs pose path: within {traj.ik_error[0]:.2g} m and {traj.ik_error[1]:.2g} rad"
    )
    lines.append(f"peak |tau| {fmt(check.peak, 2)} N·m at t = {fmt(check.peak_time, 3)} s")
    lines.append(check.verdict())
    lines += limits_check_lines(check.limits_check)
    lines += [f"figure {f}" for f in figures]
    emit(args, payload, "\n".join(lines))
    return 0
