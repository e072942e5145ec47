"""A corpus law whose torque becomes NaN once t > 0.05 s: exit 1 naming the law and the time, never a NaN result."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin import Controller, Gains, LawInput, LawOutput, Terms, gain


@dataclass(frozen=True, eq=False)
class NanTorqueGains(Gains):
    """Gains of :class:`NanTorque`."""

    kp: Any = gain(100.0, unit="N·m/rad", doc="stiffness")


class NanTorque(Controller):
    """``τ = −kp e`` until t = 0.05 s, then NaN."""

    name = "corpus-bad-torque"
    title = "torque turns non-finite at t > 0.05 s"
    Gains = NanTorqueGains

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        tau = -self.gains.kp * (x.q - x.q_des)
        return LawOutput(tau * np.nan if x.t > 0.05 else tau)
