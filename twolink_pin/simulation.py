"""Closed-loop simulation: a controller driving the plant along a reference trajectory.

Two integrators over the state ``x = (q, q̇, z)`` (``z``: the controller's state):

* ``"rk4"`` (default): classical fixed-step Runge–Kutta 4, the control law evaluated at
  every stage, the reference precomputed on the half-step grid. Exact ``sgn`` friction
  is fine here.

  With ``control_period`` set, the law is sampled instead (what a digital controller
  does): evaluated once every ``control_period`` (a whole number of steps) at the state
  of that instant, and its output — the torque τ and the controller state's derivative
  ż — held constant (zero-order hold) until the next sample. RK4 then integrates the
  plant under the held torque, and ``z`` grows linearly, ``z ← z + dt ż`` per step. The
  per-stage law is the continuous-time controller; the held law differs from it by
  O(control_period).
* ``"adaptive"``: scipy ``solve_ivp`` (DOP853, tolerances in the config), output on the
  same grid. Coulomb friction must then use a smooth sign (``Friction.smoothing > 0``):
  an exact ``sgn`` makes the step size collapse when a joint sticks.

For the controllers that provide :meth:`~twolink_pin.controllers.Controller.stage_kernel`
(the five laws) and the standard :class:`~twolink_pin.plant.Plant`, the RK4 loop runs as
generated Python on floats: the law's and the plant's statements inlined, Pinocchio called
with preallocated buffers (RNEA / regressor for the law, ABA for the plant), no numpy
temporaries per stage. Other controllers run the same scheme through
:meth:`~twolink_pin.controllers.Controller.compute`. Both give the same result to rounding.

A run whose state becomes non-finite or exceeds :data:`DIVERGENCE_LIMIT` stops with
:class:`~twolink_pin.errors.SimulationDivergedError` naming the controller and the time.
"""

from __future__ import annotations

import functools
import math
import re
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin
from scipy.integrate import solve_ivp

from twolink_pin.arrays import readonly, readonly_or_none
from twolink_pin.controllers.base import Controller, data_view
from twolink_pin.dynamics import ABA_CONVENTION
from twolink_pin.errors import InvalidParameterError, SimulationDivergedError
from twolink_pin.plant import Plant
from twolink_pin.trajectory import JointTrajectory, TrajectorySample

DIVERGENCE_LIMIT = 1.0e4
"""Largest |q| [rad], |q̇| [rad/s] or |z| accepted before a run is declared diverged."""
MAX_EVALUATIONS_PER_STEP = 200
"""Adaptive method: right-hand-side evaluations allowed per output interval before the
run is declared diverged (DOP853 needs about 12 per accepted step)."""
MAX_STEPS = 50_000_000
"""Cap on the number of fixed steps (duration / dt)."""


