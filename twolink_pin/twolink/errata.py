"""Where the course report is wrong or silent, with the evidence computed by the toolkit.

Each function returns an :class:`Erratum`: the report's claim, what is right, and the
numbers that show it. The report (``docs/report_comparison.md`` and the HTML report)
prints them; tests check the numbers.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from twolink_pin.controllers import Adaptive
from twolink_pin.dynamics import regressor
from twolink_pin.errors import InvalidParameterError
from twolink_pin.kinematics import inverse_kinematics
from twolink_pin.model import RobotModel
from twolink_pin.simulation import SimulationResult
from twolink_pin.trajectory import JointTrajectory, Trajectory
from twolink_pin.twolink.closed_form import coriolis_matrix, mass_matrix
from twolink_pin.twolink.reference import REPORT_COEFFICIENTS, REPORT_TABLE1


class Erratum(NamedTuple):
    """One place where the report is wrong or silent."""

    topic: str
    """Short title."""
    report: str
    """What the report says (or does not say)."""
    correct: str
    """What is right, or what we chose."""
    evidence: dict[str, Any]
    """Numbers computed by the toolkit."""


def third_via_point(robot: RobotModel) -> Erratum:
    """The text lists (0.48, 0.1) twice; Table 1's third row is IK of (0.48, −0.1)."""
    printed = inverse_kinematics(robot, (0.48, 0.1))
    corrected = inverse_kinematics(robot, (0.48, -0.1))
    table = np.array(REPORT_TABLE1["third"])
    return Erratum(
        "Third via point",
        "The text lists the via points as (0.48, 0.1), (0.38, 0), (0.48, 0.1), (0.58, 0).",
        "The third point is (0.48, −0.1): Table 1's third row is its inverse kinematics.",
        {
            "table1_row3": table.tolist(),
            "ik_of_0.48_-0.1": corrected.round(4).tolist(),
            "ik_of_0.48_0.1": printed.round(4).tolist(),
            "max_abs_diff_corrected_rad": float(np.abs(corrected.round(4) - table).max()),
            "max_abs_diff_printed_rad": float(np.abs(printed.round(4) - table).max()),
        },
    )


def printed_coefficients(trajectory: JointTrajectory) -> Erratum:
    """Eqs. 6–7 as printed miss the via points; two coefficients are misprinted."""
    t = trajectory.times
    ours = trajectory.coefficients
    printed = np.array(REPORT_COEFFICIENTS)
    printed_q = np.array([np.polynomial.polynomial.polyval(t, c) for c in printed]).T
    ours_q = np.array([np.polynomial.polynomial.polyval(t, c) for c in ours]).T
    fixed = printed.copy()
    fixed[0, 6], fixed[1, 4] = ours[0, 6], ours[1, 4]
    fixed_q = np.array([np.polynomial.polynomial.polyval(t, c) for c in fixed]).T
    return Erratum(
        "Trajectory coefficients (eqs. 6–7)",
        "θ1 has +1.95 t⁶ and θ2 has +3.19 t⁴.",
        f"θ1's t⁶ coefficient is {ours[0, 6]:.4f} (sign misprinted) and θ2's t⁴ is {ours[1, 4]:.4f}.",
        {
            "times_s": t.tolist(),
            "via_q_rad": trajectory.via_q.tolist(),
            "printed_polynomial_at_via_times_rad": printed_q.tolist(),
            "printed_max_miss_rad": float(np.abs(printed_q - trajectory.via_q).max()),
            "ours_max_miss_rad": float(np.abs(ours_q - trajectory.via_q).max()),
            "printed_with_two_fixes_max_miss_rad": float(np.abs(fixed_q - trajectory.via_q).max()),
            "ours_coefficients": ours.tolist(),
        },
    )


