"""3-D view of an arm's motion in the browser, with meshcat.

Two ways to look at a run, both built from the same scene:

* :func:`write_html` writes one self-contained HTML file (three.js, meshcat's viewer and
  the whole animation inlined; it opens from ``file://`` and makes no network request);
* :func:`serve` starts a meshcat server on the loopback interface and plays the motion
  in the browser in real time (:class:`LiveViewer`, a context manager).

The scene: the arm from the URDF's visual geometry (node ``/meshcat/arm``), a translucent
"ghost" arm following the desired motion (``/meshcat/ghost``, see
:func:`ghost_visual_model`), the end-effector trail growing as the arm moves
(``/meshcat/trail/<k>``), the desired end-effector path (``/meshcat/desired_path``),
markers at the via points (``/meshcat/via/<i>``) and a camera looking down on the x-y
plane. The motion is a meshcat ``Animation``: the viewer's *Open Controls → Animations*
panel plays, pauses and scrubs it; from JavaScript, ``viewer.animator.seek(t)``.

This module only receives arrays (times [s] and joint angles [rad]); it imports nothing
to its right in the package's data flow. It is the only module that imports meshcat
(lazily, inside the functions). Three.js draws our ``(x, y, z)`` as ``(x, z, −y)`` in its
own world frame (meshcat rotates its scene so that z is up).
"""

from __future__ import annotations

import base64
import contextlib
import logging
import math
import os
import sys
import threading
import uuid
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError, OutputError, TwolinkPinError
from twolink_pin.model import RobotModel

_log = logging.getLogger(__name__)

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
CAMERA_NODE = "/Cameras/default/rotated/<object>"
"""meshcat's default camera; its ``position`` is in three.js world axes ``(x, z, −y)`` [m]."""

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


# ----------------------------------------------------------------------------- validation


@dataclass(frozen=True)
class _Motion:
    """A validated motion, resampled to the animation's frames."""

    frames: np.ndarray
    """Frame numbers, shape (F,): frame ``k`` is shown at ``k / fps`` s of animation time."""
    fps: float
    """Frames per second of motion time [1/s]."""
    q: np.ndarray
    """Joint angles at the frames [rad], shape (F, nq)."""
    q_des: np.ndarray | None
    """Desired joint angles at the frames [rad], shape (F, nq), or ``None``."""
    via_xy: np.ndarray | None
    """Via points [m], shape (M, 2), or ``None``."""


def _finite_array(name: str, value: npt.ArrayLike, unit: str) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidParameterError(name, value, f"an array of numbers {unit}") from exc
    bad = np.argwhere(~np.isfinite(array))
    if len(bad):
        index = tuple(int(i) for i in bad[0])
        label = f"{name}[{', '.join(map(str, index))}]" if index else name
        raise InvalidParameterError(label, float(array[index]), f"finite values {unit}")
    return array


def _check_times(t: npt.ArrayLike) -> np.ndarray:
    t_arr = _finite_array("t", t, "[s]")
    if t_arr.ndim != 1 or len(t_arr) < 2:
        raise InvalidParameterError("t.shape", t_arr.shape, "(N,) with N >= 2 sample times [s]")
    steps = np.diff(t_arr)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0)) + 1
        raise InvalidParameterError(
            f"t[{i}]",
            float(t_arr[i]),
            f"a time > t[{i - 1}] = {t_arr[i - 1]:g} s (strictly increasing times)",
        )
    return t_arr


def _check_q(name: str, q: npt.ArrayLike, n: int, nq: int) -> np.ndarray:
    q_arr = _finite_array(name, q, "[rad]")
    if q_arr.shape != (n, nq):
        raise InvalidParameterError(f"{name}.shape", q_arr.shape, f"({n}, {nq}) = (len(t), robot.nq)")
    return q_arr


def _check_fps(fps: float) -> float:
    if not (isinstance(fps, (int, float)) and math.isfinite(fps) and fps > 0):
        raise InvalidParameterError("fps", fps, "a finite frame rate > 0 [1/s]")
    return float(fps)


