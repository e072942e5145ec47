"""Contact metrics of a run against a surface: the force held, the impact, the contact's extent.

For a run whose plant has a scene (:mod:`twolink_pin.contact`), with ``f_n = −n·F`` [N] the
normal force the end effector pressed on the surface of normal ``n`` (the force reference's
surface, else the scene's first; ``F`` the contact wrench, as the sensor reads it without
noise), ``f_d`` the force reference [N] and ``t_c`` the first sample in contact (penetration > 0):

* ``force_rms_error``, ``force_max_error`` [N] — RMS (over the samples) and max of
  ``|f_n − f_d|`` from :data:`SETTLE` after the first contact (``t >= t_c + SETTLE``) to the end:
  the force held once the impact is over; NaN without a force reference (nothing to hold) or
  without contact;
* ``peak_impact_force`` [N] — max ``f_n`` within :data:`SETTLE` after the first contact;
* ``time_in_contact`` [s] — samples in contact × the step;
* ``max_penetration_mm`` [mm] — the deepest penetration into any surface;
* ``tangent_rms_mm`` [mm] — RMS of the end effector's position error along the surface
  ``|(I − n nᵀ)(p − p_d)|`` (``p_d`` the forward kinematics of the joint reference) over the
  same window as the force errors: how well the motion along the surface was held;
* ``first_contact`` [s] — ``t_c`` (NaN: never in contact).

One definition, as the joint and task metrics: :class:`RunningContactMetrics` takes blocks of N
runs' samples (an engine observer: the sweep's rows), :func:`contact_metrics` feeds it a
recorded run in one block; every table (``simulate``, ``compare``, ``sweep``, the report)
reads these.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from twolink_pin.contact.stability import contact_frame
from twolink_pin.frame_poses import frame_positions
from twolink_pin.model import RobotModel
from twolink_pin.plant import Plant
from twolink_pin.simulation.result import SimulationResult
from twolink_pin.trajectory import ForceReference, Trajectory

if TYPE_CHECKING:
    from twolink_pin.simulation import Samples

SETTLE = 0.5
"""Time [s] after the first contact when the force errors start to count (the impact's
transient before it: ``peak_impact_force``); the issue's "after 0.5 s in contact"."""
CONTACT_UNITS = {
    "force_rms_error": "N",
    "force_max_error": "N",
    "peak_impact_force": "N",
    "time_in_contact": "s",
    "max_penetration_mm": "mm",
    "tangent_rms_mm": "mm",
    "first_contact": "s",
}
"""Each contact metric (a field of :class:`ContactMetrics`) and its unit: the one list the tables read."""
CONTACT_TITLES = {
    "force_rms_error": "RMS force error",
    "force_max_error": "max force error",
    "peak_impact_force": "peak impact force",
    "time_in_contact": "time in contact",
    "max_penetration_mm": "max penetration",
    "tangent_rms_mm": "RMS position error along the surface",
    "first_contact": "first contact",
}
"""A short title of each contact metric."""


class ContactMetrics(NamedTuple):
    """Contact metrics (see the module docstring): floats for one run, arrays (N,) for a batch
    (NaN for diverged runs; :meth:`run` takes one)."""

    force_rms_error: Any
    """RMS of ``f_n − f_d`` from :data:`SETTLE` after the first contact [N]."""
    force_max_error: Any
    """max ``|f_n − f_d|`` over the same window [N]."""
    peak_impact_force: Any
    """max ``f_n`` within :data:`SETTLE` after the first contact [N]."""
    time_in_contact: Any
    """Time in contact [s]."""
    max_penetration_mm: Any
    """The deepest penetration [mm]."""
    tangent_rms_mm: Any
    """RMS of the position error along the surface over the force window [mm]."""
    first_contact: Any
    """Time of the first contact [s] (NaN: never)."""

    def as_dict(self) -> dict[str, Any]:
        """Plain floats (lists for a batch) by name (for JSON; NaN as null)."""
        return {k: _plain(v) for k, v in self._asdict().items()}

    def run(self, i: int) -> ContactMetrics:
        """Run ``i``'s metrics of a batch, as floats."""
        return ContactMetrics(*(float(np.asarray(v)[i]) for v in self))

    def text(self) -> tuple[str, ...]:
        """Each metric as printed (4 significant digits, "—" for NaN)."""
        return tuple("—" if not math.isfinite(float(v)) else f"{float(v):.4g}" for v in self)


def _plain(value: Any) -> Any:
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        return float(array) if math.isfinite(float(array)) else None
    return [float(x) if math.isfinite(x) else None for x in array.tolist()]


