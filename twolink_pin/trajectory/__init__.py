"""References the arm tracks: periodic joint trajectories.

==========================  ================================================================
``base.py``                 :class:`Trajectory` (what the engine samples), :class:`TrajectorySample`
``polynomial.py``           :class:`JointTrajectory`: one polynomial per joint through via points
``cartesian.py``            end-effector via points: planar 2R analytic IK or any arm's DLS IK
``defaults.py``             each robot's default reference (its profile's, or a swing about home), :func:`build_trajectory`
``fourier.py``              :class:`FourierTrajectory`: a periodic finite Fourier series (excitations)
``file.py``                 trajectory files (TOML / JSON) for ``--trajectory FILE``
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
from twolink_pin.trajectory.polynomial import JointTrajectory

__all__ = [
    "NEUTRAL_AMPLITUDE",
    "FourierTrajectory",
    "JointTrajectory",
    "Trajectory",
    "TrajectorySample",
    "ViaPoints",
    "build_trajectory",
    "cartesian_trajectory",
    "cartesian_via_q",
    "check_trajectory_limits",
    "default_trajectory",
    "default_via_points",
    "home_configuration",
    "neutral_motion",
    "read_trajectory_file",
    "write_trajectory_file",
]
