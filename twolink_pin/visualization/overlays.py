"""What the scene draws beside the arm: the external force as an arrow, the desired frame as a
triad, the surfaces of a scene as slabs.

* **The wrench** (``wrench/``): the force ``F`` [N] of an external wrench (world axes, at a
  frame's origin: :class:`~twolink_pin.disturbances.Wrench`) drawn as an arrow from that
  frame's origin on the arm following ``q``, along ``F``, of length ``|F| · s`` where ``s``
  [m/N] (:func:`wrench_scale`) is stated in the page's legend; the arrow is visible only
  at the frames where the force is non-zero (the force held from each sample time to the
  next, as the plant applies it). The moment, if any, is not drawn.
* **The desired frame** (``desired_frame/``): a triad (x red, y green, z blue, each
  :func:`axis_length` long) at the desired pose of the end effector: the caller's poses
  (a task-space reference) or the forward kinematics of ``q_des`` (which, for the
  built-in task-space laws, is the pose they are told to reach).

* **The surfaces** (``surfaces/``) of a run's scene (:mod:`twolink_pin.contact`): a bounded
  surface as its box (the face the arm touches is the box's top), an unbounded plane as a thin
  slab :data:`SURFACE_SPAN` × the motion's extent wide, centred where the motion is, behind the
  plane; translucent grey. The contact's force on the arm is drawn by the force arrow (with any
  external wrench: their sum), from the end effector.

The arrow and the triad are animated with the arm (meshcat tracks of ``position``, ``quaternion``, ``scale``
and ``visible``); their sizes follow the motion's extent ``E`` [m] so that they read the
same on a 0.5-m arm and on a 2-m one.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pinocchio as pin

from twolink_pin.contact.scene import Scene
from twolink_pin.disturbances import Wrench
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel

WRENCH_NODE = "wrench"
"""Node of the force arrow (children ``shaft`` and ``head``; the arrow is the node's +x)."""
DESIRED_FRAME_NODE = "desired_frame"
"""Node of the desired frame's triad (children ``x``, ``y``, ``z``)."""
SURFACES_NODE = "surfaces"
"""Node of the scene's surfaces (one child per surface, by name)."""
SURFACE_COLOR = 0x868E96
"""The surfaces' colour (0xRRGGBB), drawn with :data:`SURFACE_OPACITY`."""
SURFACE_OPACITY = 0.45
SURFACE_SPAN = 1.5
"""An unbounded plane is drawn this many times the motion's extent wide."""
WRENCH_COLOR = 0x7048E8
"""Force arrow (0xRRGGBB)."""
AXIS_COLORS = (0xE03131, 0x2F9E44, 0x1971C2)
"""Triad's x, y, z axes."""
WRENCH_LENGTH = 0.3
"""The largest force is drawn at most this fraction of the motion's extent long."""
AXIS_FRACTION = 0.12
"""A triad axis is about this fraction of the motion's extent long."""
HEAD = 0.2
"""Fraction of the arrow's length that is its head."""
_Y_TO_X = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
"""A rotation taking a meshcat cylinder's axis (local y) to x."""


def _nice(x: float) -> float:
    """The largest 1, 2 or 5 × 10^k not above ``x`` > 0."""
    exponent = math.floor(math.log10(x))
    for mantissa in (5.0, 2.0, 1.0):
        if mantissa * 10.0**exponent <= x * (1 + 1e-12):
            return mantissa * 10.0**exponent
    return 10.0 ** (exponent - 1) * 5.0


def wrench_scale(forces: np.ndarray, extent: float) -> float:
    """The arrow's scale ``s`` [m/N]: a round number such that the largest force in
    ``forces`` (shape (F, 3) [N]) is at most :data:`WRENCH_LENGTH` × ``extent`` [m] long."""
    peak = float(np.max(np.linalg.norm(forces, axis=1), initial=0.0))
    return _nice(WRENCH_LENGTH * extent / peak) if peak > 0 else 1.0


def axis_length(extent: float) -> float:
    """A triad axis's length [m]: a round number near :data:`AXIS_FRACTION` × ``extent``."""
    return _nice(AXIS_FRACTION * extent)


def frame_id(robot: RobotModel, frame: str | None) -> int:
    """The id of frame ``frame`` of ``robot`` (None: the end effector).

    Raises:
        InvalidParameterError: no such frame (the message lists some).
    """
    if frame is None:
        return int(robot.ee_frame_id)
    if not robot.model.existFrame(frame):
        names = [f.name for f in robot.model.frames][:12]
        raise InvalidParameterError(
            "wrench_frame", frame, f"a frame of {robot.name}, e.g. {', '.join(names)}"
        )
    return int(robot.model.getFrameId(frame))


def frame_poses(robot: RobotModel, q_frames: np.ndarray, fid: int) -> np.ndarray:
    """World pose of frame ``fid`` at each row of ``q_frames`` [rad], shape (F, 4, 4)."""
    data = robot.model.createData()
    out = np.empty((len(q_frames), 4, 4))
    for k, qk in enumerate(q_frames):
        pin.framesForwardKinematics(robot.model, data, qk)
        out[k] = data.oMf[fid].homogeneous
    return out


def _along_x(direction: np.ndarray) -> np.ndarray:
    """A rotation taking +x to the unit vector ``direction``."""
    x = direction / np.linalg.norm(direction)
    helper = np.array([0.0, 0.0, 1.0]) if abs(x[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    y = np.cross(helper, x)
    y /= np.linalg.norm(y)
    return np.column_stack([x, y, np.cross(x, y)])


def _cylinder(
    vis: Any,
    node: str,
    length: float,
    radius: float,
    offset: np.ndarray,
    rotation: np.ndarray,
    color: int,
    tip: bool = False,
) -> None:
    """A cylinder (a cone with ``tip``) of ``length`` along ``rotation``'s y, centred at ``offset``."""
    import meshcat.geometry as mg

    shape = (
        mg.Cylinder(length, radius, radiusTop=0.0, radiusBottom=radius)
        if tip
        else mg.Cylinder(length, radius)
    )
    vis[node].set_object(shape, mg.MeshPhongMaterial(color=color))
    vis[node].set_transform(pin.SE3(rotation, offset).homogeneous)


def add_wrench(
    vis: Any,
    animation: Any,
    frames: np.ndarray,
    keys: list[Any],
    poses: np.ndarray,
    forces: np.ndarray,
    extent: float,
) -> tuple[float, np.ndarray]:
    """Draw the force arrow: at frame ``k`` from ``poses[k]``'s origin along ``forces[k]`` [N].

    Args:
        frames: Frame numbers, shape (F,); ``keys`` the same as meshcat keys them.
        poses: World pose of the frame the force acts on, shape (F, 4, 4).
        forces: Force at each frame [N], world axes, shape (F, 3); zero: not acting.
        extent: The motion's extent [m] (sizes the arrow).

    Returns:
        ``(s, tips)``: the scale [m/N] and the arrow tips while it acts [m], shape (P, 3).
    """
    scale = wrench_scale(forces, extent)
    radius = 0.008 * extent
    _cylinder(
        vis, f"{WRENCH_NODE}/shaft", 1 - HEAD, radius, np.array([(1 - HEAD) / 2, 0, 0]), _Y_TO_X, WRENCH_COLOR
    )
    _cylinder(
        vis,
        f"{WRENCH_NODE}/head",
        HEAD,
        2.5 * radius,
        np.array([1 - HEAD / 2, 0, 0]),
        _Y_TO_X,
        WRENCH_COLOR,
        tip=True,
    )
    magnitude = np.linalg.norm(forces, axis=1)
    tips = []
    shown_before: bool | None = None
    for k, key in enumerate(keys):
        acting = bool(magnitude[k] > 0)
        with animation.at_frame(vis, key)[WRENCH_NODE] as frame_vis:
            rotation = _along_x(forces[k]) if acting else np.eye(3)
            frame_vis.set_transform(pin.SE3(rotation, poses[k, :3, 3]).homogeneous)
            frame_vis.set_property(
                "scale", "vector3", [float(magnitude[k] * scale) if acting else 1.0, 1.0, 1.0]
            )
            if acting != shown_before or k == len(keys) - 1:
                frame_vis.set_property("visible", "boolean", acting)
        shown_before = acting
        if acting:
            tips.append(poses[k, :3, 3] + forces[k] * scale)
    if not magnitude[0] > 0:
        vis[WRENCH_NODE].set_property("visible", False)
    return scale, np.array(tips).reshape(-1, 3)


def add_desired_frame(vis: Any, animation: Any, keys: list[Any], poses: np.ndarray, extent: float) -> float:
    """Draw the triad at ``poses[k]`` (world, shape (F, 4, 4)) at frame ``k``; its axis length [m]."""
    length = axis_length(extent)
    radius = 0.004 * extent
    rotations = (_Y_TO_X, np.eye(3), np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]))
    for axis, (name, rotation, color) in enumerate(zip("xyz", rotations, AXIS_COLORS)):
        offset = np.zeros(3)
        offset[axis] = length / 2
        _cylinder(vis, f"{DESIRED_FRAME_NODE}/{name}", length, radius, offset, rotation, color)
    vis[DESIRED_FRAME_NODE].set_transform(poses[0])
    for key, pose in zip(keys, poses):
        with animation.at_frame(vis, key)[DESIRED_FRAME_NODE] as frame_vis:
            frame_vis.set_transform(pose)
    return length


def add_surfaces(vis: Any, scene: Scene, extent: float, centre: np.ndarray) -> list[np.ndarray]:
    """Draw ``scene``'s surfaces (see the module docstring) around the motion of extent ``extent``
    [m] centred at ``centre`` [m]; returns the corners [m] of the bounded ones (the view frames them)."""
    import meshcat.geometry as mg

    material = mg.MeshPhongMaterial(color=SURFACE_COLOR, opacity=SURFACE_OPACITY, transparent=True)
    corners = []
    for surface in scene.surfaces:
        u, w = surface.axes()
        n = surface.unit_normal
        point = np.array(surface.point)
        size: tuple[float, ...]
        if surface.size is None:
            span = SURFACE_SPAN * extent
            size = (span, span, 0.01 * extent)
            point = centre - ((centre - point) @ n) * n  # the motion's centre, on the plane
        else:
            size = surface.size
        rotation = np.column_stack([u, w, n])
        middle = point - 0.5 * size[2] * n
        vis[f"{SURFACES_NODE}/{surface.name}"].set_object(mg.Box(list(size)), material)
        vis[f"{SURFACES_NODE}/{surface.name}"].set_transform(pin.SE3(rotation, middle).homogeneous)
        if surface.size is not None:
            signs = np.array([[a, b, c] for a in (-0.5, 0.5) for b in (-0.5, 0.5) for c in (-0.5, 0.5)])
            corners.append(middle + (signs * np.array(size)) @ rotation.T)
    return corners


def run_overlays(
    wrench: Wrench | None,
    t: np.ndarray,
    scene: Scene | None = None,
    contact: np.ndarray | None = None,
) -> dict[str, Any]:
    """The keyword arguments of :func:`~twolink_pin.visualization.write_html` (and
    ``scene_page``, ``serve``) that draw a run's overlays: the desired end-effector frame
    (forward kinematics of ``q_des``) always, the plant's external force (``wrench``:
    :attr:`~twolink_pin.run_spec.PlantOptions.wrench`, None for none) at the sample times
    ``t`` [s] where it acts, zero elsewhere, plus, with a ``scene``, its surfaces and the
    contact's force on the arm (``contact``: the run's
    :attr:`~twolink_pin.simulation.SimulationResult.wrench`, the wrench the end effector applied
    to the surfaces, (K, 6); its force reversed). One definition for ``animate`` and the report."""
    out: dict[str, Any] = {"desired_frame": True}
    forces = None
    if wrench is not None:
        acting = np.array([wrench.active(float(tk)) for tk in np.asarray(t, dtype=float)])
        forces = np.where(acting[:, None], np.asarray(wrench.force[:3], dtype=float), 0.0)
        out["wrench_frame"] = wrench.frame
    if scene is not None:
        out["surfaces"] = scene
        if contact is not None:
            on_arm = -np.asarray(contact, dtype=float)[:, :3]
            forces = on_arm if forces is None else forces + on_arm
    if forces is not None:
        out["wrench"] = forces
    return out
