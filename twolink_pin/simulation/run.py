"""``simulate``: one closed-loop run, recorded — N = 1 of the engine."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from twolink_pin.arrays import readonly, readonly_or_none
from twolink_pin.controllers import Controller
from twolink_pin.errors import InvalidParameterError
from twolink_pin.plant import Plant
from twolink_pin.simulation.adaptive_step import integrate_adaptive
from twolink_pin.simulation.config import SimulationConfig, check_recorded_size, initial_state
from twolink_pin.simulation.engine import Samples, integrate
from twolink_pin.simulation.result import SimulationResult
from twolink_pin.simulation.sensing import check_contact_setup
from twolink_pin.simulation.step_check import require_stable_step
from twolink_pin.trajectory import Trajectory


def check_setup(controller: Controller, plant: Plant, trajectory: Trajectory) -> None:
    """Raise unless the law, the plant and the reference are what they must be, for the same
    number of joints."""
    if not isinstance(controller, Controller):
        raise InvalidParameterError("controller", type(controller).__name__, "a twolink_pin Controller")
    if not isinstance(plant, Plant):
        raise InvalidParameterError("plant", type(plant).__name__, "a twolink_pin Plant")
    if not isinstance(trajectory, Trajectory):
        raise InvalidParameterError("trajectory", type(trajectory).__name__, "a twolink_pin Trajectory")
    nv = plant.robot.nv
    if controller.robot.nv != nv:
        raise InvalidParameterError(
            "controller",
            f"{controller.name} for nv = {controller.robot.nv}",
            f"a law built for the plant's nv = {nv}",
        )
    if trajectory.nv != nv:
        raise InvalidParameterError(
            "trajectory", f"{trajectory.nv} joints", f"a trajectory for the plant's {nv} joints"
        )
    check_contact_setup(controller, plant, trajectory)


def estimated_truth(controller: Controller, plant: Plant) -> np.ndarray | None:
    """The plant's actual values of what ``controller`` estimates (None if nothing):
    its map's parameters of the plant's model, then the plant's friction (zeros without)."""
    parts = []
    for kind in controller.estimates:
        if kind == "inertial":
            parts.append(np.asarray(controller.robot.parameter_map.values(plant.model), dtype=float))
        else:
            friction = plant.friction
            parts.append(np.zeros(2 * plant.robot.nv) if friction is None else friction.parameters)
    return np.concatenate(parts) if parts else None


def state_labels(controller: Controller, nz: int) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """Names and units of the law's ``nz`` state entries (``z1``, … and no unit for a law
    whose declared :meth:`~twolink_pin.controllers.Controller.state_variables` do not
    describe its state, e.g. one that overrides only ``state_size``)."""
    variables = controller.state_variables()
    if len(variables) != nz:
        return tuple(f"z{i + 1}" for i in range(nz)), ("",) * nz
    return tuple(v.name for v in variables), tuple(v.unit for v in variables)


def simulate(
    controller: Controller,
    plant: Plant,
    trajectory: Trajectory,
    config: SimulationConfig | None = None,
) -> SimulationResult:
    """Run ``controller`` on ``plant`` tracking ``trajectory``, every sample recorded.

    Raises:
        InvalidParameterError: the law, plant and trajectory disagree on nv, offsets of the
            wrong length, per-run gains (use :func:`twolink_pin.simulate_batch`), or exact-sign
            friction with the adaptive method.
        StepTooLargeError: ``dt`` (or the control period) beyond the integrator's stability bound on
            the fastest mode of the start (:mod:`~twolink_pin.simulation.step_check`; refused before
            the run unless ``config.check_step`` is False).
        SimulationDivergedError: the state became non-finite or absurd (the time is given).
        ControllerError: the law raised, or returned the wrong shape or a non-finite torque.
    """
    config = config if config is not None else SimulationConfig()
    if not isinstance(config, SimulationConfig):
        raise InvalidParameterError("config", type(config).__name__, "a SimulationConfig or None")
    check_setup(controller, plant, trajectory)
    runs = controller.runs
    if runs not in (None, 1):
        raise InvalidParameterError(
            "controller", f"per-run gains for {runs} runs", "one value set (simulate_batch runs N)"
        )
    q0, v0 = initial_state(plant, trajectory, config)
    z0 = np.atleast_2d(np.asarray(controller.initial_state(), dtype=float)).reshape(1, -1)
    check_recorded_size(config.steps, plant.robot.nv, z0.shape[1])
    require_stable_step(controller, plant, trajectory, config)
    samples = _recorded_run(controller, plant, trajectory, config, q0, v0, z0)
    return _single_result(controller, plant, trajectory, config, samples)


def _recorded_run(
    controller: Controller,
    plant: Plant,
    trajectory: Trajectory,
    config: SimulationConfig,
    q0: np.ndarray,
    v0: np.ndarray,
    z0: np.ndarray,
) -> Samples:
    """Every sample of the run from ``q0`` [rad], ``v0`` [rad/s], ``z0`` (shape (nv,), (nv,),
    (1, nz)) by the config's method: the engine's RK4 (raising at a divergence) or DOP853."""
    if config.method == "rk4":
        samples = integrate(
            controller,
            plant,
            trajectory,
            config,
            q0[None],
            v0[None],
            z0,
            record=True,
            stop_on_divergence=True,
        ).record
        assert samples is not None
        return samples
    if plant.has_events:
        raise InvalidParameterError(
            "method",
            config.method,
            "'rk4' with a wrench, payload step, sensor noise, delay, joint stops or a scene",
        )
    if controller.update_period() is not None:
        raise InvalidParameterError(
            "method", config.method, f"'rk4' for '{controller.name}', a law that replans (its state jumps)"
        )
    friction = plant.friction
    if friction is not None and friction.smoothing == 0 and any(friction.coulomb):
        raise InvalidParameterError(
            "friction.smoothing", 0.0, "> 0 rad/s with the adaptive-step method (exact sgn stalls it)"
        )
    return integrate_adaptive(controller, plant, trajectory, config, q0[None], v0[None], z0)