@dataclass(frozen=True)
class SimulationConfig:
    """Settings of one run (defaults: the report's 30-s runs).

    Attributes:
        duration: Simulated time [s], > 0.
        dt: Step of RK4 and spacing of the output grid [s], > 0.
        method: ``"rk4"`` (fixed step) or ``"adaptive"`` (scipy ``solve_ivp``).
        q0_offset: ``q(0) − q_d(0)`` [rad], one per joint (the report does not state its
            initial state; we take (0.1, −0.1)).
        v0_offset: ``q̇(0) − q̇_d(0)`` [rad/s], one per joint; ``None`` means zeros.
        rtol: Relative tolerance of the adaptive method.
        atol: Absolute tolerance of the adaptive method.
        control_period: Sampling period of the law [s], a whole multiple of ``dt``
            (``rk4`` only): τ and ż held over each period. ``None`` (default): the law
            is evaluated at every RK4 stage.
    """

    duration: float = 30.0
    dt: float = 1.0e-3
    method: str = "rk4"
    q0_offset: tuple[float, ...] = (0.1, -0.1)
    v0_offset: tuple[float, ...] | None = None
    rtol: float = 1.0e-9
    atol: float = 1.0e-11
    control_period: float | None = None

    def __post_init__(self) -> None:
        for name, unit in (("duration", "s"), ("dt", "s"), ("rtol", ""), ("atol", "")):
            value = getattr(self, name)
            if not (
                isinstance(value, (int, float))
                and not isinstance(value, bool)
                and math.isfinite(value)
                and value > 0
            ):
                raise InvalidParameterError(name, value, f"a finite value > 0 {unit}".rstrip())
        if self.dt > self.duration:
            raise InvalidParameterError("dt", self.dt, f"a step <= duration ({self.duration} s)")
        if self.duration / self.dt > MAX_STEPS:
            raise InvalidParameterError(
                "dt",
                self.dt,
                f"at most {MAX_STEPS} steps over {self.duration} s (dt >= {self.duration / MAX_STEPS:g} s)",
            )
        if self.method not in ("rk4", "adaptive"):
            raise InvalidParameterError("method", self.method, "'rk4' or 'adaptive'")
        for name in ("q0_offset", "v0_offset"):
            value = getattr(self, name)
            if value is not None and not all(math.isfinite(x) for x in value):
                raise InvalidParameterError(name, value, "finite offsets")
        period = self.control_period
        if period is not None:
            if self.method != "rk4":
                raise InvalidParameterError(
                    "control_period", period, "None with the adaptive method (sampled-data needs 'rk4')"
                )
            if not (isinstance(period, (int, float)) and math.isfinite(period) and period > 0):
                raise InvalidParameterError("control_period", period, "a finite value > 0 s")
            ratio = period / self.dt
            if round(ratio) < 1 or abs(ratio - round(ratio)) > 1e-9 * ratio or period > self.duration:
                raise InvalidParameterError(
                    "control_period",
                    period,
                    f"a whole multiple of dt = {self.dt:g} s, at most the duration {self.duration:g} s",
                )

    @property
    def hold_steps(self) -> int | None:
        """Steps per control period ``round(control_period / dt)``, or None (per-stage law)."""
        return None if self.control_period is None else round(self.control_period / self.dt)

    @property
    def steps(self) -> int:
        """Number of steps ``round(duration / dt)``."""
        return max(1, round(self.duration / self.dt))


@dataclass(frozen=True)
class SimulationResult:
    """One closed-loop run. Arrays are read-only; N = number of output samples."""

    controller: str
    """Controller's registry name."""
    method: str
    """Integrator: ``"rk4"`` or ``"adaptive"``."""
    dt: float
    """Output grid spacing (and RK4 step) [s]."""
    t: np.ndarray = field(repr=False)
    """Time [s], shape (N,)."""
    q: np.ndarray = field(repr=False)
    """Joint positions [rad], shape (N, nv)."""
    v: np.ndarray = field(repr=False)
    """Joint velocities [rad/s], shape (N, nv)."""
    tau_command: np.ndarray = field(repr=False)
    """Torque the controller asked for [N·m], shape (N, nv)."""
    tau: np.ndarray = field(repr=False)
    """Torque applied to the arm (saturated if ``saturate``) [N·m], shape (N, nv)."""
    q_des: np.ndarray = field(repr=False)
    """Reference positions [rad], shape (N, nv)."""
    v_des: np.ndarray = field(repr=False)
    """Reference velocities [rad/s], shape (N, nv)."""
    a_des: np.ndarray = field(repr=False)
    """Reference accelerations [rad/s²], shape (N, nv)."""
    torque_limits: np.ndarray = field(repr=False)
    """Motor limits [N·m], shape (nv,)."""
    saturate: bool
    """Whether the plant clipped torques to the limits."""
    reference_period: float
    """Period of the reference trajectory [s]."""
    p_hat: np.ndarray | None = field(repr=False, default=None)
    """Parameter estimates, shape (N, n_p), for adaptive controllers; else None."""
    p_true: np.ndarray | None = field(repr=False, default=None)
    """True values of the estimated parameters, shape (n_p,), or None."""
    parameter_names: tuple[str, ...] = ()
    """Names of the estimated parameters."""
    control_period: float | None = None
    """Sampling period of the held law [s], or None if the law ran at every RK4 stage."""

    @property
    def duration(self) -> float:
        """Simulated time [s]."""
        return float(self.t[-1] - self.t[0])

    @property
    def e(self) -> np.ndarray:
        """Position error ``q − q_d`` [rad], shape (N, nv)."""
        return self.q - self.q_des

    @property
    def edot(self) -> np.ndarray:
        """Velocity error ``q̇ − q̇_d`` [rad/s], shape (N, nv)."""
        return self.v - self.v_des

    @property
    def p_error(self) -> np.ndarray | None:
        """``p̂ − p`` over time, shape (N, n_p), or None."""
        return None if self.p_hat is None or self.p_true is None else self.p_hat - self.p_true

    @property
    def limit_excess(self) -> np.ndarray:
        """Largest ``|τ_command| − limit`` per joint [N·m], 0 where never exceeded."""
        return np.maximum(np.abs(self.tau_command) - self.torque_limits, 0.0).max(axis=0)

    @property
    def limit_exceeded(self) -> np.ndarray:
        """Whether the commanded torque ever exceeded each joint's limit, shape (nv,)."""
        return self.limit_excess > 0

    @property
    def first_exceeded_at(self) -> list[float | None]:
        """First time [s] each joint's commanded torque exceeded its limit, or None."""
        over = np.abs(self.tau_command) > self.torque_limits
        return [float(self.t[np.argmax(col)]) if col.any() else None for col in over.T]


