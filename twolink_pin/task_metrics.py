"""Task-space errors and metrics of a run: the end effector's position [mm] and orientation [deg].

Beside the joint-space metrics (:mod:`twolink_pin.metrics`), for a task-space law or any law
judged by where the tool goes. The errors are those the task-space laws use
(:mod:`twolink_pin.controllers.task_space`): ``p − p_d`` [m] and ``log(R R_dᵀ)`` [rad] in world
axes, with ``p_d``, ``R_d`` the frame's pose at the joint reference (Pinocchio's forward
kinematics). Their norms give:

* ``position_*`` — ``|p − p_d|`` in millimetres: RMS over the run, max, and max over the last
  reference period (the whole run if shorter);
* ``orientation_*`` — the angle ``|log(R R_dᵀ)|`` in degrees, same three.

RMS here is over the output samples, ``sqrt(mean_k x_k²)``. One implementation, as for the
joint metrics: :class:`RunningTaskMetrics` takes blocks of N runs' samples (the engine's
observer in :func:`~twolink_pin.studies.batch.simulate_batch`, so a sweep's rows carry
them), :func:`task_metrics` feeds it a recorded run in one block.

Printed (:meth:`TaskMetrics.text`), a value below :data:`POSITION_RESOLUTION_MM` or
:data:`ORIENTATION_RESOLUTION_DEG` is a bound, ``< 1e-6``: the run's joint angles carry the
integrator's error (RK4: about 1e-11 rad at the default step), so digits below a nanometre or
a micro-degree are rounding, and they differ between machines (BLAS kernels). The numbers
themselves (``--json``, CSV) keep every digit.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from twolink_pin.controllers.task_space import rotation_error
from twolink_pin.errors import InvalidParameterError
from twolink_pin.frame_poses import angle_between, distance, frame_pose, poses
from twolink_pin.model import RobotModel
from twolink_pin.simulation.result import SimulationResult

if TYPE_CHECKING:
    from twolink_pin.simulation import Samples

TASK_UNITS = {
    "position_rms_mm": "mm",
    "position_max_mm": "mm",
    "position_last_period_max_mm": "mm",
    "orientation_rms_deg": "deg",
    "orientation_max_deg": "deg",
    "orientation_last_period_max_deg": "deg",
}
"""Each task metric (a field of :class:`TaskMetrics`) and its unit: the one list the tables read."""
TASK_TITLES = {
    "position_rms_mm": "RMS ‖Δp‖",
    "position_max_mm": "max ‖Δp‖",
    "position_last_period_max_mm": "last period max ‖Δp‖",
    "orientation_rms_deg": "RMS angle",
    "orientation_max_deg": "max angle",
    "orientation_last_period_max_deg": "last period max angle",
}
"""A short title of each task metric (no "|": Markdown tables hold them)."""


class TaskErrors(NamedTuple):
    """The frame's pose error at each sample."""

    position: np.ndarray
    """``p − p_d`` [m], shape (K, 3)."""
    orientation: np.ndarray
    """``log(R R_dᵀ)`` [rad] in world axes, shape (K, 3)."""


POSITION_RESOLUTION_MM = 1e-6
"""Position errors below this [mm] (1 nm) are printed as ``< 1e-6``: below the integrator's accuracy."""
ORIENTATION_RESOLUTION_DEG = 1e-6
"""Angle errors below this [deg] are printed as ``< 1e-6``: below the integrator's accuracy."""


def bounded(value: float, resolution: float, digits: int = 4) -> str:
    """``value`` to ``digits`` significant digits, or ``< resolution`` (``< 1e-6``) below it."""
    if abs(value) < resolution:
        mantissa, exponent = f"{resolution:.0e}".split("e")
        return f"< {mantissa}e{int(exponent)}"
    return f"{value:.{digits}g}"


class TaskMetrics(NamedTuple):
    """Norms of a run's task-space error (see the module docstring): floats for one run,
    arrays of shape (N,) for a batch (NaN for diverged runs; :meth:`run` takes one)."""

    position_rms_mm: Any
    """RMS of ``|p − p_d|`` over the samples [mm]."""
    position_max_mm: Any
    """max ``|p − p_d|`` [mm]."""
    position_last_period_max_mm: Any
    """max ``|p − p_d|`` over the last reference period [mm]."""
    orientation_rms_deg: Any
    """RMS of the angle ``|log(R R_dᵀ)|`` over the samples [deg]."""
    orientation_max_deg: Any
    """max angle [deg]."""
    orientation_last_period_max_deg: Any
    """max angle over the last reference period [deg]."""

    def as_dict(self) -> dict[str, Any]:
        """Plain floats (lists for a batch) by name (for JSON)."""
        return {k: np.asarray(v, dtype=float).tolist() for k, v in self._asdict().items()}

    def run(self, i: int) -> TaskMetrics:
        """Run ``i``'s metrics of a batch, as floats."""
        return TaskMetrics(*(float(np.asarray(v)[i]) for v in self))

    def text(self) -> tuple[str, ...]:
        """Each metric as printed: 4 significant digits, or a bound below the resolution
        (:data:`POSITION_RESOLUTION_MM`, :data:`ORIENTATION_RESOLUTION_DEG`)."""
        return tuple(
            bounded(
                value, POSITION_RESOLUTION_MM if name.startswith("position") else ORIENTATION_RESOLUTION_DEG
            )
            for name, value in self._asdict().items()
        )


