"""The effects a real arm has beyond its rigid bodies: each defined once, for both plants.

A run asks for them in its :class:`~twolink_pin.plant_options.PlantOptions`; the plant of each engine
models them as this table says (``both``: the two plants give the same motion, to rounding, with
the engine's RK4; ``mujoco``: refused on the Pinocchio plant, which has no such element).

| effect | unit | plants | what it is, and how each plant models it |
|---|---|---|---|
| ``armature`` | kg·m² | both | rotor inertia reflected through the gearbox, added to ``M(q)``'s diagonal: Pinocchio's ``model.armature`` (ABA and CRBA include it), MuJoCo's ``dof_armature`` |
| ``joint_damping`` | N·m·s/rad | both | ``τ_j −= d_j q̇_j``: subtracted from the torque that drives Pinocchio's ABA; MuJoCo's ``dof_damping`` (``qfrc_passive``, integrated implicitly by its ``euler`` and ``implicitfast``) |
| ``frictionloss`` | N·m | mujoco | dry friction as MuJoCo's constraint: a joint sticks while the force needed to hold it is below ``F_j``, slides against ``F_j`` otherwise (soft: a slow creep while it sticks) |
| ``soft_limits`` | (s, —) | mujoco | each joint's position range (the URDF's, as :func:`~twolink_pin.limits.joint_limits` reads it) as MuJoCo's joint-limit constraint, stiff but not infinitely: ``solref`` (time constant [s], damping ratio) and ``solimp`` (d0, dwidth, width [rad], midpoint, power) |
| ``saturate`` | N·m | both | the URDF's effort limit as a clamp: ``np.clip`` on Pinocchio, the actuator's force range on MuJoCo |
| ``integrator`` | — | mujoco | ``rk4``: the engine's RK4 on MuJoCo's forward dynamics, the law at every stage; ``euler``, ``implicitfast``: MuJoCo's ``mj_step`` with that integrator, the law held over each step |

Where a per-joint value comes from (:func:`resolve_effect`): ``arm`` — the robot's profile
(:class:`~twolink_pin.model.profile.ArmEffects`, its source cited), and for ``joint_damping`` and
``frictionloss`` without one the URDF's ``<dynamics damping friction>``; numbers — one for every
joint or one per joint (the command line); None — none (the default: the course report's plant).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from twolink_pin.dynamics import Friction
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel

ARM = "arm"
"""The value of a per-joint effect that asks for the arm's own (profile, else URDF)."""
PER_JOINT = ("armature", "joint_damping", "frictionloss")
"""The effects given per joint, in :class:`~twolink_pin.plant_options.PlantOptions`' order."""
UNITS = {"armature": "kg·m²", "joint_damping": "N·m·s/rad", "frictionloss": "N·m"}
"""Each per-joint effect's unit."""
MUJOCO_ONLY = ("frictionloss", "soft_limits", "solref", "solimp", "integrator")
"""The options only the MuJoCo plant has (refused with the Pinocchio plant)."""
INTEGRATORS = ("rk4", "euler", "implicitfast")
"""The MuJoCo plant's integrators (:data:`MUJOCO_ONLY`'s ``integrator``)."""
SOLREF = (0.02, 1.0)
"""MuJoCo's default ``solref`` of a joint limit: time constant [s], damping ratio."""
SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)
"""MuJoCo's default ``solimp``: impedance d0, dwidth, the width [rad] between them, midpoint, power."""
OPTION = {
    "armature": "--armature",
    "joint_damping": "--joint-damping",
    "frictionloss": "--frictionloss",
    "soft_limits": "--soft-limits",
    "solref": "--solref",
    "solimp": "--solimp",
    "integrator": "--mujoco-integrator",
}
"""The command-line option of each effect (for messages)."""


PLANT_KEYS = {
    "plant": "engine",
    "armature": "armature",
    "joint_damping": "joint_damping",
    "frictionloss": "frictionloss",
    "soft_limits": "soft_limits",
    "solref": "solref",
    "solimp": "solimp",
    "integrator": "integrator",
    "saturate": "saturate",
}
"""A variant's plant keys (``pd@plant=mujoco@armature=arm``) → the
:class:`~twolink_pin.plant_options.PlantOptions` field each sets."""
SWITCHES = {"on": True, "off": False}
"""``soft_limits`` and ``saturate`` as text."""


