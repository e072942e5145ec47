"""The memory a command may use: what the machine has available, read before a large input is.

A reader that needs memory in proportion to its input (a ROS bag) compares its need with
:func:`available_memory` first and refuses an input too large for it by its size on disk,
instead of being killed half-way by the kernel's out-of-memory killer.
"""

from __future__ import annotations

import os

from twolink_pin.errors import InvalidParameterError

MEMORY_ENV = "TWOLINK_PIN_MEMORY"
"""Environment variable: the memory a command may use [bytes], instead of what the machine
reports (a test, or a share of a machine that runs other work)."""


def available_memory() -> int | None:
    """Bytes this process may still allocate: :data:`MEMORY_ENV` if set, else the smaller of
    ``MemAvailable`` in ``/proc/meminfo`` and the address-space limit (``ulimit -v``); None
    where neither is known.

    Raises:
        InvalidParameterError: :data:`MEMORY_ENV` is set but not a positive whole number of bytes.
    """
    given = os.environ.get(MEMORY_ENV)
    if given is not None and given.strip():
        try:
            value = int(given)
        except ValueError:
            value = 0
        if value <= 0:
            raise InvalidParameterError(MEMORY_ENV, given, "a positive whole number of bytes")
        return value
    bounds = []
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    bounds.append(int(line.split()[1]) * 1024)  # reported in kB
                    break
    except (OSError, ValueError, IndexError):
        pass
    try:
        import resource  # POSIX only
    except ImportError:
        resource = None  # type: ignore[assignment]
    if resource is not None:
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY:
            bounds.append(int(soft))
    return min(bounds) if bounds else None
