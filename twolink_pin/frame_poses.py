"""A frame's pose at K configurations at once, entry by entry: what the task metrics read.

Pinocchio's forward kinematics composed along the chain of one-coordinate revolute and
prismatic joints to the frame (a joint of another kind: Pinocchio one configuration at a
time). A pose is held as its **entries** (:data:`Pose`): the position's 3 and the rotation's
9, each an array (K,) or, while no joint has moved it, a Python float (the exact 0s and 1s
of fixed placements). A product with an exact 0 is skipped and one with an exact 1 is the
other factor, so a planar arm's rotation costs its 4 moving entries, and every operation is
one numpy call on K contiguous numbers: no (K, 3, 3) stacks, no BLAS, so a row's value does
not depend on K (a sweep's rows do not depend on its chunks). Sums run left to right, as
the textbook writes them. Positions [m], angles [rad].
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.model import RobotModel

Entry = float | np.ndarray
"""One entry of a pose: a float (the same for every configuration) or an array (K,)."""


class Pose(NamedTuple):
    """A frame's pose at K configurations, by entries."""

    position: list[Entry]
    """``p`` [m]: 3 entries."""
    rotation: list[list[Entry]]
    """``R``: 3 rows of 3 entries."""

    def arrays(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """``(p, R)`` as arrays (K, 3) [m] and (K, 3, 3)."""
        position = np.stack([_full(e, k) for e in self.position], axis=1)
        rotation = np.stack([_full(e, k) for row in self.rotation for e in row], axis=1)
        return position, rotation.reshape(k, 3, 3)

    def shaped(self, shape: tuple[int, ...]) -> Pose:
        """The same pose with each array entry reshaped to ``shape`` (floats stay floats)."""
        return Pose(
            [_reshaped(e, shape) for e in self.position],
            [[_reshaped(e, shape) for e in row] for row in self.rotation],
        )


AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
COLUMNS = {"X": (1, 2), "Y": (2, 0), "Z": (0, 1)}
"""The columns ``(a, b)`` of ``R`` that a rotation by θ about an aligned axis mixes:
``R R_axis(θ)`` has ``c R_a + s R_b`` and ``c R_b − s R_a`` there (c = cos θ, s = sin θ)."""


class Link(NamedTuple):
    """One joint of the chain to a frame, as :func:`chain` reads it from the model."""

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


def chain(model: pin.Model, frame_id: int) -> list[Link] | None:
    """The joints from the root to ``frame_id``'s; None when one is not a revolute or prismatic
    joint of one coordinate."""
    links = []
    joint = int(model.frames[frame_id].parentJoint)
    while joint > 0:
        found = _joint_axis(model.joints[joint])
        if found is None or model.joints[joint].nq != 1:
            return None
        links.append(Link(model.jointPlacements[joint], *found, int(model.joints[joint].idx_q)))
        joint = int(model.parents[joint])
    return links[::-1]


def frame_pose(robot: RobotModel, q: np.ndarray, frame_id: int) -> Pose:
    """The frame's pose at the configurations ``q`` (K, nq) [rad, m], by entries."""
    model = robot.model
    links = chain(model, frame_id)
    if links is None:
        return _pose_one_by_one(model, q, frame_id)
    pose = Pose([0.0, 0.0, 0.0], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    for link in links:
        pose = _placed(pose, link.placement)
        angle = q[:, link.coordinate]
        if link.kind == "P":
            position = [_sum([p, _product(_dot(row, link.axis), angle)]) for p, row in zip(*pose)]
            pose = Pose(position, pose.rotation)
        elif link.aligned:
            pose = _turned(pose, COLUMNS[link.aligned], np.cos(angle), np.sin(angle))
        else:
            pose = Pose(pose.position, _times(pose.rotation, _axis_rotation(link.axis, angle)))
    return _placed(pose, model.frames[frame_id].placement)


def frame_positions(robot: RobotModel, q: np.ndarray, frame_id: int) -> np.ndarray:
    """The frame's origin [m] at the configurations ``q`` (K, nq) [rad], shape (K, 3)."""
    q = np.asarray(q, dtype=float)
    return np.stack([_full(e, len(q)) for e in frame_pose(robot, q, frame_id).position], axis=1)


def poses(robot: RobotModel, q: np.ndarray, frame_id: int) -> tuple[np.ndarray, np.ndarray]:
    """The frame's position [m] (K, 3) and rotation (K, 3, 3) at the configurations ``q`` (K, nq)."""
    q = np.asarray(q, dtype=float)
    return frame_pose(robot, q, frame_id).arrays(len(q))


def angle_between(pose: Pose, desired: Pose) -> Entry:
    """The angle ``|log(R R_dᵀ)|`` [rad] in [0, π] between two poses' rotations (entries that
    broadcast), as ``atan2(|w|, (tr E − 1)/2)`` with ``E = R R_dᵀ`` and ``w`` its skew part."""
    R, D = pose.rotation, desired.rotation
    E = [[_dot(R[i], D[j]) for j in range(3)] for i in range(3)]
    trace = _sum([E[0][0], E[1][1], E[2][2]])
    w = [_minus(E[2][1], E[1][2]), _minus(E[0][2], E[2][0]), _minus(E[1][0], E[0][1])]
    return np.arctan2(0.5 * np.sqrt(_dot(w, w)), 0.5 * (trace - 1.0))


def distance(pose: Pose, desired: Pose) -> Entry:
    """``|p − p_d|`` [m] of two poses' positions (entries that broadcast)."""
    d = [_minus(p, p_d) for p, p_d in zip(pose.position, desired.position, strict=True)]
    return np.sqrt(_dot(d, d))


# -- entries ---------------------------------------------------------------------------------


def _is(entry: Entry, value: float) -> bool:
    return isinstance(entry, float) and entry == value


def _product(x: Entry, y: Entry) -> Entry:
    """``x y``: 0 when either is an exact 0, the other when one is an exact 1."""
    if _is(x, 0.0) or _is(y, 0.0):
        return 0.0
    if _is(x, 1.0):
        return y
    if _is(y, 1.0):
        return x
    return x * y


def _sum(terms: Iterable[Entry]) -> Entry:
    """The terms added left to right, exact 0s skipped."""
    total: Entry = 0.0
    for term in terms:
        if not _is(term, 0.0):
            total = term if _is(total, 0.0) else total + term
    return total


def _minus(x: Entry, y: Entry) -> Entry:
    if _is(y, 0.0):
        return x
    return -y if _is(x, 0.0) else x - y


def _dot(x: Iterable[Entry], y: Iterable[Entry]) -> Entry:
    return _sum(_product(a, b) for a, b in zip(x, y, strict=True))


def _times(R: list[list[Entry]], C: list[list[Entry]]) -> list[list[Entry]]:
    """``R C`` by entries."""
    return [[_dot(row, [C[j][col] for j in range(3)]) for col in range(3)] for row in R]


def _floats(matrix: np.ndarray) -> list[Any]:
    return [float(x) for x in matrix] if matrix.ndim == 1 else [_floats(row) for row in matrix]


def _placed(pose: Pose, placement: pin.SE3) -> Pose:
    """The pose composed with a fixed placement: ``(p + R p_c, R R_c)``."""
    t, C = _floats(np.asarray(placement.translation)), _floats(np.asarray(placement.rotation))
    position = [_sum([p, _dot(row, t)]) for p, row in zip(*pose)]
    return Pose(position, _times(pose.rotation, C))


def _turned(pose: Pose, columns: tuple[int, int], c: np.ndarray, s: np.ndarray) -> Pose:
    """``R R_axis(θ)`` for an aligned axis: columns ``a, b`` become ``c R_a + s R_b`` and ``c R_b − s R_a``."""
    a, b = columns
    rotation = [list(row) for row in pose.rotation]
    for row in rotation:
        col_a, col_b = row[a], row[b]
        row[a] = _sum([_product(c, col_a), _product(s, col_b)])
        row[b] = _minus(_product(c, col_b), _product(s, col_a))
    return Pose(pose.position, rotation)


def _axis_rotation(axis: np.ndarray, angle: np.ndarray) -> list[list[Entry]]:
    """``exp(θ [a]×) = I + sin θ [a]× + (1 − cos θ) [a]×²`` by entries, for a unit axis ``a``."""
    x, y, z = (float(e) for e in axis)
    cross = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    K, K2 = _floats(cross), _floats(cross @ cross)
    s, versine = np.sin(angle), 1.0 - np.cos(angle)
    return [
        [_sum([1.0 if i == j else 0.0, _product(s, K[i][j]), _product(versine, K2[i][j])]) for j in range(3)]
        for i in range(3)
    ]


def _pose_one_by_one(model: pin.Model, q: np.ndarray, frame_id: int) -> Pose:
    data = model.createData()
    position, rotation = np.empty((len(q), 3)), np.empty((len(q), 3, 3))
    for k in range(len(q)):
        pin.forwardKinematics(model, data, q[k])
        placement = pin.updateFramePlacement(model, data, frame_id)
        position[k], rotation[k] = placement.translation, placement.rotation
    return Pose([position[:, i] for i in range(3)], [[rotation[:, i, j] for j in range(3)] for i in range(3)])


def _full(entry: Entry, k: int) -> np.ndarray:
    return np.full(k, entry) if isinstance(entry, float) else entry


def _reshaped(entry: Entry, shape: tuple[int, ...]) -> Entry:
    return entry if isinstance(entry, float) else entry.reshape(shape)
