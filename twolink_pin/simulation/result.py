"""One closed-loop run, recorded: :class:`SimulationResult` (read-only arrays with units)."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from twolink_pin.controllers.relaxation import RunRelaxation
from twolink_pin.limits import Crossings, JointLimits, Motion, motion_crossings


@dataclass(frozen=True)
class SimulationResult:
    """One closed-loop run. Arrays are read-only; K = number of output samples."""

    controller: str
    """Controller's registry name."""
    method: str
    """Integrator: ``"rk4"`` or ``"adaptive"``."""
    dt: float
    """Output grid spacing (and RK4 step) [s]."""
    t: np.ndarray = field(repr=False)
    """Time [s], shape (K,)."""
    q: np.ndarray = field(repr=False)
    """Joint positions [rad], shape (K, nv)."""
    v: np.ndarray = field(repr=False)
    """Joint velocities [rad/s], shape (K, nv)."""
    tau_command: np.ndarray = field(repr=False)
    """Torque the controller asked for [N·m], shape (K, nv)."""
    tau: np.ndarray = field(repr=False)
    """Torque applied to the arm (saturated if ``saturate``) [N·m], shape (K, nv)."""
    q_des: np.ndarray = field(repr=False)
    """Reference positions [rad], shape (K, nv)."""
    v_des: np.ndarray = field(repr=False)
    """Reference velocities [rad/s], shape (K, nv)."""
    a_des: np.ndarray = field(repr=False)
    """Reference accelerations [rad/s²], shape (K, nv)."""
    torque_limits: np.ndarray = field(repr=False)
    """Motor limits [N·m], shape (nv,); inf where the model has none."""
    saturate: bool
    """Whether the plant clipped torques to the limits."""
    reference_period: float
    """Period of the reference trajectory [s]."""
    p_hat: np.ndarray | None = field(repr=False, default=None)
    """Parameter estimates, shape (K, n_p), for laws that estimate parameters; else None."""
    p_true: np.ndarray | None = field(repr=False, default=None)
    """The plant's values of the estimated parameters, shape (n_p,), or None."""
    parameter_names: tuple[str, ...] = ()
    """Names of the estimated parameters."""
    control_period: float | None = None
    """Sampling period of the held law [s], or None if the law ran at every RK4 stage."""
    parameter_units: tuple[str, ...] = ()
    """SI unit of each estimated parameter."""
    parameter_kinds: tuple[str, ...] = ()
    """``"inertial"`` or ``"friction"`` for each estimated parameter."""
    robot: str = ""
    """Name of the robot simulated."""
    state: np.ndarray | None = field(repr=False, default=None)
    """The law's whole internal state ``z`` (estimates, integrators, filters …), shape
    (K, nz), for a law with state; else None."""
    state_names: tuple[str, ...] = ()
    """Name of each entry of ``state``."""
    state_units: tuple[str, ...] = ()
    """SI unit of each entry of ``state``."""
    q_measured: np.ndarray | None = field(repr=False, default=None)
    """Joint positions the law measured [rad], shape (K, nv): ``q`` plus the sensor noise of
    each step (a delay shifts the torque, not the measurement); None without sensor noise,
    where the law measures ``q``. A saved run keeps it, so that it reads as a real log."""
    v_measured: np.ndarray | None = field(repr=False, default=None)
    """Joint velocities the law measured [rad/s], as ``q_measured``."""
    position_limits: np.ndarray | None = field(repr=False, default=None)
    """Each joint's position range [rad], shape (2, nv): lower, upper (``∓inf``: none); None
    in a result saved before it was recorded (no position crossings then)."""
    velocity_limits: np.ndarray | None = field(repr=False, default=None)
    """Each joint's velocity limit [rad/s], shape (nv,) (``inf``: none); None as above."""
    joint_names: tuple[str, ...] = ()
    """The joints, in the order of ``q`` (empty in an older saved result)."""
    position_stops: bool = False
    """Whether the plant made each position range a hard stop (``--joint-stops``)."""
    wrench: np.ndarray | None = field(repr=False, default=None)
    """The contact wrench the end effector applied to the surfaces [N; N·m], world axes, about
    its frame's origin, shape (K, 6); None without a scene (:mod:`twolink_pin.contact`)."""
    penetration: np.ndarray | None = field(repr=False, default=None)
    """The deepest penetration into a surface [m], shape (K,) (0 out of contact); None without
    a scene."""
    wrench_measured: np.ndarray | None = field(repr=False, default=None)
    """The wrench the law's force sensor read (``wrench`` + its noise) [N; N·m], shape (K, 6);
    None without force noise."""
    force_des: np.ndarray | None = field(repr=False, default=None)
    """The reference's desired normal force [N], shape (K,); None without a force reference."""
    contact_normal: np.ndarray | None = field(repr=False, default=None)
    """The outward normal of the surface the force is measured on (the force reference's, else
    the scene's first), world axes, shape (3,); None without a scene."""

    @property
    def normal_force(self) -> np.ndarray | None:
        """The normal force the end effector pressed on :attr:`contact_normal`'s surface [N],
        ``−n·F``, shape (K,); None without a scene."""
        if self.wrench is None or self.contact_normal is None:
            return None
        return -(np.asarray(self.wrench)[:, :3] @ np.asarray(self.contact_normal))

    relaxed_first_time: np.ndarray | None = field(repr=False, default=None)
    """Where the law relaxed limits it could not all keep (``qp-osc``, ``mpc``): per kind
    (position, velocity, acceleration) and joint the first time [s] (NaN: never), shape (3, nv);
    None when it relaxed none (:attr:`relaxed`)."""
    relaxed_largest: np.ndarray | None = field(repr=False, default=None)
    """By how much at most [the kind's unit], shape (3, nv); None when none."""
    relaxed_span: np.ndarray | None = field(repr=False, default=None)
    """``(instants, last time [s])``: the evaluation instants at which any row was relaxed and
    the last of them, shape (2,); None when none."""

    @property
    def duration(self) -> float:
        """Simulated time [s]."""
        return float(self.t[-1] - self.t[0])

    @property
    def nv(self) -> int:
        """Number of joints."""
        return int(self.q.shape[1])

    @property
    def e(self) -> np.ndarray:
        """Position error ``q − q_d`` [rad], shape (K, nv)."""
        return self.q - self.q_des

    @property
    def edot(self) -> np.ndarray:
        """Velocity error ``q̇ − q̇_d`` [rad/s], shape (K, nv)."""
        return self.v - self.v_des

    @property
    def p_error(self) -> np.ndarray | None:
        """``p̂ − p`` over time, shape (K, n_p), or None."""
        return None if self.p_hat is None or self.p_true is None else self.p_hat - self.p_true

    @property
    def joint_limits(self) -> JointLimits:
        """The limits the run is checked against: the position range and velocity limits it
        records (none where it records none) and ``torque_limits``."""
        nv = self.nv
        none = np.full(nv, np.inf)
        lower, upper = (-none, none) if self.position_limits is None else self.position_limits
        names = self.joint_names if len(self.joint_names) == nv else tuple(f"joint{j + 1}" for j in range(nv))
        velocity = none if self.velocity_limits is None else self.velocity_limits
        return JointLimits(names, lower, upper, velocity, none, self.torque_limits)

    @property
    def relaxed(self) -> RunRelaxation | None:
        """The law's relaxations (:class:`~twolink_pin.controllers.relaxation.RunRelaxation`),
        or None when it relaxed no limit."""
        if self.relaxed_first_time is None or self.relaxed_largest is None or self.relaxed_span is None:
            return None
        return RunRelaxation(
            self.relaxed_first_time,
            self.relaxed_largest,
            int(self.relaxed_span[0]),
            float(self.relaxed_span[1]),
        )

    @cached_property
    def crossings(self) -> Crossings:
        """Where the run went past its position range, velocity and effort limits (the
        commanded torque's): :func:`~twolink_pin.limits.motion_crossings` of its samples."""
        motion = Motion(self.t, self.q, self.v, None, self.tau_command)
        return motion_crossings(motion, self.joint_limits)

    @property
    def limit_excess(self) -> np.ndarray:
        """Largest ``|τ_command| − limit`` per joint [N·m], 0 where never exceeded."""
        return self.crossings.effort.excess

    @property
    def limit_exceeded(self) -> np.ndarray:
        """Whether the commanded torque ever exceeded each joint's limit, shape (nv,)."""
        return self.crossings.effort.crossed

    @property
    def first_exceeded_at(self) -> list[float | None]:
        """First time [s] each joint's commanded torque exceeded its limit, or None."""
        return [None if np.isnan(x) else float(x) for x in self.crossings.effort.first_time]
