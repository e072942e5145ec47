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
import pinocchio as pin

from twolink_pin.controllers.task_space import rotation_error
from twolink_pin.errors import InvalidParameterError
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


AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
COLUMNS = {"X": (1, 2), "Y": (2, 0), "Z": (0, 1)}
"""The columns ``(a, b)`` of ``R`` that a rotation by θ about an aligned axis mixes:
``R R_axis(θ)`` has ``c R_a + s R_b`` and ``c R_b − s R_a`` there (c = cos θ, s = sin θ)."""


class Link(NamedTuple):
    """One joint of the chain to a frame, as :func:`_chain` reads it from the model."""

    placement: pin.SE3
    """The joint's placement in its parent's frame."""
    kind: str
    """``"R"`` (revolute) or ``"P"`` (prismatic)."""
    axis: np.ndarray
    """Its unit axis in its own frame."""
    aligned: str
    """``"X"``, ``"Y"``, ``"Z"`` for a revolute joint about that axis, else ``""``."""
    coordinate: int
    """Its index in ``q``."""


def _joint_axis(joint: Any) -> tuple[str, np.ndarray, str] | None:
    """``("R" | "P", unit axis, aligned axis or "")`` of a revolute or prismatic joint, else None."""
    name = joint.shortname().removeprefix("JointModel")
    if name in ("RevoluteUnaligned", "PrismaticUnaligned"):
        return name[0], np.asarray(joint.extract().axis, dtype=float), ""
    if len(name) == 2 and name[0] in "RP" and name[1] in AXES:
        return name[0], np.array(AXES[name[1]]), name[1] if name[0] == "R" else ""
    return None


def _chain(model: pin.Model, frame_id: int) -> list[Link] | None:
    """The joints from the root to ``frame_id``'s; None when one is not a revolute or prismatic
    joint of one coordinate."""
    chain = []
    joint = int(model.frames[frame_id].parentJoint)
    while joint > 0:
        found = _joint_axis(model.joints[joint])
        if found is None or model.joints[joint].nq != 1:
            return None
        chain.append(Link(model.jointPlacements[joint], *found, int(model.joints[joint].idx_q)))
        joint = int(model.parents[joint])
    return chain[::-1]


def _times(rotation: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """``rotation @ matrix`` for a stack of rotations (K, 3, 3) and one matrix (3, 3) or vector
    (3,): numpy's own sum of products (no BLAS), so each row's result is the same whatever K
    (a sweep's rows do not depend on its chunks)."""
    return np.einsum("kij,jl->kil" if matrix.ndim == 2 else "kij,j->ki", rotation, matrix)


def _poses(robot: RobotModel, q: np.ndarray, frame_id: int) -> tuple[np.ndarray, np.ndarray]:
    """The frame's position [m] (K, 3) and rotation (K, 3, 3) at the configurations ``q`` (K, nq):
    Pinocchio's forward kinematics, composed for all K at once along the chain of revolute and
    prismatic joints (a joint of another kind: one configuration at a time). A revolute joint
    about the unit axis ``a`` turns ``R`` into ``R exp(θ [a]×) = R + sin θ R[a]× + (1 − cos θ) R[a]×²``
    (about x, y or z: two columns of ``R`` mixed, :data:`COLUMNS`)."""
    model = robot.model
    chain = _chain(model, frame_id)
    if chain is None:
        return _poses_one_by_one(model, q, frame_id)
    return _chain_poses(model, chain, q, frame_id)


def _placed(rotation: np.ndarray, position: np.ndarray, placement: pin.SE3) -> tuple[np.ndarray, np.ndarray]:
    """``(R, p)`` composed with a fixed placement: ``(R R_c, p + R p_c)``, skipping an identity part."""
    if np.any(placement.translation):
        position = position + _times(rotation, placement.translation)
    if not np.array_equal(placement.rotation, np.eye(3)):
        rotation = _times(rotation, placement.rotation)
    return rotation, position


def frame_positions(robot: RobotModel, q: np.ndarray, frame_id: int) -> np.ndarray:
    """The frame's origin [m] at the configurations ``q`` (K, nq) [rad], shape (K, 3): the
    forward kinematics the task metrics use, for all K at once."""
    return _poses(robot, np.asarray(q, dtype=float), frame_id)[0]


def _chain_poses(
    model: pin.Model, chain: list[Link], q: np.ndarray, frame_id: int
) -> tuple[np.ndarray, np.ndarray]:
    k = len(q)
    rotation, position = np.array(np.broadcast_to(np.eye(3), (k, 3, 3))), np.zeros((k, 3))
    for link in chain:
        rotation, position = _placed(rotation, position, link.placement)
        angle = q[:, link.coordinate]
        if link.aligned:
            a, b = COLUMNS[link.aligned]
            c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
            # in place: every array here is this function's own
            col_a, col_b = rotation[:, :, a].copy(), rotation[:, :, b]
            rotation[:, :, a] = c * col_a + s * col_b
            rotation[:, :, b] = c * col_b - s * col_a
        elif link.kind == "R":
            x, y, z = link.axis
            cross = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
            rotation = (
                rotation
                + np.sin(angle)[:, None, None] * _times(rotation, cross)
                + (1.0 - np.cos(angle))[:, None, None] * _times(rotation, cross @ cross)
            )
        else:
            position = position + _times(rotation, link.axis) * angle[:, None]
    return _placed(rotation, position, model.frames[frame_id].placement)[::-1]


def _poses_one_by_one(model: pin.Model, q: np.ndarray, frame_id: int) -> tuple[np.ndarray, np.ndarray]:
    data = model.createData()
    position, rotation = np.empty((len(q), 3)), np.empty((len(q), 3, 3))
    for k in range(len(q)):
        pin.forwardKinematics(model, data, q[k])
        placement = pin.updateFramePlacement(model, data, frame_id)
        position[k], rotation[k] = placement.translation, placement.rotation
    return position, rotation


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
    p, R = _poses(robot, q, frame_id)
    p_d, R_d = _poses(robot, q_des, frame_id)
    return TaskErrors(p - p_d, rotation_error(R, R_d))


def rotation_angle(R: np.ndarray, R_des: np.ndarray) -> np.ndarray:
    """The angle ``|log(R R_dᵀ)|`` [rad] in [0, π] of rotations ``R`` against ``R_des`` (any
    shapes ``(…, 3, 3)`` that broadcast, ``R_des`` not repeated in memory): the norm of
    :func:`~twolink_pin.controllers.task_space.rotation_error`, as ``atan2(|w|, (tr E − 1)/2)``
    with ``E = R R_dᵀ`` and ``w`` its skew part."""
    E = np.matmul(R, np.swapaxes(R_des, -1, -2))
    trace = E[..., 0, 0] + E[..., 1, 1] + E[..., 2, 2]
    w = np.stack(
        [E[..., 2, 1] - E[..., 1, 2], E[..., 0, 2] - E[..., 2, 0], E[..., 1, 0] - E[..., 0, 1]], axis=-1
    )
    return np.arctan2(0.5 * np.sqrt(np.add.reduce(w * w, axis=-1)), 0.5 * (trace - 1.0))


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
        p, R = _poses(self.robot, np.nan_to_num(q.reshape(-1, nv)), self.frame_id)
        p_d, R_d = _poses(self.robot, np.asarray(samples.q_des, dtype=float)[:, 0], self.frame_id)
        position = 1e3 * np.linalg.norm(p.reshape(blocks, runs, 3) - p_d[:, None], axis=2)
        angle = np.degrees(rotation_angle(R.reshape(blocks, runs, 3, 3), R_d[:, None]))
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
