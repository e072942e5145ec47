"""One self-contained HTML file of the animated scene: :func:`write_html`.

The page inlines meshcat's viewer bundle (three.js included, ``main.min.js``) and every
scene command of :func:`~twolink_pin.visualization.scene.scene_commands`, msgpack-packed
(:func:`pack`) and base64-encoded; as it loads, it hands them in order to
``viewer.handle_command_bytearray`` (meshcat's ``static_html`` asks a server for the same
commands), then sets ``window.sceneLoaded = true``. It opens from ``file://`` and requests
nothing. The file is written through :func:`twolink_pin.files.atomic_write`;
:func:`scene_page` returns the same page as text.
"""

from __future__ import annotations

import base64
import os
from pathlib import Path
from typing import Any

import numpy.typing as npt

from twolink_pin.contact.scene import Scene
from twolink_pin.files import atomic_write
from twolink_pin.model import RobotModel
from twolink_pin.visualization._meshcat_bridge import import_meshcat
from twolink_pin.visualization.motion import prepare_motion
from twolink_pin.visualization.overlays import AXIS_COLORS, WRENCH_COLOR
from twolink_pin.visualization.scene import (
    DESIRED_PATH_COLOR,
    GHOST_RGB,
    TRAIL_COLOR,
    VIA_COLOR,
    scene_commands,
)


def pack(command: dict[str, Any]) -> bytes:
    """msgpack bytes of a lowered meshcat command, Python floats in single precision
    (~0.1 µm at 1 m; half the size). Arrays (mesh vertices) are packed as they are."""
    import umsgpack

    return bytes(umsgpack.packb(command, force_float_precision="single"))


