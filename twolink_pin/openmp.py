"""OpenMP settings for Pinocchio's parallel algorithms: the wait policy and the default thread count.

Imported first by ``twolink_pin/__init__.py``, before any module loads Pinocchio (whose
parallel algorithms run on OpenMP, which reads its environment once, when its runtime
loads with Pinocchio's library); importing this module sets the wait policy:

* :func:`set_passive_wait` sets ``OMP_WAIT_POLICY=PASSIVE`` unless the user set it. With
  the default (active) policy OpenMP's idle threads spin between parallel regions; on a
  machine whose cores are busy with other work (two batches, a sweep beside a notebook)
  those spinning threads take the cores the working ones need and a batch became 4–12×
  slower than on one thread. Passive threads sleep: at worst a wake-up per region.
  If Pinocchio was imported before ``twolink_pin``, the policy cannot be changed any more:
  set ``OMP_WAIT_POLICY=PASSIVE`` in the environment then (the default thread count
  accounts for spinning threads: see below).
* :func:`default_threads` is the thread count a batch uses when none is given: the
  ``TWOLINK_PIN_THREADS`` environment variable if set, else the cores this process may
  run on (``os.sched_getaffinity``) — all of them when the wait policy is passive, else
  less the ones other work keeps busy (the 1-minute load average, this process counted as
  one), at least 1.

Nothing here imports Pinocchio or numpy (only :mod:`twolink_pin.errors`).
"""

from __future__ import annotations

import os
import sys

from twolink_pin.errors import InvalidParameterError

THREADS_VARIABLE = "TWOLINK_PIN_THREADS"
"""Environment variable that fixes the default thread count of batches and sweeps."""
WAIT_POLICY_VARIABLE = "OMP_WAIT_POLICY"
"""OpenMP's wait-policy variable (``PASSIVE`` or ``ACTIVE``)."""


def set_passive_wait() -> bool:
    """Set ``OMP_WAIT_POLICY=PASSIVE`` unless the user set it; returns whether the policy
    in effect is passive as far as this process can tell."""
    chosen = os.environ.get(WAIT_POLICY_VARIABLE)
    if chosen is not None:
        return chosen.strip().upper() == "PASSIVE"
    if "pinocchio" in sys.modules:  # too late: OpenMP has read its environment (no warning: isort
        return False  # puts `import pinocchio` first in most scripts; the thread count adapts instead)
    os.environ[WAIT_POLICY_VARIABLE] = "PASSIVE"
    return True


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def busy_cores() -> float:
    """Cores other processes keep busy: the 1-minute load average less this process (one),
    at least 0; 0 where the load average is not available."""
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):
        return 0.0
    return max(0.0, load - 1.0)


def threads_override() -> int | None:
    """The thread count in ``TWOLINK_PIN_THREADS``, or None if it is not set.

    Raises:
        InvalidParameterError: the variable is set but not a whole number >= 1.
    """
    text = os.environ.get(THREADS_VARIABLE)
    if text is None or not text.strip():
        return None
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise InvalidParameterError(THREADS_VARIABLE, text, "a whole number of threads >= 1")
    return value


def passive_wait() -> bool:
    """Whether OpenMP's threads sleep while they wait (``OMP_WAIT_POLICY=PASSIVE`` in effect)."""
    return os.environ.get(WAIT_POLICY_VARIABLE, "").strip().upper() == "PASSIVE" and _PASSIVE_AT_IMPORT


def default_threads() -> int:
    """Threads a batch uses when none is given: ``TWOLINK_PIN_THREADS`` if set; else, with
    the passive wait policy, every core this process may use (sleeping threads take no
    core from other work, and two threads beside other work still get more of the machine
    than one: measured at load 15 on 2 cores, 3.7–4.1 s against 4.9–5.4 s, with the same
    CPU time); with the active policy (the user's choice, or Pinocchio imported first) the
    cores other work leaves free, at least 1."""
    override = threads_override()
    if override is not None:
        return override
    cores = available_cores()
    if passive_wait():
        return cores
    return max(1, min(cores, round(cores - busy_cores())))


_PASSIVE_AT_IMPORT = set_passive_wait()  # on import: twolink_pin/__init__.py imports this module first
