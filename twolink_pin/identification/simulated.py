"""Identification data made by the toolkit: a closed-loop run along an excitation, logged.

The arm (the robot's Pinocchio model with viscous and Coulomb joint friction) tracks the
excitation trajectory under :class:`FrictionCompensatedTracking` — Slotine–Li computed
torque with the exact rigid-body model *and* the plant's friction, the well-tracking law an
identification experiment runs. Because the law cancels the friction it knows at the same
instant the plant feels it, the closed loop is smooth (``q̈ = q̈_r − M⁻¹ K s``, no jump at a
velocity reversal): the jumps are in the applied torque only, as on an arm whose drives
compensate friction. The log keeps what a real one would: ``t``, ``q``, the logged ``q̇`` and
the applied ``τ``. The run is integrated by RK4 at ``dt`` (default :data:`DEFAULT_DT` =
0.5 ms, a 2-kHz log), starting on the trajectory (no initial offset).

The plant's friction is the robot profile's (the twolink: the report's V = (0.4, 0.2)
N·m·s/rad, C = (0.2, 0.1) N·m), else the plant's :data:`~twolink_pin.plant.DEFAULT_FRICTION` on every joint (a URDF's
``<dynamics>`` is not read here: the identification runs of a catalog arm stay what they were).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from twolink_pin.controllers import ComputedTorque, LawInput, LawOutput, Terms
from twolink_pin.dynamics import Friction
from twolink_pin.errors import InvalidParameterError, require_type
from twolink_pin.identification.data import RunLog
from twolink_pin.identification.observation import ParameterSet
from twolink_pin.model import RobotModel
from twolink_pin.plant import DEFAULT_FRICTION
from twolink_pin.trajectory import Trajectory

DEFAULT_DT = 5e-4
"""RK4 step and log spacing of simulated identification runs [s]."""
DEFAULT_PERIODS = 4
"""Default length of a simulated run, in periods of the excitation (3 to fit, 1 to validate)."""


class FrictionCompensatedTracking(ComputedTorque, register=False):
    r"""Computed torque with the exact model and friction compensation::

        τ = M(q) q̈_r + C(q, q̇) q̇_r + g(q) + V q̇ + C_c sgn(q̇) − K s

    On a plant with exactly that friction, ``M ṡ + (C + K) s = 0``: the tracking error decays
    and the motion is as smooth as the reference (the identification experiment's law).
    """

    name = "computed-torque+friction"
    title = "computed torque with friction compensation (identification runs)"

    def __init__(self, robot: RobotModel, gains: Any = None, *, friction: Friction) -> None:
        super().__init__(robot, gains)
        self.friction = friction
        """The friction the law compensates [N·m·s/rad, N·m]."""

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        out = super().compute(x, terms)
        return LawOutput(out.tau + self.friction.torque(x.v))


def plant_friction(robot: RobotModel) -> Friction:
    """The joint friction of ``robot``'s simulated identification runs (module docstring)."""
    if robot.profile.friction is not None:
        return Friction(*robot.profile.friction)
    viscous, coulomb = DEFAULT_FRICTION
    return Friction((viscous,) * robot.nv, (coulomb,) * robot.nv)


def simulate_log(
    robot: RobotModel,
    trajectory: Trajectory,
    duration: float | None = None,
    dt: float = DEFAULT_DT,
    friction: Friction | None = None,
    engine: str = "pinocchio",
) -> RunLog:
    """A logged closed-loop run of ``robot`` along ``trajectory`` (see the module docstring).

    Args:
        robot: The arm.
        trajectory: The excitation (any periodic reference).
        duration: Simulated time [s]; default :data:`DEFAULT_PERIODS` periods.
        dt: RK4 step and log spacing [s].
        friction: The plant's friction (compensated by the law); default :func:`plant_friction`.
        engine: The simulator of the run: ``pinocchio`` or ``mujoco`` (the same arm, MuJoCo's
            forward dynamics at each RK4 stage: :mod:`twolink_pin.mujoco_plant`).

    Returns:
        The log, with ``true_parameters`` (base parameters, then V and C per joint).

    Raises:
        InvalidParameterError: a bad duration or step, friction for another number of
            joints; SimulationDivergedError if the run diverges.
    """
    require_type(robot, RobotModel, "robot", "a RobotModel (twolink_pin.load_robot)")
    from twolink_pin.plant import ENGINES
    from twolink_pin.simulation import SimulationConfig, simulate

    if friction is None:
        friction = plant_friction(robot)
    if len(friction.viscous) != robot.nv:
        raise InvalidParameterError("friction", friction, f"viscous and Coulomb values for {robot.nv} joints")
    length = DEFAULT_PERIODS * trajectory.period if duration is None else duration
    controller = FrictionCompensatedTracking(robot, friction=friction)
    if engine not in ENGINES:
        raise InvalidParameterError("engine", engine, f"one of {', '.join(ENGINES)}")
    plant = ENGINES[engine](robot, friction=friction)
    result = simulate(controller, plant, trajectory, SimulationConfig(duration=length, dt=dt, q0_offset=0.0))
    truth = ParameterSet.of(robot, friction=True).true_values(robot.model, friction)
    return RunLog(
        t=result.t,
        q=result.q,
        tau=result.tau,
        v=result.v,
        source=f"simulated: {robot.name} tracking its reference ({controller.name}), {length:g} s at dt = {dt:g} s"
        + ("" if engine == "pinocchio" else f" on the {engine} plant"),
        true_parameters=np.asarray(truth),
        reference=trajectory,
    )
