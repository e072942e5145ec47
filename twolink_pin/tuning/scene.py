"""The tuner's 3-D scene in Viser: the arm (its URDF meshes, through Pinocchio's
``ViserVisualizer``), its translucent ghost following the reference, the end effector's
trail and desired path, and the playback (play/pause, a time scrubber, a speed).

The playback is kept light so that the page answers a control at once: :data:`FPS` frames
a second (each moves the arm and its ghost), the time scrubber's number updated
:data:`SCRUBBER_HZ` times a second (each update re-renders the panel), and no frame at all
while :meth:`ArmScene.hold` holds it: the tuner holds it from a control's move until
:data:`RESUME_AFTER` seconds after the new run is shown, so a burst of key presses meets a
still scene. (Viser's client renders on demand, each scene update opening a 250-ms window of
continuous frames: with software WebGL a playing arm keeps the browser's main thread busy.)
An arm whose visual meshes are heavy (more than :data:`TRIANGLES` triangles: the UR5's and
the Panda's hold about 10⁵) is drawn with its URDF's collision geometry, about 50 times
lighter, when it has one (:func:`light_model`)."""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.errors import InvalidParameterError, TwolinkPinError
from twolink_pin.kinematics import joint_positions
from twolink_pin.tuning.typed import Channel, read_number
from twolink_pin.visualization.scene import GHOST_RGB, ghost_visual_model, visual_model

if TYPE_CHECKING:
    from twolink_pin.model import RobotModel

FPS = 10.0
"""Playback frames per second."""
SCRUBBER_HZ = 2.0
"""Updates of the time scrubber per second while playing."""
RESUME_AFTER = 2.0
"""The playback goes on this long after a hold is released [s]."""
TRAIL_POINTS = 400
"""Largest number of points of the trail and the desired path."""
TRIANGLES = 20_000
"""The most triangles of visual meshes the tuner draws (twice: the arm and its ghost)."""
ARM_RGBA = (0.62, 0.66, 0.72, 1.0)
"""The colour of an arm drawn with its collision geometry (which has none of its own)."""
TRAIL_RGB = (194, 37, 92)
DESIRED_RGB = (43, 138, 62)