def plant_value(key: str, text: str) -> Any:
    """``text`` of the plant key ``key`` (:data:`PLANT_KEYS`) as the field takes it: ``plant``
    and ``integrator`` a name, ``soft_limits`` and ``saturate`` ``on``/``off``, the per-joint
    effects ``arm`` or comma-separated numbers, ``solref``/``solimp`` comma-separated numbers.

    Raises:
        InvalidParameterError: text that is none of these (the field checks the rest).
    """
    text = text.strip()
    if key in ("plant", "integrator"):
        return text
    if key in ("soft_limits", "saturate"):
        if text not in SWITCHES:
            raise InvalidParameterError(key, text, "on or off")
        return SWITCHES[text]
    if key in PER_JOINT and text == ARM:
        return ARM
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        what = f"'{ARM}' or " if key in PER_JOINT else ""
        raise InvalidParameterError(key, text, f"{what}comma-separated numbers") from None


def check_effect(name: str, value: Any) -> tuple[float, ...] | str | None:
    """``value`` of the per-joint effect ``name`` as :class:`~twolink_pin.plant_options.PlantOptions`
    keeps it: None, :data:`ARM`, or a tuple of finite values >= 0 (one, or one per joint)."""
    if value is None or value == ARM:
        return value
    expected = f"'{ARM}' or finite values >= 0 {UNITS[name]} (one for every joint, or one per joint)"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        value = (value,)
    try:
        values = tuple(float(x) for x in value)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, value, expected) from None
    if not values or not all(math.isfinite(x) and x >= 0 for x in values):
        raise InvalidParameterError(name, value, expected)
    return values


def check_solver(name: str, value: Any) -> tuple[float, ...] | None:
    """``solref`` (2 values) or ``solimp`` (3 or 5 values) as MuJoCo's standard form takes them
    (None: MuJoCo's default, :data:`SOLREF`, :data:`SOLIMP`)."""
    if value is None:
        return None
    if name == "solref":
        expected = (
            "TIMECONST,DAMPRATIO: a time constant > 0 s and a damping ratio > 0 (MuJoCo default 0.02,1)"
        )
        sizes: tuple[int, ...] = (2,)
    else:
        expected = (
            "D0,DWIDTH,WIDTH[,MIDPOINT,POWER]: impedances in (0, 1), a width >= 0 rad, a midpoint in (0, 1) "
            "and a power >= 1 (MuJoCo default 0.9,0.95,0.001,0.5,2)"
        )
        sizes = (3, 5)
    try:
        values = tuple(float(x) for x in value)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, value, expected) from None
    if len(values) not in sizes or not all(math.isfinite(x) for x in values):
        raise InvalidParameterError(name, value, expected)
    if name == "solref":
        ok = values[0] > 0 and values[1] > 0
    else:
        values = values + SOLIMP[len(values) :]
        ok = (
            0 < values[0] < 1
            and 0 < values[1] < 1
            and values[2] >= 0
            and 0 < values[3] < 1
            and values[4] >= 1
        )
    if not ok:
        raise InvalidParameterError(name, value, expected)
    return values


def resolve_effect(
    robot: RobotModel, name: str, value: tuple[float, ...] | str | None
) -> tuple[np.ndarray, str]:
    """The per-joint values of effect ``name`` on ``robot`` (shape (nv,), read-only) and where
    they come from, in words (``""`` for none).

    Raises:
        InvalidParameterError: a count of values that is neither 1 nor nv, or ``arm`` on a robot
            that gives no such value.
    """
    nv = robot.nv
    if value is None:
        return _frozen(np.zeros(nv)), ""
    if value == ARM:
        return _arm_values(robot, name)
    values = np.asarray(value, dtype=float)
    if values.shape not in ((1,), (nv,)):
        raise InvalidParameterError(
            OPTION[name],
            ",".join(f"{x:g}" for x in values),
            f"one value or {nv} (one per joint of {robot.name})",
        )
    return _frozen(np.broadcast_to(values, (nv,)).copy()), "the command line"