_HTML = """<!DOCTYPE html>
<html>
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body {{ margin: 0; font: 12px sans-serif; }}
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


def _legend(
    has_ghost: bool,
    has_via: bool,
    grid_spacing: float,
    wrench_scale: float | None = None,
    axis_length: float | None = None,
) -> str:
    """The HTML legend under the scene: what each colour is, the grid's spacing [m], the
    force arrow's scale [m/N] and the triad's axis length [m], and where the player is."""
    ghost = int.from_bytes(bytes(round(c * 255) for c in GHOST_RGB), "big")  # 0xRRGGBB
    items: list[tuple[int | None, str]] = [(None, "arm (q)")]
    if has_ghost:
        items.append((ghost, "ghost (q_des)"))
    items.append((TRAIL_COLOR, "end-effector trail"))
    if has_ghost:
        items.append((DESIRED_PATH_COLOR, "desired path"))
    if has_via:
        items.append((VIA_COLOR, "via points"))
    if wrench_scale is not None:
        items.append((WRENCH_COLOR, f'<label id="wrench-scale">force arrow {wrench_scale:g} m per N</label>'))
    if axis_length is not None:
        items.append(
            (
                AXIS_COLORS[0],
                f'<label id="axis-length">desired frame (x y z red green blue) {axis_length:g} m</label>',
            )
        )
    html = "".join(
        text if color is None else f'<span style="background:#{color:06x}"></span>{text}'
        for color, text in items
    )
    return html + f" &nbsp;·&nbsp; grid {grid_spacing:g} m &nbsp;·&nbsp; play: Open Controls → Animations"


def _viewer_js() -> str:
    """meshcat's viewer bundle (three.js included), the file its server serves as ``/static/main.min.js``."""
    meshcat = import_meshcat()
    source = (Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_text(encoding="utf-8")
    if "</script" in source.lower():  # would end the inline <script> early
        source = source.replace("</script", "<\\/script").replace("</SCRIPT", "<\\/SCRIPT")
    return source


def scene_page(
    robot: RobotModel,
    t: npt.ArrayLike,
    q: npt.ArrayLike,
    q_des: npt.ArrayLike | None = None,
    *,
    via_points: npt.ArrayLike | None = None,
    fps: float = 25.0,
    loop: bool = False,
    title: str = "twolink-pin: arm motion",
    wrench: npt.ArrayLike | None = None,
    wrench_frame: str | None = None,
    desired_frame: bool | npt.ArrayLike = False,
    surfaces: Scene | None = None,
) -> str:
    """The self-contained HTML page of the animated scene, as text (what :func:`write_html`
    writes and :func:`~twolink_pin.visualization.notebook.inline_animation` embeds).

    The arguments are :func:`write_html`'s but ``path``; so are the errors it raises.

    Returns:
        The whole page: the viewer's JavaScript and the scene's commands inlined.
    """
    motion = prepare_motion(
        robot,
        t,
        q,
        q_des,
        via_points,
        fps,
        wrench=wrench,
        wrench_frame=wrench_frame,
        desired_frame=desired_frame,
        surfaces=surfaces,
    )
    scene = scene_commands(robot, motion, loop=loop)
    encoded = ",\n".join(f'"{base64.b64encode(pack(c)).decode("ascii")}"' for c in scene.commands)
    return _HTML.format(
        title=title.replace("&", "&amp;").replace("<", "&lt;"),
        legend=_legend(
            motion.q_des is not None,
            motion.via_points is not None,
            scene.grid_spacing,
            scene.wrench_scale,
            scene.axis_length,
        ),
        viewer_js=_viewer_js(),
        commands=encoded,
    )


def write_html(
    robot: RobotModel,
    t: npt.ArrayLike,
    q: npt.ArrayLike,
    q_des: npt.ArrayLike | None = None,
    *,
    path: str | os.PathLike[str],
    via_points: npt.ArrayLike | None = None,
    fps: float = 25.0,
    loop: bool = False,
    title: str = "twolink-pin: arm motion",
    wrench: npt.ArrayLike | None = None,
    wrench_frame: str | None = None,
    desired_frame: bool | npt.ArrayLike = False,
    surfaces: Scene | None = None,
) -> Path:
    """Write the animated scene as one self-contained HTML file.

    Frames: the motion is resampled at ``fps`` frames per second of motion time. Frame
    ``k`` shows ``q`` at ``t[0] + k / fps`` (linear interpolation between the samples
    given), plus one last frame at ``t[-1]``; in the viewer, animation time ``τ`` [s]
    corresponds to ``t[0] + τ`` and poses are interpolated between frames. The viewer's
    *Open Controls → Animations* panel plays, pauses and scrubs it; from JavaScript,
    ``viewer.animator.seek(τ)``. A 30-s run of the twolink at 25 fps is about 1.7 MB
    (0.85 MB of it the viewer), whatever the simulation's step; meshes add their
    triangles twice (arm and ghost): about 4.7 MB more for the UR5.

    Args:
        robot: The arm (its URDF's visual geometry, meshes included, is drawn).
        t: Sample times [s], shape (N,), N >= 2, strictly increasing.
        q: Joint angles of the arm [rad], shape (N, nq).
        q_des: Desired joint angles [rad], shape (N, nq): drawn as the translucent ghost
            arm and the desired end-effector path; ``None`` for neither.
        path: The HTML file to write (replaced atomically; its directory is created).
        via_points: End-effector via points [m], shape (M, 3) or (M, 2) (then z = 0),
            shown as red spheres; or ``None``.
        fps: Animation frames per second of motion [1/s], > 0.
        loop: Repeat the animation forever instead of playing it once.
        title: The page's title.
        wrench: The external wrench on ``wrench_frame`` per sample [N, N·m], world axes,
            shape (N, 3) or (N, 6) (zero where it does not act): its force is drawn as an
            arrow from the frame on the arm, ``|F| · s`` long (``s`` [m/N] a round number
            stated in the legend), while it acts (:mod:`.overlays`); or ``None``.
        wrench_frame: The frame the wrench acts on (None: the end effector).
        desired_frame: Draw the desired end-effector frame as a triad: ``True`` at the
            forward kinematics of ``q_des``, or the desired poses per sample (world, shape
            (N, 4, 4): a task-space reference); ``False`` for none.
        surfaces: A scene's surfaces (:class:`~twolink_pin.contact.Scene`), drawn as
            translucent slabs (:mod:`.overlays`); or ``None``.

    Returns:
        ``path`` as a :class:`~pathlib.Path`.

    Raises:
        InvalidParameterError: a shape mismatch, a non-finite value, times not strictly
            increasing or ``fps <= 0`` (the error names the offending entry).
        InvalidURDFError: a mesh of the robot's URDF cannot be found or loaded.
        OutputError: ``path`` is a directory or cannot be written.
    """
    target = Path(path)
    page = scene_page(
        robot,
        t,
        q,
        q_des,
        via_points=via_points,
        fps=fps,
        loop=loop,
        title=title,
        wrench=wrench,
        wrench_frame=wrench_frame,
        desired_frame=desired_frame,
        surfaces=surfaces,
    )
    with atomic_write(target) as f:
        f.write(page)
    return target
