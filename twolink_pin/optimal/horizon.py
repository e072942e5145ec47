"""The finite-horizon QP of a model-predictive law: the plan's knot accelerations, the believed
dynamics linearised on Pinocchio's RNEA derivatives, the joint limits as hard rows.

**Decision.** The plan over the horizon ``[t, t + K h]`` is the reference plus a deviation of
piecewise-constant acceleration: ``q̈_p(s) = q̈_r(s) + δ_k`` [rad/s²] on ``[t + k h, t + (k + 1) h)``,
``k = 0 … K − 1``, from the measured state (``δq_0 = q_0 − q_r(t)``, ``δq̇_0 = q̇_0 − q̇_r(t)``).
Its states at the knots are the reference's there (the law's preview of it) plus a deviation
linear in ``u = (δ_0, …, δ_{K−1})`` (knot-major, ``K nv`` values)::

    q̇_k = q̇_r,k + δq̇_0 + h Σ_{j<k} δ_j,      q_k = q_r,k + δq_0 + k h δq̇_0 + h² Σ_{j<k} (k − j − ½) δ_j

— exact for any reference: the reference's own motion between knots is not approximated, only
the correction is piecewise constant (a reference extrapolated at constant acceleration from
``t``, ``q_r(t + s) = q_d + q̇_d s + ½ q̈_d s²``, makes this the plan of pieces of constant
acceleration ``q̈_d + δ_k``).

**Dynamics.** ``τ_k = RNEA(q_k, q̇_k, a_k)`` with ``a_k = q̈_r,k + δ_k`` on the believed
model, linearised at a plan ``ū`` (real-time iteration: the previous plan, shifted; its
states rolled out from the measured state the same way)::

    τ_k ≈ τ̄_k + ∂τ/∂q (q_k − q̄_k) + ∂τ/∂q̇ (q̇_k − q̄̇_k) + M̂ (a_k − ā_k) = τ̄_k + T_k (u − ū)

``T`` is block lower-triangular with ``M̂(q̄_k)`` on its diagonal, so it is invertible.

**Cost** [(N·m)²·s] (each error weighed as the torque it is worth; the QP holds it divided by
its Hessian's largest diagonal entry, which changes no minimiser)::

    h Σ_{k=1..K} (‖W_q (q_k − q_ref,k)‖² + ‖W_v (q̇_k − q̇_ref,k)‖²)
      + h w_τ Σ_{k=0..K−1} ‖τ_k − τ_ref,k‖²

with ``W_q = diag(weight_q)`` [N·m/rad], ``W_v = diag(weight_v)`` [N·m·s/rad], ``w_τ`` (no unit)
and ``τ_k − τ_ref,k ≈ ∂τ/∂q (q_k − q_ref,k) + ∂τ/∂q̇ (q̇_k − q̇_ref,k) + M̂ (a_k − a_ref,k)`` on
the same linearisation (the reference's torque needs no further RNEA). With ``w_τ > 0`` the
Hessian is positive definite.

**Rows** (``f``: ``limit_scale``): ``|τ_k − d̂| ≤ f τ_max`` at knots 0 … K−1 (``d̂``: the
torque the law estimates its model misses, 0 without); ``|q̈| ≤ f q̈_max`` (where the arm has
one), ``|q̇| ≤ f q̇_max`` and ``q_min ≤ q ≤ q_max`` at the **row times** ``i h / S``
(:data:`ROWS_PER_INTERVAL` = S per knot interval; the state bounds from the first row time on,
not at the measured state, which the plan cannot change). Between knots the plan is the
reference plus a deviation: a reference whose velocity has a corner between two row times would
carry the plan past a bound between them, so the velocity and acceleration rows bound the
deviation at a row time plus the reference's extreme over the row times either side (its
envelope: the deviation is linear, constant, between them — the bound then holds over the whole
interval). A joint without a kind of limit has no row for it. Each row is labelled, and has a
priority (:attr:`Horizon.priority`): the effort rows are hard, the position, velocity and
acceleration rows give way in that order when they cannot all hold, by one amount per kind and
joint over the horizon (:attr:`Horizon.group`; :mod:`twolink_pin.optimal.relaxed`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from twolink_pin.dynamics import InverseDynamicsDerivatives
from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import ACCELERATION, EFFORT, POSITION, VELOCITY, JointLimits
from twolink_pin.memory import available_memory
from twolink_pin.optimal.qp import QP

KINDS_IN_ROWS = (EFFORT, ACCELERATION, VELOCITY, POSITION)
"""The limits the QP's inequality rows bound, in the rows' order."""
ROWS_PER_INTERVAL = 5
"""``S``: the state rows' times per knot interval (every 5 ms at the default 25-ms knots)."""


