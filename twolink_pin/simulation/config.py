"""Settings of a run: :class:`SimulationConfig` and the bounds the engine enforces."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.errors import InvalidParameterError

DIVERGENCE_LIMIT = 1.0e4
"""Largest |q| [rad], |q̇| [rad/s] or |z| accepted before a run is declared diverged."""
MAX_EVALUATIONS_PER_STEP = 200
"""Adaptive method: right-hand-side evaluations allowed per output interval before the
run is declared diverged (DOP853 needs about 12 per accepted step)."""
MAX_STEPS = 10_000_000
"""Cap on the number of fixed steps (duration / dt) of one run."""
MAX_RECORDED_VALUES = 50_000_000
"""Cap on the floats a recorded run holds, ``(steps + 1) × (6 nv + nz)`` per run (400 MB):
a longer run is refused before anything is allocated (a batch without recording is not
bounded by it: its memory is O(N))."""

METHODS = ("rk4", "adaptive")
"""Integrators: fixed-step RK4, or scipy's DOP853 with error control (single runs)."""


def _positive_finite(name: str, value: Any, unit: str) -> float:
    if not (
        isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and value > 0
    ):
        raise InvalidParameterError(name, value, f"a finite value > 0 {unit}".rstrip())
    return float(value)


def _offset(name: str, value: Any) -> float | tuple[float, ...] | None:
    if value is None:
        return None
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        if not math.isfinite(value):
            raise InvalidParameterError(name, value, "finite offsets (one value, or one per joint)")
        return float(value)
    try:
        values = tuple(float(x) for x in value)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, value, "finite offsets (one value, or one per joint)") from None
    if not values or not all(math.isfinite(x) for x in values):
        raise InvalidParameterError(name, value, "finite offsets (one value, or one per joint)")
    return values


@dataclass(frozen=True)
class SimulationConfig:
    """Settings of one run (defaults: the report's 30-s runs at 1 ms).

    Attributes:
        duration: Simulated time [s], > 0.
        dt: Step of RK4 and spacing of the output grid [s], > 0.
        method: ``"rk4"`` (fixed step) or ``"adaptive"`` (scipy ``solve_ivp``, DOP853).
        q0_offset: ``q(0) − q_d(0)`` [rad]: one value per joint or one for all; ``None``
            means the robot profile's default (the twolink: (0.1, −0.1)), else zeros.
        v0_offset: ``q̇(0) − q̇_d(0)`` [rad/s], same forms; ``None`` means zeros.
        rtol: Relative tolerance of the adaptive method.
        atol: Absolute tolerance of the adaptive method.
        control_period: Sampling period of the law [s], a whole multiple of ``dt``
            (``rk4`` only): τ and ż held over each period. ``None`` (default): the law
            is evaluated at every RK4 stage.
        check_step: Check before the run that the step is within the integrator's stability
            bound on the fastest mode of the start, and refuse it otherwise
            (:mod:`twolink_pin.simulation.step_check`); False (``--no-step-check``): run anyway.
    """

    duration: float = 30.0
    dt: float = 1.0e-3
    method: str = "rk4"
    q0_offset: float | tuple[float, ...] | None = None
    v0_offset: float | tuple[float, ...] | None = None
    rtol: float = 1.0e-9
    atol: float = 1.0e-11
    control_period: float | None = None
    check_step: bool = True

    def __post_init__(self) -> None:
        if not isinstance(self.check_step, bool):
            raise InvalidParameterError("check_step", self.check_step, "True or False")
        _positive_finite("duration", self.duration, "s")
        _positive_finite("dt", self.dt, "s")
        _positive_finite("rtol", self.rtol, "")
        _positive_finite("atol", self.atol, "")
        if self.dt > self.duration:
            raise InvalidParameterError("dt", self.dt, f"a step <= duration ({self.duration} s)")
        if self.duration / self.dt > MAX_STEPS:
            raise InvalidParameterError(
                "dt",
                self.dt,
                f"at most {MAX_STEPS} steps over {self.duration} s (dt >= {self.duration / MAX_STEPS:g} s)",
            )
        if self.method not in METHODS:
            raise InvalidParameterError("method", self.method, "'rk4' or 'adaptive'")
        object.__setattr__(self, "q0_offset", _offset("q0_offset", self.q0_offset))
        object.__setattr__(self, "v0_offset", _offset("v0_offset", self.v0_offset))
        period = self.control_period
        if period is not None:
            if self.method != "rk4":
                raise InvalidParameterError(
                    "control_period", period, "None with the adaptive method (sampled-data needs 'rk4')"
                )
            _positive_finite("control_period", period, "s")
            ratio = period / self.dt
            if round(ratio) < 1 or abs(ratio - round(ratio)) > 1e-9 * ratio or period > self.duration:
                raise InvalidParameterError(
                    "control_period",
                    period,
                    f"a whole multiple of dt = {self.dt:g} s, at most the duration {self.duration:g} s",
                )

    @property
    def hold_steps(self) -> int | None:
        """Steps per control period ``round(control_period / dt)``, or None (per-stage law)."""
        return None if self.control_period is None else round(self.control_period / self.dt)

    @property
    def steps(self) -> int:
        """Number of steps ``round(duration / dt)``."""
        return max(1, round(self.duration / self.dt))


def check_recorded_size(steps: int, nv: int, nz: int, runs: int = 1) -> None:
    """Raise unless a recorded run of ``steps`` steps fits :data:`MAX_RECORDED_VALUES`."""
    values = runs * (steps + 1) * (6 * nv + nz)
    if values > MAX_RECORDED_VALUES:
        raise InvalidParameterError(
            "steps",
            steps,
            f"at most {MAX_RECORDED_VALUES:.3g} recorded values (runs × (steps + 1) × (6 nv + nz)); this run needs "
            f"{values:.3g}: use a larger dt, a shorter duration, or simulate_batch without recording",
        )


def joint_offsets(name: str, value: float | tuple[float, ...] | None, default: Any, nv: int) -> np.ndarray:
    """``value`` (or ``default`` when None) as nv offsets: one value for all joints or one each."""
    chosen = default if value is None else value
    if chosen is None:
        return np.zeros(nv)
    array = (
        np.broadcast_to(np.asarray(chosen, dtype=float).reshape(()), (nv,))
        if np.size(chosen) == 1  # one value: a number, or a list of one (a profile's [0.1])
        else np.asarray(chosen, dtype=float)
    )
    if array.shape != (nv,):
        raise InvalidParameterError(
            name, tuple(np.atleast_1d(chosen).tolist()), f"one value, or {nv} values (one per joint)"
        )
    return np.array(array)


def initial_state(plant: Any, trajectory: Any, config: SimulationConfig) -> tuple[np.ndarray, np.ndarray]:
    """``q(0) = q_d(0) + q0_offset`` and ``q̇(0) = q̇_d(0) + v0_offset``, shape (nv,) each."""
    nv = plant.robot.nv
    ref0 = trajectory.sample(0.0)
    q0 = ref0.q + joint_offsets("q0_offset", config.q0_offset, plant.robot.profile.q0_offset, nv)
    v0 = ref0.v + joint_offsets("v0_offset", config.v0_offset, None, nv)
    return q0, v0
