"""Every arm a user brings, at the defaults (issue 50, slow): each profile of ``examples/arms`` —
every fixed-base arm example-robot-data ships as its URDF has it, each arm of its trees (Baxter,
PR2, TIAGo) through a profile, a 5-link chain about parallel axes — with every built-in law for
3 s at default settings (``scripts/arms.py`` prints the same table): each runs with finite
states, and ``computed-torque`` on the exact model ends within 1e-3 rad.

Left out as the same arm as another (the test checks it): ``ur*_gripper`` (the joint-limited
UR's, its inertias and limits to 4e-9 relative: the files round their numbers differently),
``panda_collision`` (the Panda's)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin.model.catalog import example_robot_urdf

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "arms.py"
_spec = importlib.util.spec_from_file_location("arms_script", SCRIPT)
assert _spec is not None and _spec.loader is not None
arms = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(arms)


@pytest.mark.slow
@pytest.mark.parametrize("profile", arms.arm_profiles(), ids=lambda p: p.stem)
def test_every_law_runs_on_the_arm_at_its_defaults(profile: Path) -> None:
    rows = arms.run_arm(profile)
    failed = {law: row["failure"] for law, row in rows.items() if law != "nv" and not row["ok"]}
    assert not failed, failed
    exact = rows["computed-torque"]["error"]
    assert exact is not None and exact <= arms.EXACT_GOAL, exact


@pytest.mark.parametrize(
    ("left_out", "same_as"),
    [
        ("ur_description/urdf/ur3_gripper.urdf", "ur_description/urdf/ur3_joint_limited_robot.urdf"),
        ("ur_description/urdf/ur5_gripper.urdf", "ur_description/urdf/ur5_joint_limited_robot.urdf"),
        ("panda_description/urdf/panda_collision.urdf", "panda_description/urdf/panda.urdf"),
    ],
)
def test_the_arms_left_out_are_the_same_arm_as_one_that_runs(left_out: str, same_as: str) -> None:
    a, b = (pin.buildModelFromUrdf(str(example_robot_urdf(x))) for x in (left_out, same_as))
    assert a.nv == b.nv
    for name in ("lowerPositionLimit", "upperPositionLimit", "effortLimit", "velocityLimit"):
        # the grippers' files write π as 3.14159265, the joint-limited ones as 3.14159265359
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=0, atol=1e-8)
    rng = np.random.default_rng(0)
    for _ in range(3):
        q = rng.uniform(-1.0, 1.0, a.nq)
        np.testing.assert_allclose(pin.crba(a, a.createData(), q), pin.crba(b, b.createData(), q), rtol=1e-7)
        np.testing.assert_allclose(
            pin.computeGeneralizedGravity(a, a.createData(), q),
            pin.computeGeneralizedGravity(b, b.createData(), q),
            rtol=1e-7,
            atol=1e-9,
        )
