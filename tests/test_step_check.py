"""The step checked before the run (issue 50 §2): the start's fastest mode against the
integrator's stability bound — RK4's region from its polynomial, the refusal's numbers against
the run itself (beyond the largest stable step it diverges, within it it does not), the plant's
damping, a user's law without declared gains, a sampled law; a run that still diverges names
the joint that grew."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from twolink_pin import load_robot
from twolink_pin.cli import main
from twolink_pin.controllers import ComputedTorque, Controller, Gains, LawInput, LawOutput, SlotineLiGains
from twolink_pin.errors import SimulationDivergedError, StepTooLargeError
from twolink_pin.plant import Plant
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.simulation.step_check import (
    RK4_IMAGINARY_AXIS,
    RK4_REAL_AXIS,
    check_step,
    rk4_amplification,
    rk4_radius,
)
from twolink_pin.trajectory import default_trajectory

TWOLINK = load_robot()
SHORT = SimulationConfig(duration=0.3)


def test_rk4s_bounds_are_where_its_amplification_reaches_one() -> None:
    """|R(−2.785)| = 1 (the real root of z⁴/24 + z³/6 + z²/2 + z = 0 besides 0) and |R(±2√2 i)| = 1
    (|R(iy)|² = 1 − y⁶/72 + y⁸/576); the radius along every ray from 90° to 180° is where
    |R| crosses 1."""
    roots = np.roots([1 / 24, 1 / 6, 1 / 2, 1])  # R(z) − 1 = z (z³/24 + z²/6 + z/2 + 1)
    (real,) = [r.real for r in roots if abs(r.imag) < 1e-12]
    assert RK4_REAL_AXIS == pytest.approx(-real, rel=1e-12)
    assert RK4_IMAGINARY_AXIS == pytest.approx(math.sqrt(8.0), rel=1e-15)
    assert rk4_amplification(np.array([-RK4_REAL_AXIS])) == pytest.approx(1.0, abs=1e-12)
    assert rk4_radius(-1.0 + 0j) == pytest.approx(RK4_REAL_AXIS, rel=1e-6)
    assert rk4_radius(1j) == pytest.approx(RK4_IMAGINARY_AXIS, rel=1e-6)
    for angle in np.linspace(0.55 * np.pi, 0.95 * np.pi, 7):
        r = rk4_radius(np.exp(1j * angle))
        assert rk4_amplification(np.array([0.999 * r * np.exp(1j * angle)]))[0] <= 1 + 1e-9
        assert rk4_amplification(np.array([1.01 * r * np.exp(1j * angle)]))[0] > 1


def _ten_times_too_high() -> ComputedTorque:
    """The report's K (40, 50) × 100 on the twolink: a mode near 9000 1/s (RK4 at 1 ms: 2785)."""
    return ComputedTorque(TWOLINK, SlotineLiGains(k=(4000.0, 5000.0)))


def test_a_gain_100x_too_high_is_refused_naming_the_rate_the_gain_the_joint_and_the_largest_step() -> None:
    law, plant, reference = _ten_times_too_high(), Plant(TWOLINK), default_trajectory(TWOLINK)
    with pytest.raises(StepTooLargeError) as info:
        simulate(law, plant, reference, SHORT)
    text = str(info.value)
    assert info.value.name == "--dt" and info.value.value == 1e-3
    for part in (
        "'computed-torque' on twolink",
        "1/s (real)",
        "moving joint",
        "the law's gain k [N·m·s/rad]",
    ):
        assert part in text, part
    check = check_step(law, plant, reference, SHORT)
    assert not check.stable and check.rate > RK4_REAL_AXIS / 1e-3
    assert f"at most {math.floor(check.largest_step * 1e5) / 1e5:.2g} s" in text


