"""The errors of a Dask cluster (:mod:`twolink_pin.studies.cluster`): one that cannot run
the work, and a task past its wall-clock bound. Imports no Dask."""

from __future__ import annotations

from twolink_pin.errors import TwolinkPinError


class ClusterError(TwolinkPinError):
    """A Dask cluster that cannot run the work: not installed, unreachable, without workers,
    a worker that differs from the client, or a task that keeps killing its workers.

    Attributes:
        address: The scheduler's address (or what was being started).
        reason: What went wrong and what to do.
    """

    _fields: tuple[str, ...] = ("address", "reason")

    def __init__(self, address: str, reason: str) -> None:
        self.address = address
        self.reason = reason
        super().__init__(f"Dask cluster {address}: {reason}")


class TaskTimeout(ClusterError):
    """A task that ran past its wall-clock bound (:meth:`DaskEngine.run`'s ``limit_s``).

    Attributes:
        index: The task's index among the items.
        seconds: The bound [s].
    """

    _fields = ("address", "name", "index", "seconds", "owned")

    def __init__(self, address: str, name: str, index: int, seconds: float, owned: bool) -> None:
        self.name = name
        self.index = index
        self.seconds = seconds
        self.owned = owned
        stop = (
            "its workers were stopped"
            if owned
            else "it was cancelled, but the worker thread running it cannot be stopped from here: restart that worker"
        )
        self.stopped = stop
        super().__init__(
            address, f"{name} {index} ran past its bound of {seconds:g} s of wall-clock time; {stop}"
        )


class WorkerKilled(ClusterError):
    """A task whose workers died while running it, more times in a row than Dask allows
    (``KilledWorker``): what it runs ended their processes (``os._exit``, a crash in C code,
    out of memory). The sweep names the law and the runs (:mod:`twolink_pin.studies.sweep`).

    Attributes:
        index: The task's index among the items.
        deaths: How many workers died running it.
        last: The address of the last one (its log says why).
    """

    _fields = ("address", "name", "index", "deaths", "last")

    def __init__(self, address: str, name: str, index: int, deaths: int, last: str) -> None:
        self.name, self.index, self.deaths, self.last = name, index, deaths, last
        super().__init__(
            address,
            f"{name} {index} killed {deaths} worker{'s' if deaths != 1 else ''} in a row (out of memory? a crash "
            f"in the law?); the last was {last}: see its log",
        )


__all__ = ["ClusterError", "TaskTimeout", "WorkerKilled"]
