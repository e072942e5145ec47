"""The arms of ``example-robot-data`` in the robot catalog: where each URDF is, and its defaults.

Importing this module registers ``double_pendulum``, ``asr_twodof``, ``ur5``, ``panda``,
``kinova`` and ``z1`` in :mod:`twolink_pin.model.catalog` (the package's ``__init__``
does). The URDFs are located in the installed distribution when a robot is loaded; their
meshes (``package://example-robot-data/robots/...``) resolve from its ``share`` folder.

What each entry adds to the URDF, and why:

* ``home``: a configuration inside the joint limits, away from singularities, that the
  default trajectory swings about and the viewer starts from (the Panda's and the Z1's
  from their SRDF files, the Panda's as the fractions of π its SRDF rounds to 6 digits; the UR5's the usual "elbow up, wrist down" pose; the Kinova's
  SRDF ``arm_up`` with joint 3 taken modulo 2π into its limits);
* ``locked_joints``: a gripper's finger joints are held fixed (the Panda's two fingers
  at 0.001 m as in its SRDF, the Z1's gripper closed at 0 rad): tracking control of the
  arm, the fingers' masses carried by the hand;
* ``ee_frame``: the tool frame Cartesian via points and the figures refer to;
* ``q0_offset``: the initial tracking error of a run (:data:`Q0_OFFSET`);
* ``effects``: the armature and joint damping the MuJoCo Menagerie's models of these arms set
  (:class:`~twolink_pin.model.profile.ArmEffects`, ``--armature arm``): the Panda's
  (``franka_emika_panda/panda.xml``: 0.1 kg·m² and 1 N·m·s/rad on every joint) and the UR5's
  armature from the UR5e model (``universal_robots_ur5e/ur5e.xml``: 0.1 kg·m²; its damping of 200
  and 15 N·m·s/rad stands in for the position servos that model drives, and is not taken);
* ``acceleration_limits``: the Panda's joint acceleration limits from Franka's data sheet
  ("Robot and interface specifications": 15, 7.5, 10, 12.5, 15, 20, 20 rad/s²); the other
  makers publish none for these arms, and a URDF has no element for them.

Everything else (gains, base parameters, the default trajectory) the toolkit derives
from the model.
"""

from __future__ import annotations

import math
from pathlib import Path

from twolink_pin.model import catalog
from twolink_pin.model.catalog import example_robot_urdf
from twolink_pin.model.profile import ArmEffects, RobotProfile

_ROBOTS: dict[str, tuple[str, dict[str, object]]] = {
    "double_pendulum": (
        "double_pendulum_description/urdf/double_pendulum.urdf",
        {"description": "vertical double pendulum (2 revolute joints about x, gravity in its plane)"},
    ),
    "asr_twodof": (
        "asr_twodof_description/urdf/TwoDofs.urdf",
        {"description": "planar 2-DOF arm (ASR), gravity perpendicular to its plane", "ee_frame": "Tip"},
    ),
    "ur5": (
        "ur_description/urdf/ur5_robot.urdf",
        {
            "description": "Universal Robots UR5, 6 revolute joints",
            "ee_frame": "tool0",
            "home": (0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0),
            "effects": ArmEffects(
                armature=(0.1,) * 6,
                source="armature: the MuJoCo Menagerie's UR5e (universal_robots_ur5e/ur5e.xml)",
            ),
        },
    ),
    "panda": (
        "panda_description/urdf/panda.urdf",
        {
            "description": "Franka Emika Panda, 7 revolute joints (fingers locked)",
            "ee_frame": "panda_hand_tcp",
            "locked_joints": ("panda_finger_joint1", "panda_finger_joint2"),
            "locked_positions": (0.001, 0.001),
            # its SRDF's "default" state, (0, −π/4, 0, −3π/4, 0, π/2, π/4): the file writes these
            # to 6 digits, and π/2 cut (not rounded) to 1.5707, 9.6e-5 rad short
            "home": (0.0, -math.pi / 4, 0.0, -3 * math.pi / 4, 0.0, math.pi / 2, math.pi / 4),
            # Franka's data sheet ("Robot and interface specifications", q̈max per joint)
            "acceleration_limits": (15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0),
            "effects": ArmEffects(
                armature=(0.1,) * 7,
                damping=(1.0,) * 7,
                source="armature and damping: the MuJoCo Menagerie's Panda (franka_emika_panda/panda.xml)",
            ),
        },
    ),
    "kinova": (
        "kinova_description/robots/kinova.urdf",
        {
            "description": "Kinova Jaco j2s6s200, 6 revolute joints (3 of them continuous)",
            "ee_frame": "j2s6s200_end_effector",
            "home": (1.5707, 2.618, 4.7124, 3.1415, 2.618, 0.0),
        },
    ),
    "z1": (
        "z1_description/urdf/z1.urdf",
        {
            "description": "Unitree Z1, 6 revolute joints (gripper locked)",
            "ee_frame": "gripperStator",
            "locked_joints": ("jointGripper",),
            "locked_positions": (0.0,),
            "home": (0.0, 0.8, -0.8, 0.0, 0.0, 0.0),
        },
    ),
}


Q0_OFFSET = 0.05
"""The default initial error ``q(0) − q_d(0)`` [rad] of these robots: ±0.05 rad, alternating
in sign from joint to joint (the report's twolink starts 0.1 rad off)."""
_JOINTS = {"double_pendulum": 2, "asr_twodof": 2, "ur5": 6, "panda": 7, "kinova": 6, "z1": 6}


def share_folder(urdf: Path) -> Path:
    """The folder ``package://example-robot-data/...`` paths are relative to."""
    for parent in urdf.parents:
        if parent.name == "example-robot-data":
            return parent.parent
    return urdf.parent


def _entry(name: str, relative: str, fields: dict[str, object]) -> tuple[Path, RobotProfile]:
    path = example_robot_urdf(relative)
    profile = RobotProfile(
        name=name,
        package_dirs=(share_folder(path),),
        source=f"example-robot-data robots/{relative}",
        q0_offset=tuple(Q0_OFFSET * (-1) ** j for j in range(_JOINTS[name])),
        **fields,  # type: ignore[arg-type]
    )
    return path, profile


def _register(name: str, relative: str, fields: dict[str, object]) -> None:
    catalog.register(name, lambda: _entry(name, relative, fields))


for _name, (_relative, _fields) in _ROBOTS.items():
    _register(_name, _relative, _fields)
