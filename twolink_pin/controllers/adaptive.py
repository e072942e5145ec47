"""Slotine–Li adaptive control with the regressor from Pinocchio."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from twolink_pin.controllers.base import (
    Controller,
    StageKernel,
    data_view,
    diagonal_gain,
    gather,
    literal,
    pair_namespace,
    pair_values,
    positive_scalar,
)
from twolink_pin.controllers.computed_torque import DEFAULT_LAMBDA
from twolink_pin.dynamics import Friction, regressor
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel


@dataclass(frozen=True)
class AdaptiveGains:
    """Gains of :class:`Adaptive` (the report's values).

    Attributes:
        k: Sliding gain ``K`` [N·m·s/rad], diagonal.
        gamma: The report's ``γ_i``; the adaptation gain is ``Γ = diag(1/γ_i)``.
        lam: ``λ`` [1/s] (not in the report; our default 5).
        initial_estimate: ``p̂(0) = initial_estimate × p`` (report: 50 % underestimated).
    """

    k: tuple[float, ...] = (120.0, 120.0)
    gamma: tuple[float, ...] = (0.5, 0.15, 0.6)
    lam: float = DEFAULT_LAMBDA
    initial_estimate: float = 0.5

    def __post_init__(self) -> None:
        diagonal_gain("k", self.k)
        diagonal_gain("gamma", self.gamma)
        positive_scalar("lam", self.lam, "1/s")
        if not (math.isfinite(self.initial_estimate) and self.initial_estimate >= 0):
            raise InvalidParameterError("initial_estimate", self.initial_estimate, "a finite factor >= 0")


class Adaptive(Controller):
    r"""Slotine–Li adaptive control (report "Adaptive Controller")::

        τ = Y(q, q̇, q̇_r, q̈_r) p̂ − K s,      dp̂/dt = −Γ Yᵀ s,   Γ = diag(1/γ_i)

    ``Y p = M(q) q̈_r + C(q, q̇) q̇_r + g(q)``; ``Y = Y_π P`` with ``Y_π`` Pinocchio's
    ``computeJointTorqueRegressor`` polarised to ``w = q̇_r ≠ q̇``
    (:func:`twolink_pin.dynamics.regressor`) and ``P`` the robot's parameter map. With
    ``V = ½ sᵀ M s + ½ p̃ᵀ Γ⁻¹ p̃``, ``V̇ = −sᵀ K s <= 0``: ``s → 0`` (Barbalat), while
    ``p̃`` converges only if the motion is persistently exciting. The state ``z`` is ``p̂``.
    """

    name = "adaptive"

    def __init__(self, robot: RobotModel, gains: AdaptiveGains | None = None) -> None:
        super().__init__(robot)
        self.gains = gains if gains is not None else AdaptiveGains()
        self.k = diagonal_gain("k", self.gains.k, robot.nv)
        self.lam = self.gains.lam
        self.P = robot.parameter_map.matrix
        self.p_true = self._true_parameters()
        self.Gamma = 1.0 / diagonal_gain("gamma", self.gains.gamma, len(self.p_true))

    def _true_parameters(self) -> np.ndarray:
        """The estimated parameters' true values: the robot's ``p``."""
        return np.array(self.robot.p, dtype=float)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(self.robot.parameter_map.names)

    def true_parameters(self) -> np.ndarray:
        return self.p_true.copy()

    def parameters_of(self, robot: RobotModel, friction: Friction | None) -> np.ndarray:
        return np.array(robot.parameter_map.values(robot.model), dtype=float)

    def initial_state(self) -> np.ndarray:
        return self.gains.initial_estimate * self.p_true

    def regressor(self, q: np.ndarray, v: np.ndarray, v_r: np.ndarray, a_r: np.ndarray) -> np.ndarray:
        """``Y(q, q̇, q̇_r, q̈_r)``, shape (nv, len(p̂))."""
        return regressor(self.model, self.data, q, v, v_r, a_r) @ self.P

    def _extra_columns(self) -> tuple[list[str], list[dict[int, str]]] | None:
        """Kernel statements and sparse columns (joint -> expression) that :meth:`regressor`
        appends after ``Y_π P``; None if this class's regressor has no kernel form."""
        return ([], []) if type(self).regressor is Adaptive.regressor else None

    def stage_kernel(self) -> StageKernel | None:
        extra = self._extra_columns() if type(self).compute is Adaptive.compute else None
        if extra is None:
            return None
        nv, lam = self.robot.nv, literal(self.lam)
        data, namespace = pair_namespace(self.model)
        lines = []
        for j in range(nv):
            lines.append(f"c_e{j} = q{j} - qd{j}")
            lines.append(f"c_ed{j} = v{j} - vd{j}")
            lines.append(f"c_s{j} = c_ed{j} + {lam} * c_e{j}")
            lines.append(f"c_w{j} = vd{j} - {lam} * c_e{j}")
        lines.append(f"c_pack(c_in, 0, {pair_values(nv, [f'ad{j} - {lam} * c_ed{j}' for j in range(nv)])})")
        lines.append("c_reg(c_pair, c_pdata, c_Q, c_V, c_A)")
        # Y_π = Y_A − Y_B (diagonal blocks of the pair's regressor), read only where P is
        # non-zero. The pair's regressor is (2 nv) × (2 n_π), column-major.
        n_pi, rows = self.P.shape[0], 2 * nv
        used = sorted({int(r) for r in np.flatnonzero(np.any(self.P != 0, axis=1))})
        entries = {r * rows + j: f"c_a{j}_{r}" for j in range(nv) for r in used}
        entries |= {(n_pi + r) * rows + nv + j: f"c_b{j}_{r}" for j in range(nv) for r in used}
        offsets = sorted(entries)
        if offsets:
            lines.append(f"{', '.join(entries[o] for o in offsets)}, = c_gather(c_y)")
        for j in range(nv):
            lines += [f"c_d{j}_{r} = c_a{j}_{r} - c_b{j}_{r}" for r in used]
        namespace.update(
            {
                "c_y": data_view(data.jointTorqueRegressor),
                "c_gather": gather(offsets),
                "c_reg": pin.computeJointTorqueRegressor,
            }
        )
        columns: list[dict[int, str]] = []  # Y_p = Y_π P, column by column
        for i in range(self.P.shape[1]):
            column: dict[int, str] = {}
            for j in range(nv):
                terms = []
                for r in np.flatnonzero(self.P[:, i]):
                    factor = float(self.P[r, i])
                    term = f"c_d{j}_{r}" if abs(factor) == 1.0 else f"c_d{j}_{r} * {literal(abs(factor))}"
                    terms.append(("- " if factor < 0 else "+ ") + term)
                expr = " ".join(terms).removeprefix("+ ") if terms else "0.0"
                if expr.isidentifier():  # a single unit term: use it, no copy per stage
                    column[j] = expr
                else:
                    lines.append(f"c_y{j}_{i} = {expr}")
                    column[j] = f"c_y{j}_{i}"
            columns.append(column)
        extra_lines, extra_columns = extra
        lines += extra_lines
        columns += extra_columns
        for j in range(nv):
            model = " + ".join(f"{col[j]} * z{i}" for i, col in enumerate(columns) if j in col) or "0.0"
            lines.append(f"tau{j} = ({model}) - {literal(self.k[j])} * c_s{j}")
        for i, col in enumerate(columns):
            projection = " + ".join(f"{expr} * c_s{j}" for j, expr in col.items()) or "0.0"
            lines.append(f"dz{i} = -{literal(self.Gamma[i])} * ({projection})")
        return StageKernel(tuple(lines), namespace)

    def compute(
        self,
        q: np.ndarray,
        v: np.ndarray,
        q_des: np.ndarray,
        v_des: np.ndarray,
        a_des: np.ndarray,
        z: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        e = q - q_des
        edot = v - v_des
        s = edot + self.lam * e
        Y = self.regressor(q, v, v_des - self.lam * e, a_des - self.lam * edot)
        tau = Y @ z - self.k * s
        return tau, -self.Gamma * (Y.T @ s)
