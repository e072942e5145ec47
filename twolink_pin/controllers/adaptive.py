"""Slotine–Li adaptive control with the regressor from Pinocchio."""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import Any, ClassVar

import numpy as np

from twolink_pin.controllers.base import Controller
from twolink_pin.controllers.computed_torque import DEFAULT_LAMBDA, sliding_gain
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.controllers.matrix_gains import applied_form, applied_scalar
from twolink_pin.dynamics import Friction, regressor, smooth_sign
from twolink_pin.model import RobotModel

ADAPTATION_RATE = 5.0
"""α [1/s] of the robot-derived default adaptation gains (see :meth:`Adaptive.scaled_gains`)."""


@dataclass(frozen=True, eq=False)
class AdaptiveGains(Gains):
    r"""Gains of :class:`Adaptive` (report: $K = \operatorname{diag}(120, 120)$, $\gamma = (0.5, 0.15, 0.6)$).

    Attributes:
        k: Sliding gain $K$ [N·m·s/rad], an nv × nv matrix; default $\kappa M(q_0)$.
        gamma: The report's $\gamma_i$, one per estimated parameter; the adaptation gain is
            $\Gamma = \operatorname{diag}(1/\gamma_i)$. Default: see :meth:`Adaptive.scaled_gains`.
        lam: $\lambda$ [1/s] (not in the report; our default 5).
        initial_estimate: $\hat p(0)$ = ``initial_estimate`` × $p$ (report: 50 % underestimated).
    """

    k: Any = gain(None, per="joint", matrix=True, unit="N·m·s/rad", doc="sliding gain K")
    gamma: Any = gain(None, per="estimate", doc="γ_i, adaptation gain Γ = diag(1/γ_i)")
    lam: Any = gain(DEFAULT_LAMBDA, unit="1/s", doc="λ in s = ė + λ e")
    initial_estimate: Any = gain(0.5, bound="nonnegative", doc="p̂(0) = initial_estimate × p")


