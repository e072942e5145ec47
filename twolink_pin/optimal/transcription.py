"""A trajectory problem on a :class:`~twolink_pin.optimal.layout.SplineLayout`: its costs, its
constraints, and their linearisation at an iterate (what each SQP step solves).

**Costs** (:class:`~twolink_pin.optimal.cost.Cost`), integrals by Gauss–Legendre quadrature on
every knot interval (``cost_points``), in seconds of physical time::

    f(x) = w_τ ∫ τᵀτ dt + w_q ∫ ‖q − q_ref‖² dt + w_v ∫ ‖q̇ − q̇_ref‖² dt + w_j ∫ ‖q⃛‖² dt + w_T Σ h_k

with ``τ`` from the problem's :data:`~twolink_pin.dynamics.InverseDynamics` callable. The
quadratic terms are sums of squares of residuals ``r(x)``, linearised (Gauss–Newton:
Hessian ``2 JᵀJ``, no second derivatives of the dynamics); the time term is linear.

**Equalities** (:class:`Pin`: ``q^{(r)}(segment, σ) = target``): via points, rest at the
ends, an initial state; and the continuity of ``q, q̇ .. q^{(r)}`` where two segments meet
(``r = continuity_order``, 4 by default; linear for fixed durations). A row of order ``r`` is multiplied by ``time_scale^r`` and
divided by its largest basis entry, so that its value is about the change of a coefficient
[rad] that would make it hold (a via point's row: its error in radians).

**Inequalities** at ``check_points``: each joint's position range, velocity, acceleration
and effort limits where the robot has them (:class:`~twolink_pin.limits.JointLimits`), each
row divided by its limit (so a violation is a fraction of it) and tightened by ``margin``
(a fraction of the limit, so that what the linearisation and the solver's tolerance leave
stays inside); effort linearised at the iterate. Free durations stay above ``min_duration``.
What each row is in words: :mod:`~twolink_pin.optimal.row_labels`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from twolink_pin.dynamics.derivatives import InverseDynamics, InverseDynamicsDerivatives
from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import EFFORT, KINDS, POSITION, JointLimits, LimitKind
from twolink_pin.optimal.cost import Cost
from twolink_pin.optimal.layout import Points, SplineLayout
from twolink_pin.optimal.row_labels import RowLabels

CONTINUITY_ORDER = 4
"""Derivatives of ``q`` kept continuous where segments meet (a quintic spline is ``C⁴``)."""


class Pin(NamedTuple):
    """Equalities ``q^{(order)} = target`` at some points."""

    name: str
    """What they are (``via``, ``rest``, ``initial``), for messages and updates."""
    points: Points
    """Where."""
    order: int
    """Which derivative (0: position [rad], 1: velocity [rad/s], ...)."""
    target: np.ndarray
    """The values, shape (K, nv)."""


class Evaluation(NamedTuple):
    """A problem's values (and, linearised, Jacobians) at an iterate ``x``."""

    cost: float
    """``f(x)``."""
    residual: np.ndarray
    """``r(x)`` (``f = ‖r‖² + w_T Σ h``)."""
    equality: np.ndarray
    """Equality rows' values (zero when they hold), scaled to radians."""
    inequality: np.ndarray
    """Inequality rows' values, each divided by its limit."""
    lower: np.ndarray
    """Their lower bounds (``-inf``: none)."""
    upper: np.ndarray
    """Their upper bounds (``inf``: none)."""
    tau: np.ndarray
    """Torque at the check points [N·m], shape (K, nv)."""
    gradient: np.ndarray | None = None
    """``∇f`` (linearised only)."""
    residual_jacobian: np.ndarray | None = None
    """``∂r/∂x``."""
    equality_jacobian: np.ndarray | None = None
    """``∂(equality rows)/∂x``."""
    inequality_jacobian: np.ndarray | None = None
    """``∂(inequality rows)/∂x``."""

    @property
    def violation(self) -> float:
        """Largest constraint violation: ``|equality|`` [rad], inequality excess [fraction of
        its limit]; 0 when all hold."""
        parts = [0.0]
        if self.equality.size:
            parts.append(float(np.abs(self.equality).max()))
        if self.inequality.size:
            parts.append(
                float(np.max(np.maximum(self.lower - self.inequality, self.inequality - self.upper)))
            )
        return max(parts)

    @property
    def l1_violation(self) -> float:
        """``‖equality‖₁ + Σ inequality excess`` (the merit's penalty term)."""
        excess = np.maximum(np.maximum(self.lower - self.inequality, self.inequality - self.upper), 0.0)
        return float(np.abs(self.equality).sum() + excess.sum())


