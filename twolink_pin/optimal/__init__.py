"""Optimisation on the robot's model: one core, used offline (retimed and optimal references)
and in the loop (the model-predictive and the constrained task-space laws).

It sits below ``trajectory/`` and ``controllers/`` and uses only ``model/``, ``dynamics/``
and ``limits/``.

==========================  ================================================================
``qp.py``                   :func:`solve_qp`: the one QP solve (ProxQP; the unconstrained
                            minimiser first, equilibrated on request), :func:`kkt_residual`
``spline.py``               :class:`BSplineBasis`: values and derivatives of a B-spline as matrices
``layout.py``               :class:`SplineLayout`: a trajectory in spline segments, its variables
                            and Jacobians; :class:`Points` where it is evaluated
``cost.py``                 :class:`Cost`: the weights of a problem's cost terms
``transcription.py``        :class:`TrajectoryProblem`: costs, equalities (:class:`Pin`), limits,
                            linearised on the dynamics' derivatives
``row_labels.py``           what each limit row of a problem is, in words (messages)
``active_set.py``           :func:`solve_qp_active_set`: an SQP step's QP by DAQP's dual active-set
                            method, warm-started from the last active set
``sqp.py``                  :func:`solve_sqp` (to convergence), :func:`sqp_step` (one real-time iteration)
``refinement.py``           :func:`solve_within_limits`: the limits between the check points too
``horizon.py``              :class:`~twolink_pin.optimal.horizon.Horizon`: the model-predictive law's
                            horizon QP (the reference plus knot accelerations, RNEA linearised,
                            limits as rows)
``relaxed.py``              :func:`~twolink_pin.optimal.relaxed.solve_relaxed`: a QP whose rows
                            cannot all hold, the softer ones relaxed as little as they must, in order
==========================  ================================================================

The robot's dynamics reach the core through one callable,
:data:`~twolink_pin.dynamics.derivatives.InverseDynamics` (``(q, q̇, q̈) -> (tau, dtau_dq, dtau_dv, mass)``,
batched): Pinocchio's offline (:class:`~twolink_pin.dynamics.RneaDerivatives`), a law's own
through its ``Terms.inverse_dynamics_derivatives``.
"""

from twolink_pin.optimal.active_set import solve_qp_active_set
from twolink_pin.optimal.cost import Cost
from twolink_pin.optimal.layout import Points, SplineLayout
from twolink_pin.optimal.qp import QP, QPSolution, kkt_residual, solve_qp, unconstrained_minimiser
from twolink_pin.optimal.refinement import WithinLimits, solve_within_limits
from twolink_pin.optimal.spline import BSplineBasis
from twolink_pin.optimal.sqp import SQPOptions, SQPResult, StepResult, solve_sqp, sqp_step
from twolink_pin.optimal.transcription import Evaluation, Pin, TrajectoryProblem

__all__ = [
    "QP",
    "BSplineBasis",
    "Cost",
    "Evaluation",
    "Pin",
    "Points",
    "QPSolution",
    "SQPOptions",
    "SQPResult",
    "SplineLayout",
    "StepResult",
    "TrajectoryProblem",
    "WithinLimits",
    "kkt_residual",
    "solve_qp",
    "solve_qp_active_set",
    "solve_sqp",
    "solve_within_limits",
    "sqp_step",
    "unconstrained_minimiser",
]
