"""Joint friction: viscous plus Coulomb, which Pinocchio's algorithms do not model."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twolink_pin.errors import InvalidParameterError


@dataclass(frozen=True)
class Friction:
    """Joint friction ``f_i(q̇_i) = V_i q̇_i + C_i sgn(q̇_i)``.

    Attributes:
        viscous: ``V`` per joint [N·m·s/rad], >= 0.
        coulomb: ``C`` per joint [N·m], >= 0.
        smoothing: Velocity scale ε [rad/s] of the smooth sign ``tanh(q̇/ε)``; 0 (default)
            uses the exact sign, right with a fixed-step integrator. A positive ε lets an
            adaptive-step integrator pass through sticking without stalling.
    """

    viscous: tuple[float, ...]
    coulomb: tuple[float, ...]
    smoothing: float = 0.0

    def __post_init__(self) -> None:
        for name in ("viscous", "coulomb"):
            values = getattr(self, name)
            if isinstance(values, (str, bytes)) or not all(
                isinstance(x, (int, float, np.floating, np.integer)) and not isinstance(x, bool)
                for x in np.ravel(np.asarray(values, dtype=object))
            ):
                raise InvalidParameterError(name, values, "numbers >= 0, one per joint")
        if not isinstance(self.smoothing, (int, float)) or isinstance(self.smoothing, bool):
            raise InvalidParameterError("smoothing", self.smoothing, "a finite velocity >= 0 rad/s")
        if len(self.viscous) != len(self.coulomb):
            raise InvalidParameterError(
                "coulomb", self.coulomb, f"one value per joint, like viscous (length {len(self.viscous)})"
            )
        for name, values in (("viscous", self.viscous), ("coulomb", self.coulomb)):
            for x in values:
                if not (math.isfinite(x) and x >= 0):
                    raise InvalidParameterError(name, values, "finite values >= 0")
        if not (math.isfinite(self.smoothing) and self.smoothing >= 0):
            raise InvalidParameterError("smoothing", self.smoothing, "a finite velocity >= 0 rad/s")
        object.__setattr__(self, "viscous", tuple(float(x) for x in self.viscous))
        object.__setattr__(self, "coulomb", tuple(float(x) for x in self.coulomb))
        for name, values in (("_viscous", self.viscous), ("_coulomb", self.coulomb)):
            array = np.array(values, dtype=float)
            array.setflags(write=False)
            object.__setattr__(self, name, array)

    @property
    def parameters(self) -> np.ndarray:
        """``(V_1..V_n, C_1..C_n)``, matching :func:`friction_regressor`'s columns."""
        return np.array(self.viscous + self.coulomb)

    def torque(self, v: np.ndarray) -> np.ndarray:
        """Friction torque ``f(q̇)`` [N·m] at joint velocity ``v`` [rad/s]."""
        return self._viscous * v + self._coulomb * smooth_sign(v, self.smoothing)  # type: ignore[attr-defined]


def smooth_sign(v: np.ndarray, smoothing: float) -> np.ndarray:
    """``sgn(v)`` if ``smoothing == 0`` else ``tanh(v / smoothing)``."""
    return np.sign(v) if smoothing == 0 else np.tanh(v / smoothing)


def friction_regressor(v: np.ndarray, smoothing: float = 0.0) -> np.ndarray:
    """``[diag(q̇), diag(sgn q̇)]``: ``f(q̇) = Y_f (V, C)``.

    Args:
        v: Joint velocities [rad/s], shape (nv,) or one row per run (N, nv).
        smoothing: ε [rad/s] of ``tanh(q̇/ε)``; 0 for the exact sign.

    Returns:
        Shape (nv, 2 nv), or (N, nv, 2 nv) for batch input.
    """
    if not (isinstance(smoothing, (int, float)) and math.isfinite(smoothing) and smoothing >= 0):
        raise InvalidParameterError("smoothing", smoothing, "a finite velocity >= 0 rad/s")
    try:
        v = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError("v", v, "joint velocities [rad/s], shape (nv,) or (N, nv)") from None
    if v.ndim not in (1, 2) or v.shape[-1] == 0 or not np.all(np.isfinite(v)):
        raise InvalidParameterError(
            "v",
            v.tolist() if v.size <= 12 else f"shape {v.shape}",
            "finite joint velocities [rad/s], shape (nv,) or (N, nv)",
        )
    sign = smooth_sign(v, smoothing)
    nv = v.shape[-1]
    out = np.zeros((*v.shape, 2 * nv))
    j = np.arange(nv)
    out[..., j, j] = v
    out[..., j, nv + j] = sign
    return out
