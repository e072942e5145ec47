"""``qp-osc`` (twolink_pin/controllers/qp_osc.py): osc's task and posture as a QP within the
joint limits.

* Without an active limit it is ``osc``: over seeded states near each arm's reference at
  which osc's own torque meets every limit (checked here from ``pin.aba`` and the robot's
  limits, not from the law's QP), the two torques agree to 1e-9 N·m — the law's answer and
  ProxQP's answer to the same QP (at eps 1e-12) both.
* With an active limit the limit holds: from the returned torque and ``pin.aba`` (the arm's
  acceleration recomputed), the torque box, the acceleration box and both dampers hold to
  1e-8 (N·m, rad/s²: ten times the solver's 1e-9), at a Panda state heading for joint 4's
  range with the effort limits cut to 40 %.
* The KKT residual of that QP, computed by ``kkt_residual`` independently of ProxQP, is below
  1e-6 (complementarity weighs a multiplier of up to ~10³ by a distance of ~1e-9).
* A batch of N runs equals N single runs (to rounding: each run's QP is its own).
"""

from __future__ import annotations

import re
from dataclasses import replace
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from twolink_pin import (
    SimulationConfig,
    default_trajectory,
    load_robot,
    make_scenario,
    simulate,
    simulate_batch,
)
from twolink_pin.controllers import QPOperationalSpace, load_controller
from twolink_pin.errors import ControllerError, InvalidParameterError
from twolink_pin.limits import EFFORT, POSITION, joint_limits
from twolink_pin.optimal import kkt_residual, solve_qp, unconstrained_minimiser
from twolink_pin.simulation import law_input, terms_for

ROBOTS = ("panda", "ur5", "kinova", "twolink")
"""Arms of the property test (the Z1's reference passes a wrist singularity, where osc damps Λ)."""


