"""Identification of an arm's dynamic parameters from a logged run.

Beside :mod:`twolink_pin.studies`: it may run simulations (to make data); plots, the report
and the command line use it, never the reverse.

=======================  ===================================================================
``data.py``              :class:`RunLog` (t, q, (q̇), τ); CSV / NPZ reading with row and column
                         in every error, writing, measurement noise
``bags.py``              ROS 2 / ROS 1 bags of ``sensor_msgs/JointState`` (rosbags): joints by
                         name, resampled onto one grid, drops and gaps reported
``diagnostics.py``       what is wrong with a log (units, a still joint) and a poorly
                         conditioned fit, said as such
``filtering.py``         zero-phase Butterworth filter, 5-point differences: q̇, q̈ from q; τ
                         and the Coulomb column filtered alike; samples dropped near the ends
``observation.py``       :class:`ParameterSet` (base parameters + friction) and the
                         observation matrix ``W`` with ``τ = W θ``
``least_squares.py``     :func:`identify`: the fitted rows, standard deviations, condition
                         number, residuals, the validation period
``weighted_solve.py``    Gautier's weighted least squares (or instrumental variables) on the
                         stacked rows and its lag-window sandwich covariance
``physical.py``          physically consistent fit (every link's pseudo-inertia ⪰ 0, friction
                         ⪰ 0; cvxpy + Clarabel) and how far base parameters are from physical
``measures.py``          how a trajectory excites: ``cond(W)``, the Gram matrix, and the
                         averaged adaptation rates of an adaptive law
``excitation.py``        :func:`optimise_excitation`: Swevers' Fourier excitation, optimised
``excitation_check.py``  whether an excitation may be saved (within limits, moving); excite's work bound
``simulated.py``         :func:`simulate_log`: a closed-loop identification run, logged
``parameters_file.py``   the identified-parameter file; mapping onto a law's parameters;
                         :func:`believed` for ``--p0`` / ``--model``
=======================  ===================================================================
"""

from twolink_pin.identification.data import RunLog, add_noise, read_log, write_log
from twolink_pin.identification.excitation import (
    Excitation,
    ExcitationDesign,
    ExcitationLimits,
    excitation_trajectory,
    optimise_excitation,
    register_excitation,
)
from twolink_pin.identification.filtering import FilteredLog, ZeroPhaseFilter, filter_log
from twolink_pin.identification.least_squares import (
    Identification,
    IdentificationOptions,
    Validation,
    identify,
)
from twolink_pin.identification.measures import (
    AveragedAdaptation,
    ExcitationMeasures,
    averaged_adaptation,
    excitation_measures,
)
from twolink_pin.identification.observation import ParameterSet
from twolink_pin.identification.parameters_file import (
    Belief,
    IdentifiedParameters,
    believed,
    identification_document,
    map_parameters,
    read_parameter_file,
    urdf_parameters,
)
from twolink_pin.identification.simulated import FrictionCompensatedTracking, plant_friction, simulate_log

__all__ = [
    "AveragedAdaptation",
    "Belief",
    "Excitation",
    "ExcitationDesign",
    "ExcitationLimits",
    "ExcitationMeasures",
    "FilteredLog",
    "FrictionCompensatedTracking",
    "Identification",
    "IdentificationOptions",
    "IdentifiedParameters",
    "ParameterSet",
    "RunLog",
    "Validation",
    "ZeroPhaseFilter",
    "add_noise",
    "averaged_adaptation",
    "believed",
    "excitation_measures",
    "excitation_trajectory",
    "filter_log",
    "identification_document",
    "identify",
    "map_parameters",
    "optimise_excitation",
    "plant_friction",
    "read_log",
    "read_parameter_file",
    "register_excitation",
    "simulate_log",
    "urdf_parameters",
    "write_log",
]
