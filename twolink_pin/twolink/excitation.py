"""The twolink's excitations, and the report's question answered: why is p̂ still far from p at 30 s?

Two Fourier excitations (period 10 s, 5 harmonics), each the result of
:func:`~twolink_pin.identification.excitation.optimise_excitation` with the default design
(3 seeded starts from seed 0, SLSQP, 100 samples per period, the default limits: positions
within the joint limits less 5 %, ``|q̇| <= 5`` rad/s, ``|q̈| <= 10`` rad/s², torques within
80 % of 240 / 40 N·m), stored as numbers so that nothing is re-optimised
(``tests/test_identification.py`` re-optimises and compares):

* :func:`identification_excitation` — criterion ``"condition"``: the smallest ``cond(W)``
  of the four base parameters and the four friction coefficients; the twolink's default
  for ``twolink-pin identify`` (registered with :func:`register_excitation` on import);
* :func:`adaptation_excitation` — criterion ``"adaptation"``: the fastest averaged
  adaptation of the report's adaptive law (K = 120 N·m·s/rad, γ = (0.5, 0.15, 0.6)).

:func:`excitation_table` compares them with the report's own trajectory (the numbers the
HTML report shows beside Figure 27 and ``docs/identification.md`` quotes), and
:func:`adaptive_runs` runs the report's adaptive law along each.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from twolink_pin.identification.excitation import register_excitation
from twolink_pin.model import RobotModel
from twolink_pin.trajectory import FourierTrajectory, Trajectory, default_trajectory

PERIOD = 10.0
"""Period of both excitations [s]."""

IDENTIFICATION_COEFFICIENTS = {
    "a": [
        [
            -0.4960288394322902,
            0.72675994113002,
            -0.13192886202631948,
            -0.3050233029808221,
            0.1451465452531516,
        ],
        [
            0.20104197510572594,
            -0.7805857277217373,
            -0.09787628334083022,
            0.3313871693039123,
            -0.35182900249579935,
        ],
    ],
    "b": [
        [
            -0.7479966491694676,
            0.5762592760225383,
            -0.05484431930965055,
            -0.004282327876389379,
            -0.1399866690190754,
        ],
        [0.7793698924124727, -0.3602946248850944, -0.1520699466481174, 0.097296206164532, 0.2949776842707785],
    ],
    "offset": [-1.153269982991338e-05, 0.010073229773916637],
}
"""Criterion "condition" [rad/s, rad/s, rad]."""

ADAPTATION_COEFFICIENTS = {
    "a": [
        [
            -1.1864346821262288e-08,
            1.566105797314442e-09,
            -1.4420001165440629e-09,
            -4.888146381160125e-09,
            -0.10344216665049533,
        ],
        [
            1.2505067861105248,
            -0.0009143618068760055,
            0.007030637381309084,
            0.7302438935668973,
            -0.025590230375027872,
        ],
    ],
    "b": [
        [
            -2.7940579166445663e-08,
            -2.072545497681277e-08,
            4.2380849155242646e-09,
            2.0365754704840176e-09,
            -3.181415621442007,
        ],
        [
            0.8172000416250222,
            -0.0007264681156526102,
            0.013731849955924063,
            -0.8055892466740425,
            0.0008192128258221276,
        ],
    ],
    "offset": [0.0, 2.2227204845091224e-06],
}
"""Criterion "adaptation", for the report's adaptive law [rad/s, rad/s, rad]."""


def identification_excitation() -> FourierTrajectory:
    """The twolink's excitation for identification (criterion ``"condition"``)."""
    c = IDENTIFICATION_COEFFICIENTS
    return FourierTrajectory(PERIOD, c["a"], c["b"], c["offset"])


def adaptation_excitation() -> FourierTrajectory:
    """The twolink's excitation for the report's adaptive law (criterion ``"adaptation"``)."""
    c = ADAPTATION_COEFFICIENTS
    return FourierTrajectory(PERIOD, c["a"], c["b"], c["offset"])


register_excitation("twolink", identification_excitation)

TRAJECTORIES = ("report", "identification", "adaptation")
"""The three references compared, in table order."""
TITLES = {
    "report": "the report's via-point trajectory (4 s)",
    "identification": "excitation for identification: min cond(W) (10 s)",
    "adaptation": "excitation for the adaptive law: max slowest rate (10 s)",
}
"""Their display titles."""


def trajectories(robot: RobotModel) -> dict[str, Trajectory]:
    """The report's trajectory and the two excitations, by :data:`TRAJECTORIES` key."""
    return {
        "report": default_trajectory(robot),
        "identification": identification_excitation(),
        "adaptation": adaptation_excitation(),
    }


def report_adaptive(robot: RobotModel) -> Any:
    """The report's adaptive law on the twolink (its gains, p̂(0) = 0.5 p) and its plant."""
    from twolink_pin.run_spec import make_scenario

    return make_scenario("adaptive", robot)


def excitation_table(robot: RobotModel) -> list[dict[str, Any]]:
    """For each of :data:`TRAJECTORIES`: ``cond(W)`` of the identified parameters (base +
    friction, SI), ``λ_min`` of ``∫ Y_θᵀ Y_θ dt`` over a period and per second, the report's
    adaptive law's averaged rates and slowest time constant [s], and the time [s] the averaged
    model predicts for every ``|p̂_i − p_i| <= 5 % |p_i|`` from ``p̂(0) = 0.5 p``."""
    from twolink_pin.identification.measures import averaged_adaptation, excitation_measures

    controller = report_adaptive(robot).controller
    p = np.asarray(robot.p, dtype=float)
    rows = []
    for key, trajectory in trajectories(robot).items():
        measures = excitation_measures(robot, trajectory)
        averaged = averaged_adaptation(controller, trajectory)
        initial = (controller.gains.initial_estimate - 1.0) * p
        rows.append(
            {
                "trajectory": key,
                "title": TITLES[key],
                "period_s": trajectory.period,
                "condition_number": measures.condition_number,
                "gram_min_eigenvalue": measures.gram_min_eigenvalue,
                "gram_min_eigenvalue_per_s": measures.gram_min_eigenvalue_per_s,
                "adaptation_rates_per_s": averaged.rates.tolist(),
                "slowest_time_constant_s": averaged.slowest_time_constant,
                "slowest_mode": dict(zip(averaged.names, averaged.slowest_mode.tolist())),
                "predicted_time_to_5_percent_s": averaged.time_to_within(initial, p, 0.05),
            }
        )
    return rows


def adaptive_runs(
    robot: RobotModel, duration: float = 30.0, keys: tuple[str, ...] = TRAJECTORIES
) -> dict[str, Any]:
    """The report's adaptive law along each trajectory of ``keys`` for ``duration`` [s]:
    key → :class:`~twolink_pin.simulation.SimulationResult`."""
    from twolink_pin.simulation import SimulationConfig, simulate

    runs = {}
    for key in keys:
        controller, plant = report_adaptive(robot)
        runs[key] = simulate(controller, plant, trajectories(robot)[key], SimulationConfig(duration=duration))
    return runs


def time_within(t: np.ndarray, p_hat: np.ndarray, p: np.ndarray, fraction: float = 0.05) -> float | None:
    """First time [s] from which every ``|p̂_i − p_i| <= fraction |p_i|`` holds to the end of
    the run, or None if it never does."""
    inside = np.all(np.abs(p_hat - p) <= fraction * np.abs(p), axis=1)
    if not inside[-1]:
        return None
    outside = np.flatnonzero(~inside)
    return float(t[0] if outside.size == 0 else t[min(outside[-1] + 1, t.size - 1)])
