"""Closed-loop simulation: a controller driving the plant along a reference trajectory.

Two integrators over the state ``x = (q, q̇, z)`` (``z``: the controller's state):

* ``"rk4"`` (default): classical fixed-step Runge–Kutta 4, the control law evaluated at
  every stage, the reference precomputed on the half-step grid. Exact ``sgn`` friction
  is fine here.
* ``"adaptive"``: scipy ``solve_ivp`` (DOP853, tolerances in the config), output on the
  same grid. Coulomb friction must then use a smooth sign (``Friction.smoothing > 0``):
  an exact ``sgn`` makes the step size collapse when a joint sticks.

A run whose state becomes non-finite or exceeds :data:`DIVERGENCE_LIMIT` stops with
:class:`~twolink_pin.errors.SimulationDivergedError` naming the controller and the time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from twolink_pin.controllers.base import Controller
from twolink_pin.errors import InvalidParameterError, SimulationDivergedError
from twolink_pin.plant import Plant
from twolink_pin.trajectory import JointTrajectory

DIVERGENCE_LIMIT = 1.0e4
"""Largest |q| [rad], |q̇| [rad/s] or |z| accepted before a run is declared diverged."""
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
    """

    duration: float = 30.0
    dt: float = 1.0e-3
    method: str = "rk4"
    q0_offset: tuple[float, ...] = (0.1, -0.1)
    v0_offset: tuple[float, ...] | None = None
    rtol: float = 1.0e-9
    atol: float = 1.0e-11

    def __post_init__(self) -> None:
        for name, unit in (("duration", "s"), ("dt", "s"), ("rtol", ""), ("atol", "")):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
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

    @property
    def steps(self) -> int:
        """Number of steps ``round(duration / dt)``."""
        return max(1, round(self.duration / self.dt))


def _readonly(array: np.ndarray | None) -> np.ndarray | None:
    if array is None:
        return None
    array = np.array(array, dtype=float)
    array.setflags(write=False)
    return array


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
        q, v, z, tau_cmd, ref = _rk4(controller, plant, trajectory, q0, v0, z0, dt, n)
    else:
        if plant.friction is not None and plant.friction.smoothing == 0 and any(plant.friction.coulomb):
            raise InvalidParameterError(
                "friction.smoothing", 0.0, "> 0 rad/s with the adaptive-step method (exact sgn stalls it)"
            )
        q, v, z, tau_cmd, ref = _adaptive(controller, plant, trajectory, q0, v0, z0, t, config)
    p_hat = z if z.shape[1] else None
    true = controller.true_parameters()
    return SimulationResult(
        controller=controller.name,
        method=config.method,
        dt=dt,
        t=_readonly(t),
        q=_readonly(q),
        v=_readonly(v),
        tau_command=_readonly(tau_cmd),
        tau=_readonly(np.array([plant.applied_torque(x) for x in tau_cmd]) if plant.saturate else tau_cmd),
        q_des=_readonly(ref.q),
        v_des=_readonly(ref.v),
        a_des=_readonly(ref.a),
        torque_limits=_readonly(plant.limits),
        saturate=plant.saturate,
        reference_period=trajectory.period,
        p_hat=_readonly(p_hat),
        p_true=_readonly(true) if p_hat is not None else None,
        parameter_names=controller.parameter_names if p_hat is not None else (),
    )


def _rk4(controller, plant, trajectory, q, v, z, dt, n):  # type: ignore[no-untyped-def]  # internal
    half = trajectory.sample(np.arange(2 * n + 1) * (dt / 2))
    rq, rv, ra = half.q, half.v, half.a
    nv, nz = q.shape[0], z.shape[0]
    Q, V = np.empty((n + 1, nv)), np.empty((n + 1, nv))
    Z, T = np.empty((n + 1, nz)), np.empty((n + 1, nv))
    law, accel, name = controller.compute, plant.acceleration, controller.name
    h, h2, h6 = dt, dt / 2, dt / 6
    for k in range(n):
        i = 2 * k
        tau1, dz1 = law(q, v, rq[i], rv[i], ra[i], z)
        a1 = accel(q, v, tau1)
        Q[k], V[k], Z[k], T[k] = q, v, z, tau1
        q2, v2, z2 = q + h2 * v, v + h2 * a1, z + h2 * dz1
        tau2, dz2 = law(q2, v2, rq[i + 1], rv[i + 1], ra[i + 1], z2)
        a2 = accel(q2, v2, tau2)
        q3, v3, z3 = q + h2 * v2, v + h2 * a2, z + h2 * dz2
        tau3, dz3 = law(q3, v3, rq[i + 1], rv[i + 1], ra[i + 1], z3)
        a3 = accel(q3, v3, tau3)
        q4, v4, z4 = q + h * v3, v + h * a3, z + h * dz3
        tau4, dz4 = law(q4, v4, rq[i + 2], rv[i + 2], ra[i + 2], z4)
        a4 = accel(q4, v4, tau4)
        q = q + h6 * (v + 2 * (v2 + v3) + v4)
        v = v + h6 * (a1 + 2 * (a2 + a3) + a4)
        z = z + h6 * (dz1 + 2 * (dz2 + dz3) + dz4)
        _check_state(name, (k + 1) * dt, q, v, z)
    tau_end, _ = law(q, v, rq[2 * n], rv[2 * n], ra[2 * n], z)
    Q[n], V[n], Z[n], T[n] = q, v, z, tau_end
    grid = trajectory.sample(np.arange(n + 1) * dt)
    return Q, V, Z, T, grid


def _adaptive(controller, plant, trajectory, q0, v0, z0, t, config):  # type: ignore[no-untyped-def]  # internal
    nv = q0.shape[0]
    law, accel, name = controller.compute, plant.acceleration, controller.name

    def rhs(time: float, x: np.ndarray) -> np.ndarray:
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
