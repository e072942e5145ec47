"""The 3-D scene of a run, built from the robot's Pinocchio geometry, as meshcat commands.

What the scene holds (node paths below ``/meshcat``):

* the arm following ``q``: the URDF's visual geometry (:func:`visual_model`), one node per
  geometry object under ``arm/visuals/<object name>``, moved by the animation;
* its translucent "ghost" following ``q_des`` (``ghost/...``, :func:`ghost_visual_model`);
* the end-effector trail (``trail/<k>``: pieces that appear as the arm draws them), the
  desired end-effector path (``desired_path``) and the via-point markers (``via/<i>``);
* when asked, the external force as an arrow (``wrench``) and the desired frame as a triad
  (``desired_frame``): :mod:`.overlays`;
* a floor grid sized to the motion (``grid``, :func:`.camera.floor_grid`) and a camera framing the
  whole motion (:func:`.camera.frame_camera`): from above for planar motion, obliquely otherwise.

Meshes are drawn from the triangles Pinocchio loaded (``coal`` BVH models: mesh scale,
units and up axis already applied by the loader), so the page shows exactly the geometry
Pinocchio uses, in one compact binary block per mesh; a URDF's primitives (box, cylinder, sphere)
are made as Pinocchio's ``MeshcatVisualizer.loadPrimitive`` makes them (:mod:`._drawables`,
without importing Pinocchio's visualizers), other shapes go through that loader.

:func:`scene_commands` records every command in-process (no server, no browser): a
window object given to ``meshcat.Visualizer(window=...)`` keeps the lowered commands that
:mod:`.html` packs into a file and :mod:`.server` sends to a live viewer.

Frames: three.js draws our ``(x, y, z)`` as ``(x, z, −y)`` (meshcat rotates its scene
root so that z is up). To centre the view on the motion, the scene root is also
translated by ``−c`` (``c`` the centre of the framed motion [m]) and the camera
rig (:data:`CAMERA_TARGET_NODE`) by ``+c``: meshcat's orbit controls always look at the
world origin, which is then ``c``. Read positions in our frame from three.js with
``viewer.scene.worldToLocal(v)``.
"""

from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError, InvalidURDFError
from twolink_pin.kinematics import joint_positions
from twolink_pin.model import RobotModel
from twolink_pin.visualization._drawables import Drawable, drawables_of
from twolink_pin.visualization._meshcat_bridge import import_meshcat
from twolink_pin.visualization.camera import GRID_COLORS, floor_grid, frame_camera, threejs_vector
from twolink_pin.visualization.motion import Motion

ARM_NODE = "arm"
"""Root node of the arm following ``q`` (below ``/meshcat``)."""
GHOST_NODE = "ghost"
"""Root node of the translucent arm following ``q_des``."""
TRAIL_NODE = "trail"
"""Parent node of the end-effector trail's pieces."""
DESIRED_PATH_NODE = "desired_path"
"""Node of the desired end-effector path."""
VIA_NODE = "via"
"""Parent node of the via-point markers."""
GRID_NODE = "grid"
"""Node of the floor grid (in the plane z = 0, under the motion)."""
CAMERA_NODE = "/Cameras/default/rotated/<object>"
"""meshcat's default camera; its ``position`` is in three.js axes ``(x, z, −y)`` [m],
relative to :data:`CAMERA_TARGET_NODE`."""
CAMERA_TARGET_NODE = "/Cameras/default"
"""The camera rig, placed at the point the camera looks at and orbits (our axes) [m]."""
SCENE_ROOT = "/"
"""meshcat's scene root: ``(x, y, z) -> (x, z, −y)``, shifted so the view centre is the world origin."""

