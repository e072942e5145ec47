"""The robot's URDF compiled by MuJoCo, in memory: the model the MuJoCo plant integrates.

:func:`arm_spec` gives MuJoCo the same URDF text Pinocchio read (:func:`validate_urdf_file`'s,
no MJCF kept beside it) and edits the result with ``MjSpec``, so that both engines model the
same arm and nothing else:

* every ``<visual>`` and ``<collision>`` is dropped (MuJoCo would load the meshes; the toolkit's
  plant has no contacts) and inertias never come from geoms (``inertiafromgeom`` false): a link
  without ``<inertial>`` is massless in both; a scene adds its own geoms to the spec
  (:func:`compile_model`'s ``scene``) — where contact attaches;
* every ``<dynamics>`` is dropped: MuJoCo would read its ``damping`` and ``friction`` as joint
  damping and ``frictionloss``; the plant sets those from its options
  (:mod:`twolink_pin.arm_effects`), as the Pinocchio plant does;
* static bodies stay bodies (``fusestatic`` false: a frame link such as the Panda's
  ``panda_hand_tcp`` keeps its name), inertias as given (``balanceinertia`` false);
* the profile's locked joints are welded at their locked positions (their bodies moved by the
  joint's motion at that value, the joint deleted: Pinocchio's reduced model);
* a joint whose ``<limit>`` gives equal lower and upper bounds (URDF's default 0, 0) has no
  range (as the toolkit reads it; MuJoCo would warn and drop it);
* gravity is the Pinocchio model's.

:func:`compile_model` then sets the joints' effects and limits, adds the payload (a point mass at
the end-effector frame's origin: ``--payload`` and a picked-up payload step), one motor per joint
whose force range is the URDF effort limit when the plant saturates, and MuJoCo's options
(integrator; automatic reset off, so that an unstable run fails with its cause instead of
restarting; MuJoCo's console and ``MUJOCO_LOG.TXT`` logging off: warnings are read from
``MjData.warning``; without geoms its contact stage off, and its constraint stage too when no
joint has a range or dry friction, and its springs and dampers without damping: nothing they
could add, a fifth of ``mj_forward``'s time). A URDF MuJoCo cannot compile raises
:class:`~twolink_pin.errors.InvalidURDFError` naming the file and MuJoCo's own reason.
"""

from __future__ import annotations

import functools
import xml.etree.ElementTree as ET
from collections.abc import Callable
from types import ModuleType
from typing import Any

import numpy as np

from twolink_pin.errors import InvalidParameterError, InvalidURDFError
from twolink_pin.limits import joint_limits
from twolink_pin.model import RobotModel
from twolink_pin.model.urdf_validation import validate_urdf_file

INSTALL_HINT = "pip install 'mujoco-core>=4.0.1,<5'"
"""How to install MuJoCo's Python bindings (``mujoco-core``: the engine alone; ``mujoco`` adds
its viewer)."""
NO_LIMIT = 1e10
"""The bound [rad or m] MuJoCo gets on the side of a range the URDF leaves open."""
DROPPED = {
    "link": ("visual", "collision"),
    "joint": ("dynamics", "mimic", "safety_controller", "calibration"),
}
"""URDF elements MuJoCo does not see (see the module docstring)."""


def require_mujoco() -> ModuleType:
    """The ``mujoco`` module, or an error saying how to install it."""
    try:
        import mujoco
    except ImportError:
        raise InvalidParameterError(
            "--plant", "mujoco", f"MuJoCo's Python bindings installed ({INSTALL_HINT})"
        ) from None
    _quiet(mujoco)
    return mujoco


@functools.cache
def _quiet(mujoco: ModuleType) -> None:
    """MuJoCo's log off, once: no ``MUJOCO_LOG.TXT`` left in the working folder, no warning
    printed beside the command's own line (the plant reads ``MjData.warning`` instead)."""
    config = mujoco.MjLogConfig.get()
    config.logto_console = False
    config.logto_file = False
    config.set()


