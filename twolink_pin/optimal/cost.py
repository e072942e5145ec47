"""The cost of a trajectory problem (:mod:`twolink_pin.optimal.transcription`): its terms'
weights, and the reference its tracking terms compare with.

Integrals by Gauss–Legendre quadrature on every knot interval (the problem's ``cost_points``),
in seconds of physical time::

    f(x) = w_τ ∫ τᵀτ dt + w_q ∫ ‖q − q_ref‖² dt + w_v ∫ ‖q̇ − q̇_ref‖² dt + w_j ∫ ‖q⃛‖² dt + w_T Σ h_k

(``w_v`` with ``q̇_ref = 0`` is a velocity regulariser: ``∫ ‖q̇‖² dt``.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twolink_pin.errors import InvalidParameterError


@dataclass(frozen=True)
class Cost:
    """The weights of the cost (module docstring); zero: the term is absent.

    Attributes:
        effort: ``w_τ`` [1/(N²·m²·s)].
        position: ``w_q`` [1/(rad²·s)], with ``reference``.
        velocity: ``w_v`` [s/rad²], with ``reference``.
        jerk: ``w_j`` [s⁵/rad²].
        time: ``w_T`` [1/s] on the total duration (free durations only).
        reference: ``(q_ref, q̇_ref)`` at the problem's cost points, each (K, nv) [rad, rad/s].
    """

    effort: float = 0.0
    position: float = 0.0
    velocity: float = 0.0
    jerk: float = 0.0
    time: float = 0.0
    reference: tuple[np.ndarray, np.ndarray] | None = None

    def __post_init__(self) -> None:
        for name in ("effort", "position", "velocity", "jerk", "time"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and np.isfinite(value) and value >= 0):
                raise InvalidParameterError(f"cost weight {name}", value, "a finite weight >= 0")
        if (self.position > 0 or self.velocity > 0) and self.reference is None:
            raise InvalidParameterError(
                "cost reference", None, "(q_ref, v_ref) at the cost points for tracking"
            )


__all__ = ["Cost"]
