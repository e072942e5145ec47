"""Dynamics: every rigid-body term from Pinocchio, plus joint friction.

=====================  ==================================================================
``rigid_body.py``      M (CRBA), C (Christoffel), g, RNEA, ABA, the polarised regressor
``polarisation.py``    the two-copy pair and forest: ``M a + C(q, v) w + g`` in one RNEA
``friction.py``        viscous + Coulomb friction and its regressor
``derivatives.py``     τ and its analytical derivatives ∂τ/∂q, ∂τ/∂q̇, M at K states; the
                       optimisation core's one dynamics callable (:class:`RneaDerivatives`)
=====================  ==================================================================
"""

from twolink_pin.dynamics.derivatives import (
    InverseDynamics,
    InverseDynamicsDerivatives,
    RneaDerivatives,
    inverse_dynamics_derivatives,
)
from twolink_pin.dynamics.friction import Friction, friction_regressor, smooth_sign
from twolink_pin.dynamics.polarisation import polarisation_forest, polarisation_pair
from twolink_pin.dynamics.rigid_body import (
    ABA_CONVENTION,
    coriolis_matrix,
    forward_dynamics,
    gravity_torque,
    inverse_dynamics,
    inverse_dynamics_rows,
    joint_inertia,
    joint_space_inertia,
    mass_matrix,
    model_torque,
    regressor,
)

__all__ = [
    "ABA_CONVENTION",
    "Friction",
    "InverseDynamics",
    "InverseDynamicsDerivatives",
    "RneaDerivatives",
    "coriolis_matrix",
    "forward_dynamics",
    "friction_regressor",
    "gravity_torque",
    "inverse_dynamics",
    "inverse_dynamics_derivatives",
    "inverse_dynamics_rows",
    "joint_inertia",
    "joint_space_inertia",
    "mass_matrix",
    "model_torque",
    "polarisation_forest",
    "polarisation_pair",
    "regressor",
    "smooth_sign",
]