class RunningContactMetrics:
    """Running sums and maxima of N runs' contact, fed block by block (an engine observer, like
    :class:`~twolink_pin.metrics.RunningMetrics`).

    Args:
        robot: The arm (the touching frame's forward kinematics).
        runs: N.
        dt: Output grid spacing [s].
        normal: The outward normal of the surface the force is measured on, (3,).
        reference: The force reference (None: the force errors are NaN).
        frame: The touching frame's id (default: the end effector).
    """

    def __init__(
        self,
        robot: RobotModel,
        runs: int,
        dt: float,
        normal: np.ndarray,
        reference: ForceReference | None,
        frame: int | None = None,
    ) -> None:
        self.robot, self.dt = robot, dt
        self.frame = int(robot.ee_frame_id) if frame is None else frame
        self.normal = np.asarray(normal, dtype=float)
        self.reference = reference
        self.first = np.full(runs, np.nan)
        self.in_contact = np.zeros(runs, dtype=int)
        self.depth = np.zeros(runs)
        self.peak = np.zeros(runs)
        self.square = np.zeros(runs)
        self.worst = np.zeros(runs)
        self.tangent = np.zeros(runs)
        self.count = np.zeros(runs, dtype=int)

    def add(self, samples: Samples) -> None:
        """Add a block of samples (``wrench`` (B, N, 6), ``penetration`` (B, N), ``q`` (B, N, nv),
        ``q_des`` (B, 1, nv))."""
        if samples.wrench is None or samples.penetration is None:
            return
        t = np.asarray(samples.t, dtype=float)[:, None]
        force = -(np.asarray(samples.wrench)[..., :3] @ self.normal)  # f_n, (B, N)
        depth = np.asarray(samples.penetration)
        inside = depth > 0
        starts = np.isnan(self.first) & inside.any(axis=0)
        self.first[starts] = t[np.argmax(inside[:, starts], axis=0), 0]
        self.in_contact += inside.sum(axis=0)
        np.maximum(self.depth, np.nan_to_num(depth).max(axis=0), out=self.depth)
        impact = (t >= self.first) & (t <= self.first + SETTLE)  # NaN first: False
        np.maximum(self.peak, np.where(impact, force, 0.0).max(axis=0), out=self.peak)
        window = t >= self.first + SETTLE
        if not window.any():
            return
        self.count += window.sum(axis=0)
        if self.reference is not None:
            error = np.where(window, force - self.reference.sample(t), 0.0)
            self.square += (error * error).sum(axis=0)
            np.maximum(self.worst, np.abs(error).max(axis=0), out=self.worst)
        self.tangent += self._tangent_squares(samples, window)

    def _tangent_squares(self, samples: Samples, window: np.ndarray) -> np.ndarray:
        """Σ over the window's samples of ``|(I − n nᵀ)(p − p_d)|²`` [m²] per run."""
        rows = window.any(axis=1)
        q = np.asarray(samples.q, dtype=float)[rows]
        blocks, runs, nv = q.shape
        p = frame_positions(self.robot, np.nan_to_num(q.reshape(-1, nv)), self.frame).reshape(blocks, runs, 3)
        p_d = frame_positions(self.robot, np.asarray(samples.q_des, dtype=float)[rows, 0], self.frame)
        e = p - p_d[:, None]
        along = e - (e @ self.normal)[..., None] * self.normal
        return np.where(window[rows], np.sum(along * along, axis=2), 0.0).sum(axis=0)

    def result(self, dead: np.ndarray | None = None) -> ContactMetrics:
        """The metrics of the N runs, arrays (N,); runs ``dead`` (mask (N,)) are NaN."""
        with np.errstate(invalid="ignore", divide="ignore"):
            count = np.where(self.count > 0, self.count, np.nan)
            force = (
                np.sqrt(self.square / count) if self.reference is not None else np.full_like(count, np.nan)
            )
            worst = np.where(np.isnan(count), np.nan, self.worst) if self.reference is not None else force
            columns = [
                force,
                worst,
                np.where(np.isnan(self.first), np.nan, self.peak),
                self.in_contact * self.dt,
                1e3 * self.depth,
                1e3 * np.sqrt(self.tangent / count),
                self.first,
            ]
        out = []
        for column in columns:
            column = np.array(column, dtype=float)
            if dead is not None:
                column[dead] = np.nan
            column.setflags(write=False)
            out.append(column)
        return ContactMetrics(*out)


def contact_observer(
    plant: Plant, trajectory: Trajectory, runs: int, dt: float
) -> RunningContactMetrics | None:
    """The observer of ``runs`` runs of ``plant`` along ``trajectory`` (None without a scene)."""
    scene = plant.scene
    if scene is None:
        return None
    reference = trajectory.force_reference
    surface = scene.surfaces[scene.index(reference.surface) if reference is not None else 0]
    frame = contact_frame(plant.robot, scene)
    return RunningContactMetrics(plant.robot, runs, dt, surface.unit_normal, reference, frame)


def contact_metrics(
    result: SimulationResult, robot: RobotModel, frame: str | None = None
) -> ContactMetrics | None:
    """The contact metrics of ``result`` (a run on ``robot``; ``frame`` the touching frame, default
    the end effector): :class:`RunningContactMetrics` fed the recorded run in one block; None for a
    run without a scene."""
    from twolink_pin.simulation import Samples

    if result.wrench is None or result.penetration is None or result.contact_normal is None:
        return None
    reference = None
    if result.force_des is not None:  # the recorded reference, sampled where the run was
        reference = ForceReference(
            tuple(result.t.tolist()), tuple(np.maximum(result.force_des, 0.0).tolist())
        )
    fid = None if frame is None else int(robot.model.getFrameId(frame))
    running = RunningContactMetrics(robot, 1, result.dt, result.contact_normal, reference, fid)
    t = np.asarray(result.t)
    empty = np.zeros((len(t), 1, 0))
    q, q_des = np.asarray(result.q)[:, None], np.asarray(result.q_des)[:, None]
    running.add(
        Samples(
            0, t, q, empty, empty, empty, q_des, empty, empty,
            wrench=np.asarray(result.wrench)[:, None], penetration=np.asarray(result.penetration)[:, None],
        )
    )  # fmt: skip
    return running.result().run(0)


__all__ = [
    "CONTACT_TITLES",
    "CONTACT_UNITS",
    "SETTLE",
    "ContactMetrics",
    "RunningContactMetrics",
    "contact_metrics",
    "contact_observer",
]
