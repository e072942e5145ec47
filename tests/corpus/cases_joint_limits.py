"""Corpus cases of issue 36, part 1 (the joint limits read and reported everywhere): limits that
are zero, negative or NaN in a URDF, joint stops where they would do nothing, and the runs and
references that pass a limit, which must say so.

Kept apart from ``cases.py`` (same form, same ids' classes) so the lists there stay as they
are; ``tests/test_corpus.py`` runs both.
"""

from __future__ import annotations

import json

from corpus.cases import SIM, C
from corpus.spec import Case, text, twolink

LIMIT = 'effort="240" velocity="10"'
"""Joint 1's ``<limit>`` attributes in the shipped twolink.urdf (the range before them)."""
KINOVA_FAST = json.dumps(
    {
        "times": [0.0, 0.75, 1.5, 2.25, 3.0],
        "joints": [
            [1.5707, 2.618, 4.7124, 3.1415, 2.618, 0.0],
            [1.7496, 2.4391, 4.8913, 2.9029, 2.8566, -0.2386],
            [1.5707, 2.618, 4.7124, 3.1415, 2.618, 0.0],
            [1.3918, 2.7969, 4.5335, 3.3801, 2.3794, 0.2386],
            [1.5707, 2.618, 4.7124, 3.1415, 2.618, 0.0],
        ],
    }
)
"""The Kinova's default swing (rounded) in 3 s instead of 4: its 0.63 rad/s joints cannot follow."""

# fmt: off
JOINT_LIMITS: list[Case] = [
    # a limit that is zero, negative or NaN: zero is the URDF's "none", the others one line naming the joint
    C("unclear-info-urdf-velocity-negative", "info --robot arm.urdf", 2, err=("arm.urdf", "joint1", 'velocity="-1"', ">= 0"), setup=(twolink("arm.urdf", (LIMIT, 'effort="240" velocity="-1"')),)),
    C("unclear-info-urdf-velocity-nan", "info --robot arm.urdf", 2, err=("arm.urdf", "joint1", 'velocity="nan"'), setup=(twolink("arm.urdf", (LIMIT, 'effort="240" velocity="nan"')),)),
    C("unclear-info-urdf-effort-nan", "info --robot arm.urdf", 2, err=("arm.urdf", "joint1", 'effort="nan"'), setup=(twolink("arm.urdf", (LIMIT, 'effort="nan" velocity="10"')),)),
    C("unclear-info-urdf-velocity-zero", "info --robot arm.urdf --json", 0, setup=(twolink("arm.urdf", (LIMIT, 'effort="240" velocity="0"')),), note="velocity 0 is the URDF's 'no limit': null in the JSON, 'none' in the table"),
    C("unclear-trajectory-urdf-velocity-zero", "trajectory --robot arm.urdf", 0, out=("velocity [rad/s]", "none", "within every limit"), setup=(twolink("arm.urdf", (LIMIT, 'effort="240" velocity="0"')),)),
    # joint stops where they would do nothing: refused, naming the option and why
    C("wrong-simulate-joint-stops-without-range", f"simulate pd {SIM} --joint-stops --robot double_pendulum", 2, err=("--joint-stops", "position range", "joint1, joint2")),
    C("wrong-compare-joint-stops-without-range", f"compare pd {SIM} --joint-stops --robot double_pendulum --no-plot --out c", 2, err=("--joint-stops", "position range"), absent=("c",)),
    C("wrong-simulate-joint-stops-adaptive", f"simulate pd {SIM} --joint-stops --method adaptive", 2, err=("--joint-stops", "rk4", "adaptive")),
    C("wrong-sweep-joint-stops-without-range", f"sweep pd --samples 2 {SIM} --joint-stops --robot double_pendulum --no-plot --out s", 2, err=("--joint-stops", "position range"), absent=("s",)),
    # a run or a reference past a limit says so (never silently)
    C("wrong-simulate-past-the-range-warns", f"simulate pd {SIM} --q0-offset 3.5 0", 0, out=("joint 1 (joint1) passed its position range",), warns=("warning: pd: joint 1 (joint1) passed its position range", "--joint-stops")),
    C("wrong-simulate-past-the-range-stopped", f"simulate pd {SIM} --q0-offset 3.5 0 --joint-stops", 0, out=("joint stops",), not_err=("passed its position range",)),
    C("wrong-compare-past-the-range-warns", f"compare pd computed-torque {SIM} --q0-offset 3.5 0 --no-plot --out c", 0, warns=("warning: pd: joint 1 (joint1) passed its position range", "warning: computed-torque: joint 1"), exists=("c/comparison.md",), checks=()),
    C("wrong-trajectory-kinova-too-fast", "trajectory --robot kinova --trajectory fast.json", 0, out=("BEYOND A LIMIT", "velocity of j2s6s200_joint_1", "0.6283"), setup=(text("fast.json", KINOVA_FAST),)),
]
