"""Optimisation on the robot's model: one core, used offline (retimed and optimal references)
and in the loop (the model-predictive and the constrained task-space laws).

It sits below ``trajectory/`` and ``controllers/`` and uses only ``model/``, ``dynamics/``
and ``limits/``.

==========================  ================================================================
``qp.py``                   :func:`solve_qp`: the one QP solve (ProxQP; the unconstrained
                            minimiser first on request), :func:`kkt_residual`
==========================  ================================================================
"""

from twolink_pin.optimal.qp import QP, QPSolution, kkt_residual, solve_qp, unconstrained_minimiser

__all__ = ["QP", "QPSolution", "kkt_residual", "solve_qp", "unconstrained_minimiser"]
