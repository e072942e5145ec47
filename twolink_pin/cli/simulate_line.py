"""The ``twolink-pin simulate …`` line that reproduces a run: every number as ``repr`` gives
it (a float read back from its ``repr`` is the same float), so the line's run is the same
run, bit for bit. ``tune`` shows it and prints it with each run's JSON line."""

from __future__ import annotations

import math
import shlex
from collections.abc import Sequence
from typing import Any

from twolink_pin.run_spec import RunSpec
from twolink_pin.simulation import SimulationConfig

_DEFAULTS = SimulationConfig()


def _number(x: float) -> str:
    return repr(float(x))


def _numbers(values: Any) -> str:
    if isinstance(values, (list, tuple)):
        return ",".join(_number(x) for x in values)
    return _number(values)


def _window(start: float, stop: float) -> str:
    return f"@{_number(start)}:{'' if math.isinf(stop) else _number(stop)}"


def _plant_tokens(spec: RunSpec) -> list[str]:
    plant = spec.plant
    tokens: list[str] = []
    if plant.friction != "law":
        tokens.append(f"--plant-friction={plant.friction}")
    if plant.saturate:
        tokens.append("--saturate")
    if plant.friction_smoothing is not None:
        tokens.append(f"--friction-smoothing={_number(plant.friction_smoothing)}")
    if plant.wrench is not None:
        w = plant.wrench
        tokens.append(f"--wrench={_numbers(w.force)}{_window(w.start, w.stop)}")
    if plant.payload_step is not None:
        tokens.append(f"--payload-step={_number(plant.payload_step.mass)}@{_number(plant.payload_step.time)}")
    if plant.sensor_noise is not None:
        n = plant.sensor_noise
        tokens += [f"--sensor-noise={_number(n.sigma_q)},{_number(n.sigma_v)}", f"--noise-seed={n.seed}"]
    if plant.delay:
        tokens.append(f"--delay={plant.delay}")
    if plant.position_stops:
        tokens.append("--joint-stops")
    return tokens + _effect_tokens(spec)


def _effect_tokens(spec: RunSpec) -> list[str]:
    """The plant's engine and the arm's effects (:mod:`twolink_pin.arm_effects`) as options."""
    plant = spec.plant
    tokens: list[str] = []
    if plant.engine != "pinocchio":
        tokens.append(f"--plant={plant.engine}")
    for name in ("armature", "joint_damping", "frictionloss"):
        value = getattr(plant, name)
        if value is not None:
            tokens.append(
                f"--{name.replace('_', '-')}={value if isinstance(value, str) else _numbers(value)}"
            )
    if plant.soft_limits is not None:
        tokens.append(f"--soft-limits={'on' if plant.soft_limits else 'off'}")
    for name in ("solref", "solimp"):
        value = getattr(plant, name)
        if value is not None:
            tokens.append(f"--{name}={_numbers(value)}")
    if plant.integrator != "rk4":
        tokens.append(f"--mujoco-integrator={plant.integrator}")
    if spec.believed_effects:
        tokens.append("--believe-effects")
    return tokens


def _simulation_tokens(sim: SimulationConfig) -> list[str]:
    tokens = [f"--duration={_number(sim.duration)}"]
    if sim.dt != _DEFAULTS.dt:
        tokens.append(f"--dt={_number(sim.dt)}")
    if sim.method != _DEFAULTS.method:
        tokens.append(f"--method={sim.method}")
    if sim.q0_offset is not None:
        offsets = sim.q0_offset if isinstance(sim.q0_offset, tuple) else (sim.q0_offset,)
        tokens += ["--q0-offset", *(_number(x) for x in offsets)]
    if sim.control_period is not None:
        tokens.append(f"--control-period={_number(sim.control_period)}")
    return tokens


def simulate_argv(
    spec: RunSpec, robot: str | None = None, payload: float = 0.0, trajectory: str | None = None
) -> list[str]:
    """The arguments of ``twolink-pin simulate`` (after the program name) for ``spec`` on the
    robot ``robot`` (a catalog name or URDF path, None: the default) with ``payload`` [kg]
    and the reference file ``trajectory`` (None: the robot's own)."""
    if not isinstance(spec.law, str):
        raise ValueError("a law given by reference (name, file.py:Class) has a command line; a class has not")
    tokens = ["simulate", spec.law]
    if robot is not None:
        tokens.append(f"--robot={robot}")
    if payload:
        tokens.append(f"--payload={_number(payload)}")
    if trajectory is not None:
        tokens.append(f"--trajectory={trajectory}")
    tokens += _simulation_tokens(spec.simulation)
    if spec.lam is not None:
        tokens.append(f"--lambda={_number(spec.lam)}")
    tokens += [f"--gain={name}={_numbers(value)}" for name, value in spec.gains]
    if spec.parameters is not None:
        tokens.append(f"--{spec.parameters_use}={spec.parameters}")
    return tokens + _plant_tokens(spec)


def command_line(argv: Sequence[str]) -> str:
    """``twolink-pin`` and ``argv`` as one shell line (quoted where needed)."""
    return " ".join(["twolink-pin", *(shlex.quote(a) for a in argv)])


__all__ = ["command_line", "simulate_argv"]
