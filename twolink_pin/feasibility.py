"""Torque feasibility of a desired trajectory against the motor limits.

The torque the trajectory demands is ``τ_d(t) = M(q_d) q̈_d + C(q_d, q̇_d) q̇_d + g(q_d)``,
computed by RNEA along one period and compared with the URDF's effort limits (the
report's Figure 6 check, 240 and 40 N·m for the twolink).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.trajectory import Trajectory


class TorqueCheck(NamedTuple):
    """Desired torques over one period and their margins against the motor limits."""

    t: np.ndarray
    """Sample times [s], shape (N,)."""
    tau: np.ndarray
    """Desired joint torques [N·m], shape (N, nv)."""
    peak: np.ndarray
    """Peak ``|τ_i|`` over the period [N·m], shape (nv,)."""
    peak_time: np.ndarray
    """Time of each peak [s], shape (nv,)."""
    limits: np.ndarray
    """Motor torque limits [N·m], shape (nv,)."""
    margin: np.ndarray
    """``limits − peak`` [N·m], shape (nv,); negative where a limit is exceeded."""
    within_limits: bool
    """Whether every joint stays within its limit."""

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


def check_torques(robot: RobotModel, trajectory: Trajectory, samples: int = 4001) -> TorqueCheck:
    """Inverse dynamics (RNEA) along one period of ``trajectory`` at ``samples`` instants."""
    if not (isinstance(samples, int) and samples >= 2):
        raise InvalidParameterError("samples", samples, "an integer >= 2")
    t = trajectory.t0 + np.linspace(0.0, trajectory.period, samples)
    ref = trajectory.sample(t)
    data = robot.create_data()
    tau = np.array([pin.rnea(robot.model, data, q, v, a) for q, v, a in zip(ref.q, ref.v, ref.a)])
    idx = np.argmax(np.abs(tau), axis=0)
    peak = np.abs(tau[idx, np.arange(tau.shape[1])])
    limits = np.asarray(robot.torque_limits, dtype=float)
    return TorqueCheck(t, tau, peak, t[idx], limits, limits - peak, bool(np.all(peak <= limits)))