GHOST_ALPHA = 0.3
"""Opacity of the ghost arm."""
GHOST_RGB = (0.17, 0.54, 0.24)
"""Colour of the ghost arm (RGB in [0, 1]): the desired path's green."""
TRAIL_COLOR = 0xC2255C
"""End-effector trail (0xRRGGBB)."""
DESIRED_PATH_COLOR = 0x2B8A3E
"""Desired end-effector path."""
VIA_COLOR = 0xE03131
"""Via-point markers."""
VIA_RADIUS = 0.012
"""Radius of a via-point marker [m]."""
PATH_LIFT = 0.002
"""Height of the desired path above the x-y plane (and its grid) [m]; the trail is twice as high."""
MAX_TRAIL_PIECES = 120
"""The trail is drawn in at most this many pieces, each appearing when the arm has drawn it."""
GHOST_MATERIAL = {"polygonOffset": True, "polygonOffsetFactor": 1.0, "polygonOffsetUnits": 4.0}
"""three.js material settings added to the ghost's: pushed back in depth, the ghost loses
where it coincides with the arm (no z-fighting stripes) and shows where the two differ."""
BACKGROUND = ((0.98, 0.98, 0.98), (0.82, 0.85, 0.88))
"""Top and bottom colours of the background gradient (RGB in [0, 1])."""

FRAMING_FRAMES = 60
"""At most this many frames are sampled to bound the geometry's sweep for the camera."""

# ----------------------------------------------------------------------------- geometry


def _search_dirs(robot: RobotModel) -> list[Path]:
    """Folders for ``package://`` and relative mesh paths: the profile's, then the URDF's
    folder and its parents up to 4 levels (``…/robots/<name>_description/urdf/``)."""
    urdf = Path(robot.urdf_path).resolve()
    dirs: list[Path] = []
    for folder in (*robot.profile.package_dirs, *list(urdf.parents)[:5]):
        folder = Path(folder)
        if folder not in dirs:
            dirs.append(folder)
    return dirs


