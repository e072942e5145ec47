"""Slotine–Li "modified computed torque" control."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.controllers.base import Controller
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.controllers.matrix_gains import applied_form, applied_scalar
from twolink_pin.dynamics import joint_space_inertia
from twolink_pin.model import RobotModel

DEFAULT_LAMBDA = 5.0
"""λ [1/s]. The report never states its λ; 5 s⁻¹ is our documented default."""
SLIDING_RATE = 50.0
"""κ [1/s] of the robot-derived default ``K`` (:func:`sliding_gain`): at the home ``q₀`` every
mode of ``M ṡ + K s = 0`` decays at a rate between κ and :data:`MODE_SPREAD` × κ."""
MODE_SPREAD = 20.0
"""The fastest mode of the default ``K`` at home is at most this × κ (1000 1/s at κ = 50,
within RK4's 2785 1/s at 1 ms): the joint-wise design's spread, clipped (:func:`sliding_gain`)."""


@dataclass(frozen=True, eq=False)
class SlotineLiGains(Gains):
    r"""Gains of :class:`ComputedTorque` (report: $K = \operatorname{diag}(40, 50)$, equal to PD's $K_d$).

    Attributes:
        k: Sliding gain $K$ [N·m·s/rad], an nv × nv symmetric positive-definite matrix (a
            number, nv numbers for a diagonal, nv² row by row); default from $M(q_0)$, every
            mode at home between $\kappa$ and $20\kappa$ (:func:`sliding_gain`).
        lam: $\lambda$ [1/s] in $s = \dot e + \lambda e$ (not in the report; our default 5).
    """

    k: Any = gain(None, per="joint", matrix=True, unit="N·m·s/rad", doc="sliding gain K")
    lam: Any = gain(DEFAULT_LAMBDA, unit="1/s", doc="λ in s = ė + λ e")


class ComputedTorque(Controller[SlotineLiGains]):
    r"""Slotine–Li control with the exact model (report "Modified Computed Torque"):

    $$\tau = M(q)\,\ddot q_r + C(q, \dot q)\,\dot q_r + g(q) - K s$$

    with $e = q - q_d$, the sliding variable $s = \dot e + \lambda e$ and the reference
    $\dot q_r = \dot q_d - \lambda e$, $\ddot q_r = \ddot q_d - \lambda \dot e$.
    $V = \tfrac12 s^\top M s$ gives $\dot V = -s^\top K s$ (using that $\dot M - 2C$ is
    skew-symmetric), so $s \to 0$, and $e \to 0$ exponentially with rate $\lambda$ once on
    the surface $s = 0$. Slotine and Li, *Applied Nonlinear Control* (Prentice Hall,
    1991), chapter 9.
    """

    name = "computed-torque"
    title = "modified computed torque, Slotine–Li"
    Gains = SlotineLiGains

    def __init__(self, robot: RobotModel, gains: SlotineLiGains | None = None, **kwargs: Any) -> None:
        super().__init__(robot, gains, **kwargs)
        self._k, self._lam = applied_form(self.gains.k), applied_scalar(self.gains.lam)

    def scaled_gains(self) -> dict[str, Any]:
        return {"k": sliding_gain(self.robot)}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        lam = self._lam
        lam_e, edot = lam * (x.q - x.q_des), x.v - x.v_des
        tau = terms.model(x.q, x.v, x.v_des - lam_e, x.a_des - lam * edot)
        return LawOutput(tau - self._k(edot + lam_e))


def sliding_gain(robot: RobotModel) -> np.ndarray:
    r"""The default ``K`` [N·m·s/rad], (nv, nv), from the whole inertia ``M = M(q₀)`` at home.

    Each joint alone on its own inertia at rate κ is the joint-wise ``K₀ = κ diag M``; on a
    coupled arm its modes (the generalised eigenvalues ``κ w_i`` of ``(K₀, M)``, ``w_i`` with
    eigenvectors ``V``, ``Vᵀ M V = I``) spread both ways — up to 102 κ on the xArm7, whose light
    wrist then outruns RK4 at 1 ms. ``K = κ M V diag(clip(w, 1, c)) Vᵀ M`` keeps the joint-wise
    design where it lies in the band and moves the other modes to its edges: every mode of
    ``M ṡ + K s = 0`` at home between κ and ``c κ`` (:data:`MODE_SPREAD`), exactly. The band is
    not a single rate (``K = κ M``, every mode at κ) on purpose: a law with a model error
    (``robust``, the adaptive laws from ``p̂ = 0.5 p``) meets a torque error that is not
    inertial (gravity), and ``K = κ M`` is then soft along the arm's light directions — on the
    double pendulum ``robust`` tracked to 0.99 rad with it, to 0.02 rad with this ``K``.
    """
    import scipy.linalg  # here: importing the CLI stays light (tests/test_startup.py)

    M = joint_space_inertia(robot.model, robot.home)
    w, V = scipy.linalg.eigh(np.diag(np.diag(M)), M)
    MV = M @ V
    K = SLIDING_RATE * (MV * np.clip(w, 1.0, MODE_SPREAD)) @ MV.T
    return 0.5 * (K + K.T)
