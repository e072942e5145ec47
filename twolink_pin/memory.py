"""The memory a command may use: what the machine has available, read before a large input is.

A reader that needs memory in proportion to its input (a ROS bag), or a solver in proportion
to its problem (``mpc``'s horizon), compares its need with :func:`available_memory` first and refuses an input too large for it by its size on disk,
instead of being killed half-way by the kernel's out-of-memory killer.
"""

from __future__ import annotations

import os

from twolink_pin.errors import InvalidParameterError

MEMORY_ENV = "TWOLINK_PIN_MEMORY"
"""Environment variable: the memory a command may use [bytes], instead of what the machine
reports (a test, or a share of a machine that runs other work)."""


def address_space_used() -> int | None:
    """Bytes of address space this process holds now (``VmSize`` in ``/proc/self/status``),
    None where it cannot be read."""
    try:
        with open("/proc/self/status", encoding="ascii", errors="replace") as f:
            for line in f:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024  # reported in kB
    except (OSError, ValueError, IndexError):
        pass
    return None


def available_memory() -> int | None:
    """Bytes this process may still allocate: :data:`MEMORY_ENV` if set, else the smaller of
    ``MemAvailable`` in ``/proc/meminfo`` and what is left under the address-space limit
    (``ulimit -v``: the limit less the address space the process already holds, which is
    250 MB or more once Pinocchio and NumPy are imported); None where neither is known.

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
            bounds.append(max(0, int(soft) - (address_space_used() or 0)))
    return min(bounds) if bounds else None
