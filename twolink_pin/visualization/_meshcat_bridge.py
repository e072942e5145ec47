"""Everything that leans on meshcat's internals, in one place.

Written against **meshcat 0.3.2** (the Python package, with its bundled viewer), tornado
6.x and pyzmq 27; re-check this module when meshcat is upgraded. It is fragile because
meshcat 0.3.2 offers no public way to do what the live viewer needs:

* ``ZMQWebSocketBridge.__init__`` calls ``self.app.listen(port)`` with no address, so
  tornado binds **every interface**. :func:`start_bridge` subclasses the bridge so that
  ``make_app`` returns an application whose ``listen`` adds ``address=host``
  (127.0.0.1 unless the caller asks otherwise); the ZMQ command socket is bound to
  ``tcp://127.0.0.1:*`` (a free port the kernel picks), never to another interface.
* The port actually listened on is read back from tornado's ``HTTPServer._sockets`` and
  the ZMQ endpoint from ``zmq.LAST_ENDPOINT``, because the bridge only knows the ports
  it was asked for.
* meshcat's ``WebSocketHandler`` prints ``opened:``/``closed:`` on stderr for every
  browser connection; a quiet subclass replaces it, and tornado's access log goes to
  :mod:`logging` at debug level.
* :meth:`Bridge.stop` stops the HTTP server, closes the WebSockets and the ZMQ stream
  and stops the bridge's IO loop from inside that loop (meshcat has no shutdown).

:func:`import_meshcat` is here too: importing meshcat 0.3.2 imports
``zmq.eventloop.ioloop``, which pyzmq >= 17 flags as deprecated; the warning is
silenced for that import only. meshcat is imported lazily, by the functions that need
it, and only by this package.
"""

from __future__ import annotations

import asyncio
import logging
import queue
import threading
import warnings
from typing import Any

from twolink_pin.errors import OutputError

_log = logging.getLogger(__name__)

MESHCAT_VERSION = "0.3.2"
"""The meshcat release this module was written against."""


def import_meshcat() -> Any:
    """``import meshcat`` (and its server module) without pyzmq's deprecation warning."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "zmq.eventloop.ioloop is deprecated", DeprecationWarning)
        import meshcat
        import meshcat.servers.zmqserver
    return meshcat


def _url_host(host: str) -> str:
    return f"[{host}]" if ":" in host else host


class Bridge:
    """A running meshcat ZMQ/WebSocket bridge (its IO loop in a daemon thread).

    Made by :func:`start_bridge`; only :meth:`stop` touches its internals afterwards.
    """

    def __init__(self, bridge: Any, thread: threading.Thread, host: str) -> None:
        self._bridge = bridge
        self._thread = thread
        self.host: str = host
        """Address the HTTP/WebSocket server listens on."""
        self.port: int = int(bridge.fileserver_port)
        """TCP port of the HTTP/WebSocket server."""
        self.url: str = str(bridge.web_url)
        """The viewer page, ``http://<host>:<port>/static/``."""
        self.zmq_url: str = str(bridge.zmq_url)
        """meshcat's command socket, ``tcp://127.0.0.1:<port>``."""

    @property
    def running(self) -> bool:
        """Whether the bridge's thread is still serving."""
        return self._thread.is_alive()

    def stop(self, timeout: float = 10.0) -> None:
        """Close the browser connections and the listening sockets, stop the thread [s]."""
        bridge = self._bridge

        def shutdown() -> None:
            bridge.app.http_server.stop()
            for websocket in list(bridge.websocket_pool):
                websocket.close()
            bridge.zmq_stream.close(linger=0)
            bridge.ioloop.stop()

        if self._thread.is_alive():
            bridge.ioloop.add_callback(shutdown)
            self._thread.join(timeout=timeout)


def start_bridge(host: str = "127.0.0.1", port: int | None = None) -> Bridge:
    """Start meshcat's ZMQ/WebSocket bridge in a daemon thread, listening on ``host`` only.

    Args:
        host: Address of the page and WebSocket server.
        port: Its TCP port; ``None`` (or 0) lets the kernel pick a free one.

    Raises:
        OutputError: the server cannot listen on ``host:port`` (in use, no such address).
    """
    import zmq

    bridge_class = _bound_bridge_class()
    started: queue.Queue[Any] = queue.Queue()

    def run() -> None:
        loop = asyncio.new_event_loop()
        asyncio.set_event_loop(loop)
        try:
            bridge = bridge_class(zmq_url="tcp://127.0.0.1:*", host=host, port=0 if port is None else port)
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
    return Bridge(result, thread, host)


def _bound_bridge_class() -> Any:
    """meshcat's ``ZMQWebSocketBridge`` whose page and WebSocket server listen on its ``host``
    only, that logs requests at debug level and releases its ZMQ socket when it cannot start."""
    import tornado.web

    import_meshcat()
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

    class _QuietWebSocketHandler(WebSocketHandler):
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

    return _BoundBridge