def _check_state(controller: str, t: float, q: np.ndarray, v: np.ndarray, z: np.ndarray) -> None:
    worst = max(np.abs(q).max(), np.abs(v).max(), np.abs(z).max() if z.size else 0.0)
    if not worst < DIVERGENCE_LIMIT:  # also catches NaN
        what = (
            "non-finite state"
            if not math.isfinite(worst)
            else f"|state| = {worst:.3g} > {DIVERGENCE_LIMIT:g}"
        )
        raise SimulationDivergedError(controller, t, what)


def simulate(
    controller: Controller,
    plant: Plant,
    trajectory: JointTrajectory,
    config: SimulationConfig | None = None,
) -> SimulationResult:
    """Run ``controller`` on ``plant`` tracking ``trajectory``.

    Raises:
        InvalidParameterError: offsets of the wrong length, or exact-sign friction with
            the adaptive method.
        SimulationDivergedError: the state became non-finite or absurd.
    """
    config = config if config is not None else SimulationConfig()
    nv = plant.robot.nv
    if trajectory.nv != nv:
        raise InvalidParameterError(
            "trajectory", f"nv = {trajectory.nv}", f"a trajectory for nv = {nv} joints"
        )
    for name in ("q0_offset", "v0_offset"):
        value = getattr(config, name)
        if value is not None and len(value) != nv:
            raise InvalidParameterError(name, value, f"{nv} values, one per joint")
    n = config.steps
    dt = config.duration / n
    t = np.arange(n + 1) * dt
    ref0 = trajectory.sample(0.0)
    q0 = ref0.q + np.asarray(config.q0_offset, dtype=float)
    v0 = ref0.v + (np.zeros(nv) if config.v0_offset is None else np.asarray(config.v0_offset, dtype=float))
    z0 = np.array(controller.initial_state(), dtype=float)
    if config.method == "rk4":
        hold = config.hold_steps
        fast = _fast_rk4(controller, plant, trajectory, q0, v0, z0, dt, n, hold)
        if fast is None:
            fast = _rk4(controller, plant, trajectory, q0, v0, z0, dt, n, hold)
        q, v, z, tau_cmd, ref = fast
    else:
        if plant.friction is not None and plant.friction.smoothing == 0 and any(plant.friction.coulomb):
            raise InvalidParameterError(
                "friction.smoothing", 0.0, "> 0 rad/s with the adaptive-step method (exact sgn stalls it)"
            )
        q, v, z, tau_cmd, ref = _adaptive(controller, plant, trajectory, q0, v0, z0, t, config)
    p_hat = z if z.shape[1] else None
    true = controller.parameters_of(plant.robot, plant.friction)
    return SimulationResult(
        controller=controller.name,
        method=config.method,
        dt=dt,
        t=readonly(t),
        q=readonly(q),
        v=readonly(v),
        tau_command=readonly(tau_cmd),
        tau=readonly(np.array([plant.applied_torque(x) for x in tau_cmd]) if plant.saturate else tau_cmd),
        q_des=readonly(ref.q),
        v_des=readonly(ref.v),
        a_des=readonly(ref.a),
        torque_limits=readonly(plant.limits),
        saturate=plant.saturate,
        reference_period=trajectory.period,
        p_hat=readonly_or_none(p_hat),
        p_true=readonly_or_none(true) if p_hat is not None else None,
        parameter_names=controller.parameter_names if p_hat is not None else (),
        control_period=None if config.hold_steps is None else config.hold_steps * dt,
    )


