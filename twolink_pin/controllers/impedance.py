"""Cartesian impedance control with gravity compensation: a spring and damper on the frame."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from twolink_pin.controllers.base import Controller
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.controllers.matrix_gains import applied_form
from twolink_pin.controllers.task_space import (
    TaskInertia,
    block_gain,
    desired_frame,
    null_space_torque,
    row_index,
    task_error,
    task_rows,
)
from twolink_pin.dynamics import joint_space_inertia
from twolink_pin.model import RobotModel

STIFFNESS_FREQUENCY = 10.0
"""ω [rad/s] of the robot-derived default stiffness ``K_p = ω² Λ_p`` and damping
``D_p = 2 ω Λ_p``, ``Λ_p = (J_p M⁻¹ J_pᵀ)⁻¹`` the task inertia of the frame's position alone at
``home`` (``K_o``, ``D_o`` alike with the orientation rows): the frame's translation alone on
its spring is critically damped at ω in every direction; with both blocks, the task's modes
lie between 0 and √2 ω in frequency (:meth:`Impedance.scaled_gains`)."""
POSTURE_FREQUENCY = 5.0
"""ω [rad/s] of the default null-space posture gains ``ω² M(q₀)``, ``2 ω M(q₀)``: the posture
modes at home are critically damped at exactly this ω."""


@dataclass(frozen=True, eq=False)
class ImpedanceGains(Gains):
    r"""Gains of :class:`Impedance`: each a number (times I), 3 numbers (a diagonal), 9 numbers
    (a 3 × 3 matrix, row by row: ``--gain k=2000,0,0,0,2000,0,0,0,500``) or a symmetric
    positive-definite 3 × 3 matrix in world axes (or one per run). The CLI's names (``k``,
    ``d``, …) are the fields below; the law writes them $K$, $D$ (position rows: $K_p$,
    $D_p$; orientation: $K_o$, $D_o$) and $K_n$, $D_n$.

    Attributes:
        k: Translational stiffness $K_p$ [N/m]; default from the robot (see
            :data:`STIFFNESS_FREQUENCY`).
        d: Translational damping $D_p$ [N·s/m].
        k_rot: Rotational stiffness $K_o$ [N·m/rad].
        d_rot: Rotational damping $D_o$ [N·m·s/rad].
        kp_null: Posture stiffness [N·m/rad], an nv × nv matrix (null space of the task).
        kd_null: Posture damping [N·m·s/rad], an nv × nv matrix.
    """

    k: Any = gain(None, per="axis", matrix=True, unit="N/m", doc="translational stiffness K")
    d: Any = gain(None, per="axis", matrix=True, unit="N·s/m", doc="translational damping D")
    k_rot: Any = gain(None, per="axis", matrix=True, unit="N·m/rad", doc="rotational stiffness")
    d_rot: Any = gain(None, per="axis", matrix=True, unit="N·m·s/rad", doc="rotational damping")
    kp_null: Any = gain(None, per="joint", matrix=True, unit="N·m/rad", doc="posture stiffness")
    kd_null: Any = gain(None, per="joint", matrix=True, unit="N·m·s/rad", doc="posture damping")


class Impedance(Controller[ImpedanceGains]):
    r"""Cartesian impedance control with gravity compensation:

    $$\tau = \hat g(q) + J^\top\big(-K e - D \dot e\big)
    + N^\top\big(-K_n e_q - D_n \dot e_q\big)$$

    with the pose error $e = (p - p_d,\ \log(R R_d^\top))$, $\dot e = J \dot q - \dot x_d$,
    $e_q = q - q_d$ and $N^\top = I - J^\top \Lambda J \hat M^{-1}$,
    $\Lambda = (J \hat M^{-1} J^\top)^{-1}$ (the dynamically consistent null space, damped
    near singularities as in ``osc``). The frame behaves as a spring $K$ and damper $D$
    to its desired pose, with the arm's own task inertia (no inertia shaping, no model
    feedforward: it is a regulator, exact at rest). Under a constant external wrench $F$ on
    the frame, at rest $J^\top (F - K e) + N^\top \tau_n = 0$, and since $J \hat M^{-1} N^\top = 0$
    with $J$ of full row rank, $K e = F$: the frame settles at $e = K^{-1} F$.
    With the exact gravity, $V = \tfrac12 \dot q^\top M \dot q + \tfrac12 e^\top K e$ decreases
    for a constant desired pose (Hogan, "Impedance control: an approach to manipulation",
    *J. Dyn. Sys., Meas., Control* 107(1), 1985; Ott, *Cartesian Impedance Control of
    Redundant and Flexible-Joint Robots*, Springer 2008, ch. 3). The desired pose and twist
    are ``LawInput``'s ``x_des``, ``R_des``, ``twist_des`` (the SE(3) reference's, else the
    forward kinematics of the joint reference), the posture the joint reference itself;
    the task's rows are chosen as in ``osc`` (the twolink: position x, y).
    """

    name = "impedance"
    title = "Cartesian impedance + gravity compensation"
    Gains = ImpedanceGains
    task_space = True

    def __init__(self, robot: RobotModel, gains: ImpedanceGains | None = None, **kwargs: Any) -> None:
        super().__init__(robot, gains, **kwargs)
        self.rows = task_rows(robot)
        """The controlled rows of the world-aligned 6-D task (0–2 position, 3–5 orientation)."""
        g = self.gains
        self._K = block_gain(g.k, g.k_rot, self.rows)
        self._D = block_gain(g.d, g.d_rot, self.rows)
        self._redundant = len(self.rows) < robot.nv
        self._index = row_index(self.rows)  # a slice when the rows are consecutive: views
        self._inertia = TaskInertia(self.name)
        self._kp_null, self._kd_null = applied_form(g.kp_null), applied_form(g.kd_null)

    @property
    def stiffness(self) -> np.ndarray:
        """``K`` on the task's rows, shape (1 or N, k, k) [N/m, N·m/rad]."""
        return self._K

    @property
    def damped_evaluations(self) -> int:
        """Evaluations at which the task inertia was damped (near a singularity)."""
        return self._inertia.damped

    def scaled_gains(self) -> dict[str, Any]:
        r"""From the arm's inertia at ``home``: $K_p = \omega^2 \Lambda_p$, $D_p = 2\omega \Lambda_p$
        with $\Lambda_p = (J_p M^{-1} J_p^\top)^{-1}$ the task inertia of the position rows alone
        ($K_o$, $D_o$ alike with $\Lambda_o$ of the orientation rows; the axes the task leaves free
        get the mean of the others), and the posture $K_n = \omega_n^2 M$, $D_n = 2 \omega_n M$.

        At home, with the exact gravity: the posture modes are critically damped at exactly
        $\omega_n$ ($N^\top M = M - J^\top \Lambda J$ makes $M^{-1} N^\top K_n$ equal $\omega_n^2$ on
        the null space of $J$); a position-only (or orientation-only) task has every task mode
        at exactly $\omega$; with both, the task's stiffness is $\omega^2$ times the Schur
        complements of $\Lambda$'s blocks, whose generalised eigenvalues against $\Lambda$ are
        $1 \pm \sigma_i$ ($\sigma_i$ the canonical correlations of position and orientation,
        in [0, 1)): every task mode within frequency $\sqrt 2\,\omega$ and rate
        $(2 + \sqrt 2)\,\omega$, never stiffer however light the wrist. Each block is then
        scaled down where the arm near home would carry it on a light joint too fast
        (:func:`_kept_within`)."""
        robot = self.robot
        model, data, q = robot.model, robot.model.createData(), robot.home
        J = np.array(
            pin.computeFrameJacobian(
                model, data, q, robot.ee_frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
            )
        ).reshape(6, robot.nv)  # one joint: Pinocchio gives a vector
        M = joint_space_inertia(model, q)
        rows = task_rows(robot)
        w, wn = STIFFNESS_FREQUENCY, POSTURE_FREQUENCY
        gains = {"kp_null": wn**2 * M, "kd_null": 2 * wn * M}
        linear, angular = rows[rows < 3], rows[rows >= 3] - 3
        position, orientation = _axis_inertia(J[linear], M, linear), _axis_inertia(J[3 + angular], M, angular)
        position, orientation = _kept_within(robot, position, orientation, 2 * w)
        gains["k"], gains["d"] = w**2 * position, 2 * w * position
        gains["k_rot"], gains["d_rot"] = w**2 * orientation, 2 * w * orientation
        return gains

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        rows = self._index
        f = terms.frame(x.q, x.v)
        J = f.jacobian[:, rows]
        d = desired_frame(x)  # x_des, R_des, twist_des
        e = task_error(f.position, f.rotation, d.position, d.rotation, rows)
        e_dot = np.matvec(J, x.v) - d.twist[:, rows]
        force = -(np.matvec(self._K, e) + np.matvec(self._D, e_dot))
        tau = terms.gravity(x.q) + np.vecmat(force, J)
        if self._redundant:
            tau0 = -(self._kp_null(x.q - x.q_des) + self._kd_null(x.v - x.v_des))
            MinvJt = terms.solve_mass(x.q, J.transpose(0, 2, 1))
            Lam = self._inertia(np.matmul(J, MinvJt), x.t)
            tau = tau + null_space_torque(J, MinvJt, Lam, tau0)
        return LawOutput(tau)


