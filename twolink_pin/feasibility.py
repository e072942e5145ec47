"""Torque feasibility of a desired trajectory against the motor limits: the effort kind of
:func:`twolink_pin.limits.check_limits`, seen as the report's Figure 6 check; its verdict and
``within_limits`` answer for every kind of limit (one answer: a path whose torque is within its
limits but whose velocity is not is not feasible), ``within_effort_limits`` for the torque.

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
        """Whether every kind of limit holds on every joint (position, velocity, acceleration,
        effort: the one answer every command gives; :attr:`within_effort_limits` for the
        torque alone)."""
        return self.limits_check.within_limits

    @property
    def within_effort_limits(self) -> bool:
        """Whether every joint's torque stays within its effort limit."""
        return self._effort.within_limits

    def summary(self) -> dict[str, object]:
        """The check's JSON fields, as every command prints them: ``peak_torque`` [N·m],
        ``peak_time`` [s], ``torque_limits`` [N·m], ``margin`` [N·m], ``within_limits`` (every
        kind of limit) and ``within_effort_limits`` (the torque alone)."""
        return {
            "peak_torque": self.peak.tolist(),
            "peak_time": self.peak_time.tolist(),
            "torque_limits": self.limits.tolist(),
            "margin": self.margin.tolist(),
            "within_limits": self.within_limits,
            "within_effort_limits": self.within_effort_limits,
        }

    def _torque(self) -> str:
        """The tightest joint's peak torque against its limit, in words."""
        limited = np.isfinite(self.limits)
        if not limited.any():
            j = int(np.argmax(self.peak))
            return (
                f"no joint has an effort limit in the model; the largest peak is "
                f"|tau{j + 1}| = {self.peak[j]:.3g} N·m at t = {self.peak_time[j]:.3f} s"
            )
        ratio = np.where(limited, self.peak / np.where(limited, self.limits, 1.0), -1.0)
        j = int(np.argmax(ratio))
        return (
            f"peak |tau{j + 1}| = {self.peak[j]:.3g} N·m at t = {self.peak_time[j]:.3f} s "
            f"is {100 * ratio[j]:.1f}% of its {self.limits[j]:.4g} N·m limit"
        )

    def _beyond(self) -> list[str]:
        """Each limit other than the effort that a joint passes, in words."""
        names = self.limits_check.limits.joint_names
        out = []
        for kind in self.limits_check.kinds:
            if kind.kind.name == "effort":
                continue
            for j in np.flatnonzero(kind.margin < 0):
                unit = kind.kind.unit
                out.append(
                    f"the {kind.kind.name} limit of joint {j + 1} ({names[j]}): {kind.peak[j]:.4g} {unit} at "
                    f"t = {kind.time[j]:.3f} s against {kind.limit[j]:.4g} {unit}"
                )
        return out

    def verdict(self) -> str:
        """One line, the answer of :attr:`within_limits`: ``FEASIBLE`` when every kind of limit
        holds, ``NOT FEASIBLE`` otherwise; then the tightest joint's peak torque against its
        limit (a joint without an effort limit in its model has limit inf: "no limit") and each
        other limit a joint passes."""
        state = "FEASIBLE" if self.within_limits else "NOT FEASIBLE"
        beyond = self._beyond()
        tail = "" if not beyond else "; beyond " + "; ".join(beyond)
        return f"{state}: {self._torque()}{tail}"


def check_torques(robot: RobotModel, trajectory: Trajectory, samples: int | None = None) -> TorqueCheck:
    """Inverse dynamics (RNEA) along one period of ``trajectory`` against the effort limits:
    :func:`~twolink_pin.limits.check_limits`'s effort kind, on its grid (at least 4001
    instants, at most 1 ms apart) or at ``samples`` instants."""
    return TorqueCheck(check_limits(robot, trajectory, samples=samples))