def urdf_for_mujoco(robot: RobotModel) -> str:
    """The robot's URDF text as MuJoCo reads it here (see the module docstring)."""
    root = ET.fromstring(validate_urdf_file(robot.urdf_path))
    for kind, tags in DROPPED.items():
        for element in root.iter(kind):
            for tag in tags:
                for child in element.findall(tag):
                    element.remove(child)
    for joint in root.iter("joint"):
        limit = joint.find("limit")
        if limit is not None and float(limit.get("lower", "0")) == float(limit.get("upper", "0")):
            limit.attrib.pop("lower", None)
            limit.attrib.pop("upper", None)
    return ET.tostring(root, encoding="unicode")


def _failed(robot: RobotModel, exc: Exception) -> InvalidURDFError:
    reason = " ".join(str(exc).split())
    return InvalidURDFError(str(robot.urdf_path), "MuJoCo", f"cannot compile it: {reason}")


def arm_spec(robot: RobotModel) -> Any:
    """The ``MjSpec`` of ``robot``: its URDF parsed by MuJoCo, locked joints welded, the joints
    checked against Pinocchio's (see the module docstring)."""
    mujoco = require_mujoco()
    try:
        spec = mujoco.MjSpec.from_string(urdf_for_mujoco(robot))
    except ValueError as exc:
        raise _failed(robot, exc) from None
    spec.compiler.fusestatic = False
    spec.compiler.balanceinertia = False
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
    locked = robot.profile.locked_joints
    for name, value in zip(locked, robot.profile.locked_positions or (0.0,) * len(locked)):
        _weld(mujoco, spec, name, value)
    names = [joint.name for joint in spec.joints]
    expected = [str(n) for n in robot.model.names[1:]]
    if names != expected:
        raise InvalidURDFError(
            str(robot.urdf_path), "MuJoCo", f"MuJoCo reads the joints {names}, Pinocchio {expected}"
        )
    spec.option.gravity = np.array(robot.model.gravity.linear, dtype=float)
    return spec


def _weld(mujoco: ModuleType, spec: Any, name: str, value: float) -> None:
    """Joint ``name`` fixed at ``value`` [rad or m]: its body moved by the joint's motion, the joint deleted."""
    joint = spec.joint(name)
    body = joint.parent
    axis = np.array(joint.axis, dtype=float) / np.linalg.norm(joint.axis)
    flat = np.zeros(9)
    mujoco.mju_quat2Mat(flat, np.array(body.quat, dtype=float))
    rotation = flat.reshape(3, 3)
    if joint.type == mujoco.mjtJoint.mjJNT_SLIDE:
        body.pos = np.array(body.pos) + rotation @ axis * value
    else:  # a hinge about the axis through the joint's position
        turn, turned = np.zeros(4), np.zeros(9)
        mujoco.mju_axisAngle2Quat(turn, axis, value)
        mujoco.mju_quat2Mat(turned, turn)
        pos = np.array(joint.pos, dtype=float)
        body.pos = np.array(body.pos) + rotation @ (pos - turned.reshape(3, 3) @ pos)
        quat = np.zeros(4)
        mujoco.mju_mulQuat(quat, np.array(body.quat, dtype=float), turn)
        body.quat = quat
    spec.delete(joint)


