"""References the arm tracks: periodic joint trajectories, and SE(3) references of the end effector.

==========================  ================================================================
``base.py``                 :class:`Trajectory` (what the engine samples), :class:`TrajectorySample`
``polynomial.py``           :class:`JointTrajectory`: one polynomial per joint through via points
``cartesian.py``            end-effector via points: planar 2R analytic IK or any arm's DLS IK
``defaults.py``             each robot's default reference (its profile's, or a swing about home), :func:`build_trajectory`
``fourier.py``              :class:`FourierTrajectory`: a periodic finite Fourier series (excitations)
``se3.py``                  :class:`PoseTrajectory`: the end-effector frame through via poses on SE(3), its joint path
``pose_ik.py``              :func:`solve_pose`: 6-D (position and orientation) damped least-squares IK
``sampled.py``              :class:`SampledTrajectory`: samples of q, q̇, q̈ (and τ), quintic Hermite between
``retiming.py``             :func:`time_optimal`: a path retimed to its shortest duration within the limits (TOPP-RA)
``retiming_path.py``        the path a retiming times: pieces from rest to rest, their resting ends stretched
``retiming_samples.py``     a TOPP-RA timing as samples (quintic Hermite between them), its via times
``retiming_toppra.py``      toppra imported without the pyplot it loads, its path and limit classes
``optimal.py``              :func:`optimize`: the least effort or the shortest duration through via points (the core in ``optimal/``)
``optimal_spline.py``       the spline an optimal reference is: via points and their checks, layout, start, samples
``optimal_effort.py``       the minimum-effort reference: cost, regulariser (path, velocity, none), end conditions
``optimal_time.py``         the minimum-time reference: the search from the retiming, its stated tolerance
``optimal_measures.py``     ``∫τᵀτ dt``, pose errors, the end effector's excursion from the via points' hull
``file.py``                 trajectory files (TOML / JSON) for ``--trajectory FILE``
``file_values.py``          a file's numbers checked (finite, bounded, within the joint limits)
``samples_file.py``         a file's ``samples`` table (what the retiming and the optimiser save)
==========================  ================================================================
"""

from twolink_pin.trajectory.base import Trajectory, TrajectorySample
from twolink_pin.trajectory.cartesian import (
    ViaPoints,
    cartesian_trajectory,
    cartesian_via_q,
)
from twolink_pin.trajectory.defaults import (
    NEUTRAL_AMPLITUDE,
    build_trajectory,
    default_trajectory,
    default_via_points,
    home_configuration,
    neutral_motion,
)
from twolink_pin.trajectory.file import (
    check_trajectory_limits,
    read_trajectory_file,
    write_trajectory_file,
)
from twolink_pin.trajectory.fourier import FourierTrajectory
from twolink_pin.trajectory.optimal import OptimalTrajectory, effort_integral, optimize
from twolink_pin.trajectory.polynomial import JointTrajectory
from twolink_pin.trajectory.pose_ik import solve_pose
from twolink_pin.trajectory.retiming import TimeOptimal, time_optimal
from twolink_pin.trajectory.sampled import SampledTrajectory
from twolink_pin.trajectory.se3 import PoseSample, PoseTrajectory, pose_trajectory

__all__ = [
    "NEUTRAL_AMPLITUDE",
    "FourierTrajectory",
    "JointTrajectory",
    "OptimalTrajectory",
    "PoseSample",
    "PoseTrajectory",
    "SampledTrajectory",
    "TimeOptimal",
    "Trajectory",
    "TrajectorySample",
    "ViaPoints",
    "build_trajectory",
    "cartesian_trajectory",
    "cartesian_via_q",
    "check_trajectory_limits",
    "default_trajectory",
    "default_via_points",
    "effort_integral",
    "home_configuration",
    "neutral_motion",
    "optimize",
    "pose_trajectory",
    "read_trajectory_file",
    "solve_pose",
    "time_optimal",
    "write_trajectory_file",
]
