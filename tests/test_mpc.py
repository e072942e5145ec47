"""The ``mpc`` law (controllers/mpc.py) and its horizon QP (optimal/horizon.py), against closed
forms and second methods: a reference the plan can represent is tracked to rounding; the QP's
torque rows equal central differences of Pinocchio's RNEA; a binding replan's KKT residual,
computed here, is below the stated tolerance; a batch equals its single runs; bad gains and a
replan that cannot hold fail at once, naming what is wrong."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin import Plant, SimulationConfig, load_robot, simulate, simulate_batch
from twolink_pin.controllers import LawInput, ModelPredictive, MPCGains
from twolink_pin.errors import ControllerError, InvalidParameterError
from twolink_pin.limits import EFFORT, VELOCITY, joint_limits
from twolink_pin.optimal import kkt_residual, solve_qp
from twolink_pin.simulation.terms import terms_for
from twolink_pin.trajectory import Trajectory, TrajectorySample, default_trajectory

ROBOT = load_robot()
KKT_TOLERANCE = 1e-6
"""A replan's KKT residual bound, in the QP's own units (the cost over its largest curvature,
so O(1) whatever the arm): ProxQP is asked for 1e-9 on its residuals."""


class Parabola(Trajectory):
    """``q_d(t) = q0 + v0 t + ½ a t²``: constant acceleration, what the plan's pieces are."""

    def __init__(self, q0: np.ndarray, v0: np.ndarray, a: np.ndarray) -> None:
        self.q0, self.v0, self.a = q0, v0, a
        self.t0, self.period = 0.0, 100.0

    @property
    def nv(self) -> int:
        return self.q0.size

    def sample(self, t: float | np.ndarray) -> TrajectorySample:
        t = np.asarray(t, dtype=float)[..., None]
        q = self.q0 + self.v0 * t + 0.5 * self.a * t * t
        v = self.v0 + self.a * t
        a = np.broadcast_to(self.a, q.shape)
        return TrajectorySample(q, v, a, np.zeros_like(q))


@pytest.mark.parametrize("ahead", ["preview", "extrapolate"])
@pytest.mark.parametrize("replan", [0.01, 0.06], ids=["within-the-first-piece", "across-pieces"])
def test_a_reference_the_plan_can_represent_is_tracked_to_rounding(replan: float, ahead: str) -> None:
    """Exact model, start on the reference, constant reference acceleration, no limit active:
    every replan's plan is the reference itself (previewed or extrapolated: the same here), the
    torque its inverse dynamics, and RK4 integrates a quadratic exactly — the error stays at
    rounding (1e-9 rad), not at the feedback's level; also when the law follows the plan past
    its first piece between replans (60 ms against knots 25 ms apart)."""
    reference = Parabola(np.array([0.3, 0.8]), np.array([0.5, -0.4]), np.array([1.0, -1.5]))
    law = ModelPredictive(ROBOT, MPCGains(replan_period=replan, reference_ahead=ahead))
    run = simulate(law, Plant(ROBOT), reference, SimulationConfig(duration=0.5, q0_offset=0.0))
    limits = joint_limits(ROBOT)
    assert limits.excess(EFFORT, run.tau_command).max() < -30  # far from every limit (240, 40 N·m)
    assert np.abs(run.e).max() < 1e-9
    assert np.abs(run.v - run.v_des).max() < 1e-7  # the feedback's 10⁴ 1/s² times rounding


def _replan_input(law: ModelPredictive, q: np.ndarray, v: np.ndarray, t: float = 0.0) -> LawInput:
    sample = default_trajectory(ROBOT).sample(t)
    z = np.zeros((q.shape[0], law.state_size))
    return LawInput(t, q, v, z, sample.q[None], sample.v[None], sample.a[None])