def _check_via(via_xy: npt.ArrayLike | None) -> np.ndarray | None:
    if via_xy is None:
        return None
    xy = _finite_array("via_xy", via_xy, "[m]")
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise InvalidParameterError("via_xy.shape", xy.shape, "(M, 2): via points (x, y) [m]")
    return xy


def _frame_numbers(t: np.ndarray, fps: float) -> np.ndarray:
    """Frames ``0, 1, 2, …`` every ``1/fps`` s from ``t[0]``, plus a last one at ``t[-1]``."""
    span = float(t[-1] - t[0]) * fps
    whole = math.floor(span + 1e-9)
    frames = np.arange(whole + 1, dtype=float)
    if span - whole > 1e-6:
        frames = np.append(frames, span)
    return frames


def _resample(t: np.ndarray, q: np.ndarray, times: np.ndarray) -> np.ndarray:
    return np.column_stack([np.interp(times, t, q[:, j]) for j in range(q.shape[1])])


def _prepare(
    robot: RobotModel,
    t: npt.ArrayLike,
    q: npt.ArrayLike,
    q_des: npt.ArrayLike | None,
    via_xy: npt.ArrayLike | None,
    fps: float,
) -> _Motion:
    t_arr = _check_times(t)
    q_arr = _check_q("q", q, len(t_arr), robot.nq)
    q_des_arr = None if q_des is None else _check_q("q_des", q_des, len(t_arr), robot.nq)
    fps = _check_fps(fps)
    via = _check_via(via_xy)
    frames = _frame_numbers(t_arr, fps)
    times = t_arr[0] + frames / fps
    times[-1] = min(times[-1], t_arr[-1])  # rounding
    return _Motion(
        frames=frames,
        fps=fps,
        q=_resample(t_arr, q_arr, times),
        q_des=None if q_des_arr is None else _resample(t_arr, q_des_arr, times),
        via_xy=via,
    )


# ----------------------------------------------------------------------------- scene


def visual_model(robot: RobotModel) -> pin.GeometryModel:
    """The URDF's visual geometry of ``robot``, attached to the joints of ``robot.model``."""
    return pin.buildGeomFromUrdf(robot.model, str(robot.urdf_path), pin.GeometryType.VISUAL)


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


def _import_meshcat() -> Any:
    """``import meshcat`` (it imports ``zmq.eventloop.ioloop``, which pyzmq >= 17 flags as deprecated)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "zmq.eventloop.ioloop is deprecated", DeprecationWarning)
        import meshcat
        import meshcat.servers.zmqserver
    return meshcat


class _RecorderWindow:
    """Stands in for meshcat's ``ViewerWindow``: keeps every command instead of sending it.

    ``meshcat.Visualizer(window=...)`` sends each command through ``window.send``; here the
    lowered command (the dict meshcat packs with msgpack) is appended to :attr:`commands`.
    """

    def __init__(self) -> None:
        self.commands: list[dict[str, Any]] = []

    def send(self, command: Any) -> None:
        self.commands.append(command.lower())


def _placements(
    model: pin.Model, geom: pin.GeometryModel, q_frames: np.ndarray
) -> dict[str, list[np.ndarray]]:
    """Homogeneous transform (scale included) of each visual object at each frame."""
    data, gdata = model.createData(), pin.GeometryData(geom)
    out: dict[str, list[np.ndarray]] = {obj.name: [] for obj in geom.geometryObjects}
    for qk in q_frames:
        pin.forwardKinematics(model, data, qk)
        pin.updateGeometryPlacements(model, data, geom, gdata)
        for i, obj in enumerate(geom.geometryObjects):
            scale = np.diag(np.append(np.asarray(obj.meshScale, dtype=float), 1.0))
            out[obj.name].append(gdata.oMg[i].homogeneous @ scale)
    return out


def _ee_positions(robot: RobotModel, q_frames: np.ndarray) -> np.ndarray:
    """End-effector position at each frame [m], shape (F, 3)."""
    data = robot.create_data()
    points = np.empty((len(q_frames), 3))
    for k, qk in enumerate(q_frames):
        pin.framesForwardKinematics(robot.model, data, qk)
        points[k] = data.oMf[robot.ee_frame_id].translation
    return points


def _line(points: np.ndarray, color: int, lift: float) -> Any:
    import meshcat.geometry as mg

    lifted = np.array(points, dtype=np.float32)
    lifted[:, 2] += lift
    return mg.Line(mg.PointsGeometry(lifted.T), mg.LineBasicMaterial(color=color, linewidth=2.0))


def _add_arm(
    vis: Any,
    animation: Any,
    robot: RobotModel,
    geom: pin.GeometryModel,
    root: str,
    motion: _Motion,
    q_frames: np.ndarray,
) -> None:
    """Load ``geom`` under ``root`` with pinocchio's MeshcatVisualizer, animate its moving objects."""
    from pinocchio.visualize import MeshcatVisualizer

    viz = MeshcatVisualizer(robot.model, None, geom)
    viz.initViewer(viewer=vis)
    viz.loadViewerModel(rootNodeName=root)
    placements = _placements(robot.model, geom, q_frames)
    for obj in geom.geometryObjects:
        node = viz.getViewerNodeName(obj, pin.GeometryType.VISUAL)
        transforms = placements[obj.name]
        vis[node].set_transform(transforms[0])
        if obj.parentJoint == 0:
            continue  # fixed to the world: no track
        for frame, transform in zip(motion.frames, transforms):
            with animation.at_frame(vis, _key(frame))[node] as frame_vis:
                frame_vis.set_transform(transform)