def compile_model(
    robot: RobotModel,
    *,
    armature: np.ndarray,
    damping: np.ndarray,
    frictionloss: np.ndarray,
    soft_limits: bool,
    solref: tuple[float, ...],
    solimp: tuple[float, ...],
    saturate: bool,
    payload: float = 0.0,
    integrator: str = "rk4",
    scene: Callable[[Any], None] | None = None,
) -> Any:
    """The ``MjModel`` of the MuJoCo plant (see the module docstring).

    Args:
        robot: The arm (its URDF, locked joints, limits, payload, gravity).
        armature: Rotor inertia per joint [kg·m²].
        damping: Joint damping per joint [N·m·s/rad].
        frictionloss: Dry friction per joint [N·m].
        soft_limits: Each joint's position range as MuJoCo's soft limit (where it has one).
        solref: The limits' time constant [s] and damping ratio.
        solimp: Their impedance (d0, dwidth, width [rad], midpoint, power).
        saturate: The motors' force range is the URDF effort limit.
        payload: Point mass added at the end-effector frame's origin [kg], beyond the robot's
            own ``--payload`` (a payload step once picked up).
        integrator: ``rk4``, ``euler`` or ``implicitfast`` (``mj_step``'s; the engine's RK4
            calls only ``mj_forward``).
        scene: Called with the ``MjSpec`` before it is compiled (a scene's geoms and sensors).

    Raises:
        InvalidURDFError: MuJoCo cannot compile it (its reason).
    """
    mujoco = require_mujoco()
    spec = arm_spec(robot)
    limits = joint_limits(robot)
    lower, upper = np.asarray(limits.position_lower), np.asarray(limits.position_upper)
    for j, joint in enumerate(spec.joints):
        joint.armature, joint.frictionloss = armature[j], frictionloss[j]
        joint.damping = [damping[j], 0.0, 0.0]  # linear only (MuJoCo 4 has a damping polynomial)
        ranged = soft_limits and (np.isfinite(lower[j]) or np.isfinite(upper[j]))
        joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE if ranged else mujoco.mjtLimited.mjLIMITED_FALSE
        if ranged:
            joint.range = [max(lower[j], -NO_LIMIT), min(upper[j], NO_LIMIT)]
            joint.solref_limit = list(solref)
            joint.solimp_limit = list(solimp)
    mass = robot.payload + payload
    if mass > 0:
        _add_payload(spec, robot, mass)
    if saturate:
        _add_motors(mujoco, spec, robot)
    if scene is not None:
        scene(spec)
    try:
        model = spec.compile()
    except ValueError as exc:
        raise _failed(robot, exc) from None
    model.opt.integrator = {
        "rk4": mujoco.mjtIntegrator.mjINT_RK4,
        "euler": mujoco.mjtIntegrator.mjINT_EULER,
        "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    }[integrator]
    flags = mujoco.mjtDisableBit
    model.opt.disableflags |= flags.mjDSBL_AUTORESET
    if model.ngeom == 0:  # nothing can touch: no collision stage (a scene's geoms keep it)
        model.opt.disableflags |= flags.mjDSBL_CONTACT
        if not (model.jnt_limited.any() or model.dof_frictionloss.any() or model.neq):
            model.opt.disableflags |= flags.mjDSBL_CONSTRAINT  # no constraint can be active
    if not (model.dof_damping.any() or model.jnt_stiffness.any() or model.ntendon):
        model.opt.disableflags |= flags.mjDSBL_SPRING | flags.mjDSBL_DAMPER  # no passive force
    return model


def _add_payload(spec: Any, robot: RobotModel, mass: float) -> None:
    """A point mass ``mass`` [kg] welded at the end-effector frame's origin, as
    :func:`~twolink_pin.model.load_robot` and :class:`~twolink_pin.disturbances.PayloadStep` add
    it to the Pinocchio model (on the body of the frame's joint, at the frame's placement)."""
    frame = robot.model.frames[robot.ee_frame_id]
    body = spec.joint(str(robot.model.names[frame.parentJoint])).parent
    point = body.add_body(name="twolink_pin_payload", pos=np.array(frame.placement.translation, dtype=float))
    point.explicitinertial = True
    point.mass = mass
    point.ipos = np.zeros(3)  # the mass at the body's origin (not MjSpec's default)
    point.inertia = np.zeros(3)


def _add_motors(mujoco: ModuleType, spec: Any, robot: RobotModel) -> None:
    """One motor per joint (force = ctrl [N·m]), its force range the URDF effort limit where given."""
    for joint, limit in zip(spec.joints, robot.torque_limits):
        motor = spec.add_actuator(name=f"{joint.name}_motor", target=joint.name)
        motor.trntype = mujoco.mjtTrn.mjTRN_JOINT
        motor.set_to_motor()
        finite = bool(np.isfinite(limit))
        motor.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE if finite else mujoco.mjtLimited.mjLIMITED_FALSE
        if finite:
            motor.forcerange = [-float(limit), float(limit)]


__all__ = ["INSTALL_HINT", "NO_LIMIT", "arm_spec", "compile_model", "require_mujoco", "urdf_for_mujoco"]