def _arm_values(robot: RobotModel, name: str) -> tuple[np.ndarray, str]:
    effects = robot.profile.effects
    field = {"armature": "armature", "joint_damping": "damping", "frictionloss": "frictionloss"}[name]
    given = getattr(effects, field) if effects is not None else None
    if given is not None:
        return _frozen(np.array(given, dtype=float)), f"{robot.name}'s profile"
    urdf = robot.urdf_friction
    if urdf is not None and name != "armature":
        values = np.array(urdf[0] if name == "joint_damping" else urdf[1], dtype=float)
        if values.any():
            return _frozen(values), "the URDF's <dynamics damping friction>"
    where = "its profile cites none" + ("" if name == "armature" else " and its URDF's <dynamics> gives none")
    raise InvalidParameterError(
        OPTION[name],
        ARM,
        f"values in {UNITS[name]} ({robot.name} gives no {name.replace('_', ' ')}: {where})",
    )


def refuse_idle(options: Any, robot: RobotModel, method: str) -> None:
    """Refuse an effect of ``options`` (a :class:`~twolink_pin.plant_options.PlantOptions`) that would do
    nothing on ``robot`` (a silent no-op is a wrong answer), or that ``method`` cannot run.

    Raises:
        InvalidParameterError: the option, its value and why it would do nothing.
    """
    for name in PER_JOINT:
        value = getattr(options, name)
        if isinstance(value, tuple) and not any(value):
            raise InvalidParameterError(
                OPTION[name],
                ",".join(f"{x:g}" for x in value),
                f"a value > 0 {UNITS[name]} on some joint (0 everywhere is the default: none)",
            )
    asked = [(n, getattr(options, n)) for n in ("soft_limits", "solref", "solimp") if getattr(options, n)]
    if asked:
        from twolink_pin.limits import POSITION, joint_limits

        if not joint_limits(robot).given(POSITION).any():
            name, value = asked[0]
            raise InvalidParameterError(
                OPTION[name],
                "on" if value is True else ",".join(f"{x:g}" for x in value),
                f"a robot with a position range on some joint ({robot.name}'s joints have none: no limit to soften)",
            )
    if options.integrator != "rk4" and method != "rk4":
        raise InvalidParameterError(
            "--mujoco-integrator",
            options.integrator,
            f"--method rk4 (MuJoCo's {options.integrator} steps the run itself; --method {method} is another integrator)",
        )


def believe_effects(
    robot: RobotModel, plant: Any, friction: Friction | None
) -> tuple[RobotModel, Friction | None]:
    """The robot and friction a law believes with the plant's effects (``--believe-effects``):
    its model is the plant's (``model.armature`` set, so ``M(q)`` has the armature) and its
    viscous friction, if it has one, gains the plant's joint damping."""
    believed = dataclasses.replace(robot, model=plant.model)
    if friction is not None and plant.joint_damping.any():
        viscous = tuple(float(v + d) for v, d in zip(friction.viscous, plant.joint_damping))
        friction = dataclasses.replace(friction, viscous=viscous)
    return believed, friction


def per_joint(name: str, values: Any, nv: int) -> np.ndarray:
    """An effect's values as a plant keeps them: a read-only (nv,) array of finite values >= 0
    (None: zeros)."""
    out = np.zeros(nv) if values is None else np.array(values, dtype=float)
    if out.shape != (nv,) or not (np.isfinite(out).all() and (out >= 0).all()):
        raise InvalidParameterError(
            name, values, f"{nv} finite values >= 0 {UNITS.get(name, '')} (one per joint)"
        )
    return _frozen(out)


def _frozen(values: np.ndarray) -> np.ndarray:
    values = np.array(values, dtype=float)
    values.setflags(write=False)
    return values


__all__ = [
    "ARM",
    "INTEGRATORS",
    "MUJOCO_ONLY",
    "OPTION",
    "PER_JOINT",
    "PLANT_KEYS",
    "SOLIMP",
    "SOLREF",
    "SWITCHES",
    "UNITS",
    "believe_effects",
    "check_effect",
    "check_solver",
    "per_joint",
    "plant_value",
    "refuse_idle",
    "resolve_effect",
]
