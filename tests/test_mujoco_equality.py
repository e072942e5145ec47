"""Issue 44 part 2: every extra effect off and RK4 at the run's dt, a law's run on the MuJoCo plant is
its run on the Pinocchio plant to 1e-8 rad — the twolink, the UR5 and the Panda × pd, computed
torque, adaptive, osc, over 10 s here (two and a half periods: every loop has converged; the
whole suite's share kept to ~25 s of CPU), over the goal's 30 s in ``scripts/benchmark.py
--mujoco-only`` (measured: 9e-16 rad at most). 1-s runs of four of them are in the fast tier
(test_mujoco_plant.py)."""

from __future__ import annotations

import numpy as np
import pytest

from twolink_pin.model import load_robot
from twolink_pin.plant_options import PlantOptions
from twolink_pin.run_spec import RunSpec
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.trajectory import default_trajectory

CASES = [
    (robot, law)
    for robot in ("twolink", "ur5", "panda")
    for law in ("pd", "computed-torque", "adaptive", "osc")
]


@pytest.mark.slow
@pytest.mark.parametrize(("robot", "law"), CASES, ids=[f"{r}-{law}" for r, law in CASES])
def test_the_same_law_on_both_plants_agrees_to_1e_8_rad(robot: str, law: str) -> None:
    arm = load_robot(robot)
    reference = default_trajectory(arm)
    q = []
    for engine in ("pinocchio", "mujoco"):
        spec = RunSpec(law=law, plant=PlantOptions(engine=engine), simulation=SimulationConfig(duration=10.0))
        q.append(simulate(*spec.build(arm), reference, spec.simulation).q)
    assert np.abs(q[0] - q[1]).max() <= 1e-8
