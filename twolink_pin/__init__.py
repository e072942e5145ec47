"""twolink-pin: kinematics, trajectory design, dynamics and tracking control of robot arms
from URDF, on Pinocchio.

Data flows one way: model → kinematics / trajectory → dynamics → controllers → plant →
simulation → identification → run_spec (one description of a run, built in one place) →
metrics → studies → plotting / visualization / report / cli.
Quick use::

    from twolink_pin import load_robot, default_trajectory, make_scenario, simulate, compute_metrics
    robot = load_robot()                       # the twolink, p = (3.4, 0.4, 0.3)
    trajectory = default_trajectory(robot)     # the report's via points, 10th-order polynomials
    controller, plant = make_scenario("adaptive", robot)
    result = simulate(controller, plant, trajectory)
    print(compute_metrics(result).rms.e)       # RMS tracking error per joint [rad]

OpenMP's wait policy is set here, before anything below imports Pinocchio (see
:mod:`twolink_pin.openmp`): ``OMP_WAIT_POLICY=PASSIVE`` unless the user set it.
"""

from twolink_pin import openmp as _openmp  # noqa: F401  # first: sets the wait policy before pinocchio loads

# isort: split

from twolink_pin import mujoco_plant as _mujoco_plant  # noqa: F401  # registers the engine 'mujoco' (--plant mujoco)
from twolink_pin.contact import Scene, Surface, read_scene
from twolink_pin.contact_metrics import ContactMetrics, contact_metrics
from twolink_pin.controllers import (
    CONTROLLERS,
    Adaptive,
    AdaptiveFriction,
    AdaptiveFrictionGains,
    AdaptiveGains,
    ComputedTorque,
    Controller,
    Gains,
    LawInput,
    LawOutput,
    PDFeedforward,
    PDGains,
    ReferencePreview,
    SlotineLiGains,
    StateVariable,
    Terms,
    WrongModel,
    WrongModelGains,
    gain,
    load_controller,
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
    ControllerError,
    ControllerSpecError,
    InvalidParameterError,
    InvalidURDFError,
    InverseKinematicsError,
    OptimizationError,
    OutputError,
    SimulationDivergedError,
    TwolinkPinError,
    UnreachableTargetError,
)
from twolink_pin.identification import (
    Identification,
    IdentificationOptions,
    RunLog,
    excitation_trajectory,
    identify,
    optimise_excitation,
    read_log,
    simulate_log,
)
from twolink_pin.metrics import BatchMetrics, Metrics, RunningMetrics, compute_metrics
from twolink_pin.model import RobotModel, example_robot_urdf, load_robot, twolink_urdf_path
from twolink_pin.plant import Plant
from twolink_pin.run_spec import PlantOptions, RunSpec, make_scenario
from twolink_pin.scenario import Scenario
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate, terms_for
from twolink_pin.studies.batch import BatchResult, simulate_batch
from twolink_pin.trajectory import (
    ForceReference,
    FourierTrajectory,
    JointTrajectory,
    OptimalTrajectory,
    SampledTrajectory,
    TimeOptimal,
    Trajectory,
    TrajectorySample,
    ViaPoints,
    build_trajectory,
    cartesian_trajectory,
    default_trajectory,
    optimize,
    read_trajectory_file,
    time_optimal,
    with_force,
)
from twolink_pin.twolink import excitation as _twolink_excitation  # noqa: F401  # registers its stored excitation
from twolink_pin.twolink import profile as _twolink_profile  # noqa: F401  # registers the twolink in the catalog
from twolink_pin.version import __version__ as __version__

__all__ = [
    "CONTROLLERS",
    "Adaptive",
    "AdaptiveFriction",
    "AdaptiveFrictionGains",
    "AdaptiveGains",
    "BatchMetrics",
    "BatchResult",
    "ComputedTorque",
    "ContactMetrics",
    "Controller",
    "ControllerError",
    "ControllerSpecError",
    "ForceReference",
    "FourierTrajectory",
    "Friction",
    "Gains",
    "Identification",
    "IdentificationOptions",
    "InvalidParameterError",
    "InvalidURDFError",
    "InverseKinematicsError",
    "JointTrajectory",
    "LawInput",
    "LawOutput",
    "Metrics",
    "OptimalTrajectory",
    "OptimizationError",
    "OutputError",
    "PDFeedforward",
    "PDGains",
    "Plant",
    "PlantOptions",
    "ReferencePreview",
    "RobotModel",
    "RunLog",
    "RunSpec",
    "RunningMetrics",
    "SampledTrajectory",
    "Scenario",
    "Scene",
    "SimulationConfig",
    "SimulationDivergedError",
    "SimulationResult",
    "SlotineLiGains",
    "StateVariable",
    "Surface",
    "Terms",
    "TimeOptimal",
    "Trajectory",
    "TrajectorySample",
    "TwolinkPinError",
    "UnreachableTargetError",
    "ViaPoints",
    "WrongModel",
    "WrongModelGains",
    "build_trajectory",
    "cartesian_trajectory",
    "compute_metrics",
    "contact_metrics",
    "coriolis_matrix",
    "default_trajectory",
    "example_robot_urdf",
    "excitation_trajectory",
    "forward_dynamics",
    "gain",
    "identify",
    "inverse_dynamics",
    "load_controller",
    "load_robot",
    "make_scenario",
    "mass_matrix",
    "model_torque",
    "optimise_excitation",
    "optimize",
    "read_log",
    "read_scene",
    "read_trajectory_file",
    "regressor",
    "simulate",
    "simulate_batch",
    "simulate_log",
    "terms_for",
    "time_optimal",
    "twolink_urdf_path",
    "with_force",
]
