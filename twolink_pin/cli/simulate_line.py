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
    """A gain's value as ``--gain`` reads it: a number, numbers joined by commas (a matrix
    row by row), or a word as it is (a gain declared with ``choices``: mpc's
    ``reference_ahead=preview``)."""
    if isinstance(values, str):
        return values
    if isinstance(values, (list, tuple)):
        return ",".join(_numbers(x) for x in values)
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
        force = f",{_number(n.sigma_f)}" if n.sigma_f else ""
        tokens += [
            f"--sensor-noise={_number(n.sigma_q)},{_number(n.sigma_v)}{force}",
            f"--noise-seed={n.seed}",
        ]
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


def _scene_tokens(spec: RunSpec, scene: str | None) -> list[str]:
    """``--scene FILE`` (the file the scene was read from), or ``--wall …`` for a scene that is
    one plane with ``--wall``'s defaults otherwise; none without a scene.

    Raises:
        ValueError: a scene from no file that ``--wall`` cannot say.
    """
    from twolink_pin.contact.scene import DEFAULT_RADIUS, DEFAULT_SLIP_VELOCITY

    given = spec.plant.scene
    if given is None:
        return []
    if scene is not None:
        return [f"--scene={scene}"]
    (s,) = given.surfaces if len(given.surfaces) == 1 else (None,)
    plain = (
        given.radius == DEFAULT_RADIUS
        and given.slip_velocity == DEFAULT_SLIP_VELOCITY
        and given.frame is None
    )
    if (
        s is None
        or not plain
        or s.size is not None
        or s.solref is not None
        or s.solimp is not None
        or s.name != "wall"
    ):
        raise ValueError("a scene read from no file and beyond one --wall plane has no command line")
    wall = f"{_numbers(s.point)}:{_numbers(s.normal)}:{_number(s.stiffness)}:{_number(s.damping)}:{_number(s.friction)}"
    return [f"--wall={wall}"]


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
    if not sim.check_step:
        tokens.append("--no-step-check")
    return tokens


def simulate_argv(
    spec: RunSpec,
    robot: str | None = None,
    payload: float = 0.0,
    trajectory: str | None = None,
    scene: str | None = None,
    repair_inertias: bool = False,
) -> list[str]:
    """The arguments of ``twolink-pin simulate`` (after the program name) for ``spec`` on the
    robot ``robot`` (a catalog name, a URDF or profile path, None: the default) with ``payload``
    [kg], the reference file ``trajectory`` (None: the robot's own), the scene file ``scene`` the
    spec's scene was read from (None: ``--wall``, or no scene) and ``--repair-inertias``."""
    if not isinstance(spec.law, str):
        raise ValueError("a law given by reference (name, file.py:Class) has a command line; a class has not")
    tokens = ["simulate", spec.law]
    if robot is not None:
        tokens.append(f"--robot={robot}")
    if payload:
        tokens.append(f"--payload={_number(payload)}")
    if repair_inertias:
        tokens.append("--repair-inertias")
    if trajectory is not None:
        tokens.append(f"--trajectory={trajectory}")
    tokens += _simulation_tokens(spec.simulation)
    if spec.lam is not None:
        tokens.append(f"--lambda={_number(spec.lam)}")
    tokens += [f"--gain={name}={_numbers(value)}" for name, value in spec.gains]
    if spec.parameters is not None:
        tokens.append(f"--{spec.parameters_use}={spec.parameters}")
    return tokens + _plant_tokens(spec) + _scene_tokens(spec, scene)


def command_line(argv: Sequence[str]) -> str:
    """``twolink-pin`` and ``argv`` as one shell line (quoted where needed)."""
    return " ".join(["twolink-pin", *(shlex.quote(a) for a in argv)])


__all__ = ["command_line", "simulate_argv"]
