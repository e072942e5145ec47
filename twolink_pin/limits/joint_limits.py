"""A robot's joint limits, read once from its model and profile.

:func:`joint_limits` reads them: the position range, velocity and effort limits from the
URDF (as Pinocchio parsed them; a velocity or effort of 0 means "none", as the URDF
convention has it), the acceleration limits from the robot's profile (a URDF has no such
element). :class:`JointLimits` holds them as arrays, one value per joint, ``±inf`` where
there is none, and gives every user the same reading: the bounds of a kind, which joints
have one, the limits scaled for headroom, what a motion exceeds them by.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.arrays import readonly
from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits.kinds import KINDS, POSITION, LimitKind

if TYPE_CHECKING:
    from twolink_pin.model import RobotModel


@dataclass(frozen=True)
class JointLimits:
    """Every limit of every joint, ``±inf`` where the robot gives none.

    Attributes:
        joint_names: The joints, in the order of ``q``.
        position_lower: Lowest position [rad], shape (nv,); ``-inf``: none.
        position_upper: Highest position [rad], shape (nv,); ``inf``: none.
        velocity: ``|q̇| <=`` this [rad/s], shape (nv,); ``inf``: none.
        acceleration: ``|q̈| <=`` this [rad/s²], shape (nv,); ``inf``: none.
        effort: ``|τ| <=`` this [N·m], shape (nv,); ``inf``: none.
    """

    joint_names: tuple[str, ...]
    position_lower: np.ndarray = field(repr=False)
    position_upper: np.ndarray = field(repr=False)
    velocity: np.ndarray = field(repr=False)
    acceleration: np.ndarray = field(repr=False)
    effort: np.ndarray = field(repr=False)

    def __post_init__(self) -> None:
        nv = len(self.joint_names)
        for name in ("position_lower", "position_upper", "velocity", "acceleration", "effort"):
            try:
                value = np.array(getattr(self, name), dtype=float)
            except (TypeError, ValueError):
                raise InvalidParameterError(
                    name, getattr(self, name), f"{nv} numbers, one per joint"
                ) from None
            if value.shape != (nv,):
                raise InvalidParameterError(
                    name, f"shape {value.shape}", f"shape ({nv},): one value per joint"
                )
            object.__setattr__(self, name, readonly(value))
        for j, joint in enumerate(self.joint_names):
            lo, hi = float(self.position_lower[j]), float(self.position_upper[j])
            if math.isnan(lo) or math.isnan(hi) or lo > hi or lo == math.inf or hi == -math.inf:
                raise InvalidParameterError(
                    f"position range of joint '{joint}'", (lo, hi), "lower <= upper [rad], not NaN"
                )
            for kind in KINDS[1:]:
                limit = float(getattr(self, kind.name)[j])
                if not limit > 0:  # NaN, 0 and negative
                    raise InvalidParameterError(
                        f"{kind.name} limit of joint '{joint}'",
                        limit,
                        f"a {kind.name} limit > 0 {kind.unit} (inf for none)",
                    )

    @property
    def nv(self) -> int:
        """Number of joints."""
        return len(self.joint_names)

    def bounds(self, kind: LimitKind) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)`` of ``kind``, each shape (nv,), ``∓inf`` where there is none."""
        if kind is POSITION or kind.name == "position":
            return self.position_lower, self.position_upper
        limit = getattr(self, kind.name)
        return -limit, limit

    def given(self, kind: LimitKind) -> np.ndarray:
        """Which joints have a ``kind`` limit (a finite bound on either side), shape (nv,)."""
        lower, upper = self.bounds(kind)
        return np.isfinite(lower) | np.isfinite(upper)

    def require(self, kind: LimitKind, why: str) -> None:
        """Raise unless every joint has a ``kind`` limit.

        Raises:
            InvalidParameterError: naming the first joint without one and ``why`` it is needed.
        """
        missing = np.flatnonzero(~self.given(kind))
        if missing.size:
            j = int(missing[0])
            raise InvalidParameterError(
                f"{kind.name} limit of joint '{self.joint_names[j]}'",
                None,
                f"a {kind.name} limit [{kind.unit}] in the robot's model to {why} "
                f"(joints without one: {', '.join(self.joint_names[i] for i in missing)})",
            )

    def scaled(self, fraction: float) -> JointLimits:
        """The limits with velocity, acceleration and effort multiplied by ``fraction``
        (0 < fraction <= 1: headroom for feedback); the position range is kept.

        Raises:
            InvalidParameterError: ``fraction`` outside (0, 1].
        """
        if not (
            isinstance(fraction, (int, float))
            and not isinstance(fraction, bool)
            and math.isfinite(fraction)
            and 0 < fraction <= 1
        ):
            raise InvalidParameterError("limit scale", fraction, "a fraction 0 < F <= 1 of each limit")
        f = float(fraction)
        return JointLimits(
            self.joint_names,
            self.position_lower,
            self.position_upper,
            self.velocity * f,
            self.acceleration * f,
            self.effort * f,
        )

    def excess(self, kind: LimitKind, values: np.ndarray) -> np.ndarray:
        """How far each of ``values`` (shape (..., nv), the quantity ``kind`` bounds) lies
        beyond its bounds: positive beyond, negative inside (the distance to the nearer
        bound), ``-inf`` for a joint without a ``kind`` limit."""
        lower, upper = self.bounds(kind)
        with np.errstate(invalid="ignore"):
            out = np.maximum(values - upper, lower - values)
        return np.where(np.isnan(out), -np.inf, out)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: ``position_lower``, ``position_upper``, ``velocity``, ``effort`` (and
        ``acceleration`` when any joint has one), lists with ``None`` where there is none."""

        def finite(x: np.ndarray) -> list[float | None]:
            return [float(v) if math.isfinite(v) else None for v in x.tolist()]

        out: dict[str, Any] = {
            "position_lower": finite(self.position_lower),
            "position_upper": finite(self.position_upper),
            "velocity": finite(self.velocity),
            "effort": finite(self.effort),
        }
        if np.isfinite(self.acceleration).any():
            out["acceleration"] = finite(self.acceleration)
        return out

    @classmethod
    def from_mapping(cls, joint_names: tuple[str, ...], values: Mapping[str, Any]) -> JointLimits:
        """Limits from :meth:`as_dict`'s form (``None`` for none; absent acceleration: none)."""
        nv = len(joint_names)

        def column(key: str, fill: float) -> np.ndarray:
            raw = values.get(key)
            if raw is None:
                return np.full(nv, fill)
            return np.array([fill if x is None else x for x in raw], dtype=float)

        return cls(
            tuple(joint_names),
            column("position_lower", -np.inf),
            column("position_upper", np.inf),
            column("velocity", np.inf),
            column("acceleration", np.inf),
            column("effort", np.inf),
        )


