"""Task-space errors and metrics of a run: the end effector's position [mm] and orientation [deg].

Beside the joint-space metrics (:mod:`twolink_pin.metrics`), for a task-space law or any law
judged by where the tool goes. The errors are those the task-space laws use
(:mod:`twolink_pin.controllers.task_space`): ``p − p_d`` [m] and ``log(R R_dᵀ)`` [rad] in world
axes, with ``p_d``, ``R_d`` the frame's pose at the joint reference (Pinocchio's forward
kinematics). Their norms give:

* ``position_*`` — ``|p − p_d|`` in millimetres: RMS over the run, max, and max over the last
  reference period (the whole run if shorter);
* ``orientation_*`` — the angle ``|log(R R_dᵀ)|`` in degrees, same three.

Printed (:meth:`TaskMetrics.text`), a value below :data:`POSITION_RESOLUTION_MM` or
:data:`ORIENTATION_RESOLUTION_DEG` is a bound, ``< 1e-6``: the run's joint angles carry the
integrator's error (RK4: about 1e-11 rad at the default step), so digits below a nanometre or
a micro-degree are rounding, and they differ between machines (BLAS kernels). The numbers
themselves (``--json``, CSV) keep every digit.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.controllers.task_space import rotation_error
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.simulation.result import SimulationResult


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
    """Norms of a run's task-space error (see the module docstring)."""

    position_rms_mm: float
    position_max_mm: float
    position_last_period_max_mm: float
    orientation_rms_deg: float
    orientation_max_deg: float
    orientation_last_period_max_deg: float

    def as_dict(self) -> dict[str, Any]:
        """Plain floats by name (for JSON)."""
        return {k: float(v) for k, v in self._asdict().items()}

    def text(self) -> tuple[str, ...]:
        """Each metric as printed: 4 significant digits, or a bound below the resolution
        (:data:`POSITION_RESOLUTION_MM`, :data:`ORIENTATION_RESOLUTION_DEG`)."""
        return tuple(
            bounded(
                value, POSITION_RESOLUTION_MM if name.startswith("position") else ORIENTATION_RESOLUTION_DEG
            )
            for name, value in self._asdict().items()
        )


def _poses(robot: RobotModel, q: np.ndarray, frame_id: int) -> tuple[np.ndarray, np.ndarray]:
    model, data = robot.model, robot.model.createData()
    position, rotation = np.empty((len(q), 3)), np.empty((len(q), 3, 3))
    for k in range(len(q)):
        pin.forwardKinematics(model, data, q[k])
        placement = pin.updateFramePlacement(model, data, frame_id)
        position[k], rotation[k] = placement.translation, placement.rotation
    return position, rotation


def task_errors(robot: RobotModel, q: np.ndarray, q_des: np.ndarray, frame: str | None = None) -> TaskErrors:
    """The pose error of ``frame`` (default the end effector) at configurations ``q`` against
    ``q_des`` [rad], both shape (K, nq)."""
    q, q_des = np.atleast_2d(np.asarray(q, dtype=float)), np.atleast_2d(np.asarray(q_des, dtype=float))
    if q.shape != q_des.shape or q.shape[1] != robot.nq:
        raise InvalidParameterError("q", f"shape {q.shape}", f"(K, {robot.nq}) like q_des {q_des.shape}")
    if frame is None:
        frame_id = robot.ee_frame_id
    elif isinstance(frame, str) and robot.model.existFrame(frame):
        frame_id = int(robot.model.getFrameId(frame))
    else:
        raise InvalidParameterError("frame", frame, f"a frame of {robot.name}")
    p, R = _poses(robot, q, frame_id)
    p_d, R_d = _poses(robot, q_des, frame_id)
    return TaskErrors(p - p_d, rotation_error(R, R_d))


def task_metrics(result: SimulationResult, robot: RobotModel, frame: str | None = None) -> TaskMetrics:
    """Task-space metrics of ``result`` (a run on ``robot``)."""
    errors = task_errors(robot, np.asarray(result.q), np.asarray(result.q_des), frame)
    t = np.asarray(result.t)
    last = t >= t[-1] - result.reference_period - 1e-12
    position = 1e3 * np.linalg.norm(errors.position, axis=1)
    angle = np.degrees(np.linalg.norm(errors.orientation, axis=1))
    return TaskMetrics(
        float(np.sqrt(np.mean(position**2))),
        float(position.max()),
        float(position[last].max()),
        float(np.sqrt(np.mean(angle**2))),
        float(angle.max()),
        float(angle[last].max()),
    )
