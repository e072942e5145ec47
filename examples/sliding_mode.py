"""A sliding-mode tracking controller with a boundary layer, written as a user would.

This file is the example of ``docs/writing_a_controller.md``: one class, its gains, the law
in the docstring and one method. Run it with::

    twolink-pin simulate examples/sliding_mode.py:SlidingMode
    twolink-pin sweep examples/sliding_mode.py:SlidingMode --samples 200 --param-error 0.3
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin import Controller, Gains, LawInput, LawOutput, Terms, gain
from twolink_pin.dynamics import joint_inertia


@dataclass(frozen=True, eq=False)
class SlidingModeGains(Gains):
    """Gains of :class:`SlidingMode`.

    Attributes:
        k: Linear sliding gain ``K`` [N·m·s/rad] per joint; default ``10 diag M(q₀)``.
        ks: Switching gain ``K_s`` [N·m] per joint; default ``2 diag M(q₀)`` in N·m.
        phi: Boundary-layer width ``φ`` [rad/s] of ``sat(s/φ)``.
        lam: ``λ`` [1/s] in ``s = ė + λ e``.
    """

    k: Any = gain(None, per="joint", unit="N·m·s/rad", doc="linear sliding gain K")
    ks: Any = gain(None, per="joint", unit="N·m", doc="switching gain K_s")
    phi: Any = gain(0.05, unit="rad/s", doc="boundary layer φ of sat(s/φ)")
    lam: Any = gain(5.0, unit="1/s", doc="λ in s = ė + λ e")


class SlidingMode(Controller):
    r"""Sliding-mode control with a boundary layer (Slotine & Li, *Applied Nonlinear
    Control*, 1991, §7.4)::

        τ = M̂(q) q̈_r + Ĉ(q, q̇) q̇_r + ĝ(q) − K s − K_s sat(s/φ),
        s = ė + λ e,  q̇_r = q̇_d − λ e,  q̈_r = q̈_d − λ ė,  sat(x) = clip(x, −1, 1)

    With the exact model it is Slotine–Li's law plus a switching term that, outside the
    layer ``|s_i| > φ``, makes ``sᵀ M ṡ <= −sᵀ K s − K_s |s|`` whatever a bounded model
    error ``|Δτ_i| < K_s,i``: the error reaches the layer in finite time and stays there.
    """

    name = "sliding-mode"
    title = "sliding mode with a boundary layer"
    Gains = SlidingModeGains

    def scaled_gains(self) -> dict[str, Any]:
        inertia = joint_inertia(self.robot.model, self.robot.home)  # diag M(home) [kg·m²]
        return {"k": 10.0 * inertia, "ks": 2.0 * inertia}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        e, edot = x.q - x.q_des, x.v - x.v_des
        s = edot + g.lam * e
        tau = terms.model(x.q, x.v, x.v_des - g.lam * e, x.a_des - g.lam * edot)
        return LawOutput(tau - g.k * s - g.ks * np.clip(s / g.phi, -1.0, 1.0))
