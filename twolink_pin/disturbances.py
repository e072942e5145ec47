"""What the world does to the arm and to what its law measures: plain, frozen settings.

A :class:`~twolink_pin.plant.Plant` may carry any of them (all off by default; the course
report uses none):

* :class:`Wrench` — an external force and moment on a frame, world-aligned, over a time
  window;
* :class:`PayloadStep` — a point mass picked up at the end effector at a time (the law is
  not told: its model stays what it believed);
* :class:`SensorNoise` — Gaussian noise on the ``q`` and ``q̇`` the law sees (the plant
  moves on the true state), and on the force its sensor reads (a scene's contact), seeded,
  independent per run;
* ``delay`` (on the plant) — steps between a measurement and the torque it produces.

**Timing.** Events act on whole steps of the engine's grid ``t_k = k dt``: the wrench is
on during step k when ``start <= t_k < stop``, the payload is on from the first step with
``t_k >= time``; one noise sample per step is added at every RK4 stage of that step; with a
delay the law is sampled once per step (or per ``control_period``) and the torque applied
during step k is the one computed from the measurement at step ``k − delay`` (the first
computed torque before that). The law's own state advances with its own output, undelayed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.errors import InvalidParameterError

if TYPE_CHECKING:
    import pinocchio as pin


def _finite(
    name: str, value: Any, expected: str, *, positive: bool = False, nonnegative: bool = False
) -> float:
    if not (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)):
        raise InvalidParameterError(name, value, expected)
    if (positive and not value > 0) or (nonnegative and not value >= 0):
        raise InvalidParameterError(name, value, expected)
    return float(value)


@dataclass(frozen=True)
class Wrench:
    """An external wrench on a frame over ``[start, stop)``.

    Attributes:
        force: ``(Fx, Fy, Fz)`` [N] or ``(Fx, Fy, Fz, Mx, My, Mz)`` [N, N·m], in world axes,
            applied at the frame's origin.
        start: When it starts [s], >= 0.
        stop: When it stops [s], > start (``inf``: never).
        frame: The frame it acts on; None: the robot's end effector.
        scale: One factor per run of a batch (a sweep's drawn wrench, ``--wrench-scale``):
            run i feels ``scale[i] · force``; None: every run feels ``force``.
    """

    force: tuple[float, ...]
    start: float = 0.0
    stop: float = math.inf
    frame: str | None = None
    scale: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        try:
            values = tuple(float(x) for x in self.force)
        except (TypeError, ValueError):
            raise InvalidParameterError("wrench.force", self.force, "3 or 6 numbers [N, N·m]") from None
        if len(values) not in (3, 6) or not all(math.isfinite(x) for x in values):
            raise InvalidParameterError("wrench.force", self.force, "3 or 6 finite numbers [N, N·m]")
        object.__setattr__(self, "force", values + (0.0,) * (6 - len(values)))
        start = _finite("wrench.start", self.start, "a time >= 0 s", nonnegative=True)
        stop = self.stop
        if not (isinstance(stop, (int, float)) and not isinstance(stop, bool) and stop > start):
            raise InvalidParameterError("wrench.stop", stop, f"a time > start ({start:g} s)")
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "stop", float(stop))
        if self.frame is not None and not (isinstance(self.frame, str) and self.frame):
            raise InvalidParameterError("wrench.frame", self.frame, "a frame name or None (the end effector)")
        if self.scale is not None:
            try:
                scale = tuple(float(x) for x in self.scale)
            except (TypeError, ValueError):
                raise InvalidParameterError("wrench.scale", self.scale, "one finite factor per run") from None
            if not scale or not all(math.isfinite(x) for x in scale):
                raise InvalidParameterError("wrench.scale", self.scale, "one finite factor per run")
            object.__setattr__(self, "scale", scale)

    def active(self, t: float) -> bool:
        """Whether the wrench acts during the step that starts at ``t`` [s]."""
        return self.start <= t < self.stop

    def forces(self, runs: int) -> np.ndarray:
        """The wrench [N, N·m] each of ``runs`` runs feels: (6,), or (runs, 6) with ``scale``."""
        if self.scale is None:
            return np.array(self.force)
        if len(self.scale) != runs:
            raise InvalidParameterError("wrench.scale", f"{len(self.scale)} factors", f"one per run ({runs})")
        return np.outer(self.scale, self.force)


@dataclass(frozen=True)
class PayloadStep:
    """A point mass picked up at the end effector's origin.

    Attributes:
        mass: The payload [kg], > 0.
        time: When it is picked up [s], >= 0.
    """

    mass: float
    time: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "mass", _finite("payload_step.mass", self.mass, "a mass > 0 kg", positive=True)
        )
        object.__setattr__(
            self, "time", _finite("payload_step.time", self.time, "a time >= 0 s", nonnegative=True)
        )

    def model(self, model: pin.Model, frame_id: int) -> pin.Model:
        """A copy of ``model`` carrying the payload at frame ``frame_id``'s origin."""
        import pinocchio as pin

        out = model.copy()
        frame = out.frames[frame_id]
        point = pin.Inertia(self.mass, np.zeros(3), np.zeros((3, 3)))
        out.inertias[frame.parentJoint] = out.inertias[frame.parentJoint] + frame.placement.act(point)
        return out


@dataclass(frozen=True)
class SensorNoise:
    """Gaussian noise on what the law measures.

    Attributes:
        sigma_q: Standard deviation on each ``q`` [rad], >= 0.
        sigma_v: Standard deviation on each ``q̇`` [rad/s], >= 0.
        seed: Seed of the noise; run r of a batch draws from ``default_rng([seed, stream + r])``.
        stream: The first run's stream (a single run is run ``stream`` of a batch).
        sigma_f: Standard deviation on each force component [N] of the wrench the force sensor
            reads (a scene's contact, :mod:`twolink_pin.contact`; the moments are read exactly),
            >= 0; run r draws it from ``default_rng([seed, stream + r, 1])``.
    """

    sigma_q: float
    sigma_v: float = 0.0
    seed: int = 0
    stream: int = 0
    sigma_f: float = 0.0

    def __post_init__(self) -> None:
        expected = "a standard deviation >= 0 [rad or rad/s]"
        object.__setattr__(
            self, "sigma_q", _finite("sensor_noise.sigma_q", self.sigma_q, expected, nonnegative=True)
        )
        object.__setattr__(
            self, "sigma_v", _finite("sensor_noise.sigma_v", self.sigma_v, expected, nonnegative=True)
        )
        object.__setattr__(
            self,
            "sigma_f",
            _finite("sensor_noise.sigma_f", self.sigma_f, "a standard deviation >= 0 [N]", nonnegative=True),
        )
        for name in ("seed", "stream"):
            value = getattr(self, name)
            if not (isinstance(value, int) and not isinstance(value, bool) and value >= 0):
                raise InvalidParameterError(f"sensor_noise.{name}", value, "a whole number >= 0")

    def generators(self, runs: int) -> list[np.random.Generator]:
        """One generator per run of a batch of ``runs``."""
        return [np.random.default_rng([self.seed, self.stream + r]) for r in range(runs)]

    def force_generators(self, runs: int) -> list[np.random.Generator]:
        """One generator of the force sensor's noise per run of a batch of ``runs``."""
        return [np.random.default_rng([self.seed, self.stream + r, 1]) for r in range(runs)]


def check_delay(delay: Any) -> int:
    """``delay`` as a whole number of steps >= 0."""
    if not (isinstance(delay, int) and not isinstance(delay, bool) and 0 <= delay <= 100_000):
        raise InvalidParameterError("delay", delay, "a whole number of steps from 0 to 100000")
    return delay
