"""Where the tuner's page is served: the ``--host`` and ``--port`` checked before the server
starts, so that a host that cannot be listened on is one clear error at once (Viser's server
would try a thousand ports and wait forever), and a host other than loopback is said out
loud: whoever reaches the port can run laws and download the runs.

Nothing here imports viser: a plain socket is bound to the address and closed again.
"""

from __future__ import annotations

import errno
import ipaddress
import socket
from typing import NamedTuple

from twolink_pin.errors import InvalidParameterError

HOST_EXPECTED = (
    "an address of this machine to listen on (127.0.0.1: this machine only; 0.0.0.0: every interface)"
)
"""What ``--host`` must be (the end of its error message)."""


class Address(NamedTuple):
    """A host checked for listening."""

    host: str
    """The host as given."""
    addresses: tuple[str, ...]
    """The IP addresses it resolves to."""
    loopback: bool
    """True when every one of them is a loopback address (only this machine can connect)."""


def _resolve(host: str) -> tuple[tuple[int, str], ...]:
    try:
        infos = socket.getaddrinfo(host, None, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError, ValueError) as exc:
        reason = exc.strerror if isinstance(exc, socket.gaierror) and exc.strerror else str(exc)
        raise InvalidParameterError(
            "--host", host, f"{HOST_EXPECTED}; the name does not resolve ({reason})"
        ) from None
    found: dict[tuple[int, str], None] = {}
    for family, _, _, _, sockaddr in infos:
        if family in (socket.AF_INET, socket.AF_INET6):
            found[(family, str(sockaddr[0]))] = None
    if not found:
        raise InvalidParameterError(
            "--host", host, f"{HOST_EXPECTED}; it resolves to no IPv4 or IPv6 address"
        )
    return tuple(found)


def check_listen(host: str, port: int = 0) -> Address:
    """Check that the page can be served on ``host`` and ``port`` (0: any free port).

    Raises:
        InvalidParameterError: ``--host`` does not resolve or no interface of this machine
            has its address; ``--port`` is in use (or not allowed) on it.
    """
    resolved = _resolve(host)
    for family, address in resolved:
        with socket.socket(family, socket.SOCK_STREAM) as probe:
            probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as the server binds
            try:
                probe.bind((address, port))
            except OSError as exc:
                reason = exc.strerror or str(exc)
                if port and exc.errno in (errno.EADDRINUSE, errno.EACCES):
                    raise InvalidParameterError(
                        "--port", port, f"a free port on {host} ({reason}); leave --port out for a free one"
                    ) from None
                raise InvalidParameterError(
                    "--host", host, f"{HOST_EXPECTED}; cannot listen on {address} ({reason})"
                ) from None
    loopback = all(ipaddress.ip_address(a.split("%")[0]).is_loopback for _, a in resolved)
    return Address(host, tuple(a for _, a in resolved), loopback)


def exposure_note(address: Address, port: int) -> str:
    """The line that says a page served beyond this machine is reachable from the network."""
    where = ", ".join(address.addresses)
    return (
        f"twolink-pin: note: with --host {address.host} the page is reachable from the network ({where}, port "
        f"{port}): anyone who reaches it can run laws and download the runs; --host 127.0.0.1 keeps it on this machine"
    )


__all__ = ["HOST_EXPECTED", "Address", "check_listen", "exposure_note"]
