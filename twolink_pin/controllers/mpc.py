"""Model-predictive control: a finite-horizon plan within the joint limits, replanned every period."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from twolink_pin.controllers.base import Controller, StateVariable
from twolink_pin.controllers.disturbance import DisturbanceObserver
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.controllers.relaxation import Relaxations, RunRelaxation
from twolink_pin.dynamics import joint_inertia
from twolink_pin.errors import InvalidParameterError, OptimizationError
from twolink_pin.limits import joint_limits
from twolink_pin.model import RobotModel
from twolink_pin.optimal import solve_qp
from twolink_pin.optimal.horizon import Horizon, HorizonQPs, check_memory, knots_of, whole_knots
from twolink_pin.optimal.relaxed import solve_relaxed

TRACKING_RATE = 60.0
"""ω [rad/s] of the default weights: ``W_q = ω² diag M̂(q₀)``, ``W_v = 2 ω diag M̂(q₀)`` — each
error weighed as the torque a critically damped PD at ω would ask for it (60 rad/s: a 20-%
model error on the retimed twolink is corrected before it grows; at 20 rad/s it lagged 3×)."""
FEEDBACK_RATE = 100.0
"""ω_fb [rad/s] of the default feedback toward the plan between replans, ``K_p = ω_fb²``,
``K_d = 2 ω_fb``: it holds the plan against what the plan did not foresee (an acceleration jump
of the reference inside a step, the model's error) for the 10 ms until the next replan."""
MAX_ITER = 200
"""Most ProxQP iterations of one replan: a QP this small (tens of variables) is solved in tens;
one that cannot hold is told apart at once instead of iterating for minutes."""
RELAXED_MAX_ITER = 1000
"""Most ProxQP iterations of a replan with its rows relaxed (more variables, a linear penalty)."""
RELAX_AFTER = 30
"""With ``on_infeasible = "relax"``, the ProxQP iterations a replan gets with its rows hard
before it is solved relaxed: the relaxed QP has the hard one's solution whenever that exists
(the penalty is exact), so this only spares the larger solve when the hard one converges."""
MAX_INNER = 20
"""Most of ProxQP's inner iterations per outer one (its default 1500): a QP that cannot hold,
its bounds at 1e12 (a damper of horizon 1e-12 s), spent 1300 per outer iteration and a second a
solve; a feasible one takes a few."""
INFEASIBILITY_EPS = 1e-9
"""ProxQP's infeasibility tolerances: its default, 1e-4, declared feasible replans infeasible
after 10 iterations (a problem that cannot hold is still told apart by the closest feasible point)."""
ACCEPT = 1e-6
"""A replan stopped at :data:`MAX_ITER` whose (equilibrated) primal and dual residuals are
both below this is accepted: the tolerance a plan needs (ProxQP is asked for 1e-9)."""
OBSERVER_RATE = 150.0
"""Default ω_o [rad/s] of the disturbance observer (2.5 × the tracking rate: it learns the
missing torque faster than the plan corrects the error it causes; a 20-% model error on the
retimed twolink changes that torque with every switch of the reference's acceleration)."""
LIMIT_SCALE = 0.998
"""Default ``f``: the plan may use 99.8 % of the velocity, acceleration and effort limits. The
0.2 % is what a reference at its limits needs: at an acceleration corner of the reference the
arm's velocity, integrated over a 1-ms step, overshoots the plan's by up to ``Δq̈ dt / 3``
(0.03 rad/s on the retimed twolink), and a plan at the limit would carry it past; 5 % headroom
(before) made the twolink's time-optimal path untrackable (it needs 99.7 % of a velocity limit)."""
PLAN_COLUMNS = 2
"""``t_plan`` and ``replans``: the entries of ``z`` before the plan's deviations."""


@dataclass(frozen=True, eq=False)
class MPCGains(Gains):
    r"""Gains of :class:`ModelPredictive`.

    Attributes:
        horizon: $T$ [s], the length of the plan, a whole number of knot intervals; default 0.2 s.
        knot_interval: $h$ [s] between the plan's knots ($K = T/h$ pieces of constant
            acceleration); default 0.025 s.
        replan_period: [s] between replans, a multiple of the simulation step; default 0.01 s.
        weight_q: $W_q$ per joint [N·m/rad]; default $\omega^2 \operatorname{diag} \hat M(q_0)$, ω = 60 rad/s.
        weight_v: $W_v$ per joint [N·m·s/rad]; default $2\omega \operatorname{diag} \hat M(q_0)$.
        weight_tau: $w_\tau$ (no unit), the weight of the torque's deviation from the reference's; default 1.
        kp, kd: the local feedback toward the plan between replans [1/s², 1/s]; default
            $\omega_{fb}^2$, $2\omega_{fb}$ with $\omega_{fb}$ = 100 rad/s (10 000, 200).
        limit_scale: $f$, the fraction of the velocity, acceleration and effort limits the plan may
            use (headroom for the feedback; the position range is kept); default 0.998
            (:data:`LIMIT_SCALE`).
        observer_rate: $\omega_o$ [rad/s] of the disturbance observer (0: none); default 150.
        reference_ahead: ``"preview"`` (the reference at the knots, from the engine) or
            ``"extrapolate"`` (from its sample at the replan, at constant acceleration).
        on_infeasible: ``"relax"`` (the position, velocity and acceleration rows give way, in
            that order, and the run goes on) or ``"fail"`` (the run ends, naming the row).
    """

    horizon: Any = gain(0.2, unit="s", doc="length T of the plan", multiple_of="knot_interval")
    knot_interval: Any = gain(0.025, unit="s", doc="time h between the plan's knots")
    replan_period: Any = gain(0.01, unit="s", doc="time between replans (a multiple of the step)")
    weight_q: Any = gain(None, per="joint", unit="N·m/rad", doc="weight W_q of the position error")
    weight_v: Any = gain(None, per="joint", unit="N·m·s/rad", doc="weight W_v of the velocity error")
    weight_tau: Any = gain(1.0, doc="weight w_τ of the torque's deviation from the reference's")
    kp: Any = gain(
        FEEDBACK_RATE**2, per="joint", unit="1/s²", doc="stiffness of the feedback toward the plan"
    )
    kd: Any = gain(2 * FEEDBACK_RATE, per="joint", unit="1/s", doc="damping of the feedback toward the plan")
    limit_scale: Any = gain(
        LIMIT_SCALE,
        bound="fraction",
        doc="fraction f of the velocity, acceleration and effort limits planned with",
    )
    observer_rate: Any = gain(
        OBSERVER_RATE, unit="rad/s", bound="nonnegative", doc="rate ω_o of the disturbance observer (0: none)"
    )
    reference_ahead: Any = gain(
        "preview",
        choices=("preview", "extrapolate"),
        doc="the reference over the horizon: previewed or extrapolated",
    )
    on_infeasible: Any = gain(
        "relax",
        choices=("relax", "fail"),
        doc="when the limits cannot all hold: relax them in order, or fail",
    )


ONE_VALUE = ("horizon", "knot_interval", "replan_period", "limit_scale")
"""Gains that shape the QP or the replanning instants: one value for every run."""


class HorizonRoundedWarning(UserWarning):
    """``mpc``'s horizon was not a whole number of knot intervals: it plans over the nearest."""


class ModelPredictive(Controller[MPCGains]):
    r"""Model-predictive control within the joint limits (real-time iteration), offset-free.

    **Every replanning period** (at $t_r$) it plans the next $T$ seconds from the measured state
    on its **believed** model (``--model``): the reference $q_r$ plus a deviation of $K = T/h$
    pieces of constant acceleration $\delta_k$, from the measured deviation
    $(q - q_r, \dot q - \dot q_r)(t_r)$, solving one QP (:mod:`twolink_pin.optimal.horizon`)

    $$\min_{\delta}\ h\sum_{k=1}^{K} \|W_q (q_k - q_{r,k})\|^2 + \|W_v(\dot q_k - \dot q_{r,k})\|^2
    + h\, w_\tau \sum_{k=0}^{K-1} \|\tau_k - \tau_{r,k}\|^2$$

    subject to $|\tau_k - \hat d| \le f\tau_{max}$, $|a_k| \le f \ddot q_{max}$,
    $|\dot q_k| \le f \dot q_{max}$ and $q_{min} \le q_k \le q_{max}$ (the state bounds from the
    first knot on), with $\tau_k = \hat{\mathrm{RNEA}}(q_k, \dot q_k, \ddot q_{r,k} + \delta_k)$
    linearised on Pinocchio's RNEA derivatives at the previous plan shifted to $t_r$ (one QP per
    replan: Diehl's real-time iteration); the QP's variable is the step from that plan. Every
    run's unconstrained minimiser first (one batched LAPACK solve for the N runs; where it meets
    every row it is the solution), else ProxQP on the equilibrated QP, cold, at most
    :data:`MAX_ITER` iterations.

    **The reference over the horizon** is the engine's preview of it at the knots
    (:meth:`preview_times`: $0, h, \ldots, K h$ ahead, :class:`~twolink_pin.controllers.ReferencePreview`):
    the plan sees a corner of the reference before it comes. With ``reference_ahead =
    "extrapolate"`` (or without a preview) it is extrapolated from the sample at $t_r$ at constant
    acceleration.

    **Offset-free** (Pannocchia & Rawlings 2003; Maeder, Borrelli & Morari 2009): a disturbance
    observer (:mod:`twolink_pin.controllers.disturbance`) estimates the torque $d$ the believed
    model misses ($\hat M \ddot q + \hat b = \tau + d$) from the gap between the velocity error
    it predicts and the one measured, with integral action,

    $$\dot{\hat e} = \hat M^{-1}(\tau - \hat b + \hat d) - \ddot q_d + 2\omega_o (\dot q - \dot q_d - \hat e),
    \qquad \dot{\hat d} = \omega_o^2 \hat M(q_0)(\dot q - \dot q_d - \hat e)$$

    (a constant $d$ is learnt exactly), and both the plan (its effort rows) and the torque below
    compensate it: a model 20 % wrong leaves no steady lag.

    **Between replans** it follows the plan $(q_p, \dot q_p, a_p)(t)$ — the reference at $t$ plus
    the planned deviation — with computed torque on the believed model, clipped to the effort
    limits ($f < 1$ leaves it the headroom):

    $$\tau = \operatorname{clip}\big(\hat M (a_p + K_p (q_p - q) + K_d(\dot q_p - \dot q))
    + \hat C \dot q + \hat g - \hat d,\ \pm\tau_{max}\big)$$

    **State** $z$: the plan — its time $t_r$, the count of replans, the measured deviation it
    starts from and its $\delta_k$ — then the observer's $\hat d$ and $\hat e$ ($2 + (4 + K) n_v$
    numbers), recorded like any state. **A batch of N runs** takes one derivatives call for all N
    plans and solves their unconstrained minimisers in one call; the runs where a row binds go to
    ProxQP one after the other. The runs never mix, so a batch equals its single runs.

    **When the rows cannot all hold** (``on_infeasible = "relax"``, the default) the effort rows
    stay hard and the position, velocity and acceleration rows give way, in that order, with an
    exact penalty (:mod:`twolink_pin.optimal.relaxed`); the run records where and by how much
    (:meth:`run_relaxations`) and goes on. With ``"fail"``, or when even that solve fails, the run
    ends at that time naming the row (:meth:`run_failure`): a single run fails (exit 1), a run of
    a batch or a sweep is flagged with the time and the text while the others go on.
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
        if not whole_knots(g.horizon, g.knot_interval):
            warnings.warn(
                f"mpc: horizon = {g.horizon:g} s is {g.horizon / g.knot_interval:.4g} knot intervals of "
                f"{g.knot_interval:g} s, not a whole number: it plans over {knots} knots = "
                f"{knots * g.knot_interval:g} s",
                HorizonRoundedWarning,
                stacklevel=2,
            )
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
        self._relax = g.on_infeasible == "relax"
        self._preview = g.reference_ahead == "preview"
        self._failures: dict[int, str] = {}  # run → why its replan failed (:meth:`run_failure`)
        self.relaxations = Relaxations(nv)
        """Where and by how much each run's replans relaxed rows (:meth:`run_relaxations`)."""
        K = self.horizon.knots
        self._offsets = self.horizon.times.copy()  # the row times: the knots and S − 1 between each
        self._offsets.setflags(write=False)
        s = self._offsets[None, :, None]
        self._row_times = (s, 0.5 * s * s)  # s and s²/2 [s, s²] at the row times, (1, K S + 1, 1)
        first = PLAN_COLUMNS + (2 + K) * nv
        self.observer = DisturbanceObserver(robot, self.believed_parameters(), g.observer_rate, first)
        """The estimate of the torque the model misses (its ``d̂``, ``ê`` follow the plan in ``z``)."""
        self._observing = self.observer.on
        self._columns = (
            slice(PLAN_COLUMNS, PLAN_COLUMNS + nv),
            slice(PLAN_COLUMNS + nv, PLAN_COLUMNS + 2 * nv),
            [slice(PLAN_COLUMNS + (2 + k) * nv, PLAN_COLUMNS + (3 + k) * nv) for k in range(K)],
            *self.observer.columns,
        )  # the columns of δq_0, δq̇_0, each δ_k, d̂ and ê in z
        self._interval, self._per_interval, self._last = (
            self.horizon.interval,
            1 / self.horizon.interval,
            K - 1,
        )
        self._zeros: dict[tuple[int, ...], np.ndarray] = {}

    def scaled_gains(self) -> dict[str, Any]:
        inertia = joint_inertia(self.robot.model, self.robot.home)
        return {"weight_q": TRACKING_RATE**2 * inertia, "weight_v": 2 * TRACKING_RATE * inertia}

    def preview_times(self) -> np.ndarray | None:
        """The QP's row times ``0, h/S, …, K h`` [s] ahead — the knots and the times between
        at which the state rows are checked (:class:`~twolink_pin.optimal.horizon.Horizon`);
        None when the gains say ``extrapolate``."""
        return self._offsets if self._preview else None

    # -- the state: the plan and the observer --------------------------------------------

    def state_variables(self) -> tuple[StateVariable, ...]:
        nv, K = self.robot.nv, self.horizon.knots
        plan = [StateVariable("t_plan", "s", "plan"), StateVariable("replans", "", "plan")]
        plan += [StateVariable(f"dq0_{j + 1}", "rad", "plan") for j in range(nv)]
        plan += [StateVariable(f"dv0_{j + 1}", "rad/s", "plan") for j in range(nv)]
        plan += [StateVariable(f"d{k}_{j + 1}", "rad/s²", "plan") for k in range(K) for j in range(nv)]
        plan += DisturbanceObserver.state_variables(nv)
        return (*super().state_variables(), *plan)

    def update_period(self) -> float | None:
        return float(cast(MPCGains, self.gains).replan_period)

    def _split(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``t_plan`` (N,), ``replans`` (N,) and the plan's deviations ``δ_k`` (N, K, nv)."""
        nv, K = self.robot.nv, self.horizon.knots
        plan = z[:, PLAN_COLUMNS + 2 * nv : PLAN_COLUMNS + (2 + K) * nv]
        return z[:, 0], z[:, 1], plan.reshape(z.shape[0], K, nv)

    # -- the replan ----------------------------------------------------------------------

    def update(self, x: LawInput, terms: Terms) -> np.ndarray:
        qps, u_bar, deviation = self._problems(x, terms)
        step, inside = qps.unconstrained()
        given_up = ~(np.isfinite(x.q).all(1) & np.isfinite(x.v).all(1) & np.isfinite(x.z).all(1))
        failed = [int(i) for i in np.flatnonzero(given_up)]  # ended already: no QP
        for i in np.flatnonzero(~inside & ~given_up):  # a row binds: ProxQP, one run after the other
            solution = self._solve(qps, int(i), x.t, len(inside))
            if solution is None:
                failed.append(int(i))
            else:
                step[i] = solution
        u = u_bar + step.reshape(u_bar.shape)
        nv = x.q.shape[1]
        ehat = self._columns[4]
        z = np.array(x.z, dtype=float)
        z[:, 0], z[:, 1] = x.t, x.z[:, 1] + 1
        z[:, PLAN_COLUMNS : PLAN_COLUMNS + 2 * nv] = deviation
        z[:, PLAN_COLUMNS + 2 * nv : PLAN_COLUMNS + 2 * nv + u[0].size] = u.reshape(u.shape[0], -1)
        fresh = x.z[:, 1] < 0.5  # the first replan: the observer starts at the measured velocity error
        z[fresh, ehat] = (x.v - x.v_des)[fresh]
        z[failed, PLAN_COLUMNS:] = np.nan
        return z

    def _solve(self, qps: HorizonQPs, i: int, t: float, runs: int) -> np.ndarray | None:
        """Run ``i``'s replan where a row binds: its step, or None when it ends here (why:
        :meth:`run_failure`). With ``on_infeasible = "relax"`` a QP ProxQP cannot solve hard is
        solved with its rows relaxed in order, and the relaxation recorded."""
        at = f"the MPC replan at t = {t:.6g} s"
        what = at if runs == 1 else f"{at} (run {i})"
        qp = qps.qp(i)
        try:
            return solve_qp(
                qp, what=what, max_iter=RELAX_AFTER if self._relax else MAX_ITER,
                infeasibility_eps=INFEASIBILITY_EPS, scale=True, accept=ACCEPT, explain=not self._relax, max_inner=MAX_INNER,
            ).x  # fmt: skip
        except OptimizationError as exc:
            if not self._relax:  # this run ends here (run_failure says why), the others go on
                self._failures.setdefault(i, str(exc))  # the first reason: what ended it
                return None
        hz = self.horizon
        try:
            relaxed = solve_relaxed(
                qp,
                hz.priority,
                group=hz.group,
                what=what,
                max_iter=RELAXED_MAX_ITER,
                accept=ACCEPT,
                max_inner=MAX_INNER,
            )
        except OptimizationError as exc:
            self._failures.setdefault(i, str(exc))
            return None
        amounts = self.horizon.relaxed_amounts(relaxed.slack)
        if amounts.max() > 0:
            self.relaxations.add(i, t, amounts)
        return relaxed.solution.x

    def run_failure(self, run: int) -> str | None:
        return self._failures.get(run)

    def run_relaxations(self, run: int) -> RunRelaxation | None:
        return self.relaxations.of(run)

    def initial_state(self) -> np.ndarray:
        self._failures.clear()  # a new simulation: no run given up yet
        self.relaxations.clear()
        return super().initial_state()

    def problems(self, x: LawInput, terms: Terms) -> HorizonQPs:
        """The QPs of the runs at a replan (what :meth:`update` solves; e.g. to check its KKT
        conditions): over the step ``u − ū`` [rad/s²] from the shifted plan ``ū``, its rows
        labelled in ``self.horizon.labels``."""
        return self._problems(x, terms)[0]

    def reference_over_horizon(self, x: LawInput) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``q_r``, ``q̇_r``, ``q̈_r`` at the row times ``t + i h / S``, each (1, K S + 1, nv): the
        preview when the law has one, else the sample at ``t`` extrapolated at constant acceleration."""
        if self._preview and x.preview is not None:
            return x.preview.q, x.preview.v, x.preview.a
        s, half_s2 = self._row_times
        a_des = x.a_des[:, None]
        return (
            x.q_des[:, None] + x.v_des[:, None] * s + a_des * half_s2,
            x.v_des[:, None] + a_des * s,
            np.broadcast_to(a_des, (1, s.shape[1], a_des.shape[2])),
        )

    def _problems(self, x: LawInput, terms: Terms) -> tuple[HorizonQPs, np.ndarray, np.ndarray]:
        """The QPs, the plan ``ū`` (N, K, nv) they step from and the measured deviation
        ``(δq_0, δq̇_0)`` (N, 2 nv)."""
        hz = self.horizon
        K, h = hz.knots, hz.interval
        _, replans, plan = self._split(x.z)
        # the previous plan shifted to now (every run replans at the same instants): knot k of
        # the new plan starts in piece shifted[k] of the old one, the last one held
        since = x.t - float(x.z[:, 0].max())
        shifted = np.minimum(((since + h * np.arange(K)) / h + 1e-9).astype(int), K - 1)
        u_bar = plan[:, shifted]
        u_bar[replans < 0.5] = 0.0  # no plan yet: follow the reference
        reference = self.reference_over_horizon(x)
        dq0, dv0 = x.q - reference[0][:, 0], x.v - reference[1][:, 0]
        states = hz.plan(reference, dq0, dv0, u_bar)
        S = hz.per_interval
        knots = slice(0, K * S, S)
        d = terms.inverse_dynamics_derivatives(states[0][:, knots], states[1][:, knots], states[2][:, knots])
        dhat = x.z[:, self._columns[3]] if self._observing else None
        qps = hz.problems(states, d, reference, self._weights, dhat)
        return qps, u_bar, np.concatenate((dq0, dv0), axis=1)

    # -- between replans: follow the plan, learn the missing torque ----------------------

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        z = x.z
        since = x.t - (
            z[0, 0] if z.shape[0] == 1 else z[:, 0].max()
        )  # every run replans at the same instants
        k = min(int(since * self._per_interval + 1e-9), self._last) if since > 0 else 0
        r = since - k * self._interval if since > 0 else 0.0
        dq0, dv0, a, dhat, _ = self._columns
        qk, vk, ak = z[:, dq0], z[:, dv0], z[:, a[k]]
        if k:  # past the first piece (a replan period longer than a knot interval): knot k's deviation
            u = self._split(z)[2]
            qk = qk + (k * self._interval) * vk + np.matmul(self.horizon.sq_knots[k], u)
            vk = vk + np.matmul(self.horizon.sv_knots[k], u)
        # the plan at t: the reference now plus the planned deviation; its acceleration relative
        # to the reference's, the deviation's plus the feedback toward it
        ev = x.v - x.v_des
        relative = (
            ak + self._kp * (qk + (vk + (0.5 * r) * ak) * r - (x.q - x.q_des)) + self._kd * (vk + ak * r - ev)
        )
        accel = x.a_des + relative
        wanted = terms.model(x.q, x.v, x.v, accel)
        if not self._observing:
            tau = np.minimum(wanted, self._effort)
            np.maximum(tau, self._lowest, out=tau)
            zeros = self._zeros.get(z.shape)
            if zeros is None:
                zeros = self._zeros[z.shape] = np.zeros(z.shape)
                zeros.setflags(write=False)
            return LawOutput(tau, zeros)
        return self._observed(x, terms, relative, wanted - z[:, dhat], ev)

    def _observed(
        self, x: LawInput, terms: Terms, relative: np.ndarray, wanted: np.ndarray, ev: np.ndarray
    ) -> LawOutput:
        """The torque ``wanted`` (the missing torque compensated) clipped, and ż: zeros for the
        plan, the observer's ``d̂̇`` and ``ê̇`` (:mod:`twolink_pin.controllers.disturbance`);
        ``relative``: the acceleration asked for less the reference's, ``ev``: ``q̇ − q̇_d``."""
        z = x.z
        tau = np.minimum(wanted, self._effort)
        np.maximum(tau, self._lowest, out=tau)
        # M̂⁻¹(τ − b̂ + d̂) = accel + M̂⁻¹(τ − wanted): the clipped part only where it clipped
        cut = tau - wanted
        if cut.any():
            relative = relative + terms.solve_mass(x.q, cut)
        drift, rate = self.observer.derivative(self.observer.gap(z, ev), relative)
        plan = self._zeros.get(z.shape)
        if plan is None:  # the plan's columns: they move only at a replan
            plan = self._zeros[z.shape] = np.zeros((z.shape[0], self._columns[3].start))
        return LawOutput(tau, np.concatenate((plan, drift, rate), axis=1))