def _rk4(controller, plant, trajectory, q, v, z, dt, n, hold=None):  # internal
    """RK4 through ``controller.compute``; ``hold``: steps per control period, or None."""
    half = trajectory.sample(np.arange(2 * n + 1) * (dt / 2))
    rq, rv, ra = half.q, half.v, half.a
    nv, nz = q.shape[0], z.shape[0]
    Q, V = np.empty((n + 1, nv)), np.empty((n + 1, nv))
    Z, T = np.empty((n + 1, nz)), np.empty((n + 1, nv))
    law, accel, name = controller.compute, plant.acceleration, controller.name
    h, h2, h6 = dt, dt / 2, dt / 6
    tau1 = dz1 = None
    for k in range(n):
        i = 2 * k
        if hold is None or k % hold == 0:
            tau1, dz1 = law(q, v, rq[i], rv[i], ra[i], z)
        a1 = accel(q, v, tau1)
        Q[k], V[k], Z[k], T[k] = q, v, z, tau1
        if hold is None:
            q2, v2, z2 = q + h2 * v, v + h2 * a1, z + h2 * dz1
            tau2, dz2 = law(q2, v2, rq[i + 1], rv[i + 1], ra[i + 1], z2)
            a2 = accel(q2, v2, tau2)
            q3, v3, z3 = q + h2 * v2, v + h2 * a2, z + h2 * dz2
            tau3, dz3 = law(q3, v3, rq[i + 1], rv[i + 1], ra[i + 1], z3)
            a3 = accel(q3, v3, tau3)
            q4, v4, z4 = q + h * v3, v + h * a3, z + h * dz3
            tau4, dz4 = law(q4, v4, rq[i + 2], rv[i + 2], ra[i + 2], z4)
            a4 = accel(q4, v4, tau4)
            z = z + h6 * (dz1 + 2 * (dz2 + dz3) + dz4)
        else:  # zero-order hold: τ and ż fixed over the step
            q2, v2 = q + h2 * v, v + h2 * a1
            a2 = accel(q2, v2, tau1)
            q3, v3 = q + h2 * v2, v + h2 * a2
            a3 = accel(q3, v3, tau1)
            q4, v4 = q + h * v3, v + h * a3
            a4 = accel(q4, v4, tau1)
            z = z + h * dz1
        q = q + h6 * (v + 2 * (v2 + v3) + v4)
        v = v + h6 * (a1 + 2 * (a2 + a3) + a4)
        _check_state(name, (k + 1) * dt, q, v, z)
    if hold is None or n % hold == 0:
        tau1, _ = law(q, v, rq[2 * n], rv[2 * n], ra[2 * n], z)
    Q[n], V[n], Z[n], T[n] = q, v, z, tau1
    grid = TrajectorySample(*(x[::2] for x in half))  # t_k = 2k · dt/2 exactly
    return Q, V, Z, T, grid


# -- the generated fast loop ---------------------------------------------------------------