def y3_sign(robot: RobotModel, seed: int = 0, samples: int = 200) -> Erratum:
    """Y3's lower-left Coriolis entry: printed −q̇1 sin q2, correct +q̇1 sin q2."""
    rng = np.random.default_rng(seed)
    p = np.asarray(robot.p)
    P = robot.parameter_map.matrix
    data = robot.create_data()
    err_ours, err_printed = 0.0, 0.0
    for _ in range(samples):
        q, v, w, a = rng.uniform(-np.pi, np.pi, size=(4, 2))
        exact = mass_matrix(q, p) @ a + coriolis_matrix(q, v, p) @ w
        ours = regressor(robot.model, data, q, v, w, a) @ P @ p
        printed = ours.copy()
        printed[1] -= 2 * p[2] * v[0] * np.sin(q[1]) * w[0]
        err_ours = max(err_ours, float(np.abs(ours - exact).max()))
        err_printed = max(err_printed, float(np.abs(printed - exact).max()))
    return Erratum(
        "Sign in the regressor Y3",
        "Y3's Coriolis part is [[−q̇2 sin q2, −(q̇1+q̇2) sin q2], [−q̇1 sin q2, 0]].",
        "The lower-left entry is +q̇1 sin q2 (the report's own C(θ, θ̇) has the + sign).",
        {
            "states": samples,
            "max_error_pinocchio_regressor_Nm": err_ours,
            "max_error_printed_Y3_Nm": err_printed,
        },
    )


def unstated_settings(lam: float, q0_offset: tuple[float, ...]) -> Erratum:
    """λ, the initial state and the Table 2 norm are not in the report (the text states the
    values this run used)."""
    offset = ", ".join(f"{x:g}" for x in q0_offset)
    return Erratum(
        "Unstated λ, initial state and norm",
        "The report never gives λ, the initial state of its runs, nor which norm Table 2 shows.",
        f"We use λ = {lam:g} 1/s, q(0) = q_d(0) + ({offset}) rad, q̇(0) = 0, and report RMS, L2 and max.",
        {"lambda_per_s": lam, "q0_offset_rad": list(q0_offset)},
    )


def robust_naming(result: SimulationResult) -> Erratum:
    """The "Robust Controller" is law 2 on a wrong model: no robustifying term."""
    last = result.t >= result.t[-1] - result.reference_period - 1e-12
    e_last = np.abs(result.e[last]).max(axis=0)
    return Erratum(
        "\u201cRobust Controller\u201d",
        "Calls Slotine–Li with M̂ = 0.5 M, Ĉ = 0.5 C a robust controller.",
        "It has no robustifying (switching or saturated) term; its error does not vanish.",
        {"last_period_max_abs_e_rad": e_last.tolist()},
    )


def parameter_convergence(result: SimulationResult, controller: Adaptive, trajectory: Trajectory) -> Erratum:
    """Do the adaptive estimates approach the true values, and how fast?

    Evidence: ``|p̃|`` at several times; the excitation Gram matrix
    ``G = (1/T) ∫ Yᵀ K⁻¹ Y dt`` along one period of the desired motion (positive
    definite = persistently exciting) and the slowest rate of the averaged adaptation
    ``dp̃/dt ≈ −Γ G p̃`` (valid once ``s`` is small: ``s ≈ K⁻¹ Y p̃``), with the run's own
    gains ``K`` and ``Γ = diag(1/γ)`` (``controller``), computed by
    :func:`twolink_pin.identification.measures.averaged_adaptation`.

    Raises:
        InvalidParameterError: ``result`` holds no parameter estimates.
    """
    from twolink_pin.identification.measures import averaged_adaptation

    if result.p_hat is None or result.p_true is None:
        raise InvalidParameterError("result", result.controller, "a run of an adaptive law (with p̂)")
    n_p = controller.robot.parameter_map.size
    averaged = averaged_adaptation(controller, trajectory)
    p_err = result.p_hat[:, :n_p] - result.p_true[:n_p]
    checkpoints = [tc for tc in (0.0, 10.0, 20.0, 30.0) if tc <= result.t[-1] + 1e-9]
    norms = {
        f"{tc:g}": float(np.linalg.norm(p_err[np.searchsorted(result.t, tc - 1e-9)])) for tc in checkpoints
    }
    slowest = averaged.slowest_time_constant
    return Erratum(
        "Parameter errors \u201capproaching zero\u201d",
        "Parameter errors, although not zero in 30 s, approach zero and will reach zero asymptotically.",
        (
            "The motion is persistently exciting, so they do converge, but the slowest mode has a time "
            f"constant of about {slowest:.0f} s: in 30 s the estimates are still far from the truth. "
            "An excitation designed for it converges in seconds with the same gains (see the identification "
            "section)."
        ),
        {
            "p_error_norm_at_t": norms,
            "excitation_gram_eigenvalues": np.linalg.eigvalsh(averaged.gram).tolist(),
            "averaged_adaptation_rates_per_s": averaged.rates.tolist(),
            "slowest_time_constant_s": slowest,
            "p_hat_final": result.p_hat[-1, :n_p].tolist(),
            "p_true": result.p_true[:n_p].tolist(),
        },
    )