def _key(frame: float) -> float | int:
    """A frame number as meshcat keys it (an int when whole: smaller once packed)."""
    return int(frame) if float(frame).is_integer() else float(frame)


def _add_trail(vis: Any, animation: Any, motion: _Motion, points: np.ndarray) -> None:
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


def _joint_positions(robot: RobotModel, q_frames: np.ndarray) -> np.ndarray:
    """Origins of every joint and of the end-effector frame at each frame [m], shape (F·(njoints+1), 3)."""
    data = robot.create_data()
    points: list[np.ndarray] = []
    for qk in q_frames:
        pin.framesForwardKinematics(robot.model, data, qk)
        points.extend(m.translation.copy() for m in data.oMi)
        points.append(data.oMf[robot.ee_frame_id].translation.copy())
    return np.array(points)


CAMERA_FOV = 75.0
"""Vertical field of view of meshcat's default camera [deg]."""
CAMERA_ASPECT = 1.6
"""Window width / height the camera is framed for (e.g. 800 × 500 px)."""
CAMERA_TILT = 0.05
"""Camera offset towards −y per metre of height: nearly straight down, yet not degenerate
for the orbit controls, and every grid line stays in front of the camera."""


def _camera_position(points: np.ndarray) -> list[float]:
    """Camera above the base framing ``points`` [m] (shape (P, 3)), in three.js axes ``(x, z, −y)``.

    meshcat's orbit controls always look at the world origin (the arm's base), so the
    camera is placed above it, high enough that the base-centred box holding every point
    (plus 5 cm for the links' width) fits the view.
    """
    half = np.max(np.abs(points[:, :2]), axis=0) + 0.05
    tan_half = math.tan(math.radians(CAMERA_FOV / 2))
    height = max(1.1 * half[1] / tan_half, 1.1 * half[0] / (tan_half * CAMERA_ASPECT), 0.2)
    return [0.0, float(height), float(CAMERA_TILT * height)]


