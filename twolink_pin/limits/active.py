"""Where a motion rides its limits: the stretches of time each limit of each joint is active.

A time-optimal motion is, at every instant, on at least one limit (else it could go faster);
a designer wants to know which one, and where: "effort of joint 2 from 0.00 to 0.08 s,
velocity of joint 1 from 0.21 to 0.30 s". :func:`active_limits` reads that off a sampled
motion: a limit is active at a sample when the quantity is within ``tolerance`` (a fraction
of the limit; of the range for the position) of its bound, and consecutive active samples
make one stretch.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from twolink_pin.limits.joint_limits import JointLimits
from twolink_pin.limits.kinds import KINDS, POSITION, LimitKind, Motion

ACTIVE_TOLERANCE = 0.01
"""A limit is active where the quantity is within this fraction of it."""
GAP = 0.02
"""Two stretches of one limit closer than this fraction of the duration are one."""


class ActiveLimit(NamedTuple):
    """One stretch of time during which one limit of one joint is active."""

    kind: LimitKind
    """The kind of limit."""
    joint: int
    """The joint, 0-based."""
    joint_name: str
    """Its name in the model."""
    start: float
    """First active sample [s]."""
    end: float
    """Last active sample [s]."""

    def describe(self) -> str:
        """``effort of joint 2 (joint2): 0.000–0.081 s``."""
        return f"{self.kind.name} of joint {self.joint + 1} ({self.joint_name}): {self.start:.3f}–{self.end:.3f} s"

    def summary(self) -> dict[str, object]:
        """JSON-ready."""
        return {
            "kind": self.kind.name,
            "joint": self.joint + 1,
            "name": self.joint_name,
            "start": self.start,
            "end": self.end,
        }


def _closeness(kind: LimitKind, values: np.ndarray, limits: JointLimits) -> np.ndarray:
    """How close each value is to its bound, as a fraction (0 on the bound, negative beyond),
    ``inf`` for a joint without the limit; shape (K, nv)."""
    lower, upper = limits.bounds(kind)
    excess = limits.excess(kind, values)  # -distance inside, +beyond
    if kind is POSITION:
        scale = np.where(np.isfinite(upper - lower), upper - lower, np.inf)
    else:
        scale = upper
    with np.errstate(invalid="ignore", divide="ignore"):
        out = -excess / scale
    return np.where(np.isfinite(out), out, np.inf)


def active_limits(
    motion: Motion, limits: JointLimits, tolerance: float = ACTIVE_TOLERANCE, gap: float = GAP
) -> tuple[ActiveLimit, ...]:
    """The stretches of ``motion`` during which a limit is within ``tolerance`` of its bound
    (module docstring), two stretches of one limit less than ``gap`` of the motion's duration
    apart counted as one, in time order (kinds and joints as :data:`~twolink_pin.limits.kinds.KINDS`
    and the joints order them at a tie)."""
    found: list[ActiveLimit] = []
    span = float(motion.t[-1] - motion.t[0]) if motion.t.size else 0.0
    for kind in KINDS:
        values = kind.of(motion)
        if values is None:
            continue
        active = _closeness(kind, values, limits) <= tolerance
        for j in range(values.shape[1]):
            on = active[:, j].astype(np.int8)
            edges = np.diff(np.concatenate([[0], on, [0]]))
            stretches: list[list[float]] = []
            for first, last in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1, strict=True):
                start, end = float(motion.t[first]), float(motion.t[last])
                if stretches and start - stretches[-1][1] < gap * span:
                    stretches[-1][1] = end
                else:
                    stretches.append([start, end])
            found += [ActiveLimit(kind, j, limits.joint_names[j], a, b) for a, b in stretches]
    return tuple(sorted(found, key=lambda a: (a.start, KINDS.index(a.kind), a.joint)))


__all__ = ["ACTIVE_TOLERANCE", "GAP", "ActiveLimit", "active_limits"]
