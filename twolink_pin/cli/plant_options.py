"""The plant's engine and the arm's effects on the command line: ``--plant``, ``--armature``,
``--joint-damping``, ``--frictionloss``, ``--soft-limits``, ``--solref``, ``--solimp``,
``--mujoco-integrator`` (:mod:`twolink_pin.arm_effects`).

Each value type raises :class:`argparse.ArgumentTypeError` naming the value and the expected
form (one line on stderr, exit 2); :func:`plant_effects` gives them to the run's
:class:`~twolink_pin.run_spec.PlantOptions`, which refuses an effect the chosen plant lacks.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

from twolink_pin.arm_effects import ARM, INTEGRATORS, UNITS, check_effect, check_solver, plant_value
from twolink_pin.cli.arguments import MAX_TEXT
from twolink_pin.cli.common_options import run_group
from twolink_pin.errors import InvalidParameterError

MAX_EFFECT = 1e6
"""Largest armature [kg·m²], damping [N·m·s/rad] or dry friction [N·m] accepted."""


def _shown(text: str) -> str:
    return repr(text if len(text) <= MAX_TEXT else text[:MAX_TEXT] + "…")


def per_joint(name: str) -> Callable[[str], Any]:
    """``arm`` or finite numbers >= 0 (one, or one per joint, comma-separated) in the effect's unit."""

    def parse(text: str) -> Any:
        expected = f"'{ARM}' or numbers >= 0 {UNITS[name]}, one or one per joint (e.g. 0.1 or 0.1,0.05), got {_shown(text)}"
        try:
            value = check_effect(name, plant_value(name, text))
        except InvalidParameterError:
            raise argparse.ArgumentTypeError(f"expected {expected}") from None
        if isinstance(value, tuple) and max(value) > MAX_EFFECT:
            raise argparse.ArgumentTypeError(f"expected at most {MAX_EFFECT:g}: {expected}")
        return value

    return parse


def solver(name: str) -> Callable[[str], tuple[float, ...]]:
    """``solref`` or ``solimp`` as MuJoCo's standard form takes them."""

    def parse(text: str) -> tuple[float, ...]:
        try:
            value = check_solver(name, plant_value(name, text))
        except InvalidParameterError as exc:
            raise argparse.ArgumentTypeError(f"expected {exc.expected}, got {_shown(text)}") from None
        assert value is not None
        return value

    return parse


def add_plant_options(p: argparse.ArgumentParser) -> None:
    """The plant's engine and the arm's effects, on a command that simulates (its run options)."""
    group = run_group(p)
    group.add_argument(
        "--plant",
        choices=("pinocchio", "mujoco"),
        default="pinocchio",
        help="the simulator the arm runs on: Pinocchio's ABA (default) or MuJoCo, the same URDF compiled by "
        "MuJoCo (docs/mujoco.md)",
    )
    group.add_argument(
        "--armature",
        type=per_joint("armature"),
        metavar="arm|A[,A…]",
        help="rotor inertia through the gearbox [kg·m²] on each joint's diagonal of M (both plants): one "
        "value, one per joint, or 'arm' (the robot's, e.g. the Menagerie's Panda)",
    )
    group.add_argument(
        "--joint-damping",
        type=per_joint("joint_damping"),
        metavar="arm|D[,D…]",
        help="joint damping [N·m·s/rad], τ −= D q̇ (both plants): one value, one per joint, or 'arm' "
        "(the robot's profile, else its URDF's <dynamics damping>)",
    )
    group.add_argument(
        "--frictionloss",
        type=per_joint("frictionloss"),
        metavar="arm|F[,F…]",
        help="MuJoCo's dry friction [N·m], a constraint: the joint sticks below F (--plant mujoco): one value, "
        "one per joint, or 'arm' (the robot's, else its URDF's <dynamics friction>)",
    )
    group.add_argument(
        "--soft-limits",
        choices=("on", "off"),
        default=None,
        help="each joint's URDF position range as MuJoCo's soft limit (--plant mujoco; default on)",
    )
    group.add_argument(
        "--solref",
        type=solver("solref"),
        metavar="TIMECONST,DAMPRATIO",
        help="the soft limits' time constant [s] and damping ratio (--plant mujoco; MuJoCo's default 0.02,1)",
    )
    group.add_argument(
        "--solimp",
        type=solver("solimp"),
        metavar="D0,DWIDTH,WIDTH[,MID,POWER]",
        help="the soft limits' impedance (--plant mujoco; MuJoCo's default 0.9,0.95,0.001,0.5,2)",
    )
    group.add_argument(
        "--believe-effects",
        action="store_true",
        help="the law's model includes the plant's armature (its M(q)) and joint damping (the friction a "
        "friction-estimating law believes)",
    )
    group.add_argument(
        "--mujoco-integrator",
        choices=INTEGRATORS,
        default="rk4",
        help="rk4: the engine's RK4 on MuJoCo's forward dynamics, the law at every stage (default); euler, "
        "implicitfast: MuJoCo's mj_step, the law held over each step (--plant mujoco)",
    )


def plant_effects(args: Any) -> dict[str, Any]:
    """The engine and the arm's effects the arguments ask for, as
    :class:`~twolink_pin.run_spec.PlantOptions` fields (the defaults for a command without them)."""
    soft = getattr(args, "soft_limits", None)
    return {
        "engine": getattr(args, "plant", None) or "pinocchio",
        "armature": getattr(args, "armature", None),
        "joint_damping": getattr(args, "joint_damping", None),
        "frictionloss": getattr(args, "frictionloss", None),
        "soft_limits": None if soft is None else soft == "on",
        "solref": getattr(args, "solref", None),
        "solimp": getattr(args, "solimp", None),
        "integrator": getattr(args, "mujoco_integrator", None) or "rk4",
    }


__all__ = ["MAX_EFFECT", "add_plant_options", "per_joint", "plant_effects", "solver"]