class Adaptive(Controller[AdaptiveGains]):
    r"""Slotine–Li adaptive control (report "Adaptive Controller"):

    $$\tau = Y(q, \dot q, \dot q_r, \ddot q_r)\,\hat p - K s, \qquad
    \dot{\hat p} = -\Gamma\, Y^\top s, \qquad \Gamma = \operatorname{diag}(1/\gamma_i)$$

    with $s$, $\dot q_r$ and $\ddot q_r$ as in :class:`ComputedTorque`, and
    $Y p = M(q)\,\ddot q_r + C(q, \dot q)\,\dot q_r + g(q)$: Pinocchio's joint-torque
    regressor, polarised to $w = \dot q_r \ne \dot q$, times the robot's parameter map.
    With $V = \tfrac12 s^\top M s + \tfrac12 \tilde p^\top \Gamma^{-1} \tilde p$ and
    $\tilde p = \hat p - p$, $\dot V = -s^\top K s \le 0$: $s \to 0$ (Barbalat), while
    $\tilde p$ converges only if the motion is persistently exciting. The state $z$ is
    $\hat p$. A subclass that also estimates friction (``estimates`` with ``"friction"``)
    appends $Y_f = [\operatorname{diag}(\dot q), \operatorname{diag}(\operatorname{sgn} \dot q)]$
    to $Y$: the law is the same (written with $Y_f$'s diagonal structure:
    $Y_f \hat f = \hat V \odot \dot q + \hat C \odot \operatorname{sgn} \dot q$ and
    $Y_f^\top s = (\dot q \odot s, \operatorname{sgn} \dot q \odot s)$). Slotine and Li,
    "On the adaptive control of robot manipulators", *Int. J. Robotics Research* 6(3),
    1987; *Applied Nonlinear Control*, chapter 9.
    """

    name = "adaptive"
    title = "Slotine–Li adaptive, p̂(0) = 0.5 p"
    Gains = AdaptiveGains
    estimates: ClassVar[tuple[str, ...]] = ("inertial",)

    def __init__(
        self,
        robot: RobotModel,
        gains: AdaptiveGains | None = None,
        *,
        model_parameters: np.ndarray | None = None,
        friction: Friction | None = None,
    ) -> None:
        if friction is None and robot.profile.friction is not None:
            friction = Friction(*robot.profile.friction)
        self.friction = friction
        """The friction the law believes (default: the robot profile's): its sign smoothing
        and the values the friction estimates start from."""
        super().__init__(robot, gains, model_parameters=model_parameters)
        # Derived once: the law below runs 10⁵ times per simulated minute.
        nv = robot.nv
        self._inertial = "inertial" in self.estimates
        self._friction = "friction" in self.estimates
        start = self.robot.parameter_map.size if self._inertial else 0
        # z's columns as index tuples made once: p̂, then V̂ and Ĉ per joint
        self._p_hat, self._v_hat, self._c_hat = (
            (slice(None), slice(0, start)),
            (slice(None), slice(start, start + nv)),
            (slice(None), slice(start + nv, start + 2 * nv)),
        )
        smoothing = 0.0 if friction is None else friction.smoothing
        self._sign = np.sign if smoothing == 0 else partial(smooth_sign, smoothing=smoothing)
        self._minus_k = applied_form(-np.asarray(self.gains.k))
        self._lam = applied_scalar(self.gains.lam)
        self._minus_rate = -1.0 / np.asarray(self.gains.gamma)

    def initial_state(self) -> np.ndarray:
        g = self.gains
        parts = []
        for kind in self.estimates:
            if kind == "inertial":
                parts.append(g.initial_estimate * self.believed_parameters())
            else:
                values = np.zeros(2 * self.robot.nv) if self.friction is None else self.friction.parameters
                parts.append(getattr(g, "friction_initial_estimate", 1.0) * values)
        if all(np.ndim(p) == 1 for p in parts):
            return np.concatenate(parts)
        rows = max(np.atleast_2d(p).shape[0] for p in parts)
        return np.concatenate(
            [np.broadcast_to(np.atleast_2d(p), (rows, np.shape(p)[-1])) for p in parts], axis=1
        )

    def scaled_gains(self) -> dict[str, Any]:
        """``K = κ M(q₀)`` and ``γ_i = G_ii / α``: ``G = Σ Yᵀ K⁻¹ Y`` over unit joint
        accelerations and gravity at 8 seeded configurations within the joint limits, so
        that each parameter alone adapts at about α (:data:`ADAPTATION_RATE`) under unit excitation."""
        k = sliding_gain(self.robot)
        return {"k": k, "gamma": _gram_diagonal(self, k) / ADAPTATION_RATE}

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        lam, v, z = self._lam, x.v, x.z
        lam_e, edot = lam * (x.q - x.q_des), v - x.v_des
        s = edot + lam_e
        tau = self._minus_k(s)
        if self._inertial:
            Y = terms.regressor(x.q, v, x.v_des - lam_e, x.a_des - lam * edot)
            tau = tau + np.matvec(Y, z[self._p_hat])
            projection = np.vecmat(s, Y)
        if self._friction:  # Y_f = [diag(q̇), diag(sgn q̇)]: element-wise terms
            sign = self._sign(v)
            tau = tau + z[self._v_hat] * v + z[self._c_hat] * sign
            friction = (v * s, sign * s)
            projection = np.concatenate((projection, *friction) if self._inertial else friction, 1)
        return LawOutput(tau, projection * self._minus_rate)


def _gram_diagonal(law: Adaptive, k: np.ndarray) -> np.ndarray:
    """``diag Σ Yᵀ K⁻¹ Y`` over unit accelerations (and gravity) at seeded configurations
    (``k``: K, (nv, nv), or its diagonal (nv,))."""
    k = np.asarray(k, dtype=float)
    diagonal = k if k.ndim == 1 else (np.diag(k) if not np.any(k - np.diag(np.diag(k))) else None)
    model = law.robot.model
    data = model.createData()
    nv = model.nv
    lower = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -np.pi)
    upper = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, np.pi)
    rng = np.random.default_rng(0)
    P = law.robot.parameter_map.matrix
    total = np.zeros(law.state_size)
    zero = np.zeros(nv)
    for _ in range(8):
        q = rng.uniform(np.maximum(lower, -np.pi), np.minimum(upper, np.pi))
        for a in [*np.eye(nv), zero]:
            columns = []
            if "inertial" in law.estimates:
                columns.append(regressor(model, data, q, zero, zero, a) @ P)
            if "friction" in law.estimates:
                columns.append(np.hstack([np.eye(nv), np.eye(nv)]) if not a.any() else np.zeros((nv, 2 * nv)))
            Y = np.hstack(columns)
            weighted = Y * Y / diagonal[:, None] if diagonal is not None else Y * np.linalg.solve(k, Y)
            total += np.sum(weighted, axis=0)
    floor = 1e-9 * max(float(total.max()), 1e-300)
    return np.maximum(total, floor)