class Arm:
    """A robot, its reference, osc and qp-osc with default gains, and one Data for pin.aba."""

    def __init__(self, name: str) -> None:
        self.robot = load_robot(name)
        self.reference = default_trajectory(self.robot)
        self.osc = load_controller("osc")(self.robot)
        self.qp = QPOperationalSpace(self.robot)
        self.limits = joint_limits(self.robot)
        self.data = self.robot.model.createData()

    def state(self, seed: int, spread: float = 0.05) -> tuple[Any, np.ndarray]:
        """The law input at a random time of the reference, the state off it by up to
        ``spread`` rad and 4 × spread rad/s; and the state's (q, q̇) as one row."""
        rng = np.random.default_rng(seed)
        t = float(rng.uniform(0.0, 4.0))
        s = self.reference.sample(np.array([t]))
        qd, vd, ad = (np.asarray(a, dtype=float).reshape(1, -1) for a in (s[0], s[1], s[2]))
        q = qd + rng.uniform(-spread, spread, qd.shape)
        v = vd + rng.uniform(-4 * spread, 4 * spread, qd.shape)
        z = np.zeros((1, self.qp.state_size))  # qp-osc's observer, at rest (osc reads no state)
        return law_input(self.osc, t, q, v, z, qd, vd, ad), np.concatenate((q, v))

    def acceleration(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """q̈ [rad/s²] of the arm under ``tau`` [N·m] (Pinocchio's ABA: the plant's dynamics)."""
        return pin.aba(self.robot.model, self.data, q, v, tau).copy()

    def excess(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, scale: float = 1.0) -> dict[str, float]:
        """How far ``tau`` and the acceleration it gives go past each limit the law keeps
        (positive: beyond), with the default horizons: computed from the limits alone."""
        lim, g = self.limits, self.qp.gains
        h, hv = np.asarray(g.position_horizon).ravel(), np.full(self.robot.nv, float(g.velocity_horizon))
        a = self.acceleration(q, v, tau)
        ahead = q + 2 * h * v + h * h * a
        with np.errstate(invalid="ignore"):
            return {
                "effort": float(np.max(np.abs(tau) - scale * lim.effort)),
                "acceleration": float(np.nanmax(np.abs(a) - scale * lim.acceleration)),
                "velocity": float(np.nanmax(np.abs(v + hv * a) - scale * lim.velocity)),
                "position": float(np.max(np.maximum(ahead - lim.position_upper, lim.position_lower - ahead))),
            }


ARMS: dict[str, Arm] = {}


def arm(name: str) -> Arm:
    if name not in ARMS:
        ARMS[name] = Arm(name)
    return ARMS[name]


@pytest.mark.parametrize("name", ROBOTS)
@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_without_an_active_limit_qp_osc_is_osc(name: str, seed: int) -> None:
    a = arm(name)
    x, _ = a.state(seed)
    damped = a.osc.damped_evaluations
    tau_osc = a.osc.compute(x, terms_for(a.osc)).tau
    assume(a.osc.damped_evaluations == damped)  # away from a singularity (osc damps Λ there)
    assume(max(a.excess(x.q[0], x.v[0], tau_osc[0]).values()) < -1e-6)  # osc meets every limit
    tau_qp = a.qp.compute(x, terms_for(a.qp)).tau
    np.testing.assert_allclose(tau_qp, tau_osc, rtol=0, atol=1e-9)
    # the same QP through ProxQP (no unconstrained start), at eps 1e-12: at its default 1e-9 a
    # residual in the posture's weakest direction (w M̂ ≈ 7e-5 kg·m² at the Panda's wrist) is 4e-8 N·m
    terms = terms_for(a.qp)
    solution = solve_qp(a.qp.problems(x, terms)[0], eps=1e-12)
    tau_prox = terms.mass(x.q)[0] @ solution.x + terms.bias(x.q, x.v)[0]
    np.testing.assert_allclose(tau_prox, tau_osc[0], rtol=0, atol=1e-9)


def _near_joint_4s_range() -> tuple[Arm, QPOperationalSpace, Any]:
    """The Panda reaching forward, 0.1 rad inside joint 4's upper limit (an almost straight
    elbow) at 0.6 rad/s toward it, its reference the same state coasting on (q̈_d = 0), and a
    qp-osc whose effort limits are cut to 40 %."""
    a = arm("panda")
    tight = QPOperationalSpace(a.robot, a.qp.Gains(limit_scale=0.4))
    q = np.array([[0.0, 0.6, 0.0, a.limits.position_upper[3] - 0.1, 0.0, 1.2, 0.785]])
    v = np.array([[0.0, -0.3, 0.0, 0.6, 0.0, 0.3, 0.0]])
    z = np.zeros((1, tight.state_size))
    return a, tight, law_input(a.osc, 0.0, q, v, z, q, v, np.zeros_like(q))


def test_an_active_limit_holds_to_the_solvers_tolerance() -> None:
    a, tight, x = _near_joint_4s_range()
    q, v = x.q[0], x.v[0]
    tau_osc = a.osc.compute(x, terms_for(a.osc)).tau[0]
    unconstrained = a.excess(q, v, tau_osc, scale=0.4)
    assert unconstrained["position"] > 0.05 and unconstrained["effort"] > 1.0  # osc would cross both
    tau = tight.compute(x, terms_for(tight)).tau[0]
    held = a.excess(q, v, tau, scale=0.4)
    assert max(held.values()) < 1e-8, held
    assert abs(held["position"]) < 1e-8  # the position damper is the active one: on its bound
    acceleration = a.acceleration(q, v, tau)
    dt = 1e-3  # and one step of 1 ms ahead stays inside the range and the velocity box
    assert np.all(q + dt * v + 0.5 * dt * dt * acceleration <= a.limits.position_upper)
    assert np.all(np.abs(v + dt * acceleration) <= a.limits.velocity)


def test_the_kkt_residual_of_an_active_qp_is_below_1e_6() -> None:
    _, tight, x = _near_joint_4s_range()
    qp = tight.problems(x, terms_for(tight))[0]
    solution = solve_qp(qp, unconstrained_first=True)
    assert solution.iterations > 0 and np.count_nonzero(solution.z) > 0  # ProxQP, limits active
    active = [tight.labels[i] for i in np.flatnonzero(solution.z)]
    assert any("position range" in label and "panda_joint4" in label for label in active), active
    assert kkt_residual(qp, solution) < 1e-6


def test_a_batch_equals_its_single_runs() -> None:
    """Four states (one with active limits) on one reference, computed together and one by one:
    the same torques to 1e-12 N·m (rounding: BLAS may sum a matrix-vector product held in a
    stack in another order than the same product on its own array); and a 0.1-s batch of three
    runs from three offsets equals its three single runs (1e-9 N·m, 1e-12 rad: the tolerance
    tests/test_batch.py gives every law)."""
    a = arm("panda")
    near = _near_joint_4s_range()[2]
    x, _ = a.state(1)
    rng = np.random.default_rng(0)
    q = np.concatenate((x.q, x.q + rng.uniform(-0.3, 0.3, x.q.shape), near.q, near.q))
    v = np.concatenate((x.v, x.v, near.v, -near.v))
    batch = x._replace(q=q, v=v, z=np.zeros((4, a.qp.state_size)))
    active = [unconstrained_minimiser(p) is None for p in a.qp.problems(batch, terms_for(a.qp, 4))]
    assert active[2] and not active[0]  # ProxQP for one run, the closed form for another
    together = a.qp.compute(batch, terms_for(a.qp, 4)).tau
    alone = [a.qp.compute(x._replace(q=q[i : i + 1], v=v[i : i + 1]), terms_for(a.qp)).tau for i in range(4)]
    np.testing.assert_allclose(together, np.concatenate(alone), rtol=0, atol=1e-12)
    law, plant = make_scenario("qp-osc", a.robot)
    offsets = np.array([[0.3] * 7, [-0.3] * 7, [0.0, 0.3, 0.0, -0.3, 0.0, 0.3, 0.0]])
    config = SimulationConfig(duration=0.1, dt=1e-3)
    runs = simulate_batch(law, plant, a.reference, config, q0_offsets=offsets, progress=False, record=True)
    assert runs.tau_command is not None and runs.q is not None
    for i, offset in enumerate(offsets):
        single = simulate(law, plant, a.reference, replace(config, q0_offset=tuple(offset)))
        np.testing.assert_allclose(runs.tau_command[i], single.tau_command, rtol=0, atol=1e-9)
        np.testing.assert_allclose(runs.q[i], single.q, rtol=0, atol=1e-12)


def test_gains_beyond_one_are_refused() -> None:
    with pytest.raises(
        InvalidParameterError, match=r"posture_weight = 1.5 is invalid: .*a fraction 0 < value <= 1"
    ):
        QPOperationalSpace(arm("panda").robot, arm("panda").qp.Gains(posture_weight=1.5))
    with pytest.raises(InvalidParameterError, match=r"limit_scale\[1\] = 2.0 is invalid"):
        QPOperationalSpace(arm("panda").robot, arm("panda").qp.Gains(limit_scale=[0.5, 2.0]))


def test_controllers_and_tune_list_its_gains_with_units(capsys: pytest.CaptureFixture[str]) -> None:
    """``twolink-pin controllers`` lists qp-osc's gains with their units; ``tune qp-osc`` has a
    control per gain (per joint for the horizons, in s), the fractions ranging over (0, 1]."""
    from twolink_pin.cli import main
    from twolink_pin.run_spec import gains_used
    from twolink_pin.tuning.knobs import knobs_of

    assert main(["controllers"]) == 0
    listed = next(line for line in capsys.readouterr().out.splitlines() if "posture_weight" in line)
    for shown in (
        "kp [1/s²] (3 × 3 matrix)",
        "kp_null [1/s²]",
        "position_horizon [s]",
        "velocity_horizon [s]",
    ):
        assert shown in listed
    knobs = {k.label: k for k in knobs_of(QPOperationalSpace.Gains, gains_used(arm("panda").qp))}
    assert knobs["position_horizon joint 4 [s]"].value == pytest.approx(2.175 / 12.5)  # v / a of joint 4
    assert (knobs["posture_weight"].low, knobs["posture_weight"].high) == (0.0, 1.0)
    assert (knobs["limit_scale"].low, knobs["limit_scale"].high, knobs["limit_scale"].value) == (
        0.0,
        1.0,
        1.0,
    )


def test_limits_that_cannot_hold_fail_the_run_naming_the_constraint() -> None:
    """Effort limits at 1 % cannot hold the Panda up within its acceleration limits (at 1 %):
    the QP has no solution. With ``on_infeasible = "fail"`` the run's torque is NaN and its
    reason names a row by its label and the time (the engine ends that run with it); with the
    default ``relax`` the torque is finite and within the 1 % effort box, and the law records
    the acceleration rows it let go (the only rows in conflict with the effort box here)."""
    a = arm("panda")
    x, _ = a.state(3)
    weak = QPOperationalSpace(a.robot, a.qp.Gains(limit_scale=0.01, on_infeasible="fail"))
    weak.initial_state()
    assert np.isnan(weak.compute(x, terms_for(weak)).tau).all()
    reason = weak.run_failure(0)
    assert reason is not None and re.search(
        r"the QP at t = .* s failed .* cannot all hold: .* of joint \d", reason
    )
    relaxing = QPOperationalSpace(a.robot, a.qp.Gains(limit_scale=0.01))
    relaxing.initial_state()
    tau = relaxing.compute(x, terms_for(relaxing)).tau[0]
    assert np.abs(tau).max() > 0 and (np.abs(tau) <= 0.01 * a.limits.effort * (1 + 1e-9)).all()
    relaxed = relaxing.run_relaxations(0)
    assert relaxed is not None and relaxed.instants == 1
    assert np.nanmax(relaxed.largest[2]) > 0  # acceleration


def test_an_infeasible_first_qp_fails_within_the_iteration_cap() -> None:
    """The UR5 at ``limit_scale = 1e-12`` (a hostile run): its first QP cannot hold. With
    ``fail`` the run fails at t = 0 within 200 of ProxQP's outer iterations (about a thousand of
    its inner ones; uncapped it took 11 million and 131 s); with ``relax`` it runs, every
    commanded torque within 1e-12 of each limit, and says where it relaxed."""
    robot = load_robot("ur5")
    reference = default_trajectory(robot)
    config = SimulationConfig(duration=0.01)
    law = QPOperationalSpace(robot, QPOperationalSpace.Gains(limit_scale=1e-12, on_infeasible="fail"))
    plant = make_scenario("qp-osc", robot)[1]
    with pytest.raises(ControllerError) as failed:
        simulate(law, plant, reference, config)
    message = str(failed.value)
    assert "'qp-osc' failed at t = 0 s" in message
    iterations = int(message.split("failed after ")[1].split(" iterations")[0])
    assert iterations <= 2000  # 200 of ProxQP's outer iterations (it counts its inner ones)
    law = QPOperationalSpace(robot, QPOperationalSpace.Gains(limit_scale=1e-12))
    run = simulate(law, plant, reference, config)
    assert (np.abs(run.tau_command) <= 1e-12 * joint_limits(robot).effort * (1 + 1e-6)).all()
    assert run.relaxed is not None and run.relaxed.first_time[~np.isnan(run.relaxed.first_time)].min() == 0.0


def test_a_damper_of_horizon_1e_12_s_near_a_range_is_solved_within_the_caps() -> None:
    """``position_horizon = 1e-12`` s with the Panda's elbow started 1 mrad inside its range (a
    hostile run: it ran for more than 300 s). The damper then asks for bounds of order 1e21 rad/s²:
    read as none on their loose side and as 1e12 on the other, and ProxQP's inner iterations capped,
    each QP ends within its caps — the run finishes, its commanded torque within the effort limits,
    the elbow inside its range to RK4's rounding."""
    robot = load_robot("panda")
    limits = joint_limits(robot)
    reference = default_trajectory(robot)
    offset = np.zeros(7)
    offset[3] = limits.position_lower[3] + 1e-3 - reference.sample(0.0).q[3]
    law = QPOperationalSpace(robot, QPOperationalSpace.Gains(position_horizon=1e-12))
    plant = make_scenario("qp-osc", robot)[1]
    run = simulate(law, plant, reference, SimulationConfig(duration=0.02, q0_offset=offset))
    assert np.isfinite(run.q).all() and run.t[-1] == pytest.approx(0.02)
    assert (np.abs(run.tau_command) <= limits.effort * (1 + 1e-9)).all()
    assert run.q[:, 3].min() >= limits.position_lower[3] - 1e-6


def test_a_run_whose_qp_cannot_hold_ends_alone_in_a_batch() -> None:
    """Three Panda runs with ``fail`` and per-run headroom (1, 0.01, 1): the middle one cannot
    hold and ends at t = 0 with the law's reason; the others equal their single runs (it used to
    end the whole batch, and a sweep with it)."""
    robot = load_robot("panda")
    gains = QPOperationalSpace.Gains(limit_scale=[1.0, 0.01, 1.0], on_infeasible="fail")
    law = QPOperationalSpace(robot, gains)
    plant = make_scenario("qp-osc", robot)[1]
    config = SimulationConfig(duration=0.01)
    batch = simulate_batch(
        law, plant, default_trajectory(robot), config, q0_offsets=np.zeros((3, 7)), record=True
    )
    assert np.isnan(batch.diverged_at[[0, 2]]).all() and batch.diverged_at[1] == 0.0
    assert batch.divergence[1] is not None and "cannot all hold" in batch.divergence[1]
    single = simulate(
        QPOperationalSpace(robot), plant, default_trajectory(robot), replace(config, q0_offset=0.0)
    )
    np.testing.assert_allclose(batch.q[0], single.q, rtol=0, atol=1e-9)


def test_a_solver_that_stops_mid_run_fails_the_run_at_that_time(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """ProxQP allowed no iteration (and no closed form) once the run is past 0.05 s, and
    ``on_infeasible = "fail"``: the QP it cannot finish fails the run there — exit status 1, one
    line on stderr naming the law, the time and what stopped — not a traceback and not a torque
    held from the step before."""
    import twolink_pin.controllers.qp_osc as law_module
    import twolink_pin.optimal.qp as qp_module
    from twolink_pin.cli import main

    real = law_module.solve_qp

    def starved(qp: Any, **kwargs: Any) -> Any:
        if float(kwargs["what"].split("t = ")[1].split(" s")[0]) <= 0.05:
            return real(qp, **kwargs)
        return real(qp, **{**kwargs, "max_iter": 0, "unconstrained_first": False})

    monkeypatch.setattr(law_module, "solve_qp", starved)
    monkeypatch.setattr(
        qp_module, "_infeasible_reason", lambda *args: None
    )  # a slow solve, not infeasibility
    argv = ["simulate", "qp-osc", "--robot", "panda", "--duration", "0.2", "--gain", "on_infeasible=fail"]
    assert main(argv) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0], err
    assert "controller 'qp-osc' failed at t = 0.05" in err[0] and "ProxQP stopped with status" in err[0], err[
        0
    ]


def test_per_run_gains_give_each_run_its_own_qp() -> None:
    """One law with posture_weight (0.01, 1) and limit_scale (1, 0.4) per run (a sweep's draws,
    beside osc's matrix gains) drives two runs at the state near joint 4's range as the two
    single laws do; the weight and the headroom change the answer there."""
    a, _, near = _near_joint_4s_range()
    both = QPOperationalSpace(a.robot, a.qp.Gains(posture_weight=[0.01, 1.0], limit_scale=[1.0, 0.4]))
    assert both.runs == 2
    x = near._replace(
        q=np.repeat(near.q, 2, axis=0), v=np.repeat(near.v, 2, axis=0), z=np.zeros((2, both.state_size))
    )
    together = both.compute(x, terms_for(both, 2)).tau
    for i, (w, f) in enumerate([(0.01, 1.0), (1.0, 0.4)]):
        single = QPOperationalSpace(a.robot, a.qp.Gains(posture_weight=w, limit_scale=f))
        np.testing.assert_allclose(
            together[i], single.compute(near, terms_for(single)).tau[0], rtol=0, atol=1e-12
        )
    assert np.abs(together[0] - together[1]).max() > 1.0


@pytest.mark.parametrize("name", ["ur5", "panda", "kinova", "z1", "twolink"])
def test_it_runs_on_every_arm_osc_runs_on_within_the_limits(name: str) -> None:
    """0.2 s of each arm's default reference from 0.05 rad off: every commanded torque within
    its limit and every joint inside its range at every sample (the Z1's reference passes a wrist
    singularity, where the QP's posture term holds the damped direction)."""
    robot = load_robot(name)
    law, plant = make_scenario("qp-osc", robot)
    result = simulate(law, plant, default_trajectory(robot), SimulationConfig(duration=0.2, q0_offset=0.05))
    limits = joint_limits(robot)
    assert np.all(np.isfinite(result.tau_command))
    assert limits.excess(EFFORT, result.tau_command).max() <= 1e-9
    assert limits.excess(POSITION, result.q).max() < 0
