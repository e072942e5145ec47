"""A corpus law whose robot-derived gains raise while the law is built (before any step)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin import Controller, Gains, LawInput, LawOutput, Terms, gain


@dataclass(frozen=True, eq=False)
class InitRaisesGains(Gains):
    """Gains of :class:`InitRaises`."""

    kp: Any = gain(None, per="joint", unit="N·m/rad", doc="stiffness, derived from the robot")


class InitRaises(Controller):
    """``τ = −kp e``; deriving ``kp`` raises ``ZeroDivisionError``."""

    name = "corpus-init-raises"
    title = "raises while deriving its gains"
    Gains = InitRaisesGains

    def scaled_gains(self) -> dict[str, Any]:
        return {"kp": 1.0 / 0.0}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        return LawOutput(-self.gains.kp * (x.q - x.q_des))