NEIGHBOURHOOD = 0.5
"""Half-width [rad or m] of the box about home where :func:`_kept_within` samples the arm."""
NEIGHBOURHOOD_SAMPLES = 64
"""Configurations it samples there (a Halton sequence, unscrambled: the same every time)."""
FASTEST_TASK_RATE = 400.0
"""The task damping's fastest joint-space rate [1/s] :func:`_kept_within` allows near home: ten
times the home's at most (2 ω × 2), a seventh of RK4's bound at 1 ms."""


def _kept_within(
    robot: RobotModel, position: np.ndarray, orientation: np.ndarray, damping: float
) -> tuple[np.ndarray, np.ndarray]:
    """The blocks scaled down (each by its own factor ≤ 1) so that the task damping
    ``damping × block``'s fastest joint-space rate — the largest generalised eigenvalue of
    ``(Jᵀ D J, M(q))`` — stays within :data:`FASTEST_TASK_RATE` at every one of
    :data:`NEIGHBOURHOOD_SAMPLES` configurations within :data:`NEIGHBOURHOOD` of home. A fixed
    Cartesian stiffness meets a configuration-dependent arm: where a light wrist's axis lines up
    with a task direction the wrist alone carries the block (TIAGo's arm: 2900 1/s 0.85 s into the
    default reference, diverging at 1 ms, with the home's blocks)."""
    from scipy.stats import qmc  # here: importing the CLI stays light

    model, data = robot.model, robot.model.createData()
    rows = task_rows(robot)
    lower, upper = np.array(model.lowerPositionLimit), np.array(model.upperPositionLimit)
    unit = qmc.Halton(d=robot.nv, scramble=False).random(NEIGHBOURHOOD_SAMPLES + 1)[1:]
    samples = np.clip(robot.home + (2 * unit - 1) * NEIGHBOURHOOD, lower, upper)
    scales = []
    for block, first in ((position, 0), (orientation, 3)):
        axes = rows[(rows >= first) & (rows < first + 3)]
        fastest = 0.0
        for q in (robot.home, *samples):
            J = np.array(
                pin.computeFrameJacobian(
                    model, data, q, robot.ee_frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
                )
            ).reshape(6, robot.nv)[axes]
            if not len(axes):
                break
            Dj = J.T @ (damping * block[np.ix_(axes - first, axes - first)]) @ J
            fastest = max(
                fastest,
                float(np.max(np.linalg.eigvals(np.linalg.solve(joint_space_inertia(model, q), Dj)).real)),
            )
        scales.append(min(1.0, FASTEST_TASK_RATE / fastest) if fastest > 0 else 1.0)
    return scales[0] * position, scales[1] * orientation


SINGULAR_MOBILITY = 1e-12
"""A direction of ``J M⁻¹ Jᵀ`` whose eigenvalue is below this fraction of the largest cannot move
at home (a singular home, e.g. the stretched twolink): its stiffness is the mean of the others'."""


def _axis_inertia(J: np.ndarray, M: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """``(J M⁻¹ Jᵀ)⁻¹`` of the task rows ``J`` (k, nv) on world ``axes`` (k of x, y, z), as a
    3 × 3 matrix in world axes (a direction that cannot move at home, and the free axes: the mean
    of the others' eigenvalues; the identity without any axis)."""
    if not len(axes):
        return np.eye(3)
    mobility = J @ np.linalg.solve(M, J.T)
    a, U = np.linalg.eigh(0.5 * (mobility + mobility.T))
    moving = a > SINGULAR_MOBILITY * max(float(a.max()), 1e-300)
    masses = np.where(moving, 1.0 / np.where(moving, a, 1.0), 0.0)
    mean = float(np.mean(masses[moving])) if moving.any() else 1.0
    masses = np.where(moving, masses, mean)
    block = np.eye(3) * mean
    block[np.ix_(axes, axes)] = (U * masses) @ U.T
    return 0.5 * (block + block.T)