def test_the_torque_rows_are_the_linearised_rnea() -> None:
    """The QP's effort rows ``T`` (∂τ_k/∂u at the knots) equal central differences of
    ``pin.rnea`` along the rolled-out plan, on the law's believed model (masses 20 % light)."""
    law = ModelPredictive(ROBOT, model_parameters=np.asarray(ROBOT.p) * 0.8)
    terms = terms_for(law)
    rng = np.random.default_rng(3)
    q, v = rng.uniform(-1, 1, (1, 2)), rng.uniform(-2, 2, (1, 2))
    x = _replan_input(law, q, v)
    qps, u_bar, deviation = law._problems(x, terms)
    reference = law.reference_over_horizon(x)
    hz = law.horizon
    K, nv, S = hz.knots, ROBOT.nv, hz.per_interval
    from twolink_pin.model.parameters import model_with_parameters

    model = model_with_parameters(ROBOT.model, ROBOT.parameter_map, np.asarray(ROBOT.p) * 0.8)
    data = model.createData()

    def torques(u: np.ndarray) -> np.ndarray:
        qs, vs, accel = hz.plan(reference, deviation[:, :nv], deviation[:, nv:], u.reshape(1, K, nv))
        return np.concatenate(
            [pin.rnea(model, data, qs[0, k * S], vs[0, k * S], accel[0, k * S]) for k in range(K)]
        )

    base, eps = u_bar.reshape(-1), 1e-6
    numeric = np.stack(
        [(torques(base + eps * e) - torques(base - eps * e)) / (2 * eps) for e in np.eye(K * nv)], axis=1
    )
    T = qps.C[0, : K * nv]  # the effort rows come first, knot-major, every twolink joint has one
    np.testing.assert_allclose(T, numeric, rtol=0, atol=1e-6 * np.abs(numeric).max())


def test_a_binding_replan_meets_the_kkt_conditions() -> None:
    """Far from the reference (0.8 rad), the unconstrained plan asks more than the effort
    limits: ProxQP solves the QP, a limit row is active and the KKT residual (computed by
    ``kkt_residual``, not the solver) is below :data:`KKT_TOLERANCE`."""
    law = ModelPredictive(ROBOT)
    q = default_trajectory(ROBOT).sample(0.0).q[None] + np.array([[0.8, -0.8]])
    qps = law.problems(_replan_input(law, q, np.zeros((1, 2))), terms_for(law))
    _, inside = qps.unconstrained()
    assert not inside[0]
    qp = qps.qp(0)
    solution = solve_qp(qp, max_iter=200, infeasibility_eps=1e-9)
    assert np.abs(solution.z).max() > 1e-6  # a row binds
    assert kkt_residual(qp, solution) < KKT_TOLERANCE


def test_a_run_whose_replan_cannot_hold_ends_alone_in_a_batch() -> None:
    """Run 1 of three starts where the position rows cannot hold (the single run fails at
    t = 0 naming the row): in a batch that run ends at t = 0 with the law's reason, and the two
    others equal their single runs (a second method: each simulated alone)."""
    offsets = np.array([[0.1, -0.1], [3.0, 3.0], [0.0, 0.3]])
    config = SimulationConfig(duration=0.15)
    trajectory = default_trajectory(ROBOT)
    fail = MPCGains(on_infeasible="fail")
    with pytest.raises(ControllerError) as alone:
        simulate(
            ModelPredictive(ROBOT, fail), Plant(ROBOT), trajectory,
            SimulationConfig(duration=0.15, q0_offset=(3.0, 3.0)),
        )  # fmt: skip
    assert "failed at t = 0 s" in str(alone.value) and "position range" in str(alone.value)
    batch = simulate_batch(
        ModelPredictive(ROBOT, fail), Plant(ROBOT), trajectory, config, q0_offsets=offsets, record=True
    )
    assert np.isnan(batch.diverged_at[[0, 2]]).all() and batch.diverged_at[1] == 0.0
    reason = batch.divergence[1]
    assert reason is not None and "the MPC replan at t = 0 s (run 1)" in reason, reason
    assert "cannot all hold" in reason and "position range" in reason, reason
    for i in (0, 2):
        single = simulate(
            ModelPredictive(ROBOT, fail), Plant(ROBOT), trajectory,
            SimulationConfig(duration=0.15, q0_offset=tuple(offsets[i])),
        )  # fmt: skip
        np.testing.assert_allclose(batch.q[i], single.q, rtol=0, atol=1e-12)


def test_a_batch_of_n_runs_equals_its_single_runs() -> None:
    """Three start offsets (one far enough for the limits to bind at its first replans) and
    per-run weights in one batch: each run equals its single run to rounding."""
    offsets = np.array([[0.1, -0.1], [0.8, -0.8], [0.0, 0.3]])
    weights = np.array([[1600.0, 160.0], [800.0, 80.0], [1600.0, 320.0]])
    config = SimulationConfig(duration=0.15)
    batch_law = ModelPredictive(ROBOT, MPCGains(weight_q=weights))
    batch = simulate_batch(
        batch_law, Plant(ROBOT), default_trajectory(ROBOT), config, q0_offsets=offsets, record=True
    )
    for i, offset in enumerate(offsets):
        law = ModelPredictive(ROBOT, MPCGains(weight_q=weights[i]))
        single = simulate(
            law,
            Plant(ROBOT),
            default_trajectory(ROBOT),
            SimulationConfig(duration=0.15, q0_offset=tuple(offset)),
        )
        np.testing.assert_allclose(batch.q[i], single.q, rtol=0, atol=1e-12)
        np.testing.assert_allclose(batch.tau_command[i], single.tau_command, rtol=0, atol=1e-9)