def joint_limits(robot: RobotModel) -> JointLimits:
    """The limits of ``robot``: position range, velocity and effort from its URDF (a
    velocity or effort of 0, or a joint Pinocchio gives no range, is "none"), acceleration
    from its profile's ``acceleration_limits`` (none otherwise).

    Raises:
        InvalidParameterError: the profile's acceleration limits are not one value > 0 per joint.
    """
    model = robot.model
    nv = robot.nv
    names = tuple(str(model.names[j]) for j in range(1, model.njoints) for _ in range(model.nvs[j]))
    lower, upper = np.full(nv, -np.inf), np.full(nv, np.inf)
    for j in range(1, model.njoints):
        iq, iv = model.idx_qs[j], model.idx_vs[j]
        if model.nqs[j] == model.nvs[j]:  # revolute, prismatic: one coordinate per velocity
            lower[iv : iv + model.nvs[j]] = model.lowerPositionLimit[iq : iq + model.nqs[j]]
            upper[iv : iv + model.nvs[j]] = model.upperPositionLimit[iq : iq + model.nqs[j]]
    velocity = np.where(model.velocityLimit > 0, model.velocityLimit, np.inf)
    accel = robot.profile.acceleration_limits
    acceleration = np.full(nv, np.inf) if accel is None else np.array(accel, dtype=float)
    if acceleration.shape != (nv,):
        raise InvalidParameterError(
            f"{robot.name}: acceleration_limits", accel, f"{nv} values [rad/s²], one per joint"
        )
    return JointLimits(
        names, lower, upper, velocity, acceleration, np.asarray(robot.torque_limits, dtype=float)
    )
