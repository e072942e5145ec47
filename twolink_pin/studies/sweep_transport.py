"""A sweep's chunks on a Dask worker: the robot and the law shipped there (:class:`RobotSource`,
:class:`SweepJob`) and the task that runs a chunk (:func:`run_chunk_task`)."""

from __future__ import annotations

import contextlib
import hashlib
import json
import shutil
import tempfile
import threading
import uuid
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from twolink_pin.controllers import Controller
from twolink_pin.model import RobotModel
from twolink_pin.studies.cluster import ClusterError
from twolink_pin.studies.sweep_cases import SweepConfig
from twolink_pin.studies.sweep_rows import ChunkRows, PreparedSweep
from twolink_pin.trajectory import Trajectory

# -- on a worker -------------------------------------------------------------------------------------


def _robot_digest(robot: RobotModel) -> str:
    """A digest of everything of the robot a run's numbers depend on."""
    model = robot.model
    digest = hashlib.sha256()
    arrays = [robot.p, robot.torque_limits, robot.link_lengths, np.asarray(model.gravity.linear)]
    arrays += [np.asarray(inertia.toDynamicParameters()) for inertia in model.inertias]
    arrays += [np.asarray(placement.homogeneous) for placement in model.jointPlacements]
    for name in (
        "lowerPositionLimit",
        "upperPositionLimit",
        "effortLimit",
        "velocityLimit",
        "damping",
        "friction",
    ):
        arrays.append(np.asarray(getattr(model, name)))
    for array in arrays:
        digest.update(np.ascontiguousarray(array, dtype=float).tobytes())
    digest.update("\0".join([robot.name, *robot.parameter_map.names, str(robot.ee_frame_id)]).encode())
    return digest.hexdigest()


@dataclass(frozen=True)
class RobotSource:
    """How a worker rebuilds the client's robot (a :class:`RobotModel` does not pickle):
    its catalog name, or its URDF text when it is not a catalog robot, the payload, the
    end-effector frame — and a digest the rebuilt robot must match."""

    name: str
    """Catalog name or URDF file stem."""
    urdf: str | None
    """The URDF text (None for a catalog robot, which every worker has)."""
    payload: float
    """Point mass at the end effector [kg]."""
    ee_frame: str
    """End-effector frame name."""
    digest: str
    """:func:`_robot_digest` of the client's robot."""
    profile: str | None = None
    """The robot's profile file as text (None: the catalog's, or a plain URDF's generic one); its
    ``urdf`` key is pointed at the URDF text shipped beside it."""

    @classmethod
    def of(cls, robot: RobotModel) -> RobotSource:
        """The source of ``robot``."""
        from twolink_pin.model import catalog

        in_catalog = False
        if robot.name in catalog.CATALOG:
            with contextlib.suppress(Exception):
                own = catalog.resolve(robot.name)[0]
                in_catalog = own.exists() and Path(robot.urdf_path).samefile(own)
        text = None if in_catalog else (robot.urdf_text or Path(robot.urdf_path).read_text(encoding="utf-8"))
        file = robot.profile.file
        profile = None if in_catalog or file is None else Path(file).read_text(encoding="utf-8")
        return cls(robot.name, text, float(robot.payload), robot.ee_frame, _robot_digest(robot), profile)

    def load(self) -> RobotModel:
        """The robot, rebuilt here (a URDF into this process's :func:`_stored` files).

        Raises:
            ClusterError: the rebuilt robot differs from the client's.
        """
        from twolink_pin.model import load_robot

        source: str | Path = self.name
        if self.urdf is not None:
            source = _stored(f"{self.name}.urdf", self.urdf)
        if self.profile is not None and self.urdf is not None:  # the profile, its urdf the text shipped
            import tomllib

            data = tomllib.loads(self.profile)
            lines = [line for line in self.profile.splitlines() if not line.strip().startswith("urdf")]
            if "name" not in data:
                lines.insert(0, f"name = {json.dumps(self.name)}")
            lines.insert(0, f"urdf = {json.dumps(str(source))}")
            source = _stored(f"{self.name}.toml", "\n".join(lines) + "\n")
        robot = load_robot(source, payload=self.payload)
        if robot.ee_frame != self.ee_frame or _robot_digest(robot) != self.digest:
            robot = load_robot(source, payload=self.payload, ee_frame=self.ee_frame)
        if _robot_digest(robot) != self.digest:
            import socket

            raise ClusterError(
                f"worker on {socket.gethostname()}",
                f"its robot '{self.name}' differs from the client's (another URDF, example-robot-data or "
                "parameter map): the runs would not be the client's",
            )
        return robot


