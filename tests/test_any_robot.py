"""Any arm from URDF, end to end: the named robots of example-robot-data, their base parameters,
the numerical inverse kinematics, trajectory files, and the adaptive law on arms under gravity.

Independent checks: base-parameter counts from the theory of planar arms, ``Y_β β = Y_π π`` and
the rank of a freshly stacked regressor (not the one the map was built from), Pinocchio's own
continuous-joint model against our unbounded-revolute one, the total mass of the reduced Panda,
forward kinematics of the IK's answers, and the Lyapunov function of Slotine–Li along a run.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin import (
    InvalidParameterError,
    InvalidURDFError,
    InverseKinematicsError,
    RobotModel,
    SimulationConfig,
    load_robot,
    make_scenario,
    simulate,
)
from twolink_pin.cli import main
from twolink_pin.kinematics import end_effector_position, solve_position
from twolink_pin.model import catalog
from twolink_pin.model.base_parameters import BaseParameterMap
from twolink_pin.model.parameters import inertial_parameters
from twolink_pin.trajectory import (
    check_trajectory_limits,
    default_trajectory,
    read_trajectory_file,
)
from twolink_pin.twolink.reference import REPORT_P

NAMED = ("twolink", "asr_twodof", "double_pendulum", "kinova", "panda", "ur5", "z1")
"""The catalog: the twolink first, then its profile files (robots/*.toml) by name."""


@pytest.fixture(scope="module", params=NAMED)
def named(request: pytest.FixtureRequest):
    return load_robot(request.param)


def _random_states(model: pin.Model, n: int, seed: int):
    rng = np.random.default_rng(seed)
    lower = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -np.pi)
    upper = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, np.pi)
    for _ in range(n):
        yield rng.uniform(lower, upper), rng.normal(size=model.nv), rng.normal(size=model.nv)


# ------------------------------------------------------------------------ the catalog


def test_the_catalog_names_the_seven_robots_the_default_first() -> None:
    assert catalog.names() == NAMED


def test_every_named_robot_loads_with_one_angle_per_joint(named) -> None:
    """nq == nv everywhere (continuous joints made unbounded revolute), a home inside the limits,
    and the default trajectory inside the position limits over its whole period."""
    assert (
        named.nq
        == named.nv
        == {"twolink": 2, "double_pendulum": 2, "asr_twodof": 2}.get(
            named.name, {"ur5": 6, "panda": 7, "kinova": 6, "z1": 6}.get(named.name)
        )
    )
    lower, upper = named.model.lowerPositionLimit, named.model.upperPositionLimit
    assert np.all((lower <= named.home) & (named.home <= upper))
    check_trajectory_limits(named, default_trajectory(named))


def test_an_unknown_name_lists_the_valid_ones() -> None:
    with pytest.raises(InvalidURDFError) as err:
        load_robot("ur55")
    for name in NAMED:
        assert name in str(err.value)


def test_kinova_continuous_joints_have_pinocchios_dynamics() -> None:
    """The Kinova's four continuous joints, one unbounded angle each, give the same M(q), C(q, q̇) q̇
    and g(q) as Pinocchio's own (cos, sin) model of the same URDF, at random states."""
    robot = load_robot("kinova")
    native = pin.buildModelFromUrdf(str(robot.urdf_path))
    assert native.nq == 9 and native.nv == 6  # three continuous joints in the URDF's arm chain
    unbounded = np.flatnonzero(np.isinf(robot.model.lowerPositionLimit))
    assert unbounded.size == native.nq - native.nv
    d1, d2 = robot.create_data(), native.createData()
    for q, v, a in _random_states(robot.model, 5, seed=3):
        q = np.where(np.isinf(robot.model.lowerPositionLimit), np.random.default_rng(1).uniform(-9, 9), q)
        q_native = np.concatenate(
            [
                [np.cos(q[i]), np.sin(q[i])] if native.nqs[j] == 2 else [q[i]]
                for j, i in zip(range(1, native.njoints), range(robot.nv))
            ]
        )
        np.testing.assert_allclose(
            pin.rnea(robot.model, d1, q, v, a), pin.rnea(native, d2, q_native, v, a), rtol=1e-12, atol=1e-12
        )


def test_panda_fingers_are_locked_and_their_mass_carried() -> None:
    robot = load_robot("panda")
    full = pin.buildModelFromUrdf(str(robot.urdf_path))
    assert robot.nv == 7 and full.nv == 9
    assert pin.computeTotalMass(robot.model) == pytest.approx(pin.computeTotalMass(full), rel=1e-12)


def test_a_zero_effort_limit_means_no_limit_and_says_so(capsys: pytest.CaptureFixture[str]) -> None:
    assert np.all(np.isinf(load_robot("double_pendulum").torque_limits))
    assert main(["robots"]) == 0
    out = capsys.readouterr().out
    assert "double_pendulum" in out and "effort limits (none, none)" in out and "no torque check" in out


# ------------------------------------------------------------------- base parameters


@pytest.mark.parametrize(("name", "count"), [("twolink", 4), ("asr_twodof", 4), ("double_pendulum", 6)])
def test_base_parameter_counts_of_planar_arms_match_the_theory(name: str, count: int) -> None:
    """A planar 2R arm whose plane is horizontal has 4 base parameters (ZZ1 + l1² m2, ZZ2, mx2,
    my2); under gravity in its plane 2 more (mx1 + l1 m2, my1)."""
    assert BaseParameterMap(load_robot(name).model).size == count


def test_y_beta_beta_equals_y_pi_pi_and_has_full_column_rank(named) -> None:
    """At fresh random states (another seed than the map's): Y_π π = Y_β β to 1e-10 of the
    torque scale; the stacked Y_π has n_β singular values above 1e-6 of the largest and the
    rest below 1e-11 (a clear gap: the Kinova's URDF writes π as 3.14159265359, which leaves
    two directions at 1e-13, numerically nonzero and physically unidentifiable); Y_β has full
    column rank."""
    model = named.model
    base = BaseParameterMap(model)
    pi, beta = inertial_parameters(model), base.values(model)
    data = model.createData()
    stacked = []
    for q, v, a in _random_states(model, max(30, 3 * base.size // model.nv), seed=12345):
        Y = pin.computeJointTorqueRegressor(model, data, q, v, a).copy()
        stacked.append(Y)
        tau = Y @ pi
        np.testing.assert_allclose(
            Y @ base.matrix @ beta, tau, rtol=0, atol=1e-10 * max(1.0, np.abs(tau).max())
        )
        np.testing.assert_allclose(
            pin.rnea(model, data, q, v, a), tau, rtol=0, atol=1e-9 * max(1.0, np.abs(tau).max())
        )
    W = np.vstack(stacked)
    sv = np.linalg.svd(W, compute_uv=False) / np.linalg.norm(W, 2)
    assert sv[base.size - 1] > 1e-6 and (base.size == sv.size or sv[base.size] < 1e-11)
    s = np.linalg.svd(W @ base.matrix, compute_uv=False)
    assert s[-1] > 1e-8 * s[0]


def test_the_twolinks_report_parameters_from_its_base_parameters() -> None:
    """The twolink's base parameters are (link1.Izz + l1² link2.m, link2.mcx, link2.mcy,
    link2.Izz) with Izz about the joints. Its centre of mass lies on the link's x axis
    (mcy = 0), so the report's three lumped parameters are p1 = β1 + β4, p2 = β4,
    p3 = l1 β2: (3.4, 0.4, 0.3) kg·m², equal to the lumped map's p."""
    robot = load_robot("twolink")
    base = BaseParameterMap(robot.model)
    beta = dict(zip(base.names, base.values(robot.model)))
    l1 = float(robot.link_lengths[0])
    assert list(beta) == [f"link1.Izz + {l1**2:.4g} link2.m", "link2.mcx", "link2.mcy", "link2.Izz"]
    b1, b2, b3, b4 = beta.values()
    assert b3 == pytest.approx(0.0, abs=1e-15)
    p = np.array([b1 + b4, b4, l1 * b2])
    np.testing.assert_allclose(p, robot.p, rtol=1e-12)
    np.testing.assert_allclose(p, list(REPORT_P.values()), rtol=1e-12)


def test_info_json_lists_the_base_parameters_and_friction_on_request(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["info", "--robot", "ur5", "--json", "--friction"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["base_parameters"]["count"] == len(info["base_parameters"]["names"]) == 36
    assert (
        info["friction_parameters"]["names"][:2] == ["V1", "V2"]
        and len(info["friction_parameters"]["names"]) == 12
    )


# ----------------------------------------------------------------- inverse kinematics


@settings(max_examples=25, deadline=None)
@given(st.sampled_from(("ur5", "panda", "z1", "twolink")), st.integers(0, 2**31 - 1))
def test_ik_round_trip_to_1e_9_m(name: str, seed: int) -> None:
    """A point the arm reaches (FK of a configuration near home) is found again from home to 1e-9 m."""
    robot = _robot(name)
    rng = np.random.default_rng(seed)
    q = np.clip(
        robot.home + rng.uniform(-0.5, 0.5, robot.nv),
        robot.model.lowerPositionLimit,
        robot.model.upperPositionLimit,
    )
    target = end_effector_position(robot, q)[: 2 if name == "twolink" else 3]
    try:
        solution = solve_position(robot, target, robot.home)
    except InverseKinematicsError as err:
        assert "singular" in err.reason  # the one accepted failure: a (near-)singular answer
        return
    assert np.linalg.norm(end_effector_position(robot, solution)[: target.size] - target) <= 1e-9
    assert np.all(solution >= robot.model.lowerPositionLimit) and np.all(
        solution <= robot.model.upperPositionLimit
    )


@functools.cache
def _robot(name: str) -> RobotModel:
    """The catalog's robot, loaded once per worker when a test first needs it (not at collection)."""
    return load_robot(name)


def test_ik_reports_unreachable_and_singular_targets() -> None:
    ur5 = _robot("ur5")
    with pytest.raises(InverseKinematicsError, match=r"not reached: the closest .* m away"):
        solve_position(ur5, (2.0, 0.0, 0.0), ur5.home)
    twolink = _robot("twolink")
    reach = float(np.sum(twolink.link_lengths))
    with pytest.raises(InverseKinematicsError, match="singular configuration"):
        solve_position(twolink, (reach, 0.0), np.array([0.1, 0.2]))


# -------------------------------------------------------------------- trajectory files


def _write(path: Path, document: dict) -> Path:
    path.write_text(json.dumps(document))
    return path


def test_a_joint_via_file_is_the_trajectory_it_describes(tmp_path: Path) -> None:
    robot = _robot("ur5")
    via = [list(robot.home + d) for d in (0.0, 0.2, 0.0, -0.2, 0.0)]
    trajectory = read_trajectory_file(
        _write(tmp_path / "v.json", {"times": [0, 1, 2, 3, 4], "joints": via}), robot
    )
    np.testing.assert_allclose(trajectory.sample(np.arange(5.0)).q, via, atol=1e-9)
    toml = tmp_path / "v.toml"
    toml.write_text("times = [0, 1, 2, 3, 4]\njoints = " + json.dumps(via) + "\nperiod = 5.0\n")
    assert read_trajectory_file(toml, robot).period == 5.0


def test_a_cartesian_via_file_passes_through_its_points(tmp_path: Path) -> None:
    robot = _robot("ur5")
    square = [[0.45, 0.1, 0.4], [0.45, -0.1, 0.4], [0.45, -0.1, 0.25], [0.45, 0.1, 0.25], [0.45, 0.1, 0.4]]
    path = _write(tmp_path / "square.json", {"times": [0, 1, 2, 3, 4], "positions": square})
    trajectory = read_trajectory_file(path, robot)
    for k, t in enumerate(range(5)):
        q = trajectory.sample(float(t)).q
        assert np.linalg.norm(end_effector_position(robot, q) - square[k]) < 1e-8


@pytest.mark.parametrize(
    ("document", "message"),
    [
        ({"times": [0, 1], "joints": [[0, 0, 0], [0, 0, 0]]}, r"joints\[0\].*expected 2 joint positions"),
        (
            {"times": [0, 1, 1], "joints": [[0, 0]] * 3},
            r"times\[2\] = 1\.0 is invalid: expected strictly increasing",
        ),
        (
            {"times": [0, 1], "joints": [[0, 0], [0, 4.0]]},
            r"joints\[1\]\[1\] = 4\.0 .* limits \[-3\.14159, 3\.14159\] rad",
        ),
        (
            {"times": [0, 1], "joints": [[0, 0], [0, 1.0]]},
            r"joints\[1\] = \[0, 1\.0\] .* must end where it starts",
        ),
        ({"times": [0, 1], "joints": [[0, 0], [0, 0]], "speed": 3}, r"speed .* only the keys"),
        ({"times": [0, 1], "positions": [[5.0, 0.0], [0.3, 0.0]]}, r"via point 0: not reached"),
        ({"times": [0, 1]}, r"exactly one of 'joints' \(rad\) and 'positions' \(m\)"),
    ],
)
def test_bad_via_files_are_refused_with_the_value_and_the_limit(
    tmp_path: Path, document: dict, message: str
) -> None:
    with pytest.raises((InvalidParameterError, InverseKinematicsError), match=message):
        read_trajectory_file(_write(tmp_path / "bad.json", document), _robot("twolink"))


def test_a_via_file_whose_motion_leaves_the_limits_between_points_is_refused(tmp_path: Path) -> None:
    """Via points inside the limits, but the polynomial through them overshoots a limit."""
    path = _write(tmp_path / "o.json", {"times": [0, 0.4, 1], "joints": [[0, 0], [3.0, 0], [0, 0]]})
    with pytest.raises(InvalidParameterError, match=r"q1\(.* s\) = 3\.\d+ rad.* between the via points"):
        read_trajectory_file(path, _robot("twolink"))


# ------------------------------------------------------------- adaptive on arms in gravity


def _lyapunov(robot, result, controller) -> tuple[np.ndarray, np.ndarray]:
    """V = ½ sᵀ M(q) s + ½ p̃ᵀ Γ⁻¹ p̃ along the run, and −sᵀ K s (its derivative in theory)."""
    gains = controller.gains
    lam, k = float(gains.lam), np.asarray(gains.k)[0]  # K, (nv, nv)
    inv_gamma = np.ravel(gains.gamma)  # Γ = diag(1/γ): Γ⁻¹ = diag(γ)
    data = robot.create_data()
    e, edot = result.q - result.q_des, result.v - result.v_des
    s = edot + lam * e
    p_err = result.p_hat - result.p_true
    V = np.empty(len(result.t))
    for i, q in enumerate(result.q):
        M = pin.crba(robot.model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        V[i] = 0.5 * s[i] @ M @ s[i] + 0.5 * np.sum(inv_gamma * p_err[i] ** 2)
    return V, -np.einsum("ij,jk,ik->i", s, k, s)


@pytest.mark.parametrize(("name", "duration"), [("double_pendulum", 6.0), ("ur5", 4.0)])
def test_adaptive_tracks_under_gravity_with_v_dot_le_0(name: str, duration: float) -> None:
    """Slotine–Li from p̂(0) = 0.5 β: V never increases beyond the integration error (1e-6 of
    V(0) per step), its decrease equals ∫ sᵀ K s dt to 1 %, and the tracking error shrinks."""
    robot = load_robot(name)
    controller, plant = make_scenario("adaptive", robot)
    np.testing.assert_allclose(controller.initial_state(), 0.5 * robot.p)
    result = simulate(controller, plant, default_trajectory(robot), SimulationConfig(duration=duration))
    V, V_dot = _lyapunov(robot, result, controller)
    assert np.diff(V).max() <= 1e-6 * V[0]
    dt = result.dt
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (V_dot[1:] + V_dot[:-1]) * dt)])
    np.testing.assert_allclose(V - V[0], integral, atol=0.01 * (V[0] - V[-1]))
    e = np.abs(result.q - result.q_des).max(axis=1)
    assert e[-int(1.0 / dt) :].max() < 0.5 * e[: int(0.5 / dt)].max()


@pytest.mark.slow
def test_simulate_adaptive_on_the_ur5_tracks_within_its_limits(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", "adaptive", "--robot", "ur5", "--duration", "12", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert max(out["metrics"]["final_period_max_abs_e"]) < 0.02  # rad
    assert not any(out["limit_exceeded"])
    assert len(out["p_hat_final"]) == 36


def test_the_end_effector_figure_draws_the_distance_pinocchio_gives(tmp_path: Path) -> None:
    """The right panel's curve is |x − x_d| [mm] from Pinocchio's frame placements at every
    sample; the left panel draws the plane the desired path spans most (y-z for the square)."""
    from twolink_pin.plotting.cartesian import _end_effector_figure, save_end_effector_figure

    robot = _robot("ur5")
    trajectory = read_trajectory_file(Path(__file__).parents[1] / "examples" / "ur5_square.toml", robot)
    controller, plant = make_scenario("adaptive", robot)
    result = simulate(controller, plant, trajectory, SimulationConfig(duration=0.5))
    data = robot.create_data()
    expected = []
    for q, qd in zip(result.q, result.q_des):
        pin.framesForwardKinematics(robot.model, data, qd)
        x_d = data.oMf[robot.ee_frame_id].translation.copy()
        pin.framesForwardKinematics(robot.model, data, q)
        expected.append(np.linalg.norm(data.oMf[robot.ee_frame_id].translation - x_d) * 1e3)
    fig = _end_effector_figure(robot, result)
    path_ax, error_ax = fig.axes
    np.testing.assert_allclose(error_ax.get_lines()[0].get_ydata(), expected, rtol=1e-12)
    assert path_ax.get_xlabel() == "y [m]" and path_ax.get_ylabel() == "z [m]"
    written = save_end_effector_figure(robot, result, tmp_path / "ee.png")
    assert written.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_pandas_home_is_its_srdf_default_pose_printed_exactly(capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 38 §9: the SRDF's "default" state writes (0, −π/4, 0, −3π/4, 0, π/2, π/4) to 6 digits
    and cuts π/2 to 1.5707; the profile holds the fractions of π (each within 1e-4 rad of the
    file's digits), and ``info`` prints them as they are (was q6 = 1.5707)."""
    import math
    import re
    import xml.etree.ElementTree as ET

    from twolink_pin.cli import main
    from twolink_pin.model import example_robot_urdf

    srdf = ET.parse(example_robot_urdf("panda_description/srdf/panda.srdf")).getroot()
    state = next(s for s in srdf.iter("group_state") if s.get("name") == "default")
    written = [
        float(next(j for j in state if j.get("name") == f"panda_joint{i}").get("value")) for i in range(1, 8)
    ]
    exact = (0.0, -math.pi / 4, 0.0, -3 * math.pi / 4, 0.0, math.pi / 2, math.pi / 4)
    home = load_robot("panda").home
    assert tuple(home) == exact
    np.testing.assert_allclose(written, exact, rtol=0, atol=1e-4)
    assert main(["info", "--robot", "panda"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("home"))
    printed = re.search(r"q = \[(.*)\] rad", line)
    assert printed is not None and tuple(float(x) for x in printed[1].split(",")) == exact
