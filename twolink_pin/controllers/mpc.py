"""Model-predictive control: a finite-horizon plan within the joint limits, replanned every period."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from twolink_pin.controllers.base import Controller, LawInput, LawOutput, StateVariable, Terms
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.dynamics import joint_inertia
from twolink_pin.errors import InvalidParameterError, OptimizationError
from twolink_pin.limits import joint_limits
from twolink_pin.model import RobotModel
from twolink_pin.optimal import solve_qp
from twolink_pin.optimal.horizon import Horizon, HorizonQPs, check_memory, knots_of

TRACKING_RATE = 20.0
"""ω [rad/s] of the default weights: ``W_q = ω² diag M̂(q₀)``, ``W_v = 2 ω diag M̂(q₀)`` — each
error weighed as the torque a critically damped PD at ω would ask for it."""
MAX_ITER = 200
"""Most ProxQP iterations of one replan: a QP this small (tens of variables) is solved in tens;
one that cannot hold is told apart at once instead of iterating for minutes."""
INFEASIBILITY_EPS = 1e-9
"""ProxQP's infeasibility tolerances: its default, 1e-4, declared feasible replans infeasible
after 10 iterations (a problem that cannot hold is still told apart by the closest feasible point)."""


@dataclass(frozen=True, eq=False)
class MPCGains(Gains):
    r"""Gains of :class:`ModelPredictive`.

    Attributes:
        horizon: $T$ [s], the length of the plan; default 0.2 s.
        knot_interval: $h$ [s] between the plan's knots ($K = T/h$ pieces of constant
            acceleration); default 0.025 s.
        replan_period: [s] between replans, a multiple of the simulation step; default 0.01 s.
        weight_q: $W_q$ per joint [N·m/rad]; default $\omega^2 \operatorname{diag} \hat M(q_0)$, ω = 20 rad/s.
        weight_v: $W_v$ per joint [N·m·s/rad]; default $2\omega \operatorname{diag} \hat M(q_0)$.
        weight_tau: $w_\tau$ (no unit), the weight of the torque's deviation from the reference's; default 1.
        kp, kd: the local feedback toward the plan between replans [1/s², 1/s]; default 400, 40.
        limit_scale: $f$, the fraction of the velocity, acceleration and effort limits the plan may
            use (headroom for the feedback; the position range is kept); default 0.95.
    """

    horizon: Any = gain(0.2, unit="s", multiple_of="knot_interval", doc="length T of the plan")
    knot_interval: Any = gain(0.025, unit="s", doc="time h between the plan's knots")
    replan_period: Any = gain(0.01, unit="s", doc="time between replans (a multiple of the step)")
    weight_q: Any = gain(None, per="joint", unit="N·m/rad", doc="weight W_q of the position error")
    weight_v: Any = gain(None, per="joint", unit="N·m·s/rad", doc="weight W_v of the velocity error")
    weight_tau: Any = gain(1.0, doc="weight w_τ of the torque's deviation from the reference's")
    kp: Any = gain(400.0, per="joint", unit="1/s²", doc="stiffness of the feedback toward the plan")
    kd: Any = gain(40.0, per="joint", unit="1/s", doc="damping of the feedback toward the plan")
    limit_scale: Any = gain(
        0.95, bound="fraction", doc="fraction f of the velocity, acceleration and effort limits planned with"
    )


ONE_VALUE = ("horizon", "knot_interval", "replan_period", "limit_scale")
"""Gains that shape the QP or the replanning instants: one value for every run."""


class ModelPredictive(Controller[MPCGains]):
    r"""Model-predictive control within the joint limits (real-time iteration).

    **Every replanning period** (at $t_r$) it plans the next $T$ seconds from the measured state
    on its **believed** model (``--model``): $K = T/h$ pieces of constant acceleration $a_k$,
    solving one QP (:mod:`twolink_pin.optimal.horizon`)

    $$\min_{a}\ h\sum_{k=1}^{K} \|W_q (q_k - q_{r,k})\|^2 + \|W_v(\dot q_k - \dot q_{r,k})\|^2
    + h\, w_\tau \sum_{k=0}^{K-1} \|\tau_k - \tau_{r,k}\|^2$$

    subject to $|\tau_k| \le f\tau_{max}$, $|a_k| \le f \ddot q_{max}$, $|\dot q_k| \le f \dot q_{max}$
    and $q_{min} \le q_k \le q_{max}$ (the state bounds from the first knot on), with
    $\tau_k = \hat{\mathrm{RNEA}}(q_k, \dot q_k, a_k)$ linearised on Pinocchio's RNEA derivatives
    at the previous plan shifted to $t_r$ (one QP per replan, not solved to convergence of the
    nonlinear problem: Diehl's real-time iteration); the QP's variable is the step from that plan.
    Every run's unconstrained minimiser first (one batched LAPACK solve for the N runs; where it
    meets every row it is the solution), else ProxQP, cold, at most :data:`MAX_ITER` iterations.

    **The reference over the horizon** is extrapolated from the sample at $t_r$ at constant
    acceleration, $q_r(t_r + s) = q_d + \dot q_d s + \tfrac12 \ddot q_d s^2$: a law sees the
    reference at its own instant only (the contract gives no preview). A short horizon keeps that
    close.

    **Between replans** it follows the plan $(q_p, \dot q_p, a_p)(t)$ with computed torque on the
    believed model, clipped to the effort limits ($f < 1$ leaves it the headroom):

    $$\tau = \operatorname{clip}\big(\hat M (a_p + K_p (q_p - q) + K_d(\dot q_p - \dot q))
    + \hat C \dot q + \hat g,\ \pm\tau_{max}\big)$$

    **State** $z$: the plan — its time $t_r$, the count of replans, the measured state it starts
    from and its accelerations $a_k$ ($2 + (2 + K) n_v$ numbers) — recorded like any state.
    **A batch of N runs** takes one derivatives call for all N plans, builds the N QPs as batched
    arrays and solves their unconstrained minimisers in one call; the runs where a row binds go
    to ProxQP one after the other. The runs never mix, so a batch equals its single runs. A QP whose rows cannot all hold, or a solver that stops short, ends
    that run at that time naming the row (:meth:`run_failure`): a single run fails (exit 1), a run
    of a batch or a sweep is flagged with the time and the text while the others go on.
    """

    name = "mpc"
    title = "model-predictive control within the joint limits"
    Gains = MPCGains

    def __init__(self, robot: RobotModel, gains: MPCGains | None = None, **kwargs: Any) -> None:
        super().__init__(robot, gains, **kwargs)
        g = cast(MPCGains, self.gains)
        for name in ONE_VALUE:
            if not isinstance(getattr(g, name), float):
                raise InvalidParameterError(
                    f"gains.{name}",
                    "one value per run",
                    f"one value of {name} for every run (it shapes the plan)",
                )
        self.limits = joint_limits(robot)
        """The robot's limits (unscaled: ``limit_scale`` scales them in the QP)."""
        knots = knots_of(g.horizon, g.knot_interval)
        check_memory(knots, g.knot_interval, self.limits, self.runs or 1, "horizon")
        self.horizon = Horizon(knots, g.knot_interval, self.limits, g.limit_scale)
        """The QP's structure: knots, integration matrices, labelled rows."""
        self._weights = self.horizon.weights(g.weight_q, g.weight_v, g.weight_tau)
        self._effort = np.where(np.isfinite(self.limits.effort), self.limits.effort, np.inf).reshape(1, -1)
        """``τ_max`` [N·m] per joint (inf where none), (1, nv): where :meth:`compute` clips
        (every constant of :meth:`compute` is (1, nv): numpy broadcasts (1, nv) against (N, nv)
        at a quarter of the cost of (nv,))."""
        self._lowest = -self._effort
        nv = robot.nv
        self._kp, self._kd = (
            np.broadcast_to(np.atleast_2d(k), (np.atleast_2d(k).shape[0], nv)).copy() for k in (g.kp, g.kd)
        )
        self._zeros: dict[tuple[int, ...], np.ndarray] = {}
        self._failures: dict[int, str] = {}  # run → why its replan failed (:meth:`run_failure`)
        s = self.horizon.interval * np.arange(self.horizon.knots + 1)[None, :, None]
        self._knot_times = (s, 0.5 * s * s)  # s and s²/2 [s, s²] at the knots, (1, K + 1, 1)
        K = self.horizon.knots
        self._columns = (
            slice(2, 2 + nv),
            slice(2 + nv, 2 + 2 * nv),
            [slice(2 + (2 + k) * nv, 2 + (3 + k) * nv) for k in range(K)],
        )  # the columns of q_0, q̇_0 and each a_k in z
        self._interval, self._per_interval, self._last = (
            self.horizon.interval,
            1 / self.horizon.interval,
            K - 1,
        )

    def scaled_gains(self) -> dict[str, Any]:
        inertia = joint_inertia(self.robot.model, self.robot.home)
        return {"weight_q": TRACKING_RATE**2 * inertia, "weight_v": 2 * TRACKING_RATE * inertia}

    # -- the state: the plan -------------------------------------------------------------

    def state_variables(self) -> tuple[StateVariable, ...]:
        nv, K = self.robot.nv, self.horizon.knots
        plan = [StateVariable("t_plan", "s", "plan"), StateVariable("replans", "", "plan")]
        plan += [StateVariable(f"q0_{j + 1}", "rad", "plan") for j in range(nv)]
        plan += [StateVariable(f"v0_{j + 1}", "rad/s", "plan") for j in range(nv)]
        plan += [StateVariable(f"a{k}_{j + 1}", "rad/s²", "plan") for k in range(K) for j in range(nv)]
        return (*super().state_variables(), *plan)

    def update_period(self) -> float | None:
        return float(cast(MPCGains, self.gains).replan_period)

    def _split(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``t_plan`` (N,), ``replans`` (N,) and the plan's accelerations ``a_k`` (N, K, nv)."""
        nv = self.robot.nv
        return z[:, 0], z[:, 1], z[:, 2 + 2 * nv :].reshape(z.shape[0], self.horizon.knots, nv)

    # -- the replan ----------------------------------------------------------------------

    def update(self, x: LawInput, terms: Terms) -> np.ndarray:
        qps, u_bar = self._problems(x, terms)
        step, inside = qps.unconstrained()
        at = f"the MPC replan at t = {x.t:.6g} s"
        given_up = ~(np.isfinite(x.q).all(1) & np.isfinite(x.v).all(1) & np.isfinite(x.z).all(1))
        failed = [int(i) for i in np.flatnonzero(given_up)]  # ended already: no QP
        for i in np.flatnonzero(~inside & ~given_up):  # a row binds: ProxQP, one run after the other
            what = at if len(inside) == 1 else f"{at} (run {i})"
            try:
                solution = solve_qp(
                    qps.qp(int(i)), what=what, max_iter=MAX_ITER, infeasibility_eps=INFEASIBILITY_EPS
                )
            except OptimizationError as exc:  # this run ends here (run_failure says why), the others go on
                self._failures.setdefault(int(i), str(exc))  # the first reason: what ended it
                failed.append(int(i))
                continue
            step[i] = solution.x
        u = u_bar + step.reshape(u_bar.shape)
        nv = x.q.shape[1]
        z = np.empty(x.z.shape)
        z[:, 0], z[:, 1] = x.t, x.z[:, 1] + 1
        z[:, 2 : 2 + nv], z[:, 2 + nv : 2 + 2 * nv], z[:, 2 + 2 * nv :] = x.q, x.v, u.reshape(u.shape[0], -1)
        z[failed, 2:] = np.nan
        return z

    def run_failure(self, run: int) -> str | None:
        return self._failures.get(run)

    def initial_state(self) -> np.ndarray:
        self._failures.clear()  # a new simulation: no run given up yet
        return super().initial_state()

    def problems(self, x: LawInput, terms: Terms) -> HorizonQPs:
        """The QPs of the runs at a replan (what :meth:`update` solves; e.g. to check its KKT
        conditions): over the step ``u − ū`` [rad/s²] from the shifted plan ``ū``, its rows
        labelled in ``self.horizon.labels``."""
        return self._problems(x, terms)[0]

    def _problems(self, x: LawInput, terms: Terms) -> tuple[HorizonQPs, np.ndarray]:
        hz = self.horizon
        K, h = hz.knots, hz.interval
        _, replans, plan = self._split(x.z)
        # the previous plan shifted to now (every run replans at the same instants): knot k of
        # the new plan starts in piece shifted[k] of the old one, the last one held
        since = x.t - float(x.z[:, 0].max())
        shifted = np.minimum(((since + h * np.arange(K)) / h + 1e-9).astype(int), K - 1)
        u_bar = plan[:, shifted]
        fresh = replans < 0.5  # no plan yet: the reference's acceleration
        u_bar[fresh] = x.a_des[0]
        s, half_s2 = self._knot_times
        a_des = x.a_des[:, None]
        reference = (
            x.q_des[:, None] + x.v_des[:, None] * s + a_des * half_s2,
            x.v_des[:, None] + a_des * s,
            a_des,
        )
        qb, vb = hz.rollout(x.q, x.v, u_bar)
        d = terms.inverse_dynamics_derivatives(qb[:, :K], vb[:, :K], u_bar)
        return hz.problems(x.q, x.v, u_bar, (qb, vb), d, reference, self._weights), u_bar

    # -- between replans: follow the plan ------------------------------------------------

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        z = x.z
        since = x.t - (
            z[0, 0] if z.shape[0] == 1 else z[:, 0].max()
        )  # every run replans at the same instants
        k = min(int(since * self._per_interval + 1e-9), self._last) if since > 0 else 0
        r = since - k * self._interval if since > 0 else 0.0
        q0, v0, a = self._columns
        qk, vk, ak = z[:, q0], z[:, v0], z[:, a[k]]
        if k:  # past the first piece (a replan period longer than a knot interval): knot k's state
            u = self._split(z)[2]
            qk = qk + (k * self._interval) * vk + np.matmul(self.horizon.sq[k], u)
            vk = vk + np.matmul(self.horizon.sv[k], u)
        accel = ak + self._kp * (qk + (vk + (0.5 * r) * ak) * r - x.q) + self._kd * (vk + ak * r - x.v)
        tau = np.minimum(terms.model(x.q, x.v, x.v, accel), self._effort)
        np.maximum(tau, self._lowest, out=tau)
        zeros = self._zeros.get(z.shape)
        if zeros is None:
            zeros = self._zeros[z.shape] = np.zeros(z.shape)
            zeros.setflags(write=False)
        return LawOutput(tau, zeros)
