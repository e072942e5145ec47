"""A reference checked against every limit of the arm along one period.

:func:`reference_motion` samples one period of a trajectory on a fine grid and computes
the torque it demands by inverse dynamics (Pinocchio's RNEA, the robot's model with its
payload; plus a plant's friction when one is given); :func:`check_limits` compares each
kind of limit (:mod:`twolink_pin.limits.kinds`) with it, joint by joint: the peak, its
time, the limit, the margin.

**The grid**, one for every command, figure-less check and report that states a peak: at least
:data:`MIN_SAMPLES` instants over a period and no more than :data:`MAX_STEP` apart (1 ms: a
polynomial through via points a second apart changes by far less than its limits' margins
between two samples), at most :data:`MAX_SAMPLES`. A reference made of samples (a retimed or
optimal reference, a samples file: :class:`~twolink_pin.trajectory.sampled.SampledTrajectory`)
is checked on each interval between two of its samples at evenly spaced instants, both ends
included, as many per interval as those two rules ask: its samples are where its acceleration
jumps (a time-optimal retiming's switches), and its peaks are there — an even grid over the
period missed them (the retimed twolink's peak |τ|/limit 0.9969, 0.9984 where they are 0.99829,
0.99983), and an instant at a jump is taken from both sides.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, NamedTuple, Protocol

import numpy as np

from twolink_pin.dynamics.rigid_body import inverse_dynamics_rows
from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits.joint_limits import JointLimits, joint_limits
from twolink_pin.limits.kinds import KINDS, LimitKind, Motion

if TYPE_CHECKING:
    from twolink_pin.dynamics import Friction
    from twolink_pin.model import RobotModel


class PeriodicReference(Protocol):
    """What a check asks of a reference (a :class:`~twolink_pin.trajectory.Trajectory` is one;
    the limits sit below the trajectories and do not import them)."""

    t0: float
    """Start of the first period [s]."""
    period: float
    """Repetition period [s]."""

    def sample(self, t: np.ndarray) -> Any:
        """Desired ``q`` [rad], ``v`` [rad/s] and ``a`` [rad/s²] at the times ``t`` [s], each (N, nv)."""


MIN_SAMPLES = 4001
"""Fewest instants at which one period is checked."""
MAX_STEP = 1e-3
"""Largest time between two checked instants [s] (up to :data:`MAX_SAMPLES`)."""
MAX_SAMPLES = 200_001
"""Most instants of one check (a period of 200 s at 1 ms)."""


def check_grid(t0: float, period: float, samples: int | None = None) -> np.ndarray:
    """The instants [s] at which one period from ``t0`` is checked (see the module docstring),
    or ``samples`` evenly spaced ones, both ends included."""
    if samples is None:
        samples = min(MAX_SAMPLES, max(MIN_SAMPLES, math.ceil(period / MAX_STEP) + 1))
    if not (isinstance(samples, int) and not isinstance(samples, bool) and samples >= 2):
        raise InvalidParameterError("samples", samples, "an integer >= 2")
    return t0 + np.linspace(0.0, period, samples)


def per_interval(times: np.ndarray) -> int:
    """Instants per interval between two samples at ``times`` [s] (a time given twice: an
    acceleration jump, no interval) for the check grid's two rules (module docstring)."""
    steps = np.diff(np.asarray(times, dtype=float))
    steps = steps[steps > 0]
    wanted = max(math.ceil((MIN_SAMPLES - 1) / steps.size), math.ceil(float(steps.max()) / MAX_STEP))
    return max(1, min(wanted, (MAX_SAMPLES - 1) // steps.size))


def reference_motion(
    robot: RobotModel,
    trajectory: PeriodicReference,
    samples: int | None = None,
    friction: Friction | None = None,
) -> Motion:
    """One period of ``trajectory`` on the check grid (module docstring: a sampled reference's
    aligned on its samples; ``samples`` evenly spaced instants instead when given), with the
    torque it demands: ``τ = M(q) q̈ + C(q, q̇) q̇ + g(q)`` (RNEA on ``robot``'s model, payload
    included) ``+ f(q̇)`` with ``friction``."""
    dense = getattr(trajectory, "dense", None)
    if samples is None and dense is not None:
        t, ref = dense(per_interval(trajectory.times))  # type: ignore[attr-defined]
    else:
        t = check_grid(trajectory.t0, trajectory.period, samples)
        ref = trajectory.sample(t)
    tau = inverse_dynamics_rows(robot.model, ref.q, ref.v, ref.a)
    if friction is not None:
        tau = tau + friction.torque(ref.v)
    return Motion(t, ref.q, ref.v, ref.a, tau)


class KindCheck(NamedTuple):
    """One kind of limit along a motion, per joint (arrays of shape (nv,))."""

    kind: LimitKind
    """The kind checked."""
    peak: np.ndarray
    """The value nearest its bounds (or furthest beyond): ``max |x|`` for a symmetric
    kind, the position closest to its range's ends for the position [the kind's unit]."""
    time: np.ndarray
    """When the peak happens [s]."""
    limit: np.ndarray
    """The bound the peak is compared with (for the position: the nearer end of the
    range); ``inf`` for a joint without this limit."""
    margin: np.ndarray
    """How far inside its bounds the peak stays; negative beyond; ``inf`` without a limit."""

    @property
    def within_limits(self) -> bool:
        """Whether every joint stays within its bounds."""
        return bool(np.all(self.margin >= 0))

    def summary(self) -> dict[str, Any]:
        """JSON-ready: ``peak``, ``time``, ``limit``, ``margin`` (``None`` where a joint has
        no limit) and ``within_limits``."""

        def finite(x: np.ndarray) -> list[float | None]:
            return [float(v) if math.isfinite(v) else None for v in x.tolist()]

        return {
            "peak": self.peak.tolist(),
            "time": self.time.tolist(),
            "limit": finite(self.limit),
            "margin": finite(self.margin),
            "within_limits": self.within_limits,
        }


class LimitsCheck(NamedTuple):
    """Every kind of limit along a motion (:func:`check_limits`)."""

    motion: Motion
    """The motion checked."""
    limits: JointLimits
    """The limits it was checked against."""
    kinds: tuple[KindCheck, ...]
    """One check per kind the motion carries, in :data:`~twolink_pin.limits.kinds.KINDS` order."""

    @property
    def within_limits(self) -> bool:
        """Whether every kind holds on every joint."""
        return all(k.within_limits for k in self.kinds)

    def of(self, name: str) -> KindCheck:
        """The check of the kind called ``name``."""
        for k in self.kinds:
            if k.kind.name == name:
                return k
        raise KeyError(name)

    def summary(self) -> dict[str, Any]:
        """JSON-ready: one entry per kind (:meth:`KindCheck.summary`) and ``within_limits``."""
        out: dict[str, Any] = {k.kind.name: k.summary() for k in self.kinds}
        out["within_limits"] = self.within_limits
        return out


def check_motion(motion: Motion, limits: JointLimits) -> LimitsCheck:
    """Each kind of ``limits`` that ``motion`` carries, joint by joint."""
    checks = []
    for kind in KINDS:
        values = kind.of(motion)
        if values is None:
            continue
        given = limits.given(kind)
        lower, upper = limits.bounds(kind)
        idx = _worst_instants(values, lower, upper, given, kind.symmetric)
        cols = np.arange(values.shape[1])
        at = values[idx, cols]
        if kind.symmetric:
            peak, limit = np.abs(at), upper
        else:
            nearer_upper = (upper - at) <= (at - lower)
            peak, limit = at, np.where(nearer_upper, upper, lower)
        margin = np.where(given, -limits.excess(kind, at[None, :])[0], np.inf)
        checks.append(KindCheck(kind, peak, motion.t[idx], limit, margin))
    return LimitsCheck(motion, limits, tuple(checks))


class Shortfall(NamedTuple):
    """A limit far below what a motion needs (:func:`shortfall`)."""

    kind: KindCheck
    """The kind's check."""
    joint: int
    """The joint (from 0)."""
    ratio: float
    """What the motion needs over the limit."""

    def describe(self, names: tuple[str, ...] | list[str]) -> tuple[str, str, str]:
        """``(what, value, need)`` for :class:`~twolink_pin.errors.InvalidParameterError`:
        ``velocity limit of joint 2 (joint2)``, ``3.15e-300 rad/s``, ``the 4.57 rad/s …``."""
        k, j = self.kind, self.joint
        unit = k.kind.unit
        return (
            f"{k.kind.name} limit of joint {j + 1} ({names[j]})",
            f"{float(k.limit[j]):.4g} {unit}",
            f"{self.ratio:.3g} times less than the {float(k.peak[j]):.4g} {unit} the reference needs at its own "
            f"timing (t = {float(k.time[j]):.4g} s)",
        )


def shortfall(check: LimitsCheck, factor: Callable[[LimitKind], float]) -> Shortfall | None:
    """The velocity, acceleration or effort limit that ``check``'s motion needs most beyond,
    when it needs more than ``factor(kind)`` times it (None otherwise): a limit so far below
    what a reference needs that an optimisation's rows (each divided by its limit) would hold
    numbers of 1e300 and its solver fail without naming it."""
    worst: Shortfall | None = None
    for k in check.kinds:
        if not k.kind.symmetric:
            continue
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            ratio = np.where(np.isfinite(k.limit) & (k.limit > 0), k.peak / k.limit, 0.0)
        j = int(np.argmax(ratio))
        if ratio[j] > factor(k.kind) and (worst is None or ratio[j] > worst.ratio):
            worst = Shortfall(k, j, float(ratio[j]))
    return worst


def _worst_instants(
    values: np.ndarray, lower: np.ndarray, upper: np.ndarray, given: np.ndarray, symmetric: bool
) -> np.ndarray:
    """Each joint's instant nearest its limit (or furthest beyond): the largest ``|x|`` for a
    symmetric kind; the position nearest either end of its range; a joint without the limit
    its largest ``|x|``. Chosen on the values themselves, not on ``|x| − limit``: beside a limit
    of 1e300 that difference is −1e300 at every instant and its largest would be the first."""
    largest = np.argmax(np.abs(values), axis=0)
    if symmetric:
        return largest
    high, low = np.argmax(values, axis=0), np.argmin(values, axis=0)
    cols = np.arange(values.shape[1])
    to_upper, to_lower = upper - values[high, cols], values[low, cols] - lower
    nearer = np.where(to_upper < to_lower, high, np.where(to_lower < to_upper, low, largest))
    return np.where(given, nearer, largest)


def check_limits(
    robot: RobotModel,
    trajectory: PeriodicReference,
    *,
    samples: int | None = None,
    limits: JointLimits | None = None,
    friction: Friction | None = None,
) -> LimitsCheck:
    """``trajectory`` against every limit of ``robot`` along one period (module docstring:
    the grid), the torque by inverse dynamics (with ``friction`` when given).

    Args:
        robot: The arm (its model, payload included, gives the torque).
        trajectory: The reference.
        samples: Instants over the period (default: the check grid).
        limits: The limits (default :func:`~twolink_pin.limits.joint_limits` of ``robot``).
        friction: A plant's friction added to the torque.
    """
    motion = reference_motion(robot, trajectory, samples, friction)
    return check_motion(motion, joint_limits(robot) if limits is None else limits)
