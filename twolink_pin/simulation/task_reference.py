"""The task-space reference a task-space law sees: desired pose, twist and acceleration of the
end-effector frame, sampled where the engine samples the joint reference.

For a law that declares ``task_space = True``
(:attr:`~twolink_pin.controllers.Controller.task_space`) :func:`task_reference` gives, per
sample time, ``x_des`` (1, 3) [m], ``R_des`` (1, 3, 3), ``twist_des`` (1, 6) and
``accel_des`` (1, 6), world-aligned with the linear rows first (the convention of
:class:`~twolink_pin.controllers.FrameTerms`):

* from the SE(3) reference itself when the trajectory is a
  :class:`~twolink_pin.trajectory.se3.PoseTrajectory` (via poses);
* else from the forward kinematics of the joint reference on the law's robot:
  ``x_d = f(q_d)``, ``[ṗ_d; ω_d] = J(q_d) q̇_d``, ``[p̈_d; ω̇_d] = J(q_d) q̈_d + J̇ q̇_d``
  (Pinocchio's ``getFrameVelocity`` and ``getFrameClassicalAcceleration``,
  ``LOCAL_WORLD_ALIGNED``) — what the task laws computed themselves before.

Any other law gets ``None`` in those four fields (and costs nothing). The arrays are
read-only, like the rest of the reference.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from twolink_pin.controllers import Controller, LawInput
from twolink_pin.controllers.contact_input import ContactInput
from twolink_pin.simulation.containment import read_only
from twolink_pin.simulation.preview import preview_offsets, previews
from twolink_pin.trajectory import Trajectory, TrajectorySample
from twolink_pin.trajectory.se3 import PoseSample, PoseTrajectory

WORLD_ALIGNED = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class _Nones:
    """``[i]`` → None for every i: the four task fields of a law that is not task-space."""

    def __getitem__(self, index: int) -> None:
        return None


NONES = _Nones()


def forward_pose(controller: Controller, joint: TrajectorySample) -> PoseSample:
    """The end-effector frame's pose, twist and classical acceleration [m, rad; world-aligned,
    linear first] along the joint samples ``joint`` ((K, nv) arrays), on the law's robot."""
    robot = controller.robot
    model = robot.model
    data = model.createData()
    fid = robot.ee_frame_id
    q, v, a = (np.atleast_2d(x) for x in (joint.q, joint.v, joint.a))
    k = q.shape[0]
    position, rotation = np.empty((k, 3)), np.empty((k, 3, 3))
    twist, accel = np.empty((k, 6)), np.empty((k, 6))
    for i in range(k):
        pin.forwardKinematics(model, data, q[i], v[i], a[i])
        placement = pin.updateFramePlacement(model, data, fid)
        position[i] = placement.translation
        rotation[i] = placement.rotation
        twist[i] = pin.getFrameVelocity(model, data, fid, WORLD_ALIGNED).vector
        accel[i] = pin.getFrameClassicalAcceleration(model, data, fid, WORLD_ALIGNED).vector
    return PoseSample(position, rotation, twist, accel)


def desired_pose(
    controller: Controller, trajectory: Trajectory | None, t: np.ndarray, joint: TrajectorySample
) -> PoseSample:
    """The desired frame at times ``t`` [s] (K,): the SE(3) reference's, else (any other
    trajectory, or None) the forward kinematics of the joint samples ``joint`` at those times."""
    if isinstance(trajectory, PoseTrajectory) and controller.robot.nv == trajectory.nv:
        return trajectory.pose(t)
    return forward_pose(controller, joint)


def task_reference(
    controller: Controller, trajectory: Trajectory | None, t: np.ndarray, joint: TrajectorySample
) -> tuple[Sequence[Any], Sequence[Any], Sequence[Any], Sequence[Any]]:
    """``x_des``, ``R_des``, ``twist_des``, ``accel_des`` per sample time ``t`` [s], each
    indexable by the sample (an item of shape (1, …), read-only); four :data:`NONES` for a
    law that is not task-space."""
    if not getattr(controller, "task_space", False):
        return NONES, NONES, NONES, NONES  # type: ignore[return-value]
    pose = desired_pose(controller, trajectory, np.asarray(t, dtype=float), joint)
    return tuple(read_only(np.ascontiguousarray(x[:, None])) for x in pose)  # type: ignore[return-value]


def law_input(
    controller: Controller,
    t: float,
    q: np.ndarray,
    v: np.ndarray,
    z: np.ndarray,
    q_des: np.ndarray,
    v_des: np.ndarray,
    a_des: np.ndarray,
    trajectory: Trajectory | None = None,
    contact: ContactInput | None = None,
) -> LawInput:
    """The :class:`~twolink_pin.controllers.LawInput` the engine would build at time ``t`` [s]
    (to evaluate a law by itself, e.g. in a test): the reference ``q_des``, ``v_des``,
    ``a_des`` of shape (1, nv) and, for a task-space law, the desired frame from
    ``trajectory``'s SE(3) reference if it has one, else from their forward kinematics;
    ``contact``: what the force sensor reads (None: no scene); for a law that declares preview
    times, ``trajectory`` sampled there (None without a trajectory)."""
    joint = TrajectorySample(q_des, v_des, a_des, np.zeros_like(a_des))
    task = task_reference(controller, trajectory, np.array([t]), joint)
    ahead = previews(preview_offsets(controller), trajectory, np.array([t]))[0]
    px, pr, pw, pa = (x[0] for x in task)
    return LawInput(t, q, v, z, q_des, v_des, a_des, px, pr, pw, pa, contact, ahead)


def reference_rows(
    controller: Controller,
    trajectory: Trajectory,
    t: np.ndarray,
    joint: TrajectorySample,
    rq: np.ndarray,
    rv: np.ndarray,
    ra: np.ndarray,
    contact: Sequence[ContactInput] | None = None,
    ahead: np.ndarray | None = None,
    at: np.ndarray | None = None,
) -> list[tuple[Any, ...]]:
    """Per sample time ``t`` [s], the nine reference fields of a
    :class:`~twolink_pin.controllers.LawInput` after ``(t, q, v, z)``: ``q_des``, ``v_des``,
    ``a_des`` (the rows of the read-only ``rq``, ``rv``, ``ra``, each (K, 1, nv)), the four task
    fields of :func:`task_reference` (None for a law that is not task-space), the contact's
    reference part (``contact``, one per time: :meth:`~twolink_pin.simulation.sensing.ForceSensor.rows`,
    whose wrench the sensor fills in; None without a scene) and the preview at the offsets
    ``ahead`` [s] (:mod:`twolink_pin.simulation.preview`; None without, and at the times ``at``
    (K,) bool leaves out)."""
    px, pr, pw, pa = task_reference(controller, trajectory, t, joint)
    touch = contact if contact is not None else [None] * len(t)
    preview = previews(ahead, trajectory, t, at)
    # Rows by iteration in C (zip over the arrays: the same read-only views as rq[i]; no
    # Python __getitem__ of NONES, no Python loop per row)
    if px is NONES:
        px = pr = pw = pa = [None] * len(t)
    return list(zip(rq, rv, ra, px, pr, pw, pa, touch, preview, strict=True))
