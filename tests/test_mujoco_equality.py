"""Issue 44 part 2, over the whole 30 s: every extra effect off and RK4 at the run's dt, a law's run
on the MuJoCo plant is its run on the Pinocchio plant to 1e-8 rad — the twolink, the UR5 and the
Panda × pd, computed torque, adaptive, osc. (1-s runs of four of them are in the fast tier:
test_mujoco_plant.py; scripts/benchmark.py --mujoco-only prints these numbers.)"""

from __future__ import annotations

import numpy as np
import pytest

from twolink_pin.model import load_robot
from twolink_pin.plant import PlantOptions
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
def test_thirty_seconds_of_the_same_law_on_both_plants_agree_to_1e_8_rad(robot: str, law: str) -> None:
    arm = load_robot(robot)
    reference = default_trajectory(arm)
    q = []
    for engine in ("pinocchio", "mujoco"):
        spec = RunSpec(law=law, plant=PlantOptions(engine=engine), simulation=SimulationConfig(duration=30.0))
        q.append(simulate(*spec.build(arm), reference, spec.simulation).q)
    assert np.abs(q[0] - q[1]).max() <= 1e-8