@dataclass(frozen=True)
class SweepJob:
    """Everything a worker needs to run chunks of one study (pickled into each task)."""

    token: str
    """Unique per sweep: the workers' cache key."""
    config: SweepConfig
    """The study."""
    law_class_name: str
    """The law's class name."""
    law_file: tuple[str, str] | None
    """``(file name, source)`` of a law loaded from a file (shipped: workers need not have it)."""
    robot: RobotSource
    """The arm."""
    trajectory: Trajectory
    """The reference."""
    record: bool
    """Keep trajectories."""
    threads: int
    """Threads of the batch engine per task."""

    @classmethod
    def of(
        cls,
        config: SweepConfig,
        law: type[Controller],
        robot: RobotModel,
        trajectory: Trajectory,
        record: bool,
    ) -> SweepJob:
        """A new sweep's job (a fresh token) of the study ``config`` of ``law`` on ``robot``."""
        return cls(
            uuid.uuid4().hex,
            config,
            law.__name__,
            law_source(law),
            RobotSource.of(robot),
            trajectory,
            record,
            config.threads or 1,
        )

    def prepare(self) -> PreparedSweep:
        """The shared part of the chunks, built on this worker."""
        from twolink_pin.controllers.loading import load_controller

        robot = self.robot.load()
        if self.law_file is not None:
            path = _stored(*self.law_file)
            cls = load_controller(f"{path}:{self.law_class_name}")
        else:
            cls = self.config.run.law_class()
        return PreparedSweep(self.config, cls, robot, self.trajectory, self.record)


_STORE: list[Path] = []


def _stored(name: str, text: str) -> Path:
    """``text`` as file ``name`` in this process's private folder (created on first use with
    mode 0700, removed at exit), one subfolder per content: the same law or URDF in a later
    sweep is the same path, so the module loaded then is reused (a law registers its name
    once per process: after editing a law's file, restart the workers or rename the law)."""
    if not _STORE:
        import atexit

        folder = Path(tempfile.mkdtemp(prefix="twolink-pin-worker-"))
        atexit.register(shutil.rmtree, folder, True)
        _STORE.append(folder)
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]
    path = _STORE[0] / digest / Path(name).name
    if not path.is_file():
        path.parent.mkdir(exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return path


_PREPARED: OrderedDict[str, PreparedSweep] = OrderedDict()
_PREPARED_LOCK = threading.Lock()
_PREPARED_KEEP = 4


def run_chunk_task(
    job: SweepJob, start: int, stop: int, progress: Callable[[int], None] | None = None
) -> ChunkRows:
    """The task of one chunk on a worker: :meth:`SweepJob.prepare` once per worker and
    sweep (cached), then the runs."""
    with _PREPARED_LOCK:
        prepared = _PREPARED.get(job.token)
        if prepared is None:
            prepared = job.prepare()
            _PREPARED[job.token] = prepared
            while len(_PREPARED) > _PREPARED_KEEP:
                _PREPARED.popitem(last=False)
    if progress is not None:
        progress(0)  # the runs start: the client's per-run bound (--timeout) counts from here
    return prepared.run(start, stop, job.threads, progress)


def law_source(cls: type[Controller]) -> tuple[str, str] | None:
    """``(file name, source)`` of a law loaded from a file, else None (an importable law)."""
    if not cls.__module__.startswith("twolink_pin_user_"):
        return None
    import inspect

    path = Path(inspect.getfile(cls))
    return path.name, path.read_text(encoding="utf-8")


def versions_text(env: Sequence[tuple[str, str]]) -> str:
    return ", ".join(f"{name} {version}" for name, version in env)