def _environment_dirs() -> list[Path]:
    """Folders Pinocchio also searches: ``ROS_PACKAGE_PATH`` and ``AMENT_PREFIX_PATH``/share."""
    dirs = [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    dirs += [Path(p) / "share" for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return dirs


def _mesh_candidates(filename: str, dirs: Sequence[Path]) -> tuple[str, list[Path]]:
    """How a URDF mesh path is looked up: the path searched for, and the files tried."""
    if filename.startswith("package://"):
        relative = filename[len("package://") :]
        return relative, [d / relative for d in dirs]
    if filename.startswith("file://"):
        return filename[len("file://") :], [Path(filename[len("file://") :])]
    if os.path.isabs(filename):
        return filename, [Path(filename)]
    return filename, [d / filename for d in dirs]


def _visual_error(robot: RobotModel, dirs: Sequence[Path], exc: Exception) -> InvalidURDFError:
    """An :class:`InvalidURDFError` for Pinocchio's failure to build the visual geometry,
    naming the first mesh that cannot be found and the folders searched."""
    path = str(robot.urdf_path)
    searched = [*dirs, *_environment_dirs()]
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError):
        root = None
    for link in [] if root is None else root.iter("link"):
        for visual in link.iter("visual"):
            mesh = visual.find("geometry/mesh")
            if mesh is None or not mesh.get("filename"):
                continue
            filename = str(mesh.get("filename"))
            looked_for, candidates = _mesh_candidates(filename, searched)
            if not any(c.is_file() for c in candidates):
                where = (
                    f"looked for {looked_for} in {', '.join(map(str, searched))}"
                    if len(candidates) > 1 or not os.path.isabs(looked_for)
                    else f"no file {looked_for}"
                )
                return InvalidURDFError(
                    path,
                    f"link '{link.get('name')}' <visual> <mesh filename='{filename}'>",
                    f"mesh file not found: {where}",
                )
    detail = str(exc).strip()
    match = re.search(r"message: (.*)", detail)
    detail = (match.group(1) if match else detail.splitlines()[0] if detail else type(exc).__name__).strip()
    return InvalidURDFError(path, "<visual>", f"Pinocchio could not build the visual geometry: {detail}")


def visual_model(robot: RobotModel, kind: pin.GeometryType = pin.GeometryType.VISUAL) -> pin.GeometryModel:
    """The URDF's visual geometry of ``robot`` (``kind``: or its collision geometry), meshes
    loaded, attached to ``robot.model``'s joints.

    Mesh paths (``package://name/...`` or relative) are looked up in
    ``robot.profile.package_dirs``, then in the URDF's folder and its parents up to 4
    levels, so the meshes of a description package laid out as
    ``<dir>/<name>_description/{urdf,meshes}`` (example-robot-data) are found.

    Raises:
        InvalidURDFError: a mesh cannot be found (the error names the link, the mesh file
            and the folders searched) or cannot be loaded.
    """
    dirs = _search_dirs(robot)
    try:
        return pin.buildGeomFromUrdf(
            robot.model, str(robot.urdf_path), kind, package_dirs=[str(d) for d in dirs]
        )
    except (ValueError, RuntimeError) as exc:
        raise _visual_error(robot, dirs, exc) from exc


def ghost_visual_model(
    visual: pin.GeometryModel, alpha: float = GHOST_ALPHA, rgb: Sequence[float] | None = None
) -> pin.GeometryModel:
    """A copy of ``visual`` whose objects are translucent: the "ghost" of the arm.

    Args:
        visual: Visual geometry (left unchanged).
        alpha: Opacity of every object, in (0, 1].
        rgb: One colour (RGB in [0, 1]) for every object; ``None`` keeps each object's.

    Raises:
        InvalidParameterError: ``alpha`` outside (0, 1] or ``rgb`` not three values in [0, 1].
    """
    if not (isinstance(alpha, (int, float)) and 0 < alpha <= 1):
        raise InvalidParameterError("alpha", alpha, "an opacity in (0, 1]")
    if rgb is not None and (len(rgb) != 3 or not all(0 <= c <= 1 for c in rgb)):
        raise InvalidParameterError("rgb", rgb, "three values (r, g, b) in [0, 1]")
    ghost = visual.copy()
    for obj in ghost.geometryObjects:
        color = np.array(obj.meshColor, dtype=float)
        if rgb is not None:
            color[:3] = rgb
        color[3] = alpha
        obj.meshColor = color
    return ghost


def _placements(
    model: pin.Model, geom: pin.GeometryModel, drawables: Sequence[Drawable | None], q_frames: np.ndarray
) -> np.ndarray:
    """Transform of each drawn object at each frame (``meshScale`` where the transform
    carries it), shape (F, n_objects, 4, 4)."""
    data, gdata = model.createData(), pin.GeometryData(geom)
    scales = np.array(
        [
            np.append(np.asarray(o.meshScale, dtype=float), 1.0)
            if d is not None and d.scaled_by_transform
            else np.ones(4)
            for o, d in zip(geom.geometryObjects, drawables)
        ]
    ).reshape(-1, 4)
    out = np.empty((len(q_frames), len(geom.geometryObjects), 4, 4))
    for k, qk in enumerate(q_frames):
        pin.forwardKinematics(model, data, qk)
        pin.updateGeometryPlacements(model, data, geom, gdata)
        for i in range(len(geom.geometryObjects)):
            out[k, i] = gdata.oMg[i].homogeneous * scales[i]
    return out


def _key(frame: float) -> float | int:
    """A frame number as meshcat keys it (an int when whole: smaller once packed)."""
    return int(frame) if float(frame).is_integer() else float(frame)


def _material(rgba: np.ndarray, ghost: bool) -> Any:
    import meshcat.geometry as mg

    color = int.from_bytes(bytes(round(float(np.clip(c, 0, 1)) * 255) for c in rgba[:3]), "big")
    alpha = float(rgba[3])
    extra = GHOST_MATERIAL if ghost else {}
    return mg.MeshPhongMaterial(color=color, transparent=alpha < 1, opacity=alpha, **extra)


def _add_arm(
    vis: Any,
    animation: Any,
    geom: pin.GeometryModel,
    drawables: Sequence[Drawable | None],
    placements: np.ndarray,
    root: str,
    motion: Motion,
    ghost: bool,
) -> None:
    """Load each drawable object of ``geom`` under ``<root>/visuals/<name>``, animate the moving ones."""
    import meshcat.geometry as mg

    for i, (obj, drawable) in enumerate(zip(geom.geometryObjects, drawables)):
        if drawable is None:
            continue
        node = f"{root}/visuals/{obj.name}"
        shape = drawable.make()
        if isinstance(shape, mg.Object):
            vis[node].set_object(shape)
        else:
            vis[node].set_object(shape, _material(np.asarray(obj.meshColor, dtype=float), ghost))
        vis[node].set_transform(placements[0, i])
        if obj.parentJoint == 0:
            continue  # fixed to the world: no track
        for frame, transform in zip(motion.frames, placements[:, i]):
            with animation.at_frame(vis, _key(frame))[node] as frame_vis:
                frame_vis.set_transform(transform)


def _line(points: np.ndarray, color: int, lift: float) -> Any:
    import meshcat.geometry as mg

    lifted = np.array(points, dtype=np.float32)
    lifted[:, 2] += lift
    return mg.Line(mg.PointsGeometry(lifted.T), mg.LineBasicMaterial(color=color, linewidth=2.0))


def _add_trail(vis: Any, animation: Any, motion: Motion, points: np.ndarray) -> None:
    """The end-effector trail: pieces that appear (``visible`` tracks) once the arm drew them."""
    n_frames = len(motion.frames)
    per_piece = max(1, math.ceil((n_frames - 1) / MAX_TRAIL_PIECES))
    last = _key(motion.frames[-1])
    for k, start in enumerate(range(0, n_frames - 1, per_piece)):
        end = min(start + per_piece, n_frames - 1)
        node = f"{TRAIL_NODE}/{k:03d}"
        vis[node].set_object(_line(points[start : end + 1], TRAIL_COLOR, 2 * PATH_LIFT))
        for frame, shown in ((0, False), (_key(motion.frames[end]), True), (last, True)):
            with animation.at_frame(vis, frame)[node] as frame_vis:
                frame_vis.set_property("visible", "boolean", shown)


# ----------------------------------------------------------------------------- commands


class _RecorderWindow:
    """Stands in for meshcat's ``ViewerWindow``: keeps every command instead of sending it.

    ``meshcat.Visualizer(window=...)`` sends each command through ``window.send``; here the
    lowered command (the dict meshcat packs with msgpack) is appended to :attr:`commands`.
    """

    def __init__(self) -> None:
        self.commands: list[dict[str, Any]] = []

    def send(self, command: Any) -> None:
        self.commands.append(command.lower())


def _sample(frames: np.ndarray, n: int) -> np.ndarray:
    """At most ``n`` indices spread over ``frames`` (first and last included)."""
    return np.unique(np.linspace(0, len(frames) - 1, min(n, len(frames))).round().astype(int))


class Scene(NamedTuple):
    """A recorded scene."""

    commands: list[dict[str, Any]]
    """Every meshcat command (lowered dicts, ready for msgpack), the animation last."""
    grid_spacing: float
    """Spacing of the floor grid's lines [m]."""
    wrench_scale: float | None = None
    """Length of the force arrow per newton [m/N] (None: no wrench drawn)."""
    axis_length: float | None = None
    """Length of the desired frame's axes [m] (None: no triad drawn)."""


def scene_commands(robot: RobotModel, motion: Motion, *, loop: bool = False, play: bool = True) -> Scene:
    """Record every meshcat command of the scene of ``motion``.

    Args:
        robot: The arm.
        motion: The frames to animate (:func:`~twolink_pin.visualization.motion.prepare_motion`).
        loop: Repeat the animation forever.
        play: Start playing as soon as the viewer has the scene.

    Raises:
        InvalidURDFError: the robot's visual geometry cannot be built (:func:`visual_model`).
    """
    meshcat = import_meshcat()
    import meshcat.geometry as mg
    from meshcat.animation import Animation

    window = _RecorderWindow()
    vis = meshcat.Visualizer(window=window)
    animation = Animation(default_framerate=motion.fps)

    vis["/Background"].set_property("top_color", list(BACKGROUND[0]))
    vis["/Background"].set_property("bottom_color", list(BACKGROUND[1]))
    vis["/Axes"].set_property("visible", False)
    vis["/Grid"].set_property("visible", False)  # replaced by one sized to the motion (floor_grid)

    geom = visual_model(robot)
    drawables = drawables_of(robot, geom)
    arms = [(ARM_NODE, geom, motion.q, False)]
    if motion.q_des is not None:
        arms.append((GHOST_NODE, ghost_visual_model(geom, GHOST_ALPHA, GHOST_RGB), motion.q_des, True))
    framing: list[np.ndarray] = []
    joints: list[np.ndarray] = []
    desired_path: np.ndarray | None = None
    for root, model_geom, q_frames, ghost in arms:
        placements = _placements(robot.model, model_geom, drawables, q_frames)
        _add_arm(vis, animation, model_geom, drawables, placements, root, motion, ghost)
        positions = joint_positions(robot, q_frames)  # (F, njoints, 3), end effector last
        joints.append(positions.reshape(-1, 3))
        sampled = placements[_sample(motion.frames, FRAMING_FRAMES)]
        for i, drawable in enumerate(drawables):
            if drawable is not None and len(drawable.corners):
                rotations, translations = sampled[:, i, :3, :3], sampled[:, i, :3, 3]
                framing.append(
                    (translations[:, None, :] + drawable.corners @ rotations.transpose(0, 2, 1)).reshape(
                        -1, 3
                    )
                )
        if ghost:
            desired_path = positions[:, -1]
            vis[DESIRED_PATH_NODE].set_object(_line(positions[:, -1], DESIRED_PATH_COLOR, PATH_LIFT))
        else:
            _add_trail(vis, animation, motion, positions[:, -1])
    if motion.via_points is not None:
        marker = mg.Sphere(VIA_RADIUS)
        for i, point in enumerate(motion.via_points):
            node = vis[f"{VIA_NODE}/{i}"]
            node.set_object(marker, mg.MeshPhongMaterial(color=VIA_COLOR))
            node.set_transform(pin.SE3(np.eye(3), point).homogeneous)
        framing.append(motion.via_points)
    joint_points = np.vstack(joints)
    wrench_scale, axis_length = _add_overlays(vis, animation, robot, motion, joint_points, framing)
    in_view = np.vstack([joint_points, *framing])
    centre, camera = frame_camera(joint_points, in_view, desired_path)
    spacing, (minor, major) = floor_grid(in_view, centre, camera)
    for name, segments, color in (("minor", minor, GRID_COLORS[0]), ("major", major, GRID_COLORS[1])):
        if len(segments):
            material = mg.LineBasicMaterial(color=color)
            vis[f"{GRID_NODE}/{name}"].set_object(mg.LineSegments(mg.PointsGeometry(segments.T), material))
    root_transform = np.eye(4)
    root_transform[:3, :3] = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]  # meshcat's z-up rotation
    root_transform[:3, 3] = root_transform[:3, :3] @ -centre
    vis[SCENE_ROOT].set_transform(root_transform)
    vis[CAMERA_TARGET_NODE].set_transform(pin.SE3(np.eye(3), centre).homogeneous)
    vis[CAMERA_NODE].set_property("position", threejs_vector(camera - centre))
    vis.set_animation(animation, play=play, repetitions=math.inf if loop else 1)
    return Scene(window.commands, spacing, wrench_scale, axis_length)


def _add_overlays(
    vis: Any,
    animation: Any,
    robot: RobotModel,
    motion: Motion,
    joints: np.ndarray,
    framing: list[np.ndarray],
) -> tuple[float | None, float | None]:
    """The force arrow, the desired frame's triad and the surfaces (:mod:`.overlays`), if the
    motion has them: the arrow's scale [m/N] and the axis length [m]; the arrow's tips and the
    bounded surfaces' corners join ``framing``."""
    from twolink_pin.visualization import overlays

    extent = float(max(np.max(np.ptp(joints, axis=0)), 1e-3))  # the motion's size [m]
    keys = [_key(frame) for frame in motion.frames]
    scale = length = None
    if motion.wrench is not None:
        poses = overlays.frame_poses(robot, motion.q, overlays.frame_id(robot, motion.wrench_frame))
        scale, tips = overlays.add_wrench(vis, animation, motion.frames, keys, poses, motion.wrench, extent)
        framing.append(tips)
    if motion.desired_poses is not None:
        length = overlays.add_desired_frame(vis, animation, keys, motion.desired_poses, extent)
    if motion.surfaces is not None:
        framing.extend(overlays.add_surfaces(vis, motion.surfaces, extent, joints.mean(axis=0)))
    return scale, length
