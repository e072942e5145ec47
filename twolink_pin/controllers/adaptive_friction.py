"""Slotine–Li adaptive control that also estimates joint friction."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin.controllers.adaptive import Adaptive, AdaptiveGains
from twolink_pin.controllers.gains import gain


@dataclass(frozen=True, eq=False)
class AdaptiveFrictionGains(AdaptiveGains):
    """Gains of :class:`AdaptiveFriction` (report: K = diag(90, 90),
    γ = (0.5, 0.15, 0.6, 1.7, 1.4, 2.5, 2.5) for p1, p2, p3, V1, V2, C1, C2).

    Attributes:
        k: Sliding gain ``K`` [N·m·s/rad], diagonal.
        gamma: ``γ`` per estimated parameter (inertial, then V and C per joint);
            ``Γ = diag(1/γ_i)``.
        lam: ``λ`` [1/s].
        initial_estimate: ``p̂(0) = initial_estimate × p``.
        friction_initial_estimate: Friction estimates start at this factor × the values
            the law believes (the report says only "close to their real values": 0.9).
    """

    friction_initial_estimate: Any = gain(0.9, bound="nonnegative", doc="f̂(0) = this × the believed friction")


class AdaptiveFriction(Adaptive):
    r"""Adaptive control with viscous and Coulomb friction in the regressor::

        τ = [Y  Y_f] (p̂, f̂) − K s,    d(p̂, f̂)/dt = −Γ [Y  Y_f]ᵀ s,
        Y_f(q̇) = [diag(q̇), diag(sgn q̇)],  f̂ = (V̂_1..V̂_n, Ĉ_1..Ĉ_n)

    for the plant ``M q̈ + C q̇ + g + V q̇ + C_c sgn(q̇) = τ`` (the law of :class:`Adaptive`
    with friction among its estimates). Its ``friction`` argument is the friction model it
    believes: the sign smoothing and the values ``f̂(0)`` is scaled from.
    """

    name = "adaptive-friction"
    title = "adaptive, friction estimated too"
    Gains = AdaptiveFrictionGains
    estimates = ("inertial", "friction")
