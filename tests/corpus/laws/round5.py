"""Corpus laws of issue 48's fifth hostile run: a hook besides ``compute`` that raises, a law
that ends the process with ``os._exit``, a law that ignores ``SIGALRM`` and then never
returns, a law that never returns with no ``--timeout`` given. Each tracks with
``τ = −kp e`` until it acts (at t > 0.01 s).
"""

from __future__ import annotations

import os
import signal
import time
from dataclasses import dataclass
from typing import Any

from twolink_pin import Controller, Gains, LawInput, LawOutput, Terms, gain


@dataclass(frozen=True, eq=False)
class Round5Gains(Gains):
    """Gains of the laws below."""

    kp: Any = gain(100.0, unit="N·m/rad", doc="stiffness")


class _Base(Controller):
    title = "misbehaves"
    Gains = Round5Gains

    def act(self, x: LawInput) -> None:
        """The misbehaviour (at t > 0.01 s)."""

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        if x.t > 0.01:
            self.act(x)
        return LawOutput(-self.gains.kp * (x.q - x.q_des))


class PeriodRaises(_Base):
    """Its ``update_period`` hook raises."""

    name = "corpus-period-raises"

    def update_period(self) -> float | None:
        raise RuntimeError("corpus: the period hook failed")


class ExitsHard(_Base):
    """``os._exit(0)`` in ``compute``: the process would end at once, with status 0."""

    name = "corpus-exits-hard"

    def act(self, x: LawInput) -> None:
        os._exit(0)


class IgnoresAlarm(_Base):
    """Ignores ``SIGALRM`` (what ``--timeout`` arms), then never returns."""

    name = "corpus-ignores-alarm"

    def act(self, x: LawInput) -> None:
        signal.signal(signal.SIGALRM, signal.SIG_IGN)
        time.sleep(86400)


class BlocksAlarm(_Base):
    """Blocks ``SIGALRM`` in the thread's mask, then never returns."""

    name = "corpus-blocks-alarm"

    def act(self, x: LawInput) -> None:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM})
        time.sleep(86400)