def _plant_lines(plant: Plant, nv: int) -> tuple[list[str], list[str]]:
    """Statements of ``plant.acceleration`` on floats: (torque part, acceleration part).

    The torque part binds the applied torque for ``tau{j}`` (saturation ``p_u{j}``, then
    friction, which reads ``v{j}``, into ``p_f{j}``); the acceleration part writes ``q``, ``v``
    and the applied torque into ABA's input buffer in one ``struct.pack_into``, calls ABA and
    binds ``a{j}``.
    """
    torque: list[str] = []
    applied: list[str] = []
    for j in range(nv):
        expr = f"tau{j}"
        limit = float(plant.limits[j])
        if plant.saturate and math.isfinite(limit):
            lim = repr(limit)
            torque.append(f"p_u{j} = {lim} if tau{j} > {lim} else (-{lim} if tau{j} < -{lim} else tau{j})")
            expr = f"p_u{j}"
        friction = plant.friction
        if friction is not None:
            viscous, coulomb = repr(float(friction.viscous[j])), repr(float(friction.coulomb[j]))
            if friction.smoothing == 0:
                sign = f"((v{j} > 0.0) - (v{j} < 0.0))"
            else:
                sign = f"p_tanh(v{j} / {float(friction.smoothing)!r})"
            expr = f"{expr} - ({viscous} * v{j} + {coulomb} * {sign})"
        if expr.isidentifier():  # the command or its saturation: pack it, no copy per stage
            applied.append(expr)
        else:
            torque.append(f"p_f{j} = {expr}")
            applied.append(f"p_f{j}")
    values = [f"q{j}" for j in range(nv)] + [f"v{j}" for j in range(nv)] + applied
    accel = [f"p_pack(p_in, 0, {', '.join(values)})"]
    accel.append("p_aba(p_model, p_data, p_q, p_v, p_t, p_world)")  # result read from data.ddq
    accel += [f"a{j} = p_ddq[{j}]" for j in range(nv)]
    return torque, accel


_TEMPLATE_NAME = re.compile(r"\b(qd|vd|ad|tau|dz|q|v|z|a)(\d+)\b")


def _at_stage(lines: Sequence[str], stage: int, held: bool) -> list[str]:
    """``lines`` with the template names (``q0``, ``tau1``, ...) renamed for RK4 stage ``stage``.

    Stage 1 reads the step's state ``x_q{j}``, ``x_v{j}``, ``x_z{i}``; stage s > 1 its own
    ``q{s}_{j}``, ``v{s}_{j}``, ``z{s}_{i}``; the law's outputs become ``t{s}_{j}``, ``dz{s}_{i}``
    and the plant's ``a{s}_{j}`` — no copies between stages. With ``held`` every stage uses
    the torque of stage 1 (``t1_{j}``), held since the last sample.
    """

    def rename(match: re.Match[str]) -> str:
        kind, index = match.group(1), match.group(2)
        if kind in ("qd", "vd", "ad"):
            return match.group(0)
        if kind == "tau":
            return f"t{1 if held else stage}_{index}"
        if kind in ("dz", "a"):
            return f"{kind}{stage}_{index}"
        return f"x_{kind}{index}" if stage == 1 else f"{kind}{stage}_{index}"

    return [_TEMPLATE_NAME.sub(rename, line) for line in lines]