@dataclass(frozen=True)
class TrajectoryProblem:
    """A joint trajectory problem (module docstring).

    Attributes:
        layout: The variables.
        dynamics: ``(q, q̇, q̈) -> τ`` and its derivatives, batched.
        limits: The joint limits the inequalities keep (each kind where a joint has one).
        cost: The cost's weights.
        cost_points: Where the integrals are evaluated (a quadrature).
        check_points: Where the limits are constrained.
        pins: Equalities at points.
        kinds: The limit kinds constrained at the check points (default all four, where given).
        hull: Kinds of ``position``, ``velocity``, ``acceleration`` constrained on the spline's
            coefficients instead (:meth:`~twolink_pin.optimal.spline.BSplineBasis.derivative_coefficients`:
            everywhere, no grid; conservative by how far a control point lies outside its curve;
            few rows, where an active arc at the check points made many, degenerate ones).
        margin: Fraction of each limit kept free (default 1e-5: more than the SQP's
            feasibility tolerance, so what it leaves stays inside the limit).
        time_scale: A typical segment duration [s] (scales the equality rows).
        min_duration: Shortest segment when durations are free [s].
        continuity: Whether segments join (equality rows).
        continuity_order: The highest derivative of ``q`` continuous where segments join
            (default :data:`CONTINUITY_ORDER`: ``C⁴``, a quintic spline's smoothness; ``2`` lets
            the jerk jump there, as the least-effort motion's does at a via point).
    """

    layout: SplineLayout
    dynamics: InverseDynamics
    limits: JointLimits
    cost: Cost
    cost_points: Points
    check_points: Points
    pins: tuple[Pin, ...] = ()
    kinds: tuple[LimitKind, ...] = KINDS
    hull: tuple[LimitKind, ...] = ()
    margin: float = 1e-5
    time_scale: float = 1.0
    min_duration: float = 1e-3
    continuity: bool = True
    continuity_order: int = CONTINUITY_ORDER
    _joins: dict[tuple[int, int], tuple[object, Points, Points]] = field(
        default_factory=dict, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        if self.limits.nv != self.layout.nv:
            raise InvalidParameterError("limits", self.limits.nv, f"limits of {self.layout.nv} joints")
        if not (isinstance(self.continuity_order, int) and 0 <= self.continuity_order <= CONTINUITY_ORDER):
            raise InvalidParameterError(
                "continuity_order", self.continuity_order, f"an integer from 0 to {CONTINUITY_ORDER}"
            )
        if not (0 <= self.margin < 0.5):
            raise InvalidParameterError("margin", self.margin, "a fraction 0 <= m < 0.5 of each limit")

    # -- changes ---------------------------------------------------------------------------------
    def with_check_points(self, points: Points) -> TrajectoryProblem:
        """The same problem constrained at ``points`` instead."""
        return replace(self, check_points=points)

    def with_pin(self, name: str, order: int, target: np.ndarray) -> TrajectoryProblem:
        """The same problem with the targets of its pin ``name`` of ``order`` replaced
        (a receding horizon's new initial state)."""
        pins = tuple(
            p._replace(target=np.asarray(target, dtype=float).reshape(p.target.shape))
            if p.name == name and p.order == order
            else p
            for p in self.pins
        )
        return replace(self, pins=pins)

    def with_cost(self, cost: Cost) -> TrajectoryProblem:
        """The same problem with another cost (a receding horizon's new reference)."""
        return replace(self, cost=cost)

    # -- evaluation ------------------------------------------------------------------------------
    def evaluate(self, x: np.ndarray, jacobians: bool = False) -> Evaluation:
        """Values at ``x`` (and, with ``jacobians``, the linearisation)."""
        layout = self.layout
        kin_cost = [layout.derivative(x, self.cost_points, r) for r in range(4)]
        kin_check = [layout.derivative(x, self.check_points, r) for r in range(3)]
        needs_tau_cost = self.cost.effort > 0
        needs_tau_check = EFFORT in self.kinds and bool(self.limits.given(EFFORT).any())
        terms = self._torques(kin_cost, kin_check, needs_tau_cost, needs_tau_check)
        tau_cost, tau_check = terms[0], terms[1]
        residual, jac_r = self._residual(x, kin_cost, tau_cost, terms[2], jacobians)
        h = layout.durations_of(x)
        cost = float(residual @ residual) + (
            self.cost.time * float(h.sum()) if layout.free_durations else 0.0
        )
        equality, jac_e = self._equalities(x, jacobians)
        ineq, lower, upper, jac_i = self._inequalities(x, kin_check, tau_check, terms[3], jacobians)
        if not jacobians:
            return Evaluation(cost, residual, equality, ineq, lower, upper, tau_check)
        assert jac_r is not None
        gradient = 2.0 * jac_r.T @ residual
        if layout.free_durations:
            gradient[layout.segments * layout.block :] += self.cost.time
        return Evaluation(
            cost, residual, equality, ineq, lower, upper, tau_check, gradient, jac_r, jac_e, jac_i
        )

    def _torques(
        self, kin_cost: list[np.ndarray], kin_check: list[np.ndarray], at_cost: bool, at_check: bool
    ) -> tuple[np.ndarray, np.ndarray, InverseDynamicsDerivatives | None, InverseDynamicsDerivatives | None]:
        """τ at the cost and check points (one call of the dynamics on both), and the terms."""
        nv = self.layout.nv
        empty = np.zeros((0, nv))
        groups = [(kin_cost, at_cost), (kin_check, at_check)]
        q = np.concatenate([k[0] if use else empty for k, use in groups])
        if q.shape[0] == 0:
            return np.zeros((self.cost_points.size, nv)), np.zeros((self.check_points.size, nv)), None, None
        v = np.concatenate([k[1] if use else empty for k, use in groups])
        a = np.concatenate([k[2] if use else empty for k, use in groups])
        terms = self.dynamics(q, v, a)
        n_cost = self.cost_points.size if at_cost else 0
        first = InverseDynamicsDerivatives(*(t[:n_cost] for t in terms)) if at_cost else None
        second = InverseDynamicsDerivatives(*(t[n_cost:] for t in terms)) if at_check else None
        tau_cost = first.tau if first is not None else np.zeros((self.cost_points.size, nv))
        tau_check = second.tau if second is not None else np.zeros((self.check_points.size, nv))
        return tau_cost, tau_check, first, second

    def torque_jacobian(
        self,
        x: np.ndarray,
        points: Points,
        terms: InverseDynamicsDerivatives,
        kin: list[np.ndarray] | None = None,
    ) -> np.ndarray:
        """``∂τ/∂x`` at ``points`` from the dynamics' derivatives (``kin``: q, q̇, q̈ there,
        when known), shape (K, nv, size): ``Σ_r G_r ∂q^{(r)}/∂x`` with ``G = (∂τ/∂q, ∂τ/∂q̇, M)``."""
        layout = self.layout
        K, nv = points.size, layout.nv
        h = layout.durations_of(x)[points.segment]
        block = np.zeros((K, nv, layout.n, nv))  # [k, a, i, b]: ∂τ_a/∂C_{seg, i, b}
        for order, G in ((0, terms.dtau_dq), (1, terms.dtau_dv), (2, terms.mass)):
            block += np.einsum("kab,ki->kaib", G, points.rows[order] / h[:, None] ** order)
        J = np.zeros((K, nv, layout.size))
        k = np.arange(K)[:, None, None, None]
        a = np.arange(nv)[None, :, None, None]
        b = np.arange(nv)[None, None, None, :]
        J[k, a, layout.columns(points)[:, None, :, None] + b] = block
        if layout.free_durations:
            if kin is None:
                kin = [layout.derivative(x, points, r) for r in range(3)]
            dh = -np.einsum("kab,kb->ka", terms.dtau_dv, kin[1]) - 2.0 * np.einsum(
                "kab,kb->ka", terms.mass, kin[2]
            )
            J[np.arange(K), :, layout.duration_column(points)] = dh / h[:, None]
        return J

    def _residual(
        self,
        x: np.ndarray,
        kin: list[np.ndarray],
        tau: np.ndarray,
        terms: InverseDynamicsDerivatives | None,
        jacobians: bool,
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """The cost's residuals and, with ``jacobians``, their Jacobian."""
        layout, cost, points = self.layout, self.cost, self.cost_points
        h = layout.durations_of(x)[points.segment]
        sqrt_w = np.sqrt(points.weight * h)[:, None]
        blocks: list[tuple[float, np.ndarray, int | None]] = []  # (weight, value, order or None: τ)
        if cost.effort > 0:
            blocks.append((cost.effort, tau, None))
        if cost.position > 0 and cost.reference is not None:
            blocks.append((cost.position, kin[0] - cost.reference[0], 0))
        if cost.velocity > 0 and cost.reference is not None:
            blocks.append((cost.velocity, kin[1] - cost.reference[1], 1))
        if cost.jerk > 0:
            blocks.append((cost.jerk, kin[3], 3))
        values = [np.sqrt(w) * sqrt_w * value for w, value, _ in blocks]
        residual = np.concatenate([v.ravel() for v in values]) if values else np.zeros(0)
        if not jacobians:
            return residual, None
        parts = []
        for (w, _value, order), scaled in zip(blocks, values, strict=True):
            if order is None:
                assert terms is not None
                J = self.torque_jacobian(x, points, terms, kin)
            else:
                J = layout.jacobian(x, points, order, kin[order])
            J = np.sqrt(w) * sqrt_w[:, :, None] * J
            if layout.free_durations:  # the weight's sqrt(h)
                cols = layout.segments * layout.block + points.segment
                J[np.arange(points.size), :, cols] += scaled / (2.0 * h[:, None])
            parts.append(J.reshape(-1, layout.size))
        jac = np.concatenate(parts) if parts else np.zeros((0, layout.size))
        return residual, jac

    def _equalities(self, x: np.ndarray, jacobians: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """The pins and the continuity rows (module docstring) and their Jacobian."""
        layout, scale = self.layout, self.time_scale
        values: list[np.ndarray] = []
        jacs: list[np.ndarray] = []
        for pin in self.pins:
            value = layout.derivative(x, pin.points, pin.order)
            row = _row_scale(pin.points, pin.order, scale)
            values.append(((value - pin.target) * row).ravel())
            if jacobians:
                J = layout.jacobian(x, pin.points, pin.order, value) * row[:, :, None]
                jacs.append(J.reshape(-1, layout.size))
        if self.continuity and layout.segments > 1:
            ends, starts = self._join_points()
            for order in range(0, min(self.continuity_order, layout.basis.degree - 1) + 1):
                left = layout.derivative(x, ends, order)
                right = layout.derivative(x, starts, order)
                row = _row_scale(ends, order, scale)
                values.append(((left - right) * row).ravel())
                if jacobians:
                    J = layout.jacobian(x, ends, order, left) - layout.jacobian(x, starts, order, right)
                    jacs.append((J * row[:, :, None]).reshape(-1, layout.size))
        value = np.concatenate(values) if values else np.zeros(0)
        if not jacobians:
            return value, None
        return value, (np.concatenate(jacs) if jacs else np.zeros((0, layout.size)))

    def _join_points(self) -> tuple[Points, Points]:
        """Where two segments meet: the ends of the earlier ones, the starts of the later ones
        (made once per basis and segment count: problems made by :meth:`with_check_points`
        share them; the basis is kept with them, so that its ``id`` is not reused)."""
        basis, S = self.layout.basis, self.layout.segments
        key = (id(basis), S)
        if key not in self._joins:
            ends = self.layout.points(np.arange(S - 1), np.ones(S - 1))
            self._joins[key] = (basis, ends, self.layout.points(np.arange(1, S), np.zeros(S - 1)))
        _, ends, starts = self._joins[key]
        return ends, starts

    def _inequalities(
        self,
        x: np.ndarray,
        kin: list[np.ndarray],
        tau: np.ndarray,
        terms: InverseDynamicsDerivatives | None,
        jacobians: bool,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
        """Limit rows at the check points (divided by their limit, tightened by the margin)
        and the durations' lower bounds; with ``jacobians``, their Jacobian."""
        layout, points, limits = self.layout, self.check_points, self.limits
        values, lowers, uppers, jacs = [], [], [], []
        for kind in self.kinds:
            given = limits.given(kind)
            if not given.any():
                continue
            lower, upper = limits.bounds(kind)
            scale, lo, hi = self.row_bounds(kind, lower, upper)
            value = tau if kind is EFFORT else kin[kind.order or 0]
            values.append((value[:, given] / scale[given]).ravel())
            lowers.append(np.broadcast_to(lo[given], (points.size, int(given.sum()))).ravel())
            uppers.append(np.broadcast_to(hi[given], (points.size, int(given.sum()))).ravel())
            if jacobians:
                if kind is EFFORT:
                    assert terms is not None
                    J = self.torque_jacobian(x, points, terms, kin)
                else:
                    J = layout.jacobian(x, points, kind.order or 0, value)
                jacs.append((J[:, given, :] / scale[given][None, :, None]).reshape(-1, layout.size))
        for kind in self.hull:
            rows = self._hull_rows(x, kind, jacobians)
            if rows is not None:
                values.append(rows[0])
                lowers.append(rows[1])
                uppers.append(rows[2])
                if jacobians:
                    jacs.append(rows[3])
        if layout.free_durations:
            S = layout.segments
            values.append(layout.durations_of(x) / self.min_duration)
            lowers.append(np.ones(S))
            uppers.append(np.full(S, np.inf))
            J = np.zeros((S, layout.size))
            J[np.arange(S), S * layout.block + np.arange(S)] = 1.0 / self.min_duration
            jacs.append(J)
        if not values:
            return np.zeros(0), np.zeros(0), np.zeros(0), np.zeros((0, layout.size)) if jacobians else None
        jac = np.concatenate(jacs) if jacobians else None
        return np.concatenate(values), np.concatenate(lowers), np.concatenate(uppers), jac

    def grid_rows(self, points: int) -> int:
        """How many of the inequality rows are at the check points, for ``points`` of them
        (they come first, kind by kind, each point's given joints in turn)."""
        return points * sum(int(self.limits.given(kind).sum()) for kind in self.kinds)

    def _hull_rows(
        self, x: np.ndarray, kind: LimitKind, jacobians: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """``kind``'s rows on the coefficients of its derivative (``hull``): value, bounds,
        Jacobian (empty without ``jacobians``); None when no joint has the limit."""
        layout, limits = self.layout, self.limits
        given = limits.given(kind)
        if not given.any():
            return None
        order = kind.order or 0
        scale, lo, hi = self.row_bounds(kind, *limits.bounds(kind))
        M = layout.basis.derivative_coefficients(order)  # (m, n)
        C, h = layout.coefficients(x), layout.durations_of(x)
        S, m, nv = layout.segments, M.shape[0], layout.nv
        value = np.einsum("an,snj->saj", M, C) / (h[:, None, None] ** order)  # (S, m, nv)
        rows = (value[:, :, given] / scale[given]).ravel()
        count = S * m * int(given.sum())
        lower, upper = np.tile(lo[given], S * m), np.tile(hi[given], S * m)
        if not jacobians:
            return rows, lower, upper, np.zeros((0, layout.size))
        J = np.zeros((S, m, nv, layout.size))
        j = np.arange(nv)
        for k in range(S):
            block = np.einsum("an,ij->aijn", M / h[k] ** order, np.eye(nv))  # [a, row joint, coef, joint]
            J[k, :, :, k * layout.block : (k + 1) * layout.block] = block.transpose(0, 1, 3, 2).reshape(
                m, nv, -1
            )
            if layout.free_durations and order > 0:
                J[k, :, j, S * layout.block + k] = (-order * value[k] / h[k]).T
        J = J[:, :, given, :] / scale[given][None, None, :, None]
        return rows, lower, upper, J.reshape(count, layout.size)

    def row_bounds(
        self, kind: LimitKind, lower: np.ndarray, upper: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(scale, lo, hi)`` of ``kind``'s rows per joint: a row is the quantity divided by
        ``scale``, kept in ``[lo, hi]`` (the limit less the margin)."""
        if kind is POSITION:
            width = np.where(np.isfinite(upper - lower), upper - lower, 1.0)
            scale = np.where(np.isfinite(width) & (width > 0), np.maximum(np.abs(lower), np.abs(upper)), 1.0)
            scale = np.where(np.isfinite(scale) & (scale > 0), scale, 1.0)
            return scale, (lower + self.margin * width) / scale, (upper - self.margin * width) / scale
        scale = np.where(np.isfinite(upper), upper, 1.0)
        bound = np.where(np.isfinite(upper), 1.0 - self.margin, np.inf)
        return scale, -bound, bound

    def labels(self, x: np.ndarray) -> Sequence[str]:
        """What each inequality row is (``effort of joint 2 (joint2) at t = 0.310 s``), in
        the order of :meth:`evaluate`'s rows."""
        return RowLabels(self, self.layout.times(x, self.check_points))


def _row_scale(points: Points, order: int, time_scale: float) -> np.ndarray:
    """The factor of each equality row of ``order`` at ``points`` (shape (K, 1)): ``time_scale^order``
    over the largest basis entry, so that a row's value is about the change of a coefficient
    [rad] that would make it hold."""
    largest = np.abs(points.rows[order]).max(axis=1)
    return (time_scale**order / np.where(largest > 0, largest, 1.0))[:, None]


__all__ = ["CONTINUITY_ORDER", "Cost", "Evaluation", "Pin", "TrajectoryProblem"]
