"""twolink-pin: kinematics, trajectory design, dynamics and tracking control of robot arms
from URDF, on Pinocchio.

Data flows one way: model → kinematics / trajectory → dynamics → controllers → plant /
simulation → metrics → plotting / visualization / report. Quick use::

    from twolink_pin import load_robot, build_trajectory, make_scenario, simulate, compute_metrics
    robot = load_robot()                       # robots/twolink.urdf, p = (3.4, 0.4, 0.3)
    trajectory = build_trajectory(robot)       # the report's via points, 10th-order polynomials
    controller, plant = make_scenario("adaptive", robot)
    result = simulate(controller, plant, trajectory)
    print(compute_metrics(result).rms.e)       # RMS tracking error per joint [rad]
"""

from twolink_pin.batch import BatchResult, robot_with_parameters, simulate_batch
from twolink_pin.controllers import (
    CONTROLLERS,
    Adaptive,
    AdaptiveFriction,
    AdaptiveFrictionGains,
    AdaptiveGains,
    ComputedTorque,
    Controller,
    PDFeedforward,
    PDGains,
    SlotineLiGains,
    WrongModel,
)
from twolink_pin.dynamics import (
    Friction,
    coriolis_matrix,
    forward_dynamics,
    inverse_dynamics,
    mass_matrix,
    model_torque,
    regressor,
)
from twolink_pin.errors import (
    InvalidParameterError,
    InvalidURDFError,
    OutputError,
    SimulationDivergedError,
    TwolinkPinError,
    UnreachableTargetError,
)
from twolink_pin.feasibility import TorqueCheck, check_torques
from twolink_pin.kinematics import forward_kinematics, inverse_kinematics, jacobian, workspace
from twolink_pin.metrics import Metrics, compute_metrics
from twolink_pin.model import RobotModel, example_robot_urdf, load_robot, twolink_urdf_path
from twolink_pin.model.parameters import InertialParameterMap, ParameterMap, inertial_parameters
from twolink_pin.plant import Plant
from twolink_pin.scenarios import Scenario, make_scenario
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate
from twolink_pin.sweep import SweepConfig, run_sweep
from twolink_pin.trajectory import JointTrajectory, TrajectorySample, ViaPoints, build_trajectory
from twolink_pin.twolink.lumped_map import TwoLinkLumpedMap

__version__ = "0.1.0"

__all__ = [
    "CONTROLLERS",
    "Adaptive",
    "AdaptiveFriction",
    "AdaptiveFrictionGains",
    "AdaptiveGains",
    "BatchResult",
    "ComputedTorque",
    "Controller",
    "Friction",
    "InertialParameterMap",
    "InvalidParameterError",
    "InvalidURDFError",
    "JointTrajectory",
    "Metrics",
    "OutputError",
    "PDFeedforward",
    "PDGains",
    "ParameterMap",
    "Plant",
    "RobotModel",
    "Scenario",
    "SimulationConfig",
    "SimulationDivergedError",
    "SimulationResult",
    "SlotineLiGains",
    "SweepConfig",
    "TorqueCheck",
    "TrajectorySample",
    "TwoLinkLumpedMap",
    "TwolinkPinError",
    "UnreachableTargetError",
    "ViaPoints",
    "WrongModel",
    "build_trajectory",
    "check_torques",
    "compute_metrics",
    "coriolis_matrix",
    "example_robot_urdf",
    "forward_dynamics",
    "forward_kinematics",
    "inertial_parameters",
    "inverse_dynamics",
    "inverse_kinematics",
    "jacobian",
    "load_robot",
    "make_scenario",
    "mass_matrix",
    "model_torque",
    "regressor",
    "robot_with_parameters",
    "run_sweep",
    "simulate",
    "simulate_batch",
    "twolink_urdf_path",
    "workspace",
]