def _rk4_source(
    law: tuple[str, ...], plant: Plant, nv: int, nz: int, hold: int | None, names: tuple[str, ...]
) -> str:
    """Source of ``_run``: the RK4 loop with the law and the plant inlined (see module doc)."""
    J, I = range(nv), range(nz)  # noqa: E741  # joint and controller-state indices
    held = hold is not None
    torque, accel = _plant_lines(plant, nv)
    # With a held law and no friction the applied torque changes only at the samples.
    torque_at_sample = held and plant.friction is None
    out: list[str] = []

    def emit(indent: int, lines: Sequence[str]) -> None:
        out.extend("    " * indent + line for line in lines)

    def reference(index: str) -> list[str]:
        return [f"qd{j} = rq{j}[{index}]; vd{j} = rv{j}[{index}]; ad{j} = ra{j}[{index}]" for j in J]

    def law_at(stage: int) -> list[str]:
        lines = _at_stage(law, stage, held=False)
        return lines + (_at_stage(torque, 1, held=True) if torque_at_sample else [])

    def plant_at(stage: int) -> list[str]:
        return _at_stage(([] if torque_at_sample else torque) + accel, stage, held)

    def stage_state(stage: int, step: str, previous: int) -> list[str]:
        v_prev = "x_v" if previous == 1 else f"v{previous}_"
        lines = [
            f"q{stage}_{j} = x_q{j} + {step} * {v_prev}{j}; v{stage}_{j} = x_v{j} + {step} * a{previous}_{j}"
            for j in J
        ]
        if not held:
            lines += [f"z{stage}_{i} = x_z{i} + {step} * dz{previous}_{i}" for i in I]
        return lines

    # one output row per step: (q, v, τ_command, z), packed at byte offset o
    row = [f"x_q{j}" for j in J] + [f"x_v{j}" for j in J] + [f"t1_{j}" for j in J] + [f"x_z{i}" for i in I]
    records = [f"o_pack(outputs, o, {', '.join(row)})"]
    width = 8 * len(row)

    out.append("def _run(_ns, n, m, h, h2, h6, state, refs, outputs):")
    emit(1, [f"{name} = _ns[{name!r}]" for name in names])
    emit(1, [f"x_q{j}, x_v{j} = state[0][{j}], state[1][{j}]" for j in J])
    emit(1, [f"x_z{i} = state[2][{i}]" for i in I])
    emit(1, [f"rq{j}, rv{j}, ra{j} = refs[0][{j}], refs[1][{j}], refs[2][{j}]" for j in J])
    emit(1, ["o_pack = _ns['o_pack']"])
    if held:  # the held law's outputs exist before the first sample
        emit(1, [f"t1_{j} = 0.0" for j in J] + [f"dz1_{i} = 0.0" for i in I])
    else:  # stage 1 of step k reads the reference loaded by stage 4 of step k - 1
        emit(1, reference("0"))
    emit(1, ["for k in range(n):", f"    o = {width} * k"])
    if hold == 1:  # a sample at every step
        emit(2, reference("2 * k") + law_at(1))
    elif held:
        emit(2, ["if k % m == 0:"])
        emit(3, reference("2 * k") + law_at(1))
    else:
        emit(2, ["r = 2 * k", *law_at(1)])
    emit(2, records + plant_at(1))
    for stage, step, previous in ((2, "h2", 1), (3, "h2", 2), (4, "h", 3)):
        emit(2, stage_state(stage, step, previous))
        if not held:
            if stage in (2, 4):
                emit(2, reference("r + 1" if stage == 2 else "r + 2"))
            emit(2, law_at(stage))
        emit(2, plant_at(stage))
    emit(2, [f"x_q{j} = x_q{j} + h6 * (x_v{j} + 2 * (v2_{j} + v3_{j}) + v4_{j})" for j in J])
    emit(2, [f"x_v{j} = x_v{j} + h6 * (a1_{j} + 2 * (a2_{j} + a3_{j}) + a4_{j})" for j in J])
    if held:
        emit(2, [f"x_z{i} = x_z{i} + h * dz1_{i}" for i in I])
    else:
        emit(2, [f"x_z{i} = x_z{i} + h6 * (dz1_{i} + 2 * (dz2_{i} + dz3_{i}) + dz4_{i})" for i in I])
    inside = " and ".join(
        [f"-LIMIT < x_q{j} < LIMIT and -LIMIT < x_v{j} < LIMIT" for j in J]
        + [f"-LIMIT < x_z{i} < LIMIT" for i in I]
    )
    state = ", ".join([f"x_q{j}" for j in J] + [f"x_v{j}" for j in J] + [f"x_z{i}" for i in I])
    emit(2, [f"if not ({inside}):", f"    return k + 1, ({state},)"])
    # the last sample: the law at t_n (held: only if t_n is a sampling instant)
    if held:
        emit(1, ["if n % m == 0:"])
        emit(2, reference("2 * n") + law_at(1))
    else:
        emit(1, reference("2 * n") + law_at(1))
    emit(1, [f"o = {width} * n", *records, "return 0, None"])
    return "\n".join(out).replace("LIMIT", repr(DIVERGENCE_LIMIT)) + "\n"


def _floats(array: np.ndarray) -> memoryview:
    """A memoryview on a contiguous float64 array: item access gives Python floats, ~30 ns."""
    return memoryview(array)  # type: ignore[arg-type]  # numpy's stubs lack __buffer__ before 3.12


@functools.lru_cache(maxsize=64)
def _compile(source: str) -> Callable[..., Any]:
    namespace: dict[str, Any] = {}
    exec(compile(source, "<twolink_pin.simulation fast RK4>", "exec"), namespace)  # built by _rk4_source
    run: Callable[..., Any] = namespace["_run"]
    return run


