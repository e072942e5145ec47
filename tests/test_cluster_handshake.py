"""A listener that is not a Dask scheduler (an SSH server's greeting) is named as such, not
reported as the exabyte MemoryError Dask meets when it reads the greeting as a frame length."""

from __future__ import annotations

import socket
import threading

import pytest

pytest.importorskip("distributed")

from twolink_pin.errors import TwolinkPinError
from twolink_pin.studies.cluster import handshake


def test_a_non_dask_listener_is_named_not_a_memory_error() -> None:
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(4)
    port = server.getsockname()[1]

    def greet() -> None:
        while True:
            try:
                peer, _ = server.accept()
            except OSError:
                return
            peer.sendall(b"SSH-2.0-OpenSSH_9.6\r\n" + b"\xff" * 64)

    threading.Thread(target=greet, daemon=True).start()
    try:
        with pytest.raises(TwolinkPinError) as caught:
            handshake(f"tcp://127.0.0.1:{port}", 10.0)
    finally:
        server.close()
    message = str(caught.value)
    assert "not as a Dask scheduler" in message and str(port) in message
    assert "MemoryError" not in message and "EiB" not in message