def _scene_commands(
    robot: RobotModel, motion: _Motion, *, loop: bool = False, play: bool = True
) -> list[dict[str, Any]]:
    """Every meshcat command of the scene (lowered dicts), the animation last."""
    meshcat = _import_meshcat()
    import meshcat.geometry as mg
    from meshcat.animation import Animation

    window = _RecorderWindow()
    vis = meshcat.Visualizer(window=window)
    animation = Animation(default_framerate=motion.fps)

    vis["/Background"].set_property("top_color", list(BACKGROUND[0]))
    vis["/Background"].set_property("bottom_color", list(BACKGROUND[1]))
    vis["/Axes"].set_property("visible", False)  # the grid (0.5 m) is reference enough

    geom = visual_model(robot)
    _add_arm(vis, animation, robot, geom, ARM_NODE, motion, motion.q)
    if motion.q_des is not None:
        first = len(window.commands)
        _add_arm(
            vis,
            animation,
            robot,
            ghost_visual_model(geom, GHOST_ALPHA, GHOST_RGB),
            GHOST_NODE,
            motion,
            motion.q_des,
        )
        for command in window.commands[first:]:
            if command["type"] == "set_object":
                for material in command["object"].get("materials", []):
                    material.update(GHOST_MATERIAL)
        vis[DESIRED_PATH_NODE].set_object(
            _line(_ee_positions(robot, motion.q_des), DESIRED_PATH_COLOR, PATH_LIFT)
        )
    _add_trail(vis, animation, motion, _ee_positions(robot, motion.q))
    if motion.via_xy is not None:
        marker = mg.Sphere(VIA_RADIUS)
        for i, (x, y) in enumerate(motion.via_xy):
            node = vis[f"{VIA_NODE}/{i}"]
            node.set_object(marker, mg.MeshPhongMaterial(color=VIA_COLOR))
            node.set_transform(pin.SE3(np.eye(3), np.array([x, y, 0.0])).homogeneous)
    shown = [motion.q] if motion.q_des is None else [motion.q, motion.q_des]
    points = np.vstack([_joint_positions(robot, qs) for qs in shown])
    if motion.via_xy is not None:
        points = np.vstack([points, np.column_stack([motion.via_xy, np.zeros(len(motion.via_xy))])])
    vis[CAMERA_NODE].set_property("position", _camera_position(points))
    vis.set_animation(animation, play=play, repetitions=math.inf if loop else 1)
    return window.commands


def _pack(command: dict[str, Any]) -> bytes:
    """msgpack bytes of a command, floats in single precision (~0.1 µm at 1 m; half the size)."""
    import umsgpack

    return bytes(umsgpack.packb(command, force_float_precision="single"))


# ----------------------------------------------------------------------------- HTML

_HTML = """<!DOCTYPE html>
<html>
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body {{ margin: 0; font: 13px sans-serif; }}
#meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
#legend {{ position: absolute; left: 8px; bottom: 8px; padding: 4px 8px; background: rgba(255,255,255,0.8);
  border-radius: 4px; color: #222; pointer-events: none; }}
#legend span {{ display: inline-block; width: 14px; height: 3px; margin: 0 4px 3px 9px;
  vertical-align: middle; }}
</style>
</head>
<body>
<div id="meshcat-pane"></div>
<div id="legend">{legend}</div>
<script>
{viewer_js}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
(function () {{
  var commands = [
{commands}
  ];
  for (var i = 0; i < commands.length; i++) {{
    var text = atob(commands[i]);
    var bytes = new Uint8Array(text.length);
    for (var j = 0; j < text.length; j++) {{ bytes[j] = text.charCodeAt(j); }}
    viewer.handle_command_bytearray(bytes);
  }}
}})();
window.sceneLoaded = true;
</script>
<script id="embedded-json"></script>
</body>
</html>
"""


def _legend(has_ghost: bool, has_via: bool) -> str:
    """The HTML legend under the scene: what each colour is, and where the player is."""
    ghost = int.from_bytes(bytes(round(c * 255) for c in GHOST_RGB), "big")  # 0xRRGGBB
    items: list[tuple[int | None, str]] = [(None, "arm (q)")]
    if has_ghost:
        items.append((ghost, "ghost (q_des)"))
    items.append((TRAIL_COLOR, "end-effector trail"))
    if has_ghost:
        items.append((DESIRED_PATH_COLOR, "desired path"))
    if has_via:
        items.append((VIA_COLOR, "via points"))
    html = "".join(
        text if color is None else f'<span style="background:#{color:06x}"></span>{text}'
        for color, text in items
    )
    return html + " &nbsp;·&nbsp; play: Open Controls → Animations"


