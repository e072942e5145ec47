"""The engine for a plant that pushes back (:mod:`twolink_pin.disturbances`): N runs, RK4.

:func:`~twolink_pin.simulation.engine.integrate` hands a plant with events here; a plant
without keeps the plain engine (and the course report's numbers). The same RK4 as the
engine, with per step k (``t_k = k dt``):

* the law's measurement ``(q, q̇) + noise_k`` (one noise sample per step and run, from
  the run's own generator, drawn block by block so that a run's noise does not depend on
  its batch);
* the plant: ``q̈ = ABA_k(q, q̇, sat(τ) − f(q̇) + J(q)ᵀ F_k)`` with ``ABA_k`` on the model
  with the payload from its step on, ``F_k`` the wrench if on during step k (``J`` the
  wrench frame's world-aligned Jacobian at each RK4 stage);
* without delay the law runs at every RK4 stage (or held, with a ``control_period``), as in
  the engine; with ``delay = d`` it is sampled (every step, or every control period) and
  step k applies the torque computed at the latest sample ``<= k − d`` (before the first
  such sample: the first torque computed); ``z`` advances by ``dt ż`` with the undelayed ż.

The recorded command is the torque applied. Divergence is detected and reported as in the
engine (per block; a diverged run of a batch is parked on the reference).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from twolink_pin.controllers import Controller, LawInput
from twolink_pin.errors import ControllerError, SimulationDivergedError, TwolinkPinError, raised_at
from twolink_pin.plant import Plant
from twolink_pin.simulation.config import SimulationConfig
from twolink_pin.simulation.containment import contained, read_only
from twolink_pin.simulation.forward import dynamics_for
from twolink_pin.simulation.rigid_terms import RigidBodyTerms
from twolink_pin.simulation.task_reference import task_reference
from twolink_pin.simulation.terms import terms_for
from twolink_pin.trajectory import Trajectory

if TYPE_CHECKING:  # the engine imports this module when a plant has events
    from twolink_pin.simulation.engine import EngineRun, Observer


def _payload_plant(plant: Plant) -> Plant:
    step = plant.payload_step
    assert step is not None
    robot = plant.robot
    model = step.model(robot.model, robot.ee_frame_id)
    heavier = Plant.__new__(Plant)
    heavier.__dict__.update(plant.__dict__)
    heavier.model = model
    return heavier


def integrate_events(
    controller: Controller,
    plant: Plant,
    trajectory: Trajectory,
    config: SimulationConfig,
    q0: np.ndarray,
    v0: np.ndarray,
    z0: np.ndarray,
    *,
    record: bool,
    observer: Observer | None = None,
    threads: int | None = None,
    stop_on_divergence: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> EngineRun:
    """:func:`~twolink_pin.simulation.engine.integrate` for a plant with events (same
    arguments, same :class:`~twolink_pin.simulation.engine.EngineRun`)."""
    from twolink_pin.simulation.engine import (
        BLOCK,
        EngineRun,
        Samples,
        _bad_rows,
        _flag_block,
        _state_detail,
        _validate,
    )

    runs, nv = q0.shape
    nz = z0.shape[1]
    name = controller.name
    terms = terms_for(controller, runs, threads)
    before = dynamics_for(plant, runs, threads)
    after = dynamics_for(_payload_plant(plant), runs, threads) if plant.payload_step is not None else None
    wrench = plant.wrench
    kinematics = RigidBodyTerms(plant.robot, None) if wrench is not None else None
    force = None if wrench is None else wrench.forces(runs)
    noise = plant.sensor_noise
    generators = noise.generators(runs) if noise is not None else []
    delay = plant.delay
    n = config.steps
    dt = config.duration / n
    hold = config.hold_steps
    sampled = hold is not None or delay > 0
    hold = hold if hold is not None else 1
    total = n + 1
    size = total if record else min(total, BLOCK)
    Q, V, T = (np.empty((size, runs, nv)) for _ in range(3))
    Z = np.empty((size, runs, nz))
    RQ, RV, RA = (np.empty((size, 1, nv)) for _ in range(3))
    times = np.arange(total) * dt
    diverged_at = np.full(runs, np.nan)
    detail: list[str | None] = [None] * runs
    alive = np.ones(runs, dtype=bool)
    z_start = np.array(z0, dtype=float)
    q, v, z = np.array(q0, dtype=float), np.array(v0, dtype=float), z_start.copy()
    no_state = np.zeros((runs, 0))
    outputs: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # sample step -> (τ, ż)
    first_tau: np.ndarray | None = None
    first = True
    now = 0.0

    compute = contained(controller)  # the engine's one door: read-only inputs, sys.exit named

    def law(t: float, q: np.ndarray, v: np.ndarray, z: np.ndarray, i: int) -> tuple[np.ndarray, np.ndarray]:
        nonlocal first, now
        now = t
        x = LawInput(t, q + noise_q, v + noise_v, z, rq[i], rv[i], ra[i], px[i], pr[i], pw[i], pa[i])
        out = compute(x, terms)
        if first:
            _validate(controller, out, runs, nv, nz, t)
            first = False
        return out.tau, (out.dz if nz and out.dz is not None else no_state)

    def accel(k: int, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        t = k * dt
        dynamics = after if after is not None and t >= plant.payload_step.time else before  # type: ignore[union-attr]
        if wrench is not None and wrench.active(t):
            assert kinematics is not None and force is not None
            J = kinematics.frame(q, np.zeros_like(v), wrench.frame).jacobian
            tau = tau + np.vecmat(np.broadcast_to(force, (J.shape[0], 6)), J)
        return dynamics(q, v, tau).copy()

    noise_q = noise_v = np.zeros((1, nv))
    with np.errstate(all="ignore"):
        for k0 in range(0, total, BLOCK):
            k1 = min(k0 + BLOCK, total)
            last_half = min(2 * k1, 2 * n)
            half_t = np.arange(2 * k0, last_half + 1) * (dt / 2)
            half = trajectory.sample(half_t)
            rq, rv, ra = (read_only(x[:, None, :]) for x in (half.q, half.v, half.a))  # shared: read-only
            px, pr, pw, pa = task_reference(controller, trajectory, half_t, half)  # None unless task-space
            if noise is not None:
                draws = np.stack([g.standard_normal((k1 - k0, 2 * nv)) for g in generators], axis=1)
                block_q, block_v = noise.sigma_q * draws[..., :nv], noise.sigma_v * draws[..., nv:]
            off = 0 if record else k0
            filled = k0 - off
            try:
                for k in range(k0, k1):
                    i = 2 * (k - k0)
                    t = k * dt
                    if noise is not None:
                        noise_q, noise_v = block_q[k - k0], block_v[k - k0]
                    if sampled:
                        if k % hold == 0:
                            outputs[k] = law(t, q, v, z, i)
                            if first_tau is None:
                                first_tau = outputs[k][0]
                        sample = max((s for s in outputs if s <= k - delay), default=None)
                        for s in [s for s in outputs if sample is not None and s < sample]:
                            del outputs[s]
                        current = max(s for s in outputs if s <= k)
                        dz = outputs[current][1]
                        assert first_tau is not None
                        tau = first_tau if sample is None else outputs[sample][0]
                    else:
                        tau, dz = law(t, q, v, z, i)
                    b = k - off
                    Q[b], V[b], T[b] = q, v, tau
                    if nz:
                        Z[b] = z
                    filled = b + 1
                    if k == n:
                        break
                    a1 = accel(k, q, v, tau)
                    if not sampled:
                        q2, v2 = q + dt / 2 * v, v + dt / 2 * a1
                        tau2, dz2 = law(t + dt / 2, q2, v2, z + dt / 2 * dz, i + 1)
                        a2 = accel(k, q2, v2, tau2)
                        q3, v3 = q + dt / 2 * v2, v + dt / 2 * a2
                        tau3, dz3 = law(t + dt / 2, q3, v3, z + dt / 2 * dz2, i + 1)
                        a3 = accel(k, q3, v3, tau3)
                        q4, v4 = q + dt * v3, v + dt * a3
                        tau4, dz4 = law(t + dt, q4, v4, z + dt * dz3, i + 2)
                        a4 = accel(k, q4, v4, tau4)
                        if nz:
                            z = z + dt / 6 * (dz + 2 * (dz2 + dz3) + dz4)
                    else:
                        q2, v2 = q + dt / 2 * v, v + dt / 2 * a1
                        a2 = accel(k, q2, v2, tau)
                        q3, v3 = q + dt / 2 * v2, v + dt / 2 * a2
                        a3 = accel(k, q3, v3, tau)
                        q4, v4 = q + dt * v3, v + dt * a3
                        a4 = accel(k, q4, v4, tau)
                        if nz:
                            z = z + dt * dz
                    q = q + dt / 6 * (v + 2 * (v2 + v3) + v4)
                    v = v + dt / 6 * (a1 + 2 * (a2 + a3) + a4)
            except (KeyboardInterrupt, SystemExit, MemoryError):
                raise
            except (SimulationDivergedError, ControllerError):
                raise
            except Exception as exc:
                _flag_block(Q, V, Z, T, k0 - off, filled, times, off, alive, diverged_at, detail, name, True)
                what = str(exc) if isinstance(exc, TwolinkPinError) else f"{type(exc).__name__}: {exc}"
                raise ControllerError(name, now, what + raised_at(exc, controller)) from exc
            rows = slice(k0 - off, k1 - off)
            RQ[rows], RV[rows], RA[rows] = (x[: 2 * (k1 - k0) : 2] for x in (rq, rv, ra))
            newly = _flag_block(
                Q,
                V,
                Z,
                T,
                k0 - off,
                k1 - off,
                times,
                off,
                alive,
                diverged_at,
                detail,
                name,
                stop_on_divergence,
            )
            if k1 <= n:
                current_bad = _bad_rows(q[None])[0] | _bad_rows(v[None])[0] | _bad_rows(z[None])[0]
                late = alive & current_bad
                if late.any():
                    if stop_on_divergence:
                        raise SimulationDivergedError(name, k1 * dt, _state_detail(q, v, z, late))
                    for r in np.flatnonzero(late):
                        diverged_at[r] = k1 * dt
                        detail[r] = _state_detail(q, v, z, np.eye(runs, dtype=bool)[r])
                    alive &= ~late
                    newly |= late
                if newly.any():
                    j = 2 * (k1 - k0)
                    q[newly], v[newly], z[newly] = rq[j][0], rv[j][0], z_start[newly]
            if observer is not None:
                observer.add(
                    Samples(
                        k0, times[k0:k1], Q[rows], V[rows], Z[rows], T[rows], RQ[rows], RV[rows], RA[rows]
                    )
                )
            if progress is not None:
                progress(min(k1, n), n)
    recorded = Samples(0, times, Q, V, Z, T, RQ, RV, RA) if record else None
    return EngineRun(times, recorded, z, diverged_at, tuple(detail))
