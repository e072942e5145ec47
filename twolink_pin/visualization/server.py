"""The scene served live by a meshcat server on the loopback interface: :func:`serve`.

The server (meshcat's ZMQ/WebSocket bridge, started by
:func:`~twolink_pin.visualization._meshcat_bridge.start_bridge`) runs in a daemon thread
of this process and listens on 127.0.0.1 unless the caller names another address. The
scene's commands are sent to it over its ZMQ socket; a browser opening
:attr:`LiveViewer.url` receives them over a WebSocket and plays the animation by its own
clock.
"""

from __future__ import annotations

import sys
from typing import Any

import numpy.typing as npt

from twolink_pin.contact.scene import Scene
from twolink_pin.errors import InvalidParameterError, TwolinkPinError
from twolink_pin.model import RobotModel
from twolink_pin.visualization._meshcat_bridge import Bridge, start_bridge
from twolink_pin.visualization.html import pack
from twolink_pin.visualization.motion import prepare_motion
from twolink_pin.visualization.scene import scene_commands

REPLY_TIMEOUT = 10.0
"""Longest wait for the server to acknowledge one command [s]."""


class LiveViewer:
    """A meshcat server (in a background thread) holding one animated scene.

    Made by :func:`serve`. Open :attr:`url` in a browser: the page connects to the server
    over a WebSocket, receives the scene and plays the animation in real time (by the
    browser's clock; ``loop=True`` repeats it). :meth:`close` (or leaving the ``with``
    block) closes the connections and the listening sockets and stops the thread.
    """

    def __init__(self, bridge: Bridge) -> None:
        import zmq

        self._bridge = bridge
        self._context = zmq.Context()
        self._socket = self._context.socket(zmq.REQ)
        self._socket.setsockopt(zmq.RCVTIMEO, round(REPLY_TIMEOUT * 1000))
        self._socket.setsockopt(zmq.LINGER, 0)
        self._socket.connect(bridge.zmq_url)
        self._closed = False
        self.wrench_scale: float | None = None
        """Length of the force arrow per newton [m/N] (the live page has no legend); None: no arrow."""
        self.host: str = bridge.host
        """Address the HTTP/WebSocket server listens on."""
        self.port: int = bridge.port
        """TCP port of the HTTP/WebSocket server."""
        self.url: str = bridge.url
        """The page to open, ``http://<host>:<port>/static/``."""
        self.zmq_url: str = bridge.zmq_url
        """meshcat's command socket (always on 127.0.0.1)."""

    def _send(self, command: dict[str, Any]) -> None:
        """Send one lowered meshcat command to the server (and any connected browser)."""
        import zmq

        if self._closed:
            raise TwolinkPinError("the live viewer is closed")
        self._socket.send_multipart([command["type"].encode(), command["path"].encode(), pack(command)])
        try:
            reply = self._socket.recv()
        except zmq.Again as exc:
            raise TwolinkPinError(
                f"the meshcat server at {self.zmq_url} did not answer within {REPLY_TIMEOUT:g} s"
            ) from exc
        if reply != b"ok":
            raise TwolinkPinError(f"the meshcat server refused a {command['type']} command: {reply!r}")

    @property
    def running(self) -> bool:
        """Whether the server's thread is still serving."""
        return self._bridge.running

    def close(self) -> None:
        """Close the browser connections and the server's sockets, stop its thread (idempotent)."""
        if self._closed:
            return
        self._closed = True
        self._socket.close(linger=0)
        self._context.term()
        self._bridge.stop()

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
    via_points: npt.ArrayLike | None = None,
    fps: float = 25.0,
    host: str = "127.0.0.1",
    port: int | None = None,
    loop: bool = False,
    open_browser: bool = False,
    quiet: bool = False,
    wrench: npt.ArrayLike | None = None,
    wrench_frame: str | None = None,
    desired_frame: bool | npt.ArrayLike = False,
    surfaces: Scene | None = None,
) -> LiveViewer:
    """Serve the animated scene live with meshcat, on ``host`` only.

    The scene and its frames are those of :func:`~twolink_pin.visualization.write_html`
    (same arguments). The server runs in a daemon thread of this process; call
    :meth:`LiveViewer.close` (or use the result as a context manager) to stop it. A caller
    that waits for Ctrl-C does so itself::

        with serve(robot, t, q, q_des, via_points=via) as viewer:
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
        wrench, wrench_frame, desired_frame, surfaces: the force arrow, the desired frame's
            triad and a scene's surfaces, as :func:`~twolink_pin.visualization.write_html` (the live page has no legend:
            the arrow's scale is :func:`~twolink_pin.visualization.overlays.wrench_scale`).

    Raises:
        InvalidParameterError: bad arrays (as ``write_html``), ``host`` empty or ``port``
            not in 0..65535.
        InvalidURDFError: a mesh of the robot's URDF cannot be found or loaded.
        OutputError: the server cannot listen on ``host:port`` (in use, no such address).
    """
    if port is not None and not (isinstance(port, int) and not isinstance(port, bool) and 0 <= port <= 65535):
        raise InvalidParameterError("port", port, "None (any free port) or an integer in 0..65535")
    if not isinstance(host, str) or not host:
        raise InvalidParameterError("host", host, "an address to listen on, e.g. '127.0.0.1'")
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
    viewer = LiveViewer(start_bridge(host, port))
    viewer.wrench_scale = scene.wrench_scale
    try:
        for command in scene.commands:
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
