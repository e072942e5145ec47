"""A corpus law that returns one torque too many: exit 1 naming the law and the expected shape."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin import Controller, Gains, LawInput, LawOutput, Terms, gain


@dataclass(frozen=True, eq=False)
class WrongShapeGains(Gains):
    """Gains of :class:`WrongShape`."""

    kp: Any = gain(100.0, unit="N·m/rad", doc="stiffness")


class WrongShape(Controller):
    """``τ`` of shape (N, nv + 1)."""

    name = "corpus-wrong-shape"
    title = "one torque too many"
    Gains = WrongShapeGains

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        tau = -self.gains.kp * (x.q - x.q_des)
        return LawOutput(np.concatenate([tau, tau[:, :1]], axis=1))