class CostWeights(NamedTuple):
    """The cost's weights over the knots (:meth:`Horizon.weights`)."""

    q2: np.ndarray
    """``W_q²`` per knot and joint, (1 or N, K nv) [(N·m/rad)²]."""
    v2: np.ndarray
    """``W_v²`` per knot and joint, (1 or N, K nv) [(N·m·s/rad)²]."""
    tau: np.ndarray
    """``w_τ``, (1 or N, 1, 1)."""
    tracking: np.ndarray
    """``Qᵀ W_q² Q + Vᵀ W_v² V``, the Hessian's part that does not change, (1 or N, K nv, K nv)."""


class HorizonQPs(NamedTuple):
    """The QPs of N runs over the step ``x = u − ū`` [rad/s²], as batched arrays (one
    factorisation call solves all N unconstrained minimisers: :meth:`unconstrained`)."""

    H: np.ndarray
    """Hessians, (N, n, n), positive definite (the cost over its largest curvature)."""
    g: np.ndarray
    """Linear costs, (N, n)."""
    C: np.ndarray
    """Inequality rows, (N, m, n)."""
    l: np.ndarray  # noqa: E741  (the solver's name)
    """Lower bounds, (N, m)."""
    u: np.ndarray
    """Upper bounds, (N, m)."""
    labels: Sequence[str]
    """What each row bounds (:attr:`Horizon.labels`)."""

    def qp(self, i: int) -> QP:
        """Run ``i``'s QP for :func:`~twolink_pin.optimal.solve_qp`."""
        return QP(self.H[i], self.g[i], None, None, self.C[i], self.l[i], self.u[i], self.labels)

    def unconstrained(self) -> tuple[np.ndarray, np.ndarray]:
        """Every run's unconstrained minimiser ``−H⁻¹ g`` (N, n) (one batched LAPACK call) and
        whether it meets every row, exactly (N,) bool: where it does it is the QP's solution
        (the KKT conditions hold with zero multipliers)."""
        x = np.linalg.solve(self.H, -self.g[..., None])[..., 0]
        cx = np.matvec(self.C, x)
        return x, ((cx >= self.l) & (cx <= self.u)).all(axis=1)


