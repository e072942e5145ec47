"""What each inequality row of a trajectory problem is, in words (``the velocity limit of
joint 2 (joint2) at t = 0.31 s``), for the message of a QP whose rows cannot all hold."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from twolink_pin.limits import JointLimits, LimitKind
from twolink_pin.optimal.layout import SplineLayout


class LabelledProblem(Protocol):
    """What the labels read of a problem
    (:class:`~twolink_pin.optimal.transcription.TrajectoryProblem` has it)."""

    @property
    def layout(self) -> SplineLayout: ...
    @property
    def limits(self) -> JointLimits: ...
    @property
    def kinds(self) -> tuple[LimitKind, ...]: ...
    @property
    def hull(self) -> tuple[LimitKind, ...]: ...
    @property
    def min_duration(self) -> float: ...


class RowLabels(Sequence[str]):
    """The labels of a problem's inequality rows, made when one is read (a failed solve
    reads one; thousands of rows are built every iteration)."""

    def __init__(self, problem: LabelledProblem, times: np.ndarray) -> None:
        self.times = times
        self.names = problem.limits.joint_names
        self.blocks: list[tuple[str, np.ndarray]] = []
        for kind in problem.kinds:
            given = problem.limits.given(kind)
            if given.any():
                self.blocks.append((kind.name, np.flatnonzero(given)))
        self.hull: list[tuple[str, np.ndarray, int]] = []
        layout = problem.layout
        for kind in problem.hull:
            given = problem.limits.given(kind)
            if given.any():
                m = layout.basis.size - (kind.order or 0)
                self.hull.append((kind.name, np.flatnonzero(given), layout.segments * m))
        self.coefficients = layout.basis.size
        self.durations = problem.layout.segments if problem.layout.free_durations else 0
        self.min_duration = problem.min_duration

    def __len__(self) -> int:
        grid = sum(len(self.times) * joints.size for _, joints in self.blocks)
        return grid + sum(n * joints.size for _, joints, n in self.hull) + self.durations

    def __getitem__(self, i: int) -> str:  # type: ignore[override]
        for name, joints in self.blocks:
            n = len(self.times) * joints.size
            if i < n:
                k, j = divmod(i, joints.size)
                joint = int(joints[j])
                return f"the {name} limit of joint {joint + 1} ({self.names[joint]}) at t = {self.times[k]:.4g} s"
            i -= n
        for name, joints, count in self.hull:
            n = count * joints.size
            if i < n:
                k, j = divmod(i, joints.size)
                joint = int(joints[j])
                return f"the {name} limit of joint {joint + 1} ({self.names[joint]}) on its spline's coefficient {k}"
            i -= n
        return f"the duration of segment {i} >= {self.min_duration:g} s"


__all__ = ["LabelledProblem", "RowLabels"]