def _fast_rk4(
    controller: Controller,
    plant: Plant,
    trajectory: JointTrajectory,
    q0: np.ndarray,
    v0: np.ndarray,
    z0: np.ndarray,
    dt: float,
    n: int,
    hold: int | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, TrajectorySample] | None:
    """The generated float loop, or None when the controller or plant has no kernel form."""
    if (
        type(plant).acceleration is not Plant.acceleration
        or type(plant).applied_torque is not Plant.applied_torque
    ):
        return None
    kernel = controller.stage_kernel()
    if kernel is None:
        return None
    nv, nz = q0.shape[0], z0.shape[0]
    if any(not key.startswith("c_") for key in kernel.namespace):
        raise AssertionError(f"kernel names must start with 'c_': {sorted(kernel.namespace)}")
    buffer = np.zeros(3 * nv)  # [q, v, τ]: ABA's inputs
    namespace = {
        **kernel.namespace,
        "p_q": buffer[:nv],
        "p_v": buffer[nv : 2 * nv],
        "p_t": buffer[2 * nv :],
        "p_in": _floats(buffer),
        "p_pack": struct.Struct(f"{3 * nv}d").pack_into,
        "p_model": plant.model,
        "p_data": plant.data,
        "p_aba": pin.aba,
        "p_world": ABA_CONVENTION,
        "p_ddq": data_view(plant.data.ddq),
        "p_tanh": math.tanh,
    }
    source = _rk4_source(kernel.lines, plant, nv, nz, hold, tuple(namespace))
    run = _compile(source)
    half = trajectory.sample(np.arange(2 * n + 1) * (dt / 2))
    # Read as floats through memoryviews: no list of 6 n Python floats to build.
    refs = tuple([_floats(np.ascontiguousarray(column)) for column in x.T] for x in (half.q, half.v, half.a))
    state = (q0.tolist(), v0.tolist(), z0.tolist())
    rows = np.empty((n + 1, 3 * nv + nz))  # per step (q, v, τ_command, z)
    namespace["o_pack"] = struct.Struct(f"{3 * nv + nz}d").pack_into
    status, last = run(namespace, n, hold or 1, dt, dt / 2, dt / 6, state, refs, _floats(rows.reshape(-1)))
    if status:
        _check_state(
            controller.name,
            status * dt,
            np.array(last[:nv]),
            np.array(last[nv : 2 * nv]),
            np.array(last[2 * nv :]),
        )
        raise AssertionError("the fast loop stopped on a state _check_state accepts")  # pragma: no cover
    Q, V, T, Z = rows[:, :nv], rows[:, nv : 2 * nv], rows[:, 2 * nv : 3 * nv], rows[:, 3 * nv :]
    grid = TrajectorySample(*(x[::2] for x in half))  # t_k = 2k · dt/2 exactly
    return Q, V, Z, T, grid


def _adaptive(controller, plant, trajectory, q0, v0, z0, t, config):  # internal
    nv = q0.shape[0]
    law, accel, name = controller.compute, plant.acceleration, controller.name

    budget = MAX_EVALUATIONS_PER_STEP * (len(t) - 1) + 10_000
    calls = 0

    def rhs(time: float, x: np.ndarray) -> np.ndarray:
        nonlocal calls
        calls += 1
        if calls > budget:  # a collapsing step size: stiff or diverging, never a hang
            raise SimulationDivergedError(
                name,
                time,
                f"the adaptive step collapsed ({budget} evaluations); the problem is too stiff for DOP853",
            )
        q, v, z = x[:nv], x[nv : 2 * nv], x[2 * nv :]
        _check_state(name, time, q, v, z)
        ref = trajectory.sample(time)
        tau, dz = law(q, v, ref.q, ref.v, ref.a, z)
        return np.concatenate([v, accel(q, v, tau), dz])

    sol = solve_ivp(
        rhs,
        (t[0], t[-1]),
        np.concatenate([q0, v0, z0]),
        method="DOP853",
        t_eval=t,
        rtol=config.rtol,
        atol=config.atol,
    )
    if sol.status != 0:
        raise SimulationDivergedError(name, float(sol.t[-1]) if sol.t.size else 0.0, sol.message)
    x = sol.y.T
    q, v, z = x[:, :nv], x[:, nv : 2 * nv], x[:, 2 * nv :]
    grid = trajectory.sample(t)
    tau = np.array([law(q[k], v[k], grid.q[k], grid.v[k], grid.a[k], z[k])[0] for k in range(len(t))])
    return q, v, z, tau, grid
