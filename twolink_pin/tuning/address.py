"""Where the tuner's page is served: the ``--host`` and ``--port`` checked before the server
starts, so that a host that cannot be listened on is one clear error at once (Viser's server
would try a thousand ports and wait forever), and a host other than loopback is said out
loud: whoever reaches the port can run laws and download the runs.

A multicast or broadcast address is refused: Linux lets a TCP socket bind to one (224.0.0.1,
255.255.255.255, a network's broadcast address such as 192.0.2.255) and listen, but no
browser can connect to it. Besides naming the multicast and the limited-broadcast addresses,
the check connects to the probe it listens on: an address a page cannot be reached at fails
there (a network's broadcast address: "Network is unreachable"), on any system.

Nothing here imports viser: a plain socket is bound to the address, listened on, connected
to and closed again.
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


CONNECT_WAIT = 10.0
"""Bound on the connection to the probe [s] (to this machine: it answers at once)."""


def _not_unicast(address: str) -> str | None:
    """Why ``address`` is no address to serve on (multicast, broadcast), or None."""
    ip = ipaddress.ip_address(address.split("%")[0])
    if ip.is_multicast:
        return f"{address} is a multicast address"
    if ip == ipaddress.IPv4Address("255.255.255.255"):
        return f"{address} is the broadcast address"
    return None


def _reachable(probe: socket.socket, family: int, address: str, host: str) -> None:
    """Connect to the listening ``probe``: an address a page cannot be reached at (a
    broadcast address of a network) is refused."""
    name = probe.getsockname()
    target = name[0]
    if ipaddress.ip_address(target.split("%")[0]).is_unspecified:  # every interface: this machine's loopback
        target = "::1" if family == socket.AF_INET6 else "127.0.0.1"
    with socket.socket(family, socket.SOCK_STREAM) as client:
        client.settimeout(CONNECT_WAIT)
        try:
            client.connect((target, name[1], *name[2:]) if family == socket.AF_INET6 else (target, name[1]))
        except OSError as exc:
            reason = exc.strerror or str(exc)
            raise InvalidParameterError(
                "--host",
                host,
                f"{HOST_EXPECTED}; nothing can connect to {address} ({reason}): a broadcast or multicast "
                "address is no address a page can be served on",
            ) from None


def check_listen(host: str, port: int = 0) -> Address:
    """Check that the page can be served on ``host`` and ``port`` (0: any free port).

    Raises:
        InvalidParameterError: ``--host`` does not resolve, no interface of this machine
            has its address, or it is a multicast or broadcast address; ``--port`` is in use
            (or not allowed) on it.
    """
    resolved = _resolve(host)
    for _, address in resolved:
        why = _not_unicast(address)
        if why is not None:
            raise InvalidParameterError(
                "--host", host, f"{HOST_EXPECTED}; {why}, which no page can be served on"
            )
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
            probe.listen(1)
            _reachable(probe, family, address, host)
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
