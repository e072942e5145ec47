"""Torque feasibility of a desired trajectory against the motor limits: the effort kind of
:func:`twolink_pin.limits.check_limits`, seen as the report's Figure 6 check.

The torque the trajectory demands is ``τ_d(t) = M(q_d) q̈_d + C(q_d, q̇_d) q̇_d + g(q_d)``,
computed by RNEA along one period and compared with the URDF's effort limits (240 and 40 N·m
for the twolink). The check itself — the grid, the torque, the peak, its time, the margin — is
:mod:`twolink_pin.limits.check`'s, defined once; :class:`TorqueCheck` is a view of its effort
kind with the names the report, the figures and ``trajectory`` have always used.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from twolink_pin.limits import EFFORT, LimitsCheck, check_limits

if TYPE_CHECKING:
    from twolink_pin.model import RobotModel
    from twolink_pin.trajectory import Trajectory


class TorqueCheck:
    """Desired torques over one period and their margins against the motor limits: a view
    of the effort kind of a :class:`~twolink_pin.limits.LimitsCheck`.

    Args:
        check: The limits check whose effort kind this shows (its motion carries a torque).
    """

    def __init__(self, check: LimitsCheck) -> None:
        if check.motion.tau is None:
            raise ValueError("a limits check without torques has no effort kind")
        self.limits_check = check
        self._effort = check.of(EFFORT.name)

    @property
    def t(self) -> np.ndarray:
        """Sample times [s], shape (N,)."""
        return self.limits_check.motion.t

    @property
    def tau(self) -> np.ndarray:
        """Desired joint torques [N·m], shape (N, nv)."""
        tau = self.limits_check.motion.tau
        assert tau is not None
        return tau

    @property
    def peak(self) -> np.ndarray:
        """Peak ``|τ_i|`` over the period [N·m], shape (nv,)."""
        return self._effort.peak

    @property
    def peak_time(self) -> np.ndarray:
        """Time of each peak [s], shape (nv,)."""
        return self._effort.time

    @property
    def limits(self) -> np.ndarray:
        """Motor torque limits [N·m], shape (nv,); inf where the model has none."""
        return self._effort.limit

    @property
    def margin(self) -> np.ndarray:
        """``limits − peak`` [N·m], shape (nv,); negative where a limit is exceeded."""
        return self._effort.margin

    @property
    def within_limits(self) -> bool:
        """Whether every joint stays within its limit."""
        return self._effort.within_limits

    def summary(self) -> dict[str, object]:
        """The check's JSON fields, as every command prints them: ``peak_torque`` [N·m],
        ``peak_time`` [s], ``torque_limits`` [N·m], ``margin`` [N·m], ``within_limits``."""
        return {
            "peak_torque": self.peak.tolist(),
            "peak_time": self.peak_time.tolist(),
            "torque_limits": self.limits.tolist(),
            "margin": self.margin.tolist(),
            "within_limits": self.within_limits,
        }

    def verdict(self) -> str:
        """One line: feasible or not, with the tightest joint's peak and limit (a joint
        without an effort limit in its model has limit inf: "no limit")."""
        state = "FEASIBLE" if self.within_limits else "NOT FEASIBLE"
        limited = np.isfinite(self.limits)
        if not limited.any():
            j = int(np.argmax(self.peak))
            return (
                f"{state}: no joint has an effort limit in the model; the largest peak is "
                f"|tau{j + 1}| = {self.peak[j]:.3g} N·m at t = {self.peak_time[j]:.3f} s"
            )
        ratio = np.where(limited, self.peak / np.where(limited, self.limits, 1.0), -1.0)
        j = int(np.argmax(ratio))
        return (
            f"{state}: peak |tau{j + 1}| = {self.peak[j]:.3g} N·m at t = {self.peak_time[j]:.3f} s "
            f"is {100 * ratio[j]:.1f}% of its {self.limits[j]:.4g} N·m limit"
        )


def check_torques(robot: RobotModel, trajectory: Trajectory, samples: int | None = None) -> TorqueCheck:
    """Inverse dynamics (RNEA) along one period of ``trajectory`` against the effort limits:
    :func:`~twolink_pin.limits.check_limits`'s effort kind, on its grid (at least 4001
    instants, at most 1 ms apart) or at ``samples`` instants."""
    return TorqueCheck(check_limits(robot, trajectory, samples=samples))