def test_the_torque_stays_within_the_effort_limit_from_a_far_start() -> None:
    """Every commanded torque of a run that starts 0.8 rad away is within the effort limit,
    and the plan's velocity rows keep every joint under its velocity limit (to RK4's rounding)."""
    law = ModelPredictive(ROBOT)
    run = simulate(
        law, Plant(ROBOT), default_trajectory(ROBOT), SimulationConfig(duration=0.3, q0_offset=(0.8, -0.8))
    )
    limits = joint_limits(ROBOT)
    assert limits.excess(EFFORT, run.tau_command).max() <= 0
    assert np.abs(run.tau_command[:, 0]).max() >= 0.95 * limits.effort[0]  # the planned limit was reached
    assert limits.excess(VELOCITY, run.v).max() < 1e-6


@pytest.mark.parametrize(
    ("gains", "words"),
    [
        ({"horizon": 0.0}, "horizon = 0.0 is invalid"),
        ({"horizon": -0.1}, "horizon = -0.1 is invalid"),
        ({"horizon": float("nan")}, "horizon = nan is invalid"),
        ({"horizon": 0.01}, "at least one knot interval (0.025 s)"),
        ({"horizon": np.array([0.2, 0.3])}, "one value of horizon for every run"),
    ],
)
def test_a_bad_horizon_is_refused(gains: dict, words: str) -> None:
    with pytest.raises(InvalidParameterError, match=words.replace("(", r"\(").replace(")", r"\)")):
        ModelPredictive(ROBOT, MPCGains(**gains))