def _single_result(
    controller: Controller, plant: Plant, trajectory: Trajectory, config: SimulationConfig, samples: Samples
) -> SimulationResult:
    """The run's ``samples`` (N = 1) as a :class:`SimulationResult` (:func:`run_result`)."""
    rows: dict[str, np.ndarray | None] = {"t": samples.t}
    for name in SAMPLED:
        x = getattr(samples, name)
        rows[name] = None if x is None else x[:, 0]
    return run_result(controller, plant, trajectory, config, rows)


SAMPLED = (
    "q", "v", "tau_command", "q_des", "v_des", "a_des", "z", "q_measured", "v_measured",
    "wrench", "penetration", "wrench_measured",
)  # fmt: skip
"""The per-sample rows of one run :func:`run_result` reads (besides ``t``), each (K, ·)."""


def contact_rows(plant: Plant, trajectory: Trajectory, t: np.ndarray) -> dict[str, np.ndarray | None]:
    """A run's contact fields of :class:`SimulationResult` that are not samples of the engine: the
    force reference at the sample times ``t`` [s] and the normal the force is measured along."""
    scene, reference = plant.scene, trajectory.force_reference
    if scene is None:
        return {"force_des": None, "contact_normal": None}
    surface = scene.surfaces[scene.index(reference.surface) if reference is not None else 0]
    force = None if reference is None else readonly(reference.sample(t))
    return {"force_des": force, "contact_normal": readonly(surface.unit_normal)}


def run_result(
    controller: Controller,
    plant: Plant,
    trajectory: Trajectory,
    config: SimulationConfig,
    rows: Mapping[str, np.ndarray | None],
) -> SimulationResult:
    """One run's rows (``t`` and :data:`SAMPLED`, each (K, ·) from sample 0; the measured ones
    may be absent or None) of ``simulate(controller, plant, trajectory, config)`` as its
    :class:`SimulationResult`: the applied torque, the law's estimates picked out of its state,
    read-only arrays. ``simulate`` makes its result so, and so does a run cut short (``tune``'s
    finished periods of a run in flight)."""
    tau_command = np.asarray(rows["tau_command"])
    z = np.asarray(rows["z"])
    estimates = controller.state_size > 0 and controller.estimates
    true = estimated_truth(controller, plant)
    names, units = state_labels(controller, z.shape[1])
    columns = controller.estimate_columns if estimates else None
    p_hat = None if columns is None else (z if len(columns) == z.shape[1] else z[:, columns])
    limits = plant.joint_limits
    measured = [rows.get(name) for name in ("q_measured", "v_measured")]
    relaxed = controller.run_relaxations(0) if hasattr(controller, "run_relaxations") else None
    return SimulationResult(
        controller=controller.name,
        method=config.method,
        dt=config.duration / config.steps,
        t=readonly(np.asarray(rows["t"])),
        q=readonly(np.asarray(rows["q"])),
        v=readonly(np.asarray(rows["v"])),
        tau_command=readonly(tau_command),
        tau=readonly(plant.applied_torque(tau_command)),
        q_des=readonly(np.asarray(rows["q_des"])),
        v_des=readonly(np.asarray(rows["v_des"])),
        a_des=readonly(np.asarray(rows["a_des"])),
        torque_limits=readonly(plant.limits),
        saturate=plant.saturate,
        reference_period=trajectory.period,
        p_hat=readonly(p_hat) if p_hat is not None else None,
        p_true=readonly_or_none(true) if estimates else None,
        parameter_names=controller.parameter_names if estimates else (),
        control_period=None
        if config.hold_steps is None
        else config.hold_steps * config.duration / config.steps,
        parameter_units=controller.parameter_units if estimates else (),
        parameter_kinds=controller.parameter_kinds if estimates else (),
        robot=plant.robot.name,
        state=readonly(z) if z.shape[1] else None,
        state_names=names,
        state_units=units,
        q_measured=None if measured[0] is None else readonly(np.asarray(measured[0])),
        v_measured=None if measured[1] is None else readonly(np.asarray(measured[1])),
        position_limits=readonly(np.stack([limits.position_lower, limits.position_upper])),
        velocity_limits=readonly(limits.velocity),
        joint_names=limits.joint_names,
        position_stops=plant.position_stops,
        **{name: readonly_or_none(rows.get(name)) for name in ("wrench", "penetration", "wrench_measured")},
        **contact_rows(plant, trajectory, np.asarray(rows["t"])),
        relaxed_first_time=None if relaxed is None else readonly(relaxed.first_time),
        relaxed_largest=None if relaxed is None else readonly(relaxed.largest),
        relaxed_span=None if relaxed is None else readonly(np.array([relaxed.instants, relaxed.last_time])),
    )
