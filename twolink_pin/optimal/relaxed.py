"""A QP whose softer rows give way, in a stated order, when its rows cannot all hold.

A law that keeps limits as the rows of a QP (``qp-osc``, ``mpc``) meets states where no point
meets them all — a push it cannot resist, a start beyond a range. Rather than stop, it solves
two QPs, a hierarchy of two levels (as the field's hierarchical QP controllers do; Kanoun,
Lamiraux & Wieber 2011, Escande, Mansard & Wieber 2014):

1. **The least relaxation.** A slack ``s_g ≥ 0`` per soft group ``g`` (a row, or every row of
   one kind and joint over a horizon), the hard rows kept, the cost the **exact penalty**
   (Fletcher, *Practical Methods of Optimization*, §12.3) of the slacks alone::

       min  Σ_g ρ_g s_g + ½ μ ‖s‖² + ½ ε ‖x‖²
       s.t. hard rows   l_j <= C_j x <= u_j
            soft rows   l_i − s_g(i) <= C_i x <= u_i + s_g(i),   s >= 0

   The L1 penalty is exact: when the rows can all hold, ``s = 0`` is its minimiser (any
   ``ρ > 0``: the objective's slope at 0 is ``ρ``, the regularisers ``μ``, ``ε`` are far
   smaller), so nothing is relaxed that need not be; when they cannot, the slacks are the
   least that restores feasibility, and the **order** is the penalties': each priority (0, 1,
   2 — position, velocity, acceleration) weighs :data:`ORDER_RATIO` times the one before, so a
   velocity row gives way only where relaxing the position rows cannot restore feasibility at
   a hundredth of the cost. Hard rows (priority −1, the effort rows) never give way; they must
   hold together (a law's effort box always can).
2. **The law's own QP within it**: the same QP, each soft row's bounds widened by its group's
   slack, solved as any other (:func:`~twolink_pin.optimal.solve_qp`). The task is served as
   well as the least relaxation allows — never traded against a limit (a single penalised QP
   would trade the task's error against the limits' excess at whatever exchange rate its
   penalties set, and let a pushed arm's wrist spin past its range to keep the hand's path).

Both are solved equilibrated (:func:`~twolink_pin.optimal.qp.equilibrate`), so that a slack is
measured alike on every row; what is reported is each row's excess at the solution, in the
row's own unit.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from twolink_pin.optimal.qp import QP, QPSolution, equilibrate, solve_qp

ORDER_RATIO = 1e2
"""Each priority's penalty over the one before (position, then velocity, then acceleration)."""
SLACK_CURVATURE = 1e-6
"""``μ``, the slacks' curvature (their penalty's slope is 1 for priority 0): a strictly convex
first level, without moving its minimiser by more than ``μ s / ρ``."""
REGULARISATION = 1e-6
"""``ε``, the variables' curvature in the first level (it asks only for a feasible point; at
1e-9 ProxQP did not converge in 1000 iterations on a twolink plan started beyond its range)."""
SLACK_TOLERANCE = 1e-7
"""A relaxation (equilibrated: relative to its row's largest coefficient) below this is the
solver's rounding, not a relaxation: reported as 0."""
FIRST_ACCEPT = 1e-6
"""The first level stopped at its iteration cap is accepted with residuals below this: its
slacks need no more (the second level widens the rows by them and a margin)."""
MARGIN = 1e-9
"""Added to each widened bound of the second level (equilibrated units), so that a row the
least relaxation leaves exactly on its bound is not infeasible by the first solve's rounding."""


class RelaxedSolution(NamedTuple):
    """What :func:`solve_relaxed` returns."""

    solution: QPSolution
    """The second level's minimiser over the original variables (``x``, the multipliers of the
    original rows, ProxQP's iterations and scaled residuals)."""
    slack: np.ndarray
    """How far each row lies beyond its bounds at the solution, in the row's own unit,
    (n_in,); 0 for a row that held (and for every hard row)."""
    widened: QP
    """The second level's problem (equilibrated): the law's QP with the soft rows widened by the
    least relaxation (to check its KKT conditions)."""