def test_a_horizon_too_long_for_the_memory_is_refused_before_it_is_made(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv("TWOLINK_PIN_MEMORY", str(10**6))
    with pytest.raises(InvalidParameterError, match=r"fit in memory: .* MB needed .* 1 MB available"):
        ModelPredictive(ROBOT, MPCGains(horizon=10.0))


@pytest.mark.parametrize("period", [0.0005, 0.0015])
def test_a_replan_period_not_a_multiple_of_the_step_is_refused(period: float) -> None:
    law = ModelPredictive(ROBOT, MPCGains(replan_period=period))
    with pytest.raises(InvalidParameterError, match=r"mpc: update period.*multiple of the simulation step"):
        simulate(law, Plant(ROBOT), default_trajectory(ROBOT), SimulationConfig(duration=0.05))


def test_a_replan_that_cannot_hold_fails_at_once_naming_the_row() -> None:
    """Joint 1 starts 0.86 rad beyond its range: no torque within the limit brings it back by
    the first row time. With ``on_infeasible = "fail"`` the run fails at t = 0 naming the
    position row, within the iteration cap (as before relaxation existed)."""
    law = ModelPredictive(ROBOT, MPCGains(on_infeasible="fail"))
    with pytest.raises(ControllerError) as raised:
        simulate(
            law, Plant(ROBOT), default_trajectory(ROBOT), SimulationConfig(duration=0.1, q0_offset=(4.0, 0.0))
        )
    message = str(raised.value)
    assert "'mpc' failed at t = 0 s" in message
    assert "the position range [-3.14159, 3.14159] rad of joint 1 (joint1) at t + 0.005 s" in message
    iterations = int(message.split("failed after ")[1].split(" iterations")[0])
    assert iterations <= 200


def test_a_solver_that_stops_mid_run_fails_the_run_at_that_time(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """ProxQP allowed no iteration from t = 0.02 s on, while the effort limit binds (a 0.8-rad
    start): the replan it cannot finish fails the run there — exit status 1, one line naming
    the law, the time and what stopped — not a traceback and not a plan held from before."""
    from typing import Any

    import twolink_pin.controllers.mpc as law_module
    import twolink_pin.optimal.qp as qp_module
    from twolink_pin.cli import main

    real = law_module.solve_qp

    def starved(qp: Any, **kwargs: Any) -> Any:
        if float(kwargs["what"].split("t = ")[1].split(" s")[0]) >= 0.02:
            kwargs["max_iter"] = 0
        return real(qp, **kwargs)

    monkeypatch.setattr(law_module, "solve_qp", starved)
    monkeypatch.setattr(
        qp_module, "_infeasible_reason", lambda *args: None
    )  # a slow solve, not infeasibility
    argv = [
        "simulate",
        "mpc",
        "--duration",
        "0.1",
        "--q0-offset",
        "0.8",
        "-0.8",
        "--gain",
        "on_infeasible=fail",
    ]
    assert main(argv) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0], err
    assert "controller 'mpc' failed at t = 0.02 s" in err[0] and "ProxQP stopped with status" in err[0], err[
        0
    ]


def test_controllers_and_tune_list_its_gains_with_units(capsys: pytest.CaptureFixture[str]) -> None:
    """``twolink-pin controllers`` lists mpc's gains with their units; ``tune mpc`` has a control
    per gain (per joint for the weights and the feedback), limit_scale ranging over (0, 1]."""
    from twolink_pin.cli import main
    from twolink_pin.run_spec import gains_used
    from twolink_pin.tuning.knobs import knobs_of

    assert main(["controllers"]) == 0
    listed = next(line for line in capsys.readouterr().out.splitlines() if "knot_interval" in line)
    for shown in (
        "horizon [s]",
        "replan_period [s]",
        "weight_q [N·m/rad]",
        "weight_v [N·m·s/rad]",
        "kp [1/s²]",
    ):
        assert shown in listed
    law = ModelPredictive(ROBOT)
    knobs = {k.label: k for k in knobs_of(MPCGains, gains_used(law))}
    assert {"horizon [s]", "replan_period [s]", "weight_tau", "weight_q joint 2 [N·m/rad]"} <= set(knobs)
    assert (knobs["limit_scale"].low, knobs["limit_scale"].high, knobs["limit_scale"].value) == (
        0.0,
        1.0,
        0.998,
    )


def test_a_sweep_keeps_its_runs_when_one_replan_cannot_hold(
    tmp_path: object, capsys: pytest.CaptureFixture[str]
) -> None:
    """``sweep mpc`` whose draws put one start where the rows cannot hold (this seed: run 5,
    which alone fails at t = 0 with ``on_infeasible = "fail"``): the sweep finishes and writes
    every run; with the default ``relax`` that run relaxes its rows and finishes too (it used
    to end the whole sweep with exit 1)."""
    import json
    from pathlib import Path

    from twolink_pin.cli import main

    out = Path(str(tmp_path)) / "sweep"
    argv = ["sweep", "mpc", "--samples", "8", "--q0-offset", "1.5", "1.5", "--q0-spread", "1.5"]
    assert main([*argv, "--duration", "0.05", "--out", str(out), "--no-plot"]) == 0
    text = capsys.readouterr().out
    assert "8 runs" in text, text
    import csv

    rows = list(csv.DictReader((out / "runs.csv").open()))
    assert [r["diverged"] for r in rows] == ["0"] * 8
    q0 = (float(rows[5]["q0_offset1"]), float(rows[5]["q0_offset2"]))
    with pytest.raises(ControllerError, match="failed at t = 0 s"):  # that start alone fails
        simulate(
            ModelPredictive(ROBOT, MPCGains(on_infeasible="fail")), Plant(ROBOT), default_trajectory(ROBOT),
            SimulationConfig(duration=0.05, q0_offset=q0),
        )  # fmt: skip
    assert json.loads((out / "summary.json").read_text())["samples"] == 8


def test_a_duration_that_is_no_whole_number_of_steps_replans_every_ten_steps() -> None:
    """0.1003 s at dt = 1 ms is 100 steps of 1.003 ms (the engine stretches the step to end on
    the duration): the replanning period counts 10 configured steps, as the control period does,
    instead of being refused against the stretched step (``report --controller mpc`` failed so
    on the twolink's retimed reference, 0.5281 s)."""
    config = SimulationConfig(duration=0.1003)
    result = simulate(ModelPredictive(ROBOT), Plant(ROBOT), default_trajectory(ROBOT), config)
    names = list(result.state_names)
    replans = result.state[:, names.index("replans")]
    replanned = result.t[np.flatnonzero(np.diff(replans)) + 1]  # when the count went up
    np.testing.assert_allclose(replanned, 10 * (0.1003 / 100) * np.arange(1, 11), rtol=0, atol=1e-12)
