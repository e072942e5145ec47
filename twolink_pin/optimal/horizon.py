"""The finite-horizon QP of a model-predictive law: the plan's knot accelerations, the believed
dynamics linearised on Pinocchio's RNEA derivatives, the joint limits as hard rows.

**Decision.** The plan over the horizon ``[t, t + K h]`` is piecewise-constant acceleration:
``a_k`` [rad/s²] on ``[t + k h, t + (k + 1) h)``, ``k = 0 … K − 1``, from the measured state
``(q_0, q̇_0)``. Its states at the knots are linear in ``u = (a_0, …, a_{K−1})`` (knot-major,
``K nv`` values)::

    q̇_k = q̇_0 + h Σ_{j<k} a_j,      q_k = q_0 + k h q̇_0 + h² Σ_{j<k} (k − j − ½) a_j

(exact for that acceleration: the velocity is linear between knots, so a velocity bound at the
knots holds between them too).

**Dynamics.** ``τ_k = RNEA(q_k, q̇_k, a_k)`` on the believed model, linearised at a plan
``ū`` (real-time iteration: the previous plan, shifted; its states rolled out from the measured
state the same way)::

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

**Rows** (hard; ``f``: ``limit_scale``): ``|τ_k| ≤ f τ_max`` at knots 0 … K−1, ``|a_k| ≤ f
q̈_max`` (where the arm has one), ``|q̇_k| ≤ f q̇_max`` and ``q_min ≤ q_k ≤ q_max`` at knots
1 … K — the state bounds from the first knot on, not at the measured state (which the plan
cannot change). A joint without a kind of limit has no row for it. Each row is labelled.
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

    Args:
        knots: ``K ≥ 1``, the number of knot intervals.
        interval: ``h`` [s] > 0.
        limits: The robot's joint limits (unscaled).
        limit_scale: ``f``, the fraction of the velocity, acceleration and effort limits used
            (one value for every run; the position range is kept).
    """

    def __init__(self, knots: int, interval: float, limits: JointLimits, limit_scale: float) -> None:
        self.knots, self.interval, self.limits, self.nv = int(knots), float(interval), limits, limits.nv
        K, h, nv = self.knots, self.interval, self.nv
        k = np.arange(K + 1)[:, None]
        j = np.arange(K)[None, :]
        self.sq = np.where(j < k, h * h * (k - j - 0.5), 0.0)
        """``q_k − q_0 − k h q̇_0 = Σ_j sq[k, j] a_j``, shape (K + 1, K) [s²]."""
        self.sv = np.where(j < k, h, 0.0)
        """``q̇_k − q̇_0 = Σ_j sv[k, j] a_j``, shape (K + 1, K) [s]."""
        eye = np.eye(nv)
        self._kh = (h * np.arange(K + 1))[:, None]
        self.Q = np.kron(self.sq, eye)  # ((K+1) nv, K nv)
        self.V = np.kron(self.sv, eye)
        self._Qk = self.Q.reshape(K + 1, nv, K * nv)
        self._Vk = self.V.reshape(K + 1, nv, K * nv)
        f = float(limit_scale)
        rows: list[tuple[str, int, int, float, float]] = []  # kind, knot, joint, lower, upper
        for kind in KINDS_IN_ROWS:
            given = np.flatnonzero(limits.given(kind))
            first = 0 if kind in (EFFORT, ACCELERATION) else 1
            last = K - 1 if kind in (EFFORT, ACCELERATION) else K
            for kn in range(first, last + 1):
                for jj in given:
                    if kind is POSITION:
                        lo, hi = limits.position_lower[jj], limits.position_upper[jj]
                    else:
                        hi = f * float(getattr(limits, kind.name)[jj])
                        lo = -hi
                    rows.append((kind.name, kn, int(jj), float(lo), float(hi)))
        self.rows = rows
        """Per inequality row: the kind's name, the knot, the joint (0-based), its bounds."""
        self.labels: Sequence[str] = tuple(self._label(r) for r in rows)
        """What each row bounds, in words (a message's bounds and value are the row's: the
        quantity less its value on the plan the QP steps from)."""
        kind_of = np.array([r[0] for r in rows], dtype=object)
        knot = np.array([r[1] for r in rows], dtype=int)
        joint = np.array([r[2] for r in rows], dtype=int)
        self._lower = np.array([r[3] for r in rows])
        self._upper = np.array([r[4] for r in rows])
        effort = np.flatnonzero(kind_of == EFFORT.name)
        state = np.flatnonzero(kind_of != EFFORT.name)
        C = np.zeros((len(rows), K * nv))
        for i in state:
            kn, jj = knot[i], joint[i]
            if kind_of[i] == ACCELERATION.name:
                C[i, kn * nv + jj] = 1.0
            elif kind_of[i] == VELOCITY.name:
                C[i] = self._Vk[kn, jj]
            else:
                C[i] = self._Qk[kn, jj]
        self._C_state = C[state]
        # the state rows' value at the measured state: q0_j + k h q̇0_j (position), q̇0_j (velocity)
        B = np.zeros((state.size, 2 * nv))
        for r, i in enumerate(state):
            if kind_of[i] == POSITION.name:
                B[r, joint[i]], B[r, nv + joint[i]] = 1.0, float(knot[i]) * h
            elif kind_of[i] == VELOCITY.name:
                B[r, nv + joint[i]] = 1.0
        self._state_map = np.concatenate((self._C_state, B), axis=1).T.copy()  # (K nv + 2 nv, rows)
        # the rows of each kind and the variables of the effort rows' torques: slices where contiguous
        self._effort = _contiguous(effort)
        self._effort_index = _contiguous(knot[effort] * nv + joint[effort])
        self._state = _contiguous(state)
        select = np.zeros((K, nv, K * nv))
        for block in range(K):
            select[block, :, block * nv : (block + 1) * nv] = eye
        self._QVE = np.concatenate((self._Qk[:K], self._Vk[:K], select), axis=1)  # (K, 3 nv, K nv)
        self._QVs = np.concatenate((self.Q[nv:], self.V[nv:]), axis=0)  # (2 K nv, K nv)

    def _label(self, row: tuple[str, int, int, float, float]) -> str:
        name, kn, jj, lo, hi = row
        joint = f"joint {jj + 1} ({self.limits.joint_names[jj]})"
        when = f"at knot {kn} (t + {kn * self.interval:.6g} s)"
        kind = {k.name: k for k in KINDS_IN_ROWS}[name]
        held = f"(row: {kind.symbol} less its value on the shifted plan [{kind.unit}])"
        if kind is POSITION:
            return f"the position range [{lo:.6g}, {hi:.6g}] rad of {joint} {when} {held}"
        return f"the {name} limit |{kind.symbol}| <= {hi:.6g} {kind.unit} of {joint} {when} {held}"

    @property
    def variables(self) -> int:
        """``K nv``: the QP's variables."""
        return self.knots * self.nv

    def rollout(self, q0: np.ndarray, v0: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The knot states ``q_k``, ``q̇_k`` [rad, rad/s], each (N, K + 1, nv), of the plan ``u``
        (N, K, nv) [rad/s²] from ``(q0, v0)`` (N, nv)."""
        q = q0[:, None] + self._kh * v0[:, None] + np.matmul(self.sq, u)
        v = v0[:, None] + np.matmul(self.sv, u)
        return q, v

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
        q0: np.ndarray,
        v0: np.ndarray,
        u_bar: np.ndarray,
        states: tuple[np.ndarray, np.ndarray],
        d: InverseDynamicsDerivatives,
        reference: tuple[np.ndarray, np.ndarray, np.ndarray],
        weights: CostWeights,
    ) -> HorizonQPs:
        """The QPs of the N runs, over ``x = u − ū`` (the step from the linearisation plan:
        the plan is ``ū + x``).

        Args:
            q0, v0: The measured state [rad, rad/s], (N, nv).
            u_bar: The plan linearised at [rad/s²], (N, K, nv).
            states: ``ū``'s knot states from ``(q0, v0)`` (:meth:`rollout`).
            d: τ and its derivatives at ``ū``'s states, knots 0 … K−1, (N, K, nv[, nv]).
            reference: ``q_ref``, ``q̇_ref``, ``q̈_ref`` at knots 0 … K, each (1 or N, K + 1, nv)
                or broadcastable to it (a constant acceleration: (1, 1, nv)).
            weights: :meth:`weights`.
        """
        N, K, nv = q0.shape[0], self.knots, self.nv
        n = K * nv
        qb, vb = states
        qr, vr, ar = reference
        # T: the torque's Jacobian over u, (N, K, nv, K nv); block lower-triangular, M̂ on the diagonal
        # T: the torque's Jacobian over u, (N, K nv, K nv): [∂τ/∂q, ∂τ/∂q̇, M̂] at knot k times
        # [∂q_k/∂u; ∂q̇_k/∂u; ∂a_k/∂u] — block lower-triangular, M̂ on its diagonal
        D = np.concatenate((d.dtau_dq, d.dtau_dv, d.mass), axis=-1)  # (N, K, nv, 3 nv)
        T = np.matmul(D, self._QVE).reshape(N, n, n)
        # errors at ū (x = 0): e = A x + e(ū)
        dq, dv = qb - qr, vb - vr
        eq = dq[:, 1:].reshape(N, n)  # q_k − q_ref,k, knots 1..K
        ev = dv[:, 1:].reshape(N, n)
        et = np.matmul(
            D, np.concatenate((dq[:, :K], dv[:, :K], u_bar - ar[:, :K]), axis=-1)[..., None]
        ).reshape(N, n)
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
        # each row's value at x = 0: the effort rows' τ̄, the state rows' (u, q0, q̇0) at ū
        at_bar = np.empty((N, len(self.rows)))
        at_bar[:, self._effort] = d.tau.reshape(N, n)[:, self._effort_index]
        at_bar[:, self._state] = np.matmul(
            np.concatenate((u_bar.reshape(N, n), q0, v0), axis=1), self._state_map
        )
        lower, upper = self._lower - at_bar, self._upper - at_bar
        return HorizonQPs(H, g, C, lower, upper, self.labels)


def _contiguous(index: np.ndarray) -> slice | np.ndarray:
    """``index`` as a slice when it is a run of consecutive integers (a view, not a copy)."""
    if index.size and (np.diff(index) == 1).all():
        return slice(int(index[0]), int(index[-1]) + 1)
    return index


def knots_of(horizon: float, interval: float) -> int:
    """``K = round(horizon / interval)`` knot intervals, at least 1: the horizon [s] in
    intervals of ``interval`` [s] (a horizon shorter than one interval is refused)."""
    if not horizon >= interval:
        raise InvalidParameterError(
            "horizon", horizon, f"a horizon [s] of at least one knot interval ({interval:g} s)"
        )
    return max(1, round(horizon / interval))


SOLVER_FACTOR = 10
"""ProxQP's dense solver holds up to ``10 (n + m)²`` numbers while it solves a QP of ``n``
variables and ``m`` rows (its KKT factor, the factorisation's workspace, the scaled copies;
measured from the process's peak address space: 4.5 to 9.2 for the twolink's and the Panda's
rows, ``m`` = 3 n to 4 n; ``tests/test_memory.py``)."""


def horizon_bytes(knots: int, limits: JointLimits, runs: int) -> int:
    """Bytes the QPs of a horizon of ``knots`` take at most (:func:`check_memory`): ``n = K nv``
    variables, ``m`` rows (one per knot and limit the robot has), ``N`` runs::

        8 B × (10 (n + m)² + 9 n² + 2 m n + N (5 n² + m n))

    the solver's (:data:`SOLVER_FACTOR`; one QP at a time), the law's fixed matrices (the
    integration maps, 9 n² and 2 m n) and each run's Hessian, torque Jacobian and rows with
    their temporaries (5 n² + m n)."""
    n = knots * limits.nv
    m = knots * sum(int(limits.given(kind).sum()) for kind in KINDS_IN_ROWS)
    return 8 * (SOLVER_FACTOR * (n + m) ** 2 + 9 * n * n + 2 * m * n + runs * (5 * n * n + m * n))


def check_memory(knots: int, interval: float, limits: JointLimits, runs: int, what: str = "horizon") -> None:
    """Refuse a horizon whose QPs would not fit in the memory available
    (:func:`~twolink_pin.memory.available_memory`: what is left under ``ulimit -v`` too), before
    anything of its size is made (:func:`horizon_bytes`): a solver that runs out of memory
    aborts the process (C++'s ``std::terminate``), it cannot be caught.

    Raises:
        InvalidParameterError: naming the horizon's knots, the bytes needed and available.
    """
    n = knots * limits.nv
    m = knots * sum(int(limits.given(kind).sum()) for kind in KINDS_IN_ROWS)
    need, have = horizon_bytes(knots, limits, runs), available_memory()
    if have is not None and need > have:
        raise InvalidParameterError(
            what,
            f"{knots * interval:g} s ({knots} knots of {interval:g} s)",
            f"a horizon whose QPs fit in memory: {need / 1e6:.4g} MB needed for {runs} run(s) "
            f"(8 B × (10 (n + m)² + 9 n² + 2 m n + N (5 n² + m n)), n = {n} variables, m = {m} rows), "
            f"{have / 1e6:.4g} MB available",
        )