def least_relaxation(qp: QP, priority: np.ndarray, group: np.ndarray | None = None) -> tuple[QP, np.ndarray]:
    """The first level's problem over ``(x, s)`` for the (equilibrated) ``qp``'s rows whose
    ``priority`` (n_in,) is ``>= 0``, and the slack each soft row shares (its slot in ``s``, by
    ``group``: rows of one group — one kind and joint over a horizon — give way by one amount;
    None: a slack per row). A group's penalty is its rows' highest priority's.

    Rows: the hard rows as they are; per soft row ``C_i x + s_g >= l_i`` and
    ``C_i x − s_g <= u_i`` (one side each); ``s >= 0``.
    """
    assert qp.C is not None and qp.l is not None and qp.u is not None
    soft = np.flatnonzero(priority >= 0)
    hard = np.flatnonzero(priority < 0)
    labels_of = np.arange(soft.size) if group is None else np.asarray(group)[soft]
    _, slot = np.unique(labels_of, return_inverse=True)
    m = int(slot.max()) + 1 if slot.size else 0
    n, k = qp.g.shape[0], soft.size
    H = np.zeros((n + m, n + m))
    H[:n, :n] = REGULARISATION * np.eye(n)
    H[n:, n:] = SLACK_CURVATURE * np.eye(m)
    rank = np.zeros(m)
    np.maximum.at(rank, slot, priority[soft].astype(float))
    g = np.concatenate((np.zeros(n), ORDER_RATIO**rank))
    share = np.zeros((k, m))
    share[np.arange(k), slot] = 1.0
    inf = np.full(k, np.inf)
    C = np.concatenate(
        (
            np.concatenate((qp.C[hard], np.zeros((hard.size, m))), axis=1),
            np.concatenate((qp.C[soft], share), axis=1),
            np.concatenate((qp.C[soft], -share), axis=1),
            np.concatenate((np.zeros((m, n)), np.eye(m)), axis=1),
        )
    )
    lower = np.concatenate((qp.l[hard], qp.l[soft], -inf, np.zeros(m)))
    upper = np.concatenate((qp.u[hard], inf, qp.u[soft], np.full(m, np.inf)))
    return QP(H, g, qp.A, qp.b, C, lower, upper), slot


def solve_relaxed(
    qp: QP,
    priority: np.ndarray,
    *,
    group: np.ndarray | None = None,
    what: str = "QP",
    eps: float = 1e-9,
    max_iter: int = 1000,
    accept: float | None = None,
    max_inner: int | None = None,
) -> RelaxedSolution:
    """Solve ``qp`` with its rows of ``priority >= 0`` relaxed as little as they must be, in
    order (the module docstring's two levels).

    Args:
        qp: The problem (inequality rows required).
        priority: Per inequality row, (n_in,): −1 hard, else its priority (0 gives way first).
        group: Per inequality row, the slack it shares with the rows of the same group (None:
            one each).
        what: The problem in words, for messages.
        eps, max_iter, accept, max_inner: As :func:`~twolink_pin.optimal.solve_qp`'s (on the
            scaled problems).

    Raises:
        OptimizationError: a level did not converge, or the hard rows alone cannot hold.
    """
    priority = np.asarray(priority)
    scaled, back = equilibrate(qp)
    assert scaled.C is not None and scaled.l is not None and scaled.u is not None
    first, slot = least_relaxation(scaled, priority, group)
    found = solve_qp(
        first, eps=eps, max_iter=max_iter, what=f"{what} (its least relaxation)", accept=max(accept or 0.0, FIRST_ACCEPT),
        infeasibility_eps=eps, explain=False, gap_rel=eps, max_inner=max_inner,
    )  # fmt: skip
    n = qp.g.shape[0]
    soft = np.flatnonzero(priority >= 0)
    given = np.maximum(found.x[n:], 0.0)
    room = np.zeros(priority.size)
    room[soft] = np.where(given[slot] > SLACK_TOLERANCE, given[slot] + MARGIN, 0.0)
    widened = scaled._replace(l=scaled.l - room, u=scaled.u + room)
    solution = solve_qp(
        widened, eps=eps, max_iter=max_iter, what=what, accept=accept, infeasibility_eps=eps, explain=False,
        max_inner=max_inner,
    )  # fmt: skip
    cx = scaled.C[soft] @ solution.x
    excess = np.maximum(np.maximum(scaled.l[soft] - cx, cx - scaled.u[soft]), 0.0)
    slack = np.zeros(priority.size)
    slack[soft] = np.where(excess > SLACK_TOLERANCE, excess, 0.0) / back.R[soft]  # in each row's own unit
    return RelaxedSolution(back.unscaled(solution), slack, widened)
