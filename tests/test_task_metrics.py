"""Task-space errors and metrics against the twolink's closed-form kinematics and Pinocchio's log3."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest_sim import ROBOT, TRAJECTORY

from twolink_pin.controllers import PDFeedforward
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import load_robot
from twolink_pin.plant import Plant
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.task_metrics import TaskMetrics, bounded, task_errors, task_metrics
from twolink_pin.twolink import closed_form


def test_twolink_errors_and_metrics_are_the_closed_form() -> None:
    result = simulate(PDFeedforward(ROBOT), Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=0.5))
    q, qd = np.asarray(result.q), np.asarray(result.q_des)
    l1, l2 = ROBOT.link_lengths
    errors = task_errors(ROBOT, q, qd)
    planar = closed_form.forward_kinematics(q, l1, l2) - closed_form.forward_kinematics(qd, l1, l2)
    np.testing.assert_allclose(errors.position[:, :2], planar, atol=1e-12)
    np.testing.assert_allclose(errors.position[:, 2], 0.0, atol=1e-12)
    turn = np.angle(np.exp(1j * ((q[:, 0] + q[:, 1]) - (qd[:, 0] + qd[:, 1]))))
    np.testing.assert_allclose(errors.orientation[:, 2], turn, atol=1e-9)
    np.testing.assert_allclose(errors.orientation[:, :2], 0.0, atol=1e-12)
    m = task_metrics(result, ROBOT)
    distance = 1e3 * np.linalg.norm(planar, axis=1)
    assert m.position_rms_mm == pytest.approx(np.sqrt(np.mean(distance**2)), rel=1e-9)
    assert m.position_max_mm == pytest.approx(distance.max(), rel=1e-9)
    assert m.position_last_period_max_mm == m.position_max_mm  # the run is shorter than a period
    assert m.orientation_max_deg == pytest.approx(np.degrees(np.abs(turn).max()), rel=1e-6)
    assert m.position_max_mm > 1.0  # the run starts 0.1 rad off


def test_orientation_error_is_pinocchios_log3_on_the_panda() -> None:
    panda = load_robot("panda")
    rng = np.random.default_rng(1)
    q, qd = rng.uniform(-2, 2, (2, 20, 7))
    errors = task_errors(panda, q, qd)
    data = panda.model.createData()
    for k in range(20):
        pin.framesForwardKinematics(panda.model, data, q[k])
        R = data.oMf[panda.ee_frame_id].rotation.copy()
        pin.framesForwardKinematics(panda.model, data, qd[k])
        Rd = data.oMf[panda.ee_frame_id].rotation.copy()
        np.testing.assert_allclose(errors.orientation[k], pin.log3(R @ Rd.T), atol=1e-9)
    with pytest.raises(InvalidParameterError, match="frame"):
        task_errors(panda, q, qd, frame="nope")


def test_errors_below_the_integrators_accuracy_are_printed_as_bounds() -> None:
    """A value below 1 nm or 1e-6 deg is printed ``< 1e-6`` (its digits are rounding that moves
    with the machine's BLAS kernels); above it, 4 significant digits. The numbers keep every digit."""
    m = TaskMetrics(3.068, 34.65, 7.663e-09, 0.6265, 1e-6, 1.274e-09)
    assert m.text() == ("3.068", "34.65", "< 1e-6", "0.6265", "1e-06", "< 1e-6")
    assert m.as_dict()["position_last_period_max_mm"] == 7.663e-09
    assert (
        bounded(-2e-7, 1e-6) == "< 1e-6" and bounded(5e-3, 1e-2) == "< 1e-2" and bounded(0.02, 1e-2) == "0.02"
    )


CORPUS_URDF = ("axis_minus_z", "axis_x", "prismatic", "tool_offset", "rotated_base", "offset_elbow", "arm3")


@pytest.mark.parametrize(
    "source",
    [
        None,
        "double_pendulum",
        "asr_twodof",
        "ur5",
        "panda",
        "kinova",
        "z1",
        *(f"urdf:{n}" for n in CORPUS_URDF),
    ],
)
def test_poses_of_many_configurations_are_pinocchios_forward_kinematics(source: str | None) -> None:
    """Second method: the poses the metrics compose for K configurations at once (revolute
    joints about any axis, prismatic ones, offsets, a tool frame) are Pinocchio's
    ``framesForwardKinematics`` of each, to 1e-12."""
    from pathlib import Path

    from twolink_pin.frame_poses import poses

    if source is not None and source.startswith("urdf:"):
        source = str(Path(__file__).parent / "corpus" / "urdf" / f"{source[5:]}.urdf")
    robot = load_robot(source)
    q = np.random.default_rng(3).uniform(-3.0, 3.0, (60, robot.nq))
    position, rotation = poses(robot, q, robot.ee_frame_id)
    data = robot.model.createData()
    for k in range(len(q)):
        pin.framesForwardKinematics(robot.model, data, q[k])
        placement = data.oMf[robot.ee_frame_id]
        np.testing.assert_allclose(position[k], placement.translation, rtol=0, atol=1e-12)
        np.testing.assert_allclose(rotation[k], placement.rotation, rtol=0, atol=1e-12)


def test_rotation_angle_is_the_norm_of_log3_near_0_and_near_pi() -> None:
    from twolink_pin.frame_poses import Pose, angle_between

    rng = np.random.default_rng(4)
    axes = rng.normal(size=(40, 3))
    axes /= np.linalg.norm(axes, axis=1)[:, None]
    angles = np.concatenate(
        [[0.0, 1e-12, 1e-7], rng.uniform(0, np.pi, 34), [np.pi - 1e-6, np.pi - 1e-9, np.pi]]
    )
    R_des = np.array([pin.exp3(v) for v in rng.normal(size=(40, 3))])
    R = np.array([pin.exp3(a * v) @ Rd for a, v, Rd in zip(angles, axes, R_des, strict=True)])
    expected = [np.linalg.norm(pin.log3(r @ rd.T)) for r, rd in zip(R, R_des, strict=True)]
    entries = [[[R[:, i, j] for j in range(3)] for i in range(3)] for R in (R, R_des)]
    angle = angle_between(Pose([0.0] * 3, entries[0]), Pose([0.0] * 3, entries[1]))
    np.testing.assert_allclose(angle, expected, rtol=0, atol=1e-9)


def reference_task_metrics(robot: object, result: object) -> dict[str, float]:
    """The task metrics of a run computed another way: Pinocchio's FK of each recorded q and
    q_des, the distance and log3's angle sample by sample (RMS over the samples)."""
    model = robot.model  # type: ignore[attr-defined]
    frame = robot.ee_frame_id  # type: ignore[attr-defined]
    data = model.createData()
    t = np.asarray(result.t)  # type: ignore[attr-defined]
    dist, angle = np.empty(len(t)), np.empty(len(t))
    for k in range(len(t)):
        pin.framesForwardKinematics(model, data, result.q[k])  # type: ignore[attr-defined]
        actual = data.oMf[frame].copy()
        pin.framesForwardKinematics(model, data, result.q_des[k])  # type: ignore[attr-defined]
        desired = data.oMf[frame]
        dist[k] = 1e3 * np.linalg.norm(actual.translation - desired.translation)
        angle[k] = np.degrees(np.linalg.norm(pin.log3(actual.rotation @ desired.rotation.T)))
    last = t >= t[-1] - result.reference_period - 1e-12  # type: ignore[attr-defined]
    return {
        "position_rms_mm": float(np.sqrt(np.mean(dist**2))),
        "position_max_mm": float(dist.max()),
        "position_last_period_max_mm": float(dist[last].max()),
        "orientation_rms_deg": float(np.sqrt(np.mean(angle**2))),
        "orientation_max_deg": float(angle.max()),
        "orientation_last_period_max_deg": float(angle[last].max()),
    }


def test_simulate_prints_a_joint_laws_task_errors_as_fk_of_its_run_gives_them(
    tmp_path: object, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 38 §8: ``simulate computed-torque --robot ur5`` (a joint-space law) reports the end
    effector's errors, equal to FK of its saved q against q_des (Pinocchio, log3)."""
    import json
    from pathlib import Path

    from twolink_pin.cli import main
    from twolink_pin.simulation.storage import load_result

    saved = Path(str(tmp_path)) / "run.npz"
    argv = ["simulate", "computed-torque", "--robot", "ur5", "--duration", "0.2", "--save", str(saved)]
    assert main([*argv, "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)["task_metrics"]
    expected = reference_task_metrics(load_robot("ur5"), load_result(saved))
    assert printed == pytest.approx(expected, rel=1e-9, abs=1e-12)
    assert printed["position_max_mm"] > 1.0  # the run starts 0.05 rad off on each joint
    assert main(argv[:-2]) == 0  # and the text summary has its two lines
    text = capsys.readouterr().out
    assert "task |p − p_d| RMS" in text and "task angle     RMS" in text
