"""Operational-space control as a quadratic program: ``osc``'s task within the joint limits."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from twolink_pin.controllers.base import StateVariable
from twolink_pin.controllers.disturbance import DisturbanceObserver
from twolink_pin.controllers.gains import gain
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.controllers.osc import OperationalSpace, OSCGains
from twolink_pin.controllers.relaxation import Relaxations, RunRelaxation
from twolink_pin.controllers.task_space import posture_acceleration, row_index, task_acceleration
from twolink_pin.errors import OptimizationError
from twolink_pin.limits import ACCELERATION, EFFORT, POSITION, VELOCITY, JointLimits, LimitKind, joint_limits
from twolink_pin.model import RobotModel
from twolink_pin.optimal import QP, solve_qp
from twolink_pin.optimal.relaxed import solve_relaxed

POSTURE_WEIGHT = 0.01
"""Default ``w``: the posture's weight against the task's (both in the arm's inertia metric)."""
KINDS_IN_ROWS = (EFFORT, ACCELERATION, VELOCITY, POSITION)
"""The limits the QP's inequality rows bound, in the rows' order."""
HORIZON_FLOOR = 0.1
"""Shortest default position-damper horizon ``h`` [s]: ``1/h`` = 10 rad/s, ``osc``'s task frequency."""
VELOCITY_HORIZON = 0.02
"""Default velocity-damper horizon ``h_v`` [s]: short, so that it brakes only near the limit, and 20
steps of the default 1-ms step, so that RK4 follows it smoothly."""
MAX_ITER = 200
"""Most ProxQP iterations of one step's QP (a few variables and tens of rows: solved in tens); a
QP that cannot hold is told apart at once (uncapped, the UR5's first step at ``limit_scale =
1e-12`` took 11 million iterations and 131 s to fail, and a run ignored SIGTERM for 5 s)."""
RELAXED_MAX_ITER = 1000
"""Most ProxQP iterations of a step's QP with its rows relaxed."""
RELAXED_ROUNDING = 1e-7
"""A row's excess (relative to its value, at least 1) below this after a relaxed solve is the
solver's rounding, not a relaxation."""
RELAX_AFTER = 30
"""With ``on_infeasible = "relax"``, the ProxQP iterations a step's QP gets with its rows hard
before it is solved relaxed (whose answer is the hard one's whenever that exists: the penalty
is exact); a QP that cannot hold costs 30, not 200, iterations before its answer."""
MAX_INNER = 20
"""Most of ProxQP's inner iterations per outer one (its default 1500): a QP that cannot hold,
its bounds at 1e12 (a damper of horizon 1e-12 s), spent 1300 per outer iteration and a second a
solve; a feasible one takes a few."""
INFEASIBILITY_EPS = 1e-9
"""ProxQP's infeasibility tolerances (its default, 1e-4, calls feasible steps infeasible)."""
ACCEPT = 1e-6
"""A QP stopped at :data:`MAX_ITER` whose equilibrated residuals are both below this is accepted."""
PRIORITY = {EFFORT: -1, POSITION: 0, VELOCITY: 1, ACCELERATION: 2}
"""The order rows give way in when they cannot all hold (−1: never)."""
OBSERVER_RATE = 150.0
"""Default ω_o [rad/s] of the disturbance observer (``mpc``'s): without it a push the model
does not know makes every row a belief — the QP holds the acceleration it thinks the arm has
while the arm, pushed, has another, and it never asks for the torque that would resist."""


@dataclass(frozen=True, eq=False)
class QPOSCGains(OSCGains):
    r"""Gains of :class:`QPOperationalSpace`: ``osc``'s (:class:`~twolink_pin.controllers.osc.OSCGains`,
    matrix gains included) and three of the QP's own.

    Attributes:
        posture_weight: $w$, the posture's weight against the task's, $0 < w \le 1$
            (dimensionless: both costs are in the arm's inertia metric); it matters only when
            a limit is active; default 0.01.
        position_horizon: $h$ per joint [s] of the position damper; default per joint
            $\max(\dot q_{max} / \ddot q_{max},\ 0.1\ \mathrm{s})$ with the robot's velocity and
            acceleration limits (0.1 s where it has no acceleration limit).
        velocity_horizon: $h_v$ per joint [s] of the velocity damper; default 0.02 s.
        limit_scale: $f$, the fraction of the velocity, acceleration and effort limits the
            law may use, $0 < f \le 1$ (headroom; the position range is kept); default 1.
        on_infeasible: ``"relax"`` (the position, velocity and acceleration rows give way, in
            that order, the effort rows held; the run goes on) or ``"fail"`` (the run ends,
            naming the row); default ``"relax"``.
        observer_rate: $\omega_o$ [rad/s] of the disturbance observer (0: none); default 150.
    """

    posture_weight: Any = gain(POSTURE_WEIGHT, bound="fraction", doc="posture weight w against the task")
    position_horizon: Any = gain(None, per="joint", unit="s", doc="horizon h of the position damper")
    velocity_horizon: Any = gain(
        VELOCITY_HORIZON, per="joint", unit="s", doc="horizon h_v of the velocity damper"
    )
    limit_scale: Any = gain(
        1.0, bound="fraction", doc="fraction f of the velocity, acceleration and effort limits used"
    )
    on_infeasible: Any = gain(
        "relax",
        choices=("relax", "fail"),
        doc="when the limits cannot all hold: relax them in order, or fail",
    )
    observer_rate: Any = gain(
        OBSERVER_RATE, unit="rad/s", bound="nonnegative", doc="rate ω_o of the disturbance observer (0: none)"
    )


def default_horizon(limits: JointLimits) -> np.ndarray:
    """``h`` [s] per joint: ``max(q̇_max / q̈_max, HORIZON_FLOOR)``, the floor where a joint
    has no velocity or no acceleration limit (see :class:`QPOperationalSpace`)."""
    with np.errstate(invalid="ignore"):
        ratio = limits.velocity / limits.acceleration  # inf / inf = nan, v / inf = 0
    return np.where(np.isfinite(ratio), np.maximum(ratio, HORIZON_FLOOR), HORIZON_FLOOR)


class QPOperationalSpace(OperationalSpace):
    r"""Operational-space control as a quadratic program over $(\ddot q, \tau)$ at every
    evaluation, with the joint limits as constraints:

    $$\min_{\ddot q,\ \tau}\ \tfrac12 \|J \ddot q + \dot J \dot q - \ddot x^*\|^2_{\hat\Lambda}
    + \tfrac{w}{2} \|\ddot q - \ddot q_n\|^2_{\hat M - J^\top \hat\Lambda J}
    \quad \text{s.t.} \quad \hat M \ddot q + \hat b = \tau,\quad |\tau| \le f \tau_{max},\quad
    |\ddot q| \le f \ddot q_{max},$$

    $$|\dot q + h_v \ddot q| \le f \dot q_{max}, \qquad
    q_{min} \le q + 2 h \dot q + h^2 \ddot q \le q_{max}$$

    with ``osc``'s desired task acceleration $\ddot x^* = \ddot x_d - D \dot e - K e$ (on the
    rows ``task_rows`` picks, orientation included), its posture acceleration
    $\ddot q_n = \ddot q_d - K_n e_q - D_n \dot e_q$, $\hat\Lambda = (J \hat M^{-1} J^\top)^{-1}$
    and $\hat b = \hat C \dot q + \hat g$, all on the law's believed model, and the robot's
    limits (:func:`~twolink_pin.limits.joint_limits`; a joint without a kind of limit has no
    row for it). It is solved with $\tau$ eliminated: $\tau = \hat M \ddot q + \hat b$ turns
    the effort box into the rows $\hat M \ddot q$ within $\pm f \tau_{max} - \hat b$, the same
    QP over $\ddot q$ alone (half the variables, no equality; ProxQP takes half the time).

    **The posture at a lower weight, and exactly ``osc`` when no limit is active.** Both costs
    are accelerations in the arm's inertia metric (kg·m²/s⁴), so $w$ has no unit. The
    posture's metric $\hat M - J^\top \hat\Lambda J = N^\top \hat M N$ sees only the
    dynamically consistent null space ($N = I - \hat M^{-1} J^\top \hat\Lambda J$), the task's
    only its complement: the two costs do not compete, and without an active constraint the
    minimiser is, for every $w > 0$,
    $\ddot q = \hat M^{-1} J^\top \hat\Lambda (\ddot x^* - \dot J \dot q) + N \ddot q_n$ —
    ``osc``'s acceleration, whose torque $\hat M \ddot q + \hat b$ is ``osc``'s torque. A limit makes them compete, and $w$ weighs the posture against
    the task: one QP rather than two prioritised ones (half the solves; the same answer
    whenever the task can be met exactly). Near a singularity, where ``osc`` damps
    $\hat\Lambda$, the posture term also holds the damped directions (then the two laws differ).

    **Limits as constraints on $\ddot q$.** The velocity damper
    $\dot q + h_v \ddot q \le \dot q_{max}$ keeps $\dot q \le \dot q_{max}$ for any $h_v > 0$ (Grönwall:
    $\frac{d}{dt}(\dot q_{max} - \dot q) \ge -(\dot q_{max} - \dot q) / h_v$); a short one
    brakes only near the limit. The position damper is critically damped: for the distance
    $d = q_{max} - q$ it reads $\ddot d + \frac{2}{h} \dot d + \frac{1}{h^2} d \ge 0$, which
    keeps the set $\dot q \le d / h$ invariant, so $q$ never passes $q_{max}$ from a state in
    it. (The constant-acceleration bound $q + h \dot q + \frac12 h^2 \ddot q \le q_{max}$ is
    the same damper at $\zeta = 1/\sqrt 2$, whose step response overshoots by 4 %.) In that
    set the damper asks at most the deceleration $\dot q / h \le \dot q_{max} / h$, so the
    default $h = \dot q_{max} / \ddot q_{max}$ never asks more than the acceleration limit; its
    floor of 0.1 s keeps the damper no stiffer than ``osc``'s task (10 rad/s). Whether the
    effort box can give what the dampers ask is the QP's to say: when it cannot, the limits
    cannot all hold. The limits hold on the believed model: with a wrong model the arm's
    acceleration differs from the planned one, and a damper holds only up to that error.

    **Solved by** :func:`~twolink_pin.optimal.solve_qp`, one QP per run (a loop over N), its
    unconstrained minimiser first (one linear solve; when it meets every limit it is the QP's
    solution) and ProxQP, cold-started, when it does not. The law holds no state: a run's
    torque depends on its own input alone, so a batch equals its single runs. (A parallel
    batch of ProxQP solves would not help: most of a solve this small is its set-up, which
    runs in Python before the solve.) Constraints that cannot all hold, or a solver that stops
    short, raise :class:`~twolink_pin.errors.OptimizationError` naming the constraint and the
    time: the run fails (exit status 1); it never holds a torque.
    """

    name = "qp-osc"
    title = "operational-space control as a QP within the joint limits"
    Gains = QPOSCGains

    def __init__(self, robot: RobotModel, gains: QPOSCGains | None = None, **kwargs: Any) -> None:
        super().__init__(robot, gains, **kwargs)
        self.limits = joint_limits(robot)
        """The robot's limits (unscaled: ``limit_scale`` scales them in the QP)."""
        given = [(kind, int(j)) for kind in KINDS_IN_ROWS for j in np.flatnonzero(self.limits.given(kind))]
        scale = cast(QPOSCGains, self.gains).limit_scale
        self.labels = tuple(_label(kind, j, self.limits, scale) for kind, j in given)
        """What each inequality row of the QP bounds, in order: effort, acceleration, velocity, position."""
        effort = np.array([j for kind, j in given if kind is EFFORT], dtype=int)
        self._n_effort = effort.size
        self._effort = row_index(effort) if effort.size else effort  # usually every joint: a slice, a view
        self._joints = np.array([j for kind, j in given if kind is not EFFORT], dtype=int)
        self._kinematic = np.eye(robot.nv)[self._joints]  # the rows of q̈ the other limits bound
        lower, upper, a_q, a_v = self._row_coefficients(given)
        self._rows = (lower, upper, a_q[:, self._n_effort :], a_v[:, self._n_effort :])
        self._weight = np.asarray(cast(QPOSCGains, self.gains).posture_weight, dtype=float).reshape(-1, 1, 1)
        effort_limit = np.where(
            np.isfinite(self.limits.effort),
            np.asarray(scale, dtype=float).reshape(-1, 1) * self.limits.effort,
            np.inf,
        )
        self._highest, self._lowest = effort_limit, -effort_limit  # f τ_max [N·m], (1 or N, nv)
        self._priority = np.array([PRIORITY[kind] for kind, _ in given], dtype=int)
        self._row_joint = np.array([j for _, j in given], dtype=int)
        self._amount = self._row_units(given)
        self._relax = cast(QPOSCGains, self.gains).on_infeasible == "relax"
        self.observer = DisturbanceObserver(
            robot, self.believed_parameters(), cast(QPOSCGains, self.gains).observer_rate, 0
        )
        """The estimate of the torque the model misses (a push, a wrong mass): the QP's dynamics
        are ``M̂ q̈ + b̂ − d̂ = τ`` (``d̂``, ``ê``: the law's state ``z``)."""
        self._failures: dict[int, str] = {}  # run → why its step's QP failed (:meth:`run_failure`)
        self.relaxations = Relaxations(robot.nv)
        """Where and by how much each run's QPs relaxed rows (:meth:`run_relaxations`)."""

    def _row_units(self, given: list[tuple[LimitKind, int]]) -> np.ndarray:
        """Per run and row, (1 or N, n_in), the factor from a row's slack [rad/s²] to how far
        its limit was moved, in the limit's unit: ``h²`` for a position damper [rad], ``h_v``
        for a velocity damper [rad/s], 1 for an acceleration row (0 for the effort rows)."""
        g = cast(QPOSCGains, self.gains)
        h, hv = np.atleast_2d(g.position_horizon), np.atleast_2d(g.velocity_horizon)
        runs = max(h.shape[0], hv.shape[0])
        shape = (runs, self.robot.nv)
        per_kind = {
            EFFORT: np.zeros(shape),
            ACCELERATION: np.ones(shape),
            VELOCITY: np.broadcast_to(hv, shape),
            POSITION: np.broadcast_to(h * h, shape),
        }
        columns = [per_kind[kind][:, j] for kind, j in given]
        return np.stack(columns, axis=-1) if columns else np.zeros((runs, 0))

    def _row_coefficients(self, given: list[tuple[LimitKind, int]]) -> tuple[np.ndarray, ...]:
        """Per inequality row, ``(lower, upper, a_q, a_v)`` with the row's bounds
        ``lower + a_q q_j + a_v q̇_j`` and ``upper + a_q q_j + a_v q̇_j`` (effort rows: before
        ``− b̂``), each (1 or N, n_in), from the gains (fixed with the law)."""
        g = cast(QPOSCGains, self.gains)
        lim, f = self.limits, np.asarray(g.limit_scale).reshape(-1, 1)
        h, hv = np.atleast_2d(g.position_horizon), np.atleast_2d(g.velocity_horizon)
        runs = max(a.shape[0] for a in (f, h, hv))
        shape = (runs, self.robot.nv)
        zero = np.zeros(shape)
        per_kind = {  # lower, upper, a_q, a_v per joint
            EFFORT: (-f * lim.effort, f * lim.effort, zero, zero),
            ACCELERATION: (-f * lim.acceleration, f * lim.acceleration, zero, zero),
            VELOCITY: (-f * lim.velocity / hv, f * lim.velocity / hv, zero, -1.0 / hv),
            POSITION: (lim.position_lower / (h * h), lim.position_upper / (h * h), -1.0 / (h * h), -2.0 / h),
        }
        columns = [
            np.stack([np.broadcast_to(a, shape)[:, j] for a in per_kind[kind]]) for kind, j in given
        ]  # each (4, runs)
        table = np.stack(columns, axis=-1) if columns else np.zeros((4, runs, 0))
        return tuple(np.ascontiguousarray(t) for t in table)

    def scaled_gains(self) -> dict[str, Any]:
        return {"position_horizon": default_horizon(joint_limits(self.robot))}

    def state_variables(self) -> tuple[StateVariable, ...]:
        return (*super().state_variables(), *DisturbanceObserver.state_variables(self.robot.nv))

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        # a run ended already (its torque NaN at an earlier stage): no QP, a NaN torque again
        ended = ~(np.isfinite(x.q).all(1) & np.isfinite(x.v).all(1) & np.isfinite(x.z).all(1))
        if ended.any():
            keep = ~ended[:, None]
            x = x._replace(
                q=np.where(keep, x.q, self.robot.home), v=np.where(keep, x.v, 0.0), z=np.where(keep, x.z, 0.0)
            )
        problems, M, b = self._problems(x, terms)
        accel = np.empty_like(b)  # q̈ per run; then τ = M̂ q̈ + b̂
        at = f"the QP at t = {x.t:.6g} s"
        for i, qp in enumerate(problems):
            what = at if len(problems) == 1 else f"{at} (run {i})"
            accel[i] = np.nan if ended[i] else self._solve(qp, i, x.t, what, (M[i], b[i]))
        tau = np.matvec(M, accel) + b
        if self._n_effort:  # the effort rows hold to the solver's 1e-9: the box itself, exactly
            np.clip(tau, self._lowest, self._highest, out=tau)
        dz = np.zeros(x.z.shape)
        if self.observer.on:  # M̂⁻¹(τ − b̂ + d̂) is the QP's q̈ (the clip moved it by rounding only)
            gap = self.observer.gap(x.z, x.v - x.v_des)
            dz[:, self.observer.columns[0]], dz[:, self.observer.columns[1]] = self.observer.derivative(
                gap, accel - x.a_des
            )
        return LawOutput(tau, dz)

    def _solve(
        self, qp: QP, i: int, t: float, what: str, dynamics: tuple[np.ndarray, np.ndarray]
    ) -> np.ndarray:
        """Run ``i``'s ``q̈``: the QP's minimiser; with its rows relaxed in order when they cannot
        all hold (``on_infeasible = "relax"``, recorded), else NaN: the run ends here
        (:meth:`run_failure` says why). ``dynamics``: the run's ``(M̂, b̂ − d̂)``."""
        try:
            return solve_qp(
                qp, what=what, unconstrained_first=True, max_iter=RELAX_AFTER if self._relax else MAX_ITER,
                scale=True, accept=ACCEPT, infeasibility_eps=INFEASIBILITY_EPS, explain=not self._relax, max_inner=MAX_INNER,
            ).x  # fmt: skip
        except OptimizationError as exc:
            if not self._relax:
                self._failures.setdefault(i, str(exc))
                return np.full(qp.g.shape, np.nan)
        try:
            accel = solve_relaxed(
                qp, self._priority, what=what, max_iter=RELAXED_MAX_ITER, accept=ACCEPT, max_inner=MAX_INNER
            ).solution.x
        except OptimizationError:
            accel = self._saturated(qp, i, dynamics)
        assert qp.C is not None and qp.l is not None and qp.u is not None
        cx = qp.C @ accel
        excess = np.maximum(np.maximum(qp.l - cx, cx - qp.u), 0.0)
        moved = np.where(excess > RELAXED_ROUNDING * np.maximum(1.0, np.abs(cx)), excess, 0.0)
        moved = moved * self._amount[min(i, self._amount.shape[0] - 1)]
        if moved.max(initial=0.0) > 0:
            amounts = np.zeros((3, self.robot.nv))
            soft = self._priority >= 0
            np.maximum.at(amounts, (self._priority[soft], self._row_joint[soft]), moved[soft])
            self.relaxations.add(i, t, amounts)
        return accel

    def _saturated(self, qp: QP, i: int, dynamics: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        """The last resort when even the relaxed QP fails (an effort box narrower than the
        solver's tolerance, ``limit_scale = 1e-12``): the cost's minimiser's torque clipped to
        the effort box, and the acceleration it gives (every other row relaxed as it falls)."""
        M, b = dynamics
        tau = M @ np.linalg.solve(qp.H, -qp.g) + b
        row = min(i, self._highest.shape[0] - 1)
        tau = np.clip(tau, self._lowest[row], self._highest[row])
        return np.linalg.solve(M, tau - b)

    def run_failure(self, run: int) -> str | None:
        return self._failures.get(run)

    def run_relaxations(self, run: int) -> RunRelaxation | None:
        return self.relaxations.of(run)

    def initial_state(self) -> np.ndarray:
        self._failures.clear()  # a new simulation: no run given up, nothing relaxed yet
        self.relaxations.clear()
        return super().initial_state()

    def problems(self, x: LawInput, terms: Terms) -> list[QP]:
        """The QP of each run at this evaluation (what :meth:`compute` solves; e.g. to inspect
        one, or check its KKT conditions): over ``q̈`` [rad/s²] with ``τ = M̂ q̈ + b̂``
        substituted, so that the effort box is the rows ``M̂ q̈`` within ``±f τ_max − b̂``; the
        inequality rows are labelled in :attr:`labels`."""
        return self._problems(x, terms)[0]

    def _problems(self, x: LawInput, terms: Terms) -> tuple[list[QP], np.ndarray, np.ndarray]:
        """:meth:`problems`, and ``M̂`` (N, nv, nv) and ``b̂`` (N, nv) they were built from."""
        g = cast(QPOSCGains, self.gains)
        task = task_acceleration(x, terms, self._index, self._K, self._D)
        J = task.jacobian
        Jt = J.transpose(0, 2, 1)
        Lam = self._inertia(np.matmul(J, terms.solve_mass(x.q, Jt)), x.t)
        JtLam = np.matmul(Jt, Lam)
        task_hessian = np.matmul(JtLam, J)  # Jᵀ Λ J
        M, b = terms.mass(x.q), terms.bias(x.q, x.v)
        if self.observer.on:
            b = b - self.observer.estimate(x.z)  # the torque the model misses, as estimated
        posture = self._weight * (M - task_hessian)  # w Nᵀ M N: the null space (and any damped direction)
        H = task_hessian + posture
        gradient = -np.matvec(JtLam, task.desired - task.drift) - np.matvec(
            posture, posture_acceleration(x, g.kp_null, g.kd_null)
        )
        runs, n_effort = H.shape[0], self._n_effort
        C = np.empty((runs, len(self.labels), self.robot.nv))
        C[:, :n_effort] = M[:, self._effort]
        C[:, n_effort:] = self._kinematic
        lower, upper, a_q, a_v = self._rows
        shift = np.concatenate(
            (-b[:, self._effort], x.q[:, self._joints] * a_q + x.v[:, self._joints] * a_v), axis=1
        )
        lower, upper = lower + shift, upper + shift
        problems = [
            QP(H[i], gradient[i], None, None, C[i], lower[i], upper[i], self.labels) for i in range(runs)
        ]
        return problems, M, b


def _label(kind: LimitKind, j: int, limits: JointLimits, scale: Any) -> str:
    """What row ``(kind, j)`` of the QP bounds, in words, and the quantity the row holds (the
    bounds a message gives are the row's)."""
    joint = f"joint {j + 1} ({limits.joint_names[j]})"
    if kind is POSITION:
        lo, hi = limits.position_lower[j], limits.position_upper[j]
        return f"the position range [{lo:.6g}, {hi:.6g}] rad of {joint} (row: q̈ [rad/s²] in its damper q + 2h q̇ + h² q̈)"
    value = float(getattr(limits, kind.name)[j])
    bound = f"{value * scale:.6g}" if isinstance(scale, float) else f"limit_scale × {value:.6g}"
    row = {
        EFFORT: "M̂ q̈ = τ − b̂ [N·m]",
        ACCELERATION: "q̈ [rad/s²]",
        VELOCITY: "q̈ [rad/s²] in its damper q̇ + h_v q̈",
    }[kind]
    return f"the {kind.name} limit |{kind.symbol}| <= {bound} {kind.unit} of {joint} (row: {row})"
