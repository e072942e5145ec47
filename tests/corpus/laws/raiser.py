"""A corpus law that raises once t > 0.05 s: the run must end with exit 1 naming the law and the time."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin import Controller, Gains, LawInput, LawOutput, Terms, gain


@dataclass(frozen=True, eq=False)
class RaiserGains(Gains):
    """Gains of :class:`Raiser`."""

    kp: Any = gain(100.0, unit="N·m/rad", doc="stiffness")


class Raiser(Controller):
    """``τ = −kp e`` until t = 0.05 s, then ``RuntimeError``."""

    name = "corpus-raiser"
    title = "raises at t > 0.05 s"
    Gains = RaiserGains

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        if x.t > 0.05:
            raise RuntimeError("corpus boom")
        return LawOutput(-self.gains.kp * (x.q - x.q_des))
