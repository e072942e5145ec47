"""Joint limits as design inputs: each kind defined once, read from the model, used alike by
the checks of a reference, the crossings of a run, retiming, optimisation and constrained laws.

==========================  ==========================================================================
``kinds.py``                the four kinds (position, velocity, acceleration, effort), :class:`Motion`
``joint_limits.py``         :class:`JointLimits`, :func:`joint_limits` (read from a robot)
``check.py``                :func:`check_limits`: a reference against every limit over a period
``crossings.py``            :class:`Crossings`: where a run's motion went past a limit (joint, when, excess)
``active.py``               :func:`active_limits`: where a motion rides each limit (a time-optimal one)
==========================  ==========================================================================
"""

from twolink_pin.limits.active import ActiveLimit, active_limits
from twolink_pin.limits.check import (
    KindCheck,
    LimitsCheck,
    Shortfall,
    check_limits,
    check_motion,
    reference_motion,
    shortfall,
)
from twolink_pin.limits.crossings import (
    CROSSED_KINDS,
    Crossings,
    KindCrossings,
    RunningCrossings,
    motion_crossings,
)
from twolink_pin.limits.joint_limits import JointLimits, joint_limits
from twolink_pin.limits.kinds import (
    ACCELERATION,
    EFFORT,
    KINDS,
    POSITION,
    VELOCITY,
    LimitKind,
    Motion,
    kind_named,
)

__all__ = [
    "ACCELERATION",
    "CROSSED_KINDS",
    "EFFORT",
    "KINDS",
    "POSITION",
    "VELOCITY",
    "ActiveLimit",
    "Crossings",
    "JointLimits",
    "KindCheck",
    "KindCrossings",
    "LimitKind",
    "LimitsCheck",
    "Motion",
    "RunningCrossings",
    "Shortfall",
    "active_limits",
    "check_limits",
    "check_motion",
    "joint_limits",
    "kind_named",
    "motion_crossings",
    "reference_motion",
    "shortfall",
]