class Horizon:
    """The horizon's fixed structure: ``K`` knots ``h`` [s] apart for a robot of ``nv`` joints
    and its limits, the integration matrices and the rows' labels (built once per law).

    The state rows are checked ``S`` times per knot interval (:data:`ROWS_PER_INTERVAL`, the
    **row times** ``t + i h / S``), not only at the knots: between knots the plan is the
    reference plus a deviation, and a reference whose velocity peaks between two knots would
    carry the plan past a limit there.

    Args:
        knots: ``K ≥ 1``, the number of knot intervals.
        interval: ``h`` [s] > 0.
        limits: The robot's joint limits (unscaled).
        limit_scale: ``f``, the fraction of the velocity, acceleration and effort limits used
            (one value for every run; the position range is kept).
        per_interval: ``S``, the row times per knot interval.
    """

    def __init__(
        self,
        knots: int,
        interval: float,
        limits: JointLimits,
        limit_scale: float,
        per_interval: int = ROWS_PER_INTERVAL,
    ) -> None:
        self.knots, self.interval, self.limits, self.nv = int(knots), float(interval), limits, limits.nv
        self.per_interval = S = int(per_interval)
        K, h, nv = self.knots, self.interval, self.nv
        self.times = h / S * np.arange(K * S + 1)
        """The row times [s] from now, ``i h / S`` for ``i = 0 … K S`` (the knots every ``S``th):
        where the law wants the reference (its preview)."""
        self.sq, self.sv = _integration(K, h, S)
        """``q(t_i) − q_0 − t_i q̇_0 = Σ_j sq[i, j] a_j`` [s²] and ``q̇(t_i) − q̇_0 = Σ_j sv[i, j] a_j``
        [s] at the row times, shape (K S + 1, K) (the knots: rows ``0, S, …, K S``)."""
        self.sq_knots, self.sv_knots = self.sq[::S], self.sv[::S]
        eye = np.eye(nv)
        self._t = self.times[:, None]
        self.Q = np.kron(self.sq_knots, eye)  # ((K+1) nv, K nv): the knots' positions
        self.V = np.kron(self.sv_knots, eye)
        self._QVs = np.concatenate((self.Q[nv:], self.V[nv:]), axis=0)  # (2 K nv, K nv)
        rows = _rows(K, S, limits, float(limit_scale))
        self.rows = rows
        """Per inequality row: the kind's name, the row time's index (the knot's for the effort
        rows), the joint (0-based), its bounds."""
        self.labels: Sequence[str] = tuple(self._label(r) for r in rows)
        """What each row bounds, in words (a message's bounds and value are the row's: the
        quantity less its value on the plan the QP steps from)."""
        self._layout(rows)

    def _layout(self, rows: list[tuple[str, int, int, float, float]]) -> None:
        """The rows' coefficients and where their values at a plan are read from."""
        K, S, nv = self.knots, self.per_interval, self.nv
        kind_of = np.array([r[0] for r in rows], dtype=object)
        at_time = np.array([r[1] for r in rows], dtype=int)
        joint = np.array([r[2] for r in rows], dtype=int)
        self._lower = np.array([r[3] for r in rows])
        self._upper = np.array([r[4] for r in rows])
        effort = np.flatnonzero(kind_of == EFFORT.name)
        state = np.flatnonzero(kind_of != EFFORT.name)
        fine = K * S + 1
        C = np.zeros((len(rows), K * nv))
        # each state row's value at a plan: an entry of [q (K S + 1, nv), q̇ (K S + 1, nv), q̈ (K S, nv)]
        at = np.zeros(len(rows), dtype=int)
        for i in state:
            ti, jj = at_time[i], joint[i]
            if kind_of[i] == ACCELERATION.name:
                C[i, (ti // S) * nv + jj] = 1.0
                at[i] = 2 * fine * nv + ti * nv + jj
            elif kind_of[i] == VELOCITY.name:
                C[i, jj::nv] = self.sv[ti]
                at[i] = fine * nv + ti * nv + jj
            else:
                C[i, jj::nv] = self.sq[ti]
                at[i] = ti * nv + jj
        self._C_state = C[state]
        self._state_at = at[state]
        self.joint = joint
        """The joint (0-based) of each row."""
        order = {POSITION.name: 0, VELOCITY.name: 1, ACCELERATION.name: 2}
        self.priority = np.array([order.get(r[0], -1) for r in rows], dtype=int)
        """Per row: −1 hard (effort), else the order it gives way in when the rows cannot all
        hold — 0 position, 1 velocity, 2 acceleration (:mod:`twolink_pin.optimal.relaxed`; the
        index into :data:`~twolink_pin.controllers.relaxation.RELAXED_KINDS`)."""
        self.group = np.where(self.priority >= 0, self.priority * self.nv + joint, -1)
        """Per row, the slack it shares when relaxed: one per kind and joint over the horizon
        (a limit given way by one amount, whatever the row time); −1 for the hard rows."""
        # the rows of each kind and the variables of the effort rows' torques: slices where contiguous
        self._effort = _contiguous(effort)
        self._effort_index = _contiguous(at_time[effort] * nv + joint[effort])
        self._effort_joint = joint[effort]
        self._state = _contiguous(state)
        select = np.zeros((K, nv, K * nv))
        for block in range(K):
            select[block, :, block * nv : (block + 1) * nv] = np.eye(nv)
        Qk = self.Q.reshape(K + 1, nv, K * nv)
        Vk = self.V.reshape(K + 1, nv, K * nv)
        self._QVE = np.concatenate((Qk[:K], Vk[:K], select), axis=1)  # (K, 3 nv, K nv)
        self._piece = np.arange(K * S) // S  # the piece each row time (but the last) lies in

    def _label(self, row: tuple[str, int, int, float, float]) -> str:
        name, ti, jj, lo, hi = row
        joint = f"joint {jj + 1} ({self.limits.joint_names[jj]})"
        kind = {k.name: k for k in KINDS_IN_ROWS}[name]
        if kind is EFFORT:
            when = f"at knot {ti} (t + {ti * self.interval:.6g} s)"
        else:
            when = f"at t + {self.times[ti]:.6g} s"
        held = f"(row: {kind.symbol} less its value on the shifted plan [{kind.unit}])"
        if kind is POSITION:
            return f"the position range [{lo:.6g}, {hi:.6g}] rad of {joint} {when} {held}"
        return f"the {name} limit |{kind.symbol}| <= {hi:.6g} {kind.unit} of {joint} {when} {held}"

    @property
    def variables(self) -> int:
        """``K nv``: the QP's variables."""
        return self.knots * self.nv

    def relaxed_amounts(self, slack: np.ndarray) -> np.ndarray:
        """A relaxed solve's slack per row [the row's unit] as the largest per kind that gives
        way and joint, (3, nv) (position, velocity, acceleration; 0 where none)."""
        amounts = np.zeros((3, self.nv))
        soft = self.priority >= 0
        np.maximum.at(amounts, (self.priority[soft], self.joint[soft]), slack[soft])
        return amounts

    def rollout(self, q0: np.ndarray, v0: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``q``, ``q̇`` [rad, rad/s] at the row times, each (N, K S + 1, nv), of pieces of
        constant acceleration ``u`` (N, K, nv) [rad/s²] from ``(q0, v0)`` (N, nv) — the plan's
        deviation from the reference, from the measured state's deviation."""
        q = q0[:, None] + self._t * v0[:, None] + np.matmul(self.sq, u)
        v = v0[:, None] + np.matmul(self.sv, u)
        return q, v

    def plan(
        self,
        reference: tuple[np.ndarray, np.ndarray, np.ndarray],
        dq0: np.ndarray,
        dv0: np.ndarray,
        u: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The plan at the row times: the reference ``(q_r, q̇_r, q̈_r)`` (1 or N, K S + 1, nv)
        plus the deviation ``u`` (N, K, nv) from ``(dq0, dv0)`` (N, nv): ``q``, ``q̇`` (N, K S + 1, nv)
        and ``q̈`` (N, K S, nv) [rad, rad/s, rad/s²]."""
        qr, vr, ar = reference
        dq, dv = self.rollout(dq0, dv0, u)
        return qr + dq, vr + dv, ar[:, :-1] + u[:, self._piece]

    def weights(self, weight_q: np.ndarray, weight_v: np.ndarray, weight_tau: np.ndarray) -> CostWeights:
        """The cost's weights laid out over the knots, and its tracking Hessian (made once per law).

        Args:
            weight_q, weight_v: ``W_q`` [N·m/rad], ``W_v`` [N·m·s/rad], (1 or N, nv) or scalars.
            weight_tau: ``w_τ`` (no unit), a scalar or (N, 1).
        """
        K, nv = self.knots, self.nv
        wq, wv = (np.atleast_2d(np.asarray(w, dtype=float)) for w in (weight_q, weight_v))
        wq2 = np.tile(np.broadcast_to(wq, (wq.shape[0], nv)) ** 2, (1, K))
        wv2 = np.tile(np.broadcast_to(wv, (wv.shape[0], nv)) ** 2, (1, K))
        Qs, Vs = self.Q[nv:], self.V[nv:]
        tracking = np.matmul(Qs.T * wq2[:, None, :], Qs) + np.matmul(Vs.T * wv2[:, None, :], Vs)
        wt = np.asarray(weight_tau, dtype=float).reshape(-1, 1, 1)
        return CostWeights(wq2, wv2, wt, tracking)

    def problems(
        self,
        states: tuple[np.ndarray, np.ndarray, np.ndarray],
        d: InverseDynamicsDerivatives,
        reference: tuple[np.ndarray, np.ndarray, np.ndarray],
        weights: CostWeights,
        disturbance: np.ndarray | None = None,
    ) -> HorizonQPs:
        """The QPs of the N runs, over ``x = u − ū`` (the step from the linearisation plan:
        the plan's deviation is ``ū + x``).

        Args:
            states: The plan ``ū`` at the row times (:meth:`plan`): ``q``, ``q̇`` (N, K S + 1, nv),
                ``q̈`` (N, K S, nv).
            d: τ and its derivatives at the plan's knots 0 … K−1, (N, K, nv[, nv]).
            reference: ``q_r``, ``q̇_r``, ``q̈_r`` at the row times, each (1 or N, K S + 1, nv).
            weights: :meth:`weights`.
            disturbance: ``d̂`` [N·m], (N, nv): the torque the model misses, which the motor's
                torque ``τ_k − d̂`` must keep within its limit (None: 0).
        """
        qf, vf, af = states
        S = self.per_interval
        qb, vb, ab = qf[:, ::S], vf[:, ::S], af[:, ::S]
        qr, vr, ar = (x[:, ::S] for x in reference)
        N, K, nv = qb.shape[0], self.knots, self.nv
        n = K * nv
        # T: the torque's Jacobian over u, (N, K nv, K nv): [∂τ/∂q, ∂τ/∂q̇, M̂] at knot k times
        # [∂q_k/∂u; ∂q̇_k/∂u; ∂a_k/∂u] — block lower-triangular, M̂ on its diagonal
        D = np.concatenate((d.dtau_dq, d.dtau_dv, d.mass), axis=-1)  # (N, K, nv, 3 nv)
        T = np.matmul(D, self._QVE).reshape(N, n, n)
        # errors at ū (x = 0): e = A x + e(ū)
        dq, dv = qb - qr, vb - vr
        eq = dq[:, 1:].reshape(N, n)  # q_k − q_ref,k, knots 1..K
        ev = dv[:, 1:].reshape(N, n)
        et = np.matmul(D, np.concatenate((dq[:, :K], dv[:, :K], ab - ar[:, :K]), axis=-1)[..., None]).reshape(
            N, n
        )
        Tt = T.transpose(0, 2, 1)
        H = weights.tracking + weights.tau * np.matmul(Tt, T)
        g = np.matmul(np.concatenate((weights.q2 * eq, weights.v2 * ev), axis=1), self._QVs) + weights.tau[
            :, :, 0
        ] * np.matvec(Tt, et)
        # the cost in units of its largest curvature (the minimiser is the same; the solver's
        # absolute tolerances then mean the same on every arm and weight)
        scale = H.reshape(N, n * n)[:, :: n + 1].max(axis=1)[:, None]
        H, g = H / scale[..., None], g / scale
        C = np.empty((N, len(self.rows), n))
        C[:, self._effort] = T[:, self._effort_index]
        C[:, self._state] = self._C_state
        # each row's value at x = 0: the effort rows' τ̄ (less d̂), the state rows' plan at ū —
        # the velocity and acceleration rows with the reference's envelope over the neighbouring
        # row times: the deviation is linear (constant) between them, the reference may have a
        # corner there, so the bound holds over the whole interval, not only at its ends
        vr, ar_full = reference[1], reference[2]
        lo_bar, hi_bar = np.empty((N, len(self.rows))), np.empty((N, len(self.rows)))
        tau_bar = d.tau.reshape(N, n)[:, self._effort_index]
        if disturbance is not None:
            tau_bar = tau_bar - disturbance[:, self._effort_joint]
        lo_bar[:, self._effort] = hi_bar[:, self._effort] = tau_bar
        for out, envelope in ((lo_bar, np.minimum), (hi_bar, np.maximum)):
            v = vf + (_envelope(vr, envelope) - vr)
            a = af + (_envelope(ar_full, envelope)[:, :-1] - ar_full[:, :-1])
            plan = np.concatenate((qf.reshape(N, -1), v.reshape(N, -1), a.reshape(N, -1)), axis=1)
            out[:, self._state] = plan[:, self._state_at]
        return HorizonQPs(H, g, C, self._lower - lo_bar, self._upper - hi_bar, self.labels)


def _envelope(x: np.ndarray, pick: np.ufunc) -> np.ndarray:
    """Per row time (axis 1 of ``x``, (·, T, nv)), ``pick`` (``np.maximum`` or ``np.minimum``)
    of ``x`` there and at the row times either side: the reference's extreme over the two
    intervals a row time bounds."""
    y = np.array(np.broadcast_to(x, x.shape))
    pick(y[:, 1:], x[:, :-1], out=y[:, 1:])
    pick(y[:, :-1], x[:, 1:], out=y[:, :-1])
    return y


def _integration(K: int, h: float, S: int) -> tuple[np.ndarray, np.ndarray]:
    """``sq``, ``sv`` (K S + 1, K) of :class:`Horizon`: at row time ``t_i = i h / S``, piece ``j``
    (``[j h, (j + 1) h)``) has run for ``f = clip(t_i / h − j, 0, 1)`` of its length, so it moved
    the velocity by ``f h a_j`` and the position by ``h² f²/2 a_j`` while under way, by
    ``h² (t_i / h − j − ½) a_j`` once over."""
    r = (np.arange(K * S + 1) / S)[:, None] - np.arange(K)[None, :]  # t_i / h − j
    f = np.clip(r, 0.0, 1.0)
    sv = h * f
    sq = h * h * np.where(r >= 1.0, r - 0.5, 0.5 * f * f)
    return sq, sv


def _rows(K: int, S: int, limits: JointLimits, f: float) -> list[tuple[str, int, int, float, float]]:
    """The QP's inequality rows ``(kind, time index, joint, lower, upper)``, kind by kind
    (:data:`KINDS_IN_ROWS`): effort at the knots 0 … K−1 (the index is the knot's), acceleration
    at the row times 0 … K S − 1, velocity and position at 1 … K S (from the first row time on:
    the measured state is what it is); a joint without a kind of limit has none."""
    rows: list[tuple[str, int, int, float, float]] = []
    for kind in KINDS_IN_ROWS:
        given = np.flatnonzero(limits.given(kind))
        if kind is EFFORT:
            times = range(K)
        elif kind is ACCELERATION:
            times = range(K * S)
        else:
            times = range(1, K * S + 1)
        for ti in times:
            for jj in given:
                if kind is POSITION:
                    lo, hi = float(limits.position_lower[jj]), float(limits.position_upper[jj])
                else:
                    hi = f * float(getattr(limits, kind.name)[jj])
                    lo = -hi
                rows.append((kind.name, ti, int(jj), lo, hi))
    return rows


def _contiguous(index: np.ndarray) -> slice | np.ndarray:
    """``index`` as a slice when it is a run of consecutive integers (a view, not a copy)."""
    if index.size and (np.diff(index) == 1).all():
        return slice(int(index[0]), int(index[-1]) + 1)
    return index


WHOLE = 1e-9
"""How far ``horizon / knot_interval`` may lie from a whole number (relative) and still be one."""


def knots_of(horizon: float, interval: float) -> int:
    """``K = round(horizon / interval)`` knot intervals, at least 1: the horizon [s] in
    intervals of ``interval`` [s] (a horizon shorter than one interval is refused; one that is
    not a whole number of intervals is rounded: :func:`whole_knots` says whether it was)."""
    if not horizon >= interval:
        raise InvalidParameterError(
            "horizon", horizon, f"a horizon [s] of at least one knot interval ({interval:g} s)"
        )
    return max(1, round(horizon / interval))


def whole_knots(horizon: float, interval: float) -> bool:
    """Whether ``horizon`` [s] is a whole number of knot intervals ``interval`` [s] (to
    :data:`WHOLE`, relative)."""
    ratio = horizon / interval
    return abs(ratio - round(ratio)) <= WHOLE * max(1.0, ratio)


SOLVER_FACTOR = 10
"""ProxQP's dense solver holds up to ``10 (n + m)²`` numbers while it solves a QP of ``n``
variables and ``m`` rows (its KKT factor, the factorisation's workspace, the scaled copies;
measured from the process's peak address space: 4.5 to 9.2 for the twolink's and the Panda's
rows, ``m`` = 3 n to 4 n; ``tests/test_memory.py``)."""


def horizon_bytes(knots: int, limits: JointLimits, runs: int) -> int:
    """Bytes the QPs of a horizon of ``knots`` take at most (:func:`check_memory`): ``n = K nv``
    variables, ``m`` rows (:func:`row_count`), ``N`` runs::

        8 B × (10 (n + m)² + 9 n² + 2 m n + N (5 n² + m n))

    the solver's (:data:`SOLVER_FACTOR`; one QP at a time), the law's fixed matrices (the
    integration maps, 9 n² and 2 m n) and each run's Hessian, torque Jacobian and rows with
    their temporaries (5 n² + m n)."""
    n = knots * limits.nv
    m = row_count(knots, limits)
    return 8 * (SOLVER_FACTOR * (n + m) ** 2 + 9 * n * n + 2 * m * n + runs * (5 * n * n + m * n))


def row_count(knots: int, limits: JointLimits) -> int:
    """The horizon QP's rows: one per knot and effort limit, :data:`ROWS_PER_INTERVAL` per knot
    interval and other limit the robot has (position, velocity, acceleration)."""
    per_time = {kind: int(limits.given(kind).sum()) for kind in KINDS_IN_ROWS}
    state = sum(per_time.values()) - per_time[EFFORT]
    return knots * (per_time[EFFORT] + ROWS_PER_INTERVAL * state)


def check_memory(knots: int, interval: float, limits: JointLimits, runs: int, what: str = "horizon") -> None:
    """Refuse a horizon whose QPs would not fit in the memory available
    (:func:`~twolink_pin.memory.available_memory`: what is left under ``ulimit -v`` too), before
    anything of its size is made (:func:`horizon_bytes`): a solver that runs out of memory
    aborts the process (C++'s ``std::terminate``), it cannot be caught.

    Raises:
        InvalidParameterError: naming the horizon's knots, the bytes needed and available.
    """
    n = knots * limits.nv
    m = row_count(knots, limits)
    need, have = horizon_bytes(knots, limits, runs), available_memory()
    if have is not None and need > have:
        raise InvalidParameterError(
            what,
            f"{knots * interval:g} s ({knots} knots of {interval:g} s)",
            f"a horizon whose QPs fit in memory: {need / 1e6:.4g} MB needed for {runs} run(s) "
            f"(8 B × (10 (n + m)² + 9 n² + 2 m n + N (5 n² + m n)), n = {n} variables, m = {m} rows), "
            f"{have / 1e6:.4g} MB available",
        )
