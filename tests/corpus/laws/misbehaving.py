"""Corpus laws that misbehave as user code can: each must end the run with an error naming
the law (exit 1, nothing written), never a changed simulation, a silent exit or a hang.

Which misbehaviour a law shows is its class; each tracks with ``τ = −kp e`` until it acts.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin import Controller, Gains, LawInput, LawOutput, Terms, gain


@dataclass(frozen=True, eq=False)
class MisGains(Gains):
    """Gains of the misbehaving laws."""

    kp: Any = gain(100.0, unit="N·m/rad", doc="stiffness")


class _Base(Controller):
    title = "misbehaves"
    Gains = MisGains

    def act(self, x: LawInput) -> None:
        """The misbehaviour (at t > 0.01 s)."""

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        if x.t > 0.01:
            self.act(x)
        return LawOutput(-self.gains.kp * (x.q - x.q_des))


class ExitZero(_Base):
    """``sys.exit(0)`` in ``compute``: must not look like success."""

    name = "corpus-exit-zero"

    def act(self, x: LawInput) -> None:
        sys.exit(0)


class ExitThree(_Base):
    """``sys.exit(3)`` in ``compute``."""

    name = "corpus-exit-three"

    def act(self, x: LawInput) -> None:
        sys.exit(3)


class WritesState(_Base):
    """Writes into its input state ``x.q``."""

    name = "corpus-writes-state"

    def act(self, x: LawInput) -> None:
        x.q[...] = 0.0


class WritesReference(_Base):
    """Adds to the reference ``x.q_des`` (shared with later steps) in place."""

    name = "corpus-writes-reference"

    def act(self, x: LawInput) -> None:
        np.add(x.q_des, 1.0, out=x.q_des)


class Hog(_Base):
    """Allocates far past memory (2^44 doubles: 128 TiB)."""

    name = "corpus-hog"

    def act(self, x: LawInput) -> None:
        np.ones(2**44)


class Sleeper(_Base):
    """Never returns (sleeps a day)."""

    name = "corpus-sleeper"

    def act(self, x: LawInput) -> None:
        time.sleep(86400)


class Spinner(_Base):
    """Never returns (a busy loop in Python)."""

    name = "corpus-spinner"

    def act(self, x: LawInput) -> None:
        while True:
            pass


class Printer(_Base):
    """Prints on every call (what a debugging user does)."""

    name = "corpus-printer"

    def act(self, x: LawInput) -> None:
        print("corpus-printer says hello", x.t)