def test_beyond_the_largest_stable_step_the_run_diverges_and_within_it_it_does_not() -> None:
    """The check's largest stable dt, against the simulation itself (run anyway)."""
    law, plant, reference = _ten_times_too_high(), Plant(TWOLINK), default_trajectory(TWOLINK)
    largest = check_step(law, plant, reference, SHORT).largest_step
    runs = {}
    for factor in (0.9, 1.1):
        config = dataclasses.replace(SHORT, dt=factor * largest, check_step=False, duration=0.2)
        result = simulate(law, plant, reference, config)
        runs[factor] = np.abs(np.asarray(result.q) - np.asarray(result.q_des)).max()
    assert runs[0.9] <= 0.1 + 1e-12  # never beyond the initial offset
    assert runs[1.1] > 100.0  # the fast mode grows by |R(λ dt)| > 1 every step
    with pytest.raises(SimulationDivergedError, match=r"\(q̇ of joint \d \[rad/s\]\)|non-finite"):
        simulate(law, plant, reference, dataclasses.replace(SHORT, dt=1.3 * largest, check_step=False))


def test_the_defaults_pass_on_every_catalog_arm() -> None:
    from twolink_pin.model.catalog import names
    from twolink_pin.run_spec import RunSpec

    for name in names():
        robot = load_robot(name)
        for law in ("pd", "computed-torque", "adaptive", "impedance"):
            scenario = RunSpec(law=law).build(robot)
            assert check_step(*scenario, default_trajectory(robot), SHORT).stable, (name, law)


DAMPED = """<?xml version="1.0"?>
<robot name="damped">
  <link name="base"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="50" velocity="3"/></joint>
  <link name="upper"><inertial><origin xyz="0.2 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
  <joint name="wrist" type="revolute"><parent link="upper"/><child link="hand"/>
    <origin xyz="0.4 0 0"/><axis xyz="1 0 0"/><limit lower="-2" upper="2" effort="5" velocity="3"/>
    <dynamics damping="2" friction="0"/></joint>
  <link name="hand"><inertial><origin xyz="0 0 0"/><mass value="0.05"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
</robot>
"""


def test_the_plants_joint_damping_over_a_light_joint_is_refused_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """2 N·m·s/rad on a 1e-4 kg·m² wrist: rate 2e4 1/s (the xArm7's joint 7 alike); the largest
    stable step it gives runs."""
    urdf = tmp_path / "damped.urdf"
    urdf.write_text(DAMPED)
    argv = ["simulate", "pd", "--robot", str(urdf), "--plant-friction", "on", "--duration", "0.05"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "the plant's joint damping: 2 N·m·s/rad on joint 2" in err[0], err
    assert "moving joint 2 (wrist) most" in err[0]
    largest = float(err[0].split("at most ")[1].split(" s")[0])
    assert main([*argv, "--dt", f"{largest:g}"]) == 0


class Stiff(Controller, register=False):
    """A user's law with no gains declared: τ = −10⁷ (q − q_d), undamped: modes ±i √(10⁷/M),
    5600 rad/s on the twolink's second joint (RK4 at 1 ms holds to 2828)."""

    name = "stiff"
    title = "stiff"
    Gains = dataclasses.make_dataclass("StiffGains", [], bases=(Gains,), frozen=True, eq=False)

    def compute(self, x: LawInput, terms: object) -> LawOutput:
        return LawOutput(-1e7 * (x.q - x.q_des))


def test_a_law_without_declared_gains_is_linearised_and_refused() -> None:
    law = Stiff(TWOLINK)
    with pytest.raises(
        StepTooLargeError, match=r"oscillating at .* set by the law's position feedback on joint \d"
    ):
        simulate(law, Plant(TWOLINK), default_trajectory(TWOLINK), SHORT)


def test_a_sampled_law_whose_period_is_too_long_is_refused_naming_the_control_period() -> None:
    law = ComputedTorque(TWOLINK, SlotineLiGains(k=(400.0, 500.0)))
    held = dataclasses.replace(SHORT, control_period=0.02)
    with pytest.raises(StepTooLargeError) as info:
        simulate(law, Plant(TWOLINK), default_trajectory(TWOLINK), held)
    assert info.value.name == "--control-period"
    check = check_step(law, Plant(TWOLINK), default_trajectory(TWOLINK), held)
    assert 0 < check.largest_step < 0.02
    fine = dataclasses.replace(held, control_period=round(check.largest_step, 3) or 1e-3)
    assert check_step(law, Plant(TWOLINK), default_trajectory(TWOLINK), fine).stable


def test_a_run_that_still_diverges_names_the_joint_that_grew(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["simulate", "computed-torque", "--gain", "k=4000,5000", "--duration", "0.3", "--no-step-check"]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "diverged at t = " in err and ("of joint" in err)
