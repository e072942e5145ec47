"""Computed torque that looks ahead: a law that asks the engine for the reference ahead of now.

This file is the preview example of ``docs/writing_a_controller.md``. A torque that reaches
the motor ``ℓ`` seconds late (a bus, a filter: ``--delay STEPS``) acts on the arm as it will
be then, toward the reference as it will be then. The law declares the one time it wants
the reference at, ``preview_times() = (ℓ,)``, and reads it from ``x.preview``::

    twolink-pin simulate examples/look_ahead.py:LookAhead --delay 10 --gain lead=0.01
    twolink-pin compare examples/look_ahead.py:LookAhead@lead=0.01 examples/look_ahead.py:LookAhead@lead=0 --delay 10
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin import Controller, Gains, LawInput, LawOutput, Terms, gain


@dataclass(frozen=True, eq=False)
class LookAheadGains(Gains):
    """Gains of :class:`LookAhead`.

    Attributes:
        kp: ``K_p`` [1/s²] per joint; default 100 (10 rad/s, critically damped with ``kd``).
        kd: ``K_d`` [1/s] per joint; default 20.
        lead: ``ℓ`` [s], how far ahead the law aims (the delay it makes up for); default 0.
    """

    kp: Any = gain(100.0, per="joint", unit="1/s²", doc="stiffness K_p")
    kd: Any = gain(20.0, per="joint", unit="1/s", doc="damping K_d")
    lead: Any = gain(0.0, unit="s", bound="nonnegative", doc="look-ahead ℓ: the delay it makes up for")


class LookAhead(Controller):
    r"""Computed torque toward the reference ``ℓ`` seconds ahead, from the state predicted there
    (the arm moving on at the reference's acceleration ``q̈_d(t)`` meanwhile)::

        q⁺ = q + ℓ q̇ + ½ ℓ² q̈_d(t),   q̇⁺ = q̇ + ℓ q̈_d(t)
        τ = M̂(q) (q̈_d(t + ℓ) + K_p (q_d(t + ℓ) − q⁺) + K_d (q̇_d(t + ℓ) − q̇⁺)) + Ĉ(q, q̇) q̇ + ĝ(q)

    With ``ℓ = 0`` it is computed torque; with ``ℓ`` the plant's delay its torque, applied at
    ``t + ℓ``, acts toward where the arm should then be from where it will then be.
    """

    name = "look-ahead"
    title = "computed torque toward the reference ahead"
    Gains = LookAheadGains

    def preview_times(self) -> tuple[float]:
        return (float(self.gains.lead),)  # one time ahead of now [s]: x.preview holds it

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        ahead = x.preview  # q, v, a of shape (1, P, nv): P = 1 here
        q_d, v_d, a_d = ahead.q[:, 0], ahead.v[:, 0], ahead.a[:, 0]
        lead = g.lead
        q_next = x.q + lead * x.v + (0.5 * lead * lead) * x.a_des  # where the arm will be at t + ℓ
        v_next = x.v + lead * x.a_des
        accel = a_d + g.kp * (q_d - q_next) + g.kd * (v_d - v_next)
        return LawOutput(terms.model(x.q, x.v, x.v, accel))