def _segments(points: np.ndarray) -> np.ndarray:
    """A polyline ``(P, 3)`` as line segments ``(P − 1, 2, 3)``."""
    step = max(1, len(points) // TRAIL_POINTS)
    p = points[::step]
    return np.stack([p[:-1], p[1:]], axis=1).astype(np.float32)


def _triangles(geometry: Any) -> int:
    return sum(int(getattr(obj.geometry, "num_tris", 0)) for obj in geometry.geometryObjects)


def light_model(robot: RobotModel) -> Any:
    """The geometry the tuner draws: the visual meshes, or, when they hold more than
    :data:`TRIANGLES` triangles, the collision geometry if it is lighter (coloured
    :data:`ARM_RGBA`)."""
    import pinocchio as pin

    visual = visual_model(robot)
    if _triangles(visual) <= TRIANGLES:
        return visual
    try:
        collision = visual_model(robot, pin.GeometryType.COLLISION)
    except TwolinkPinError:
        return visual
    if not collision.ngeoms or _triangles(collision) >= _triangles(visual):
        return visual
    for obj in collision.geometryObjects:
        obj.meshColor = np.array(ARM_RGBA)
    return collision


SHIFT = 0.2
"""How far right of the motion's centre the camera looks, as a share of its distance: the
controls float over the right part of the 3-D view (:mod:`.results`), so the arm is drawn
in the part left of them (about the middle of what they leave at 1366 to 1920 px)."""


def view_of(points: np.ndarray, shift: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Where the camera looks (the motion's centre [m], moved ``shift`` × the camera's
    distance to the screen's right) and where it is: along the normal of a planar motion,
    obliquely otherwise, far enough to see it all."""
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    spread = points - points.mean(axis=0)
    _, sigma, axes = np.linalg.svd(spread, full_matrices=False)
    radius = float(max(np.linalg.norm(points - centre, axis=1).max(), 0.2))
    if sigma[-1] < 1e-6 * max(sigma[0], 1e-12):  # planar: look along its normal, from the side of +z
        direction = axes[-1] * (1.0 if axes[-1][2] >= 0 else -1.0) + np.array([0.0, -0.15, 0.0])
    else:
        direction = np.array([1.0, -1.2, 0.8])
    direction /= np.linalg.norm(direction)
    distance = 2.2 * radius
    right = np.cross(-direction, np.array([0.0, 0.0, 1.0]))  # the screen's right, z up
    if np.linalg.norm(right) > 1e-9:
        centre = centre + shift * distance * right / np.linalg.norm(right)
    return centre, centre + distance * direction


class ArmScene:
    """The arm, its ghost and trail in ``server``'s scene, with the playback controls in its
    GUI (created in the folder open when this is built); a number typed into the time's or
    the speed's box arrives through ``channel`` (:class:`~twolink_pin.tuning.typed.Channel`).
    :meth:`focused` is told whether a control has the focus (:mod:`.typed_js`)."""

    def __init__(self, server: Any, robot: RobotModel, channel: Channel | None = None) -> None:
        import pinocchio as pin
        from pinocchio.visualize import ViserVisualizer

        self._server = server
        self._robot = robot
        visual = light_model(robot)
        self.arm = ViserVisualizer(robot.model, pin.GeometryModel(), visual)
        self.arm.initViewer(viewer=server)
        self.arm.loadViewerModel("arm")
        self.ghost = ViserVisualizer(
            robot.model, pin.GeometryModel(), ghost_visual_model(visual, rgb=GHOST_RGB)
        )
        self.ghost.initViewer(viewer=server)
        self.ghost.loadViewerModel("ghost")
        self.playing = server.gui.add_checkbox("play", True, hint="play or pause the run")
        self.time = server.gui.add_slider("time [s]", 0.0, 1.0, 0.01, 0.0, hint="the instant shown")
        self.speed = server.gui.add_slider("speed", 0.1, 4.0, 0.1, 1.0, hint="× real time")
        self.time.on_update(self._on_scrub)
        self.note = server.gui.add_markdown("")
        if channel is not None:
            channel.register(self.time.label, lambda _i, text: self._typed(self.time, text))
            channel.register(self.speed.label, lambda _i, text: self._typed(self.speed, text))
        self._lock = threading.Lock()
        self._t = np.zeros(1)
        self._q = np.array([robot.home])
        self._q_des = self._q
        self._now = 0.0
        self._stop = threading.Event()
        self._framed = False
        self._held = threading.Event()
        self._resume_at = 0.0
        self._holds: set[str] = set()
        self._thread = threading.Thread(target=self._play, name="twolink-pin-tune-playback", daemon=True)
        self._thread.start()

    def show(self, t: np.ndarray, q: np.ndarray, q_des: np.ndarray) -> None:
        """Play the run ``q`` [rad] against ``q_des`` [rad] at the times ``t`` [s]."""
        ee = joint_positions(self._robot, q)[:, -1, :]
        ee_des = joint_positions(self._robot, q_des)[:, -1, :]
        scene = self._server.scene
        scene.add_line_segments("trail", _segments(ee), TRAIL_RGB, thickness=3.0, thickness_units="screen")
        scene.add_line_segments(
            "desired_path", _segments(ee_des), DESIRED_RGB, thickness=2.0, thickness_units="screen"
        )
        if not self._framed:  # the first run frames the view; later ones keep the user's
            self._framed = True
            joints = joint_positions(self._robot, q_des[:: max(1, len(q_des) // 50)]).reshape(-1, 3)
            centre, eye = view_of(np.vstack([joints, ee, ee_des]), SHIFT)
            self._server.initial_camera.look_at = centre
            self._server.initial_camera.position = eye
            self._server.initial_camera.up = (0.0, 0.0, 1.0)
        with self._lock:
            self._t, self._q, self._q_des = t, q, q_des
            self._now = min(self._now, float(t[-1]))
        self.time.max = float(t[-1])
        self._draw()

    def hold(self, held: bool, resume_after: float = 0.0, why: str = "run") -> None:
        """Stop drawing frames (True), or go on ``resume_after`` seconds from now (False),
        without touching play/pause; each reason ``why`` (a run in flight, a focused
        control) holds until it is released."""
        with self._lock:
            if held:
                self._holds.add(why)
            else:
                self._holds.discard(why)
                self._resume_at = max(self._resume_at, time.monotonic() + resume_after)
            if self._holds:
                self._held.set()
            else:
                self._held.clear()

    def focused(self, value: str) -> None:
        """The page's focus box says ``"1"`` (a control has the focus: hold still) or ``"0"``."""
        self.hold(value == "1", RESUME_AFTER, why="focus")

    def close(self) -> None:
        """Stop the playback thread."""
        self._stop.set()

    def _typed(self, slider: Any, text: str) -> None:
        """A number typed into the time's box (an instant past the run's end is its end) or
        the speed's (> 0: × real time; past the slider's end, the end moves)."""
        try:
            if slider is self.time:
                value = min(max(read_number("time [s]", text, 0.0), 0.0), float(self.time.max))
            else:
                value = read_number("speed", text, 0.0, None, above_low=True)
        except InvalidParameterError as exc:
            self.note.content = f"**refused**: {exc}"
            return
        self.note.content = ""
        if value > float(slider.max):
            slider.max = value
        slider.value = value
        if slider is self.time:
            self._seek(value)

    def _on_scrub(self, event: Any) -> None:
        if event.client is not None:  # the user moved it (the playback sets it too)
            self._seek(float(self.time.value))

    def _seek(self, now: float) -> None:
        with self._lock:
            self._now = now
        if not self.playing.value:
            self._draw()

    def _draw(self) -> None:
        with self._lock:
            i = int(np.searchsorted(self._t, self._now).clip(0, len(self._t) - 1))
            q, q_des = self._q[i], self._q_des[i]
        with self._server.atomic():
            self.arm.display(q)
            self.ghost.display(q_des)

    def _play(self) -> None:
        last = scrubbed = time.monotonic()
        while not self._stop.wait(1.0 / FPS):
            now = time.monotonic()
            elapsed, last = now - last, now
            if not self.playing.value or self._held.is_set() or now < self._resume_at:
                continue
            with self._lock:
                end = float(self._t[-1])
                self._now = (self._now + elapsed * float(self.speed.value)) % end if end > 0 else 0.0
                shown = self._now
            if now - scrubbed >= 1.0 / SCRUBBER_HZ:
                scrubbed = now
                self.time.value = round(shown, 2)
            self._draw()


__all__ = ["ArmScene", "view_of"]