def _viewer_js() -> str:
    """meshcat's viewer bundle (three.js included), the file its server serves as ``/static/main.min.js``."""
    meshcat = _import_meshcat()
    source = (Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_text(encoding="utf-8")
    if "</script" in source.lower():  # would end the inline <script> early
        source = source.replace("</script", "<\\/script").replace("</SCRIPT", "<\\/SCRIPT")
    return source


def _atomic_write_text(path: Path, text: str) -> None:
    """Write ``text`` to a new file beside ``path``, then ``os.replace`` it onto ``path``."""
    if path.is_dir():
        raise OutputError(str(path), "is a directory; expected a file path")
    parent = path.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(str(parent), f"cannot create the directory ({exc.strerror})") from exc
    tmp = parent / f".{path.name}.{uuid.uuid4().hex}.tmp"
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # umask applies
    except OSError as exc:
        raise OutputError(str(path), f"cannot write in {parent} ({exc.strerror})") from exc
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def write_html(
    robot: RobotModel,
    t: npt.ArrayLike,
    q: npt.ArrayLike,
    q_des: npt.ArrayLike | None = None,
    *,
    path: str | os.PathLike[str],
    via_xy: npt.ArrayLike | None = None,
    fps: float = 25.0,
    loop: bool = False,
    title: str = "twolink-pin: arm motion",
) -> Path:
    """Write the animated scene as one self-contained HTML file.

    The file inlines meshcat's viewer (three.js included, ``main.min.js``) and every scene
    command, msgpack-packed and base64-encoded, which the page hands to
    ``viewer.handle_command_bytearray`` in order as it loads (meshcat's ``static_html``
    asks its server for the same commands; here they are recorded in-process by a
    window object given to ``meshcat.Visualizer(window=...)``, so no server or browser is
    needed). The page then sets ``window.sceneLoaded = true``; it requests nothing.

    Frames: the motion is resampled at ``fps`` frames per second of motion time. Frame
    ``k`` shows ``q`` at ``t[0] + k / fps`` (linear interpolation between the samples
    given), plus one last frame at ``t[-1]``; in the viewer, animation time ``τ`` [s]
    corresponds to ``t[0] + τ`` and poses are interpolated between frames. A 30-s run at
    25 fps is about 1.7 MB (0.85 MB of it the viewer), whatever the simulation's step.

    Args:
        robot: The arm (its URDF gives the visual geometry).
        t: Sample times [s], shape (N,), N >= 2, strictly increasing.
        q: Joint angles of the arm [rad], shape (N, nq).
        q_des: Desired joint angles [rad], shape (N, nq): drawn as the translucent ghost
            arm and the desired end-effector path; ``None`` for neither.
        path: The HTML file to write (replaced atomically; its directory is created).
        via_xy: Via points ``(x, y)`` [m], shape (M, 2), shown as red spheres; or ``None``.
        fps: Animation frames per second of motion [1/s], > 0.
        loop: Repeat the animation forever instead of playing it once.
        title: The page's title.

    Returns:
        ``path`` as a :class:`~pathlib.Path`.

    Raises:
        InvalidParameterError: a shape mismatch, a non-finite value, times not strictly
            increasing or ``fps <= 0`` (the error names the offending entry).
        OutputError: ``path`` is a directory or cannot be written.
    """
    target = Path(path)
    motion = _prepare(robot, t, q, q_des, via_xy, fps)
    commands = _scene_commands(robot, motion, loop=loop)
    encoded = ",\n".join(f'"{base64.b64encode(_pack(c)).decode("ascii")}"' for c in commands)
    html = _HTML.format(
        title=title.replace("&", "&amp;").replace("<", "&lt;"),
        legend=_legend(motion.q_des is not None, motion.via_xy is not None),
        viewer_js=_viewer_js(),
        commands=encoded,
    )
    _atomic_write_text(target, html)
    return target


# ----------------------------------------------------------------------------- live server


def _url_host(host: str) -> str:
    return f"[{host}]" if ":" in host else host


def _start_bridge(host: str, port: int | None) -> tuple[Any, threading.Thread]:
    """Start meshcat's ZMQ/WebSocket bridge in a thread, listening on ``host`` only.

    meshcat 0.3.2's ``ZMQWebSocketBridge`` calls ``app.listen(port)`` without an address,
    so tornado binds every interface. The subclass below hands it an application whose
    ``listen`` adds ``address=host``; its ZMQ socket binds ``tcp://127.0.0.1:*`` (any free
    port). ``port=None`` listens on a free port chosen by the kernel.
    """
    import asyncio
    import queue

    import tornado.web

    _import_meshcat()
    from meshcat.servers.zmqserver import (
        VIEWER_HTML,
        VIEWER_ROOT,
        StaticFileHandlerNoCache,
        WebSocketHandler,
        ZMQWebSocketBridge,
    )

    class _BoundApplication(tornado.web.Application):
        bind_address = "127.0.0.1"
        http_server: Any = None

        def listen(self, port: int, address: str | None = None, **kwargs: Any) -> Any:
            self.http_server = super().listen(port, address=self.bind_address, **kwargs)
            return self.http_server

    class _QuietWebSocketHandler(WebSocketHandler):  # meshcat's prints "opened:"/"closed:" on stderr
        def open(self) -> None:
            self.bridge.websocket_pool.add(self)
            self.bridge.send_scene(self)

        def on_close(self) -> None:
            self.bridge.websocket_pool.discard(self)

    def log_request(handler: Any) -> None:
        _log.debug("%d %s", handler.get_status(), handler._request_summary())

    class _BoundBridge(ZMQWebSocketBridge):
        def __init__(self, **kwargs: Any) -> None:
            try:
                super().__init__(**kwargs)
            except BaseException:  # e.g. the port is taken: release the ZMQ socket bound already
                stream = getattr(self, "zmq_stream", None)
                if stream is not None:
                    stream.close(linger=0)
                raise

        def make_app(self) -> tornado.web.Application:
            static = {"path": VIEWER_ROOT, "default_filename": VIEWER_HTML}
            app = _BoundApplication(
                [
                    (r"/static/(.*)", StaticFileHandlerNoCache, static),
                    (r"/", _QuietWebSocketHandler, {"bridge": self}),
                ],
                log_function=log_request,
            )
            app.bind_address = self.host
            return app

    started: queue.Queue[Any] = queue.Queue()

    def run() -> None:
        loop = asyncio.new_event_loop()
        asyncio.set_event_loop(loop)
        try:
            bridge = _BoundBridge(zmq_url="tcp://127.0.0.1:*", host=host, port=0 if port is None else port)
            import zmq

            bridge.zmq_url = bridge.zmq_socket.getsockopt_string(zmq.LAST_ENDPOINT)
            sockets = bridge.app.http_server._sockets.values()
            bridge.fileserver_port = next(iter(sockets)).getsockname()[1]
            bridge.web_url = f"http://{_url_host(host)}:{bridge.fileserver_port}/static/"
        except BaseException as exc:
            started.put(exc)
            loop.close()
            return
        started.put(bridge)
        try:
            bridge.run()
        finally:
            bridge.ioloop.close(all_fds=True)

    thread = threading.Thread(target=run, name=f"meshcat-bridge-{host}", daemon=True)
    thread.start()
    result = started.get(timeout=30)
    if isinstance(result, BaseException):
        thread.join(timeout=5)
        if isinstance(result, OSError):
            raise OutputError(f"{host}:{port}", f"cannot listen there ({result.strerror})") from result
        raise result
    return result, thread


class LiveViewer:
    """A meshcat server (in a background thread) holding one animated scene.

    Made by :func:`serve`. Open :attr:`url` in a browser: the page connects to the server
    over a WebSocket, receives the scene and plays the animation in real time (by the
    browser's clock; ``loop=True`` repeats it). :meth:`close` (or leaving the ``with``
    block) closes the connections and the listening sockets and stops the thread.
    """

    def __init__(self, bridge: Any, thread: threading.Thread, host: str) -> None:
        import zmq

        self._bridge = bridge
        self._thread = thread
        self._context = zmq.Context()
        self._socket = self._context.socket(zmq.REQ)
        self._socket.setsockopt(zmq.RCVTIMEO, 10_000)
        self._socket.setsockopt(zmq.LINGER, 0)
        self._socket.connect(bridge.zmq_url)
        self._closed = False
        self.host: str = host
        """Address the HTTP/WebSocket server listens on."""
        self.port: int = int(bridge.fileserver_port)
        """TCP port of the HTTP/WebSocket server."""
        self.url: str = str(bridge.web_url)
        """The page to open, ``http://<host>:<port>/static/``."""
        self.zmq_url: str = str(bridge.zmq_url)
        """meshcat's command socket (always on 127.0.0.1)."""

    def _send(self, command: dict[str, Any]) -> None:
        """Send one lowered meshcat command to the server (and any connected browser)."""
        import zmq

        if self._closed:
            raise TwolinkPinError("the live viewer is closed")
        self._socket.send_multipart([command["type"].encode(), command["path"].encode(), _pack(command)])
        try:
            reply = self._socket.recv()
        except zmq.Again as exc:
            raise TwolinkPinError(f"the meshcat server at {self.zmq_url} did not answer within 10 s") from exc
        if reply != b"ok":
            raise TwolinkPinError(f"the meshcat server refused a {command['type']} command: {reply!r}")

    @property
    def running(self) -> bool:
        """Whether the server's thread is still serving."""
        return self._thread.is_alive()

    def close(self) -> None:
        """Close the browser connections and the server's sockets, stop its thread (idempotent)."""
        if self._closed:
            return
        self._closed = True
        self._socket.close(linger=0)
        self._context.term()
        bridge = self._bridge

        def shutdown() -> None:
            bridge.app.http_server.stop()
            for websocket in list(bridge.websocket_pool):
                websocket.close()
            bridge.zmq_stream.close(linger=0)
            bridge.ioloop.stop()

        if self._thread.is_alive():
            bridge.ioloop.add_callback(shutdown)
            self._thread.join(timeout=10)

    def __enter__(self) -> LiveViewer:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "closed" if self._closed else "open"
        return f"<LiveViewer {self.url} ({state})>"


def serve(
    robot: RobotModel,
    t: npt.ArrayLike,
    q: npt.ArrayLike,
    q_des: npt.ArrayLike | None = None,
    *,
    via_xy: npt.ArrayLike | None = None,
    fps: float = 25.0,
    host: str = "127.0.0.1",
    port: int | None = None,
    loop: bool = False,
    open_browser: bool = False,
    quiet: bool = False,
) -> LiveViewer:
    """Serve the animated scene live with meshcat, on ``host`` only.

    The scene and its frames are those of :func:`write_html` (same arguments). The server
    runs in a daemon thread of this process; call :meth:`LiveViewer.close` (or use the
    result as a context manager) to stop it. A caller that waits for Ctrl-C does so itself::

        with serve(robot, t, q, q_des, via_xy=via) as viewer:
            try:
                threading.Event().wait()
            except KeyboardInterrupt:
                pass

    Args:
        host: Address to listen on: ``127.0.0.1`` (default) keeps the viewer local; give
            ``0.0.0.0`` explicitly to expose it on every interface.
        port: TCP port of the page and WebSocket; ``None`` picks a free one.
        loop: Repeat the motion forever.
        open_browser: Open :attr:`LiveViewer.url` with :mod:`webbrowser`.
        quiet: Do not print the URL on stdout.

    Raises:
        InvalidParameterError: bad arrays (as :func:`write_html`) or ``port`` not in 0..65535.
        OutputError: the server cannot listen on ``host:port`` (in use, no such address).
    """
    if port is not None and not (isinstance(port, int) and 0 <= port <= 65535):
        raise InvalidParameterError("port", port, "None (any free port) or an integer in 0..65535")
    if not isinstance(host, str) or not host:
        raise InvalidParameterError("host", host, "an address to listen on, e.g. '127.0.0.1'")
    motion = _prepare(robot, t, q, q_des, via_xy, fps)
    commands = _scene_commands(robot, motion, loop=loop)
    bridge, thread = _start_bridge(host, port)
    viewer = LiveViewer(bridge, thread, host)
    try:
        for command in commands:
            viewer._send(command)
    except BaseException:
        viewer.close()
        raise
    if not quiet:
        print(f"twolink-pin viewer: {viewer.url}", file=sys.stdout, flush=True)
    if open_browser:
        import webbrowser

        webbrowser.open(viewer.url, new=2)
    return viewer


__all__ = [
    "ARM_NODE",
    "CAMERA_NODE",
    "DESIRED_PATH_NODE",
    "GHOST_NODE",
    "TRAIL_NODE",
    "VIA_NODE",
    "LiveViewer",
    "ghost_visual_model",
    "serve",
    "visual_model",
    "write_html",
]
