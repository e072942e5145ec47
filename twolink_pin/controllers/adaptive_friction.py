"""Slotine–Li adaptive control that also estimates joint friction."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from twolink_pin.controllers.adaptive import Adaptive, AdaptiveGains
from twolink_pin.controllers.gains import gain


@dataclass(frozen=True, eq=False)
class AdaptiveFrictionGains(AdaptiveGains):
    r"""Gains of :class:`AdaptiveFriction` (report: $K = \operatorname{diag}(90, 90)$,
    $\gamma = (0.5, 0.15, 0.6, 1.7, 1.4, 2.5, 2.5)$ for $p_1, p_2, p_3, V_1, V_2, C_1, C_2$).

    Attributes:
        k: Sliding gain $K$ [N·m·s/rad], an nv × nv matrix; default $\kappa M(q_0)$.
        gamma: $\gamma_i$ per estimated parameter (inertial, then $V$ and $C$ per joint);
            $\Gamma = \operatorname{diag}(1/\gamma_i)$.
        lam: $\lambda$ [1/s].
        initial_estimate: $\hat p(0)$ = ``initial_estimate`` × $p$.
        friction_initial_estimate: Friction estimates start at this factor × the values
            the law believes (the report says only "close to their real values": 0.9).
    """

    friction_initial_estimate: Any = gain(0.9, bound="nonnegative", doc="f̂(0) = this × the believed friction")


class AdaptiveFriction(Adaptive):
    r"""Adaptive control with viscous and Coulomb friction in the regressor:

    $$\tau = \begin{bmatrix} Y & Y_f \end{bmatrix} \begin{bmatrix} \hat p \\ \hat f \end{bmatrix} - K s,
    \qquad \frac{d}{dt} \begin{bmatrix} \hat p \\ \hat f \end{bmatrix}
    = -\Gamma \begin{bmatrix} Y^\top \\ Y_f^\top \end{bmatrix} s$$

    $$Y_f(\dot q) = \begin{bmatrix} \operatorname{diag}(\dot q) & \operatorname{diag}(\operatorname{sgn} \dot q) \end{bmatrix},
    \qquad \hat f = (\hat V_1, \dots, \hat V_n, \hat C_1, \dots, \hat C_n)$$

    for the plant $M \ddot q + C \dot q + g + V \dot q + C_c \operatorname{sgn}(\dot q) = \tau$
    (the law of :class:`Adaptive` with friction among its estimates). Its ``friction``
    argument is the friction model it believes: the sign smoothing and the values
    $\hat f(0)$ is scaled from.
    """

    name = "adaptive-friction"
    title = "adaptive, friction estimated too"
    Gains = AdaptiveFrictionGains
    estimates = ("inertial", "friction")
