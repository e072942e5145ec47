"""Stage markers: where a running command has got to, for tests and supervisors.

When the environment variable :data:`READY_FILE` names a file, :func:`ready` appends one
line per stage reached (``started``, ``parsed``, ``running``, ``writing``; ``serving``:
``tune``'s page is up), so that a test can send Ctrl-C at a known stage instead of after a
guessed delay (which a busy machine breaks). Without the variable it does nothing. A failure
to write the marker is ignored: it never changes what the command does.
"""

from __future__ import annotations

import os

READY_FILE = "TWOLINK_PIN_READY_FILE"
"""Environment variable: the file :func:`ready` appends stage names to."""


def ready(stage: str) -> None:
    """Append ``stage`` (one word) as a line to the file named by :data:`READY_FILE`, if any."""
    path = os.environ.get(READY_FILE)
    if not path:
        return
    try:
        fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o600)
        try:
            os.write(fd, f"{stage}\n".encode())
        finally:
            os.close(fd)
    except OSError:
        pass


__all__ = ["READY_FILE", "ready"]