def _frame_id(robot: RobotModel, frame: str | None) -> int:
    if frame is None:
        return int(robot.ee_frame_id)
    if isinstance(frame, str) and robot.model.existFrame(frame):
        return int(robot.model.getFrameId(frame))
    raise InvalidParameterError("frame", frame, f"a frame of {robot.name}")


def task_errors(robot: RobotModel, q: np.ndarray, q_des: np.ndarray, frame: str | None = None) -> TaskErrors:
    """The pose error of ``frame`` (default the end effector) at configurations ``q`` against
    ``q_des`` [rad], both shape (K, nq)."""
    q, q_des = np.atleast_2d(np.asarray(q, dtype=float)), np.atleast_2d(np.asarray(q_des, dtype=float))
    if q.shape != q_des.shape or q.shape[1] != robot.nq:
        raise InvalidParameterError("q", f"shape {q.shape}", f"(K, {robot.nq}) like q_des {q_des.shape}")
    frame_id = _frame_id(robot, frame)
    p, R = poses(robot, q, frame_id)
    p_d, R_d = poses(robot, q_des, frame_id)
    return TaskErrors(p - p_d, rotation_error(R, R_d))


class RunningTaskMetrics:
    """Running sums and maxima of N runs' task errors, fed block by block (an engine observer,
    like :class:`~twolink_pin.metrics.RunningMetrics`).

    Args:
        robot: The arm the runs drive (its frame's pose is Pinocchio's forward kinematics).
        runs: N.
        dt: Output grid spacing [s].
        samples: Total number of samples K (sample K − 1 ends the run).
        period: Reference period [s] (the "last period" window).
        frame: The frame (default the end effector).
    """

    def __init__(
        self, robot: RobotModel, runs: int, dt: float, samples: int, period: float, frame: str | None = None
    ) -> None:
        self.robot, self.frame_id = robot, _frame_id(robot, frame)
        self.samples = samples
        self.last_start = (samples - 1) * dt - period - 1e-12
        self.square = np.zeros((2, runs))
        self.peak = np.zeros((2, runs))
        self.last = np.zeros((2, runs))

    def add(self, samples: Samples) -> None:
        """Add a block of samples (``q`` (B, N, nv), ``q_des`` (B, 1, nv))."""
        q = np.asarray(samples.q, dtype=float)
        blocks, runs, nv = q.shape
        pose = frame_pose(self.robot, np.nan_to_num(q.reshape(-1, nv)), self.frame_id).shaped((blocks, runs))
        desired = frame_pose(self.robot, np.asarray(samples.q_des, dtype=float)[:, 0], self.frame_id)
        desired = desired.shaped((blocks, 1))
        position = np.broadcast_to(1e3 * distance(pose, desired), (blocks, runs))
        angle = np.broadcast_to(np.degrees(angle_between(pose, desired)), (blocks, runs))
        both = np.stack([position, angle], axis=1)  # (B, 2, N)
        self.square += (both * both).sum(axis=0)
        np.maximum(self.peak, both.max(axis=0), out=self.peak)
        late = np.asarray(samples.t) >= self.last_start
        if late.any():
            np.maximum(self.last, both[late].max(axis=0), out=self.last)

    def result(self, dead: np.ndarray | None = None) -> TaskMetrics:
        """The metrics of the N runs, arrays (N,); runs ``dead`` (mask (N,)) are NaN."""
        rms = np.sqrt(self.square / self.samples)
        columns = [rms[0], self.peak[0], self.last[0], rms[1], self.peak[1], self.last[1]]
        out = []
        for column in columns:
            column = np.array(column)
            if dead is not None:
                column[dead] = np.nan
            column.setflags(write=False)
            out.append(column)
        return TaskMetrics(*out)


def task_metrics(result: SimulationResult, robot: RobotModel, frame: str | None = None) -> TaskMetrics:
    """Task-space metrics of ``result`` (a run on ``robot``): :class:`RunningTaskMetrics` fed
    the recorded run in one block."""
    from twolink_pin.simulation import Samples

    q, q_des = np.asarray(result.q, dtype=float), np.asarray(result.q_des, dtype=float)
    if q.shape != q_des.shape or q.ndim != 2 or q.shape[1] != robot.nq:
        raise InvalidParameterError("q", f"shape {q.shape}", f"(K, {robot.nq}) like q_des {q_des.shape}")
    t = np.asarray(result.t)
    running = RunningTaskMetrics(robot, 1, result.dt, len(t), result.reference_period, frame)
    empty = np.zeros((len(t), 1, 0))
    running.add(Samples(0, t, q[:, None], empty, empty, empty, q_des[:, None], empty, empty))
    return running.result().run(0)
